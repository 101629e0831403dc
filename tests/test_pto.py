"""PTO law, eq. (35): both variants, omega_c closed form, ZOH riding, properties."""

import math

import numpy as np
import pytest
from conftest import zoh_step
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.model.curves import bisect, h, level_residual, omega_c
from ptoverify.model.laws import LAW_NAMES, Region, make_law, pto_law
from ptoverify.model.zones import corrected_zone, printed_zone

PAPER = paper_config()
A, W, T = PAPER.plant.a, PAPER.plant.w_max, PAPER.plant.sample_time
LAWS = {name: make_law(name, PAPER) for name in ("pto", "pto-printed")}
OMEGA0 = corrected_zone(PAPER, verify=False).omega0

finite_x1 = st.floats(-60.0, 60.0, allow_nan=False)
finite_x2 = st.floats(-320.0, 320.0, allow_nan=False)


@pytest.mark.parametrize("name", ["pto", "pto-printed"])
def test_registered(name):
    assert name in LAW_NAMES
    law = make_law(name, PAPER)
    assert law.name == name and law.note


def test_printed_variant_falls_back_and_says_so():
    z = printed_zone(PAPER)
    assert not z.usable
    law = LAWS["pto-printed"]
    assert "no switching zone" in law.note and "empty" in law.note
    # outside the linear zone it is the time-optimal law
    to = make_law("to", PAPER)
    x1, x2 = np.linspace(0.6, 50, 300), np.linspace(-300, 300, 300)
    assert_allclose(
        law(x1, x2)[0],
        to(x1, x2)[0],
        rtol=0,
        atol=0,
        err_msg="pto-printed equals TO outside the linear zone",
    )


@settings(max_examples=300, deadline=None)
@given(finite_x1, finite_x2)
def test_properties_finite_bounded_odd(x1, x2):
    for law in LAWS.values():
        u, r = law.scalar(x1, x2)
        assert math.isfinite(u) and abs(u) <= W
        um, _ = law.scalar(-x1, -x2)
        assert um == -u, (law.name, x1, x2)
        uv, rv = law(np.array([x1, 7.0]), np.array([x2, -30.0]))
        assert uv[0] == u and rv[0] == r, "one state alone and in a batch"


def test_vector_odd_and_bounded_dense():
    x1, x2 = np.meshgrid(np.linspace(-50, 50, 301), np.linspace(-300, 300, 301))
    for law in LAWS.values():
        u, r = law(x1, x2)
        um, rm = law(-x1, -x2)
        assert np.all(np.isfinite(u)) and np.abs(u).max() <= W
        assert_allclose(um, -u, rtol=0, atol=0, err_msg=f"{law.name} odd symmetry")


def test_regions_zone_and_linear():
    law = LAWS["pto"]
    d = PAPER.pto.d
    # a state between l1 and l1* right of the linear zone
    s = 250.0
    x1_l1 = W * float(h(s / W)) / A
    x1_l1s = OMEGA0 * float(h(s / OMEGA0)) / A
    x1 = 0.5 * (max(x1_l1, d) + x1_l1s)
    u, r = law.scalar(x1, -s)
    assert r == Region.ZONE_P and OMEGA0 <= u <= W
    u, r = law.scalar(-x1, s)
    assert r == Region.ZONE_N
    assert law.scalar(0.1, 0.0) == (-PAPER.pto.k1 * 0.1, int(Region.LINEAR))
    assert law.scalar(0.4, 300.0)[1] == Region.SATURATED
    assert law.scalar(0.0, 0.0) == (0.0, int(Region.ORIGIN))
    assert law.scalar(20.0, 0.0) == (-W, int(Region.BANG_N))


def test_zone_input_is_the_level_of_the_curve_through_the_state():
    """In the zone, u = omega_c (eqs. 28-32): the level whose curve passes through the state,
    checked against a bisection on the level residual (independent of the closed form)."""
    rng = np.random.default_rng(3)
    s = rng.uniform(150.0, 300.0, 400)
    om = rng.uniform(OMEGA0 * 1.01, W * 0.99, 400)
    x1 = om * h(s / om) / A  # on the level-om curve, between l1* and l1
    keep = x1 >= PAPER.pto.d
    x1, s, om = x1[keep], s[keep], om[keep]
    assert x1.size > 100
    ref = bisect(
        lambda w: level_residual(x1, -s, A, w), np.full(x1.size, 1e-3), np.full(x1.size, 1e6)
    )
    u, r = LAWS["pto"](x1, -s)
    assert (r == Region.ZONE_P).all()
    assert_allclose(u, ref, rtol=1e-10, err_msg="zone input vs bisection on the level")
    assert_allclose(u, omega_c(x1, -s, A), rtol=0, err_msg="zone input is omega_c")


def test_zone_state_rides_its_curve_under_zoh():
    """u = omega_c keeps a sampled state on its curve (one-sample map by scipy ZOH).

    States midway between l1* and l1 at velocities where that point lies outside
    the linear zone (x1 >= d); every state is checked, none skipped.
    """
    law = LAWS["pto"]
    s_all = np.linspace(1.0, W * (1 - 1e-6), 400)
    x1_all = 0.5 * (OMEGA0 * h(s_all / OMEGA0) + W * h(s_all / W)) / A
    keep = x1_all >= PAPER.pto.d
    assert keep.sum() >= 100, "too few zone states outside the linear zone to test"
    for x1, s in zip(x1_all[keep][::10], s_all[keep][::10]):
        u, r = law.scalar(float(x1), -float(s))
        assert r == Region.ZONE_P, f"state ({x1}, {-s}) should be in the zone"
        y1, y2 = zoh_step(x1, -s, u, A, T)
        assert_allclose(
            level_residual(y1, y2, A, u),
            0.0,
            atol=1e-9,
            err_msg="residual of the omega_c curve after one sample",
        )


def test_scalar_path_is_the_vector_path_on_zone_states():
    law = LAWS["pto"]
    pts = [
        (0.5 * (OMEGA0 * float(h(s / OMEGA0)) + W * float(h(s / W))) / A, -s)
        for s in np.linspace(150, 300, 200)
    ]
    pts += [
        (float(a), float(b)) for a, b in zip(np.linspace(-50, 50, 200), np.linspace(300, -300, 200))
    ]
    x1 = np.array([p[0] for p in pts])
    x2 = np.array([p[1] for p in pts])
    u_vec, r_vec = law(x1, x2)
    assert {Region.ZONE_P, Region.LINEAR} <= set(r_vec.tolist())
    for k, (a, b) in enumerate(pts):  # one state: the same path, so the same floats
        assert law.scalar(a, b) == (u_vec[k], r_vec[k])


def test_no_zone_when_omega0_none():
    law = pto_law(PAPER, None)
    _, r = law(np.linspace(0.6, 2, 50), np.full(50, -250.0))
    assert not np.any((r == Region.ZONE_P) | (r == Region.ZONE_N))


@pytest.mark.parametrize("name", ["pto", "pto-printed"])
def test_cli_simulate(name, capsys):
    import json

    assert main(["simulate", "--law", name, "--signal", "step", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["law"] == name and abs(out["final_error_mm"]) < 1e-3


def test_every_named_law_is_built_and_no_other():
    """The names the command line offers (config.LAW_NAMES) are exactly the laws make_law builds."""
    from ptoverify.errors import InputError

    assert [make_law(n, PAPER).name for n in LAW_NAMES] == list(LAW_NAMES)
    with pytest.raises(InputError, match="choose from to, pd, pto, pto-printed"):
        make_law("bang-bang", PAPER)
