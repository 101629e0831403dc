"""Shared fixtures and helpers: plants, random states, the ZOH reference, ``with_d``.

The helpers are imported by the test modules (``from conftest import ...``);
they live here once.
"""

import dataclasses
import functools

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from derivations.common import PlantNumbers  # noqa: E402
from ptoverify.config import Config, PDGains, Plant, PTOSettings, paper_config  # noqa: E402

#: The hostile audit (tests/audit/run_audit.py) is a script, not a test module.
collect_ignore = ["audit"]


@pytest.fixture
def paper_cfg() -> Config:
    return paper_config()


def other_configs() -> list[Config]:
    """Two more plants: the 'a = 30 rad/s' reading, and a slower, finer-sampled axis."""
    return [
        Config(
            "slow-a",
            Plant(a=30.0, w_max=300.0, sample_time=0.002, position_range=50.0),
            PDGains(),
            PTOSettings(),
        ),
        Config(
            "fine-T",
            Plant(a=100.0, w_max=100.0, sample_time=0.001, position_range=20.0),
            PDGains(kp=100.0, kd=0.5),
            PTOSettings(d=0.2, k1=100.0, k2=1.0),
        ),
    ]


ALL_CONFIGS = [paper_config(), *other_configs()]

#: The plants of :data:`ALL_CONFIGS` by name.
PLANTS = {c.name: c.plant for c in ALL_CONFIGS}


@pytest.fixture(params=ALL_CONFIGS, ids=lambda c: c.name)
def any_cfg(request) -> Config:
    return request.param


def with_d(cfg: Config, d: float) -> Config:
    """``cfg`` with the PTO linear-zone half-width set to ``d`` [mm]."""
    return dataclasses.replace(cfg, pto=dataclasses.replace(cfg.pto, d=d))


def random_states(plant: Plant, n: int, seed: int) -> np.ndarray:
    """``n`` states uniform in the envelope |x1| <= position_range, |x2| < w_max, shape (n, 2)."""
    rng = np.random.default_rng(seed)
    x1 = rng.uniform(-1.0, 1.0, n) * plant.position_range
    x2 = rng.uniform(-1.0, 1.0, n) * plant.w_max * (1.0 - 1e-9)
    return np.column_stack([x1, x2])


@functools.lru_cache(maxsize=64)
def zoh_reference(a: float, T: float) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """(Ad, Bd) of eq. (1) by ``scipy.signal.cont2discrete(method="zoh")``.

    Independent of ``ptoverify.model.plant`` (scipy builds it from expm of the
    augmented matrix): the reference for every one-sample map.  Computed once
    per (a, T) and returned read-only (the same matrices every call; the
    sample-by-sample reference simulations call this per sample).
    """
    from scipy.signal import cont2discrete  # here: scipy.signal is not imported to collect

    A = np.array([[0.0, 1.0], [0.0, -a]])
    B = np.array([[0.0], [a]])
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), T, method="zoh")
    Ad.flags.writeable = Bd.flags.writeable = False
    return Ad, Bd


def zoh_step(x1, x2, u, a: float, T: float):  # noqa: N803
    """One ZOH sample of eq. (1) from (x1, x2) under held u (broadcasting), by :func:`zoh_reference`."""
    Ad, Bd = zoh_reference(a, T)
    X = np.stack(
        np.broadcast_arrays(np.asarray(x1, float), np.asarray(x2, float), np.asarray(u, float))
    )
    y1 = Ad[0, 0] * X[0] + Ad[0, 1] * X[1] + Bd[0, 0] * X[2]
    y2 = Ad[1, 0] * X[0] + Ad[1, 1] * X[1] + Bd[1, 0] * X[2]
    return y1, y2


def plant_numbers(cfg: Config) -> PlantNumbers:
    """The configuration's numbers as the derivations take them."""
    p = cfg.plant
    return PlantNumbers(
        a=p.a, w_max=p.w_max, T=p.sample_time, d=cfg.pto.d, k1=cfg.pto.k1, k2=cfg.pto.k2
    )


def cell_states(grid, bound: np.ndarray, per_cell: int, seed: int):
    """States that cover every cell of a proof's grid, each with the bound it must meet.

    Every node of the grid (the four corners of each cell, closed cells: a node is
    held to the least bound of the cells it closes) and ``per_cell`` seeded states
    uniform inside every cell (held to that cell's bound).  Uniform states over the
    envelope leave the grid's fine cells with few or none (a million of them miss
    5,585 of the 44,416 proved cells of the paper's nominal proof); these reach every
    cell, at its corners, where its enclosure's extremes are taken.  Measured on that
    proof: with 4 per cell (225,000 states) some state attains its cell's bound in
    14,819 cells, so a bound one sample too low there fails the check; a million
    uniform states attain it in 9,877 cells (14,888 for both sets together).

    Parameters
    ----------
    grid : Grid
        The proof's cells (cell index j * n1 + i).
    bound : ndarray
        Certified bound per cell [samples] (inf: unproven).
    per_cell : int
        Seeded states inside each cell.
    seed : int
        Seed of the inside states.

    Returns
    -------
    x1, x2, bound : ndarray
        States [mm], [mm/s] and the bound of each (inf: no proved cell holds it).
    """
    n1, n2 = grid.shape
    pad = np.full((n2 + 2, n1 + 2), np.inf)
    pad[1:-1, 1:-1] = bound.reshape(n2, n1)
    node = np.minimum.reduce([pad[:-1, :-1], pad[:-1, 1:], pad[1:, :-1], pad[1:, 1:]])
    c1, c2 = np.meshgrid(grid.e1, grid.e2)  # node (i, j) at (e1[i], e2[j])
    x1lo, x1hi, x2lo, x2hi = (np.repeat(v, per_cell) for v in grid.boxes())
    rng = np.random.default_rng(seed)
    f1, f2 = rng.uniform(0.0, 1.0, (2, x1lo.size))
    x1 = np.concatenate([c1.ravel(), x1lo + f1 * (x1hi - x1lo)])
    x2 = np.concatenate([c2.ravel(), x2lo + f2 * (x2hi - x2lo)])
    return x1, x2, np.concatenate([node.ravel(), np.repeat(bound, per_cell)])


#: A small configuration for ``ptoverify robust`` (a 5 mm envelope, so a short horizon):
#: ``test_robust_cli`` and ``test_dask`` run the command on it.
ROBUST_SMALL = """\
name = "small"
[plant]
bandwidth_hz = 30.0
w_max = 300.0
sample_time = 0.002
position_range = 5.0
[pd]
kp = 356.0
kd = 1.15
[pto]
d = 0.5
k1 = 323.0
k2 = 3.6
[robustness]
a_ratio = [0.9, 1.25]
w_max_ratio = [0.95, 1.0]
delay_samples = [0, 1]
"""


def assert_same_proof(p, q) -> None:
    """Two proofs of one law are equal array by array: bounds, stride verdicts, gaps and
    leaves, images and macro-steps of every sub-interval, and the properties' JSON."""
    np.testing.assert_array_equal(p.bound, q.bound)
    for bp, bq in zip(p.balls, q.balls, strict=True):
        for name in ("strict", "relaxed", "strict_gap", "relaxed_gap"):
            np.testing.assert_array_equal(getattr(bp.stride, name), getattr(bq.stride, name))
        for u, v in zip(bp.stride.leaves, bq.stride.leaves, strict=True):
            np.testing.assert_array_equal(u, v)
        for u, v in zip(bp.image, bq.image, strict=True):
            np.testing.assert_array_equal(u, v)
        np.testing.assert_array_equal(bp.k, bq.k)
    assert p.to_json()["properties"] == q.to_json()["properties"]
