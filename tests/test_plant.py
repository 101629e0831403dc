import numpy as np
from conftest import zoh_reference, zoh_step
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp

from ptoverify.model.plant import flow, step, zoh_matrices


def augmented_expm(a, u, t, x0):
    """State after t by the scipy ZOH reference held for t (independent of eq. 7)."""
    return np.array(zoh_step(x0[0], x0[1], u, a, t))


def test_flow_matches_expm_and_solve_ivp(any_cfg):
    p = any_cfg.plant
    rng = np.random.default_rng(2)
    for _ in range(50):
        x0 = rng.uniform([-50, -400], [50, 400])
        u = rng.uniform(-p.w_max, p.w_max)
        t = rng.uniform(0, 0.1)
        x = np.array(flow(x0[0], x0[1], u, t, p.a))
        # expm: rounding of the 3x3 Pade approximant, about 1e-13 relative to |x|
        assert_allclose(
            x,
            augmented_expm(p.a, u, t, x0),
            rtol=1e-12,
            atol=1e-11,
            err_msg="flow vs expm of the augmented matrix",
        )
        sol = solve_ivp(
            lambda _, y: [y[1], -p.a * y[1] + p.a * u],
            (0, t),
            x0,
            rtol=1e-12,
            atol=1e-12,
            method="DOP853",
        )
        assert_allclose(
            x, sol.y[:, -1], rtol=1e-9, atol=1e-9, err_msg="flow vs solve_ivp at rtol 1e-12"
        )


def test_zoh_matrices_match_expm(any_cfg):
    p = any_cfg.plant
    Ad, Bd = zoh_matrices(p.a, p.T)
    Ad_ref, Bd_ref = zoh_reference(p.a, p.T)
    assert_allclose(Ad, Ad_ref, rtol=1e-13, atol=1e-16, err_msg="Ad vs scipy cont2discrete")
    assert_allclose(Bd, Bd_ref, rtol=1e-12, atol=1e-16, err_msg="Bd vs scipy cont2discrete")
    x = np.array([3.0, -120.0])
    assert_allclose(
        Ad @ x + Bd[:, 0] * 250.0,
        np.array(step(x[0], x[1], 250.0, p)),
        rtol=1e-13,
        err_msg="one-sample map vs ZOH matrices",
    )


def test_flow_vectorized_broadcasts(paper_cfg):
    x1, x2 = flow(np.zeros(5), np.linspace(-1, 1, 5), 300.0, 0.01, paper_cfg.plant.a)
    assert x1.shape == (5,) and x2.shape == (5,)
