import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from ptoverify.model.curves import switching_function
from ptoverify.model.mintime import min_time
from ptoverify.model.plant import flow


def arc_by_arc(x1, x2, plant):
    """Reference: propagate the exact flow under -s w until sigma = 0, then +s w to x2 = 0."""
    a, w = plant.a, plant.w_max
    sig = switching_function(x1, x2, a, w)
    s = 1.0 if sig > 0 or (sig == 0 and x2 < 0) else -1.0

    def sigma_after(t):
        y1, y2 = flow(x1, x2, -s * w, t, a)
        return float(switching_function(y1, y2, a, w))

    t_hi = 1e-3
    while np.sign(sigma_after(t_hi)) == np.sign(sig) and sig != 0:
        t_hi *= 2
    t1 = 0.0 if sig == 0 else brentq(sigma_after, 0.0, t_hi, xtol=1e-300, rtol=8.9e-16, maxiter=500)
    y1, y2 = flow(x1, x2, -s * w, t1, a)
    # second arc under +s w: x2(t) = s w + (y2 - s w) e^{-a t} = 0
    t2 = np.log((y2 - s * w) / (-s * w)) / a
    z1, _ = flow(y1, y2, s * w, t2, a)
    return t1, t2, float(z1)


def test_closed_form_vs_arc_by_arc(any_cfg):
    p = any_cfg.plant
    rng = np.random.default_rng(6)
    pts = np.c_[
        rng.uniform(-p.position_range, p.position_range, 150),
        rng.uniform(-1.5 * p.w_max, 1.5 * p.w_max, 150),
    ]
    mt = min_time(pts[:, 0], pts[:, 1], p)
    for i, (x1, x2) in enumerate(pts):
        t1, t2, miss = arc_by_arc(x1, x2, p)
        # both sides are round-off exact; the brentq crossing is found to ~1 ulp of t
        assert_allclose(mt.t_f[i], t1 + t2, rtol=1e-12, err_msg=f"t_f at {x1, x2}")
        assert_allclose(
            mt.t_switch[i],
            t1,
            rtol=1e-10,
            atol=1e-12 * (t1 + t2),
            err_msg=f"switch time at {x1, x2}",
        )
        assert abs(miss) < 1e-9 * max(1.0, abs(x1)), "arc-by-arc does not end at the origin"


def test_closed_form_vs_brute_force_switch_search(paper_cfg):
    """Grid over one switch time: the best miss lies within one grid cell of the closed form."""
    p = paper_cfg.plant
    a, w = p.a, p.w_max
    rng = np.random.default_rng(7)
    for x1, x2 in rng.uniform([-50, -250], [50, 250], size=(10, 2)):
        mt = min_time(x1, x2, p)
        s = float(mt.side)
        t1 = np.linspace(0, 2 * float(mt.t_f) + 0.01, 200001)
        y1, y2 = flow(x1, x2, -s * w, t1, a)
        with np.errstate(invalid="ignore"):
            t2 = np.log((y2 - s * w) / (-s * w)) / a  # second arc until x2 = 0
        z1, _ = flow(y1, y2, s * w, t2, a)
        i = np.nanargmin(np.abs(z1))
        dt = t1[1] - t1[0]
        assert abs(t1[i] - float(mt.t_switch)) <= 2 * dt, "switch time off the grid optimum"
        assert abs(t1[i] + t2[i] - float(mt.t_f)) <= 4 * dt, "t_f off the grid optimum"


def test_edges(paper_cfg):
    p = paper_cfg.plant
    mt = min_time(0.0, 0.0, p)
    assert float(mt.t_f) == 0.0 and float(mt.t_switch) == 0.0
    # symmetry t(-x) = t(x)
    rng = np.random.default_rng(8)
    x1, x2 = rng.uniform(-50, 50, 1000), rng.uniform(-900, 900, 1000)
    assert_allclose(
        min_time(-x1, -x2, p).t_f, min_time(x1, x2, p).t_f, rtol=1e-14, err_msg="t_f symmetry"
    )
    # exactly at x2 = -w_max the closed form stays finite and consistent
    mt = min_time(10.0, -p.w_max, p)
    t1, t2, _ = arc_by_arc(10.0, -p.w_max, p)
    assert_allclose(float(mt.t_f), t1 + t2, rtol=1e-12, err_msg="x2 = -w_max")


@pytest.mark.parametrize("x1,x2", [(5.0, 0.0), (-20.0, 100.0), (0.3, -400.0)])
def test_scalar_and_vector_agree(paper_cfg, x1, x2):
    p = paper_cfg.plant
    v = min_time(np.array([x1, 1.0]), np.array([x2, 1.0]), p)
    s = min_time(x1, x2, p)
    assert float(s.t_f) == v.t_f[0]
