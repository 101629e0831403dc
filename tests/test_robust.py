"""Robustness study: mismatch kernel, zero box, margins, worst-case search, Dask."""

import dataclasses
import math

import numpy as np
import pytest

from ptoverify.config import Robustness, paper_config
from ptoverify.model.laws import Law, make_law
from ptoverify.model.plant import flow
from ptoverify.model.poles import sampled_spectral_radius
from ptoverify.sim.simulate import Mismatch, simulate_batch
from ptoverify.studies.properties import default_steps, initial_grid, law_properties, oscillating
from ptoverify.studies.robust import (
    RobustSettings,
    grid_worst,
    horizon_steps,
    linear_loop_margin,
    linear_loop_radii,
    map_states,
    no_limit_cycle_margin,
    robust_maps,
    run_robust,
    trajectory_properties,
    worst_case,
    worst_cases,
)

CFG = paper_config()
TINY = RobustSettings(n1=5, n2=5, rest=4, n_a=3, n_w=2, search_iterations=2, search_population=6)


def _reference_loop(law, plant, x0, steps, a_ratio, w_ratio, delay, q):
    """Independent closed loop: plant.flow on the true plant, a delay line, a quantizer."""
    a, w = plant.a * a_ratio, plant.w_max * w_ratio
    x = np.array(x0, dtype=float)
    xs, line = [x.copy()], []
    held = None
    for _ in range(steps):
        y1 = q * round(x[0] / q) if q else x[0]
        u, _ = law.scalar(float(y1), float(x[1]))
        line.append(u)
        held = line[0] if held is None else held
        if len(line) > delay:
            held = line.pop(0)
        v = min(max(held, -w), w)
        x = np.array(flow(x[0], x[1], v, plant.sample_time, a), dtype=float)
        xs.append(x.copy())
    return np.array(xs)


@pytest.mark.parametrize("law_name", ["pd", "pto", "to"])
@pytest.mark.parametrize("delay", [0, 1, 2])
def test_mismatch_kernel_matches_independent_loop(law_name, delay):
    law, p = make_law(law_name, CFG), CFG.plant
    x0s = [(12.0, -40.0), (-3.0, 250.0), (0.7, 0.0)]
    m = Mismatch(a_ratio=0.83, w_max_ratio=0.91, delay_samples=delay, position_quantum=0.001)
    b = simulate_batch(law, p, [s[0] for s in x0s], [s[1] for s in x0s], 120, mismatch=m)
    for i, x0 in enumerate(x0s):
        ref = _reference_loop(law, p, x0, 120, 0.83, 0.91, delay, 0.001)
        np.testing.assert_allclose(
            b.x1[:, i], ref[:, 0], rtol=1e-9, atol=1e-9, err_msg=f"x1 from {x0}, delay {delay}"
        )
        np.testing.assert_allclose(
            b.x2[:, i], ref[:, 1], rtol=1e-9, atol=1e-7, err_msg=f"x2 from {x0}, delay {delay}"
        )


def test_zoh_of_true_plant_is_cont2discrete():
    from scipy.signal import cont2discrete

    p, r = CFG.plant, 1.2
    a = p.a * r
    A, B = np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), p.sample_time, method="zoh")
    law = Law(
        "const",
        lambda x1, x2: (np.full(x1.shape, 100.0), np.zeros(x1.shape, np.int8)),
        lambda x1, x2: (100.0, 0),
        p.w_max,
    )
    b = simulate_batch(law, p, [1.0], [-20.0], 1, mismatch=Mismatch(a_ratio=r))
    want = Ad @ np.array([1.0, -20.0]) + Bd[:, 0] * 100.0
    np.testing.assert_allclose([b.x1[1, 0], b.x2[1, 0]], want, rtol=1e-12, err_msg="one ZOH sample")


def test_noise_is_seeded_and_batch_independent():
    law, p = make_law("pd", CFG), CFG.plant
    m = Mismatch(velocity_noise=5.0, seed=3)
    one = simulate_batch(law, p, [10.0], [0.0], 200, mismatch=m)
    two = simulate_batch(law, p, [-4.0, 10.0], [30.0, 0.0], 200, mismatch=m)
    assert np.array_equal(one.x1[:, 0], two.x1[:, 1]), "a state's trajectory depends on its batch"
    other = simulate_batch(
        law, p, [10.0], [0.0], 200, mismatch=Mismatch(velocity_noise=5.0, seed=4)
    )
    assert not np.array_equal(one.x1, other.x1), "the seed does not reach the noise"


@pytest.mark.parametrize("law_name", ["pto", "to", "pd"])
def test_zero_box_reproduces_nominal_properties(law_name):
    x1, x2, _ = initial_grid(CFG, 9, 9, 10)
    steps = default_steps(CFG)
    nominal = law_properties(make_law(law_name, CFG), CFG, n1=9, n2=9, rest=10, steps=steps)
    props = trajectory_properties(
        law_name, CFG, x1, x2, Mismatch(), steps=steps, with_settling=False
    )
    assert int(props["stride_overs"].sum()) == nominal.stride_overs
    assert int((props["limit_cycle_mm"] > 0).sum()) == nominal.limit_cycles
    over = np.nan_to_num(props["overshoot_mm"], nan=0.0).max()
    assert over == pytest.approx(nominal.max_overshoot_mm, abs=0.0), "overshoot differs"


def test_zero_box_maps_equal_nominal_simulation():
    box = Robustness(
        a_ratio=(1.0, 1.0), w_max_ratio=(1.0, 1.0), delay_samples=(0, 0), position_quantum=0.0
    )
    cfg = dataclasses.replace(CFG, robustness=box)
    maps = robust_maps(cfg, dataclasses.replace(TINY, laws=("to",)))
    (cell,) = maps.laws["to"]
    x1, x2 = map_states(cfg, TINY)
    nominal = simulate_batch(make_law("to", CFG), CFG.plant, x1, x2, horizon_steps(cfg))
    window = nominal.x1[-max(20, horizon_steps(cfg) // 4) :]
    assert cell.limit_cycle_states == int(oscillating(window, 1e-3).sum())
    assert cell.limit_cycle_states > 0, "sampled TO limit-cycles nominally (a known finding)"


@pytest.mark.parametrize("law_name, gains", [("pd", ("kp", "kd")), ("pto", ("k1", "k2"))])
def test_linear_margin_endpoints_against_independent_eigenvalues(law_name, gains):
    from scipy.signal import cont2discrete

    sect = CFG.pd if law_name == "pd" else CFG.pto
    k = np.array([[getattr(sect, gains[0]), getattr(sect, gains[1])]])
    p = CFG.plant

    def radius(r):
        a = p.a * r
        A, B = np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])
        Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), p.sample_time, method="zoh")
        return np.abs(np.linalg.eigvals(Ad - Bd @ k)).max()

    lo, hi = linear_loop_margin(law_name, CFG).interval
    for end in (lo, hi):
        if end is not None:
            assert abs(radius(end) - 1.0) < 1e-9, f"spectral radius at the endpoint {end}"
    # brute force: every scanned ratio inside is stable, the first beyond is not
    scan = np.geomspace(0.1, 10.0, 301)
    unstable = np.array([radius(r) >= 1.0 for r in scan])
    inside = (scan >= (lo or 0.1)) & (scan <= (hi or 10.0))
    assert not unstable[inside].any(), "an unstable ratio inside the reported interval"
    if hi is not None:
        assert unstable[(scan > hi)][0], "the ratio just beyond hi is stable"
    if lo is None:
        assert not unstable[scan <= 1.0].any()


@pytest.mark.parametrize("law_name", ["pd", "pto"])
def test_linear_loop_radii_against_scipy_and_one_by_one(law_name):
    """The stacked radii: SciPy's ZOH loop (with and without the delay state), each
    ratio bit for bit as alone, and without delay sampled_spectral_radius's value."""
    from scipy.signal import cont2discrete

    k1, k2 = (CFG.pd.kp, CFG.pd.kd) if law_name == "pd" else (CFG.pto.k1, CFG.pto.k2)
    p = CFG.plant
    ratios = np.geomspace(0.1, 10.0, 97)
    for delay in (0, 1):
        radii = linear_loop_radii(law_name, CFG, ratios, delay_samples=delay)
        for r, got in zip(ratios, radii, strict=True):
            a = p.a * r
            A, B = np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])
            Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), p.sample_time)
            K = np.array([[k1, k2]])
            M = Ad - Bd @ K if delay == 0 else np.block([[Ad, Bd], [-K, np.zeros((1, 1))]])
            assert abs(got - np.abs(np.linalg.eigvals(M)).max()) < 1e-12
            alone = linear_loop_radii(law_name, CFG, [r], delay_samples=delay)[0]
            assert got == alone
            if delay == 0:
                assert got == sampled_spectral_radius(a, p.sample_time, k1, k2)


def test_linear_margin_of_to_is_none_and_unstable_design_is_reported():
    assert linear_loop_margin("to", CFG).interval is None

    bad = dataclasses.replace(CFG, pd=dataclasses.replace(CFG.pd, kp=1e5))
    assert sampled_spectral_radius(bad.plant.a, bad.plant.T, 1e5, bad.pd.kd) > 1
    m = linear_loop_margin("pd", bad)
    assert m.interval is None and "unstable" in m.note


def _trap_law(cfg):
    """PD with a planted defect: near rest at 40 <= x1 <= 46 mm it outputs 0 (a trap)."""
    pd = make_law("pd", cfg)

    def vector(x1, x2):
        u, r = pd(x1, x2)
        trap = (x1 >= 40.0) & (x1 <= 46.0) & (np.abs(x2) < 40.0)
        return np.where(trap, 0.0, u), r

    def scalar(x1, x2):
        u, r = vector(np.array([x1]), np.array([x2]))
        return float(u[0]), int(r[0])

    return Law("trap", vector, scalar, cfg.plant.w_max, "PD with a planted trap")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_search_finds_planted_worst_case_the_grid_misses(seed):
    """For several seeds: the trap is not a lucky draw of one seed."""
    s = RobustSettings(n1=7, n2=6, rest=6, n_a=3, n_w=2, search_iterations=20, search_population=40)
    box = dataclasses.replace(CFG.robustness, delay_samples=(0, 0), seed=seed)
    cfg = dataclasses.replace(CFG, robustness=box)
    (cells,) = robust_maps(cfg, dataclasses.replace(s, laws=(_trap_law,))).laws.values()
    assert all(c.not_settled == 0 for c in cells), "the grid must miss the trap"
    w = worst_case(_trap_law, "settling_ratio_nt", cfg, grid_worst(cells, "settling_ratio_nt"), s)
    assert w.grid is not None
    assert w.unbounded and w.searched == math.inf, "the search did not find the trap"
    x1, x2 = w.state
    # reproducible: the reported state and parameters never settle either
    m = Mismatch(
        a_ratio=w.params.a_ratio,
        w_max_ratio=w.params.w_max_ratio,
        delay_samples=w.params.delay_samples,
        position_quantum=w.params.position_quantum,
    )
    again = trajectory_properties(_trap_law, cfg, np.array([x1]), np.array([x2]), m)
    assert again["settling_ratio_nt"][0] == math.inf
    end = simulate_batch(_trap_law(cfg), cfg.plant, [x1], [x2], 400, mismatch=m)
    assert 40.0 <= end.x1[-1, 0] <= 46.0, (
        f"the counterexample {w['state']} does not end in the trap"
    )


def test_mixed_delays_in_one_batch_equal_separate_runs():
    """Per-state delays (the lockstep search's batches) reproduce each delay's own run."""
    law, p = make_law("pto", CFG), CFG.plant
    x1, x2 = np.array([12.0, -3.0, 0.7, 30.0]), np.array([-40.0, 250.0, 0.0, 10.0])
    delays = np.array([0, 1, 2, 1])
    ar = np.array([0.85, 1.2, 1.0, 0.95])
    both = simulate_batch(
        law,
        p,
        x1,
        x2,
        150,
        mismatch=Mismatch(a_ratio=ar, delay_samples=delays, position_quantum=1e-3),
    )
    for i in range(4):
        m = Mismatch(a_ratio=ar[i], delay_samples=int(delays[i]), position_quantum=1e-3)
        one = simulate_batch(law, p, x1[i : i + 1], x2[i : i + 1], 150, mismatch=m)
        assert np.array_equal(both.x1[:, i], one.x1[:, 0]), f"state {i}, delay {delays[i]}"
        assert np.array_equal(both.x2[:, i], one.x2[:, 0]), f"state {i}, delay {delays[i]}"


def test_no_limit_cycle_margin_against_a_brute_force_scan():
    """The edge lies in the first failing step of an independent scan, and is clean itself."""
    x1, x2 = map_states(CFG, TINY)

    def clean(r):
        props = trajectory_properties(
            "pto", CFG, x1, x2, Mismatch(a_ratio=float(r)), with_settling=False
        )
        return not (props["limit_cycle_mm"] > 0).any()

    lo, hi = no_limit_cycle_margin("pto", CFG, TINY, rtol=1e-3).interval
    assert hi is not None and 1.0 < hi < 10.0
    assert clean(hi), f"limit cycle at the reported edge {hi}"
    scan = np.geomspace(1.0, 10.0, 40)
    first = next(i for i, r in enumerate(scan) if not clean(r))
    assert scan[first - 1] <= hi < scan[first], (hi, scan[first - 1], scan[first])
    step = scan[first] / scan[first - 1]
    assert any(not clean(hi * step ** (k / 64)) for k in range(1, 65))


def test_maps_do_not_depend_on_batching(monkeypatch):
    """Cells simulated together or in batches of one cell give the same maps, bit for bit."""
    import ptoverify.studies.robust.maps as maps_mod

    s = dataclasses.replace(TINY, laws=("pto",))
    together = robust_maps(CFG, s)
    monkeypatch.setattr(maps_mod, "BATCH_STATES", 1)
    assert robust_maps(CFG, s).to_json() == together.to_json()


def test_search_is_deterministic_for_a_seed():
    """Two runs of the seeded search give the same worst cases; another seed differs."""
    s = dataclasses.replace(TINY, laws=("pto",))
    (cells,) = robust_maps(CFG, s).laws.values()
    starts = {p: grid_worst(cells, p) for p in ("overshoot_mm", "settling_ratio_nt")}
    one = worst_cases("pto", CFG, starts, s)
    assert worst_cases("pto", CFG, starts, s) == one
    other = dataclasses.replace(CFG, robustness=dataclasses.replace(CFG.robustness, seed=5))
    assert worst_cases("pto", other, starts, s) != one, "the seed does not reach the search"
    for prop, w in one.items():
        assert w.searched >= w.grid, f"{prop}: searched below the grid's worst"


def test_search_population_below_five_is_an_input_error():
    from ptoverify.errors import InputError

    with pytest.raises(InputError, match="at least 5"):
        run_robust(CFG, dataclasses.replace(TINY, search_population=4, laws=("pd",)))


@pytest.mark.parametrize("law_name", ["to", "pd", "pto", "pto-printed"])
def test_mirrored_state_has_the_same_properties(law_name):
    """The laws are odd and so is the mismatched loop: from (-x1, -x2) every measured
    property equals that from (x1, x2), bit for bit, with a quantizer and delays."""
    x1, x2 = map_states(CFG, dataclasses.replace(TINY, n1=9, n2=7, rest=10))
    rng = np.random.default_rng(3)
    n = x1.size
    m = Mismatch(
        a_ratio=rng.uniform(0.5, 2.0, n),
        w_max_ratio=rng.uniform(0.8, 1.0, n),
        delay_samples=rng.integers(0, 3, n),
        position_quantum=0.02,
    )
    a = trajectory_properties(law_name, CFG, x1, x2, m)
    b = trajectory_properties(law_name, CFG, -x1, -x2, m)
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k], equal_nan=True), k
    assert np.nanmax(a["settling_ratio_nt"]) > 1.0


def test_grid_worst_keeps_a_cell_that_never_settles():
    """A cell whose worst state never settles (inf) is the worst start, not left out: the
    report's 'grid worst' then says unbounded, as the map's own figure does."""
    from ptoverify.studies.robust.results import MapCell, PropertyMax
    from ptoverify.studies.robust.search import grid_worst, merge_found

    def cell(ratio, a):
        pm = PropertyMax(0.0, (1.0, 0.0))
        return MapCell(a, 1.0, 1, pm, pm, pm, PropertyMax(ratio, (a, 2.0)), 0, 0, 0)

    cells = [cell(8.3, 0.9), cell(math.inf, 1.1), cell(math.nan, 1.2)]
    starts = grid_worst(cells, "settling_ratio_nt")
    assert [s.value for s in starts] == [math.inf, 8.3], "inf first, NaN left out"
    worst = merge_found(paper_config(), {"settling_ratio_nt": starts}, [])["settling_ratio_nt"]
    assert worst.grid_unbounded and worst.unbounded and worst.state == (1.1, 2.0)


@pytest.mark.parametrize("law_name", ["ptos", "cascade-p"])
def test_baseline_linear_margins_against_the_laws_own_slopes(law_name):
    """The baselines' margins: the loop's gains read off the law itself (its slopes at the
    origin, unclipped), SciPy's ZOH plant; with and without the one-sample delay."""
    from scipy.signal import cont2discrete

    fn = make_law(law_name, CFG)
    h = 1e-6
    u, _ = fn(np.array([h, 0.0]), np.array([0.0, h]))
    K = np.array([[-u[0] / h, -u[1] / h]])
    p = CFG.plant

    def radius(r, delay):
        a = p.a * r
        A, B = np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])
        Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), p.sample_time, method="zoh")
        M = Ad - Bd @ K if delay == 0 else np.block([[Ad, Bd], [-K, np.zeros((1, 1))]])
        return np.abs(np.linalg.eigvals(M)).max()

    for delay in (0, 1):
        m = linear_loop_margin(law_name, CFG, delay_samples=delay)
        if m.interval is None:
            assert radius(1.0, delay) >= 1.0 - 1e-9
            continue
        for end in m.interval:
            if end is not None:
                assert abs(radius(end, delay) - 1.0) < 1e-6, (delay, end)
        lo, hi = m.interval
        for r in np.geomspace(lo or 0.1, hi or 10.0, 25)[1:-1]:
            assert radius(r, delay) < 1.0
