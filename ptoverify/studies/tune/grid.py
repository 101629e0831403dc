"""The tuning's grid properties: limit cycles and stride-overs on the gates' grid.

:func:`grid_counts` computes the two counts of
:func:`ptoverify.studies.properties.law_properties` that the tuning's constraints
need, every state of the gates' grid simulated; :func:`grid_checked` applies them
to a candidate.
"""

from __future__ import annotations

import dataclasses
import threading

from ptoverify.config import Config
from ptoverify.model.laws import make_law
from ptoverify.model.memo import memo
from ptoverify.sim.simulate import chunk_states, simulate_batch
from ptoverify.studies.properties import (
    default_steps,
    initial_grid,
    oscillating,
    stride_over_counts,
)
from ptoverify.studies.tune.measure import Candidate, tuned_config

__all__ = ["LIMIT_CYCLE_BAND", "grid_counts", "grid_checked"]


LIMIT_CYCLE_BAND = 1e-3  # [mm]


def grid_counts(cfg: Config, law: str) -> tuple[int, int]:
    """Limit cycles and stride-overs of ``law`` on the gates' grid.

    The two counts of :func:`ptoverify.studies.properties.law_properties` that the tuning's
    constraints need, from the same pieces (its grid, horizon, simulation,
    limit-cycle test over the last quarter of the horizon, and the stride-overs of
    its crossing masks as :func:`ptoverify.studies.properties.stride_over_counts` counts
    them), without the other properties; the stride-overs are counted for the PTO
    only (0 for other laws).

    Every state of the grid is simulated, once per configuration and law (memoized:
    tunings under two bounds often reach the same candidate; the side-by-side
    searches run in threads, so one computes it while the other waits).

    Parameters
    ----------
    cfg : Config
        Configuration the law is built from.
    law : str
        Law name.

    Returns
    -------
    limit_cycles, stride_overs : int
        States that end in a sustained oscillation; transitions that stride over l1/l2.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> grid_counts(paper_config(), "pd")
    (0, 0)
    """
    with _ONE_AT_A_TIME:  # (the threads share the GIL: waiting costs no parallelism)
        return _grid_counts(cfg, law)


_ONE_AT_A_TIME = threading.Lock()


@memo(maxsize=64)
def _grid_counts(cfg: Config, law: str) -> tuple[int, int]:
    fn = make_law(law, cfg)
    x1, x2, _ = initial_grid(cfg)
    steps = default_steps(cfg)
    cycles = strides = 0
    size = chunk_states(steps)
    for s in range(0, x1.size, size):  # each state's trajectory is its own: counts add up
        res = simulate_batch(fn, cfg.plant, x1[s : s + size], x2[s : s + size], steps)
        cycles += int(oscillating(res.x1[-max(20, steps // 4) :], LIMIT_CYCLE_BAND).sum())
        if law == "pto":
            strides += int(stride_over_counts(res.x1, res.x2, res.region, cfg).sum())
    return cycles, strides


def grid_checked(cfg: Config, law: str, c: Candidate) -> Candidate:
    """Check the grid properties of a candidate (no limit cycle; PTO: no stride-over).

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        ``pd`` or ``pto``.
    c : Candidate
        The candidate.

    Returns
    -------
    Candidate
        ``c`` marked ``verified``, infeasible with the reason where a property fails.
    """
    cycles, strides = grid_counts(tuned_config(cfg, law, c.gains), law)
    bad = []
    if cycles:
        bad.append(f"{cycles} limit cycles on the gate grid")
    if strides:
        bad.append(f"{strides} stride-overs on the gate grid")
    if bad:
        return dataclasses.replace(c, feasible=False, verified=True, reason="; ".join(bad))
    return dataclasses.replace(c, verified=True)
