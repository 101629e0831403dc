import mpmath
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from ptoverify.model.curves import (
    h,
    level_curve_x1,
    level_residual,
    omega_c,
    root_22,
    root_22_bisect,
    root_k,
    root_k_bisect,
    switching_function,
)
from ptoverify.model.plant import flow


def test_h_against_mpmath():
    r = np.concatenate([10 ** np.linspace(-150, 3, 400), -(10 ** np.linspace(-150, -1e-3, 300))])
    # below ~1e-154, h = r^2/2 underflows: not an admissible range
    with mpmath.workdps(400):  # r - ln(1 + r) cancels ~2 log10(1/r) digits
        ref = np.array([float(mpmath.mpf(x) - mpmath.log1p(mpmath.mpf(x))) for x in r])
    # h is evaluated by a series or by r - log1p(r); both within a few ulps of the value
    assert_allclose(h(r), ref, rtol=4e-15, atol=0, err_msg="h(r) = r - ln(1 + r)")


@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_state_on_curve_rides_it_to_origin(any_cfg, sign):
    """A state on l1 (l2) under +w_max (-w_max) stays on it and reaches the origin in time."""
    p = any_cfg.plant
    w = p.w_max
    for s in np.linspace(0.05, 2.0, 9) * w:
        x2 = -sign * s
        x1 = float(level_curve_x1(x2, p.a, w))
        u = sign * w
        t_hit = np.log1p(s / w) / p.a  # x2(t) = u + (x2 - u) e^{-at} = 0
        ts = np.linspace(0, t_hit, 7)
        y1, y2 = flow(x1, x2, u, ts, p.a)
        scale = p.a * abs(x1) + s
        assert np.abs(level_residual(y1, y2, p.a, w)).max() < 1e-13 * scale, "left the curve"
        assert_allclose(
            [y1[-1], y2[-1]],
            [0, 0],
            atol=1e-12 * (abs(x1) + s),
            err_msg="end of the curve is not the origin",
        )


def test_root_22_against_bisection():
    rng = np.random.default_rng(3)
    b0 = np.concatenate(
        [rng.uniform(0, 20, 5000), 10 ** rng.uniform(-14, 4, 5000), [1e-300, 1e-15, 1.0, 1e300]]
    )
    y, yb = root_22(b0), root_22_bisect(b0)
    # bisection to the last bit; the closed form is Newton-polished: a few ulps
    assert_allclose(y, yb, rtol=2e-15, err_msg="eq. (22) positive root, Lambert W vs bisection")
    assert np.all(y > 0)


def test_root_22_negative_branch_satisfies_equation():
    b0 = 10 ** np.linspace(-10, 0.5, 200)  # beyond, 1 + y = O(e^{-1-b0}) is below round-off
    y = root_22(b0, branch=0)
    assert np.all((y > -1) & (y < 0))
    assert_allclose(h(y), b0, rtol=1e-13, err_msg="eq. (22) root in (-1, 0)")


def test_root_k_against_bisection():
    rng = np.random.default_rng(4)
    m = np.concatenate(
        [
            rng.uniform(0, 1, 4000),
            10 ** rng.uniform(-15, 0, 3000),
            1 - 10 ** rng.uniform(-12, -0.5, 2000),
            -(10 ** rng.uniform(-15, 3, 2000)),
            [1e-100, -1e-100],
        ]
    )
    m = m[(m != 0) & (m < 1)]
    z, zb = root_k(m), root_k_bisect(m)
    # conditioning of z in m is ~1/(k |ln k|) near k -> 0: allow 1e-13 there, ulps elsewhere
    k = 1 - m
    rtol = np.where(k < 1e-3, 1e-12, 4e-15)
    assert np.all(np.abs(z - zb) <= rtol * np.abs(zb)), "eqs. (26)/(31) root vs bisection"
    assert np.all(np.sign(z) == np.sign(m))


def test_root_k_edges():
    assert root_k(0.0) == 0.0
    assert np.isnan(root_k(1.0)) and np.isnan(root_k(2.0)) and np.isnan(root_k(np.nan))
    # k -> 1: tiny root z ~ 2 m (series of ln(1+z) = (1-m) z)
    assert_allclose(root_k(1e-200), 2e-200, rtol=1e-15, err_msg="tiny root")


def test_omega_c_solves_eq_28(any_cfg):
    p = any_cfg.plant
    rng = np.random.default_rng(5)
    x2 = -rng.uniform(1, 2 * p.w_max, 2000)
    x1 = rng.uniform(0.001, 0.999, 2000) * (-x2) / p.a  # 0 < m < 1
    wc = omega_c(x1, x2, p.a)
    for i in range(0, 2000, 97):
        ref = brentq(
            lambda om: p.a * x1[i] + x2[i] + om * np.log1p(-x2[i] / om),
            1e-9,
            1e12,
            xtol=1e-14,
            rtol=1e-15,
            maxiter=500,
        )
        assert_allclose(wc[i], ref, rtol=1e-11, err_msg="omega_c vs brentq on eq. (28)")
    assert_allclose(omega_c(-x1, -x2, p.a), wc, rtol=0, err_msg="mirror (eq. 33)")


def test_switching_function_sign_convention(paper_cfg):
    p = paper_cfg.plant
    assert switching_function(1.0, 0.0, p.a, p.w_max) > 0  # right: u = -w_max
    assert switching_function(-1.0, 0.0, p.a, p.w_max) < 0
    x2 = -100.0
    x1 = level_curve_x1(x2, p.a, p.w_max)
    assert abs(switching_function(x1, x2, p.a, p.w_max)) < 1e-12


def test_root_k_against_scipy_lambertw():
    """Our W_{-1} iteration against scipy's Lambert W, away from the branch point."""
    from scipy.special import lambertw

    m = np.linspace(0.01, 0.99, 500)
    k = 1 - m
    ref = -1 - np.real(lambertw(-k * np.exp(-k), -1)) / k
    assert_allclose(root_k(m), ref, rtol=1e-12, err_msg="z = -1 - W_{-1}(-k e^{-k}) / k")


def test_h_and_e2_at_random_points_against_mpmath():
    """h (series |r| < 0.2, else r - log1p r) and e^u - 1 - u (series |u| < 0.5) at random
    points on both sides of each switch-over, in 60 digits: within a few ulps."""
    from ptoverify.model.curves import _e2

    rng = np.random.default_rng(21)
    r = np.concatenate(
        [rng.uniform(-0.99, 3.0, 3000), 0.2 + rng.uniform(-1e-3, 1e-3, 500), [0.2, -0.2]]
    )
    u = np.concatenate([rng.uniform(-6.0, 6.0, 3000), 0.5 + rng.uniform(-1e-3, 1e-3, 500)])
    with mpmath.workdps(60):
        h_ref = np.array([float(mpmath.mpf(x) - mpmath.log1p(mpmath.mpf(x))) for x in r])
        e2_ref = np.array([float(mpmath.expm1(mpmath.mpf(x)) - mpmath.mpf(x)) for x in u])
    # r - log1p(r) for |r| >= 0.2 loses at most ~3 bits to cancellation (h >= 0.017 r)
    assert_allclose(h(r), h_ref, rtol=4e-15, atol=0, err_msg="h(r) at random points")
    assert_allclose(_e2(u), e2_ref, rtol=4e-15, atol=0, err_msg="e^u - 1 - u at random points")


def test_h_is_elementwise_for_any_shape_and_batch():
    """One evaluation: an element's h does not depend on its batch (sizes 1..5000, 0-d, 2-D)."""
    rng = np.random.default_rng(8)
    r = np.concatenate([rng.uniform(-0.3, 0.3, 4000), rng.uniform(-0.99, 5.0, 1000)])
    rng.shuffle(r)
    whole = h(r)
    assert [float(h(v)) for v in r[:500]] == whole[:500].tolist()
    for size in (1, 2, 63, 64, 65, 1000, 5000):
        parts = np.concatenate([h(r[i : i + size]) for i in range(0, r.size, size)])
        assert np.array_equal(parts, whole), f"batches of {size}"
    assert np.array_equal(h(r.reshape(50, 100)), whole.reshape(50, 100))


def test_level_side_is_the_residual():
    """level_side(a x1, x2, omega) is a x1 + level_term(x2, omega) for every state, the
    infinite velocities (+-inf: the side of x2) and any batch size included."""
    from ptoverify.model.curves import level_side, level_term

    rng = np.random.default_rng(7)
    n = 5000
    omega = 10.0 ** rng.uniform(0.0, 3.0, n)
    x2 = omega * rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-12.0, 0.5, n)
    x2[::7], x2[1::7], x2[2::7] = np.inf, -np.inf, -0.0
    ax1 = rng.uniform(-1e3, 1e3, n)
    with np.errstate(invalid="ignore"):
        full = ax1 + level_term(x2, omega)
        for band in (0.0, 1e-2):
            assert np.array_equal(level_side(ax1, x2, omega, band), full, equal_nan=True)
        assert (full[::7] == np.inf).all() and (full[1::7] == -np.inf).all()  # x2's side
        for size in (1, 63, 64, 65):
            got = [
                level_side(ax1[i : i + size], x2[i : i + size], omega[i : i + size])
                for i in range(0, 650, size)
            ]
            assert np.array_equal(np.concatenate(got)[:650], full[:650], equal_nan=True)


def test_level_curve_x1_against_mpmath(paper_cfg):
    """x1 on l1 / l2 (eqs. 9, 11) at random velocities: a x1 = -x2 -+ w ln(1 -+ x2/w), 50 digits."""
    p = paper_cfg.plant
    rng = np.random.default_rng(12)
    x2 = rng.uniform(-1.0, 1.0, 400) * p.w_max * 10.0 ** rng.uniform(-6, 0, 400)
    with mpmath.workdps(50):
        ref = []
        for v in x2:
            vm, s = mpmath.mpf(v), -mpmath.sign(v)
            ref.append(float((-vm - s * p.w_max * mpmath.log(1 - s * vm / p.w_max)) / p.a))
    assert_allclose(level_curve_x1(x2, p.a, p.w_max), ref, rtol=4e-15, atol=0, err_msg="l1, l2")


def test_root_22_against_mpmath_and_batch_independent():
    """Eq. (22) roots at random b0 against mpmath's Lambert W (50 digits); a root does not
    depend on its batch (0-d, sizes 1, 64, whole) or branch-point series range."""
    rng = np.random.default_rng(14)
    b0 = np.concatenate(
        [10.0 ** rng.uniform(-8, 3, 300), [1e-3, np.nextafter(1e-3, 0), 20.0, 21.0]]
    )
    y = root_22(b0)
    with mpmath.workdps(50):
        ref = [float(-1 - mpmath.lambertw(-mpmath.exp(-1 - mpmath.mpf(b)), -1)) for b in b0]
    assert_allclose(y, ref, rtol=4e-15, err_msg="eq. (22) root vs mpmath Lambert W_{-1}")
    assert [float(root_22(b)) for b in b0] == y.tolist()
    assert np.array_equal(
        np.concatenate([root_22(b0[i : i + 64]) for i in range(0, b0.size, 64)]), y
    )
    assert np.isnan(root_22([-1.0, np.nan, np.inf])).all() and root_22(0.0) == 0.0


def test_omega_c_is_elementwise_for_any_batch():
    rng = np.random.default_rng(2024)
    a = 188.5
    x2 = -rng.uniform(1, 600, 4000)
    x1 = rng.uniform(0.001, 0.999, 4000) * (-x2) / a
    x1[:8], x2[:8] = (
        [0.0, 1.0, -1.0, 0.0, 1.0, 5.0, -5.0, 0.0],
        [0.0, 0.0, 1.0, 1.0, 1.0, -1.0, -1.0, -0.0],
    )
    with np.errstate(all="ignore"):
        big = omega_c(x1, x2, a)
        for size in (1, 3, 64, 65):
            parts = [omega_c(x1[i : i + size], x2[i : i + size], a) for i in range(0, 4000, size)]
            assert np.array_equal(np.concatenate(parts), big, equal_nan=True), size
    assert np.isnan(big[0]) and big[1] == big[2] == 0.0 and big[4] == np.inf  # eq. (32) limits
