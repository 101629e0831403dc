"""Tests of the PTOS claim and the baselines' fair configurations (studies/ptos_claim.py).

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
from ptoverify.model.baselines import linear_loop_gains
from ptoverify.model.laws import make_law
from ptoverify.studies.ptos_claim import ptos_claim, reading_config

CFG = paper_config()


def _stable(cfg, law) -> bool:
    Ad, Bd = zoh_reference(cfg.plant.a, cfg.plant.sample_time)
    K = np.array([linear_loop_gains(law, cfg)])
    return float(np.abs(np.linalg.eigvals(Ad - Bd @ K)).max()) < 1.0


def test_linear_gains_are_those_of_the_laws():
    """The linear loop's gains equal the laws' own slopes near the origin (unclipped)."""
    assert linear_loop_gains("to", CFG) is None
    for law in ("pd", "pto", "ptos", "cascade-p"):
        k1, k2 = linear_loop_gains(law, CFG)
        fn = make_law(law, CFG)
        x1, x2 = np.array([1e-4, 0.0]), np.array([0.0, 1e-3])
        u, _ = fn(x1, x2)
        assert u[0] == pytest.approx(-k1 * 1e-4, rel=1e-12)
        assert u[1] == pytest.approx(-k2 * 1e-3, rel=1e-12, abs=1e-18)
    assert _stable(CFG, "pd") and _stable(CFG, "cascade-p")


def test_fair_configs_come_from_fair_tunings():
    from ptoverify.studies.ptos_claim import fair_configs
    from ptoverify.studies.tune import TuneBudget, fair_tunings

    b = TuneBudget(maxiter=2, popsize=4, d_grid=2, d_refine=0)
    got = fair_configs(CFG, ("to", "cascade-p"), budget=b)
    ft = fair_tunings(CFG, b, ("cascade-p",))
    assert got["to"] is CFG
    assert got["cascade-p"] == ft.config("cascade-p", "pto-paper")
    with pytest.raises(InputError, match="bound"):
        fair_configs(CFG, ("pd",), "nope")


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
