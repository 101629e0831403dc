"""Benchmark of ``ptoverify prove`` against the targets of issue 24 (not a timed test).

Run: ``.venv/bin/python benchmarks/prove.py [--dask local]``; writes
``benchmarks/prove_results.json``: wall and CPU times [s], peak memory [MB],
coverage, certified worst vs simulated worst [samples], for the nominal corrected
PTO (one core) and the a-interval [0.8, 1.25] proof in-process (one core) and, with
``--dask``, on the given cluster (``local``: two worker processes); the load
average at the start says how busy the machine was.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from pathlib import Path

from ptoverify.config import paper_config
from ptoverify.studies.prove import parse_a_interval, run_prove


def _figures(run, wall: float, cpu: float) -> dict:
    p = run.proofs[0]
    return {
        "wall_s": round(wall, 2),
        "cpu_s_this_process": round(cpu, 2),
        "proof_s": p.timings_s["proof"],
        "coverage": {q.name: q.coverage for q in p.properties},
        "status": {q.name: q.status for q in p.properties},
        "bound_samples": p.bound_samples,
        "simulated_worst_samples": p.simulated_worst_samples,
        "certified_max_ratio_nt": p.certified_max_ratio_nt,
        "excluded_radius_mm": p.excluded_radius,
        "cells": p.cells,
    }


def main(argv: list[str]) -> int:
    """Run the benchmark; ``--dask ADDRESS`` runs the a-interval there."""
    dask = argv[argv.index("--dask") + 1] if "--dask" in argv else None
    cfg = paper_config()
    out = {"load_average_at_start": [round(v, 2) for v in os.getloadavg()]}
    a_int = parse_a_interval("0.8,1.25", cfg.plant.a)
    cases = [
        ("nominal", {}),
        ("nominal_excursion_1mm", {"excursion": 1.0}),
        ("a_interval_0.8_1.25", {"a_interval": a_int}),
    ]
    if dask:
        cases.append(("a_interval_0.8_1.25_dask", {"a_interval": a_int, "dask": dask}))
    for key, kw in cases:
        t, c = time.perf_counter(), time.process_time()
        run = run_prove(cfg, laws=("pto",), **kw)
        fig = _figures(run, time.perf_counter() - t, time.process_time() - c)
        out[key] = dict(fig, backend=run.backend, pieces=len(run.proofs[0].balls))
    out["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    path = Path(__file__).with_name("prove_results.json")
    path.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
