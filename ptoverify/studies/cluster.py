"""Reaching a Dask scheduler: the address checked up front, every network step time-boxed.

Decisions (issue 28):

* ``--dask`` is ``local`` (a LocalCluster on this machine) or ``tcp://HOST:PORT``
  with a port in 1..65535.  Everything else is bad input (exit 2) at once,
  before any computation: ``''``, ``inproc://`` (an address inside one process,
  meaningless to a command line), ``tls://`` and ``wss://`` (they need
  certificates that the command line has no option for), ``ucx://`` (an
  optional transport), a missing or out-of-range port.
* Connecting is time-boxed as a whole: the client is built in a daemon thread
  and the caller waits at most ``timeout``; a listener that accepts and never
  answers, one that answers garbage (which Dask may read as an absurd message
  length and fail with ``MemoryError``), a refused connection or an unknown
  host all become :class:`~ptoverify.errors.ClusterError` (exit 1) naming the
  address and the cause, within the time box.
"""

from __future__ import annotations

import logging
import re
import tempfile
import threading
from typing import Any

from ptoverify.errors import ClusterError, InputError

__all__ = ["DASK_CONNECT_TIMEOUT_S", "check_dask_address", "connect", "ensure_reachable"]

#: how long to wait for a Dask scheduler, all steps [s]; with the start of the command
#: (imports, about 2 s; more on a loaded machine) a run against a silent listener ends
#: within the 10 s the README states: every command checks the scheduler before its work
DASK_CONNECT_TIMEOUT_S = 3.0
_TCP = re.compile(r"^tcp://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>\d{1,5})$")


def check_dask_address(address: str) -> str:
    """Validate ``--dask``: ``local`` or ``tcp://HOST:PORT`` (port 1..65535).

    Parameters
    ----------
    address : str
        The address given.

    Returns
    -------
    str
        The address, unchanged.

    Raises
    ------
    InputError
        Any other address (exit 2), with the reason.

    Examples
    --------
    >>> check_dask_address("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    """
    if address == "local":
        return address
    scheme = address.split("://", 1)[0] if "://" in address else ""
    if scheme and scheme != "tcp":
        raise InputError(
            f"--dask {address!r}: only tcp://HOST:PORT or 'local' are supported "
            f"({scheme}:// is not)"
        )
    m = _TCP.match(address)
    if m is None:
        raise InputError(
            f"--dask must be 'local' or a scheduler address like tcp://HOST:PORT, got {address!r}"
        )
    port = int(m["port"])
    if not 1 <= port <= 65535:
        raise InputError(f"--dask {address!r}: port {port} is not in 1..65535")
    return address


def connect(address: str, timeout: float = DASK_CONNECT_TIMEOUT_S) -> Any:
    """Connect a ``dask.distributed.Client`` to a scheduler within ``timeout``.

    Parameters
    ----------
    address : str
        ``tcp://HOST:PORT`` (checked by :func:`check_dask_address`).
    timeout : float
        Budget for every step of connecting [s].

    Returns
    -------
    dask.distributed.Client
        A connected client (close it, e.g. with ``with client:``).

    Raises
    ------
    InputError
        A malformed address.
    ClusterError
        No scheduler answered within ``timeout``, or what answered is not one.
    """
    check_dask_address(address)
    if address == "local":
        raise InputError("connect() needs a scheduler address; 'local' starts its own cluster")
    from dask.distributed import Client

    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            box["client"] = Client(address, timeout=timeout)
        except BaseException as exc:  # noqa: BLE001 - any failure here is the cluster's
            box["error"] = exc

    worker = threading.Thread(target=attempt, name="ptoverify-dask-connect", daemon=True)
    worker.start()
    worker.join(timeout)
    if worker.is_alive():
        raise ClusterError(
            f"cannot reach the Dask scheduler at {address}: no answer within {timeout:g} s "
            "(is it a Dask scheduler?); start it, or use --dask local"
        )
    if "error" in box:
        exc = box["error"]
        raise ClusterError(
            f"cannot reach the Dask scheduler at {address} ({type(exc).__name__}: "
            f"{' '.join(str(exc).split())[:200]}); start it, or use --dask local"
        )
    return box["client"]


def ensure_reachable(address: str) -> None:
    """Check ``address`` and that a scheduler answers there, before any computation.

    A command calls it first, so that an unreachable or silent scheduler ends the
    run within :data:`DASK_CONNECT_TIMEOUT_S` of start-up, not after its set-up work
    (the study then connects again: a few milliseconds for a real scheduler).

    Parameters
    ----------
    address : str
        ``local`` (nothing to reach: the study starts its own cluster) or
        ``tcp://HOST:PORT``.

    Raises
    ------
    InputError
        A malformed address, or Dask not installed.
    ClusterError
        No scheduler answered within :data:`DASK_CONNECT_TIMEOUT_S`.
    """
    check_dask_address(address)
    if address == "local":
        return
    try:
        import dask.distributed  # noqa: F401 - what connect() needs
    except ImportError:
        raise InputError("--dask needs dask.distributed: pip install 'ptoverify[dask]'") from None
    connect(address).close()


def dask_map(address: str, fn: Any, jobs: list) -> list:
    """Run ``fn`` on every job on a ``dask.distributed`` cluster; results in job order.

    The one way every command (``robust``, ``design``, ``prove``) uses Dask.

    Parameters
    ----------
    address : str
        ``local`` (a LocalCluster of 2 worker processes started for the call and
        closed after it) or ``tcp://HOST:PORT`` (an existing scheduler, reached
        within :data:`DASK_CONNECT_TIMEOUT_S`).
    fn : callable
        A picklable function of one job.
    jobs : list
        The jobs.

    Returns
    -------
    list
        ``[fn(job) for job in jobs]``, computed on the cluster.

    Raises
    ------
    InputError
        A malformed address, or Dask not installed (the optional extra ``ptoverify[dask]``).
    ClusterError
        The scheduler could not be reached.
    """
    check_dask_address(address)
    try:
        import dask
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError("--dask needs dask.distributed: pip install 'ptoverify[dask]'") from None
    jobs = list(jobs)
    if address == "local":
        with (
            # the cluster's scratch space in a folder of this run, removed after the
            # cluster closes (Dask's default, $TMPDIR/dask-scratch-space, stayed; run 7)
            tempfile.TemporaryDirectory(prefix="ptoverify-dask-") as scratch,
            dask.config.set({"temporary-directory": scratch}),
            LocalCluster(
                n_workers=2,
                threads_per_worker=1,
                processes=True,
                # the scheduler serves HTTP whatever this says: a port of its own, as
                # Dask's default 8787 may be another cluster's ("Port 8787 is already in
                # use" was a three-line warning on the command's stderr)
                dashboard_address="127.0.0.1:0",
                # the workers' own logs (a heartbeat to a scheduler closed by SIGINT or
                # SIGTERM logs a traceback) stay off the command's stderr; a task's
                # exception still reaches gather (audit run 7)
                silence_logs=logging.CRITICAL,
            ) as cluster,
            Client(cluster) as client,
        ):
            return _gather(client, fn, jobs)
    with connect(address) as client:
        return _gather(client, fn, jobs)


def _gather(client: Any, fn: Any, jobs: list) -> list:
    """Map ``fn`` over ``jobs`` on ``client``; on an interruption, a quiet teardown.

    SIGINT or SIGTERM (``outdir.Terminated``, a BaseException) while waiting leaves the
    client's waits to end with ``AllExit`` as the cluster closes, which asyncio and
    Dask log, with tracebacks, on stderr (audit run 7: 170 lines before the one
    ``interrupted`` line).  The process is ending, so their loggers are silenced
    before the exception goes on; results and ordinary failures are unchanged.
    """
    try:
        return client.gather(client.map(fn, jobs, pure=False))
    except BaseException as exc:
        if not isinstance(exc, Exception):  # KeyboardInterrupt, SIGTERM's Terminated, exit
            for name in ("asyncio", "distributed", "tornado"):
                logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        raise
