"""``conform --table``: a table of the implementation's values judged where it has points.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions, "Tables"): coverage of the probe set or of the envelope, agreement,
|u| <= w_max and odd symmetry at mirrored grid states; the closed-loop
properties need a callable and are ``not_run``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import (
    DEFAULT_RTOL,
    LATTICE,
    MATCH_TOL,
    agreement,
    conformance_grid,
    failure,
    random_states,
    read_table,
    region_counts,
    table_coverage,
    ties,
)
from ptoverify.conform.closedloop import CLOSED_PROPERTIES
from ptoverify.conform.reflaw import has_curves
from ptoverify.conform.result import ConformResult, agreement_verdict, input_bound
from ptoverify.model.laws import Region
from ptoverify.model.memo import memo
from ptoverify.verdict import FAIL, NOT_RUN, PASS, Verdict

__all__ = ["MIN_PER_REGION", "conform_table", "judge_table"]

MIN_PER_REGION = 100  #: judged table states per reference region (the origin: 1)


@memo(maxsize=8)
def _needed_regions(cfg: Config) -> tuple[str, ...]:
    """Return the reference's regions a table must populate: those it has on the grid.

    A baseline: only its regions of positive area (those the lattice states meet).
    """
    need = region_counts(*conformance_grid(cfg), cfg)
    if not has_curves(cfg):  # a baseline: only its regions of positive area (module docstring)
        lattice = region_counts(*random_states(cfg, LATTICE * LATTICE), cfg)
        need = {k: v for k, v in need.items() if k in lattice}
    return tuple(need)


def _coverage(agree: dict, cov: dict, cfg: Config) -> Verdict:
    """Judge coverage: the probe set held, or the lattice filled and every region populated."""
    need = _needed_regions(cfg)
    have = {k: v["points"] - v["excluded"] for k, v in agree["regions"].items()}
    short = []
    for name in need:
        want = 1 if name == Region.ORIGIN.name else MIN_PER_REGION
        if have.get(name, 0) < want:
            short.append(f"{name} {have.get(name, 0)} < {want}")
    rule = (
        f"the table must hold the {cov['probes']} states of --emit-grid (within "
        f"{MATCH_TOL:g} of position_range and w_max), or else a state in each of the "
        f"{LATTICE} x {LATTICE} cells of the envelope and {MIN_PER_REGION} judged states in "
        f"each region of {', '.join(need)} (the origin 1)"
    )
    if cov["missing"] == 0:
        detail = f"holds all {cov['probes']} states of --emit-grid"
        return Verdict("coverage", PASS, 0, 0, detail, "<=", "states missing")
    m = cov["first_missing"]
    held = (
        f"{cov['missing']} of {cov['probes']} states of --emit-grid missing (first "
        f"({m[0]:.10g}, {m[1]:.10g}))"
    )
    if cov["empty_cells"] == 0 and not short:
        detail = f"{held}, but the table fills all {cov['cells']} cells and every region"
        return Verdict("coverage", PASS, 0, 0, detail, "<=", "cells empty")
    gaps = []
    if cov["empty_cells"]:
        e = cov["first_empty"]
        gaps.append(
            f"{cov['empty_cells']} of {cov['cells']} cells empty (first centred at "
            f"({e[0]:.4g}, {e[1]:.4g}))"
        )
    if short:
        gaps.append("too few states in " + ", ".join(short))
    detail = f"insufficient coverage: {held}; {'; '.join(gaps)}; {rule}"
    return Verdict("coverage", FAIL, cov["missing"], 0, detail, "<=", "states missing")


def _table_symmetry(x1, x2, u, rows, cfg: Config, rtol: float) -> tuple[Verdict, list[dict]]:
    """u(-x) = -u(x) at the grid states whose exact mirror the table also holds."""
    name = "odd-symmetry"
    tol = rtol * cfg.plant.w_max
    mirror = rows[::-1]  # the grid is sorted and symmetric: state i mirrors state n-1-i
    ok = (rows >= 0) & (mirror >= 0)
    i, j = rows[ok], mirror[ok]
    exact = (x1[i] == -x1[j]) & (x2[i] == -x2[j])
    i, j = i[exact], j[exact]
    if not i.size:
        why = "no grid state and its exact mirror in the table (needs the --emit-grid states)"
        return Verdict(name, NOT_RUN, None, None, why), []
    err = np.abs(u[i] + u[j])
    bad = err > tol
    tie = ties(x1[i], x2[i], cfg)
    v = Verdict(
        name,
        FAIL if bad.any() else PASS,
        float(err.max()),
        tol,
        f"max |u(x) + u(-x)| over {i.size} table states whose mirror the table holds, "
        f"{int(tie.sum())} of them curve ties (a mirrored tie must take the mirrored branch)",
        "<=",
        "mm/s",
    )
    if not bad.any():
        return v, []
    k = int(np.argmax(bad))
    on = " (a curve tie)" if tie[k] else ""
    a, b = int(i[k]), int(j[k])
    return v, [failure(name, (x1[a], x2[a]), f"u(x) = {u[a]:.10g}, u(-x) = {u[b]:.10g} mm/s{on}")]


def conform_table(
    path: str | Path,
    cfg: Config,
    *,
    rtol: float = DEFAULT_RTOL,
    keep: dict | None = None,
    precision: str = "float64",
) -> ConformResult:
    """Judge a table x1, x2, u (CSV) against the reference where it has points.

    Reads the file (:func:`ptoverify.conform.agreement.read_table`), then
    :func:`judge_table`.

    Parameters
    ----------
    path : str or Path
        CSV with columns x1, x2, u (a regular file).
    cfg : Config
        Configuration.
    rtol : float
        Agreement tolerance relative to w_max.
    keep : dict, optional
        Receives ``states`` = (x1, x2, u), the table's states and values, and
        ``reference`` = (u_ref, region, tie) there (:func:`agreement`).
    precision : str
        ``float64`` or ``float32`` (:mod:`ptoverify.conform.precision`).

    Returns
    -------
    ConformResult
        As :func:`judge_table`, with the time the read took.
    """
    from ptoverify.conform.precision import check_precision

    check_precision(precision)  # before the read (judge_table checks it too, for its own callers)
    t0 = time.perf_counter()
    x1, x2, u = read_table(path, cfg)
    t_read = time.perf_counter() - t0
    return judge_table(
        x1, x2, u, cfg, source=str(path), rtol=rtol, keep=keep, precision=precision, t_read=t_read
    )


def judge_table(
    x1: NDArray[np.float64],
    x2: NDArray[np.float64],
    u: NDArray[np.float64],
    cfg: Config,
    *,
    source: str = "table",
    rtol: float = DEFAULT_RTOL,
    keep: dict | None = None,
    precision: str = "float64",
    t_read: float = 0.0,
) -> ConformResult:
    """Judge a table's values u at its states (x1, x2), as ``conform --table`` does.

    Parameters
    ----------
    x1, x2 : ndarray
        The table's states [mm], [mm/s], in row order.
    u : ndarray
        The implementation's value at each state [mm/s].
    cfg : Config
        Configuration.
    source : str
        What the table is, for the result (the file name for ``--table``).
    rtol : float
        Agreement tolerance relative to w_max.
    keep : dict, optional
        As :func:`conform_table`.
    precision : str
        ``float64`` or ``float32`` (:mod:`ptoverify.conform.precision`).
    t_read : float
        Time the table took to read [s], for ``timings_s``.

    Returns
    -------
    ConformResult
        ``coverage``, ``agreement``, ``input-bound-grid`` and ``odd-symmetry``
        (at mirrored grid states); closed-loop properties ``not_run``.
    """
    from ptoverify.conform.precision import check_precision

    check_precision(precision)
    t0 = time.perf_counter() - t_read
    if keep is not None:
        keep["states"] = (x1, x2, u)
    agree, failures = agreement(x1, x2, u, cfg, rtol, precision=precision, keep=keep)
    agree["sources"] = {"table": int(x1.size)}
    cov = table_coverage(x1, x2, cfg)
    agree["coverage"] = {k: v for k, v in cov.items() if k != "grid_rows"}
    props = {"coverage": _coverage(agree, cov, cfg), "agreement": agreement_verdict(agree)}
    if not props["coverage"].passed:
        failures.insert(
            0, {"property": "coverage", "state": None, "detail": props["coverage"].detail}
        )
    props["input-bound-grid"], f = input_bound(x1, x2, u, cfg, "at the table's states")
    failures += f
    props["odd-symmetry"], f = _table_symmetry(x1, x2, u, cov["grid_rows"], cfg, rtol)
    failures += f
    for name in CLOSED_PROPERTIES:
        props[name] = Verdict(name, NOT_RUN, None, None, "needs a callable law (--law)")
    ok = not failures and agree["pass"] and props["coverage"].passed
    total = time.perf_counter() - t0
    return ConformResult(
        ok,
        "table",
        source,
        f"table of {x1.size} states",
        agree,
        props,
        failures,
        {"read": round(t_read, 4), "total": round(total, 4)},
        cfg.name,
        precision=precision,
        reference=cfg.conform.reference,
    )
