"""Robustness maps: per-trajectory properties on mismatched plants, over a grid.

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
times a grid of initial states, every state simulated (no mirror pairing).
Simulations go through :func:`evaluate_probes`
(:func:`ptoverify.sim.lockstep.simulate_asks`), which the margins and the
worst-case search use too.  N* of the true plants comes from
:func:`ptoverify.model.reach.zonotope_steps_each` (a plant per state, one
vectorized search), the stride-overs from
:func:`ptoverify.studies.properties.stride_over_counts`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.laws import Law
from ptoverify.sim.lockstep import Ask, simulate_asks
from ptoverify.sim.simulate import BatchResult, Mismatch
from ptoverify.studies.robust.results import MapCell, PropertyMax, RobustMaps
from ptoverify.studies.robust.trajectory import (
    SETTLING,
    LawSpec,
    _limit_cycle_mm,
    _measure,
    horizon_steps,
    nominal_law,
    trajectory_properties,
)
from ptoverify.studies.sweep import even_points

__all__ = [
    "LAWS",
    "PROPERTIES",
    "RobustSettings",
    "Probe",
    "evaluate_probes",
    "trajectory_properties",
    "horizon_steps",
    "MAX_BOX_WORK",
    "box_work",
    "check_box_work",
    "map_states",
    "robust_maps",
    "BATCH_STATES",
    "map_cells",
    "maps_dict",
    "SETTLING",
    "LawSpec",
    "nominal_law",
]

LAWS = ("to", "pd", "pto", "pto-printed")
#: Properties searched for their worst case (larger is worse for each).
PROPERTIES = ("stride_overs", "limit_cycle_mm", "overshoot_mm", "settling_ratio_nt")


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


#: Most perturbation cells x horizon samples a robustness study may need [cell-samples]:
#: the default box (30 cells) at the longest horizon the loader lets through (about 12,000
#: samples, range / (w_max T) = 2000 and a T = 0.01) needs 360,000.
MAX_BOX_WORK = 400_000


def box_work(cfg: Config, s: RobustSettings | None = None) -> tuple[int, int]:
    """Return the perturbation cells of the maps and the horizon of every trajectory.

    The study's time grows with their product (every search, margin scan and
    map cell simulates :func:`horizon_steps` samples per state).

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    s : RobustSettings, optional
        Grid sizes (n_a, n_w).

    Returns
    -------
    cells : int
        a_ratio x w_max_ratio x delay values of the maps [-].
    horizon : int
        Samples simulated per trajectory [samples].
    """
    ars, wrs, delays = _map_axes(cfg, s or RobustSettings())
    return len(ars) * len(wrs) * len(delays), horizon_steps(cfg)


def check_box_work(cfg: Config, s: RobustSettings | None = None) -> None:
    """Raise InputError, before any simulation, when the box needs more than :data:`MAX_BOX_WORK`.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    s : RobustSettings, optional
        Grid sizes (n_a, n_w).

    Raises
    ------
    InputError
        Naming the ``[robustness]`` keys that set the work and the limit.
    """
    cells, horizon = box_work(cfg, s)
    if cells * horizon <= MAX_BOX_WORK:
        return
    box = cfg.robustness
    n_delay = box.delay_samples[1] - box.delay_samples[0] + 1
    raise InputError(
        f"config key 'robustness.delay_samples' = {list(box.delay_samples)} gives {cells} "
        f"perturbation cells ({n_delay} delays x a_ratio x w_max_ratio values) and "
        f"'robustness.a_ratio' / 'robustness.w_max_ratio' down to {box.a_ratio[0]:g} / "
        f"{box.w_max_ratio[0]:g} a horizon of {horizon:,} samples: {cells * horizon:,} "
        f"cell-samples, over the limit of {MAX_BOX_WORK:,} (narrow the delays or raise "
        "the lower ratios)"
    )


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


def _summarize(
    props: dict[str, NDArray], x1: NDArray, x2: NDArray, cell: tuple[int, float, float]
) -> MapCell:
    """Summarize one map cell's per-state properties; ``cell`` is (delay, w_ratio, a_ratio)."""
    worst = {}
    for key in PROPERTIES:
        v = props[key]
        fin = v[~np.isnan(v)]
        k = int(np.nanargmax(np.where(np.isnan(v), -np.inf, v)))
        worst[key] = (float(fin.max()) if fin.size else math.nan, (float(x1[k]), float(x2[k])))
    r = props["settling_ratio_nt"]
    dl, wr, ar = cell
    return MapCell(
        a_ratio=ar,
        w_max_ratio=wr,
        delay_samples=dl,
        stride_overs=PropertyMax(*worst["stride_overs"]),
        limit_cycle_mm=PropertyMax(*worst["limit_cycle_mm"]),
        overshoot_mm=PropertyMax(*worst["overshoot_mm"]),
        settling_ratio_nt=PropertyMax(
            *worst["settling_ratio_nt"],
            median=float(np.median(r)),
            p95=float(np.percentile(r, 95, method="higher")),
        ),
        states_with_stride_over=int((props["stride_overs"] > 0).sum()),
        limit_cycle_states=int((props["limit_cycle_mm"] > 0).sum()),
        not_settled=int(np.isinf(props["settling_s"]).sum()),
    )


BATCH_STATES = 16384  #: most states simulated at once (memory: ~25 bytes x states x horizon)


@dataclass(frozen=True)
class Probe:
    """Initial states of one law on mismatched plants, to simulate and measure.

    Attributes
    ----------
    ask : Ask
        The law, initial states [mm], [mm/s] and mismatch (per-state arrays allowed).
    settle : bool
        Also measure the settling ratio (needs N* of each true plant).
    cycles_only : bool
        Measure the limit-cycle amplitude only (the margin scans need nothing else).
    """

    ask: Ask
    settle: bool = True
    cycles_only: bool = False


def evaluate_probes(
    cfg: Config,
    probes: Sequence[Probe],
    *,
    seconds: dict[str, float] | None = None,
) -> list[dict[str, NDArray[np.float64]]]:
    """Simulate probes over :func:`horizon_steps` and measure each trajectory.

    The one simulation path of the study: maps, margins and the worst-case search
    all come here (:func:`ptoverify.sim.lockstep.simulate_asks`, runs of at most
    :data:`BATCH_STATES` states).  Each state's properties are those of
    :func:`trajectory_properties` for it alone (``settling_ratio_tf`` left out).

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    probes : sequence of Probe
        What to simulate.
    seconds : dict, optional
        Wall time [s] added per ask stage.

    Returns
    -------
    list of dict
        Per probe, arrays of shape (n,): ``stride_overs`` [-], ``limit_cycle_mm`` [mm],
        ``overshoot_mm`` [mm], and with ``settle`` ``settling_s`` [s] and
        ``settling_ratio_nt`` [-]; with ``cycles_only`` ``limit_cycle_mm`` alone.
    """

    def measure(k: int, b: BatchResult) -> dict[str, NDArray[np.float64]]:
        ask = probes[k].ask
        if probes[k].cycles_only:
            return {"limit_cycle_mm": _limit_cycle_mm(b.x1)}
        return _measure(b, cfg, ask.x1, ask.x2, b.mismatch, probes[k].settle, with_tf=False)

    return simulate_asks(
        [p.ask for p in probes],
        cfg.plant,
        horizon_steps(cfg),
        measure,
        round_states=BATCH_STATES,
        seconds=seconds,
    )


def _map_axes(cfg: Config, s: RobustSettings) -> tuple[list[float], list[float], list[int]]:
    """Return the perturbation grid of the maps: a_ratio, w_max_ratio and delay values."""
    box = cfg.robustness
    ars = _ratio_grid(*box.a_ratio, s.n_a).tolist()
    wrs = _ratio_grid(*box.w_max_ratio, s.n_w).tolist()
    return ars, wrs, list(range(box.delay_samples[0], box.delay_samples[1] + 1))


def _map_probes(fn: Law, cfg: Config, s: RobustSettings) -> tuple[list[Probe], list[tuple]]:
    """Every map cell of one law as probes: all states of a cell, cells in rows of a probe.

    Cells in the order delay, w_max_ratio, a_ratio, each (delay, w_max_ratio,
    a_ratio); a probe holds as many whole cells as fit in :data:`BATCH_STATES`.
    """
    box = cfg.robustness
    x1, x2 = map_states(cfg, s)
    ars, wrs, delays = _map_axes(cfg, s)
    cells = [(int(dl), float(wr), float(ar)) for dl in delays for wr in wrs for ar in ars]
    n = x1.size
    per = max(1, BATCH_STATES // max(n, 1))
    probes = []
    for i in range(0, len(cells), per):
        part = cells[i : i + per]
        m = Mismatch(
            a_ratio=np.repeat([ar for _, _, ar in part], n),
            w_max_ratio=np.repeat([wr for _, wr, _ in part], n),
            delay_samples=np.repeat([dl for dl, _, _ in part], n),
            position_quantum=box.position_quantum,
            velocity_noise=box.velocity_noise,
            seed=box.seed,
        )
        ask = Ask(fn, np.tile(x1, len(part)), np.tile(x2, len(part)), m, stage="maps")
        probes.append(Probe(ask, settle=True))
    return probes, cells


def _map_cells(
    cfg: Config, s: RobustSettings, cells: list[tuple], props: list[dict[str, NDArray]]
) -> tuple[MapCell, ...]:
    """Summarize the measured probes of :func:`_map_probes` cell by cell."""
    x1, x2 = map_states(cfg, s)
    n = x1.size
    flat = {k: np.concatenate([p[k] for p in props]) for k in props[0]}
    return tuple(
        _summarize({k: v[i * n : (i + 1) * n] for k, v in flat.items()}, x1, x2, cell)
        for i, cell in enumerate(cells)
    )


def map_cells(
    laws: Sequence[LawSpec],
    cfg: Config,
    s: RobustSettings,
    *,
    seconds: dict[str, float] | None = None,
) -> list[tuple[MapCell, ...]]:
    """Return every map cell of each law, all laws' probes simulated together.

    Parameters
    ----------
    laws : sequence of str or callable
        Law names or factories ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration with its box.
    s : RobustSettings
        Grid sizes.
    seconds : dict, optional
        Wall time [s] added to stage ``maps``.

    Returns
    -------
    list of tuple of MapCell
        Per law, its cells in the order delay, w_max_ratio, a_ratio.
    """
    made = [_map_probes(nominal_law(law, cfg), cfg, s) for law in laws]
    props = evaluate_probes(cfg, [p for probes, _ in made for p in probes], seconds=seconds)
    out, at = [], 0
    for probes, cells in made:
        out.append(_map_cells(cfg, s, cells, props[at : at + len(probes)]))
        at += len(probes)
    return out


def map_task(law: LawSpec, cfg: Config, s: RobustSettings) -> tuple[MapCell, ...]:
    """Return every map cell of one law: the picklable unit a Dask runner distributes.

    Parameters
    ----------
    law : str or callable
        Law name or factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration with its box.
    s : RobustSettings
        Grid sizes.

    Returns
    -------
    tuple of MapCell
        The law's cells (:func:`map_cells`).
    """
    return map_cells([law], cfg, s)[0]


Runner = Callable[[list[tuple]], list[Any]]


def robust_maps(
    cfg: Config,
    settings: RobustSettings | None = None,
    *,
    runner: Runner | None = None,
) -> RobustMaps:
    """Evaluate every law on a grid of perturbations times a grid of initial states.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    settings : RobustSettings, optional
        Grid sizes and laws.
    runner : callable, optional
        ``runner(tasks) -> results`` evaluating every cell of one law per task
        (``(law, cfg, settings)``), in order: in-process by default;
        :func:`ptoverify.studies.robust.cluster.dask_runner` distributes them.  A state's properties do not depend on
        the states simulated with it, so the maps do not depend on where or in
        which order the tasks ran.

    Returns
    -------
    RobustMaps
        The grid axes, the states per cell and each law's cells, in the order
        delay, w_max_ratio, a_ratio.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> s = RobustSettings(n1=3, n2=3, rest=2, n_a=2, n_w=1, laws=("pd",))
    >>> maps = robust_maps(paper_config(), s)
    >>> maps.states, len(maps.laws["pd"])
    (11, 4)
    """
    s = settings or RobustSettings()
    check_box_work(cfg, s)
    if runner is None:
        cells = map_cells(s.laws, cfg, s)
    else:
        cells = runner([(law, cfg, s) for law in s.laws])
    return maps_dict(cfg, s, dict(zip(s.laws, cells, strict=True)))


def maps_dict(cfg: Config, s: RobustSettings, laws: dict) -> RobustMaps:
    """Build the maps: the grid axes, the states per cell, each law's cells.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    s : RobustSettings
        Grid sizes.
    laws : dict
        Law -> its cells (:func:`map_cells`).

    Returns
    -------
    RobustMaps
        See :func:`robust_maps`.
    """
    ars, wrs, delays = _map_axes(cfg, s)
    return RobustMaps(
        a_ratio=tuple(ars),
        w_max_ratio=tuple(wrs),
        delay_samples=tuple(delays),
        states=int(map_states(cfg, s)[0].size),
        laws={law: tuple(cells) for law, cells in laws.items()},
    )
