"""Closed-loop properties over a grid of initial states (simulation)."""

import numpy as np
import pytest
from conftest import with_d

from ptoverify.config import paper_config
from ptoverify.model.laws import make_law
from ptoverify.studies.properties import initial_grid, law_properties, oscillating

PAPER = paper_config()


CONFIGS = {
    "paper": PAPER,
    "a30": PAPER.with_plant(a=30.0),
    "T1ms": PAPER.with_plant(sample_time=0.001),
    "d1": with_d(PAPER, 1.0),
}


def test_grid_size():
    x1, x2, rest = initial_grid(PAPER)
    assert x1.size >= 10_000 and rest.sum() == 200
    assert np.abs(x1).max() <= PAPER.plant.position_range
    assert np.abs(x2).max() <= PAPER.plant.w_max


def test_oscillation_criterion():
    k = np.arange(80)[:, None]
    sustained = 0.3 * (-1.0) ** k * np.ones((1, 1))
    decaying = 0.3 * (-0.7) ** k
    settled = np.full((80, 1), 1e-5)
    one_sided = 0.3 + 0.0 * k
    x = np.hstack([sustained, decaying, settled, one_sided])
    assert oscillating(x, 1e-3).tolist() == [True, False, False, False]


def test_paper_corrected_pto():
    p = law_properties(make_law("pto", PAPER), PAPER)
    assert p.states >= 10_000
    assert p.stride_overs == 0 and p.crossings_into_linear == 0
    assert p.limit_cycles == 0 and p.not_settled == 0
    assert p.u_within_limit and p.zone_samples > 0
    assert p.overshoots == 0


def test_paper_to_limit_cycles():
    """Sampled TO at the defaults oscillates around the origin (criterion detects it)."""
    p = law_properties(make_law("to", PAPER), PAPER, n1=21, n2=21, rest=20)
    assert p.limit_cycles > 0 and p.u_within_limit


@pytest.mark.slow
@pytest.mark.parametrize("name", ["a30", "T1ms", "d1"])
def test_other_configs_corrected_pto(name):
    cfg = CONFIGS[name]
    p = law_properties(make_law("pto", cfg), cfg)
    assert p.stride_overs == 0 and p.crossings_into_linear == 0
    assert p.limit_cycles == 0 and p.u_within_limit


@pytest.mark.slow
def test_a30_to_strides_over():
    cfg = CONFIGS["a30"]
    p = law_properties(make_law("to", cfg), cfg, n1=31, n2=31, rest=20)
    assert p.stride_overs > 0


def _oscillating_reference(x1: np.ndarray, band: float) -> list[bool]:
    """The module docstring's criterion, one trajectory at a time in plain Python."""
    out = []
    for col in x1.T.tolist():
        signs = [1 if v > 0 else -1 for v in col if abs(v) > band]
        changes = sum(a != b for a, b in zip(signs, signs[1:], strict=False))
        half = len(col) // 2
        first = max(abs(v) for v in col[:half]) if half else -np.inf
        second = max(abs(v) for v in col[half:])
        out.append(changes >= 4 and second > band and second >= 0.5 * first)
    return out


def test_oscillating_against_a_plain_reference():
    """Decaying and sustained sines, flat stretches inside the band, exact zeros."""
    rng = np.random.default_rng(1)
    for _ in range(40):
        w, n = int(rng.integers(4, 120)), int(rng.integers(1, 30))
        k = np.arange(w)[:, None]
        x = np.sin(rng.uniform(0.05, 3.0, n) * k + rng.uniform(0.0, 6.0, n))
        x *= 10.0 ** rng.uniform(-4.0, 0.0, n) * np.exp(-rng.uniform(0.0, 0.08, n) * k)
        x[rng.random((w, n)) < 0.1] = 0.0
        band = 10.0 ** rng.uniform(-4.0, -2.0)
        assert oscillating(x, band).tolist() == _oscillating_reference(x, band)


def _crossings_reference(X1, X2, R, cfg):
    """crossing_masks by its definition, sigma at every sample (curves.switching_function)."""
    from ptoverify.model.curves import switching_function
    from ptoverify.model.laws import Region
    from ptoverify.verdict import tie_band

    p, d = cfg.plant, cfg.pto.d
    tol = tie_band(p.w_max, p.a, p.position_range)
    sig = switching_function(X1, X2, p.a, p.w_max)
    out = np.abs(X1) >= d
    R = R[: X1.shape[0] - 1]
    src = out[:-1] & (R != Region.ZONE_P) & (R != Region.ZONE_N)
    s0, s1, v0 = sig[:-1], sig[1:], X2[:-1]
    n_side = (s0 > 0) | ((s0 == 0) & (v0 > 0))
    p_side = (s0 < 0) | ((s0 == 0) & (v0 < 0))
    cross = src & ((n_side & (s1 < -tol)) | (p_side & (s1 > tol)))
    return cross & out[1:], cross & ~out[1:]


@pytest.mark.parametrize("name", ["to", "pto-printed"])
def test_crossing_masks_against_the_definition(name):
    """On sampled TO and PTO trajectories (which stride over and enter zones), and on a view."""
    from ptoverify.sim.simulate import Mismatch, simulate_batch
    from ptoverify.studies.properties import crossing_masks, stride_over_counts

    cfg = CONFIGS["a30"]
    x1, x2, _ = initial_grid(cfg, 9, 9, 10)
    b = simulate_batch(
        make_law(name, cfg), cfg.plant, x1, x2, 300, mismatch=Mismatch(a_ratio=1.1, delay_samples=1)
    )
    want = _crossings_reference(b.x1, b.x2, b.region, cfg)
    got = crossing_masks(b.x1, b.x2, b.region, cfg)
    assert want[0].any() and want[1].any(), "the case must exercise both kinds"
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    cols = slice(3, -4)  # a view of a larger batch, as the robustness study passes them
    counts = stride_over_counts(b.x1[:, cols], b.x2[:, cols], b.region[:, cols], cfg)
    assert counts.tolist() == want[0][:, cols].sum(axis=0).tolist()
