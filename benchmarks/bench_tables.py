"""Timings of ``conform --table`` on the emitted grid, and of its one CSV reader.

    python benchmarks/bench_tables.py          # table
    python benchmarks/bench_tables.py --json   # one JSON object

The table is the one a firmware team writes: the states of ``conform --emit-grid``
(about 212,000 rows) and the reference's u, each number as Python's repr.  Timed
in this process (imports not counted), best of ``--repeat`` runs, wall and CPU
seconds (the machine is shared; CPU is the stable figure):

- ``read_columns``: :func:`ptoverify.tables.read_columns` of x1, x2, u;
- ``conform_table``: ``ptoverify conform --table FILE --json`` through ``cli.main``;
- what the reader's time is made of: the rows split by one ``csv.reader`` alone,
  the three columns' text to float64 by ``np.array(..., dtype=float)`` alone (what
  the reader does), and ``np.loadtxt`` of the same lines (a C parser with another
  accepted syntax: no Python ``float`` forms such as ``1_0``, no line numbers), for
  comparison only.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from ptoverify.cli import main  # noqa: E402
from ptoverify.config import paper_config  # noqa: E402
from ptoverify.conform.gate import reference_law  # noqa: E402
from ptoverify.tables import read_columns  # noqa: E402


def _best(fn, repeat: int) -> dict:
    """Best wall and best CPU seconds of ``repeat`` calls of ``fn``."""
    wall, cpu = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return {"wall_s": min(wall), "cpu_s": min(cpu)}


def _table(folder: Path) -> Path:
    """The emitted grid and the reference's u at it, written as a firmware team would."""
    grid = folder / "grid.csv"
    assert main(["conform", "--emit-grid", str(grid)]) == 0
    rows = grid.read_text().splitlines()[1:]
    x = np.array([[float(v) for v in r.split(",")] for r in rows])
    u = reference_law(x[:, 0], x[:, 1], paper_config())
    table = folder / "table.csv"
    with open(table, "w") as fh:
        fh.write("x1,x2,u\n")
        fh.writelines(f"{r},{v!r}\n" for r, v in zip(rows, u.tolist()))
    return table


def run(repeat: int) -> dict:
    """Time the reader and the command; return the figures."""
    with tempfile.TemporaryDirectory() as tmp:
        table = _table(Path(tmp))
        with open(table) as fh:
            fh.readline()
            lines = fh.readlines()
        rows = list(csv.reader(lines))
        texts = [[r[j] for r in rows] for j in range(3)]

        def command():
            with contextlib.redirect_stdout(io.StringIO()):
                assert main(["conform", "--table", str(table), "--json"]) == 0

        command()  # imports and memos, once
        out = {
            "rows": len(lines),
            "load_avg_start": os.getloadavg()[0],
            "read_columns": _best(lambda: read_columns(table, ("x1", "x2", "u")), repeat),
            "conform_table": _best(command, repeat),
            "csv_reader_alone": _best(lambda: list(csv.reader(lines)), repeat),
            "float_columns_alone": _best(lambda: [np.array(t, dtype=float) for t in texts], repeat),
            "np_loadtxt_alone": _best(
                lambda: np.loadtxt(lines, delimiter=",", comments=None), repeat
            ),
        }
        out["load_avg_end"] = os.getloadavg()[0]
    return out


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--repeat", type=int, default=5, help="runs of each timing (best kept)")
    return ap.parse_args(argv)


if __name__ == "__main__":
    args = parse_args()
    res = run(args.repeat)
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        print(f"{res['rows']} rows, load {res['load_avg_start']:.1f}-{res['load_avg_end']:.1f}")
        for key, v in res.items():
            if isinstance(v, dict):
                print(f"{key:<22} wall {v['wall_s']:.3f} s   cpu {v['cpu_s']:.3f} s")
