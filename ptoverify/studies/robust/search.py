"""Worst-case search over the uncertainty box: SciPy's differential evolution.

Per law, property (of :data:`~ptoverify.studies.robust.maps.PROPERTIES`) and delay
of the box, one :func:`scipy.optimize.differential_evolution` (its default
strategy best/1/bin, F dithered in [0.5, 1], CR 0.7, ``vectorized=True`` so each
generation is one batch) maximizes the property over (x1_0 [mm], x2_0 [mm/s],
a_ratio, w_max_ratio).  Its initial population holds the grid's worst cells of
that delay, the rest a scrambled Latin hypercube
(:class:`scipy.stats.qmc.LatinHypercube`), both seeded from ``box.seed``.  Every
trajectory simulated counts toward every property's worst (the settling ratio
only where it was computed: in the settling searches), so a property's searched
value is the worst over all evaluated points of the box and the grid's worst
cell (which the maps simulated), so never below the grid's worst.  The grid's
worst cells also seed the first population (the optimizer keeps its population
in unit coordinates, so it re-evaluates them to within round-off, not exactly).

All searches, of all laws, run side by side
(:func:`ptoverify.sim.lockstep.run_together`): each generation of every search is
one round of simulations (:func:`ptoverify.studies.robust.maps.evaluate_probes`).
A state's properties do not depend on the states simulated with it, so each
search gives what it gives alone, and the result is deterministic for a seed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.laws import Law
from ptoverify.sim.lockstep import Ask, run_together
from ptoverify.sim.simulate import Mismatch
from ptoverify.studies.robust.maps import (
    PROPERTIES,
    LawSpec,
    Probe,
    RobustSettings,
    evaluate_probes,
    nominal_law,
)
from ptoverify.studies.robust.results import CaseParams, MapCell, Start, WorstCase

__all__ = ["worst_case", "worst_cases", "search_jobs", "grid_worst", "merge_found"]

#: Objective given to the optimizer for a non-finite value (it minimizes -value):
#: +-this for +-inf (a never-settling state is the worst), -this for NaN.
OBJECTIVE_CAP = 1e12


def worst_case(
    law: LawSpec,
    prop: str,
    cfg: Config,
    grid_worst: list[Start],
    settings: RobustSettings | None = None,
) -> WorstCase:
    """Search the box for the worst value of ``prop`` under ``law``.

    One property of :func:`worst_cases` (see there).

    Parameters
    ----------
    law, prop : str
        Law name and one of :data:`PROPERTIES`.
    cfg : Config
        Nominal configuration with its box.
    grid_worst : list of Start
        Starting points (:func:`grid_worst`), worst first.
    settings : RobustSettings, optional
        Population and generations.

    Returns
    -------
    WorstCase
        The grid's and the searched worst, where, and the evaluations.
    """
    return worst_cases(law, cfg, {prop: grid_worst}, settings)[prop]


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


def grid_worst(cells: Sequence[MapCell], prop: str, k: int = 4) -> list[Start]:
    """Return the ``k`` worst cells of a map for ``prop`` as search starting points.

    Parameters
    ----------
    cells : sequence of MapCell
        The cells of one law (``robust_maps(...).laws[law]``).
    prop : str
        One of :data:`PROPERTIES`.
    k : int
        How many cells.

    Returns
    -------
    list of Start
        Each cell's worst state of ``prop`` and its perturbation, worst first;
        an unbounded worst (inf: a state that never settles) comes first, a cell
        without a value (NaN) is left out.
    """
    scored = [c for c in cells if not math.isnan(c.prop(prop).max) and c.prop(prop).max > -math.inf]
    scored.sort(key=lambda c: -c.prop(prop).max)
    return [
        Start(
            state=c.prop(prop).state,
            value=c.prop(prop).max,
            a_ratio=c.a_ratio,
            w_max_ratio=c.w_max_ratio,
            delay_samples=c.delay_samples,
        )
        for c in scored[:k]
    ]


def _problems(cfg: Config, props: Sequence[str]) -> list[tuple[str, int]]:
    """(property, delay) of every search of one law: each property at each delay of the box."""
    box = cfg.robustness
    delays = range(box.delay_samples[0], box.delay_samples[1] + 1)
    return [(prop, dl) for prop in props for dl in delays]


def _initial(
    cfg: Config, prop: str, delay: int, starts: list[Start], size: int, rng
) -> NDArray[np.float64]:
    """Return the first population (size, 4): grid worst cells of ``delay``, then an LHS."""
    from scipy.stats import qmc  # here: scipy.stats costs 0.4 s to import, and only this uses it

    lo, hi = _box_bounds(cfg, prop)
    pop = lo + (hi - lo) * qmc.LatinHypercube(d=4, rng=rng).random(size)
    mine = [g for g in starts if g.delay_samples == delay]
    for i, g in enumerate(mine[:size]):
        z = np.array([*g.state, g.a_ratio, g.w_max_ratio])
        if prop == "overshoot_mm":  # from rest, x1_0 > 0 (the box's overshoot variables)
            z[0], z[1] = abs(z[0]), 0.0
        pop[i] = np.clip(z, lo, hi)
    return pop


def _search_job(
    fn: Law, cfg: Config, prop: str, delay: int, starts: list[Start], s: RobustSettings
) -> Callable[[Callable[[list[Probe]], list[dict[str, NDArray]]]], dict[str, Any]]:
    """One differential evolution (law, property, delay) as a :func:`run_together` job.

    The job returns, per property, the worst value its trajectories reached
    (``value``, ``z`` = (x1, x2, a_ratio, w_max_ratio), ``delay``) and the number of
    trajectories it simulated (``count``).
    """
    box = cfg.robustness
    seed = [box.seed, PROPERTIES.index(prop), delay]  # one stream per search

    def job(ev: Callable[[list[Probe]], list[dict[str, NDArray]]]) -> dict[str, Any]:
        from scipy.optimize import differential_evolution  # here: 0.5 s of import otherwise

        rng = np.random.default_rng(seed)
        found: dict[str, Any] = {
            p: {"value": -math.inf, "z": None, "delay": delay} for p in PROPERTIES
        }
        found["count"] = 0

        def objective(x: NDArray) -> NDArray:  # x: (4, S), one column per candidate
            z = np.ascontiguousarray(x.T)
            m = Mismatch(
                a_ratio=z[:, 2],
                w_max_ratio=z[:, 3],
                delay_samples=delay,
                position_quantum=box.position_quantum,
                velocity_noise=box.velocity_noise,
                seed=box.seed,
            )
            ask = Ask(fn, z[:, 0].copy(), z[:, 1].copy(), m, stage="worst_case")
            (out,) = ev([Probe(ask, settle=prop.startswith("settling"))])
            found["count"] += len(z)
            for p, v in out.items():  # every trajectory counts toward every property's worst
                if p not in found:
                    continue
                w = np.where(np.isnan(v), -np.inf, v)
                k = int(np.argmax(w))
                if w[k] > found[p]["value"]:
                    found[p] = {"value": float(w[k]), "z": z[k].copy(), "delay": delay}
            v = np.nan_to_num(out[prop], nan=-OBJECTIVE_CAP, posinf=OBJECTIVE_CAP)
            return -np.clip(v, -OBJECTIVE_CAP, OBJECTIVE_CAP)

        pop = _initial(cfg, prop, delay, starts, s.search_population, rng)
        lo, hi = _box_bounds(cfg, prop)
        differential_evolution(
            objective,
            list(zip(lo, hi, strict=True)),
            init=pop,
            rng=rng,
            maxiter=s.search_iterations,
            polish=False,
            vectorized=True,
            updating="deferred",
            # a fixed budget: SciPy's documented stopping rule, std(energies) <=
            # atol + tol |mean(energies)|, never holds with tol = 0 and atol < 0
            # (a flat population, e.g. no limit cycle anywhere yet, keeps searching)
            tol=0.0,
            atol=-1.0,
        )
        return found

    return job


def search_jobs(
    fn: Law, cfg: Config, starts: dict[str, list[Start]], s: RobustSettings
) -> list[Callable]:
    """Return the jobs of one law's searches: one per property and delay of the box.

    Parameters
    ----------
    fn : Law
        The nominal law.
    cfg : Config
        Nominal configuration with its box.
    starts : dict
        Property -> starting points (:func:`grid_worst`).
    s : RobustSettings
        Population and generations.

    Returns
    -------
    list of callable
        Jobs of :func:`ptoverify.sim.lockstep.run_together`; their results go to
        :func:`merge_found`.
    """
    if s.search_population < 5:  # SciPy's differential evolution needs five members
        raise InputError(
            f"robust: the search population must be at least 5, got {s.search_population}"
        )
    return [
        _search_job(fn, cfg, prop, dl, starts[prop], s) for prop, dl in _problems(cfg, list(starts))
    ]


def merge_found(
    cfg: Config, starts: dict[str, list[Start]], found: list[dict[str, Any]]
) -> dict[str, WorstCase]:
    """Combine one law's search results (:func:`search_jobs`, in order) into its worst cases.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box.
    starts : dict
        Property -> starting points (:func:`grid_worst`).
    found : list of dict
        The searches' results, in the order of :func:`search_jobs`.

    Returns
    -------
    dict
        Property -> :class:`WorstCase` (see :func:`worst_cases`).
    """
    box = cfg.robustness
    count = sum(f["count"] for f in found)
    out: dict[str, dict[str, Any]] = {}
    for prop in starts:
        best = {"value": -math.inf, "z": None, "delay": box.delay_samples[0]}
        for g in starts[prop][:1]:  # the grid's worst cell: a trajectory the maps simulated
            z0 = np.array([*g.state, g.a_ratio, g.w_max_ratio], dtype=float)
            best = {"value": float(g.value), "z": z0, "delay": g.delay_samples}
        for f in found:  # in search order; ties keep the first
            if f[prop]["value"] > best["value"]:
                best = f[prop]
        vals = [float(g.value) for g in starts[prop]]
        g = max(vals) if vals else -math.inf
        z, searched = best["z"], best["value"]
        out[prop] = WorstCase(
            grid=g if g > -math.inf else None,
            grid_unbounded=g == math.inf,
            searched=searched if searched > -math.inf else None,
            unbounded=searched == math.inf,  # e.g. never settles (JSON: searched null)
            state=(float(z[0]), float(z[1])) if z is not None else None,
            params=CaseParams(
                a_ratio=float(z[2]) if z is not None else None,
                w_max_ratio=float(z[3]) if z is not None else None,
                delay_samples=int(best["delay"]),
                position_quantum=box.position_quantum,
                velocity_noise=box.velocity_noise,
                seed=box.seed,
            ),
            evaluations=count,
        )
    return out


def worst_cases(
    law: LawSpec,
    cfg: Config,
    starts: dict[str, list[Start]],
    settings: RobustSettings | None = None,
) -> dict[str, WorstCase]:
    """Search the box for the worst value of each property in ``starts`` under ``law``.

    Variables: x1_0 [mm], x2_0 [mm/s] (for ``overshoot_mm`` x2_0 = 0 and
    d <= x1_0 <= position_range), a_ratio, w_max_ratio; each delay of the box is
    searched separately, by SciPy's differential evolution (module docstring),
    the searches side by side.

    Parameters
    ----------
    law : str or callable
        Law name, or a factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration with its box.
    starts : dict
        Property (of :data:`PROPERTIES`) -> starting points (:func:`grid_worst`).
    settings : RobustSettings, optional
        Population and generations.

    Returns
    -------
    dict
        Property -> :class:`WorstCase`: the grid's worst (the best starting value),
        the searched worst, where (state and the full mismatch: quantum, noise,
        seed), ``evaluations`` (trajectories of this law's searches, all properties).
    """
    s = settings or RobustSettings()
    jobs = search_jobs(nominal_law(law, cfg), cfg, starts, s)
    found = run_together(lambda probes: evaluate_probes(cfg, probes), jobs)
    return merge_found(cfg, starts, found)
