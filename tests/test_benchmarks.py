"""Benchmark suite smoke test, and the speed-ups' bit-for-bit equivalence.

``benchmarks/run.py --json --small`` runs in a subprocess (no speed asserted).
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ptoverify.model.curves import omega_c
from ptoverify.model.laws import make_law
from ptoverify.model.mintime import min_time
from ptoverify.model.plant import flow
from ptoverify.sim.simulate import simulate_batch

ROOT = Path(__file__).resolve().parent.parent

KEYS = {
    "law_vector_evals_per_s",
    "law_scalar_us",
    "omega_c_bisection_vs_closed_form",
    "mintime_vector_evals_per_s",
    "sim_state_steps_per_s",
    "two_phase_ms",
    "collocation_ms",
    "collocation_vs_two_phase_error_ratio",
    "discrete_ms",
    "discrete_batch_states_per_s",
    "discrete_lp_states_per_s",
    "discrete_batch_vs_lp_ratio",
    "check_s",
    "report_s",
    "report_jobs1_s",
    "report_pool_speedup",
    "sweep_s",
    "tune_pd_s",
    "tune_pto_s",
    "robust_s",
    "robust_gates_s",
    "robust_study_s",
    "robust_maps_state_cells_per_s",
    "robust_maps_dask_local_state_cells_per_s",
    "robust_maps_trajectory_steps_per_s",
}


@pytest.fixture(scope="module")
def small_run() -> dict:
    p = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "run.py"), "--json", "--small"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=240,
    )
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_exact_keys(small_run):
    assert set(small_run) == KEYS | {"machine"}


@pytest.mark.parametrize("key", sorted(KEYS))
def test_values_finite_positive(small_run, key):
    v = small_run[key]
    if v is None:
        # only the whole-process figures may be missing, and then with a reason
        assert key in (
            "report_s",
            "report_jobs1_s",
            "report_pool_speedup",
            "check_s",
            "robust_s",
            "robust_gates_s",
            "robust_maps_dask_local_state_cells_per_s",
        ), f"{key} is null"
        assert small_run["machine"]["notes"][key], f"{key} is null without a reason"
        return
    assert isinstance(v, float | int) and math.isfinite(v) and v > 0, f"{key} = {v!r}"


def test_machine(small_run):
    m = small_run["machine"]
    assert m["cores"] >= 1 and m["cpu"] and m["blas"]
    assert Path(m["ptoverify"]) == ROOT / "ptoverify", "benchmarked another tree's package"


# ---------------------------------------------------------------- the speed-ups change no bit
def _states(cfg, n, seed):
    rng = np.random.default_rng(seed)
    p = cfg.plant
    x1 = rng.uniform(-1, 1, n) * p.position_range * 10.0 ** rng.uniform(-6, 0, n)
    x2 = rng.uniform(-1.5, 1.5, n) * p.w_max * 10.0 ** rng.uniform(-6, 0, n)
    x1[:4], x2[:4] = [0.0, 0.0, 1.0, -0.0], [0.0, 1.0, 0.0, 0.0]
    return x1, x2


def _pieces(fn, x1, x2, size=997):
    """Evaluate fn on small slices (one block each) and concatenate."""
    parts = [fn(x1[i : i + size], x2[i : i + size]) for i in range(0, x1.size, size)]
    return tuple(np.concatenate(p) for p in zip(*parts, strict=True))


def test_law_mintime_omega_c_batch_independent(any_cfg):
    """Evaluation of large arrays equals evaluation slice by slice, bit for bit."""
    x1, x2 = _states(any_cfg, 41_083, 7)
    law = make_law("pto", any_cfg)
    for got, want, what in zip(
        law.vector(x1, x2), _pieces(law.vector, x1, x2), ("u", "region"), strict=True
    ):
        np.testing.assert_array_equal(got, want, err_msg=f"PTO law {what}, slices")

    def mt(a, b):
        m = min_time(a, b, any_cfg.plant)
        return m.t_f, m.t_switch, m.side, m.q

    for got, want, what in zip(
        mt(x1, x2), _pieces(mt, x1, x2), ("t_f", "t_switch", "side", "q"), strict=True
    ):
        np.testing.assert_array_equal(got, want, err_msg=f"min_time {what}, slices")
    with np.errstate(all="ignore"):
        np.testing.assert_array_equal(
            omega_c(x1, x2, any_cfg.plant.a),
            _pieces(lambda a, b: (omega_c(a, b, any_cfg.plant.a),), x1, x2)[0],
            err_msg="omega_c, slices",
        )


def test_simulate_batch_is_the_exact_flow(any_cfg):
    """simulate_batch's in-place update equals plant.flow step by step, bit for bit."""
    x1, x2 = _states(any_cfg, 500, 8)
    law = make_law("pto", any_cfg)
    p = any_cfg.plant
    res = simulate_batch(law, p, x1, x2, 60)
    for k in range(60):
        u, region = law(x1, x2)
        np.testing.assert_array_equal(u, res.u[k], err_msg=f"input at step {k}")
        np.testing.assert_array_equal(region, res.region[k], err_msg=f"region at step {k}")
        x1, x2 = flow(x1, x2, u, p.sample_time, p.a)
        np.testing.assert_array_equal(x1, res.x1[k + 1], err_msg=f"x1 at step {k + 1}")
        np.testing.assert_array_equal(x2, res.x2[k + 1], err_msg=f"x2 at step {k + 1}")
