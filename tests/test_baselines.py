"""Tests of the baseline laws (model/baselines.py), their config tables and derivation.

References: hand computations of Workman's profile in plain ``math`` at chosen
states, the PD law (cascade P and PTOS at k = a are saturated P loops), the
SymPy records of ``derivations/baselines.py``, and properties over random
states (hypothesis).
"""

import dataclasses
import json
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from derivations import baselines as dbase
from derivations.record import judge
from ptoverify.cli import main
from ptoverify.config import (
    ALL_LAW_NAMES,
    PAPER_MAPPING,
    PDGains,
    config_from_mapping,
    paper_config,
)
from ptoverify.errors import ConfigError
from ptoverify.model.baselines import cascade_law, ptos_design, ptos_law
from ptoverify.model.laws import Region, make_law, pd_law

CFG = paper_config()
A_RAD, W = CFG.plant.a, CFG.plant.w_max


def _hand_ptos(x1, x2, a, w, alpha, k):
    """Workman's profile and command, by hand (module docstring of baselines)."""
    acc = a * w  # A
    k1 = alpha * k * k / 2.0
    y_l = acc / k1
    e = -x1
    if abs(e) <= y_l:
        f = k1 / k * e
    else:
        f = math.copysign(math.sqrt(2.0 * alpha * acc * abs(e)) - acc / k, e)
    v = k / a * f - (k / a - 1.0) * x2
    return max(-w, min(w, v)), y_l


@pytest.mark.parametrize("k_over_a", [1.0, 2.5, 6.0])
@pytest.mark.parametrize(("x1", "x2"), [(0.05, 0.0), (-0.2, 30.0), (1.0, -50.0), (3.0, 0.0)])
def test_ptos_matches_hand_computation(k_over_a, x1, x2):
    law = ptos_law(CFG, alpha=0.8, k=k_over_a * A_RAD)
    want, _ = _hand_ptos(x1, x2, A_RAD, W, 0.8, k_over_a * A_RAD)
    u, _ = law(np.array([x1]), np.array([x2]))
    assert_allclose(u[0], want, rtol=1e-12, atol=1e-9, err_msg="PTOS u against the hand formula")
    assert_allclose(law.scalar(x1, x2)[0], want, rtol=1e-12, atol=1e-9, err_msg="scalar PTOS u")


def test_profile_continuous_in_value_and_slope_at_the_edge():
    """At |x1| = y_l the two branches meet with one value and one slope.

    At x2 = 0 the edge value is exactly w_max for any k ((k/a) A / k = w_max), so
    the state moves toward the target (x2 < 0) to keep u unclipped.
    """
    k = 6.0 * A_RAD  # the branch acts below the saturation
    law = ptos_law(CFG, alpha=0.7, k=k)
    y_l = ptos_design(CFG, alpha=0.7, k=k).y_l
    h = 1e-7 * y_l
    x = np.array([y_l - 2 * h, y_l - h, y_l, y_l + h, y_l + 2 * h])
    x2 = -40.0
    u, region = law(x, np.full(5, x2))
    assert region.tolist()[:3] == [Region.LINEAR] * 3 and region[-1] == Region.ZONE_N
    # value: jump across the edge no larger than the slope times the step
    slope_in = (u[1] - u[0]) / h
    slope_out = (u[4] - u[3]) / h
    hand_slope = -(k / A_RAD) * 0.7 * k / 2.0  # -(k/a) alpha k / 2 (k1 / k times k / a)
    assert_allclose([slope_in, slope_out], hand_slope, rtol=1e-4, err_msg="slope at y_l")
    assert_allclose(u[3] - u[2], hand_slope * h, rtol=1e-4, err_msg="value continuity at y_l")
    kv = k / A_RAD - 1.0
    want = -(k / A_RAD) * A_RAD * W / k - kv * x2  # f(y_l) = A / k
    assert_allclose(u[2], want, rtol=1e-12, err_msg="u at the edge")


def test_ptos_saturates_and_default_is_a_p_loop():
    law = make_law("ptos", CFG)
    u, region = law(np.array([40.0, -40.0]), np.array([0.0, 0.0]))
    assert u.tolist() == [-W, W] and set(region.tolist()) == {Region.SATURATED}
    # k = a: u = f(-x1) and f(y_l) = w_max, so PTOS is sat(-(alpha a / 2) x1) bit for bit
    p = ptos_design(CFG)
    assert p.kv == 0.0 and p.offset == pytest.approx(W, rel=1e-14)
    rng = np.random.default_rng(3)
    x1, x2 = rng.uniform(-60, 60, 5000), rng.uniform(-400, 400, 5000)
    ref = pd_law(dataclasses.replace(CFG, pd=PDGains(kp=CFG.ptos.alpha * A_RAD / 2, kd=0.0)))
    assert_array_equal(law(x1, x2)[0], ref(x1, x2)[0], err_msg="PTOS at k = a vs saturated P")


def test_cascade_is_saturated_p_with_default_gain():
    law = make_law("cascade-p", CFG)
    assert law.scalar(0.1, 123.0) == (pytest.approx(-A_RAD / 4 * 0.1, rel=1e-15), Region.LINEAR)
    assert law.scalar(-50.0, 0.0) == (W, Region.SATURATED)
    cfg = config_from_mapping({**PAPER_MAPPING, "cascade": {"kp": 80.0}})
    assert make_law("cascade-p", cfg).scalar(1.0, 0.0)[0] == -80.0


finite = st.floats(-1e4, 1e4, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    x1=finite,
    x2=finite,
    alpha=st.floats(0.05, 1.0),
    k_ratio=st.floats(0.2, 20.0),
    kp=st.floats(0.0, 5000.0),
)
def test_properties_finite_bounded_odd(x1, x2, alpha, k_ratio, kp):
    for law in (ptos_law(CFG, alpha=alpha, k=k_ratio * A_RAD), cascade_law(CFG, kp=kp)):
        u, r = law(np.array([x1, -x1]), np.array([x2, -x2]))
        assert np.all(np.isfinite(u)) and np.all(np.abs(u) <= W), law.name
        assert u[1] == -u[0] or (u[0] == 0 and u[1] == 0), f"{law.name} not odd"
        assert law.scalar(x1, x2) == (u[0], r[0]), f"{law.name}: scalar vs vector"


def test_names_and_cli_simulate():
    assert {"ptos", "cascade-p"} <= set(ALL_LAW_NAMES)
    for name in ("ptos", "cascade-p"):
        assert make_law(name, CFG).name == name


def test_cli_simulate_baselines(capsys):
    for name in ("ptos", "cascade-p"):
        assert main(["simulate", "--law", name, "--json"]) == 0
        out = json.loads(capsys.readouterr().out)
        assert out["metrics"]["settling_0p01mm_s"] > 0, name


# ------------------------------------------------------------------ configuration
def test_config_tables():
    cfg = config_from_mapping({**PAPER_MAPPING, "ptos": {"alpha": 0.5, "k": 400.0}})
    assert (cfg.ptos.alpha, cfg.ptos.k) == (0.5, 400.0)
    assert config_from_mapping(cfg.to_mapping()) == cfg
    assert "ptos" not in paper_config().to_mapping()  # the paper's digest is unchanged
    assert cfg.digest() != paper_config().digest()


@pytest.mark.parametrize(
    ("table", "match"),
    [
        ({"ptos": {"alpha": 0.0}}, "ptos.alpha"),
        ({"ptos": {"alpha": 1.5}}, "ptos.alpha"),
        ({"ptos": {"k": -1.0}}, "ptos.k"),
        ({"ptos": {"beta": 1.0}}, "unknown config key 'ptos.beta'"),
        ({"cascade": {"kp": "fast"}}, "cascade.kp"),
        ({"cascade": {"kp": 1e9}}, "cascade.kp"),
        ({"cascade": 3}, "cascade"),
    ],
)
def test_config_rejects(table, match):
    with pytest.raises(ConfigError, match=match):
        config_from_mapping({**PAPER_MAPPING, **table})


# ------------------------------------------------------------------ derivation
def test_derivation_records_verified():
    recs = {r.id: r for r in dbase.records()}
    assert set(recs) == {"PTOS-v", "PTOS-y", "PTOS-0", "PTOS-1", "PTOS-A", "PTOS-sat"}
    assert all(r.verdict == "verified" for r in recs.values()), [r.note for r in recs.values()]


def test_derivation_detects_a_wrong_edge():
    """The judge that verifies y_l = 2 A / (alpha k^2) rejects the guess y_l = A / k^2."""
    sol = dbase.continuity_solution()
    s = dbase.SYMBOLS
    wrong = s["A"] / s["k"] ** 2
    j = judge(wrong, sol[s["y_l"]], dbase._sampler)
    assert j.verdict == "erratum"
    assert sp.simplify(sol[s["k1"]] - s["alpha"] * s["k"] ** 2 / 2) == 0


def test_numerics_follow_derivation():
    sol = dbase.continuity_solution()
    s = dbase.SYMBOLS
    p = ptos_design(CFG, alpha=0.6, k=900.0)
    at = {s["alpha"]: 0.6, s["k"]: 900.0, s["A"]: A_RAD * W}
    assert_allclose(p.y_l, float(sol[s["y_l"]].subs(at)), rtol=1e-14, err_msg="y_l")
    assert_allclose(p.k1, float(sol[s["k1"]].subs(at)), rtol=1e-14, err_msg="k1")
