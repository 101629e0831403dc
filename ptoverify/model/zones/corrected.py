"""The corrected zone: the omega0 and d that meet the principle, and the zone per law."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config, PTOSettings
from ptoverify.model.curves import level_curve_x1, root_22
from ptoverify.model.memo import memo

from .margins import _tol, _worst_margin, _worst_margins, principle_violations
from .types import _NAN, PTOZone


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
    return np.array(_worst_margins(cfg, omegas, reading, floor=-tol)) >= -tol


@memo(maxsize=16)
def _feasible_intervals(cfg: Config, reading: str, scan: int) -> tuple[tuple[float, float], ...]:
    """Scan omega0 over (0, w_max], then bisect every edge of the feasible set."""
    w, tol = cfg.plant.w_max, _tol(cfg)
    grid = np.unique(
        np.concatenate([np.geomspace(1e-4 * w, w, scan // 2), np.linspace(w / scan, w, scan // 2)])
    )
    ok = _feasible_many(cfg, grid, reading, tol)

    def edge(good: float, bad: float) -> float:
        # bisection, up to 60 halvings until |good - bad| <= 1e-10 w_max, two halvings per
        # call: the midpoint and both midpoints that can follow it, each the one a halving
        # at a time computes (the same halvings, at two thirds of the cost)
        halvings = 0
        while halvings < 60:
            mid = 0.5 * (good + bad)
            nxt = (0.5 * (mid + bad), 0.5 * (good + mid))  # after mid: feasible, or not
            ok = _feasible_many(cfg, np.array([mid, *nxt]), reading, tol)
            good, bad = (mid, bad) if ok[0] else (good, mid)
            halvings += 1
            if abs(good - bad) <= 1e-10 * w or halvings == 60:
                break
            mid, ok_mid = (nxt[0], ok[1]) if ok[0] else (nxt[1], ok[2])
            good, bad = (mid, bad) if ok_mid else (good, mid)
            halvings += 1
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
        return _worst_margins(cfg, np.zeros(1), reading, d, floor=-tol)[0] >= -tol

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
        y_star=-x20 / w if math.isfinite(x20) else _NAN,  # eq. (22)'s y* = -x~20 / w_max
        k=k,
        z_star=y if math.isfinite(x20) else _NAN,  # eq. (26)'s z* = -x~20 / omega0
        valid=valid,
        degenerate=degenerate,
        reason="; ".join(parts),
        feasible_intervals=tuple(intervals),
        reading=reading,
        margin=margin,
        d_min=dmin,
        details=details,
    )
