"""Conformance grid, tables, and agreement with the reference PTO law, region by region.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform` has the command's
decisions).  Here:

* :func:`conformance_grid`: the states ``--emit-grid`` writes, dense near l1,
  l2, l1*, l2* (the zone boundary), the switching zone, |x1| = d, the origin
  and |x2| = w_max;
* :func:`read_table`: a CSV with columns x1, x2, u;
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
from ptoverify.verdict import FAIL, NOT_RUN, PASS, UNVERIFIED  # noqa: F401 - re-exported

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
    "input_bound",
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


def read_table(path: str | Path) -> tuple[NDArray, NDArray, NDArray]:
    """Read a CSV with a header naming columns x1, x2, u (others ignored).

    Parameters
    ----------
    path : str or Path
        CSV file.

    Returns
    -------
    x1, x2, u : ndarray
        States [mm], [mm/s] and the implementation's input [mm/s].

    Raises
    ------
    InputError
        Unreadable file, missing column, empty table, a field that is not a
        finite number (line and column named).
    """
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(
            f"cannot read table '{path}': {getattr(exc, 'strerror', None) or exc}"
        ) from None
    except csv.Error as exc:
        raise InputError(f"table '{path}': malformed CSV: {exc}") from None
    if not rows:
        raise InputError(f"table '{path}' is empty")
    header = [h.strip() for h in rows[0]]
    cols = {}
    for name in ("x1", "x2", "u"):
        if name not in header:
            raise InputError(
                f"table '{path}': no column '{name}' in header {','.join(header)} (need x1, x2, u)"
            )
        cols[name] = header.index(name)
    data = []
    for line, row in enumerate(rows[1:], start=2):
        if not any(f.strip() for f in row):
            continue
        vals = []
        for name, j in cols.items():
            text = row[j].strip() if j < len(row) else ""
            try:
                v = float(text)
            except ValueError:
                v = math.nan
            if not math.isfinite(v):
                raise InputError(
                    f"table '{path}' line {line}: column {name} = {text!r} is not a finite number"
                )
            vals.append(v)
        data.append(vals)
    if not data:
        raise InputError(f"table '{path}' has a header but no rows")
    arr = np.array(data, dtype=float)
    return arr[:, 0].copy(), arr[:, 1].copy(), arr[:, 2].copy()


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
    u_ref, reg = reference(cfg)(x1, x2)
    du = np.abs(u - u_ref)
    tie = ties(x1, x2, cfg)
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


def input_bound(x1: NDArray, x2: NDArray, u: NDArray, cfg: Config, where: str):
    """Judge |u| <= w_max at the given states; returns (property, failures)."""
    w = cfg.plant.w_max
    over = np.abs(u) > w
    prop = {
        "status": FAIL if over.any() else PASS,
        "measured": float(np.abs(u).max()),
        "limit": w,
        "detail": f"max |u| [mm/s] {where}; limit w_max",
    }
    fails = []
    if over.any():
        i = int(np.argmax(over))
        fails.append(
            failure(
                "input-bound-grid",
                (x1[i], x2[i]),
                f"|u| = {abs(u[i]):.10g} mm/s > w_max = {w:g} mm/s {where}",
            )
        )
    return prop, fails
