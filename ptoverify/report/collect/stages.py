"""The report's independent stages, each computing and drawing one part of the report."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ptoverify.config import Config

from .parts import (
    _environment,
    _ground_truth,
    _plots,
    _poles,
    _robust,
    figure_inputs,
    tuning_results,
    write_traces,
)
from .settings import TRACE_DIR, _settings_json


def _stage_derivations(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """SymPy: the equation records and the derivation gate (the only SymPy users)."""
    import derivations
    from ptoverify.report.sections import render_records
    from ptoverify.studies.checks import run_checks

    p = cfg.plant
    plant = derivations.PlantNumbers(
        a=p.a, w_max=p.w_max, T=p.sample_time, d=cfg.pto.d, k1=cfg.pto.k1, k2=cfg.pto.k2
    )
    records = derivations.all_records(plant)
    return {
        "derivations": [r.to_json() for r in records],
        "_records": records,
        "_rendered": render_records(records),  # MathML and units: SymPy work, done here
        "_checks": run_checks(cfg, [SYMBOLIC_GATE]),
    }


def _stage_ground_truth(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """CasADi: the minimum-time table, the convergence study, and the environment."""
    gt = _ground_truth(cfg)
    files = [] if figdir is None else _plots().save_ground_truth(gt.pop("_study"), figdir)
    return {"ground_truth": gt, "environment": _environment(cfg), "_files": files}


def _stage_core(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Zones, poles, properties, claims and the numeric gates (they share memoized work)."""
    from ptoverify.model.zones import zone_summary
    from ptoverify.studies.checks import GATES, GateContext, run_checks
    from ptoverify.studies.claims import evaluate_claims, response_metrics
    from ptoverify.studies.properties import all_properties

    props = all_properties(cfg)
    ctx = GateContext(cfg, given_pto_properties=props["pto"])
    here = [g for g in GATES if g != SYMBOLIC_GATE and g not in POLE_GATES + PROOF_GATES]
    return {
        "zone": zone_summary(cfg),
        "properties": {k: v.to_json() for k, v in props.items()},
        "claims": [c.to_json() for c in evaluate_claims(cfg)],
        "responses": response_metrics(cfg),
        "_checks": run_checks(cfg, here, context=ctx),
    }


def _stage_sweep(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Run the suboptimality sweep and draw its maps."""
    from ptoverify.studies.sweep import run_sweep

    sweep = run_sweep(cfg)
    return {
        "sweep": {
            "laws": {k: v.to_json() for k, v in sweep.laws.items()},
            "grid": list(sweep.x1.shape),
            "steps": sweep.steps,
            "velocity_band": sweep.velocity_band,
            "skipped": sweep.skipped,
            "settings": _settings_json(sweep.settings),
        },
        "_files": [] if figdir is None else _plots().save_sweep(sweep, figdir),
    }


def _stage_robust(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Run the robustness study at :data:`ROBUST_SETTINGS`, judge its gates, draw its maps."""
    res, gates = _robust(cfg)
    return {
        "robust": res,
        "_checks": gates,
        "_files": [] if figdir is None else _plots().save_robust(res["maps"], figdir),
    }


def _stage_proofs(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Prove the corrected PTO and PD over the envelope (interval arithmetic), with their gates."""
    from ptoverify.studies.checks import run_checks
    from ptoverify.studies.prove import nominal_proof
    from ptoverify.studies.prove.run import prove_law

    proofs = {"pto": nominal_proof(cfg), "pd": prove_law(cfg, "pd")}
    files = []
    if figdir is not None:
        for law, proof in proofs.items():
            files.append(_plots().save_proof_map(proof, figdir / f"proof_bound_{law}.png"))
    out = {}
    for law, proof in proofs.items():
        j = proof.to_json()
        j.pop("timings_s", None)
        out[law] = j
    return {"proofs": out, "_files": files, "_checks": run_checks(cfg, list(PROOF_GATES))}


def _stage_tuning(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Run the fair tuning comparison and draw its Pareto fronts."""
    res = tuning_results(cfg)
    files = []
    if figdir is not None:
        files = _plots().save_tuning(res, figdir)
        from ptoverify.report.charts import tables_dir, write_penalty_csv

        files += _plots().save_penalty(res["penalty"], figdir, "penalty_moves_tuned")
        write_penalty_csv(res["penalty"], tables_dir(figdir) / "penalty_moves_tuned.csv")
    return {"tuning": res, "_files": files}


def _stage_charts(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Penalty against move size (configured gains) and the coarse design chart."""
    from ptoverify.report.charts import charts_stage

    return charts_stage(cfg, figdir, _plots)


def _stage_figures(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Draw the paper's figures and the zone geometry; write the responses as CSV traces."""
    if figdir is None:
        return {"_files": []}
    inputs = figure_inputs(cfg)
    traces = write_traces(inputs.sims, figdir.parent / TRACE_DIR)
    return {"_files": _plots().save_all(inputs, figdir), "_traces": traces}


def _stage_poles(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Analyse the loops' poles (python-control), with the two gates that read them."""
    from ptoverify.studies.checks import run_checks

    return {"poles": _poles(cfg), "_checks": run_checks(cfg, list(POLE_GATES))}


#: The gate that needs SymPy: it runs in the derivations' stage, the others in ``core``.
SYMBOLIC_GATE = "derivation-identities-vs-numerics"


#: The gates that read the loops' poles: they run beside the poles (their own stage).
POLE_GATES = ("pd-sampled-stable", "linear-zone-sampled-stable")


#: The gates that read the proofs: they run beside them (their own stage).
PROOF_GATES = ("proof-no-stride-over", "proof-reach")


#: The report's stages, longest first as measured (issue 23, 2026-12-07: CPU in one process,
#: imports done: tuning 8.4 s, robustness 6.2, sweep 5.2, charts 5.0, figures 4.0, closed
#: loop 2.8, derivations 2.8, proofs 2.8, ground truth 1.3, poles 0.2): the order the
#: processes take them in, so the longest starts first and the short ones fill in at the end.
_STAGE_FUNCTIONS: dict[str, Callable[[Config, Path | None], dict[str, Any]]] = {
    "tuning": _stage_tuning,
    "robustness": _stage_robust,
    "suboptimality sweep": _stage_sweep,
    "penalty and design chart": _stage_charts,
    "paper figures": _stage_figures,
    "closed loop, claims and gates": _stage_core,
    "derivations": _stage_derivations,
    "proofs": _stage_proofs,
    "ground truth": _stage_ground_truth,
    "poles": _stage_poles,
}


_SKIP_STAGE = {"robust": "robustness", "tuning": "tuning", "charts": "penalty and design chart"}


def _run_stage(name: str, cfg: Config, figdir: Path | None) -> tuple[dict[str, Any], float]:
    """Run one stage; return its results and its wall time [s] (a pool's task)."""
    t0 = time.perf_counter()
    out = _STAGE_FUNCTIONS[name](cfg, figdir)
    return out, time.perf_counter() - t0


#: The stages ``collect`` runs (and announces as each ends), longest first.
STAGES = tuple(_STAGE_FUNCTIONS)
