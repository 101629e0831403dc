"""The report's fixed sizes and names: skippable stages, study settings, the paper's title."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

#: Stages ``--skip`` can leave out (the expensive ones).
SKIPPABLE = ("robust", "tuning", "charts")


#: Sizes of the report's robustness study: overrides of
#: :class:`ptoverify.studies.robust.RobustSettings`.  Empty: the report runs the same study as
#: ``ptoverify robust`` on its defaults (all four laws; a few seconds, `robust_study_s`).
ROBUST_SETTINGS: dict[str, Any] = {}


#: Search effort of the report's tunings (:class:`ptoverify.studies.tune.TuneBudget`, fixed seed),
#: reduced from ``ptoverify tune``'s defaults (30 generations, population factor 10, 9 d
#: points, 4 refinements): the four tunings take a few seconds (benchmarks/README.md).
TUNE_SETTINGS = {"maxiter": 15, "popsize": 8, "d_grid": 5, "d_refine": 2, "seed": 0}


#: States of the ground-truth table [mm], [mm/s]: a step, moves with speed, on/near a
#: curve, beyond saturation, and near the origin.
GROUND_TRUTH_STATES: tuple[tuple[float, float], ...] = (
    (5.0, 0.0),
    (-5.0, 0.0),
    (50.0, 0.0),
    (-20.0, 150.0),
    (12.0, -250.0),
    (0.3, -80.0),
    (-40.0, -290.0),
    (0.05, 0.0),
)


CONVERGENCE_INTERVALS = (10, 20, 50, 100, 200)


_TIMING_KEYS = {"seconds", "timings", "solve_time_s", "elapsed_s", "wall_s"}


Progress = Callable[[str], None]


def _clean(obj: Any) -> Any:
    """JSON-safe copy: numpy to Python, NaN/inf to None, wall-clock timings dropped."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items() if k not in _TIMING_KEYS}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, np.generic):
        return _clean(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


#: Folder of the report's CSV traces (one per law and signal, with feed-forward).
TRACE_DIR = "traces"


def _settings_json(settings: Any) -> dict[str, Any]:
    from dataclasses import asdict, is_dataclass

    return asdict(settings) if is_dataclass(settings) else dict(vars(settings))


# ------------------------------------------------------------------ sections
#: The paper this report verifies, by its title.
PAPER_TITLE = "Approximate Time-Optimal Control Considering System Bandwidth and Saturation"
