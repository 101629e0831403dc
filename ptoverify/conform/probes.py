"""The states ``conform`` probes, and tables of a law's values.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions):

* :func:`conformance_grid`: a fixed grid dense near l1, l2, l1*, l2* (the zone
  boundary), the switching zone, |x1| = d, the origin and |x2| = w_max;
* :func:`probe_set`: what both routes probe and ``--emit-grid`` writes: the
  grid, ``N_RANDOM`` seeded random states (one jittered state in each cell of
  a ``LATTICE`` x ``LATTICE`` lattice, the rest uniform) and ``N_BAND`` seeded
  states in a band around l1/l2, l1*/l2* and |x1| = d;
* with a baseline reference (``[conform] reference``) d is its linear
  region's edge (:func:`ptoverify.conform.reflaw.linear_edge`) and there is no
  l1*, l2*; the states around l1, l2 stay (the plant's switching curves);
* :func:`read_table`: a CSV with columns x1, x2, u (regular files, in chunks);
* :func:`table_coverage`: does a table hold the probe set (or fill the lattice)?
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.reflaw import linear_edge, omega0_ref, tie_band
from ptoverify.errors import InputError
from ptoverify.model.curves import level_curve_x1, root_22
from ptoverify.model.memo import memo

__all__ = [
    "N_RANDOM",
    "RANDOM_SEED",
    "N_BAND",
    "LATTICE",
    "MATCH_TOL",
    "conformance_grid",
    "random_states",
    "band_states",
    "probe_set",
    "grid_csv",
    "table_coverage",
    "read_table",
]

N_RANDOM = 100_000  #: seeded random agreement states over the envelope
RANDOM_SEED = 15  #: seed of those states (issue 15)
LATTICE = 200  #: lattice cells per axis: one random state in each, and the table fill rule
N_BAND = 80_000  #: seeded states in the band around the curves and |x1| = d
MATCH_TOL = 1e-6  #: a table state matches a probe within this fraction of R, w_max per axis


def conformance_grid(cfg: Config, n: int = 61, n_curve: int = 121) -> tuple[NDArray, NDArray]:
    """States dense near every curve, boundary, the origin and |x2| = w_max.

    Built once per (configuration, ``n``, ``n_curve``) in a process
    (:mod:`ptoverify.model.memo`): every conformance, the determinism states, the
    probe set and a table's coverage read the same grid.  The arrays are
    read-only (shared).

    An ``n`` x ``n`` background over |x1| <= position_range, |x2| <= w_max, plus,
    for ``n_curve`` speeds |x2| (geometric from 1e-6 w_max, and linear):

    * l1, l2 (level w_max) and l1*, l2* (level omega0, the zone boundary), also
      at ``n_curve`` speeds from where each curve leaves |x1| < d up to w_max: the
      curve point and points at residual offsets of +-10^k TIE_BAND, k = 1..7,
      with TIE_BAND = 1e-9 (w_max + a position_range) [mm/s];
    * the switching-zone band between l1 and l1*: 11 points across it;
    * the linear-zone edges x1 = +-d exactly, one ulp either side, and
      +-d (1 +- 10^-k), k = 1..9;
    * |x2| = w_max exactly and w_max (1 - 10^-k), k = 1..9, over n positions;
    * the origin and 16 directions at radii 10^-k (d, w_max), k = 0..9.

    Parameters
    ----------
    cfg : Config
        Configuration.
    n, n_curve : int
        Background resolution and number of speeds along each curve.

    Returns
    -------
    x1, x2 : ndarray
        States [mm], [mm/s], inside the envelope, duplicates removed, symmetric
        under x -> -x; read-only.
    """
    return _conformance_grid(cfg, int(n), int(n_curve))


@memo(maxsize=16)
def _conformance_grid(cfg: Config, n: int, n_curve: int) -> tuple[NDArray, NDArray]:
    """Build :func:`conformance_grid` (memoized; read-only arrays)."""
    p = cfg.plant
    a, w, R, d = p.a, p.w_max, p.position_range, linear_edge(cfg)
    band = tie_band(cfg)
    g1, g2 = np.meshgrid(np.linspace(-R, R, n), np.linspace(-w, w, n))
    xs, vs = [g1.ravel()], [g2.ravel()]
    s = np.unique(
        np.concatenate(
            [
                np.geomspace(1e-6 * w, w, n_curve // 2),
                np.linspace(w / n_curve, w, n_curve - n_curve // 2),
            ]
        )
    )
    rho = band * 10.0 ** np.arange(1, 8)
    offsets = np.concatenate([-rho[::-1], [0.0], rho]) / a
    om = omega0_ref(cfg)
    levels = (w,) if om is None else (w, om)
    for level in levels:  # speeds where the curve lies outside |x1| < d
        s_d = level * float(root_22(a * d / level))
        if s_d < w:
            s = np.concatenate([s, np.linspace(s_d, w, n_curve)])
    s = np.unique(s)
    for x2 in (-s, s):
        for level in levels:
            c = level_curve_x1(x2, a, level)
            xs.append((c[:, None] + offsets[None, :]).ravel())
            vs.append(np.repeat(x2, offsets.size))
        if om is not None:
            c1, c2 = level_curve_x1(x2, a, w), level_curve_x1(x2, a, om)
            f = np.linspace(0.0, 1.0, 11)
            xs.append((c1[:, None] + f[None, :] * (c2 - c1)[:, None]).ravel())
            vs.append(np.repeat(x2, f.size))
    k = 10.0 ** -np.arange(1, 10)
    edge = np.concatenate(
        [[d, np.nextafter(d, 0.0), np.nextafter(d, np.inf)], d * (1 - k), d * (1 + k)]
    )
    v = np.linspace(-w, w, n_curve)
    for sign in (1.0, -1.0):
        e1, e2 = np.meshgrid(sign * edge, v)
        xs.append(e1.ravel())
        vs.append(e2.ravel())
        top = sign * np.concatenate([[w], w * (1 - k)])
        t1, t2 = np.meshgrid(np.linspace(-R, R, n), top)
        xs.append(t1.ravel())
        vs.append(t2.ravel())
    r = 10.0 ** -np.arange(0, 10)
    ang = np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)
    xs.append(np.concatenate([[0.0], (r[:, None] * d * np.cos(ang)).ravel()]))
    vs.append(np.concatenate([[0.0], (r[:, None] * w * np.sin(ang)).ravel()]))
    x1, x2 = np.concatenate(xs), np.concatenate(vs)
    keep = (np.abs(x1) <= R) & (np.abs(x2) <= w)
    x1, x2 = np.concatenate([x1[keep], -x1[keep]]), np.concatenate([x2[keep], -x2[keep]])
    pts = np.unique(np.stack([x1, x2], axis=1), axis=0)
    x1, x2 = pts[:, 0].copy(), pts[:, 1].copy()
    x1.flags.writeable = x2.flags.writeable = False  # shared by every caller (memo)
    return x1, x2


def random_states(cfg: Config, n: int = N_RANDOM) -> tuple[NDArray, NDArray]:
    """Seeded random states over the envelope: jittered lattice cells, then uniform.

    The first k^2 states (k = min(``LATTICE``, floor(sqrt(n)))) are one per cell
    of a k x k lattice over |x1| <= position_range, |x2| <= w_max, uniform in the
    middle 80 % of the cell (so a state rounded by less than a tenth of a cell
    stays in it); the other n - k^2 are uniform over the envelope.  Seed
    ``RANDOM_SEED``.

    Parameters
    ----------
    cfg : Config
        Configuration.
    n : int
        Number of states.

    Returns
    -------
    x1, x2 : ndarray
        States [mm], [mm/s].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> x1, x2 = random_states(paper_config(), 1000)
    >>> x1.size, bool(abs(x1).max() <= 50.0)
    (1000, True)
    """
    rng = np.random.default_rng(RANDOM_SEED)
    R, w = cfg.plant.position_range, cfg.plant.w_max
    k = min(LATTICE, math.isqrt(max(n, 0)))
    j1, j2 = np.meshgrid(np.arange(k), np.arange(k))
    c1 = (j1.ravel() + rng.uniform(0.1, 0.9, k * k)) * (2.0 / max(k, 1)) - 1.0
    c2 = (j2.ravel() + rng.uniform(0.1, 0.9, k * k)) * (2.0 / max(k, 1)) - 1.0
    m = n - k * k
    x1 = np.concatenate([c1 * R, rng.uniform(-R, R, m)])
    x2 = np.concatenate([c2 * w, rng.uniform(-w, w, m)])
    return x1, x2


def band_states(cfg: Config, n: int = N_BAND) -> tuple[NDArray, NDArray]:
    """Seeded states in a band around l1/l2, l1*/l2* and the linear-zone edges |x1| = d.

    ``3n/8`` states around the switching curve l1/l2 (level w_max), ``3n/8``
    around l1*/l2* (level omega0; to l1/l2 if there is no zone) and ``n/4``
    around x1 = +-d: the speed uniform in |x2| <= w_max, the position offset
    from the curve (or edge) of random sign and log-uniform magnitude from
    10 TIE_BAND / a to ``max(2 d, 0.02 position_range)`` [mm].  Seed
    ``RANDOM_SEED + 3``; states outside the envelope are dropped.

    Parameters
    ----------
    cfg : Config
        Configuration.
    n : int
        Number of states drawn.

    Returns
    -------
    x1, x2 : ndarray
        States [mm], [mm/s].
    """
    rng = np.random.default_rng(RANDOM_SEED + 3)
    p = cfg.plant
    a, w, R, d = p.a, p.w_max, p.position_range, linear_edge(cfg)
    lo, hi = 10.0 * tie_band(cfg) / a, max(2.0 * d, 0.02 * R)
    om = omega0_ref(cfg)
    n_c = 3 * n // 8
    n_e = n - 2 * n_c

    def offsets(m):
        mag = np.exp(rng.uniform(math.log(lo), math.log(hi), m))
        return np.where(rng.random(m) < 0.5, -mag, mag)

    xs, vs = [], []
    for level in (w, w if om is None else om):
        v = rng.uniform(-w, w, n_c)
        xs.append(level_curve_x1(v, a, level) + offsets(n_c))
        vs.append(v)
    v = rng.uniform(-w, w, n_e)
    xs.append(np.where(rng.random(n_e) < 0.5, -d, d) + offsets(n_e))
    vs.append(v)
    x1, x2 = np.concatenate(xs), np.concatenate(vs)
    keep = (np.abs(x1) <= R) & (np.abs(x2) <= w)
    return x1[keep], x2[keep]


def probe_set(
    cfg: Config,
    *,
    grid: tuple[NDArray, NDArray] | None = None,
    n_random: int = N_RANDOM,
    n_band: int = N_BAND,
) -> dict[str, tuple[NDArray, NDArray]]:
    """Return the states both ``conform`` routes probe: grid, random states, curve band.

    ``--emit-grid`` writes exactly these (in this order), and a ``--table`` must
    hold them (:func:`table_coverage`); a ``--law`` is also probed at the states
    its closed loop visits.

    Parameters
    ----------
    cfg : Config
        Configuration.
    grid : (x1, x2), optional
        The fixed grid; default :func:`conformance_grid`.
    n_random, n_band : int
        Sizes of :func:`random_states` and :func:`band_states`.

    Returns
    -------
    dict
        ``grid``, ``random``, ``band``: each (x1 [mm], x2 [mm/s]).
    """
    return {
        "grid": conformance_grid(cfg) if grid is None else grid,
        "random": random_states(cfg, n_random),
        "band": band_states(cfg, n_band),
    }


def grid_csv(cfg: Config) -> str:
    """Return the probe set (:func:`probe_set`) as CSV text, columns x1, x2 (exact repr).

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    str
        Header ``x1,x2`` and one state per line [mm], [mm/s].
    """
    parts = probe_set(cfg).values()
    x1 = np.concatenate([p[0] for p in parts])
    x2 = np.concatenate([p[1] for p in parts])
    lines = ["x1,x2"] + [f"{a!r},{b!r}" for a, b in zip(x1.tolist(), x2.tolist())]
    return "\n".join(lines) + "\n"


_HALF = round(1.0 / MATCH_TOL)  #: lattice steps from 0 to the envelope's edge
_OFF = round(1.5 / MATCH_TOL) + 1  #: offset of lattice indices (|s| clipped to 1.5: >= 1)
_FINE = 9  #: the near-probe bitmap's cells are 2^9 lattice steps wide
_M = ((2 * _OFF + 1) >> _FINE) + 1  #: bitmap cells per axis


def _lattice(s: NDArray) -> NDArray[np.int32]:
    """Lattice index (step MATCH_TOL, offset _OFF) of scaled coordinates (|s| clipped to 1.5)."""
    q = np.clip(s, -1.5, 1.5)
    q *= 1.0 / MATCH_TOL
    np.rint(q, out=q)
    out = q.astype(np.int32)
    out += _OFF
    return out


_NEIGHBOURS = [(d1, d2) for d1 in (0, -1, 1) for d2 in (0, -1, 1)]


def _bitmap_cell(q1: NDArray, q2: NDArray) -> NDArray[np.int32]:
    """Near-probe bitmap cell of lattice indices (_M x _M cells)."""
    c = q1 >> _FINE
    c *= _M
    c += q2 >> _FINE
    return c


def _match(x1, x2, q1, q2, p1, p2, n_grid: int, R: float, w: float) -> NDArray[np.intp]:
    """Table row holding each probe (-1 if none); exact rows for the first n_grid probes.

    ``q1``, ``q2`` are the table's lattice indices (:func:`_lattice`).  A bitmap of
    cells near some probe keeps the sorted search to the few table rows near one.
    """
    pq1, pq2 = _lattice(p1 / R), _lattice(p2 / w)
    e1 = np.concatenate([pq1 + d1 for d1, _ in _NEIGHBOURS]).astype(np.int64)
    e2 = np.concatenate([pq2 + d2 for _, d2 in _NEIGHBOURS]).astype(np.int64)
    uk, inv = np.unique((e1 << 23) | e2, return_inverse=True)
    near = np.zeros(_M * _M, dtype=bool)
    near[_bitmap_cell(e1, e2)] = True
    cand = np.flatnonzero(near[_bitmap_cell(q1, q2)])
    tk = (q1[cand].astype(np.int64) << 23) | q2[cand]
    pos = np.minimum(np.searchsorted(uk, tk), uk.size - 1)
    hit = uk[pos] == tk
    cand, pos = cand[hit], pos[hit]  # table rows near some probe
    holder = np.full(uk.size, -1, dtype=np.intp)
    holder[pos] = cand
    rows = holder[inv.reshape(len(_NEIGHBOURS), pq1.size)]
    first = np.argmax(rows >= 0, axis=0)  # offset 0 first, then the neighbours
    row = rows[first, np.arange(pq1.size)]
    # grid states: the row of an exactly equal state when there is one (odd symmetry)
    z = x1[cand] + 1j * x2[cand]
    order = np.argsort(z)
    pz = p1[:n_grid] + 1j * p2[:n_grid]
    if z.size:
        j = np.minimum(np.searchsorted(z[order], pz), z.size - 1)
        exact = z[order[j]] == pz
        row[:n_grid] = np.where(exact, cand[order[j]], row[:n_grid])
    return row


def table_coverage(x1: NDArray, x2: NDArray, cfg: Config) -> dict:
    """How much of the probe set a table holds, and how much of the lattice it fills.

    A probe state is held when a table state lies within ``MATCH_TOL`` of it
    per axis, scaled by position_range and w_max (both rounded to a lattice of
    that step: within 0.5 step always, never beyond 1.5 steps), so a table
    whose states were rounded to float32 (6e-8 relative) still holds it.  The
    fill rule counts the cells of a ``LATTICE`` x ``LATTICE`` lattice over the
    envelope that hold no table state.

    Parameters
    ----------
    x1, x2 : ndarray
        Table states [mm], [mm/s].
    cfg : Config
        Configuration.

    Returns
    -------
    dict
        ``probes`` (size of the probe set), ``missing`` (probe states not held),
        ``first_missing`` [x1, x2] or None, ``cells``, ``empty_cells``,
        ``first_empty`` (centre [x1, x2] of the first empty cell, or None) and
        ``grid_rows``: for each grid state, the index of the table row that
        holds it (-1 if none; the row of an exactly equal state when there is one).
    """
    R, w = cfg.plant.position_range, cfg.plant.w_max
    probes = probe_set(cfg)
    p1 = np.concatenate([p[0] for p in probes.values()])
    p2 = np.concatenate([p[1] for p in probes.values()])
    n_grid = probes["grid"][0].size
    q1, q2 = _lattice(x1 / R), _lattice(x2 / w)
    if (
        x1.size >= p1.size
        and np.array_equal(x1[: p1.size], p1)
        and np.array_equal(x2[: p1.size], p2)
    ):  # the --emit-grid file with u appended, rows in order
        row = np.arange(p1.size)
    else:
        row = _match(x1, x2, q1, q2, p1, p2, n_grid, R, w)
    miss = row < 0
    # lattice cells (binned on the MATCH_TOL lattice): LATTICE cells over [-1, 1]
    L, per = LATTICE, round(2 * _HALF / LATTICE)
    q1 -= _OFF - _HALF
    q2 -= _OFF - _HALF
    inside = (q1 >= 0) & (q1 <= 2 * _HALF) & (q2 >= 0) & (q2 <= 2 * _HALF)
    i1, i2 = q1[inside], q2[inside]
    del q1, q2, inside
    i1 //= per
    i2 //= per
    np.minimum(i1, L - 1, out=i1)
    np.minimum(i2, L - 1, out=i2)
    i1 *= L
    i1 += i2
    empty = np.bincount(i1, minlength=L * L) == 0
    first_empty = None
    if empty.any():
        c = int(np.argmax(empty))
        first_empty = [((c // L + 0.5) * 2.0 / L - 1.0) * R, ((c % L + 0.5) * 2.0 / L - 1.0) * w]
    return {
        "probes": int(p1.size),
        "missing": int(miss.sum()),
        "first_missing": [float(p1[np.argmax(miss)]), float(p2[np.argmax(miss)])]
        if miss.any()
        else None,
        "cells": L * L,
        "empty_cells": int(empty.sum()),
        "first_empty": first_empty,
        "grid_rows": row[:n_grid],
    }


def _far(x1, x2, cfg: Config):
    """States beyond 1000 x the envelope (as ``mintime`` rejects them)."""
    p = cfg.plant
    return (np.abs(x1) > 1e3 * p.position_range) | (np.abs(x2) > 1e3 * p.w_max)


def read_table(path: str | Path, cfg: Config | None = None) -> tuple[NDArray, NDArray, NDArray]:
    """Read a CSV with a header naming columns x1, x2, u (others ignored).

    Parameters
    ----------
    path : str or Path
        CSV file (:func:`ptoverify.tables.read_columns`).
    cfg : Config, optional
        When given, states beyond 1000 x the envelope (|x1| > 1000
        position_range or |x2| > 1000 w_max, as ``mintime``) are bad input.

    Returns
    -------
    x1, x2, u : ndarray
        States [mm], [mm/s] and the implementation's input [mm/s].

    Raises
    ------
    InputError
        Not a regular file, unreadable, missing column, empty table, a field
        that is not a finite number or a state far outside the envelope (line
        and column named).
    """
    from ptoverify.tables import read_columns

    (x1, x2, u), lines = read_columns(path, ("x1", "x2", "u"), what="table")
    if cfg is not None:
        far = np.flatnonzero(_far(x1, x2, cfg))
        if far.size:
            k = int(far[0])
            raise InputError(
                f"table '{path}' line {lines[k]}: state ({x1[k]:g}, {x2[k]:g}) is far "
                f"outside the envelope (|x1| <= {1e3 * cfg.plant.position_range:g} mm, "
                f"|x2| <= {1e3 * cfg.plant.w_max:g} mm/s accepted)"
            )
    return x1, x2, u
