"""The work of a proof, estimated from the configuration and checked up front.

What a proof's time and memory grow with (measured, :mod:`.ball`):

* the cells of the grid (:func:`~ptoverify.studies.prove.ball.law_grid`): every
  cell gets an input enclosure, up to 2 x ``Resolution.steps`` macro-step
  images, its successors and the longest-path bound;
* the cells the first no-stride-over check leaves open
  (:func:`~ptoverify.studies.prove.stride.unsettled_cells`): each is cut into
  8 x 8 boxes, again and again; a cell that fails on an area costs
  1 + 64 + 64^2 box checks before the cap stops it, and holds its failing boxes
  as leaves (the refinement runs :data:`~ptoverify.studies.prove.stride.REFINE_CHUNK`
  cells at a time, so its working memory is bounded per chunk).  Where one sample carries a state across many cells (large a T)
  or the yardstick d is 0, most cells near the switching curves stay open.

The estimate is, per sub-interval of a, ``cells + refined x 4,160`` box
checks: the cells are counted exactly from the grid's edges, the refined cells
by that first check itself (vectorized, one pass over the cells, well under a
second).  The estimate is not guaranteed, but it was an upper bound of the box
checks counted in every case measured, and close where the refined cells fail
on areas (the paper's ``to`` 2.2 % above them, the all-zero-gains ``pto`` 2.2 %,
``cascade-p`` 4 %, ``pd`` 22 %, ``pto`` 93 %); the guaranteed bound is
``cells + refined x 102,464`` (:func:`box_checks_bound`).  The limits are :data:`MAX_PROOF_CELLS`,
:data:`MAX_PROOF_WORK` and :data:`MAX_PROOF_PIECES`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.lawbox import LawSpec
from ptoverify.model.zohmaps import step_maps
from ptoverify.studies.prove.ball import Resolution, fine_extent, law_grid
from ptoverify.studies.prove.stride import (
    REFINE_CAP,
    REFINE_DEPTH,
    REFINE_SPLIT,
    unsettled_cells,
)

__all__ = [
    "ProofWork",
    "sub_intervals",
    "proof_work",
    "check_proof_work",
    "box_checks_bound",
    "MAX_PROOF_CELLS",
    "MAX_PROOF_WORK",
    "MAX_PROOF_PIECES",
    "BOXES_PER_REFINED_CELL",
]

#: Most cells of a proof grid.  The paper's largest grid is cascade-p's (103,920 cells,
#: 7.5 s and 0.37 GB on the 2-core reference machine); memory grows about linearly.
MAX_PROOF_CELLS = 400_000

#: Most estimated box checks per sub-interval of a (``cells + refined x 4,160``).  At the
#: paper's values ``to`` and ``pto-printed`` estimate 4.9 million (47-138 s, 0.65 GB);
#: ``pto`` 0.1, ``pd`` 0.65 and ``cascade-p`` 1.56 million.  Refused: a T = 20 (``to`` 80
#: million, passed 10 GB in 70 s) and every gain and d zero (``pto`` 12 million: 230 s,
#: 2.7 GB before the refinement ran in chunks).
MAX_PROOF_WORK = 8_000_000

#: Most sub-intervals of a (each is a whole proof): the widest ``[robustness] a_ratio``
#: [0.1, 10] makes 60 pieces of at most :data:`ptoverify.studies.prove.PIECE_RATIO`.
MAX_PROOF_PIECES = 64

#: Box checks of a refined cell that fails on an area: 64 children, then the 64 children of
#: each (the 4,096 are over the cap of 256 failing boxes, so the refinement stops there).
BOXES_PER_REFINED_CELL = REFINE_SPLIT + REFINE_SPLIT**2


def box_checks_bound(refined: int, cells: int) -> int:
    """Return the most box checks the no-stride-over refinement can make (a guaranteed bound).

    A refined cell is split at most ``REFINE_DEPTH / 3`` times; a split of a level
    with m failing boxes makes 64 m children, and a level goes on only while
    m <= ``REFINE_CAP``: 64, then at most 64^2, then at most 256 x 64 per level.

    Parameters
    ----------
    refined : int
        Cells the first check leaves open [-].
    cells : int
        Cells of the grid [-].

    Returns
    -------
    int
        ``cells`` plus ``refined`` times the per-cell maximum (102,464) [box checks].

    Examples
    --------
    >>> box_checks_bound(1, 0)
    102464
    """
    per_cell, failing = 0, 1
    for _ in range(REFINE_DEPTH // 3):
        per_cell += REFINE_SPLIT * failing
        failing = min(REFINE_SPLIT * failing, REFINE_CAP)
    return cells + refined * per_cell


@dataclass(frozen=True)
class ProofWork:
    """The estimated work of one law's proof.

    Attributes
    ----------
    law : str
        Law name.
    cells : int
        Cells of the grid [-] (exact).
    refined : tuple of int
        Per sub-interval of a, the cells the first no-stride-over check leaves open [-]
        (exact: the proof refines these).
    estimate : int
        Largest ``cells + refined x`` :data:`BOXES_PER_REFINED_CELL` over the
        sub-intervals [box checks].
    """

    law: str
    cells: int
    refined: tuple
    estimate: int

    @property
    def pieces(self) -> int:
        """Sub-intervals of a [-]."""
        return len(self.refined)


def _edges(lo: float, hi: float, pieces: int) -> np.ndarray:
    """Edges of the geometric sub-intervals of [lo, hi] (exact ends; [lo, lo] for a point)."""
    if hi > lo:
        edges = np.geomspace(lo, hi, pieces + 1)
        edges[0], edges[-1] = lo, hi  # exact ends
        return edges
    return np.array([lo, lo])


def sub_intervals(lo: float, hi: float, pieces: int) -> list[tuple[float, float]]:
    """Return the sub-intervals of a a proof runs on, geometric, with exact ends.

    Parameters
    ----------
    lo, hi : float
        The plant's a interval [rad/s] (lo == hi: the point).
    pieces : int
        Sub-intervals (1 for a point).

    Returns
    -------
    list of tuple of float
        (a_lo, a_hi) per sub-interval [rad/s].

    Examples
    --------
    >>> sub_intervals(100.0, 100.0, 3)
    [(100.0, 100.0)]
    """
    e = _edges(lo, hi, pieces)
    return [(float(e[q]), float(e[q + 1])) for q in range(len(e) - 1)]


def _cells_at_least(cfg: Config, spec: LawSpec, res: Resolution, excursion: float) -> int:
    """Return a lower bound of the grid's cells from its widths alone (no grid is built) [-].

    Along x1 the cells are h1 wide up to the fine extent and at most h1_max wide beyond
    (:func:`~ptoverify.studies.prove.graph.make_grid`); along x2 there are ceil(2 w / h2).
    """
    end = cfg.plant.position_range + excursion
    fine = min(fine_extent(spec), end)
    half = math.floor(fine / res.h1) + math.floor((end - fine) / res.h1_max)
    n2 = max(2, math.ceil(2 * cfg.plant.w_max / res.h2))
    return max(2, 2 * half - 2) * n2


def proof_work(
    cfg: Config,
    spec: LawSpec,
    res: Resolution,
    pieces: list[tuple[float, float]],
    excursion: float = 0.0,
) -> ProofWork:
    """Estimate a proof's work, refusing a grid over :data:`MAX_PROOF_CELLS` before building it.

    Parameters
    ----------
    cfg : Config
        Configuration.
    spec : LawSpec
        The law.
    res : Resolution
        Grid settings.
    pieces : list of tuple of float
        Sub-intervals (a_lo, a_hi) of the plant's a [rad/s].
    excursion : float
        Margin beyond the envelope [mm].

    Returns
    -------
    ProofWork
        Cells, refined cells per sub-interval, the estimate.

    Raises
    ------
    InputError
        More than :data:`MAX_PROOF_CELLS` cells or :data:`MAX_PROOF_PIECES` sub-intervals.
    """
    if len(pieces) > MAX_PROOF_PIECES:
        raise InputError(
            f"prove: {len(pieces)} sub-intervals of a (--a-interval), over the limit of "
            f"{MAX_PROOF_PIECES} (each is a whole proof; narrow the interval)"
        )
    low = _cells_at_least(cfg, spec, res, excursion)
    if low > MAX_PROOF_CELLS:
        _too_many_cells(cfg, spec.name, low, "at least ")
    grid = law_grid(cfg, spec, res, excursion)
    if grid.size > MAX_PROOF_CELLS:
        _too_many_cells(cfg, spec.name, grid.size, "")
    boxes = grid.boxes()
    refined = tuple(
        int(unsettled_cells(spec, cfg, step_maps((a0, a1), cfg.plant.sample_time, 1), boxes).sum())
        for a0, a1 in pieces
    )
    estimate = grid.size + max(refined) * BOXES_PER_REFINED_CELL
    return ProofWork(spec.name, grid.size, refined, estimate)


def _too_many_cells(cfg: Config, law: str, cells: int, qualifier: str) -> None:
    """Raise the one-line InputError of a grid over :data:`MAX_PROOF_CELLS`."""
    p = cfg.plant
    raise InputError(
        f"prove: law '{law}' needs {qualifier}{cells:,} proof cells (plant.position_range = "
        f"{p.position_range:g} mm, plant.w_max = {p.w_max:g} mm/s), over the limit of "
        f"{MAX_PROOF_CELLS:,}"
    )


def check_proof_work(work: ProofWork, cfg: Config) -> None:
    """Raise InputError, before the proof runs, when its estimate exceeds :data:`MAX_PROOF_WORK`.

    Parameters
    ----------
    work : ProofWork
        The estimate (:func:`proof_work`).
    cfg : Config
        Configuration (named in the message).

    Raises
    ------
    InputError
        One line naming the keys that set the work and the limit.
    """
    if work.estimate <= MAX_PROOF_WORK:
        return
    p = cfg.plant
    gains = {"pd": "pd.kp, pd.kd", "cascade-p": "cascade.kp"}.get(work.law, "pto.k1, pto.k2")
    raise InputError(
        f"prove: law '{work.law}' needs about {work.estimate:,} box checks per sub-interval "
        f"of a ({work.cells:,} cells, {max(work.refined):,} left open by the first "
        f"no-stride-over check, {BOXES_PER_REFINED_CELL:,} each), over the limit of "
        f"{MAX_PROOF_WORK:,}: it grows with a T = plant.a x plant.sample_time = "
        f"{p.a * p.sample_time:.4g} and as pto.d = {cfg.pto.d:g} mm and the gains ({gains}) shrink"
    )
