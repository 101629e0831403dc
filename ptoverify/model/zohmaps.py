"""Enclosures of the exact j-step ZOH maps, for a point a or an interval of a.

The plant x1' = x2, x2' = -a x2 + a u under an input held at u for j samples
maps (x1, x2) to

    x1_j = x1 + t_j u + p_j (x2 - u),    x2_j = u + e_j (x2 - u),

with t_j = j T, e_j = exp(-a j T) and p_j = (1 - e_j) / a = int_0^{jT} exp(-a s) ds
(eq. 7).  The coefficients are computed in python-flint ``arb`` and converted
to floats outward (:func:`ptoverify.model.intervals.arb_interval`).

Over an interval of a (the plant's a any constant in it) the enclosures stay
tight, without the wrapping of a ball evaluated through many operations:

* e_j and p_j are decreasing in a (p_j is the integral of exp(-a s) over
  [0, jT]), so their range over [a_lo, a_hi] is the hull of their values at
  the two ends, each evaluated in arb at a point;
* x1_j is increasing in x1, x2 and u (p_j > 0 and t_j - p_j >= 0) and x2_j in
  x2 and u (0 < e_j <= 1), so the image box's lower corner is the image of the
  box's lower corner (and u's lower end) and likewise the upper: written as
  above, each corner's image depends on a only through one factor, p_j or e_j,
  times a number of known sign, so the coefficient's interval gives the exact
  range of the corner's image over a (outward rounded);
* the closed-loop powers Acl(a)^j of a linear law are enclosed by the mean
  value form on sub-intervals: Acl(a)^j is in Acl(c)^j + D_j(S) (a - c) for a
  in a sub-interval S centred at c, D_j = d(Acl^j)/da enclosed over S by the
  product rule D_{j+1} = D_j Acl + Acl^j dAcl/da (ball arithmetic); the
  wrapping of the ball evaluation then enters only multiplied by the
  sub-interval's radius.

Catalogue: :func:`a_ball`, :class:`StepMaps`, :func:`step_maps`,
:func:`affine_image`, :func:`linear_image`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from flint import arb, arb_mat, ctx

from ptoverify.model.intervals import ARB_PREC, add, arb_interval, mul, sub

__all__ = ["a_ball", "StepMaps", "step_maps", "affine_image", "linear_image", "LIN_PIECES"]

#: Sub-intervals of a ball of a for the mean-value enclosure of the closed-loop powers.
LIN_PIECES = 16


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
    """Enclosures of the exact j-step ZOH maps, j = 0..K, under a constant input.

    x1_j = x1 + t_j u + p_j (x2 - u), x2_j = u + e_j (x2 - u), with t_j = j T,
    e_j = exp(-a j T), p_j = (1 - e_j) / a; s1_j = t_j - p_j and s2_j = 1 - e_j
    are the same map's coefficients of u in x1 + p_j x2 + s1_j u and
    e_j x2 + s2_j u.  Each entry is an interval (lo, hi) of arrays of shape
    (K + 1,) (index j; index 0 is the identity), valid for every constant a in
    the ball the maps were built for.

    Attributes
    ----------
    p, e, s1, s2, t : tuple of ndarray
        Coefficient intervals [s], [-], [s], [-], [s].
    lin : tuple of ndarray or None
        Closed-loop powers: (lo, hi), each of shape (K + 1, 2, 2) [s^0, s, 1/s].
    """

    p: tuple
    e: tuple
    s1: tuple
    s2: tuple
    t: tuple
    lin: tuple | None


def _closed_loop(x: arb, T: arb, k: arb_mat):  # noqa: N803
    """Acl(x) = A - B K and its derivative in a, as arb matrices valid over the ball x."""
    e = (-x * T).exp()
    q = -(-x * T).expm1() / x  # (1 - e) / x
    dq = (T * e - q) / x
    a_m = arb_mat([[1, q], [0, e]])
    b_m = arb_mat([[T - q], [1 - e]])
    da = arb_mat([[0, dq], [0, -T * e]])
    db = arb_mat([[-dq], [T * e]])
    return a_m - b_m * k, da - db * k


def _ends(a) -> tuple[arb, arb]:
    """Return the ends of a's interval as exact arb points (a float pair, or a ball's bounds)."""
    if isinstance(a, tuple):
        return arb(a[0]), arb(a[1])
    return (a, a) if a.rad() == 0 else (a.lower(), a.upper())


def _floats(m: arb_mat):
    """Outward float bounds (lo, hi) of a 2x2 arb matrix, each of shape (2, 2)."""
    iv = [[arb_interval(m[r, c]) for c in range(2)] for r in range(2)]
    return np.array([[v[0] for v in row] for row in iv]), np.array(
        [[v[1] for v in row] for row in iv]
    )


def _lin_powers(lo: arb, hi: arb, T: float, K: int, gains):  # noqa: N803
    """Float bounds (lo, hi), shape (K + 1, 2, 2), of Acl(a)^j for every a in [lo, hi]."""
    t = arb(T)
    k = arb_mat([[arb(gains[0]), arb(gains[1])]])
    eye = arb_mat([[1, 0], [0, 1]])
    low = np.full((K + 1, 2, 2), np.inf)
    high = np.full((K + 1, 2, 2), -np.inf)
    if not hi > lo:
        acl = _closed_loop(lo, t, k)[0]
        power = eye
        for j in range(K + 1):
            low[j], high[j] = _floats(power)
            power = power * acl
        return low, high
    # the hull of the pieces' enclosures, taken in floats (a union of arb balls would
    # round its radius up to 30 bits)
    for i in range(LIN_PIECES):
        piece = (lo + (hi - lo) * i / LIN_PIECES).union(lo + (hi - lo) * (i + 1) / LIN_PIECES)
        c = arb(piece.mid())  # exact point
        delta = piece - c  # contains a - c for every a in the piece
        acl_c = _closed_loop(c, t, k)[0]
        acl_s, dacl_s = _closed_loop(piece, t, k)
        p_c, p_s, d_s = eye, eye, arb_mat(2, 2)
        for j in range(K + 1):
            m_lo, m_hi = _floats(p_c + d_s * delta)
            low[j], high[j] = np.minimum(low[j], m_lo), np.maximum(high[j], m_hi)
            p_c, d_s, p_s = p_c * acl_c, d_s * acl_s + p_s * dacl_s, p_s * acl_s
    return low, high


def step_maps(a, T: float, K: int, gains: tuple[float, float] | None = None) -> StepMaps:  # noqa: N803
    """Enclose the j-step ZOH maps for j = 0..K in arb, then as float intervals.

    Parameters
    ----------
    a : arb or tuple of float
        Bandwidth [rad/s]: an arb point, a ball (:func:`a_ball`; its bounds, a
        little wider than the interval it was made from), or (a_lo, a_hi), the
        interval itself (tightest).
    T : float
        Sampling period [s].
    K : int
        Largest number of steps.
    gains : tuple of float, optional
        Linear law gains (g1 [1/s], g2 [-]), u = -g1 x1 - g2 x2.

    Returns
    -------
    StepMaps
        The enclosures, valid for every constant a in the ball.

    Examples
    --------
    >>> m = step_maps(arb(100), 0.01, 2)
    >>> bool(m.e[0][1] <= 0.36787944117144233 <= m.e[1][1] and m.e[1][1] - m.e[0][1] < 1e-16)
    True
    """
    cols = {k: ([], []) for k in ("p", "e", "s1", "s2", "t")}
    lin = None
    with ctx.workprec(ARB_PREC):
        t = arb(T)
        # e_j, p_j are monotone in a: the hull of the two ends' values encloses the range
        # (taken in floats: a union of arb balls would round its radius up to 30 bits)
        a_lo, a_hi = _ends(a)
        ends = (a_lo, a_hi) if a_hi > a_lo else (a_lo,)
        for j in range(K + 1):
            vals = {"t": [j * t]}
            for x in ends:
                e = (-x * t * j).exp()
                p = -(-x * t * j).expm1() / x if j else arb(0)
                for name, v in (("e", e), ("p", p), ("s2", 1 - e), ("s1", j * t - p)):
                    vals.setdefault(name, []).append(v)
            for name, vs in vals.items():
                bounds = [arb_interval(v) for v in vs]
                cols[name][0].append(min(b[0] for b in bounds))
                cols[name][1].append(max(b[1] for b in bounds))
        if gains is not None:
            lin = _lin_powers(a_lo, a_hi, T, K, gains)
    arr = {k: (np.array(v[0]), np.array(v[1])) for k, v in cols.items()}
    return StepMaps(arr["p"], arr["e"], arr["s1"], arr["s2"], arr["t"], lin)


def affine_image(maps: StepMaps, j, box, u):
    """Enclose the j-step image of boxes under a constant input in an interval.

    The image is monotone in the state and the input (module docstring), so
    its lower corner is x1lo + t_j ulo + p_j (x2lo - ulo), ulo + e_j (x2lo -
    ulo) minimized over the coefficients' intervals, and the upper likewise.

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
    p = (maps.p[0][j], maps.p[1][j])
    e = (maps.e[0][j], maps.e[1][j])
    t = (maps.t[0][j], maps.t[1][j])
    out = []
    for x1, x2, uu, end in ((box[0], box[2], u[0], 0), (box[1], box[3], u[1], 1)):
        ui = (uu, uu)
        dx = sub((x2, x2), ui)
        y1 = add(add((x1, x1), mul(t, ui)), mul(p, dx))
        y2 = add(ui, mul(e, dx))
        out.append((y1[end], y2[end]))
    return out[0][0], out[1][0], out[0][1], out[1][1]


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
