"""Poles of the PD and linear-zone loops: python-control vs independent references."""

import numpy as np
import pytest
from conftest import zoh_reference
from numpy.testing import assert_allclose

from ptoverify.config import paper_config
from ptoverify.model.poles import all_loop_poles, critical_gain, loop_poles, lyapunov_counterexample

PAPER = paper_config()
CONFIGS = {
    "paper": PAPER,
    "a30": PAPER.with_plant(a=30.0),
    "T1ms": PAPER.with_plant(sample_time=0.001),
}


def expm_closed_loop(a, T, K):
    """Ad - Bd K with Ad, Bd from scipy's cont2discrete (independent of zoh_matrices)."""
    Ad, Bd = zoh_reference(a, T)
    return Ad - Bd @ np.atleast_2d(K)


def as_complex(pairs):
    return np.sort_complex(np.array([complex(r, i) for r, i in pairs]))


@pytest.mark.parametrize("name", list(CONFIGS))
def test_sampled_poles_vs_numpy_expm(name):
    cfg = CONFIGS[name]
    a, T = cfg.plant.a, cfg.plant.sample_time
    for lp in all_loop_poles(cfg).values():
        ref = np.sort_complex(np.linalg.eigvals(expm_closed_loop(a, T, lp.gains)))
        # eigenvalues of a 2x2 matrix with entries O(1): a few ulps
        assert_allclose(
            as_complex(lp.sampled_poles),
            ref,
            atol=1e-12,
            err_msg=f"{lp.name} sampled poles vs numpy/expm",
        )
        assert lp.pole_mismatch < 1e-12
        assert_allclose(
            lp.sampled_moduli,
            np.sort(np.abs(ref))[::-1],
            atol=1e-12,
            err_msg=f"{lp.name} pole moduli",
        )


@pytest.mark.parametrize("name", list(CONFIGS))
def test_continuous_poles_closed_form(name):
    """Eq. (37): s^2 + a (1 + k2) s + a k1 = 0 (and the PD analogue)."""
    cfg = CONFIGS[name]
    a = cfg.plant.a
    for lp in all_loop_poles(cfg).values():
        k1, k2 = lp.gains
        ref = np.sort_complex(np.roots([1.0, a * (1 + k2), a * k1]).astype(complex))
        assert_allclose(
            as_complex(lp.continuous_poles),
            ref,
            rtol=1e-10,
            err_msg=f"{lp.name} continuous poles vs eq. (37)",
        )
        wn = np.sqrt(a * k1)
        assert_allclose(
            np.prod(lp.continuous_wn), wn**2, rtol=1e-10, err_msg="product of natural frequencies"
        )


@pytest.mark.parametrize("name", list(CONFIGS))
def test_margins(name):
    for lp in all_loop_poles(CONFIGS[name]).values():
        assert lp.stable_continuous and lp.stable_sampled and lp.lyapunov_conditions
        assert_allclose(
            lp.gain_margin,
            lp.gain_margin_eig,
            rtol=1e-9,
            err_msg=f"{lp.name} gain margin vs eigenvalue scaling",
        )
        assert 0 < lp.phase_margin_deg < 180


def test_lyapunov_conditions_do_not_imply_sampled_stability():
    res = lyapunov_counterexample(PAPER)
    for which in ("k1", "k2"):
        loop = res[f"{which}_raised"]["loop"]
        assert loop["lyapunov_conditions"] and loop["stable_continuous"]
        assert not loop["stable_sampled"] and max(loop["sampled_moduli"]) > 1
        assert res[f"{which}_raised"]["growth"] > 1e3
    a, T = PAPER.plant.a, PAPER.plant.sample_time
    k1c = res["k1_critical"]
    rad = np.abs(np.linalg.eigvals(expm_closed_loop(a, T, [k1c, PAPER.pto.k2]))).max()
    assert_allclose(rad, 1.0, atol=1e-9, err_msg="spectral radius at the critical k1")


def test_critical_gain_rejects_unstable_start():
    a, T = PAPER.plant.a, PAPER.plant.sample_time
    with pytest.raises(ValueError):
        critical_gain(a, T, 1e5, 3.6)


def test_loop_poles_json():
    import json

    lp = loop_poles("x", PAPER.plant.a, 0.002, 323.0, 3.6)
    json.dumps(lp.to_json(), allow_nan=True)


@pytest.mark.parametrize("delay", [0, 1, 2, 3])
@pytest.mark.parametrize("gains", [(356.0, 1.15), (323.0, 3.6), (900.0, 0.3)])
def test_delayed_loop_radius_matches_python_control_feedback(delay, gains):
    """Independent reference: python-control's closed loop of L(z) = K (zI - Ad)^-1 Bd z^-delay."""
    import control as ct

    from ptoverify.model.poles import delayed_loop_radius

    a, T = 2 * np.pi * 30, 0.002
    k1, k2 = gains
    A = np.array([[0.0, 1.0], [0.0, -a]])
    B = np.array([[0.0], [a]])
    plant = ct.sample_system(ct.ss(A, B, np.array([[k1, k2]]), [[0.0]]), T, method="zoh")
    lag = ct.tf([1.0], [1.0] + [0.0] * delay, T)
    cl = ct.feedback(ct.series(lag, plant), 1)
    want = float(np.abs(ct.poles(cl)).max())
    got = delayed_loop_radius(a, T, k1, k2, delay)
    np.testing.assert_allclose(got, want, rtol=1e-9, err_msg="spectral radius with delay")


def test_delay_margin_samples_is_the_last_stable_delay():
    from ptoverify.model.poles import delay_margin_samples, delayed_loop_radius

    a, T = 2 * np.pi * 30, 0.002
    for k1, k2 in ((356.0, 1.15), (323.0, 3.6), (50.0, 0.2)):
        n = delay_margin_samples(a, T, k1, k2)
        assert all(delayed_loop_radius(a, T, k1, k2, d) < 1 for d in range(n + 1))
        assert delayed_loop_radius(a, T, k1, k2, n + 1) >= 1 or n == 20
