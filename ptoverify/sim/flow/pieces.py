"""Monotone pieces of a trajectory between samples: extrema, crossings and error derivatives."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ptoverify.errors import InputError

from .signal import zoh_flow

if TYPE_CHECKING:
    from .signal import Signal, Trajectory


@dataclass(frozen=True)
class Pieces:
    """Intervals (split at the reference's cuts) and their monotone pieces of e.

    Attributes
    ----------
    t0, h : ndarray, shape (m,)
        Interval starts and lengths [s].
    x1, x2, u : ndarray, shape (m,)
        State at each start [mm], [mm/s] and held input [mm/s].
    a : float
        Bandwidth [rad/s].
    sig : Signal or None
        The reference (None: x1 itself).
    brk : ndarray, shape (m, K)
        Piece boundaries as offsets [s], sorted, first 0, last h.
    """

    t0: NDArray[np.float64]  # (m,) interval starts [s]
    h: NDArray[np.float64]  # (m,) lengths [s]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    u: NDArray[np.float64]
    a: float
    sig: Signal | None
    brk: NDArray[np.float64]  # (m, K) piece boundaries in s, sorted, first 0, last h

    def at(self, s):
        """Return (x1, x2, r, r') at offsets s (broadcast against (m, 1))."""
        c = (slice(None),) + (None,) * (np.ndim(s) - 1)
        y1, y2 = zoh_flow(self.x1[c], self.x2[c], self.u[c], s, self.a)
        tt = self.t0[c] + s
        if self.sig is None:
            return y1, y2, np.zeros_like(y1), np.zeros_like(y1)
        w, amp = self.sig.omega, self.sig.amplitude * (self.sig.kind == "sine")
        slope = self.sig.slope(self.t0 + 0.5 * self.h)[c]
        r = self.sig.r(tt) if self.sig.kind != "ramp" else self.sig.r(self.t0)[c] + slope * s
        return y1, y2, r, slope + amp * w * np.cos(w * tt)


def split_intervals(tr: Trajectory, sig: Signal | None, extra: tuple[float, ...] = ()):
    """Interval arrays with the reference's cuts (and ``extra`` times) inserted.

    Parameters
    ----------
    tr : Trajectory
        The record.
    sig : Signal or None
        The reference (its cuts: the ramp's end).
    extra : tuple of float
        More cut times [s].

    Returns
    -------
    tuple
        t0, h of shape (m,) [s]; x1, x2, u with m rows [mm], [mm/s], [mm/s].
    """
    t0, h = tr.t[:-1], np.diff(tr.t)
    x1, x2, u = tr.x1[:-1], tr.x2[:-1], tr.u
    cuts = [c for c in (*(sig.cuts if sig else ()), *extra) if tr.t[0] < c < tr.t[-1]]
    for c in cuts:
        k = int(np.searchsorted(t0, c, side="right") - 1)
        s = c - t0[k]
        if s <= 0.0 or s >= h[k]:
            continue
        y1, y2 = zoh_flow(x1[k], x2[k], u[k], s, tr.a)
        t0 = np.insert(t0, k + 1, c)
        h = np.insert(h, k + 1, h[k] - s)
        h[k] = s
        x1, x2 = np.insert(x1, k + 1, y1, axis=0), np.insert(x2, k + 1, y2, axis=0)
        u = np.insert(u, k + 1, u[k], axis=0)
    return t0, h, x1, x2, u


def _cos_roots(theta0, dtheta, c):
    """Offsets (m, 2) in [0, dtheta] where cos(theta0 + x) = c (NaN if none); dtheta < 2 pi."""
    ok = np.abs(c) <= 1.0
    al = np.arccos(np.clip(c, -1.0, 1.0))
    out = np.full(np.shape(theta0) + (2,), np.nan)
    for j, alpha in enumerate((al, -al)):
        x = np.mod(alpha - theta0, 2.0 * math.pi)
        out[..., j] = np.where(ok & (x <= dtheta), x, np.nan)
    return out


def bracketed_newton(fdf, lo, hi, flo, tol):
    """Vectorized safeguarded Newton on brackets [lo, hi] with one sign change.

    Parameters
    ----------
    fdf : callable
        x -> (f(x), f'(x)), vectorized.
    lo, hi : ndarray
        Brackets [s].
    flo : ndarray
        f(lo).
    tol : float
        Stopping width [s].

    Returns
    -------
    ndarray
        The roots [s].

    ``fdf(x)`` returns (f, f').  A Newton step that leaves the bracket is
    replaced by bisection; iteration stops within ``tol`` of the root.
    """
    x = 0.5 * (lo + hi)
    live = np.ones(x.shape, dtype=bool)
    for _ in range(200):
        fx, dfx = fdf(x)
        same = np.sign(fx) == np.sign(flo)
        lo, flo = np.where(same, x, lo), np.where(same, fx, flo)
        hi = np.where(same, hi, x)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            xn = x - fx / dfx
        xn = np.where((xn > lo) & (xn < hi), xn, 0.5 * (lo + hi))
        done = (fx == 0) | (np.abs(xn - x) <= tol) | (hi - lo <= tol)
        x = np.where(live & (fx != 0), xn, x)
        live &= ~done
        if not live.any():
            break
    return x


def error_derivatives(x2, u, t0, slope, amp, w, a, s, order):
    """Return e^(order) and e^(order + 1) at offsets s (order 1 or 2).

    Parameters
    ----------
    x2, u : array_like
        Velocity at the interval's start and held input [mm/s].
    t0 : array_like
        Interval start [s].
    slope : array_like
        Ramp slope on the interval [mm/s].
    amp : float
        Sine amplitude [mm] (0: none).
    w : float
        Sine angular frequency [rad/s].
    a : float
        Bandwidth [rad/s].
    s : array_like
        Offsets [s].
    order : int
        1 or 2 [-].

    Returns
    -------
    tuple of ndarray
        The two derivatives [mm/s^order], [mm/s^(order + 1)].
    """
    dv = (x2 - u) * np.exp(-a * s)
    th = w * (t0 + s)
    c, sn = np.cos(th), np.sin(th)
    d2 = -amp * w * w * sn + a * dv
    if order == 1:
        return slope + amp * w * c - u - dv, d2
    return d2, -amp * w**3 * c - a * a * dv


def reference_parts(p: Pieces):
    """Return per-interval slope, sine amplitude and omega of the reference.

    Parameters
    ----------
    p : Pieces
        The intervals.

    Returns
    -------
    tuple
        Slope [mm/s] of shape (m,), amplitude [mm], omega [rad/s].
    """
    sig = p.sig
    if sig is None:
        return np.zeros(p.h.size), 0.0, 0.0
    return sig.slope(p.t0 + 0.5 * p.h), sig.amplitude * (sig.kind == "sine"), sig.omega


def piece_error_derivatives(p: Pieces, s):
    """Return e'(s) [mm/s] and e''(s) [mm/s^2] at offsets s of shape (m, K).

    Parameters
    ----------
    p : Pieces
        The intervals.
    s : ndarray, shape (m, K)
        Offsets [s].

    Returns
    -------
    tuple of ndarray
        e' [mm/s] and e'' [mm/s^2].
    """
    slope, amp, w = reference_parts(p)
    c = (slice(None), None)
    return error_derivatives(p.x2[c], p.u[c], p.t0[c], slope[c], amp, w, p.a, s, 1)


def interval_extrema(p0: Pieces, order: int) -> NDArray[np.float64]:
    """Return zeros in (0, h) of e' (order 1) or e'' (order 2) per interval.

    Parameters
    ----------
    p0 : Pieces
        The intervals.
    order : int
        1 or 2 [-].

    Returns
    -------
    ndarray, shape (m, 3)
        Offsets [s], NaN where none.
    """
    a, h = p0.a, p0.h
    m = h.size
    slope, amp, w = reference_parts(p0)
    if not (w > 0.0 and amp != 0.0):  # e' = v - x2(s): one closed-form root; e'' != 0
        out = np.full((m, 3), np.nan)
        if order == 1:
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                out[:, 0] = np.log1p((p0.x2 - slope) / (slope - p0.u)) / a
            out = np.where((out > 0) & (out < h[:, None]), out, np.nan)
        return out
    if w * float(h.max()) >= 2.0 * math.pi:
        raise InputError("a sine reference needs more than one sample per period")
    # e^{as} e^(order) is monotone between the closed-form roots of
    # cos(w t + psi + phi) = c: at most one zero of e^(order) between them
    psi = 0.0 if order == 1 else 0.5 * math.pi
    cc = a * (p0.u - slope) / (abs(amp) * w * math.hypot(a, w)) if order == 1 else np.zeros(m)
    shift = 0.0 if amp > 0 else math.pi
    r = _cos_roots(w * p0.t0 + psi + math.atan2(w, a) + shift, w * h, cc) / w
    brk = np.zeros((m, 4))
    brk[:, 1:] = h[:, None]
    brk[:, 1:3] = np.sort(np.where(np.isnan(r), h[:, None], r), axis=1)
    lo, hi = brk[:, :-1], brk[:, 1:]
    c = (slice(None), None)
    args = (p0.x2[c], p0.u[c], p0.t0[c], slope[c], amp, w, a)
    flo = error_derivatives(*args, lo, order)[0]
    fhi = error_derivatives(*args, hi, order)[0]
    out = np.full(lo.shape, np.nan)
    has = (flo * fhi < 0) & (hi > lo)
    if has.any():
        idx = np.nonzero(has)
        k = idx[0]
        g = (p0.x2[k], p0.u[k], p0.t0[k], slope[k], amp, w, a)
        # a few ulps of the absolute time t0 + s: the precision any time of the record has
        tol = 4.0 * np.finfo(float).eps * float(np.max(np.abs(p0.t0) + h))
        out[idx] = bracketed_newton(
            lambda x: error_derivatives(*g, x, order), lo[idx], hi[idx], flo[idx], tol
        )
    return np.where((out > 0) & (out < h[:, None]), out, np.nan)


def monotone_pieces(tr: Trajectory, sig: Signal | None, what: str = "e") -> Pieces:
    """Split the record into pieces on which e (what='e') or x1 (what='x1') is monotone.

    Parameters
    ----------
    tr : Trajectory
        The record.
    sig : Signal or None
        The reference.
    what : str
        ``e`` or ``x1``.

    Returns
    -------
    Pieces
        The pieces.
    """
    t0, h, x1, x2, u = split_intervals(tr, sig)
    return pieces_of_intervals(t0, h, x1, x2, u, tr.a, sig if what == "e" else None, 1)


def pieces_of_intervals(t0, h, x1, x2, u, a: float, sig: Signal | None, order: int) -> Pieces:
    """Return pieces of intervals on which e (order 1) or e' (order 2) is monotone.

    Parameters
    ----------
    t0, h : ndarray, shape (m,)
        Interval starts and lengths [s].
    x1, x2, u : ndarray, shape (m,)
        Start states [mm], [mm/s] and inputs [mm/s].
    a : float
        Bandwidth [rad/s].
    sig : Signal or None
        The reference.
    order : int
        1 or 2 [-].

    Returns
    -------
    Pieces
        The pieces.
    """
    p = Pieces(t0, h, x1, x2, u, a, sig, np.empty((0, 0)))
    z = interval_extrema(p, order)
    z = z[:, ~np.isnan(z).all(axis=0)]  # columns no interval uses
    brk = np.concatenate([np.zeros((h.size, 1)), np.where(np.isnan(z), h[:, None], z)], axis=1)
    brk = np.concatenate([np.sort(brk, axis=1), h[:, None]], axis=1)
    return Pieces(t0, h, x1, x2, u, a, sig, brk)


def piece_value(p: Pieces, s, what: str):
    """Return e (what='e') or x1 at offsets s.

    Parameters
    ----------
    p : Pieces
        The intervals.
    s : ndarray
        Offsets [s].
    what : str
        ``e`` or ``x1``.

    Returns
    -------
    ndarray
        Values [mm].
    """
    y1, _, r, _ = p.at(s)
    return r - y1 if what == "e" else y1


def piece_crossing(p: Pieces, k: int, s0: float, s1: float, level: float, what: str) -> float:
    """Return the time where the monotone e (or x1) of interval k crosses level.

    Parameters
    ----------
    p : Pieces
        The intervals.
    k : int
        Interval index [-].
    s0, s1 : float
        The monotone piece [s].
    level : float
        Level [mm].
    what : str
        ``e`` or ``x1``.

    Returns
    -------
    float
        Absolute time [s].
    """
    x1k, dv, uk, a, t0 = float(p.x1[k]), float(p.x2[k] - p.u[k]), float(p.u[k]), p.a, float(p.t0[k])
    sig = p.sig if what == "e" else None
    kind = sig.kind if sig else ""
    amp, w = (sig.amplitude, sig.omega) if sig else (0.0, 0.0)
    r0 = float(sig.r(t0)) if sig else 0.0
    slope = float(sig.slope(t0 + 0.5 * float(p.h[k]))) if sig else 0.0

    def f(s: float) -> float:  # eq. (7) in scalar arithmetic, as zoh_flow
        y1 = x1k + uk * s + dv * -math.expm1(-a * s) / a
        if sig is None:
            return y1 - level
        r = amp * math.sin(w * (t0 + s)) if kind == "sine" else r0 + slope * s
        return r - y1 - level

    f0, f1 = f(s0), f(s1)
    if f0 == 0.0 or s1 <= s0:
        return float(p.t0[k] + s0)
    if f1 == 0.0 or f0 * f1 > 0:  # touching the level at the end of the piece
        return float(p.t0[k] + s1)
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
