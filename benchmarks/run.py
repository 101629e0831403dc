"""Benchmark suite of issue 7: speed of the laws, closed forms, solvers and CLI.

Run from the repository root::

    python benchmarks/run.py            # table
    python benchmarks/run.py --json     # one JSON object (the issue's keys + machine)
    python benchmarks/run.py --json --small   # CI smoke test: small sizes, no speed meaning

Every figure is the median over ``--repeat`` measurements (solver figures: the
median over their states).  Ratios are measured side by side in the same run.
With ``--small`` the sizes are cut so the whole run takes seconds; ``check_s``
then times ``ptoverify check --gate roots-closed-form-vs-bisection`` (one cheap
gate) and ``report_s`` ``ptoverify report --help``, so the figures only show
that the harness works.  At full size ``report_s`` times ``ptoverify report
--quiet --out TMPDIR`` (a temporary folder, so the tracked reports/ is untouched),
``report_jobs1_s`` the same with ``--jobs 1`` (every stage in one process), run in
turn with it, and ``report_pool_speedup`` is their ratio,
and ``sweep_s`` ``ptoverify sweep --quiet --json`` (200 x 200 states, 4 laws, settling
between samples; ``--small``: ``--grid 4``).
The command-line timings run after the tree's bytecode caches are written
(:func:`compile_bytecode`), as an installed package has them.
``robust_s`` times ``ptoverify robust --json`` at the paper's box and default sizes,
``robust_gates_s`` the two gates of ``check --robust``, ``robust_study_s`` the study itself
in-process (``run_robust`` at the defaults, the report's robustness stage, after a warm-up
that builds the laws; median of 3, on one core); the robust maps' throughput
is measured in-process and on a Dask LocalCluster side by side (the latter not with
``--small``: cluster start-up would dominate).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
LOAD_AT_START = [round(x, 2) for x in os.getloadavg()]  # 1, 5, 15 min, before any work
# `python benchmarks/run.py` puts benchmarks/, not the repository root, first on sys.path;
# an editable install elsewhere (another worktree) would then be measured instead of this
# tree.  Only this script does this; the package never edits sys.path.
if sys.path[0] != str(ROOT):
    sys.path.insert(0, str(ROOT))

from ptoverify.config import paper_config  # noqa: E402
from ptoverify.model.curves import omega_c  # noqa: E402
from ptoverify.model.laws import make_law  # noqa: E402
from ptoverify.model.mintime import (  # noqa: E402
    ZOHReach,
    discrete_min_steps,
    discrete_min_steps_batch,
    min_time,
)
from ptoverify.sim.simulate import simulate_batch  # noqa: E402

TARGETS = {  # key: (target, ">=" or "<=")
    "law_vector_evals_per_s": (2e6, ">="),
    "law_scalar_us": (20.0, "<="),
    "omega_c_bisection_vs_closed_form": (10.0, ">="),
    "mintime_vector_evals_per_s": (5e6, ">="),
    "sim_state_steps_per_s": (2e6, ">="),
    "two_phase_ms": (20.0, "<="),
    "collocation_ms": (150.0, "<="),
    "collocation_vs_two_phase_error_ratio": (None, ""),
    "discrete_ms": (50.0, "<="),
    "discrete_batch_states_per_s": (5e5, ">="),
    "discrete_lp_states_per_s": (None, ""),
    "discrete_batch_vs_lp_ratio": (None, ""),
    "check_s": (60.0, "<="),
    "report_s": (10.0, "<="),
    "report_jobs1_s": (None, ""),
    "report_pool_speedup": (None, ""),
    "sweep_s": (30.0, "<="),
    "tune_pd_s": (20.0, "<="),
    "tune_pto_s": (120.0, "<="),
    "robust_s": (60.0, "<="),
    "robust_gates_s": (60.0, "<="),
    "robust_study_s": (2.5, "<="),
    "robust_maps_state_cells_per_s": (None, ""),
    "robust_maps_dask_local_state_cells_per_s": (None, ""),
    "robust_maps_trajectory_steps_per_s": (None, ""),
}

FULL = {
    "law": 10**6,
    "scalar": 20000,
    "omega": 10**5,
    "mintime": 10**6,
    "sim_states": 10000,
    "sim_steps": 250,
    "two_phase": 50,
    "collocation": 20,
    "discrete_batch": 10**6,
    "discrete_lp": 30,
    "repeat": 7,
    "cli_repeat": 3,
    "tune": {},  # tune's defaults, as `ptoverify tune` runs it
}
SMALL = {
    "law": 2000,
    "scalar": 200,
    "omega": 2000,
    "mintime": 2000,
    "sim_states": 100,
    "sim_steps": 20,
    "two_phase": 3,
    "collocation": 2,
    "discrete_batch": 2000,
    "discrete_lp": 3,
    "repeat": 2,
    "cli_repeat": 1,
    "tune": {"maxiter": 1, "popsize": 3, "d_grid": 2, "d_refine": 0},
}


def envelope_states(cfg, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Uniform random states in |x1| <= position_range, |x2| <= w_max."""
    rng = np.random.default_rng(seed)
    p = cfg.plant
    return (rng.uniform(-1.0, 1.0, n) * p.position_range, rng.uniform(-1.0, 1.0, n) * p.w_max)


def median_time(fn, repeat: int) -> float:
    """Median wall time [s] of ``fn()`` over ``repeat`` calls, after one warm-up call."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def median_times(fns: list, repeat: int) -> list[float]:
    """Median wall times [s] of several functions timed in turn, for a ratio.

    Each round times every function once, so a change of machine load during
    the run falls on all of them alike.
    """
    for fn in fns:
        fn()
    times = [[] for _ in fns]
    for _ in range(repeat):
        for t, fn in zip(times, fns, strict=True):
            t0 = time.perf_counter()
            fn()
            t.append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]


# ---------------------------------------------------------------- laws
def bench_law_vector(cfg, size: dict) -> float:
    law = make_law("pto", cfg)
    x1, x2 = envelope_states(cfg, size["law"], 1)
    return size["law"] / median_time(lambda: law.vector(x1, x2), size["repeat"])


def bench_law_scalar(cfg, size: dict, zone_only: bool = False) -> float:
    """Mean time of one ``law.scalar`` call over random envelope states [us], median of runs.

    ``zone_only``: only states where the law uses omega_c (the costliest branch).
    """
    law = make_law("pto", cfg)
    x1, x2 = envelope_states(cfg, 50 * size["scalar"] if zone_only else size["scalar"], 2)
    if zone_only:
        _, region = law.vector(x1, x2)
        sel = np.flatnonzero((region == 3) | (region == 4))[: size["scalar"]]
        x1, x2 = x1[sel], x2[sel]
    pairs = list(zip(x1.tolist(), x2.tolist(), strict=True))
    f = law.scalar

    def run():
        for a, b in pairs:
            f(a, b)

    return 1e6 * median_time(run, size["repeat"]) / len(pairs)


# ---------------------------------------------------------------- omega_c
def omega_c_bisection(
    x1: np.ndarray, x2: np.ndarray, a: float, tol: float = 1e-12, max_iter: int = 200
) -> np.ndarray:
    """omega_c by the paper's method: bisection on f(z) = ln(1 + z) - k z, eq. (31).

    k = 1 + a x1 / x2 (eq. 30), 0 < k < 1; the non-trivial root z* > 0 lies in
    (0, 1/k^2 + 1]: f > 0 on (0, z*), f < 0 beyond.  The bracket is halved,
    vectorized over all states, until hi - lo <= tol * hi (relative tolerance
    1e-12) or ``max_iter`` halvings; then omega_c = |x2| / z* (eq. 32).
    """
    k = 1.0 + a * x1 / x2
    lo = np.full_like(k, 1e-300)
    hi = 1.0 / (k * k) + 1.0
    for _ in range(max_iter):
        mid = 0.5 * (lo + hi)
        pos = np.log1p(mid) - k * mid > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
        if np.all(hi - lo <= tol * hi):
            break
    return np.abs(x2) / (0.5 * (lo + hi))


def omega_states(cfg, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """States in the fourth quadrant with 0 < m = -a x1/x2 < 1 (omega_c finite)."""
    rng = np.random.default_rng(seed)
    p = cfg.plant
    x2 = -rng.uniform(1e-3, 1.0, n) * p.w_max
    m = rng.uniform(1e-6, 1.0 - 1e-6, n)
    return -m * x2 / p.a, x2


def bench_omega(cfg, size: dict) -> dict:
    a = cfg.plant.a
    x1, x2 = omega_states(cfg, size["omega"], 3)
    t_closed, t_bisect = median_times(
        [lambda: omega_c(x1, x2, a), lambda: omega_c_bisection(x1, x2, a)], size["repeat"]
    )
    rel = np.abs(omega_c_bisection(x1, x2, a) / omega_c(x1, x2, a) - 1.0)
    return {
        "ratio": t_bisect / t_closed,
        "closed_ms": 1e3 * t_closed,
        "bisection_ms": 1e3 * t_bisect,
        "max_rel_diff": float(np.max(rel)),
    }


# ---------------------------------------------------------------- min time, simulation
def bench_mintime(cfg, size: dict) -> float:
    x1, x2 = envelope_states(cfg, size["mintime"], 4)
    return size["mintime"] / median_time(lambda: min_time(x1, x2, cfg.plant), size["repeat"])


def bench_sim(cfg, size: dict) -> float:
    law = make_law("pto", cfg)
    x1, x2 = envelope_states(cfg, size["sim_states"], 5)
    n = size["sim_steps"]
    t = median_time(lambda: simulate_batch(law, cfg.plant, x1, x2, n), max(1, size["repeat"] - 2))
    return size["sim_states"] * n / t


# ---------------------------------------------------------------- solvers
def bench_ocp(cfg, size: dict) -> dict:
    """Two-phase and collocation (N = 100, warm start) on the same states, wall time."""
    from ptoverify.model.ocp import CollocationOCP, TwoPhaseOCP

    plant = cfg.plant
    rng = np.random.default_rng(21)
    n2 = size["two_phase"]
    S = np.column_stack(
        [
            rng.uniform(-1, 1, n2) * plant.position_range,
            rng.uniform(-1, 1, n2) * plant.w_max * (1 - 1e-9),
        ]
    )
    tp = TwoPhaseOCP(plant)
    tp.solve(10.0, 0.0)  # build + warm-up
    t_tp, res_tp = [], []
    for x1, x2 in S:
        t0 = time.perf_counter()
        res_tp.append(tp.solve(float(x1), float(x2)))
        t_tp.append(time.perf_counter() - t0)
    Sc = S[: size["collocation"]]
    co = CollocationOCP(plant, 100, warm_start=True)
    co.solve(10.0, 0.0)
    t_co, res_co = [], []
    for x1, x2 in Sc:
        t0 = time.perf_counter()
        res_co.append(co.solve(float(x1), float(x2)))
        t_co.append(time.perf_counter() - t0)
    tf = min_time(Sc[:, 0], Sc[:, 1], plant).t_f
    err_co = np.abs(np.array([r.t_f for r in res_co]) - tf) / tf
    err_tp = np.abs(np.array([r.t_f for r in res_tp[: len(Sc)]]) - tf) / tf
    med_tp = float(np.median(err_tp))
    return {
        "two_phase_ms": 1e3 * statistics.median(t_tp),
        "collocation_ms": 1e3 * statistics.median(t_co),
        "collocation_err": float(np.median(err_co)),
        "two_phase_err": med_tp,
        "ratio": float(np.median(err_co)) / max(med_tp, 2.2e-16),
        "failures": sum(not r.success for r in res_tp + res_co),
    }


def bench_discrete(cfg, size: dict) -> float:
    d = discrete_min_steps(50.0, 0.0, cfg.plant)
    assert d.success, d.status
    return 1e3 * median_time(
        lambda: discrete_min_steps(50.0, 0.0, cfg.plant), max(5, size["repeat"])
    )


def bench_discrete_batch(cfg, size: dict) -> dict:
    """N* for many envelope states: zonotopes (batch) vs the LP search, same run.

    The LP side is the per-state wall time of ``discrete_min_steps`` (with its
    N* - 1 confirmation, as the CLI and the gate call it) over the first
    ``discrete_lp`` states; the two N* are compared on those states.
    """
    plant = cfg.plant
    x1, x2 = envelope_states(cfg, size["discrete_batch"], 7)
    n_lp = size["discrete_lp"]
    reach = ZOHReach(plant)

    def lp():
        return [discrete_min_steps(a, b, plant, reach=reach) for a, b in zip(x1[:n_lp], x2[:n_lp])]

    t_batch, t_lp = median_times(
        [lambda: discrete_min_steps_batch(x1, x2, plant), lp], max(3, size["repeat"] // 2)
    )
    d = discrete_min_steps_batch(x1, x2, plant)
    ref = lp()
    disagree = int(sum(r.steps != s for r, s in zip(ref, d.steps[:n_lp].tolist())))
    batch, lp_rate = x1.size / t_batch, n_lp / t_lp
    return {
        "batch_states_per_s": batch,
        "lp_states_per_s": lp_rate,
        "ratio": batch / lp_rate,
        "lp_states": n_lp,
        "batch_states": int(x1.size),
        "disagreements": disagree,
        "tests_per_state": d.tests / x1.size,
    }


def bench_tune(cfg, size: dict) -> dict:
    """Wall time [s] of one PD and one PTO tune on the step (no bound, seed 0), once each.

    Tuning is seconds to a minute, so it is timed once, not as a median.
    """
    from ptoverify.studies.tune import tune

    out = {}
    for law in ("pd", "pto"):
        t0 = time.perf_counter()
        r = tune(cfg, law, "step", **size["tune"])
        out[f"{law}_s"] = time.perf_counter() - t0
        out[f"{law}_evaluations"] = r.evaluations
        out[f"{law}_settling_ms"] = 1e3 * r.best.settling_2pct_s
    return out


# ---------------------------------------------------------------- whole process
def _median_or_none(values: list) -> float | None:
    """Median of the values, None if any is None (a run that did not happen)."""
    return None if any(v is None for v in values) else statistics.median(values)


def run_cli(args: list[str], repeat: int) -> tuple[float | None, str]:
    """Median wall time [s] of ``python -m ptoverify ARGS`` (cwd repo root)."""
    times, note = [], ""
    for _ in range(repeat):
        t0 = time.perf_counter()
        p = subprocess.run(
            [sys.executable, "-m", "ptoverify", *args], cwd=ROOT, capture_output=True, text=True
        )
        times.append(time.perf_counter() - t0)
        if p.returncode == 2 and "invalid choice" in p.stderr:
            return None, f"'ptoverify {args[0]}' does not exist in this tree"
        if p.returncode not in (0, 1):
            return None, f"'ptoverify {' '.join(args)}' exited {p.returncode}"
        if p.returncode == 1:
            note = f"'ptoverify {' '.join(args)}' exited 1 (a gate did not pass)"
    return statistics.median(times), note


# ---------------------------------------------------------------- robustness
def bench_robust_maps(cfg, small: bool) -> dict:
    """Maps of ``ptoverify robust`` in-process and on a Dask LocalCluster, side by side.

    The same maps (bit for bit, asserted); the Dask figure includes starting and
    stopping its 2-process LocalCluster, as ``robust --dask local`` does.
    """
    from ptoverify.studies.robust import RobustSettings, dask_runner, horizon_steps, robust_maps

    s = RobustSettings(n1=5, n2=5, rest=4, n_a=3, n_w=2) if small else RobustSettings()
    t0 = time.perf_counter()
    here = robust_maps(cfg, s)
    t_here = time.perf_counter() - t0
    cells = here.states * sum(len(c) for c in here.laws.values())
    out = {
        "state_cells": cells,
        "in_process_s": t_here,
        "state_cells_per_s": cells / t_here,
        "trajectory_steps_per_s": cells * horizon_steps(cfg) / t_here,
        "dask_local_s": None,
        "dask_local_state_cells_per_s": None,
        "dask_note": "",
    }
    if small:
        out["dask_note"] = "not timed with --small (LocalCluster start-up dominates)"
        return out
    t0 = time.perf_counter()
    there = robust_maps(cfg, s, runner=dask_runner("local"))
    t_there = time.perf_counter() - t0
    if there.to_json() != here.to_json():
        raise AssertionError("Dask local maps differ from the in-process maps")
    out["dask_local_s"] = t_there
    out["dask_local_state_cells_per_s"] = cells / t_there
    return out


def bench_robust_study(cfg, small: bool, repeat: int) -> dict:
    """``run_robust`` in-process at the defaults: median wall and CPU time, simulations run.

    One warm-up study first (imports, the corrected zone, memoized per plant), as in
    the report, which has built the laws by then; not with ``small`` (a smoke test, no
    speed meaning: the one study then also builds them).
    """
    from ptoverify.studies.robust import RobustSettings, run_robust

    s = (
        RobustSettings(n1=3, n2=3, rest=2, n_a=2, n_w=2, search_iterations=1, search_population=5)
        if small
        else RobustSettings()
    )
    if not small:
        run_robust(cfg, s)
    walls, cpus = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        res = run_robust(cfg, s)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return {
        "wall_s": statistics.median(walls),
        "cpu_s": statistics.median(cpus),
        "stages_s": {k: round(v, 3) for k, v in res.timings_s.items()},
    }


# ---------------------------------------------------------------- machine
def machine() -> dict:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    blas = "unknown"
    try:
        from threadpoolctl import threadpool_info

        libs = [i for i in threadpool_info() if i.get("user_api") == "blas"]
        if libs:
            i = libs[0]
            blas = (
                f"{i.get('internal_api')} {i.get('version')} "
                f"({i.get('architecture')}, {i.get('num_threads')} threads)"
            )
    except ImportError:
        try:
            cfg = np.show_config(mode="dicts")
            b = cfg["Build Dependencies"]["blas"]
            blas = f"{b.get('name')} {b.get('version')}"
        except Exception:  # noqa: BLE001 - older numpy: no dict mode
            pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "numpy": np.__version__,
        "blas": blas,
        "openblas_coretype": os.environ.get("OPENBLAS_CORETYPE"),
        "load_average_start": LOAD_AT_START,
        "load_average_end": [round(x, 2) for x in os.getloadavg()],
        "ptoverify": str(Path(sys.modules["ptoverify"].__file__).parent),
        "bytecode": BYTECODE_NOTE,
    }


#: How the command-line timings find this tree's bytecode (see :func:`compile_bytecode`).
BYTECODE_NOTE = "not compiled yet"


def compile_bytecode() -> str:
    """Write the bytecode caches of this tree's packages before the command-line timings.

    A first run of ``ptoverify`` normally writes them and every later run reads them.
    Where ``PYTHONDONTWRITEBYTECODE`` is set (as in some sandboxes), none is ever
    written, and every process would compile the ~25,000 lines it imports anew
    (about 0.2 s of CPU per process, three processes in a report).  Compiling once
    here times the commands as an ordinary installation runs them.

    Returns
    -------
    str
        What was done, for ``machine()["bytecode"]``.
    """
    import compileall

    ok = all(compileall.compile_dir(ROOT / pkg, quiet=1) for pkg in ("ptoverify", "derivations"))
    how = "set" if os.environ.get("PYTHONDONTWRITEBYTECODE") else "not set"
    state = "written" if ok else "NOT all written"
    return f"caches of ptoverify/ and derivations/ {state} first (PYTHONDONTWRITEBYTECODE {how})"


# ---------------------------------------------------------------- main
def run(small: bool) -> tuple[dict, dict]:
    size = SMALL if small else FULL
    cfg = paper_config()
    out, extra = {}, {}
    out["law_vector_evals_per_s"] = bench_law_vector(cfg, size)
    out["law_scalar_us"] = bench_law_scalar(cfg, size)
    extra["law_scalar_zone_us"] = bench_law_scalar(cfg, size, zone_only=True)
    om = bench_omega(cfg, size)
    out["omega_c_bisection_vs_closed_form"] = om["ratio"]
    extra["omega_c"] = om
    out["mintime_vector_evals_per_s"] = bench_mintime(cfg, size)
    out["sim_state_steps_per_s"] = bench_sim(cfg, size)
    oc = bench_ocp(cfg, size)
    out["two_phase_ms"] = oc["two_phase_ms"]
    out["collocation_ms"] = oc["collocation_ms"]
    out["collocation_vs_two_phase_error_ratio"] = oc["ratio"]
    extra["ocp"] = oc
    out["discrete_ms"] = bench_discrete(cfg, size)
    db = bench_discrete_batch(cfg, size)
    out["discrete_batch_states_per_s"] = db["batch_states_per_s"]
    out["discrete_lp_states_per_s"] = db["lp_states_per_s"]
    out["discrete_batch_vs_lp_ratio"] = db["ratio"]
    extra["discrete_batch"] = db
    tu = bench_tune(cfg, size)
    out["tune_pd_s"], out["tune_pto_s"] = tu["pd_s"], tu["pto_s"]
    extra["tune"] = tu
    global BYTECODE_NOTE
    BYTECODE_NOTE = compile_bytecode()
    check = ["check", "--gate", "roots-closed-form-vs-bisection"] if small else ["check"]
    out["check_s"], extra["check_note"] = run_cli(check, size["cli_repeat"])
    with tempfile.TemporaryDirectory() as tmp:  # never the tracked reports/ folder
        report = ["report", "--help"] if small else ["report", "--quiet", "--out", tmp]
        serial = report if small else [*report, "--jobs", "1"]
        pool_times, serial_times = [], []
        for _ in range(size["cli_repeat"]):  # side by side: the pool, then one process
            t, extra["report_note"] = run_cli(report, 1)
            pool_times.append(t)
            serial_times.append(run_cli(serial, 1)[0])
        out["report_s"] = _median_or_none(pool_times)
        out["report_jobs1_s"] = _median_or_none(serial_times)
        out["report_pool_speedup"] = (
            out["report_jobs1_s"] / out["report_s"]
            if out["report_s"] and out["report_jobs1_s"]
            else None
        )
    sweep = ["sweep", "--quiet", "--json"] + (["--grid", "4"] if small else [])
    out["sweep_s"], extra["sweep_note"] = run_cli(sweep, size["cli_repeat"])
    rb = bench_robust_maps(cfg, small)
    out["robust_maps_state_cells_per_s"] = rb["state_cells_per_s"]
    out["robust_maps_dask_local_state_cells_per_s"] = rb["dask_local_state_cells_per_s"]
    out["robust_maps_trajectory_steps_per_s"] = rb["trajectory_steps_per_s"]
    extra["robust_maps"] = rb
    st = bench_robust_study(cfg, small, 1 if small else 3)
    out["robust_study_s"] = st["wall_s"]
    extra["robust_study"] = st
    robust = ["robust", "--quiet", "--json"]
    if small:
        robust += ["--grid", "3", "--law", "pd", "--generations", "1", "--population", "5"]
    out["robust_s"], extra["robust_note"] = run_cli(robust, size["cli_repeat"])
    gates = ["check", "--gate", "robust-no-limit-cycle", "--gate", "robust-settling"]
    if small:
        out["robust_gates_s"], extra["robust_gates_note"] = None, "not run with --small"
    else:
        out["robust_gates_s"], extra["robust_gates_note"] = run_cli(gates, size["cli_repeat"])
    extra["vector_vs_scalar"] = out["law_vector_evals_per_s"] * out["law_scalar_us"] * 1e-6
    return out, extra


def table(out: dict, extra: dict) -> str:
    rows = [f"{'key':<38} {'measured':>12} {'target':>10}  met"]
    for key, (target, op) in TARGETS.items():
        v = out[key]
        if target is None:
            met, tgt = "-", "-"
        elif v is None:
            met, tgt = "n/a", f"{op} {target:g}"
        else:
            met = "yes" if (v >= target if op == ">=" else v <= target) else "NO"
            tgt = f"{op} {target:g}"
        vs = "null" if v is None else f"{v:.4g}"
        rows.append(f"{key:<38} {vs:>12} {tgt:>10}  {met}")
    om, oc = extra["omega_c"], extra["ocp"]
    rows += [
        "",
        f"omega_c: bisection {om['bisection_ms']:.1f} ms vs closed form "
        f"{om['closed_ms']:.2f} ms, max rel diff {om['max_rel_diff']:.2g}",
        f"t_f rel error median: collocation {oc['collocation_err']:.3g}, two-phase "
        f"{oc['two_phase_err']:.3g}; solver failures {oc['failures']}",
        f"vector law vs scalar law (per-state speed-up): {extra['vector_vs_scalar']:.3g}",
        f"N* zonotope batch {extra['discrete_batch']['batch_states_per_s']:.3g} states/s vs LP "
        f"{extra['discrete_batch']['lp_states_per_s']:.3g} states/s: ratio "
        f"{extra['discrete_batch']['ratio']:.3g}; "
        f"{extra['discrete_batch']['disagreements']} disagreements on "
        f"{extra['discrete_batch']['lp_states']} states",
        f"scalar law on switching-zone states only (omega_c by Newton): "
        f"{extra['law_scalar_zone_us']:.3g} us",
        f"tune (step, no bound): PD {extra['tune']['pd_evaluations']} evaluations, best "
        f"settling {extra['tune']['pd_settling_ms']:.4g} ms; PTO "
        f"{extra['tune']['pto_evaluations']} evaluations, {extra['tune']['pto_settling_ms']:.4g} ms",
    ]
    rb = extra["robust_maps"]
    dask = (
        f"Dask LocalCluster {rb['dask_local_s']:.3g} s (with start-up)"
        if rb["dask_local_s"] is not None
        else f"Dask: {rb['dask_note']}"
    )
    rows.append(
        f"robust maps: {rb['state_cells']} state-cells in-process {rb['in_process_s']:.3g} s; {dask}"
    )
    st = extra["robust_study"]
    rows.append(
        f"robust study in-process: wall {st['wall_s']:.3g} s, CPU {st['cpu_s']:.3g} s; "
        f"stages {st['stages_s']}"
    )
    for k in ("check_note", "report_note", "sweep_note", "robust_note", "robust_gates_note"):
        if extra[k]:
            rows.append(f"{k}: {extra[k]}")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--small", action="store_true", help="small sizes (CI smoke test)")
    args = ap.parse_args(argv)
    out, extra = run(args.small)
    if args.json:
        obj = dict(out)
        obj["machine"] = machine()
        notes = {
            k: v
            for k, v in (
                ("check_s", extra["check_note"]),
                ("report_s", extra["report_note"]),
                ("report_jobs1_s", extra["report_note"]),
                ("report_pool_speedup", extra["report_note"]),
                ("sweep_s", extra["sweep_note"]),
                ("robust_s", extra["robust_note"]),
                ("robust_gates_s", extra["robust_gates_note"]),
                ("robust_maps_dask_local_state_cells_per_s", extra["robust_maps"]["dask_note"]),
            )
            if v
        }
        if notes:  # reasons for a null (or a failing gate) ride with machine
            obj["machine"]["notes"] = notes
        print(json.dumps(obj, indent=1))
    else:
        print(table(out, extra))
        print("machine:", json.dumps(machine()))
    return 0 if all(v is None or math.isfinite(v) for v in out.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
