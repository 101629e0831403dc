"""The certified target ellipse x' P x <= c of the sampled linear loop.

P solves the discrete Lyapunov equation Acl' P Acl - P = -I of the ZOH-sampled
loop under the law's linear input u = -g1 x1 - g2 x2 (SciPy, floats: P is then
a fixed matrix of floats, exact rationals).  Everything that makes it a target
is certified in arb at :data:`ptoverify.model.intervals.ARB_PREC` bits:

* P is positive definite;
* P - Acl' P Acl is positive definite for every a in the ball (decrease: the
  ellipse is invariant and x' P x falls at every sample inside it);
* the ellipse lies in the unsaturated linear zone: max |x1| = sqrt(c (P^-1)_11)
  < d and max |g1 x1 + g2 x2| = sqrt(c g' P^-1 g) <= w_max.

So a state in the ellipse stays there under the linear input, which is the
law's input there, whatever constant a in the ball the plant has.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from flint import arb, arb_mat, ctx

from ptoverify.model.intervals import ARB_PREC, add, mul

__all__ = ["Target", "make_target", "certify_decrease", "box_in_target", "closed_loop_arb"]

#: Sub-balls a ball of a is cut into to certify the decrease (each must certify).
DECREASE_PIECES = 64


@dataclass(frozen=True)
class Target:
    """A certified target ellipse.

    Attributes
    ----------
    P : tuple of tuple of float
        Symmetric 2x2 matrix [1/mm^2, s/mm^2; s/mm^2, s^2/mm^2].
    c : float
        Level of the ellipse x' P x <= c [-].
    certified : bool
        All three certificates hold (positive P, decrease, inside the zone).
    reason : str
        Which certificate failed, if one did.
    """

    P: tuple
    c: float
    certified: bool
    reason: str = ""


def closed_loop_arb(a: arb, T: float, g1: float, g2: float) -> arb_mat:  # noqa: N803
    """Return the sampled closed-loop matrix Ad - Bd [g1 g2] as an arb matrix.

    Parameters
    ----------
    a : arb
        Bandwidth ball [rad/s].
    T : float
        Sampling period [s].
    g1, g2 : float
        Gains of u = -g1 x1 - g2 x2 [1/s], [-].

    Returns
    -------
    arb_mat
        2x2 matrix, valid for every a in the ball.

    Examples
    --------
    >>> m = closed_loop_arb(arb(100), 0.01, 0.0, 0.0)
    >>> m[0, 0] == 1
    True
    """
    with ctx.workprec(ARB_PREC):
        t = arb(T)
        g = -(-a * t).expm1()
        A = arb_mat([[1, g / a], [0, 1 - g]])  # noqa: N806
        B = arb_mat([[t - g / a], [g]])  # noqa: N806
        return A - B * arb_mat([[arb(g1), arb(g2)]])


def _positive_definite(m: arb_mat) -> bool:
    """Certify that a symmetric 2x2 arb matrix is positive definite."""
    return bool(m[0, 0] > 0 and m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0] > 0)


def certify_decrease(P, a: arb, T: float, g1: float, g2: float) -> bool:  # noqa: N803
    """Certify P - Acl' P Acl > 0 for every a in the ball (checked on sub-balls covering it).

    Parameters
    ----------
    P : tuple of tuple of float
        The ellipse's matrix.
    a : arb
        Bandwidth ball [rad/s].
    T : float
        Sampling period [s].
    g1, g2 : float
        Linear gains [1/s], [-].

    Returns
    -------
    bool
        True when certified.

    Examples
    --------
    >>> certify_decrease(((1.0, 0.0), (0.0, 1.0)), arb(100), 0.01, 0.0, 0.0)
    False
    """
    with ctx.workprec(ARB_PREC):
        p = arb_mat([[arb(v) for v in row] for row in P])
        if a.rad() == 0:
            pieces = [a]
        else:  # sub-balls covering the ball: less wrapping of a through Acl' P Acl
            lo, hi = a.lower(), a.upper()
            n = DECREASE_PIECES
            pieces = [
                (lo + (hi - lo) * i / n).union(lo + (hi - lo) * (i + 1) / n) for i in range(n)
            ]
        for piece in pieces:
            acl = closed_loop_arb(piece, T, g1, g2)
            if not _positive_definite(p - acl.transpose() * p * acl):
                return False
        return True


def make_target(a: arb, a_nominal: float, T: float, g1: float, g2: float, d: float, w: float):  # noqa: N803
    """Build and certify the target ellipse of the linear law.

    Parameters
    ----------
    a : arb
        Bandwidth ball [rad/s] the decrease is certified for.
    a_nominal : float
        Bandwidth P is designed with [rad/s].
    T : float
        Sampling period [s].
    g1, g2 : float
        Linear gains [1/s], [-].
    d : float
        Linear-zone half-width [mm] (inf: none).
    w : float
        Saturation [mm/s].

    Returns
    -------
    Target
        The ellipse; ``certified`` says whether all certificates hold.

    Examples
    --------
    >>> t = make_target(arb(188.49555921538757), 188.49555921538757, 0.002, 323.0, 3.6,
    ...                 0.5, 300.0)
    >>> t.certified
    True
    """
    m = closed_loop_arb(arb(a_nominal), T, g1, g2)
    acl = np.array([[float(m[r, k].mid()) for k in range(2)] for r in range(2)])
    if not np.all(np.isfinite(acl)) or max(abs(np.linalg.eigvals(acl))) >= 1.0:
        return Target(((1.0, 0.0), (0.0, 1.0)), 0.0, False, "the sampled linear loop is unstable")
    # weights that make the zone order one: x1 / s1, x2 / s2
    s1 = d if math.isfinite(d) else w / g1
    s2 = w / max(g2, w * T)
    q = np.diag([1.0 / s1**2, 1.0 / s2**2])
    P = scipy.linalg.solve_discrete_lyapunov(acl.T, q)  # noqa: N806
    P = 0.5 * (P + P.T)  # noqa: N806
    P = ((float(P[0, 0]), float(P[0, 1])), (float(P[0, 1]), float(P[1, 1])))  # noqa: N806
    with ctx.workprec(ARB_PREC):
        p = arb_mat([[arb(v) for v in row] for row in P])
        det = p[0, 0] * p[1, 1] - p[0, 1] * p[1, 0]
        if not _positive_definite(p):
            return Target(P, 0.0, False, "P is not certified positive definite")
        inv11, inv12, inv22 = p[1, 1] / det, -p[0, 1] / det, p[0, 0] / det
        gg = arb(g1) ** 2 * inv11 + 2 * arb(g1) * arb(g2) * inv12 + arb(g2) ** 2 * inv22
        bounds = [arb(w) ** 2 / gg]
        if math.isfinite(d):
            bounds.append(arb(d) ** 2 / inv11)
        c = 0.98 * min(float(b.mid()) for b in bounds)
        inside = arb(c) * gg <= arb(w) ** 2
        if math.isfinite(d):
            inside = inside and arb(c) * inv11 < arb(d) ** 2
    if not inside:
        return Target(P, c, False, "the ellipse is not certified inside the linear zone")
    if not certify_decrease(P, a, T, g1, g2):
        return Target(P, c, False, "the decrease of x'Px is not certified")
    return Target(P, c, True)


def box_in_target(target: Target, box) -> np.ndarray:
    """Certify that boxes lie in the ellipse (all four corners do; it is convex).

    Parameters
    ----------
    target : Target
        The ellipse.
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    ndarray of bool
        True where the whole box is certified inside.

    Examples
    --------
    >>> t = Target(((1.0, 0.0), (0.0, 1.0)), 1.0, True)
    >>> box_in_target(t, tuple(np.array([v]) for v in (0.0, 0.5, 0.0, 0.5))).tolist()
    [True]
    """
    if not target.certified:
        return np.zeros(np.shape(box[0]), dtype=bool)
    (p11, p12), (_, p22) = target.P
    ok = np.ones(np.shape(box[0]), dtype=bool)
    for x1 in (box[0], box[1]):
        for x2 in (box[2], box[3]):
            q = add(
                add(
                    mul((p11, p11), mul((x1, x1), (x1, x1))),
                    mul((2 * p12, 2 * p12), mul((x1, x1), (x2, x2))),
                ),
                mul((p22, p22), mul((x2, x2), (x2, x2))),
            )
            ok &= q[1] <= target.c
    return ok
