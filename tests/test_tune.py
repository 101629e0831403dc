"""Tuning: a brute-force reference, constraints re-checked independently, TOML round trip."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.signal import cont2discrete

from ptoverify.config import config_from_mapping, load_config, paper_config
from ptoverify.errors import InputError
from ptoverify.exact import exact_metrics
from ptoverify.laws import make_law
from ptoverify.properties import law_properties
from ptoverify.simulate import simulate
from ptoverify.tune import BOUNDS, pareto_front, tune

CFG = paper_config()
# a slower, coarser plant: few samples per response, so a brute-force grid is cheap
SLOW = config_from_mapping(
    {
        "name": "slow",
        "plant": {"a": 60.0, "w_max": 200.0, "sample_time": 0.004, "position_range": 20.0},
        "pd": {"kp": 50.0, "kd": 0.5},
        "pto": {"d": 1.0, "k1": 60.0, "k2": 1.0},
    }
)


def _spectral_radius(a, T, k1, k2):
    A, B = np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]])
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), T, method="zoh")
    return np.abs(np.linalg.eigvals(Ad - Bd @ np.array([[k1, k2]]))).max()


def _settling(cfg, kp, kd):
    """Independent evaluation: simulate, then the exact metrics of that response."""
    c = dataclasses.replace(cfg, pd=dataclasses.replace(cfg.pd, kp=kp, kd=kd))
    if _spectral_radius(cfg.plant.a, cfg.plant.T, kp, kd) >= 1.0:
        return math.inf
    res = simulate(make_law("pd", c), c.plant, "step")
    v = exact_metrics(res, c.plant).exact()["settling_2pct_s"]
    return v if math.isfinite(v) else math.inf


@pytest.mark.slow
def test_pd_tune_matches_brute_force_grid():
    kps = np.geomspace(*BOUNDS["pd"]["kp"], 25)
    kds = np.linspace(*BOUNDS["pd"]["kd"], 21)
    grid = np.array([[_settling(SLOW, kp, kd) for kd in kds] for kp in kps])
    i, j = np.unravel_index(np.argmin(grid), grid.shape)
    r = tune(SLOW, "pd", "step", maxiter=40)
    # the search is continuous: it must do at least as well as the grid's best cell ...
    assert r.best.objective <= grid[i, j] * (1 + 1e-9), (r.best.gains, kps[i], kds[j])
    # ... and its value is what an independent simulation of its gains gives
    again = _settling(SLOW, r.best.gains["kp"], r.best.gains["kd"])
    assert again == pytest.approx(r.best.objective, rel=1e-12)
    # and it lies within one grid cell of a grid cell at most one cell-value worse
    near = grid[max(i - 1, 0) : i + 2, max(j - 1, 0) : j + 2]
    assert r.best.objective <= near.min() + 1e-12


def test_constraints_hold_when_resimulated_independently():
    bound = 0.01
    r = tune(CFG, "pd", "step", max_overshoot=bound, maxiter=15)
    g = r.best.gains
    assert _spectral_radius(CFG.plant.a, CFG.plant.T, g["kp"], g["kd"]) < 1.0
    cfg = r.config
    assert (cfg.pd.kp, cfg.pd.kd) == (g["kp"], g["kd"])
    res = simulate(make_law("pd", cfg), cfg.plant, "step")
    m = exact_metrics(res, cfg.plant).exact()
    assert m["overshoot_mm"] <= bound
    # between samples, not on the grid: the exact overshoot bounds the grid's
    assert m["overshoot_mm"] >= exact_metrics(res, cfg.plant).grid()["overshoot_mm"]
    assert law_properties(make_law("pd", cfg), cfg, n1=41, n2=41, rest=40).limit_cycles == 0


def test_tuned_config_round_trips_through_toml(tmp_path):
    r = tune(CFG, "pd", "step", maxiter=5)
    path = tmp_path / "tuned.toml"
    path.write_text(r.toml())
    loaded = load_config(path)
    assert loaded.pd == r.config.pd and loaded.plant == r.config.plant and loaded.pto == CFG.pto
    res = simulate(make_law("pd", loaded), loaded.plant, "step")
    m = exact_metrics(res, loaded.plant).exact()
    assert m["settling_2pct_s"] == r.best.settling_2pct_s
    assert m["overshoot_mm"] == r.best.overshoot_mm


def test_pareto_front_is_nondominated():
    r = tune(CFG, "pd", "step", maxiter=5)
    front = r.front
    assert front, "an empty front"
    for a in front:
        for b in front:
            dominated = (
                b.overshoot_mm <= a.overshoot_mm
                and b.settling_2pct_s <= a.settling_2pct_s
                and (b.overshoot_mm, b.settling_2pct_s) != (a.overshoot_mm, a.settling_2pct_s)
            )
            assert not dominated, (a, b)
    assert pareto_front(front) == front


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"law": "to"}, "law"),
        ({"law": "pd", "objective": "fastest"}, "objective"),
        ({"law": "pd", "max_overshoot": -1.0}, "overshoot"),
        ({"law": "pd", "signal": "chirp"}, "signal"),
    ],
)
def test_bad_arguments_are_input_errors(kwargs, word):
    with pytest.raises(InputError, match=word):
        tune(CFG, **kwargs)
