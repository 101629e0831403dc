"""Tests of the baseline tuning and the PTOS claim (studies/ptos_claim.py).

References: scipy's ZOH discretization for the linear loop's stability, the
``simulate --json`` metrics re-measured on the returned configuration, and the
grid properties recomputed for the verdict's rule.
"""

import math

import numpy as np
import pytest
from conftest import zoh_reference

from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.model.baselines import ptos_design
from ptoverify.studies.ptos_claim import (
    baseline_linear_gains,
    ptos_claim,
    reading_config,
    tune_baseline,
)
from ptoverify.studies.tune import response_metrics

CFG = paper_config()


def _stable(cfg, law) -> bool:
    Ad, Bd = zoh_reference(cfg.plant.a, cfg.plant.sample_time)
    K = np.array([baseline_linear_gains(cfg, law)])
    return float(np.abs(np.linalg.eigvals(Ad - Bd @ K)).max()) < 1.0


@pytest.mark.parametrize(("search", "law"), [("cascade-p", "cascade-p"), ("ptos", "ptos")])
def test_tuning_meets_its_constraints(search, law):
    bound = response_metrics(CFG, "pd", "step")["overshoot_mm"]
    t = tune_baseline(CFG, search, bound, maxiter=4, popsize=5, grid=(11, 11, 10))
    assert t.feasible and t.law == law
    m = response_metrics(t.config, law, "step")  # re-measured on the simulate --json path
    assert m["overshoot_mm"] <= bound
    assert math.isclose(m["settling_2pct_s"], t.settling_2pct_s, rel_tol=0, abs_tol=0)
    assert _stable(t.config, law)
    # the search can only improve on (or equal) the configured gains when they are feasible
    base = response_metrics(CFG, law, "step")
    if base["overshoot_mm"] <= bound and _stable(CFG, law):
        assert t.settling_2pct_s <= base["settling_2pct_s"]


def test_ideal_search_keeps_k_equal_to_a():
    t = tune_baseline(CFG, "ptos-ideal", 1.0, maxiter=3, popsize=4, grid=(11, 11, 10))
    assert ptos_design(t.config).k == CFG.plant.a and ptos_design(t.config).kv == 0.0


def test_bad_law():
    with pytest.raises(InputError, match="tune_baseline"):
        tune_baseline(CFG, "pd", 0.1)


def test_readings():
    assert reading_config(CFG, "2pi") is CFG
    assert reading_config(CFG, "hz").plant.a == CFG.bandwidth_hz


@pytest.mark.slow
def test_claim_verdict_follows_its_rule():
    res = ptos_claim(CFG, maxiter=3, popsize=4, grid=(11, 11, 10))
    assert {r for r, _ in res.verdicts} == {"2pi", "hz"}
    for reading, verdict in res.verdicts:
        rows = [m for m in res.measures if m.reading == reading]
        assert rows[0].setting == "configured"
        for m in rows:
            usable = (
                m.limit_cycles == 0
                and m.not_settled == 0
                and m.stride_overs == 0
                and m.step_overshoot_mm <= m.bound_mm
                and math.isfinite(m.step_settling_2pct_s)
            )
            assert m.usable == usable
        assert verdict == ("not reproduced" if any(m.usable for m in rows) else "reproduced")
    assert res.to_json()["verdicts"] == dict(res.verdicts)
