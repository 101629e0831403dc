"""Tests of the design charts (studies/design.py) and ``ptoverify design``.

References: scipy's ZOH discretization (``conftest.zoh_reference``) for the
linear-loop margins, the sweep's own settling for one point, and the in-process
run for the process pool (on a cluster: ``test_dask``).
"""

import json
import math

import numpy as np
import pytest
from conftest import zoh_reference

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.studies.design import (
    design_chart,
    design_point,
    point_config,
    process_runner,
)

CFG = paper_config()


def _radius(a, T, kx1, kx2, delay):  # noqa: N803
    Ad, Bd = zoh_reference(a, T)
    K = np.array([[kx1, kx2]])
    M = Ad - Bd @ K if delay == 0 else np.block([[Ad, Bd], [-K, np.zeros((1, 1))]])
    return float(np.abs(np.linalg.eigvals(M)).max())


@pytest.fixture(scope="module")
def point():
    return design_point(CFG, 0.002, 30.0, grid=6)


def test_margins_against_scipy_zoh(point):
    """Each finite margin endpoint separates a stable from an unstable loop (scipy's ZOH)."""
    checked = 0
    for r in point.laws:
        assert math.isclose(r.radius_delay1, _radius(CFG.plant.a, 0.002, r.k_x1, r.k_x2, 1),
                            rel_tol=1e-9), r.law  # fmt: skip
        for delay, (lo, hi) in ((0, (r.margin_lo, r.margin_hi)),
                                (1, (r.margin_delay_lo, r.margin_delay_hi))):  # fmt: skip
            for edge, side in ((lo, -1), (hi, +1)):
                if not (math.isfinite(edge) and edge > 0):
                    continue
                inside = _radius(
                    CFG.plant.a * edge * (1 - side * 1e-6), 0.002, r.k_x1, r.k_x2, delay
                )
                outside = _radius(
                    CFG.plant.a * edge * (1 + side * 1e-6), 0.002, r.k_x1, r.k_x2, delay
                )
                assert inside < 1.0 <= outside, (r.law, delay, edge)
                checked += 1
            if math.isnan(lo):  # unstable at the design point
                assert _radius(CFG.plant.a, 0.002, r.k_x1, r.k_x2, delay) >= 1.0, r.law
    assert checked >= 2


def test_pto_comparison(point):
    pto = point.law("pto").median_ratio_nt
    for r in point.laws:
        if r.law != "pto" and math.isfinite(r.median_ratio_nt) and math.isfinite(pto):
            assert (r.law in point.pto_beats) == (pto < r.median_ratio_nt), r.law
            assert (r.law in point.pto_loses_to) == (pto > r.median_ratio_nt), r.law


def test_point_structure(point):
    assert [r.law for r in point.laws] == ["pd", "pto", "ptos", "cascade-p"]
    medians = {r.law: r.median_ratio_nt for r in point.laws if math.isfinite(r.median_ratio_nt)}
    assert point.fastest == min(medians, key=medians.get)
    assert all(r.worst_ratio_nt >= r.median_ratio_nt for r in point.laws if r.law in medians)
    # settling / N*T may dip below 1 only by the settling band: never below 0
    assert all(v > 0 for v in medians.values())


def test_point_config_reading():
    assert point_config(CFG, 0.001, 30.0, "hz").plant.a == 30.0
    assert math.isclose(point_config(CFG, 0.001, 30.0, "2pi").plant.a, 2 * math.pi * 30.0)
    with pytest.raises(InputError, match="plant.sample_time"):
        point_config(CFG, 5.0, 30.0, "2pi")
    with pytest.raises(InputError, match="reading"):
        point_config(CFG, 0.001, 30.0, "rpm")


@pytest.mark.parametrize(
    ("argv", "msg"),
    [
        (["--sample-times", "0"], "sample times must be positive"),
        (["--bandwidths", "-3"], "bandwidths must be positive"),
        (["--grid", "1"], "--grid must be in"),
        (["--dask", "my-cluster"], "--dask must be 'local'"),
    ],
)
def test_cli_bad_input(argv, msg, capsys):
    assert main(["design", *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ptoverify: error:") and msg in err and err.count("\n") == 1


def test_cli_json_and_out(tmp_path, capsys):
    out = tmp_path / "chart"
    argv = ["design", "--sample-times", "0.002", "--bandwidths", "30", "--laws", "pd",
            "cascade-p", "--grid", "4", "--json", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert [r["law"] for r in res["points"][0]["laws"]] == ["pd", "cascade-p"]
    saved = json.loads((out / "design.json").read_text())
    assert saved["points"] == res["points"]
    rows = (out / "design.csv").read_text().splitlines()
    assert len(rows) == 1 + 2


@pytest.mark.slow
def test_tuned_point_uses_the_tuning():
    """--tuned: the law's gains are the tuning's (recomputed here), measured as configured ones."""
    from ptoverify.studies.design import TUNE_EFFORT
    from ptoverify.studies.tune import tune

    pt = design_point(CFG, 0.002, 30.0, laws=("cascade-p", "to"), grid=4, tuned_overshoot=0.0)
    r = pt.law("cascade-p")
    c = point_config(CFG, 0.002, 30.0, "2pi")
    t = tune(c, "cascade-p", "step", max_overshoot=0.0, find_runner_up=False, **TUNE_EFFORT)
    assert r.gains_from == "tuned" and r.k_x1 == t.best.gains["kp"]
    assert pt.law("to").gains_from == "configured"
    assert pt.pto_beats == () and pt.pto_loses_to == ()  # no PTO asked
    with pytest.raises(InputError, match="--tuned"):
        design_chart(CFG, [0.002], [30.0], tuned_overshoot=-1.0)


@pytest.mark.slow
def test_process_pool_equals_in_process():
    args = dict(laws=("pd", "ptos"), grid=4)
    here = design_chart(CFG, [0.002], [30.0, 60.0], **args)
    there = design_chart(CFG, [0.002], [30.0, 60.0], runner=process_runner(2), **args)
    assert here.to_json(timings=False)["points"] == there.to_json(timings=False)["points"]


def test_default_axes_are_within_the_configuration_limits():
    """`ptoverify design` with no axis options builds every default point (audit R6)."""
    from ptoverify.config import DESIGN_BANDWIDTHS_HZ, DESIGN_SAMPLE_TIMES, paper_config
    from ptoverify.studies.design import point_config

    for T in DESIGN_SAMPLE_TIMES:
        for f in DESIGN_BANDWIDTHS_HZ:
            assert point_config(paper_config(), T, f, "2pi").plant.sample_time == T


def test_a_point_outside_the_limits_is_named(capsys):
    from ptoverify.cli import main

    code = main(["design", "--sample-times", "0.00025", "--bandwidths", "5"])
    err = capsys.readouterr().err
    assert code == 2 and "design point T = 0.25 ms, bandwidth 5" in err and err.count("\n") == 1
