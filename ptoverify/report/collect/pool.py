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
    """Worker processes ``collect`` uses by default: the CPUs this process may use.

    Measured on this project's 2-core machine, idle (issue 23, final merge): the
    report took 28.2 s of wall time with ``--jobs 2`` against about 53 s with
    ``--jobs 1`` (the stages' times add up to 53 s), so the pool earns its place.
    An earlier measurement at a load average of 3-17 (other sessions running)
    showed no gain: on a busy machine pass ``--jobs 1``.

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


def _run_in_pool(
    names: list[str],
    cfg: Config,
    figdir: Path | None,
    jobs: int,
    finished: Callable[[str, tuple[dict[str, Any], float]], None],
) -> None:
    """Run the stages in ``jobs`` worker processes; ``finished(name, result)`` as each ends.

    The pool is a :class:`concurrent.futures.ProcessPoolExecutor` of spawned
    processes (fresh interpreters: no fork of solver or BLAS state).  Like every
    spawned pool, it imports the caller's main module in each worker: a script that
    calls :func:`collect` or :func:`write_report` with ``jobs`` > 1 needs the
    ``if __name__ == "__main__":`` guard.  The stages are submitted longest first.
    A stage's exception is raised here with its type (an ``InputError`` stays one)
    and a note naming the stage (the worker's traceback is its ``__cause__``).
    When the run ends early (a stage's error, Ctrl-C, SIGTERM), the stages not
    started are cancelled and the workers are terminated, so none goes on writing
    into ``figdir``.  Where no pool can be made, the stages run in this process.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = multiprocessing.get_context("spawn")
    others = set(multiprocessing.active_children())
    try:
        pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_setup)
    except OSError:  # no semaphores or pipes here: the stages run in this process
        for name in names:
            finished(name, _run_stage(name, cfg, figdir))
        return
    with pool:
        try:
            with _sigint_ignored_at_spawn():
                futures = {pool.submit(_run_stage, name, cfg, figdir): name for name in names}
            for future in as_completed(futures):
                name = futures[future]
                try:
                    result = future.result()
                except Exception as exc:
                    exc.add_note(f"in report stage '{name}' (worker process)")
                    raise
                finished(name, result)
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            workers = [p for p in multiprocessing.active_children() if p not in others]
            for process in workers:
                process.terminate()
            for process in workers:
                process.join()
            raise
