"""The tuning's step screen against the ``simulate --json`` path, on 1e5 gain sets.

``tune`` measures candidates with :class:`ptoverify.studies.tune.screen.StepScreen`
(every gain set of a batch in one simulation, per-state gains), a second path
beside :func:`ptoverify.studies.tune.measure.evaluate` (one ``simulate --json``
run per gain set).  The project's rule for a second path: it must earn at least
3x on a user-visible command, and agree with the first within a stated tolerance
on at least 1e5 seeded random inputs plus the edge sets.  This script measures
both, side by side, and writes ``benchmarks/verify_screen_results.json``::

    python benchmarks/verify_screen.py              # 1e5 gain sets, every core
    python benchmarks/verify_screen.py --n 2000     # a quick look

Inputs: ``n`` gain sets split evenly over PD, PTO, PTOS and cascade P, drawn
uniformly in the search coordinates of ``tune`` (log10 where ``LOG_GAINS``), the
PTO's d from 16 values spanning its range; plus the edge sets: every corner of
each law's search box, gains of zero where the box allows it.  The screen is
called in batches of sizes cycling through 1, 2, 3, 7, 64, 1000 and 5000 (a
result must not depend on its batch).  Compared per gain set: feasibility under
overshoot bounds 0.05 mm and 1 mm (must agree exactly), overshoot [mm] and the
2 % and 0.01 mm settling times [s] (both NaN, or within ``TOL`` absolute).
The speed figures are the per-gain-set time of each path, measured in the same run:
the screen over the whole agreement run (its cycling batch sizes) and by batch size
(1, 32, 256, 2000 PD gain sets), ``evaluate`` once per gain set.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if sys.path[0] != str(ROOT):  # measure this tree, not another editable install
    sys.path.insert(0, str(ROOT))

from ptoverify.config import paper_config  # noqa: E402
from ptoverify.studies.tune import measure as tm  # noqa: E402
from ptoverify.studies.tune import screen as sm  # noqa: E402

#: Agreement required of the screen [mm] and [s] (round-off of the two summation orders).
TOL = 1e-12
LAWS = ("pd", "pto", "ptos", "cascade-p")
BATCHES = (1, 2, 3, 7, 64, 1000, 5000)
BOUNDS_MM = (0.05, 1.0)


def draw(law: str, n: int, rng: np.random.Generator) -> list[dict[str, float]]:
    """``n`` random gain sets of ``law`` in tune's search box, then its edge set."""
    box = tm.BOUNDS[law]
    out = []
    d_values = np.geomspace(*box["d"], 16) if law == "pto" else None
    for _ in range(n):
        g = {}
        for k, (lo, hi) in box.items():
            if k == "d":
                g[k] = float(rng.choice(d_values))
            elif k in tm.LOG_GAINS:
                g[k] = float(10 ** rng.uniform(math.log10(lo), math.log10(hi)))
            else:
                g[k] = float(rng.uniform(lo, hi))
        out.append(g)
    keys = list(box)
    for corner in itertools.product(*(box[k] for k in keys)):  # the edge set
        out.append({k: float(v) for k, v in zip(keys, corner, strict=True)})
    return out


def screen_all(law: str, gains: list[dict[str, float]]):
    """The screen's responses, in batches of the cycling sizes (a fresh screen each)."""
    cfg = paper_config()
    out, i = [], 0
    t0 = time.perf_counter()
    for size in itertools.cycle(BATCHES):
        if i >= len(gains):
            break
        out += sm.StepScreen(cfg, law, True)(gains[i : i + size])
        i += size
    return out, time.perf_counter() - t0


def compare(args):
    """Evaluate one chunk on the simulate --json path and compare with the screen's numbers."""
    law, gains, raws = args
    cfg = paper_config()
    worst = {"overshoot_mm": 0.0, "settling_2pct_s": 0.0, "settling_0p01mm_s": 0.0}
    bad: list[str] = []
    spent = 0.0
    for g, raw in zip(gains, raws, strict=True):
        for k, bound in enumerate(BOUNDS_MM):
            t0 = time.perf_counter()
            ref = tm.evaluate(cfg, law, g, max_overshoot=bound)
            spent += time.perf_counter() - t0 if k == 0 else 0.0  # the first call simulates
            cand = sm.screened_candidate(
                cfg, law, g, raw, objective="settling_2pct", max_overshoot=bound, worst_ratio=None
            )
            if cand.feasible != ref.feasible:
                bad.append(f"{law} {g} bound {bound}: screen {cand.reason!r}, ref {ref.reason!r}")
        if raw.reason or not math.isfinite(ref.overshoot_mm):
            continue  # not measured (unstable loop, no zone): the feasibility check above
        pairs = (
            ("overshoot_mm", raw.overshoot_mm, ref.overshoot_mm),
            ("settling_2pct_s", raw.settling_2pct_s, ref.settling_2pct_s),
            ("settling_0p01mm_s", raw.settling_0p01mm_s, ref.settling_0p01mm_s),
        )
        for name, a, b in pairs:
            if math.isnan(a) and math.isnan(b):
                continue
            if math.isnan(a) != math.isnan(b) or math.isinf(a) != math.isinf(b):
                bad.append(f"{law} {g} {name}: screen {a!r}, ref {b!r}")
                continue
            if math.isinf(a):
                continue
            worst[name] = max(worst[name], abs(a - b))
            if abs(a - b) > TOL:
                bad.append(f"{law} {g} {name}: screen {a!r}, ref {b!r}")
    return law, len(gains), worst, bad, spent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000, help="random gain sets in all")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seed", type=int, default=20261203)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "verify_screen_results.json"))
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    started = time.time()
    work, screen_s, count = [], 0.0, 0
    for law in LAWS:
        gains = draw(law, args.n // len(LAWS), rng)
        raws, dt = screen_all(law, gains)
        screen_s += dt
        count += len(gains)
        step = 500
        work += [(law, gains[i : i + step], raws[i : i + step]) for i in range(0, len(gains), step)]
    totals = {law: {"gain_sets": 0, "worst_abs": {}, "disagreements": 0} for law in LAWS}
    examples: list[str] = []
    eval_s = 0.0
    with ProcessPoolExecutor(args.jobs) as pool:
        for law, n, worst, bad, dt in pool.map(compare, work):
            t = totals[law]
            t["gain_sets"] += n
            for k, v in worst.items():
                t["worst_abs"][k] = max(t["worst_abs"].get(k, 0.0), v)
            t["disagreements"] += len(bad)
            examples += bad[: max(0, 10 - len(examples))]
            eval_s += dt
    per_screen = screen_s / count
    per_eval = eval_s / count
    # speed by batch size: a fresh screen per batch, PD gain sets (tune's batches are a
    # generation of differential evolution, merged over the searches that run side by side)
    cfg, speed = paper_config(), {}
    sample = draw("pd", 2000, np.random.default_rng(args.seed + 1))[:2000]
    for size in (1, 32, 256, 2000):
        t0 = time.perf_counter()
        for i in range(0, len(sample), size):
            sm.StepScreen(cfg, "pd", True)(sample[i : i + size])
        speed[str(size)] = 1e3 * (time.perf_counter() - t0) / len(sample)
    result = {
        "gain_sets": count,
        "tolerance_abs": TOL,
        "batch_sizes": list(BATCHES),
        "by_law": totals,
        "disagreement_examples": examples,
        "screen_ms_per_gain_set": 1e3 * per_screen,
        "evaluate_ms_per_gain_set": 1e3 * per_eval,
        "speedup": per_eval / per_screen,
        "screen_ms_per_gain_set_by_batch": speed,
        "speedup_by_batch": {k: 1e3 * per_eval / v for k, v in speed.items()},
        "seed": args.seed,
        "jobs": args.jobs,
        "started_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(started)),
        "wall_s": time.time() - started,
        "load_at_end": [round(x, 2) for x in os.getloadavg()],
    }
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps({k: result[k] for k in ("gain_sets", "speedup_by_batch", "by_law")}, indent=1))
    return 0 if not any(t["disagreements"] for t in totals.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
