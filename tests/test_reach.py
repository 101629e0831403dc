"""N* by zonotope membership against its independent reference, the LP search.

The LP (``discrete_min_steps``: HiGHS feasibility per N, the sequence verified
by simulating the exact plant) shares nothing with ``reach.py`` but the
closed-form t_f* it starts from, and the zonotope search does not rely on that
(it tests n0 - 1).  Boundary states are built by integrating the exact flow
backwards from the origin under a bang-bang sequence with one switch (a vertex
of the N-step set) or with one fractional input (a point on an edge), so they
do not use the zonotope's formulas either.  The N-step set is convex and
contains the origin, so scaling such a state by 1 + eps moves it out and
1 - eps moves it in; eps = 1e-6 is far beyond the zonotope's margin (1e-9)
and the LP's feasibility tolerance (1e-7).
"""

import math

import numpy as np
import pytest

from ptoverify.config import Plant, paper_config
from ptoverify.errors import InputError
from ptoverify.model.mintime import ZOHReach, discrete_min_steps, discrete_min_steps_batch
from ptoverify.model.plant import flow
from ptoverify.model.reach import MARGIN, ZonotopeTable, zonotope_steps_each

PLANTS = {  # a T = 0.015, 0.377, 4
    "small-aT": Plant(a=30.0, w_max=300.0, sample_time=0.0005, position_range=20.0),
    "paper": paper_config().plant,
    "large-aT": Plant(a=2000.0, w_max=300.0, sample_time=0.002, position_range=50.0),
}
EPS = 1e-6


def random_states(plant: Plant, n_env: int, n_far: int, seed: int) -> tuple[np.ndarray, ...]:
    """n_env states in the envelope, n_far up to 10 x its position and 3 x w_max."""
    rng = np.random.default_rng(seed)
    x1 = rng.uniform(-1.0, 1.0, n_env + n_far) * plant.position_range
    x2 = rng.uniform(-1.0, 1.0, n_env + n_far) * plant.w_max
    x1[n_env:] *= 10.0
    x2[n_env:] *= 3.0
    return x1, x2


def lp_steps(x1, x2, plant: Plant) -> np.ndarray:
    reach = ZOHReach(plant)
    out = []
    for a, b in zip(x1, x2, strict=True):
        d = discrete_min_steps(float(a), float(b), plant, reach=reach)
        assert d.status == "optimal", (a, b, d.status)
        out.append(d.steps)
    return np.array(out)


def assert_agree(x1, x2, plant: Plant) -> np.ndarray:
    zono = discrete_min_steps_batch(x1, x2, plant)
    lp = lp_steps(x1, x2, plant)
    bad = np.flatnonzero(zono.steps != lp)
    assert bad.size == 0, [(x1[i], x2[i], int(zono.steps[i]), int(lp[i])) for i in bad[:5]]
    assert not zono.below_bound.any(), "N* T >= t_f* away from boundaries"
    return lp


@pytest.mark.parametrize("name", PLANTS)
def test_agrees_with_lp_random_fast(name):
    plant = PLANTS[name]
    x1, x2 = random_states(plant, 12, 4, seed=5)
    lp = assert_agree(x1, x2, plant)
    assert lp.max() >= 20


def assert_lp_confirms(x1, x2, plant: Plant) -> np.ndarray:
    """The LP at the zonotope's N* and N* - 1 only: feasible at N*, infeasible below.

    Feasibility is monotone in N (u = 0 holds the origin), so this is the LP's
    N* without its search: two HiGHS solves per state instead of the search's
    three to eight.  The LP's sequence at N* solves A u = b to round-off
    (``ZOHReach.feasible`` rejects one that does not).
    """
    zono = discrete_min_steps_batch(x1, x2, plant)
    reach = ZOHReach(plant)
    bad = []
    for a, b, n in zip(x1, x2, zono.steps, strict=True):
        at, _, st_at = reach.feasible(float(a), float(b), int(n))
        below, _, st_below = (
            reach.feasible(float(a), float(b), int(n) - 1)
            if n > 1
            else (
                False,
                None,
                "no sample: only the origin is at the origin",
            )
        )
        if not at or below:
            bad.append((a, b, int(n), st_at, st_below))
    assert not bad, bad[:5]
    assert not zono.below_bound.any(), "N* T >= t_f* away from boundaries"
    return zono.steps


def every_n_star(plant: Plant, n_far: int, seed: int) -> tuple[np.ndarray, ...]:
    """One state for every N* that 20,000 seeded envelope states take, and ``n_far`` of 2,000
    far states, spread evenly over the far states' N* (their N* ranked, both ends kept)."""
    x1, x2 = random_states(plant, 20_000, 2_000, seed)
    steps = discrete_min_steps_batch(x1, x2, plant).steps
    env = np.unique(steps[:20_000], return_index=True)[1]
    far_n, far = np.unique(steps[20_000:], return_index=True)
    far = 20_000 + far[np.unique(np.linspace(0, far.size - 1, n_far).round().astype(int))]
    pick = np.concatenate([env, far])
    return x1[pick], x2[pick], env.size


@pytest.mark.slow
def test_agrees_with_lp_on_every_n_star():
    """Zero disagreements on one state per N* of the envelope and 100 far states per plant.

    The zonotope's test differs from one N* to the next only by where the state falls in
    the one table (the segment k); so the states cover every N* the envelope takes (281,
    89 and 84 values on the three plants; 500 uniform states took 222, 87 and 83) and the
    far N* range evenly (up to 1,622, 844 and 835 samples).  754 states instead of the
    2,100 uniform ones before.  States within round-off of a boundary, where the two
    methods' tolerances differ, are the boundary tests' (below).
    """
    far_n = []
    for k, (name, plant) in enumerate(PLANTS.items()):
        x1, x2, n_env = every_n_star(plant, 100, seed=100 + k)
        steps = assert_lp_confirms(x1, x2, plant)
        assert np.unique(steps[:n_env]).size == n_env  # one state per N*
        far_n.append((name, int(steps[n_env:].max())))
    assert all(n >= 800 for _, n in far_n), f"far states reach N in the hundreds: {far_n}"


def boundary_state(plant: Plant, n: int, switch: int, sign: float, frac: float | None):
    """State from which n samples of u_k (bang-bang, one switch) reach the origin.

    Inputs: sign * w_max for k < switch, -sign * w_max after; with ``frac`` the
    input at k = switch is frac * w_max (a point on an edge of the n-step set).
    Built by the exact flow backwards in time from the origin.
    """
    u = np.where(np.arange(n) < switch, sign, -sign) * plant.w_max
    if frac is not None:
        u[switch] = frac * plant.w_max
    x1, x2 = 0.0, 0.0
    for uk in u[::-1]:
        x1, x2 = flow(x1, x2, uk, -plant.sample_time, plant.a)
    return float(x1), float(x2)


def boundary_cases(plant: Plant, count: int, seed: int):
    """Vertex and edge states of n-step sets, n >= 2 with a T n <= 8.

    Beyond a T n = 8 the backward flow multiplies round-off by e^{a T n}; the
    gauge construction below covers large n.
    """
    rng = np.random.default_rng(seed)
    n_cap = max(3, int(8.0 / (plant.a * plant.sample_time)))
    for _ in range(count):
        n = int(rng.integers(2, min(n_cap, 120) + 1))
        frac = None if rng.random() < 0.5 else float(rng.uniform(-0.9, 0.9))
        yield n, boundary_state(plant, n, int(rng.integers(0, n)), rng.choice([-1.0, 1.0]), frac)


def gauge_boundary_state(x1: float, x2: float, plant: Plant, n: int) -> tuple[float, float]:
    """The point of the ray through (x1, x2) on the boundary of the n-step set.

    min t s.t. Ad^n x0 + sum_m Ad^m Bd v_m = 0, |v_m| <= t (scipy HiGHS; matrix
    powers, not reach.py); the n-step set is convex and centrally symmetric, so
    x0 / t* is on its boundary.
    """
    from scipy.optimize import linprog

    from ptoverify.model.plant import zoh_matrices

    ad, bd = zoh_matrices(plant.a, plant.sample_time)
    scale = np.array([plant.a / plant.w_max, 1.0 / plant.w_max])
    cols, p = [], np.eye(2)
    for _ in range(n):
        cols.append(scale * (p @ bd[:, 0]) * plant.w_max)
        p = ad @ p
    G = np.column_stack(cols)
    b = -scale * (p @ np.array([x1, x2]))
    ones = np.ones((n, 1))
    a_ub = np.block([[np.eye(n), -ones], [-np.eye(n), -ones]])
    res = linprog(
        np.r_[np.zeros(n), 1.0],
        A_ub=a_ub,
        b_ub=np.zeros(2 * n),
        A_eq=np.hstack([G, np.zeros((2, 1))]),
        b_eq=b,
        bounds=(None, None),
        method="highs-ds",
    )
    assert res.status == 0, res.message
    t = float(res.x[-1])
    return x1 / t, x2 / t


@pytest.mark.parametrize("name", PLANTS)
def test_gauge_boundary_states_nudged(name):
    """Random (envelope and far) states scaled onto the boundary of their N*- and
    (N* - 1)-step sets, then moved out and in by eps."""
    plant = PLANTS[name]
    x1, x2 = random_states(plant, 2, 1, seed=9)
    n_star = discrete_min_steps_batch(x1, x2, plant).steps
    for a, b, ns in zip(x1, x2, n_star, strict=True):
        for n in (int(ns), int(ns) - 1):
            y1, y2 = gauge_boundary_state(float(a), float(b), plant, n)
            s = np.array([1.0 - EPS, 1.0 + EPS])
            zono = discrete_min_steps_batch(y1 * s, y2 * s, plant).steps
            lp = lp_steps(y1 * s, y2 * s, plant)
            assert zono.tolist() == lp.tolist(), (n, y1, y2, zono, lp)
            assert zono[0] <= n < zono[1], (n, y1, y2, zono)


@pytest.mark.parametrize("name", PLANTS)
def test_boundary_states_nudged_in_and_out(name):
    """Built on the n-step boundary: (1 - eps) x0 reaches in <= n, (1 + eps) x0 needs > n."""
    plant = PLANTS[name]
    for n, (x1, x2) in boundary_cases(plant, 12, seed=7):
        s = np.array([1.0 - EPS, 1.0 + EPS])
        zono = discrete_min_steps_batch(x1 * s, x2 * s, plant).steps
        lp = lp_steps(x1 * s, x2 * s, plant)
        assert zono.tolist() == lp.tolist(), (n, x1, x2, zono, lp)
        assert zono[0] <= n < zono[1], (n, x1, x2, zono)


@pytest.mark.parametrize("name", PLANTS)
def test_boundary_states_within_margin_count_as_inside(name):
    """On the boundary up to round-off (|u| = w_max exactly): inside, by the margin."""
    plant = PLANTS[name]
    for n, (x1, x2) in boundary_cases(plant, 30, seed=8):
        s = np.array([1.0, 1.0 + 0.1 * MARGIN])
        zono = discrete_min_steps_batch(x1 * s, x2 * s, plant).steps
        assert np.all(zono <= n), (n, x1, x2, zono)
        s = np.array([1.0 + 10 * MARGIN])  # beyond the margin: out (n-step set is convex)
        assert discrete_min_steps_batch(x1 * s, x2 * s, plant).steps[0] > n, (n, x1, x2)


def test_grid_aligned_vertex_state_is_exactly_n():
    """The continuous optimum switching on the grid: N* T = t_f*, and N* - 1 is out."""
    plant = PLANTS["paper"]
    x1, x2 = boundary_state(plant, 12, 9, -1.0, None)  # -w for 9 samples, then +w
    d = discrete_min_steps_batch(x1, x2, plant)
    assert int(d.steps) == 12 == discrete_min_steps(x1, x2, plant).steps
    assert not bool(d.below_bound)


def test_one_step_states():
    """Z_1 is a segment: a state one sample from the origin, and one just off the line."""
    plant = PLANTS["paper"]
    x1, x2 = flow(0.0, 0.0, 0.7 * plant.w_max, -plant.sample_time, plant.a)
    d = discrete_min_steps_batch([x1, x1 * (1 + 1e-6)], [x2, x2], plant)
    assert d.steps.tolist() == [1, 2]
    assert discrete_min_steps(float(x1), float(x2), plant).steps == 1


def test_table_membership_matches_facet_enumeration():
    """contains() against every facet of Z_n, by matrix powers (no table, no lookup)."""
    plant = PLANTS["small-aT"]
    c = plant.a * plant.sample_time
    tab = ZonotopeTable(plant, 400)
    rng = np.random.default_rng(3)
    ad = lambda m: np.array([[1.0, -math.expm1(-c * m)], [0.0, math.exp(-c * m)]])  # noqa: E731
    b = np.array([c + math.expm1(-c), -math.expm1(-c)])
    for n in (2, 3, 17, 150, 400):
        G = np.column_stack([ad(m) @ b for m in range(n)])
        normals = np.vstack([-G[1], G[0]])
        support = np.abs(normals.T @ G).sum(axis=1)
        # boundary points (one switch, one fractional input), scaled by 0.95..1.05
        m, j = np.arange(n)[:, None], rng.integers(0, n, 4000)
        v = np.where(m < j, 1.0, -1.0)
        v[j, np.arange(4000)] = rng.uniform(-1.0, 1.0, 4000)
        p = G @ v * rng.choice([-1.0, 1.0], 4000) * rng.uniform(0.95, 1.05, 4000)
        inv = np.array([[1.0, -math.expm1(c * n)], [0.0, math.exp(c * n)]])  # Ad^-n
        z = inv @ p
        p = ad(n) @ z
        slack = np.min(support[:, None] - np.abs(normals.T @ p), axis=0) / support.max()
        clear = np.abs(slack) > 1e-7  # not within round-off of a facet
        got = tab.contains(z[0], z[1], np.full(z.shape[1], n))
        assert np.array_equal(got[clear], slack[clear] > 0), n
        assert 0.3 < np.mean(got) < 0.7, (n, np.mean(got), np.mean(slack > 0))


def test_not_found_and_origin():
    plant = PLANTS["paper"]
    d = discrete_min_steps_batch([50.0, 0.0, 1e-6], [0.0, 0.0, 0.0], plant, n_max=10)
    assert d.steps.tolist() == [-1, 0, 2]
    assert math.isnan(d.time_s[0]) and d.time_s[1] == 0.0
    assert d.time_s[2] == pytest.approx(2 * plant.sample_time, rel=1e-15)


def test_shape_and_non_finite():
    plant = PLANTS["paper"]
    d = discrete_min_steps_batch(np.zeros((3, 4)) + 5.0, 0.0, plant)
    assert d.steps.shape == (3, 4) and d.time_s.shape == (3, 4)
    with pytest.raises(InputError):
        discrete_min_steps_batch([1.0, math.nan], [0.0, 0.0], plant)
    with pytest.raises(InputError):
        discrete_min_steps_batch([1.0], [math.inf], plant)


def test_gate_compares_zonotope_with_lp(monkeypatch, capsys):
    """The discrete-limit-consistency gate passes, and fails on a mutated batch N*."""
    import json
    from dataclasses import replace

    import ptoverify.model.mintime as mintime
    from ptoverify.cli import main

    argv = ["check", "--gate", "discrete-limit-consistency", "--json"]
    assert main(argv) == 0
    gate = json.loads(capsys.readouterr().out)["checks"][0]
    assert gate["status"] == "pass" and "zonotope" in gate["detail"]
    real = mintime.discrete_min_steps_batch

    def off_by_one(x1, x2, plant, n_max=20000):
        d = real(x1, x2, plant, n_max)
        steps = d.steps.copy()
        steps[3] += 1
        return replace(d, steps=steps)

    monkeypatch.setattr(mintime, "discrete_min_steps_batch", off_by_one)
    assert main(argv) == 1
    gate = json.loads(capsys.readouterr().out)["checks"][0]
    assert gate["status"] == "fail" and "1 of 25 states disagree" in gate["detail"]


def test_any_start_gives_the_same_n_star():
    """The search does not trust its start: n0 above N* is tested and flagged, n0 = 1 works."""
    from ptoverify.model.reach import zonotope_steps

    plant = PLANTS["paper"]
    x1, x2 = random_states(plant, 40, 10, seed=12)
    ref = discrete_min_steps_batch(x1, x2, plant)
    for n0 in (np.ones_like(ref.steps), ref.steps + 7, 3 * ref.steps):
        d = zonotope_steps(x1, x2, n0, plant)
        assert np.array_equal(d.steps, ref.steps)
        assert np.array_equal(d.below_bound, n0 - 1 >= ref.steps)


def test_each_state_with_its_own_plant_equals_the_search_per_plant():
    """zonotope_steps_each (a plant per state, closed-form generators) against the tabulated
    search of each state's plant, and the LP on a few of them."""
    rng = np.random.default_rng(11)
    checked = 0
    for T in (0.0005, 0.002):
        n = 250
        a, w = rng.uniform(20.0, 3000.0, n), rng.uniform(100.0, 500.0, n)
        x1 = rng.uniform(-50.0, 50.0, n) * rng.uniform(0.0, 1.0, n) ** 2
        x2 = rng.uniform(-1.0, 1.0, n) * w
        x1[:3], x2[:2] = 0.0, 0.0  # the origin and a state at rest
        got = zonotope_steps_each(x1, x2, 1 + rng.integers(0, 30, n), a, w, T)
        plants = [Plant(a=a[i], w_max=w[i], sample_time=T, position_range=50.0) for i in range(n)]
        want = [int(discrete_min_steps_batch(x1[i], x2[i], plants[i]).steps) for i in range(n)]
        assert got.tolist() == want
        for i in rng.choice(np.flatnonzero(got < 60), 3, replace=False):
            lp = discrete_min_steps(float(x1[i]), float(x2[i]), plants[i])
            assert lp.status == "optimal" and lp.steps == got[i], (x1[i], x2[i], plants[i])
            checked += 1
    assert checked == 6
