"""The claims at the laws' fair tunings, and the step-response metrics."""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.model.memo import memo
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.sim import metrics as mt
from ptoverify.sim.metrics import STEP_FRACTION
from ptoverify.sim.simulate import reference
from ptoverify.studies.tune import (
    FAIR_BOUNDS,
    Candidate,
    TuneBudget,
    fair_tunings,
    front_gap,
    pareto_front,
    worst_ratio_nt,
)
from ptoverify.studies.tune import response_metrics as tune_response_metrics

from .catalogue import CLAIMS
from .evaluate import evaluate_claims
from .measure import _sim
from .sentences import TUNED_CLAIMS


@memo(maxsize=8)
def _response_metrics(cfg: Config) -> dict[str, dict[str, dict[str, float]]]:
    out: dict[str, dict[str, dict[str, float]]] = {}
    for law in ("to", "pd", "pto", "pto-printed"):
        d = {"to": None, "pd": math.inf}.get(law, cfg.pto.d)
        out[law] = {
            sig: mt.summarize(_sim(cfg, law, sig, "feed-forward"), cfg.plant, d=d)
            for sig in ("step", "ramp", "sine")
        }
    return out


def response_metrics(cfg: Config) -> dict[str, dict[str, dict[str, float]]]:
    """Metrics of every Section 6 response under the primary reading, exact and on the grid.

    The responses the claims are measured on (a as configured, feed-forward),
    summarized by :func:`ptoverify.sim.metrics.summarize`: each time metric between
    samples with its sample-grid twin under ``<key>_grid``, and the linear-zone
    entry with the law's zone (PTO: |r - x1| <= d; PD: linear everywhere, 0;
    TO: none, NaN).  For a report to show both values where they differ.

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    dict
        law (``to``, ``pd``, ``pto``, ``pto-printed``) -> signal (``step``,
        ``ramp``, ``sine``) -> metric name -> value (a new dict over cached values).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> m = response_metrics(paper_config())["pd"]["step"]
    >>> m["overshoot_mm"] >= m["overshoot_mm_grid"]
    True
    """
    return {
        law: {sig: dict(v) for sig, v in by_sig.items()}
        for law, by_sig in _response_metrics(cfg).items()
    }


# ------------------------------------------------------------------ fair comparison
def _cand_json(c: Candidate) -> dict[str, Any]:
    j = c.to_json()
    keys = ("gains", "omega0", "settling_2pct_s", "overshoot_mm", "verified", "feasible")
    return {k: j[k] for k in keys}


def fair_comparison(cfg: Config, budget: TuneBudget | None = None) -> dict[str, Any]:
    """Everything the report section "Can any tuning reproduce the paper?" shows.

    Parameters
    ----------
    cfg : Config
        Configuration (plant and the paper's gains).
    budget : TuneBudget, optional
        Search effort of the tunings; default :class:`~ptoverify.studies.tune.TuneBudget`.

    Returns
    -------
    dict
        ``bounds_mm`` (name -> [mm]) and ``bound_meaning`` (name -> words);
        ``floor``: the step's ``nt_s`` (N* T) and ``tf_s`` (t_f*) [s], the
        least times to reach the target exactly, and ``band_entry_s`` [s], the
        least time to reach the 2 % band at all (full input from rest: a lower
        bound of any 2 % settling time, which can lie below t_f* since the band
        is entered before the target is reached); ``paper``: law -> the step's metrics at
        the paper's gains plus ``worst_ratio_nt``; ``fronts``: law -> the Pareto
        front of 2 % settling [s] vs overshoot [mm] over every candidate the
        tunings evaluated (cheap constraints; ``verified`` marks those checked on
        the gate grid), by increasing overshoot; ``fronts_gap``: the PTO's front
        minus the PD's (:class:`~ptoverify.studies.tune.FrontGap` as JSON, or
        ``None`` where the fronts do not overlap); ``best``: bound name -> law ->
        the best tuned gains with ``settling_2pct_s``, ``overshoot_mm``,
        ``rise_time_s``, ``settling_0p01mm_s`` and ``worst_ratio_nt`` (over the
        :data:`~ptoverify.studies.tune.WORST_GRID` envelope grid); ``claims``: one entry per claim
        judged at the best tuning (``id``, ``verdict``, ``sentence``,
        ``readings``); ``evaluations``, ``seconds``, ``budget``.
    """
    ft = fair_tunings(cfg, budget)
    step = reference("step").amplitude
    a, w = cfg.plant.a, cfg.plant.w_max
    dist = (1.0 - STEP_FRACTION) * abs(step)  # to the edge of the 2 % band, from rest
    from scipy.optimize import brentq

    floor = {
        "nt_s": float(discrete_min_steps_batch([-step], [0.0], cfg.plant).time_s[0]),
        "tf_s": float(min_time(np.array([-step]), np.array([0.0]), cfg.plant).t_f[0]),
        "band_entry_s": float(
            brentq(
                lambda t: w * (t - (1.0 - math.exp(-a * t)) / a) - dist,
                0.0,
                dist / w + 1.0,
                xtol=1e-15,
            )
        ),
    }
    paper = {law: dict(m, worst_ratio_nt=worst_ratio_nt(cfg, law)) for law, m in ft.paper.items()}
    fronts = {}
    for law in ("pd", "pto"):
        pool = [c for (lw, _), r in ft.results.items() if lw == law for c in r.front]
        uniq = {tuple(sorted(c.gains.items())): c for c in pool}
        fronts[law] = pareto_front(list(uniq.values()))
    gap = front_gap("pto", fronts["pto"], "pd", fronts["pd"])
    best: dict[str, dict[str, Any]] = {}
    for name in ft.bounds:
        best[name] = {}
        for law in ("pd", "pto"):
            r = ft.results[(law, name)]
            m = tune_response_metrics(r.config, law, "step")
            best[name][law] = _cand_json(r.best) | {
                "rise_time_s": m["rise_time_s"],
                "settling_0p01mm_s": m["settling_0p01mm_s"],
                "worst_ratio_nt": worst_ratio_nt(r.config, law),
                "evaluations": r.evaluations,
            }
    # only the claims judged at the tuning (their paper-gain readings come along)
    results = evaluate_claims(
        cfg, tuple(c for c in CLAIMS if c.id in TUNED_CLAIMS), tuned=True, budget=budget
    )
    claims = []
    for c in results:
        if c.id not in TUNED_CLAIMS:
            continue
        tuned = [r for r in c.readings if r.reading.gains is not None]
        claims.append(
            {
                "id": c.id,
                "claim": c.claim,
                "verdict": c.verdict_tuned,
                "sentence": TUNED_CLAIMS[c.id](c, tuned),
                "readings": [r.to_json() for r in tuned],
            }
        )
    uniq_runs = {id(r): r for r in ft.results.values()}.values()
    return {
        "bounds_mm": dict(ft.bounds),
        "bound_meaning": dict(FAIR_BOUNDS),
        "floor": floor,
        "paper": paper,
        "fronts": {law: [_cand_json(c) for c in f] for law, f in fronts.items()},
        "fronts_gap": None if gap is None else gap.to_json(),
        "best": best,
        "claims": claims,
        "evaluations": sum(r.evaluations for r in uniq_runs),
        "seconds": ft.seconds,
        "budget": asdict(ft.budget),
    }
