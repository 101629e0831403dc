"""Distributing the robustness maps on a ``dask.distributed`` cluster (optional extra)."""

from __future__ import annotations

from typing import Any

from ptoverify.studies import cluster as dask_cluster
from ptoverify.studies.cluster import check_dask_address
from ptoverify.studies.robust.maps import Runner, map_task

__all__ = ["DASK_CONNECT_TIMEOUT_S", "check_dask_address", "dask_runner"]

#: how long to wait for a Dask scheduler [s]
DASK_CONNECT_TIMEOUT_S = dask_cluster.DASK_CONNECT_TIMEOUT_S


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
        return dask_cluster.dask_map(address, _star_map_task, list(tasks))

    return run


def _star_map_task(task: tuple) -> Any:
    """Run one map task from its argument tuple (a picklable top-level function)."""
    return map_task(*task)
