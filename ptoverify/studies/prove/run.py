"""``ptoverify prove``: proofs over the continuum of initial states, per law.

For each sub-interval of the plant's a (one point, the nominal a, by default)
:mod:`.ball` certifies the target, proves no stride-over and builds the
macro-step images per block of cells (the jobs a cluster runs), then the
longest-path bounds.  A cell's verdict over an a-interval is the conjunction
(and its bound the maximum) over the sub-intervals, so it holds for every
constant a in it.  :func:`prove_law` gathers the per-cell results into the
properties.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from flint import arb

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.intervals import add, div, down, mul
from ptoverify.model.lawbox import enclose, law_spec
from ptoverify.model.laws import make_law
from ptoverify.model.plant import step
from ptoverify.studies.prove.ball import (
    BallResult,
    Resolution,
    assemble_ball,
    ball_target,
    cell_blocks,
    law_grid,
    prove_ball,
    prove_block,
)
from ptoverify.studies.prove.graph import Grid
from ptoverify.studies.prove.stride import Counterexample, find_counterexample
from ptoverify.studies.prove.target import Target, make_target
from ptoverify.studies.prove.work import check_proof_work, proof_work, sub_intervals

__all__ = [
    "Resolution",
    "BallResult",
    "PropertyResult",
    "LawProof",
    "prove_ball",
    "prove_law",
    "min_time_lower",
    "check_provable",
]


@dataclass(frozen=True)
class PropertyResult:
    """One proved (or not) property.

    Attributes
    ----------
    name : str
        Property name.
    status : str
        ``proved``, ``refuted`` or ``unproven``.
    coverage : float
        Fraction of the envelope's area where it is proved [-].
    counterexample : Counterexample or None
        A certified counterexample (``refuted``).
    unproven_region : dict or None
        Where the proof fails: cell count, bounding box [mm, mm/s], a few cells.
    detail : str
        One line.
    """

    name: str
    status: str
    coverage: float
    counterexample: Counterexample | None = None
    unproven_region: dict | None = None
    detail: str = ""

    def to_json(self) -> dict:
        """Plain JSON object."""
        return {
            "name": self.name,
            "status": self.status,
            "coverage": self.coverage,
            "counterexample": self.counterexample.to_json() if self.counterexample else None,
            "unproven_region": self.unproven_region,
            "detail": self.detail,
        }


@dataclass(frozen=True)
class LawProof:
    """Everything ``prove`` establishes for one law.

    Attributes
    ----------
    law : str
        Law name.
    a_interval : tuple of float
        The plant's a [rad/s] the proof covers (lo, hi).
    properties : tuple of PropertyResult
        Input bound, no stride-over (strict, relaxed), reach.
    target : Target
        The certified ellipse.
    bound_samples : int or None
        Largest certified bound over the proved cells [samples].
    simulated_worst_samples : int or None
        Largest simulated number of samples to the same ellipse [samples].
    simulated_states : int
        States simulated [-].
    simulation_over_bound : int
        Simulated states that needed more samples than their cell's bound (must be 0).
    certified_max_ratio_nt : float or None
        Certified upper bound on (samples to the target) / N* outside ``excluded_radius`` [-].
    excluded_radius : float
        |x1| below which the ratio is not bounded [mm].
    cells : int
        Number of cells [-].
    grid : Grid
        The cells.
    bound : ndarray
        Per-cell certified bound (max over sub-intervals) [samples]; inf: unproven.
    balls : tuple of BallResult
        Per sub-interval results.
    ratio_nt : ndarray or None
        Per-cell certified (samples to the target) / N* [-]; NaN where unproven or
        within ``excluded_radius`` (the certified suboptimality map).
    timings_s : dict
        Wall time per stage [s].
    """

    law: str
    a_interval: tuple
    properties: tuple
    target: Target
    bound_samples: int | None
    simulated_worst_samples: int | None
    simulated_states: int
    simulation_over_bound: int
    certified_max_ratio_nt: float | None
    excluded_radius: float
    cells: int
    grid: Grid
    bound: np.ndarray
    balls: tuple
    ratio_nt: np.ndarray | None = None
    timings_s: dict = field(default_factory=dict)

    def property(self, name: str) -> PropertyResult:
        """Return the property called ``name``."""
        return next(p for p in self.properties if p.name == name)

    def to_json(self) -> dict:
        """Return the ``prove --json`` object of this law."""
        return {
            "law": self.law,
            "a_interval": list(self.a_interval),
            "properties": {p.name: p.to_json() for p in self.properties},
            "target": {
                "P": [list(r) for r in self.target.P],
                "c": self.target.c,
                "certified": self.target.certified,
                "reason": self.target.reason,
            },
            "bound_samples": self.bound_samples,
            "simulated_worst_samples": self.simulated_worst_samples,
            "simulated_states": self.simulated_states,
            "simulation_over_bound": self.simulation_over_bound,
            "suboptimality": {
                "certified_max_ratio_nt": self.certified_max_ratio_nt,
                "excluded_radius": self.excluded_radius,
            },
            "cells": self.cells,
            "timings_s": self.timings_s,
        }


def _envelope_weights(cfg: Config, grid: Grid):
    """Area of each cell inside the envelope |x1| <= position_range [mm mm/s]."""
    b = grid.boxes()
    r = cfg.plant.position_range
    width = np.clip(np.minimum(b[1], r) - np.maximum(b[0], -r), 0.0, None)
    return b, width * (b[3] - b[2])


def _region(b, bad, area) -> dict | None:
    """Summary of the cells where a proof fails."""
    if not bad.any():
        return None
    i = np.flatnonzero(bad)
    cells = [[float(b[q][c]) for q in range(4)] for c in i[:5].tolist()]
    return {
        "cells": int(i.size),
        "area_fraction": float(area[bad].sum() / area.sum()),
        "bounding_box": [
            float(b[0][i].min()),
            float(b[1][i].max()),
            float(b[2][i].min()),
            float(b[3][i].max()),
        ],
        "first_cells": cells,
    }


def _status(name: str, ok, b, area, cex=None, detail="", gap=None) -> PropertyResult:
    """Build a property from per-cell verdicts (``gap``: unproven area per cell)."""
    inside = area > 0
    if gap is None:
        gap = np.where(ok, 0.0, area)
    cov = float(1.0 - gap[inside].sum() / area[inside].sum())
    if cex is not None:
        status = "refuted"
    elif bool(ok[inside].all()):
        status = "proved"
    else:
        status = "unproven"
    return PropertyResult(name, status, cov, cex, _region(b, ~ok & inside, area), detail)


def simulate_to_target(cfg: Config, name: str, target: Target, x1, x2, a: float, steps: int):
    """Count the samples each state needs to enter the ellipse, by exact ZOH stepping (floats).

    Parameters
    ----------
    cfg : Config
        Configuration.
    name : str
        Law name.
    target : Target
        The ellipse (a state counts as inside at x' P x <= c (1 + 1e-9)).
    x1, x2 : ndarray
        Initial states [mm], [mm/s].
    a : float
        The plant's bandwidth [rad/s].
    steps : int
        Horizon [samples].

    Returns
    -------
    ndarray of float
        First sample inside the ellipse; inf if not within ``steps``.
    """
    law = make_law(name, cfg)
    plant = cfg.with_plant(a=a).plant
    (p11, p12), (_, p22) = target.P
    level = target.c * (1 + 1e-9)
    first = np.full(x1.size, np.inf)
    # only the states not yet inside are stepped on (the law and the step act per state)
    live, y1, y2 = np.arange(x1.size), x1.copy(), x2.copy()
    for k in range(steps + 1):
        inside = p11 * y1 * y1 + 2 * p12 * y1 * y2 + p22 * y2 * y2 <= level
        first[live[inside]] = k
        out = ~inside
        live, y1, y2 = live[out], y1[out], y2[out]
        if not live.size:
            break
        u, _r = law(y1, y2)
        y1, y2 = step(y1, y2, u, plant)
    return first


def _simulate(cfg, name, target, grid, bound, a_values, n_random, seed=0):
    """Simulate the worst case to the ellipse from cell centres and seeded random states."""
    p = cfg.plant
    r = p.position_range
    b = grid.boxes()
    c1, c2 = 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])
    keep = np.abs(c1) <= r
    rng = np.random.default_rng(seed)
    x1 = np.concatenate([c1[keep], rng.uniform(-r, r, n_random)])
    x2 = np.concatenate([c2[keep], rng.uniform(-p.w_max, p.w_max, n_random)])
    i = np.clip(np.searchsorted(grid.e1, x1, "right") - 1, 0, grid.shape[0] - 1)
    j = np.clip(np.searchsorted(grid.e2, x2, "right") - 1, 0, grid.shape[1] - 1)
    cb = bound[j * grid.shape[0] + i]
    finite = np.isfinite(bound)
    horizon = int(bound[finite].max()) + 5 if finite.any() else 400
    worst, over = 0, 0
    for a in a_values:
        first = simulate_to_target(cfg, name, target, x1, x2, a, horizon)
        proved = np.isfinite(cb)
        over += int(np.count_nonzero(proved & (first > cb)))
        reached = first[proved & np.isfinite(first)]
        worst = max(worst, int(reached.max()) if reached.size else 0)
    return worst, over, x1.size


def min_time_lower(box, a_hi: float, w: float) -> np.ndarray:
    """Certified lower bound of the minimum time t_f* to the origin over boxes [s].

    For x1 > 0: whatever the input |u| <= w, x2(t) >= -w + (x2 + w) exp(-a t),
    so x1(t) >= x1 - w t + (x2 + w) (1 - exp(-a t)) / a, and with
    1 - exp(-s) >= s / (1 + s) and a <= a_hi, x1(t) > 0 while
    w t - x1 - (x2 + w) t / (1 + a_hi t) < 0, i.e. before the positive root of
    a_hi w t^2 - (a_hi x1 + x2) t - x1 = 0:
    t_f* >= ((a_hi x1 + x2) + sqrt((a_hi x1 + x2)^2 + 4 a_hi w x1)) / (2 a_hi w)
    (= x1 / w at x2 = -w).  The root increases in x1 and x2, so its minimum over
    a box right of x1 = 0 is at the lower-left corner; boxes left of it are
    mirrored ((x1, x2) -> (-x1, -x2)); boxes that meet x1 = 0 get 0.  Evaluated
    with outward rounding (np.sqrt is correctly rounded in IEEE 754).

    Parameters
    ----------
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s], within |x2| <= w.
    a_hi : float
        Largest plant bandwidth covered [rad/s] (the bound holds for every a <= a_hi).
    w : float
        Saturation w_max [mm/s].

    Returns
    -------
    ndarray
        Lower bounds of t_f* [s] (0 where the box meets x1 = 0).

    Examples
    --------
    >>> t = min_time_lower(tuple(np.array([v]) for v in (6.0, 7.0, -300.0, -290.0)), 100.0, 300.0)
    >>> bool(0.0199 < t[0] <= 0.02)
    True
    """
    x1lo, x1hi, x2lo, x2hi = (np.asarray(v, dtype=float) for v in box)
    right, left = x1lo > 0, x1hi < 0
    z1 = np.where(right, x1lo, np.where(left, -x1hi, 0.0))
    z2 = np.maximum(np.where(right, x2lo, np.where(left, -x2hi, -w)), -w)
    av = (a_hi, a_hi)
    s = add(mul(av, (z1, z1)), (z2, z2))
    sq = mul(s, s)
    four_aw = mul((4.0 * a_hi, 4.0 * a_hi), (w, w))  # 4 a_hi is exact
    disc = add((np.maximum(sq[0], 0.0), sq[1]), mul(four_aw, (z1, z1)))[0]
    root = down(np.sqrt(np.maximum(disc, 0.0)))
    num = add(s, (root, root))[0]
    den = mul((2.0 * a_hi, 2.0 * a_hi), (w, w))[1]
    t = div((num, num), (den, den))[0]
    return np.where(right | left, np.maximum(t, 0.0), 0.0)


def _ratio_per_cell(cfg, grid, bound, radius, a_hi) -> np.ndarray:
    """Certified bound / N* per cell: NaN where unproven or |x1| < radius (the suboptimality map).

    N* T >= t_f* (the sampled input is one continuous input), so N* >=
    ceil(:func:`min_time_lower` / T), with t_f* bounded for every a <= a_hi.
    """
    p = cfg.plant
    b = grid.boxes()
    near = np.where((b[0] < 0) & (b[1] > 0), 0.0, np.minimum(np.abs(b[0]), np.abs(b[1])))
    use = (near >= radius) & (np.abs(b[0]) <= p.position_range) & (np.abs(b[1]) <= p.position_range)
    use &= np.isfinite(bound)  # over the proved cells
    out = np.full(bound.shape, np.nan)
    if use.any():
        t_lo = min_time_lower(tuple(v[use] for v in b), a_hi, p.w_max)
        n_star = np.ceil(div((t_lo, t_lo), (p.sample_time, p.sample_time))[0])
        out[use] = bound[use] / n_star
    return out


def _suboptimality(ratio: np.ndarray) -> float | None:
    """Certified max of bound / N* over the cells of :func:`_ratio_per_cell` (None: none)."""
    return float(np.nanmax(ratio)) if np.isfinite(ratio).any() else None


def _counterexample(spec, cfg, balls, reading, tries: int = 3):
    """Search the failing leaves of the sub-intervals with the largest gaps for a stride-over.

    Each of the ``tries`` sub-intervals where the reading fails over the largest
    area is searched with the plant's a at its upper end, middle and lower end.
    """
    gaps = [float(getattr(bl.stride, reading + "_gap").sum()) for bl in balls]
    order = [q for q in np.argsort(gaps)[::-1] if gaps[q] > 0][:tries]
    first = None
    for q in order:
        bl = balls[q]
        leaves = bl.stride.leaves
        for a in dict.fromkeys((bl.a_hi, 0.5 * (bl.a_lo + bl.a_hi), bl.a_lo)):
            cex = find_counterexample(
                spec,
                cfg,
                leaves,
                np.ones(leaves[0].size, dtype=bool),
                relaxed=reading == "relaxed",
                a_plant=a,
            )
            if cex is not None and cex.confirmed_by_simulation:
                return cex
            first = first or cex
    return first


#: Fewest cells of the finest width across the envelope's half-width for a proof grid.
MIN_CELLS_ACROSS = 100


def check_provable(
    cfg: Config,
    res: Resolution,
    spec=None,
    pieces: list[tuple[float, float]] | None = None,
    excursion: float = 0.0,
) -> None:
    """Reject up front a configuration the proof grid cannot serve (one line, exit 2).

    The grid's cell sizes are absolute (``res``, in mm and mm/s); an envelope narrower
    than :data:`MIN_CELLS_ACROSS` of the finest cells, or a linear zone as wide as the
    envelope, leaves no grid to prove on.  With the law, its estimated work
    (:mod:`ptoverify.studies.prove.work`) must be within the stated limits.

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm], d [mm]).
    res : Resolution
        Grid settings (h1 [mm]).
    spec : LawSpec, optional
        The law; with it the proof's work is estimated and checked.
    pieces : list of tuple of float, optional
        Sub-intervals of a [rad/s] (default the nominal a).
    excursion : float
        Margin beyond the envelope [mm].

    Raises
    ------
    InputError
        Naming the key and the limit.
    """
    r, d = cfg.plant.position_range, cfg.pto.d
    if r < MIN_CELLS_ACROSS * res.h1:
        raise InputError(
            f"prove: plant.position_range = {r:g} mm is under {MIN_CELLS_ACROSS} proof cells "
            f"of {res.h1:g} mm (at least {MIN_CELLS_ACROSS * res.h1:g} mm)"
        )
    if d >= r:
        raise InputError(
            f"prove: pto.d = {d:g} mm fills the envelope |x1| <= {r:g} mm (d must be smaller)"
        )
    if spec is not None:
        a = cfg.plant.a
        check_proof_work(proof_work(cfg, spec, res, pieces or [(a, a)], excursion), cfg)


def prove_law(
    cfg: Config,
    name: str,
    *,
    a_interval: tuple[float, float] | None = None,
    pieces: int = 1,
    excursion: float = 0.0,
    res: Resolution | None = None,
    n_random: int = 20_000,
    mapper=map,
    excluded_radius: float | None = None,
    block_cells: int | None = None,
) -> LawProof:
    """Prove the properties of one law over the envelope.

    Parameters
    ----------
    cfg : Config
        Configuration.
    name : str
        ``pto``, ``pto-printed``, ``pd`` or ``to``.
    a_interval : tuple of float, optional
        The plant's a [rad/s] (lo, hi); default the nominal a.
    pieces : int
        Sub-intervals the a-interval is split into.
    excursion : float
        Margin beyond the envelope the images may use [mm].
    res : Resolution, optional
        Grid settings.
    n_random : int
        Seeded random states simulated besides the cell centres.
    mapper : callable
        ``map``-like callable running the jobs, one per sub-interval and block of
        cells (in-process or a cluster's).
    excluded_radius : float, optional
        Neighbourhood |x1| < radius [mm] left out of the suboptimality bound
        (default a tenth of position_range).
    block_cells : int, optional
        Cells per job (default all: one job per sub-interval); the result does
        not depend on it.

    Returns
    -------
    LawProof
        The proof.
    """
    t0 = time.perf_counter()
    p = cfg.plant
    res = res or Resolution()
    spec = law_spec(name, cfg)
    lo, hi = a_interval or (p.a, p.a)
    check_provable(cfg, res, spec, sub_intervals(lo, hi, pieces), excursion)
    target = make_target(arb(p.a), p.a, p.sample_time, spec.g1, spec.g2, spec.d, p.w_max)
    if not math.isfinite(spec.d) or spec.d > 0:
        pass
    else:  # no linear zone (TO): no target
        target = Target(target.P, 0.0, False, "the law has no linear zone: no target ellipse")
    grid = law_grid(cfg, spec, res, excursion)
    pieces = sub_intervals(lo, hi, pieces)
    targets = [ball_target(cfg, spec, a0, a1, target) for a0, a1 in pieces]
    blocks = cell_blocks(grid.size, block_cells)
    jobs = [
        (cfg, spec, a0, a1, res, excursion, tq, block)
        for (a0, a1), tq in zip(pieces, targets)
        for block in blocks
    ]
    done = list(mapper(_run_block, jobs))
    nb = len(blocks)
    balls = tuple(
        assemble_ball(cfg, spec, a0, a1, res, excursion, tq, done[q * nb : (q + 1) * nb])
        for q, ((a0, a1), tq) in enumerate(zip(pieces, targets))
    )
    t1 = time.perf_counter()
    bound = np.max(np.stack([bl.bound for bl in balls]), axis=0)
    b, area = _envelope_weights(cfg, grid)
    enc = enclose(spec, b)
    input_ok = (enc.lo >= -p.w_max) & (enc.hi <= p.w_max)
    props = [_status("input-bound", input_ok, b, area, detail="|u| <= w_max over every cell")]
    full = (b[1] - b[0]) * (b[3] - b[2])
    for reading in ("strict", "relaxed"):
        ok = np.logical_and.reduce([getattr(bl.stride, reading) for bl in balls])
        gap = np.minimum(sum(getattr(bl.stride, reading + "_gap") for bl in balls), full)
        cex = None
        if not ok[area > 0].all() and math.isfinite(spec.d):
            cex = _counterexample(spec, cfg, balls, reading)
        note = ""
        if cex is not None and not cex.confirmed_by_simulation:  # refuted needs both
            note = f"; a state certified in arb but not confirmed by simulate: {cex.x0}"
            cex = None
        depth = max(bl.stride.depth for bl in balls)
        props.append(
            _status(
                f"no-stride-over-{reading}",
                ok,
                b,
                area,
                cex,
                detail=f"cells refined up to {depth} times where the first check failed{note}",
                gap=gap * np.where(full > 0, area / full, 0.0),
            )
        )
    tgt = (
        balls[0].target
        if all(bl.target.certified for bl in balls)
        else next(bl.target for bl in balls if not bl.target.certified)
    )
    detail = "" if tgt.certified else f"no certified target: {tgt.reason}"
    props.append(_status("reach", np.isfinite(bound), b, area, detail=detail))
    t2 = time.perf_counter()
    finite = np.isfinite(bound) & (area > 0)
    worst = over = n_sim = None
    if tgt.certified and finite.any():
        a_values = np.linspace(lo, hi, 9) if hi > lo else [p.a]
        worst, over, n_sim = _simulate(cfg, name, target, grid, bound, a_values, n_random)
    t3 = time.perf_counter()
    radius = 0.1 * p.position_range if excluded_radius is None else excluded_radius
    ratio = (
        _ratio_per_cell(cfg, grid, bound, radius, hi)
        if tgt.certified
        else np.full(bound.shape, np.nan)
    )
    return LawProof(
        law=name,
        a_interval=(float(lo), float(hi)),
        properties=tuple(props),
        target=tgt,
        bound_samples=int(bound[finite].max()) if finite.any() else None,
        simulated_worst_samples=worst,
        simulated_states=n_sim or 0,
        simulation_over_bound=over or 0,
        certified_max_ratio_nt=_suboptimality(ratio),
        excluded_radius=radius,
        cells=grid.size,
        grid=grid,
        bound=bound,
        balls=balls,
        ratio_nt=ratio,
        timings_s={
            "proof": round(t2 - t0, 3),
            "cells_and_graph": round(t1 - t0, 3),
            "simulation": round(t3 - t2, 3),
        },
    )


def _run_block(job):
    """Run :func:`~ptoverify.studies.prove.ball.prove_block` on a job tuple (picklable)."""
    return prove_block(*job)
