"""Several searches advanced side by side, their evaluations merged into one batch.

A study is often made of sequential workloads: a differential evolution
(:func:`scipy.optimize.differential_evolution`) needs one generation's values
before it draws the next, a margin scan one bracket before the next.  Each is
small, and a small batch costs what a large one does per sample (the law's and
the integrator's fixed overhead per call).  :func:`run_together` runs each
workload (a *job*) in a thread of its own with an evaluator in place of the
batch function; whenever every running job waits on its evaluator, their
requests are joined into one call of the batch function, and the answers handed
back.  A job sees what the batch function alone would give it (the evaluation is
per item), so the outcome is that of running the jobs one after the other, and as
deterministic; only the number of batches drops.

:func:`simulate_asks` is the batch function of simulation studies: the asks of one
call are simulated by :func:`ptoverify.sim.simulate.simulate_parts` (the asks of
one law, and of the laws of one :class:`~ptoverify.model.laws.LawFamily`, share one
evaluation per sample), in runs of at most ``round_states`` states, and each ask's
trajectories are measured at once (so a round keeps measured values, not
trajectories).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.model.laws import Law
from ptoverify.sim.simulate import BatchResult, Mismatch, simulate_parts

__all__ = ["Ask", "run_together", "simulate_asks", "ROUND_STATES"]

ROUND_STATES = 16384  #: most states per simulation (memory: ~25 bytes x states x samples)

#: A job: called with an evaluator (a drop-in for the batch function), returns its result.
Job = Callable[[Callable[[list[Any]], list[Any]]], Any]


def run_together(batch_fn: Callable[[list[Any]], list[Any]], jobs: Sequence[Job]) -> list[Any]:
    """Run jobs side by side, their evaluation requests merged into one batch.

    Each job is called with an evaluator ``ev(items) -> answers`` in a thread of its
    own; whenever every running job waits on its evaluator, the requests are joined
    (in job order) into one call of ``batch_fn`` in the calling thread and the
    answers handed back.  ``batch_fn`` must answer item by item (an item's answer
    does not depend on the other items), so each job sees what ``batch_fn`` alone
    would give it.  An exception in a job, or in ``batch_fn`` (every job waiting on
    that batch then sees it), is raised here once all jobs have stopped (the first
    job's, in job order).

    Parameters
    ----------
    batch_fn : callable
        ``batch_fn(items) -> answers``, one answer per item, in order.
    jobs : sequence of callable
        ``job(ev) -> result``.

    Returns
    -------
    list
        Each job's result, in the order of the jobs.

    Examples
    --------
    >>> calls = []
    >>> def square(xs):
    ...     calls.append(len(xs))
    ...     return [x * x for x in xs]
    >>> def job(k):
    ...     return lambda ev: sum(ev([k, k + 1])) + sum(ev([k]))
    >>> run_together(square, [job(1), job(2)]), calls
    ([6, 17], [4, 2])
    """
    if len(jobs) < 2:
        return [job(batch_fn) for job in jobs]
    cv = threading.Condition()
    pending: dict[int, list] = {}
    answers: dict[int, list | BaseException] = {}
    results: list[Any] = [None] * len(jobs)
    running = set(range(len(jobs)))
    errors: dict[int, BaseException] = {}

    def evaluator(i: int) -> Callable[[list], list]:
        def ev(items: list) -> list:
            with cv:
                pending[i] = list(items)
                cv.notify_all()
                while i not in answers:
                    cv.wait()
                out = answers.pop(i)
            if isinstance(out, BaseException):  # the batch failed: stop this job too
                raise out
            return out

        return ev

    def run(i: int) -> None:
        try:
            results[i] = jobs[i](evaluator(i))
        except BaseException as exc:  # noqa: BLE001 - re-raised below
            errors[i] = exc
        finally:
            with cv:
                running.discard(i)
                cv.notify_all()

    threads = [threading.Thread(target=run, args=(i,), daemon=True) for i in range(len(jobs))]
    for th in threads:
        th.start()
    with cv:
        while True:
            while running and not running <= pending.keys():
                cv.wait()
            if not running:
                break
            order = sorted(pending)
            try:
                merged = batch_fn([x for i in order for x in pending[i]])
            except BaseException as exc:  # noqa: BLE001 - handed to every waiting job
                for i in order:
                    answers[i] = exc
            else:
                at = 0
                for i in order:
                    n = len(pending[i])
                    answers[i], at = merged[at : at + n], at + n
            pending.clear()
            cv.notify_all()
    for th in threads:
        th.join()
    if errors:
        raise errors[min(errors)]
    return results


@dataclass(frozen=True)
class Ask:
    """One simulation to run: a law from initial states under a mismatch.

    Attributes
    ----------
    law : Law
        The law (asks of the same Law object share its evaluations).
    x1, x2 : ndarray, shape (n,)
        Initial states [mm], [mm/s].
    mismatch : Mismatch or None
        True plant and measurement (None or identity: the nominal loop).
    stage : str
        Label the time of this simulation is booked to (``seconds`` of
        :func:`simulate_asks`).
    """

    law: Law
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    mismatch: Mismatch | None = None
    stage: str = ""

    @property
    def size(self) -> int:
        """Number of states."""
        return int(np.size(self.x1))


def _family(law: Law) -> Any:
    """Return the group of a law's asks: its family's key, else the law itself."""
    return ("family", law.family.key) if law.family is not None else ("law", id(law))


def simulate_asks(
    asks: Sequence[Ask],
    plant: Plant,
    steps: int,
    measure: Callable[[int, BatchResult], Any],
    *,
    round_states: int = ROUND_STATES,
    seconds: dict[str, float] | None = None,
) -> list[Any]:
    """Simulate asks in few runs and measure each: ``[measure(k, trajectories of ask k)]``.

    Consecutive asks are simulated together while a run stays within
    ``round_states`` states (an ask larger than that runs alone), the asks of a run
    ordered by law family and law (one evaluation per sample for them).  Every
    trajectory is bit for bit the one :func:`ptoverify.sim.simulate.simulate_batch`
    gives for its ask alone, so the answers do not depend on the grouping.

    Parameters
    ----------
    asks : sequence of Ask
        The simulations.
    plant : Plant
        Design plant and sample time.
    steps : int
        Samples per trajectory.
    measure : callable
        ``measure(k, batch) -> answer`` for ask ``k`` (its index in ``asks``);
        ``batch`` holds that ask's trajectories (shape (steps + 1, n) states,
        (steps, n) inputs) and its mismatch.
    round_states : int
        Most states per simulation run.
    seconds : dict, optional
        Wall time [s] added per ask stage: each run's time (simulation and
        measurement) shared by its asks in proportion to their states.

    Returns
    -------
    list
        The answers, in the order of ``asks``.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import pd_law
    >>> cfg = paper_config()
    >>> asks = [Ask(pd_law(cfg), np.array([x0]), np.array([0.0])) for x0 in (5.0, -5.0)]
    >>> ends = simulate_asks(asks, cfg.plant, 300, lambda k, b: float(b.x1[-1, 0]))
    >>> [abs(v) < 1e-6 for v in ends]
    [True, True]
    """
    out: list[Any] = [None] * len(asks)
    runs: list[list[int]] = []
    size = 0
    for k, ask in enumerate(asks):
        if not runs or size + ask.size > round_states:
            runs.append([])
            size = 0
        runs[-1].append(k)
        size += ask.size
    for run in runs:
        order: dict[Any, int] = {}
        for k in run:
            order.setdefault(_family(asks[k].law), len(order))
            order.setdefault(id(asks[k].law), len(order))
        run.sort(key=lambda k: (order[_family(asks[k].law)], order[id(asks[k].law)]))
        t = time.perf_counter()
        parts = simulate_parts(
            [(asks[k].law, asks[k].x1, asks[k].x2, asks[k].mismatch) for k in run], plant, steps
        )
        start = 0
        for k, part in zip(run, parts, strict=True):
            start += asks[k].size
            b = BatchResult(part.x1, part.x2, part.u, part.region, asks[k].mismatch)
            out[k] = measure(k, b)
        if seconds is not None:
            elapsed = time.perf_counter() - t
            for k in run:
                stage = asks[k].stage
                share = elapsed * asks[k].size / max(start, 1)
                seconds[stage] = seconds.get(stage, 0.0) + share
    return out
