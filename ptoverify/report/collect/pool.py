"""Run the report's stages in a pool of spawned worker processes."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ptoverify.config import Config

from .stages import _run_stage


def default_jobs() -> int:
    """Return the processes ``collect`` uses by default (this one and its workers): the CPUs.

    Measured on this project's 2-core machine (issue 23, 2026-12-03, load about 2 from
    the report itself): the report took 47.3-47.5 s of wall time with ``--jobs 2``
    (this process and one worker) against 75.4 s with ``--jobs 1``, so the pool earns
    its place (1.59x).  On a busy machine (other sessions running) the gain shrinks:
    pass ``--jobs 1`` there.

    Returns
    -------
    int
        ``len(os.sched_getaffinity(0))`` where available, else ``os.cpu_count()``
        (at least 1).
    """
    import os

    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        n = os.cpu_count() or 1
    return max(1, n)


def _worker_setup() -> None:
    """Prepare a pool worker: its stdout goes to stderr, and it leaves Ctrl-C to the parent.

    A stage's results return through the pool, so what it prints (C libraries
    included) goes to stderr and never mixes with the command's stdout (``--json``
    keeps it for one JSON object).  A terminal's Ctrl-C reaches the whole process
    group: the workers ignore it, and the parent, interrupted, stops them.
    """
    import os
    import signal

    sys.stdout.flush()
    os.dup2(2, 1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextmanager
def _sigint_ignored_at_spawn() -> Iterator[None]:
    """Ignore SIGINT while the pool spawns its workers, so that they start ignoring it.

    A worker installs :func:`_worker_setup` only after its interpreter has started
    and unpickled its task; a Ctrl-C before then would print a KeyboardInterrupt
    traceback from the worker.  An ignored signal stays ignored across ``exec``,
    and Python leaves an inherited SIG_IGN of SIGINT in place, so a worker spawned
    here never sees Ctrl-C.  The parent ignores it only while it submits (the
    workers are started by ``submit``); off the main thread nothing is changed.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _warm_up() -> None:
    """Import, as a worker's first task, what every stage uses (the parent checks meanwhile)."""
    import numpy  # noqa: F401
    import scipy.optimize  # noqa: F401

    import ptoverify.sim.simulate  # noqa: F401
    import ptoverify.studies.properties  # noqa: F401


def _run_in_pool(
    names: list[str],
    cfg: Config,
    figdir: Path | None,
    jobs: int,
    finished: Callable[[str, tuple[dict[str, Any], float]], None],
    before: Callable[[], None] | None = None,
) -> None:
    """Run the stages in this process and ``jobs - 1`` workers; ``finished(name, result)`` as each ends.

    The workers are a :class:`concurrent.futures.ProcessPoolExecutor` of spawned
    processes (fresh interpreters: no fork of solver or BLAS state).  Like every
    spawned pool, it imports the caller's main module in each worker: a script that
    calls :func:`collect` or :func:`write_report` with ``jobs`` > 1 needs the
    ``if __name__ == "__main__":`` guard.  This process is the last of the
    ``jobs``: it has the imports and the configuration already, so one spawn and
    one interpreter's start-up fewer.  ``names`` come longest first, and whichever
    process is free takes the next (a feeder thread hands an idle worker its next
    stage at once): the longest-first list schedule.

    ``before`` (the work-limit checks) runs once the workers are spawned and
    importing, and before any stage starts: if it raises, no stage runs.
    A stage's exception is raised here with its type (an ``InputError`` stays one)
    and a note naming the stage and where it ran (the worker's traceback is its
    ``__cause__``).  When the run ends early (a stage's error, Ctrl-C, SIGTERM),
    the stages not started are cancelled and the workers are terminated, so none
    goes on writing into ``figdir``.  Where no pool can be made, the stages run in
    this process.
    """
    import multiprocessing
    import threading
    from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait

    ctx = multiprocessing.get_context("spawn")
    others = set(multiprocessing.active_children())
    queue = list(names)
    try:
        if jobs < 2:
            raise OSError("one process: no workers")
        pool = ProcessPoolExecutor(max_workers=jobs - 1, mp_context=ctx, initializer=_worker_setup)
    except OSError:  # one process, or no semaphores or pipes here: the stages run in this process
        if before is not None:
            before()
        for name in queue:
            finished(name, _run_stage(name, cfg, figdir))
        return
    lock = threading.Lock()  # guards queue, running, failed, and calls of finished
    running: dict[Future, str] = {}
    failed: list[BaseException] = []
    stop = threading.Event()

    def submit_front() -> None:  # with the lock held
        while queue and len(running) < jobs - 1 and not failed and not stop.is_set():
            name = queue.pop(0)
            running[pool.submit(_run_stage, name, cfg, figdir)] = name

    def feeder() -> None:  # hands each idle worker the next stage as soon as it is free
        try:
            feed()
        except BaseException as exc:  # noqa: BLE001 - raised in the main thread
            with lock:
                failed.append(exc)

    def feed() -> None:
        while not stop.is_set():
            with lock:
                pending = list(running)
            if not pending:
                return
            done, _ = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            with lock:
                for future in done:
                    name = running.pop(future)
                    exc = future.exception()
                    if exc is not None:
                        exc.add_note(f"in report stage '{name}' (worker process)")
                        failed.append(exc)
                    else:
                        finished(name, future.result())
                if not failed:
                    submit_front()

    with pool:
        try:
            with _sigint_ignored_at_spawn():
                for _ in range(jobs - 1):  # spawns the workers; they import while we check
                    pool.submit(_warm_up)
            if before is not None:
                before()
            with lock:
                submit_front()
            thread = threading.Thread(target=feeder, name="ptoverify-report-feeder", daemon=True)
            thread.start()
            while True:
                with lock:
                    if failed:
                        raise failed[0]
                    if not queue:
                        break
                    name = queue.pop(0)
                try:
                    result = _run_stage(name, cfg, figdir)
                except Exception as exc:
                    exc.add_note(f"in report stage '{name}' (this process)")
                    raise
                with lock:
                    finished(name, result)
            thread.join()
            if failed:
                raise failed[0]
        except BaseException:
            stop.set()
            pool.shutdown(wait=False, cancel_futures=True)
            workers = [p for p in multiprocessing.active_children() if p not in others]
            for process in workers:
                process.terminate()
            for process in workers:
                process.join()
            raise
