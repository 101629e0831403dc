import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.laws import Region, make_law

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


def test_to_law_on_curves_and_origin():
    law = make_law("to", CFG)
    from ptoverify.curves import level_curve_x1

    x2 = -150.0
    x1 = float(level_curve_x1(x2, CFG.plant.a, W))  # on l1: +w_max (eq. 12)
    assert law.scalar(x1, x2)[0] == W or abs(law.scalar(x1, x2)[0]) == W
    assert law.scalar(0.0, 0.0) == (0.0, Region.ORIGIN)
    assert law.scalar(1.0, 0.0) == (-W, Region.BANG_N)
    assert law.scalar(-1.0, 0.0) == (W, Region.BANG_P)


def test_pd_law_saturates():
    law = make_law("pd", CFG)
    u, region = law(np.array([0.01, 10.0, -10.0]), np.zeros(3))
    assert np.allclose(u, [-CFG.pd.kp * 0.01, -W, W])
    assert list(region) == [Region.LINEAR, Region.SATURATED, Region.SATURATED]


def test_unknown_law():
    with pytest.raises(InputError, match="unknown law"):
        make_law("bangbang", CFG)
