"""Switching zone of the PTO law, Section 4: as printed (eqs. 19-27) and corrected.

Geometry (fourth quadrant, x2 = -s < 0).  The level-omega curve through the
origin is a x1 = omega h(s / omega) (eqs. 9, 13, 28); omega h(s/omega) falls as
omega grows, so for omega0 < w_max the boundary l1* lies right of l1 and the
zone S~_P = {sigma_w >= 0, residual_omega0 <= 0, x2 < 0} is the band a state
coming from the right under u = -w_max meets first.  S~_N is its mirror image.

The principle (Section 4, rules 1 and 2; Section 7)
---------------------------------------------------
"A sampled state must enter the zone but not stride over it."  On the exact
one-sample map F_u of the ZOH plant (eq. 7 held for T) it reads, for the
fourth quadrant:

    for every state x with |x1| >= d and |x2| <= w_max that lies in S_N u l2
    on or outside l1* (where eq. 35 applies u = -w_max; l1* itself is included
    as the closure of that set, as rule 1 states it for points of l1*),
    the state F_{-w_max}(x) one sample later satisfies sigma(F) >= 0, i.e. it is
    on or right of l1 (in the zone, on l1, or still in S_N).

Mirror (rule 2): states with |x1| >= d in S_P u l1 outside l2*, after one
sample of +w_max, satisfy sigma <= 0.  The plant is odd, F_{-u}(-x) = -F_u(x),
and sigma(-x) = -sigma(x), so the mirror holds exactly when the rule above
does; it is checked once and the mirror is tested separately.

Decisions, and why:

* Sources are restricted to the envelope |x2| <= w_max: that set is invariant
  under |u| <= w_max, so no state beyond it is ever sampled.
* Sources inside the linear zone |x1| < d are exempt (eq. 35 applies the linear
  law there; the paper places the linear zone "left of the intersection").
* Landing: ``reading="strict"`` (the default, used by the ``pto`` law) demands
  sigma(F) >= 0 even when F lies inside the linear zone, as rule 1 literally
  does ("(x~1, x~2) should stay above the curve l1").  ``reading="lenient"``
  also accepts any landing with |F1| < d.  The lenient reading is reported
  too: at the paper's defaults l1 lies inside |x1| < d over the whole envelope,
  so the lenient principle already holds with no zone at all (omega0 = w_max),
  while the time-optimal law then lands in the linear zone at nearly -w_max on
  the wrong side of l1; that reading cannot be what the zone is for.
* A tolerance of :func:`ptoverify.verdict.tie_band` [mm/s] on sigma absorbs
  round-off for states that ride a curve exactly.

Exact per-velocity test.  At fixed x2, F1 = x1 + c(x2) and F2 do not depend
on x1 otherwise, so sigma(F(x1, x2)) is strictly increasing in x1; the worst
source at each velocity is the left end of each x1-interval of the source set
(for the lenient reading, of each interval cut at F1 = +-d).  This is how a
candidate omega0 is decided (dense in x2); a 2-D grid over the envelope and
over the band just outside l1* verifies the result without that argument.
The same argument shows the margin cannot fall as omega0 falls (l1* moves
right); the scan over (0, w_max] does not rely on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config, PTOSettings
from ptoverify.model.curves import level_curve_x1, level_residual, level_term, root_22, root_k
from ptoverify.model.memo import memo
from ptoverify.model.plant import flow
from ptoverify.verdict import tie_band

__all__ = [
    "PTOZone",
    "printed_zone",
    "corrected_zone",
    "zone_summary",
    "principle_margin",
    "principle_violations",
    "zone_for_law",
    "clear_caches",
    "READINGS",
]

READINGS = ("strict", "lenient")
_NAN = float("nan")


@dataclass(frozen=True, kw_only=True)
class PTOZone:
    """A switching zone S~_P / S~_N (boundary l1*, l2*, eqs. 13-14) and its verdict.

    Attributes
    ----------
    construction : str
        ``printed`` (eqs. 19-27 as printed) or ``corrected``.
    omega0 : float
        Level of l1*, l2* [mm/s]; NaN when none exists.
    x20_tilde : float
        Velocity where l1* meets x1 = d [mm/s] (eq. 23 for the printed form); NaN
        when l1* never reaches x1 = d inside the envelope.
    b0, y_star, k, z_star : float
        Intermediate numbers of eqs. (21)-(26) [-] (corrected: b0 = a d / omega0,
        y* = z* = -x20_tilde / omega0, k from eq. 25).
    valid : bool
        0 < omega0 < w_max, the zone acts outside the linear zone, and the
        principle (module docstring) holds for ``reading``.
    degenerate : bool
        The zone lies entirely inside the linear zone |x1| < d (never acts).
    reason : str
        Why the verdict, in words with the numbers.
    feasible_intervals : tuple of (float, float)
        Intervals of omega0 [mm/s] in (0, w_max] where the principle holds.
    reading : str
        ``strict`` or ``lenient`` (module docstring).
    margin : float
        Worst landing residual sigma(F) over the sources [mm/s] (>= 0 holds).
    grid_violations : int or None
        Violations found on the 2-D verification grid (None: not run).
    grid_points : int or None
        Number of source states the grid checked (None: not run).
    d_min : float
        Smallest d [mm] for which some omega0 > 0 satisfies the principle
        (an infimum, reached as omega0 -> 0+).
    details : dict
        Extra numbers (JSON-able).
    """

    construction: str
    omega0: float
    x20_tilde: float
    b0: float
    y_star: float
    k: float
    z_star: float
    valid: bool
    degenerate: bool
    reason: str
    feasible_intervals: tuple[tuple[float, float], ...] = ()
    reading: str = "strict"
    margin: float = _NAN
    grid_violations: int | None = None
    grid_points: int | None = None
    d_min: float = _NAN
    details: dict = field(default_factory=dict)

    @property
    def usable(self) -> bool:
        """True when omega0 defines a non-empty zone, 0 < omega0 < w_max."""
        return bool(self.details.get("usable", False))

    def to_json(self) -> dict:
        """Return the zone as a JSON-able dict (DESIGN keys first)."""
        return {
            "omega0": self.omega0,
            "x20_tilde": self.x20_tilde,
            "valid": self.valid,
            "reason": self.reason,
            "construction": self.construction,
            "degenerate": self.degenerate,
            "reading": self.reading,
            "b0": self.b0,
            "y_star": self.y_star,
            "k": self.k,
            "z_star": self.z_star,
            "margin_mm_s": self.margin,
            "feasible_intervals": [list(iv) for iv in self.feasible_intervals],
            "grid_violations": self.grid_violations,
            "grid_points": self.grid_points,
            "d_min": self.d_min,
            **self.details,
        }


# ------------------------------------------------------------------ principle
def _tol(cfg: Config) -> float:
    """Curve tie band of :func:`ptoverify.verdict.tie_band` for ``cfg`` [mm/s]."""
    return tie_band(cfg.plant.w_max, cfg.plant.a, cfg.plant.position_range)


def _l1star_x1(x2: NDArray[np.float64], a: float, omega0: ArrayLike) -> NDArray[np.float64]:
    """x1 on l1* at velocity x2 < 0 (eq. 13); omega0 <= 0 gives the limit x1 = -x2 / a."""
    omega0 = np.asarray(omega0, dtype=float)
    with np.errstate(all="ignore"):
        return np.where(
            omega0 <= 0.0, -x2 / a, level_curve_x1(x2, a, np.where(omega0 <= 0.0, 1.0, omega0))
        )


def _source_intervals(cfg: Config, omega0: ArrayLike, x2: NDArray[np.float64], d: float):
    """Left/right ends of the source x1-intervals at each velocity (u = -w_max, |x1| >= d).

    Returns two intervals (lo, hi) per velocity, of the broadcast shape of
    ``omega0`` [mm/s] and ``x2`` [mm/s] for the first (right of l1*, x1 >= d) and
    of ``x2`` for the second (l2 <= x1 <= -d); an empty one has lo > hi.
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    neg = x2 < 0
    l1s = np.where(neg, _l1star_x1(np.where(neg, x2, -1.0), a, np.minimum(omega0, w)), 0.0)
    lo_a = np.where(neg, np.maximum(l1s, d), d)  # right piece: x1 >= d
    return (lo_a, np.inf), _l2_sources(cfg, x2, d)


def _l2_sources(cfg: Config, x2: NDArray[np.float64], d: float):
    """Return the left piece of the sources, l2 <= x1 <= -d (free of omega0)."""
    pos = x2 > 0
    with np.errstate(all="ignore"):
        l2 = level_curve_x1(np.where(pos, x2, 1.0), cfg.plant.a, cfg.plant.w_max)
    lo_b = np.where(pos & (l2 <= -d), l2, np.inf)
    hi_b = np.full_like(x2, -d)
    return lo_b, hi_b


def principle_margin(
    cfg: Config,
    omega0: float | NDArray[np.float64],
    x2: NDArray[np.float64] | None = None,
    *,
    reading: str = "strict",
    d: float | None = None,
    points: int = 4001,
) -> NDArray[np.float64]:
    """Worst landing residual of the principle at each velocity, exact in x1.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    omega0 : float or ndarray
        Level of l1* [mm/s]; values >= w_max mean no zone; 0 is the limit omega0 -> 0+.
        An array is broadcast against ``x2`` (``omegas[:, None]`` with a 1-D ``x2``
        gives one row per omega0; equal shapes pair them elementwise).
    x2 : ndarray, optional
        Velocities [mm/s], |x2| <= w_max; default ``points`` evenly over [-w_max, w_max].
    reading : {"strict", "lenient"}
        Landing rule (module docstring).
    d : float, optional
        Linear-zone half-width [mm]; default ``cfg.pto.d``.
    points : int
        Number of velocities when ``x2`` is not given.

    Returns
    -------
    ndarray
        min over the sources at that velocity of sigma(F_{-w_max}(x)) [mm/s];
        +inf where the rule exempts every source.  The principle holds where >= 0.
        Of the broadcast shape of ``omega0`` and ``x2``.  The evaluation is
        elementwise (one path for any shapes): what depends on the velocity
        alone (the landing after one sample, the l2 side) is computed on ``x2``
        and broadcast, the l1* side on the broadcast shape.
    """
    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    a, w = cfg.plant.a, cfg.plant.w_max
    d = cfg.pto.d if d is None else d
    if x2 is None:
        x2 = np.linspace(-w, w, points)
    x2 = np.asarray(x2, dtype=float)
    c1, f2 = flow(0.0, x2, -w, cfg.plant.sample_time, a)  # F1 = x1 + c1, F2 = f2
    with np.errstate(all="ignore"):
        term = level_term(f2, w)  # sigma(F) = a F1 + term: the part that is x1-free
    (lo_a, hi_a), (lo_b, hi_b) = _source_intervals(cfg, omega0, x2, d)
    return np.minimum(
        _side_margin(lo_a, hi_a, c1, term, a, d, reading),
        _side_margin(lo_b, hi_b, c1, term, a, d, reading),
    )


def _side_margin(lo, hi, c1, term, a: float, d: float, reading: str):
    """Worst landing residual from the left end(s) of one family of source intervals."""
    cands = (
        [lo]
        if reading == "strict"
        else [np.maximum(lo, d - c1), np.where(lo <= -d - c1, lo, np.inf)]
    )
    margin = None
    for x1 in cands:
        ok = np.isfinite(x1) if np.ndim(hi) == 0 and hi == np.inf else (x1 <= hi) & np.isfinite(x1)
        with np.errstate(all="ignore"):
            r = a * (np.where(ok, x1, 0.0) + c1) + term  # level_residual(F1, F2, a, w_max)
        m = np.where(ok, r, np.inf)
        margin = m if margin is None else np.minimum(margin, m)
    return margin


def _kinks(cfg: Config, omega0: float, d: float) -> list[float]:
    """Velocities [mm/s] where the worst source jumps between curves (V-shaped minima).

    l1* meets x1 = d at x2 = -omega0 y, h(y) = a d / omega0 (as eq. 22 with 2aT
    removed); l2 meets x1 = -d at x2 = w_max y, h(y) = a d / w_max.
    """
    return _kinks_many(cfg, np.array([float(omega0)]), d)[0]


def _kinks_many(cfg: Config, omegas: NDArray[np.float64], d: float) -> list[list[float]]:
    """:func:`_kinks` for each omega0 of an array (root_22 is elementwise, so identical)."""
    a, w = cfg.plant.a, cfg.plant.w_max
    out: list[list[float]] = [[] for _ in omegas]
    if d > 0:
        zone = (omegas > 0) & (omegas < w)
        ys = root_22(a * d / omegas[zone]) if zone.any() else np.empty(0)
        y_l2 = w * float(root_22(a * d / w))
        it = iter(ys)
        for lst, om, inside in zip(out, omegas.tolist(), zone.tolist(), strict=True):
            if inside:
                lst.append(-om * float(next(it)))
            elif om <= 0:
                lst.append(-a * d)
            lst.append(y_l2)
    return [[v for v in lst if -w <= v <= w] for lst in out]


def _worst_margin(cfg: Config, omega0: float, reading: str, d: float | None = None) -> float:
    """Dense worst margin over |x2| <= w_max [mm/s] (:func:`_worst_margins` of one omega0)."""
    return _worst_margins(cfg, np.array([float(omega0)]), reading, d)[0]


def _worst_margins(
    cfg: Config, omegas: NDArray[np.float64], reading: str, d: float | None = None
) -> list[float]:
    """Dense worst margin over |x2| <= w_max for each omega0 of an array [mm/s].

    4001 even velocities, the kinks of :func:`_kinks` (the minimum often sits on
    one, where a coarse grid would miss it by slope x spacing), and 201 points
    around each of the 8 lowest local minima of the even grid.  The even grids of
    all omega0 are one broadcast :func:`principle_margin` call and the refinement
    points (different per omega0) one elementwise call.
    """
    w = cfg.plant.w_max
    d = cfg.pto.d if d is None else d
    omegas = np.asarray(omegas, dtype=float).ravel()
    x2 = np.linspace(-w, w, 4001)
    M = principle_margin(cfg, omegas[:, None], x2, reading=reading, d=d)
    step = x2[1] - x2[0]
    is_min = (M[:, 1:-1] <= M[:, :-2]) & (M[:, 1:-1] <= M[:, 2:])
    kinks = _kinks_many(cfg, omegas, d)
    fines = []
    for k in range(omegas.size):
        loc = np.flatnonzero(is_min[k]) + 1
        loc = loc[np.argsort(M[k][loc])[:8]]
        bands = np.linspace(x2[loc] - step, x2[loc] + step, 201, axis=1).ravel()
        fines.append(np.clip(np.concatenate([np.array(kinks[k]), bands]), -w, w))
    sizes = np.array([f.size for f in fines])
    pts = np.concatenate(fines)
    fm = principle_margin(cfg, np.repeat(omegas, sizes), pts, reading=reading, d=d)
    ends = np.cumsum(sizes)
    return [
        float(min(M[k].min(), fm[end - n : end].min(initial=np.inf)))
        for k, (n, end) in enumerate(zip(sizes.tolist(), ends.tolist(), strict=True))
    ]


def principle_violations(
    cfg: Config,
    omega0: float,
    *,
    reading: str = "strict",
    n1: int = 801,
    n2: int = 801,
    n_band: int = 201,
) -> tuple[int, int]:
    """Count violations of the principle on 2-D grids of source states.

    Independent of the monotonicity argument: every grid state in the source set
    is stepped with u = -w_max and its landing is judged.  Two grids: the
    envelope |x1| <= position_range, |x2| <= w_max (``n1`` x ``n2``), and the
    band from max(l1*, d) out to 3 w_max T to its right (``n2`` x ``n_band``).

    Parameters
    ----------
    cfg : Config
        Configuration.
    omega0 : float
        Level of l1* [mm/s].
    reading : {"strict", "lenient"}
        Landing rule.
    n1, n2, n_band : int
        Grid sizes in x1, x2 and across the band [-].

    Returns
    -------
    violations, sources : int
        Number of violating states and of source states checked.
    """
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    R = cfg.plant.position_range
    x2 = np.linspace(-w, w, n2)
    g1, g2 = np.meshgrid(np.linspace(-R, R, n1), x2)
    (lo_a, _), _ = _source_intervals(cfg, omega0, x2, d)
    off = np.linspace(0.0, 3.0 * w * T, n_band)
    b1 = lo_a[:, None] + off[None, :]
    b2 = np.broadcast_to(x2[:, None], b1.shape)
    x1 = np.concatenate([g1.ravel(), b1.ravel()])
    x2s = np.concatenate([g2.ravel(), b2.ravel()])
    # level_residual(x1, x2, a, omega) is a x1 + level_term(x2, omega) bit for bit: the
    # velocity term once per grid velocity, repeated along the rows of both grids

    def residual(omega: float):
        term = level_term(x2, omega)
        return a * x1 + np.concatenate([np.repeat(term, n1), np.repeat(term, n_band)])

    sig = residual(w)
    in_zone = (
        (x2s < 0) & (sig >= 0) & (residual(min(omega0, w)) < 0)
        if 0 < omega0 < w
        else np.zeros_like(sig, dtype=bool)
    )
    src = (np.abs(x1) >= d) & ((sig > 0) | ((sig == 0) & (x2s > 0))) & ~in_zone
    f1, f2 = flow(x1[src], x2s[src], -w, T, a)
    bad = level_residual(f1, f2, a, w) < -_tol(cfg)
    if reading == "lenient":
        bad &= np.abs(f1) >= d
    return int(bad.sum()), int(src.sum())


# ------------------------------------------------------------------ printed
def _printed_numbers(a: float, w: float, T: float, d: float) -> dict:  # noqa: N803
    """Eqs. (21)-(27) exactly as printed."""
    b0 = a * d / w + 2.0 * a * T  # eq. (21), x~10 = d
    y = float(root_22(b0))  # eq. (22)
    x20 = -y * w  # eq. (23)
    k = 1.0 + a * d / x20  # eq. (25)
    z = float(root_k(-a * d / x20))  # eq. (26), m = 1 - k
    omega0 = -x20 / z if z != 0 else _NAN  # eq. (27)
    return {"b0": b0, "y_star": y, "x20_tilde": x20, "k": k, "z_star": z, "omega0": omega0}


def _image_residuals(cfg: Config) -> dict:
    """Residual sigma of the one-sample image of l1 under +-w_max (checks eq. 16/19)."""
    a, w, T = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time
    x2 = -np.linspace(0.01, 1.0, 200) * w
    x1 = level_curve_x1(x2, a, w)
    fp1, fp2 = flow(x1, x2, w, T, a)
    fn = flow(x1, x2, -w, T, a)
    rp = a * fp1 + fp2 + w * np.log1p(-fp2 / w)  # eq. (9) itself, valid also for x2 > 0
    rn = level_residual(fn[0], fn[1], a, w)
    return {
        "image_plus_residual_max_abs": float(np.abs(rp).max()),
        "image_minus_residual_range": [float(rn.min()), float(rn.max())],
        "eq19_residual": -2.0 * a * w * T,
    }


def printed_zone(cfg: Config) -> PTOZone:
    """Switching zone from eqs. (19)-(27) exactly as printed, with a verdict.

    b0 = a d / w_max + 2 a T (eq. 21), y* from eq. (22), x~20 = -y* w_max
    (eq. 23), k = 1 + a d / x~20 (eq. 25), z* from eq. (26), omega0 = -x~20 / z*
    (eq. 27).  Valid only if 0 < omega0 < w_max and the principle (strict
    reading, module docstring) holds for the zone it defines.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).

    Returns
    -------
    PTOZone
        The printed construction and its reasons.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> z = printed_zone(paper_config())
    >>> z.valid, z.omega0 > 300.0
    (False, True)
    """
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    num = _printed_numbers(a, w, T, d)
    om, x20 = num["omega0"], num["x20_tilde"]
    img = _image_residuals(cfg)
    reasons = [
        f"eq. (16) sign: with the +w_max flow of (15), a x1 + x2 grows by a w_max T "
        f"and the image of l1 is l1 itself (max |sigma| = "
        f"{img['image_plus_residual_max_abs']:.2e} mm/s), not the curve (19) at "
        f"sigma = -2 a w_max T = {img['eq19_residual']:.4g} mm/s; under -w_max the image "
        f"has sigma in [{img['image_minus_residual_range'][0]:.4g}, "
        f"{img['image_minus_residual_range'][1]:.4g}] mm/s, not a constant"
    ]
    if x20 < -w:
        reasons.append(
            f"x~20 = {x20:.6g} mm/s lies beyond -w_max = {-w:g} mm/s, outside the "
            "envelope |x2| <= w_max that a sampled state can reach"
        )
    usable = math.isfinite(om) and 0.0 < om < w
    if not usable:
        reasons.append(
            f"omega0 = {om:.6g} mm/s is not in (0, w_max = {w:g}): the interval "
            "[omega0, w_max] of eq. (28) is empty and l1* lies on the S_P side of "
            "l1, so the zone between l1 and l1* is empty; eq. (35) reduces to the "
            "time-optimal law outside the linear zone"
        )
    om_eff = om if usable else w  # no zone: u = -w_max up to l1
    margin = _worst_margin(cfg, om_eff, "strict")
    margin_l = _worst_margin(cfg, om_eff, "lenient")
    holds = margin >= -_tol(cfg)
    reasons.append(
        f"principle (strict) {'holds' if holds else 'fails'} for the zone it "
        f"defines: worst landing sigma = {margin:.6g} mm/s (lenient reading: "
        f"{margin_l:.6g} mm/s)"
    )
    degenerate = usable and _degenerate(cfg, om)
    valid = usable and holds and not degenerate
    details = {"usable": usable, "margin_lenient_mm_s": margin_l, **img}
    return PTOZone(
        construction="printed",
        omega0=om,
        x20_tilde=x20,
        b0=num["b0"],
        y_star=num["y_star"],
        k=num["k"],
        z_star=num["z_star"],
        valid=valid,
        degenerate=degenerate,
        reason="; ".join(reasons),
        reading="strict",
        margin=margin,
        d_min=smallest_d(cfg, "strict"),
        details=details,
    )


# ------------------------------------------------------------------ corrected
def _degenerate(cfg: Config, omega0: float) -> bool:
    """Return True when l1* stays inside |x1| < d over the envelope (zone never acts)."""
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    if not 0 < omega0 < w:
        return True
    return float(level_curve_x1(-w, a, omega0)) < d


def _feasible_many(
    cfg: Config, omegas: NDArray[np.float64], reading: str, tol: float
) -> NDArray[np.bool_]:
    """Return whether the principle holds (worst margin >= -tol [mm/s]) per omega0."""
    return np.array(_worst_margins(cfg, omegas, reading)) >= -tol


@memo(maxsize=16)
def _feasible_intervals(cfg: Config, reading: str, scan: int) -> tuple[tuple[float, float], ...]:
    """Scan omega0 over (0, w_max], then bisect every edge of the feasible set."""
    w, tol = cfg.plant.w_max, _tol(cfg)
    grid = np.unique(
        np.concatenate([np.geomspace(1e-4 * w, w, scan // 2), np.linspace(w / scan, w, scan // 2)])
    )
    ok = _feasible_many(cfg, grid, reading, tol)

    def edge(good: float, bad: float) -> float:
        # bisection, up to 60 halvings until |good - bad| <= 1e-10 w_max
        for _ in range(60):
            mid = 0.5 * (good + bad)
            good, bad = (
                (mid, bad) if _feasible_many(cfg, np.array([mid]), reading, tol)[0] else (good, mid)
            )
            if abs(good - bad) <= 1e-10 * w:
                break
        return good

    intervals, i = [], 0
    while i < len(grid):
        if not ok[i]:
            i += 1
            continue
        j = i
        while j + 1 < len(grid) and ok[j + 1]:
            j += 1
        lo = 0.0 if i == 0 else edge(float(grid[i]), float(grid[i - 1]))
        hi = w if j == len(grid) - 1 else edge(float(grid[j]), float(grid[j + 1]))
        intervals.append((lo, hi))
        i = j + 1
    return tuple(intervals)


def smallest_d(cfg: Config, reading: str = "strict") -> float:
    """Smallest d [mm] for which some omega0 > 0 meets the principle (limit omega0 -> 0+).

    Parameters
    ----------
    cfg : Config
        Configuration (a, w_max, T).
    reading : {"strict", "lenient"}
        Landing rule.

    Returns
    -------
    float
        The infimum d [mm] (bisection to 1e-9 of the position range); NaN if even
        d = position_range fails.

    Notes
    -----
    It depends on the plant alone, and is memoized on it (``clear_caches`` empties
    the memo).
    """
    return _smallest_d(Config(name="zone", plant=cfg.plant), reading)


@memo(maxsize=16)
def _smallest_d(cfg: Config, reading: str) -> float:
    tol, R = _tol(cfg), cfg.plant.position_range

    def feasible(d: float) -> bool:
        return _worst_margin(cfg, 0.0, reading, d) >= -tol

    if feasible(0.0):
        return 0.0
    if not feasible(R):
        return _NAN
    lo, hi = 0.0, R
    while hi - lo > 1e-9 * R:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if feasible(mid) else (mid, hi)
    return hi


def corrected_zone(
    cfg: Config, *, reading: str = "strict", scan: int = 200, verify: bool = True
) -> PTOZone:
    """Largest omega0 < w_max for which the principle holds, verified on a grid.

    omega0 is scanned over (0, w_max] (``scan`` points, geometric and linear),
    every edge of the feasible set is bisected to 1e-10 w_max, and the chosen
    omega0 is the top of the highest feasible interval, backed off by 1e-6
    relative (headroom for round-off in the grid check).  If that interval
    reaches w_max the principle holds with no zone; the largest omega0 < w_max
    then only approaches w_max and the zone is degenerate.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    reading : {"strict", "lenient"}
        Landing rule (module docstring).
    scan : int
        Number of omega0 values in the first scan.
    verify : bool
        Run the 2-D grid check (:func:`principle_violations`).

    Returns
    -------
    PTOZone
        The corrected zone; ``valid`` needs a feasible omega0 < w_max, a zone that
        acts outside |x1| < d, and no violation on the grid.

    Notes
    -----
    The result is memoized per (cfg, reading, scan, verify), so the report's
    zone section and the ``zone-corrected-valid`` gate share one grid check;
    :func:`clear_caches` empties the memo (for tests that perturb the internals).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> z = corrected_zone(paper_config(), verify=False)
    >>> z.valid and 0 < z.omega0 < 300.0
    True
    """
    return _corrected_zone(_zone_key(cfg), reading, scan, verify)


def _zone_key(cfg: Config) -> Config:
    """Return what a zone depends on (the plant and d): the memo key of the constructions."""
    return Config(name="zone", plant=cfg.plant, pto=PTOSettings(d=cfg.pto.d))


@memo(maxsize=16)
def _corrected_zone(cfg: Config, reading: str, scan: int, verify: bool) -> PTOZone:
    """:func:`corrected_zone`, memoized on its normalised arguments (Config is frozen).

    The verified zone is the unverified one (shared, e.g. with the laws) plus the
    grid check.
    """
    if verify:
        base = _corrected_zone(cfg, reading, scan, False)
        if not base.feasible_intervals:  # no omega0: nothing to verify
            return base
        viol, pts = principle_violations(cfg, base.omega0, reading=reading)
        return replace(
            base,
            valid=base.valid and viol == 0,
            reason=f"{base.reason}; grid check: {viol} violations in {pts} source states",
            grid_violations=viol,
            grid_points=pts,
        )
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    intervals = _feasible_intervals(cfg, reading, scan)
    dmin = smallest_d(cfg, reading)
    shown = ", ".join(f"({lo:.6g}, {hi:.6g}]" for lo, hi in intervals)
    if not intervals:
        reason = (
            f"no omega0 in (0, w_max] meets the {reading} principle for d = {d:g} mm, "
            f"T = {cfg.plant.sample_time:g} s, a = {a:.6g} rad/s; the smallest d for "
            f"which one does is {dmin:.6g} mm"
        )
        return PTOZone(
            construction="corrected",
            omega0=_NAN,
            x20_tilde=_NAN,
            b0=_NAN,
            y_star=_NAN,
            k=_NAN,
            z_star=_NAN,
            valid=False,
            degenerate=False,
            reason=reason,
            reading=reading,
            margin=_worst_margin(cfg, 0.0, reading),
            d_min=dmin,
            details={"usable": False},
        )
    top = intervals[-1][1]
    no_zone_needed = top >= w
    omega0 = (w if no_zone_needed else top) * (1.0 - 1e-6)
    margin = _worst_margin(cfg, omega0, reading)
    degenerate = _degenerate(cfg, omega0)
    y = float(root_22(a * d / omega0))  # l1* meets x1 = d: h(y) = a d / omega0
    x20 = -y * omega0 if y * omega0 <= w else _NAN
    k = 1.0 + a * d / x20 if math.isfinite(x20) else _NAN
    parts = [
        f"{reading} principle holds for omega0 in {shown} mm/s; chosen omega0 = "
        f"{omega0:.6g} mm/s, worst landing sigma = {margin:.4g} mm/s"
    ]
    if no_zone_needed:
        parts.append("the principle holds with no zone at all (omega0 = w_max)")
    if degenerate:
        parts.append(
            f"l1* reaches only x1 = {float(level_curve_x1(-w, a, omega0)):.4g} mm at "
            f"x2 = -w_max, inside the linear zone d = {d:g} mm: the zone never acts "
            "(degenerate)"
        )
    valid = (not degenerate) and omega0 < w and margin >= -_tol(cfg)
    details = {
        "usable": 0 < omega0 < w,
        "no_zone_needed": no_zone_needed,
        "l1star_x1_at_wmax_mm": float(level_curve_x1(-w, a, omega0)),
        "l1_x1_at_wmax_mm": float(level_curve_x1(-w, a, w)),
    }
    return PTOZone(
        construction="corrected",
        omega0=omega0,
        x20_tilde=x20,
        b0=a * d / omega0,
        y_star=y if math.isfinite(x20) else _NAN,
        k=k,
        z_star=y if math.isfinite(x20) else _NAN,
        valid=valid,
        degenerate=degenerate,
        reason="; ".join(parts),
        feasible_intervals=tuple(intervals),
        reading=reading,
        margin=margin,
        d_min=dmin,
        details=details,
    )


def zone_for_law(cfg: Config, variant: str) -> PTOZone:
    """Zone the ``pto`` (``corrected``) or ``pto-printed`` (``printed``) law uses.

    Memoized on what a zone depends on (the plant and d), so laws that differ
    only in gains (a tuning search) share one construction.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    variant : str
        ``corrected`` or ``printed``.

    Returns
    -------
    PTOZone
        The zone (not grid-verified).
    """
    return _zone_for_law(_zone_key(cfg), variant)


@memo(maxsize=256)
def _zone_for_law(cfg: Config, variant: str) -> PTOZone:
    return corrected_zone(cfg, verify=False) if variant == "corrected" else printed_zone(cfg)


def clear_caches() -> None:
    """Empty the memos of this module (zones, feasible intervals, d_min per configuration)."""
    for fn in (_corrected_zone, _feasible_intervals, _smallest_d, _zone_for_law):
        fn.cache_clear()


def zone_summary(cfg: Config, *, verify: bool = True) -> dict:
    """Return the ``ptoverify zone --json`` object (DESIGN.md keys plus extras).

    Parameters
    ----------
    cfg : Config
        Configuration.
    verify : bool
        Run the 2-D grid checks.

    Returns
    -------
    dict
        ``printed``, ``corrected`` (each ``omega0``, ``x20_tilde``, ``valid``,
        ``reason`` and more), ``corrected_lenient`` (the lenient reading), ``d``,
        ``w_max`` [mm/s], ``a`` [rad/s], ``sample_time`` [s].
    """
    p: PTOSettings = cfg.pto
    return {
        "printed": printed_zone(cfg).to_json(),
        "corrected": corrected_zone(cfg, verify=verify).to_json(),
        "corrected_lenient": corrected_zone(cfg, reading="lenient", verify=verify).to_json(),
        "d": p.d,
        "w_max": cfg.plant.w_max,
        "a": cfg.plant.a,
        "sample_time": cfg.plant.sample_time,
    }
