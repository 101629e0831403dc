"""What the report's stages compute, part by part: ground truth, poles, environment, traces."""

from __future__ import annotations

import math
import platform
import subprocess
from pathlib import Path
from typing import Any

import numpy as np

from ptoverify.config import Config

from .settings import CONVERGENCE_INTERVALS, GROUND_TRUTH_STATES, ROBUST_SETTINGS, TUNE_SETTINGS


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


def _plots():
    from ptoverify.report import plots

    return plots


def _robust(cfg: Config) -> tuple[dict[str, Any], list]:
    """Run the robustness study at :data:`ROBUST_SETTINGS`: its JSON and its gates.

    The JSON also holds ``baseline_margins``: PTOS and the cascade P loop at the
    configured gains (:func:`_baseline_margins`), for the margins table.
    """
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
    res["baseline_margins"] = _baseline_margins(cfg, settings)
    return res, robust_gates(result)


#: The baselines whose margins the report's robustness table adds (at the configured gains).
BASELINES = ("ptos", "cascade-p")


def _baseline_margins(cfg: Config, settings) -> dict[str, Any]:
    """Margins of the baselines at the configured gains (no maps, no search), with the gains.

    The linear-loop margins of :func:`ptoverify.studies.robust.law_margins`
    (eigenvalues, without and with a one-sample delay; about 0.1 s a law).  The
    simulated no-limit-cycle margin is left out: it would add about a quarter to
    the robustness stage (measured, benchmarks/README.md).  Their fair-tuned
    margins come with the tuning (``tuning.versus``).
    """
    from ptoverify.model.baselines import cascade_gain, ptos_design
    from ptoverify.studies.robust import law_margins

    p = ptos_design(cfg)
    gains = {"ptos": {"alpha": p.alpha, "k": p.k}, "cascade-p": {"kp": cascade_gain(cfg)}}
    return {
        law: {"gains": gains[law], **law_margins(law, cfg, settings, limit_cycles=False).to_json()}
        for law in BASELINES
    }


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
