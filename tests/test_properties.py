"""Closed-loop properties over a grid of initial states (simulation)."""

import numpy as np
import pytest
from conftest import with_d

from ptoverify.config import paper_config
from ptoverify.laws import make_law
from ptoverify.properties import initial_grid, law_properties, oscillating

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
