"""Command line: ``ptoverify <command>``; the contract is in shared/DESIGN.md.

Exit codes: 0 success (all gates pass), 1 a gate failed, 2 bad input (one
line on stderr beginning ``ptoverify: error:``, no traceback, nothing written).
``--json`` prints one JSON object on stdout and nothing else.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ptoverify.config import Config, load_config
from ptoverify.errors import InputError, PtoverifyError

__all__ = ["main", "build_parser"]


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors become one-line :class:`InputError`."""

    def error(self, message: str):  # noqa: D102
        raise InputError(f"{self.prog}: {message}")


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
    """Write a text file atomically (temp file in the same folder, then rename)."""
    path = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent or ".")
    except OSError as exc:
        raise InputError(f"cannot write '{path}': {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise InputError(f"cannot write '{path}': {exc.strerror or exc}") from None


def _config(args: argparse.Namespace) -> Config:
    return load_config(args.config)


# ---------------------------------------------------------------- mintime
def _add_mintime(sub) -> None:
    p = sub.add_parser(
        "mintime", help="minimum time from a state to the origin",
        description="Minimum time from (X1, X2) to the origin: the closed form and, where "
                    "available, the CasADi and discrete-time references.",
        epilog="example:\n  ptoverify mintime 5 0 --json\n  ptoverify mintime -- -12.5 80")
    p.add_argument("x1", type=finite_float, metavar="X1", help="initial position [mm]")
    p.add_argument("x2", type=finite_float, metavar="X2", help="initial velocity [mm/s]")
    p.add_argument("--intervals", type=positive_int, default=100,
                   help="collocation intervals N (default 100)")
    p.set_defaults(handler=_cmd_mintime)


def mintime_result(cfg: Config, x1: float, x2: float, intervals: int) -> dict[str, Any]:
    """Compute the ``mintime`` JSON object (DESIGN.md keys)."""
    from ptoverify.mintime import min_time

    plant = cfg.plant
    limit = 1e3 * plant.position_range
    if abs(x1) > limit or abs(x2) > 1e3 * plant.w_max:
        raise InputError(f"state ({x1:g}, {x2:g}) is far outside the envelope "
                         f"(|x1| <= {limit:g} mm, |x2| <= {1e3 * plant.w_max:g} mm/s accepted)")
    mt = min_time(x1, x2, plant)
    return {"x0": [x1, x2], "analytic_s": float(mt.t_f), "switch_time_s": float(mt.t_switch)}


def _cmd_mintime(args: argparse.Namespace) -> int:
    cfg = _config(args)
    result = mintime_result(cfg, args.x1, args.x2, args.intervals)
    if args.json:
        print_json(result)
    else:
        for key, value in result.items():
            print(f"{key:>22}: {value}")
    return 0


# ---------------------------------------------------------------- simulate
def _add_simulate(sub) -> None:
    from ptoverify.laws import LAW_NAMES

    p = sub.add_parser(
        "simulate", help="simulate a law on a Section 6 reference",
        description="Simulate the sampled closed loop (exact ZOH flow) of a law tracking a "
                    "Section 6 reference: step 5 mm, ramp 0-30 mm at 200 mm/s, sine 5 mm 5 Hz.",
        epilog="example:\n  ptoverify simulate --law to --signal step --csv to_step.csv")
    p.add_argument("--law", choices=LAW_NAMES, default="pto", help="control law (default pto)")
    p.add_argument("--signal", choices=("step", "ramp", "sine"), default="step",
                   help="reference signal (default step)")
    p.add_argument("--duration", type=finite_float, default=None,
                   help="simulated time [s] (default: per signal)")
    p.add_argument("--no-feedforward", action="store_true",
                   help="do not feed the reference velocity forward")
    p.add_argument("--csv", metavar="FILE", default=None, help="write the time series as CSV")
    p.set_defaults(handler=_cmd_simulate)


def _cmd_simulate(args: argparse.Namespace) -> int:
    from ptoverify.laws import make_law
    from ptoverify.simulate import simulate

    cfg = _config(args)
    if args.duration is not None and not 0 < args.duration <= 100:
        raise InputError(f"--duration must be in (0, 100] s, got {args.duration:g}")
    if args.csv and args.json:
        raise InputError("--csv and --json are exclusive")
    law = make_law(args.law, cfg)
    res = simulate(law, cfg.plant, args.signal, duration=args.duration,
                   feedforward=not args.no_feedforward)
    cols = res.columns()
    if args.csv:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(list(cols))
        for row in zip(*cols.values(), strict=True):
            writer.writerow([repr(float(v)) if k != "region" else int(v)
                             for k, v in zip(cols, row, strict=True)])
        write_atomic(args.csv, buf.getvalue())
        return 0
    tail = res.e[len(res.e) // 2:]
    summary = {"law": res.law, "signal": res.signal, "feedforward": res.feedforward,
               "note": law.note, "samples": len(res.t), "final_error_mm": float(res.e[-1]),
               "max_abs_error_second_half_mm": float(abs(tail).max())}
    if args.json:
        print_json({**summary, "series": cols})
    else:
        for key, value in summary.items():
            print(f"{key:>30}: {value}")
    return 0


# ---------------------------------------------------------------- derive
def _add_derive(sub) -> None:
    p = sub.add_parser(
        "derive", help="re-derive eqs. (3)-(39) with SymPy and judge them",
        description="Re-derive each equation from eq. (1) with SymPy and compare it with its "
                    "printed form; verdicts: verified, erratum, definition, unchecked.",
        epilog="example:\n  ptoverify derive --json")
    p.set_defaults(handler=_cmd_derive)


def _cmd_derive(args: argparse.Namespace) -> int:
    import derivations

    _config(args)
    records = derivations.all_records()
    if args.json:
        print_json({"equations": [r.to_json() for r in records]})
    else:
        for r in records:
            print(f"({r.id:>4}) {r.verdict:<10} {r.note}")
    return 0


# ---------------------------------------------------------------- check
def _add_check(sub) -> None:
    p = sub.add_parser(
        "check", help="run the verification gates (for CI)",
        description="Run every verification as a gate: pass, fail or unverified (a reference "
                    "that could not be computed). Exit 0 when all pass, 1 otherwise.",
        epilog="example:\n  ptoverify check\n  ptoverify check --json --config my_axis.toml")
    p.add_argument("--gate", action="append", default=None, metavar="NAME",
                   help="run only this gate (repeatable)")
    p.set_defaults(handler=_cmd_check)


def _cmd_check(args: argparse.Namespace) -> int:
    from ptoverify.checks import GATES, run_checks, summarize

    cfg = _config(args)
    if args.gate:
        unknown = [g for g in args.gate if g not in GATES]
        if unknown:
            raise InputError(f"unknown gate '{unknown[0]}' (choose from {', '.join(GATES)})")
    results = run_checks(cfg, args.gate)
    summary = summarize(results)
    if args.json:
        print_json({"config": cfg.name, "checks": [r.to_json() for r in results],
                    "summary": summary})
    else:
        for r in results:
            measured = "-" if r.measured is None else f"{r.measured:.3g}"
            limit = "-" if r.limit is None else f"{r.limit:.3g}"
            print(f"{r.status.upper():<10} {r.name:<40} {measured:>10} <= {limit:<10} {r.detail}")
        print(f"{summary['pass']}/{summary['total']} passed, {summary['fail']} failed, "
              f"{summary['unverified']} unverified")
    return 0 if summary["ok"] else 1


COMMANDS: list[tuple[str, Callable[[Any], None]]] = [
    ("check", _add_check),
    ("mintime", _add_mintime),
    ("simulate", _add_simulate),
    ("derive", _add_derive),
]


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser with every command."""
    common = _Parser(add_help=False)
    common.add_argument("--config", metavar="FILE", default=None,
                        help="TOML configuration (default: the paper's Section 6 values)")
    common.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    parser = _Parser(prog="ptoverify", formatter_class=argparse.RawDescriptionHelpFormatter,
                     description="Verification suite for the proximate time-optimal (PTO) "
                                 "control law with bandwidth and saturation.",
                     epilog="example:\n  ptoverify report\n  ptoverify check --json")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True,
                                parser_class=_Parser)
    real_add = sub.add_parser

    def add_parser(name, **kwargs):
        kwargs.setdefault("parents", [common])
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        return real_add(name, **kwargs)

    sub.add_parser = add_parser
    for _, add in COMMANDS:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    try:
        args = build_parser().parse_args(argv)
        return int(args.handler(args))
    except PtoverifyError as exc:
        message = " ".join(str(exc).split())
        print(f"ptoverify: error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("ptoverify: error: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
