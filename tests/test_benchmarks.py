"""Smoke test of the benchmark suite: ``benchmarks/run.py --json --small`` (no speed asserted)."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

KEYS = {"law_vector_evals_per_s", "law_scalar_us", "omega_c_bisection_vs_closed_form",
        "mintime_vector_evals_per_s", "sim_state_steps_per_s", "two_phase_ms",
        "collocation_ms", "collocation_vs_two_phase_error_ratio", "discrete_ms", "check_s",
        "report_s"}


@pytest.fixture(scope="module")
def small_run() -> dict:
    p = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "run.py"), "--json",
                        "--small"], cwd=ROOT, capture_output=True, text=True, timeout=240)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_exact_keys(small_run):
    assert set(small_run) == KEYS | {"machine"}


@pytest.mark.parametrize("key", sorted(KEYS))
def test_values_finite_positive(small_run, key):
    v = small_run[key]
    if v is None:
        # only the whole-process figures may be missing, and then with a reason
        assert key in ("report_s", "check_s"), f"{key} is null"
        assert small_run["machine"]["notes"][key], f"{key} is null without a reason"
        return
    assert isinstance(v, float | int) and math.isfinite(v) and v > 0, f"{key} = {v!r}"


def test_machine(small_run):
    m = small_run["machine"]
    assert m["cores"] >= 1 and m["cpu"] and m["blas"]
    assert Path(m["ptoverify"]) == ROOT / "ptoverify", "benchmarked another tree's package"
