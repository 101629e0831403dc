"""Rigorous enclosures of the laws (PD, PTO eq. 35, TO eq. 12, cascade P) over boxes of states.

A box is ``(x1lo, x1hi, x2lo, x2hi)``, arrays [mm], [mm/s].  The enclosure
holds for the mathematical law (real arithmetic), computed with the
outward-rounded operations of :mod:`ptoverify.model.intervals`.

How: the PTO law (TO is the PTO without linear zone and switching zone) is,
outside its linear zone |x1| < d, nonincreasing in x1 and in x2 (bang-bang
+w_max left of l1 - o - l2, the zone inputs +omega_c, decreasing from w_max to
omega0 across S~_P, -omega_c across S~_N, then -w_max); so over a box piece
outside the linear zone u lies between its values at the upper-right and the
lower-left corners.  Each corner's value is enclosed by classifying the corner
with certified signs of the switching functions (eqs. 9, 11, 13, 14); an
uncertain sign keeps every possible branch, and omega_c (eqs. 28-32) is
enclosed by bisection certified by the sign of its residual.  Inside the
linear zone, u = sat(-k1 x1 - k2 x2) is monotone too.  A box that straddles
|x1| = d gets the hull of its pieces.  The cascade P loop u = sat(-kp x1) is
PD's case with kd = 0 (the same linear-law enclosure); PTOS is not enclosed
(:func:`require_enclosure`).

Catalogue: :class:`LawSpec`, :func:`law_spec`, :func:`sigma_point`,
:func:`omega_c_iv`, :func:`enclose`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.intervals import add, div, down, h_iv, mul, sub, up
from ptoverify.model.laws import make_law

__all__ = [
    "LawSpec",
    "law_spec",
    "sigma_point",
    "omega_c_iv",
    "enclose",
    "LawBox",
    "ENCLOSED_LAWS",
    "require_enclosure",
]

#: The laws with a certified enclosure here (``prove --law`` accepts exactly these).  The
#: cascade P loop u = sat(-kp x1) is PD's enclosure with kd = 0; PTOS has none (its
#: square-root branch and its per-state clip of the velocity term are not enclosed).
ENCLOSED_LAWS = ("pto", "pto-printed", "pd", "to", "cascade-p")

_BISECTIONS = 40  #: bisection steps of the omega_c enclosure (width (w - omega0) / 2^40)


@dataclass(frozen=True)
class LawSpec:
    """Parameters of a law as the enclosures need them.

    Attributes
    ----------
    name : str
        Law name (``pd``, ``pto``, ``pto-printed``, ``to``, ``cascade-p``).
    a : float
        Bandwidth the law is designed with [rad/s].
    w_max : float
        Saturation [mm/s].
    d : float
        Linear-zone half-width [mm]; inf: linear everywhere (PD); 0: none (TO).
    g1 : float
        Position gain of the linear law [1/s] (kp or k1).
    g2 : float
        Velocity gain of the linear law [-] (kd or k2).
    omega0 : float
        Switching-zone level [mm/s]; NaN: no zone.
    """

    name: str
    a: float
    w_max: float
    d: float
    g1: float
    g2: float
    omega0: float

    @property
    def has_zone(self) -> bool:
        """Whether the law has a switching zone (0 < omega0 < w_max)."""
        return not math.isnan(self.omega0)


def law_spec(name: str, cfg: Config) -> LawSpec:
    """Return the :class:`LawSpec` of the law ``name`` as ``make_law`` builds it.

    Parameters
    ----------
    name : str
        ``pd``, ``pto``, ``pto-printed``, ``to`` or ``cascade-p``
        (:data:`ENCLOSED_LAWS`; another name is InputError).
    cfg : Config
        Configuration.

    Returns
    -------
    LawSpec
        Parameters of the law (the PTO's zone level from the law itself; the
        cascade P loop as PD with kd = 0).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law_spec("to", paper_config()).d
    0.0
    """
    require_enclosure(name)
    p = cfg.plant
    if name == "pd":
        return LawSpec(name, p.a, p.w_max, math.inf, cfg.pd.kp, cfg.pd.kd, math.nan)
    if name == "cascade-p":  # PD with kd = 0 (model.baselines.cascade_law is that law)
        from ptoverify.model.baselines import cascade_gain

        return LawSpec(name, p.a, p.w_max, math.inf, cascade_gain(cfg), 0.0, math.nan)
    law = make_law(name, cfg)
    g1, g2, d, level = law.family.params  # the PTO block's (k1, k2, d, zone level)
    return LawSpec(name, p.a, p.w_max, d, g1, g2, level)


def require_enclosure(name: str) -> None:
    """Raise InputError unless the law ``name`` has a certified enclosure (:data:`ENCLOSED_LAWS`).

    Parameters
    ----------
    name : str
        Law name.

    Raises
    ------
    InputError
        One line naming the law and the laws that have one.

    Examples
    --------
    >>> require_enclosure("cascade-p")
    """
    if name not in ENCLOSED_LAWS:
        raise InputError(
            f"law '{name}' has no certified enclosure, so it cannot be proved "
            f"(prove covers {', '.join(ENCLOSED_LAWS)})"
        )


def _iv(x):
    """Return a point array as a degenerate interval."""
    return (x, x)


def sigma_point(spec: LawSpec, x1, x2, level: float):
    """Enclose the switching function a x1 + sgn(x2) level h(|x2| / level) at points.

    Eqs. (9), (11) (level w_max) and (13), (14) (level omega0).

    Parameters
    ----------
    spec : LawSpec
        The law (its a [rad/s]).
    x1, x2 : ndarray
        Points [mm], [mm/s].
    level : float
        Input level of the curve [mm/s] > 0.

    Returns
    -------
    tuple of ndarray
        (lo, hi) [mm/s]: > 0 right of the curve.  Tight (a few ulps) where the
        value is within 1 mm/s of 0; elsewhere a looser enclosure (from
        0 <= h(r) <= r) that still excludes [-1, 1] mm/s.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> lo, hi = sigma_point(law_spec("to", paper_config()), np.array([1.0]),
    ...                      np.array([0.0]), 300.0)
    >>> bool(lo[0] <= 188.49555921538757 <= hi[0])
    True
    """
    x1, x2 = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
    ax = mul((spec.a, spec.a), _iv(x1))
    # 0 <= level h(|x2| / level) <= |x2|: a loose enclosure first; h is evaluated only
    # where that one meets [-1, 1] mm/s (the callers compare with 0 or a tie band)
    pos = x2 >= 0
    v = np.abs(x2)
    lo = np.where(pos, ax[0], down(ax[0] - v))
    hi = np.where(pos, up(ax[1] + v), ax[1])
    near = (lo <= 1.0) & (hi >= -1.0)
    if near.any():
        idx = np.flatnonzero(near)
        r = div(_iv(v[idx]), (level, level))
        hh = mul((level, level), h_iv(r))
        axi = (ax[0][idx], ax[1][idx])
        plus, minus = add(axi, hh), sub(axi, hh)
        pi = pos[idx]
        lo[idx] = np.where(pi, plus[0], minus[0])
        hi[idx] = np.where(pi, plus[1], minus[1])
    return lo, hi


def omega_c_iv(spec: LawSpec, x1, x2):
    """Enclose clip(omega_c(x1, x2), omega0, w_max), eqs. (28)-(32), at points.

    omega_c is the level of the curve through the state: the root of
    G(omega) = a |x1| - omega h(|x2| / omega), increasing in omega.  A root
    proposed in plain floats is accepted where G is certified negative just
    below it and positive just above it (or the bracket meets omega0 or w_max,
    where the clip acts); elsewhere bisection on [omega0, w_max] moves an end
    only where the sign of G at the midpoint is certified.  Either way the
    clipped root stays enclosed.

    Parameters
    ----------
    spec : LawSpec
        The law (a [rad/s], omega0, w_max [mm/s]).
    x1, x2 : ndarray
        Points [mm], [mm/s].

    Returns
    -------
    tuple of ndarray
        (lo, hi) [mm/s] within [omega0, w_max].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> s = law_spec("pto", paper_config())
    >>> lo, hi = omega_c_iv(s, np.array([0.6]), np.array([-250.0]))
    >>> bool(s.omega0 <= lo[0] <= hi[0] <= 300.0)
    True
    """
    x1 = np.abs(np.asarray(x1, dtype=float))
    v = np.abs(np.asarray(x2, dtype=float))
    ax = mul((spec.a, spec.a), _iv(x1))

    def residual(om):  # enclosure of G(om) at float points om > 0
        return sub(ax, mul(_iv(om), h_iv(div(_iv(v), _iv(om)))))

    # a proposed root (plain floats; not trusted), then certified by the residual's
    # signs just below and above it; where that fails, certified bisection
    lo = np.full(x1.shape, spec.omega0)
    hi = np.full(x1.shape, spec.w_max)
    with np.errstate(all="ignore"):
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            g = spec.a * x1 - (v - mid * np.log1p(v / mid))
            lo, hi = np.where(g < 0, mid, lo), np.where(g < 0, hi, mid)
    guess = 0.5 * (lo + hi)
    c_lo = np.maximum(guess * (1 - 1e-10), spec.omega0)
    c_hi = np.minimum(guess * (1 + 1e-10), spec.w_max)
    ok_lo = (c_lo == spec.omega0) | (residual(c_lo)[1] < 0)
    ok_hi = (c_hi == spec.w_max) | (residual(c_hi)[0] > 0)
    lo = np.where(ok_lo & ok_hi, c_lo, spec.omega0)
    hi = np.where(ok_lo & ok_hi, c_hi, spec.w_max)
    bad = ~(ok_lo & ok_hi)
    if bad.any():
        sub_spec = np.flatnonzero(bad)
        ax = (ax[0][sub_spec], ax[1][sub_spec])
        v = v[sub_spec]
        b_lo, b_hi = lo[sub_spec], hi[sub_spec]
        for _ in range(_BISECTIONS):
            mid = 0.5 * (b_lo + b_hi)
            g = residual(mid)
            b_lo = np.where(g[1] < 0, mid, b_lo)
            b_hi = np.where(g[0] > 0, mid, b_hi)
        lo[sub_spec], hi[sub_spec] = b_lo, b_hi
    return lo, hi


def _outside_point(spec: LawSpec, x1, x2):
    """Enclose the law outside its linear zone at points: (lo, hi) [mm/s]."""
    w = spec.w_max
    s_lo, s_hi = sigma_point(spec, x1, x2, w)
    inf = np.full(x1.shape, np.inf)
    lo, hi = inf.copy(), -inf
    bang_p = s_lo <= 0
    bang_n = s_hi >= 0
    if spec.has_zone:  # a state certainly in a zone takes no bang-bang input
        o_lo, o_hi = sigma_point(spec, x1, x2, spec.omega0)
        bang_n &= ~((x2 < 0) & (s_lo > 0) & (o_hi <= 0))
        bang_p &= ~((x2 > 0) & (s_hi < 0) & (o_lo >= 0))
    lo = np.where(bang_n, -w, np.where(bang_p, w, lo))
    hi = np.where(bang_p, w, np.where(bang_n, -w, hi))
    origin = (x1 == 0) & (x2 == 0)
    lo = np.where(origin, np.minimum(lo, 0.0), lo)
    hi = np.where(origin, np.maximum(hi, 0.0), hi)
    if spec.has_zone:
        zp = (x2 < 0) & (s_hi > 0) & (o_lo <= 0)
        zn = (x2 > 0) & (s_lo < 0) & (o_hi >= 0)
        z = zp | zn
        if z.any():
            c_lo, c_hi = np.full(x1.shape, spec.omega0), np.full(x1.shape, w)
            c_lo[z], c_hi[z] = omega_c_iv(spec, x1[z], x2[z])
            lo = np.where(zp, np.minimum(lo, c_lo), lo)
            hi = np.where(zp, np.maximum(hi, c_hi), hi)
            lo = np.where(zn, np.minimum(lo, -c_hi), lo)
            hi = np.where(zn, np.maximum(hi, -c_lo), hi)
    return lo, hi


@dataclass(frozen=True)
class LawBox:
    """Enclosure of a law over boxes.

    Attributes
    ----------
    lo, hi : ndarray
        Bounds of the input over each box [mm/s].
    linear : ndarray of bool
        The box lies in the linear zone and the linear input is unsaturated
        there: u = -g1 x1 - g2 x2 exactly on the whole box.
    outside : ndarray of bool
        Some point of the box lies outside the linear zone (|x1| >= d).
    """

    lo: np.ndarray
    hi: np.ndarray
    linear: np.ndarray
    outside: np.ndarray


def enclose(spec: LawSpec, box) -> LawBox:
    """Enclose the law over boxes (x1lo, x1hi, x2lo, x2hi).

    Parameters
    ----------
    spec : LawSpec
        The law.
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s], lo <= hi.

    Returns
    -------
    LawBox
        Bounds of u [mm/s] over each box, and where the box is wholly linear.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> e = enclose(law_spec("pd", paper_config()),
    ...             tuple(np.array([v]) for v in (0.1, 0.2, 0.0, 1.0)))
    >>> bool(e.lo[0] <= -356 * 0.2 - 1.15 and e.hi[0] >= -35.6 and e.linear[0])
    True
    """
    x1lo, x1hi, x2lo, x2hi = (np.asarray(v, dtype=float) for v in box)
    w, d = spec.w_max, spec.d
    lo = np.full(x1lo.shape, np.inf)
    hi = np.full(x1lo.shape, -np.inf)
    # the linear piece: |x1| < d (closure used: a superset)
    has_lin = (x1lo < d) & (x1hi > -d)
    a1, b1 = np.maximum(x1lo, -d), np.minimum(x1hi, d)
    g1, g2 = (-spec.g1, -spec.g1), (-spec.g2, -spec.g2)
    v = add(mul(g1, (a1, b1)), mul(g2, (x2lo, x2hi)))
    v_lo, v_hi = np.clip(v[0], -w, w), np.clip(v[1], -w, w)
    lo = np.where(has_lin, np.minimum(lo, v_lo), lo)
    hi = np.where(has_lin, np.maximum(hi, v_hi), hi)
    unsat = (v[0] >= -w) & (v[1] <= w)
    outside = np.zeros(x1lo.shape, dtype=bool)
    if math.isfinite(d):
        for side in (1.0, -1.0):
            if side > 0:
                has = x1hi >= d
                left, right = np.maximum(x1lo, d), x1hi
            else:
                has = x1lo <= -d
                left, right = x1lo, np.minimum(x1hi, -d)
            if not has.any():
                continue
            outside |= has
            idx = has.nonzero()[0]
            u_min = _outside_point(spec, right[idx], x2hi[idx])[0]
            u_max = _outside_point(spec, left[idx], x2lo[idx])[1]
            lo[idx] = np.minimum(lo[idx], u_min)
            hi[idx] = np.maximum(hi[idx], u_max)
    linear = has_lin & unsat & ~outside
    return LawBox(lo, hi, linear, outside)


def outside_extent(spec: LawSpec, box):
    """Return the parts of boxes outside the linear zone: right and left pieces.

    Parameters
    ----------
    spec : LawSpec
        The law (its d [mm]).
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    list of tuple
        ``(mask, piece)`` for x1 >= d and for x1 <= -d; piece is a box.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> parts = outside_extent(law_spec("pto", paper_config()),
    ...                        tuple(np.array([v]) for v in (0.0, 1.0, 0.0, 1.0)))
    >>> [bool(m[0]) for m, _ in parts]
    [True, False]
    """
    x1lo, x1hi, x2lo, x2hi = box
    d = spec.d
    right = (x1hi >= d, (np.maximum(x1lo, d), x1hi, x2lo, x2hi))
    left = (x1lo <= -d, (x1lo, np.minimum(x1hi, -d), x2lo, x2hi))
    return [right, left]
