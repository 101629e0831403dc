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

import numpy as np
from numpy.typing import ArrayLike, NDArray

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
]

Array = NDArray[np.float64]

# Taylor coefficients of h(r) = r - ln(1 + r) = sum_{n>=2} (-1)^n r^n / n
_H_SERIES = np.array([(-1.0) ** n / n for n in range(2, 26)])
# of E2(u) = e^u - 1 - u = sum_{n>=2} u^n / n!
_E2_SERIES = np.array([1.0 / np.prod(np.arange(1, n + 1, dtype=float)) for n in range(2, 22)])


def _series(x: Array, coef: Array) -> Array:
    """Return sum_j coef[j] x^(2 + j) by Horner's rule (x finite)."""
    acc = np.full_like(x, coef[-1])
    for c in coef[-2::-1]:
        acc *= x
        acc += c
    return acc * (x * x)


def _direct_or_series(x: ArrayLike, direct, radius: float, coef: Array) -> Array:
    """Return ``direct(x)``, and the series ``coef`` where |x| < ``radius``; x's shape."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        out = direct(np.atleast_1d(x)).reshape(x.shape)  # a fresh array
    near = np.abs(x) < radius
    if np.count_nonzero(near):  # (no series values: nothing to overwrite)
        out[near] = _series(x[near], coef)
    return out


def h(r: ArrayLike) -> Array:
    """Return h(r) = r - ln(1 + r), exact to round-off near r = 0.

    r - log1p(r), and the Taylor series (24 terms, Horner's rule) where
    |r| < 0.2, where the difference would cancel; one vectorized evaluation
    for any shape.

    Parameters
    ----------
    r : array_like
        Argument [-], r > -1.

    Returns
    -------
    ndarray
        h(r) >= 0 [-], of the shape of ``r``; +inf at r = +inf, so a level
        curve's residual at x2 = +-inf is +-inf (the side is that of x2).

    Examples
    --------
    >>> float(h(1e-10))      # r^2/2 - r^3/3: exact where r - log1p(r) would give 0
    4.999999999666667e-21
    """
    return _direct_or_series(r, _h_direct, 0.2, _H_SERIES)


def _h_direct(r: Array) -> Array:
    """Return r - log1p(r), and its limit +inf at r = +inf (where it reads inf - inf)."""
    out = r - np.log1p(r)
    top = r == np.inf
    if np.count_nonzero(top):
        out[top] = np.inf
    return out


def _e2(u: ArrayLike) -> Array:
    """Return e^u - 1 - u, exact to round-off near u = 0 (the series where |u| < 0.5)."""
    return _direct_or_series(u, lambda x: np.expm1(x) - x, 0.5, _E2_SERIES)


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
    return a * np.asarray(x1, dtype=float) + level_term(x2, omega)


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


def level_side(ax1: ArrayLike, x2: ArrayLike, omega: ArrayLike, band: float = 0.0) -> Array:
    """Return ``ax1 + level_term(x2, omega)``: the residual from a x1 formed by the caller.

    It is the residual itself, for every state and any number of states (no
    shortcut where a x1 alone decides the side), so it compares with 0 and
    +-``band`` as :func:`level_residual` does, NaN included (at x2 = +-inf the
    term is inf - inf).

    Parameters
    ----------
    ax1 : array_like
        a x1 [mm/s] (a [rad/s], x1 [mm]), as the caller forms it.
    x2 : array_like
        Velocity [mm/s].
    omega : float or array_like
        Input level of the curve [mm/s], omega > 0.
    band : float
        Band the caller compares the values with [mm/s], >= 0; the values do
        not depend on it (kept for callers that name it).

    Returns
    -------
    ndarray
        ax1 + sgn(x2) omega h(|x2| / omega) [mm/s].

    Examples
    --------
    >>> ax1, x2 = np.array([188.5, 1e-3, 0.0]), np.array([-50.0, -50.0, 0.0])
    >>> bool((level_side(ax1, x2, 300.0) == ax1 + level_term(x2, 300.0)).all())
    True
    """
    return np.asarray(ax1, dtype=float) + level_term(x2, omega)


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
    # imported here: scipy.special costs a process 0.2-0.4 s of import (and ~0.1 s at
    # its exit), which one that never reaches a root (the CLI's argument errors) skips
    from scipy.special import lambertw

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
        y*, of the shape of ``b0``; NaN where b0 < 0 or not finite.

    Examples
    --------
    >>> y = float(root_22(1.0))
    >>> bool(abs(y - np.log1p(y) - 1.0) < 1e-15)
    True
    """
    if branch not in (-1, 0):
        raise ValueError("branch must be -1 or 0")
    b0 = np.asarray(b0, dtype=float)
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
            # for large b0, e^u amplifies the rounding of u by u: finish with the
            # contraction y = b0 + ln(1 + y) (factor 1/(1 + y) < 0.05 per step)
            yl = np.where(bb > 20.0, y, 21.0)
            for _ in range(12):
                yl = bb + np.log1p(yl)
            y = np.where(bb > 20.0, yl, y)
    return np.where(ok, np.where(bb == 0.0, 0.0, y), np.nan)


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
    u = np.zeros(mm.shape)
    pos, neg = mm > 0, mm < 0
    with np.errstate(all="ignore"):  # each branch on the states it serves, if any
        if np.count_nonzero(pos):
            u[pos] = _u_of_m_positive(mm[pos])
        if np.count_nonzero(neg):
            u[neg] = _u_of_m_negative(mm[neg])
    z = np.expm1(u)
    z = np.where(mm == 0.0, 0.0, z)
    return np.where(ok, z, np.nan)


def _u_of_m_positive(m: Array) -> Array:
    """U = ln(1 + z*) = -k - W_{-1}(-k e^{-k}) for 0 < m < 1, k = 1 - m.

    W_{-1} is evaluated by its own iteration on the equivalent equation
    F(u) = u - k (e^u - 1) = 0 (u = -k - W): a start from the branch-point series
    (u = 2m + 2m^2/3 + 4m^3/9, m < 1/4) or from upper bounds (u <= 2m/k, refined by
    u <- ln(1 + u/k), which keeps a bound), two Halley steps (not where m <= 1e-4:
    the series start is exact to ~m^3 there), then one Newton step with the residual
    in the form that is exact for the input: m (e^u - 1) - (e^u - 1 - u) for m < 1/2
    (no cancellation for tiny roots), u - k (e^u - 1) otherwise (k small).
    Measured against bisection to the last bit: within a few ulps over (0, 1).
    """
    k = 1.0 - m
    with np.errstate(all="ignore"):
        series = m * (2.0 + m * (2.0 / 3.0 + m * 4.0 / 9.0))
        bound = 2.0 * m / k
        for _ in range(3):
            bound = np.log1p(bound / k)
        u = np.where(m >= 0.25, bound, series)
        for _ in range(2):  # Halley: u -= 2 f f' / (2 f'^2 - f f'')
            em1 = np.expm1(u)
            f = u - k * em1
            df = m - k * em1
            d2f = -(k * (em1 + 1.0))
            u = np.where(m <= 1e-4, u, u - 2.0 * f * df / (2.0 * df * df - d2f * f))
        em1 = np.expm1(u)  # Newton: u - f / (m - k em1)
        f = np.where(m < 0.5, m * em1 - _e2(u), u - k * em1)
        return u - f / (m - k * em1)


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
    x1, x2 = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
    with np.errstate(all="ignore"):
        m = -a * x1 / x2
        curve = (m > 0) & (m < 1)
        wc = np.abs(x2) / root_k(np.where(curve, m, 0.5))
    wc = np.where(curve, wc, np.where(m >= 1, 0.0, np.inf))
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
