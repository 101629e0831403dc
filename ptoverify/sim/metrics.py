"""Response metrics of Section 6: settling, overshoot, oscillation, lag, phase.

The functions here are pure numpy functions of sampled arrays: they look at
the controller's samples t_k = k T only.  :func:`summarize` reports the time
metrics of a :class:`~ptoverify.sim.simulate.SimResult` on the exact continuous
trajectory between the samples (:mod:`ptoverify.sim.exact`: overshoot, settling,
rise time, linear-zone entry, sine phase), with the sample-grid value of the
same definition beside each under the key suffixed ``_grid``.  Settling and
overshoot are :func:`ptoverify.sim.settling.settling_time` and
:func:`~ptoverify.sim.settling.overshoot` under the named definitions of
:data:`ptoverify.sim.settling.DEFINITIONS`; :func:`rise_time` is
:func:`ptoverify.sim.exact.grid_rise_time`.

The paper's wording each metric stands for:

* settling -- "adjustment time" (Sec. 6.1, Sec. 7): the time after which |e|
  stays within a band until the end of the record, under the definitions
  ``2pct`` (the classical band) and ``0p01mm`` (:data:`TIGHT_BAND`, 2 % of the
  linear zone d = 0.5 mm).
* overshoot -- "with the same overshoot" (Sec. 6.1), "avoids ... overshoots"
  (Sec. 7).
* :func:`oscillation_amplitude` and :func:`sign_reversals` -- "persistent
  oscillations in the steady-state phase" (Sec. 6.1), "series position and
  velocity oscillations" (Sec. 6.2), "reaches zero without any oscillation".
* :func:`ramp_lag` -- "the PD controller delays a large value about the command
  signal" (Sec. 6.2).
* :func:`sine_fit` / :func:`phase_delay` -- "the phase delay is about 4.5 deg"
  (Sec. 6.3); the fundamental is fitted by least squares over whole periods.
* :func:`rise_time` -- "a quicker dynamic response" (Sec. 7).
* :func:`time_to_linear_zone` -- "when the position x1 is smaller than a certain
  threshold, the system enters the linear zone" (Sec. 4).
* :func:`input_switches` -- the bang-bang "switching" of the input (Sec. 1, 4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.sim.exact import STEP_FRACTION, TIGHT_BAND, exact_metrics
from ptoverify.sim.exact import grid_rise_time as rise_time

if TYPE_CHECKING:  # pragma: no cover
    from ptoverify.sim.simulate import SimResult

__all__ = [
    "TIGHT_BAND",
    "STEP_FRACTION",
    "oscillation_amplitude",
    "sign_reversals",
    "ramp_lag",
    "SineFit",
    "sine_fit",
    "phase_delay",
    "rise_time",
    "time_to_linear_zone",
    "input_switches",
    "summarize",
]


def _arr(x: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(x, dtype=float)


def oscillation_amplitude(e: ArrayLike) -> float:
    """Amplitude of an oscillation: half the peak-to-peak of the samples.

    Apply it to the steady part of a record (e.g. its last half) to measure
    the "persistent oscillations in the steady-state phase".

    Parameters
    ----------
    e : array_like
        Signal over the steady part [mm] or [mm/s].

    Returns
    -------
    float
        (max e - min e) / 2.

    Examples
    --------
    >>> oscillation_amplitude([0.1, -0.3, 0.5, -0.1])
    0.4
    """
    e = _arr(e)
    return float(0.5 * np.ptp(e)) if e.size else math.nan


def sign_reversals(e: ArrayLike, band: float) -> int:
    """Count the sign reversals of a signal, with hysteresis.

    Samples with |e| <= band are ignored, so noise-sized wiggles around zero
    do not count: a reversal is a sample above +band following one below
    -band, or the reverse.  "Without any oscillation" is zero reversals.

    Parameters
    ----------
    e : array_like
        Signal [mm] or [mm/s].
    band : float
        Hysteresis half-width, same unit, >= 0.

    Returns
    -------
    int
        The count.

    Examples
    --------
    >>> sign_reversals([1.0, 0.5, -0.001, 0.2, -1.0, 1.0], 0.01)
    2
    """
    e = _arr(e)
    s = np.sign(e[np.abs(e) > band])
    return int(np.count_nonzero(s[1:] != s[:-1]))


def ramp_lag(t: ArrayLike, e: ArrayLike, r_dot: ArrayLike, *, skip: float = 0.5) -> float:
    """Tracking lag of a ramp: mean error while the ramp is moving.

    The mean of e = r - x1 over the samples where r' > 0, after the first
    ``skip`` fraction of that interval (the start-up transient).  A positive
    lag means the position trails the command; lag / slope is the delay in s.

    Parameters
    ----------
    t : array_like
        Sample times [s].
    e : array_like
        Error r - x1 [mm].
    r_dot : array_like
        Reference velocity [mm/s].
    skip : float
        Fraction of the moving interval left out at its start [-], in [0, 1).

    Returns
    -------
    float
        Lag [mm]; NaN if the ramp never moves.

    Examples
    --------
    >>> t = np.arange(0, 0.2, 0.001)
    >>> rd = np.where(t < 0.15, 200.0, 0.0)
    >>> round(ramp_lag(t, np.where(t < 0.15, 1.2, 0.0), rd), 6)
    1.2
    """
    t, e, r_dot = _arr(t), _arr(e), _arr(r_dot)
    moving = np.flatnonzero(r_dot > 0)
    if moving.size == 0:
        return math.nan
    t0, t1 = t[moving[0]], t[moving[-1]]
    sel = moving[t[moving] >= t0 + skip * (t1 - t0)]
    return float(np.mean(e[sel]))


@dataclass(frozen=True)
class SineFit:
    """Least-squares fit y = A sin(wt) + B cos(wt) + C of the fundamental.

    Attributes
    ----------
    amplitude : float
        sqrt(A^2 + B^2) [unit of y].
    phase_deg : float
        phi in y = amplitude sin(w t + phi) + C [deg].
    offset : float
        C [unit of y].
    residual_rms : float
        RMS of y minus the fit over the fitted samples [unit of y]: what the
        fundamental does not explain (harmonics, chattering).
    periods : int
        Number of whole periods fitted.
    """

    amplitude: float
    phase_deg: float
    offset: float
    residual_rms: float
    periods: int


def sine_fit(t: ArrayLike, y: ArrayLike, freq: float, *, t_from: float = 0.0) -> SineFit:
    """Fit the fundamental over whole periods of the steady part.

    The fit uses the largest integer number of periods 1/freq that ends at the
    last sample and starts at or after ``t_from``, so an integer number of
    periods is fitted and the harmonics are orthogonal to the fundamental.

    Parameters
    ----------
    t : array_like
        Sample times [s] (uniform).
    y : array_like
        Signal [mm].
    freq : float
        Frequency of the fundamental [Hz].
    t_from : float
        Start of the steady part [s].

    Returns
    -------
    SineFit
        The fit.

    Examples
    --------
    >>> t = np.arange(0, 1.0 + 1e-9, 0.002)
    >>> f = sine_fit(t, 2 * np.sin(2 * np.pi * 5 * t - 0.1), 5.0)
    >>> round(f.amplitude, 9), round(f.phase_deg, 6)
    (2.0, -5.729578)
    """
    t, y = _arr(t), _arr(y)
    dt = t[1] - t[0]
    per = int(round(1.0 / (freq * dt)))  # samples per period
    if abs(per * freq * dt - 1.0) > 1e-9:
        raise ValueError("the period must be a whole number of samples")
    periods = int((t[-1] - max(t_from, t[0]) + 1e-9 * dt) // (per * dt))
    if periods < 1:
        raise ValueError("the steady part holds less than one period")
    n = periods * per  # samples [-n:], whole periods
    tt, yy = t[-n:], y[-n:]
    w = 2.0 * math.pi * freq
    M = np.column_stack([np.sin(w * tt), np.cos(w * tt), np.ones_like(tt)])
    (A, B, C), *_ = np.linalg.lstsq(M, yy, rcond=None)
    res = yy - M @ np.array([A, B, C])
    return SineFit(
        float(math.hypot(A, B)),
        float(math.degrees(math.atan2(B, A))),
        float(C),
        float(np.sqrt(np.mean(res * res))),
        periods,
    )


def phase_delay(ref: SineFit, out: SineFit) -> float:
    """Phase delay of the output behind the reference [deg], wrapped to (-180, 180].

    Positive when the output lags.

    Parameters
    ----------
    ref, out : SineFit
        Fits of the reference and of the output.

    Returns
    -------
    float
        phase(ref) - phase(out) [deg].
    """
    d = (ref.phase_deg - out.phase_deg + 180.0) % 360.0 - 180.0
    return 180.0 if d == -180.0 else d


def time_to_linear_zone(
    t: ArrayLike, region: ArrayLike, codes: tuple[int, ...] | None = None
) -> float:
    """First time the linear scheme acts: "the system enters the linear zone".

    Parameters
    ----------
    t : array_like
        Sample times [s].
    region : array_like of int
        :class:`~ptoverify.model.laws.Region` code of each sample.
    codes : tuple of int, optional
        Codes that count as the linear zone; default LINEAR and SATURATED
        (eq. 34 or PD, clipped or not).

    Returns
    -------
    float
        Time of the first such sample [s], measured from t[0]; NaN if never.

    Examples
    --------
    >>> time_to_linear_zone([0.0, 0.1, 0.2], [2, 3, 5])
    0.2
    """
    from ptoverify.model.laws import Region

    codes = (Region.LINEAR, Region.SATURATED) if codes is None else codes
    t, region = _arr(t), np.asarray(region)
    k = np.flatnonzero(np.isin(region, np.asarray(codes, dtype=int)))
    return float(t[k[0]] - t[0]) if k.size else math.nan


def input_switches(u: ArrayLike, *, tol: float = 0.0) -> int:
    """Count the input switches: sign reversals of u between samples.

    Samples with |u| <= tol are skipped (u = 0 at the origin is no switch).

    Parameters
    ----------
    u : array_like
        Input [mm/s].
    tol : float
        Dead band [mm/s].

    Returns
    -------
    int
        The count.

    Examples
    --------
    >>> input_switches([300.0, -300.0, -300.0, 0.0, 300.0])
    2
    """
    return sign_reversals(u, tol)


def summarize(
    res: SimResult,
    plant: Any,
    *,
    d: float | None = None,
    band: float = TIGHT_BAND,
    step_fraction: float = STEP_FRACTION,
) -> dict[str, float]:
    """All metrics of one simulated response, by name (units in the names).

    The time metrics are measured on the exact continuous trajectory between
    the samples (:func:`ptoverify.sim.exact.exact_metrics`); each has its
    sample-grid value beside it under the same key suffixed ``_grid`` (the
    same definition restricted to the samples), so a reader sees both where
    they differ: ``settling_0p01mm_s``, ``settling_2pct_s``, ``overshoot_mm``,
    ``rise_time_s`` (step), ``linear_zone_s``, ``phase_delay_deg`` and
    ``amplitude_ratio`` (sine).  The other metrics are properties of the
    sampled sequence and have no ``_grid`` twin: ``steady_amplitude_mm`` and
    ``steady_velocity_amplitude_mm_s`` (last half of the record),
    ``error_reversals``, ``input_switches``, ``ramp_lag_mm`` (ramp) and
    ``fit_residual_rms_mm`` (sine, over whole periods of samples; NaN when a
    period is not a whole number of samples).  The signal, its final value and
    the sine's frequency are read from ``res.reference``.

    Parameters
    ----------
    res : SimResult
        A simulated response (any step, ramp or sine).
    plant : Plant or float
        The plant simulated (its bandwidth a [rad/s]), or a.
    d : float, optional
        Half-width of the law's linear zone in position error [mm] (PTO:
        cfg.pto.d; PD: inf, linear everywhere; TO: no zone, leave None).  Given,
        ``linear_zone_s`` is the first time |r - x1| <= d on the continuous
        trajectory (the grid twin: the first sample with |r - x1| < d, the PTO
        law's own test).  None: both are the first sample the law reports a
        linear region (:func:`time_to_linear_zone`), which needs no d but
        cannot see between samples.
    band : float
        Tight band [mm].
    step_fraction : float
        Classical band as a fraction of the reference's size [-].

    Returns
    -------
    dict
        Metric name -> value (NaN where undefined for this signal).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import make_law
    >>> from ptoverify.sim.simulate import simulate
    >>> cfg = paper_config()
    >>> s = summarize(simulate(make_law("pd", cfg), cfg.plant, "step"), cfg.plant)
    >>> s["overshoot_mm"] >= s["overshoot_mm_grid"]
    True
    """
    t, e, ref = res.t, res.e, res.reference
    half = t.size // 2
    em = exact_metrics(res, plant, ref, d=d, band=band, step_fraction=step_fraction)
    m = em.values
    out = {
        "steady_amplitude_mm": oscillation_amplitude(e[half:]),
        "steady_velocity_amplitude_mm_s": oscillation_amplitude((res.x2 - res.r_dot)[half:]),
        "error_reversals": float(sign_reversals(e, band)),
        "input_switches": float(input_switches(res.u)),
    }

    def both(key: str, name: str) -> None:
        out[key], out[key + "_grid"] = m[name].exact, m[name].grid

    both("settling_0p01mm_s", "settling_0p01mm_s")
    if d is None:
        out["linear_zone_s"] = out["linear_zone_s_grid"] = time_to_linear_zone(t, res.region)
    else:
        both("linear_zone_s", "linear_zone_s")
    if ref.name in ("step", "ramp"):
        both("settling_2pct_s", "settling_2pct_s")
        both("overshoot_mm", "overshoot_mm")
    if ref.name == "step":
        both("rise_time_s", "rise_time_s")
    if ref.name == "ramp":
        out["ramp_lag_mm"] = ramp_lag(t, e, res.r_dot)
    if ref.name == "sine":
        freq = ref.frequency  # the simulated sine's, never a global table's
        both("phase_delay_deg", "phase_delay_deg")
        out["amplitude_ratio"] = em.details.get("amplitude_ratio", math.nan)
        out["amplitude_ratio_grid"] = math.nan
        out["fit_residual_rms_mm"] = math.nan
        try:
            fit_r = sine_fit(t, res.r, freq, t_from=1.0 / freq)
            pos = sine_fit(t, res.x1, freq, t_from=1.0 / freq)
        except ValueError:  # no whole number of samples per period, or < 1 period
            pass
        else:
            out["amplitude_ratio_grid"] = pos.amplitude / fit_r.amplitude
            out["fit_residual_rms_mm"] = pos.residual_rms
    return out
