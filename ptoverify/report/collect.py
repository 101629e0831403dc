"""The verification report: compute every result once, draw it, render it.

``collect(cfg)`` is the one step that computes.  It runs the report's
independent stages (:data:`STAGES`): the SymPy derivations with the derivation
gate, the closed loop (zones, properties, Section 6 claims, the numeric
gates), the robustness study, the tuning comparison, the suboptimality sweep,
the ground truth (with the environment), the paper's figures and the poles.  Each stage
draws its own figures (:mod:`ptoverify.report.plots`, which only draws) from its own
results, so nothing large travels between processes.  The stages share only
the configuration, so they can run in a pool of spawned Python processes
(``jobs`` > 1), longest first; with ``jobs=1``, the default, they run in this
process one after the other, and the results are the same either
way.  Work shared inside a stage (the corrected zone and its grid check, the
corrected PTO's closed-loop properties, the claims) is memoized per frozen
configuration in the numeric modules, and the properties section hands its
PTO properties to the gates, so each runs once.  The sections
(:mod:`ptoverify.report.sections`) render the JSON results; the neutral blocks
are printed by :mod:`ptoverify.report.render`.

Two stages are optional: the robustness study
(:func:`ptoverify.studies.robust.run_robust` at :data:`ROBUST_SETTINGS`, the command's
defaults) and the tuning comparison (:func:`tuning_results`: PD and PTO tuned
on the step under shared overshoot bounds, at the reduced search effort
:data:`TUNE_SETTINGS`).  ``skip`` (the command's ``--skip robust,tuning``)
leaves them out for a quick report; their sections then say so.  Each stage's
wall time is kept in ``res["_timings"]`` (not in ``results.json``, which stays
reproducible).

``write_report`` writes the folder atomically: everything, figures included,
goes to a temporary sibling folder that is renamed into place only when
complete, and is removed when the run fails.

Two runs give the same ``results.json`` except ``meta.generated``: wall-clock
timings are not part of the results.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import platform
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.report.render import Section, render_html, render_markdown
from ptoverify.report.results import TOP_LEVEL, Results, wrap

__all__ = [
    "collect",
    "figure_inputs",
    "build_sections",
    "write_report",
    "stderr_progress",
    "GROUND_TRUTH_STATES",
    "STAGES",
    "SKIPPABLE",
    "ROBUST_SETTINGS",
    "TUNE_SETTINGS",
    "tuning_results",
]

#: Stages ``--skip`` can leave out (the expensive ones).
SKIPPABLE = ("robust", "tuning", "charts")

#: Sizes of the report's robustness study: overrides of
#: :class:`ptoverify.studies.robust.RobustSettings`.  Empty: the report runs the same study as
#: ``ptoverify robust`` on its defaults (all four laws; a few seconds, `robust_study_s`).
ROBUST_SETTINGS: dict[str, Any] = {}

#: Search effort of the report's tunings (:class:`ptoverify.studies.tune.TuneBudget`, fixed seed),
#: reduced from ``ptoverify tune``'s defaults (30 generations, population factor 10, 9 d
#: points, 4 refinements): the four tunings take a few seconds (benchmarks/README.md).
TUNE_SETTINGS = {"maxiter": 15, "popsize": 8, "d_grid": 5, "d_refine": 2, "seed": 0}

#: States of the ground-truth table [mm], [mm/s]: a step, moves with speed, on/near a
#: curve, beyond saturation, and near the origin.
GROUND_TRUTH_STATES: tuple[tuple[float, float], ...] = (
    (5.0, 0.0),
    (-5.0, 0.0),
    (50.0, 0.0),
    (-20.0, 150.0),
    (12.0, -250.0),
    (0.3, -80.0),
    (-40.0, -290.0),
    (0.05, 0.0),
)
CONVERGENCE_INTERVALS = (10, 20, 50, 100, 200)
_TIMING_KEYS = {"seconds", "timings", "solve_time_s", "elapsed_s", "wall_s"}

Progress = Callable[[str], None]


def _clean(obj: Any) -> Any:
    """JSON-safe copy: numpy to Python, NaN/inf to None, wall-clock timings dropped."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items() if k not in _TIMING_KEYS}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, np.generic):
        return _clean(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


# ------------------------------------------------------------------ collection
def _ground_truth(cfg: Config) -> dict[str, Any]:
    from ptoverify.model.ocp import convergence_study
    from ptoverify.studies.groundtruth import verified_mintime

    p = cfg.plant
    scale = (p.position_range / 50.0, p.w_max / 300.0)
    states = [(x1 * scale[0], x2 * scale[1]) for x1, x2 in GROUND_TRUTH_STATES]
    # the study's 100-interval solves of its states serve the table too (re-simulated there)
    study = convergence_study(p, np.array(states[:4]), CONVERGENCE_INTERVALS)
    rows = []
    for i, (x1, x2) in enumerate(states):
        gt = verified_mintime(  # checked a posteriori, as mintime
            x1, x2, cfg, intervals=100, collocation=study.results.get((i, 100))
        )
        mt, r2, rc, dm = gt.closed_form, gt.two_phase, gt.collocation, gt.discrete
        t_f = float(mt.t_f)
        rows.append(
            {
                "x0": [x1, x2],
                "analytic_s": t_f,
                "switch_time_s": float(mt.t_switch),
                "two_phase_s": r2.t_f if r2.success else None,
                "two_phase_status": r2.status,
                "two_phase_rel_error": abs(r2.t_f - t_f) / t_f if r2.success else None,
                "collocation_s": rc.t_f if rc.success else None,
                "collocation_status": rc.status,
                "collocation_rel_error": abs(rc.t_f - t_f) / t_f if rc.success else None,
                "collocation_resim_error_mm": rc.resim_error,
                "discrete_steps": dm.steps if dm.success else None,
                "discrete_status": dm.status,
                "discrete_s": dm.time_s if dm.success else None,
                "discrete_gap_samples": (dm.time_s - t_f) / p.T if dm.success else None,
            }
        )
    conv = {
        "intervals": list(CONVERGENCE_INTERVALS),
        "states": states[:4],
        "rel_error": study.rel_error,
        "order": study.order,
        "order_per_state": study.order_per_state,
        "success": study.success,
    }
    return {"states": rows, "convergence": conv, "_study": study}


def _poles(cfg: Config) -> dict[str, Any]:
    from ptoverify.model.poles import all_loop_poles, lyapunov_counterexample

    return {
        "loops": {k: v.to_json() for k, v in all_loop_poles(cfg).items()},
        "lyapunov_counterexample": lyapunov_counterexample(cfg),
    }


def _properties(cfg: Config) -> dict[str, Any]:
    from ptoverify.config import BASELINE_NAMES, LAW_NAMES
    from ptoverify.studies.properties import all_properties

    # the baselines beside the paper's laws (informational: the gates judge the paper's)
    laws = LAW_NAMES + BASELINE_NAMES
    return {k: v.to_json() for k, v in all_properties(cfg, laws).items()}


def _environment(cfg: Config) -> dict[str, Any]:
    from importlib.metadata import version  # the installed versions, without importing them

    import casadi

    here = Path(__file__).resolve().parent
    try:
        commit = (
            subprocess.run(
                ["git", "rev-parse", "HEAD"],
                capture_output=True,
                text=True,
                cwd=here,
                timeout=5,
                check=False,
            ).stdout.strip()
            or None
        )
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            cwd=here,
            timeout=5,
            check=False,
        ).stdout.strip()
        if commit and dirty:
            commit += " (working tree modified)"
    except (OSError, subprocess.SubprocessError):
        commit = None
    ipopt_version = _ipopt_version(casadi)
    from ptoverify import __version__

    return {
        "python": platform.python_version(),
        "ptoverify": __version__,
        "casadi": casadi.__version__,
        "ipopt": ipopt_version,
        "sympy": version("sympy"),
        "control": version("control"),
        "numpy": np.__version__,
        "scipy": version("scipy"),
        "platform": platform.platform(),
        "git_commit": commit,
        "config": cfg.to_mapping(),
    }


def _ipopt_version(casadi) -> str:
    """IPOPT's version, read from the banner of a one-variable solve (bundled with CasADi)."""
    import io
    import re
    from contextlib import redirect_stdout

    x = casadi.SX.sym("x")
    buf = io.StringIO()
    try:
        with redirect_stdout(buf):
            casadi.nlpsol(
                "probe",
                "ipopt",
                {"x": x, "f": (x - 1) ** 2},
                {"ipopt.print_level": 5, "print_time": False},
            )(x0=0)
    except Exception:  # noqa: BLE001 - environment probe only
        return "unknown"
    m = re.search(r"Ipopt version (\S+)", buf.getvalue())
    return m.group(1).rstrip(",") if m else "bundled with casadi"


# ------------------------------------------------------------------ figure inputs
def figure_inputs(cfg: Config) -> Any:
    """Simulate and construct everything the figures draw (plots only draw).

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    ptoverify.report.plots.FigureInputs
        Open-loop arcs under +-w_max (Fig. 2), sampled TO trajectories (Fig. 3),
        the zones the PTO laws use (Figs. 4-6), the one-sample image of l1
        (Fig. 5), a fourth-quadrant trajectory per PTO variant (Fig. 6), every
        law's response to step, ramp and sine with and without feed-forward
        (Figs. 7-14), and sampled PTO trajectories for the zone geometry.
    """
    from ptoverify.model.curves import level_curve_x1
    from ptoverify.model.laws import LAW_NAMES, make_law
    from ptoverify.model.plant import flow
    from ptoverify.model.zones import zone_for_law
    from ptoverify.report.plots import FigureInputs, zone_geometry_xlim
    from ptoverify.sim.simulate import simulate, simulate_batch

    p, d = cfg.plant, cfg.pto.d
    a, w, R = p.a, p.w_max, p.position_range
    laws = {name: make_law(name, cfg) for name in LAW_NAMES}
    zones = {v: zone_for_law(cfg, v) for v in ("corrected", "printed")}
    # Fig. 2: seven starts on each side, 6 / a seconds of the exact flow under +-w_max
    t = np.linspace(0, 6 / a, 200)[:, None]
    x10 = np.linspace(-4 * w / a, 4 * w / a, 7)
    open_loop = {
        "+w_max": flow(x10, np.full(7, -0.95 * w), w, t, a),
        "-w_max": flow(x10, np.full(7, 0.95 * w), -w, t, a),
    }
    # Fig. 3: from the envelope's edge, three times the farthest t_f*
    s1 = np.array([R, R, 0.6 * R, -R, -0.6 * R, -R, 0.3 * R, -0.3 * R])
    s2 = np.array([0.0, -0.8 * w, 0.9 * w, 0.0, -0.9 * w, 0.8 * w, 0.0, 0.0])
    steps = int(math.ceil(3 * (2 * R / w + 3 / a) / p.T))
    # Fig. 5: l1 moved one sample under -w_max
    neg = np.linspace(-w, 0, 300)
    l1_image = flow(level_curve_x1(neg, a, w), neg, -w, p.T, a)
    # Fig. 6: from (4 d, -w_max / 3), 60 samples
    fig6 = {
        law: simulate_batch(laws[law], p, [4 * d], [-w / 3], 60) for law in ("pto", "pto-printed")
    }
    # zone geometry: starts at rest right of the linear zone, one at -w_max, and mirrors
    xmax = zone_geometry_xlim(zones["corrected"], cfg)
    g1 = np.append(np.linspace(1.2, 0.9 * xmax / max(d, 1e-9), 4) * d, 0.9 * xmax)
    g2 = np.array([0.0, 0.0, 0.0, 0.0, -w])
    sims = {
        (signal, ff): {name: simulate(law, p, signal, feedforward=ff) for name, law in laws.items()}
        for signal in ("step", "ramp", "sine")
        for ff in (True, False)
    }
    return FigureInputs(
        cfg=cfg,
        open_loop=open_loop,
        to_batch=simulate_batch(laws["to"], p, s1, s2, steps),
        zones=zones,
        l1_image=l1_image,
        fig6=fig6,
        sims=sims,
        geometry=simulate_batch(
            laws["pto"], p, np.concatenate([g1, -g1]), np.concatenate([g2, -g2]), 60
        ),
    )


# ------------------------------------------------------------------ stages
# Each stage computes one independent part of the report and, given a figure
# folder, draws that part's figures at once, so no large object travels back
# between processes.  Stages share nothing but the configuration: memoized work
# (zones, properties, claims) is shared inside a stage, never relied on across.


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


#: Folder of the report's CSV traces (one per law and signal, with feed-forward).
TRACE_DIR = "traces"


def write_traces(sims: dict, folder: Path) -> list[str]:
    """Write every law's step, ramp and sine response (feed-forward) as a CSV file.

    Parameters
    ----------
    sims : dict
        ``(signal, feedforward) -> law -> SimResult`` (:func:`figure_inputs`).
    folder : Path
        Where to write ``<law>_<signal>.csv`` (created).

    Returns
    -------
    list of str
        The paths written, relative to the report folder (``traces/pd_step.csv``).
    """
    import csv

    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for (signal, ff), by_law in sims.items():
        if not ff:
            continue
        for law, res in by_law.items():
            cols = res.columns()
            name = f"{law}_{signal}.csv"
            with open(folder / name, "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(list(cols))
                for row in zip(*cols.values(), strict=True):
                    w.writerow([repr(float(v)) if k != "region" else v for k, v in zip(cols, row)])
            out.append(f"{folder.name}/{name}")
    return sorted(out)


def _stage_poles(cfg: Config, figdir: Path | None) -> dict[str, Any]:
    """Analyse the loops' poles (python-control), with the two gates that read them."""
    from ptoverify.studies.checks import run_checks

    return {"poles": _poles(cfg), "_checks": run_checks(cfg, list(POLE_GATES))}


def _plots():
    from ptoverify.report import plots

    return plots


#: The gate that needs SymPy: it runs in the derivations' stage, the others in ``core``.
SYMBOLIC_GATE = "derivation-identities-vs-numerics"
#: The gates that read the loops' poles: they run beside the poles (their own stage).
POLE_GATES = ("pd-sampled-stable", "linear-zone-sampled-stable")
#: The gates that read the proofs: they run beside them (their own stage).
PROOF_GATES = ("proof-no-stride-over", "proof-reach")

#: The report's stages, longest first as measured in a worker (the order a pool starts
#: them in; the short ones last, so the workers end together).
_STAGE_FUNCTIONS: dict[str, Callable[[Config, Path | None], dict[str, Any]]] = {
    "robustness": _stage_robust,
    "suboptimality sweep": _stage_sweep,
    "derivations": _stage_derivations,
    "closed loop, claims and gates": _stage_core,
    "tuning": _stage_tuning,
    "penalty and design chart": _stage_charts,
    "ground truth": _stage_ground_truth,
    "paper figures": _stage_figures,
    "proofs": _stage_proofs,
    "poles": _stage_poles,
}
_SKIP_STAGE = {"robust": "robustness", "tuning": "tuning", "charts": "penalty and design chart"}


def _run_stage(name: str, cfg: Config, figdir: Path | None) -> tuple[dict[str, Any], float]:
    """Run one stage; return its results and its wall time [s] (a pool's task)."""
    t0 = time.perf_counter()
    out = _STAGE_FUNCTIONS[name](cfg, figdir)
    return out, time.perf_counter() - t0


def default_jobs() -> int:
    """Worker processes ``collect`` uses by default: the CPUs this process may use.

    Measured on this project's 2-core machine, idle (issue 23, final merge): the
    report took 28.2 s of wall time with ``--jobs 2`` against about 53 s with
    ``--jobs 1`` (the stages' times add up to 53 s), so the pool earns its place.
    An earlier measurement at a load average of 3-17 (other sessions running)
    showed no gain: on a busy machine pass ``--jobs 1``.

    Returns
    -------
    int
        ``len(os.sched_getaffinity(0))`` where available, else ``os.cpu_count()``
        (at least 1).
    """
    import os

    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        n = os.cpu_count() or 1
    return max(1, n)


# ------------------------------------------------------------------ collect
def collect(
    cfg: Config,
    progress: Progress | None = None,
    skip: tuple[str, ...] = (),
    figdir: Path | None = None,
    jobs: int | None = None,
) -> dict[str, Any]:
    """Compute every result of the report, each once, and draw its figures.

    The stages (:data:`STAGES`) are independent: with ``jobs`` > 1 they run in
    a pool of fresh Python processes (spawned: no fork of solver or BLAS
    state), longest first, each drawing its own figures into ``figdir``; with
    ``jobs`` = 1 they run here, one after the other.  Both give the same
    results.

    Parameters
    ----------
    cfg : Config
        Configuration.
    progress : callable, optional
        ``progress(stage, fraction)`` as each stage ends.
    skip : tuple of str
        Stages of :data:`SKIPPABLE` to leave out (their results are None).
    figdir : Path, optional
        Folder the figures are drawn into (none are drawn without it).
    jobs : int, optional
        Worker processes (default :func:`default_jobs`, at most one per stage).

    Returns
    -------
    dict
        JSON-able results, plus private keys: ``_records`` (the derivation
        records), ``_files`` (the figure files written), ``_timings`` (each
        stage's wall time [s]) and ``_jobs`` (the processes used);
        :func:`write_report` drops them from the JSON.

    Raises
    ------
    InputError
        An unknown ``skip`` stage or ``jobs`` < 1.
    """
    from ptoverify.errors import InputError
    from ptoverify.studies.checks import GATES, ROBUST_GATES, summarize

    bad = sorted(set(skip) - set(SKIPPABLE))
    if bad:
        raise InputError(f"--skip: unknown stage '{bad[0]}' (choose from {', '.join(SKIPPABLE)})")
    if jobs is not None and jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {jobs}")
    names = [n for n in _STAGE_FUNCTIONS if n not in {_SKIP_STAGE[s] for s in skip}]
    jobs = min(jobs or default_jobs(), len(names))
    done: dict[str, tuple[dict[str, Any], float]] = {}

    def finished(name: str, result: tuple[dict[str, Any], float]) -> None:
        done[name] = result
        if progress:
            progress(name, len(done) / len(names))

    if jobs == 1:
        for name in names:
            finished(name, _run_stage(name, cfg, figdir))
    else:
        _run_in_pool(names, cfg, figdir, jobs, finished)

    out: dict[str, Any] = {"derivations": None, "robust": None, "tuning": None, "charts": None}
    files: list[Path] = []
    traces: list[str] = []
    checks = []
    for name in names:
        part = done[name][0]
        files += part.pop("_files", [])
        traces += part.pop("_traces", [])
        checks += part.pop("_checks", [])
        out.update(part)
    order = [*GATES, *ROBUST_GATES]
    checks.sort(key=lambda v: order.index(v.name))
    out["checks"] = [c.to_json() for c in checks]
    out["skipped"] = sorted(set(skip))
    out["summary"] = _summary(out, summarize(checks))
    for kind, group in (
        ("gates_nominal", [c for c in checks if c.name not in ROBUST_GATES]),
        ("gates_perturbed", [c for c in checks if c.name in ROBUST_GATES]),
    ):
        out["summary"][kind] = summarize(group)
    out["_files"] = files
    out["_traces"] = traces
    out["_timings"] = {name: done[name][1] for name in names}
    out["_jobs"] = jobs
    return out


def _worker_setup() -> None:
    """Prepare a pool worker: its stdout goes to stderr, and it leaves Ctrl-C to the parent.

    A stage's results return through the pool, so what it prints (C libraries
    included) goes to stderr and never mixes with the command's stdout (``--json``
    keeps it for one JSON object).  A terminal's Ctrl-C reaches the whole process
    group: the workers ignore it, and the parent, interrupted, stops them.
    """
    import os
    import signal

    sys.stdout.flush()
    os.dup2(2, 1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextmanager
def _sigint_ignored_at_spawn() -> Iterator[None]:
    """Ignore SIGINT while the pool spawns its workers, so that they start ignoring it.

    A worker installs :func:`_worker_setup` only after its interpreter has started
    and unpickled its task; a Ctrl-C before then would print a KeyboardInterrupt
    traceback from the worker.  An ignored signal stays ignored across ``exec``,
    and Python leaves an inherited SIG_IGN of SIGINT in place, so a worker spawned
    here never sees Ctrl-C.  The parent ignores it only while it submits (the
    workers are started by ``submit``); off the main thread nothing is changed.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _run_in_pool(
    names: list[str],
    cfg: Config,
    figdir: Path | None,
    jobs: int,
    finished: Callable[[str, tuple[dict[str, Any], float]], None],
) -> None:
    """Run the stages in ``jobs`` worker processes; ``finished(name, result)`` as each ends.

    The pool is a :class:`concurrent.futures.ProcessPoolExecutor` of spawned
    processes (fresh interpreters: no fork of solver or BLAS state).  Like every
    spawned pool, it imports the caller's main module in each worker: a script that
    calls :func:`collect` or :func:`write_report` with ``jobs`` > 1 needs the
    ``if __name__ == "__main__":`` guard.  The stages are submitted longest first.
    A stage's exception is raised here with its type (an ``InputError`` stays one)
    and a note naming the stage (the worker's traceback is its ``__cause__``).
    When the run ends early (a stage's error, Ctrl-C, SIGTERM), the stages not
    started are cancelled and the workers are terminated, so none goes on writing
    into ``figdir``.  Where no pool can be made, the stages run in this process.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = multiprocessing.get_context("spawn")
    others = set(multiprocessing.active_children())
    try:
        pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_setup)
    except OSError:  # no semaphores or pipes here: the stages run in this process
        for name in names:
            finished(name, _run_stage(name, cfg, figdir))
        return
    with pool:
        try:
            with _sigint_ignored_at_spawn():
                futures = {pool.submit(_run_stage, name, cfg, figdir): name for name in names}
            for future in as_completed(futures):
                name = futures[future]
                try:
                    result = future.result()
                except Exception as exc:
                    exc.add_note(f"in report stage '{name}' (worker process)")
                    raise
                finished(name, result)
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            workers = [p for p in multiprocessing.active_children() if p not in others]
            for process in workers:
                process.terminate()
            for process in workers:
                process.join()
            raise


def _robust(cfg: Config) -> tuple[dict[str, Any], list]:
    """Run the robustness study at :data:`ROBUST_SETTINGS`: its JSON and its gates."""
    from dataclasses import asdict

    from ptoverify.studies.robust import RobustSettings, robust_gates, run_robust
    from ptoverify.studies.robust.drive import drive_sweeps
    from ptoverify.studies.robust.maps import SETTLING

    settings = RobustSettings(**ROBUST_SETTINGS)
    result = run_robust(cfg, settings)
    res = result.to_json()
    res.pop("timings_s", None)
    res["settings"] = asdict(settings)
    res["settling"] = SETTLING
    res["drive"] = drive_sweeps(cfg).to_json()
    return res, robust_gates(result)


def tuning_results(cfg: Config) -> dict[str, Any]:
    """Both laws at their best tuning: :func:`ptoverify.studies.claims.fair_comparison`.

    PD and PTO tuned on the step under each shared overshoot bound (the PTO's
    and the PD's own overshoot at the paper's gains), with the floor (t_f*,
    N* T, the least 2 % band entry), the Pareto fronts and the claims judged at
    the best tuning, at the report's search effort :data:`TUNE_SETTINGS`.

    Parameters
    ----------
    cfg : Config
        Configuration (plant and the paper's gains).

    Returns
    -------
    dict
        The keys of :func:`ptoverify.studies.claims.fair_comparison` less its wall
        time, and ``versus``: the corrected PTO against fair-tuned PD, PTOS and the
        cascade P loop under both readings of a
        (:meth:`ptoverify.studies.versus.Versus.to_json`, less its wall time).
    """
    from ptoverify.studies.claims import fair_comparison
    from ptoverify.studies.tune import TuneBudget
    from ptoverify.studies.versus import versus

    budget = TuneBudget(**TUNE_SETTINGS)
    res = fair_comparison(cfg, budget)
    res.pop("seconds", None)
    res["versus"] = versus(cfg, budget).to_json()  # PD and PTO at a = 2 pi f: cached above
    res["versus"].pop("seconds", None)
    from ptoverify.report.charts import tuned_penalty

    res["penalty"] = tuned_penalty(cfg, budget)
    return res


def _settings_json(settings: Any) -> dict[str, Any]:
    from dataclasses import asdict, is_dataclass

    return asdict(settings) if is_dataclass(settings) else dict(vars(settings))


def _summary(out: dict[str, Any], gates: dict[str, Any]) -> dict[str, Any]:
    verdicts: dict[str, int] = {}
    for r in out["derivations"]:
        verdicts[r["verdict"]] = verdicts.get(r["verdict"], 0) + 1
    claims: dict[str, int] = {}
    for c in out["claims"]:
        claims[c["verdict"]] = claims.get(c["verdict"], 0) + 1
    return {
        "gates": gates,
        "derivation_verdicts": verdicts,
        "claim_verdicts": claims,
        "errata": [r["id"] for r in out["derivations"] if r["verdict"] == "erratum"],
        "claims_not_reproduced": [
            c["id"] for c in out["claims"] if c["verdict"] == "not reproduced"
        ],
        "claims_ambiguous": [c["id"] for c in out["claims"] if c["verdict"] == "ambiguous"],
        "printed_zone_valid": bool(out["zone"]["printed"]["valid"]),
        "corrected_zone_valid": bool(out["zone"]["corrected"]["valid"]),
        "corrected_omega0": out["zone"]["corrected"]["omega0"],
        "corrected_zone_margin_mm_s": out["zone"]["corrected"].get("margin_mm_s"),
        "claims_failing_every_reading": [
            c["id"]
            for c in out["claims"]
            if c["readings"] and all(r["verdict"] == "not reproduced" for r in c["readings"])
        ],
    }


# ------------------------------------------------------------------ sections
#: The paper this report verifies, by its title.
PAPER_TITLE = "Approximate Time-Optimal Control Considering System Bandwidth and Saturation"


def downloads_intro(traces: list[str]) -> str:
    """Return the paragraph under the title: the paper verified and the files to download.

    Parameters
    ----------
    traces : list of str
        The CSV traces written (relative paths).

    Returns
    -------
    str
        Markdown-style text with links (the HTML renders them as links too).
    """
    links = ", ".join(f"[{Path(t).stem.replace('_', ' ')}]({t})" for t in traces)
    text = (
        f'Verifies the PTO law of the paper "{PAPER_TITLE}" against its own equations, '
        "exact minimum times and simulation. Every number below is computed; the paper's "
        "values appear only as claims. Downloads: [results.json](results.json) (every number "
        "of this report)"
    )
    return text + (f"; CSV traces (t, r, x1, x2, e, u, region): {links}." if links else ".")


def results_view(public: dict[str, Any]) -> Results:
    """Return the strict view of ``results.json`` that the sections read.

    Parameters
    ----------
    public : dict
        The JSON object written to ``results.json``.

    Returns
    -------
    Results
        Read-only; a missing field raises, never renders as a blank.

    Raises
    ------
    ValueError
        When a key of :data:`ptoverify.report.results.TOP_LEVEL` is missing or an
        unknown one is present (a bug of the report, not bad input).
    """
    missing = [k for k in TOP_LEVEL if k not in public]
    extra = sorted(set(public) - set(TOP_LEVEL))
    if missing or extra:
        raise ValueError(f"results.json keys: missing {missing}, unexpected {extra}")
    return wrap(public)


def build_sections(
    res: Results,
    figures: dict[str, str],
    records: list | None = None,
    rendered: dict | None = None,
) -> list[Section]:
    """Turn the results into ordered sections ``(anchor, title, blocks)``.

    Parameters
    ----------
    res : Results
        The strict view of ``results.json`` (:func:`results_view`).
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    records : list of derivations.EquationRecord, optional
        The derivation records :func:`collect` made (``res["_records"]``); when
        None they are taken from ``res``.
    rendered : dict, optional
        :func:`ptoverify.report.sections.render_records` of them
        (``res["_rendered"]``), when already computed.

    Returns
    -------
    list of (str, str, list of Block)
    """
    from ptoverify.report import sections as rs

    recs = records if records is not None else res["_records"]
    parts = [
        ("verdict", "Verdict: the paper's standing", rs.verdict(res)),
        ("findings", "Headline findings", rs.headline(res, figures)),
        ("summary", "Summary: gates, errata, claims", rs.summary(res)),
        ("errata", "Errata in the paper", rs.errata(res, recs, rendered)),
        ("derivations", "Derivations: printed vs derived", rs.derivations(res, recs, rendered)),
        ("ground-truth", "Ground truth: minimum time", rs.ground_truth(res, figures)),
        ("zone", "Switching-zone geometry", rs.zone(res, figures)),
        ("poles", "Poles and stability", rs.poles(res)),
        ("properties", "Closed-loop properties over the grid", rs.properties(res)),
        ("claims", "Section 6 claims", rs.claims(res, figures)),
        ("sweep", "Suboptimality maps", rs.sweep(res, figures)),
        ("proofs", "Proved over the continuum", rs.proofs(res, figures)),
        ("robustness", "Robustness under model mismatch", rs.robustness(res, figures)),
        ("tuning", "Can any tuning reproduce the paper?", rs.tuning(res, figures)),
        ("charts", "Penalty by move size, and the design space", rs.charts(res, figures)),
        ("environment", "Environment", rs.environment(res)),
    ]
    return [(a, t if i < 2 else f"{i - 1}. {t}", b) for i, (a, t, b) in enumerate(parts)]


# ------------------------------------------------------------------ writing
def write_report(
    cfg: Config,
    out: str | Path | None = None,
    progress: Progress | None = None,
    skip: tuple[str, ...] = (),
    timings: dict[str, float] | None = None,
    jobs: int | None = None,
) -> Path:
    """Compute and write the report folder atomically.

    Parameters
    ----------
    cfg : Config
        Configuration.
    out : str or Path, optional
        Folder; default ``reports/<config name>``, which is never replaced by
        the report of another configuration (see :mod:`ptoverify.outdir`).
    progress : callable, optional
        Called with each stage's name.
    skip : tuple of str
        Stages of :data:`SKIPPABLE` to leave out (a quick report).
    timings : dict, optional
        Filled with the wall time of each stage [s] (its figures included).
    jobs : int, optional
        Worker processes (:func:`collect`; default :func:`default_jobs`).

    Returns
    -------
    Path
        The folder written (``index.html``, ``report.md``, ``results.json``,
        ``figures/*.png``).

    Raises
    ------
    InputError
        When the folder cannot be written.
    """
    from ptoverify.outdir import check_target, discard, make_temp, publish

    default = out is None
    out = check_target(
        Path("reports") / cfg.name if default else out, config_hash=cfg.digest(), default=default
    )
    tmp = make_temp(out)  # figures are drawn into it; it is renamed into place when complete
    try:
        res = collect(cfg, progress, skip, figdir=tmp / "figures", jobs=jobs)
        figures = {Path(f).stem: f"figures/{Path(f).name}" for f in res["_files"]}
        if timings is not None:
            timings.update(res["_timings"])
        public = _clean({k: v for k, v in res.items() if not k.startswith("_")})
        public["ground_truth"] = _clean(
            {k: v for k, v in res["ground_truth"].items() if not k.startswith("_")}
        )
        public["meta"] = {
            "name": cfg.name,
            "paper": PAPER_TITLE,
            "figures": sorted(figures.values()),
            "traces": res["_traces"],
            "generated": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        title = f'Verification of "{PAPER_TITLE}" (configuration {cfg.name!r})'
        intro = downloads_intro(res["_traces"])
        sections = build_sections(
            results_view(public), figures, res["_records"], res.get("_rendered")
        )
        (tmp / "results.json").write_text(
            json.dumps(public, indent=1, sort_keys=True, allow_nan=False) + "\n"
        )
        (tmp / "index.html").write_text(render_html(sections, title, intro))
        (tmp / "report.md").write_text(render_markdown(sections, title, intro))
        publish(tmp, out, config_hash=cfg.digest(), name=cfg.name, default=default)
        tmp = None
    finally:
        discard(tmp)
    return out


#: The stages ``collect`` runs (and announces as each ends), longest first.
STAGES = tuple(_STAGE_FUNCTIONS)


def stderr_progress(quiet: bool) -> Progress | None:
    """Progress bar on stderr (:mod:`ptoverify.progress`) over :data:`STAGES`, or None."""
    from ptoverify.progress import stderr_bar

    return stderr_bar(quiet, STAGES)
