"""The tuning search: differential evolution, then a compass polish, then the checks.

``ptoverify tune`` searches a law's gains for the best response under the same
constraints for every law:

* overshoot <= a bound [mm] (between samples, as ``simulate --json`` measures it);
* the sampled linear loop (PD, or the PTO's linear zone, eq. 34) is stable
  (spectral radius < 1 on the ZOH plant);
* no limit cycle, and for the PTO no stride-over, from any state of the gates'
  grid (:func:`ptoverify.studies.properties.law_properties`, 101 x 101 + 200 states;
  :func:`~ptoverify.studies.tune.grid.grid_counts` computes just these two counts, the same way).

The PTO's omega0 always comes from the corrected construction for the
candidate's d (:func:`ptoverify.model.zones.corrected_zone`); a d for which no zone can
be built is infeasible.

Method (a non-smooth objective, so no gradients): PD by
``scipy.optimize.differential_evolution`` over (log10 kp, kd), fixed seed.  For
the PTO, d runs over a geometric grid and for each d differential evolution
tunes (log10 k1, k2); the best d is then refined by a golden-section search
between its grid neighbours.  A compass search then polishes the best points
(up to :data:`COMPASS_STARTS`, at the best d).  The cheap constraints
(stability, overshoot) are applied to every candidate; the grid properties,
which cost a tenth of a second, are checked on the best candidates in order
until one passes (never skipped: a candidate that has not passed them is not
returned).

Speed, and what it does not change:

* Each generation of differential evolution is one batch (scipy's
  ``vectorized=True``, so ``updating="deferred"``), and on the step a batch is
  one :func:`ptoverify.sim.simulate.simulate_batch` run with per-state gains
  (:class:`StepScreen`).  The searches at several d (the grid, each
  golden-section pair) run side by side with their batches merged
  (:func:`ptoverify.sim.lockstep.run_together`); so do the two tunings of a law
  in :func:`ptoverify.studies.tune.fair.fair_tunings`.
  A candidate's screened numbers do not depend on its batch, so the outcome is
  deterministic for a seed.
* The screen agrees with ``simulate --json`` (scalar simulation,
  :mod:`ptoverify.sim.exact`) to round-off, not bit for bit.  Every candidate tune
  reports (best, runner-up, front) is re-measured on the ``simulate --json``
  path, and the best is the first, in the screen's order, that meets the bound
  there too; so ``simulate --config tuned.toml`` reproduces its figures exactly.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InfeasibleError, InputError
from ptoverify.sim.lockstep import run_together
from ptoverify.sim.simulate import reference
from ptoverify.studies.tune.fronts import pareto_front
from ptoverify.studies.tune.grid import grid_checked
from ptoverify.studies.tune.measure import (
    BOUNDS,
    LOG_GAINS,
    MAX_REMEASURED,
    OBJECTIVES,
    PENALTY,
    WORST_GRID,
    Candidate,
    evaluate_batch,
    gains_key,
    tuned_config,
    worst_ratios,
)
from ptoverify.studies.tune.screen import ScreenedResponse, StepScreen, screened_candidate

__all__ = ["TuneResult", "tune"]


@dataclass(frozen=True)
class TuneResult:
    """Outcome of :func:`tune`.

    Attributes
    ----------
    law, signal, objective : str
        What was tuned, on which response, for which objective.
    max_overshoot_mm : float or None
        The overshoot bound [mm].
    best : Candidate
        The best candidate that passed every constraint, grid properties included.
    runner_up : Candidate or None
        The best verified candidate at least 0.2 (normalized search units) from ``best``.
    front : list of Candidate
        Pareto front of settling vs overshoot among the evaluated candidates,
        whatever their overshoot (stable, settling; those the grid check
        rejected are left out; ``verified`` says which were checked on the grid).
    evaluations : int
        Candidates evaluated.
    seconds : float
        Wall time [s].
    config : Config
        The tuned configuration.
    """

    law: str
    signal: str
    objective: str
    max_overshoot_mm: float | None
    best: Candidate
    runner_up: Candidate | None
    front: list[Candidate]
    evaluations: int
    seconds: float
    config: Config = field(repr=False, default=None)  # type: ignore[assignment]

    def toml(self) -> str:
        """Return a TOML configuration that ``--config`` accepts, with the tuned gains."""
        m = self.config.to_mapping()
        lines = [f'name = "{m["name"]}"', "", "[plant]"]
        lines += [f"{k} = {v!r}" for k, v in m["plant"].items()]
        for sect in ("pd", "pto", "ptos", "cascade"):
            if sect in m:
                items = [(k, v) for k, v in m[sect].items() if v is not None]
                lines += ["", f"[{sect}]"] + [f"{k} = {v!r}" for k, v in items]
        return "\n".join(lines) + "\n"

    def to_json(self) -> dict[str, Any]:
        """Return the JSON of ``ptoverify tune --json`` (DESIGN.md key ``best``)."""
        return {
            "law": self.law,
            "signal": self.signal,
            "objective": self.objective,
            "max_overshoot_mm": self.max_overshoot_mm,
            "best": self.best.to_json(),
            "evaluations": self.evaluations,
            "runner_up": self.runner_up.to_json() if self.runner_up else None,
            "front": [c.to_json() for c in self.front],
            "seconds": self.seconds,
            "config_toml": self.toml(),
        }


def _unit(law: str, gains: dict[str, float]) -> np.ndarray:
    """Gains in normalized search units [0, 1] (log scale for kp, k1, d)."""
    out = []
    for k, (lo, hi) in BOUNDS[law].items():
        v = gains[k]
        if k in LOG_GAINS:
            out.append((math.log(v) - math.log(lo)) / (math.log(hi) - math.log(lo)))
        else:
            out.append((v - lo) / (hi - lo))
    return np.array(out)


class _Space:
    """The search coordinates of ``keys`` (log10 for :data:`LOG_GAINS`), other gains ``fixed``.

    ``f`` evaluates a batch of points (one column each) through ``batch_fn`` and
    returns their objectives (:data:`PENALTY` where infeasible).
    """

    LOG = LOG_GAINS

    def __init__(self, batch_fn, keys: tuple[str, ...], law: str, fixed: dict[str, float]):
        self.batch_fn, self.keys, self.fixed = batch_fn, keys, fixed
        self.bounds = np.array(
            [
                tuple(math.log10(b) for b in BOUNDS[law][k]) if k in self.LOG else BOUNDS[law][k]
                for k in keys
            ]
        )

    def gains(self, x: np.ndarray) -> dict[str, float]:
        g = dict(self.fixed)
        for k, v in zip(self.keys, x, strict=True):
            g[k] = float(10.0**v) if k in self.LOG else float(v)
        return g

    def point(self, gains: dict[str, float]) -> np.ndarray:
        return np.array([math.log10(gains[k]) if k in self.LOG else gains[k] for k in self.keys])

    def f(self, xs: np.ndarray) -> np.ndarray:  # xs: (len(keys), S), one column per point
        cands = self.batch_fn([self.gains(xs[:, j]) for j in range(xs.shape[1])])
        return np.array([c.objective if math.isfinite(c.objective) else PENALTY for c in cands])


def _de(space: _Space, seed: int, maxiter: int, popsize: int) -> None:
    """Differential evolution over the space (fixed seed; results go to its batch_fn).

    Each generation is one call of the batch function on the whole population
    (scipy's ``vectorized=True``, which implies ``updating="deferred"``: a
    generation's trials are all made from the population before it).
    """
    from scipy.optimize import differential_evolution  # here: 0.5 s of import otherwise

    differential_evolution(
        space.f,
        [tuple(b) for b in space.bounds],
        seed=seed,
        maxiter=maxiter,
        popsize=popsize,
        polish=False,
        tol=1e-6,
        vectorized=True,
        updating="deferred",
    )


#: First step of the compass polish, as a fraction of each search range [-].
COMPASS_STEP = 1.0 / 64.0
#: The compass stops once its step is below this fraction of each range [-].
COMPASS_MIN_STEP = 1.0 / 4096.0
#: Starts of the compass polish: the best points at least this far apart [-] (in
#: normalized search units), at most COMPASS_STARTS of them.
COMPASS_SPREAD = 0.05
COMPASS_STARTS = 4


def _compass(f, xs: np.ndarray, fs: np.ndarray, bounds: np.ndarray, rounds: int) -> None:
    """Compass searches from the rows of ``xs`` side by side, one batch per round.

    Each search tries its 2n axis and 2^n diagonal neighbours at its current step
    (clipped to the bounds); the best that improves on its value becomes its point,
    else its step halves.  Every round evaluates the neighbours of all searches
    still running in one call of ``f``.  Steps start at :data:`COMPASS_STEP` of
    each range; a search stops when its step falls below :data:`COMPASS_MIN_STEP`,
    all stop after ``rounds`` rounds.  Deterministic; a non-smooth objective needs
    no gradient.
    """
    k, n = xs.shape
    width = bounds[:, 1] - bounds[:, 0]
    dirs = [np.eye(n)[i] * s for i in range(n) for s in (-1.0, 1.0)]
    dirs += [np.array(c) for c in np.array(np.meshgrid(*[[-1.0, 1.0]] * n)).reshape(n, -1).T]
    dirs_a = np.array(dirs)
    m = len(dirs_a)
    x, fx = xs.astype(float).copy(), np.asarray(fs, dtype=float).copy()
    step = np.full(k, COMPASS_STEP)
    for _ in range(rounds):
        live = np.flatnonzero(step >= COMPASS_MIN_STEP)
        if live.size == 0:
            break
        pts = x[live, None, :] + dirs_a[None, :, :] * (step[live, None, None] * width)
        pts = np.clip(pts, bounds[:, 0], bounds[:, 1]).reshape(-1, n)
        vals = f(pts.T).reshape(live.size, m)
        for row, i in enumerate(live.tolist()):
            j = int(np.argmin(vals[row]))
            if vals[row, j] < fx[i]:
                x[i], fx[i] = pts[row * m + j], vals[row, j]
            else:
                step[i] /= 2.0


def _starts(law: str, cands: list[Candidate]) -> list[Candidate]:
    """Return the best candidates at least :data:`COMPASS_SPREAD` apart (PTO: at the best's d)."""
    ranked = sorted(cands, key=lambda c: c.objective)
    if law == "pto" and ranked:
        ranked = [c for c in ranked if c.gains["d"] == ranked[0].gains["d"]]
    out: list[Candidate] = []
    for c in ranked:
        u = _unit(law, c.gains)
        if all(np.abs(u - _unit(law, o.gains)).max() >= COMPASS_SPREAD for o in out):
            out.append(c)
            if len(out) == COMPASS_STARTS:
                break
    return out


def tune(
    cfg: Config,
    law: str,
    signal: str = "step",
    *,
    max_overshoot: float | None = None,
    objective: str = "settling_2pct",
    seed: int = 0,
    maxiter: int = 30,
    popsize: int = 10,
    d_grid: int = 9,
    d_refine: int = 4,
    worst_ratio: Callable[[Config, str], float] | None = None,
    polish: int = 24,
    find_runner_up: bool = True,
) -> TuneResult:
    """Search the law's gains for the best response under the constraints.

    Parameters
    ----------
    cfg : Config
        Base configuration (plant; the other law's gains are kept).
    law : str
        ``pd``, ``pto``, or a baseline: ``ptos`` (alpha, k) or ``cascade-p`` (kp)
        (:data:`~ptoverify.studies.tune.measure.BOUNDS`), tuned under the same
        constraints (the PTO alone is also checked for stride-overs: the
        others have no switching curve to stride over).
    signal : str
        ``step``, ``ramp`` or ``sine``.
    max_overshoot : float, optional
        Overshoot bound [mm]; None: unconstrained.
    objective : str
        One of :data:`OBJECTIVES`.
    seed : int
        Seed of differential evolution.
    maxiter, popsize : int
        Differential-evolution generations and population factor.
    d_grid : int
        PTO: points of the geometric d grid.
    d_refine : int
        PTO: golden-section steps refining d between the best grid point's neighbours.
    worst_ratio : callable, optional
        ``f(cfg, law) -> worst settling / N*T`` for ``worst_ratio_nt``; default
        :func:`worst_ratio_nt` over the :data:`WORST_GRID` grid.
    polish : int
        Most rounds of the compass search that polishes the best points (0: none);
        it runs at most ``maxiter`` rounds.
    find_runner_up : bool
        Search the runner-up (grid-checked; ``False`` leaves it None).

    Returns
    -------
    TuneResult
        Best, runner-up, Pareto front and the number of evaluations.

    Raises
    ------
    InputError
        Unknown law, signal or objective, or a negative overshoot bound.
    """
    check_arguments(
        law, signal, objective, max_overshoot, maxiter, popsize, d_grid, d_refine, polish
    )
    screen = StepScreen(cfg, law, objective == "settling_0p01mm") if signal == "step" else None
    return tune_checked(
        cfg,
        law,
        signal,
        max_overshoot=max_overshoot,
        objective=objective,
        seed=seed,
        maxiter=maxiter,
        popsize=popsize,
        d_grid=d_grid,
        d_refine=d_refine,
        worst_ratio=worst_ratio,
        polish=polish,
        find_runner_up=find_runner_up,
        screen=screen,
    )


def check_arguments(
    law, signal, objective, max_overshoot, maxiter, popsize, d_grid, d_refine, polish
):
    """Raise InputError on arguments :func:`tune` does not accept.

    Parameters
    ----------
    law, signal, objective : str
        As :func:`tune`.
    max_overshoot : float or None
        Overshoot bound [mm].
    maxiter, popsize, d_grid, d_refine, polish : int
        Search effort, as :func:`tune`.

    Raises
    ------
    InputError
        An argument out of range, naming it.
    """
    if law not in BOUNDS:
        raise InputError(f"tune: unknown law '{law}' (choose from {', '.join(BOUNDS)})")
    if objective not in OBJECTIVES:
        raise InputError(
            f"tune: unknown objective '{objective}' (choose from {', '.join(OBJECTIVES)})"
        )
    if max_overshoot is not None and not (max_overshoot >= 0 and math.isfinite(max_overshoot)):
        raise InputError(f"tune: --max-overshoot must be a finite number >= 0, got {max_overshoot}")
    if maxiter < 1 or popsize < 1 or d_grid < 2 or d_refine < 0 or polish < 0:
        raise InputError(
            f"tune: maxiter and popsize must be >= 1, d_grid >= 2, d_refine and polish >= 0 "
            f"(got {maxiter}, {popsize}, {d_grid}, {d_refine}, {polish})"
        )
    reference(signal)  # names the signal or raises InputError


def tune_checked(
    cfg: Config,
    law: str,
    signal: str,
    *,
    max_overshoot: float | None,
    objective: str,
    seed: int,
    maxiter: int,
    popsize: int,
    d_grid: int,
    d_refine: int,
    worst_ratio: Callable[[Config, str], float] | None,
    polish: int,
    find_runner_up: bool,
    screen: Callable[[list[dict[str, float]]], list[ScreenedResponse]] | None,
    remeasured: dict | None = None,
) -> TuneResult:
    """Run :func:`tune` on arguments already checked (:func:`check_arguments`).

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law, signal, objective : str
        As :func:`tune`.
    max_overshoot : float or None
        Overshoot bound [mm].
    seed, maxiter, popsize, d_grid, d_refine, polish : int
        Search effort, as :func:`tune`.
    worst_ratio : callable or None
        As :func:`tune`.
    find_runner_up : bool
        Search the runner-up.
    screen : callable or None
        Measures step responses in batches
        (:class:`ptoverify.studies.tune.screen.StepScreen`); None: every candidate
        on the ``simulate --json`` path.
    remeasured : dict, optional
        Keeps that path's metrics by gains (tunings of one law on one
        configuration may share it).

    Returns
    -------
    TuneResult
        As :func:`tune`.
    """
    remeasured = {} if remeasured is None else remeasured
    t0 = time.perf_counter()
    seen: dict[tuple, Candidate] = {}
    opts = {"objective": objective, "max_overshoot": max_overshoot, "worst_ratio": worst_ratio}
    key = gains_key

    def batch_fn(gs: list[dict[str, float]]) -> list[Candidate]:
        new = {key(g): g for g in gs if key(g) not in seen}
        if new:
            if screen is not None:  # the whole batch in one simulation
                gs_new = list(new.values())
                raws = screen(gs_new)
                ratios: list[float | None] = [None] * len(gs_new)
                if objective == "worst_ratio_nt" and worst_ratio is None:  # batched too
                    within = [
                        i
                        for i, r in enumerate(raws)
                        if not r.reason
                        and (max_overshoot is None or r.overshoot_mm <= max_overshoot)
                    ]
                    vals = worst_ratios(cfg, law, [gs_new[i] for i in within], *WORST_GRID)
                    for i, v in zip(within, vals, strict=True):
                        ratios[i] = v
                cs = [
                    screened_candidate(cfg, law, g, r, **opts, ratio=q)
                    for g, r, q in zip(gs_new, raws, ratios, strict=True)
                ]
            else:  # evaluated on the simulate --json path, the batch side by side
                cs = evaluate_batch(cfg, law, list(new.values()), signal=signal, **opts)
            seen.update(zip(new, cs, strict=True))
        return [seen[key(g)] for g in gs]

    measured: dict[tuple, Candidate] = {}

    def canonical_many(cs: list[Candidate]) -> list[Candidate]:
        """Return the candidates measured on the simulate --json path (what tune reports).

        Those not measured there yet are measured side by side (:func:`evaluate_batch`:
        each as it is alone).
        """
        if screen is None:  # the search measured them on that path already
            return cs
        new = {key(c.gains): c.gains for c in cs if key(c.gains) not in measured}
        if new:
            vs = evaluate_batch(
                cfg,
                law,
                list(new.values()),
                signal=signal,
                objective=objective,
                max_overshoot=max_overshoot,
                worst_ratio=worst_ratio,
                memo=remeasured,
            )
            measured.update(zip(new, vs, strict=True))
        return [measured[key(c.gains)] for c in cs]

    def canonical(c: Candidate) -> Candidate:
        """Return the candidate measured on the simulate --json path (what tune reports)."""
        return canonical_many([c])[0]

    keys = tuple(k for k in BOUNDS[law] if k != "d")
    if law != "pto":
        _de(_Space(batch_fn, keys, law, {}), seed, maxiter, popsize)
    else:
        lo, hi = BOUNDS["pto"]["d"]
        ds = np.geomspace(lo, hi, d_grid)
        score = {}
        sub = (seed, max(maxiter // 2, 5), popsize)

        def run_at(dvals: list[float]) -> None:  # one search per d, side by side
            run_together(
                batch_fn,
                [lambda ev, d=d: _de(_Space(ev, keys, law, {"d": d}), *sub) for d in dvals],
            )
            for d in dvals:
                score[d] = min(
                    (c.objective for c in seen.values() if c.gains["d"] == d), default=math.inf
                )

        run_at([float(d) for d in ds])
        # golden-section refinement of d between the best grid point's neighbours
        i = int(np.argmin([score[float(d)] for d in ds]))
        a, b = float(ds[max(i - 1, 0)]), float(ds[min(i + 1, len(ds) - 1)])
        gr = (math.sqrt(5.0) - 1.0) / 2.0
        for _ in range(d_refine):
            c1, c2 = b - gr * (b - a), a + gr * (b - a)
            run_at([d for d in dict.fromkeys((c1, c2)) if d not in score])
            a, b = (a, c2) if score[c1] <= score[c2] else (c1, b)
    starts = _starts(law, [c for c in seen.values() if c.feasible])
    if polish and starts:  # a local polish of the search's best points (d fixed)
        space = _Space(batch_fn, keys, law, {"d": starts[0].gains["d"]} if law == "pto" else {})
        xs = np.array([space.point(c.gains) for c in starts])
        rounds = min(polish, maxiter)  # as many rounds as generations, at most
        _compass(space.f, xs, np.array([c.objective for c in starts]), space.bounds, rounds)
    # the best: in order of the search's objective, the first that passes every
    # constraint measured on the simulate --json path and on the gate grid
    cands = sorted((c for c in seen.values() if c.feasible), key=lambda c: c.objective)
    best = None
    checked = 0
    for c in cands[:MAX_REMEASURED]:
        v = canonical(c)
        if v.feasible:
            v = grid_checked(cfg, law, v)
            checked += 1
        seen[key(c.gains)] = v
        if v.feasible:
            best = v
            break
        if checked >= 25:
            break
    if best is None:
        raise InfeasibleError(
            f"tune: no {law} gains in the search range meet the constraints ("
            + ("" if max_overshoot is None else f"overshoot <= {max_overshoot:g} mm, ")
            + "stable, settles within the record, no limit cycle)"
        )
    runner_up = None
    if find_runner_up:
        far = [c for c in cands if np.abs(_unit(law, c.gains) - _unit(law, best.gains)).max() > 0.2]
        for c in far[:5]:
            v = canonical(c)
            if v.feasible:
                v = grid_checked(cfg, law, v)
            if v.feasible:
                runner_up = v
                break
    # the front over the evaluated candidates, less those the grid check rejected, with
    # its members' numbers measured on the simulate --json path
    pool = pareto_front([c for c in seen.values() if c.feasible or not c.verified])
    remeasure = iter(canonical_many([c for c in pool if not c.verified]))
    front = pareto_front([c if c.verified else next(remeasure) for c in pool])
    return TuneResult(
        law=law,
        signal=signal,
        objective=objective,
        max_overshoot_mm=max_overshoot,
        best=best,
        runner_up=runner_up,
        front=front,
        evaluations=len(seen),
        seconds=time.perf_counter() - t0,
        config=dataclasses.replace(
            tuned_config(cfg, law, best.gains), name=f"{cfg.name}-tuned-{law}"
        ),
    )
