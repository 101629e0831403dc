"""Crossing times and the sine phase on the exact trajectory between samples.

Rise time (first reach of a level by x1), entry into the linear zone (first
time in {|x1 - r| <= d, |x2 - r'| <= v_max}) and the phase delay of a sine
response (continuous least squares), each with its sample-grid twin.  The
pieces on which e or x1 is monotone come from :mod:`ptoverify.sim.flow`; see
:mod:`ptoverify.sim.exact` for the definitions and the accuracy bounds.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ptoverify.errors import InputError
from ptoverify.sim.flow import (
    Pieces,
    Trajectory,
    as_float_array,
    as_signal,
    error_derivatives,
    interval_extrema,
    monotone_pieces,
    piece_crossing,
    piece_error_derivatives,
    piece_value,
    reference_parts,
    split_intervals,
    zoh_flow,
)

__all__ = [
    "rise_time",
    "rise_pair",
    "linear_zone_time",
    "linear_zone_entry",
    "sine_phase",
    "grid_phase",
    "grid_rise_time",
    "grid_first",
]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


def _first_reach(p: Pieces, level: float, sgn: float, xv=None) -> float:
    """First time [s] with sgn (x1(t) - level) >= 0 on x1-pieces p, exactly; NaN if never."""
    xv = piece_value(p, p.brk, "x1") if xv is None else xv
    v = sgn * (xv - level) >= 0
    if not v.any():
        return math.nan
    k = int(np.nonzero(v.any(axis=1))[0][0])
    j = int(np.nonzero(v[k])[0][0])
    if j == 0:
        return float(p.t0[k])
    return piece_crossing(p, k, p.brk[k, j - 1], p.brk[k, j], level, "x1")


def rise_time(tr: Trajectory, target: float, *, low: float = 0.1, high: float = 0.9) -> float:
    """Rise time from ``low`` to ``high`` of the way from x1(t_0) to target.

    Parameters
    ----------
    tr : Trajectory
        The response.
    target : float
        Final value [mm], different from x1(t_0).
    low, high : float
        Fractions [-].

    Returns
    -------
    float
        First continuous time x1 reaches the high level minus the first time it
        reaches the low level [s]; NaN if either is never reached.

    Examples
    --------
    >>> t = np.linspace(0.0, 0.3, 31)
    >>> tr = Trajectory.from_samples(t, 1 - np.exp(-20 * t), 20 * np.exp(-20 * t),
    ...                              np.zeros(30), 20.0)
    >>> round(rise_time(tr, 1.0), 6)  # ln(9) / 20
    0.109861
    """
    x0 = float(tr.x1[0])
    if target == x0:
        return math.nan
    return _rise(monotone_pieces(tr, None, "x1"), x0, target, low, high)


def _rise(p: Pieces, x0: float, target: float, low: float, high: float, xv=None) -> float:
    t_lo, t_hi = rise_pair(p, x0, target, low, high, xv)
    return t_hi - t_lo


def rise_pair(p: Pieces, x0: float, target: float, low: float, high: float, xv=None):
    """Return the absolute first times x1 reaches the low and the high level.

    Parameters
    ----------
    p : Pieces
        x1-pieces of the record (:func:`ptoverify.sim.flow.monotone_pieces`).
    x0, target : float
        Start and final value [mm].
    low, high : float
        Fractions of the way [-].
    xv : ndarray, optional
        x1 at the pieces' breaks [mm] (computed if None).

    Returns
    -------
    tuple of float
        The two times [s] (NaN if never reached).
    """
    sgn = 1.0 if target > x0 else -1.0
    xv = piece_value(p, p.brk, "x1") if xv is None else xv
    t_lo = _first_reach(p, x0 + low * (target - x0), sgn, xv)
    t_hi = _first_reach(p, x0 + high * (target - x0), sgn, xv)
    return t_lo, t_hi


def _preimage(p: Pieces, k: int, s0: float, s1: float, v0: float, v1: float, lim: float, what):
    """[lo, hi] of s in [s0, s1] with |f(s)| <= lim for f monotone (None if empty)."""
    if max(v0, v1) < -lim or min(v0, v1) > lim:
        return None
    lo, hi = s0, s1
    if abs(v0) > lim:
        lo = _cross_generic(p, k, s0, s1, math.copysign(lim, v0), what) - p.t0[k]
    if abs(v1) > lim:
        hi = _cross_generic(p, k, s0, s1, math.copysign(lim, v1), what) - p.t0[k]
    return lo, hi


def _cross_generic(p, k, s0, s1, level, what):
    if what == "e":
        return piece_crossing(p, k, s0, s1, level, "e")

    slope, amp, w = reference_parts(p)
    g = (float(p.x2[k]), float(p.u[k]), float(p.t0[k]), float(slope[k]), amp, w, p.a)

    def f(s: float) -> float:
        return float(error_derivatives(*g, s, 1)[0]) - level

    f0, f1 = f(s0), f(s1)
    if f0 * f1 > 0:
        return float(p.t0[k] + (s0 if abs(f0) < abs(f1) else s1))
    # time resolution: 4 ulps of the piece's length (about 1e-18 s for T = 2 ms), so
    # bisection ends in about 50 steps even for a crossing next to s0
    from scipy.optimize import brentq

    s = brentq(
        f,
        s0,
        s1,
        xtol=4.0 * np.finfo(float).eps * (s1 - s0),
        rtol=4.0 * np.finfo(float).eps,
        maxiter=200,
    )
    return float(p.t0[k] + s)


def linear_zone_time(tr: Trajectory, ref: Any, d: float, *, v_max: float = math.inf) -> float:
    """First time the continuous state enters {|x1 - r| <= d, |x2 - r'| <= v_max}.

    Both the position error e1 = -e and the velocity error e2 = -e' are split
    into pieces where each is monotone (extrema of e from e' = 0, of e' from
    e'' = 0, closed form or bracketed Newton), so on each piece the set is one
    interval whose ends are exact crossings.

    Parameters
    ----------
    tr : Trajectory
        The response.
    ref : Signal or Reference-like
        The reference.
    d : float
        Half-width of the zone in position error [mm] (PTO: the linear zone d;
        inf: everywhere).
    v_max : float
        Bound on the velocity error [mm/s] (default inf: no condition).

    Returns
    -------
    float
        Entry time measured from t_0 [s]; NaN if never.

    Examples
    --------
    >>> from ptoverify.sim.flow import Signal
    >>> t = np.linspace(0.0, 0.3, 31)
    >>> tr = Trajectory.from_samples(t, 1 - np.exp(-20 * t), 20 * np.exp(-20 * t),
    ...                              np.zeros(30), 20.0)
    >>> round(linear_zone_time(tr, Signal("step", 1.0), 0.5), 6)  # ln(2) / 20
    0.034657
    """
    return linear_zone_entry(monotone_pieces(tr, as_signal(ref)), d, v_max) - float(tr.t[0])


def linear_zone_entry(p: Pieces, d: float, v_max: float, ev=None) -> float:
    """Return the absolute first entry time into the zone on e-pieces p.

    Parameters
    ----------
    p : Pieces
        e-pieces of the record.
    d : float
        Position-error half-width [mm].
    v_max : float
        Velocity-error bound [mm/s].
    ev : ndarray, optional
        e at the breaks [mm] (computed if None).

    Returns
    -------
    float
        Entry time [s]; NaN if never.
    """
    if math.isfinite(v_max):  # refine so that e' is monotone on every piece too
        z2 = np.where(np.isnan(z := interval_extrema(p, 2)), p.h[:, None], z)
        brk = np.sort(np.concatenate([p.brk, z2], 1), 1)
        q = Pieces(p.t0, p.h, p.x1, p.x2, p.u, p.a, p.sig, brk)
        e, e2 = piece_value(q, brk, "e"), -piece_error_derivatives(q, brk)[0]
    else:
        q, brk = p, p.brk
        e = piece_value(p, brk, "e") if ev is None else ev
        e2 = np.zeros_like(e)
    lo, hi = brk[:, :-1], brk[:, 1:]

    def meets(v, lim):  # a monotone piece meets the band [-lim, lim] somewhere
        return (np.minimum(v[:, :-1], v[:, 1:]) <= lim) & (np.maximum(v[:, :-1], v[:, 1:]) >= -lim)

    cand = meets(e, d) & meets(e2, v_max) & (hi >= lo)
    for k, j in zip(*np.nonzero(cand), strict=True):
        s0, s1 = float(lo[k, j]), float(hi[k, j])
        a1 = _preimage(q, k, s0, s1, float(e[k, j]), float(e[k, j + 1]), d, "e")
        if a1 is None:
            continue
        if math.isfinite(v_max):
            a2 = _preimage(q, k, s0, s1, -float(e2[k, j]), -float(e2[k, j + 1]), v_max, "d1")
            if a2 is None or max(a1[0], a2[0]) > min(a1[1], a2[1]):
                continue
            a1 = (max(a1[0], a2[0]), 0.0)
        return float(q.t0[k] + a1[0])
    return math.nan


def _wrap_deg(d: float) -> float:
    d = (d + 180.0) % 360.0 - 180.0
    return 180.0 if d == -180.0 else d


def sine_phase(
    tr: Trajectory, ref: Any, *, t_from: float | None = None
) -> tuple[float, float, tuple[float, float]]:
    """Phase delay of x1 behind a sine reference, continuous least squares.

    The fundamental y = A sin(w t) + B cos(w t) + C is fitted to x1(t) and to
    r(t) over the largest whole number of periods that ends at t_n and starts at
    or after ``t_from``.  Over whole periods the three functions are orthogonal,
    so A = 2/L int x1 sin, B = 2/L int x1 cos, C = 1/L int x1; the integrals are
    8-point Gauss-Legendre per sample interval on panels with (a + w) h <= 1
    (remainder below 2e-23 of the integral's scale: exact to round-off).

    Parameters
    ----------
    tr : Trajectory
        The response.
    ref : Signal or Reference-like
        A sine reference.
    t_from : float, optional
        Start of the steady part [s]; default t_0 plus one period.

    Returns
    -------
    delay_deg : float
        phase(r) - phase(x1) wrapped to (-180, 180] [deg], positive when x1 lags.
    amplitude_ratio : float
        Amplitude of x1's fundamental over r's [-].
    window : tuple of float
        The fitted window (t_a, t_b) [s].

    Examples
    --------
    >>> from ptoverify.sim.flow import Signal
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> w = 2 * np.pi * 5.0
    >>> x1 = np.sin(w * t - 0.1)  # any smooth data; u chosen to match x2 at each end
    >>> tr = Trajectory.from_samples(t, x1, w * np.cos(w * t - 0.1), np.zeros(1000), 1e-9)
    >>> round(sine_phase(tr, Signal("sine", 1.0, 5.0))[0], 2)  # not a ZOH response
    5.73
    """
    sig = as_signal(ref)
    if sig.kind != "sine":
        raise InputError("the phase delay needs a sine reference")
    per = 1.0 / abs(sig.rate)
    tb = float(tr.t[-1])
    start = float(tr.t[0]) + per if t_from is None else max(t_from, float(tr.t[0]))
    n_per = math.floor((tb - start) / per + 1e-9)
    if n_per < 1:
        return math.nan, math.nan, (math.nan, tb)
    ta = tb - n_per * per
    t0, h, x1, x2, u = split_intervals(tr, None, (ta,))
    keep = t0 >= ta
    t0, h, x1, x2, u = t0[keep], h[keep], x1[keep], x2[keep], u[keep]
    w = sig.omega
    J = max(1, math.ceil((tr.a + w) * float(h.max())))
    node = (np.arange(J)[:, None] + 0.5 * (_GL_X[None, :] + 1.0)).ravel() / J  # in (0, 1)
    wt = np.tile(_GL_W, J) / (2.0 * J)
    s = h[:, None] * node[None, :]
    y1, _ = zoh_flow(x1[:, None], x2[:, None], u[:, None], s, tr.a)
    tt = t0[:, None] + s
    hw = h[:, None] * wt[None, :]
    sn, cs = np.sin(w * tt), np.cos(w * tt)
    L = tb - ta
    phases, amps = [], []
    for y in (sig.amplitude * sn, y1):  # r(t) = A sin(w t)
        A, B = 2.0 / L * np.sum(hw * y * sn), 2.0 / L * np.sum(hw * y * cs)
        phases.append(math.degrees(math.atan2(B, A)))
        amps.append(math.hypot(A, B))
    return _wrap_deg(phases[0] - phases[1]), amps[1] / amps[0], (ta, tb)


def grid_phase(t, x1, r, freq: float, ta: float) -> float:
    """Return the sample-grid phase delay: least squares on the samples in (t_a, t_n].

    Parameters
    ----------
    t : ndarray
        Sample times [s].
    x1, r : ndarray
        Position and reference at the samples [mm].
    freq : float
        Sine frequency [Hz].
    ta : float
        Start of the fitted window [s].

    Returns
    -------
    float
        phase(r) - phase(x1) [deg].
    """
    sel = t > ta + 1e-9 * (t[1] - t[0])
    w = 2.0 * math.pi * abs(freq)
    M = np.column_stack([np.sin(w * t[sel]), np.cos(w * t[sel]), np.ones(int(sel.sum()))])
    coef, *_ = np.linalg.lstsq(M, np.column_stack([r[sel], x1[sel]]), rcond=None)
    (ar, ax), (br, bx) = coef[0], coef[1]
    return _wrap_deg(math.degrees(math.atan2(br, ar) - math.atan2(bx, ax)))


def grid_rise_time(
    t: ArrayLike,
    x: ArrayLike,
    target: float,
    *,
    low: float = 0.1,
    high: float = 0.9,
    start: float | None = None,
) -> float:
    """Rise time on the samples, from ``low`` to ``high`` of the way from ``start`` to target.

    The sample-grid twin of :func:`rise_time` (and ``ptoverify.sim.metrics.rise_time``):
    the first sample at or past the high level minus the first at or past the low level.

    Parameters
    ----------
    t : array_like
        Sample times [s].
    x : array_like
        Position [mm].
    target : float
        Final value [mm], different from ``start``.
    low, high : float
        Fractions of the way [-].
    start : float, optional
        Initial value [mm]; default x[0].

    Returns
    -------
    float
        Rise time [s]; NaN if a level is never reached.

    Examples
    --------
    >>> t = np.linspace(0, 1, 1001)
    >>> round(grid_rise_time(t, 1 - np.exp(-10 * t), 1.0), 3)
    0.22
    """
    t, x = as_float_array(t), as_float_array(x)
    x0 = float(x[0]) if start is None else float(start)
    if target == x0:
        return math.nan
    sgn = 1.0 if target > x0 else -1.0
    lo, hi = (x0 + f * (target - x0) for f in (low, high))
    return grid_first(t, sgn * (x - hi) >= 0) - grid_first(t, sgn * (x - lo) >= 0)


def grid_first(t, y) -> float:
    """Return the first sample time where y holds.

    Parameters
    ----------
    t : ndarray
        Sample times [s].
    y : ndarray of bool
        The condition per sample.

    Returns
    -------
    float
        That time [s]; NaN if never.
    """
    k = np.flatnonzero(y)
    return float(t[k[0]]) if k.size else math.nan
