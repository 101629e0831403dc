"""The corrected PTO against fair-tuned PD, PTOS and cascade P (studies/versus.py).

References: each tuned law re-simulated independently (``simulate`` and the exact
metrics of its response), the bound measured on the PTO's paper-gain response,
and the floors from the scalar minimum-time routines.
"""

import dataclasses
import math

import pytest

from ptoverify.config import paper_config
from ptoverify.model.laws import make_law
from ptoverify.model.mintime import discrete_min_steps, min_time
from ptoverify.sim.exact import exact_metrics
from ptoverify.sim.simulate import simulate
from ptoverify.studies.tune import TuneBudget, tuned_config
from ptoverify.studies.versus import VERSUS_LAWS, versus

SMALL = TuneBudget(maxiter=2, popsize=5, d_grid=2, d_refine=0)
CFG = paper_config()


def _metrics(cfg, law):
    res = simulate(make_law(law, cfg), cfg.plant, "step")
    return exact_metrics(res, cfg.plant).exact()


@pytest.fixture(scope="module")
def result():
    return versus(CFG, SMALL)


def test_both_readings_every_law(result):
    assert [r.reading for r in result.readings] == ["2pi", "hz"]
    assert [r.a for r in result.readings] == [CFG.plant.a, CFG.bandwidth_hz]
    for r in result.readings:
        assert tuple(t.law for t in r.laws) == VERSUS_LAWS
    assert result.settling == "2pct"
    # a configuration given in rad/s has one reading only (whatever the search's effort:
    # the least one the tuning accepts)
    rad = dataclasses.replace(CFG, bandwidth_hz=None)
    least = TuneBudget(maxiter=1, popsize=1, d_grid=2, d_refine=0, polish=0)
    assert [r.reading for r in versus(rad, least).readings] == ["2pi"]


def test_tuned_numbers_are_those_of_an_independent_simulation(result):
    for r in result.readings:
        c = CFG if r.reading == "2pi" else CFG.with_plant(a=CFG.bandwidth_hz)
        # the shared bound: the PTO's overshoot at the paper's gains
        assert r.bound_mm == _metrics(c, "pto")["overshoot_mm"]
        # the floors of the 5 mm step from rest
        assert r.nt_s == pytest.approx(discrete_min_steps(-5.0, 0.0, c.plant).steps * c.plant.T)
        assert r.tf_s == pytest.approx(float(min_time(-5.0, 0.0, c.plant).t_f), rel=1e-12)
        for t in r.laws:
            if t.infeasible:
                assert t.settling_s is None and not t.gains
                continue
            m = _metrics(tuned_config(c, t.law, t.gains), t.law)
            assert m["settling_2pct_s"] == t.settling_s
            assert m["overshoot_mm"] == t.overshoot_mm <= r.bound_mm
            assert t.ratio_nt == pytest.approx(t.settling_s / r.nt_s, rel=1e-15)
            assert t.ratio_tf == pytest.approx(t.settling_s / r.tf_s, rel=1e-15)
        pto = r.law("pto").settling_s
        for law, d in r.pto_minus.items():
            other = r.law(law).settling_s
            if other is None or pto is None:
                assert d is None
            else:
                assert d == pto - other


def test_json_has_no_non_finite_numbers(result):
    def walk(v):
        if isinstance(v, dict):
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)
        elif isinstance(v, float):
            assert math.isfinite(v)

    js = result.to_json()
    walk(js)
    assert js["readings"][0]["laws"][0]["law"] == "pto"


def test_tuned_margins_against_independent_eigenvalues(result):
    from linear_loop_reference import check_interval, hand_gains

    for r in result.readings:
        c = CFG if r.reading == "2pi" else CFG.with_plant(a=CFG.bandwidth_hz)
        for t in r.laws:
            if t.infeasible:
                assert t.a_ratio_stable is None and t.a_ratio_stable_delay1 is None
                continue
            k = hand_gains(t.law, tuned_config(c, t.law, t.gains))
            check_interval(t.a_ratio_stable, *k, c.plant.a, c.plant.sample_time, 0)
            check_interval(t.a_ratio_stable_delay1, *k, c.plant.a, c.plant.sample_time, 1)
