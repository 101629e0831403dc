"""Command line: ``ptoverify <command>``; the contract is in shared/DESIGN.md.

This module parses arguments, calls one numeric function per command and
formats its result; it computes nothing itself and imports no solver and no
simulator.

Exit codes: 0 success (all gates pass); 1 a gate failed, a reference could not
be computed, or an internal error (a bug: one line ``ptoverify: internal error:
...``; ``--debug`` shows the traceback); 2 bad input (one line on stderr
beginning ``ptoverify: error:``, no traceback, nothing written).  ``--json``
prints one JSON object on stdout and nothing else.  ``--version`` prints the
version.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ptoverify import __version__
from ptoverify.config import Config, load_config
from ptoverify.errors import ClusterError, InputError, SolverError
from ptoverify.outdir import (
    ENVIRONMENT_ERRNOS,
    OutputBusy,
    Terminated,
    check_target,
    discard,
    guarded_std_streams,
    make_temp,
    os_error,
    publish,
    sigterm_raises,
)
from ptoverify.outdir import write_atomic as _write_atomic

__all__ = ["main", "build_parser"]


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors become one-line :class:`InputError`.

    Any float literal with a leading minus (``-5``, ``-1e2``, ``-.5``, ``-5.``) is a
    negative number, not an option, so states can be given as positionals.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(
            r"^-(\d+\.?\d*([eE][-+]?\d+)?|\.\d+([eE][-+]?\d+)?|inf|nan)$", re.I
        )

    def error(self, message: str):  # noqa: D102
        # "ptoverify: error: mintime: ...", not "ptoverify: error: ptoverify mintime: ..."
        where = self.prog.removeprefix("ptoverify").strip()
        raise InputError(f"{where}: {message}" if where else message)


def finite_float(text: str) -> float:
    """Parse a finite float (rejects NaN and infinities)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def positive_int(text: str) -> int:
    """Parse a positive integer."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive: {text!r}")
    return value


def _seed_int(text: str) -> int:
    """Parse a seed: an integer in [0, 2^32), the range of ``robustness.seed``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be in [0, 2^32): {text!r}")
    return value


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays and non-finite floats to JSON-safe values (NaN -> None)."""
    import numpy as np

    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def print_json(obj: Any) -> None:
    """Print one JSON object on stdout."""
    sys.stdout.write(json.dumps(to_jsonable(obj), allow_nan=False, indent=2) + "\n")


def write_atomic(path: str | Path, text: str) -> None:
    """Write a text file atomically (see :func:`ptoverify.outdir.write_atomic`)."""
    _write_atomic(path, text)


def _config(args: argparse.Namespace) -> Config:
    return load_config(args.config)


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
        default=100,
        help="collocation intervals N (default 100, at most 2000)",
    )
    p.set_defaults(handler=_cmd_mintime)


def _mintime_states(args: argparse.Namespace, cfg: Config) -> int:
    from ptoverify.commands import mintime_states

    if args.x1 is not None:
        raise InputError("give either X1 X2 or --states, not both")
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
    if args.intervals > 2000:
        raise InputError(f"--intervals must be at most 2000, got {args.intervals}")
    result = verified_mintime(args.x1, args.x2, cfg, intervals=args.intervals).to_json()
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
        choices=("to", "pd", "pto", "pto-printed"),
        default=None,
        help="study only this law (repeatable; default all four)",
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
        help="tune PD (kp, kd) or PTO (d, k1, k2) for a fair comparison",
        description="Search a law's gains (differential evolution, fixed seed; the PTO's "
        "omega0 from the corrected construction for each d) for the best response under an "
        "overshoot bound (between samples), a stable sampled linear loop and no limit cycle "
        "(PTO: nor stride-over) on the gate grid. Prints the gains as a TOML configuration.",
        epilog="example:\n  ptoverify tune --law pd --signal step --max-overshoot 0\n"
        "  ptoverify tune --law pto --json > tuned.json",
    )
    p.add_argument("--law", choices=("pd", "pto"), required=True, help="law to tune")
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


# ---------------------------------------------------------------- junit
def _add_junit(p) -> None:
    p.add_argument(
        "--junit",
        metavar="FILE",
        default=None,
        help="also write JUnit XML (one testcase per gate/property; unverified is an error)",
    )


def _check_junit(args: argparse.Namespace) -> None:
    """Validate --junit FILE before any computation."""
    if args.junit is None:
        return
    path = Path(args.junit)
    if args.junit.strip() == "" or path.is_dir():
        raise InputError(f"--junit must name a file, got {args.junit!r}")
    if not path.absolute().parent.is_dir():
        raise InputError(f"--junit '{args.junit}': folder '{path.parent}' does not exist")


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
        "(robust-no-limit-cycle, robust-settling; adds about 10 s)",
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
        choices=("pto", "pto-printed", "pd", "to"),
        default=None,
        help="prove only this law (repeatable; default all four)",
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


# ---------------------------------------------------------------- report
def _add_report(sub) -> None:
    p = sub.add_parser(
        "report",
        help="write the verification report (HTML, Markdown, JSON, figures)",
        description="Run every verification and write a report folder: index.html (opens "
        "offline; MathML equations), report.md, results.json and figures/*.png. "
        "Written atomically: a failed run leaves nothing half-written.",
        epilog="example:\n  ptoverify report\n  ptoverify report --config axis.toml --out "
        "reports/axis",
    )
    p.add_argument(
        "--out", metavar="DIR", default=None, help="report folder (default reports/<config name>)"
    )
    p.add_argument(
        "--skip",
        metavar="STAGES",
        default="",
        help="comma-separated expensive stages to leave out for a quick report: robust, "
        "tuning (their sections then say so)",
    )
    p.add_argument(
        "--jobs",
        metavar="N",
        type=int,
        default=None,
        help="worker processes for the report's independent stages (default: the CPUs "
        "available; 1 runs every stage in this process). The results do not depend on it",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    p.set_defaults(handler=_cmd_report)


def _cmd_report(args: argparse.Namespace) -> int:
    from ptoverify.report.collect import stderr_progress, write_report

    cfg = _config(args)
    if args.out is not None and Path(args.out).exists() and not Path(args.out).is_dir():
        raise InputError(f"--out '{args.out}' exists and is not a directory")
    skip = tuple(x.strip() for x in args.skip.split(",") if x.strip())
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    out = write_report(
        cfg, args.out, stderr_progress(args.quiet), skip=skip, timings=timings, jobs=args.jobs
    )
    if not args.quiet:
        print(
            f"report written in {time.perf_counter() - t0:.1f} s wall; stage timings "
            "(each with its figures, in parallel processes): "
            + ", ".join(f"{k} {v:.1f} s" for k, v in timings.items()),
            file=sys.stderr,
        )
    res = json.loads((out / "results.json").read_text())
    if args.json:
        print_json({"out": str(out), "summary": res["summary"]})
    else:
        g = res["summary"]["gates"]
        print(
            f"wrote {out}/index.html, report.md, results.json, "
            f"{len(res['meta']['figures'])} figures; gates {g['pass']}/{g['total']} pass"
        )
    return 0


# ---------------------------------------------------------------- conform
_CONFORM_EPILOG = """\
Loading a callable RUNS USER CODE: --law imports the named module (or executes the named
.py file) in a child process (spawned; stdout/stderr captured and shown on stderr; memory
limited to 4 GiB where the OS allows; --timeout for everything, 10 s + 1 ms per state per
batch); a hang, crash or any exit of it is a finding (exit 1) and the properties it left
unevaluated are "unverified". Only the module or file you name is loaded; no path is searched
(MODULE must be importable from sys.path as it stands; give path/to/file.py:FUNCTION for a
file). The callable is u = f(x1, x2, cfg) with x1 [mm], x2 [mm/s], cfg the ptoverify Config;
it must accept Python floats and may accept numpy arrays (vectorized use is detected: an
array call of 8 probe states must equal element-wise calls to 1e-12 w_max; the output says
which mode was used).

Judged (callable): agreement with the reference PTO law (corrected omega0), region by
region, |u - u_ref| <= TOL * w_max (default 1e-6) on a grid dense near l1, l2, l1*, l2*,
the zone, |x1| = d, the origin and |x2| = w_max; points within 1e-9 (w_max + a range) mm/s
of a computed curve outside |x1| < d are excluded and counted (a float tie may flip the
region there); odd symmetry; |u| <= w_max; closed loop as `check` gates it: no stride-over,
no limit cycle (and settled within 1e-3 mm), |u| <= w_max, and settling against the
discrete-time limit N*T: worst (settling samples - N*) <= E_ref + max(2, ceil(E_ref/2)),
E_ref the reference's worst. Both routes probe the same set, which --emit-grid writes: the
grid, 100,000 seeded random states and 80,000 states around the curves and |x1| = d (a --law
also at every state its closed loop visits). Table: agreement, |u| <= w_max and odd symmetry
(mirrored grid states) at its points only; it must hold every emitted state (within 1e-6 of
the range and w_max), or else a state in each of 200 x 200 cells and 100 per region, otherwise
"insufficient coverage" (exit 1). The reference is evaluated at the table's x1, x2, so
firmware that rounds the state (float32) must write back the state it actually evaluated.

--report DIR also writes a report for a review (verdict, properties with units, heat maps of
|u - u_ref| with l1, l2, l1*, l2* and |x1| < d, closed loop, settling / N*T, step/ramp/sine
responses of a --law next to the reference); DIR is checked before anything runs and written
atomically.

Exit codes: 0 conforms, 1 does not (each failing property named with the first state that
shows it; a law that raises, returns NaN/inf, or has memory is a finding), 2 bad input
(import error, missing attribute, not callable, wrong signature, a non-number or wrong
shape returned, unreadable table).

examples:
  ptoverify conform --law ptoverify.conform.gate:reference_law
  ptoverify conform --law examples/my_pto.py:pto --json
  ptoverify conform --emit-grid grid.csv      # fill in column u, then:
  ptoverify conform --table grid_with_u.csv
  ptoverify conform --law examples/my_pto.py:pto --report review    # HTML/Markdown/JSON report"""


def _add_conform(sub) -> None:
    p = sub.add_parser(
        "conform",
        help="gate a third-party PTO implementation (callable or table)",
        description="Check that a third-party implementation of the PTO law agrees with the "
        "verified reference and keeps its closed-loop properties.",
        epilog=_CONFORM_EPILOG,
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument(
        "--law",
        metavar="MODULE:FUNCTION",
        help="callable u = f(x1, x2, cfg) to judge (runs its code)",
    )
    src.add_argument("--table", metavar="FILE.csv", help="CSV with columns x1, x2, u")
    src.add_argument(
        "--emit-grid",
        metavar="FILE.csv",
        help="write the probe set (columns x1, x2; grid, random and curve-band states) and exit",
    )
    p.add_argument(
        "--tolerance",
        type=finite_float,
        default=None,
        metavar="TOL",
        help="agreement tolerance relative to w_max (default 1e-6)",
    )
    p.add_argument(
        "--timeout",
        type=finite_float,
        default=120.0,
        metavar="S",
        help="budget for the whole conformance of a --law [s] (default 120); the law runs "
        "in a child process, and a hang, crash or exit of it is a finding",
    )
    p.add_argument(
        "--report",
        metavar="DIR",
        default=None,
        help="also write a report folder for a review (index.html, report.md, results.json, "
        "figures/): verdict, properties, map of |u - u_ref| with the region boundaries, "
        "closed loop, step/ramp/sine responses; checked before computing, written atomically",
    )
    _add_junit(p)
    p.set_defaults(handler=_cmd_conform)


def _cmd_conform(args: argparse.Namespace) -> int:
    from ptoverify.conform import gate as conform

    for flag, value in (
        ("--law", args.law),
        ("--table", args.table),
        ("--emit-grid", args.emit_grid),
    ):
        if value is not None and value.strip() == "":
            raise InputError(f"{flag} is empty")
    cfg = _config(args)
    rtol = conform.DEFAULT_RTOL if args.tolerance is None else args.tolerance
    if not 0 < rtol < 1:
        raise InputError(f"--tolerance must be in (0, 1), got {rtol:g}")
    _check_junit(args)
    target = None
    if args.report is not None:
        from ptoverify.report.conform_report import check_report_target

        if args.emit_grid:
            raise InputError("--report needs --law or --table, not --emit-grid")
        target = check_report_target(args.report, cfg)
    if args.emit_grid:
        text = conform.grid_csv(cfg)
        write_atomic(args.emit_grid, text)
        if args.json:
            print_json(
                {
                    "grid": str(args.emit_grid),
                    "points": text.count("\n") - 1,
                    "columns": ["x1", "x2"],
                }
            )
        return 0
    if not 0 < args.timeout <= 86400:
        raise InputError(f"--timeout must be in (0, 86400] s, got {args.timeout:g}")
    evidence = None
    if target is not None:
        from ptoverify.conform.evidence import conform_with_evidence

        result, evidence = conform_with_evidence(
            cfg, law=args.law, table=args.table, rtol=rtol, timeout=args.timeout
        )
    elif args.table:
        result = conform.conform_table(args.table, cfg, rtol=rtol)
    else:  # the law runs in a child process; what it prints goes to stderr afterwards
        result = conform.conform_spec(args.law, cfg, rtol=rtol, timeout=args.timeout)
    if args.law and result.law_output:
        print(result.law_output, end="", file=sys.stderr)
    if args.junit:
        from ptoverify.conform.junit import conform_verdicts, junit_xml

        verdicts, states = conform_verdicts(result)
        props = {"config": cfg.name, "target": result.target, "mode": result.mode}
        xml = junit_xml(verdicts, "ptoverify.conform.gate", states, props, result.conforms)
        write_atomic(args.junit, xml)
    if target is not None:
        from ptoverify.report.conform_report import write_conform_report

        write_conform_report(result, evidence, cfg, target)
    if args.json:
        out = result.to_json()
        if target is not None:
            out["report"] = str(target / "index.html")
        print_json(out)
    else:
        print(conform.format_result(result))
        if target is not None:
            print(f"wrote report {target}/index.html, report.md, results.json, figures/")
    return 0 if result.conforms else 1


COMMANDS: list[tuple[str, Callable[[Any], None]]] = [
    ("report", _add_report),
    ("check", _add_check),
    ("mintime", _add_mintime),
    ("simulate", _add_simulate),
    ("derive", _add_derive),
    ("sweep", _add_sweep),
    ("zone", _add_zone),
    ("conform", _add_conform),
    ("robust", _add_robust),
    ("tune", _add_tune),
    ("design", _add_design),
    ("penalty", _add_penalty),
    ("prove", _add_prove),
]


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every command."""
    common = _Parser(add_help=False)
    common.add_argument(
        "--config",
        metavar="FILE",
        default=None,
        help="TOML configuration (default: the paper's Section 6 values)",
    )
    common.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    common.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,
        help="on an internal error, show the traceback",
    )
    parser = _Parser(
        prog="ptoverify",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Verification suite for the proximate time-optimal (PTO) "
        "control law with bandwidth and saturation.",
        epilog="example:\n  ptoverify report\n  ptoverify check --json",
    )
    parser.add_argument(
        "--version", action="version", version=f"ptoverify {__version__}", help="print the version"
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        help="on an internal error (a bug), show the traceback instead of one line",
    )
    sub = parser.add_subparsers(
        dest="command", metavar="COMMAND", required=True, parser_class=_Parser
    )
    real_add = sub.add_parser

    def add_parser(name, **kwargs):
        kwargs.setdefault("parents", [common])
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        return real_add(name, **kwargs)

    sub.add_parser = add_parser
    for _, add in COMMANDS:
        add(sub)
    return parser


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        0 success; 1 a gate failed, a solver failed, or an internal error; 2 bad
        input; 130 interrupted.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    with guarded_std_streams():  # a closed pipe keeps the run's own exit code
        return _run(argv)


def _outputs(argv: list[str]) -> str | None:
    """List the output options given, to name in an OS error without a file name."""
    flags = ("--out", "--csv", "--junit", "--report", "--emit-grid")
    named = [f"{a} {b}" for a, b in zip(argv, argv[1:]) if a in flags]
    return ", ".join(named) or None


def _say(text: str) -> None:
    print(f"ptoverify: {text}", file=sys.stderr)


def _run(argv: list[str]) -> int:
    """Run one command line inside the guarded streams; return the exit code."""
    debug = "--debug" in argv  # known even if parsing fails
    try:
        args = build_parser().parse_args(argv)
        debug = bool(getattr(args, "debug", False))
        with sigterm_raises():
            code = int(args.handler(args))
        sys.stdout.flush()  # a write that fails shows here, inside the handlers below
        return code
    except Terminated:
        _say("error: terminated (SIGTERM); nothing written")
        return 143
    except OutputBusy as exc:
        _say(f"error: {_one_line(exc)}")
        return 1
    except (SolverError, ClusterError) as exc:  # the input was fine; the run could not be done
        _say(f"error: {_one_line(exc)}")
        return 1
    except InputError as exc:
        _say(f"error: {_one_line(exc)}")
        return 2
    except KeyboardInterrupt:
        _say("error: interrupted")
        return 130
    except BrokenPipeError as exc:  # not through the guarded streams: the verdict is unknown
        _say(f"error: a pipe closed before the run ended ({_one_line(exc)}); no verdict")
        return 1
    except OSError as exc:
        if exc.errno not in ENVIRONMENT_ERRNOS or debug:
            return _internal(exc, debug)
        _say(f"error: {_one_line(os_error(exc, exc.filename or _outputs(argv)))}")
        return 2
    except Exception as exc:  # noqa: BLE001 - anything else is a bug, never "bad input"
        return _internal(exc, debug)


def _internal(exc: Exception, debug: bool) -> int:
    if debug:
        raise exc
    _say(
        f"internal error: {type(exc).__name__}: {_one_line(exc)[:300]} "
        "(a bug; rerun with --debug for the traceback)"
    )
    return 1


if __name__ == "__main__":
    sys.exit(main())
