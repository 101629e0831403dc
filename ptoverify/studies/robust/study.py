"""The robustness study as one run: maps, margins, worst cases, and its gates.

:func:`run_robust` runs every law's maps (:mod:`ptoverify.studies.robust.maps`, on
Dask if asked), the linear margins, and then the worst-case searches of all laws
(:mod:`ptoverify.studies.robust.search`) side by side with the no-limit-cycle
margin scans (:mod:`ptoverify.studies.robust.margins`), every round of them one
batch of simulations (:func:`ptoverify.sim.lockstep.run_together`).
:func:`robust_gates` judges the corrected PTO's worst cases.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.sim.lockstep import run_together
from ptoverify.studies.robust.cluster import dask_runner
from ptoverify.studies.robust.maps import (
    RobustSettings,
    check_box_work,
    evaluate_probes,
    map_cells,
    maps_dict,
    nominal_law,
    robust_maps,
)
from ptoverify.studies.robust.margins import linear_loop_margin, margin_job, most_robust
from ptoverify.studies.robust.results import LawMargins, RobustMaps, WorstCase
from ptoverify.studies.robust.search import grid_worst, merge_found, search_jobs
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict

__all__ = ["RobustResult", "run_robust", "robust_gates", "describe_case", "GATE_LAW"]


@dataclass(frozen=True)
class RobustResult:
    """Everything ``ptoverify robust`` computes.

    Attributes
    ----------
    config : Config
        The nominal configuration (with its box).
    settings : RobustSettings
        Sizes of the study.
    maps : RobustMaps
        Every law's map cells (:func:`ptoverify.studies.robust.maps.robust_maps`).
    margins : dict
        Law -> :class:`LawMargins` (empty when the settings skip the margins).
    worst : dict
        Law -> property -> :class:`WorstCase`.
    timings_s : dict
        Wall time per stage [s]: ``maps``, ``margins``, ``worst_case``, ``total``.
    backend : str
        ``in-process`` or the Dask scheduler used.
    """

    config: Config
    settings: RobustSettings
    maps: RobustMaps
    margins: dict[str, LawMargins]
    worst: dict[str, dict[str, WorstCase]]
    timings_s: dict[str, float] = field(default_factory=dict)
    backend: str = "in-process"

    def to_json(self) -> dict[str, Any]:
        """Return the JSON of ``ptoverify robust --json`` (non-finite numbers as None)."""
        return _finite(
            {
                "box": self.config.robustness.to_mapping(),
                "margins": {law: m.to_json() for law, m in self.margins.items()},
                "worst": {
                    law: {prop: w.to_json() for prop, w in by.items()}
                    for law, by in self.worst.items()
                },
                "maps": self.maps.to_json(),
                "most_robust": most_robust(self.margins).to_json(),
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

    Raises
    ------
    InputError
        The box needs more than ``maps.MAX_BOX_WORK`` cell-samples (checked first).
    """
    s = settings or RobustSettings()
    check_box_work(cfg, s)
    report = progress or (lambda stage, frac: None)
    timings: dict[str, float] = {}
    booked: dict[str, float] = {}
    t0 = time.perf_counter()
    report("margins", 0.0)
    linear = {
        law: (linear_loop_margin(law, cfg), linear_loop_margin(law, cfg, delay_samples=1))
        for law in s.laws
    }
    t_linear = time.perf_counter() - t0
    report("maps", 0.05)
    t1 = time.perf_counter()
    if dask:
        by_law = robust_maps(cfg, s, runner=dask_runner(dask)).laws
        cells = [by_law[law] for law in s.laws]
    else:
        cells = map_cells(s.laws, cfg, s, seconds=booked)
    timings["maps"] = time.perf_counter() - t1
    # every law's searches and margin scans side by side: one batch per round
    fns = [nominal_law(law, cfg) for law in s.laws]
    starts = [{prop: grid_worst(c, prop) for prop in s.properties} for c in cells]
    per_law = [search_jobs(fn, cfg, st, s) for fn, st in zip(fns, starts, strict=True)]
    jobs = [j for js in per_law for j in js]
    if s.margins:
        jobs += [margin_job(fn, cfg, s) for fn in fns]
    rounds = 0

    def evaluate(probes: list) -> list:
        nonlocal rounds
        out = evaluate_probes(cfg, probes, seconds=booked)
        rounds += 1
        done = min(1.0, rounds / (s.search_iterations + 1))
        report("margins, worst cases", 0.3 + 0.7 * done)
        return out

    t2 = time.perf_counter()
    results = run_together(evaluate, jobs)
    t_together = time.perf_counter() - t2
    worst, at = {}, 0
    for law, st, js in zip(s.laws, starts, per_law, strict=True):
        worst[law] = merge_found(cfg, st, results[at : at + len(js)])
        at += len(js)
    margins = (
        {law: LawMargins(*linear[law], results[at + i]) for i, law in enumerate(s.laws)}
        if s.margins
        else {}
    )
    scans = booked.get("margins", 0.0)
    timings["margins"] = (t_linear if s.margins else 0.0) + scans
    timings["worst_case"] = max(t_together - scans, 0.0)
    timings["total"] = time.perf_counter() - t0
    maps = maps_dict(cfg, s, dict(zip(s.laws, cells, strict=True)))
    return RobustResult(cfg, s, maps, margins, worst, timings, dask or "in-process")


# -- gates ---------------------------------------------------------------------

GATE_LAW = "pto"  #: the law the robustness gates judge (the corrected PTO)


def describe_case(case: WorstCase) -> str:
    """Describe a worst case in words, with units (no Python repr).

    Parameters
    ----------
    case : WorstCase
        A worst case (``state`` [mm, mm/s] and ``params``).

    Returns
    -------
    str
        E.g. "x0 = (48.01 mm, -87.3 mm/s), a_true/a = 1.25, drive limit 1 w_max, delay
        1 sample, encoder 0.001 mm, velocity noise 0 mm/s (seed 0)".

    Examples
    --------
    >>> from ptoverify.studies.robust.results import CaseParams
    >>> describe_case(WorstCase(0.5, False, 0.6, False, (1.0, -2.0),
    ...     CaseParams(1.25, 1.0, 1, 0.001, 0.0, 0), 100))
    'x0 = (1 mm, -2 mm/s), a_true/a = 1.25, drive limit 1 w_max, delay 1 sample(s), encoder 0.001 mm, velocity noise 0 mm/s (seed 0)'
    """
    x = case.state or (None, None)
    p = case.params

    def g(v: Any) -> str:
        return "?" if v is None else f"{float(v):.4g}"

    return (
        f"x0 = ({g(x[0])} mm, {g(x[1])} mm/s), a_true/a = {g(p.a_ratio)}, "
        f"drive limit {g(p.w_max_ratio)} w_max, delay {p.delay_samples} sample(s), "
        f"encoder {g(p.position_quantum)} mm, velocity noise "
        f"{g(p.velocity_noise)} mm/s (seed {p.seed})"
    )


#: What the robustness gates check, in a sentence (the report's gate table).
LIMIT_CYCLE_DESCRIPTION = (
    "No limit cycle from any state anywhere in the [robustness] box (true a, drive limit, "
    "computation delay, encoder quantum), by grid and seeded search"
)
SETTLING_DESCRIPTION = (
    "Every state settles (box-0p01mm, on the samples) within the limit times N* T of the true "
    "plant, anywhere in the [robustness] box, by grid and seeded search"
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
    lc = worst.get("limit_cycle_mm")
    v = None if lc is None else lc.searched
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
                LIMIT_CYCLE_DESCRIPTION,
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
                LIMIT_CYCLE_DESCRIPTION,
            )
        )
    st = worst.get("settling_ratio_nt")
    v = None if st is None else st.searched
    limit = box.settling_ratio_limit
    if st is None or (v is None and not st.unbounded):
        out.append(
            Verdict(
                "robust-settling",
                UNVERIFIED,
                None,
                limit,
                f"{law}: the worst-case search did not evaluate settling / N*T",
                "<=",
                "1",
                SETTLING_DESCRIPTION,
            )
        )
    else:
        value = math.inf if st.unbounded else float(v)
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
                SETTLING_DESCRIPTION,
            )
        )
    return out
