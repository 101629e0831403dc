"""Per-trajectory measures of the closed-loop properties: oscillation and stride-overs.

Part of :mod:`ptoverify.studies.properties` (which re-exports every name
here, and whose docstring defines a stride-over, a crossing into the linear
zone and a sustained oscillation): the measures on one batch of sampled
trajectories, used by the property grids, the robustness maps and ``conform``.
"""

from __future__ import annotations

import numpy as np

from ptoverify.config import Config
from ptoverify.model.curves import level_side, switching_function
from ptoverify.model.laws import Region
from ptoverify.verdict import tie_band

__all__ = ["oscillating", "crossing_masks", "stride_over_counts", "STRIDE_BLOCK"]


def oscillating(x1: np.ndarray, band: float) -> np.ndarray:
    """Sustained-oscillation test (module docstring) on a window of samples.

    Parameters
    ----------
    x1 : ndarray, shape (window, n)
        Positions over the last ``window`` samples of ``n`` runs [mm].
    band : float
        Samples with |x1| <= band do not count as a sign [mm].

    Returns
    -------
    ndarray of bool, shape (n,)
        At least 4 sign changes and a second-half peak above ``band`` and at
        least half the first-half peak.

    Examples
    --------
    >>> t = np.arange(200)[:, None]
    >>> oscillating(np.sin(0.3 * t), 1e-3).tolist(), oscillating(np.exp(-0.1 * t), 1e-3).tolist()
    ([True], [False])
    """
    W = x1.shape[0]  # noqa: N806
    pos = x1 > band
    big = x1 < -band
    big |= pos
    # carry the sign of the last sample beyond the band forward, so that small samples
    # do not count: code 2 (k + 1) + [x1_k > 0] at such samples, 0 elsewhere, carried
    # by a running maximum (0: none yet; its parity: the sign)
    code = big.astype(np.int16 if 2 * W + 2 < 2**15 else np.int64)
    code *= (2 * np.arange(1, W + 1, dtype=code.dtype))[:, None]
    code += pos
    for k in range(1, W):  # row by row: contiguous, unlike accumulate along axis 0
        np.maximum(code[k], code[k - 1], out=code[k])
    flips = code[1:] != 0
    flips &= code[:-1] != 0
    parity = code[1:] ^ code[:-1]
    parity &= 1
    flips &= parity.astype(bool)
    changes = np.count_nonzero(flips, axis=0)
    half = x1.shape[0] // 2
    ax = np.abs(x1)
    first, second = ax[:half].max(axis=0), ax[half:].max(axis=0)
    return (changes >= 4) & (second > band) & (second >= 0.5 * first)


def _at(A: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """``A.ravel()[flat]`` (row-major flat indices) without copying a strided view."""
    if A.flags.c_contiguous:
        return A.ravel()[flat]
    return A[np.divmod(flat, A.shape[1])]


def _crossings(
    X1: np.ndarray,  # noqa: N803
    X2: np.ndarray,  # noqa: N803
    R: np.ndarray,  # noqa: N803
    cfg: Config,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Find the transitions that cross l1 - o - l2 (see :func:`crossing_masks`), compressed.

    Returns the sample k and trajectory j of each transition k -> k + 1 that
    starts outside the zones and the linear zone, whether it crosses, and whether
    it lands outside the linear zone.  sigma is evaluated only at the two ends of
    these transitions (it is elementwise, so the values are those of the whole grid).
    Views of larger arrays are read in place.
    """
    p = cfg.plant
    a, w, d = p.a, p.w_max, cfg.pto.d
    tol = tie_band(w, a, p.position_range)
    out = X1 >= d  # |x1| >= d, without a float temporary of the whole grid
    out |= X1 <= -d
    R = R[: X1.shape[0] - 1]
    if R.dtype == np.int8 and Region.ZONE_N == Region.ZONE_P + 1:  # one pass: R in {P, N}
        zone = (R - np.int8(Region.ZONE_P)).view(np.uint8) <= 1
    else:
        zone = (R == Region.ZONE_P) | (R == Region.ZONE_N)
    src = out[:-1]
    src &= ~zone
    n = X1.shape[1]
    f = np.flatnonzero(src)  # src is a fresh C-ordered array: flat index k n + j
    k, j = np.divmod(f, n)
    # sigma once at every sample that starts or ends such a transition (most do both)
    ends = np.zeros(X1.shape, dtype=bool)
    ends[:-1] = src
    ends[1:] |= src
    e = np.flatnonzero(ends)
    sig = np.empty(X1.size)  # written only at e (the pages elsewhere stay untouched)
    sig[e] = switching_function(_at(X1, e), _at(X2, e), a, w)
    v0 = _at(X2, f)
    s0, s1 = sig[f], sig[f + n]
    n_side = (s0 > 0) | ((s0 == 0) & (v0 > 0))
    p_side = (s0 < 0) | ((s0 == 0) & (v0 < 0))
    cross = (n_side & (s1 < -tol)) | (p_side & (s1 > tol))
    return k, j, cross, out.ravel()[f + n]


def crossing_masks(
    X1: np.ndarray,
    X2: np.ndarray,
    R: np.ndarray,  # noqa: N803
    cfg: Config,
) -> tuple[np.ndarray, np.ndarray]:
    """Stride-overs and crossings into the linear zone, per sample transition.

    A transition k -> k+1 crosses when sigma changes side strictly beyond the tie band
    :func:`ptoverify.verdict.tie_band` [mm/s]; it starts outside the zone and the linear zone.
    A stride-over lands outside the linear zone; otherwise it is a crossing into it.

    Parameters
    ----------
    X1, X2 : ndarray, shape (steps + 1, n)
        States at the samples [mm], [mm/s].
    R : ndarray, shape (steps, n) or (steps + 1, n)
        Region codes of the samples (only the first ``steps`` rows are used).
    cfg : Config
        Configuration.

    Returns
    -------
    stride, into_linear : ndarray of bool, shape (steps, n)
    """
    k, j, cross, lands_out = _crossings(X1, X2, R, cfg)
    shape = (X1.shape[0] - 1, X1.shape[1])
    stride, into = np.zeros(shape, dtype=bool), np.zeros(shape, dtype=bool)
    hit = cross & lands_out
    stride[k[hit], j[hit]] = True
    hit = cross & ~lands_out
    into[k[hit], j[hit]] = True
    return stride, into


def stride_over_counts(
    X1: np.ndarray,
    X2: np.ndarray,
    R: np.ndarray,  # noqa: N803
    cfg: Config,
) -> np.ndarray:
    """Stride-overs of each trajectory: ``crossing_masks(...)[0].sum(axis=0)``, without the masks.

    Parameters
    ----------
    X1, X2 : ndarray, shape (steps + 1, n)
        States at the samples [mm], [mm/s].
    R : ndarray, shape (steps, n) or (steps + 1, n)
        Region codes of the samples.
    cfg : Config
        Configuration.

    Returns
    -------
    ndarray of int, shape (n,)
        Stride-overs per trajectory [-].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import make_law
    >>> from ptoverify.sim.simulate import simulate_batch
    >>> cfg = paper_config()
    >>> b = simulate_batch(make_law("to", cfg), cfg.plant, [40.0, 5.0], [0.0, 0.0], 100)
    >>> counts = stride_over_counts(b.x1, b.x2, b.region, cfg)
    >>> counts.tolist() == crossing_masks(b.x1, b.x2, b.region, cfg)[0].sum(axis=0).tolist()
    True
    """
    p = cfg.plant
    a, w, d = p.a, p.w_max, cfg.pto.d
    tol = tie_band(w, a, p.position_range)
    rows, n = X1.shape
    R = R[: rows - 1]  # noqa: N806
    one_pass = R.dtype == np.int8 and Region.ZONE_N == Region.ZONE_P + 1
    counts = np.zeros(n, dtype=np.intp)
    # a few columns at a time (cache-sized boolean masks); sigma only at the two ends
    # of the transitions that can be stride-overs (start outside the zones and the
    # linear zone, land outside the linear zone), read in place from the views
    cols = max(1, STRIDE_BLOCK // rows)
    for j0 in range(0, n, cols):
        j1 = min(j0 + cols, n)
        x1 = np.ascontiguousarray(X1[:, j0:j1])
        out = x1 >= d  # |x1| >= d
        out |= x1 <= -d
        r = R[:, j0:j1]
        if one_pass:  # R in {ZONE_P, ZONE_N}
            zone = (r - np.int8(Region.ZONE_P)).view(np.uint8) <= 1
        else:
            zone = (r == Region.ZONE_P) | (r == Region.ZONE_N)
        hit = np.greater(out[:-1], zone)  # starts outside the zones and the linear zone
        hit &= out[1:]  # lands outside the linear zone
        f = np.flatnonzero(hit)  # k (j1 - j0) + j: the sample k of column j, in x1 too
        if f.size == 0:
            continue
        x2 = np.ascontiguousarray(X2[:, j0:j1])
        v0 = x2.take(f)
        # sigma's sides and comparisons with +-tol (ptoverify.model.curves.level_side)
        s0 = level_side(a * x1.take(f), v0, w, tol)
        f1 = f + (j1 - j0)  # the next sample
        s1 = level_side(a * x1.take(f1), x2.take(f1), w, tol)
        on = s0 == 0
        n_side = s0 > 0
        n_side |= on & (v0 > 0)
        p_side = s0 < 0
        p_side |= on & (v0 < 0)
        n_side &= s1 < -tol
        p_side &= s1 > tol
        n_side |= p_side
        counts[j0:j1] += np.bincount(f[n_side] % (j1 - j0), minlength=j1 - j0)
    return counts


STRIDE_BLOCK = 65536  #: samples per block of :func:`stride_over_counts`
