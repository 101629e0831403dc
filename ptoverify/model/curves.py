"""Switching function, switching curves and the roots of eqs. (22), (26), (31).

The curves through the origin under a constant input of level omega are

* x2 <= 0 (fourth quadrant, input +omega):  a x1 + x2 + omega ln(1 - x2/omega) = 0
  -- l1 for omega = w_max (eq. 9), l1* for omega0 (eq. 13), eq. (28) for omega_c;
* x2 >= 0 (second quadrant, input -omega):  a x1 + x2 - omega ln(1 + x2/omega) = 0
  -- l2 (eq. 11), l2* (eq. 14), eq. (33).

Both branches are one function, :func:`level_residual`::

    s(x1, x2; omega) = a x1 + sgn(x2) * omega * h(|x2| / omega),   h(r) = r - ln(1 + r)

computed with a series for small r so that it is exact to round-off near the
origin.  ``s > 0`` lies right of (above) the curve, ``s < 0`` left of (below).
With omega = w_max it is the switching function of the time-optimal law.

Roots.  Eq. (22), ln(1+y) = y - b0, and eqs. (26)/(31), ln(1+z) = k z, are
solved in closed form with the Lambert W function (the paper uses bisection):

* (22): y = -1 - W_{-1}(-e^{-1-b0})  (y > 0; the W_0 branch gives y in (-1, 0));
* (26), (31): z = -1 - W(-k e^{-k}) / k, branch W_{-1} for 0 < k < 1 (z > 0)
  and W_0 for k > 1 (-1 < z < 0); z = 0 is the trivial root.

Near the branch point -1/e the argument of W loses half the digits, so the
functions here take m = 1 - k (which callers form without cancellation, e.g.
m = -a x1 / x2) and polish the Lambert-W value with Newton steps on the
well-conditioned forms h(y) = b0 and m = 1 - u/(e^u - 1), u = ln(1 + z).
The bisection solvers are kept as the independent reference.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import lambertw

__all__ = [
    "h",
    "level_residual",
    "level_term",
    "level_side",
    "switching_function",
    "level_curve_x1",
    "root_22",
    "root_k",
    "omega_c",
    "bisect",
    "root_22_bisect",
    "root_k_bisect",
    "blockwise",
]

Array = NDArray[np.float64]

# Taylor coefficients of h(r) = r - ln(1 + r) = sum_{n>=2} (-1)^n r^n / n
_H_SERIES = np.array([(-1.0) ** n / n for n in range(2, 26)])
# of E2(u) = e^u - 1 - u = sum_{n>=2} u^n / n!
_E2_SERIES = np.array([1.0 / np.prod(np.arange(1, n + 1, dtype=float)) for n in range(2, 22)])
# the same, highest first, as Python floats (the one-value paths of h and _e2)
_H_COEF = tuple(float(c) for c in _H_SERIES[::-1])
_E2_COEF = tuple(float(c) for c in _E2_SERIES[::-1])


BLOCK = 8192  # states per block: 64 kB per float array, heap-allocated and cache-resident


def blockwise(fn, *arrays: ArrayLike, block: int = BLOCK):
    """Apply an elementwise array function block by block over broadcast arrays.

    Large temporaries (> 128 kB) are fresh ``mmap`` pages for every numpy
    operation, and first-touch page faults then cost more than the arithmetic;
    blocks of ``block`` elements stay in the heap and the cache.  Every output
    element depends only on the inputs at its index, so the result is bit-for-bit
    that of ``fn`` on the whole arrays.

    Parameters
    ----------
    fn : callable
        ``fn(*arrays) -> ndarray or tuple of ndarray``, elementwise; it is
        given 1-D arrays (of at most ``2 * block`` elements).
    *arrays : array_like
        Inputs, broadcast together.
    block : int
        Elements per block.

    Returns
    -------
    ndarray or tuple of ndarray
        As ``fn``, of the broadcast shape.
    """
    first = arrays[0]
    if (  # one block of 1-D float arrays of one shape: fn on them as they are
        type(first) is np.ndarray
        and first.ndim == 1
        and first.size <= 2 * block
        and all(
            type(a) is np.ndarray and a.dtype == np.float64 and a.shape == first.shape
            for a in arrays
        )
    ):
        return fn(*arrays)
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in arrays))
    shape, n = arrays[0].shape, arrays[0].size
    flat = [a.ravel() for a in arrays]
    if n <= 2 * block:  # one block; fn sees 1-D arrays always
        res = fn(*flat)
        if isinstance(res, tuple):
            return tuple(r.reshape(shape) for r in res)
        return res.reshape(shape)
    outs, single = None, False
    for i in range(0, n, block):
        res = fn(*(a[i : i + block] for a in flat))
        if outs is None:
            single = not isinstance(res, tuple)
            outs = [np.empty(n, dtype=r.dtype) for r in ((res,) if single else res)]
        for o, r in zip(outs, (res,) if single else res, strict=True):
            o[i : i + block] = r
    outs = tuple(o.reshape(shape) for o in outs)
    return outs[0] if single else outs


def _series(x: Array, coef: Array, lowest: int) -> Array:
    """Evaluate sum_j coef[j] x^(lowest + j) by Horner's rule (x finite).

    The accumulator starts at the top coefficient, which is what the first step
    0 * x + coef[-1] gives for finite x, so the roundings are those of Horner's
    rule from zero; its product with x is formed directly (``coef[-1] * x``).
    """
    acc = x * float(coef[-1])  # the first step, coef[-1] * x (exact same product)
    acc += float(coef[-2])
    for c in _constants(coef):  # in place: the same roundings as acc * x + c
        acc *= x
        acc += c
    return acc * x**lowest


_CONSTANTS: dict[int, tuple] = {}


def _constants(coef: Array) -> tuple:
    """coef[-3::-1] as 0-d arrays (no conversion of a Python float per operation)."""
    key = id(coef)
    if key not in _CONSTANTS or _CONSTANTS[key][0] is not coef:
        _CONSTANTS[key] = (coef, tuple(np.array(c) for c in coef[-3::-1].tolist()))
    return _CONSTANTS[key][1]


def _horner(x: float, coef: tuple[float, ...]) -> float:
    """:func:`_series` with ``lowest = 2`` for one Python float, highest coefficient first.

    Python floats round as numpy's float64 (IEEE double, no fused multiply-add),
    and ``x**2`` is ``x * x`` in numpy, so the result is bit for bit that of
    :func:`_series` on an array holding x.
    """
    acc = coef[0]
    for c in coef[1:]:
        acc = acc * x + c
    return acc * (x * x)


def h(r: ArrayLike) -> Array:
    """Return h(r) = r - ln(1 + r), exact to round-off near r = 0.

    Parameters
    ----------
    r : array_like
        Argument [-], r > -1.

    Returns
    -------
    ndarray
        h(r) >= 0 [-].

    Examples
    --------
    >>> float(h(1e-10))      # r^2/2 - r^3/3: exact where r - log1p(r) would give 0
    4.999999999666667e-21
    """
    r = np.asarray(r, dtype=float)
    if r.ndim == 0:  # one value: Horner on a Python float (bit for bit, see _horner)
        x = float(r)
        if abs(x) < 0.2:
            return np.asarray(_horner(x, _H_COEF))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(r - np.log1p(r))
    if r.size > 2 * BLOCK:  # cache-sized blocks (see blockwise); elementwise, so identical
        return blockwise(_h_block, r)
    return _h_block(r)


#: Up to this many series values per array are summed one by one in Python
#: (:func:`_horner`, bit for bit); more, by numpy passes over all of them.
FEW = 16


def _h_block(r: Array) -> Array:
    """:func:`h` on an array: r - log1p(r), and the series where |r| < 0.2."""
    with np.errstate(invalid="ignore", divide="ignore"):
        out = r - np.log1p(r)
    _put_series(out, r, np.abs(r) < 0.2, _H_SERIES, _H_COEF)  # the series only where used
    return out


def _put_series(out: Array, x: Array, where: NDArray[np.bool_], coef: Array, hcoef) -> None:
    """Overwrite ``out`` with the series of x (lowest power 2) where ``where`` holds."""
    count = np.count_nonzero(where)
    if count == 0:
        return
    if count <= FEW:  # a few values: no 2 x 20 numpy passes for them
        idx = where.ravel().nonzero()[0]  # np.flatnonzero, without its wrappers
        flat = out.reshape(-1)  # out is a fresh contiguous array: a view
        for i, v in zip(idx.tolist(), x.reshape(-1)[idx].tolist(), strict=True):
            flat[i] = _horner(v, hcoef)
    elif count == where.size:  # everywhere: no gather and scatter
        out[...] = _series(x, coef, 2)
    else:
        out[where] = _series(x[where], coef, 2)


def _e2(u: Array) -> Array:
    """Return e^u - 1 - u, exact to round-off near u = 0."""
    u = np.asarray(u, dtype=float)
    if u.ndim == 0:  # one value: Horner on a Python float (bit for bit, see _horner)
        x = float(u)
        if abs(x) < 0.5:
            return np.asarray(_horner(x, _E2_COEF))
        with np.errstate(over="ignore", invalid="ignore"):
            return np.asarray(np.expm1(u) - u)
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.expm1(u) - u
    _put_series(out, u, np.abs(u) < 0.5, _E2_SERIES, _E2_COEF)  # the series only where used
    return out


def level_residual(x1: ArrayLike, x2: ArrayLike, a: float, omega: ArrayLike) -> Array:
    """Residual of the level-omega curve through the origin, eqs. (9), (11), (13), (14).

    Parameters
    ----------
    x1, x2 : array_like
        State [mm], [mm/s].
    a : float
        Bandwidth [rad/s].
    omega : array_like
        Input level of the curve [mm/s], omega > 0.

    Returns
    -------
    ndarray
        a x1 + sgn(x2) omega h(|x2|/omega) [mm/s]: zero on the curve, positive
        right of it, negative left of it.
    """
    x1, x2, omega = (np.asarray(v, dtype=float) for v in (x1, x2, omega))
    if x1.ndim == 0 and x2.ndim == 0 and omega.ndim == 0:
        return a * x1 + level_term(x2, omega)
    if max(x1.size, x2.size) > 2 * BLOCK:  # cache-sized blocks; elementwise, so identical
        if omega.ndim == 0:
            return blockwise(lambda b1, b2: _level_residual(b1, b2, a, omega), x1, x2)
        return blockwise(lambda b1, b2, bo: _level_residual(b1, b2, a, bo), x1, x2, omega)
    return _level_residual(x1, x2, a, omega)


def _level_residual(x1: Array, x2: Array, a: float, omega: Array) -> Array:
    """:func:`level_residual` on float arrays (one block)."""
    return a * x1 + level_term(x2, omega)


def level_term(x2: ArrayLike, omega: ArrayLike) -> Array:
    """Return the velocity term of :func:`level_residual`, sgn(x2) omega h(|x2| / omega).

    ``level_residual(x1, x2, a, omega)`` is ``a * x1 + level_term(x2, omega)``, bit
    for bit, so a caller that scans many x1 at fixed velocities computes it once.

    Parameters
    ----------
    x2 : array_like
        Velocity [mm/s].
    omega : array_like
        Input level of the curve [mm/s], omega > 0.

    Returns
    -------
    ndarray
        sgn(x2) omega h(|x2| / omega) [mm/s].

    Examples
    --------
    >>> bool(level_residual(2.0, -50.0, 188.5, 300.0) == 188.5 * 2.0 + level_term(-50.0, 300.0))
    True
    """
    x2, omega = np.asarray(x2, dtype=float), np.asarray(omega, dtype=float)
    return np.sign(x2) * omega * h(np.abs(x2) / omega)


#: |level_term(x2, omega)| <= x2^2 / (2 omega), as h(r) <= r^2 / 2 for r >= 0; the bound
#: :func:`level_side` uses, 1e-6 relative above it (the round-off of h, of the term and of
#: the bound itself is below 1e-14 relative) plus an absolute floor below any term that
#: the bound's underflow could hide [mm/s]
_TERM_BOUND = 0.5 * (1.0 + 1e-6)
_TERM_FLOOR = 1e-300


#: Below this many states :func:`level_side` computes the sum everywhere (for few
#: states a numpy call's fixed cost outweighs the work it would save; from a few
#: dozen on, skipping the term's 24-term series where a x1 decides saves more)
SIDE_MIN = 64


def level_side(ax1: Array, x2: Array, omega: float | Array, band: float = 0.0) -> Array:
    """Return values that compare with 0 and +-band as ``ax1 + level_term(x2, omega)`` does.

    Where |ax1| exceeds a bound on the term (x2^2 / (2 omega), 1e-6 relative
    above it) plus 2 band, or where ax1 has the term's sign (x2's) and
    |ax1| > band, the sum has the sign of ax1, is never 0 and is beyond
    +-band, so ax1 is returned there; elsewhere (and where anything is NaN, or
    x2 = +-inf, where the term is NaN) the sum itself, bit for bit.  The term, a
    logarithm and a 24-term series near the curve's vertex, is then computed only
    near the curve.  Use
    it only where the value is read through ``< 0``, ``== 0``, ``> 0``,
    ``np.sign``, ``< -band`` and ``> band``.

    Parameters
    ----------
    ax1 : ndarray, shape (n,)
        a x1 [mm/s] (a [rad/s], x1 [mm]), as the caller forms it; not modified.
    x2 : ndarray, shape (n,)
        Velocity [mm/s].
    omega : float or ndarray, shape (n,)
        Input level of the curve [mm/s], omega > 0.
    band : float
        Band the values are compared with [mm/s], >= 0.

    Returns
    -------
    ndarray, shape (n,)
        Values with those comparisons of ax1 + level_term(x2, omega) [mm/s].

    Examples
    --------
    >>> ax1, x2 = np.array([188.5, 1e-3, 0.0]), np.array([-50.0, -50.0, 0.0])
    >>> full = ax1 + level_term(x2, 300.0)
    >>> bool((np.sign(level_side(ax1, x2, 300.0)) == np.sign(full)).all())
    True
    """
    if ax1.size < SIDE_MIN:  # few states: the fewest numpy calls
        return ax1 + level_term(x2, omega)
    bound = x2 * x2
    bound /= omega
    bound *= _TERM_BOUND
    bound += _TERM_FLOOR + 2.0 * band
    mag = np.abs(ax1)
    far = mag > bound  # False where anything is NaN: computed in full
    # a x1 of x2's sign (the term's): no cancellation, |sum| >= |a x1| > band
    same = ax1 * x2
    same = same > 0
    same &= bound < math.inf  # not at x2 = +-inf, where the term (inf - inf) is NaN
    if band > 0.0:
        same &= mag > band
    far |= same
    n_far = np.count_nonzero(far)
    if n_far == far.size:
        return ax1.copy()
    if 4 * n_far < far.size:  # mostly near: the sum everywhere (no gather and scatter)
        return ax1 + level_term(x2, omega)
    near = (~far).nonzero()[0]  # np.flatnonzero of the 1-D mask, without its wrappers
    out = ax1.copy()
    om = omega[near] if np.ndim(omega) else omega
    out[near] = ax1[near] + level_term(x2[near], om)
    return out


def switching_function(x1: ArrayLike, x2: ArrayLike, a: float, w_max: float) -> Array:
    """Switching function of the time-optimal law, curves l1 (eq. 9) and l2 (eq. 11).

    Parameters
    ----------
    x1, x2 : array_like
        State [mm], [mm/s].
    a : float
        Bandwidth [rad/s].
    w_max : float
        Velocity saturation [mm/s].

    Returns
    -------
    ndarray
        sigma [mm/s]: > 0 in S_N (u = -w_max), < 0 in S_P (u = +w_max), 0 on l1 - o - l2.

    Examples
    --------
    >>> float(switching_function(1.0, 0.0, 188.5, 300.0))
    188.5
    """
    return level_residual(x1, x2, a, w_max)


def level_curve_x1(x2: ArrayLike, a: float, omega: ArrayLike) -> Array:
    """Position x1 on the level-omega curve through the origin at velocity x2.

    Parameters
    ----------
    x2 : array_like
        Velocity [mm/s]; x2 < 0 gives l1-type points (eq. 9, 13, 28), x2 > 0
        l2-type points (eq. 11, 14, 33).
    a : float
        Bandwidth [rad/s].
    omega : array_like
        Input level [mm/s].

    Returns
    -------
    ndarray
        x1 [mm] such that ``level_residual(x1, x2, a, omega) == 0``.
    """
    x2, omega = np.asarray(x2, dtype=float), np.asarray(omega, dtype=float)
    return -np.sign(x2) * omega * h(np.abs(x2) / omega) / a


def _lambertw_real(x: Array, branch: int) -> Array:
    with np.errstate(all="ignore"):
        return np.real(lambertw(x, branch))


def root_22(b0: ArrayLike, branch: int = -1) -> Array:
    """Root y of eq. (22), ln(1 + y) = y - b0, in closed form.

    Parameters
    ----------
    b0 : array_like
        b0 >= 0 (eq. 21).
    branch : {-1, 0}
        -1: the root y >= 0, y = -1 - W_{-1}(-e^{-1-b0}); 0: the root in (-1, 0].

    Returns
    -------
    ndarray
        y*, NaN where b0 < 0 or not finite.

    Examples
    --------
    >>> y = float(root_22(1.0))
    >>> bool(abs(y - np.log1p(y) - 1.0) < 1e-15)
    True
    """
    if branch not in (-1, 0):
        raise ValueError("branch must be -1 or 0")
    b0 = np.asarray(b0, dtype=float)
    if b0.ndim == 0:
        return np.asarray(_root_22_one(float(b0), branch))
    ok = np.isfinite(b0) & (b0 >= 0)
    bb = np.where(ok, b0, 1.0)
    sign = 1.0 if branch == -1 else -1.0
    # initial u = ln(1 + y): branch-point series where W is ill-conditioned
    with np.errstate(all="ignore"):
        y_w = -1.0 - _lambertw_real(-np.exp(-1.0 - bb), branch)
        u = np.where(
            bb < 1e-3,
            sign * np.sqrt(2.0 * bb) * (1.0 + sign * np.sqrt(2.0 * bb) / 3.0),
            np.log1p(np.maximum(y_w, -1.0 + 1e-300)),
        )
        big = ~np.isfinite(u)  # e^{-1-b0} underflowed: y ~ b0 + ln(1+b0)
        u = np.where(big & (sign > 0), np.log1p(bb + np.log1p(bb)), u)
        u = np.where(big & (sign < 0), -bb - 1.0, u)
        if branch == 0:
            u = np.maximum(u, -bb - 1.0)  # y > -1: e^u - 1 - u = b0 => u > -b0 - 1
        for _ in range(4):  # Newton on E2(u) = b0; E2'(u) = e^u - 1
            du = (_e2(u) - bb) / np.expm1(u)
            u = np.where(u != 0.0, u - du, u)
    y = np.expm1(u)
    if branch == -1:
        # for large b0, e^u amplifies the rounding of u by u: finish with the contraction
        # y = b0 + ln(1 + y) (factor 1/(1 + y) < 0.05 per step), exact to round-off
        large = bb > 20.0
        if np.any(large):
            yl = np.where(large, y, 21.0)
            for _ in range(12):
                yl = bb + np.log1p(yl)
            y = np.where(large, yl, y)
    return np.where(ok, np.where(bb == 0.0, 0.0, y), np.nan)


def _nanmax(x: float, y: float) -> float:
    """np.maximum for two floats: NaN if either is NaN."""
    return x if (x >= y or x != x) else y


def _root_22_one(b0: float, branch: int) -> float:
    """:func:`root_22` for one value, bit for bit.

    The same operations in the same order as the array path, on Python floats;
    each transcendental function is numpy's (whose results differ from
    ``math``'s in the last bit for some arguments), so every rounding is the
    array path's.  Only the branch that the array path selects is computed.
    """
    ok = math.isfinite(b0) and b0 >= 0
    bb = b0 if ok else 1.0
    sign = 1.0 if branch == -1 else -1.0
    with np.errstate(all="ignore"):
        if bb < 1e-3:
            u = sign * math.sqrt(2.0 * bb) * (1.0 + sign * math.sqrt(2.0 * bb) / 3.0)
        else:
            y_w = -1.0 - float(_lambertw_real(-np.exp(-1.0 - bb), branch))
            u = float(np.log1p(_nanmax(y_w, -1.0 + 1e-300)))
        if not math.isfinite(u):  # e^{-1-b0} underflowed: y ~ b0 + ln(1+b0)
            u = float(np.log1p(bb + float(np.log1p(bb)))) if sign > 0 else -bb - 1.0
        if branch == 0:
            u = _nanmax(u, -bb - 1.0)
        for _ in range(4):  # Newton on E2(u) = b0; E2'(u) = e^u - 1
            if u != 0.0:
                u = u - (float(_e2(u)) - bb) / float(np.expm1(u))
        y = float(np.expm1(u))
        if branch == -1 and bb > 20.0:
            for _ in range(12):
                y = bb + float(np.log1p(y))
    if not ok:
        return math.nan
    return 0.0 if bb == 0.0 else y


def _m_of_u(u: Array) -> Array:
    """Return m = 1 - u / (e^u - 1) = E2(u) / (e^u - 1), exact near u = 0."""
    with np.errstate(all="ignore"):
        series = u / 2.0 - u * u / 12.0 + u**4 / 720.0
        return np.where(np.abs(u) < 1e-4, series, _e2(u) / np.expm1(u))


def root_k(m: ArrayLike) -> Array:
    """Non-trivial root z of eqs. (26)/(31), ln(1 + z) = k z, with m = 1 - k.

    Parameters
    ----------
    m : array_like
        m = 1 - k.  For eq. (31), m = -a x1 / x2; for eq. (26),
        m = -a x10 / x20 (eqs. 25, 30).

    Returns
    -------
    ndarray
        z* > 0 for 0 < m < 1 (k in (0, 1), branch W_{-1}); -1 < z* < 0 for m < 0
        (k > 1, branch W_0); 0 for m = 0 (double root); NaN for m >= 1 or not
        finite (no non-trivial root).

    Examples
    --------
    >>> z = float(root_k(0.5))
    >>> bool(abs(np.log1p(z) - 0.5 * z) < 1e-15)
    True
    """
    m = np.asarray(m, dtype=float)
    ok = np.isfinite(m) & (m < 1.0)
    mm = np.where(ok, m, 0.5)
    pos = mm > 0
    u = np.zeros_like(mm)
    if np.any(pos):
        mp = mm[pos] if mm.ndim else mm
        up = _u_of_m_positive(np.atleast_1d(mp))
        if mm.ndim:
            u[pos] = up
        else:
            u = up.reshape(())
    if np.any(mm < 0):
        u = np.where(mm < 0, _u_of_m_negative(mm), u)
    z = np.expm1(u)
    z = np.where(mm == 0.0, 0.0, z)
    return np.where(ok, z, np.nan)


def _u_of_m_positive(m: Array) -> Array:
    """U = ln(1 + z*) = -k - W_{-1}(-k e^{-k}) for 0 < m < 1, k = 1 - m.

    W_{-1} is evaluated by its own iteration on the equivalent equation
    F(u) = u - k (e^u - 1) = 0 (u = -k - W): a start from the branch-point series
    (u = 2m + 2m^2/3 + 4m^3/9, m < 1/4) or from upper bounds (u <= 2m/k, refined by
    u <- ln(1 + u/k), which keeps a bound), two Halley steps, then one Newton step with
    the residual in the form that is exact for the input: m (e^u - 1) - (e^u - 1 - u) for
    m < 1/2 (no cancellation for tiny roots), u - k (e^u - 1) otherwise (k small).
    Measured against bisection to the last bit: within a few ulps over (0, 1).
    """
    k = 1.0 - m
    with np.errstate(all="ignore"):
        u = m * (2.0 + m * (2.0 / 3.0 + m * 4.0 / 9.0))
        big = (m >= 0.25).ravel().nonzero()[0]  # the bound start, only where it is used
        if big.size:
            kb = k[big]
            bound = 2.0 * m[big] / kb
            for _ in range(3):
                bound = np.log1p(bound / kb)
            u[big] = bound
        keep = (m <= 1e-4).ravel().nonzero()[0]  # the series start is exact to ~m^3 already there
        u_keep = u[keep]
        # two Halley steps u -= 2 f f' / (2 f'^2 - f f'') over all states (those in `keep`
        # are restored after), in place with the same roundings as f = u - k em1,
        # f' = m - k em1, f'' = -k (em1 + 1) written out
        em1, f, df, num, den = (np.empty_like(u) for _ in range(5))
        for _ in range(2):
            np.expm1(u, out=em1)
            np.multiply(k, em1, out=f)
            np.subtract(m, f, out=df)  # f'
            np.subtract(u, f, out=f)  # f
            em1 += 1.0
            em1 *= k
            np.negative(em1, out=em1)  # f''
            np.multiply(2.0, f, out=num)
            num *= df
            np.multiply(2.0, df, out=den)
            den *= df
            em1 *= f
            den -= em1
            num /= den
            u -= num
        u[keep] = u_keep
        np.expm1(u, out=em1)  # Newton: u - f / (m - k em1)
        np.multiply(k, em1, out=f)
        np.subtract(m, f, out=den)
        np.subtract(u, f, out=f)
        small = (m < 0.5).ravel().nonzero()[0]
        if small.size:
            f[small] = m[small] * em1[small] - _e2(u[small])
        f /= den
        return np.subtract(u, f, out=f)


def _u_of_m_negative(m: Array) -> Array:
    """U = ln(1 + z*) for m < 0 (k > 1, W_0 branch), scipy's W_0 polished by Newton."""
    k = 1.0 - m
    with np.errstate(all="ignore"):
        z_w = -1.0 - _lambertw_real(-k * np.exp(-k), 0) / k
        u = np.log1p(np.maximum(z_w, -1.0 + 1e-300))
        u = np.where(np.abs(m) < 1e-3, 2.0 * m * (1.0 + m / 3.0), u)
        u = np.where(np.isfinite(u), u, -1.0)
        for _ in range(4):  # Newton on m(u) = m
            em1 = np.expm1(u)
            dm = (u * np.exp(u) - em1) / em1**2  # m'(u)
            dm = np.where(np.abs(u) < 1e-4, 0.5 - u / 6.0, dm)
            u = u - (_m_of_u(u) - m) / dm
    return np.where(m < 0, u, 0.0)


def omega_c(x1: ArrayLike, x2: ArrayLike, a: float) -> Array:
    """Level omega_c of the curve through the state, eqs. (28)-(33).

    In the fourth quadrant (x1 > 0, x2 < 0) omega_c solves
    a x1 + x2 + omega_c ln(1 - x2/omega_c) = 0 (eq. 28) via eqs. (30)-(32);
    in the second quadrant the mirror image (eq. 33).

    Parameters
    ----------
    x1, x2 : array_like
        State [mm], [mm/s].
    a : float
        Bandwidth [rad/s].

    Returns
    -------
    ndarray
        omega_c [mm/s] > 0.  +inf where x1 x2 >= 0 with x2 != 0 (no curve of
        finite level, the limit omega -> inf), 0 where m = -a x1/x2 >= 1
        (the limit omega -> 0, including x2 = 0, x1 != 0); NaN at the origin.

    Examples
    --------
    >>> wc = float(omega_c(0.1, -100.0, 188.5))
    >>> bool(abs(188.5 * 0.1 - 100.0 + wc * np.log1p(100.0 / wc)) < 1e-10)
    True
    """
    return blockwise(lambda b1, b2: _omega_c(b1, b2, a), x1, x2)


def _omega_c(x1: Array, x2: Array, a: float) -> Array:
    """:func:`omega_c` on broadcast float arrays (one block)."""
    with np.errstate(all="ignore"):
        m = -a * x1 / x2
        if m.size and ((m > 0) & (m < 1)).all():  # every state has a curve
            return np.abs(x2) / np.expm1(_u_of_m_positive(m))
        w = root_k(np.where((m > 0) & (m < 1), m, 0.5))
        wc = np.abs(x2) / w
    wc = np.where((m > 0) & (m < 1), wc, np.where(m >= 1, 0.0, np.inf))
    wc = np.where((x2 == 0) & (x1 != 0), 0.0, wc)
    return np.where((x1 == 0) & (x2 == 0), np.nan, wc)


def bisect(f, lo: ArrayLike, hi: ArrayLike, tol: float = 0.0, max_iter: int = 2000) -> Array:
    """Vectorized bisection for a sign change of f on [lo, hi].

    Parameters
    ----------
    f : callable
        Vectorized function; f(lo) and f(hi) must differ in sign.
    lo, hi : array_like
        Brackets.
    tol : float
        Stop when hi - lo <= tol (0: until the bracket stops shrinking).
    max_iter : int
        Iteration cap.

    Returns
    -------
    ndarray
        Midpoint of the final bracket.
    """
    lo, hi = np.broadcast_arrays(
        np.asarray(lo, dtype=float).copy(), np.asarray(hi, dtype=float).copy()
    )
    lo, hi = lo.copy(), hi.copy()
    f_lo = np.sign(f(lo))
    for _ in range(max_iter):
        mid = 0.5 * (lo + hi)
        active = (hi - lo > tol) & (mid > lo) & (mid < hi)
        if not np.any(active):
            break
        f_mid = np.sign(f(mid))
        left = (f_mid == f_lo) & active
        lo = np.where(left, mid, lo)
        hi = np.where(active & ~left, mid, hi)
    return 0.5 * (lo + hi)


def root_22_bisect(b0: ArrayLike, tol: float = 0.0) -> Array:
    """Positive root of eq. (22) by bisection (the paper's method; reference).

    Parameters
    ----------
    b0 : array_like
        b0 > 0.
    tol : float
        Bracket width at which to stop; 0 bisects to the last bit.

    Returns
    -------
    ndarray
        y* > 0.
    """
    b0 = np.asarray(b0, dtype=float)
    return bisect(lambda y: h(y) - b0, np.zeros_like(b0), 2.0 * b0 + 2.0, tol)


def root_k_bisect(m: ArrayLike, tol: float = 0.0) -> Array:
    """Non-trivial root of eqs. (26)/(31) by bisection (reference for :func:`root_k`).

    Parameters
    ----------
    m : array_like
        m = 1 - k, with m < 1 and m != 0.
    tol : float
        Bracket width at which to stop; 0 bisects to the last bit.

    Returns
    -------
    ndarray
        z* (> 0 for 0 < m < 1, in (-1, 0) for m < 0).
    """
    m = np.asarray(m, dtype=float)
    k = 1.0 - m
    pos = m > 0
    lo = np.where(pos, m, -1.0)  # phi(m) = m^2 - h(m) > 0 for 0 < m < 1
    hi = np.where(pos, 1.0 / np.where(pos, k, 1.0) ** 2 + 1.0, 0.0)

    # phi(z) = ln(1+z) - k z = m z - h(z): > 0 between 0 and z* for m > 0; the first form
    # is exact for small k, the second for small m
    def phi(z):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(m >= 0.5, np.log1p(z) - k * z, m * z - h(z))

    return bisect(phi, lo, hi, tol)
