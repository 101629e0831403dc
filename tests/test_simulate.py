import numpy as np
from numpy.testing import assert_allclose

from ptoverify.laws import make_law
from ptoverify.plant import zoh_matrices
from ptoverify.simulate import SIGNALS, simulate, simulate_batch


def test_simulate_matches_zoh_matrices(paper_cfg):
    """The loop reproduces x[k+1] = Ad x[k] + Bd u[k] with the logged inputs."""
    p = paper_cfg.plant
    for sig in SIGNALS:
        res = simulate(make_law("pd", paper_cfg), p, sig)
        Ad, Bd = zoh_matrices(p.a, p.T)
        X = np.c_[res.x1, res.x2]
        pred = X[:-1] @ Ad.T + res.u[:-1, None] * Bd[:, 0]
        assert_allclose(X[1:], pred, rtol=1e-12, atol=1e-10, err_msg=f"{sig}: ZOH recursion")
        assert np.all(np.abs(res.u) <= p.w_max)
        assert_allclose(res.e, res.r - res.x1, rtol=0, atol=0, err_msg="error definition")


def test_references():
    t = np.array([0.0, 0.1, 0.2])
    assert_allclose(SIGNALS["step"].r(t), 5.0, err_msg="step")
    assert_allclose(SIGNALS["ramp"].r(t), [0.0, 20.0, 30.0], err_msg="ramp saturates at 30 mm")
    assert_allclose(SIGNALS["sine"].r(np.array([0.05])), [5.0], err_msg="sine peak at T/4")


def test_batch_matches_single(paper_cfg):
    law = make_law("to", paper_cfg)
    p = paper_cfg.plant
    x1 = np.array([5.0, -3.0, 20.0])
    x2 = np.array([0.0, 100.0, -50.0])
    b = simulate_batch(law, p, x1, x2, 60)
    for j in range(3):
        y1, y2 = x1[j], x2[j]
        for k in range(60):
            u, _ = law.scalar(y1, y2)
            assert u == b.u[k, j]
            Ad, Bd = zoh_matrices(p.a, p.T)
            y1, y2 = Ad @ [y1, y2] + Bd[:, 0] * u
        assert_allclose(
            [y1, y2],
            [b.x1[-1, j], b.x2[-1, j]],
            rtol=1e-9,
            atol=1e-9,
            err_msg="batch vs one-by-one",
        )


def test_pd_step_settles_and_to_keeps_oscillating(paper_cfg):
    p = paper_cfg.plant
    pd = simulate(make_law("pd", paper_cfg), p, "step")
    to = simulate(make_law("to", paper_cfg), p, "step")
    assert abs(pd.e[-1]) < 1e-6
    tail = to.e[-50:]
    assert np.ptp(tail) > 1e-3 and np.sum(np.diff(np.sign(tail)) != 0) > 5
