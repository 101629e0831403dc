"""Speed and agreement of the minimum-time references (issue 4).

Run: python benchmarks/bench_ocp.py [--states 500]  (prints one JSON object).

* two-phase OCP: warm solve time, median over 50 random states (target 20 ms);
* collocation N = 100: solve time, median over 20 states (target 150 ms), cold
  (the default) and warm-started;
* N* for a 50 mm step from rest on the paper plant (target 50 ms);
* agreement with the closed form and the distribution of N* T - t_f* (in
  samples T) over random states of three plants;
* the collocation convergence study (t_f error vs N, observed order).
"""

import argparse
import json
import time

import numpy as np

from ptoverify.config import Plant, paper_config
from ptoverify.model.mintime import ZOHReach, discrete_min_steps, min_time
from ptoverify.model.ocp import CollocationOCP, TwoPhaseOCP, convergence_study

PLANTS = {
    "paper": paper_config().plant,
    "slow-a": Plant(a=30.0, w_max=300.0, sample_time=0.002, position_range=50.0),
    "fine-T": Plant(a=100.0, w_max=100.0, sample_time=0.001, position_range=20.0),
}


def states(plant, n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.uniform(-1, 1, n) * plant.position_range,
            rng.uniform(-1, 1, n) * plant.w_max * (1 - 1e-9),
        ]
    )


def quantiles(x):
    x = np.asarray(x, dtype=float)
    return {
        q: float(np.quantile(x, p))
        for q, p in (("min", 0), ("p05", 0.05), ("median", 0.5), ("p95", 0.95), ("max", 1))
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=500)
    args = ap.parse_args()
    plant = PLANTS["paper"]
    out = {}

    tp = TwoPhaseOCP(plant)
    tp.solve(10.0, 0.0)
    S = states(plant, 50, 21)
    times = [tp.solve(x1, x2).solve_time_s for x1, x2 in S]
    out["two_phase_warm_ms"] = quantiles(1e3 * np.array(times))

    S = states(plant, 20, 22)
    for warm in (False, True):
        co = CollocationOCP(plant, 100, warm_start=warm)
        co.solve(10.0, 0.0)
        res = [co.solve(x1, x2) for x1, x2 in S]
        key = "collocation100_warm" if warm else "collocation100_cold"
        out[key + "_ms"] = quantiles([1e3 * r.solve_time_s for r in res])
        out[key + "_iterations"] = quantiles([r.iterations for r in res])

    discrete_min_steps(50.0, 0.0, plant)  # imports, generator table
    t = []
    for _ in range(20):
        t0 = time.perf_counter()
        d = discrete_min_steps(50.0, 0.0, plant)
        t.append(time.perf_counter() - t0)
    out["discrete_50mm_step"] = {
        "steps": d.steps,
        "lp_solves": d.lp_solves,
        "ms": quantiles(1e3 * np.array(t)),
    }

    for name, pl in PLANTS.items():
        S = states(pl, args.states, 23)
        mt = min_time(S[:, 0], S[:, 1], pl)
        tp = TwoPhaseOCP(pl)
        r2 = [tp.solve(x1, x2) for x1, x2 in S]
        rel2 = np.abs(np.array([r.t_f for r in r2]) - mt.t_f) / mt.t_f
        sw2 = np.abs(np.array([r.t_switch for r in r2]) - mt.t_switch)
        co = CollocationOCP(pl, 100)
        rc = [co.solve(x1, x2) for x1, x2 in S[:60]]
        relc = np.abs(np.array([r.t_f for r in rc]) - mt.t_f[:60]) / mt.t_f[:60]
        reach = ZOHReach(pl)
        t0 = time.perf_counter()
        dm = [discrete_min_steps(x1, x2, pl, reach=reach) for x1, x2 in S]
        el = time.perf_counter() - t0
        gap = np.array([x.time_s for x in dm]) - mt.t_f
        out[name] = {
            "states": len(S),
            "two_phase_failures": int(sum(not r.success for r in r2)),
            "two_phase_rel_err": quantiles(rel2),
            "two_phase_switch_err_s": quantiles(sw2),
            "collocation100_states": len(rc),
            "collocation100_failures": int(sum(not r.success for r in rc)),
            "collocation100_rel_err": quantiles(relc),
            "collocation100_resim_error_mm": quantiles([r.resim_error for r in rc]),
            "discrete_status": sorted({x.status for x in dm}),
            "discrete_gap_in_T": quantiles(gap / pl.sample_time),
            "discrete_gap_histogram_T": np.histogram(
                gap / pl.sample_time, bins=np.linspace(0, 1.5, 7)
            )[0].tolist(),
            "discrete_ms_per_state": 1e3 * el / len(S),
        }

    cs = [(50.0, 0.0), (5.0, 0.0), (0.5, 0.0), (-20.0, 250.0), (30.0, -299.0)]
    for control in ("points", "interval"):
        st = convergence_study(plant, cs, control=control)
        out[f"convergence_{control}"] = {
            "intervals": st.intervals.tolist(),
            "states": st.states.tolist(),
            "rel_error": st.rel_error.tolist(),
            "resim_error_mm": st.resim_error.tolist(),
            "order_per_state": st.order_per_state.tolist(),
            "order": st.order,
            "all_converged": bool(st.success.all()),
        }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
