"""Outward-rounded interval arithmetic on NumPy arrays, and ZOH map enclosures.

An interval is a pair ``(lo, hi)`` of float arrays (or floats) with lo <= hi.
Every operation returns an interval that contains the exact real result for
every choice of operands in the operand intervals.

Why ``np.nextafter`` outward on every result is sound: NumPy's ``+ - * /`` on
float64 are IEEE 754 operations in round-to-nearest, so the computed result r
differs from the exact real result by at most half an ulp of r (overflow gives
inf, which is still a bound).  The exact result therefore lies in
``[nextafter(r, -inf), nextafter(r, +inf)]``: one ulp outward on each side
covers the half ulp of error.  No transcendental libm call is trusted: log1p
and h(r) = r - ln(1 + r) are enclosed by bounded series evaluated with these
operations (:func:`log1p_point`, :func:`h_point`), and the exponentials of the
ZOH map are computed in python-flint ``arb`` ball arithmetic and converted to
floats outward (:func:`arb_interval`).

Catalogue: :func:`down`, :func:`up`, :func:`add`, :func:`sub`, :func:`mul`,
:func:`div`, :func:`log1p_point`, :func:`log1p_iv`, :func:`h_point`,
:func:`h_iv`, :func:`arb_interval`, :func:`a_ball`, :class:`StepMaps`,
:func:`step_maps`, :func:`affine_image`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from flint import arb, arb_mat, ctx

__all__ = [
    "down",
    "up",
    "add",
    "sub",
    "mul",
    "div",
    "log1p_point",
    "log1p_iv",
    "h_point",
    "h_iv",
    "arb_interval",
    "a_ball",
    "StepMaps",
    "step_maps",
    "affine_image",
    "ARB_PREC",
]

ARB_PREC = 200  #: working precision of the arb certificates [bits]
_SERIES_TERMS = 14  #: odd terms of the atanh series of ln (|s| <= 0.172: error < 1e-22)
_H_TERMS = 28  #: terms of the alternating series of h on [0, 1/4]


def down(x):
    """Return the next float below x (one ulp outward).

    Parameters
    ----------
    x : array_like
        Rounded-to-nearest result of one IEEE operation.

    Returns
    -------
    ndarray
        A lower bound of the exact result.

    Examples
    --------
    >>> float(down(1.0)) < 1.0
    True
    """
    return np.nextafter(x, -np.inf)


def up(x):
    """Return the next float above x (one ulp outward).

    Parameters
    ----------
    x : array_like
        Rounded-to-nearest result of one IEEE operation.

    Returns
    -------
    ndarray
        An upper bound of the exact result.

    Examples
    --------
    >>> float(up(1.0)) > 1.0
    True
    """
    return np.nextafter(x, np.inf)


def add(p, q):
    """Enclose p + q for intervals p, q (pairs of arrays or floats).

    Parameters
    ----------
    p, q : tuple
        Intervals (lo, hi).

    Returns
    -------
    tuple
        (lo, hi) containing every sum.

    Examples
    --------
    >>> lo, hi = add((0.1, 0.1), (0.2, 0.2))
    >>> float(lo) <= 0.30000000000000004 <= float(hi)
    True
    """
    return down(np.add(p[0], q[0])), up(np.add(p[1], q[1]))


def sub(p, q):
    """Enclose p - q for intervals p, q.

    Parameters
    ----------
    p, q : tuple
        Intervals (lo, hi).

    Returns
    -------
    tuple
        (lo, hi) containing every difference.

    Examples
    --------
    >>> [float(v) < 1e-16 for v in sub((1.0, 1.0), (1.0, 1.0))]
    [True, True]
    """
    return down(np.subtract(p[0], q[1])), up(np.subtract(p[1], q[0]))


def mul(p, q):
    """Enclose p * q for intervals p, q (the four endpoint products).

    Parameters
    ----------
    p, q : tuple
        Intervals (lo, hi).

    Returns
    -------
    tuple
        (lo, hi) containing every product.

    Examples
    --------
    >>> [float(v) for v in mul((-1.0, 2.0), (3.0, 3.0))]
    [-3.0000000000000004, 6.000000000000001]
    """
    a = np.multiply(p[0], q[0])
    b = np.multiply(p[0], q[1])
    c = np.multiply(p[1], q[0])
    d = np.multiply(p[1], q[1])
    lo = np.minimum(np.minimum(a, b), np.minimum(c, d))
    hi = np.maximum(np.maximum(a, b), np.maximum(c, d))
    return down(lo), up(hi)


def div(p, q):
    """Enclose p / q for intervals p and q with q > 0.

    Parameters
    ----------
    p : tuple
        Numerator interval (lo, hi).
    q : tuple
        Denominator interval (lo, hi), lo > 0.

    Returns
    -------
    tuple
        (lo, hi) containing every quotient.

    Examples
    --------
    >>> lo, hi = div((1.0, 1.0), (3.0, 3.0))
    >>> float(lo) < 1 / 3 < float(hi)
    True
    """
    a = np.divide(p[0], q[0])
    b = np.divide(p[0], q[1])
    c = np.divide(p[1], q[0])
    d = np.divide(p[1], q[1])
    lo = np.minimum(np.minimum(a, b), np.minimum(c, d))
    hi = np.maximum(np.maximum(a, b), np.maximum(c, d))
    return down(lo), up(hi)


def _recip(n: int) -> tuple[float, float]:
    """Enclose 1 / n for a positive integer n."""
    r = 1.0 / n
    return float(down(r)), float(up(r))


_LN2 = None  # set lazily by _ln2()


def _ln2() -> tuple[float, float]:
    """Enclose ln 2 (from arb)."""
    global _LN2
    if _LN2 is None:
        with ctx.workprec(ARB_PREC):
            _LN2 = arb_interval(arb(2).log())
    return _LN2


def _atanh_series(s):
    """Enclose 2 atanh(s) = ln((1 + s) / (1 - s)) for an interval s with |s| <= 0.18."""
    s2 = mul(s, s)
    acc = _recip(2 * _SERIES_TERMS + 1)
    for k in range(_SERIES_TERMS - 1, -1, -1):  # Horner in s^2
        acc = add(mul(acc, s2), _recip(2 * k + 1))
    # omitted terms k > K: 2 sum s^(2k+1)/(2k+1) <= 2 |s|^(2K+3) / ((2K+3)(1 - s^2))
    # <= |s| * 2e-24 for |s| <= 0.175 and K = 14 (0.175^30 < 1e-22); larger |s|: no bound
    m = np.maximum(np.abs(s[0]), np.abs(s[1]))
    tail = np.where(m <= 0.175, up(m * 2e-24), np.inf)
    val = mul(s, acc)
    val = (down(2.0 * val[0]), up(2.0 * val[1]))
    return down(val[0] - tail), up(val[1] + tail)


def log1p_point(r):
    """Enclose ln(1 + r) at float points r > -1 (no libm call).

    |r| <= 1/4: ln(1 + r) = 2 atanh(s), s = r / (2 + r), by a bounded series.
    Otherwise 1 + r is enclosed, each endpoint split exactly by ``np.frexp``
    into m 2^e with m in [1/sqrt 2, sqrt 2), ln = e ln 2 + 2 atanh((m-1)/(m+1)).

    Parameters
    ----------
    r : ndarray
        Points [-], r > -1.

    Returns
    -------
    tuple
        (lo, hi) with lo <= ln(1 + r) <= hi.

    Examples
    --------
    >>> lo, hi = log1p_point(np.array([1.0]))
    >>> bool(lo[0] <= np.log(2.0) <= hi[0])
    True
    """
    r = np.asarray(r, dtype=float)
    lo, hi = np.empty(r.shape), np.empty(r.shape)
    small = np.abs(r) <= 0.25
    if small.any():
        rs = r[small]
        s = div((rs, rs), add((2.0, 2.0), (rs, rs)))
        lo[small], hi[small] = _atanh_series(s)
    big = ~small
    if big.any():
        rb = r[big]
        x = add((1.0, 1.0), (rb, rb))  # 1 + r enclosed; ln is increasing
        ends = [_log_point(np.maximum(xe, np.finfo(float).tiny)) for xe in x]
        lo[big], hi[big] = ends[0][0], ends[1][1]
    return lo, hi


def _log_point(x):
    """Enclose ln x at float points x > 0 by an exact frexp split and a series."""
    m, e = np.frexp(x)  # exact: x = m 2^e, m in [0.5, 1)
    low = m < np.sqrt(0.5)
    m = np.where(low, 2.0 * m, m)  # exact scaling by 2
    e = np.where(low, e - 1, e).astype(float)
    t = div(sub((m, m), (1.0, 1.0)), add((m, m), (1.0, 1.0)))
    return add(mul((e, e), _ln2()), _atanh_series(t))


def log1p_iv(p):
    """Enclose ln(1 + r) over intervals r in [lo, hi], lo > -1 (increasing).

    Parameters
    ----------
    p : tuple
        Interval (lo, hi) [-].

    Returns
    -------
    tuple
        (lo, hi) containing ln(1 + r) for every r in p.

    Examples
    --------
    >>> lo, hi = log1p_iv((np.array([0.5]), np.array([2.0])))
    >>> bool(lo[0] <= np.log(1.5) and np.log(3.0) <= hi[0])
    True
    """
    return log1p_point(p[0])[0], log1p_point(p[1])[1]


def h_point(r):
    """Enclose h(r) = r - ln(1 + r) at float points r >= 0 (eq. 9's h).

    r <= 1/4: the alternating series sum_{n>=2} (-r)^n / n, whose remainder
    is bounded by its first omitted term; otherwise r - :func:`log1p_point`.

    Parameters
    ----------
    r : ndarray
        Points [-], r >= 0.

    Returns
    -------
    tuple
        (lo, hi) with lo <= h(r) <= hi, lo >= 0.

    Examples
    --------
    >>> lo, hi = h_point(np.array([1.0]))
    >>> bool(lo[0] <= 1.0 - np.log(2.0) <= hi[0])
    True
    """
    r = np.asarray(r, dtype=float)
    lo, hi = np.empty(r.shape), np.empty(r.shape)
    small = r <= 0.25
    if small.any():
        rs = r[small]
        rr = (rs, rs)
        acc = _recip(_H_TERMS)
        acc = (-acc[1], -acc[0]) if _H_TERMS % 2 else acc
        for n in range(_H_TERMS - 1, 1, -1):  # Horner: sum_{n=2}^{N} (-1)^n r^(n-2) / n
            c = _recip(n)
            c = (-c[1], -c[0]) if n % 2 else c
            acc = add(mul(acc, rr), c)
        val = mul(mul(acc, rr), rr)
        # alternating, decreasing terms (r <= 1/4): the error is below the first omitted
        # term r^(N+1) / (N+1) <= r^2 0.25^(N-1) / (N+1) <= r^2 1e-17 for N = 28
        tail = up(up(rs * rs) * 1e-17)
        lo[small], hi[small] = down(val[0] - tail), up(val[1] + tail)
    big = ~small
    if big.any():
        rb = r[big]
        lo[big], hi[big] = sub((rb, rb), log1p_point(rb))
    return np.maximum(lo, 0.0), hi


def h_iv(p):
    """Enclose h(r) = r - ln(1 + r) over intervals r in [lo, hi] >= 0 (increasing).

    Parameters
    ----------
    p : tuple
        Interval (lo, hi) [-], lo >= 0.

    Returns
    -------
    tuple
        (lo, hi) containing h(r) for every r in p.

    Examples
    --------
    >>> lo, hi = h_iv((np.array([0.0]), np.array([1.0])))
    >>> float(lo[0]), bool(hi[0] >= 1.0 - np.log(2.0))
    (0.0, True)
    """
    return h_point(p[0])[0], h_point(p[1])[1]


def arb_interval(x: arb) -> tuple[float, float]:
    """Convert an arb ball to floats (lo, hi) rounded outward.

    The arb comparisons used are certain (True only when they hold for every
    point of the ball), so the returned floats bound the ball.

    Parameters
    ----------
    x : arb
        Ball.

    Returns
    -------
    tuple of float
        lo <= every point of x <= hi.

    Examples
    --------
    >>> lo, hi = arb_interval(arb(1) / 3)
    >>> lo < 1 / 3 < hi or lo <= 1 / 3 <= hi
    True
    """
    if not x.is_finite():
        return -np.inf, np.inf
    lo = float(x.lower())
    while not arb(lo) <= x:
        lo = float(down(lo))
    hi = float(x.upper())
    while not arb(hi) >= x:
        hi = float(up(hi))
    return lo, hi


def a_ball(a_lo: float, a_hi: float) -> arb:
    """Return an arb ball containing the closed interval [a_lo, a_hi].

    Parameters
    ----------
    a_lo, a_hi : float
        Bandwidth interval [rad/s], a_lo <= a_hi.

    Returns
    -------
    arb
        Ball containing [a_lo, a_hi].

    Examples
    --------
    >>> a_ball(1.0, 2.0).contains(arb(1.5))
    True
    """
    return arb(a_lo).union(arb(a_hi))


@dataclass(frozen=True)
class StepMaps:
    """Enclosures of the exact j-step ZOH maps, j = 1..K, under a constant input.

    x1_j = x1 + p_j x2 + s1_j u, x2_j = e_j x2 + s2_j u, with e_j = exp(-a j T),
    p_j = (1 - e_j) / a, s1_j = j T - p_j, s2_j = 1 - e_j; and the j-th power
    of the closed-loop matrix of a linear law u = -g1 x1 - g2 x2.  Each entry is
    an interval (lo, hi) of arrays of shape (K + 1,) (index j; index 0 is the
    identity), valid for every constant a in the ball the maps were built for.

    Attributes
    ----------
    p, e, s1, s2 : tuple of ndarray
        Coefficient intervals [s], [-], [s], [-].
    lin : tuple of ndarray or None
        Closed-loop powers: (lo, hi), each of shape (K + 1, 2, 2) [s^0, s, 1/s].
    """

    p: tuple
    e: tuple
    s1: tuple
    s2: tuple
    lin: tuple | None


def step_maps(a: arb, T: float, K: int, gains: tuple[float, float] | None = None) -> StepMaps:  # noqa: N803
    """Enclose the j-step ZOH maps for j = 0..K in arb, then as float intervals.

    Parameters
    ----------
    a : arb
        Bandwidth ball [rad/s] (a point or :func:`a_ball`).
    T : float
        Sampling period [s].
    K : int
        Largest number of steps.
    gains : tuple of float, optional
        Linear law gains (g1 [1/s], g2 [-]), u = -g1 x1 - g2 x2.

    Returns
    -------
    StepMaps
        The enclosures.

    Examples
    --------
    >>> m = step_maps(arb(100), 0.01, 2)
    >>> bool(m.e[0][1] < np.exp(-1.0) < m.e[1][1])
    True
    """
    cols = {k: ([], []) for k in ("p", "e", "s1", "s2")}
    mats = ([], [])
    with ctx.workprec(ARB_PREC):
        t = arb(T)
        ed = (-a * t).exp()
        if gains is not None:
            g = -(-a * t).expm1()  # 1 - e^{-aT}
            A = arb_mat([[1, g / a], [0, 1 - g]])  # noqa: N806
            B = arb_mat([[t - g / a], [g]])  # noqa: N806
            K1 = arb_mat([[arb(gains[0]), arb(gains[1])]])  # noqa: N806
            acl = A - B * K1
            power = arb_mat([[1, 0], [0, 1]])
        ej = arb(1)
        for j in range(K + 1):
            vals = {"e": ej, "p": (1 - ej) / a, "s2": 1 - ej}
            vals["s1"] = j * t - vals["p"]
            for k, v in vals.items():
                lo, hi = arb_interval(v)
                cols[k][0].append(lo)
                cols[k][1].append(hi)
            if gains is not None:
                iv = [[arb_interval(power[r, c]) for c in range(2)] for r in range(2)]
                mats[0].append([[iv[r][c][0] for c in range(2)] for r in range(2)])
                mats[1].append([[iv[r][c][1] for c in range(2)] for r in range(2)])
                power = power * acl
            ej = ej * ed
    arr = {k: (np.array(v[0]), np.array(v[1])) for k, v in cols.items()}
    lin = (np.array(mats[0]), np.array(mats[1])) if gains is not None else None
    return StepMaps(arr["p"], arr["e"], arr["s1"], arr["s2"], lin)


def affine_image(maps: StepMaps, j, box, u):
    """Enclose the j-step image of boxes under a constant input in an interval.

    Parameters
    ----------
    maps : StepMaps
        Coefficient enclosures.
    j : ndarray of int
        Number of steps per box (0..K).
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].
    u : tuple of ndarray
        Input interval (lo, hi) [mm/s], held constant over the j steps.

    Returns
    -------
    tuple of ndarray
        Image box (x1lo, x1hi, x2lo, x2hi).

    Examples
    --------
    >>> m = step_maps(arb(100), 0.01, 1)
    >>> b = affine_image(m, np.array([1]), tuple(np.zeros(1) for _ in range(4)),
    ...                  (np.ones(1), np.ones(1)))
    >>> bool(b[0][0] < 0.01 - (1 - np.exp(-1)) / 100 < b[1][0])
    True
    """
    x1 = (box[0], box[1])
    x2 = (box[2], box[3])
    p = (maps.p[0][j], maps.p[1][j])
    e = (maps.e[0][j], maps.e[1][j])
    s1 = (maps.s1[0][j], maps.s1[1][j])
    s2 = (maps.s2[0][j], maps.s2[1][j])
    y1 = add(add(x1, mul(p, x2)), mul(s1, u))
    y2 = add(mul(e, x2), mul(s2, u))
    return y1[0], y1[1], y2[0], y2[1]


def linear_image(maps: StepMaps, j, box):
    """Enclose the j-step image of boxes under the closed-loop linear map.

    Parameters
    ----------
    maps : StepMaps
        Enclosures built with ``gains``.
    j : ndarray of int
        Steps per box (0..K).
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    tuple of ndarray
        Image box (x1lo, x1hi, x2lo, x2hi).

    Examples
    --------
    >>> m = step_maps(arb(100), 0.01, 1, gains=(0.0, 0.0))
    >>> b = linear_image(m, np.array([0]), (np.ones(1), np.ones(1), np.ones(1), np.ones(1)))
    >>> bool(b[0][0] <= 1.0 <= b[1][0])
    True
    """
    lo, hi = maps.lin
    x1 = (box[0], box[1])
    x2 = (box[2], box[3])
    out = []
    for r in range(2):
        m1 = (lo[j, r, 0], hi[j, r, 0])
        m2 = (lo[j, r, 1], hi[j, r, 1])
        out.append(add(mul(m1, x1), mul(m2, x2)))
    return out[0][0], out[0][1], out[1][0], out[1][1]
