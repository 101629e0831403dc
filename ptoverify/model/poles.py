"""Closed-loop poles of the PD loop and of the PTO linear zone (eq. 37), python-control.

Both loops are state feedback u = -K x on the plant of eq. (1),
A = [[0, 1], [0, -a]], B = [[0], [a]]:

* PD: K = [kp, kd] (u = -kp x1 - kd x2);
* linear zone, eq. (34): K = [k1, k2], whose continuous closed loop is eq. (37),
  x2' = -a k1 x1 - a (1 + k2) x2.

Continuous loop: poles of A - B K.  Sampled loop: the plant is sampled with
zero-order hold at T (``control.sample_system(..., method="zoh")``), the law
is applied at the samples, poles of Ad - Bd K.  The loop is broken at the plant
input for the margins: L(z) = K (zI - Ad)^-1 Bd (``control.stability_margins``).
The saturation is ignored here: these are the small-signal loops.

Independent reference: numpy eigenvalues of Ad - Bd K with Ad, Bd from
:func:`ptoverify.model.plant.zoh_matrices` (closed form, not python-control).

Section 5's Lyapunov argument (eqs. 38-39) gives k1 > 0, 1 + k2 > 0 for the
continuous loop (37).  :func:`lyapunov_counterexample` shows by computation that
these conditions do not make the sampled loop stable.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config
from ptoverify.model.memo import memo
from ptoverify.model.plant import zoh_matrices

__all__ = [
    "LoopPoles",
    "loop_poles",
    "all_loop_poles",
    "sampled_spectral_radius",
    "spectral_radii",
    "critical_gain",
    "lyapunov_counterexample",
]


def _pairs(z: np.ndarray) -> list[list[float]]:
    """Complex numbers as [re, im] pairs (JSON-able), sorted by real then imaginary part."""
    z = np.sort_complex(np.asarray(z, dtype=complex))
    return [[float(v.real), float(v.imag)] for v in z]


@dataclass(frozen=True)
class LoopPoles:
    """Poles, damping, natural frequency and margins of one state-feedback loop.

    Attributes
    ----------
    name : str
        ``pd`` or ``linear``.
    gains : list of float
        K = [k_x1 [1/s], k_x2 [-]].
    sample_time : float
        T [s].
    continuous_poles, sampled_poles : list of [re, im]
        Poles [1/s] and z-plane poles [-], from python-control.
    continuous_wn, continuous_zeta : list of float
        Natural frequency [rad/s] and damping ratio [-] per continuous pole.
    sampled_wn, sampled_zeta : list of float
        The same for the sampled poles mapped by s = ln(z) / T (``control.damp``).
    sampled_moduli : list of float
        |z| of the sampled poles [-].
    numpy_sampled_poles : list of [re, im]
        Independent eigenvalues of Ad - Bd K (closed-form ZOH matrices).
    pole_mismatch : float
        max |python-control - numpy| over the sorted sampled poles [-].
    gain_margin, phase_margin_deg, stability_margin : float
        Margins of the sampled loop broken at the plant input [-], [deg], [-].
        The gain margin includes the phase crossover at the Nyquist frequency
        z = -1, where L is real; python-control 0.10 does not report a crossover
        at that end point (see ``gain_margin_python_control``).
    gain_margin_python_control : float
        ``control.stability_margins`` as returned [-].
    gain_margin_eig : float
        Independent gain margin: the scale g of K at which max |eig(Ad - g Bd K)|
        reaches 1 (bisection) [-].
    phase_crossover, gain_crossover : float
        Their frequencies [rad/s].
    stable_continuous, stable_sampled : bool
        All poles in the open left half-plane / inside the unit circle.
    lyapunov_conditions : bool
        k_x1 > 0 and 1 + k_x2 > 0 (Section 5).
    gain_margin_db : float
        ``gain_margin`` in decibels, 20 log10 of it [dB].
    delay_margin_samples : int
        Most whole samples of computation delay (u_k applied at k + n) with which the
        sampled loop stays stable, from 0 up to :data:`MAX_DELAY_SAMPLES`; -1 when it is
        unstable without delay [samples].
    """

    name: str
    gains: list[float]
    sample_time: float
    continuous_poles: list[list[float]]
    continuous_wn: list[float]
    continuous_zeta: list[float]
    sampled_poles: list[list[float]]
    sampled_moduli: list[float]
    sampled_wn: list[float]
    sampled_zeta: list[float]
    numpy_sampled_poles: list[list[float]]
    pole_mismatch: float
    gain_margin: float
    gain_margin_python_control: float
    gain_margin_eig: float
    phase_margin_deg: float
    stability_margin: float
    phase_crossover: float
    gain_crossover: float
    stable_continuous: bool
    stable_sampled: bool
    lyapunov_conditions: bool
    gain_margin_db: float = math.nan
    delay_margin_samples: int = -1

    def to_json(self) -> dict:
        """Return the record as a JSON-able dict."""
        return asdict(self)


#: Largest computation delay :func:`delay_margin_samples` tries [samples].
MAX_DELAY_SAMPLES = 20


def delayed_loop_radius(a: float, T: float, k_x1: float, k_x2: float, delay: int) -> float:  # noqa: N803
    """Spectral radius of the sampled loop with ``delay`` samples of computation delay.

    The state is augmented with the ``delay`` inputs still in flight:
    x_{k+1} = Ad x_k + Bd u_{k-delay}, u_k = -K x_k.

    Parameters
    ----------
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : float
        Gains [1/s], [-] of u = -k_x1 x1 - k_x2 x2.
    delay : int
        Computation delay [samples], >= 0.

    Returns
    -------
    float
        Largest |z| [-]; < 1 means stable.

    Examples
    --------
    >>> r0 = delayed_loop_radius(188.5, 0.002, 356.0, 1.15, 0)
    >>> abs(r0 - sampled_spectral_radius(188.5, 0.002, 356.0, 1.15)) < 1e-12
    True
    """
    if delay == 0:
        return sampled_spectral_radius(a, T, k_x1, k_x2)  # the undelayed loop, one path
    Ad, Bd = zoh_matrices(a, T)
    K = np.array([[k_x1, k_x2]])
    n = 2 + delay
    M = np.zeros((n, n))
    M[:2, :2] = Ad
    M[:2, n - 1 : n] = Bd  # the oldest input in flight acts now
    M[2, :2] = -K[0]  # u_k enters the register
    for i in range(3, n):
        M[i, i - 1] = 1.0
    return float(np.abs(np.linalg.eigvals(M)).max())


def delay_margin_samples(a: float, T: float, k_x1: float, k_x2: float) -> int:  # noqa: N803
    """Return the most whole samples of computation delay the sampled loop tolerates.

    Parameters
    ----------
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : float
        Gains [1/s], [-].

    Returns
    -------
    int
        Largest n <= :data:`MAX_DELAY_SAMPLES` with the loop stable for every delay
        0..n [samples]; -1 when unstable without delay.
    """
    n = -1
    for d in range(MAX_DELAY_SAMPLES + 1):
        if delayed_loop_radius(a, T, k_x1, k_x2, d) >= 1.0:
            break
        n = d
    return n


def _plant(a: float) -> tuple[np.ndarray, np.ndarray]:
    return np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])


def _scale_margin(Ad: np.ndarray, Bd: np.ndarray, K: np.ndarray) -> float:  # noqa: N803
    """Scale g of K at which the sampled loop reaches |z| = 1 (inf beyond 1e6)."""

    def radius(g: float) -> float:
        return float(np.abs(np.linalg.eigvals(Ad - g * Bd @ K)).max())

    if radius(1.0) >= 1:
        return float("nan")
    lo, hi = 1.0, 2.0
    while radius(hi) < 1:
        lo, hi = hi, 2.0 * hi
        if hi > 1e6:
            return math.inf
    while hi - lo > 1e-12 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radius(mid) < 1 else (lo, mid)
    return hi


def sampled_spectral_radius(a: float, T: float, k_x1: float, k_x2: float) -> float:  # noqa: N803
    """Largest |z| of the sampled loop Ad - Bd K (numpy, closed-form ZOH).

    Parameters
    ----------
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : float
        Gains [1/s], [-] of u = -k_x1 x1 - k_x2 x2.

    Returns
    -------
    float
        Spectral radius [-]; < 1 means the sampled loop is stable.
    """
    return float(spectral_radii(a, T, k_x1, k_x2)[0])


def spectral_radii(a: float, T: float, k_x1: ArrayLike, k_x2: ArrayLike) -> NDArray[np.float64]:  # noqa: N803
    """Spectral radius of the sampled linear loop Ad - Bd [k_x1, k_x2], per gain pair.

    Many gain pairs in one stacked eigenvalue call (:func:`sampled_spectral_radius`
    is the one-pair case).

    Parameters
    ----------
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : array_like
        Gains [1/s], [-] of u = -k_x1 x1 - k_x2 x2, one pair per entry.

    Returns
    -------
    ndarray
        Largest |z| per pair [-]; < 1 means the sampled loop is stable.

    Examples
    --------
    >>> bool(spectral_radii(188.5, 0.002, [356.0], [0.62])[0] < 1.0)
    True
    """
    Ad, Bd = zoh_matrices(a, T)
    k = np.stack(np.broadcast_arrays(np.asarray(k_x1, float), np.asarray(k_x2, float)), axis=-1)
    return np.abs(np.linalg.eigvals(Ad - Bd @ k.reshape(-1, 1, 2))).max(axis=-1)


def loop_poles(name: str, a: float, T: float, k_x1: float, k_x2: float) -> LoopPoles:  # noqa: N803
    """Analyse the loop u = -k_x1 x1 - k_x2 x2, continuous and ZOH-sampled.

    Parameters
    ----------
    name : str
        Label of the loop.
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : float
        Gains [1/s], [-].

    Returns
    -------
    LoopPoles
        Poles, damping, natural frequencies and sampled-loop margins.

    Examples
    --------
    >>> lp = loop_poles("linear", 188.5, 0.002, 323.0, 3.6)
    >>> lp.stable_continuous, lp.pole_mismatch < 1e-12
    (True, True)
    """
    return _loop_poles(str(name), float(a), float(T), float(k_x1), float(k_x2))


@memo(maxsize=64)
def _loop_poles(name: str, a: float, T: float, k_x1: float, k_x2: float) -> LoopPoles:  # noqa: N803
    """Analyse one loop (:func:`loop_poles`), memoized on the scalar arguments.

    The report's poles section and the two sampled-stability gates read the same loops.
    """
    import control as ct  # here, not at import: python-control pulls in scipy.signal and pyplot

    A, B = _plant(a)
    K = np.array([[k_x1, k_x2]])
    cl = ct.ss(A - B @ K, B, np.eye(2), np.zeros((2, 1)))
    wn_c, zeta_c, p_c = ct.damp(cl, doprint=False)
    plant_d = ct.sample_system(ct.ss(A, B, np.eye(2), np.zeros((2, 1))), T, method="zoh")
    Ad, Bd = plant_d.A, plant_d.B
    cl_d = ct.ss(Ad - Bd @ K, Bd, np.eye(2), np.zeros((2, 1)), T)
    wn_d, zeta_d, p_d = ct.damp(cl_d, doprint=False)
    loop = ct.ss(Ad, Bd, K, np.zeros((1, 1)), T)  # broken at the plant input
    # epsw: the plant's integrator puts a pole of L at z = 1; frequencies below
    # 1e-3 rad/s are static gain, not a crossover (avoids a spurious gm at w = 0)
    gm, pm, sm, wpc, wgc, _ = ct.stability_margins(loop, epsw=1e-3)
    l_nyq = complex(loop(-1.0))  # L at the Nyquist frequency
    gm_nyq = -1.0 / l_nyq.real if l_nyq.real < 0 else math.inf
    Ad_n, Bd_n = zoh_matrices(a, T)
    p_n = np.linalg.eigvals(Ad_n - Bd_n @ K)
    mismatch = float(np.abs(np.sort_complex(ct.poles(cl_d)) - np.sort_complex(p_n)).max())
    return LoopPoles(
        name=name,
        gains=[float(k_x1), float(k_x2)],
        sample_time=float(T),
        continuous_poles=_pairs(p_c),
        continuous_wn=[float(v) for v in wn_c],
        continuous_zeta=[float(v) for v in zeta_c],
        sampled_poles=_pairs(p_d),
        sampled_moduli=[float(v) for v in np.abs(p_d)],
        sampled_wn=[float(v) for v in wn_d],
        sampled_zeta=[float(v) for v in zeta_d],
        numpy_sampled_poles=_pairs(p_n),
        pole_mismatch=mismatch,
        gain_margin=float(min(gm, gm_nyq)),
        gain_margin_python_control=float(gm),
        gain_margin_eig=_scale_margin(Ad_n, Bd_n, K),
        phase_margin_deg=float(pm),
        stability_margin=float(sm),
        phase_crossover=float(wpc),
        gain_crossover=float(wgc),
        stable_continuous=bool(np.all(np.real(p_c) < 0)),
        stable_sampled=bool(np.all(np.abs(p_d) < 1)),
        lyapunov_conditions=bool(k_x1 > 0 and 1 + k_x2 > 0),
        gain_margin_db=float(20.0 * math.log10(min(gm, gm_nyq)))
        if 0 < min(gm, gm_nyq) < math.inf
        else math.nan,
        delay_margin_samples=delay_margin_samples(a, T, k_x1, k_x2),
    )


def all_loop_poles(cfg: Config) -> dict[str, LoopPoles]:
    """Return the PD loop and the linear-zone loop (eq. 37) for a configuration.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], T [s], kp, kd, k1, k2).

    Returns
    -------
    dict
        ``pd`` and ``linear`` -> :class:`LoopPoles`.
    """
    a, T = cfg.plant.a, cfg.plant.sample_time
    return {
        "pd": loop_poles("pd", a, T, cfg.pd.kp, cfg.pd.kd),
        "linear": loop_poles("linear", a, T, cfg.pto.k1, cfg.pto.k2),
    }


def critical_gain(
    a: float,
    T: float,
    k_x1: float,
    k_x2: float,
    which: str = "k1",  # noqa: N803
    upper: float = 1e7,
) -> float:
    """Gain at which a sampled pole of the linear loop reaches |z| = 1.

    The gain named by ``which`` is raised from its given value (kept stable) by
    doubling until the sampled loop is unstable, then bisected to 1e-12 relative.
    The crossing is unique: the closed-loop characteristic polynomial
    z^2 + c1 z + c0 has coefficients affine in the gains, and the Jury
    conditions |c0| < 1, 1 + c1 + c0 > 0, 1 - c1 + c0 > 0 are linear in them,
    so the stable set along one gain is an interval.

    Parameters
    ----------
    a : float
        Bandwidth [rad/s].
    T : float
        Sampling period [s].
    k_x1, k_x2 : float
        Starting gains [1/s], [-]; the sampled loop must be stable there.
    which : {"k1", "k2"}
        Gain to raise.
    upper : float
        Give up beyond this gain (returns inf).

    Returns
    -------
    float
        The critical value of the raised gain.
    """

    def radius(g: float) -> float:
        return (
            sampled_spectral_radius(a, T, g, k_x2)
            if which == "k1"
            else sampled_spectral_radius(a, T, k_x1, g)
        )

    lo = k_x1 if which == "k1" else k_x2
    lo = max(lo, 1e-9)
    if radius(lo) >= 1:
        raise ValueError("the starting gains must give a stable sampled loop")
    hi = 2.0 * lo
    while radius(hi) < 1:
        lo, hi = hi, 2.0 * hi
        if hi > upper:
            return math.inf
    while hi - lo > 1e-12 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if radius(mid) < 1 else (lo, mid)
    return hi


def lyapunov_counterexample(cfg: Config, factor: float = 1.2, steps: int = 200) -> dict:
    """Show that k1 > 0, 1 + k2 > 0 (Section 5) do not make the sampled loop stable.

    For the linear zone, k1 is raised with k2 fixed (and k2 with k1 fixed) until
    a sampled pole leaves the unit circle; at ``factor`` times the critical gain
    the Lyapunov conditions still hold and the continuous loop (37) is stable, but
    the sampled loop is not.  An independent simulation of the sampled linear
    loop (exact ZOH flow) from x = (d, 0) confirms the growth.

    Parameters
    ----------
    cfg : Config
        Configuration.
    factor : float
        Multiple of the critical gain used for the counterexample.
    steps : int
        Samples simulated.

    Returns
    -------
    dict
        ``k1_critical``, ``k2_critical`` and, per raised gain, the counterexample
        loop (:class:`LoopPoles` as dict) and the growth |x1_N| / |x1_0|.
    """
    a, T = cfg.plant.a, cfg.plant.sample_time
    k1, k2 = cfg.pto.k1, cfg.pto.k2
    out: dict = {}
    Ad, Bd = zoh_matrices(a, T)
    for which in ("k1", "k2"):
        crit = critical_gain(a, T, k1, k2, which)
        g1, g2 = (factor * crit, k2) if which == "k1" else (k1, factor * crit)
        lp = loop_poles(f"linear-{which}-raised", a, T, g1, g2)
        K = np.array([[g1, g2]])
        x = np.array([cfg.pto.d or 1.0, 0.0])
        x0 = abs(x[0])
        for _ in range(steps):
            x = Ad @ x - (Bd @ (K @ x)).ravel()
        out[f"{which}_critical"] = crit
        out[f"{which}_raised"] = {"loop": lp.to_json(), "growth": float(abs(x[0]) / x0)}
    return out
