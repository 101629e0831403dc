"""The verification report: collect every result once, then draw and render it.

``collect(cfg)`` is the one step that computes: the derivations, the ground
truth, the zones, the poles, the closed-loop properties, the Section 6 claims,
the sweep, the gates, and the responses and trajectories the figures draw
(:func:`figure_inputs`).  It returns one dict: the JSON-able results
(``results.json``) plus private keys (``_records``, ``_sweep``, ``_figures``,
``ground_truth._study``) holding the objects that the figures and the
derivation section need.  The figures (:mod:`ptoverify.plots`) and the sections
(:mod:`ptoverify.report_sections`) only draw from it; the neutral blocks are
printed by :mod:`ptoverify.render`.  Work shared with the gates (the corrected
zone and its grid check, the corrected PTO's closed-loop properties, the
claims) is memoized per frozen configuration in the numeric modules, so it runs
once per report.  The SymPy derivations share nothing with the numerics and
take about a third of the time, so they run in a separate Python process while
the numerics run (in this process where no process can be started).

Two stages cost more than the rest together and are optional: the robustness
study (:func:`ptoverify.robust.run_robust` at :data:`ROBUST_SETTINGS`, the
command's defaults) and the tuning comparison (:func:`tuning_results`: PD and
PTO tuned on the step under shared overshoot bounds, at the reduced search
effort :data:`TUNE_SETTINGS`).  ``skip`` (the
command's ``--skip robust,tuning``) leaves them out for a quick report; their
sections then say so.  Each stage's wall time is kept in ``res["_timings"]``
(not in ``results.json``, which stays reproducible).

``write_report`` writes the folder atomically: everything goes to a temporary
sibling folder that is renamed into place only when complete.

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
from ptoverify.render import Section, render_html, render_markdown

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
SKIPPABLE = ("robust", "tuning")

#: Sizes of the report's robustness study: overrides of
#: :class:`ptoverify.robust.RobustSettings`.  Empty: the report runs the same study as
#: ``ptoverify robust`` on its defaults (all four laws; about 20-25 s on 2 cores).
ROBUST_SETTINGS: dict[str, Any] = {}

#: Search effort of the report's tunings (:class:`ptoverify.tune.TuneBudget`, fixed seed),
#: reduced from ``ptoverify tune``'s defaults (30 generations, population factor 10, 9 d
#: points, 4 refinements) so the four tunings take about a minute.
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
CONVERGENCE_INTERVALS = (10, 20, 40, 80, 100, 200, 400)
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
    from ptoverify.groundtruth import verified_mintime
    from ptoverify.ocp import convergence_study

    p = cfg.plant
    scale = (p.position_range / 50.0, p.w_max / 300.0)
    states = [(x1 * scale[0], x2 * scale[1]) for x1, x2 in GROUND_TRUTH_STATES]
    rows = []
    for x1, x2 in states:
        gt = verified_mintime(x1, x2, cfg, intervals=100)  # checked a posteriori, as mintime
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
    study = convergence_study(p, np.array(states[:4]), CONVERGENCE_INTERVALS)
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
    from ptoverify.poles import all_loop_poles, lyapunov_counterexample

    return {
        "loops": {k: v.to_json() for k, v in all_loop_poles(cfg).items()},
        "lyapunov_counterexample": lyapunov_counterexample(cfg),
    }


def _properties(cfg: Config) -> dict[str, Any]:
    from ptoverify.properties import all_properties

    return {k: v.to_json() for k, v in all_properties(cfg).items()}


def _environment(cfg: Config) -> dict[str, Any]:
    import casadi
    import control
    import scipy
    import sympy

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
        "sympy": sympy.__version__,
        "control": control.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
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
    ptoverify.plots.FigureInputs
        Open-loop arcs under +-w_max (Fig. 2), sampled TO trajectories (Fig. 3),
        the zones the PTO laws use (Figs. 4-6), the one-sample image of l1
        (Fig. 5), a fourth-quadrant trajectory per PTO variant (Fig. 6), every
        law's response to step, ramp and sine with and without feed-forward
        (Figs. 7-14), and sampled PTO trajectories for the zone geometry.
    """
    from ptoverify.curves import level_curve_x1
    from ptoverify.laws import LAW_NAMES, make_law
    from ptoverify.plant import flow
    from ptoverify.plots import FigureInputs, zone_geometry_xlim
    from ptoverify.simulate import simulate, simulate_batch
    from ptoverify.zones import zone_for_law

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


# ------------------------------------------------------------------ collect


def collect(
    cfg: Config, progress: Progress | None = None, skip: tuple[str, ...] = ()
) -> dict[str, Any]:
    """Compute every result of the report, each once.

    Parameters
    ----------
    cfg : Config
        Configuration.
    progress : callable, optional
        ``progress(stage)`` before each stage (:data:`STAGES`).
    skip : tuple of str
        Stages of :data:`SKIPPABLE` to leave out (their results are None).

    Returns
    -------
    dict
        JSON-able results, plus private keys with the objects the figures and
        sections need: ``_records`` (derivation records), ``_sweep``
        (SweepResult), ``_figures`` (:class:`ptoverify.plots.FigureInputs`) and
        ``ground_truth._study`` (ConvergenceStudy); :func:`write_report` drops
        them from the JSON.
    """
    from ptoverify.errors import InputError

    bad = sorted(set(skip) - set(SKIPPABLE))
    if bad:
        raise InputError(f"--skip: unknown stage '{bad[0]}' (choose from {', '.join(SKIPPABLE)})")
    timings: dict[str, float] = {}
    clock = {"stage": None, "t": time.perf_counter()}

    def say(stage: str) -> None:
        now = time.perf_counter()
        if clock["stage"] is not None:
            timings[clock["stage"]] = now - clock["t"]
        clock.update(stage=stage, t=now)
        if progress and stage:
            progress(stage)

    out: dict[str, Any] = {"derivations": None, "skipped": sorted(set(skip))}
    say("derivations")
    import derivations

    p = cfg.plant
    plant = derivations.PlantNumbers(
        a=p.a, w_max=p.w_max, T=p.sample_time, d=cfg.pto.d, k1=cfg.pto.k1, k2=cfg.pto.k2
    )
    with _in_background("derivations", "all_records", plant) as records_later:
        _numerics(cfg, out, say, set(skip))
        say("waiting for the derivations")
        records = records_later()
    say("")
    timings.pop("", None)
    out["_timings"] = timings
    out["derivations"] = [r.to_json() for r in records]
    out["_records"] = records
    out["summary"] = _summary(out, out.pop("_gates"))
    return out


def _numerics(cfg: Config, out: dict[str, Any], say: Callable[[str], None], skip: set[str]) -> None:
    """Run the numeric stages of :func:`collect` in order, into ``out``."""
    from ptoverify.checks import run_checks, summarize
    from ptoverify.claims import evaluate_claims, response_metrics
    from ptoverify.sweep import run_sweep
    from ptoverify.zones import zone_summary

    say("ground truth")
    out["ground_truth"] = _ground_truth(cfg)
    say("switching zone")
    out["zone"] = zone_summary(cfg)
    say("poles")
    out["poles"] = _poles(cfg)
    say("closed-loop properties")
    out["properties"] = _properties(cfg)
    say("Section 6 claims")
    out["claims"] = [c.to_json() for c in evaluate_claims(cfg)]
    out["responses"] = response_metrics(cfg)
    say("suboptimality sweep")
    sweep = run_sweep(cfg)
    out["sweep"] = {
        "laws": {k: v.to_json() for k, v in sweep.laws.items()},
        "grid": list(sweep.x1.shape),
        "steps": sweep.steps,
        "velocity_band": sweep.velocity_band,
        "skipped": sweep.skipped,
        "settings": _settings_json(sweep.settings),
    }
    out["_sweep"] = sweep
    say("gates")
    checks = run_checks(cfg)
    out["checks"] = [c.to_json() for c in checks]
    out["_gates"] = summarize(checks)
    out["environment"] = _environment(cfg)
    say("robustness")
    out["robust"] = None if "robust" in skip else _robust(cfg)
    say("tuning")
    out["tuning"] = None if "tuning" in skip else tuning_results(cfg)
    say("figure data")
    out["_figures"] = figure_inputs(cfg)


def _robust(cfg: Config) -> dict[str, Any]:
    """Run the robustness study at :data:`ROBUST_SETTINGS` (JSON, settings included)."""
    from dataclasses import asdict

    from ptoverify.robust import RobustSettings, run_robust

    settings = RobustSettings(**ROBUST_SETTINGS)
    res = run_robust(cfg, settings).to_json()
    res.pop("timings_s", None)
    res["settings"] = asdict(settings)
    return res


def tuning_results(cfg: Config) -> dict[str, Any]:
    """Both laws at their best tuning: :func:`ptoverify.claims.fair_comparison`.

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
        The keys of :func:`ptoverify.claims.fair_comparison` less its wall time.
    """
    from ptoverify.claims import fair_comparison
    from ptoverify.tune import TuneBudget

    res = fair_comparison(cfg, TuneBudget(**TUNE_SETTINGS))
    res.pop("seconds", None)
    return res


_CHILD = (
    "import importlib, pickle, sys\n"
    "fn = getattr(importlib.import_module(sys.argv[1]), sys.argv[2])\n"
    "with open(sys.argv[3], 'rb') as f:\n"
    "    args = pickle.load(f)\n"
    "with open(sys.argv[3], 'wb') as f:\n"
    "    pickle.dump(fn(*args), f)\n"
)


@contextmanager
def _in_background(module: str, name: str, *args: Any) -> Iterator[Callable[[], Any]]:
    """Run ``module.name(*args)`` in a fresh Python process while the body runs.

    Yields a getter of its result.  The SymPy derivations take about as long
    as all the numerics together and share nothing with them, so on two cores
    the report overlaps the two.  The worker is a new interpreter started with
    ``sys.executable`` (no fork of solver or BLAS state, no re-import of the
    caller's ``__main__``), with this process's ``sys.path``; it returns its
    result pickled through a temporary file.  A failure in it raises
    ``RuntimeError`` with its last lines of stderr.  Where no process can be
    started, ``module.name()`` runs here when the result is asked for.
    """
    import importlib
    import os
    import pickle
    import tempfile

    fd, result = tempfile.mkstemp(suffix=".pickle")
    with os.fdopen(fd, "wb") as f:  # the arguments go in; the child overwrites with its result
        pickle.dump(args, f)
    log = tempfile.TemporaryFile()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    try:
        try:
            child = subprocess.Popen(
                [sys.executable, "-c", _CHILD, module, name, result],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=log,
                env=env,
            )
        except OSError:  # no process can be started here: compute in this process
            fn = getattr(importlib.import_module(module), name)
            yield lambda: fn(*args)
            return

        def get() -> Any:
            if child.wait() != 0:
                log.seek(0)
                tail = log.read().decode(errors="replace").strip().splitlines()[-3:]
                raise RuntimeError(f"{module}.{name} failed in its worker: {' | '.join(tail)}")
            with open(result, "rb") as f:
                return pickle.load(f)  # noqa: S301 - our own child's output

        try:
            yield get
        finally:
            if child.poll() is None:
                child.kill()
                child.wait()
    finally:
        log.close()
        os.unlink(result)


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
def build_sections(
    res: dict[str, Any], figures: dict[str, str], records: list | None = None
) -> list[Section]:
    """Turn the results into ordered sections ``(anchor, title, blocks)``.

    Parameters
    ----------
    res : dict
        Output of :func:`collect` (JSON part).
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    records : list of derivations.EquationRecord, optional
        The derivation records :func:`collect` made (``res["_records"]``); when
        None they are taken from ``res``.

    Returns
    -------
    list of (str, str, list of Block)
    """
    from ptoverify import report_sections as rs

    recs = records if records is not None else res["_records"]
    parts = [
        ("findings", "Headline findings", rs.headline(res, figures)),
        ("summary", "Summary: gates, errata, claims", rs.summary(res)),
        ("errata", "Errata in the paper", rs.errata(res, recs)),
        ("derivations", "Derivations: printed vs derived", rs.derivations(res, recs)),
        ("ground-truth", "Ground truth: minimum time", rs.ground_truth(res, figures)),
        ("zone", "Switching-zone geometry", rs.zone(res, figures)),
        ("poles", "Poles and stability", rs.poles(res)),
        ("properties", "Closed-loop properties over the grid", rs.properties(res)),
        ("claims", "Section 6 claims", rs.claims(res, figures)),
        ("sweep", "Suboptimality maps", rs.sweep(res, figures)),
        ("robustness", "Robustness under model mismatch", rs.robustness(res, figures)),
        ("tuning", "Can any tuning reproduce the paper?", rs.tuning(res, figures)),
        ("environment", "Environment", rs.environment(res)),
    ]
    return [(a, t if i == 0 else f"{i}. {t}", b) for i, (a, t, b) in enumerate(parts)]


# ------------------------------------------------------------------ writing
def _figures(res: dict[str, Any], figdir: Path) -> dict[str, str]:
    """Draw every figure from the collected results; return key -> relative path."""
    from ptoverify import plots

    files = plots.save_all(res["_figures"], figdir)
    files += plots.save_sweep(res["_sweep"], figdir)
    files += plots.save_ground_truth(res["ground_truth"]["_study"], figdir)
    if res.get("robust"):
        files += plots.save_robust(res["robust"]["maps"], figdir)
    if res.get("tuning"):
        files += plots.save_tuning(res["tuning"], figdir)
    return {Path(f).stem: f"figures/{Path(f).name}" for f in files}


def write_report(
    cfg: Config,
    out: str | Path | None = None,
    progress: Progress | None = None,
    skip: tuple[str, ...] = (),
    timings: dict[str, float] | None = None,
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
        Filled with the wall time of each stage [s] (figures included).

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
    res = collect(cfg, progress, skip)  # nothing is written before this ends
    tmp = make_temp(out)
    try:
        if progress:
            progress("figures")
        t0 = time.perf_counter()
        figures = _figures(res, tmp / "figures")
        if timings is not None:
            timings.update(res["_timings"], figures=time.perf_counter() - t0)
        public = _clean({k: v for k, v in res.items() if not k.startswith("_")})
        public["ground_truth"] = _clean(
            {k: v for k, v in res["ground_truth"].items() if not k.startswith("_")}
        )
        public["meta"] = {
            "name": cfg.name,
            "figures": sorted(figures.values()),
            "generated": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        title = f"ptoverify verification report: {cfg.name}"
        sections = build_sections(public, figures, res["_records"])
        (tmp / "results.json").write_text(
            json.dumps(public, indent=1, sort_keys=True, allow_nan=False) + "\n"
        )
        (tmp / "index.html").write_text(render_html(sections, title))
        (tmp / "report.md").write_text(render_markdown(sections, title))
        publish(tmp, out, config_hash=cfg.digest(), name=cfg.name, default=default)
        tmp = None
    finally:
        discard(tmp)
    return out


#: The stages ``collect`` and ``write_report`` announce, in order.
STAGES = (
    "derivations",
    "ground truth",
    "switching zone",
    "poles",
    "closed-loop properties",
    "Section 6 claims",
    "suboptimality sweep",
    "gates",
    "robustness",
    "tuning",
    "figure data",
    "waiting for the derivations",
    "figures",
)


def stderr_progress(quiet: bool) -> Progress | None:
    """Progress bar on stderr (:mod:`ptoverify.progress`) over :data:`STAGES`, or None."""
    from ptoverify.progress import stderr_bar

    return stderr_bar(quiet, STAGES)
