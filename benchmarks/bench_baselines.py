"""Timings of issue 25: penalty curves, design charts, dask against one process.

    python benchmarks/bench_baselines.py            # penalty, 6 x 5 chart, 2 x 2 dask vs in-process
    python benchmarks/bench_baselines.py --big      # also 20 x 20 on a 2-worker LocalCluster
    python benchmarks/bench_baselines.py --json     # one JSON object
    python benchmarks/bench_baselines.py --speedup 20 --json   # N x N: dask local vs one process

Targets (the issue): penalty curves for all laws <= 10 s; the coarse (6 x 5) chart
adds <= 15 s to a report on 2 cores; a 20 x 20 chart <= 10 min on a 2-worker
LocalCluster.  Wall and CPU seconds of this process are both recorded (the
machine is shared; CPU time is the stable figure for in-process runs).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from ptoverify.config import ALL_LAW_NAMES, paper_config  # noqa: E402
from ptoverify.studies.design import dask_design_runner, design_chart  # noqa: E402
from ptoverify.studies.penalty import penalty_curves  # noqa: E402


def _timed(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w0, time.process_time() - c0


def _speedup(cfg, n: int, in_process_first: bool = False) -> dict:
    """The n x n design chart (default T and bandwidth ranges, geometric), dask local then in-process.

    The dask run goes first by default (``--in-process-first`` swaps them); either
    way no memo is warm for either run (the in-process run is this process's only
    one, and the LocalCluster's workers are fresh processes).  Wall seconds of both, this
    process's CPU seconds of the in-process run, the sum of the points' own wall
    times of each run, and whether the two charts' points are equal.
    """
    import numpy as np

    from ptoverify.studies.design import BANDWIDTHS_HZ, SAMPLE_TIMES

    ts = np.geomspace(min(SAMPLE_TIMES), max(SAMPLE_TIMES), n).tolist()
    bw = np.geomspace(min(BANDWIDTHS_HZ), max(BANDWIDTHS_HZ), n).tolist()
    out: dict = {
        "grid": f"{n} x {n}",
        "sample_times_s": [ts[0], ts[-1]],
        "bandwidths_hz": [bw[0], bw[-1]],
    }
    out["order"] = "in-process first" if in_process_first else "dask first"
    out["load_avg_start"] = os.getloadavg()[0]

    def dask_run():
        there, out["dask_local_wall_s"], _ = _timed(
            lambda: design_chart(cfg, ts, bw, runner=dask_design_runner("local"), backend="local")
        )
        out["dask_local_sum_of_points_s"] = sum(p.seconds for p in there.points)
        return there

    def local_run():
        here, out["in_process_wall_s"], out["in_process_cpu_s"] = _timed(
            lambda: design_chart(cfg, ts, bw)
        )
        out["in_process_sum_of_points_s"] = sum(p.seconds for p in here.points)
        return here

    first, second = (local_run, dask_run) if in_process_first else (dask_run, local_run)
    a = first()
    out["load_avg_between"] = os.getloadavg()[0]
    b = second()
    here, there = (a, b) if in_process_first else (b, a)
    out["load_avg_end"] = os.getloadavg()[0]
    out["speedup_wall"] = out["in_process_wall_s"] / out["dask_local_wall_s"]
    out["equal_points"] = (
        here.to_json(timings=False)["points"] == there.to_json(timings=False)["points"]
    )
    return out


def main() -> int:
    """Run the timings; print a table or JSON."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--big", action="store_true", help="also the 20 x 20 chart (minutes)")
    ap.add_argument(
        "--speedup",
        type=int,
        default=None,
        metavar="N",
        help="only the N x N chart over the default ranges, --dask local (2 workers) and then "
        "in this one process, side by side (issue 25, third round)",
    )
    ap.add_argument("--in-process-first", action="store_true", help="with --speedup")
    args = ap.parse_args()
    cfg = paper_config()
    if args.speedup is not None:
        out = _speedup(cfg, args.speedup, args.in_process_first)
        print(
            json.dumps(out, indent=2)
            if args.json
            else "\n".join(f"{k:<42} {v}" for k, v in out.items())
        )
        return 0
    out: dict = {"load_avg_start": os.getloadavg()[0]}
    penalty_curves(cfg, ("pd",), count=4)  # imports and first-call costs out of the timing
    _, out["penalty_all_laws_wall_s"], out["penalty_all_laws_cpu_s"] = _timed(
        lambda: penalty_curves(cfg, ALL_LAW_NAMES)
    )
    _, out["design_6x5_wall_s"], out["design_6x5_cpu_s"] = _timed(lambda: design_chart(cfg))
    axes = ([0.002, 0.004], [30.0, 60.0])
    here, out["design_2x2_in_process_wall_s"], _ = _timed(lambda: design_chart(cfg, *axes))
    there, out["design_2x2_dask_local_wall_s"], _ = _timed(
        lambda: design_chart(cfg, *axes, runner=dask_design_runner("local"), backend="local")
    )
    out["design_2x2_dask_equals_in_process"] = (
        here.to_json(timings=False)["points"] == there.to_json(timings=False)["points"]
    )
    if args.big:
        import numpy as np

        ts = np.geomspace(0.00025, 0.008, 20).tolist()
        bw = np.geomspace(5.0, 100.0, 20).tolist()
        big, out["design_20x20_dask_local_wall_s"], _ = _timed(
            lambda: design_chart(cfg, ts, bw, runner=dask_design_runner("local"), backend="local")
        )
        out["design_20x20_sum_of_point_s"] = sum(p.seconds for p in big.points)
        out["design_20x20_speedup_vs_one_process_est"] = (
            out["design_20x20_sum_of_point_s"] / out["design_20x20_dask_local_wall_s"]
        )
    out["load_avg_end"] = os.getloadavg()[0]
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        for k, v in out.items():
            print(f"{k:<42} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
