"""Named settling definitions, and the one settling time and overshoot.

Every settling time the suite prints is measured under one of the
definitions of :data:`DEFINITIONS`, by name, with :func:`settling_time`; every
overshoot with :func:`overshoot`.  Both read the exact continuous trajectory
between the samples (ZOH flow, eq. 7; :mod:`ptoverify.sim.flow`) and work on
one trajectory or a batch on the same sample times.

A definition bounds the error e = r - x1 by a band (in mm, or as a fraction
of the reference's size: step height, ramp end value, sine amplitude), and
optionally the velocity error e' = r' - x2 by a velocity band given as a
distance b_v: |e'| <= a b_v [mm/s] (a state coasting with u = 0 from that speed
moves at most b_v further).  The settling time is the last exit of the
continuous trajectory from that box, measured from the record's start: 0 if
never outside, NaN if the record ends outside or the settled tail is shorter
than the definition's hold time.  Its sample-grid twin (the same definition
read on the samples only) is returned beside it.

For regulation to the origin (``reference`` None) e = -x1 and e' = -x2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ptoverify.errors import InputError
from ptoverify.sim.flow import (
    Signal,
    Trajectory,
    as_signal,
    bracketed_newton,
    error_derivatives,
    pieces_of_intervals,
    split_intervals,
    zoh_flow,
)

__all__ = [
    "SettlingDefinition",
    "DEFINITIONS",
    "definition",
    "Settling",
    "settling_time",
    "grid_settling",
    "Overshoot",
    "overshoot",
    "grid_overshoot",
    "definitions_table",
]


@dataclass(frozen=True)
class SettlingDefinition:
    """A named settling definition: a box around the reference and a hold time.

    Attributes
    ----------
    name : str
        The name every user and every printed value refers to.
    description : str
        One line: what it measures and where the suite uses it.
    band_mm : float or None
        Position band |r - x1| <= band_mm [mm] (None: see ``band_fraction``).
    band_fraction : float or None
        Position band as a fraction of the reference's size |amplitude| [-]
        (exactly one of ``band_mm`` and ``band_fraction`` is given).
    velocity_band_mm : float or None
        Velocity band as a distance b_v: |r' - x2| <= a b_v [mm/s] (None: no
        velocity condition) [mm].
    hold_s : float
        Shortest settled tail that counts as settled [s].
    """

    name: str
    description: str
    band_mm: float | None = None
    band_fraction: float | None = None
    velocity_band_mm: float | None = None
    hold_s: float = 0.0

    def __post_init__(self) -> None:
        """Check that exactly one position band is given and all are positive."""
        if (self.band_mm is None) == (self.band_fraction is None):
            raise InputError(f"settling '{self.name}': give band_mm or band_fraction")
        for v in (self.band_mm, self.band_fraction, self.velocity_band_mm):
            if v is not None and not (math.isfinite(v) and v > 0):
                raise InputError(f"settling '{self.name}': bands must be finite and > 0")
        if not (math.isfinite(self.hold_s) and self.hold_s >= 0):
            raise InputError(f"settling '{self.name}': hold must be >= 0 s")

    def position_band(self, size: float) -> float:
        """Return the position band [mm] for a reference of size ``size`` [mm]."""
        if self.band_mm is not None:
            return float(self.band_mm)
        if not (math.isfinite(size) and size > 0):
            raise InputError(f"settling '{self.name}' needs a reference of nonzero size")
        return float(self.band_fraction) * abs(size)

    def velocity_band(self, a: float) -> float:
        """Return the velocity band [mm/s] for bandwidth ``a`` [rad/s] (inf: none)."""
        return math.inf if self.velocity_band_mm is None else a * self.velocity_band_mm

    def band_text(self) -> str:
        """Return the box in words, e.g. ``abs(e) <= 0.01 mm, abs(e') <= a * 0.01 mm``.

        Returns
        -------
        str
            The box (no ``|``, so that it fits a Markdown table cell).
        """
        pos = (
            f"abs(e) <= {self.band_mm:g} mm"
            if self.band_mm is not None
            else f"abs(e) <= {100 * self.band_fraction:g} % of the reference's size"
        )
        if self.velocity_band_mm is not None:
            pos += f", abs(e') <= a * {self.velocity_band_mm:g} mm [mm/s]"
        return pos


DEFINITIONS: dict[str, SettlingDefinition] = {
    d.name: d
    for d in (
        SettlingDefinition(
            "2pct",
            "classical band (Sec. 6.1 'adjustment time'): simulate, report, tune, claims",
            band_fraction=0.02,
        ),
        SettlingDefinition(
            "5pct",
            "the wider classical band: the claims' second reading of 'adjustment time'",
            band_fraction=0.05,
        ),
        SettlingDefinition(
            "0p01mm",
            "tight band, 2 % of the paper's linear zone d = 0.5 mm: simulate, report, tune",
            band_mm=0.01,
        ),
        SettlingDefinition(
            "box-0p01mm",
            "regulation box held 50 ms: sweep, robust, tune's settling / (N* T)",
            band_mm=0.01,
            velocity_band_mm=0.01,
            hold_s=0.05,
        ),
        SettlingDefinition(
            "0p001mm",
            "the closed-loop properties' and the conformance gate's settled band",
            band_mm=0.001,
        ),
    )
}
"""The settling definitions, by name (the README's table is generated from it)."""


def definition(name: str | SettlingDefinition) -> SettlingDefinition:
    """Return the definition called ``name`` (a definition is returned as is).

    Parameters
    ----------
    name : str or SettlingDefinition
        A key of :data:`DEFINITIONS`.

    Returns
    -------
    SettlingDefinition
        The definition.

    Examples
    --------
    >>> definition("0p01mm").band_mm
    0.01
    """
    if isinstance(name, SettlingDefinition):
        return name
    if name not in DEFINITIONS:
        raise InputError(f"unknown settling definition '{name}' ({', '.join(DEFINITIONS)})")
    return DEFINITIONS[name]


def definitions_table() -> str:
    """Return the Markdown table of :data:`DEFINITIONS` (the README's).

    Returns
    -------
    str
        One row per definition: name, box, hold [s], description.
    """
    rows = ["| name | settled when | hold [s] | what and where |", "|---|---|---|---|"]
    for d in DEFINITIONS.values():
        rows.append(f"| `{d.name}` | {d.band_text()} | {d.hold_s:g} | {d.description} |")
    return "\n".join(rows)


@dataclass(frozen=True)
class Settling:
    """Settling times of one or more trajectories under one definition.

    Attributes
    ----------
    definition : SettlingDefinition
        The definition measured.
    time : ndarray, shape (k,)
        Last exit of the continuous trajectory from the box, from the record's
        start [s]: 0 if never outside, NaN if not settled (outside at the end,
        or settled for less than the hold time).
    grid : ndarray, shape (k,)
        The same definition on the samples only [s]: the first sample from
        which every later sample is in the box; NaN likewise.
    accuracy : float
        Bound on the root-finding and round-off error of ``time`` [s]: 4 eps T
        (the stopping width) + 4 eps t_end (t_k + s); the crossing also moves
        with the round-off of eq. (7) divided by the slope of the crossed signal.
    """

    definition: SettlingDefinition
    time: NDArray[np.float64]
    grid: NDArray[np.float64]
    accuracy: float


#: Intervals x trajectories examined at once (bounds the memory of the pieces).
_BLOCK = 1 << 20


def settling_time(
    trajectory: Trajectory, reference: object, definition_: str | SettlingDefinition
) -> Settling:
    """Settling time under a named definition, exactly between samples.

    Parameters
    ----------
    trajectory : Trajectory
        One trajectory (x1 of shape (n + 1,)) or a batch (shape (n + 1, k)).
    reference : Signal, Reference-like, tuple or None
        The reference r(t) (:func:`ptoverify.sim.flow.as_signal`); None for
        regulation to the origin.
    definition_ : str or SettlingDefinition
        A name of :data:`DEFINITIONS` or a definition.

    Returns
    -------
    Settling
        Exact and sample-grid times, shape (k,) (k = 1 for one trajectory).

    Examples
    --------
    >>> t = np.linspace(0.0, 0.3, 151)
    >>> tr = Trajectory.from_samples(t, 1 - np.exp(-20 * t), 20 * np.exp(-20 * t),
    ...                              np.zeros(150), 20.0)
    >>> s = settling_time(tr, ("step", 1.0), "2pct")
    >>> round(float(s.time[0]), 6), float(s.grid[0])  # ln(50) / 20, then the next sample
    (0.195601, 0.196)
    """
    d = definition(definition_)
    sig = Signal("step", 0.0) if reference is None else as_signal(reference)
    b1, b2 = d.position_band(abs(sig.amplitude)), d.velocity_band(trajectory.a)
    t = trajectory.t
    one = trajectory.x1.ndim == 1
    X1 = trajectory.x1[:, None] if one else trajectory.x1
    X2 = trajectory.x2[:, None] if one else trajectory.x2
    U = trajectory.u[:, None] if one else trajectory.u
    k = X1.shape[1]
    T = float(np.max(np.diff(t)))
    t_end = float(t[-1])
    exact = np.empty(k)
    cols = max(1, _BLOCK // max(1, t.size))
    for c in range(0, k, cols):
        sl = slice(c, c + cols)
        tr = Trajectory(t, X1[:, sl], X2[:, sl], U[:, sl], trajectory.a)
        last, ended = _last_exit(tr, sig, b1, 1, T)
        if math.isfinite(b2):
            last2, ended2 = _last_exit(tr, sig, b2, 2, T)
            last, ended = np.maximum(last, last2), ended | ended2
        exact[sl] = np.where(ended, np.nan, last)
    hold_ok = t_end - exact >= d.hold_s - 1e-9 * T
    exact = np.where(hold_ok, exact - float(t[0]), np.nan)
    grid = grid_settling(trajectory, reference, d)
    eps = float(np.finfo(float).eps)
    return Settling(d, exact, grid, 4.0 * eps * T + 4.0 * eps * abs(t_end))


def grid_settling(
    trajectory: Trajectory, reference: object, definition_: str | SettlingDefinition
) -> NDArray[np.float64]:
    """Settling time under a named definition, read on the samples only.

    The first sample from which every later sample lies in the definition's box,
    measured from the record's start; NaN where the record ends outside or the
    settled tail is shorter than the hold time.  It is the ``grid`` twin that
    :func:`settling_time` returns beside the exact time, for studies that judge
    on the samples alone (``robust``: the same definition, without the cost of
    the exact last exit).

    Parameters
    ----------
    trajectory : Trajectory
        One trajectory or a batch (``u`` is not read); the velocity band is
        that of ``trajectory.a`` [rad/s].
    reference : Signal, Reference-like, tuple or None
        The reference r(t); None for regulation to the origin.
    definition_ : str or SettlingDefinition
        A name of :data:`DEFINITIONS` or a definition.

    Returns
    -------
    ndarray, shape (k,)
        Settling times on the sample grid [s].

    Examples
    --------
    >>> t = np.arange(4) * 0.1
    >>> tr = Trajectory.from_samples(t, [1.0, 0.5, 0.0, 0.0], [0, 0, 0, 0], [0, 0, 0], 10.0)
    >>> grid_settling(tr, None, "0p01mm").tolist()  # in the band from the third sample on
    [0.2]
    """
    d = definition(definition_)
    sig = Signal("step", 0.0) if reference is None else as_signal(reference)
    b1, b2 = d.position_band(abs(sig.amplitude)), d.velocity_band(trajectory.a)
    t = trajectory.t
    X1 = trajectory.x1[:, None] if trajectory.x1.ndim == 1 else trajectory.x1
    X2 = trajectory.x2[:, None] if trajectory.x2.ndim == 1 else trajectory.x2
    T = float(np.max(np.diff(t)))
    t_end = float(t[-1])
    out = np.abs(sig.r(t)[:, None] - X1) > b1
    if math.isfinite(b2):
        out |= np.abs(sig.r_dot(t)[:, None] - X2) > b2
    rev = out[::-1]
    kg = np.where(rev.any(axis=0), t.size - rev.argmax(axis=0), 0)
    tg = t[np.minimum(kg, t.size - 1)]
    ok = (kg < t.size) & (t_end - tg >= d.hold_s - 1e-9 * T)
    return np.where(ok, tg - float(t[0]), np.nan)


def _last_exit(tr: Trajectory, sig: Signal, band: float, order: int, T: float):  # noqa: N803
    """Absolute last time [s] |e| (order 1) or |e'| (order 2) exceeds band, per column.

    Returns (time, ended): t_0 where never outside; ``ended`` where the record
    ends outside.  The last exit lies in the last interval with an end outside
    (its start, or its end as the left limit: e' jumps where a ramp ends), or
    in a later interval whose ends are both inside but whose piece between
    them leaves the band.  Only those intervals are split into
    monotone pieces.  For a step or ramp reference, e' = r' - x2 is monotone on
    each interval (x2 is), so e' has no interior excursion, and e has one only
    where e' changes sign on the interval and |e_k| + h |e'_k| reaches the band
    (|e'| <= |e'_k| up to the extremum); for a sine every later interval is
    examined.
    """
    t0, h, x1, x2, u = split_intervals(tr, sig)
    m, k = x1.shape
    slope = sig.slope(t0 + 0.5 * h)[:, None]
    amp, w = sig.amplitude * (sig.kind == "sine"), sig.omega
    sampled = x1.shape[0] == tr.x1.shape[0] - 1  # no cut: each interval ends at a sample

    def at_ends(x, full):  # the state at each interval's end (the next interval's start)
        return full[1:] if sampled else np.concatenate([x[1:], full[-1:]])

    if order == 1:
        e_start, e_end = sig.r(t0)[:, None] - x1, sig.r(t0 + h)[:, None] - at_ends(x1, tr.x1)
        e_last = float(sig.r(tr.t[-1])) - tr.x1[-1]
    else:  # e' jumps where the ramp ends: the end of an interval is its left limit
        e_start = slope + amp * w * np.cos(w * t0)[:, None] - x2
        e_end = slope + amp * w * np.cos(w * (t0 + h))[:, None] - at_ends(x2, tr.x2)
        e_last = float(sig.r_dot(tr.t[-1])) - tr.x2[-1]
    ended = np.abs(e_last) > band
    abs_start = np.abs(e_start)
    outs = (abs_start > band) | (np.abs(e_end) > band)
    rows = np.arange(m)[:, None]
    L = np.where(outs.any(axis=0), m - 1 - outs[::-1].argmax(axis=0), -1)
    cand = rows == L[None, :]
    if sig.kind == "sine":
        cand |= rows > L[None, :]
    elif order == 1:
        d_start, d_end = slope - x2, slope - at_ends(x2, tr.x2)
        with np.errstate(invalid="ignore"):
            reach = abs_start + h[:, None] * np.abs(d_start) >= band * (1.0 - 1e-9)
            cand |= (rows > L[None, :]) & (d_start * d_end < 0.0) & reach
    ci, cc = np.nonzero(cand)  # row-major: by interval, then column
    last = np.full(k, float(tr.t[0]))
    if ci.size == 0:
        return last, ended
    p = pieces_of_intervals(t0[ci], h[ci], x1[ci, cc], x2[ci, cc], u[ci, cc], tr.a, sig, order)
    slope_c = slope[ci, 0]
    dargs = (p.x2[:, None], p.u[:, None], p.t0[:, None], slope_c[:, None], amp, w, p.a)
    ev = _e_at(p, p.brk) if order == 1 else error_derivatives(*dargs, p.brk, 1)[0]
    K = ev.shape[1]
    out = np.abs(ev) > band
    hit = np.flatnonzero(out.any(axis=1))
    best = np.full(k, -1)
    np.maximum.at(best, cc[hit], hit)  # each column's latest candidate with a point outside
    col = np.flatnonzero(best >= 0)
    f = best[col]
    j = K - 1 - out[f, ::-1].argmax(axis=1)
    at_end = j == K - 1  # outside at the end of the interval
    last[col[at_end]] = p.t0[f[at_end]] + p.h[f[at_end]]
    f, j, col = f[~at_end], j[~at_end], col[~at_end]
    if f.size:
        lo, hi = p.brk[f, j], p.brk[f, j + 1]
        level = np.copysign(band, ev[f, j])
        if order == 1:
            g = (p.x1[f], p.x2[f], p.u[f], p.t0[f], slope_c[f], amp, w, p.a, sig)

            def fdf(s):
                return _e_and_slope(*g, s, level)

        else:
            gd = (p.x2[f], p.u[f], p.t0[f], slope_c[f], amp, w, p.a)

            def fdf(s):
                d1, d2 = error_derivatives(*gd, s, 1)
                return d1 - level, d2

        s = bracketed_newton(fdf, lo, hi, fdf(lo)[0], 4.0 * np.finfo(float).eps * T)
        last[col] = p.t0[f] + s
    return last, ended


def _e_at(p, s):
    """Return e = r - x1 [mm] at offsets s of shape (m, K) of pieces p."""
    y1, _, r, _ = p.at(s)
    return r - y1


def _e_and_slope(x1k, x2k, uk, t0, slope, amp, w, a, sig, s, level):
    """e(s) - level [mm] and e'(s) [mm/s] on intervals (vectorized; eq. 7)."""
    y1, y2 = zoh_flow(x1k, x2k, uk, s, a)
    if sig.kind == "sine":
        r, rd = amp * np.sin(w * (t0 + s)), amp * w * np.cos(w * (t0 + s))
    else:
        r, rd = sig.r(t0) + slope * s, slope
    return r - y1 - level, rd - y2


@dataclass(frozen=True)
class Overshoot:
    """Overshoot past a final value, on the continuous trajectory.

    Attributes
    ----------
    value : ndarray, shape (k,)
        max(0, max_t s (x1(t) - target)) [mm], s = sign(target - x1(t_0)).
    t_peak : ndarray, shape (k,)
        Time of that maximum, from the record's start [s] (NaN when 0).
    grid : ndarray, shape (k,)
        The same on the samples only [mm].
    """

    value: NDArray[np.float64]
    t_peak: NDArray[np.float64]
    grid: NDArray[np.float64]


def overshoot(trajectory: Trajectory, target: float) -> Overshoot:
    """Overshoot past ``target`` on the exact trajectory between samples.

    The extrema of x1 between samples are at s* = ln((u - x2k)/u) / a when
    0 < s* < T_k (closed form), so the maximum is exact.

    Parameters
    ----------
    trajectory : Trajectory
        One trajectory or a batch (see :func:`settling_time`).
    target : float
        Final value [mm]; the direction of travel is sign(target - x1(t_0))
        (up when equal).

    Returns
    -------
    Overshoot
        Values of shape (k,).

    Examples
    --------
    >>> from ptoverify.model.plant import flow
    >>> x1, x2 = flow(0.0, 20.0, -1.0, 0.1, 100.0)  # one sample of 0.1 s
    >>> tr = Trajectory.from_samples([0.0, 0.1], [0.0, x1], [20.0, x2], [-1.0], 100.0)
    >>> ov = overshoot(tr, 0.15)  # both samples are below 0.15 mm
    >>> round(float(ov.value[0]), 6), round(float(ov.t_peak[0]), 6)  # s* = ln(21) / 100
    (0.019555, 0.030445)
    """
    tr = trajectory
    one = tr.x1.ndim == 1
    X1 = tr.x1[:, None] if one else tr.x1
    X2 = tr.x2[:, None] if one else tr.x2
    U = tr.u[:, None] if one else tr.u
    t = tr.t
    t0, h = t[:-1, None], np.diff(t)[:, None]
    x1, x2 = X1[:-1], X2[:-1]
    sgn = np.where(target >= X1[0], 1.0, -1.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s_star = np.log1p(-x2 / U) / tr.a
    inner = np.isfinite(s_star) & (s_star > 0) & (s_star < h)
    s_star = np.where(inner, s_star, 0.0)
    y1, _ = zoh_flow(x1, x2, U, s_star, tr.a)
    cand = sgn * (np.where(inner, y1, x1) - target)
    cand_t = t0 + s_star
    also = sgn * (X1 - target)  # the samples themselves
    cols = np.arange(X1.shape[1])
    j, i = cand.argmax(axis=0), also.argmax(axis=0)
    cj, ai = cand[j, cols], also[i, cols]
    best = np.where(cj >= ai, cj, ai)
    tb = np.where(cj >= ai, cand_t[j, 0 * cols], t[i]) - float(t[0])
    pos = best > 0
    return Overshoot(
        np.where(pos, best, 0.0), np.where(pos, tb, np.nan), grid_overshoot(X1, target)
    )


def grid_overshoot(x1: NDArray, target: float) -> NDArray[np.float64]:
    """Overshoot past ``target`` read on the samples only: the ``grid`` of :func:`overshoot`.

    For studies that judge on the samples alone (the gate grid's properties, the
    robustness maps), without the cost of the extrema between samples.

    Parameters
    ----------
    x1 : ndarray, shape (n,) or (n, k)
        Sampled positions [mm] (one trajectory, or k as columns).
    target : float
        Final value [mm]; the direction of travel is sign(target - x1[0]) (up when equal).

    Returns
    -------
    ndarray, shape (k,)
        max(0, max_k s (x1[k] - target)) [mm] per trajectory.

    Examples
    --------
    >>> grid_overshoot(np.array([[2.0, -1.0], [-0.5, 0.25], [0.0, 0.0]]), 0.0).tolist()
    [0.5, 0.25]
    """
    X1 = x1[:, None] if x1.ndim == 1 else x1
    sgn = np.where(target >= X1[0], 1.0, -1.0)
    return np.maximum((sgn * (X1 - target)).max(axis=0), 0.0)
