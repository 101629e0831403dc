"""The commands mintime, simulate, derive, zone and check: parse, call, format."""

from __future__ import annotations

import argparse
import csv
import io
import json
import sys
from pathlib import Path

from ptoverify.config import Config
from ptoverify.errors import InputError

from .common import (
    _add_junit,
    _check_junit,
    _config,
    _seed_int,
    finite_float,
    positive_int,
    print_json,
    write_atomic,
)


# ---------------------------------------------------------------- mintime
def _add_mintime(sub) -> None:
    p = sub.add_parser(
        "mintime",
        help="minimum time from a state to the origin",
        description="Minimum time from (X1, X2) to the origin: the closed form and, where "
        "available, the CasADi and discrete-time references.",
        epilog="example:\n  ptoverify mintime 5 0 --json\n  ptoverify mintime -- -12.5 80\n"
        "  ptoverify mintime --states states.csv --out times.csv",
    )
    p.add_argument("x1", type=finite_float, nargs="?", metavar="X1", help="initial position [mm]")
    p.add_argument("x2", type=finite_float, nargs="?", metavar="X2", help="initial velocity [mm/s]")
    p.add_argument(
        "--states",
        metavar="IN.csv",
        default=None,
        help="many states (CSV, columns x1, x2): closed form and exact N* per row, no solver",
    )
    p.add_argument(
        "--out", metavar="OUT.csv", default=None, help="with --states: write the table here"
    )
    p.add_argument(
        "--intervals",
        type=positive_int,
        default=None,
        help="collocation intervals N (default 100, at most 2000; not with --states)",
    )
    p.set_defaults(handler=_cmd_mintime)


def _mintime_states(args: argparse.Namespace, cfg: Config) -> int:
    from ptoverify.commands import mintime_states

    if args.x1 is not None:
        raise InputError("give either X1 X2 or --states, not both")
    if args.intervals is not None:  # never ignored (audit run 7)
        raise InputError("--intervals sets the collocation of one state; --states runs no solver")
    if args.out is not None and args.json:
        raise InputError("--out and --json are alternatives")
    cols = mintime_states(args.states, cfg)
    names = list(cols)
    # N* not found (-1, NaN): null in JSON, an empty field in CSV; floats as repr (round trip)
    rows = [
        [None if (v != v or v == -1) else v for v in r]
        for r in zip(*(cols[k].tolist() for k in names), strict=True)
    ]
    if args.json:  # compact: the C encoder (indent would take seconds at 10^5 rows)
        obj = {"states": [dict(zip(names, r, strict=True)) for r in rows]}
        sys.stdout.write(json.dumps(obj, allow_nan=False) + "\n")
        return 0
    out = [",".join(names)]
    out += [",".join("" if v is None else repr(v) for v in r) for r in rows]
    text = "\n".join(out) + "\n"
    if args.out is None:
        sys.stdout.write(text)
    else:
        write_atomic(args.out, text)
        print(f"wrote {len(out) - 1} rows to {args.out}")
    return 0


def _cmd_mintime(args: argparse.Namespace) -> int:
    from ptoverify.studies.groundtruth import verified_mintime

    cfg = _config(args)
    if args.states is not None:
        return _mintime_states(args, cfg)
    if args.out is not None:
        raise InputError("--out needs --states")
    if args.x1 is None or args.x2 is None:
        raise InputError("mintime needs X1 X2 or --states IN.csv")
    intervals = 100 if args.intervals is None else args.intervals
    if intervals > 2000:
        raise InputError(f"--intervals must be at most 2000, got {intervals}")
    result = verified_mintime(args.x1, args.x2, cfg, intervals=intervals).to_json()
    if args.json:
        print_json(result)
    else:
        for key, value in result.items():
            print(f"{key:>22}: {value}")
    return 0


# ---------------------------------------------------------------- simulate
def _add_simulate(sub) -> None:
    from ptoverify.config import ALL_LAW_NAMES

    p = sub.add_parser(
        "simulate",
        help="simulate a law on a Section 6 reference",
        description="Simulate the sampled closed loop (exact ZOH flow) of a law tracking a "
        "Section 6 reference: step 5 mm, ramp 0-30 mm at 200 mm/s, sine 5 mm 5 Hz.",
        epilog="example:\n  ptoverify simulate --law to --signal step --csv to_step.csv",
    )
    p.add_argument("--law", choices=ALL_LAW_NAMES, default="pto", help="control law (default pto)")
    p.add_argument(
        "--signal",
        choices=("step", "ramp", "sine"),
        default=None,
        help="reference signal (default step)",
    )
    p.add_argument(
        "--duration",
        type=finite_float,
        default=None,
        help="simulated time [s] (default: per signal)",
    )
    p.add_argument(
        "--no-feedforward", action="store_true", help="do not feed the reference velocity forward"
    )
    for flag, metavar, text in (
        ("--step", "MM", "step height [mm] (default 5)"),
        ("--ramp-speed", "MM_S", "ramp speed [mm/s] (default 200)"),
        ("--ramp-to", "MM", "ramp end value [mm] (default 30)"),
        ("--amplitude", "MM", "sine amplitude [mm] (default 5)"),
        ("--frequency", "HZ", "sine frequency [Hz] (default 5)"),
    ):
        p.add_argument(flag, type=finite_float, metavar=metavar, default=None, help=text)
    p.add_argument(
        "--x0",
        nargs=2,
        type=finite_float,
        metavar=("X1", "X2"),
        default=None,
        help="regulate from this state [mm] [mm/s] to the origin instead of tracking a "
        "reference (reproduces a counterexample of `ptoverify robust`)",
    )
    for flag, kind, metavar, text in (
        ("--a-ratio", finite_float, "R", "true a over design a (with --x0; default 1)"),
        ("--w-max-ratio", finite_float, "R", "drive saturation over w_max (with --x0; default 1)"),
        ("--delay", int, "N", "computation delay [samples] (with --x0; default 0)"),
        ("--quantum", finite_float, "MM", "encoder resolution [mm] (with --x0; default 0)"),
        ("--velocity-noise", finite_float, "MM_S", "velocity noise sd [mm/s] (with --x0)"),
        ("--seed", _seed_int, "N", "noise seed (with --x0; default 0)"),
    ):
        p.add_argument(flag, type=kind, metavar=metavar, default=None, help=text)
    p.add_argument("--csv", metavar="FILE", default=None, help="write the time series as CSV")
    p.set_defaults(handler=_cmd_simulate)


def _cmd_simulate(args: argparse.Namespace) -> int:
    from ptoverify.sim.runs import run_simulation

    cfg = _config(args)
    if args.csv is not None and args.json:
        raise InputError("--csv and --json are exclusive")
    if args.csv is not None and (args.csv.strip() == "" or Path(args.csv).is_dir()):
        raise InputError(f"--csv must name a file, got {args.csv!r}")
    mismatch = {
        "a_ratio": args.a_ratio,
        "w_max_ratio": args.w_max_ratio,
        "delay_samples": args.delay,
        "position_quantum": args.quantum,
        "velocity_noise": args.velocity_noise,
        "seed": args.seed,
    }
    if args.x0 is not None:
        return _simulate_regulation(args, cfg, {k: v for k, v in mismatch.items() if v is not None})
    flags = dict(
        zip(
            mismatch,
            ("--a-ratio", "--w-max-ratio", "--delay", "--quantum", "--velocity-noise", "--seed"),
            strict=True,
        )
    )
    given = [flags[k] for k, v in mismatch.items() if v is not None]
    if given:
        raise InputError(f"the plant/measurement mismatch options need --x0 (got {given[0]})")
    _check_reference_options(args, cfg)
    run = run_simulation(
        cfg,
        args.law,
        args.signal or "step",
        duration=args.duration,
        feedforward=not args.no_feedforward,
        step=args.step,
        ramp_speed=args.ramp_speed,
        ramp_to=args.ramp_to,
        amplitude=args.amplitude,
        frequency=args.frequency,
    )
    if args.csv is not None:
        cols = run.result.columns()
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(list(cols))
        for row in zip(*cols.values(), strict=True):
            writer.writerow(
                [
                    repr(float(v)) if k != "region" else int(v)
                    for k, v in zip(cols, row, strict=True)
                ]
            )
        write_atomic(args.csv, buf.getvalue())
        return 0
    if args.json:
        print_json(run.to_json())
    else:
        summary = run.summary()
        metrics, grid = run.metrics()  # everything computed before anything is printed
        for key, value in summary.items():
            print(f"{key:>30}: {value}")
        for key, value in metrics.items():
            print(f"{key:>30}: {value} (sample grid: {grid[key]})")
    return 0


def _check_reference_options(args: argparse.Namespace, cfg: Config) -> None:
    """Reject reference options no simulation can serve, before anything runs.

    Heights within 1000 x the position range (as ``--x0`` and ``mintime``
    accept states), a ramp speed in (0, 1000 w_max], and a sine frequency in
    (0, 1 / (2 T)): above the Nyquist frequency of the sampled loop the sine is
    not a reference the loop can see.
    """
    p = cfg.plant
    far = 1e3 * p.position_range
    for flag, value in (("--step", args.step), ("--ramp-to", args.ramp_to)):
        if value is not None and abs(value) > far:
            raise InputError(
                f"{flag} {value:g} mm is beyond 1000 x the position range ({far:g} mm)"
            )
    if args.amplitude is not None and not 0 <= args.amplitude <= far:
        raise InputError(f"--amplitude must be in [0, {far:g}] mm, got {args.amplitude:g}")
    if args.ramp_speed is not None and not 0 < args.ramp_speed <= 1e3 * p.w_max:
        raise InputError(
            f"--ramp-speed must be in (0, {1e3 * p.w_max:g}] mm/s, got {args.ramp_speed:g}"
        )
    nyquist = 0.5 / p.sample_time
    if args.frequency is not None and not 0 < args.frequency < nyquist:
        raise InputError(
            f"--frequency must be in (0, {nyquist:g}) Hz (below the Nyquist frequency "
            f"1 / (2 T), T = {p.sample_time:g} s), got {args.frequency:g}"
        )


def _simulate_regulation(args: argparse.Namespace, cfg: Config, mismatch: dict) -> int:
    from ptoverify.commands import run_regulation

    ref_flags = (args.signal, args.step, args.ramp_speed, args.ramp_to, args.amplitude)
    if any(v is not None for v in (*ref_flags, args.frequency)) or args.no_feedforward:
        raise InputError("--x0 regulates to the origin: no reference options with it")
    out = run_regulation(cfg, args.law, tuple(args.x0), duration=args.duration, **mismatch)
    if args.csv is not None:
        cols = out["series"]
        lines = [",".join(cols)]
        for row in zip(*cols.values(), strict=True):
            lines.append(",".join(repr(float(v)) for v in row))
        write_atomic(args.csv, "\n".join(lines) + "\n")
        return 0
    if args.json:
        print_json(out)
    else:
        for key in ("law", "x0", "mismatch", "samples", "final_state", "properties"):
            print(f"{key:>14}: {out[key]}")
    return 0


# ---------------------------------------------------------------- derive
def _add_derive(sub) -> None:
    p = sub.add_parser(
        "derive",
        help="re-derive eqs. (3)-(39) with SymPy and judge them",
        description="Re-derive each equation from eq. (1) with SymPy and compare it with its "
        "printed form; verdicts: verified, erratum, definition, unchecked.",
        epilog="example:\n  ptoverify derive --json",
    )
    p.set_defaults(handler=_cmd_derive)


def _cmd_derive(args: argparse.Namespace) -> int:
    import derivations

    cfg = _config(args)
    p = cfg.plant
    records = derivations.all_records(
        derivations.PlantNumbers(
            a=p.a, w_max=p.w_max, T=p.sample_time, d=cfg.pto.d, k1=cfg.pto.k1, k2=cfg.pto.k2
        )
    )
    if args.json:
        print_json({"equations": [r.to_json() for r in records]})
    else:
        for r in records:
            print(f"({r.id:>4}) {r.verdict:<10} {r.note}")
    return 0


# ---------------------------------------------------------------- check
def _add_check(sub) -> None:
    p = sub.add_parser(
        "check",
        help="run the verification gates (for CI)",
        description="Run every verification as a gate: pass, fail or unverified (a reference "
        "that could not be computed). Exit 0 when all pass, 1 otherwise.",
        epilog="example:\n  ptoverify check\n  ptoverify check --json --config my_axis.toml",
    )
    p.add_argument(
        "--gate",
        action="append",
        default=None,
        metavar="NAME",
        help="run only this gate (repeatable)",
    )
    p.add_argument(
        "--max-iter",
        type=positive_int,
        default=None,
        metavar="N",
        help="cap IPOPT iterations (a solver that then fails makes its gate "
        "unverified, and the run fails)",
    )
    p.add_argument(
        "--robust",
        action="store_true",
        help="also run the robustness gates over the [robustness] box "
        "(robust-no-limit-cycle, robust-settling, proof-reach-a-interval; adds about 20 s)",
    )
    _add_junit(p)
    p.set_defaults(handler=_cmd_check)


def _cmd_check(args: argparse.Namespace) -> int:
    from ptoverify.studies.checks import run_checks, summarize

    cfg = _config(args)
    _check_junit(args)
    results = run_checks(cfg, args.gate, max_iter=args.max_iter, robust=args.robust)
    summary = summarize(results)
    if args.junit:
        from ptoverify.conform.junit import junit_xml

        write_atomic(args.junit, junit_xml(results, "ptoverify.check", None, {"config": cfg.name}))
    if args.json:
        print_json(
            {"config": cfg.name, "checks": [r.to_json() for r in results], "summary": summary}
        )
    else:
        for r in results:
            measured = "-" if r.measured is None else f"{r.measured:.3g}"
            limit = "-" if r.limit is None else f"{r.limit:.3g}"
            print(
                f"{r.status.upper():<10} {r.name:<36} {measured:>9} {r.comparison:<2} "
                f"{limit:<9} {r.detail}"
            )
        print(
            f"{summary['pass']}/{summary['total']} passed, {summary['fail']} failed, "
            f"{summary['unverified']} unverified"
        )
    return 0 if summary["ok"] else 1


# ---------------------------------------------------------------- zone
def _add_zone(sub) -> None:
    p = sub.add_parser(
        "zone",
        help="switching zone: as printed (eqs. 19-27) and corrected",
        description="Carry out the switching-zone construction of eqs. (19)-(27) as printed, "
        "judge it against the paper's principle (a sampled state must not stride "
        "over the zone), and compute the corrected omega0 with its feasible "
        "intervals, verified on a grid.",
        epilog="example:\n  ptoverify zone --json\n  ptoverify zone --config fast.toml",
    )
    p.add_argument(
        "--no-verify",
        action="store_true",
        help="skip the 2-D grid verification of the corrected zone",
    )
    p.add_argument(
        "--no-outcome",
        action="store_true",
        help="skip the closed-loop outcome (simulation of both PTO variants)",
    )
    p.set_defaults(handler=_cmd_zone)


def _cmd_zone(args: argparse.Namespace) -> int:
    from ptoverify.commands import run_zone

    cfg = _config(args)
    result = run_zone(cfg, verify=not args.no_verify, outcome=not args.no_outcome)
    if args.json:
        print_json(result)
        return 0
    print(
        f"d = {result['d']:g} mm, w_max = {result['w_max']:g} mm/s, a = {result['a']:.6g} "
        f"rad/s, T = {result['sample_time']:g} s"
    )
    for key in ("printed", "corrected", "corrected_lenient"):
        z = result[key]
        print(
            f"\n[{key}] omega0 = {z['omega0']:.6g} mm/s, x20_tilde = {z['x20_tilde']:.6g} "
            f"mm/s, valid = {z['valid']}, degenerate = {z['degenerate']}"
        )
        for part in z["reason"].split("; "):
            print(f"  - {part}")
    for name, o in result.get("outcome", {}).items():
        print(
            f"\n[outcome {name}] enters zone before crossing l1/l2: "
            f"{o['enters_zone_before_crossing']}; settles without overshoot: "
            f"{o['settles_without_overshoot']} (stride-overs {o['stride_overs']}, crossings "
            f"into the linear zone {o['crossings_into_linear']}, overshoots {o['overshoots']}, "
            f"max {o['max_overshoot_mm']:.3g} mm, limit cycles {o['limit_cycles']})"
        )
    return 0
