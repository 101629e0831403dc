import mpmath
import numpy as np
import pytest
from conftest import ALL_CONFIGS
from hypothesis import given, settings
from hypothesis import strategies as st

from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.model.laws import Region, make_law

CFG = paper_config()
W = CFG.plant.w_max
states = st.tuples(st.floats(-1e4, 1e4, allow_nan=False), st.floats(-1e5, 1e5, allow_nan=False))


@pytest.mark.parametrize("name", ["to", "pd"])
@settings(max_examples=300, deadline=None)
@given(x=states)
def test_law_properties(name, x):
    law = make_law(name, CFG)
    u, region = law.scalar(*x)
    assert np.isfinite(u) and abs(u) <= W
    u_neg, _ = law.scalar(-x[0], -x[1])
    assert u_neg == -u, "odd symmetry u(-x) = -u(x)"
    uv, rv = law(np.array([x[0]]), np.array([x[1]]))
    assert uv[0] == u and rv[0] == region, "vector and scalar paths disagree"


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
