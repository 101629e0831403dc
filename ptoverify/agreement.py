"""Conformance grid, tables, and agreement with the reference PTO law, region by region.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform` has the command's
decisions).  Here:

* :func:`conformance_grid`: the states ``--emit-grid`` writes, dense near l1,
  l2, l1*, l2* (the zone boundary), the switching zone, |x1| = d, the origin
  and |x2| = w_max;
* :func:`read_table`: a CSV with columns x1, x2, u (regular files, in chunks);
* :func:`agreement`: |u - u_ref| <= rtol w_max per reference region (default
  rtol = 1e-6), with the largest |du| and its state.  Points outside |x1| < d
  within ``tie_band`` = 1e-9 (w_max + a position_range) mm/s of a computed
  curve (l1/l2 or l1*/l2*) are excluded and counted: a float tie there can
  flip the region, and u jumps by up to 2 w_max.  The linear-zone edge
  |x1| = d, x2 = 0 and the origin are exact float comparisons, so nothing near
  them is excluded.
"""

from __future__ import annotations

import csv
import functools
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify import verdict
from ptoverify.config import Config
from ptoverify.curves import level_curve_x1, level_residual, root_22, switching_function
from ptoverify.errors import InputError
from ptoverify.laws import Law, Region, make_law

__all__ = [
    "DEFAULT_RTOL",
    "reference",
    "tie_band",
    "failure",
    "conformance_grid",
    "grid_csv",
    "read_table",
    "ties",
    "agreement",
    "region_counts",
    "largest_gap",
]

DEFAULT_RTOL = 1e-6  #: agreement tolerance relative to w_max


@functools.lru_cache(maxsize=8)
def reference(cfg: Config) -> Law:
    """Return ``make_law("pto", cfg)``, built once per configuration."""
    return make_law("pto", cfg)


def tie_band(cfg: Config) -> float:
    """Return the exclusion band of ``verdict.tie_band`` for ``cfg`` [mm/s]."""
    p = cfg.plant
    return verdict.tie_band(p.w_max, p.a, p.position_range)


def omega0_ref(cfg: Config) -> float | None:
    """omega0 [mm/s] the reference uses, None when it has no switching zone."""
    from ptoverify.zones import zone_for_law

    z = zone_for_law(cfg, "corrected")
    ok = z.usable and not z.degenerate and 0.0 < z.omega0 < cfg.plant.w_max
    return float(z.omega0) if ok else None


def failure(prop: str, state, detail: str, **extra) -> dict:
    """Return a failure entry: property, state [x1, x2], detail (and extra keys)."""
    return {
        "property": prop,
        "state": [float(state[0]), float(state[1])],
        "detail": detail,
        **extra,
    }


# ------------------------------------------------------------------ grid and table
def conformance_grid(cfg: Config, n: int = 61, n_curve: int = 121) -> tuple[NDArray, NDArray]:
    """States dense near every curve, boundary, the origin and |x2| = w_max.

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
        under x -> -x.
    """
    p = cfg.plant
    a, w, R, d = p.a, p.w_max, p.position_range, cfg.pto.d
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
    return pts[:, 0].copy(), pts[:, 1].copy()


def grid_csv(cfg: Config) -> str:
    """Return the conformance grid as CSV text, columns x1, x2 (exact float repr)."""
    x1, x2 = conformance_grid(cfg)
    lines = ["x1,x2"] + [f"{a!r},{b!r}" for a, b in zip(x1.tolist(), x2.tolist())]
    return "\n".join(lines) + "\n"


def _chunk_error(path, lines, first_line: int, cols: dict, cfg: Config | None) -> InputError:
    """Locate the first bad line of a chunk that numpy rejected (slow path, one chunk)."""
    for line, row in enumerate(csv.reader(lines), start=first_line):
        if not any(f.strip() for f in row):
            continue
        vals = {}
        for name, j in cols.items():
            text = row[j].strip() if j < len(row) else ""
            try:
                v = float(text)
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                return InputError(
                    f"table '{path}' line {line}: column {name} = {text!r} is not a finite number"
                )
            vals[name] = v
        if cfg is not None and _far(vals["x1"], vals["x2"], cfg):
            return InputError(
                f"table '{path}' line {line}: state ({vals['x1']:g}, {vals['x2']:g}) is far "
                f"outside the envelope (|x1| <= {1e3 * cfg.plant.position_range:g} mm, "
                f"|x2| <= {1e3 * cfg.plant.w_max:g} mm/s accepted)"
            )
    return InputError(f"table '{path}' near line {first_line}: malformed row")


def _far(x1, x2, cfg: Config):
    """States beyond 1000 x the envelope (as ``mintime`` rejects them)."""
    p = cfg.plant
    return (np.abs(x1) > 1e3 * p.position_range) | (np.abs(x2) > 1e3 * p.w_max)


_CHUNK_LINES = 500_000  #: table lines parsed per numpy call


def read_table(path: str | Path, cfg: Config | None = None) -> tuple[NDArray, NDArray, NDArray]:
    """Read a CSV with a header naming columns x1, x2, u (others ignored), in chunks.

    Only regular files are read (a device or a FIFO is bad input at once).
    Chunks of 500000 lines are parsed by numpy, so memory stays about twice
    the table's numeric size.

    Parameters
    ----------
    path : str or Path
        CSV file.
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
    import itertools
    import os
    import stat

    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise InputError(f"table '{path}' is not a regular file")
        fh = open(path, newline="", encoding="utf-8")
    except OSError as exc:
        raise InputError(f"cannot read table '{path}': {exc.strerror or exc}") from None
    chunks = []
    try:
        with fh:
            head = fh.readline()
            if not head.strip():
                raise InputError(f"table '{path}' is empty")
            header = [h.strip() for h in next(csv.reader([head]))]
            cols = {}
            for name in ("x1", "x2", "u"):
                if name not in header:
                    raise InputError(
                        f"table '{path}': no column '{name}' in header {','.join(header)} "
                        "(need x1, x2, u)"
                    )
                cols[name] = header.index(name)
            line = 2
            while True:
                lines = list(itertools.islice(fh, _CHUNK_LINES))
                if not lines:
                    break
                try:
                    arr = np.loadtxt(
                        lines,
                        delimiter=",",
                        usecols=tuple(cols.values()),
                        ndmin=2,
                        comments=None,
                        quotechar='"',
                    )
                except ValueError:
                    raise _chunk_error(path, lines, line, cols, cfg) from None
                bad = not np.isfinite(arr).all()
                if cfg is not None and arr.size:
                    bad = bad or bool(_far(arr[:, 0], arr[:, 1], cfg).any())
                if bad:
                    raise _chunk_error(path, lines, line, cols, cfg)
                chunks.append(arr)
                line += len(lines)
    except UnicodeDecodeError as exc:
        raise InputError(f"cannot read table '{path}': not UTF-8 text ({exc.reason})") from None
    except csv.Error as exc:
        raise InputError(f"table '{path}': malformed CSV: {exc}") from None
    if not sum(c.shape[0] for c in chunks):
        raise InputError(f"table '{path}' has a header but no rows")
    out = tuple(np.concatenate([c[:, k] for c in chunks]) for k in range(3))
    return out[0], out[1], out[2]


# ------------------------------------------------------------------ agreement
def ties(x1: NDArray, x2: NDArray, cfg: Config) -> NDArray[np.bool_]:
    """Points outside |x1| < d within TIE_BAND of l1/l2 or l1*/l2* (region may flip)."""
    a, w = cfg.plant.a, cfg.plant.w_max
    band = tie_band(cfg)
    near = np.abs(switching_function(x1, x2, a, w)) <= band
    om = omega0_ref(cfg)
    if om is not None:
        near |= np.abs(level_residual(x1, x2, a, om)) <= band
    return near & (np.abs(x1) >= cfg.pto.d)


def _reference_chunked(x1, x2, cfg: Config, chunk: int = 1_000_000):
    """Return u_ref, region codes and the tie mask, computed a million states at a time."""
    u_ref, reg = np.empty(x1.size), np.empty(x1.size, dtype=np.int8)
    tie = np.empty(x1.size, dtype=bool)
    for i in range(0, x1.size, chunk):
        s = slice(i, i + chunk)
        u_ref[s], reg[s] = reference(cfg)(x1[s], x2[s])
        tie[s] = ties(x1[s], x2[s], cfg)
    return u_ref, reg, tie


def region_counts(x1: NDArray, x2: NDArray, cfg: Config) -> dict[str, int]:
    """Count states per reference region (regions with none left out)."""
    _, reg, _ = _reference_chunked(np.asarray(x1, float), np.asarray(x2, float), cfg)
    counts = np.bincount(reg, minlength=len(Region))
    return {code.name: int(counts[code]) for code in Region if counts[code]}


def largest_gap(x1: NDArray, x2: NDArray, cfg: Config, n: int = 201) -> dict:
    """Find the largest disc of the envelope with no probed state (on an n x n lattice).

    Probed states are binned to the lattice and the distance to the nearest
    occupied node is measured in the scaled state (x1 / position_range,
    x2 / w_max), so the gap is an ellipse with the reported half-widths.

    Parameters
    ----------
    x1, x2 : ndarray
        Probed states [mm], [mm/s].
    cfg : Config
        Configuration.
    n : int
        Lattice resolution per axis.

    Returns
    -------
    dict
        ``center`` [x1, x2], ``radius`` (scaled), ``half_width_mm``, ``half_width_mm_s``.
    """
    from scipy.ndimage import distance_transform_edt

    R, w = cfg.plant.position_range, cfg.plant.w_max
    inside = (np.abs(x1) <= R) & (np.abs(x2) <= w)
    i1 = np.rint((x1[inside] / R + 1.0) * 0.5 * (n - 1)).astype(np.intp)
    i2 = np.rint((x2[inside] / w + 1.0) * 0.5 * (n - 1)).astype(np.intp)
    empty = np.ones((n, n), dtype=bool)
    empty[i2, i1] = False
    dist = distance_transform_edt(empty) if not empty.all() else np.full((n, n), np.inf)
    k2, k1 = np.unravel_index(int(np.argmax(dist)), dist.shape)
    r = float(dist[k2, k1]) * 2.0 / (n - 1)
    q = np.array([[k1, k2]]) * 2.0 / (n - 1) - 1.0
    i = 0
    return {
        "center": [float(q[i, 0] * R), float(q[i, 1] * w)],
        "radius": r,
        "half_width_mm": r * R,
        "half_width_mm_s": r * w,
    }


def agreement(
    x1: NDArray, x2: NDArray, u: NDArray, cfg: Config, rtol: float = DEFAULT_RTOL
) -> tuple[dict, list[dict]]:
    """Compare u with the reference PTO law, region by region.

    Parameters
    ----------
    x1, x2 : ndarray
        States [mm], [mm/s].
    u : ndarray
        The implementation's input [mm/s] at those states.
    cfg : Config
        Configuration.
    rtol : float
        Tolerance relative to w_max.

    Returns
    -------
    summary : dict
        ``points``, ``excluded``, ``tolerance_mm_s``, ``max_abs_du``, ``worst``,
        ``regions`` (per reference region: points, excluded, max_abs_du, state,
        u, u_ref, violations).
    failures : list of dict
        One ``agreement`` failure (first state in order, worst named) or none.
    """
    w = cfg.plant.w_max
    tol = rtol * w
    u_ref, reg, tie = _reference_chunked(x1, x2, cfg)
    du = np.abs(u - u_ref)
    judged = ~tie
    bad = judged & (du > tol)
    regions = {}
    for code in Region:
        m = reg == code
        if not m.any():
            continue
        mj = m & judged
        entry = {
            "code": int(code),
            "points": int(m.sum()),
            "excluded": int((m & tie).sum()),
            "violations": int((m & bad).sum()),
            "max_abs_du": 0.0,
            "state": None,
        }
        if mj.any():
            i = int(np.flatnonzero(mj)[np.argmax(du[mj])])
            entry.update(
                max_abs_du=float(du[i]),
                state=[float(x1[i]), float(x2[i])],
                u=float(u[i]),
                u_ref=float(u_ref[i]),
            )
        entry["pass"] = entry["violations"] == 0
        regions[code.name] = entry
    worst = int(np.argmax(np.where(judged, du, -1.0)))
    summary = {
        "points": int(x1.size),
        "excluded": int(tie.sum()),
        "rtol": rtol,
        "tolerance_mm_s": tol,
        "tie_band_mm_s": tie_band(cfg),
        "max_abs_du": float(du[worst]) if judged.any() else 0.0,
        "worst": {
            "state": [float(x1[worst]), float(x2[worst])],
            "u": float(u[worst]),
            "u_ref": float(u_ref[worst]),
            "region": Region(reg[worst]).name,
        },
        "violations": int(bad.sum()),
        "pass": not bad.any(),
        "regions": regions,
    }
    failures = []
    if bad.any():
        i = int(np.argmax(bad))
        failures.append(
            failure(
                "agreement",
                (x1[i], x2[i]),
                f"|u - u_ref| = {du[i]:.6g} mm/s > {tol:.3g} mm/s ({rtol:g} w_max) in region "
                f"{Region(reg[i]).name} (u = {u[i]:.10g}, u_ref = {u_ref[i]:.10g}); "
                f"{int(bad.sum())} of {int(judged.sum())} judged points disagree, worst "
                f"{du[worst]:.6g} mm/s at ({x1[worst]:.10g}, {x2[worst]:.10g}) in "
                f"{Region(reg[worst]).name}",
            )
        )
    return summary, failures
