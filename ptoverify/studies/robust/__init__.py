"""Robustness under model mismatch: maps, margins and a worst-case search.

maps      per-trajectory properties on mismatched plants (trajectory_properties),
          the one simulation path of the study (evaluate_probes), and the maps over
          a grid of perturbations times a grid of initial states (robust_maps)
margins   linear-loop stability margins (eigenvalues) and the no-limit-cycle margin
          (simulated), most_robust
search    worst cases by SciPy's differential evolution, seeded (worst_cases)
cluster   the maps on a dask.distributed cluster (dask_runner, check_dask_address)
study     the whole study (run_robust -> RobustResult) and its gates (robust_gates)
results   the typed results, each with to_json: RobustMaps (MapCell, PropertyMax),
          WorstCase (CaseParams, Start), LawMargins (Margin), MostRobust
"""

from ptoverify.studies.robust.cluster import (
    DASK_CONNECT_TIMEOUT_S,
    check_dask_address,
    dask_runner,
)
from ptoverify.studies.robust.maps import (
    BATCH_STATES,
    LAWS,
    PROPERTIES,
    Probe,
    RobustSettings,
    evaluate_probes,
    horizon_steps,
    map_cells,
    map_states,
    robust_maps,
    trajectory_properties,
)
from ptoverify.studies.robust.margins import (
    MARGIN_RANGE,
    law_margins,
    linear_loop_margin,
    linear_loop_radii,
    most_robust,
    no_limit_cycle_margin,
)
from ptoverify.studies.robust.results import (
    CaseParams,
    LawMargins,
    MapCell,
    Margin,
    MostRobust,
    PropertyMax,
    RobustMaps,
    Start,
    WorstCase,
)
from ptoverify.studies.robust.search import grid_worst, worst_case, worst_cases
from ptoverify.studies.robust.study import (
    GATE_LAW,
    RobustResult,
    describe_case,
    robust_gates,
    run_robust,
)

__all__ = [
    "CaseParams",
    "LawMargins",
    "MapCell",
    "Margin",
    "MostRobust",
    "PropertyMax",
    "RobustMaps",
    "Start",
    "WorstCase",
    "BATCH_STATES",
    "DASK_CONNECT_TIMEOUT_S",
    "GATE_LAW",
    "LAWS",
    "MARGIN_RANGE",
    "PROPERTIES",
    "Probe",
    "RobustResult",
    "RobustSettings",
    "check_dask_address",
    "dask_runner",
    "law_margins",
    "describe_case",
    "evaluate_probes",
    "grid_worst",
    "horizon_steps",
    "linear_loop_margin",
    "linear_loop_radii",
    "map_cells",
    "map_states",
    "most_robust",
    "no_limit_cycle_margin",
    "robust_gates",
    "robust_maps",
    "run_robust",
    "trajectory_properties",
    "worst_case",
    "worst_cases",
]
