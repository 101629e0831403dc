"""Distributing the robustness maps on a ``dask.distributed`` cluster (optional extra)."""

from __future__ import annotations

import re
from typing import Any

from ptoverify.errors import ClusterError, InputError
from ptoverify.studies.robust.maps import Runner, map_task

__all__ = ["DASK_CONNECT_TIMEOUT_S", "check_dask_address", "dask_runner"]

DASK_CONNECT_TIMEOUT_S = 10.0  #: how long to wait for a Dask scheduler [s]
_ADDRESS = re.compile(r"^(tcp|tls|ucx|inproc|ws|wss)://[^\s/:]+(:\d{1,5})?$|^local$")


def check_dask_address(address: str) -> str:
    """Validate ``--dask``: ``local`` or ``PROTOCOL://HOST:PORT``.

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
        A malformed address (exit 2); an unreachable one is a
        :class:`ptoverify.errors.ClusterError` when the run connects.

    Examples
    --------
    >>> check_dask_address("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    """
    if not _ADDRESS.match(address):
        raise InputError(
            f"--dask must be 'local' or a scheduler address like tcp://HOST:PORT, got {address!r}"
        )
    return address


def dask_runner(address: str) -> Runner:
    """Return a runner for :func:`robust_maps` on a ``dask.distributed`` cluster.

    Parameters
    ----------
    address : str
        Scheduler address (``tcp://host:port``), or ``local`` to start a
        LocalCluster of 2 worker processes on this machine for the run.

    Returns
    -------
    callable
        ``runner(tasks) -> results`` in task order.

    Raises
    ------
    InputError
        A malformed address.
    ClusterError
        (When the runner runs) the scheduler could not be reached within
        :data:`DASK_CONNECT_TIMEOUT_S`.
    """
    check_dask_address(address)

    def run(tasks: list[tuple]) -> list[Any]:
        from dask.distributed import Client, LocalCluster

        if address == "local":
            with (
                LocalCluster(
                    n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
                ) as cluster,
                Client(cluster) as client,
            ):
                return client.gather(client.map(map_task, *zip(*tasks, strict=True), pure=False))
        try:
            client = Client(address, timeout=DASK_CONNECT_TIMEOUT_S)
        except OSError as exc:  # TimeoutError and refused connections
            raise ClusterError(
                f"cannot reach the Dask scheduler at {address} within "
                f"{DASK_CONNECT_TIMEOUT_S:g} s ({type(exc).__name__}); start it, or use --dask local"
            ) from None
        with client:
            return client.gather(client.map(map_task, *zip(*tasks, strict=True), pure=False))

    return run
