"""mpmath's Lambert W, with its branch-point series coefficients computed once.

Records 22W, 26W and 31W evaluate W_0 and W_{-1} at hundreds of points near the
branch point -1/e.  There mpmath's ``lambertw`` starts from the series of Corless
et al. in p = sqrt(2 (e z + 1)), whose coefficients u_l it recomputes at every
call by a recurrence costing O(l^2) operations (most of its time here).  The
coefficients depend only on the working precision, so :func:`lambertw` keeps them
per precision and otherwise runs mpmath's own algorithm (mpmath 1.3,
``mpmath/functions/functions.py``: ``lambertw`` and ``_lambertw_series``),
operation for operation: its values are mpmath's, bit for bit (the tests compare
them on both branches).  Away from the branch point it calls ``mpmath.lambertw``.
"""

from __future__ import annotations

from typing import Any

import mpmath

__all__ = ["lambertw"]

#: Working precision [bits] -> (u, a): the series coefficients and their helper sums.
_COEFFICIENTS: dict[int, tuple[dict[int, Any], dict[int, Any]]] = {}


def _near_branch_point(ctx: Any, z: Any, k: int) -> bool:
    """Whether mpmath's lambertw would start from the branch-point series."""
    magz = ctx.mag(z)
    if not (-10 < magz < 900 and -1000 < k < 1000):
        return False
    if not (magz < 1 and abs(z + 0.36787944117144) < 0.05):
        return False
    return k == 0 or (k == -1 and ctx._im(z) >= 0) or (k == 1 and ctx._im(z) < 0)


def _series(ctx: Any, z: Any, k: int, tol: int) -> tuple[Any, bool]:
    """Run the branch-point part of mpmath's ``_lambertw_series``, coefficients kept."""
    delta = ctx.sum_accurately(lambda: [z, ctx.exp(-1)])
    cancellation = -ctx.mag(delta)
    ctx.prec += cancellation
    p = ctx.sqrt(2 * (ctx.e * z + 1))
    ctx.prec -= cancellation
    u, a = _COEFFICIENTS.setdefault(
        ctx.prec, ({0: ctx.mpf(-1), 1: ctx.mpf(1)}, {0: ctx.mpf(2), 1: ctx.mpf(-1)})
    )
    if k != 0:
        p = -p
    s = ctx.zero
    for l in range(max(2, cancellation)):  # noqa: E741 - mpmath's name
        if l not in u:
            a[l] = ctx.fsum(u[j] * u[l + 1 - j] for j in range(2, l))
            u[l] = (l - 1) * (u[l - 2] / 2 + a[l - 2] / 4) / (l + 1) - a[l] / 2 - u[l - 1] / (l + 1)
        term = u[l] * p**l
        s += term
        if ctx.mag(term) < -tol:
            return s, True
    ctx.prec += cancellation // 2
    return s, False


def lambertw(z: Any, k: int = 0) -> Any:
    """Lambert W_k(z) at mpmath's working precision, equal to ``mpmath.lambertw(z, k)``.

    Parameters
    ----------
    z : mpmath number or number
        Argument.
    k : int
        Branch.

    Returns
    -------
    mpmath.mpf or mpmath.mpc

    Examples
    --------
    >>> z = mpmath.mpf(-0.3678)
    >>> lambertw(z, -1) == mpmath.lambertw(z, -1)
    True
    """
    ctx = mpmath.mp
    z = ctx.convert(z)
    k = int(k)
    if not ctx.isnormal(z):
        return ctx.lambertw(z, k)
    prec = ctx.prec
    ctx.prec += 20 + ctx.mag(k or 1)
    try:
        if not _near_branch_point(ctx, z, k):
            ctx.prec = prec
            return ctx.lambertw(z, k)
        tol = ctx.prec - 5
        w, done = _series(ctx, z, k, tol)
        if not done:  # Halley iteration on w exp(w) = z, as mpmath's
            two = ctx.mpf(2)
            for _ in range(100):
                ew = ctx.exp(w)
                wew = w * ew
                wewz = wew - z
                wn = w - wewz / (wew + ew - (w + two) * wewz / (two * w + two))
                if ctx.mag(wn - w) <= ctx.mag(wn) - tol:
                    w = wn
                    break
                w = wn
    finally:
        ctx.prec = prec
    return +w
