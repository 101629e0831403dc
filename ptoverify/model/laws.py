"""Control laws: time-optimal (eq. 12), PD, and the region bookkeeping.

A law is a :class:`Law`: calling it with arrays of states returns the input
and the region code of each state; ``law.scalar(x1, x2)`` is the cheap path
for one state given as Python floats.  Every law returns |u| <= w_max.

Region codes (:class:`Region`) name the branch of the law that acted, so a
simulation can say which region every sample used.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from enum import IntEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import ALL_LAW_NAMES, BASELINE_NAMES, LAW_NAMES, Config
from ptoverify.errors import InputError
from ptoverify.model.curves import blockwise, level_side, omega_c

__all__ = [
    "Region",
    "Law",
    "LawFamily",
    "to_law",
    "pd_law",
    "pto_law",
    "pto_corrected_law",
    "pto_printed_law",
    "omega_c_scalar",
    "make_law",
    "register_law",
    "with_state_gains",
    "LAW_NAMES",
    "h_scalar",
]


class Region(IntEnum):
    """Branch of a law that produced the input."""

    ORIGIN = 0  #: the origin, u = 0
    BANG_P = 1  #: S_P or l1, u = +w_max (eq. 12)
    BANG_N = 2  #: S_N or l2, u = -w_max
    ZONE_P = 3  #: switching zone S~_P or l1*, u = +omega_c (eq. 28)
    ZONE_N = 4  #: switching zone S~_N or l2*, u = -omega_c (eq. 33)
    LINEAR = 5  #: linear (PD) input, unsaturated (eq. 34 or PD)
    SATURATED = 6  #: linear input clipped at +-w_max


_I8 = {r: np.int8(r) for r in Region}  # region codes as int8 scalars (np.where keeps int8)

ArrayFn = Callable[
    [NDArray[np.float64], NDArray[np.float64]], tuple[NDArray[np.float64], NDArray[np.int8]]
]
ScalarFn = Callable[[float, float], tuple[float, int]]


@dataclass(frozen=True)
class LawFamily:
    """Laws that are one elementwise function with different parameters.

    A batch that drives states with several laws of one family evaluates them
    in one call, each state with its law's parameters
    (:func:`ptoverify.sim.simulate.simulate_segments`): per sample, one call's
    fixed overhead in place of one per law.  Each state's input and region are
    bit for bit those of its own law's vector path.

    Attributes
    ----------
    key : tuple
        Laws with equal keys belong to one family (their ``vector`` is the same function).
    vector : callable
        ``vector(x1, x2, *params) -> (u, region)`` on float arrays, each parameter
        a float or an array of the states' shape.
    params : tuple of float
        This law's parameters.
    """

    key: tuple
    vector: Callable[..., tuple[NDArray[np.float64], NDArray[np.int8]]]
    params: tuple[float, ...]


@dataclass(frozen=True)
class Law:
    """A feedback law u = f(x1, x2), vectorized and scalar.

    Attributes
    ----------
    name : str
        Name (``to``, ``pd``, ``pto``, ``pto-printed``).
    vector : callable
        ``vector(x1, x2) -> (u, region)`` on float arrays.
    scalar : callable
        ``scalar(x1, x2) -> (u, region)`` on Python floats.
    w_max : float
        Saturation [mm/s] the law respects.
    note : str
        What the law is, in one line (says when a variant falls back).
    family : LawFamily or None
        The family the law belongs to (the TO and PTO laws of one plant), if any.
    odd : bool
        Whether u(-x1, -x2) == -u(x1, x2) bit for bit, so that a state's mirror has
        the negated trajectory (true of the suite's laws, tested; a law built
        elsewhere, a user's or a shifted one, is not assumed odd).  Only odd laws
        let the sweep and the robustness maps simulate one state of a mirrored pair.
    """

    name: str
    vector: ArrayFn
    scalar: ScalarFn
    w_max: float
    note: str = ""
    family: LawFamily | None = None
    odd: bool = False

    def __call__(
        self, x1: ArrayLike, x2: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
        """Evaluate the law on arrays; returns (u [mm/s], region codes)."""
        x1, x2 = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
        if x1.shape != x2.shape:
            x1, x2 = np.broadcast_arrays(x1, x2)
        return self.vector(x1, x2)


_H_COEF = tuple((-1.0) ** n / n for n in range(25, 1, -1))  # Horner order, highest first


def h_scalar(r: float) -> float:
    """Return r - ln(1 + r) for a Python float, exact near 0 (see ``curves.h``).

    Parameters
    ----------
    r : float
        Argument [-], r > -1.

    Returns
    -------
    float
        h(r) >= 0 [-].

    Examples
    --------
    >>> h_scalar(1e-10)
    4.999999999666667e-21
    """
    if -0.2 < r < 0.2:
        acc = 0.0
        for c in _H_COEF:
            acc = acc * r + c
        return acc * r * r
    return r - math.log1p(r)


def sigma_scalar(x1: float, x2: float, a: float, omega: float) -> float:
    """Scalar :func:`ptoverify.model.curves.level_residual` (eqs. 9, 11, 13, 14).

    Parameters
    ----------
    x1, x2 : float
        State [mm], [mm/s].
    a : float
        Bandwidth [rad/s].
    omega : float
        Input level of the curve [mm/s], omega > 0.

    Returns
    -------
    float
        a x1 + sgn(x2) omega h(|x2|/omega) [mm/s]: > 0 right of the curve.

    Examples
    --------
    >>> sigma_scalar(1.0, 0.0, 100.0, 300.0)
    100.0
    """
    if x2 > 0:
        return a * x1 + omega * h_scalar(x2 / omega)
    if x2 < 0:
        return a * x1 - omega * h_scalar(-x2 / omega)
    return a * x1


def _bang(sigma: NDArray[np.float64], x2: NDArray[np.float64], w: float):
    """Time-optimal input from the switching function: S_P u l1 -> +w, S_N u l2 -> -w."""
    pos = sigma < 0
    on = sigma == 0
    if on.any():  # on the curve: the sign of x2 decides
        pos |= on & (x2 < 0)
    return _pick_sign(pos, w), _pick_region(pos, Region.BANG_P, Region.BANG_N)


def _pick_sign(pos, w: float):
    """``np.where(pos, w, -w)`` without branches: 2 w pos - w, exact for 0 < w < inf.

    (np.where on an irregular mask costs several times the arithmetic.)
    """
    u = np.empty(pos.shape)
    if 0.0 < w < math.inf:  # 2 w is exact, 2 w - w = w and 0 - w = -w exactly
        np.multiply(pos, 2.0 * w, out=u)
        np.subtract(u, w, out=u)
    else:
        u[...] = np.where(pos, w, -w)
    return u


def _pick_region(pos, yes: Region, no: Region):
    """``np.where(pos, yes, no)`` as int8 codes, without branches (yes = no - 1 or no + 1)."""
    region = np.empty(pos.shape, dtype=np.int8)
    if yes == no - 1:
        np.subtract(_I8[no], pos, out=region)
    else:
        np.add(_I8[no], pos, out=region)
    return region


def _origin(x1, x2, u, region):
    """Set u = 0, region ORIGIN at the origin (in place); return (u, region)."""
    origin = x1 == 0
    if origin.any():  # x2 only where x1 is 0 (rare away from the origin)
        origin &= x2 == 0
        if origin.any():
            u[origin], region[origin] = 0.0, Region.ORIGIN
    return u, region


def to_law(cfg: Config) -> Law:
    """Time-optimal feedback law, eq. (12).

    u = +w_max in S_P and on l1, -w_max in S_N and on l2, 0 at the origin, where
    S_P / S_N are the sides of the switching curve l1 - o - l2 (eqs. 9, 11).

    Parameters
    ----------
    cfg : Config
        Configuration (plant a, w_max).

    Returns
    -------
    Law
        The TO law.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = to_law(paper_config())
    >>> law.scalar(5.0, 0.0)
    (-300.0, 2)
    """
    a, w = cfg.plant.a, cfg.plant.w_max

    def vector(x1, x2):
        # the sign of switching_function(x1, x2, a, w) = a x1 + level_term(x2, w)
        u, region = _bang(level_side(a * x1, x2, w), x2, w)
        return _origin(x1, x2, u, region)

    # the PTO block with no linear zone (|x1| < 0 never holds) and no switching zone
    # runs exactly this arithmetic: TO is a member of the PTO family
    family = _pto_family(a, w, (0.0, 0.0, 0.0, math.nan))

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        if x1 == 0.0 and x2 == 0.0:
            return 0.0, int(Region.ORIGIN)
        s = sigma_scalar(x1, x2, a, w)
        if s < 0 or (s == 0 and x2 < 0):
            return w, int(Region.BANG_P)
        return -w, int(Region.BANG_N)

    return Law("to", vector, scalar, w, "time-optimal bang-bang, eq. (12)", family, odd=True)


def saturate_linear(v: NDArray[np.float64], w: float):
    """Clip a linear input to +-w; region LINEAR where unclipped, SATURATED where clipped.

    Parameters
    ----------
    v : ndarray
        Unsaturated input [mm/s].
    w : float
        Saturation level w_max [mm/s].

    Returns
    -------
    u : ndarray
        Clipped input [mm/s].
    region : ndarray of int8
        :class:`Region` code per entry.

    Examples
    --------
    >>> u, r = saturate_linear(np.array([1.0, -500.0]), 300.0)
    >>> u.tolist(), [Region(k).name for k in r]
    ([1.0, -300.0], ['LINEAR', 'SATURATED'])
    """
    u = np.minimum(np.maximum(v, -w), w)  # np.clip(v, -w, w), without its wrapper
    return u, _pick_region(np.abs(v) > w, Region.SATURATED, Region.LINEAR)


def pd_law(cfg: Config, *, gains: tuple[NDArray, NDArray] | None = None) -> Law:
    """PD law u = sat(-kp x1 - kd x2), saturated at +-w_max.

    In tracking, x1 is the position error x1 - r, so u = kp (r - x1) - kd x2.
    The paper does not say that its PD is saturated; the plant's input is
    limited to |u| <= w_max (eq. 1), so the input is clipped there.

    Parameters
    ----------
    cfg : Config
        Configuration (w_max, kp [1/s], kd [-]).
    gains : tuple of ndarray, optional
        Per-state (kp [1/s], kd [-]) in place of the configuration's, for
        evaluating many gain sets in one batch (see :func:`with_state_gains`).

    Returns
    -------
    Law
        The PD law.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> pd_law(paper_config()).scalar(0.1, 0.0)
    (-35.6, 5)
    """
    w, kp, kd = cfg.plant.w_max, cfg.pd.kp, cfg.pd.kd
    if gains is not None:
        return _state_gains_law(
            "pd", lambda x1, x2: saturate_linear(-gains[0] * x1 - gains[1] * x2, w), w
        )

    def vector(x1, x2):
        return saturate_linear(-kp * x1 - kd * x2, w)

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        v = -kp * x1 - kd * x2
        if v > w:
            return w, int(Region.SATURATED)
        if v < -w:
            return -w, int(Region.SATURATED)
        return v, int(Region.LINEAR)

    return Law("pd", vector, scalar, w, f"PD u = sat(-{kp:g} x1 - {kd:g} x2)", odd=True)


def omega_c_scalar(x1: float, x2: float, a: float) -> float:
    """Level omega_c of the curve through (x1, x2), eqs. (28)-(32), for Python floats.

    Solves eq. (31) in u = ln(1 + w), where it reads m = 1 - u / (e^u - 1) with
    m = -a x1 / x2 (eq. 30, m = 1 - k).  m(u) is increasing and concave for
    u > 0 and m(u) < u / 2, so Newton from u = 2 m climbs monotonically to the
    root; then omega_c = |x2| / (e^u - 1) (eq. 32).

    Parameters
    ----------
    x1, x2 : float
        State [mm], [mm/s] with x1 x2 < 0.
    a : float
        Bandwidth [rad/s].

    Returns
    -------
    float
        omega_c [mm/s]; 0.0 when m >= 1, inf when m <= 0.

    Examples
    --------
    >>> wc = omega_c_scalar(0.1, -100.0, 188.5)
    >>> abs(188.5 * 0.1 - 100.0 + wc * math.log1p(100.0 / wc)) < 1e-10
    True
    """
    m = -a * x1 / x2
    if m <= 0.0:
        return math.inf
    if m >= 1.0:
        return 0.0
    u = 2.0 * m
    for _ in range(60):
        if u < 1e-3:
            g = u * (0.5 - u * (1.0 / 12.0 - u * u / 720.0)) - m
            dg = 0.5 - u / 6.0
        else:
            e = math.expm1(u)
            g = 1.0 - u / e - m
            dg = ((u - 1.0) * e + u) / (e * e)
        du = g / dg
        u -= du
        if abs(du) <= 4e-16 * u:
            break
    return abs(x2) / math.expm1(u)


def _pto_block(a: float, w: float) -> Callable:
    """Return the PTO law's elementwise function of a plant, eq. (35), parameters explicit.

    ``block(x1, x2, g1, g2, dd, lv)``: linear gains k1 [1/s], k2 [-], linear-zone
    half-width d [mm], switching-zone level [mm/s] (NaN: no zone), each a float or
    one per state; on 1-D float arrays of one block (:func:`ptoverify.model.curves.blockwise`).
    """

    def block(x1, x2, g1, g2, dd, lv):
        # each branch on the states it acts on (the linear zone first, as it takes
        # precedence); the same elementwise arithmetic as evaluating every branch
        # everywhere and selecting, so the result is unchanged.  g1, g2: the linear
        # gains, dd: d, lv: the zone's level (NaN: no zone); floats or one per state
        lin = np.abs(x1) < dd
        n_lin = np.count_nonzero(lin)
        if n_lin == lin.size:  # all in the linear zone: no masks
            u, region = saturate_linear(-g1 * x1 - g2 * x2, w)
            return _origin(x1, x2, u, region)
        if 2 * n_lin >= lin.size:  # mostly linear: the linear input everywhere, the
            # other states overwritten below (no gather and scatter of the linear ones)
            with np.errstate(invalid="ignore", over="ignore"):  # only where overwritten
                u, region = saturate_linear(-g1 * x1 - g2 * x2, w)
        else:
            u = np.empty(x1.shape)
            region = np.empty(x1.shape, dtype=np.int8)
            if n_lin:
                il = lin.nonzero()[0]  # indices: one search of the mask, then gathers
                if np.ndim(g1):
                    g1, g2 = g1.take(il), g2.take(il)
                u[il], region[il] = saturate_linear(-g1 * x1.take(il) - g2 * x2.take(il), w)
        if n_lin < lin.size:
            out = (~lin).nonzero()[0]
            y1, y2 = x1.take(out), x2.take(out)
            sig = level_side(a * y1, y2, w)  # the sign of switching_function
            uo, ro = _bang(sig, y2, w)
            per = np.ndim(lv) > 0
            if per or not math.isnan(lv):
                # ((y2 < 0) & (sig > 0)) | ((y2 > 0) & (sig < 0)), in fewer passes
                between = np.sign(y2)
                between *= np.sign(sig)
                between = between < 0
                if per:
                    lv = lv.take(out)
                    between &= ~np.isnan(lv)
                cand = between.nonzero()[0]
                if cand.size:
                    c1, c2 = y1.take(cand), y2.take(cand)
                    lc = lv.take(cand) if per else lv
                    r0 = level_side(a * c1, c2, lc)  # the sign of level_residual
                    zp = (c2 < 0) & (r0 <= 0)
                    inz = zp | ((c2 > 0) & (r0 >= 0))
                    if inz.any():  # closed form only where it is used
                        # np.clip(omega_c, lc, w), without its wrapper
                        wc = np.maximum(omega_c(c1[inz], c2[inz], a), lc[inz] if per else lc)
                        np.minimum(wc, w, out=wc)
                        zpi = zp[inz]
                        idx = cand[inz]
                        uo[idx] = np.where(zpi, wc, -wc)
                        ro[idx] = np.where(zpi, Region.ZONE_P, Region.ZONE_N)
            u[out], region[out] = uo, ro
        return _origin(x1, x2, u, region)

    return block


def _pto_family(a: float, w: float, params: tuple[float, ...]) -> LawFamily:
    """Return the PTO family of a plant (:class:`LawFamily`), this member's ``params``."""
    block = _pto_block(a, w)

    def vector(x1, x2, *p):
        return blockwise(block, x1, x2, *p)

    return LawFamily(("pto-block", float(a), float(w)), vector, tuple(float(v) for v in params))


def pto_law(
    cfg: Config,
    omega0: float | None,
    name: str = "pto",
    note: str = "",
    *,
    gains: tuple[NDArray, ...] | None = None,
) -> Law:
    """PTO law, eq. (35), with the saturated linear zone of eq. (34).

    Regions, first match wins:

    * origin: u = 0;
    * S_L, |x1| < d: u = sat(-k1 x1 - k2 x2) (eq. 34, clipped at +-w_max);
    * S~_P u l1*, x2 < 0, sigma > 0 and a x1 + x2 + omega0 ln(1 - x2/omega0) <= 0:
      u = +omega_c (eqs. 28-32), clipped to [omega0, w_max];
    * S~_N u l2*, the mirror image: u = -omega_c (eq. 33);
    * S_P u l1: u = +w_max; S_N u l2: u = -w_max (eq. 12).

    The linear zone takes precedence over the others (the paper's "when the
    position x1 is smaller than a certain threshold ... linear control").

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], d [mm], k1 [1/s], k2 [-]).
    omega0 : float or None
        Level of l1*, l2* [mm/s], 0 < omega0 < w_max; None: no switching zone.
    name, note : str
        Law name and one-line description.
    gains : tuple of ndarray, optional
        Per-state (k1 [1/s], k2 [-]) of the linear zone in place of the
        configuration's, or (k1, k2, d [mm], zone level [mm/s], NaN: no zone)
        in place of cfg's gains, d and ``omega0`` (see :func:`with_state_gains`).

    Returns
    -------
    Law
        The PTO law, |u| <= w_max, odd in the state.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = pto_law(paper_config(), 100.0)
    >>> law.scalar(0.1, 0.0)
    (-32.300000000000004, 5)
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    d, k1, k2 = cfg.pto.d, cfg.pto.k1, cfg.pto.k2
    zone = omega0 is not None and 0.0 < omega0 < w
    om = float(omega0) if zone else w

    params = (k1, k2, d, om if zone else math.nan)
    family = _pto_family(a, w, params)
    pto_block = _pto_block(a, w)

    def block(x1, x2, g1=k1, g2=k2, dd=d, lv=params[3]):
        return pto_block(x1, x2, g1, g2, dd, lv)

    if gains is not None:
        return _state_gains_law(name, lambda x1, x2: blockwise(block, x1, x2, *gains), w)

    def vector(x1, x2):
        return blockwise(block, x1, x2)

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        if x1 == 0.0 and x2 == 0.0:
            return 0.0, int(Region.ORIGIN)
        if -d < x1 < d:
            v = -k1 * x1 - k2 * x2
            if v > w:
                return w, int(Region.SATURATED)
            if v < -w:
                return -w, int(Region.SATURATED)
            return v, int(Region.LINEAR)
        s = sigma_scalar(x1, x2, a, w)
        if zone:
            if x2 < 0 and s > 0 and sigma_scalar(x1, x2, a, om) <= 0:
                return min(max(omega_c_scalar(x1, x2, a), om), w), int(Region.ZONE_P)
            if x2 > 0 and s < 0 and sigma_scalar(x1, x2, a, om) >= 0:
                return -min(max(omega_c_scalar(x1, x2, a), om), w), int(Region.ZONE_N)
        if s < 0 or (s == 0 and x2 < 0):
            return w, int(Region.BANG_P)
        return -w, int(Region.BANG_N)

    note = note or f"PTO eq. (35), omega0 = {om:g} mm/s"
    return Law(name, vector, scalar, w, note, family, odd=True)


def pto_corrected_law(cfg: Config, *, gains: tuple[NDArray, NDArray] | None = None) -> Law:
    """PTO law with the corrected omega0 (``zones.corrected_zone``, strict reading).

    Parameters
    ----------
    cfg : Config
        Configuration.
    gains : tuple of ndarray, optional
        Per-state (k1, k2), as :func:`pto_law`.

    Returns
    -------
    Law
        ``pto``; without a usable corrected zone, the law has no switching zone
        and its note says so.
    """
    z = _corrected(cfg)
    if z.usable and not z.degenerate:
        note = (
            f"PTO eq. (35), corrected omega0 = {z.omega0:.6g} mm/s "
            f"({'valid' if z.valid else 'NOT valid'})"
        )
        return pto_law(cfg, z.omega0, "pto", note, gains=gains)
    return pto_law(
        cfg,
        None,
        "pto",
        f"PTO eq. (35) without switching zone: no corrected omega0 acts ({z.reason})",
        gains=gains,
    )


def _corrected(cfg: Config):
    """Return the corrected zone the ``pto`` law of ``cfg`` uses (``zones.zone_for_law``)."""
    from ptoverify.model.zones import zone_for_law

    return zone_for_law(cfg, "corrected")


def _corrected_level(cfg: Config) -> float:
    """Level [mm/s] of the zone the ``pto`` law of ``cfg`` acts with; NaN: no zone."""
    z = _corrected(cfg)
    lv = z.omega0 if z.usable and not z.degenerate else None
    return float(lv) if lv is not None and 0.0 < lv < cfg.plant.w_max else math.nan


def pto_printed_law(cfg: Config) -> Law:
    """PTO law with omega0 from eqs. (19)-(27) as printed (``zones.printed_zone``).

    When the printed omega0 is not in (0, w_max) the interval [omega0, w_max] of
    eq. (28) is empty, so the text implies no switching zone: the law is the
    time-optimal law outside the linear zone, and its note says so.

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    Law
        ``pto-printed``.
    """
    from ptoverify.model.zones import zone_for_law

    z = zone_for_law(cfg, "printed")
    if z.usable:
        return pto_law(
            cfg,
            z.omega0,
            "pto-printed",
            f"PTO eq. (35), printed omega0 = {z.omega0:.6g} mm/s "
            f"({'valid' if z.valid else 'NOT valid'})",
        )
    return pto_law(
        cfg,
        None,
        "pto-printed",
        f"printed omega0 = {z.omega0:.6g} mm/s is not below w_max = {cfg.plant.w_max:g}"
        " mm/s: [omega0, w_max] is empty, so no switching zone; time-optimal outside"
        " the linear zone, saturated eq. (34) inside",
    )


def _state_gains_law(name: str, vector: ArrayFn, w: float) -> Law:
    """Return a law whose gains are one per state: only its vector path exists."""

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        raise TypeError("a law with per-state gains has no scalar path; call it on arrays")

    return Law(name, vector, scalar, w, f"{name} with per-state linear gains")


def with_state_gains(name: str, cfg: Config, gains: dict[str, ArrayLike]) -> Law:
    """Return the law ``name`` with linear gains that differ from state to state.

    Evaluating many gain sets in one batch: call the law on arrays of the
    gains' shape, and state i is driven by gains i.  Each entry is computed
    with the same arithmetic as the vector path of the law built from a
    configuration holding that entry's gains, so it equals it bit for bit.
    For the PTO, d [mm] may be given per state too (key ``d``); each state then
    acts with the corrected zone of its d, as ``make_law("pto", ...)`` builds
    it; without it, d and the zone are ``cfg``'s.

    Parameters
    ----------
    name : str
        ``pd`` (gains ``kp`` [1/s], ``kd`` [-]) or ``pto`` (``k1`` [1/s], ``k2`` [-]).
    cfg : Config
        Configuration (plant; for the PTO its d [mm]).
    gains : dict
        The two gains of the law (and the PTO's ``d``), arrays of one shape.

    Returns
    -------
    Law
        Vector path only (its scalar path raises TypeError).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = with_state_gains("pd", paper_config(), {"kp": [100.0, 200.0], "kd": [0.0, 0.0]})
    >>> law(np.array([0.1, 0.1]), np.zeros(2))[0].tolist()
    [-10.0, -20.0]
    """
    keys = {"pd": ("kp", "kd"), "pto": ("k1", "k2")}
    if name not in keys:
        raise InputError(f"per-state gains: law '{name}' has none (choose from pd, pto)")
    g1, g2 = (np.asarray(gains[k], dtype=float) for k in keys[name])
    if g1.shape != g2.shape:
        raise InputError("per-state gains: both gains need one shape")
    if name == "pd":
        return pd_law(cfg, gains=(g1, g2))
    if "d" not in gains:
        d = np.full(g1.shape, cfg.pto.d)
    else:
        d = np.broadcast_to(np.asarray(gains["d"], dtype=float), g1.shape).copy()
    levels = {
        v: _corrected_level(replace(cfg, pto=replace(cfg.pto, d=v))) for v in np.unique(d).tolist()
    }
    lv = np.array([levels[v] for v in d.ravel().tolist()]).reshape(d.shape)
    return pto_law(cfg, None, "pto", gains=(g1, g2, d, lv))


_FACTORIES: dict[str, Callable[[Config], Law]] = {
    "to": to_law,
    "pd": pd_law,
    "pto": pto_corrected_law,
    "pto-printed": pto_printed_law,
}


def register_law(name: str, factory: Callable[[Config], Law]) -> None:
    """Let :func:`make_law` build a law defined in another module of this layer.

    The baselines (:mod:`ptoverify.model.baselines`, which import this module)
    register themselves when the ``ptoverify.model`` package is imported.

    Parameters
    ----------
    name : str
        One of :data:`ptoverify.config.BASELINE_NAMES`.
    factory : callable
        ``factory(cfg) -> Law``.
    """
    if name not in BASELINE_NAMES:
        raise ValueError(f"register_law: {name!r} is not a baseline name")
    _FACTORIES[name] = factory


def make_law(name: str, cfg: Config) -> Law:
    """Build a law by name: ``to``, ``pd``, ``pto``, ``pto-printed``, ``ptos``, ``cascade-p``.

    Parameters
    ----------
    name : str
        Law name.
    cfg : Config
        Configuration.

    Returns
    -------
    Law
        The law.
    """
    if name not in _FACTORIES:
        raise InputError(f"unknown law '{name}' (choose from {', '.join(ALL_LAW_NAMES)})")
    return _FACTORIES[name](cfg)
