"""The fair comparison: PD, PTO (and the baselines) tuned on the step under shared bounds."""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field

from ptoverify.config import Config
from ptoverify.errors import InfeasibleError, InputError
from ptoverify.model.memo import memo
from ptoverify.sim.lockstep import run_together
from ptoverify.studies.tune.measure import response_metrics
from ptoverify.studies.tune.screen import StepScreen
from ptoverify.studies.tune.search import TuneResult, check_arguments, tune_checked

__all__ = ["FAIR_BOUNDS", "TuneBudget", "FairTunings", "fair_tunings"]


# ---------------------------------------------------------------- fair comparison
@dataclass(frozen=True)
class TuneBudget:
    """Search effort of the fair-comparison tunings (:func:`fair_tunings`).

    Attributes
    ----------
    maxiter, popsize : int
        Differential-evolution generations and population factor.
    d_grid : int
        PTO: points of the geometric d grid.
    d_refine : int
        PTO: golden-section steps on d.
    seed : int
        Seed (fixed, so the comparison is reproducible).
    polish : int
        Most rounds of the compass search that polishes the best points (at most
        ``maxiter`` of them run).
    """

    maxiter: int = 30
    popsize: int = 10
    d_grid: int = 9
    d_refine: int = 4
    seed: int = 0
    polish: int = 24


#: The shared overshoot bounds of the fair comparison, by name, with their meaning.
FAIR_BOUNDS = {
    "pto-paper": "the PTO's overshoot at the paper's gains",
    "pd-paper": "the PD's overshoot at the paper's gains",
}


@dataclass(frozen=True)
class FairTunings:
    """Both laws tuned on the step under each shared overshoot bound.

    Attributes
    ----------
    bounds : dict
        Bound name (:data:`FAIR_BOUNDS`) -> overshoot bound [mm], measured between
        samples on the paper-gain response of that law.
    paper : dict
        ``pd``, ``pto`` -> response metrics of the step at the paper's gains
        (:func:`response_metrics`).
    results : dict
        (law, bound name) -> :class:`TuneResult` (settling_2pct objective), for
        each tuning that found gains meeting the constraints.
    budget : TuneBudget
        The search effort used.
    seconds : float
        Wall time of the tunings [s].
    infeasible : dict
        (law, bound name) -> why no gains in the search range meet the
        constraints (those tunings are not in ``results``).
    """

    bounds: dict[str, float]
    paper: dict[str, dict[str, float]]
    results: dict[tuple[str, str], TuneResult]
    budget: TuneBudget
    seconds: float
    infeasible: dict[tuple[str, str], str] = field(default_factory=dict)

    def config(self, law: str, bound: str) -> Config:
        """Return the configuration of ``law`` tuned under the bound named ``bound``."""
        return self.results[(law, bound)].config


@memo(maxsize=8)
def _paper(cfg: Config) -> dict[str, dict[str, float]]:
    """Return the step's metrics at the paper's gains of PD and PTO (the bounds' source)."""
    return {law: response_metrics(cfg, law, "step") for law in ("pd", "pto")}


@memo(maxsize=32)
def _law_tunings(
    cfg: Config, budget: TuneBudget, law: str, values: tuple[float, ...]
) -> dict[float, TuneResult | str]:
    """One law tuned under each bound value, side by side on one shared screen.

    A value under which no gains meet the constraints maps to the reason (tune's
    InputError message).  Memoized per law: :func:`_fair_tunings` always asks
    for every bound's value, so a law is tuned once per configuration and budget
    whichever bounds a caller names.
    """
    effort = {
        "seed": budget.seed,
        "maxiter": budget.maxiter,
        "popsize": budget.popsize,
        "d_grid": budget.d_grid,
        "d_refine": budget.d_refine,
        "polish": budget.polish,
    }
    for v in values:
        check_arguments(
            law, "step", "settling_2pct", v, **{k: effort[k] for k in effort if k != "seed"}
        )
    out: dict[float, TuneResult | str] = {}
    shared: dict = {}

    def job(ev, v=0.0):
        try:
            out[v] = tune_checked(
                cfg,
                law,
                "step",
                max_overshoot=v,
                objective="settling_2pct",
                worst_ratio=None,
                find_runner_up=False,  # the comparison does not show one
                screen=ev,
                remeasured=shared,
                **effort,
            )
        except InfeasibleError as exc:  # no gains meet the constraints: the reason
            out[v] = str(exc)

    # each is what tune() gives alone, in fewer simulations
    run_together(StepScreen(cfg, law, False), [functools.partial(job, v=v) for v in values])
    return out


def _fair_tunings(
    cfg: Config, budget: TuneBudget, laws: tuple[str, ...], names: tuple[str, ...]
) -> FairTunings:
    t0 = time.perf_counter()
    paper = _paper(cfg)
    every = {"pto-paper": paper["pto"]["overshoot_mm"], "pd-paper": paper["pd"]["overshoot_mm"]}
    bounds = {name: every[name] for name in names}
    values = tuple(dict.fromkeys(every.values()))  # every bound: one memo entry per law
    results, infeasible = {}, {}
    for law in laws:
        by_value = _law_tunings(cfg, budget, law, values)
        for name, b in bounds.items():
            r = by_value[b]
            if isinstance(r, str):
                infeasible[(law, name)] = r
            else:
                results[(law, name)] = r
    return FairTunings(
        bounds, paper, results, budget, time.perf_counter() - t0, infeasible=infeasible
    )


def fair_tunings(
    cfg: Config,
    budget: TuneBudget | None = None,
    laws: tuple[str, ...] = ("pd", "pto"),
    bounds: tuple[str, ...] = tuple(FAIR_BOUNDS),
) -> FairTunings:
    """Tune each law on the step under each shared overshoot bound (memoized).

    The bounds (:data:`FAIR_BOUNDS`) are the overshoots, between samples, of the
    PTO and of the PD at the paper's gains: under the first, "the same overshoot"
    is the PTO's (the paper's premise for the 31 %), under the second the PD's.
    Each law minimizes its 2 % settling time of the step under the bound
    (:func:`tune`, fixed seed, no runner-up: the comparison does not show one); a
    tuning shared by two bounds of equal value is run once.  A law's tunings run
    side by side on one shared screen (each gives what :func:`tune` gives alone).
    Results are cached per (configuration, budget): at the report's budget the
    four tunings take about 0.9 s of CPU on the paper's plant, at the default
    budget about 1.7 s.

    Parameters
    ----------
    cfg : Config
        Configuration (plant and the paper's gains).
    budget : TuneBudget, optional
        Search effort; default :class:`TuneBudget`.
    laws : tuple of str
        The laws tuned (keys of :data:`~ptoverify.studies.tune.measure.BOUNDS`):
        PD and PTO by default; the baselines ``ptos`` and ``cascade-p`` under the
        same bounds, constraints and search.  Each law's tunings are cached
        alone, so adding a law does not re-tune the others.
    bounds : tuple of str
        Names of the bounds (:data:`FAIR_BOUNDS`) to tune under; default both.

    Returns
    -------
    FairTunings
        Bounds, paper-gain metrics and the tuned results.

    Raises
    ------
    InputError
        An unknown bound name.
    """
    unknown = [b for b in bounds if b not in FAIR_BOUNDS]
    if unknown or not bounds:
        raise InputError(f"fair tunings: bounds must be among {', '.join(FAIR_BOUNDS)}")
    return _fair_tunings(cfg, budget or TuneBudget(), tuple(laws), tuple(dict.fromkeys(bounds)))
