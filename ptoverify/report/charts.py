"""The report's penalty-against-move-size curves and its coarse design chart (collect side).

Two results the report adds beside the paper's design point (issue 25):

- :func:`penalty_results`: each law's settling time of point-to-point moves from
  rest against the move size, beside t_f* and N* T
  (:func:`ptoverify.studies.penalty.penalty_curves`), at the configured gains
  here and at each law's best tuning in the tuning stage;
- :func:`design_results`: a coarse design chart, :data:`CHART_SAMPLE_TIMES` x
  :data:`CHART_BANDWIDTHS_HZ` (5 x 5 points) under the reading a = 2 pi f, every
  law at the configured gains (:func:`ptoverify.studies.design.design_chart`,
  exactly what ``ptoverify design`` gives at those points), with the counts the
  report's verdict across the chart states (:func:`chart_summary`).

Both are JSON-able dicts for ``results.json``; the report's sections only read them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from ptoverify.config import Config

__all__ = [
    "PENALTY_LAWS",
    "CHART_SAMPLE_TIMES",
    "CHART_BANDWIDTHS_HZ",
    "CHART_LAWS",
    "penalty_results",
    "design_results",
    "chart_summary",
    "write_penalty_csv",
    "tuned_penalty",
    "tables_dir",
    "charts_stage",
]

#: The laws of the penalty curves.
PENALTY_LAWS = ("to", "pd", "pto", "ptos", "cascade-p")
#: The coarse chart's sample times [s]: ``design``'s defaults less 0.25 ms, which the
#: configuration check rejects at 5 Hz (a T < 0.01).
CHART_SAMPLE_TIMES = (0.0005, 0.001, 0.002, 0.004, 0.008)
#: The coarse chart's bandwidths [Hz] (``design``'s defaults).
CHART_BANDWIDTHS_HZ = (5.0, 10.0, 30.0, 60.0, 100.0)
#: The laws of the coarse chart.
CHART_LAWS = ("pd", "pto", "ptos", "cascade-p")


def penalty_results(
    cfg: Config, configs: dict[str, Config] | None = None, setting: str = "configured"
) -> dict[str, Any]:
    """Return the penalty curves of :data:`PENALTY_LAWS` as JSON (less the wall time).

    Parameters
    ----------
    cfg : Config
        Configuration (plant, gains).
    configs : dict, optional
        Law name -> the configuration of its gains (e.g. its best tuning).
    setting : str
        Whose gains (recorded).

    Returns
    -------
    dict
        :meth:`ptoverify.studies.penalty.PenaltyResult.to_json` less ``seconds``,
        plus ``definition_description`` (the named settling definition's
        description, :data:`ptoverify.sim.settling.DEFINITIONS`), ``count`` (move
        sizes) and per law ``never_settled`` (sizes it never settles from).
    """
    from ptoverify.sim.settling import definition
    from ptoverify.studies.penalty import penalty_curves

    res = penalty_curves(cfg, PENALTY_LAWS, configs=configs, setting=setting).to_json()
    res.pop("seconds", None)
    res["definition_description"] = definition(res["settling_definition"]).description
    res["count"] = len(res["sizes_mm"])
    for c in res["laws"].values():
        c["never_settled"] = sum(t is None for t in c["settling_s"])
    return res


def write_penalty_csv(penalty: Mapping, path: Path) -> Path:
    """Write the penalty curves of ``results.json`` as CSV: one row per (law, size).

    Parameters
    ----------
    penalty : Mapping
        :func:`penalty_results`.
    path : Path
        The file.

    Returns
    -------
    Path
        The file written.
    """
    cols = ["settling_s", "arrival_s", "ratio_nt", "ratio_tf"]
    lines = [",".join(["law", "size_mm", "t_f_s", "n_star", "nt_s", *cols])]

    def cell(v: Any) -> str:
        return "" if v is None else repr(v)

    for law, c in penalty["laws"].items():
        for i, s in enumerate(penalty["sizes_mm"]):
            row = [law, cell(s), cell(penalty["t_f_s"][i]), str(penalty["n_star"][i])]
            row += [cell(penalty["nt_s"][i])] + [cell(c[k][i]) for k in cols]
            lines.append(",".join(row))
    path.write_text("\n".join(lines) + "\n")
    return path


def _number(v: Any) -> float | None:
    """Return a finite number of the chart JSON as float, else None (inf, NaN are strings)."""
    return float(v) if isinstance(v, (int, float)) and math.isfinite(v) else None


def chart_summary(points: list[Mapping], cfg: Config) -> dict[str, Any]:
    """Return the counts and extremes the verdict across the chart states.

    Parameters
    ----------
    points : list of Mapping
        The chart's points (:meth:`ptoverify.studies.design.DesignChart.to_json`).
    cfg : Config
        The configuration (its T and bandwidth name the paper's cell).

    Returns
    -------
    dict
        ``cells``; ``fastest``: law -> {``cells`` where it has the least median
        settling / N*T, ``by_max``: its largest lead there (runner-up's median
        over its own [-])}; ``pto_zone_unusable``, ``pto_zone_degenerate``,
        ``pto_delay_unstable`` (cells where the PTO's linear zone has spectral
        radius >= 1 with one sample of delay), each a count, with the
        (T [s], bandwidth [Hz]) of those cells; ``paper_cell``: the index of the
        configuration's own (T, bandwidth), or None when off the chart.
    """
    fastest: dict[str, dict[str, Any]] = {}
    unusable, degenerate, delay = [], [], []
    paper = None
    for i, p in enumerate(points):
        cell = [p["sample_time"], p["bandwidth_hz"]]
        if p["fastest"]:
            f = fastest.setdefault(p["fastest"], {"cells": 0, "by_max": None})
            f["cells"] += 1
            by = _number(p["fastest_by"])
            if by is not None and (f["by_max"] is None or by > f["by_max"]):
                f["by_max"] = by
        if not p["pto_zone_usable"]:
            unusable.append(cell)
        if p["pto_zone_degenerate"]:
            degenerate.append(cell)
        pto = next((r for r in p["laws"] if r["law"] == "pto"), None)
        rho = None if pto is None else _number(pto["radius_delay1"])
        if rho is not None and rho >= 1.0:
            delay.append(cell)
        if (
            cfg.bandwidth_hz is not None
            and math.isclose(p["sample_time"], cfg.plant.sample_time, rel_tol=1e-12)
            and math.isclose(p["bandwidth_hz"], cfg.bandwidth_hz, rel_tol=1e-12)
        ):
            paper = i
    return {
        "cells": len(points),
        "fastest": fastest,
        "pto_zone_unusable": len(unusable),
        "pto_zone_unusable_cells": unusable,
        "pto_zone_degenerate": len(degenerate),
        "pto_zone_degenerate_cells": degenerate,
        "pto_delay_unstable": len(delay),
        "pto_delay_unstable_cells": delay,
        "paper_cell": paper,
    }


def design_results(cfg: Config) -> dict[str, Any]:
    """Return the coarse design chart as JSON, with its summary (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (w_max, range and gains; its own T and bandwidth are one cell
        when they lie on the chart).

    Returns
    -------
    dict
        :meth:`ptoverify.studies.design.DesignChart.to_json` without timings, plus
        ``summary`` (:func:`chart_summary`).
    """
    from ptoverify.studies.design import design_chart

    chart = design_chart(
        cfg, list(CHART_SAMPLE_TIMES), list(CHART_BANDWIDTHS_HZ), laws=CHART_LAWS, reading="2pi"
    )
    res = chart.to_json(timings=False)
    res["summary"] = chart_summary(res["points"], cfg)
    return res


def tuned_penalty(cfg: Config, budget: Any) -> dict[str, Any]:
    """Penalty curves at each law's best tuning under the shared bound (the versus bound).

    Parameters
    ----------
    cfg : Config
        Configuration.
    budget : TuneBudget
        The search effort (the tunings are those of :func:`tuning_results`, cached).

    Returns
    -------
    dict
        :func:`ptoverify.report.charts.penalty_results` at the tuned gains.
    """
    from ptoverify.report.charts import PENALTY_LAWS, penalty_results
    from ptoverify.studies.ptos_claim import fair_configs
    from ptoverify.studies.versus import BOUND

    configs = fair_configs(cfg, PENALTY_LAWS, BOUND, budget=budget)
    return penalty_results(cfg, configs, f"tuned {BOUND}")


def tables_dir(figdir: Path) -> Path:
    """Return the report's folder of CSV tables (``tables/`` beside ``figures/``), created.

    Parameters
    ----------
    figdir : Path
        The report's figure folder.

    Returns
    -------
    Path
        ``figdir/../tables``.
    """
    path = figdir.parent / "tables"
    path.mkdir(parents=True, exist_ok=True)
    return path


def charts_stage(cfg: Config, figdir: Path | None, plots: Callable[[], Any]) -> dict[str, Any]:
    """Run the report's charts stage: penalty (configured gains) and the coarse chart.

    Parameters
    ----------
    cfg : Config
        Configuration.
    figdir : Path or None
        Figure folder (None: nothing drawn or written).
    plots : callable
        Returns the plotting package (imported only when drawing).

    Returns
    -------
    dict
        ``charts`` (``penalty``, ``design``) and ``_files`` (figures written); the
        penalty CSV goes to ``tables/penalty_moves.csv``.
    """
    charts = {"penalty": penalty_results(cfg), "design": design_results(cfg)}
    files = []
    if figdir is not None:
        files = plots().save_charts(charts, figdir)
        write_penalty_csv(charts["penalty"], tables_dir(figdir) / "penalty_moves.csv")
    return {"charts": charts, "_files": files}
