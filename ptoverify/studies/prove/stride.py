"""No stride-over, proved per cell, and certified counterexamples.

The definitions are :mod:`ptoverify.studies.properties`': a sample with
|x1| >= d (the PTO's d, the yardstick of every law), not in a switching zone,
on the S_N side of l1 - o - l2 (sigma >= 0) strides over when the next sample
has sigma < -tol (tol = :func:`ptoverify.verdict.tie_band`); the mirror for
S_P.  Strict reading: any such crossing fails.  Relaxed reading: a crossing
that lands in the linear strip |x1| < d is allowed.

Per cell, each piece outside the strip is mapped one sample with the input of
its bang-bang points (-w_max on the S_N side, +w_max on S_P; PD: the input's
enclosure over the piece), and the image's sigma is bounded by monotonicity
(sigma increases in x1 and x2).  A lemma closes the case the boxes cannot:
under u = -w_max, while x2 >= 0, sigma(x) = a x1 + w_max h(x2 / w_max) is
constant along the flow (d sigma / dt = a x2 + x2 / (w_max + x2) (-a x2 - a
w_max) = 0), so a state with sigma >= 0 and x2 >= 0 whose next x2 is >= 0
keeps sigma >= 0 (x2 is monotone over the sample); the mirror for u = +w_max.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from flint import arb, ctx

from ptoverify.config import Config
from ptoverify.model.intervals import ARB_PREC
from ptoverify.model.lawbox import LawSpec, enclose, sigma_point
from ptoverify.model.laws import make_law
from ptoverify.model.zohmaps import StepMaps, affine_image
from ptoverify.sim.simulate import simulate_batch
from ptoverify.verdict import tie_band

__all__ = [
    "stride_check",
    "unsettled_cells",
    "StrideResult",
    "Counterexample",
    "find_counterexample",
    "REFINE_SPLIT",
    "REFINE_DEPTH",
    "REFINE_CAP",
    "REFINE_CHUNK",
]

_SPLIT = 8  #: a failing box is cut into _SPLIT x _SPLIT children (three halvings)
#: Children of one refined box (:func:`stride_check`).
REFINE_SPLIT = _SPLIT * _SPLIT
#: Most halvings of a refined cell's sides (:func:`stride_check`'s ``depth``).
REFINE_DEPTH = 24
#: Most failing boxes of one cell carried to the next level (:func:`stride_check`'s ``cap``).
REFINE_CAP = 256
#: Cells refined together: at most 128 x 256 x 64 boxes (2.1 million) at a level.
REFINE_CHUNK = 128


def _sides(spec: LawSpec, piece, u_lo, u_hi, maps: StepMaps, d: float, tol: float):
    """Strict and relaxed verdicts of one outside piece per cell (bool arrays)."""
    w = spec.w_max
    one = np.ones(piece[0].size, dtype=np.intp)
    strict = np.ones(piece[0].size, dtype=bool)
    relaxed = strict.copy()
    bang = np.isfinite(spec.d)  # PTO and TO: S_N's non-zone points take -w_max
    # S_N candidates: sigma_w >= 0 possible (largest at the upper-right corner)
    s_hi = sigma_point(spec, piece[1], piece[3], w)[1]
    s_lo = sigma_point(spec, piece[0], piece[2], w)[0]
    for side in (-1.0, 1.0):  # the input of the side: -w on S_N, +w on S_P
        cand = (s_hi >= 0) if side < 0 else (s_lo <= 0)
        if bang:
            cand &= (u_lo <= -w) if side < 0 else (u_hi >= w)  # has bang-bang points
            u = (np.full(one.size, side * w),) * 2
        else:
            u = (u_lo, u_hi)
        img = affine_image(maps, one, piece, u)
        y2lo, y2hi = np.clip(img[2], -w, w), np.clip(img[3], -w, w)
        if side < 0:
            ok = sigma_point(spec, img[0], y2lo, w)[0] >= -tol
            if bang:
                ok |= (piece[2] >= 0) & (y2lo >= 0)  # the invariance lemma
        else:
            ok = sigma_point(spec, img[1], y2hi, w)[1] <= tol
            if bang:
                ok |= (piece[3] <= 0) & (y2hi <= 0)
        lands_in = (img[0] > -d) & (img[1] < d)
        strict &= ~cand | ok
        relaxed &= ~cand | ok | lands_in
    return strict, relaxed


def _check(spec: LawSpec, cfg: Config, maps: StepMaps, boxes):
    """Prove no stride-over per box, strict and relaxed readings (no refinement).

    Parameters
    ----------
    spec : LawSpec
        The law.
    cfg : Config
        Configuration (the yardstick d [mm], the tie band).
    maps : StepMaps
        One-step map enclosures (the plant's a, or a ball of a).
    boxes : tuple of ndarray
        Cells (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    strict, relaxed : ndarray of bool
        Proved per cell.
    """
    p = cfg.plant
    d = cfg.pto.d
    tol = tie_band(p.w_max, p.a, p.position_range)
    x1lo, x1hi, x2lo, x2hi = boxes
    strict = np.ones(x1lo.size, dtype=bool)
    relaxed = strict.copy()
    for right in (True, False):
        has = (x1hi >= d) if right else (x1lo <= -d)
        idx = np.flatnonzero(has)
        if idx.size == 0:
            continue
        lo = np.maximum(x1lo[idx], d) if right else x1lo[idx]
        hi = x1hi[idx] if right else np.minimum(x1hi[idx], -d)
        piece = (lo, hi, x2lo[idx], x2hi[idx])
        enc = enclose(spec, piece)
        s, r = _sides(spec, piece, enc.lo, enc.hi, maps, d, tol)
        strict[idx] &= s
        relaxed[idx] &= r
    return strict, relaxed


def unsettled_cells(spec: LawSpec, cfg: Config, maps: StepMaps, boxes) -> np.ndarray:
    """Return the cells the first no-stride-over check leaves open (they are refined).

    Parameters
    ----------
    spec : LawSpec
        The law.
    cfg : Config
        Configuration (the yardstick d [mm], the tie band).
    maps : StepMaps
        One-step map enclosures (the plant's a, or a ball of a).
    boxes : tuple of ndarray
        Cells (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    ndarray of bool
        True where either reading is not proved on the whole cell:
        :func:`stride_check` refines exactly these.
    """
    s, r = _check(spec, cfg, maps, boxes)
    return ~s | ~r


@dataclass(frozen=True)
class StrideResult:
    """No stride-over per cell, after refinement.

    Attributes
    ----------
    strict, relaxed : ndarray of bool
        Proved on the whole cell, in each reading.
    strict_gap, relaxed_gap : ndarray
        Area of the cell where the proof fails [mm mm/s].
    leaves : tuple of ndarray
        The smallest boxes where a reading still fails (x1lo, x1hi, x2lo, x2hi).
    depth : int
        Refinement levels used (each halves the boxes' sides).
    """

    strict: np.ndarray
    relaxed: np.ndarray
    strict_gap: np.ndarray
    relaxed_gap: np.ndarray
    leaves: tuple
    depth: int


def _split(b):
    """Cut boxes into _SPLIT x _SPLIT children that tile each box exactly."""
    f = np.arange(_SPLIT) / _SPLIT  # each side cut in _SPLIT: 3 levels at once
    t1 = np.repeat(f, _SPLIT)[:, None]
    t2 = np.tile(f, _SPLIT)[:, None]
    # a child's upper edge is computed exactly as its neighbour's lower edge
    # (t + 1/8 is exact), and the last one is the box's own edge: no gaps
    lo1 = b[0] + t1 * (b[1] - b[0])
    lo2 = b[2] + t2 * (b[3] - b[2])
    u1, u2 = t1 + 1.0 / _SPLIT, t2 + 1.0 / _SPLIT
    hi1 = np.where(u1 >= 1.0, b[1], b[0] + u1 * (b[1] - b[0]))
    hi2 = np.where(u2 >= 1.0, b[3], b[2] + u2 * (b[3] - b[2]))
    return tuple(v.ravel() for v in (lo1, hi1, lo2, hi2))


def _refine(spec: LawSpec, cfg: Config, maps: StepMaps, cur, s, r, depth: int, cap: int):
    """Refine the failing boxes of m cells (box i is cell i); return the kept leaves, the depth.

    Each kept entry is (boxes, owner in 0..m-1, strict fails, relaxed fails).
    """
    m = cur[0].size
    owner = np.arange(m)
    kept = []
    level = deepest = 0
    while True:
        bad = ~s | ~r
        go = bad & (np.bincount(owner[bad], minlength=m)[owner] <= cap)
        if level >= depth:
            go[:] = False
        stop = bad & ~go
        kept.append((tuple(v[stop] for v in cur), owner[stop], ~s[stop], ~r[stop]))
        if not go.any():
            break
        cur = _split(tuple(v[go] for v in cur))
        owner = np.tile(owner[go], _SPLIT * _SPLIT)
        s, r = _check(spec, cfg, maps, cur)
        level += 3
        deepest = level
    return kept, deepest


def stride_check(
    spec: LawSpec,
    cfg: Config,
    maps: StepMaps,
    boxes,
    *,
    depth: int = REFINE_DEPTH,
    cap: int = REFINE_CAP,
    chunk: int = REFINE_CHUNK,
) -> StrideResult:
    """Prove no stride-over per cell, refining failing cells.

    A failing box is cut into 8 x 8 children (three halvings of each side, so
    children tile the box exactly: the last child ends at the box's edge); each
    child is checked again, down to ``depth`` halvings, for as long as at most
    ``cap`` boxes of its cell fail.  Each cell is refined on its own, so the
    result of a cell does not depend on the other cells checked with it (a
    cluster may split the cells into blocks).  The verdict of a cell holds where
    all its leaves pass; the failing leaves' area is its gap.

    Parameters
    ----------
    spec : LawSpec
        The law.
    cfg : Config
        Configuration (the yardstick d [mm], the tie band).
    maps : StepMaps
        One-step map enclosures.
    boxes : tuple of ndarray
        Cells (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].
    depth : int
        Most refinement levels.
    cap : int
        Most failing boxes of one cell carried to the next level.
    chunk : int
        Cells refined together (memory; the result does not depend on it).

    Returns
    -------
    StrideResult
        Per-cell verdicts and gaps; leaves ordered by cell, then position.
    """
    n = boxes[0].size
    s, r = _check(spec, cfg, maps, boxes)  # the cells of unsettled_cells fail here
    cells = np.flatnonzero(~s | ~r)
    # failing leaves no longer refined: (boxes, owner, strict fails, relaxed fails)
    kept = [(tuple(v[:0] for v in boxes), cells[:0], s[:0], r[:0])]
    deepest = 0
    for at in range(0, cells.size, chunk):  # a chunk of cells at a time: bounded memory
        c = cells[at : at + chunk]
        part, level = _refine(spec, cfg, maps, tuple(v[c] for v in boxes), s[c], r[c], depth, cap)
        kept += [(b, c[o], fs, fr) for b, o, fs, fr in part]
        deepest = max(deepest, level)
    leaves = tuple(np.concatenate([k[0][q] for k in kept]) for q in range(4))
    owner = np.concatenate([k[1] for k in kept])
    fail_s = np.concatenate([k[2] for k in kept])
    fail_r = np.concatenate([k[3] for k in kept])
    order = np.lexsort((leaves[2], leaves[0], owner))  # canonical: by cell, then position
    leaves = tuple(v[order] for v in leaves)
    owner, fail_s, fail_r = owner[order], fail_s[order], fail_r[order]
    area = (leaves[1] - leaves[0]) * (leaves[3] - leaves[2])
    gap_s = np.bincount(owner[fail_s], weights=area[fail_s], minlength=n)
    gap_r = np.bincount(owner[fail_r], weights=area[fail_r], minlength=n)
    strict = np.bincount(owner[fail_s], minlength=n) == 0
    relaxed = np.bincount(owner[fail_r], minlength=n) == 0
    return StrideResult(strict, relaxed, gap_s, gap_r, leaves, deepest)


@dataclass(frozen=True)
class Counterexample:
    """A certified stride-over.

    Attributes
    ----------
    x0 : tuple of float
        The state [mm], [mm/s] (exact floats).
    x1 : tuple of float
        Its next sample, rounded from the arb ball [mm], [mm/s].
    u : float
        The law's input there [mm/s] (certified branch).
    sigma0, sigma1 : float
        Switching function before and after [mm/s] (midpoints of certified balls).
    lands_in_strip : bool
        The next sample lies in |x1| < d (a stride-over only in the strict reading).
    confirmed_by_simulation : bool
        ``simulate``'s one step (floats) shows the same crossing.
    a_plant : float
        The plant's bandwidth of the step [rad/s] (the law keeps its design a).
    """

    x0: tuple
    x1: tuple
    u: float
    sigma0: float
    sigma1: float
    lands_in_strip: bool
    confirmed_by_simulation: bool
    a_plant: float = float("nan")

    def to_json(self) -> dict:
        """Plain JSON object."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


def _sigma_arb(a: arb, x1: arb, x2: arb, level: float) -> arb:
    """Switching function in arb (eqs. 9, 11, 13, 14); x2's sign must be certain."""
    lv = arb(level)
    r = abs(x2) / lv
    h = r - r.log1p()
    return a * x1 + (lv * h if x2 > 0 else -lv * h if x2 < 0 else 0)


def _certify(spec: LawSpec, cfg: Config, x1: float, x2: float, a_plant: float):
    """Certify a stride-over from (x1, x2) in arb, plant's a = a_plant; None if it cannot."""
    p = cfg.plant
    d, w = cfg.pto.d, p.w_max
    tol = tie_band(w, p.a, p.position_range)
    if abs(x1) < d or x2 == 0.0 or not np.isfinite(spec.d) or abs(x1) < spec.d:
        return None
    with ctx.workprec(ARB_PREC):
        a = arb(spec.a)
        s0 = _sigma_arb(a, arb(x1), arb(x2), w)
        if s0 > 0:
            side = -1.0
        elif s0 < 0:
            side = 1.0
        else:
            return None
        if spec.has_zone:  # certify that the state is not in the zone: sigma_omega0 on S's side
            so = _sigma_arb(a, arb(x1), arb(x2), spec.omega0)
            if not ((so > 0) if side < 0 else (so < 0)):
                return None
        u = side * w
        e = (-arb(a_plant) * arb(p.sample_time)).exp()
        y2 = arb(u) + (arb(x2) - arb(u)) * e
        y1 = arb(x1) + arb(u) * arb(p.sample_time) + (arb(x2) - arb(u)) * (1 - e) / arb(a_plant)
        if not (y2 > 0 or y2 < 0):
            return None
        s1 = _sigma_arb(a, y1, y2, w)
        crossed = (s1 < -tol) if side < 0 else (s1 > tol)
        if not crossed:
            return None
        inside = abs(y1) < d
        outside = abs(y1) >= d
        if not (inside or outside):
            return None
        return (float(y1.mid()), float(y2.mid())), u, float(s0.mid()), float(s1.mid()), bool(inside)


def find_counterexample(
    spec: LawSpec,
    cfg: Config,
    boxes,
    failing,
    *,
    relaxed: bool,
    limit: int = 400,
    a_plant: float | None = None,
):
    """Search failing cells for a certified stride-over.

    Parameters
    ----------
    spec : LawSpec
        The law (PTO or TO).
    cfg : Config
        Configuration.
    boxes : tuple of ndarray
        Cells [mm], [mm/s].
    failing : ndarray of bool
        Cells whose proof failed.
    relaxed : bool
        Search for a crossing that lands outside the strip (relaxed reading).
    limit : int
        Cells tried at most (spread evenly over the failing ones).
    a_plant : float, optional
        The plant's bandwidth [rad/s] (default the configuration's); the law
        keeps the configuration's design.

    Returns
    -------
    Counterexample or None
        A state certified in arb and confirmed by one simulated step.
    """
    idx = np.flatnonzero(failing)
    idx = idx[np.unique(np.linspace(0, idx.size - 1, min(limit, idx.size)).astype(int))]
    law = make_law(spec.name, cfg)
    a_plant = cfg.plant.a if a_plant is None else a_plant
    plant = cfg.with_plant(a=a_plant).plant
    for c in idx.tolist():
        for f1, f2 in ((0.5, 0.5), (0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)):
            x1 = float(boxes[0][c] + f1 * (boxes[1][c] - boxes[0][c]))
            x2 = float(boxes[2][c] + f2 * (boxes[3][c] - boxes[2][c]))
            got = _certify(spec, cfg, x1, x2, a_plant)
            if got is None or (relaxed and got[4]):
                continue
            y, u, s0, s1, inside = got
            b = simulate_batch(law, plant, [x1], [x2], 1)
            z1, z2 = float(b.x1[1, 0]), float(b.x2[1, 0])
            sim = bool(b.u[0, 0] == u and abs(z1 - y[0]) < 1e-9 and abs(z2 - y[1]) < 1e-6)
            return Counterexample((x1, x2), y, u, s0, s1, inside, sim, a_plant)
    return None
