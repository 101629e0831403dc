"""Agreement with the reference law (the PTO, or a baseline), region by region.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions).  The probed states and tables are in :mod:`ptoverify.conform.probes`,
the reference law and the float64 tie band in :mod:`ptoverify.conform.reflaw`
(both re-exported here).  Here:

* :func:`agreement`: |u - u_ref| <= rtol w_max per reference region (default
  rtol = 1e-6), with the largest |du| and its state.  Points outside |x1| < d
  within ``tie_band`` = 1e-9 (w_max + a position_range) mm/s of a computed
  curve (l1/l2 or l1*/l2*) are excluded and counted: a float tie there can
  flip the region, and u jumps by up to 2 w_max.  The linear-zone edge
  |x1| = d, x2 = 0 and the origin are exact float comparisons, so nothing near
  them is excluded.  With ``precision="float32"`` the reference is evaluated
  at the state rounded to float32 and the float32 ties of
  :mod:`ptoverify.conform.precision` are excluded too.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.probes import (
    LATTICE,
    MATCH_TOL,
    N_BAND,
    N_RANDOM,
    RANDOM_SEED,
    band_states,
    conformance_grid,
    grid_csv,
    probe_set,
    random_states,
    read_table,
    table_coverage,
)
from ptoverify.conform.reflaw import (
    DEFAULT_RTOL,
    failure,
    has_curves,
    omega0_ref,
    reference,
    tie_band,
)
from ptoverify.model.curves import level_residual, switching_function
from ptoverify.model.laws import Region

__all__ = [
    "DEFAULT_RTOL",
    "reference",
    "tie_band",
    "omega0_ref",
    "failure",
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
    "ties",
    "reference_values",
    "agreement",
    "region_counts",
    "largest_gap",
]


def ties(x1: NDArray, x2: NDArray, cfg: Config) -> NDArray[np.bool_]:
    """Points outside |x1| < d within TIE_BAND of l1/l2 or l1*/l2* (region may flip).

    None for a baseline reference (:func:`ptoverify.conform.reflaw.has_curves`):
    it is continuous in the state, so no float tie flips its u.
    """
    if not has_curves(cfg):
        return np.zeros(np.shape(x1), dtype=bool)
    a, w = cfg.plant.a, cfg.plant.w_max
    band = tie_band(cfg)
    near = np.abs(switching_function(x1, x2, a, w)) <= band
    om = omega0_ref(cfg)
    if om is not None:
        near |= np.abs(level_residual(x1, x2, a, om)) <= band
    return near & (np.abs(x1) >= cfg.pto.d)


def reference_values(
    x1: NDArray, x2: NDArray, cfg: Config, chunk: int = 1_000_000, precision: str = "float64"
) -> tuple[NDArray, NDArray, NDArray]:
    """Return u_ref, region codes and the tie mask, computed a million states at a time.

    In ``float32`` mode the reference is evaluated at the state rounded to
    float32 and the ties include :func:`ptoverify.conform.precision.float32_ties`.

    Parameters
    ----------
    x1, x2 : ndarray
        States [mm], [mm/s].
    cfg : Config
        Configuration.
    chunk : int
        States per evaluation.
    precision : str
        ``float64`` or ``float32``.

    Returns
    -------
    u_ref : ndarray
        The reference's u [mm/s].
    region : ndarray of int8
        Reference region codes.
    tie : ndarray of bool
        Ties (excluded from the agreement).
    """
    from ptoverify.conform.precision import as_seen, float32_ties

    u_ref, reg = np.empty(x1.size), np.empty(x1.size, dtype=np.int8)
    tie = np.empty(x1.size, dtype=bool)
    om = omega0_ref(cfg) if precision == "float32" else None
    for i in range(0, x1.size, chunk):
        s = slice(i, i + chunk)
        y1, y2 = as_seen(x1[s], x2[s], precision)
        u_ref[s], reg[s] = reference(cfg)(y1, y2)
        tie[s] = ties(y1, y2, cfg)
        if precision == "float32" and has_curves(cfg):  # a baseline is continuous
            tie[s] |= float32_ties(y1, y2, cfg, om)
    return u_ref, reg, tie


def region_counts(x1: NDArray, x2: NDArray, cfg: Config) -> dict[str, int]:
    """Count states per reference region (regions with none left out).

    Parameters
    ----------
    x1, x2 : ndarray
        States [mm], [mm/s].
    cfg : Config
        Configuration of the reference law.

    Returns
    -------
    dict
        Region name -> number of states.
    """
    _, reg, _ = reference_values(np.asarray(x1, float), np.asarray(x2, float), cfg)
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
    x1: NDArray,
    x2: NDArray,
    u: NDArray,
    cfg: Config,
    rtol: float = DEFAULT_RTOL,
    *,
    precision: str = "float64",
    keep: dict | None = None,
) -> tuple[dict, list[dict]]:
    """Compare u with the reference law, region by region.

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
    precision : str
        ``float64``, or ``float32``: the reference at the state rounded to
        float32, float32 ties excluded (:mod:`ptoverify.conform.precision`).
    keep : dict, optional
        Receives ``reference``: (u_ref, region, tie) of :func:`reference_values` at
        the states (the report's maps read them instead of computing them again).

    Returns
    -------
    summary : dict
        ``precision``, ``points``, ``excluded``, ``tolerance_mm_s``, ``max_abs_du``, ``worst``,
        ``regions`` (per reference region: points, excluded, max_abs_du, state,
        u, u_ref, violations).
    failures : list of dict
        One ``agreement`` failure (first state in order, worst named) or none.
    """
    w = cfg.plant.w_max
    tol = rtol * w
    u_ref, reg, tie = reference_values(x1, x2, cfg, precision=precision)
    if keep is not None:
        keep["reference"] = (u_ref, reg, tie)
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
        "precision": precision,
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
