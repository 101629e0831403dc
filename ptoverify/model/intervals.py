"""Outward-rounded interval arithmetic on NumPy arrays.

An interval is a pair ``(lo, hi)`` of float arrays (or floats) with lo <= hi.
Every operation returns an interval that contains the exact real result for
every choice of operands in the operand intervals.

Why widening every result outward is sound: NumPy's ``+ - * /`` on float64
are IEEE 754 operations in round-to-nearest, so the computed result r differs
from the exact real result by at most half an ulp of r.  Any float at least
half an ulp below (above) r is then a lower (upper) bound.  :func:`down` and
:func:`up` move r by two ulps relative (|r| 2^-51, plus 2^-1000 for tiny r),
which stays outward even after the widening's own rounding (proof in
:func:`down`); ``np.nextafter`` (exactly one ulp) would be as sound and is ten
times slower on large arrays.  Every result stays finite here (the grid and
the constants are finite), and non-finite images are treated as exits.  No transcendental libm call is trusted: log1p
and h(r) = r - ln(1 + r) are enclosed by bounded series evaluated with these
operations (:func:`log1p_point`, :func:`h_point`), and the exponentials of the
ZOH map are computed in python-flint ``arb`` ball arithmetic and converted to
floats outward (:func:`arb_interval`).

Catalogue: :func:`down`, :func:`up`, :func:`add`, :func:`sub`, :func:`mul`,
:func:`div`, :func:`log1p_point`, :func:`log1p_iv`, :func:`h_point`,
:func:`h_iv`, :func:`arb_interval`.  The ZOH map enclosures built on them are
in :mod:`ptoverify.model.zohmaps`.
"""

from __future__ import annotations

import numpy as np
from flint import arb, ctx

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
    "ARB_PREC",
]

ARB_PREC = 200  #: working precision of the arb certificates [bits]
_SERIES_TERMS = 11  #: odd terms of the atanh series of ln (|s| <= 0.175: error < 1e-19 |s|)
_H_TERMS = 28  #: terms of the alternating series of h on [0, 1/4]


_REL = 2.0**-51  #: two ulps of a normal float, relative
_ABS = 2.0**-1000  #: covers results below 2^-970 (subnormal scaling) [any unit]


def down(x):
    """Return a float below x by at least two ulps: x - (|x| 2^-51 + 2^-1000).

    Sound lower bound of the exact result e of the IEEE operation that gave x
    (|e - x| <= ulp(x) / 2): for normal x, delta = |x| 2^-51 >= 2 ulp(x) (the
    product by a power of two is exact and adding 2^-1000 only rounds up), and
    fl(x - delta) <= x - delta + ulp(x - delta) / 2 <= x - 2 ulp(x) + ulp(x)
    since ulp(x - delta) <= 2 ulp(x); so the result is <= x - ulp(x) <= e.
    For |x| < 2^-970 the 2^-1000 term dominates every rounding error.
    (np.nextafter is exact one-ulp widening too, but ten times slower.)

    Parameters
    ----------
    x : array_like
        Rounded-to-nearest result of one IEEE operation (finite).

    Returns
    -------
    ndarray
        A lower bound of the exact result.

    Examples
    --------
    >>> float(down(1.0)) < 1.0
    True
    """
    t = np.abs(x)
    if not isinstance(t, np.ndarray):
        return x - (t * _REL + _ABS)
    t *= _REL
    t += _ABS
    return np.subtract(x, t, out=t)


def up(x):
    """Return a float above x by at least two ulps (see :func:`down`).

    Parameters
    ----------
    x : array_like
        Rounded-to-nearest result of one IEEE operation (finite).

    Returns
    -------
    ndarray
        An upper bound of the exact result.

    Examples
    --------
    >>> float(up(1.0)) > 1.0
    True
    """
    t = np.abs(x)
    if not isinstance(t, np.ndarray):
        return x + (t * _REL + _ABS)
    t *= _REL
    t += _ABS
    return np.add(x, t, out=t)


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
    >>> lo, hi = mul((-1.0, 2.0), (3.0, 3.0))
    >>> bool(lo < -3.0 and 6.0 < hi and hi - lo < 9.0 + 1e-14)
    True
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


def _mul_pos(p, q):
    """Enclose p * q for nonnegative intervals p, q (two products)."""
    return down(np.multiply(p[0], q[0])), up(np.multiply(p[1], q[1]))


_ATANH_COEF = None  # enclosures of 1 / (2k + 1), k = 0..K, set by _atanh_coef()


def _atanh_coef():
    """Enclosures of the atanh series' coefficients 1 / (2k + 1)."""
    global _ATANH_COEF
    if _ATANH_COEF is None:
        _ATANH_COEF = [_recip(2 * k + 1) for k in range(_SERIES_TERMS + 1)]
    return _ATANH_COEF


def _atanh_series(s):
    """Enclose 2 atanh(s) = ln((1 + s) / (1 - s)) for an interval s with |s| <= 0.175."""
    coef = _atanh_coef()
    s2 = mul(s, s)
    s2 = (np.maximum(s2[0], 0.0), s2[1])  # a square is nonnegative
    acc = coef[_SERIES_TERMS]
    for k in range(_SERIES_TERMS - 1, -1, -1):  # Horner in s^2: all terms nonnegative
        acc = add(_mul_pos(acc, s2), coef[k])
    # omitted terms k > K: 2 sum s^(2k+1)/(2k+1) <= 2 |s|^(2K+3) / ((2K+3)(1 - s^2))
    # <= |s| * 1e-19 for |s| <= 0.175 and K = 11 (2 0.175^24 / (25 0.969) < 5.7e-20)
    m = np.maximum(np.abs(s[0]), np.abs(s[1]))
    tail = np.where(m <= 0.175, up(m * 1e-19), 1e300)  # 1e300: no bound
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
        # s = fl(1 + r) is within ulp(s)/2 of 1 + r, and ln has slope <= 1/(s (1 - 2^-53))
        # there, so |ln(1 + r) - ln s| < 2^-52: one series at s, widened by 2^-52
        xs = np.maximum(1.0 + rb, np.finfo(float).tiny)
        ln = _log_point(xs)
        lo[big], hi[big] = down(ln[0] - 2.0**-52), up(ln[1] + 2.0**-52)
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


_H_COEF = None  # enclosures of (-1)^n / n, set by _h_coef()


def _h_coef():
    """Enclosures of the h series' coefficients (-1)^n / n, index n."""
    global _H_COEF
    if _H_COEF is None:
        c = [_recip(n) if n else (0.0, 0.0) for n in range(_H_TERMS + 1)]
        _H_COEF = [(-v[1], -v[0]) if n % 2 else v for n, v in enumerate(c)]
    return _H_COEF


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
        coef = _h_coef()
        acc = coef[_H_TERMS]
        for n in range(_H_TERMS - 1, 1, -1):  # Horner: sum_{n=2}^{N} (-1)^n r^(n-2) / n
            acc = add(mul(acc, rr), coef[n])
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
        lo = float(np.nextafter(lo, -np.inf))
    hi = float(x.upper())
    while not arb(hi) >= x:
        hi = float(np.nextafter(hi, np.inf))
    return lo, hi
