"""The study commands robust, tune, sweep, design, penalty and prove: parse, call, format."""

from __future__ import annotations

import argparse
import json
import math

from ptoverify.errors import InputError
from ptoverify.outdir import (
    check_target,
    discard,
    make_temp,
    publish,
)

from .common import _config, _seed_int, finite_float, positive_int, print_json, to_jsonable


# ---------------------------------------------------------------- robust
def _add_robust(sub) -> None:
    p = sub.add_parser(
        "robust",
        help="robustness under model mismatch: maps, margins, worst cases",
        description="Simulate TO, PD, PTO and PTO-printed (designed for the nominal plant) on "
        "plants and measurements across the [robustness] box of the configuration (true a / "
        "design a, drive saturation, computation delay, encoder quantum, velocity noise): "
        "maps over a perturbation grid, margins in a_true / a_design, and a seeded "
        "worst-case search (differential evolution started from the grid's worst cells).",
        epilog="example:\n  ptoverify robust --json > robust.json\n"
        "  ptoverify robust --dask local --grid 21",
    )
    p.add_argument(
        "--dask",
        metavar="ADDRESS",
        default=None,
        help="run the maps on a dask.distributed scheduler (tcp://host:port), or 'local' to "
        "start a LocalCluster on this machine",
    )
    p.add_argument(
        "--grid", type=positive_int, default=15, metavar="N", help="N x N initial states (15)"
    )
    p.add_argument(
        "--law",
        action="append",
        choices=("to", "pd", "pto", "pto-printed", "ptos", "cascade-p"),
        default=None,
        help="study only this law (repeatable; default the paper's four: to, pd, pto, "
        "pto-printed; the baselines ptos, cascade-p on request)",
    )
    p.add_argument(
        "--generations",
        type=int,
        default=12,
        metavar="N",
        help="differential-evolution generations of the worst-case search (12; 0 to 500)",
    )
    p.add_argument(
        "--population",
        type=int,
        default=24,
        metavar="N",
        help="candidates per generation of each search (24; 5 to 1000)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    p.set_defaults(handler=_cmd_robust)


def _cmd_robust(args: argparse.Namespace) -> int:
    from ptoverify.commands import run_robust_study
    from ptoverify.progress import stderr_bar

    cfg = _config(args)
    if args.dask is not None:
        from ptoverify.studies.cluster import ensure_reachable

        ensure_reachable(args.dask)  # bad input or no scheduler: at once, before any work
    if not 3 <= args.grid <= 101:
        raise InputError(f"--grid must be in [3, 101], got {args.grid}")
    if not 0 <= args.generations <= 500:
        raise InputError(f"--generations must be in [0, 500], got {args.generations}")
    if not 5 <= args.population <= 1000:
        raise InputError(f"--population must be in [5, 1000], got {args.population}")
    res = run_robust_study(
        cfg,
        grid=args.grid,
        dask=args.dask,
        laws=tuple(dict.fromkeys(args.law)) if args.law else None,
        generations=args.generations,
        population=args.population,
        progress=stderr_bar(args.quiet),
    )
    if args.json:
        print_json(res)
        return 0
    for law, m in res["margins"].items():
        print(f"{law:<12} margins: {m}")
    for law, w in res["worst"].items():
        for prop, v in w.items():
            shown = "inf" if v.get("unbounded") else v["searched"]
            print(f"{law:<12} worst {prop:<18} grid {v['grid']}  searched {shown}  at {v['state']}")
    print(f"most robust linear loop: {res['most_robust']['law']}")
    return 0


# ---------------------------------------------------------------- tune
def _add_tune(sub) -> None:
    p = sub.add_parser(
        "tune",
        help="tune the gains of PD, PTO, PTOS or cascade P fairly",
        description="Search a law's gains (differential evolution, fixed seed; the PTO's "
        "omega0 from the corrected construction for each d) for the best response under an "
        "overshoot bound (between samples), a stable sampled linear loop and no limit cycle "
        "(PTO: nor stride-over) on the gate grid. Prints the gains as a TOML configuration.",
        epilog="example:\n  ptoverify tune --law pd --signal step --max-overshoot 0\n"
        "  ptoverify tune --law pto --json > tuned.json\n"
        "  ptoverify tune --law ptos --max-overshoot 0",
    )
    p.add_argument(
        "--law",
        choices=("pd", "pto", "ptos", "cascade-p"),
        required=True,
        help="law to tune (ptos, cascade-p: the baselines, same constraints)",
    )
    p.add_argument(
        "--signal", choices=("step", "ramp", "sine"), default="step", help="response (step)"
    )
    p.add_argument(
        "--max-overshoot",
        type=finite_float,
        default=None,
        metavar="MM",
        help="overshoot bound [mm], between samples (default: none)",
    )
    p.add_argument(
        "--objective",
        choices=("settling_2pct", "settling_0p01mm", "worst_ratio_nt"),
        default="settling_2pct",
        help="what to minimize (default settling_2pct); worst_ratio_nt: the worst settling / "
        "N*T over a 20 x 20 grid of the envelope",
    )
    p.add_argument("--seed", type=_seed_int, default=0, help="search seed (default 0)")
    p.add_argument(
        "--maxiter",
        type=int,
        default=30,
        metavar="N",
        help="differential-evolution generations (default 30; the PTO uses max(N/2, 5) per d)",
    )
    p.set_defaults(handler=_cmd_tune)


def _cmd_tune(args: argparse.Namespace) -> int:
    from ptoverify.studies.tune import tune

    cfg = _config(args)
    res = tune(
        cfg,
        args.law,
        args.signal,
        max_overshoot=args.max_overshoot,
        objective=args.objective,
        seed=args.seed,
        maxiter=args.maxiter,
    )
    if args.json:
        print_json(res.to_json())
        return 0
    b = res.best
    print(
        f"# best {args.law} on the {args.signal}: settling (2 %) {b.settling_2pct_s * 1e3:.4g} ms, "
        f"overshoot {b.overshoot_mm:.4g} mm, {args.objective} {b.objective:.6g}, "
        f"{res.evaluations} evaluations, "
        f"{res.seconds:.1f} s"
    )
    print(res.toml(), end="")
    return 0


# ---------------------------------------------------------------- sweep
def _add_sweep(sub) -> None:
    from ptoverify.config import ALL_LAW_NAMES

    p = sub.add_parser(
        "sweep",
        help="suboptimality of each law over a grid of initial states",
        description="Settling time of each law (to 0.01 mm and a * 0.01 mm/s, held 0.05 s) from "
        "a grid of initial states over the envelope, divided by the continuous "
        "minimum time t_f* and by the discrete limit N* T.",
        epilog="example:\n  ptoverify sweep --json\n  ptoverify sweep --out sweep-paper",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="write heat maps and sweep.json into DIR (atomically)",
    )
    p.add_argument(
        "--grid",
        type=positive_int,
        default=200,
        help="grid points per axis (default 200: 40,000 states; at most 1000)",
    )
    p.add_argument(
        "--law",
        action="append",
        choices=ALL_LAW_NAMES,
        default=None,
        help="sweep only this law (repeatable; default to, pd, pto, pto-printed)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    p.set_defaults(handler=_cmd_sweep)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from ptoverify.studies.sweep import SweepSettings, run_sweep

    cfg = _config(args)
    if args.grid < 2 or args.grid > 1000:
        raise InputError(f"--grid must be in [2, 1000], got {args.grid}")
    target = tmp = None
    if args.out is not None:
        target = check_target(args.out, config_hash=cfg.digest())
    try:
        from ptoverify.progress import stderr_bar

        bar = stderr_bar(args.quiet)
        laws = tuple(dict.fromkeys(args.law)) if args.law else SweepSettings.laws
        res = run_sweep(cfg, SweepSettings(args.grid, args.grid, laws=laws), progress=bar)
        result = res.to_json()
        if args.out is not None:
            tmp = make_temp(target)
            from ptoverify.report.plots import save_sweep

            files = save_sweep(res, tmp)
            (tmp / "sweep.json").write_text(json.dumps(to_jsonable(result), indent=2) + "\n")
            result["files"] = [str(target / f.name) for f in files] + [str(target / "sweep.json")]
            publish(tmp, target, config_hash=cfg.digest(), name=cfg.name)
            tmp = None
    finally:
        discard(tmp)
    if args.json:
        print_json(result)
    else:
        print(
            f"sweep over {result['grid']['states']} states, band {result['band_mm']} mm, "
            f"horizon {result['horizon_s']:.3f} s"
        )
        print(
            f"{'law':<12} {'settled':>8} {'median t/tf*':>13} {'worst t/tf*':>12} "
            f"{'median t/N*T':>13} {'worst t/N*T':>12}  worst state (x1 mm, x2 mm/s)"
        )
        for name, r in result["laws"].items():
            ws = r["worst_state_tf"]
            num = {
                k: "n/a" if not math.isfinite(r[k]) else f"{r[k]:.3f}"
                for k in ("median_ratio_tf", "worst_ratio_tf", "median_ratio_nt", "worst_ratio_nt")
            }
            where = "(never settles)" if not math.isfinite(ws[0]) else f"({ws[0]:.2f}, {ws[1]:.1f})"
            print(
                f"{name:<12} {r['fraction_settled']:>8.1%} {num['median_ratio_tf']:>13} "
                f"{num['worst_ratio_tf']:>12} {num['median_ratio_nt']:>13} "
                f"{num['worst_ratio_nt']:>12}  {where}"
            )
        for name, why in result["skipped"].items():
            print(f"{name:<12} skipped: {why}")
        for f in result.get("files", []):
            print(f"wrote {f}")
    return 0


# ---------------------------------------------------------------- design
def _add_design(sub) -> None:
    from ptoverify.config import ALL_LAW_NAMES, DESIGN_BANDWIDTHS_HZ, DESIGN_GRID, DESIGN_LAWS
    from ptoverify.config import DESIGN_SAMPLE_TIMES as SAMPLE_TIMES

    p = sub.add_parser(
        "design",
        help="design charts over sample time x bandwidth",
        description="Every law at the configuration's gains over a grid of sample time T x "
        "bandwidth: median and worst settling / N*T over an envelope grid, the linear loop's "
        "margin in a_true / a_design without and with a one-sample delay, the PTO zone.",
        epilog="example:\n  ptoverify design --sample-times 0.001 0.002 --bandwidths 10 30 --json"
        "\n  ptoverify design --dask local --out design-paper",
    )
    p.add_argument(
        "--sample-times",
        nargs="+",
        type=finite_float,
        metavar="S",
        default=list(SAMPLE_TIMES),
        help="sample times T [s] (default 0.25-8 ms)",
    )
    p.add_argument(
        "--bandwidths",
        nargs="+",
        type=finite_float,
        metavar="HZ",
        default=list(DESIGN_BANDWIDTHS_HZ),
        help="bandwidths [Hz] (default 5-100)",
    )
    p.add_argument(
        "--laws",
        nargs="+",
        choices=ALL_LAW_NAMES,
        default=list(DESIGN_LAWS),
        help="laws (default pd pto ptos cascade-p)",
    )
    p.add_argument(
        "--reading",
        choices=("2pi", "hz"),
        default="2pi",
        help="a = 2 pi f (2pi, default) or a = f rad/s (hz)",
    )
    p.add_argument(
        "--grid",
        type=positive_int,
        default=DESIGN_GRID,
        metavar="N",
        help=f"N x N envelope states per point ({DESIGN_GRID}; 2 to 100)",
    )
    p.add_argument(
        "--jobs", type=positive_int, default=1, metavar="N", help="local worker processes (1)"
    )
    p.add_argument(
        "--tuned",
        type=finite_float,
        metavar="MM",
        default=None,
        help="tune every law at every point (step, overshoot <= MM, stable, no limit cycle)",
    )
    p.add_argument(
        "--dask",
        metavar="ADDRESS",
        default=None,
        help="run the points on a dask.distributed scheduler, or 'local'",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="write design.json and design.csv into DIR (atomically)",
    )
    p.set_defaults(handler=_cmd_design)


def _cmd_design(args: argparse.Namespace) -> int:
    from ptoverify.studies.design import dask_design_runner, design_chart, process_runner

    cfg = _config(args)
    if args.dask and args.jobs > 1:
        raise InputError("--dask and --jobs are exclusive")
    if args.dask is not None:
        from ptoverify.studies.cluster import ensure_reachable

        ensure_reachable(args.dask)  # bad input or no scheduler: at once, before any work
    runner = dask_design_runner(args.dask) if args.dask else None
    if args.jobs > 1:
        runner = process_runner(args.jobs)
    target = tmp = None
    if args.out is not None:
        target = check_target(args.out, config_hash=cfg.digest())
    try:
        chart = design_chart(
            cfg,
            args.sample_times,
            args.bandwidths,
            laws=args.laws,
            reading=args.reading,
            grid=args.grid,
            runner=runner,
            backend=args.dask or (f"{args.jobs} processes" if args.jobs > 1 else "in-process"),
            tuned_overshoot=args.tuned,
        )
        result = chart.to_json()
        if args.out is not None:
            tmp = make_temp(target)
            (tmp / "design.json").write_text(json.dumps(result, indent=2) + "\n")
            (tmp / "design.csv").write_text(chart.to_csv())
            result["files"] = [str(target / "design.json"), str(target / "design.csv")]
            publish(tmp, target, config_hash=cfg.digest(), name=cfg.name)
            tmp = None
    finally:
        discard(tmp)
    if args.json:
        print_json(result)
        return 0
    print(
        f"design chart ({chart.reading} reading), {len(chart.points)} points, "
        f"{chart.seconds:.1f} s; median / worst settling over N*T"
    )
    for pt in chart.points:
        cells = "  ".join(
            f"{r.law} {r.median_ratio_nt:.2f}/{r.worst_ratio_nt:.2f}" for r in pt.laws
        )
        print(
            f"T {pt.sample_time * 1e3:g} ms, {pt.bandwidth_hz:g} Hz: fastest {pt.fastest or '-'}"
            f" (x{pt.fastest_by:.2f}); {cells}"
        )
    for f in result.get("files", []):
        print(f"wrote {f}")
    return 0


# ---------------------------------------------------------------- penalty
def _add_penalty(sub) -> None:
    from ptoverify.config import ALL_LAW_NAMES

    p = sub.add_parser(
        "penalty",
        help="settling against move size, beside t_f* and N*T",
        description="Point-to-point moves from rest, 0.01 mm to the position range "
        "(log-spaced): each law's settling (0.01 mm, exact between samples, held 0.05 s) and "
        "arrival, beside the minimum time t_f* and the discrete limit N*T.",
        epilog="example:\n  ptoverify penalty --json\n  ptoverify penalty --tuned --out penalty",
    )
    p.add_argument("--laws", nargs="+", choices=ALL_LAW_NAMES, default=list(ALL_LAW_NAMES))
    p.add_argument("--count", type=positive_int, default=40, metavar="N", help="sizes (40)")
    p.add_argument(
        "--tuned",
        action="store_true",
        help="each law at its best tuning under the PTO's paper-gain overshoot",
    )
    p.add_argument("--out", metavar="DIR", default=None, help="write penalty.json and .csv")
    p.set_defaults(handler=_cmd_penalty)


def _cmd_penalty(args: argparse.Namespace) -> int:
    from ptoverify.studies.penalty import penalty_curves
    from ptoverify.studies.ptos_claim import fair_configs

    cfg = _config(args)
    if not 2 <= args.count <= 1000:
        raise InputError(f"--count must be in [2, 1000], got {args.count}")
    laws = tuple(dict.fromkeys(args.laws))
    target = check_target(args.out, config_hash=cfg.digest()) if args.out else None
    configs = fair_configs(cfg, laws) if args.tuned else None
    res = penalty_curves(
        cfg, laws, count=args.count, configs=configs,
        setting="tuned pto-paper" if args.tuned else "configured",
    )  # fmt: skip
    result = res.to_json()
    if target is not None:
        tmp = make_temp(target)
        try:
            (tmp / "penalty.json").write_text(json.dumps(result, indent=2) + "\n")
            res.write_csv(tmp / "penalty.csv")
            publish(tmp, target, config_hash=cfg.digest(), name=cfg.name)
        except BaseException:
            discard(tmp)
            raise
        result["files"] = [str(target / "penalty.json"), str(target / "penalty.csv")]
    if args.json:
        print_json(result)
        return 0
    print(f"penalty ({res.setting}); settling: {res.settling}")
    print(
        f"{'law':<12} "
        + " ".join(f"{s:>9.3g}" for s in res.sizes_mm[:: max(1, len(res.sizes_mm) // 8)])
    )
    for c in res.curves:
        cells = c.ratio_nt[:: max(1, len(res.sizes_mm) // 8)]
        print(f"{c.law:<12} " + " ".join(f"{v:>9.2f}" for v in cells))
    print("(settling / N*T at the sizes in mm above; nan: never settles)")
    for f in result.get("files", []):
        print(f"wrote {f}")
    return 0


# ---------------------------------------------------------------- prove
def _add_prove(sub) -> None:
    p = sub.add_parser(
        "prove",
        help="prove properties over every initial state (interval arithmetic)",
        description="Prove, with outward-rounded interval arithmetic and arb certificates over "
        "a cell partition of the whole envelope, that the sampled closed loop of each law "
        "keeps |u| <= w_max, never strides over (strict and relaxed readings), and reaches "
        "a certified target ellipse within a certified number of samples; each property "
        "is proved, refuted (certified counterexample) or unproven (with where).",
        epilog="example:\n  ptoverify prove --json\n  ptoverify prove --a-interval 0.8,1.25 "
        "--out proof\n  ptoverify prove --check proof/certificate-pto.npz",
    )
    p.add_argument(
        "--a-interval",
        metavar="LO,HI",
        default=None,
        help="prove for every constant a in [LO, HI] x the nominal a",
    )
    p.add_argument(
        "--excursion",
        type=float,
        default=0.0,
        metavar="MM",
        help="allow images this far beyond |x1| = position_range (0)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="write certificates, proof.json and a map of the bound into DIR",
    )
    p.add_argument(
        "--check",
        metavar="CERT",
        default=None,
        help="re-verify a certificate (.npz) independently; exit 1 if inconsistent",
    )
    p.add_argument(
        "--full", action="store_true", help="with --check: step every proved cell in arb (slow)"
    )
    p.add_argument(
        "--law",
        action="append",
        choices=("pto", "pto-printed", "pd", "to", "cascade-p", "ptos"),
        default=None,
        help="prove only this law (repeatable; default the paper's four: pto, pto-printed, pd, "
        "to; cascade-p on request; ptos has no certified enclosure: bad input)",
    )
    p.add_argument(
        "--dask",
        metavar="ADDRESS",
        default=None,
        help="run the a sub-intervals on a dask.distributed scheduler, or 'local'",
    )
    p.set_defaults(handler=_cmd_prove)


def _cmd_prove(args: argparse.Namespace) -> int:
    import numpy as np

    from ptoverify.studies.prove import parse_a_interval, run_prove
    from ptoverify.studies.prove.certificate import certificate_arrays, check_certificate

    cfg = _config(args)
    if args.full and args.check is None:
        raise InputError("--full needs --check CERT (it steps a certificate's cells in arb)")
    if args.check is not None:
        used = {"--law": args.law, "--a-interval": args.a_interval, "--dask": args.dask}
        used |= {"--out": args.out, "--excursion": args.excursion or None}
        if any(v is not None for v in used.values()):  # never ignored (audit run 7)
            names = ", ".join(f for f, v in used.items() if v is not None)
            raise InputError(f"--check re-verifies a certificate as it is: no {names}")
        import zipfile

        try:
            with np.load(args.check, allow_pickle=False) as f:
                data = {k: f[k] for k in f.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:  # not an .npz
            raise InputError(f"--check: cannot read {args.check}: {exc}") from None
        res = check_certificate(data, cfg, full=args.full)
        if args.json:
            print_json({"check": res.to_json()})
        else:
            print(
                "certificate consistent" if res.ok else "INCONSISTENT: " + "; ".join(res.problems)
            )
        return 0 if res.ok else 1
    if not math.isfinite(args.excursion):
        raise InputError("--excursion must be a finite number of mm")
    a_int = parse_a_interval(args.a_interval, cfg.plant.a) if args.a_interval is not None else None
    if args.dask is not None:
        from ptoverify.studies.cluster import ensure_reachable

        ensure_reachable(args.dask)  # bad input or no scheduler: at once, before any work
    laws = tuple(dict.fromkeys(args.law)) if args.law else ("pto", "pto-printed", "pd", "to")
    from ptoverify.model.lawbox import require_enclosure

    for name in laws:  # before --out is touched
        require_enclosure(name)
    target = tmp = None
    if args.out is not None:
        target = check_target(args.out, config_hash=cfg.digest())
    try:
        run = run_prove(cfg, laws=laws, a_interval=a_int, excursion=args.excursion, dask=args.dask)
        result = run.to_json()
        if args.out is not None:
            tmp = make_temp(target)
            from ptoverify.report.plots import save_proof_map

            for proof in run.proofs:
                np.savez(tmp / f"certificate-{proof.law}.npz", **certificate_arrays(proof, cfg))
                save_proof_map(proof, tmp / f"proof-{proof.law}.png")
            (tmp / "proof.json").write_text(json.dumps(to_jsonable(result), indent=2) + "\n")
            publish(tmp, target, config_hash=cfg.digest(), name=cfg.name)
            tmp = None
    finally:
        discard(tmp)
    if args.json:
        print_json(result)
        return 0
    for law, r in result["laws"].items():
        for name, pr in r["properties"].items():
            print(f"{law:<12} {name:<24} {pr['status']:<9} coverage {pr['coverage']:.5%}")
        print(
            f"{law:<12} bound {r['bound_samples']} samples, simulated worst "
            f"{r['simulated_worst_samples']}, cells {r['cells']}, {r['timings_s']}"
        )
    return 0
