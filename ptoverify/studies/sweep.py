"""Suboptimality sweep: each law's settling time over a grid of initial states.

For every initial state of a grid over the envelope |x1| <= position_range,
|x2| <= w_max, each law regulates the sampled plant to the origin (batch
simulation, exact ZOH flow, all states at once).  Its settling time is
divided by two lower bounds:

* t_f*, the continuous minimum time (closed form, :func:`~ptoverify.model.mintime.min_time`);
* N* T, the discrete-time limit: the fewest ZOH samples from which the origin
  can be reached exactly with |u_k| <= w_max
  (:func:`~ptoverify.model.mintime.discrete_min_steps_batch`: exact 2-D zonotope
  membership, about 10^6 states/s; the LP search is its reference in the tests).

Decisions (the issue is silent on them):

* Grid: 200 x 200 = 40,000 states, evenly spaced and including the envelope's
  corners.  An even count per axis keeps the origin (t_f* = 0) off the grid.
  Every state is simulated (no mirror-halving), in chunks of 2,048 (the
  trajectories of one chunk are held in memory, never the whole grid's).
* Settled: the settling definition ``box-0p01mm``
  (:data:`ptoverify.sim.settling.DEFINITIONS`): |x1| <= ``band`` (0.01 mm)
  and |x2| <= ``velocity_band`` (default a * band: a state coasting with
  u = 0 from the velocity band moves at most x2 / a = band further) on the
  continuous trajectory, from some time on until the end of the horizon.  The
  settling time is the last exit from that box, found exactly between samples
  on the ZOH flow (:func:`ptoverify.sim.settling.settling_time`), including
  excursions out of the box between two samples that are both inside it.  A
  ratio can fall slightly below 1: settling to a band is easier than reaching
  the origin exactly.
* The sample-grid reading (the first sample from which every later sample is
  in the box) is kept alongside: ``LawSweep.grid`` and ``sample_grid`` in the
  JSON.  The exact time is within one sample before the grid time
  (grid - T < exact), and later than it only where the trajectory leaves the
  box between samples after the grid's settled sample (``excursions_after_grid``).
* A state counts as settled only if it stays settled for at least ``hold``
  (default 0.05 s = 25 samples at T = 2 ms) before the horizon ends (the grid
  reading counts whole samples); the horizon is 4 max t_f* + hold over the
  grid, rounded up to whole samples.
* N* is computed for every grid state (a fraction of a second at 40,000).
* Statistics per law: the fraction of states that settle, the median of the
  ratio over the settled states, the worst (largest) ratio with its state, the
  percentiles 50/95/99/max of both ratios, and the five worst states of each
  (the worst states lie next to the origin, where t_f* is a few samples and a
  fixed settling tail weighs most).
* The settling times come from one call, :func:`settling_times`, which returns
  both readings.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config, Plant
from ptoverify.errors import InputError
from ptoverify.model.laws import LAW_NAMES, make_law
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.sim.exact import BatchSettling
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import DEFINITIONS, SettlingDefinition, settling_time
from ptoverify.sim.simulate import chunk_states, simulate_batch
from ptoverify.studies.grids import even_points, grid_states

__all__ = [
    "SweepSettings",
    "LawSweep",
    "SweepResult",
    "run_sweep",
    "settling_times",
    "sweep_definition",
    "grid_states",
    "even_points",
    "discrete_limit",
]

Progress = Callable[[str, float], None]


@dataclass(frozen=True)
class SweepSettings:
    """Settings of the sweep (defaults: module docstring).

    Attributes
    ----------
    n1, n2 : int
        Grid points along x1 and x2 [-].
    band : float
        Position band [mm].
    velocity_band : float or None
        Velocity band [mm/s]; None gives a * band.
    hold : float
        Shortest settled tail that counts [s].
    horizon_factor : float
        Horizon in units of the largest t_f* on the grid [-] (plus ``hold``).
    laws : tuple of str
        Laws to sweep.
    """

    n1: int = 200
    n2: int = 200
    band: float = DEFINITIONS["box-0p01mm"].band_mm
    velocity_band: float | None = None
    hold: float = DEFINITIONS["box-0p01mm"].hold_s
    horizon_factor: float = 4.0
    laws: tuple[str, ...] = LAW_NAMES


@dataclass(frozen=True)
class LawSweep:
    """One law's sweep result; arrays have the grid's shape (n2, n1).

    Attributes
    ----------
    law : str
        Law name.
    settle_time : ndarray
        Settling time between samples (exact last exit from the box) [s]; NaN
        where the law does not settle.  Every statistic below is of this reading.
    ratio_tf : ndarray
        settle_time / t_f* [-].
    ratio_nt : ndarray
        settle_time / (N* T) [-].
    fraction_settled : float
        Share of grid states that settle [-].
    median_ratio_tf, median_ratio_nt : float
        Medians over the settled states [-].
    worst_ratio_tf, worst_ratio_nt : float
        Largest ratios over the settled states [-].
    worst_state_tf, worst_state_nt : tuple of float
        (x1 [mm], x2 [mm/s]) of the largest ratios.
    p95_ratio_tf : float
        95th percentile of settle_time / t_f* over the settled states [-]; the
        worst ratio sits next to the origin, where t_f* is a few samples.
    percentiles_tf, percentiles_nt : dict
        ``p50``, ``p95``, ``p99``, ``max`` of each ratio over the settled states [-].
    worst_states_tf, worst_states_nt : list
        The five largest ratios, worst first, as [x1 [mm], x2 [mm/s], ratio].
    seconds : float
        Wall time of this law's simulation [s].
    grid : LawSweep or None
        The same statistics of the sample-grid reading (settling at the first
        sample from which every later sample is in the box); None inside it.
    excursions_after_grid : int
        States whose trajectory leaves the box between samples after the grid's
        settled sample (exact time > grid time) [-].
    """

    law: str
    settle_time: NDArray[np.float64]
    ratio_tf: NDArray[np.float64]
    ratio_nt: NDArray[np.float64]
    fraction_settled: float
    median_ratio_tf: float
    median_ratio_nt: float
    worst_ratio_tf: float
    worst_ratio_nt: float
    worst_state_tf: tuple[float, float]
    worst_state_nt: tuple[float, float]
    seconds: float
    p95_ratio_tf: float = math.nan
    percentiles_tf: dict = field(default_factory=dict)
    percentiles_nt: dict = field(default_factory=dict)
    worst_states_tf: list = field(default_factory=list)
    worst_states_nt: list = field(default_factory=list)
    grid: LawSweep | None = None
    excursions_after_grid: int = 0

    def to_json(self) -> dict:
        """Return the statistics (not the arrays) as a JSON-able dict.

        The top-level keys are the between-samples reading; ``sample_grid`` holds
        the same keys for the sample-grid reading (without ``seconds``).
        """
        out = self._stats_json()
        out["seconds"] = self.seconds
        if self.grid is not None:
            out["excursions_after_grid"] = self.excursions_after_grid
            out["sample_grid"] = self.grid._stats_json()
        return out

    def _stats_json(self) -> dict:
        return {
            "law": self.law,
            "fraction_settled": self.fraction_settled,
            "median_ratio_tf": self.median_ratio_tf,
            "median_ratio_nt": self.median_ratio_nt,
            "worst_ratio_tf": self.worst_ratio_tf,
            "worst_state_tf": list(self.worst_state_tf),
            "worst_ratio_nt": self.worst_ratio_nt,
            "worst_state_nt": list(self.worst_state_nt),
            "p95_ratio_tf": self.p95_ratio_tf,
            "percentiles_ratio_tf": self.percentiles_tf,
            "percentiles_ratio_nt": self.percentiles_nt,
            "worst_states_tf": self.worst_states_tf,
            "worst_states_nt": self.worst_states_nt,
        }


@dataclass(frozen=True)
class SweepResult:
    """The whole sweep.

    Attributes
    ----------
    x1, x2 : ndarray, shape (n2, n1)
        Initial states [mm], [mm/s] (meshgrid, x1 along columns).
    t_f : ndarray
        Continuous minimum time t_f* [s].
    n_star : ndarray of int
        Discrete limit N* [samples]; -1 where not computed or not found.
    laws : dict of str to LawSweep
        Per law.
    settings : SweepSettings
        The settings used.
    velocity_band : float
        The velocity band used [mm/s].
    steps : int
        Horizon [samples].
    sample_time : float
        T [s].
    timings : dict
        Wall times [s] of the stages.
    skipped : dict
        Laws that could not be built, with the reason.
    """

    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    t_f: NDArray[np.float64]
    n_star: NDArray[np.int64]
    laws: dict[str, LawSweep]
    settings: SweepSettings
    velocity_band: float
    steps: int
    sample_time: float
    timings: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        """Return the ``sweep --json`` object."""
        s = self.settings
        return {
            "grid": {
                "n1": s.n1,
                "n2": s.n2,
                "states": int(self.x1.size),
                "x1_range_mm": [float(self.x1.min()), float(self.x1.max())],
                "x2_range_mm_s": [float(self.x2.min()), float(self.x2.max())],
            },
            "band_mm": s.band,
            "velocity_band_mm_s": self.velocity_band,
            "hold_s": s.hold,
            "settling": "between samples (exact ZOH flow); sample_grid: on the samples",
            "horizon_s": self.steps * self.sample_time,
            "horizon_steps": self.steps,
            "n_star_computed": int(np.count_nonzero(self.n_star >= 0)),
            "laws": {name: r.to_json() for name, r in self.laws.items()},
            "skipped": self.skipped,
            "timings_s": self.timings,
        }


#: Most samples per trajectory (horizon) a sweep may simulate: 80 x the paper's (about
#: 620).  The hold is fixed in seconds (0.05 s), so a fine sample time (T = 1e-7 s: 5e5
#: samples of hold) would otherwise run without bound.
MAX_HORIZON_STEPS = 50_000


def settling_times(
    law,
    plant: Plant,
    x1: NDArray,
    x2: NDArray,
    steps: int,
    band: float,
    velocity_band: float,
    hold: float,
    chunk: int | None = None,
) -> BatchSettling:
    """Settling times of ``law`` from each state, between samples and on the grid.

    Every state is simulated (:func:`ptoverify.sim.simulate.simulate_batch`) and
    measured with :func:`ptoverify.sim.settling.settling_time` under the box
    |x1| <= band, |x2| <= velocity_band held ``hold`` (the registry's
    ``box-0p01mm`` at the defaults).

    Parameters
    ----------
    law : Law
        Feedback law (vectorized path).
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], sample_time T [s]).
    x1, x2 : ndarray, shape (n,)
        Initial states [mm], [mm/s].
    steps : int
        Horizon [samples].
    band, velocity_band : float
        Half-widths of the settled box [mm], [mm/s].
    hold : float
        Shortest settled tail [s].
    chunk : int, optional
        At most this many states simulated at once (memory: about 25 bytes x
        chunk x steps); default :func:`ptoverify.sim.simulate.chunk_states` of the
        horizon (at most 24 MiB per trajectory array: the next chunk reuses the
        memory of the last; 2,048 states, which the sweep used before, cost it
        about 40 % more CPU in per-sample overhead).

    Returns
    -------
    BatchSettling
        ``time``: exact last exit from the box [s]; ``grid``: the first sample
        from which every later sample is in the box [s]; NaN where not settled.
    """
    box = sweep_definition(plant, band, velocity_band, hold)
    chunk = chunk_states(steps) if chunk is None else chunk
    ts, tg = np.empty(x1.size), np.empty(x1.size)
    acc = 0.0
    t = np.arange(steps + 1) * plant.sample_time
    for i in range(0, x1.size, chunk):
        b = simulate_batch(law, plant, x1[i : i + chunk], x2[i : i + chunk], steps)
        st = settling_time(Trajectory(t, b.x1, b.x2, b.u, plant.a), None, box)
        ts[i : i + chunk], tg[i : i + chunk], acc = st.time, st.grid, max(acc, st.accuracy)
    return BatchSettling(ts, tg, acc)


def sweep_definition(
    plant: Plant, band: float, velocity_band: float, hold: float
) -> SettlingDefinition:
    """Return the settling definition of a sweep box: ``box-0p01mm`` at the defaults.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s]).
    band, velocity_band : float
        Half-widths of the box [mm], [mm/s].
    hold : float
        Shortest settled tail [s].

    Returns
    -------
    SettlingDefinition
        The registry's ``box-0p01mm`` when the box is its, else an ad-hoc ``sweep-box``.
    """
    known = DEFINITIONS["box-0p01mm"]
    if (band, velocity_band, hold) == (
        known.band_mm,
        known.velocity_band(plant.a),
        known.hold_s,
    ):
        return known
    return SettlingDefinition(
        "sweep-box",
        "the sweep's box with non-default settings",
        band_mm=band,
        velocity_band_mm=velocity_band / plant.a,
        hold_s=hold,
    )


def discrete_limit(plant: Plant, x1: NDArray, x2: NDArray) -> NDArray[np.int64]:
    """N* for each state (-1 where N* > 20000), by zonotope membership.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], T [s]).
    x1, x2 : ndarray
        Initial states [mm], [mm/s] (any shape; raveled).

    Returns
    -------
    ndarray of int64
        Fewest ZOH samples to the origin [-], flat.
    """
    return discrete_min_steps_batch(np.ravel(x1), np.ravel(x2), plant).steps


def _stats(ratio: NDArray, x1: NDArray, x2: NDArray) -> tuple[float, float, tuple[float, float]]:
    ok = np.isfinite(ratio)
    if not ok.any():
        return math.nan, math.nan, (math.nan, math.nan)
    k = int(np.nanargmax(np.where(ok, ratio, -np.inf)))
    return float(np.median(ratio[ok])), float(ratio.flat[k]), (float(x1.flat[k]), float(x2.flat[k]))


def _percentiles(ratio: NDArray) -> dict:
    r = ratio[np.isfinite(ratio)]
    if not r.size:
        return {k: math.nan for k in ("p50", "p95", "p99", "max")}
    p50, p95, p99 = np.percentile(r, [50, 95, 99])
    return {"p50": float(p50), "p95": float(p95), "p99": float(p99), "max": float(r.max())}


def _worst(ratio: NDArray, x1: NDArray, x2: NDArray, count: int = 5) -> list:
    r = np.where(np.isfinite(ratio), ratio, -np.inf).ravel()
    top = np.argsort(-r, kind="stable")[:count]
    return [[float(x1.flat[i]), float(x2.flat[i]), float(r[i])] for i in top if np.isfinite(r[i])]


def _law_sweep(name, st, t_f, nt, X1, X2, seconds, grid=None, later=0) -> LawSweep:
    """Statistics of one law's settling times ``st`` (one reading)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        r_tf, r_nt = st / t_f, st / nt
    med_tf, worst_tf, at_tf = _stats(r_tf, X1, X2)
    med_nt, worst_nt, at_nt = _stats(r_nt, X1, X2)
    pct_tf = _percentiles(r_tf)
    return LawSweep(
        name,
        st,
        r_tf,
        r_nt,
        float(np.mean(np.isfinite(st))),
        med_tf,
        med_nt,
        worst_tf,
        worst_nt,
        at_tf,
        at_nt,
        seconds,
        pct_tf["p95"],
        pct_tf,
        _percentiles(r_nt),
        _worst(r_tf, X1, X2),
        _worst(r_nt, X1, X2),
        grid,
        later,
    )


def run_sweep(
    cfg: Config, settings: SweepSettings | None = None, *, progress: Progress | None = None
) -> SweepResult:
    """Run the suboptimality sweep.

    Parameters
    ----------
    cfg : Config
        Configuration (plant and law settings).
    settings : SweepSettings, optional
        Grid, bands, horizon and laws; default :class:`SweepSettings`.
    progress : callable, optional
        ``progress(stage, fraction)`` called as the sweep advances.

    Returns
    -------
    SweepResult
        Per-law settling times, ratios and statistics.

    Raises
    ------
    InputError
        A grid under 2 x 2, or a horizon over ``MAX_HORIZON_STEPS`` samples.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> res = run_sweep(paper_config(), SweepSettings(n1=4, n2=4, laws=("pd",)))
    >>> res.laws["pd"].fraction_settled
    1.0
    """
    s = settings or SweepSettings()
    if s.n1 < 2 or s.n2 < 2:
        raise InputError("the sweep grid needs at least 2 points per axis")
    plant, T = cfg.plant, cfg.plant.sample_time
    vband = plant.a * s.band if s.velocity_band is None else s.velocity_band
    report = progress or (lambda stage, frac: None)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    X1, X2 = grid_states(plant, s.n1, s.n2)
    t_f = min_time(X1, X2, plant).t_f
    hold_steps = math.ceil(s.hold / T - 1e-9)
    steps = math.ceil(s.horizon_factor * float(t_f.max()) / T) + hold_steps
    if steps > MAX_HORIZON_STEPS:
        raise InputError(
            f"the sweep's horizon is {steps:,} samples ({s.horizon_factor:g} x the largest t_f* "
            f"+ the {s.hold:g} s hold, at T = {T:g} s), more than the limit of "
            f"{MAX_HORIZON_STEPS:,}: use a longer sample_time"
        )
    timings["min_time"] = time.perf_counter() - t0
    report("discrete limit N*", 0.0)
    t1 = time.perf_counter()
    n_star = discrete_limit(plant, X1, X2).reshape(X1.shape)
    timings["discrete_limit"] = time.perf_counter() - t1
    settle: dict[str, BatchSettling] = {}
    secs: dict[str, float] = {}
    skipped: dict[str, str] = {}
    for i, name in enumerate(s.laws):
        report(f"simulate {name}", (i + 1) / (len(s.laws) + 1))
        try:
            law = make_law(name, cfg)
        except InputError as exc:
            skipped[name] = str(exc)
            continue
        t1 = time.perf_counter()
        settle[name] = settling_times(
            law, plant, X1.ravel(), X2.ravel(), steps, s.band, vband, s.hold
        )
        secs[name] = time.perf_counter() - t1
        timings[f"simulate_{name}"] = secs[name]
    nt = np.where(n_star > 0, n_star * T, np.nan)
    laws = {}
    for name, st in settle.items():
        exact, grid = st.time.reshape(X1.shape), st.grid.reshape(X1.shape)
        with np.errstate(invalid="ignore"):
            later = int(np.count_nonzero(exact > grid))
        on_grid = _law_sweep(name, grid, t_f, nt, X1, X2, secs[name])
        laws[name] = _law_sweep(name, exact, t_f, nt, X1, X2, secs[name], on_grid, later)
    timings["total"] = time.perf_counter() - t0
    report("done", 1.0)
    return SweepResult(X1, X2, t_f, n_star, laws, s, vband, steps, T, timings, skipped)
