"""Sampled-data closed loop, exact between samples (ZOH flow, no Euler).

At each sample t_k = k T the law sees the error state and its input is held
for one period; the plant moves by its exact flow (eq. 7)::

    e1_k = x1_k - r_k,   e2_k = x2_k - f * r'_k          (f = 1 with feed-forward)
    u_k  = sat(f * r'_k + law(e1_k, e2_k))
    x_{k+1} = flow(x_k, u_k, T)

The Section 6 references are a 5 mm step, a ramp from 0 to 30 mm at
200 mm/s, and a 5 mm, 5 Hz sine.  The paper does not say how its laws track
a moving reference; ``feedforward`` selects the reading (with reference
velocity feed-forward, the error obeys the plant's own dynamics for a ramp).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.laws import Law

__all__ = [
    "Reference",
    "reference",
    "SIGNALS",
    "SimResult",
    "simulate",
    "BatchResult",
    "Mismatch",
    "simulate_batch",
]


@dataclass(frozen=True)
class Reference:
    """A reference signal r(t) with its derivative.

    Attributes
    ----------
    name : str
        ``step``, ``ramp`` or ``sine``.
    amplitude : float
        Step height, ramp end value or sine amplitude [mm].
    rate : float
        Ramp slope [mm/s] or sine frequency [Hz] (unused for the step).
    duration : float
        Default simulated time [s].
    """

    name: str
    amplitude: float
    rate: float
    duration: float

    def r(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the reference position [mm] at times t [s]."""
        if self.name == "step":
            return np.full_like(t, self.amplitude)
        if self.name == "ramp":
            return np.minimum(self.rate * t, self.amplitude)
        return self.amplitude * np.sin(2.0 * math.pi * self.rate * t)

    def r_dot(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the reference velocity [mm/s] at times t [s] (0 for the step)."""
        if self.name == "step":
            return np.zeros_like(t)
        if self.name == "ramp":
            return np.where(self.rate * t < self.amplitude, self.rate, 0.0)
        omega = 2.0 * math.pi * self.rate
        return self.amplitude * omega * np.cos(omega * t)


SIGNALS: dict[str, Reference] = {
    "step": Reference("step", 5.0, 0.0, 0.2),
    "ramp": Reference("ramp", 30.0, 200.0, 0.4),
    "sine": Reference("sine", 5.0, 5.0, 1.0),
}


def reference(name: str) -> Reference:
    """Return the Section 6 reference called ``name`` (step, ramp, sine)."""
    try:
        return SIGNALS[name]
    except KeyError:
        raise InputError(f"unknown signal '{name}' (choose from step, ramp, sine)") from None


@dataclass(frozen=True)
class SimResult:
    """A sampled closed-loop response; arrays of length n + 1 (samples 0..n).

    Attributes
    ----------
    law, signal : str
        What was simulated.
    feedforward : bool
        Whether the reference velocity was fed forward.
    t : ndarray
        Sample times [s].
    r, r_dot : ndarray
        Reference [mm] and its velocity [mm/s].
    x1, x2 : ndarray
        Position [mm] and velocity [mm/s] at the samples.
    e : ndarray
        Control error r - x1 [mm].
    u : ndarray
        Input held from each sample to the next [mm/s] (the last is computed, not applied).
    region : ndarray of int8
        :class:`~ptoverify.laws.Region` code of each sample.
    """

    law: str
    signal: str
    feedforward: bool
    t: NDArray[np.float64]
    r: NDArray[np.float64]
    r_dot: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    e: NDArray[np.float64]
    u: NDArray[np.float64]
    region: NDArray[np.int8]

    def columns(self) -> dict[str, NDArray]:
        """Return the time series as named columns (for CSV and JSON)."""
        return {
            "t": self.t,
            "r": self.r,
            "x1": self.x1,
            "x2": self.x2,
            "e": self.e,
            "u": self.u,
            "region": self.region,
        }


def simulate(
    law: Law,
    plant: Plant,
    signal: str | Reference = "step",
    *,
    duration: float | None = None,
    feedforward: bool = True,
) -> SimResult:
    """Simulate the sampled closed loop tracking a reference from rest at 0.

    Parameters
    ----------
    law : Law
        Feedback law.
    plant : Plant
        Plant and sample time.
    signal : str or Reference
        ``step``, ``ramp``, ``sine`` or a :class:`Reference`.
    duration : float, optional
        Simulated time [s]; default the signal's.
    feedforward : bool
        Feed the reference velocity forward (see module docstring).

    Returns
    -------
    SimResult
        The response at the samples.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.laws import pd_law
    >>> cfg = paper_config()
    >>> res = simulate(pd_law(cfg), cfg.plant, "step")
    >>> bool(abs(res.e[-1]) < 1e-6)
    True
    """
    ref = reference(signal) if isinstance(signal, str) else signal
    duration = ref.duration if duration is None else duration
    n = int(round(duration / plant.sample_time))
    t = np.arange(n + 1) * plant.sample_time
    r, r_dot = ref.r(t), ref.r_dot(t)
    ff = r_dot if feedforward else np.zeros_like(r_dot)
    x1, x2 = np.zeros(n + 1), np.zeros(n + 1)
    u, region = np.zeros(n + 1), np.zeros(n + 1, dtype=np.int8)
    w, a, T = plant.w_max, plant.a, plant.sample_time
    g = -math.expm1(-a * T)
    law_scalar = law.scalar
    for k in range(n + 1):
        v, region[k] = law_scalar(float(x1[k] - r[k]), float(x2[k] - ff[k]))
        uk = min(max(v + ff[k], -w), w)
        u[k] = uk
        if k < n:
            dv = x2[k] - uk
            x1[k + 1] = x1[k] + uk * T + dv * g / a
            x2[k + 1] = x2[k] - dv * g
    return SimResult(law.name, ref.name, feedforward, t, r, r_dot, x1, x2, r - x1, u, region)


@dataclass(frozen=True)
class Mismatch:
    """How the simulated plant and measurement differ from the design.

    The law is always the nominal one; only the plant it drives and what it
    measures change.  The identity mismatch (the default) reproduces the
    nominal loop bit for bit.

    Attributes
    ----------
    a_ratio : float or ndarray, shape (n,)
        True bandwidth over design bandwidth a [-], per state or shared.
    w_max_ratio : float or ndarray, shape (n,)
        The drive saturates at ``w_max_ratio * w_max`` [-] (at or below what the
        law assumes); the commanded input is recorded unclipped.
    delay_samples : int
        Computation delay: the input computed from x_k is applied from sample
        k + delay.  Before the first computed input acts, the loop holds the
        input computed from the initial state (the controller was already running).
    position_quantum : float
        Encoder resolution [mm]: the law sees ``q round(x1 / q)`` (0: exact).
    velocity_noise : float
        Standard deviation of Gaussian noise on the measured x2 [mm/s] (0: none).
        One sequence (seeded) is drawn per run and added to every state of the
        batch, so a state's trajectory does not depend on the batch it ran in.
    seed : int
        Seed of the noise sequence.
    """

    a_ratio: float | NDArray[np.float64] = 1.0
    w_max_ratio: float | NDArray[np.float64] = 1.0
    delay_samples: int = 0
    position_quantum: float = 0.0
    velocity_noise: float = 0.0
    seed: int = 0

    @property
    def is_identity(self) -> bool:
        """Whether this is the nominal loop (no mismatch of any kind)."""
        return (
            np.all(np.asarray(self.a_ratio) == 1.0)
            and np.all(np.asarray(self.w_max_ratio) == 1.0)
            and self.delay_samples == 0
            and self.position_quantum == 0.0
            and self.velocity_noise == 0.0
        )

    def to_json(self) -> dict:
        """Return the mismatch as a JSON-able dict (arrays as lists)."""

        def num(v):
            v = np.asarray(v, dtype=float)
            return float(v) if v.ndim == 0 else v.tolist()

        return {
            "a_ratio": num(self.a_ratio),
            "w_max_ratio": num(self.w_max_ratio),
            "delay_samples": int(self.delay_samples),
            "position_quantum": float(self.position_quantum),
            "velocity_noise": float(self.velocity_noise),
            "seed": int(self.seed),
        }


@dataclass(frozen=True)
class BatchResult:
    """Regulation to the origin from many initial states.

    Attributes
    ----------
    x1, x2 : ndarray, shape (steps + 1, n)
        States at the samples [mm], [mm/s].
    u : ndarray, shape (steps, n)
        Inputs [mm/s].
    region : ndarray of int8, shape (steps, n)
        Region codes.
    mismatch : Mismatch or None
        The plant/measurement mismatch simulated (None: the nominal loop).
    """

    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    u: NDArray[np.float64]
    region: NDArray[np.int8]
    mismatch: Mismatch | None = None


def simulate_batch(
    law: Law,
    plant: Plant,
    x1: ArrayLike,
    x2: ArrayLike,
    steps: int,
    *,
    mismatch: Mismatch | None = None,
) -> BatchResult:
    """Simulate the sampled loop to the origin from many initial states at once.

    Parameters
    ----------
    law : Law
        Feedback law (its vectorized path is used).
    plant : Plant
        Design plant and sample time (the law's).
    x1, x2 : array_like, shape (n,)
        Initial states [mm], [mm/s].
    steps : int
        Number of samples.
    mismatch : Mismatch, optional
        True plant and measurement relative to ``plant`` (see :class:`Mismatch`);
        None or the identity is the nominal loop, bit for bit.

    Returns
    -------
    BatchResult
        The trajectories; ``u`` is the commanded input of each sample.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.laws import pd_law
    >>> cfg = paper_config()
    >>> b = simulate_batch(pd_law(cfg), cfg.plant, [5.0], [0.0], 300)
    >>> bool(abs(b.x1[-1, 0]) < 1e-6)
    True
    >>> slow = simulate_batch(pd_law(cfg), cfg.plant, [5.0], [0.0], 300,
    ...                       mismatch=Mismatch(a_ratio=0.8, delay_samples=1))
    >>> bool(abs(slow.x1[-1, 0]) < 1e-3), bool(slow.x1[40, 0] != b.x1[40, 0])
    (True, True)
    """
    if mismatch is not None and not mismatch.is_identity:
        return _simulate_mismatch(law, plant, x1, x2, steps, mismatch)
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    n = x1.shape[0]
    X1, X2 = np.empty((steps + 1, n)), np.empty((steps + 1, n))
    U, R = np.empty((steps, n)), np.empty((steps, n), dtype=np.int8)
    X1[0], X2[0] = x1, x2
    T, a = plant.sample_time, plant.a
    g = -np.expm1(-a * np.float64(T))  # 1 - e^{-aT}, as plant.flow computes it
    dv = np.empty(n)
    for k in range(steps):
        U[k], R[k] = law(X1[k], X2[k])
        # plant.flow in place, the same roundings: x1 + u T + (x2 - u) g / a, x2 - (x2 - u) g
        np.subtract(X2[k], U[k], out=dv)
        dv *= g
        np.subtract(X2[k], dv, out=X2[k + 1])
        np.multiply(U[k], T, out=X1[k + 1])
        X1[k + 1] += X1[k]
        dv /= a
        X1[k + 1] += dv
    return BatchResult(X1, X2, U, R, mismatch)


def _simulate_mismatch(
    law: Law, plant: Plant, x1: ArrayLike, x2: ArrayLike, steps: int, m: Mismatch
) -> BatchResult:
    """Run the loop of :func:`simulate_batch` with a true plant and a measurement model."""
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    n = x1.shape[0]
    if m.delay_samples < 0 or m.position_quantum < 0 or m.velocity_noise < 0:
        raise InputError("mismatch: delay, quantum and noise must be >= 0")
    X1, X2 = np.empty((steps + 1, n)), np.empty((steps + 1, n))
    U, R = np.empty((steps, n)), np.empty((steps, n), dtype=np.int8)
    X1[0], X2[0] = x1, x2
    T = plant.sample_time
    a = plant.a * np.broadcast_to(np.asarray(m.a_ratio, dtype=float), (n,))
    w_true = plant.w_max * np.broadcast_to(np.asarray(m.w_max_ratio, dtype=float), (n,))
    g = -np.expm1(-a * T)
    q = float(m.position_quantum)
    noise = (
        np.random.default_rng(m.seed).normal(0.0, m.velocity_noise, steps)
        if m.velocity_noise > 0
        else np.zeros(steps)
    )
    pending: list[np.ndarray] = []  # commanded inputs not yet applied (the delay line)
    applied = None
    for k in range(steps):
        y1 = q * np.round(X1[k] / q) if q > 0 else X1[k]
        y2 = X2[k] + noise[k]
        U[k], R[k] = law(y1, y2)
        pending.append(U[k])
        if applied is None:  # the controller was running: hold what x_0 commands
            applied = U[0]
        if len(pending) > m.delay_samples:
            applied = pending.pop(0)
        uk = np.clip(applied, -w_true, w_true)
        dv = (X2[k] - uk) * g
        X2[k + 1] = X2[k] - dv
        X1[k + 1] = X1[k] + uk * T + dv / a
    return BatchResult(X1, X2, U, R, m)
