"""Every command's ``--dask`` run equals its in-process run, on one real LocalCluster.

The cluster (2 single-threaded worker processes, as ``--dask local`` starts) is this
module's, reached by its ``tcp://`` address as ``--dask HOST:PORT`` reaches a
scheduler; every command goes through ``studies.cluster.dask_map``, whose ``local``
branch starts such a cluster and then does the same.  One cluster for the three
commands instead of one each (a start costs about 1.5 s and 2 s of CPU; an idle
cluster about 8 % of a core, so it lives only as long as this module's tests).
``--dask local`` itself is run by ``test_robust_cli`` (in-process) and ``test_cluster``
(the command line: its scratch space, its signals, an unreachable scheduler).
"""

from __future__ import annotations

import contextlib
import io
import json
import logging

import pytest
from conftest import ROBUST_SMALL, assert_same_proof

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.studies.design import dask_design_runner, design_chart
from ptoverify.studies.prove import run_prove
from ptoverify.studies.prove.ball import Resolution

CFG = paper_config()


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory) -> str:
    """The ``tcp://`` address of the module's LocalCluster."""
    import dask
    from dask.distributed import LocalCluster

    scratch = tmp_path_factory.mktemp("dask-scratch")
    with dask.config.set({"temporary-directory": str(scratch)}):
        cluster = LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            # an HTTP port of its own: 8787, Dask's default, stays free for the
            # clusters ``--dask local`` starts in other tests meanwhile
            dashboard_address="127.0.0.1:0",
            silence_logs=logging.CRITICAL,
        )
    with cluster:
        assert cluster.scheduler_address.startswith("tcp://")
        yield cluster.scheduler_address


@pytest.mark.slow
def test_design_chart(scheduler):
    """2 x 2 chart, every law: the cluster gives exactly the in-process result."""
    args = dict(laws=("pd", "pto", "ptos", "cascade-p"), grid=4)
    here = design_chart(CFG, [0.002, 0.004], [30.0, 60.0], **args)
    there = design_chart(CFG, [0.002, 0.004], [30.0, 60.0], runner=dask_design_runner(scheduler),
                         backend=scheduler, **args)  # fmt: skip
    assert here.to_json(timings=False)["points"] == there.to_json(timings=False)["points"]
    assert there.backend == scheduler


@pytest.mark.slow
def test_prove_sub_intervals_and_blocks(scheduler):
    """Sub-intervals of a, whole (one job each, the cluster's default) and in blocks of
    cells (3 each): the in-process proof exactly, array by array."""
    a0 = CFG.plant.a
    coarse = Resolution(h1=0.2, h2=20.0, h1_max=5.0, h_edge=0.5, steps=40)  # ~2,000 cells
    kw = dict(laws=("pd",), a_interval=(0.99 * a0, 1.01 * a0), pieces=2, n_random=100, res=coarse)
    here = run_prove(CFG, **kw)
    for blocks in (None, 700):
        there = run_prove(CFG, dask=scheduler, block_cells=blocks, **kw)
        assert_same_proof(here.proofs[0], there.proofs[0])
        assert there.backend == f"dask:{scheduler}"


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.slow
def test_robust_maps_through_the_command_line(scheduler, tmp_path):
    """``robust --dask tcp://...`` (PD and the printed PTO, no search): the same maps."""
    config = tmp_path / "small.toml"
    config.write_text(ROBUST_SMALL)
    argv = ["robust", "--config", str(config), "--law", "pd", "--law", "pto-printed",
            "--grid", "3", "--generations", "0", "--population", "8", "--quiet",
            "--json"]  # fmt: skip
    code, here, err = _run(argv)
    assert code == 0, err
    code, there, err = _run([*argv, "--dask", scheduler])
    assert code == 0, err
    here, there = json.loads(here), json.loads(there)
    assert there["backend"] == scheduler
    assert here["maps"] == there["maps"] and here["worst"] == there["worst"]
