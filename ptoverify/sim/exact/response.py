"""Exact metrics of one response: settling, overshoot, rise, lag and phase between samples."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ptoverify.errors import InputError
from ptoverify.sim.events import (
    grid_first,
    grid_phase,
    grid_rise_time,
    linear_zone_entry,
    rise_pair,
    sine_phase,
)
from ptoverify.sim.flow import (
    Signal,
    Trajectory,
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

from .types import (
    METRIC_KEYS,
    PHASE_TOL_DEG,
    POSITION_TOL,
    STEP_FRACTION,
    TIGHT_BAND,
    TIME_TOL_SAMPLES,
    Compared,
    ExactMetrics,
)


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
    nan = np.full(1 if tr.x1.ndim == 1 else tr.x1.shape[1], math.nan)
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
    responses and need only these (the tuning's candidates).  It is
    :func:`settling_and_overshoot_many` of the one response.

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
    return settling_and_overshoot_many(
        [res], plant, reference, band=band, step_fraction=step_fraction
    )[0]


def settling_and_overshoot_many(
    results: Sequence[Any],
    plant: Any,
    reference: Any = None,
    *,
    band: float = TIGHT_BAND,
    step_fraction: float = STEP_FRACTION,
) -> list[dict[str, float]]:
    """:func:`settling_and_overshoot` of responses on one sample grid, measured side by side.

    The responses are the columns of one batch trajectory; every step of the
    evaluation is per column (the settling times' root finding stops each
    column on its own), so each value is the one its response gives alone.

    Parameters
    ----------
    results : sequence of object
        Responses with arrays ``t`` [s] (one grid for all), ``x1`` [mm], ``x2``
        [mm/s], ``u`` [mm/s] (see :func:`exact_metrics`).
    plant : Plant or float
        Has ``a`` [rad/s], or is a.
    reference : Signal, Reference-like or tuple, optional
        The reference of every response; default the first response's (see
        :func:`exact_metrics`).
    band : float
        Tight settling band [mm].
    step_fraction : float
        Classical band as a fraction of the reference's size |amplitude| [-].

    Returns
    -------
    list of dict
        Per response, in order: as :func:`settling_and_overshoot`.

    Raises
    ------
    InputError
        Sample grids that differ, or a response that :func:`settling_and_overshoot`
        refuses (non-finite samples).
    """
    first = results[0]
    if reference is None:
        reference = getattr(first, "reference", None) or _infer(first)
    t = np.asarray(first.t, dtype=float)
    if any(not np.array_equal(np.asarray(r.t, dtype=float), t) for r in results[1:]):
        raise InputError("settling_and_overshoot_many: the responses need one sample grid")
    a = plant if isinstance(plant, (int, float)) else plant.a
    x1, x2, u = (np.column_stack([getattr(r, k) for r in results]) for k in ("x1", "x2", "u"))
    tr = Trajectory.from_samples(t, x1, x2, u, float(a))
    set2, set01, ov = _core(tr, as_signal(reference), band, step_fraction)
    return [
        {
            "overshoot_mm": math.nan if ov is None else float(ov.value[j]),
            "settling_2pct_s": float(set2.time[j]),
            "settling_0p01mm_s": float(set01.time[j]),
        }
        for j in range(len(results))
    ]


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
