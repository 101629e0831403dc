"""Response metrics on the exact continuous trajectory, between the samples.

Within a sample the input u_k is held, so the plant follows eq. (7) exactly::

    x2(s) = u + (x2k - u) e^{-a s}
    x1(s) = x1k + u s + (x2k - u)(1 - e^{-a s}) / a,     0 <= s <= T_k

Every metric here is read on that continuous trajectory, never by
sub-sampling.  The error e(t) = r(t) - x1(t) has its extrema where
e'(s) = r'(t) - x2(s) = 0: in closed form for a step or ramp (x2(s) = r' has one
root, s* = ln((x2k - u)/(r' - u)) / a; for x1, s* = ln((u - x2k)/u) / a), and for a
sine by bracketed Newton on pieces where e' has at most one zero: e^{as} e'(s) is
monotone between the roots of cos(omega t + phi) = a (u - r'_lin)/(A omega R),
R = sqrt(a^2 + omega^2), phi = atan2(omega, a), which are closed form.  Between
its extrema e is monotone, so every band or level crossing is unique on its
piece and is found by ``brentq`` to round-off.

Definitions (the sample-grid value, returned side by side, is the same
definition restricted to the samples t_k):

* overshoot: max(0, max_t s (x1(t) - r_end)), s = sign(r_end - x1(t_0)) [mm];
* settling to a band: the last exit time of |e(t)| from the band, measured from
  t_0; 0 if never outside, NaN if the record ends outside [s] (bands: 2 % of the
  reference's size -- step height, ramp end value, sine amplitude -- and 0.01 mm);
* rise time: first time x1 reaches 90 % minus first time it reaches 10 % of the
  way from x1(t_0) to r_end [s] (step and ramp);
* linear zone: the first time the state is in {|x1 - r| <= d, |x2 - r'| <= v_max}
  (the PTO law's zone is |x1 - r| < d with v_max = inf; the grid uses the law's
  strict < d) [s];
* phase delay (sine): phase(r) - phase(x1) [deg] of the continuous least-squares
  fundamental over whole periods ending at the record's end and starting at or
  after one period: over whole periods sin, cos and 1 are orthogonal, so the fit
  is three integrals, computed per sample interval by 8-point Gauss-Legendre on
  panels with (a + omega) h <= 1.  The integrand is entire, its 16th derivative
  at most (a + omega)^16 times its scale, so the quadrature remainder is below
  2e-23 of the integral's scale: exact to round-off (no analytic antiderivative,
  whose differences would cancel for small omega h).

A metric's exact and grid values are flagged ``differs`` when they differ by
more than :data:`TIME_TOL_SAMPLES` sample periods (times), :data:`POSITION_TOL`
(overshoot) or :data:`PHASE_TOL_DEG` (phase).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.errors import InputError
from ptoverify.sim.events import (
    grid_first,
    grid_phase,
    grid_rise_time,
    linear_zone_entry,
    linear_zone_time,
    rise_pair,
    rise_time,
    sine_phase,
)
from ptoverify.sim.flow import (
    Signal,
    Trajectory,
    as_float_array,
    as_signal,
    monotone_pieces,
)
from ptoverify.sim.settling import (
    DEFINITIONS,
    Settling,
    SettlingDefinition,
    overshoot,
    settling_time,
)

__all__ = [
    "TIGHT_BAND",
    "STEP_FRACTION",
    "TIME_TOL_SAMPLES",
    "POSITION_TOL",
    "PHASE_TOL_DEG",
    "METRIC_KEYS",
    "Signal",
    "as_signal",
    "Trajectory",
    "Compared",
    "ExactMetrics",
    "ResponseMetrics",
    "grid_rise_time",
    "rise_time",
    "linear_zone_time",
    "sine_phase",
    "exact_metrics",
    "metrics_from_arrays",
    "settling_and_overshoot",
    "BatchSettling",
    "settling_times_batch",
]

TIGHT_BAND = DEFINITIONS["0p01mm"].band_mm
"""Tight settling band [mm] (2 % of the paper's linear zone d = 0.5 mm)."""
STEP_FRACTION = DEFINITIONS["2pct"].band_fraction
"""Classical settling band as a fraction of the reference's size [-]."""
TIME_TOL_SAMPLES = 0.01
"""Time metrics differ when |exact - grid| > 0.01 T (T the median sample period)."""
POSITION_TOL = 1e-4
"""Overshoot differs when |exact - grid| > 1e-4 mm (1 % of the tight band)."""
PHASE_TOL_DEG = 0.01
"""Phase delay differs when |exact - grid| > 0.01 deg."""
METRIC_KEYS = (
    "overshoot_mm",
    "settling_2pct_s",
    "settling_0p01mm_s",
    "rise_time_s",
    "phase_delay_deg",
    "linear_zone_s",
)
"""Keys of :meth:`ExactMetrics.exact` (the first five are ``simulate --json`` ``metrics``)."""


@dataclass(frozen=True)
class Compared:
    """A metric on the exact trajectory and on the sample grid.

    Attributes
    ----------
    exact : float
        Between samples (the value to report) [unit of the metric].
    grid : float
        On the samples t_k only.
    tol : float
        Tolerance of :attr:`differs`, same unit.
    accuracy : float
        Bound on the error of :attr:`exact` from root finding and round-off,
        same unit (0 when the value is decided without a root, NaN when the
        metric is undefined); see :func:`metrics_from_arrays`.  Two exact values
        closer than the sum of their accuracies are a true tie
        (:meth:`compare`).
    """

    exact: float
    grid: float
    tol: float
    accuracy: float = 0.0

    @property
    def delta(self) -> float:
        """Return exact - grid (NaN when either is undefined)."""
        return self.exact - self.grid

    @property
    def differs(self) -> bool:
        """True when |exact - grid| > tol, or exactly one of them is NaN."""
        ne, ng = math.isnan(self.exact), math.isnan(self.grid)
        if ne or ng:
            return ne != ng
        return abs(self.exact - self.grid) > self.tol

    def compare(self, other: Compared, *, grid: bool = False) -> int | None:
        """Order two values of one metric: -1 (self smaller), 0 (true tie), +1.

        Exact values tie when |self - other| <= self.accuracy + other.accuracy
        (neither can be told from the other to the precision they are computed
        to); grid values tie only when equal (they are sample times).

        Parameters
        ----------
        other : Compared
            The other response's value of the same metric.
        grid : bool
            Compare the grid values instead of the exact ones.

        Returns
        -------
        int or None
            -1, 0 or +1; None when either value is NaN (undefined, never settled).

        Examples
        --------
        >>> Compared(0.1, 0.1, 0.0, 1e-12).compare(Compared(0.1 + 1e-13, 0.1, 0.0, 1e-12))
        0
        """
        x, y = (self.grid, other.grid) if grid else (self.exact, other.exact)
        if math.isnan(x) or math.isnan(y):
            return None
        tie = 0.0 if grid else self.accuracy + other.accuracy
        return 0 if abs(x - y) <= tie else (-1 if x < y else 1)


@dataclass(frozen=True)
class ResponseMetrics:
    """The ``simulate --json`` ``metrics`` of one response (DESIGN.md).

    Attributes
    ----------
    overshoot_mm : float
        Overshoot past the final value [mm] (NaN for a sine).
    settling_2pct_s : float
        Settling time under the ``2pct`` definition [s] (NaN: never settles).
    settling_0p01mm_s : float
        Settling time under the ``0p01mm`` definition [s] (NaN: never settles).
    rise_time_s : float
        10-90 % rise time [s] (NaN unless a step or ramp).
    phase_delay_deg : float or None
        Phase delay of x1 behind a sine [deg]; None unless the reference is a sine.
    """

    overshoot_mm: float
    settling_2pct_s: float
    settling_0p01mm_s: float
    rise_time_s: float
    phase_delay_deg: float | None = None

    def to_json(self) -> dict[str, float | None]:
        """Return the JSON object: one key per field (NaN as None; no phase unless a sine)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "phase_delay_deg" and v is None:
                continue
            out[f.name] = None if v is None or math.isnan(v) else float(v)
        return out


@dataclass(frozen=True)
class ExactMetrics:
    """Metrics of one response, exact and on the grid, by key (:data:`METRIC_KEYS`).

    Attributes
    ----------
    signal : Signal
        The reference the metrics were measured against.
    values : dict of str to Compared
        ``overshoot_mm``, ``settling_2pct_s``, ``settling_0p01mm_s``,
        ``rise_time_s``, ``phase_delay_deg``, ``linear_zone_s`` (NaN where
        undefined for the signal).
    details : dict of str to float
        ``t_peak_s`` (time of the overshoot), ``band_2pct_mm``,
        ``amplitude_ratio`` and ``fit_from_s`` / ``fit_to_s`` (sine window).
    """

    signal: Signal
    values: dict[str, Compared]
    details: dict[str, float]

    def exact(self) -> dict[str, float]:
        """Exact values by key (for ``simulate --json`` ``metrics``)."""
        return {k: v.exact for k, v in self.values.items()}

    def grid(self) -> dict[str, float]:
        """Sample-grid values by key."""
        return {k: v.grid for k, v in self.values.items()}

    def json_metrics(self, *, grid: bool = False) -> dict[str, float | None]:
        """Return ``simulate --json`` ``metrics`` (DESIGN.md): exact values, None if undefined.

        Keys ``overshoot_mm``, ``settling_2pct_s``, ``settling_0p01mm_s``,
        ``rise_time_s``, and ``phase_delay_deg`` for a sine only.  With
        ``grid=True`` the same keys hold the sample-grid values
        (``simulate --json`` ``metrics_grid``).
        """
        return self.response(grid=grid).to_json()

    def response(self, *, grid: bool = False) -> ResponseMetrics:
        """Return the ``simulate --json`` metrics as a :class:`ResponseMetrics`.

        Parameters
        ----------
        grid : bool
            The sample-grid values instead of the exact ones.

        Returns
        -------
        ResponseMetrics
            The five metrics (phase only for a sine).
        """
        pick = self.grid() if grid else self.exact()
        phase = pick["phase_delay_deg"] if self.signal.kind == "sine" else None
        return ResponseMetrics(
            pick["overshoot_mm"],
            pick["settling_2pct_s"],
            pick["settling_0p01mm_s"],
            pick["rise_time_s"],
            phase,
        )

    def differing(self) -> list[str]:
        """Keys whose exact and grid values differ beyond tolerance."""
        return [k for k, v in self.values.items() if v.differs]


def metrics_from_arrays(
    t: ArrayLike,
    x1: ArrayLike,
    x2: ArrayLike,
    u: ArrayLike,
    a: float,
    reference: Any,
    *,
    d: float | None = None,
    v_max: float = math.inf,
    band: float = TIGHT_BAND,
    step_fraction: float = STEP_FRACTION,
) -> ExactMetrics:
    """All metrics of a sampled response, exact between samples and on the grid.

    Parameters
    ----------
    t : array_like, shape (n + 1,)
        Sample times [s].
    x1, x2 : array_like, shape (n + 1,)
        Position [mm] and velocity [mm/s] at the samples.
    u : array_like, shape (n,) or (n + 1,)
        Input held on [t_k, t_k+1) [mm/s] (a trailing unused value is ignored).
    a : float
        Bandwidth [rad/s].
    reference : Signal, Reference-like or tuple
        The reference r(t) (see :func:`as_signal`).
    d : float, optional
        Linear-zone half-width in position error [mm] (PTO: cfg.pto.d; PD: inf;
        None: ``linear_zone_s`` is NaN).
    v_max : float
        Velocity-error bound of the zone [mm/s] (default inf).
    band : float
        Tight settling band [mm].
    step_fraction : float
        Classical band as a fraction of the reference's size |amplitude| [-].

    Returns
    -------
    ExactMetrics
        Each value's :attr:`Compared.accuracy` bounds its error: a position
        (overshoot) is exact up to the round-off of evaluating eq. (7),
        dx = 8 eps X with X = max|x1| + |amplitude| + max|u| h + max|x2 - u| / a
        (every term of the evaluation is at most X); a crossing time t* up to
        brentq's tolerance on the offset in its sample (xtol + rtol s <= 8 eps h) plus
        the round-off of t_k + s (2 eps t*) plus dx over the slope of the crossed
        signal there (|r' - x2| for e, |x2| for x1); a rise time is the sum of its
        two crossings'; the phase up to 16 N eps rad for its N quadrature terms.

    Examples
    --------
    >>> t = np.linspace(0.0, 0.3, 151)
    >>> m = metrics_from_arrays(t, 1 - np.exp(-20 * t), 20 * np.exp(-20 * t),
    ...                         np.zeros(150), 20.0, ("step", 1.0))
    >>> round(m.exact()["settling_2pct_s"], 6), m.grid()["settling_2pct_s"]  # ln(50)/20
    (0.195601, 0.196)
    """
    tr = Trajectory.from_samples(t, x1, x2, u, a)
    sig = as_signal(reference)
    T = tr.period
    tt, y1, y2 = tr.t, tr.x1, tr.x2
    e_grid = sig.r(tt) - y1
    nan = math.nan
    set2, set01, ov = _core(tr, sig, band, step_fraction)
    band2 = (
        STEP_FRACTION * abs(sig.amplitude)
        if step_fraction is None
        else step_fraction * abs(sig.amplitude)
    )
    acc = _Accuracy(tr, sig)
    vals: dict[str, Compared] = {}
    details: dict[str, float] = {"band_2pct_mm": band2, "t_peak_s": nan}
    for key, st in (("settling_2pct_s", set2), ("settling_0p01mm_s", set01)):
        ex = float(st.time[0])
        err = acc.time(float(tt[0]) + ex, "e") if ex > 0 else (0.0 if ex == 0 else nan)
        vals[key] = Compared(ex, float(st.grid[0]), TIME_TOL_SAMPLES * T, err)
    if ov is not None:
        target = float(sig.r(tt[-1]))
        vals["overshoot_mm"] = Compared(
            float(ov.value[0]), float(ov.grid[0]), POSITION_TOL, acc.position
        )
        details["t_peak_s"] = float(ov.t_peak[0])
        rt = err = nan
        if target != y1[0]:
            t_lo, t_hi = rise_pair(monotone_pieces(tr, None, "x1"), float(y1[0]), target, 0.1, 0.9)
            rt, err = t_hi - t_lo, acc.time(t_lo, "x1") + acc.time(t_hi, "x1")
        vals["rise_time_s"] = Compared(
            rt, grid_rise_time(tt, y1, target), TIME_TOL_SAMPLES * T, err
        )
    else:
        vals["overshoot_mm"] = Compared(nan, nan, POSITION_TOL, nan)
        vals["rise_time_s"] = Compared(nan, nan, TIME_TOL_SAMPLES * T, nan)
    if sig.kind == "sine":
        ph, ratio, (ta, tb) = sine_phase(tr, sig)
        g = grid_phase(tt, y1, sig.r(tt), sig.rate, ta) if math.isfinite(ta) else nan
        vals["phase_delay_deg"] = Compared(ph, g, PHASE_TOL_DEG, acc.phase_deg(sig))
        details.update(amplitude_ratio=ratio, fit_from_s=ta, fit_to_s=tb)
    else:
        vals["phase_delay_deg"] = Compared(nan, nan, PHASE_TOL_DEG, nan)
    if d is None:
        vals["linear_zone_s"] = Compared(nan, nan, TIME_TOL_SAMPLES * T, nan)
    else:
        ez = linear_zone_entry(monotone_pieces(tr, sig), d, v_max) - float(tt[0])
        inside = (np.abs(e_grid) < d) & (np.abs(y2 - sig.r_dot(tt)) <= v_max)
        gz = grid_first(tt, inside) - float(tt[0])
        err = acc.time(float(tt[0]) + ez, "e") if ez > 0 else (0.0 if ez == 0 else nan)
        vals["linear_zone_s"] = Compared(ez, gz, TIME_TOL_SAMPLES * T, err)
    return ExactMetrics(sig, {k: vals[k] for k in METRIC_KEYS}, details)


def _core(tr: Trajectory, sig: Signal, band: float, step_fraction: float | None):
    """Settling under the classical and the tight definitions, and the overshoot.

    Returns (Settling, Settling, Overshoot or None): the definitions of the
    registry when ``band`` and ``step_fraction`` are theirs (2 % and 0.01 mm by
    default), else ad-hoc ones; the overshoot for a step or ramp only.  A band
    of zero width (a fraction of a reference of size 0) settles never: NaN.
    """
    frac = STEP_FRACTION if step_fraction is None else step_fraction
    d2 = _named(SettlingDefinition("custom", "fraction band", band_fraction=frac))
    d01 = _named(SettlingDefinition("custom", "tight band", band_mm=band))
    ov = overshoot(tr, float(sig.r(tr.t[-1]))) if sig.kind in ("step", "ramp") else None
    nan = np.full(1, math.nan)
    set2 = settling_time(tr, sig, d2) if sig.amplitude != 0 else Settling(d2, nan, nan, math.nan)
    return set2, settling_time(tr, sig, d01), ov


def _named(d: SettlingDefinition) -> SettlingDefinition:
    """Return the registry's definition with the box and hold of ``d``, else ``d``."""
    for known in DEFINITIONS.values():
        if (known.band_mm, known.band_fraction, known.velocity_band_mm, known.hold_s) == (
            d.band_mm,
            d.band_fraction,
            d.velocity_band_mm,
            d.hold_s,
        ):
            return known
    return d


def settling_and_overshoot(
    res: Any,
    plant: Any,
    reference: Any = None,
    *,
    band: float = TIGHT_BAND,
    step_fraction: float = STEP_FRACTION,
) -> dict[str, float]:
    """Return the exact settling times and overshoot of a response, without other metrics.

    The values of ``exact_metrics(res, plant, reference).exact()`` for these keys,
    bit for bit (the same computation, without the sample-grid readings, the rise
    time, the phase and the accuracy bounds): for callers that measure many
    responses and need only these (the tuning's candidates).

    Parameters
    ----------
    res : object
        Has arrays ``t`` [s], ``x1`` [mm], ``x2`` [mm/s], ``u`` [mm/s] (see
        :func:`exact_metrics`).
    plant : Plant or float
        Has ``a`` [rad/s], or is a.
    reference : Signal, Reference-like or tuple, optional
        The reference (see :func:`exact_metrics`).
    band : float
        Tight settling band [mm].
    step_fraction : float
        Classical band as a fraction of the reference's size |amplitude| [-].

    Returns
    -------
    dict
        ``overshoot_mm`` [mm] (NaN unless a step or ramp), ``settling_2pct_s`` and
        ``settling_0p01mm_s`` [s] (NaN: never settles).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import make_law
    >>> from ptoverify.sim.simulate import simulate
    >>> cfg = paper_config()
    >>> res = simulate(make_law("pd", cfg), cfg.plant, "step")
    >>> full = exact_metrics(res, cfg.plant).exact()
    >>> all(v == full[k] for k, v in settling_and_overshoot(res, cfg.plant).items())
    True
    """
    if reference is None:
        reference = getattr(res, "reference", None) or _infer(res)
    a = plant if isinstance(plant, (int, float)) else plant.a
    tr = Trajectory.from_samples(res.t, res.x1, res.x2, res.u, float(a))
    set2, set01, ov = _core(tr, as_signal(reference), band, step_fraction)
    return {
        "overshoot_mm": math.nan if ov is None else float(ov.value[0]),
        "settling_2pct_s": float(set2.time[0]),
        "settling_0p01mm_s": float(set01.time[0]),
    }


class _Accuracy:
    """Error bounds of the exact values of one response (see metrics_from_arrays)."""

    def __init__(self, tr: Trajectory, sig: Signal):
        eps = float(np.finfo(float).eps)
        h = np.diff(tr.t)
        scale = (
            float(np.max(np.abs(tr.x1)))
            + abs(sig.amplitude)
            + float(np.max(np.abs(tr.u) * h))
            + float(np.max(np.abs(tr.x2[:-1] - tr.u))) / tr.a
        )
        self.tr, self.sig, self.eps, self.h = tr, sig, eps, float(h.max())
        self.position = 8.0 * eps * scale

    def time(self, t: float, what: str) -> float:
        """Bound [s] on the error of a crossing of e (``e``) or x1 (``x1``) found at t [s]."""
        if not math.isfinite(t):
            return math.nan
        _, v = self.tr.state(np.array([t]))
        slope = abs(float(v[0]) - (float(self.sig.r_dot(t)) if what == "e" else 0.0))
        root = 8.0 * self.eps * self.h + 2.0 * self.eps * abs(t)
        return root + (self.position / slope if slope > 0 else math.inf)

    def phase_deg(self, sig: Signal) -> float:
        """Bound [deg] on the round-off of the fitted phase: N eps rad for N quadrature terms."""
        J = max(1, math.ceil((self.tr.a + sig.omega) * self.h))
        return math.degrees(16.0 * self.tr.intervals * J * self.eps * 8)


def exact_metrics(res: Any, plant: Any, reference: Any = None, **kwargs: Any) -> ExactMetrics:
    """All metrics of a SimResult-like response (duck-typed), exact and on the grid.

    Parameters
    ----------
    res : object
        Has arrays ``t`` [s], ``x1`` [mm], ``x2`` [mm/s], ``u`` [mm/s]; and, when
        ``reference`` is None, a ``reference`` attribute, or ``signal`` naming a
        step or ramp together with ``r`` (and ``r_dot`` for a ramp).
    plant : Plant or float
        Has ``a`` [rad/s], or is a.
    reference : Signal, Reference-like or tuple, optional
        The reference; a sine must be given (its frequency is not inferred).
    **kwargs
        ``d``, ``v_max``, ``band``, ``step_fraction`` of :func:`metrics_from_arrays`.

    Returns
    -------
    ExactMetrics

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import make_law
    >>> from ptoverify.sim.simulate import simulate
    >>> cfg = paper_config()
    >>> res = simulate(make_law("pd", cfg), cfg.plant, "step")
    >>> m = exact_metrics(res, cfg.plant)
    >>> m.values["overshoot_mm"].exact >= m.values["overshoot_mm"].grid
    True
    """
    if reference is None:
        reference = getattr(res, "reference", None) or _infer(res)
    a = plant if isinstance(plant, (int, float)) else plant.a
    return metrics_from_arrays(res.t, res.x1, res.x2, res.u, float(a), reference, **kwargs)


def _infer(res: Any) -> Signal:
    """Read a step or ramp reference from a result's sampled r (and r_dot)."""
    name = getattr(res, "signal", None)
    r = np.asarray(getattr(res, "r", []), dtype=float)
    if name == "step" and r.size:
        return Signal("step", float(r[-1]))
    if name == "ramp" and r.size and hasattr(res, "r_dot"):
        rd = np.asarray(res.r_dot, dtype=float)
        return Signal("ramp", float(r[np.argmax(np.abs(r))]), float(np.max(np.abs(rd))))
    raise InputError(f"pass the reference of this '{name}' response explicitly")


@dataclass(frozen=True)
class BatchSettling:
    """Settling times of many regulation records, between samples and on the grid.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Exact settling time [s] from the record's start: the last exit of the
        continuous trajectory from the box |x1| <= band_x1, |x2| <= band_x2
        (0 if never outside); NaN when the record ends outside or the settled
        tail is shorter than ``hold``.
    grid : ndarray, shape (n,)
        Sample-grid settling time [s]: k T for the first sample k after the last
        sample outside the box (``ptoverify.studies.sweep.settle_steps``); NaN likewise,
        with the hold counted in whole samples, ceil(hold / T).
    accuracy : float
        Bound on the error of :attr:`time` [s] (see :func:`settling_times_batch`).
    """

    time: NDArray[np.float64]
    grid: NDArray[np.float64]
    accuracy: float


def settling_times_batch(
    x1: ArrayLike,
    x2: ArrayLike,
    u: ArrayLike,
    a: float,
    T: float,  # noqa: N803
    band_x1: float,
    band_x2: float,
    hold: float = 0.0,
) -> BatchSettling:
    """Exact last exit from a band box for many ZOH records at once (regulation).

    The box is |x1| <= band_x1 and |x2| <= band_x2.  The last time outside the
    box is the later of the last exits of x1 and of x2 from their own bands,
    found separately:

    * x2(s) = u + (x2k - u) e^{-a s} is monotone on each sample, so it leaves its
      band between samples only if a sample is outside: its last exit is in the
      interval after the last sample outside, at the closed-form
      s = ln((x2k - u)/(L - u)) / a, L = +-band_x2.
    * x1 is convex or concave on each sample (x1'' = x2' has one sign), with an
      interior extremum only where x2 changes sign, at s* = ln((u - x2k)/u) / a.
      Its last exit is in the latest interval that has a point outside -- its
      first sample, or an excursion x1(s*) outside the band between two samples
      that are both inside -- on the monotone piece after that point, found by
      safeguarded Newton on eq. (7) to 4 ulps of T.

    Parameters
    ----------
    x1, x2 : array_like, shape (steps + 1, n) or (steps + 1,)
        Position [mm] and velocity [mm/s] at the samples t_k = k T.
    u : array_like, shape (steps, n) or (steps,)
        Input held on [t_k, t_k+1) [mm/s].
    a : float
        Bandwidth [rad/s].
    T : float
        Sample period [s].
    band_x1 : float
        Position band [mm], > 0.
    band_x2 : float
        Velocity band [mm/s], > 0.
    hold : float
        Shortest settled tail that counts [s]: settled only if
        t_end - time >= hold - 1e-9 T (the grid value: whole samples,
        ceil(hold / T - 1e-9), as ``ptoverify.studies.sweep``).

    Returns
    -------
    BatchSettling
        ``time`` (between samples) and ``grid`` (on the samples), shape (n,),
        and ``accuracy`` = 4 eps T (Newton's stopping width) + 4 eps t_end
        (round-off of k T + s) [s]; the x1 crossing also moves with the
        round-off of eq. (7), about 8 eps X / |x2| for X the size of its terms.
        Where both are finite, grid - T < time (the sample before the grid
        value is outside the box) and grid <= T ceil(time / T) (every sample
        from the exact time on is inside); time > grid only when the
        trajectory leaves the box between samples after the grid value.

    Examples
    --------
    >>> a, T = 10.0, 0.1
    >>> t = np.arange(11) * T
    >>> x2 = 5.0 * np.exp(-a * t)  # u = 0: x1 = 0.5 (1 - e^{-a t}) - 0.5
    >>> x1 = -0.5 * np.exp(-a * t)
    >>> st = settling_times_batch(x1, x2, np.zeros(10), a, T, 0.01, 1.0)
    >>> round(float(st.time[0]), 6), float(st.grid[0])  # ln(50) / 10, then the sample after
    (0.391202, 0.4)
    """
    x1, x2, u = as_float_array(x1), as_float_array(x2), as_float_array(u)
    if x1.ndim == 1:
        x1, x2, u = x1[:, None], x2[:, None], u[:, None]
    steps = x1.shape[0] - 1
    if steps < 1 or x2.shape != x1.shape or u.shape != (steps, x1.shape[1]):
        raise InputError("x1, x2 must be (steps + 1, n) and u (steps, n), steps >= 1")
    if not (band_x1 > 0 and band_x2 > 0 and a > 0 and T > 0 and hold >= 0):
        raise InputError("bands, a and T must be positive and hold >= 0")
    vb = None if math.isinf(band_x2) else band_x2 / a
    box = _named(
        SettlingDefinition("custom", "box", band_mm=band_x1, velocity_band_mm=vb, hold_s=hold)
    )
    tr = Trajectory(np.arange(steps + 1) * T, x1, x2, u, float(a))
    st = settling_time(tr, None, box)
    return BatchSettling(st.time, st.grid, st.accuracy)
