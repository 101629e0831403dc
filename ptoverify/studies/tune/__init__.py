"""Fair comparisons: every law's gains tuned under one set of constraints.

PD (kp, kd), PTO (d, k1, k2) and the baselines PTOS (alpha, k) and cascade P (kp).

measure   gain sets: Candidate, tuned_config, response_metrics (the
          ``simulate --json`` path), evaluate (and evaluate_batch), worst_ratio_nt
grid      grid_counts, grid_checked: limit cycles and stride-overs on the gates' grid
screen    many gain sets' step responses in one simulation (the search's screen)
search    tune: SciPy's differential evolution (searches side by side through
          ptoverify.sim.lockstep.run_together), a compass polish, the checks;
          TuneResult
fronts    pareto_front; front_gap, one law's front minus another's (FrontGap)
fair      fair_tunings: the laws tuned under shared overshoot bounds (FairTunings;
          memoized per law and bound, infeasible tunings recorded with the reason)
"""

from ptoverify.studies.tune.fair import FAIR_BOUNDS, FairTunings, TuneBudget, fair_tunings
from ptoverify.studies.tune.fronts import FrontGap, front_gap, pareto_front
from ptoverify.studies.tune.grid import LIMIT_CYCLE_BAND, grid_counts
from ptoverify.studies.tune.measure import (
    BOUNDS,
    OBJECTIVES,
    WORST_GRID,
    Candidate,
    evaluate,
    response_metrics,
    tuned_config,
    worst_ratio_nt,
)
from ptoverify.studies.tune.search import TuneResult, tune

__all__ = [
    "BOUNDS",
    "FAIR_BOUNDS",
    "LIMIT_CYCLE_BAND",
    "OBJECTIVES",
    "WORST_GRID",
    "Candidate",
    "FairTunings",
    "FrontGap",
    "TuneBudget",
    "TuneResult",
    "evaluate",
    "fair_tunings",
    "front_gap",
    "grid_counts",
    "pareto_front",
    "response_metrics",
    "tune",
    "tuned_config",
    "worst_ratio_nt",
]
