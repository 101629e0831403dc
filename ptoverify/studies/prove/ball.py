"""One sub-interval of a: the grid, the per-cell work in blocks, the bounds.

:func:`ball_target` certifies the target's decrease for the sub-interval;
:func:`prove_block` proves no stride-over and builds the macro-step images of
a block of consecutive cells (every cell's result depends on that cell only,
so blocks may run anywhere, e.g. on a dask cluster); :func:`assemble_ball`
joins the blocks in cell order and computes the longest-path bounds on the
whole graph; :func:`prove_ball` does all three in-process.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from flint import arb

from ptoverify.config import Config
from ptoverify.model.lawbox import LawSpec
from ptoverify.model.zohmaps import a_ball, step_maps
from ptoverify.studies.prove.graph import (
    Grid,
    Images,
    images,
    longest_path,
    make_grid,
    successors,
)
from ptoverify.studies.prove.stride import StrideResult, stride_check
from ptoverify.studies.prove.target import Target, box_in_target, certify_decrease

__all__ = [
    "Resolution",
    "fine_extent",
    "BallResult",
    "BlockResult",
    "law_grid",
    "ball_target",
    "cell_blocks",
    "prove_block",
    "assemble_ball",
    "prove_ball",
]


@dataclass(frozen=True)
class Resolution:
    """Grid and macro-step settings.

    Attributes
    ----------
    h1 : float
        Cell width near the origin and the zones [mm].
    h2 : float
        Cell height [mm/s].
    h1_max : float
        Largest cell width [mm].
    h_edge : float
        Cell width at the envelope's edge [mm].
    steps : int
        Longest macro-step [samples].
    """

    h1: float = 0.02
    h2: float = 5.0
    h1_max: float = 2.0
    h_edge: float = 0.05
    steps: int = 200


def fine_extent(spec: LawSpec) -> float:
    """Half-width of the finely gridded strip [mm]: the zones, the curves, the linear zone.

    Parameters
    ----------
    spec : LawSpec
        The law.

    Returns
    -------
    float
        |x1| below which cells have the fine width, one millimetre beyond the
        widest of the linear zone, the switching curves within |x2| <= w_max
        (eqs. 9, 13) and w_max / g1 [mm].
    """
    w = spec.w_max
    level = spec.omega0 if spec.has_zone else w
    curve = level * (w / level - math.log1p(w / level)) / spec.a
    extent = max(curve, w / spec.g1 if spec.g1 > 0 else 0.0)
    if math.isfinite(spec.d):
        extent = max(extent, spec.d)
    return extent + 1.0


@dataclass(frozen=True)
class BallResult:
    """Per-cell results for one sub-interval of a.

    Attributes
    ----------
    a_lo, a_hi : float
        The plant's bandwidth interval [rad/s].
    target : Target
        The ellipse (decrease certified for this interval when ``certified``).
    bound : ndarray
        Certified samples to the target per cell; inf: unproven.
    stride : StrideResult
        No stride-over per cell, in each reading.
    k : ndarray of int
        Samples of each cell's macro-step.
    image : tuple of ndarray
        Each cell's macro-step image box [mm], [mm/s].
    u_lo, u_hi : ndarray
        Input enclosure per cell [mm/s].
    exits : ndarray of bool
        The image leaves the grid.
    """

    a_lo: float
    a_hi: float
    target: Target
    bound: np.ndarray
    stride: StrideResult
    k: np.ndarray
    image: tuple
    u_lo: np.ndarray
    u_hi: np.ndarray
    exits: np.ndarray


def law_grid(cfg: Config, spec: LawSpec, res: Resolution, excursion: float) -> Grid:
    """Return the grid of a proof: the envelope widened by ``excursion`` [mm] along x1.

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm], w_max [mm/s]).
    spec : LawSpec
        The law.
    res : Resolution
        Grid settings.
    excursion : float
        Margin allowed beyond the envelope [mm].

    Returns
    -------
    Grid
        The grid.
    """
    p = cfg.plant
    return make_grid(
        p.position_range + excursion,
        p.w_max,
        fine_extent(spec),
        res.h1,
        res.h2,
        res.h1_max,
        res.h_edge,
    )


def ball_target(cfg: Config, spec: LawSpec, a_lo: float, a_hi: float, target: Target) -> Target:
    """Return the target with its decrease certified for every a in [a_lo, a_hi] (or not).

    Parameters
    ----------
    cfg : Config
        Configuration (the sampling period [s]).
    spec : LawSpec
        The law (its linear gains).
    a_lo, a_hi : float
        The plant's bandwidth interval [rad/s].
    target : Target
        Ellipse built for the nominal a.

    Returns
    -------
    Target
        ``target``, or a copy marked not certified with the reason.
    """
    ball = arb(a_lo) if a_lo == a_hi else a_ball(a_lo, a_hi)
    T = cfg.plant.sample_time  # noqa: N806
    if target.certified and not certify_decrease(target.P, ball, T, spec.g1, spec.g2):
        return Target(target.P, target.c, False, "decrease not certified for this a-interval")
    return target


def cell_blocks(n: int, size: int | None) -> list[tuple[int, int]]:
    """Split cells 0..n-1 into consecutive blocks of at most ``size`` cells.

    Parameters
    ----------
    n : int
        Number of cells.
    size : int or None
        Cells per block; None: one block.

    Returns
    -------
    list of tuple of int
        (start, stop) per block.

    Examples
    --------
    >>> cell_blocks(10, 4)
    [(0, 4), (4, 8), (8, 10)]
    """
    size = n if not size else max(1, int(size))
    return [(i, min(i + size, n)) for i in range(0, n, size)]


@dataclass(frozen=True)
class BlockResult:
    """Per-cell results of a block of consecutive cells (one sub-interval of a).

    Attributes
    ----------
    start, stop : int
        The cells start..stop-1 [-].
    stride : StrideResult
        No stride-over of the block's cells.
    images : Images
        Their macro-step images.
    """

    start: int
    stop: int
    stride: StrideResult
    images: Images


def prove_block(
    cfg: Config,
    spec: LawSpec,
    a_lo: float,
    a_hi: float,
    res: Resolution,
    excursion: float,
    target: Target,
    block: tuple[int, int],
) -> BlockResult:
    """Prove no stride-over and build the images of the cells in ``block``.

    Parameters
    ----------
    cfg : Config
        Configuration.
    spec : LawSpec
        The law.
    a_lo, a_hi : float
        The plant's bandwidth interval [rad/s].
    res : Resolution
        Grid settings.
    excursion : float
        Margin allowed beyond the envelope [mm].
    target : Target
        The ellipse as :func:`ball_target` returned it for this interval.
    block : tuple of int
        (start, stop): the cells start..stop-1 of :func:`law_grid`.

    Returns
    -------
    BlockResult
        The block's per-cell results.
    """
    p = cfg.plant
    start, stop = block
    boxes = tuple(v[start:stop] for v in law_grid(cfg, spec, res, excursion).boxes())
    gains = (spec.g1, spec.g2) if target.certified else None
    maps = step_maps((a_lo, a_hi), p.sample_time, res.steps, gains=gains)
    stride = stride_check(spec, cfg, maps, boxes)
    img = images(spec, maps, target, boxes, p.position_range + excursion, res.steps)
    return BlockResult(start, stop, stride, img)


def assemble_ball(
    cfg: Config,
    spec: LawSpec,
    a_lo: float,
    a_hi: float,
    res: Resolution,
    excursion: float,
    target: Target,
    blocks: list,
) -> BallResult:
    """Join a sub-interval's blocks in cell order and compute the longest-path bounds.

    Parameters
    ----------
    cfg : Config
        Configuration.
    spec : LawSpec
        The law.
    a_lo, a_hi : float
        The plant's bandwidth interval [rad/s].
    res : Resolution
        Grid settings.
    excursion : float
        Margin allowed beyond the envelope [mm].
    target : Target
        The ellipse as :func:`ball_target` returned it for this interval.
    blocks : list of BlockResult
        Blocks covering every cell once (any order).

    Returns
    -------
    BallResult
        Per-cell results of the sub-interval.
    """
    grid = law_grid(cfg, spec, res, excursion)
    blocks = sorted(blocks, key=lambda b: b.start)
    if [b.start for b in blocks] != [0, *[b.stop for b in blocks[:-1]]] or (
        blocks[-1].stop != grid.size
    ):
        raise ValueError("the blocks do not cover the cells once, in order")
    st = [b.stride for b in blocks]
    im = [b.images for b in blocks]

    def cat(values):
        return np.concatenate(values)

    stride = StrideResult(
        cat([s.strict for s in st]),
        cat([s.relaxed for s in st]),
        cat([s.strict_gap for s in st]),
        cat([s.relaxed_gap for s in st]),
        tuple(cat([s.leaves[q] for s in st]) for q in range(4)),
        max(s.depth for s in st),
    )
    img = Images(
        cat([i.k for i in im]),
        tuple(cat([i.box[q] for i in im]) for q in range(4)),
        cat([i.to_target for i in im]),
        cat([i.u_lo for i in im]),
        cat([i.u_hi for i in im]),
    )
    starts, succ, exits = successors(grid.e1, grid.e2, img)
    if target.certified:
        in_target = box_in_target(target, grid.boxes())
        bound = longest_path(starts, succ, img.k, in_target, img.to_target, exits)
    else:
        bound = np.full(grid.size, np.inf)
    return BallResult(a_lo, a_hi, target, bound, stride, img.k, img.box, img.u_lo, img.u_hi, exits)


def prove_ball(
    cfg: Config,
    spec: LawSpec,
    a_lo: float,
    a_hi: float,
    res: Resolution,
    excursion: float,
    target: Target,
) -> BallResult:
    """Prove reach and no stride-over on every cell for every a in [a_lo, a_hi], in-process.

    Parameters
    ----------
    cfg : Config
        Configuration (the law is designed with its a).
    spec : LawSpec
        The law.
    a_lo, a_hi : float
        The plant's bandwidth interval [rad/s].
    res : Resolution
        Grid settings.
    excursion : float
        Margin allowed beyond the envelope [mm].
    target : Target
        Ellipse (built for the nominal a); its decrease is certified here for the interval.

    Returns
    -------
    BallResult
        Per-cell results.
    """
    target = ball_target(cfg, spec, a_lo, a_hi, target)
    n = law_grid(cfg, spec, res, excursion).size
    block = prove_block(cfg, spec, a_lo, a_hi, res, excursion, target, (0, n))
    return assemble_ball(cfg, spec, a_lo, a_hi, res, excursion, target, [block])
