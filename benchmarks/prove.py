"""Benchmark of ``ptoverify prove`` against the targets of issue 24 (not a timed test).

Run: ``.venv/bin/python benchmarks/prove.py [--dask local]``; writes
``benchmarks/prove_results.json``: wall times [s], peak memory [MB], coverage,
certified worst vs simulated worst [samples], for the nominal corrected PTO (one
core) and the a-interval [0.8, 1.25] proof (in-process, or on the given cluster).
"""

from __future__ import annotations

import json
import resource
import sys
import time
from pathlib import Path

from ptoverify.config import paper_config
from ptoverify.studies.prove import parse_a_interval, run_prove


def _figures(run, wall: float) -> dict:
    p = run.proofs[0]
    return {
        "wall_s": round(wall, 2),
        "proof_s": p.timings_s["proof"],
        "coverage": {q.name: q.coverage for q in p.properties},
        "status": {q.name: q.status for q in p.properties},
        "bound_samples": p.bound_samples,
        "simulated_worst_samples": p.simulated_worst_samples,
        "cells": p.cells,
    }


def main(argv: list[str]) -> int:
    """Run the benchmark; ``--dask ADDRESS`` runs the a-interval there."""
    dask = argv[argv.index("--dask") + 1] if "--dask" in argv else None
    cfg = paper_config()
    out = {}
    t = time.perf_counter()
    out["nominal"] = _figures(run_prove(cfg, laws=("pto",)), time.perf_counter() - t)
    t = time.perf_counter()
    out["nominal_excursion_1mm"] = _figures(
        run_prove(cfg, laws=("pto",), excursion=1.0), time.perf_counter() - t
    )
    t = time.perf_counter()
    run = run_prove(
        cfg, laws=("pto",), a_interval=parse_a_interval("0.8,1.25", cfg.plant.a), dask=dask
    )
    out["a_interval_0.8_1.25"] = dict(_figures(run, time.perf_counter() - t), backend=run.backend)
    out["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    path = Path(__file__).with_name("prove_results.json")
    path.write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
