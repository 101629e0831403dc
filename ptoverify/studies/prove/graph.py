"""Cell partition of the envelope, certified images with macro-steps, longest paths.

The envelope |x1| <= X1, |x2| <= w_max is cut by a tensor grid graded fine
near the origin, the linear zone and the switching zone, coarse elsewhere.
Each cell's image under the exact ZOH map with the enclosed input is a box
(:mod:`ptoverify.model.intervals`); the cell links to every cell that box
meets.  Macro-steps: while the input is certified constant (+-w_max: bang-bang
or saturated) or certified linear and unsaturated, the exact j-step map is
applied to the original cell (no wrapping) and the edge counts j samples.

x2 images are intersected with [-w_max, w_max]: x2' = e x2 + (1 - e) u with
0 < e < 1 and |u| <= w_max is a convex combination, so |x2| <= w_max is
invariant for every a > 0 (exact, not a rounding argument).

The bound of a cell is the longest path (in samples) from it to the target
ellipse: 0 inside the target, else the macro-step's samples plus the largest
bound of its successors.  A cell on a cycle, with an image that leaves the
grid, or that reaches such a cell, has no bound (infinite): unproven.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ptoverify.model.intervals import add, mul
from ptoverify.model.lawbox import LawSpec, enclose, sigma_point
from ptoverify.model.zohmaps import StepMaps, affine_image, linear_image
from ptoverify.studies.prove.target import Target, box_in_target

__all__ = ["Grid", "make_grid", "Images", "images", "successors", "longest_path"]


@dataclass(frozen=True)
class Grid:
    """A tensor grid of cells over the envelope.

    Attributes
    ----------
    e1 : ndarray
        Position edges [mm], increasing, from -X1 to X1.
    e2 : ndarray
        Velocity edges [mm/s], increasing, from -w_max to w_max.
    """

    e1: np.ndarray
    e2: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(cells along x1, cells along x2)."""
        return self.e1.size - 1, self.e2.size - 1

    @property
    def size(self) -> int:
        """Number of cells."""
        return (self.e1.size - 1) * (self.e2.size - 1)

    def boxes(self):
        """Cell boxes (x1lo, x1hi, x2lo, x2hi), cell index = j * n1 + i."""
        n1, n2 = self.shape
        i = np.tile(np.arange(n1), n2)
        j = np.repeat(np.arange(n2), n1)
        return self.e1[i], self.e1[i + 1], self.e2[j], self.e2[j + 1]


def _graded(fine_to: float, h_fine: float, h_max: float, end: float, growth: float = 1.3):
    """Edges from 0 to ``end``: step h_fine up to fine_to, then growing to h_max."""
    edges = [0.0]
    h = h_fine
    while edges[-1] < end:
        if edges[-1] >= fine_to:
            h = min(h * growth, h_max)
        edges.append(min(edges[-1] + h, end))
        if end - edges[-1] < 0.25 * h:  # no sliver at the end
            edges[-1] = end
    return np.array(edges)


def make_grid(
    x1_end: float,
    w: float,
    fine_to: float,
    h1: float,
    h2: float,
    h1_max: float,
    h_edge: float = 0.05,
) -> Grid:
    """Build the graded grid over |x1| <= x1_end, |x2| <= w.

    Parameters
    ----------
    x1_end : float
        Half-width of the gridded positions [mm].
    w : float
        Saturation w_max [mm/s].
    fine_to : float
        Cells of width h1 for |x1| <= fine_to [mm] (all of them when fine_to >= x1_end).
    h1 : float
        Fine cell width [mm].
    h2 : float
        Cell height [mm/s].
    h1_max : float
        Largest cell width [mm].
    h_edge : float
        Cell width at the envelope's edge |x1| = x1_end [mm].

    Returns
    -------
    Grid
        The grid (symmetric about the origin).

    Examples
    --------
    >>> g = make_grid(50.0, 300.0, 1.0, 0.1, 10.0, 2.0)
    >>> float(g.e1[0]), float(g.e1[-1]), g.shape[1]
    (-50.0, 50.0, 60)
    """
    fine_to = min(fine_to, x1_end)  # a fine strip wider than the envelope: all fine
    mid = 0.5 * (fine_to + x1_end)
    inner = _graded(fine_to, h1, h1_max, mid)
    # fine again towards the envelope's edge, where states really leave it
    outer = x1_end - _graded(1.0, h_edge, h1_max, x1_end - mid)[::-1]
    half = np.concatenate([inner[:-1], outer])
    e1 = np.concatenate([-half[:0:-1], half])
    n2 = max(2, int(np.ceil(2 * w / h2)))
    e2 = np.linspace(-w, w, n2 + 1)
    return Grid(e1, e2)


@dataclass(frozen=True)
class Images:
    """Certified macro-step images of the cells.

    Attributes
    ----------
    k : ndarray of int
        Samples of each cell's macro-step [-].
    box : tuple of ndarray
        Image box after k samples (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].
    to_target : ndarray of bool
        The image is certified inside the target ellipse.
    u_lo, u_hi : ndarray
        Input enclosure over the cell [mm/s].
    """

    k: np.ndarray
    box: tuple
    to_target: np.ndarray
    u_lo: np.ndarray
    u_hi: np.ndarray


def _clip_x2(box, w: float):
    """Intersect the x2 range with [-w, w] (invariant set, see the module docstring)."""
    return box[0], box[1], np.clip(box[2], -w, w), np.clip(box[3], -w, w)


def constant_input(spec: LawSpec, box) -> np.ndarray:
    """Return +-w_max where the law is certified constant over the box, else 0.

    Cheap: one corner's classification (monotonicity, see :mod:`ptoverify.model.lawbox`).

    Parameters
    ----------
    spec : LawSpec
        The law.
    box : tuple of ndarray
        (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].

    Returns
    -------
    ndarray
        w_max, -w_max or 0 per box [mm/s].
    """
    x1lo, x1hi, x2lo, x2hi = box
    w, d = spec.w_max, spec.d
    out = np.zeros(x1lo.shape)
    # inside the linear zone, saturated: sign of -g1 x1 - g2 x2 at the extreme corners
    inside = (x1lo > -d) & (x1hi < d)
    g1, g2 = (-spec.g1, -spec.g1), (-spec.g2, -spec.g2)
    v_max = add(mul(g1, (x1lo, x1lo)), mul(g2, (x2lo, x2lo)))[1]  # outward rounded
    v_min = add(mul(g1, (x1hi, x1hi)), mul(g2, (x2hi, x2hi)))[0]
    out = np.where(inside & (v_min > w), w, out)
    out = np.where(inside & (v_max < -w), -w, out)
    if np.isfinite(d):
        # u = -w right of the zone (x1 >= d), +w left of it, iff certified at the corner
        # nearest the curves; both sides in one enclosure per curve (elementwise)
        right, left = np.flatnonzero(x1lo >= d), np.flatnonzero(x1hi <= -d)
        nr = right.size
        if nr + left.size:
            c1 = np.concatenate([x1lo[right], x1hi[left]])
            c2 = np.concatenate([x2lo[right], x2hi[left]])
            s_lo, s_hi = sigma_point(spec, c1, c2, w)
            # with a zone the curve of level omega0 as well; without, the level is w_max
            lo, hi = sigma_point(spec, c1, c2, spec.omega0) if spec.has_zone else (s_lo, s_hi)
            # -w needs sigma_w > 0 and, with a zone, sigma_omega0 > 0 (+w: both < 0)
            ok = (s_lo[:nr] > 0) & (lo[:nr] > 0)
            out[right] = np.where(ok, -w, out[right])
            ok = (s_hi[nr:] < 0) & (hi[nr:] < 0)
            out[left] = np.where(ok, w, out[left])
    return out


def images(
    spec: LawSpec,
    maps: StepMaps,
    target: Target,
    boxes,
    x1_end: float,
    steps: int,
) -> Images:
    """Certified macro-step images of cells.

    Parameters
    ----------
    spec : LawSpec
        The law.
    maps : StepMaps
        Step-map enclosures up to ``steps`` (with the linear gains).
    target : Target
        Certified ellipse (images inside it end their macro-step).
    boxes : tuple of ndarray
        Cells (x1lo, x1hi, x2lo, x2hi) [mm], [mm/s].
    x1_end : float
        Half-width of the grid [mm] (an image beyond it ends its macro-step).
    steps : int
        Longest macro-step [samples].

    Returns
    -------
    Images
        The images.
    """
    w = spec.w_max
    n = boxes[0].size
    enc = enclose(spec, boxes)
    k = np.ones(n, dtype=np.intp)
    one = np.ones(n, dtype=np.intp)
    out = list(_clip_x2(affine_image(maps, one, boxes, (enc.lo, enc.hi)), w))
    to_target = np.zeros(n, dtype=bool)
    const = np.where(enc.lo == enc.hi, enc.lo, 0.0)
    const = np.where(np.abs(const) == w, const, 0.0)
    modes = [("const", np.flatnonzero(const != 0))]
    if maps.lin is not None:
        modes.append(("lin", np.flatnonzero(enc.linear)))
    for mode, active in modes:
        for j in range(1, steps + 1):
            if active.size == 0:
                break
            sub = tuple(b[active] for b in boxes)
            jj = np.full(active.size, j)
            if mode == "const":
                u = const[active]
                img = _clip_x2(affine_image(maps, jj, sub, (u, u)), w)
            else:
                img = _clip_x2(linear_image(maps, jj, sub), w)
            for q in range(4):
                out[q][active] = img[q]
            k[active] = j
            inside = (img[0] >= -x1_end) & (img[1] <= x1_end)
            if mode == "const":
                keep = inside & (constant_input(spec, img) == u)
            else:
                hit = box_in_target(target, img)
                to_target[active] = hit
                keep = inside & ~hit & enclose(spec, img).linear
            active = active[keep]
    return Images(k, tuple(out), to_target, enc.lo, enc.hi)


def successors(e1: np.ndarray, e2: np.ndarray, img: Images):
    """Cells that each image box meets, as a CSR list.

    Parameters
    ----------
    e1, e2 : ndarray
        Grid edges [mm], [mm/s].
    img : Images
        The images.

    Returns
    -------
    starts : ndarray of int, shape (n + 1,)
        Successors of cell c are ``succ[starts[c]:starts[c + 1]]``.
    succ : ndarray of int
        Cell indices (j * n1 + i).
    exits : ndarray of bool
        The image leaves the grid.
    """
    n1, n2 = e1.size - 1, e2.size - 1
    y1lo, y1hi, y2lo, y2hi = img.box
    exits = (y1lo < e1[0]) | (y1hi > e1[-1]) | (y2lo < e2[0]) | (y2hi > e2[-1])
    exits |= ~(np.isfinite(y1lo) & np.isfinite(y1hi) & np.isfinite(y2lo) & np.isfinite(y2hi))
    i0 = np.clip(np.searchsorted(e1, y1lo, "left") - 1, 0, n1 - 1)
    i1 = np.clip(np.searchsorted(e1, y1hi, "right") - 1, 0, n1 - 1)
    j0 = np.clip(np.searchsorted(e2, y2lo, "left") - 1, 0, n2 - 1)
    j1 = np.clip(np.searchsorted(e2, y2hi, "right") - 1, 0, n2 - 1)
    none = exits | img.to_target
    wi = np.where(none, 0, i1 - i0 + 1)
    wj = np.where(none, 0, j1 - j0 + 1)
    counts = wi * wj
    starts = np.zeros(counts.size + 1, dtype=np.intp)
    np.cumsum(counts, out=starts[1:])
    owner = np.repeat(np.arange(counts.size), counts)
    r = np.arange(starts[-1]) - starts[owner]
    di, dj = r % wi[owner], r // wi[owner]
    succ = (j0[owner] + dj) * n1 + (i0[owner] + di)
    return starts, succ, exits


def longest_path(starts, succ, k, in_target, to_target, exits) -> np.ndarray:
    """Longest path to the target, in samples, for every cell (inf: none).

    Parameters
    ----------
    starts, succ : ndarray
        CSR successor lists (:func:`successors`).
    k : ndarray of int
        Samples of each cell's edge.
    in_target : ndarray of bool
        The cell lies in the target (bound 0).
    to_target : ndarray of bool
        The cell's image lies in the target (bound k).
    exits : ndarray of bool
        The cell's image leaves the grid (no bound).

    Returns
    -------
    ndarray of float
        Certified bound per cell [samples]; inf where unproven.
    """
    n = k.size
    bound = np.full(n, np.inf)
    bound[to_target] = k[to_target]
    bound[in_target] = 0.0
    resolved = np.isfinite(bound)
    counts = starts[1:] - starts[:-1]
    # Levels of the successor graph (Kahn's order): a cell is done when its last
    # unresolved successor is; each edge is visited once to count, once to take its
    # maximum, and once to be released (not once per level for every pending cell).
    pending = ~resolved & ~exits & (counts > 0)
    owner = np.repeat(np.arange(n), counts)
    live = pending[owner] & ~resolved[succ]  # edges still to wait for
    src, dst = owner[live], succ[live]
    left = np.bincount(src, minlength=n)  # unresolved successors of each pending cell
    order = np.argsort(dst, kind="stable")
    preds = src[order]  # the waiting cells, grouped by the successor they wait for
    pstart = np.zeros(n + 1, dtype=np.intp)
    np.cumsum(np.bincount(dst, minlength=n), out=pstart[1:])
    ready = np.flatnonzero(pending & (left == 0))
    while ready.size:
        c = counts[ready]
        seg = np.cumsum(c) - c
        idx = np.repeat(starts[ready] - seg, c) + np.arange(seg[-1] + c[-1])
        bound[ready] = k[ready] + np.maximum.reduceat(bound[succ[idx]], seg)
        pc = pstart[ready + 1] - pstart[ready]
        if not pc.any():
            break
        pseg = np.cumsum(pc) - pc
        waiting = preds[np.repeat(pstart[ready] - pseg, pc) + np.arange(pc.sum())]
        left -= np.bincount(waiting, minlength=n)
        waiting = np.unique(waiting)
        ready = waiting[left[waiting] == 0]
    return bound
