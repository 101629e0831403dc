"""Control laws: time-optimal (eq. 12), PD, PTO (eq. 35), and the region bookkeeping.

A law is a :class:`Law`: calling it with states returns the input and the
region code of each state.  Each law has one evaluation, its vector path;
one state (``law.scalar(x1, x2)`` or ``law(x1, x2)`` on floats) is that path
on an array of one state, so a state's input does not depend on the batch it
is evaluated in.  Every law returns |u| <= w_max.

Region codes (:class:`Region`) name the branch of the law that acted, so a
simulation can say which region every sample used.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import ALL_LAW_NAMES, BASELINE_NAMES, LAW_NAMES, Config
from ptoverify.errors import InputError
from ptoverify.model.curves import level_residual, omega_c
from ptoverify.model.regions import ArrayFn, LawFamily, Region, ScalarFn

__all__ = [
    "Region",
    "Law",
    "LawFamily",
    "to_law",
    "pd_law",
    "pto_law",
    "pto_corrected_law",
    "pto_printed_law",
    "saturate_linear",
    "make_law",
    "register_law",
    "with_state_gains",
    "LAW_NAMES",
]


def _on_one_state(vector: ArrayFn, x1: float, x2: float) -> tuple[float, int]:
    """Evaluate ``vector`` on an array of the one state (x1 [mm], x2 [mm/s])."""
    u, region = vector(np.array([x1], dtype=float), np.array([x2], dtype=float))
    return float(u[0]), int(region[0])


@dataclass(frozen=True)
class Law:
    """A feedback law u = f(x1, x2): one vector path, and one state through it.

    Attributes
    ----------
    name : str
        Name (``to``, ``pd``, ``pto``, ``pto-printed``).
    vector : callable
        ``vector(x1, x2) -> (u [mm/s], region)`` on 1-D float arrays of one shape.
    scalar : callable or None
        ``scalar(x1, x2) -> (u [mm/s], region)`` on Python floats.  None (the
        suite's laws): ``vector`` on an array of the one state.  A law built
        around third-party code may give that code's own one-state mode.
    w_max : float
        Saturation [mm/s] the law respects.
    note : str
        What the law is, in one line (says when a variant falls back).
    family : LawFamily or None
        The family the law belongs to (the TO and PTO laws of one plant), if any.
    """

    name: str
    vector: ArrayFn
    scalar: ScalarFn | None
    w_max: float
    note: str = ""
    family: LawFamily | None = None

    def __post_init__(self) -> None:
        """Make ``scalar`` the vector path on one state where none is given."""
        if self.scalar is None:
            object.__setattr__(self, "scalar", partial(_on_one_state, self.vector))

    def __call__(
        self, x1: ArrayLike, x2: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
        """Evaluate the law on states of any shape (floats: an array of one state).

        Parameters
        ----------
        x1, x2 : array_like
            Position [mm] and velocity [mm/s], broadcast together.

        Returns
        -------
        u : ndarray
            Input [mm/s], of the broadcast shape (0-d for two floats).
        region : ndarray of int8
            :class:`Region` code per state.
        """
        x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        u, region = self.vector(x1.ravel(), x2.ravel())
        return u.reshape(x1.shape), region.reshape(x1.shape)


#: Region codes as int8 scalars: ``np.where`` on them gives int8 arrays directly.
_BANG_P, _BANG_N = np.int8(Region.BANG_P), np.int8(Region.BANG_N)
_ZONE_P, _ZONE_N = np.int8(Region.ZONE_P), np.int8(Region.ZONE_N)
_LINEAR, _SATURATED = np.int8(Region.LINEAR), np.int8(Region.SATURATED)


def _bang(sigma: NDArray[np.float64], x2: NDArray[np.float64], w: float):
    """Time-optimal input from the switching function: S_P u l1 -> +w, S_N u l2 -> -w."""
    pos = (sigma < 0) | ((sigma == 0) & (x2 < 0))  # on the curve: the sign of x2 decides
    return np.where(pos, w, -w), np.where(pos, _BANG_P, _BANG_N)


def _origin(x1, x2, u, region):
    """Set u = 0, region ORIGIN at the origin (in place); return (u, region)."""
    zero = x1 == 0
    if np.count_nonzero(zero):  # (x2 read only where some x1 is 0)
        origin = zero & (x2 == 0)
        if np.count_nonzero(origin):
            u[origin], region[origin] = 0.0, Region.ORIGIN
    return u, region


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
    region = np.where(np.abs(v) > w, _SATURATED, _LINEAR)  # (a NaN compares False, silently)
    return np.minimum(np.maximum(v, -w), w), region  # np.clip(v, -w, w)


def _pd_input(x1, x2, kp, kd, w: float):
    """PD input sat(-kp x1 - kd x2) and its region; gains floats or one per state."""
    return saturate_linear(-kp * x1 - kd * x2, w)


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
        return _state_gains_law("pd", partial(_pd_input, w=w), gains, w)

    def vector(x1, x2):
        return _pd_input(x1, x2, kp, kd, w)

    return Law("pd", vector, None, w, f"PD u = sat(-{kp:g} x1 - {kd:g} x2)")


def _pto_block(a: float, w: float) -> Callable:
    """Return the PTO law's elementwise function of a plant, eq. (35), parameters explicit.

    ``block(x1, x2, g1, g2, dd, lv)``: linear gains k1 [1/s], k2 [-], linear-zone
    half-width d [mm], switching-zone level [mm/s] (NaN: no zone), each a float or
    one per state.  Each branch is evaluated on the states it acts on (masks: one
    way for every batch, whichever branches act); the linear zone first, as it
    takes precedence.
    """

    def block(x1, x2, g1, g2, dd, lv):
        u = np.empty(x1.shape)
        region = np.empty(x1.shape, dtype=np.int8)
        lin = np.abs(x1) < dd
        n_lin = np.count_nonzero(lin)
        if n_lin:  # S_L, eq. (34)
            g1l, g2l = _at(g1, lin), _at(g2, lin)
            u[lin], region[lin] = _pd_input(x1[lin], x2[lin], g1l, g2l, w)
        if n_lin < lin.size:
            out = ~lin
            u[out], region[out] = _outside_linear(x1[out], x2[out], _at(lv, out), a, w)
        return _origin(x1, x2, u, region)

    return block


def _at(p, mask):
    """Return a parameter at the states of ``mask`` (a float as it is, else its entries)."""
    return p[mask] if isinstance(p, np.ndarray) and p.ndim else p


def _outside_linear(y1, y2, lv, a: float, w: float):
    """PTO input outside the linear zone: eq. (12), or omega_c in the switching zone.

    ``lv``: the zone's level [mm/s] (NaN: no zone), a float or one per state;
    eqs. (13), (14), (28)-(33).
    """
    sig = level_residual(y1, y2, a, w)  # switching function, eqs. (9), (11)
    u, region = _bang(sig, y2, w)  # eq. (12)
    one_level = isinstance(lv, float)  # one level for every state (a configuration's law)
    if one_level and math.isnan(lv):  # no zone at all (to): no candidates
        return u, region
    # zone candidates: between l1 and l2 (x2 and sigma of opposite signs), with a zone
    between = np.sign(y2) * np.sign(sig) < 0
    if not one_level:
        between &= ~np.isnan(lv)
    cand = np.nonzero(between)[0]  # y2 is 1-D
    if cand.size:
        c1, c2, lc = y1[cand], y2[cand], _at(lv, cand)
        r0 = level_residual(c1, c2, a, lc)  # on or inside l1* (l2*), eqs. (13), (14)
        zp = (c2 < 0) & (r0 <= 0)
        inz = zp | ((c2 > 0) & (r0 >= 0))
        if np.count_nonzero(inz):
            # omega_c clipped to [level, w_max], eqs. (28)-(33)
            wc = np.minimum(np.maximum(omega_c(c1[inz], c2[inz], a), _at(lc, inz)), w)
            idx, zpi = cand[inz], zp[inz]
            u[idx] = np.where(zpi, wc, -wc)
            region[idx] = np.where(zpi, _ZONE_P, _ZONE_N)
    return u, region


def _pto_family(a: float, w: float, params: tuple[float, ...]) -> LawFamily:
    """Return the PTO family of a plant (:class:`LawFamily`), this member's ``params``."""
    return LawFamily(("pto-block", float(a), float(w)), _pto_block(a, w), tuple(map(float, params)))


def _bind(family: LawFamily) -> ArrayFn:
    """``vector(x1, x2)`` = ``family.vector(x1, x2, *family.params)``."""

    def vector(x1, x2):
        return family.vector(x1, x2, *family.params)

    return vector


def to_law(cfg: Config) -> Law:
    """Time-optimal feedback law, eq. (12).

    u = +w_max in S_P and on l1, -w_max in S_N and on l2, 0 at the origin, where
    S_P / S_N are the sides of the switching curve l1 - o - l2 (eqs. 9, 11).
    It is the PTO law's function with no linear zone (d = 0) and no switching
    zone, which is eq. (12) exactly (a member of the PTO family).

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
    family = _pto_family(a, w, (0.0, 0.0, 0.0, math.nan))
    return Law("to", _bind(family), None, w, "time-optimal bang-bang, eq. (12)", family)


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
    family = _pto_family(a, w, (k1, k2, d, om if zone else math.nan))
    if gains is not None:
        per_state = gains if len(gains) == 4 else (*gains, *family.params[2:])
        return _state_gains_law(name, family.vector, per_state, w)
    note = note or f"PTO eq. (35), omega0 = {om:g} mm/s"
    return Law(name, _bind(family), None, w, note, family)


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


def _state_gains_law(name: str, fn: Callable, gains: tuple, w: float) -> Law:
    """Return a law whose parameters are one per state: ``fn(x1, x2, *gains)``.

    Its states must have the gains' shape (state i is driven by gains i), so its
    one-state path exists only for one gain set.
    """
    arrays = np.broadcast_arrays(*(np.asarray(g, dtype=float) for g in gains))
    flat = tuple(g.ravel() for g in arrays)  # Law.__call__ hands the states flattened

    def vector(x1, x2):
        if x1.shape != flat[0].shape:
            raise ValueError(
                f"a law with {flat[0].size} per-state gain sets was given {x1.size} states"
            )
        return fn(x1, x2, *flat)

    return Law(name, vector, None, w, f"{name} with per-state linear gains")


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
        ``pd`` (gains ``kp`` [1/s], ``kd`` [-]), ``pto`` (``k1`` [1/s], ``k2`` [-]),
        or a baseline registered with its per-state factory (:func:`register_law`:
        ``ptos`` with ``alpha`` [-], ``k`` [1/s]; ``cascade-p`` with ``kp`` [1/s]).
    cfg : Config
        Configuration (plant; for the PTO its d [mm]).
    gains : dict
        The two gains of the law (and the PTO's ``d``), arrays of one shape.

    Returns
    -------
    Law
        For states of the gains' shape (others raise ValueError).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = with_state_gains("pd", paper_config(), {"kp": [100.0, 200.0], "kd": [0.0, 0.0]})
    >>> law(np.array([0.1, 0.1]), np.zeros(2))[0].tolist()
    [-10.0, -20.0]
    """
    if name in _STATE_FACTORIES:  # a baseline (registered with its per-state factory)
        return _STATE_FACTORIES[name](cfg, gains)
    keys = {"pd": ("kp", "kd"), "pto": ("k1", "k2")}
    if name not in keys:
        choices = ", ".join(["pd", "pto", *_STATE_FACTORIES])
        raise InputError(f"per-state gains: law '{name}' has none (choose from {choices})")
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


#: Per-state factories of the baselines (:func:`with_state_gains`), by law name.
_STATE_FACTORIES: dict[str, Callable[[Config, dict[str, ArrayLike]], Law]] = {}


def register_law(
    name: str,
    factory: Callable[[Config], Law],
    state_gains: Callable[[Config, dict[str, ArrayLike]], Law] | None = None,
) -> None:
    """Let :func:`make_law` build a law defined in another module of this layer.

    The baselines (:mod:`ptoverify.model.baselines`, which import this module)
    register themselves when the ``ptoverify.model`` package is imported.

    Parameters
    ----------
    name : str
        One of :data:`ptoverify.config.BASELINE_NAMES`.
    factory : callable
        ``factory(cfg) -> Law``.
    state_gains : callable, optional
        ``state_gains(cfg, gains) -> Law`` with gains one per state, for
        :func:`with_state_gains` (bit for bit the law ``factory`` builds from a
        configuration holding one state's gains).
    """
    if name not in BASELINE_NAMES:
        raise ValueError(f"register_law: {name!r} is not a baseline name")
    _FACTORIES[name] = factory
    if state_gains is not None:
        _STATE_FACTORIES[name] = state_gains


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
