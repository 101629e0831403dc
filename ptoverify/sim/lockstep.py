"""Many dependent simulation workloads advanced together, one simulation per round.

A study such as the robustness study is made of sequential workloads: a
differential evolution needs one generation's trajectories before it draws the
next, a bisection one bracket before the next.  Each workload is small, and a
small batch costs what a large one does per sample (the law's and the
integrator's fixed overhead per call).  Here each workload is a *job*, a
generator that yields the simulations it needs next (:class:`Ask`) and is sent
their trajectories; :func:`run_lockstep` gathers the asks of all jobs into
rounds and runs each round as one :func:`ptoverify.sim.simulate.simulate_segments`
call, in which the asks of one law, and of the laws of one
:class:`~ptoverify.model.laws.LawFamily`, share one evaluation per sample.

Every trajectory is bit for bit the one :func:`ptoverify.sim.simulate.simulate_batch`
gives for its ask alone (states are independent), so what the jobs compute does
not depend on how their asks were grouped into rounds.

Riders.  An ask marked ``rider`` (e.g. a margin scan, which nothing waits for)
only joins a round in which its law is evaluated anyway, or a round with no
other work; it then adds states to an evaluation, not evaluations.
"""

from __future__ import annotations

import time
from collections.abc import Generator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.model.laws import Law
from ptoverify.sim.simulate import BatchResult, Mismatch, TrajectoryBuffers, simulate_segments

__all__ = ["Ask", "Job", "LockstepRun", "run_lockstep", "ROUND_STATES"]

ROUND_STATES = 16384  #: states simulated per round (memory: ~25 bytes x states x samples)


@dataclass(frozen=True)
class Ask:
    """One simulation a job needs: a law from initial states under a mismatch.

    Attributes
    ----------
    law : Law
        The law (asks of the same Law object share its evaluations).
    x1, x2 : ndarray, shape (n,)
        Initial states [mm], [mm/s].
    mismatch : Mismatch or None
        True plant and measurement (None or identity: the nominal loop).
    rider : bool
        May wait for a round that evaluates its law anyway (module docstring).
    stage : str
        Label the time of this simulation is booked to (:attr:`LockstepRun.seconds`).
    """

    law: Law
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    mismatch: Mismatch | None = None
    rider: bool = False
    stage: str = ""

    @property
    def size(self) -> int:
        """Number of states."""
        return int(np.size(self.x1))


#: A job: yields a list of asks, is sent their trajectories (one BatchResult per ask,
#: in order), and returns its result.
Job = Generator[list[Ask], list[BatchResult], Any]


@dataclass
class LockstepRun:
    """What :func:`run_lockstep` returns.

    Attributes
    ----------
    results : list
        Each job's return value, in the order of the jobs.
    rounds : int
        Simulations run.
    state_steps : int
        Trajectory samples simulated (states x samples, summed over rounds).
    seconds : dict
        Wall time [s] per ask stage: each round's simulation time shared by the
        stages of its asks in proportion to their states, plus the time the jobs
        spent (measuring, deciding) after receiving that stage's trajectories.
    """

    results: list[Any]
    rounds: int = 0
    state_steps: int = 0
    seconds: dict[str, float] = field(default_factory=dict)


def _family(law: Law) -> Any:
    """Return the group of a law's asks: its family's key, else the law itself."""
    return ("family", law.family.key) if law.family is not None else ("law", id(law))


def run_lockstep(
    jobs: list[Job],
    plant: Plant,
    steps: int,
    *,
    round_states: int = ROUND_STATES,
    on_round: Any = None,
    reuse: bool = False,
) -> LockstepRun:
    """Run jobs to completion, their asks gathered into rounds of one simulation each.

    Each round takes the waiting asks that are not riders in the order they were
    asked, as long as the round stays within ``round_states`` states (at least
    one), then the riders whose law the round evaluates (any rider when the round
    has nothing else), within the same limit.  A job is resumed once all the
    asks of its last yield are simulated.

    Parameters
    ----------
    jobs : list of generator
        The jobs (:data:`Job`).
    plant : Plant
        Design plant and sample time.
    steps : int
        Samples per trajectory.
    round_states : int
        Most states per round (an ask larger than this runs alone).
    on_round : callable, optional
        ``on_round(rounds_done, jobs_done, jobs_total)`` after each round (progress).
    reuse : bool
        Write every round's trajectories into the same memory
        (:class:`ptoverify.sim.simulate.TrajectoryBuffers`: the pages are faulted in
        once, not at every round).  The trajectories sent to a job are then
        overwritten by the next round, so they are valid only until the job
        yields its next asks: for jobs that keep nothing of them (measured
        values are new arrays).  The values simulated are the same.

    Returns
    -------
    LockstepRun
        The jobs' results and the run's counts and times.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import pd_law
    >>> cfg = paper_config()
    >>> def job(x0):
    ...     (b,) = yield [Ask(pd_law(cfg), np.array([x0]), np.array([0.0]))]
    ...     return float(b.x1[-1, 0])
    >>> run = run_lockstep([job(5.0), job(-5.0)], cfg.plant, 300)
    >>> run.rounds, [abs(v) < 1e-6 for v in run.results]
    (1, [True, True])
    """
    out = LockstepRun([None] * len(jobs))
    buffers = TrajectoryBuffers() if reuse else None
    waiting: dict[int, list] = {}  # job -> [asks, trajectories, still to simulate]
    queue: list[tuple[int, int]] = []  # (job, ask) in the order asked
    done = 0

    def book(stage: str, seconds: float) -> None:
        out.seconds[stage] = out.seconds.get(stage, 0.0) + seconds

    def resume(j: int, sent: list[BatchResult] | None, stage: str) -> None:
        nonlocal done
        t = time.perf_counter()
        try:
            while True:
                asks = jobs[j].send(sent) if sent is not None else next(jobs[j])
                if asks:
                    break
                sent = []  # nothing to simulate: answer at once
        except StopIteration as stop:
            out.results[j] = stop.value
            done += 1
            return
        finally:
            book(stage, time.perf_counter() - t)
        waiting[j] = [list(asks), [None] * len(asks), len(asks)]
        queue.extend((j, i) for i in range(len(asks)))

    for j in range(len(jobs)):
        resume(j, None, "")
    while queue:
        chosen: list[tuple[int, int]] = []
        size = 0
        laws: set[int] = set()
        for j, i in queue:
            ask = waiting[j][0][i]
            if ask.rider or (chosen and size + ask.size > round_states):
                continue
            chosen.append((j, i))
            size += ask.size
            laws.add(id(ask.law))
        for j, i in queue:
            ask = waiting[j][0][i]
            if not ask.rider or (laws and id(ask.law) not in laws):
                continue
            if chosen and size + ask.size > round_states:
                continue
            chosen.append((j, i))
            size += ask.size
        taken = set(chosen)
        queue = [q for q in queue if q not in taken]
        # the asks of one law next to each other, and the laws of one family
        # (laws.LawFamily): one evaluation of them per sample
        order: dict[Any, int] = {}
        for j, i in chosen:
            law = waiting[j][0][i].law
            order.setdefault(_family(law), len(order))
            order.setdefault(id(law), len(order))
        chosen.sort(
            key=lambda q: (
                order[_family(waiting[q[0]][0][q[1]].law)],
                order[id(waiting[q[0]][0][q[1]].law)],
            )
        )
        asks = [waiting[j][0][i] for j, i in chosen]
        t = time.perf_counter()
        batch = simulate_segments(
            [(a.law, a.x1, a.x2, a.mismatch) for a in asks], plant, steps, buffers=buffers
        )
        elapsed = time.perf_counter() - t
        out.rounds += 1
        out.state_steps += size * steps
        start = 0
        ready = []
        for (j, i), ask in zip(chosen, asks, strict=True):
            sl = slice(start, start + ask.size)
            start += ask.size
            book(ask.stage, elapsed * ask.size / max(size, 1))
            w = waiting[j]
            w[1][i] = BatchResult(
                batch.x1[:, sl], batch.x2[:, sl], batch.u[:, sl], batch.region[:, sl], ask.mismatch
            )
            w[2] -= 1
            if w[2] == 0:
                ready.append((j, ask.stage))
        if buffers is not None:  # a job still waiting keeps copies: the next round reuses
            done_now = {j for j, _ in ready}
            for j, i in chosen:
                if j not in done_now:
                    b = waiting[j][1][i]
                    waiting[j][1][i] = BatchResult(
                        b.x1.copy(), b.x2.copy(), b.u.copy(), b.region.copy(), b.mismatch
                    )
        for j, stage in ready:
            sent = waiting.pop(j)[1]
            resume(j, sent, stage)
        if on_round is not None:
            on_round(out.rounds, done, len(jobs))
    if waiting:  # a job waits on nothing: cannot happen (every ask is queued)
        raise RuntimeError("run_lockstep: a job is waiting on asks that were never queued")
    return out
