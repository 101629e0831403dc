"""The zone's principle: the margin by which one sample under -w_max stays inside it."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config, Plant
from ptoverify.model.curves import level_curve_x1, level_residual, level_term, root_22
from ptoverify.model.memo import memo
from ptoverify.model.plant import flow
from ptoverify.verdict import tie_band

from .types import READINGS


# ------------------------------------------------------------------ principle
def _tol(cfg: Config) -> float:
    """Curve tie band of :func:`ptoverify.verdict.tie_band` for ``cfg`` [mm/s]."""
    return tie_band(cfg.plant.w_max, cfg.plant.a, cfg.plant.position_range)


def _l1star_x1(x2: NDArray[np.float64], a: float, omega0: ArrayLike) -> NDArray[np.float64]:
    """x1 on l1* at velocity x2 < 0 (eq. 13); omega0 <= 0 gives the limit x1 = -x2 / a."""
    omega0 = np.asarray(omega0, dtype=float)
    with np.errstate(all="ignore"):
        if np.all(omega0 <= 0.0):  # the limit everywhere (smallest_d): no curve to evaluate
            return np.broadcast_to(-x2 / a, np.broadcast_shapes(x2.shape, omega0.shape))
        return np.where(
            omega0 <= 0.0, -x2 / a, level_curve_x1(x2, a, np.where(omega0 <= 0.0, 1.0, omega0))
        )


def _source_intervals(
    cfg: Config,
    omega0: ArrayLike,
    x2: NDArray[np.float64],
    d: float,
    l2: NDArray[np.float64] | None = None,
):
    """Left/right ends of the source x1-intervals at each velocity (u = -w_max, |x1| >= d).

    Returns two intervals (lo, hi) per velocity, of the broadcast shape of
    ``omega0`` [mm/s] and ``x2`` [mm/s] for the first (right of l1*, x1 >= d) and
    of ``x2`` for the second (l2 <= x1 <= -d); an empty one has lo > hi.  ``l2``:
    :func:`_velocity_terms`' x1 on l2 at ``x2`` when the caller has it.
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    neg = x2 < 0
    l1s = np.where(neg, _l1star_x1(np.where(neg, x2, -1.0), a, np.minimum(omega0, w)), 0.0)
    lo_a = np.where(neg, np.maximum(l1s, d), d)  # right piece: x1 >= d
    return (lo_a, np.inf), _l2_sources(cfg, x2, d, l2)


def _l2_sources(
    cfg: Config, x2: NDArray[np.float64], d: float, l2: NDArray[np.float64] | None = None
):
    """Return the left piece of the sources, l2 <= x1 <= -d (free of omega0)."""
    pos = x2 > 0
    if l2 is None:
        l2 = _l2_x1(cfg.plant, x2)
    lo_b = np.where(pos & (l2 <= -d), l2, np.inf)
    hi_b = np.full_like(x2, -d)
    return lo_b, hi_b


def _l2_x1(plant: Plant, x2: NDArray[np.float64]) -> NDArray[np.float64]:
    """x1 on l2 at the velocities x2 > 0 (others: at x2 = 1, unused) [mm]."""
    with np.errstate(all="ignore"):
        return level_curve_x1(np.where(x2 > 0, x2, 1.0), plant.a, plant.w_max)


def _velocity_terms(plant: Plant, x2: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
    """Return what :func:`principle_margin` reads off the velocity alone (no omega0, no d).

    (c1, term, l2): the landing after one sample under -w_max is F1 = x1 + c1 with
    sigma(F) = a F1 + term, and l2's x1 at ``x2`` (:func:`_l2_x1`).
    """
    a, w = plant.a, plant.w_max
    c1, f2 = flow(0.0, x2, -w, plant.sample_time, a)  # F1 = x1 + c1, F2 = f2
    with np.errstate(all="ignore"):
        term = level_term(f2, w)  # sigma(F) = a F1 + term: the part that is x1-free
    return c1, term, _l2_x1(plant, x2)


#: The even velocities of :func:`_worst_margins` (their number).
EVEN_POINTS = 4001


@memo(maxsize=64)
def _even_velocities(plant: Plant) -> tuple[NDArray[np.float64], ...]:
    """Return the :data:`EVEN_POINTS` even velocities over [-w_max, w_max] and their terms.

    Once per plant (read-only arrays): x2 and :func:`_velocity_terms` of it.
    """
    x2 = np.linspace(-plant.w_max, plant.w_max, EVEN_POINTS)
    out = (x2, *_velocity_terms(plant, x2))
    for arr in out:
        arr.setflags(write=False)
    return out


def principle_margin(
    cfg: Config,
    omega0: float | NDArray[np.float64],
    x2: NDArray[np.float64] | None = None,
    *,
    reading: str = "strict",
    d: float | None = None,
    points: int = EVEN_POINTS,
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
        Number of velocities when ``x2`` is not given (the default grid and what
        depends on its velocities alone are computed once per plant).

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
    w = cfg.plant.w_max
    if x2 is None:
        if points == EVEN_POINTS:  # the default grid: its velocity terms are kept per plant
            x2, *terms = _even_velocities(cfg.plant)
            return _margin_at(cfg, omega0, x2, terms, reading, d)
        x2 = np.linspace(-w, w, points)
    x2 = np.asarray(x2, dtype=float)
    return _margin_at(cfg, omega0, x2, _velocity_terms(cfg.plant, x2), reading, d)


def _margin_at(cfg: Config, omega0, x2, terms, reading: str, d: float | None):
    """:func:`principle_margin` at velocities ``x2`` whose :func:`_velocity_terms` are given."""
    if reading not in READINGS:
        raise ValueError(f"reading must be one of {READINGS}")
    a = cfg.plant.a
    d = cfg.pto.d if d is None else d
    c1, term, l2 = terms
    (lo_a, hi_a), (lo_b, hi_b) = _source_intervals(cfg, omega0, x2, d, l2)
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
        y_l2 = _l2_kink(a, w, d)
        it = iter(ys)
        for lst, om, inside in zip(out, omegas.tolist(), zone.tolist(), strict=True):
            if inside:
                lst.append(-om * float(next(it)))
            elif om <= 0:
                lst.append(-a * d)
            lst.append(y_l2)
    return [[v for v in lst if -w <= v <= w] for lst in out]


@memo(maxsize=256)
def _l2_kink(a: float, w: float, d: float) -> float:
    """Velocity [mm/s] where l2 meets x1 = -d: w_max y, h(y) = a d / w_max (free of omega0)."""
    return w * float(root_22(a * d / w))


def _worst_margin(cfg: Config, omega0: float, reading: str, d: float | None = None) -> float:
    """Dense worst margin over |x2| <= w_max [mm/s] (:func:`_worst_margins` of one omega0)."""
    return _worst_margins(cfg, np.array([float(omega0)]), reading, d)[0]


def _worst_margins(
    cfg: Config,
    omegas: NDArray[np.float64],
    reading: str,
    d: float | None = None,
    *,
    floor: float = -np.inf,
) -> list[float]:
    """Dense worst margin over |x2| <= w_max for each omega0 of an array [mm/s].

    4001 even velocities, the kinks of :func:`_kinks` (the minimum often sits on
    one, where a coarse grid would miss it by slope x spacing), and 201 points
    around each of the 8 lowest local minima of the even grid.  The even grids of
    all omega0 are one broadcast :func:`principle_margin` call and the refinement
    points (different per omega0) one elementwise call.

    An omega0 whose even grid already falls below ``floor`` [mm/s] is not refined
    (the refinement can only lower its minimum): its value is that of the even grid,
    below ``floor`` as its worst margin is, which is all a test ``>= floor`` reads.
    """
    w = cfg.plant.w_max
    d = cfg.pto.d if d is None else d
    omegas = np.asarray(omegas, dtype=float).ravel()
    x2 = _even_velocities(cfg.plant)[0]  # principle_margin's default velocities
    M = principle_margin(cfg, omegas[:, None], reading=reading, d=d)
    lows = M.min(axis=1)
    refine = np.flatnonzero(~(lows < floor))  # (NaN rows refined as before)
    step = x2[1] - x2[0]
    is_min = (M[:, 1:-1] <= M[:, :-2]) & (M[:, 1:-1] <= M[:, 2:])
    kinks = _kinks_many(cfg, omegas[refine], d)
    fines = []
    for k, kink in zip(refine.tolist(), kinks, strict=True):
        loc = np.flatnonzero(is_min[k]) + 1
        loc = loc[np.argsort(M[k][loc])[:8]]
        bands = np.linspace(x2[loc] - step, x2[loc] + step, 201, axis=1).ravel()
        fines.append(np.clip(np.concatenate([np.array(kink), bands]), -w, w))
    out = [float(v) for v in lows]
    if not fines:
        return out
    sizes = np.array([f.size for f in fines])
    pts = np.concatenate(fines)
    fm = principle_margin(cfg, np.repeat(omegas[refine], sizes), pts, reading=reading, d=d)
    ends = np.cumsum(sizes)
    for k, n, end in zip(refine.tolist(), sizes.tolist(), ends.tolist(), strict=True):
        out[k] = float(min(M[k].min(), fm[end - n : end].min(initial=np.inf)))
    return out


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
