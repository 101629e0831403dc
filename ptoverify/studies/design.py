"""Design charts: every law over a grid of sample time T x bandwidth.

At each design point (T, f) the configuration's plant is re-sampled: a = 2 pi f
(reading ``2pi``) or a = f rad/s (reading ``hz``), the configuration's w_max
and position range, each law at the configuration's gains.  The point is
validated as a configuration file would be (:func:`ptoverify.config.config_from_mapping`,
so a bad T or bandwidth is an InputError naming the key).  Per law:

* settling / N*T over an n x n grid of the envelope (:func:`ptoverify.studies.sweep.grid_states`;
  the sweep's settling, exact between samples, :func:`ptoverify.studies.sweep.settling_times`;
  N* by :func:`ptoverify.model.mintime.discrete_min_steps_batch`): median and worst,
  and the fraction of states that settle;
* the robustness margin of its linear loop in a_true / a_design, without and
  with a one-sample delay (:func:`ptoverify.studies.robust.linear_loop_margin`,
  the law's linear loop,
  :func:`ptoverify.model.baselines.linear_loop_gains`), and the
  spectral radius of the delayed loop at the design a;

and for the PTO its corrected zone (:func:`ptoverify.model.zones.zone_for_law`):
usable, degenerate (inside the linear zone), why.  Every point is independent:
:func:`design_chart` runs them in this process or on a ``dask.distributed``
cluster (``runner``), and the results are equal.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence

import numpy as np

from ptoverify.config import (
    ALL_LAW_NAMES,
    DESIGN_BANDWIDTHS_HZ,
    DESIGN_GRID,
    DESIGN_LAWS,
    DESIGN_SAMPLE_TIMES,
    Config,
    config_from_mapping,
)
from ptoverify.errors import InfeasibleError, InputError
from ptoverify.model.baselines import linear_loop_gains
from ptoverify.model.laws import make_law
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.model.zones import zone_for_law
from ptoverify.studies.design_results import DesignChart, DesignPoint, LawAtPoint
from ptoverify.studies.ptos_claim import READINGS
from ptoverify.studies.robust import linear_loop_margin, linear_loop_radii
from ptoverify.studies.sweep import SweepSettings, grid_states, settling_times

__all__ = [
    "DESIGN_LAWS",
    "SAMPLE_TIMES",
    "BANDWIDTHS_HZ",
    "LawAtPoint",
    "DesignPoint",
    "DesignChart",
    "design_point",
    "design_chart",
    "dask_design_runner",
    "process_runner",
]


SAMPLE_TIMES = DESIGN_SAMPLE_TIMES  #: default T [s]
BANDWIDTHS_HZ = DESIGN_BANDWIDTHS_HZ  #: default bandwidths [Hz]
GRID = DESIGN_GRID  #: default envelope grid per axis (even: the origin is off the grid)


def point_config(cfg: Config, sample_time: float, bandwidth_hz: float, reading: str) -> Config:
    """Return the validated configuration of one design point.

    Parameters
    ----------
    cfg : Config
        Base configuration (w_max, range, gains).
    sample_time : float
        T [s].
    bandwidth_hz : float
        Bandwidth [Hz].
    reading : str
        ``2pi`` (a = 2 pi f) or ``hz`` (a = f rad/s).

    Returns
    -------
    Config
        The configuration (validated as a file would be).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> point_config(paper_config(), 0.001, 30.0, "hz").plant.a
    30.0
    """
    if reading not in READINGS:
        raise InputError(f"--reading must be one of {', '.join(READINGS)}, got {reading!r}")
    m = cfg.to_mapping()
    plant = {k: v for k, v in m["plant"].items() if k not in ("a", "bandwidth_hz")}
    plant["sample_time"] = float(sample_time)
    plant["bandwidth_hz" if reading == "2pi" else "a"] = float(bandwidth_hz)
    return config_from_mapping({**m, "plant": plant})


def _margin(law: str, cfg: Config, delay: int) -> tuple[float, float]:
    """(lo, hi) of the linear loop's stable a_true / a_design interval."""
    got = linear_loop_margin(law, cfg, delay_samples=delay).interval
    if got is None:
        return math.nan, math.nan
    lo, hi = got
    return (0.0 if lo is None else lo), (math.inf if hi is None else hi)


#: Search effort of the tunings at a design point (smaller than ``tune``'s default: a
#: chart tunes every law at every point).
TUNE_EFFORT = {"maxiter": 10, "popsize": 8, "d_grid": 5, "d_refine": 2, "polish": 8}


def tuned_law_config(cfg: Config, name: str, max_overshoot: float) -> Config | None:
    """Return the configuration of ``name`` tuned on the step (None: infeasible).

    Every law with gains (PD, PTO, PTOS, cascade P) by
    :func:`ptoverify.studies.tune.tune`, each minimizing the 2 % settling of the
    Section 6 step under the same overshoot bound, a stable sampled linear loop and
    no limit cycle; effort :data:`TUNE_EFFORT`.  TO and the printed
    PTO have nothing to tune: ``cfg``.

    Parameters
    ----------
    cfg : Config
        The design point's configuration.
    name : str
        Law name.
    max_overshoot : float
        Overshoot bound [mm].

    Returns
    -------
    Config or None
        The tuned configuration.
    """
    from ptoverify.studies.tune import BOUNDS, tune

    if name not in BOUNDS:
        return cfg
    try:
        return tune(
            cfg, name, "step", max_overshoot=max_overshoot, find_runner_up=False, **TUNE_EFFORT
        ).config
    except InfeasibleError:  # tune's answer when no gains meet the constraints
        return None


def _law_at(
    name: str, cfg: Config, grid: int, states: tuple, overshoot: float | None = None
) -> LawAtPoint:
    """Measure one law at one point (module docstring); tuned first if ``overshoot`` is set."""
    gains_from = "configured"
    if overshoot is not None and name not in ("to", "pto-printed"):
        tuned = tuned_law_config(cfg, name, overshoot)
        gains_from = "tuning infeasible" if tuned is None else "tuned"
        cfg = tuned or cfg
    x1, x2, nt, steps = states
    s = SweepSettings()
    p = cfg.plant
    law = make_law(name, cfg)
    # the sweep's settling, exact between samples
    st = settling_times(law, p, x1, x2, steps, s.band, p.a * s.band, s.hold).time
    ok = np.isfinite(nt)
    ratio = st[ok] / nt[ok]
    settled = np.isfinite(ratio)
    worst = float(ratio.max()) if settled.all() else math.inf
    median = float(np.median(ratio[settled])) if settled.all() else math.nan
    if name == "to":
        gains, m0, m1, rad = (math.nan, math.nan), (math.nan,) * 2, (math.nan,) * 2, math.nan
    else:
        gains = linear_loop_gains(name, cfg)
        m0, m1 = _margin(name, cfg, 0), _margin(name, cfg, 1)
        rad = float(linear_loop_radii(name, cfg, [1.0], delay_samples=1)[0])
    frac = float(np.count_nonzero(settled)) / max(1, ratio.size)
    return LawAtPoint(name, law.note, *gains, median, worst, frac, *m0, *m1, rad, gains_from)


def design_point(
    cfg: Config,
    sample_time: float,
    bandwidth_hz: float,
    reading: str = "2pi",
    laws: Sequence[str] = DESIGN_LAWS,
    grid: int = GRID,
    tuned_overshoot: float | None = None,
) -> DesignPoint:
    """Measure every law at one design point (module docstring).

    Parameters
    ----------
    cfg : Config
        Base configuration.
    sample_time : float
        T [s].
    bandwidth_hz : float
        Bandwidth [Hz].
    reading : str
        ``2pi`` or ``hz``.
    laws : sequence of str
        Law names.
    grid : int
        Envelope grid per axis, >= 2.
    tuned_overshoot : float, optional
        Tune every law at the point under this step overshoot bound [mm]
        (:func:`tuned_law_config`); None: the configuration's gains.

    Returns
    -------
    DesignPoint
        The point.
    """
    t0 = time.perf_counter()
    c = point_config(cfg, sample_time, bandwidth_hz, reading)
    p = c.plant
    X1, X2 = grid_states(p, grid, grid)
    x1, x2 = X1.ravel(), X2.ravel()
    s = SweepSettings()
    t_f = min_time(x1, x2, p).t_f
    steps = math.ceil(s.horizon_factor * float(t_f.max()) / p.T) + math.ceil(s.hold / p.T - 1e-9)
    n_star = discrete_min_steps_batch(x1, x2, p).steps
    nt = np.where(n_star > 0, n_star * p.T, np.nan)
    rows = tuple(_law_at(n, c, grid, (x1, x2, nt, steps), tuned_overshoot) for n in laws)
    z = zone_for_law(c, "corrected")
    ranked = sorted((r.median_ratio_nt, r.law) for r in rows if math.isfinite(r.median_ratio_nt))
    fastest = ranked[0][1] if ranked else ""
    by = ranked[1][0] / ranked[0][0] if len(ranked) > 1 else math.inf
    beats, loses = _against_pto(rows)
    return DesignPoint(
        float(sample_time),
        float(bandwidth_hz),
        p.a,
        rows,
        bool(z.usable),
        bool(z.degenerate),
        z.reason,
        fastest,
        float(by),
        beats,
        loses,
        time.perf_counter() - t0,
    )


def _against_pto(rows: tuple[LawAtPoint, ...]) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(laws the PTO beats, laws that beat it) by median settling / N*T (NaN: never settles)."""
    pto = next((r for r in rows if r.law == "pto"), None)
    if pto is None:
        return (), ()

    def key(r: LawAtPoint) -> float:
        return r.median_ratio_nt if math.isfinite(r.median_ratio_nt) else math.inf

    others = [r for r in rows if r.law != "pto"]
    beats = tuple(r.law for r in others if key(pto) < key(r))
    loses = tuple(r.law for r in others if key(r) < key(pto))
    return beats, loses


Runner = Callable[[list[tuple]], list[DesignPoint]]


def _check_axes(values: Sequence[float], what: str) -> tuple[float, ...]:
    vals = tuple(float(v) for v in values)
    if not vals or any(not math.isfinite(v) or v <= 0 for v in vals):
        raise InputError(f"{what} must be positive numbers, got {list(values)}")
    if len(vals) > 50:
        raise InputError(f"{what}: at most 50 values, got {len(vals)}")
    return vals


def design_chart(
    cfg: Config,
    sample_times: Sequence[float] = SAMPLE_TIMES,
    bandwidths_hz: Sequence[float] = BANDWIDTHS_HZ,
    *,
    laws: Sequence[str] = DESIGN_LAWS,
    reading: str = "2pi",
    grid: int = GRID,
    runner: Runner | None = None,
    backend: str = "in-process",
    tuned_overshoot: float | None = None,
) -> DesignChart:
    """Measure every design point (module docstring).

    Parameters
    ----------
    cfg : Config
        Base configuration.
    sample_times : sequence of float
        T [s].
    bandwidths_hz : sequence of float
        Bandwidths [Hz].
    laws : sequence of str
        Law names.
    reading : str
        ``2pi`` or ``hz``.
    grid : int
        Envelope grid per axis (2 to 100).
    runner : callable, optional
        ``runner(tasks) -> points`` in task order, each task the arguments of
        :func:`design_point`; default: in this process, one after the other.
    backend : str
        Name of the runner, recorded.
    tuned_overshoot : float, optional
        Tune every law at every point under this overshoot bound [mm].

    Returns
    -------
    DesignChart
        The chart.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> ch = design_chart(paper_config(), [0.002], [30.0], laws=("pd",), grid=4)
    >>> ch.points[0].fastest
    'pd'
    """
    t0 = time.perf_counter()
    ts, bw = _check_axes(sample_times, "sample times"), _check_axes(bandwidths_hz, "bandwidths")
    laws = tuple(dict.fromkeys(laws))
    for name in laws:
        if name not in ALL_LAW_NAMES:
            raise InputError(f"unknown law '{name}' (choose from {', '.join(ALL_LAW_NAMES)})")
    if not 2 <= grid <= 100:
        raise InputError(f"--grid must be in [2, 100], got {grid}")
    for T in ts:  # validate every point before any runs  # noqa: N806
        for f in bw:
            try:
                point_config(cfg, T, f, reading)
            except InputError as exc:
                raise InputError(
                    f"design point T = {1e3 * T:g} ms, bandwidth {f:g} "
                    f"({'Hz, a = 2 pi f' if reading == '2pi' else 'rad/s'}): {exc}"
                ) from None
    if tuned_overshoot is not None and not (
        math.isfinite(tuned_overshoot) and tuned_overshoot >= 0
    ):
        raise InputError(f"--tuned must be a finite overshoot >= 0 mm, got {tuned_overshoot}")
    tasks = [(cfg, T, f, reading, laws, grid, tuned_overshoot) for T in ts for f in bw]
    points = (runner or _in_process)(tasks)
    return DesignChart(
        cfg.name,
        reading,
        ts,
        bw,
        laws,
        grid,
        tuned_overshoot,
        tuple(points),
        backend,
        time.perf_counter() - t0,
    )


def _in_process(tasks: list[tuple]) -> list[DesignPoint]:
    return [design_point(*t) for t in tasks]


def _task(args: tuple) -> DesignPoint:
    """One design point from its argument tuple (a dask task)."""
    return design_point(*args)


def process_runner(jobs: int) -> Runner:
    """Return a runner for :func:`design_chart` on ``jobs`` local processes.

    ``concurrent.futures.ProcessPoolExecutor`` with spawned workers; the points
    are the in-process ones (each computed alone, in the same way).

    Parameters
    ----------
    jobs : int
        Worker processes, >= 1.

    Returns
    -------
    callable
        ``runner(tasks) -> points`` in task order.
    """
    if jobs < 1:
        raise InputError(f"--jobs must be >= 1, got {jobs}")

    def run(tasks: list[tuple]) -> list[DesignPoint]:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        ctx = multiprocessing.get_context("spawn")  # no fork of a threaded parent
        with ProcessPoolExecutor(min(jobs, max(1, len(tasks))), mp_context=ctx) as pool:
            return list(pool.map(_task, tasks))

    return run


def dask_design_runner(address: str) -> Runner:
    """Return a runner for :func:`design_chart` on a ``dask.distributed`` cluster.

    Parameters
    ----------
    address : str
        Scheduler address (``tcp://host:port``), or ``local`` to start a
        LocalCluster of 2 single-threaded worker processes for the run.

    Returns
    -------
    callable
        ``runner(tasks) -> points`` in task order.

    Raises
    ------
    InputError
        A malformed address.
    """
    from ptoverify.studies.cluster import check_dask_address, dask_map

    check_dask_address(address)

    def run(tasks: list[tuple]) -> list[DesignPoint]:
        return dask_map(address, _task, list(tasks))

    return run
