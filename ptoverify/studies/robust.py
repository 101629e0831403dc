"""Robustness under model mismatch: maps, margins and a worst-case search.

The law is always built from the nominal configuration; the simulated plant
and the measurement vary inside the uncertainty box of ``[robustness]``
(:class:`ptoverify.config.Robustness`): true a over design a, the drive's
saturation over the law's w_max, a computation delay of whole samples, an
encoder quantum on x1 and Gaussian noise on the measured x2.

Per trajectory (regulation to the origin from x0, by
:func:`ptoverify.sim.simulate.simulate_batch` with a :class:`Mismatch`):

stride_overs
    Stride-overs of the law's own switching curves (the design a and w_max:
    the curves the law decides with), :func:`ptoverify.studies.properties.crossing_masks`.
limit_cycle_mm
    Peak |x1| over the last quarter of the horizon when the trajectory
    oscillates there (:func:`ptoverify.studies.properties.oscillating`), else 0 [mm].
overshoot_mm
    From rest (x2 = 0, |x1| >= d): the largest excursion beyond the origin
    on the side opposite to x1_0, at the samples [mm].
settling_ratio_nt, settling_ratio_tf
    Settling time (|x1| <= 0.01 mm and |x2| <= 0.01 a mm/s, held 0.05 s, the
    sweep's band) over N*T and over t_f* of the *true* plant (true a, true
    saturation) [-]; inf when the trajectory does not settle in the horizon.
    Read on the samples, unlike the sweep: under a delay or a weaker drive the
    input the plant receives is not the commanded one the batch records, so the
    sweep's between-samples reconstruction does not apply here.

Maps evaluate a grid of perturbations (a_ratio x w_max_ratio x each delay)
times a grid of initial states.  Margins bisect a_true / a_design around 1.
The worst-case search is a seeded differential evolution (scipy's default
strategy, all searches of a law in lockstep so each generation is one batch
simulation) started from the grid's worst cells, then a batched local polish,
so the searched value is never below the grid's worst.

How the study runs.  Its simulations are sequential workloads (a generation
needs the previous one, a margin bracket the previous bracket), each small; a
small batch costs what a large one does per sample.  So :func:`run_robust`
runs them as :mod:`ptoverify.sim.lockstep` jobs: every law's maps, then the
searches of all laws, one simulation per round, and the no-limit-cycle margin
scans riding along in those rounds (each law is then evaluated 18 times 385
samples in all: its maps and 17 search generations).  Every trajectory is bit
for bit the one it has simulated alone, so the results do not depend on the
grouping (tested); ``timings_s`` books each round's time to the stages of its
states.  N* of the true plants comes from
:func:`ptoverify.model.reach.zonotope_steps_each` (a plant per state, one vectorized
search), the stride-overs from :func:`ptoverify.studies.properties.stride_over_counts`.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Generator
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config, Plant
from ptoverify.errors import ClusterError, InputError
from ptoverify.model.laws import Law, make_law
from ptoverify.model.mintime import min_time
from ptoverify.model.plant import zoh_matrices
from ptoverify.model.reach import zonotope_steps_each
from ptoverify.sim.lockstep import Ask, Job, run_lockstep
from ptoverify.sim.simulate import BatchResult, Mismatch, simulate_batch
from ptoverify.studies import cluster as dask_cluster
from ptoverify.studies.properties import oscillating, stride_over_counts
from ptoverify.studies.sweep import even_points, mirror_pairs, settle_steps
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict

__all__ = [
    "LAWS",
    "PROPERTIES",
    "RobustSettings",
    "trajectory_properties",
    "horizon_steps",
    "map_states",
    "robust_maps",
    "linear_loop_margin",
    "linear_loop_radii",
    "no_limit_cycle_margin",
    "worst_case",
    "worst_cases",
    "grid_worst",
    "dask_runner",
    "check_dask_address",
    "DASK_CONNECT_TIMEOUT_S",
    "most_robust",
    "RobustResult",
    "run_robust",
    "robust_gates",
    "describe_case",
]

LAWS = ("to", "pd", "pto", "pto-printed")
#: Properties searched for their worst case (larger is worse for each).
PROPERTIES = ("stride_overs", "limit_cycle_mm", "overshoot_mm", "settling_ratio_nt")
SETTLE_BAND_MM = 0.01  #: settling band on x1 [mm], as the sweep's
SETTLE_HOLD_S = 0.05  #: shortest settled tail [s], as the sweep's
MARGIN_RANGE = (0.1, 10.0)  #: a_true / a_design searched for margins [-]
MARGIN_RTOL = 1e-12  #: relative accuracy of the margin endpoints (the contract asks 1e-6)


@dataclass(frozen=True)
class RobustSettings:
    """Sizes of the robustness study.

    Attributes
    ----------
    n_a, n_w : int
        Points of the a_ratio and w_max_ratio grids (geometric in a_ratio,
        with 1 included when the box contains it).
    n1, n2 : int
        Initial-state grid over the envelope (x1 [mm] by x2 [mm/s]).
    rest : int
        Initial states at rest, |x1| in [d, position_range], both signs.
    laws : tuple of str
        Laws studied.
    search_iterations : int
        Generations of differential evolution per law, property and delay.
    search_population : int
        Population size of differential evolution (candidates per generation).
    properties : tuple of str
        Properties searched for their worst case (subset of :data:`PROPERTIES`).
    margins : bool
        Also compute the margins (bisections on a_ratio).
    """

    n_a: int = 5
    n_w: int = 3
    n1: int = 15
    n2: int = 15
    rest: int = 20
    laws: tuple[str, ...] = LAWS
    search_iterations: int = 12
    search_population: int = 24
    properties: tuple[str, ...] = PROPERTIES
    margins: bool = True


# -- per-trajectory properties -------------------------------------------------


def horizon_steps(cfg: Config) -> int:
    """Return the horizon [samples]: twice the envelope at the slowest drive, + 60/a.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box (the slowest a and w_max of the box).

    Returns
    -------
    int
        Samples simulated per trajectory.
    """
    p, box = cfg.plant, cfg.robustness
    w = p.w_max * box.w_max_ratio[0]
    a = p.a * box.a_ratio[0]
    return int(math.ceil((2.0 * p.position_range / w + 60.0 / a) / p.sample_time))


def _true_plant(plant: Plant, a_ratio: float, w_ratio: float) -> Plant:
    return replace(plant, a=plant.a * a_ratio, w_max=plant.w_max * w_ratio)


def _n_star(x1: NDArray, x2: NDArray, a_ratio: NDArray, w_ratio: NDArray, plant: Plant) -> NDArray:
    """N* of each state for its own true plant (a_ratio, w_max_ratio), nan where not found.

    One vectorized zonotope search for every mix of plants
    (:func:`ptoverify.model.reach.zonotope_steps_each`), started from the continuous
    bound ceil(t_f* / T) of the true plant (t_f* in the plant's dimensionless time,
    min_time of the unit plant; the start only changes the number of tests).
    """
    a, w = plant.a * a_ratio, plant.w_max * w_ratio
    unit = replace(plant, a=1.0, w_max=1.0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        tau = min_time(a * x1 / w, x2 / w, unit).t_f  # a t_f* [-]
        n0 = np.nan_to_num(np.ceil(tau / (a * plant.sample_time) - 1e-9), nan=1.0, posinf=1.0)
    steps = zonotope_steps_each(x1, x2, np.maximum(n0, 1.0), a, w, plant.sample_time)
    return np.where(steps >= 0, steps, np.nan).astype(float)


LawSpec = str | Callable[[Config], Law]


def _law(spec: LawSpec, cfg: Config) -> Law:
    """Build the nominal law: a name for :func:`make_law`, or a factory ``f(cfg) -> Law``."""
    return make_law(spec, cfg) if isinstance(spec, str) else spec(cfg)


def trajectory_properties(
    law_name: LawSpec,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    mismatch: Mismatch,
    *,
    steps: int | None = None,
    with_settling: bool | NDArray[np.bool_] = True,
    batch: BatchResult | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Simulate ``law_name`` (nominal design) on a mismatched plant and measure each state.

    Parameters
    ----------
    law_name : str or callable
        ``to``, ``pd``, ``pto`` or ``pto-printed``, or a factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration (the law's design and the box).
    x1, x2 : ndarray, shape (n,)
        Initial states [mm], [mm/s].
    mismatch : Mismatch
        The plant and measurement (a_ratio and w_max_ratio may be arrays of shape (n,)).
    steps : int, optional
        Horizon [samples]; default covers the slowest plant of the box.
    with_settling : bool or ndarray of bool, shape (n,)
        Also compute the settling ratios (needs t_f* and N* of each true plant),
        for every state or for the states of a mask (nan elsewhere).
    batch : BatchResult, optional
        The simulation of exactly these states, mismatch and horizon, when the
        caller already has it (it is measured, not simulated again).

    Returns
    -------
    dict
        Arrays of shape (n,): ``stride_overs`` [-], ``limit_cycle_mm`` [mm],
        ``overshoot_mm`` [mm] (nan where x0 is not at rest), ``settling_s`` [s],
        ``settling_ratio_nt`` and ``settling_ratio_tf`` [-] (see module docstring).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> cfg = paper_config()
    >>> out = trajectory_properties("pd", cfg, np.array([5.0]), np.array([0.0]), Mismatch())
    >>> float(out["stride_overs"][0]), bool(out["settling_ratio_nt"][0] > 1.0)
    (0.0, True)
    """
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    steps = horizon_steps(cfg) if steps is None else steps
    if batch is None:
        batch = simulate_batch(_law(law_name, cfg), cfg.plant, x1, x2, steps, mismatch=mismatch)
    return _measure(batch, cfg, x1, x2, mismatch, with_settling, with_tf=True)


def _limit_cycle_mm(x1: NDArray) -> NDArray[np.float64]:
    """Peak |x1| [mm] of the last quarter of each trajectory that oscillates there, else 0."""
    window = max(20, (x1.shape[0] - 1) // 4)
    tail = x1[-window:]
    return np.where(oscillating(tail, 1e-3), np.abs(tail).max(axis=0), 0.0)


def _measure(
    b: BatchResult,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    mismatch: Mismatch,
    with_settling: bool | NDArray[np.bool_],
    *,
    with_tf: bool,
) -> dict[str, NDArray[np.float64]]:
    """Measure the properties of :func:`trajectory_properties` on a simulated batch.

    ``with_tf`` False leaves ``settling_ratio_tf`` out (the study reads only the
    ratio to N*T; t_f* of each true plant is then not computed).
    """
    n = x1.size
    amp = _limit_cycle_mm(b.x1)
    rest = np.flatnonzero((x2 == 0.0) & (np.abs(x1) >= cfg.pto.d) & (x1 != 0.0))
    over = np.full(n, np.nan)
    if rest.size:  # the largest excursion beyond the origin, on the side opposite to x1_0
        run = b.x1[:, rest] if rest.size < n else b.x1
        over[rest] = np.maximum((-np.sign(x1[rest])[None, :] * run).max(axis=0), 0.0)
    out = {
        "stride_overs": stride_over_counts(b.x1, b.x2, b.region, cfg).astype(float),
        "limit_cycle_mm": amp,
        "overshoot_mm": over,
    }
    need = np.broadcast_to(np.asarray(with_settling, dtype=bool), (n,))
    if not need.any():
        return out
    T = cfg.plant.sample_time
    hold = math.ceil(SETTLE_HOLD_S / T - 1e-9)
    sel = np.flatnonzero(need)
    x1s, x2s = (b.x1, b.x2) if sel.size == n else (b.x1[:, sel], b.x2[:, sel])
    k = np.full(n, -1)
    k[sel] = settle_steps(x1s, x2s, SETTLE_BAND_MM, cfg.plant.a * SETTLE_BAND_MM, hold)
    settle = np.where(k >= 0, k * T, np.inf)
    ar = np.broadcast_to(np.asarray(mismatch.a_ratio, dtype=float), (n,))
    wr = np.broadcast_to(np.asarray(mismatch.w_max_ratio, dtype=float), (n,))
    n_star = np.full(n, np.nan)
    n_star[sel] = _n_star(x1[sel], x2[sel], ar[sel], wr[sel], cfg.plant)
    with np.errstate(divide="ignore", invalid="ignore"):
        out["settling_s"] = np.where(need, settle, np.nan)
        ratio_nt = np.where(n_star > 0, settle / (n_star * T), 0.0)
        out["settling_ratio_nt"] = np.where(need & ~np.isnan(n_star), ratio_nt, np.nan)
    if with_tf:
        t_f = np.full(n, np.nan)
        for key in set(zip(ar[need].tolist(), wr[need].tolist(), strict=True)):
            on = (ar == key[0]) & (wr == key[1]) & need
            t_f[on] = min_time(x1[on], x2[on], _true_plant(cfg.plant, *key)).t_f
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio_tf = np.where(t_f > 0, settle / t_f, 0.0)
            out["settling_ratio_tf"] = np.where(need & ~np.isnan(t_f), ratio_tf, np.nan)
    return out


# -- maps ----------------------------------------------------------------------


def _ratio_grid(lo: float, hi: float, n: int) -> NDArray[np.float64]:
    """Geometric grid on [lo, hi] with 1 included when lo <= 1 <= hi."""
    if n <= 1 or lo == hi:
        return np.array([1.0 if lo <= 1.0 <= hi else lo])
    g = np.geomspace(lo, hi, n)
    if lo <= 1.0 <= hi:
        g[np.argmin(np.abs(np.log(g)))] = 1.0
    return np.unique(g)


def map_states(cfg: Config, s: RobustSettings | None = None) -> tuple[NDArray, NDArray]:
    """Return the initial states of the maps: an n1 x n2 envelope grid plus states at rest.

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm], w_max [mm/s], d [mm]).
    s : RobustSettings, optional
        Grid sizes.

    Returns
    -------
    x1, x2 : ndarray
        Initial states [mm], [mm/s].
    """
    s = s or RobustSettings()
    p, d = cfg.plant, cfg.pto.d
    g1, g2 = np.meshgrid(even_points(p.position_range, s.n1), even_points(p.w_max, s.n2))
    r1 = np.linspace(max(d, 1e-3 * p.position_range), p.position_range, max(s.rest // 2, 1))
    x1 = np.concatenate([g1.ravel(), r1, -r1])
    x2 = np.concatenate([g2.ravel(), np.zeros(2 * r1.size)])
    return x1, x2


def _summarize(props: dict[str, NDArray], x1: NDArray, x2: NDArray) -> dict[str, Any]:
    """One map cell's summary of the per-state properties."""
    summary: dict[str, Any] = {}
    for key in PROPERTIES:
        v = props[key]
        fin = v[~np.isnan(v)]
        k = int(np.nanargmax(np.where(np.isnan(v), -np.inf, v)))
        summary[key] = {
            "max": float(fin.max()) if fin.size else math.nan,
            "state": [float(x1[k]), float(x2[k])],
        }
    summary["states_with_stride_over"] = int((props["stride_overs"] > 0).sum())
    summary["limit_cycle_states"] = int((props["limit_cycle_mm"] > 0).sum())
    summary["not_settled"] = int(np.isinf(props["settling_s"]).sum())
    r = props["settling_ratio_nt"]
    summary["settling_ratio_nt"]["median"] = float(np.median(r))
    summary["settling_ratio_nt"]["p95"] = float(np.percentile(r, 95, method="higher"))
    return summary


def _maps_job(
    fn: Law,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    ars: list[float],
    wrs: list[float],
    delays: list[int],
) -> Job:
    """Every map cell of one law (a :mod:`ptoverify.sim.lockstep` job returning the cells).

    All (delay, w, a) cells times all states in one ask per :data:`BATCH_STATES`
    states, each state with its cell's a_ratio, w_max_ratio and delay; cells in
    the order delay, w_max_ratio, a_ratio.
    """
    box = cfg.robustness
    cells = [(int(dl), float(wr), float(ar)) for dl in delays for wr in wrs for ar in ars]
    # Without velocity noise and with an odd law (Law.odd) the loop is odd (linear
    # plants, a quantizer
    # q rint(x / q) and a clip at +-w that are odd, bit for bit), so a state's mirror
    # (-x1, -x2) has the negated trajectory and the same properties: one of each
    # mirrored pair is simulated and measured (tests/test_robust.py compares the
    # maps with every state simulated).
    pairs = mirror_pairs(x1, x2) if box.velocity_noise == 0 and fn.odd else None
    reps, where = pairs if pairs else (np.arange(x1.size), np.arange(x1.size))
    y1, y2 = x1[reps], x2[reps]
    n = y1.size
    parts = [[cells[i] for i in group] for group in _groups(len(cells), n)]
    asks = []
    for part in parts:
        m = Mismatch(
            a_ratio=np.repeat([ar for _, _, ar in part], n),
            w_max_ratio=np.repeat([wr for _, wr, _ in part], n),
            delay_samples=np.repeat([dl for dl, _, _ in part], n),
            position_quantum=box.position_quantum,
            velocity_noise=box.velocity_noise,
            seed=box.seed,
        )
        asks.append(Ask(fn, np.tile(y1, len(part)), np.tile(y2, len(part)), m, stage="maps"))
    batches = yield asks
    out = []
    for part, ask, batch in zip(parts, asks, batches, strict=True):
        props = _measure(batch, cfg, ask.x1, ask.x2, ask.mismatch, True, with_tf=False)
        for i, (dl, wr, ar) in enumerate(part):
            cell = {k: v[i * n : (i + 1) * n][where] for k, v in props.items()}
            out.append(
                {"a_ratio": ar, "w_max_ratio": wr, "delay_samples": dl} | _summarize(cell, x1, x2)
            )
    return out


def _map_task(
    law: LawSpec,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    ars: list[float],
    wrs: list[float],
    delays: list[int],
) -> list[dict[str, Any]]:
    """Every cell of one law (:func:`_maps_job` run alone).

    A picklable task (the unit :func:`dask_runner` distributes); cells in the
    order delay, w_max_ratio, a_ratio.
    """
    job = _maps_job(_law(law, cfg), cfg, x1, x2, ars, wrs, delays)
    return run_lockstep(
        [job], cfg.plant, horizon_steps(cfg), round_states=BATCH_STATES, reuse=True
    ).results[0]


def _map_axes(cfg: Config, s: RobustSettings) -> tuple[list[float], list[float], list[int]]:
    """Return the perturbation grid of the maps: a_ratio, w_max_ratio and delay values."""
    box = cfg.robustness
    ars = _ratio_grid(*box.a_ratio, s.n_a).tolist()
    wrs = _ratio_grid(*box.w_max_ratio, s.n_w).tolist()
    return ars, wrs, list(range(box.delay_samples[0], box.delay_samples[1] + 1))


BATCH_STATES = 16384  #: largest batch simulated at once (memory: ~4 x 8 bytes x states x horizon)


def _groups(items: int, per_item: int) -> list[range]:
    """Split ``items`` blocks of ``per_item`` states into batches of <= BATCH_STATES states."""
    size = max(1, BATCH_STATES // max(per_item, 1))
    return [range(i, min(i + size, items)) for i in range(0, items, size)]


Runner = Callable[[list[tuple]], list[Any]]


def robust_maps(
    cfg: Config,
    settings: RobustSettings | None = None,
    *,
    runner: Runner | None = None,
) -> dict[str, Any]:
    """Evaluate every law on a grid of perturbations times a grid of initial states.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    settings : RobustSettings, optional
        Grid sizes and laws.
    runner : callable, optional
        ``runner(tasks) -> results`` evaluating ``_map_task(*task)`` for each task
        (one per law, every delay in it), in order: in-process by default;
        :func:`dask_runner` distributes them.  Each task is deterministic, so
        the maps do not depend on where or in which order the tasks ran.

    Returns
    -------
    dict
        ``a_ratio``, ``w_max_ratio``, ``delay_samples`` (the grid axes), ``states``
        (initial states per cell) and per law a list of cell summaries (``laws``),
        in the order delay, w_max_ratio, a_ratio.
    """
    s = settings or RobustSettings()
    ars, wrs, delays = _map_axes(cfg, s)
    x1, x2 = map_states(cfg, s)
    tasks = [(law, cfg, x1, x2, ars, wrs, delays) for law in s.laws]
    run = runner or (lambda ts: [_map_task(*t) for t in ts])
    return _maps_dict(cfg, s, dict(zip(s.laws, run(tasks), strict=True)))


def _maps_dict(cfg: Config, s: RobustSettings, laws: dict) -> dict[str, Any]:
    """Build the ``maps`` object: the grid axes, the states per cell, each law's cells."""
    ars, wrs, delays = _map_axes(cfg, s)
    return {
        "a_ratio": ars,
        "w_max_ratio": wrs,
        "delay_samples": delays,
        "states": int(map_states(cfg, s)[0].size),
        "laws": laws,
    }


#: how long to wait for a Dask scheduler [s]
DASK_CONNECT_TIMEOUT_S = dask_cluster.DASK_CONNECT_TIMEOUT_S


def check_dask_address(address: str) -> str:
    """Validate ``--dask``: ``local`` or ``PROTOCOL://HOST:PORT``.

    Parameters
    ----------
    address : str
        The address given.

    Returns
    -------
    str
        The address, unchanged.

    Raises
    ------
    InputError
        A malformed address (exit 2); an unreachable one is a
        :class:`ptoverify.errors.ClusterError` when the run connects.

    Examples
    --------
    >>> check_dask_address("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    """
    return dask_cluster.check_dask_address(address)  # one validation: studies.cluster


def dask_runner(address: str) -> Runner:
    """Return a runner for :func:`robust_maps` on a ``dask.distributed`` cluster.

    Parameters
    ----------
    address : str
        Scheduler address (``tcp://host:port``), or ``local`` to start a
        LocalCluster of 2 worker processes on this machine for the run.

    Returns
    -------
    callable
        ``runner(tasks) -> results`` in task order.

    Raises
    ------
    InputError
        A malformed address.
    ClusterError
        (When the runner runs) the scheduler could not be reached within
        :data:`DASK_CONNECT_TIMEOUT_S`.
    """
    check_dask_address(address)

    def run(tasks: list[tuple]) -> list[Any]:
        from dask.distributed import Client, LocalCluster

        if address == "local":
            with (
                LocalCluster(
                    n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
                ) as cluster,
                Client(cluster) as client,
            ):
                return client.gather(client.map(_map_task, *zip(*tasks, strict=True), pure=False))
        try:
            client = dask_cluster.connect(address, DASK_CONNECT_TIMEOUT_S)  # every step time-boxed
        except OSError as exc:  # TimeoutError and refused connections
            raise ClusterError(
                f"cannot reach the Dask scheduler at {address} within "
                f"{DASK_CONNECT_TIMEOUT_S:g} s ({type(exc).__name__}); start it, or use --dask local"
            ) from None
        with client:
            return client.gather(client.map(_map_task, *zip(*tasks, strict=True), pure=False))

    return run


# -- margins -------------------------------------------------------------------


def _linear_gains(law: str, cfg: Config) -> tuple[float, float] | None:
    if law == "pd":
        return cfg.pd.kp, cfg.pd.kd
    if law in ("pto", "pto-printed"):
        return cfg.pto.k1, cfg.pto.k2
    return None


EDGE_CHUNK = 64  #: scan points of :func:`_edge` tested per stacked eigenvalue call


def _edge(
    stable: Callable[[NDArray], NDArray[np.bool_]],
    toward: float,
    *,
    grid: int = 400,
    rtol: float = MARGIN_RTOL,
) -> float | None:
    """Where ``stable`` first fails going from 1 toward ``toward`` (None: never in range).

    Scans a geometric grid of ``grid`` points from 1 to ``toward``
    (:data:`EDGE_CHUNK` points per call of ``stable``, which tests an array of
    ratios; the points beyond the first failure cannot change the edge), then
    bisects the first stable/unstable pair to ``rtol`` relative.
    """
    pts = np.geomspace(1.0, toward, grid)
    for at in range(1, grid, EDGE_CHUNK):
        bad = np.flatnonzero(~stable(pts[at : at + EDGE_CHUNK]))
        if bad.size:
            j = at + int(bad[0])
            lo, hi = float(pts[j - 1]), float(pts[j])  # pts[0] is 1.0
            while abs(hi - lo) > rtol * min(abs(lo), abs(hi)):
                mid = math.sqrt(lo * hi)
                lo, hi = (mid, hi) if stable(np.array([mid]))[0] else (lo, mid)
            return lo
    return None


def linear_loop_radii(
    law: str, cfg: Config, a_ratio: ArrayLike, *, delay_samples: int = 0
) -> NDArray[np.float64]:
    """Spectral radius of the sampled linear loop at each a_true / a_design.

    The loop of :func:`linear_loop_margin`: ``Ad - Bd K`` of the ZOH plant of
    the true a (as :func:`ptoverify.model.poles.sampled_spectral_radius` forms it), or
    with a one-sample delay ``[[Ad, Bd], [-K, 0]]``; all ratios in one stacked
    eigenvalue call, each matrix as alone (LAPACK's ``geev`` per matrix).

    Parameters
    ----------
    law : str
        ``pd``, ``pto`` or ``pto-printed`` (a law with a linear loop).
    cfg : Config
        Nominal configuration (a [rad/s], T [s], the gains).
    a_ratio : array_like, shape (n,)
        a_true / a_design [-].
    delay_samples : int
        0 or 1 [samples].

    Returns
    -------
    ndarray, shape (n,)
        Largest |z| [-]; < 1 means stable.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> (linear_loop_radii("pd", paper_config(), [1.0, 10.0]) < 1.0).tolist()
    [True, False]
    """
    gains = _linear_gains(law, cfg)
    if gains is None or delay_samples not in (0, 1):
        raise InputError(
            f"linear_loop_radii: no linear loop for {law!r} with delay {delay_samples}"
        )
    a, T = cfg.plant.a, cfg.plant.sample_time
    K = np.array([gains])  # noqa: N806

    def loop(r: float) -> NDArray[np.float64]:
        Ad, Bd = zoh_matrices(a * r, T)  # noqa: N806
        if delay_samples == 0:
            return Ad - Bd @ K
        return np.block([[Ad, Bd], [-K, np.zeros((1, 1))]])

    ratios = np.atleast_1d(np.asarray(a_ratio, dtype=float))
    if ratios.size == 0:
        return np.empty(0)
    mats = np.stack([loop(float(r)) for r in ratios])
    return np.abs(np.linalg.eigvals(mats)).max(axis=-1)


def linear_loop_margin(law: str, cfg: Config, *, delay_samples: int = 0) -> dict[str, Any]:
    """Largest interval of a_true / a_design around 1 where the sampled linear loop is stable.

    The linear loop is PD's u = -kp x1 - kd x2 or the PTO's linear zone
    u = -k1 x1 - k2 x2 (eq. 34), unsaturated, on the ZOH plant with the true a
    and the design T; stable means spectral radius < 1 (:func:`linear_loop_radii`).
    With a one-sample computation delay the loop state is (x1, x2, u_{k-1}):
    z_{k+1} = [[Ad, Bd], [-K, 0]] z_k.

    Parameters
    ----------
    law : str
        Law name (TO has no linear loop).
    cfg : Config
        Nominal configuration.
    delay_samples : int
        0 or 1 [samples].

    Returns
    -------
    dict
        ``linear_loop_a_ratio_stable`` (``..._delay1`` with a delay): [lo, hi] with
        each endpoint the last stable ratio to 1e-12 relative (``None`` where
        stability reaches past the searched range [0.1, 10]), or ``None`` with a
        note when there is no linear loop or it is unstable at the design point.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> lo, hi = linear_loop_margin("pd", paper_config())["linear_loop_a_ratio_stable"]
    >>> lo is None and hi > 1.0
    True
    """
    if delay_samples not in (0, 1):
        raise InputError(f"linear_loop_margin: delay_samples must be 0 or 1, got {delay_samples}")
    key = "linear_loop_a_ratio_stable" + ("_delay1" if delay_samples else "")
    note = key.replace("_a_ratio_stable", "_note")
    if _linear_gains(law, cfg) is None:
        return {key: None, note: "no linear loop"}

    def stable(ratios: NDArray) -> NDArray[np.bool_]:
        return linear_loop_radii(law, cfg, ratios, delay_samples=delay_samples) < 1.0

    if not stable(np.array([1.0]))[0]:
        return {key: None, note: "unstable at the design point"}
    lo = _edge(stable, MARGIN_RANGE[0])
    hi = _edge(stable, MARGIN_RANGE[1])
    return {key: [lo, hi], note: ""}


def no_limit_cycle_margin(
    law: LawSpec, cfg: Config, settings: RobustSettings | None = None, *, rtol: float = 1e-3
) -> dict[str, Any]:
    """Interval of a_true / a_design around 1 with no limit cycle from any grid state.

    Saturation, delay and measurement stay nominal (ratio 1, no delay, exact
    measurement) so the interval isolates the bandwidth error.  The property is
    checked on the map's state grid; the endpoints come from a 40-point
    geometric scan of each side (stopping at its first failure) then a
    16-section of the bracket to ``rtol`` relative (:func:`_edges`).

    Parameters
    ----------
    law : str
        Law name.
    cfg : Config
        Nominal configuration.
    settings : RobustSettings, optional
        The state grid.
    rtol : float
        Relative accuracy of the endpoints [-].

    Returns
    -------
    dict
        ``no_limit_cycle_a_ratio``: [lo, hi] (``None`` endpoints beyond [0.1, 10]),
        or ``None`` with a note when the nominal loop already has a limit cycle.
    """
    s = settings or RobustSettings()
    job = _margin_job(_law(law, cfg), cfg, s, rtol=rtol)
    return run_lockstep(
        [job], cfg.plant, horizon_steps(cfg), round_states=BATCH_STATES, reuse=True
    ).results[0]


SCAN_CHUNK = 8  #: scan points of each side tested per step of :func:`_edges`
MARGIN_ASK_RATIOS = 16  #: ratios per simulation ask of a margin (so it rides beside others)


def _margin_job(fn: Law, cfg: Config, s: RobustSettings, *, rtol: float = 1e-3) -> Job:
    """:func:`no_limit_cycle_margin` as a :mod:`ptoverify.sim.lockstep` job (its asks ride along).

    The loop here is odd for an odd law (``Law.odd``; no quantizer, delay or noise),
    so a state and its mirror have the same limit cycle: one state of each
    mirrored pair is simulated (every state for a law not known to be odd).
    """
    x1, x2 = map_states(cfg, s)
    pairs = mirror_pairs(x1, x2) if fn.odd else None
    if pairs:
        x1, x2 = x1[pairs[0]], x2[pairs[0]]
    n = x1.size

    def clean(ratios: NDArray) -> Generator[list[Ask], list[BatchResult], NDArray[np.bool_]]:
        """No limit cycle from any grid state, for each ratio."""
        parts = [
            ratios[i : i + MARGIN_ASK_RATIOS] for i in range(0, ratios.size, MARGIN_ASK_RATIOS)
        ]
        asks = [
            Ask(
                fn,
                np.tile(x1, r.size),
                np.tile(x2, r.size),
                Mismatch(a_ratio=np.repeat(r, n)),
                rider=True,
                stage="margins",
            )
            for r in parts
        ]
        batches = yield asks
        lc = [_limit_cycle_mm(b.x1).reshape(-1, n) for b in batches]  # the property alone
        return ~(np.concatenate(lc) > 0).any(axis=1)

    if not (yield from clean(np.array([1.0])))[0]:
        return {"no_limit_cycle_a_ratio": None, "no_limit_cycle_note": "limit cycles nominally"}
    edges = _edges(grid=40, rtol=rtol)
    ratios = next(edges)
    while True:
        flags = yield from clean(ratios)
        try:
            ratios = edges.send(flags)
        except StopIteration as stop:
            lo, hi = stop.value
            return {"no_limit_cycle_a_ratio": [lo, hi], "no_limit_cycle_note": ""}


def _edges(
    *, grid: int, rtol: float, split: int = 16, chunk: int = SCAN_CHUNK
) -> Generator[NDArray, NDArray[np.bool_], tuple[float | None, float | None]]:
    """Both edges of a property around 1 within :data:`MARGIN_RANGE` (a coroutine).

    Yields arrays of ratios, is sent whether the property holds at each, and
    returns the two edges.  The same edge as :func:`_edge`: the first failing
    point of a ``grid``-point geometric scan from 1 outward, then the bracket
    narrowed to ``rtol``.  The scan advances both sides ``chunk`` points at a
    time and stops a side at its first failure (a point beyond it cannot change
    the edge, so it is not tested); each narrowing round tests ``split - 1``
    interior points of every bracket at once (the bracket shrinks ``split``-fold
    per round instead of 2-fold per test).
    """
    sides = [np.geomspace(1.0, end, grid)[1:] for end in MARGIN_RANGE]
    bad_at: list[int | None] = [None, None]
    at = 0
    while True:
        todo = [i for i in (0, 1) if bad_at[i] is None and at < sides[i].size]
        if not todo:
            break
        chunks = [sides[i][at : at + chunk] for i in todo]
        flags = yield np.concatenate(chunks)
        pos = 0
        for i, c in zip(todo, chunks, strict=True):
            bad = np.flatnonzero(~flags[pos : pos + c.size])
            pos += c.size
            if bad.size:
                bad_at[i] = at + int(bad[0])
        at += chunk
    brackets: list[list[float] | None] = []
    for pts, j in zip(sides, bad_at, strict=True):
        brackets.append(
            None if j is None else [1.0 if j == 0 else float(pts[j - 1]), float(pts[j])]
        )
    live = [b for b in brackets if b is not None]
    while any(abs(b[1] - b[0]) > rtol * min(abs(b[0]), abs(b[1])) for b in live):
        # geometric interior points of each bracket, from its ok end to its failing end
        inner = [b[0] * (b[1] / b[0]) ** (np.arange(1, split) / split) for b in live]
        f = yield np.concatenate(inner)
        for k, b in enumerate(live):
            fk = f[k * (split - 1) : (k + 1) * (split - 1)]
            bad = np.flatnonzero(~fk)
            pts = inner[k]
            if bad.size == 0:
                b[0] = float(pts[-1])
            else:
                j = int(bad[0])
                b[0], b[1] = (b[0] if j == 0 else float(pts[j - 1])), float(pts[j])
    return tuple(None if b is None else b[0] for b in brackets)  # type: ignore[return-value]


# -- worst-case search ---------------------------------------------------------


def worst_case(
    law: LawSpec,
    prop: str,
    cfg: Config,
    grid_worst: list[dict[str, Any]],
    settings: RobustSettings | None = None,
) -> dict[str, Any]:
    """Search the box for the worst value of ``prop`` under ``law``.

    One property of :func:`worst_cases` (see there).

    Parameters
    ----------
    law, prop : str
        Law name and one of :data:`PROPERTIES`.
    cfg : Config
        Nominal configuration with its box.
    grid_worst : list of dict
        Starting points: each ``state`` [x1 mm, x2 mm/s], ``params``
        (``a_ratio``, ``w_max_ratio``, ``delay_samples``) and ``value``.
    settings : RobustSettings, optional
        Population and generations.

    Returns
    -------
    dict
        ``grid`` (the best starting value), ``searched``, ``state`` and ``params``
        (with the full mismatch: quantum, noise, seed), ``evaluations``.
    """
    return worst_cases(law, cfg, {prop: grid_worst}, settings)[prop]


DE_MUTATION = (0.5, 1.0)  #: differential weight F, dithered per generation (scipy's default)
DE_STRATEGY = "rand1bin"
DE_CROSSOVER = 0.7  #: crossover probability CR (scipy's default)
POLISH_ROUNDS = 4  #: rounds of the batched local polish
POLISH_STEP = 0.05  #: first polish step, as a fraction of each variable's range (halved per round)


def latin_hypercube(rng: np.random.Generator, n: int, d: int) -> NDArray[np.float64]:
    """``n`` points in [0, 1)^d, one in each of the ``n`` strata of every coordinate.

    Scrambled Latin hypercube sampling, drawn exactly as SciPy's
    ``scipy.stats.qmc.LatinHypercube(d, rng=rng).random(n)`` draws it (a child
    generator spawned from ``rng``, uniform offsets, one shuffle per coordinate;
    ``tests/test_robust.py`` compares the two), without importing
    ``scipy.stats``, whose import costs more than a second of the report.

    Parameters
    ----------
    rng : numpy.random.Generator
        Parent generator (advanced by one spawn, as SciPy advances it).
    n : int
        Number of points [-].
    d : int
        Dimension [-].

    Returns
    -------
    ndarray of float, shape (n, d)
        The points.

    Examples
    --------
    >>> pts = latin_hypercube(np.random.default_rng(0), 4, 2)
    >>> sorted(np.floor(pts[:, 0] * 4).astype(int).tolist())
    [0, 1, 2, 3]
    """
    child = rng.spawn(1)[0]
    offsets = child.uniform(size=(n, d))
    perms = np.tile(np.arange(1, n + 1), (d, 1))
    for i in range(d):
        child.shuffle(perms[i, :])
    return (perms.T - offsets) / n


def choices_without_replacement(
    rng: np.random.Generator, pop: int, k: int, times: int
) -> NDArray[np.int64]:
    """Draw ``rng.choice(pop, k, replace=False)`` ``times`` times, all at once, as NumPy draws.

    NumPy's ``Generator.choice`` without replacement (no ``p``, ``shuffle=True``,
    ``pop <= 10000`` or ``k <= pop // 50``) runs Floyd's algorithm, one bounded
    integer per j = pop - k, ..., pop - 1 (the value, or j where the value was
    picked already), then shuffles the k picks (Fisher-Yates, one bounded
    integer per i = k - 1, ..., 1).  Each bounded integer in [0, r] (r < 2**32 - 1)
    is Lemire's: the top 32 bits of a 32-bit draw times r + 1, unless the low 32
    bits fall below (2**32 - 1 - r) mod (r + 1), which draws again.  Here the
    2 k - 1 draws of every call are taken at once (``rng.integers`` of 32-bit
    words, the same stream) and Floyd's and the shuffle's steps are done for
    all calls together; where any draw would be redrawn (probability below
    r 2**-32 per draw: about 5e-9 for the search's populations), the generator
    is put back and the calls are made one by one.  Either way the result and
    the generator's state afterwards are those of the loop of calls
    (``tests/test_robust.py`` compares them).

    Parameters
    ----------
    rng : numpy.random.Generator
        Generator (advanced as the calls advance it).
    pop : int
        Population size [-].
    k : int
        Picks per call, ``k <= pop`` [-].
    times : int
        Number of calls [-].

    Returns
    -------
    ndarray of int64, shape (times, k)
        Row c: what the c-th call returns.

    Examples
    --------
    >>> a, b = np.random.default_rng(3), np.random.default_rng(3)
    >>> mine = choices_without_replacement(a, 23, 3, 5)
    >>> ref = [b.choice(23, 3, replace=False).tolist() for _ in range(5)]
    >>> mine.tolist() == ref, a.random() == b.random()
    (True, True)
    """
    if times > 0 and _floyd_is_numpys():
        picks = _floyd_batch(rng, pop, k, times)
        if picks is not None:
            return picks
    return np.array(
        [rng.choice(pop, k, replace=False) for _ in range(times)], dtype=np.int64
    ).reshape(times, k)


def _floyd_batch(
    rng: np.random.Generator, pop: int, k: int, times: int
) -> NDArray[np.int64] | None:
    """Draw as :func:`choices_without_replacement` does, all at once; or return None.

    None (the generator left as it was) where NumPy would not run Floyd's
    algorithm or a draw would be redrawn.
    """
    top = 0xFFFFFFFF
    # Floyd's bounds r = pop - k .. pop - 1 and the shuffle's k - 1 .. 1 all draw
    # (r >= 1) by Lemire's 32-bit method (r < 2**32 - 1) when Floyd's algorithm runs
    # (k = 0 draws nothing: NumPy's own call)
    if not (
        times > 0 and k >= 1 and 1 <= pop - k and pop - 1 < top and (pop <= 10000 or k <= pop // 50)
    ):
        return None
    state = rng.bit_generator.state
    bounds = [pop - k + t for t in range(k)] + list(range(k - 1, 0, -1))
    words = rng.integers(0, top + 1, size=(times, len(bounds)), dtype=np.uint32)
    # Lemire: m = word (r + 1), the value m >> 32, redrawn where the low word is
    # below (2**32 - 1 - r) mod (r + 1); every bound of every call at once
    m = words.astype(np.uint64)
    m *= np.array([r + 1 for r in bounds], dtype=np.uint64)
    low = m & np.uint64(top)
    if (low < np.array([(top - r) % (r + 1) for r in bounds], dtype=np.uint64)).any():
        rng.bit_generator.state = state
        return None
    m >>= np.uint64(32)
    vals = m.astype(np.int64).T  # row c: the value of bound c in each call
    picks = np.empty((times, k), dtype=np.int64)
    picks[:, 0] = vals[0]
    for t in range(1, k):  # Floyd: the value, or j = pop - k + t where it is taken
        taken = (picks[:, :t] == vals[t][:, None]).any(axis=1)
        picks[:, t] = np.where(taken, pop - k + t, vals[t])
    rows = np.arange(times)
    for c, i in enumerate(range(k - 1, 0, -1)):  # the shuffle: swap picks i, j
        j = vals[k + c]
        held = picks[rows, j]
        picks[rows, j] = picks[:, i]
        picks[:, i] = held
    return picks


@functools.cache
def _floyd_is_numpys() -> bool:
    """Whether this NumPy's ``Generator.choice`` draws as :func:`_floyd_batch` does.

    The batch follows NumPy's algorithm, which a NumPy release may change; it is
    checked once per process on a few cases (draws and the generator's state
    after them), and where it differs every draw is NumPy's own call.
    """
    for pop, k in ((23, 3), (7, 2), (200, 4)):
        a, b = np.random.default_rng(pop), np.random.default_rng(pop)
        mine = _floyd_batch(a, pop, k, 16)
        ref = [b.choice(pop, k, replace=False).tolist() for _ in range(16)]
        if mine is None or mine.tolist() != ref or a.random() != b.random():
            return False
    return True


def _distinct_others(rng: np.random.Generator, n_pop: int, k: int) -> NDArray[np.int64]:
    """Per member i, ``k`` distinct other members: ``rng.choice`` of the others, draw for draw.

    ``rng.choice(n_pop - 1, k, replace=False)`` draws exactly what
    ``rng.choice(np.delete(np.arange(n_pop), i), k, replace=False)`` draws (the
    choice depends only on the population size), shifted past i; the n_pop calls
    are drawn together (:func:`choices_without_replacement`).
    """
    out = choices_without_replacement(rng, n_pop - 1, k, n_pop)
    out += out >= np.arange(n_pop)[:, None]
    return out


def _box_bounds(cfg: Config, prop: str) -> tuple[NDArray, NDArray]:
    """Bounds of (x1 [mm], x2 [mm/s], a_ratio, w_max_ratio) searched for ``prop``."""
    box, p = cfg.robustness, cfg.plant
    R, w, d = p.position_range, p.w_max, cfg.pto.d
    if prop == "overshoot_mm":  # from rest, d <= x1_0 (odd laws: the sign is symmetric)
        lo = [max(d, 1e-3 * R), 0.0, box.a_ratio[0], box.w_max_ratio[0]]
        hi = [R, 0.0, box.a_ratio[1], box.w_max_ratio[1]]
    else:
        lo = [-R, -w, box.a_ratio[0], box.w_max_ratio[0]]
        hi = [R, w, box.a_ratio[1], box.w_max_ratio[1]]
    return np.array(lo, dtype=float), np.array(hi, dtype=float)


def worst_cases(
    law: LawSpec,
    cfg: Config,
    starts: dict[str, list[dict[str, Any]]],
    settings: RobustSettings | None = None,
) -> dict[str, dict[str, Any]]:
    """Search the box for the worst value of each property in ``starts`` under ``law``.

    Variables: x1_0 [mm], x2_0 [mm/s] (for ``overshoot_mm`` x2_0 = 0 and
    d <= x1_0 <= position_range), a_ratio, w_max_ratio; each delay of the box is
    searched separately.  Per property and delay, a differential evolution
    (strategy best/1/bin, F dithered in [0.5, 1], CR 0.7, as scipy's
    ``differential_evolution`` defaults; out-of-bounds trials resampled
    uniformly; deferred updating) whose initial population holds the grid's
    worst cells of that delay and uniform samples (seed ``box.seed``), then a
    batched local polish (:data:`POLISH_ROUNDS` rounds of Gaussian and compass
    steps around the best, the step halving each round).  All the
    (property, delay) searches advance in lockstep and each generation is one
    batch simulation; every trajectory simulated counts toward every
    property's worst (the settling ratio only where it was computed: in the
    settling searches), so a property's value is the worst over all evaluated
    points of the box, never below the grid's worst (the grid's cells are in
    the first population).

    Parameters
    ----------
    law : str or callable
        Law name, or a factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration with its box.
    starts : dict
        Property (of :data:`PROPERTIES`) -> starting points (:func:`grid_worst`):
        each ``state`` [x1 mm, x2 mm/s], ``params`` (``a_ratio``, ``w_max_ratio``,
        ``delay_samples``) and ``value``.
    settings : RobustSettings, optional
        Population and generations.

    Returns
    -------
    dict
        Per property: ``grid`` (the best starting value), ``searched``, ``state``
        and ``params`` (with the full mismatch: quantum, noise, seed),
        ``evaluations`` (trajectories simulated by this search, all properties).
    """
    s = settings or RobustSettings()
    job = _searches_job([_law(law, cfg)], cfg, [starts], s)
    run = run_lockstep([job], cfg.plant, horizon_steps(cfg), round_states=BATCH_STATES, reuse=True)
    return run.results[0][0]


#: A search coroutine: yields (candidates (S, 4), delays (S,), settle mask (S,)), is sent
#: the measured properties of those candidates, returns the per-property worst cases.
_Search = Generator[tuple[NDArray, NDArray, NDArray], dict[str, NDArray], dict[str, Any]]


def _searches_job(
    fns: list[Law],
    cfg: Config,
    starts: list[dict[str, list[dict[str, Any]]]],
    s: RobustSettings,
) -> Job:
    """Run the worst-case searches of several laws as one :mod:`ptoverify.sim.lockstep` job.

    Each law's search is its own coroutine (:func:`_de_search`, with its own
    seeded generator, so its result does not depend on the others); at each
    step every law's candidates are one ask and all are measured together.
    Returns the list of :func:`worst_cases` results, in the order of ``fns``.
    """
    box = cfg.robustness
    searches = [_de_search(cfg, st, s) for st in starts]
    results: list[Any] = [None] * len(searches)
    sent: list[dict[str, NDArray] | None] = [None] * len(searches)
    live = list(range(len(searches)))
    while True:
        asked = []
        for i in live:
            try:
                z, delay, settle = (
                    next(searches[i]) if sent[i] is None else searches[i].send(sent[i])
                )
            except StopIteration as stop:
                results[i] = stop.value
                continue
            asked.append((i, z, delay, settle))
        if not asked:
            return results
        live = [i for i, *_ in asked]
        Z = np.concatenate([z for _, z, _, _ in asked])  # noqa: N806
        m = Mismatch(
            a_ratio=Z[:, 2],
            w_max_ratio=Z[:, 3],
            delay_samples=np.concatenate([d for _, _, d, _ in asked]),
            position_quantum=box.position_quantum,
            velocity_noise=box.velocity_noise,
            seed=box.seed,
        )
        x1, x2 = Z[:, 0].copy(), Z[:, 1].copy()
        edges = np.cumsum([0, *(len(z) for _, z, _, _ in asked)]).tolist()
        asks = []
        for (i, z, delay, _), lo, hi in zip(asked, edges[:-1], edges[1:], strict=True):
            part = Mismatch(
                a_ratio=Z[lo:hi, 2],
                w_max_ratio=Z[lo:hi, 3],
                delay_samples=delay,
                position_quantum=box.position_quantum,
                velocity_noise=box.velocity_noise,
                seed=box.seed,
            )
            asks.append(Ask(fns[i], x1[lo:hi], x2[lo:hi], part, stage="worst_case"))
        batches = yield asks
        both = BatchResult(
            *(
                np.concatenate([getattr(b, f) for b in batches], axis=1)
                for f in ("x1", "x2", "u", "region")
            )
        )
        out = _measure(
            both, cfg, x1, x2, m, np.concatenate([st for *_, st in asked]), with_tf=False
        )
        for (i, *_), lo, hi in zip(asked, edges[:-1], edges[1:], strict=True):
            sent[i] = {k: v[lo:hi] for k, v in out.items()}


def _together(jobs: list[Job]) -> Job:
    """Run several jobs as one: each step asks what all live jobs ask; returns their results."""
    results: list[Any] = [None] * len(jobs)
    sent: list[Any] = [None] * len(jobs)
    live = list(range(len(jobs)))
    while True:
        asked = []
        for i in live:
            try:
                asked.append((i, next(jobs[i]) if sent[i] is None else jobs[i].send(sent[i])))
            except StopIteration as stop:
                results[i] = stop.value
        if not asked:
            return results
        live = [i for i, _ in asked]
        batches = yield [a for _, asks in asked for a in asks]
        at = 0
        for i, asks in asked:
            sent[i] = batches[at : at + len(asks)]
            at += len(asks)


def _study_job(
    fns: list[Law], cfg: Config, s: RobustSettings, cells: list[list[dict[str, Any]]] | None
) -> Job:
    """Every law's maps (unless given), then their worst-case searches: (cells, worst) per law."""
    if cells is None:
        x1, x2 = map_states(cfg, s)
        axes = _map_axes(cfg, s)
        cells = yield from _together([_maps_job(fn, cfg, x1, x2, *axes) for fn in fns])
    starts = [{prop: grid_worst(c, prop) for prop in s.properties} for c in cells]
    worst = yield from _searches_job(fns, cfg, starts, s)
    return list(zip(cells, worst, strict=True))


def _de_search(cfg: Config, starts: dict[str, list[dict[str, Any]]], s: RobustSettings) -> _Search:
    """Run the search of :func:`worst_cases` for one law as a coroutine (see :data:`_Search`)."""
    box = cfg.robustness
    props = list(starts)
    delays = list(range(box.delay_samples[0], box.delay_samples[1] + 1))
    problems = [(prop, dl) for prop in props for dl in delays]
    bounds = [_box_bounds(cfg, prop) for prop, _ in problems]
    rng = np.random.default_rng(box.seed)
    best = {prop: {"value": -math.inf, "z": None, "delay": delays[0]} for prop in props}
    count = 0

    def evaluate(pops: list[NDArray]) -> _Search:
        """Each problem's population (S_i, 4) -> its values (S_i,), larger is worse."""
        nonlocal count
        Z = np.concatenate(pops)  # noqa: N806
        sizes = [len(z) for z in pops]
        owner = np.repeat(np.arange(len(pops)), sizes)
        delay = np.array([problems[i][1] for i in owner], dtype=np.int64)
        settle = np.array([problems[i][0].startswith("settling") for i in owner])
        out = yield Z, delay, settle  # the driver simulates and measures them
        count += len(Z)
        for prop in props:  # every trajectory counts toward every property's worst
            v = np.where(np.isnan(out[prop]), -np.inf, out[prop])
            k = int(np.argmax(v))
            if v[k] > best[prop]["value"]:
                best[prop].update(value=float(v[k]), z=Z[k].copy(), delay=int(delay[k]))
        edges = np.cumsum([0, *sizes])
        res = []
        for i, (prop, _) in enumerate(problems):
            v = out[prop][edges[i] : edges[i + 1]]
            res.append(np.where(np.isnan(v), -np.inf, v))
        return res

    # initial populations: the grid's worst cells of the problem's delay, then uniform
    pops, grid_value = [], {}
    for (prop, dl), (lo, hi) in zip(problems, bounds, strict=True):
        lhs = latin_hypercube(rng, s.search_population, 4)
        pop = lo + (hi - lo) * lhs
        mine = [g for g in starts[prop] if int(g["params"]["delay_samples"]) == dl]
        for i, g in enumerate(mine[: s.search_population]):
            z = np.array([*g["state"], g["params"]["a_ratio"], g["params"]["w_max_ratio"]])
            if prop == "overshoot_mm":
                z[0], z[1] = abs(z[0]), 0.0
            pop[i] = np.clip(z, lo, hi)
        pops.append(pop)
    for prop in props:
        vals = [float(g["value"]) for g in starts[prop]]
        grid_value[prop] = max(vals) if vals else -math.inf
    fit = yield from evaluate(pops)
    for _ in range(s.search_iterations):
        f_weight = rng.uniform(*DE_MUTATION)
        trials = []
        for pop, f, (lo, hi) in zip(pops, fit, bounds, strict=True):
            n_pop = len(pop)
            b = pop[int(np.argmax(f))] if DE_STRATEGY == "best1bin" else None
            # the best/1 donors are drawn whatever the strategy (the seeded stream stays
            # that of the published runs), then rand/1's three
            r = _distinct_others(rng, n_pop, 2)
            if b is None:
                r = _distinct_others(rng, n_pop, 3)
                mutant = pop[r[:, 2]] + f_weight * (pop[r[:, 0]] - pop[r[:, 1]])
            else:
                mutant = b + f_weight * (pop[r[:, 0]] - pop[r[:, 1]])
            cross = rng.random(pop.shape) < DE_CROSSOVER
            cross[np.arange(n_pop), rng.integers(0, 4, n_pop)] = True
            trial = np.where(cross, mutant, pop)
            outside = (trial < lo) | (trial > hi)
            trial = np.where(outside, lo + (hi - lo) * rng.random(pop.shape), trial)
            trials.append(trial)
        tfit = yield from evaluate(trials)
        for i in range(len(pops)):
            better = tfit[i] >= fit[i]
            pops[i][better], fit[i][better] = trials[i][better], tfit[i][better]
    # batched polish around each problem's best
    centre = [pop[int(np.argmax(f))].copy() for pop, f in zip(pops, fit, strict=True)]
    cval = [float(np.max(f)) for f in fit]
    for rnd in range(POLISH_ROUNDS):
        step = POLISH_STEP * 0.5**rnd
        cands = []
        for c, (lo, hi) in zip(centre, bounds, strict=True):
            span = (hi - lo) * step
            compass = c + np.concatenate([np.diag(span), -np.diag(span)])
            gauss = c + span * rng.standard_normal((max(s.search_population - 8, 1), 4))
            cands.append(np.clip(np.concatenate([compass, gauss]), lo, hi))
        cfit = yield from evaluate(cands)
        for i in range(len(centre)):
            k = int(np.argmax(cfit[i]))
            if cfit[i][k] > cval[i]:
                centre[i], cval[i] = cands[i][k].copy(), float(cfit[i][k])
    out: dict[str, dict[str, Any]] = {}
    for prop in props:
        g, z = grid_value[prop], best[prop]["z"]
        searched = best[prop]["value"]
        out[prop] = {
            "grid": g if g > -math.inf else None,
            "grid_unbounded": g == math.inf,
            "searched": searched if searched > -math.inf else None,
            "unbounded": searched == math.inf,  # e.g. never settles: JSON shows searched null
            "state": [float(z[0]), float(z[1])] if z is not None else None,
            "params": {
                "a_ratio": float(z[2]) if z is not None else None,
                "w_max_ratio": float(z[3]) if z is not None else None,
                "delay_samples": int(best[prop]["delay"]),
                "position_quantum": box.position_quantum,
                "velocity_noise": box.velocity_noise,
                "seed": box.seed,
            },
            "evaluations": count,
        }
    return out


def grid_worst(cells: list[dict[str, Any]], prop: str, k: int = 4) -> list[dict[str, Any]]:
    """Return the ``k`` worst cells of a map for ``prop`` as search starting points.

    Parameters
    ----------
    cells : list of dict
        Cell summaries of one law (``robust_maps(...)["laws"][law]``).
    prop : str
        One of :data:`PROPERTIES`.
    k : int
        How many cells.

    Returns
    -------
    list of dict
        ``state`` [x1 mm, x2 mm/s], ``value``, ``params`` of each cell, worst first.
    """
    scored = [c for c in cells if math.isfinite(c[prop]["max"])]
    scored.sort(key=lambda c: -c[prop]["max"])
    return [
        {
            "state": c[prop]["state"],
            "value": c[prop]["max"],
            "params": {
                "a_ratio": c["a_ratio"],
                "w_max_ratio": c["w_max_ratio"],
                "delay_samples": c["delay_samples"],
            },
        }
        for c in scored[:k]
    ]


# -- the whole study -----------------------------------------------------------


@dataclass(frozen=True)
class RobustResult:
    """Everything ``ptoverify robust`` computes.

    Attributes
    ----------
    config : Config
        The nominal configuration (with its box).
    settings : RobustSettings
        Sizes of the study.
    maps : dict
        :func:`robust_maps`.
    margins : dict
        Per law: :func:`linear_loop_margin` and :func:`no_limit_cycle_margin`.
    worst : dict
        Per law and property: :func:`worst_case`.
    timings_s : dict
        Wall time per stage [s].
    backend : str
        ``in-process`` or the Dask scheduler used.
    """

    config: Config
    settings: RobustSettings
    maps: dict[str, Any]
    margins: dict[str, Any]
    worst: dict[str, Any]
    timings_s: dict[str, float] = field(default_factory=dict)
    backend: str = "in-process"

    def to_json(self) -> dict[str, Any]:
        """Return the JSON of ``ptoverify robust --json`` (non-finite numbers as None)."""
        return _finite(
            {
                "box": self.config.robustness.to_mapping(),
                "margins": self.margins,
                "worst": self.worst,
                "maps": self.maps,
                "most_robust": most_robust(self.margins),
                "timings_s": self.timings_s,
                "backend": self.backend,
            }
        )


def _finite(v: Any) -> Any:
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, np.floating):
        return _finite(float(v))
    if isinstance(v, np.integer):
        return int(v)
    return v


def most_robust(margins: dict[str, Any]) -> dict[str, Any]:
    """Which law's linear loop tolerates the widest bandwidth error (log-width of the interval).

    Parameters
    ----------
    margins : dict
        Per law, the output of :func:`linear_loop_margin`.

    Returns
    -------
    dict
        ``law`` and ``log_width`` per law (ln(hi/lo), endpoints beyond the searched
        range taken at the range's ends), or ``law`` None when no law has a margin.
    """
    widths: dict[str, float] = {}
    for law, m in margins.items():
        iv = m.get("linear_loop_a_ratio_stable")
        if iv is None:
            continue
        lo = iv[0] if iv[0] is not None else MARGIN_RANGE[0]
        hi = iv[1] if iv[1] is not None else MARGIN_RANGE[1]
        widths[law] = math.log(hi / lo)
    if not widths:
        return {"law": None, "log_width": {}}
    return {"law": max(widths, key=widths.get), "log_width": widths}


def run_robust(
    cfg: Config,
    settings: RobustSettings | None = None,
    *,
    dask: str | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> RobustResult:
    """Run the robustness study: maps, margins and worst cases.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box (``[robustness]``).
    settings : RobustSettings, optional
        Sizes of the study.
    dask : str, optional
        Scheduler address or ``local`` to distribute the maps on Dask; None runs in-process.
    progress : callable, optional
        ``progress(stage, fraction)``.

    Returns
    -------
    RobustResult
        The study.
    """
    s = settings or RobustSettings()
    report = progress or (lambda stage, frac: None)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    report("margins", 0.0)
    linear = {
        law: {
            **linear_loop_margin(law, cfg),
            **linear_loop_margin(law, cfg, delay_samples=1),
        }
        for law in s.laws
    }
    t_linear = time.perf_counter() - t0
    cells: dict[Any, list[dict[str, Any]]] = {}
    if dask:
        report("maps", 0.05)
        t1 = time.perf_counter()
        cells = robust_maps(cfg, s, runner=dask_runner(dask))["laws"]
        timings["maps"] = time.perf_counter() - t1
    # every law's maps, search and margin scan advance together: one simulation per
    # round, in which the margin scans ride along (ptoverify.sim.lockstep)
    fns = [_law(law, cfg) for law in s.laws]
    given = [cells[law] for law in s.laws] if dask else None
    jobs = [_study_job(fns, cfg, s, given)]
    if s.margins:
        jobs += [_margin_job(fn, cfg, s) for fn in fns]
    run = run_lockstep(
        jobs,
        cfg.plant,
        horizon_steps(cfg),
        round_states=BATCH_STATES,
        reuse=True,  # the jobs keep measured values only, never the trajectories
        on_round=lambda r, done, total: report(
            "maps, margins, worst cases", 0.1 + 0.9 * done / total
        ),
    )
    study = run.results[0]
    maps = _maps_dict(cfg, s, {law: study[i][0] for i, law in enumerate(s.laws)})
    worst = {law: study[i][1] for i, law in enumerate(s.laws)}
    margins = (
        {law: linear[law] | run.results[1 + i] for i, law in enumerate(s.laws)} if s.margins else {}
    )
    if not dask:
        timings["maps"] = run.seconds.get("maps", 0.0)
    timings["margins"] = (t_linear if s.margins else 0.0) + run.seconds.get("margins", 0.0)
    timings["worst_case"] = run.seconds.get("worst_case", 0.0)
    timings["total"] = time.perf_counter() - t0
    return RobustResult(cfg, s, maps, margins, worst, timings, dask or "in-process")


# -- gates ---------------------------------------------------------------------

GATE_LAW = "pto"  #: the law the robustness gates judge (the corrected PTO)


def describe_case(case: dict[str, Any]) -> str:
    """Describe a worst case in words, with units (no Python repr).

    Parameters
    ----------
    case : dict
        A :func:`worst_case` entry (``state`` [mm, mm/s] and ``params``).

    Returns
    -------
    str
        E.g. "x0 = (48.01 mm, -87.3 mm/s), a_true/a = 1.25, drive limit 1 w_max, delay
        1 sample, encoder 0.001 mm, velocity noise 0 mm/s (seed 0)".

    Examples
    --------
    >>> describe_case({"state": [1.0, -2.0], "params": {"a_ratio": 1.25, "w_max_ratio": 1.0,
    ...     "delay_samples": 1, "position_quantum": 0.001, "velocity_noise": 0.0, "seed": 0}})
    'x0 = (1 mm, -2 mm/s), a_true/a = 1.25, drive limit 1 w_max, delay 1 sample(s), encoder 0.001 mm, velocity noise 0 mm/s (seed 0)'
    """
    x = case.get("state") or [float("nan"), float("nan")]
    p = case.get("params") or {}

    def g(v: Any) -> str:
        return "?" if v is None else f"{float(v):.4g}"

    return (
        f"x0 = ({g(x[0])} mm, {g(x[1])} mm/s), a_true/a = {g(p.get('a_ratio'))}, "
        f"drive limit {g(p.get('w_max_ratio'))} w_max, delay {p.get('delay_samples')} sample(s), "
        f"encoder {g(p.get('position_quantum'))} mm, velocity noise "
        f"{g(p.get('velocity_noise'))} mm/s (seed {p.get('seed')})"
    )


def robust_gates(result: RobustResult, law: str = GATE_LAW) -> list[Verdict]:
    """Judge the box: ``robust-no-limit-cycle`` and ``robust-settling`` for ``law``.

    Parameters
    ----------
    result : RobustResult
        A study that includes ``law``.
    law : str
        The law judged.

    Returns
    -------
    list of Verdict
        ``robust-no-limit-cycle``: the worst searched limit-cycle amplitude [mm]
        must be 0 (no limit cycle anywhere in the box); ``robust-settling``: the
        worst searched settling / N*T [-] must be within ``settling_ratio_limit``
        (a trajectory that never settles fails).  A property the search could not
        evaluate is ``unverified``.
    """
    box = result.config.robustness
    worst = result.worst.get(law, {})
    out = []
    lc = worst.get("limit_cycle_mm", {})
    v = lc.get("searched")
    where = f" at {describe_case(lc)}" if v else ""
    if v is None:
        out.append(
            Verdict(
                "robust-no-limit-cycle",
                UNVERIFIED,
                None,
                0.0,
                f"{law}: the worst-case search did not evaluate the limit-cycle amplitude",
                "<=",
                "mm",
            )
        )
    else:
        out.append(
            Verdict(
                "robust-no-limit-cycle",
                PASS if v <= 0.0 else FAIL,
                float(v),
                0.0,
                f"{law}: largest limit-cycle amplitude found in the box (grid, then "
                f"differential evolution){where}",
                "<=",
                "mm",
            )
        )
    st = worst.get("settling_ratio_nt", {})
    v = st.get("searched")
    limit = box.settling_ratio_limit
    if v is None and not st.get("unbounded"):
        out.append(
            Verdict(
                "robust-settling",
                UNVERIFIED,
                None,
                limit,
                f"{law}: the worst-case search did not evaluate settling / N*T",
                "<=",
                "1",
            )
        )
    else:
        value = math.inf if st.get("unbounded") else float(v)
        out.append(
            Verdict(
                "robust-settling",
                PASS if value <= limit else FAIL,
                value,
                limit,
                f"{law}: worst settling time / N*T of the true plant found in the box "
                f"(inf: never settles) at {describe_case(st)}; "
                f"limit from [robustness] settling_ratio_limit",
                "<=",
                "1",
            )
        )
    return out
