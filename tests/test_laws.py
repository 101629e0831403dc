"""Laws (eqs. 12, 34, 35, PD): properties over the state space, one path, region boundaries."""

import dataclasses

import mpmath
import numpy as np
import pytest
from conftest import ALL_CONFIGS
from hypothesis import given, settings
from hypothesis import strategies as st

from ptoverify.config import PDGains, PTOSettings, paper_config
from ptoverify.errors import InputError
from ptoverify.model.curves import h, level_curve_x1
from ptoverify.model.laws import LAW_NAMES, Region, make_law, pto_law, with_state_gains

CFG = paper_config()
W = CFG.plant.w_max
LAWS = {name: make_law(name, CFG) for name in LAW_NAMES}
# finite positions; velocities finite or infinite (the side of every curve is then x2's)
states = st.tuples(
    st.floats(-1e4, 1e4, allow_nan=False),
    st.one_of(st.floats(-1e5, 1e5, allow_nan=False), st.sampled_from([np.inf, -np.inf])),
)


@pytest.mark.parametrize("name", LAW_NAMES)
@settings(max_examples=300, deadline=None)
@given(x=states)
def test_law_properties(name, x):
    """Finite output, |u| <= w_max, u(-x) = -u(x) exactly; one state alone is the batch's."""
    law = LAWS[name]
    u, region = law.scalar(*x)
    assert np.isfinite(u) and abs(u) <= W
    u_neg, _ = law.scalar(-x[0], -x[1])
    assert u_neg == -u, "odd symmetry u(-x) = -u(x)"
    uv, rv = law(np.array([x[0], 3.0, -0.2]), np.array([x[1], -250.0, 40.0]))
    assert uv[0] == u and rv[0] == region, "one state alone and in a batch disagree"
    u0, r0 = law(x[0], x[1])  # floats: the vector path on one state, 0-d results
    assert u0.shape == () and (float(u0), int(r0)) == (u, region)


def edge_states(cfg, n, seed):
    """States on every branch and boundary: on l1/l2 (ties, computed with the suite's curves),
    on l1*/l2*, at |x1| = d (both sides), the origin, +-0, +-inf velocity, beyond w_max."""
    rng = np.random.default_rng(seed)
    w, a, d = cfg.plant.w_max, cfg.plant.a, cfg.pto.d
    om = LAWS["pto"].family.params[3]
    x2 = rng.uniform(-1.2 * w, 1.2 * w, n) * rng.choice([1.0, 1e-2, 1e-6], n)
    x1 = rng.uniform(-40.0, 40.0, n) * rng.choice([1.0, 0.05, 1e-4], n)
    k = n // 8
    x1[:k] = level_curve_x1(x2[:k], a, w)  # on l1 / l2 as the law computes them (ties)
    x1[k : 2 * k] = level_curve_x1(x2[k : 2 * k], a, om)  # on l1* / l2*
    x1[2 * k : 3 * k] = (
        level_curve_x1(x2[2 * k : 3 * k], a, w)
        + rng.uniform(0, 3, k) * np.abs(x2[2 * k : 3 * k]) / a
    )  # between l1 and l1* (zone candidates)
    x1[3 * k : 4 * k] = rng.choice([d, -d, np.nextafter(d, 0.0), -np.nextafter(d, 0.0)], k)
    x2[4 * k : 4 * k + 20] = rng.choice([np.inf, -np.inf, 0.0, -0.0], 20)
    x1[4 * k + 20 : 4 * k + 40] = rng.choice([0.0, -0.0], 20)
    x1[-4:], x2[-4:] = [0.0, -0.0, 0.0, -0.0], [0.0, 0.0, -0.0, -0.0]
    return x1, x2


@pytest.mark.parametrize("name", LAW_NAMES)
def test_batch_size_independence(name):
    """A state gives the same u and region alone, in batches of 63, 64, 65 and 5000."""
    law = LAWS[name]
    x1, x2 = edge_states(CFG, 5000, 17)
    u, r = law(x1, x2)
    assert np.isfinite(u).all() and (np.abs(u) <= W).all()
    if name in ("pto", "pto-printed", "to"):
        assert {Region.ORIGIN, Region.BANG_P, Region.BANG_N} <= set(r.tolist())
    for size in (63, 64, 65):
        parts = [law(x1[i : i + size], x2[i : i + size]) for i in range(0, x1.size, size)]
        assert np.array_equal(np.concatenate([p[0] for p in parts]), u), f"u, batches of {size}"
        assert np.array_equal(np.concatenate([p[1] for p in parts]), r), f"region, {size}"
    one = [law.scalar(float(a), float(b)) for a, b in zip(x1[::5], x2[::5])]
    assert [v for v, _ in one] == u[::5].tolist() and [c for _, c in one] == r[::5].tolist()
    um, rm = law(-x1, -x2)
    assert np.array_equal(um, -u), "odd symmetry on the edge states"


def test_infinite_velocity_takes_the_side_of_x2():
    """x2 = +inf lies right of every curve (u = -w_max or saturated), -inf left of it."""
    x1 = np.array([-30.0, -0.1, 0.0, 0.1, 30.0])
    for name, law in LAWS.items():
        up, _ = law(x1, np.full(5, np.inf))
        un, _ = law(x1, np.full(5, -np.inf))
        assert (up == -W).all() and (un == W).all(), name


def l1_x1_mp(x2: float, a: float, w: float) -> mpmath.mpf:
    """x1 on l1 (x2 < 0) or l2 (x2 > 0) in 50 digits: a x1 = -x2 -+ w ln(1 -+ x2/w) (eqs. 9, 11)."""
    with mpmath.workdps(50):
        x2m, s = mpmath.mpf(x2), -mpmath.sign(x2)
        return (-x2m - s * w * mpmath.log(1 - s * x2m / w)) / a


@pytest.mark.parametrize("cfg", ALL_CONFIGS, ids=lambda c: c.name)
def test_to_law_switches_on_the_curve(cfg):
    """Either side of l1 - o - l2, 1e-9 of the range away: +w_max left, -w_max right (eq. 12).

    The curve is evaluated in 50 digits from eqs. (9), (11), independently of
    ``ptoverify.model.curves``; the offset is 1e-9 R [mm], far above the round-off of
    the switching function (~1e-13 of its scale).
    """
    law = make_law("to", cfg)
    a, w, R = cfg.plant.a, cfg.plant.w_max, cfg.plant.position_range
    delta = 1e-9 * R
    for x2 in np.concatenate([-np.geomspace(1e-3, 0.999, 12), np.geomspace(1e-3, 0.999, 12)]) * w:
        xc = l1_x1_mp(float(x2), a, w)
        left, right = float(xc - delta), float(xc + delta)
        assert law.scalar(left, x2) == (w, Region.BANG_P), f"left of the curve at x2 = {x2}"
        assert law.scalar(right, x2) == (-w, Region.BANG_N), f"right of the curve at x2 = {x2}"
    assert law.scalar(0.0, 0.0) == (0.0, Region.ORIGIN)
    assert law.scalar(delta, 0.0) == (-w, Region.BANG_N)
    assert law.scalar(-delta, 0.0) == (w, Region.BANG_P)


def test_pd_law_saturates():
    law = make_law("pd", CFG)
    u, region = law(np.array([0.01, 10.0, -10.0]), np.zeros(3))
    assert np.allclose(u, [-CFG.pd.kp * 0.01, -W, W])
    assert list(region) == [Region.LINEAR, Region.SATURATED, Region.SATURATED]


def test_unknown_law():
    with pytest.raises(InputError, match="unknown law"):
        make_law("bangbang", CFG)


def test_family_vector_is_each_laws_vector():
    """One call of the PTO family, each state with its law's parameters, bit for bit."""
    rng = np.random.default_rng(5)
    n = 3000
    x1 = rng.uniform(-50.0, 50.0, n) * rng.uniform(0.0, 1.0, n) ** 3
    x2 = rng.uniform(-350.0, 350.0, n) * rng.uniform(0.0, 1.0, n)
    x1[:6] = [0.0, CFG.pto.d, -CFG.pto.d, np.nan, 1.0, np.inf]
    x2[:6] = [0.0, 0.0, 1.0, 0.0, np.nan, 0.0]
    laws = [make_law(name, CFG) for name in ("to", "pto", "pto-printed")]
    pick = rng.integers(0, 3, n)
    params = [np.array([laws[k].family.params[i] for k in pick]) for i in range(4)]
    with np.errstate(invalid="ignore"):
        u, region = laws[0].family.vector(x1, x2, *params)
        for k, law in enumerate(laws):
            mine = pick == k
            want_u, want_r = law.vector(x1[mine], x2[mine])
            assert np.array_equal(u[mine], want_u, equal_nan=True), law.name
            assert np.array_equal(region[mine], want_r), law.name
    assert {Region.ZONE_P, Region.ZONE_N, Region.LINEAR, Region.BANG_P} <= set(region.tolist())


def test_pto_regions_at_the_boundaries():
    """|x1| = d is outside the linear zone (|x1| < d); l1* bounds the zone, l1 splits S_P from it."""
    law = LAWS["pto"]
    a, d = CFG.plant.a, CFG.pto.d
    om = law.family.params[3]
    assert law.scalar(np.nextafter(d, 0.0), 0.0)[1] == Region.LINEAR
    assert law.scalar(-np.nextafter(d, 0.0), 0.0)[1] == Region.LINEAR
    assert law.scalar(d, 0.0) == (-W, Region.BANG_N)
    assert law.scalar(-d, 0.0) == (W, Region.BANG_P)
    # a velocity where l1* lies right of the linear zone: x1 on l1* is in the zone, at u = omega0
    s = 280.0
    x1_star = om * float(h(s / om)) / a
    assert x1_star > d
    u, r = law.scalar(x1_star, -s)
    assert r == Region.ZONE_P and om <= u <= W
    assert law.scalar(x1_star + 1e-9, -s) == (-W, Region.BANG_N), "right of l1*: S_N"
    # across l1 (where it lies right of the linear zone, beyond the envelope): S_P | zone
    s = 600.0
    x1_l1 = W * float(h(s / W)) / a
    assert x1_l1 > d
    assert law.scalar(x1_l1 - 1e-9, -s) == (W, Region.BANG_P), "left of l1: u = +w_max"
    assert law.scalar(x1_l1 + 1e-9, -s)[1] == Region.ZONE_P, "right of l1: the zone"


def test_per_state_gains_are_each_configurations_law():
    """with_state_gains: state i with gains i equals the law built from those gains."""
    rng = np.random.default_rng(2024)
    n = 600
    ds = rng.choice([0.2, 0.5, 1.0, 1.7, 3.0, 5.0], n)
    k1, k2 = 10 ** rng.uniform(1, 3.5, n), rng.uniform(0, 10, n)
    x1, x2 = edge_states(CFG, n, 4)
    u, r = with_state_gains("pto", CFG, {"k1": k1, "k2": k2, "d": ds})(x1, x2)
    for i in range(n):
        c = dataclasses.replace(
            CFG, pto=PTOSettings(d=float(ds[i]), k1=float(k1[i]), k2=float(k2[i]))
        )
        assert make_law("pto", c).scalar(float(x1[i]), float(x2[i])) == (u[i], r[i]), i
    assert {Region.ZONE_P, Region.ZONE_N, Region.LINEAR, Region.BANG_P} <= set(r.tolist())
    kp, kd = 10 ** rng.uniform(1, 3.5, n), rng.uniform(0, 4, n)
    law = with_state_gains("pd", CFG, {"kp": kp, "kd": kd})
    u, r = law(x1, x2)
    for i in range(0, n, 7):
        c = dataclasses.replace(CFG, pd=PDGains(kp=float(kp[i]), kd=float(kd[i])))
        assert make_law("pd", c).scalar(float(x1[i]), float(x2[i])) == (u[i], r[i])
    with pytest.raises(ValueError, match="per-state gain sets"):
        law.scalar(1.0, 0.0)  # one state for 600 gain sets


def test_pto_without_zone_per_state_level_nan():
    """A NaN zone level per state is the law without its switching zone."""
    n = 500
    x1, x2 = edge_states(CFG, n, 9)
    c = dataclasses.replace(CFG, pto=PTOSettings(d=0.3, k1=80.0, k2=1.2))
    gains = (np.full(n, 80.0), np.full(n, 1.2), np.full(n, 0.3), np.full(n, np.nan))
    u, r = pto_law(c, None, gains=gains)(x1, x2)
    ur, rr = pto_law(c, None)(x1, x2)
    assert np.array_equal(u, ur) and np.array_equal(r, rr)
