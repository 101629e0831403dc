"""Timings of issue 25: penalty curves, design charts, dask against one process.

    python benchmarks/bench_baselines.py            # penalty, 6 x 5 chart, 2 x 2 dask vs in-process
    python benchmarks/bench_baselines.py --big      # also 20 x 20 on a 2-worker LocalCluster
    python benchmarks/bench_baselines.py --json     # one JSON object

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


def main() -> int:
    """Run the timings; print a table or JSON."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--big", action="store_true", help="also the 20 x 20 chart (minutes)")
    args = ap.parse_args()
    cfg = paper_config()
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
