"""Fast paths equal the general paths, bit for bit, against references written here.

The one-value paths of ``curves`` (Horner on Python floats), the few-value
series, the cache-sized blocks, ``blockwise`` without broadcasting, the laws
with per-state gains and the batched zone scan are only faster: each is checked
to give exactly the floats of an independent evaluation (a plain numpy Horner
rule, per-element calls, one law per configuration, the scalar-omega0 margin).
"""

import dataclasses

import numpy as np
import pytest

from ptoverify.config import PDGains, PTOSettings, paper_config
from ptoverify.model import curves, zones
from ptoverify.model.curves import (
    h,
    level_curve_x1,
    level_residual,
    level_term,
    omega_c,
    root_22,
    switching_function,
)
from ptoverify.model.laws import Region, make_law, pto_law, saturate_linear, with_state_gains

CFG = paper_config()
RNG = np.random.default_rng(2024)


def same(a, b) -> bool:
    """Equal floats, NaN where NaN, the same sign of zero."""
    a, b = np.asarray(a), np.asarray(b)
    return (
        a.shape == b.shape
        and np.array_equal(a, b, equal_nan=True)
        and np.array_equal(np.signbit(a), np.signbit(b))
    )


def horner_reference(x, lowest_power_coefs):
    """sum c_n x^n (n >= 2) by Horner's rule from zero, written out on a numpy array."""
    acc = np.zeros_like(x)
    for c in lowest_power_coefs[::-1]:
        acc = acc * x + c
    return acc * (x * x)


H_COEF = np.array([(-1.0) ** n / n for n in range(2, 26)])
E2_COEF = np.array([1.0 / np.prod(np.arange(1, n + 1, dtype=float)) for n in range(2, 22)])


def h_reference(r):
    with np.errstate(all="ignore"):
        return np.where(np.abs(r) < 0.2, horner_reference(r, H_COEF), r - np.log1p(r))


def e2_reference(u):
    with np.errstate(all="ignore"):
        return np.where(np.abs(u) < 0.5, horner_reference(u, E2_COEF), np.expm1(u) - u)


def near(edge, n=400):
    """Values within a few ulps and within 1e-9 of +-edge, and the edges themselves."""
    ulps = np.nextafter(edge, np.inf) - edge
    base = np.concatenate([edge + ulps * np.arange(-4, 5), edge + RNG.uniform(-1e-9, 1e-9, n)])
    return np.concatenate([base, -base])


R_VALUES = np.concatenate(
    [
        near(0.2),
        RNG.uniform(-0.999, 4.0, 3000),
        10.0 ** RNG.uniform(-150, 3, 1000),
        -(10.0 ** RNG.uniform(-150, -0.01, 500)),
        [0.0, -0.0, -1.0, np.inf, np.nan],
    ]
)
U_VALUES = np.concatenate(
    [near(0.5), RNG.uniform(-5, 5, 3000), 10.0 ** RNG.uniform(-200, 0, 500), [0.0, -0.0, np.nan]]
)


def test_h_every_path_is_the_reference():
    ref = h_reference(R_VALUES)
    assert same(h(R_VALUES), ref), "array path"
    assert same([float(h(v)) for v in R_VALUES], ref), "one-value path"
    # few series values in an array (summed one by one) and many (numpy passes)
    for idx in np.array_split(np.arange(R_VALUES.size), 700):
        assert same(h(R_VALUES[idx]), ref[idx]), "few-value path"
    big = np.resize(R_VALUES, 17 * 2500)  # > 2 BLOCK
    assert same(h(big), h_reference(big)), "cache-sized blocks"
    assert same(h(big.reshape(-1, 17)), h_reference(big).reshape(-1, 17)), "2-D input"


def test_e2_every_path_is_the_reference():
    ref = e2_reference(U_VALUES)
    assert same(curves._e2(U_VALUES), ref)
    assert same([float(curves._e2(v)) for v in U_VALUES], ref)
    for idx in np.array_split(np.arange(U_VALUES.size), 500):
        assert same(curves._e2(U_VALUES[idx]), ref[idx])


def test_level_residual_paths_agree():
    n = 3 * curves.BLOCK + 5
    x1 = RNG.uniform(-50, 50, n) * RNG.choice([1.0, 1e-3, 0.0], n)
    x2 = RNG.uniform(-300, 300, n) * RNG.choice([1.0, 1e-3, 1e-9, 0.0, -0.0], n)
    a, w = CFG.plant.a, CFG.plant.w_max
    with np.errstate(all="ignore"):
        ref = a * x1 + np.sign(x2) * w * h_reference(np.abs(x2) / w)
    assert same(level_residual(x1, x2, a, w), ref), "blocks"
    assert same(level_residual(x1[:999], x2[:999], a, w), ref[:999]), "one block"
    assert same(
        [float(level_residual(p, q, a, w)) for p, q in zip(x1[:2000], x2[:2000])], ref[:2000]
    )
    om = RNG.uniform(1.0, 300.0, n)
    with np.errstate(all="ignore"):
        ref_om = a * x1 + np.sign(x2) * om * h_reference(np.abs(x2) / om)
    assert same(level_residual(x1, x2, a, om), ref_om), "per-element omega"
    assert same(a * x1 + level_term(x2, om), ref_om)
    assert same(switching_function(x1, x2, a, w), ref)
    assert same(level_curve_x1(x2[:500], a, w), [float(level_curve_x1(v, a, w)) for v in x2[:500]])


def test_blockwise_fast_path_is_the_general_path():
    x1, x2 = RNG.uniform(-5, 5, 3000), RNG.uniform(-300, 300, 3000)

    def fn(p, q):
        return p * q + p, np.abs(p) < q

    fast = curves.blockwise(fn, x1, x2)
    strided = curves.blockwise(fn, np.repeat(x1, 2)[::2], np.repeat(x2, 2)[::2])
    general = curves.blockwise(fn, x1.reshape(60, 50), x2.reshape(60, 50))
    for a, b, c in zip(fast, strided, general, strict=True):
        assert same(a, b) and same(a, c.ravel())


@pytest.mark.parametrize("branch", [-1, 0])
def test_root_22_one_value_is_the_array_path(branch):
    b0 = np.concatenate(
        [
            RNG.uniform(0, 30, 1500),
            10.0 ** RNG.uniform(-300, 300, 1500),
            [0.0, -0.0, -1.0, np.nan, np.inf, 1e300, 745.0, 709.5, 800.0],
            np.nextafter(1e-3, [0.0, 1.0]),
            np.nextafter(20.0, [0.0, 30.0]),
        ]
    )
    with np.errstate(all="ignore"):
        arr = root_22(b0, branch)
        assert same([float(root_22(v, branch)) for v in b0], arr)


# ---------------------------------------------------------------- laws
def states(n, d):
    """States across every branch: near the origin, at |x1| = d, near l1/l1*, beyond w_max."""
    w, a = CFG.plant.w_max, CFG.plant.a
    x2 = RNG.uniform(-1.1 * w, 1.1 * w, n) * RNG.choice([1.0, 1e-2, 1e-6], n)
    x1 = RNG.uniform(-40, 40, n) * RNG.choice([1.0, 0.05, 1e-4], n)
    k = n // 4  # a quarter on or just right of the switching curve (zone candidates)
    x1[:k] = level_curve_x1(x2[:k], a, w) + RNG.uniform(0, 3, k) * np.abs(x2[:k]) / a
    x1[k : k + n // 10] = RNG.choice([d, -d, np.nextafter(d, 0.0)], n // 10)
    x1[-3:], x2[-3:] = 0.0, 0.0
    return x1, x2


def test_per_state_gains_are_each_configurations_law():
    n = 2500
    ds = RNG.choice([0.2, 0.5, 1.0, 1.7, 3.0, 5.0], n)
    k1, k2 = 10 ** RNG.uniform(1, 3.5, n), RNG.uniform(0, 10, n)
    x1, x2 = states(n, 1.0)
    u, r = with_state_gains("pto", CFG, {"k1": k1, "k2": k2, "d": ds})(x1, x2)
    for i in range(n):
        c = dataclasses.replace(
            CFG, pto=PTOSettings(d=float(ds[i]), k1=float(k1[i]), k2=float(k2[i]))
        )
        ui, ri = make_law("pto", c)(x1[i : i + 1], x2[i : i + 1])
        assert (ui[0], ri[0]) == (u[i], r[i]), (i, ds[i], x1[i], x2[i])
    assert {Region.ZONE_P, Region.ZONE_N, Region.LINEAR, Region.BANG_P} <= set(r.tolist())
    kp, kd = 10 ** RNG.uniform(1, 3.5, n), RNG.uniform(0, 4, n)
    u, r = with_state_gains("pd", CFG, {"kp": kp, "kd": kd})(x1, x2)
    for i in range(0, n, 7):
        c = dataclasses.replace(CFG, pd=PDGains(kp=float(kp[i]), kd=float(kd[i])))
        assert make_law("pd", c).scalar(float(x1[i]), float(x2[i])) == (u[i], r[i])
    with pytest.raises(TypeError):
        with_state_gains("pd", CFG, {"kp": kp, "kd": kd}).scalar(1.0, 0.0)


def test_pto_vector_path_without_masks_is_the_masked_path():
    law = make_law("pto", CFG)
    x1, x2 = states(4000, CFG.pto.d)
    u, r = law(x1, x2)
    inside = np.abs(x1) < CFG.pto.d  # evaluated alone: every state linear, no masks
    ui, ri = law(x1[inside], x2[inside])
    assert same(ui, u[inside]) and np.array_equal(ri, r[inside])
    for i in range(0, 4000, 11):  # one by one: the masks of a mixed array vs none
        uo, ro = law(x1[i : i + 1], x2[i : i + 1])
        assert same(uo, u[i : i + 1]) and ro[0] == r[i]


def test_saturate_linear_is_clip():
    v = np.concatenate([RNG.uniform(-900, 900, 1000), [300.0, -300.0, 0.0, -0.0, np.nan]])
    u, r = saturate_linear(v, 300.0)
    assert same(u, np.clip(v, -300.0, 300.0)) and r.dtype == np.int8
    with np.errstate(invalid="ignore"):
        assert np.array_equal(r, np.where(np.abs(v) > 300.0, Region.SATURATED, Region.LINEAR))


def test_pto_without_zone_per_state_level_nan():
    n = 500
    x1, x2 = states(n, 0.3)
    k1, k2 = np.full(n, 80.0), np.full(n, 1.2)
    c = dataclasses.replace(CFG, pto=PTOSettings(d=0.3, k1=80.0, k2=1.2))
    lv = np.full(n, np.nan)  # no zone anywhere: the law without its switching zone
    u, r = pto_law(c, None, gains=(k1, k2, np.full(n, 0.3), lv))(x1, x2)
    ur, rr = pto_law(c, None)(x1, x2)
    assert same(u, ur) and np.array_equal(r, rr)


# ---------------------------------------------------------------- zones
def worst_margin_reference(cfg, omega0, reading, d):
    """The dense worst margin, one omega0 at a time through the scalar-omega0 margin."""
    w = cfg.plant.w_max
    x2 = np.linspace(-w, w, 4001)
    m = zones.principle_margin(cfg, omega0, x2, reading=reading, d=d)
    step = x2[1] - x2[0]
    loc = np.flatnonzero((m[1:-1] <= m[:-2]) & (m[1:-1] <= m[2:])) + 1
    loc = loc[np.argsort(m[loc])[:8]]
    a = cfg.plant.a
    kinks = []
    if 0 < omega0 < w:
        kinks.append(-omega0 * float(root_22(a * d / omega0)))
    elif omega0 <= 0:
        kinks.append(-a * d)
    kinks.append(w * float(root_22(a * d / w)))
    extra = [np.array([v for v in kinks if -w <= v <= w])]
    extra += [np.linspace(x2[i] - step, x2[i] + step, 201) for i in loc]
    fine = np.clip(np.concatenate(extra), -w, w)
    if not fine.size:
        return float(m.min())
    pm = zones.principle_margin(cfg, omega0, fine, reading=reading, d=d)
    return float(min(m.min(), pm.min()))


@pytest.mark.parametrize("reading", ["strict", "lenient"])
def test_batched_worst_margin_is_one_at_a_time(reading):
    w = CFG.plant.w_max
    for cfg, d in ((CFG, 1.0), (CFG.with_plant(a=30.0), 0.37), (CFG, 3.3)):
        om = np.concatenate([[0.0, 1e-3, w, 1.5 * w], RNG.uniform(0, w, 12)])
        got = zones._worst_margins(cfg, om, reading, d)
        ref = [worst_margin_reference(cfg, float(o), reading, d) for o in om]
        assert same(got, ref), (cfg.name, d)
        # below: a value under the threshold stays under it (the feasibility answer)
        cut = float(np.median(ref))
        fast = zones._worst_margins(cfg, om, reading, d, below=cut)
        assert [f >= cut for f in fast] == [r >= cut for r in ref]


def test_principle_margin_broadcast_rows_are_scalar_calls():
    w = CFG.plant.w_max
    x2 = np.concatenate([RNG.uniform(-w, w, 700), [0.0, -w, w]])
    om = np.array([0.0, 0.2 * w, 0.7 * w, w, 2.0 * w])
    for reading in ("strict", "lenient"):
        rows = zones.principle_margin(CFG, om[:, None], x2, reading=reading)
        for k, o in enumerate(om):
            assert same(rows[k], zones.principle_margin(CFG, float(o), x2, reading=reading))
        pair = zones.principle_margin(CFG, np.resize(om, x2.size), x2, reading=reading)
        want = [
            zones.principle_margin(CFG, float(o), x2[i : i + 1], reading=reading)[0]
            for i, o in enumerate(np.resize(om, x2.size))
        ]
        assert same(pair, want)


@pytest.mark.parametrize("reading", ["strict", "lenient"])
def test_principle_margin_rows_on_a_sorted_grid_are_scalar_calls(reading):
    """On ascending velocities the rows skip l1* where it provably lies inside |x1| < d
    (_beyond_d); every row is still the scalar-omega0 margin bit for bit."""
    for plant_cfg in (CFG, CFG.with_plant(a=30.0)):
        w, a = plant_cfg.plant.w_max, plant_cfg.plant.a
        x2 = np.linspace(-w, w, 801)
        om = np.concatenate([[0.0, -1.0, np.nan, 1e-6 * w, w, 2.0 * w], RNG.uniform(0, w, 10)])
        for d in (0.0, 0.2, 0.5, 1.0, 2.5, 6.0):
            rows = zones.principle_margin(plant_cfg, om[:, None], x2, reading=reading, d=d)
            for k, o in enumerate(om):
                want = zones.principle_margin(plant_cfg, float(o), x2, reading=reading, d=d)
                assert same(rows[k], want), (a, d, o)
    # the skip is taken, and where it is, l1* is inside the linear zone (computed directly)
    w, a, d = CFG.plant.w_max, CFG.plant.a, 0.5
    xn = np.linspace(-w, 0.0, 4001)[:-1]
    om = np.geomspace(1e-6 * w, w, 400)
    reach = zones._beyond_d(xn, om, a, d)
    assert reach.min() < xn.size // 2 and reach.max() > 0
    skipped = np.arange(xn.size)[None, :] >= reach[:, None]
    assert (level_curve_x1(xn[None, :], a, om[:, None])[skipped] < d).all()


def test_smallest_d_depends_on_the_plant_only():
    base = zones.smallest_d(CFG)
    zones.clear_caches()
    other = dataclasses.replace(CFG, pto=PTOSettings(d=3.7, k1=10.0, k2=0.1))
    assert zones.smallest_d(other) == base


def test_omega_c_small_arrays_are_the_large_array():
    x2 = -RNG.uniform(1, 600, 4000)
    x1 = RNG.uniform(0.001, 0.999, 4000) * (-x2) / CFG.plant.a
    big = omega_c(x1, x2, CFG.plant.a)
    assert same(
        np.concatenate(
            [omega_c(x1[i : i + 3], x2[i : i + 3], CFG.plant.a) for i in range(0, 4000, 3)]
        ),
        big,
    )


def feasible_intervals_reference(cfg, reading, scan=200):
    """Scan and one-midpoint-at-a-time bisection of the feasible omega0 (the plain algorithm)."""
    w, tol = cfg.plant.w_max, zones._tol(cfg)
    grid = np.unique(
        np.concatenate([np.geomspace(1e-4 * w, w, scan // 2), np.linspace(w / scan, w, scan // 2)])
    )

    def ok(om):
        return worst_margin_reference(cfg, float(om), reading, cfg.pto.d) >= -tol

    good_at = [ok(om) for om in grid]

    def edge(good, bad):
        for _ in range(60):
            mid = 0.5 * (good + bad)
            good, bad = (mid, bad) if ok(mid) else (good, mid)
            if abs(good - bad) <= 1e-10 * w:
                break
        return good

    out, i = [], 0
    while i < len(grid):
        if not good_at[i]:
            i += 1
            continue
        j = i
        while j + 1 < len(grid) and good_at[j + 1]:
            j += 1
        lo = 0.0 if i == 0 else edge(float(grid[i]), float(grid[i - 1]))
        hi = w if j == len(grid) - 1 else edge(float(grid[j]), float(grid[j + 1]))
        out.append((lo, hi))
        i = j + 1
    return out


@pytest.mark.parametrize("reading", ["strict", "lenient"])
def test_feasible_intervals_are_the_plain_scan_and_bisection(reading):
    # the coarse pre-screen and the batched bisection give the plain algorithm's floats
    for cfg in (CFG, dataclasses.replace(CFG, pto=PTOSettings(d=3.7, k1=10.0, k2=0.1))):
        zones.clear_caches()
        got = list(zones.corrected_zone(cfg, reading=reading, verify=False).feasible_intervals)
        assert got == feasible_intervals_reference(cfg, reading), (cfg.pto.d, reading)
