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


@pytest.mark.parametrize("band", [0.0, 5.3e-6, 1e-2])
@pytest.mark.parametrize("per_state", [True, False])
def test_level_side_compares_as_the_residual(band, per_state):
    """level_side: the sum's sign, zero and comparisons with +-band, and the sum near the curve."""
    from ptoverify.model.curves import level_side, level_term

    rng = np.random.default_rng(7)
    n = 200_000
    omega = 10.0 ** rng.uniform(0.0, 3.0, n) if per_state else 300.0
    x2 = omega * rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-12.0, 0.5, n)
    term = level_term(x2, omega)
    # a x1 near -term (on the curve, within a few ulps to a few bands), anywhere, 0, NaN
    ax1 = -term * (1.0 + rng.choice([0.0, 1e-16, -1e-16, 1e-9, 1e-6, 1e-3, 1.0], n))
    ax1 += rng.choice([0.0, band, -band, 2 * band, -2 * band, 3 * band], n)
    ax1[::97] = rng.uniform(-1e3, 1e3, ax1[::97].size)
    ax1[::101], x2[::103] = 0.0, 0.0
    ax1[::211], x2[::223] = np.nan, np.nan
    full = ax1 + level_term(x2, omega)
    got = level_side(ax1, x2, omega, band)
    for cmp in (np.sign(got) == np.sign(full), (got == 0) == (full == 0)):
        assert (cmp | np.isnan(full)).all()
    assert ((got < -band) == (full < -band)).all() and ((got > band) == (full > band)).all()
    assert (np.isnan(got) == np.isnan(full)).all()
    # a x1 itself or the sum, and the sum bit for bit in the close calls
    assert ((got == ax1) | (got == full) | np.isnan(full)).all()
    close = (ax1 * x2 <= 0) & (np.abs(full) <= 1e-9 * np.abs(term) + band)
    assert close.sum() > 1000 and np.array_equal(got[close], full[close])
    assert (got != full).sum() > n // 4  # the shortcut is taken
    om = omega[:5000] if per_state else omega  # elementwise: a part gives the same
    assert np.array_equal(level_side(ax1[:5000], x2[:5000], om, band), got[:5000], equal_nan=True)


def test_h_few_series_values_as_many():
    """h's series in Python floats (few values) equals its numpy passes (many), bit for bit."""
    from ptoverify.model.curves import FEW

    rng = np.random.default_rng(11)
    n = 64 * FEW
    r = np.concatenate([rng.uniform(-0.199, 0.199, n), rng.uniform(0.2, 5.0, 500)])
    many = h(r)  # hundreds of series values: numpy passes
    for start in range(0, n, FEW):  # FEW series values at a time, with the rest
        got = h(np.concatenate([r[start : start + FEW], r[n:]]))
        assert np.array_equal(got, np.concatenate([many[start : start + FEW], many[n:]]))


@pytest.mark.parametrize("n", [10, 100, 3000])
def test_level_side_at_infinite_velocity_is_the_sum(n):
    """At x2 = +-inf the sum is NaN (the term is inf - inf): level_side gives it for any
    batch size, so a law's vector path answers as in batches of a few states and as its
    scalar path there."""
    from ptoverify.config import paper_config
    from ptoverify.model.curves import level_side, level_term
    from ptoverify.model.laws import make_law

    rng = np.random.default_rng(3)
    x2 = rng.uniform(-300.0, 300.0, n)
    x2[::3] = np.inf
    x2[1::3] = -np.inf
    ax1 = np.where(rng.random(n) < 0.5, -1.0, 1.0) * rng.uniform(1.0, 100.0, n)
    with np.errstate(invalid="ignore"):
        full = ax1 + level_term(x2, 300.0)
        got = level_side(ax1, x2, 300.0)
    assert np.isnan(full[~np.isfinite(x2)]).all()
    assert np.array_equal(np.isnan(got), np.isnan(full))
    cfg = paper_config()
    x1 = ax1 / cfg.plant.a
    for name in ("to", "pto"):
        law = make_law(name, cfg)
        with np.errstate(invalid="ignore"):
            u, r = law.vector(x1, x2)
            few = [law.vector(x1[i : i + 10], x2[i : i + 10]) for i in range(0, n, 10)]
        assert np.array_equal(u, np.concatenate([f[0] for f in few]))
        assert np.array_equal(r, np.concatenate([f[1] for f in few]))
        inf = np.flatnonzero(~np.isfinite(x2))
        want = [law.scalar(float(x1[i]), float(x2[i])) for i in inf]
        assert u[inf].tolist() == [w for w, _ in want] and r[inf].tolist() == [c for _, c in want]
