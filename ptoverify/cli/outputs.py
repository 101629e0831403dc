"""The commands that write reports: report and conform."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from ptoverify.conform_limits import CONFORM_REFERENCES
from ptoverify.errors import InputError

from .common import _add_junit, _check_junit, _config, finite_float, print_json, write_atomic


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
        "tuning, charts (their sections then say so)",
    )
    p.add_argument(
        "--jobs",
        metavar="N",
        type=int,
        default=None,
        help="processes for the report's independent stages, this one included (default: "
        "the CPUs available; 1 runs every stage in this process). The results do not depend on it",
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

--precision float32 judges firmware that computes in single precision: the reference is
evaluated at the state rounded to float32 and states within the derived float32 tie band of a
region boundary are ties (README). --delay N, --quantum MM, --velocity-noise MM_S --seed S,
--a-ratio R (or --robust: the corners of the [robustness] box) also run the closed loops of
your law and the reference under that perturbation, from the same states with the same noise:
each property must be no worse than the reference's by more than the [conform] margins; where
the reference itself fails (it limit-cycles with a one-sample delay) the output says so.

--report DIR also writes a report for a review (verdict, properties with units, heat maps of
|u - u_ref| with l1, l2, l1*, l2* and |x1| < d, closed loop, settling / N*T, step/ramp/sine
responses of a --law next to the reference); DIR is checked before anything runs and written
atomically.

Exit codes: 0 conforms, 1 does not (each failing property named with the first state that
shows it; a law that raises, returns NaN/inf, or has memory is a finding), 2 bad input
(import error, missing attribute, not callable, wrong signature, a non-number or wrong
shape returned, unreadable table).

--reference ptos|cascade-p judges your implementation of a baseline instead (PTOS or the
cascade P loop, with the configuration's [ptos] / [cascade] gains): the same gate, but the
baselines are continuous, so nothing is excluded as a curve tie, and the probes crowd the
baseline's linear-region edge in place of |x1| = d.

examples:
  ptoverify conform --law ptoverify.conform.gate:reference_law
  ptoverify conform --law examples/my_ptos.py:ptos --reference ptos
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
    p.add_argument(
        "--reference",
        choices=CONFORM_REFERENCES,
        default=None,
        help="the law to judge against: pto (the corrected PTO, default), or a baseline, ptos "
        "or cascade-p, with the configuration's [ptos] / [cascade] gains (default: the "
        "configuration's [conform] reference, pto)",
    )
    p.add_argument(
        "--precision",
        default="float64",
        metavar="P",
        help="what the implementation computes in: float64 (default) or float32 (the reference "
        "is evaluated at the state rounded to float32; float32 ties at region boundaries excluded)",
    )
    for flag, kind, metavar, text in (
        ("--delay", int, "N", "also compare closed loops with a computation delay [samples]"),
        ("--quantum", finite_float, "MM", "... with an encoder quantum [mm]"),
        (
            "--velocity-noise",
            finite_float,
            "MM_S",
            "... with velocity noise sd [mm/s] (needs --seed)",
        ),
        ("--seed", int, "S", "seed of the velocity noise (one sequence, shared by both laws)"),
        ("--a-ratio", finite_float, "R", "... with a true bandwidth a_true / a_design"),
    ):
        p.add_argument(flag, type=kind, metavar=metavar, default=None, help=text)
    p.add_argument(
        "--robust",
        action="store_true",
        help="compare closed loops at the corners of the configuration's [robustness] box",
    )
    _add_junit(p)
    p.set_defaults(handler=_cmd_conform)


def _conform_perturbations(args: argparse.Namespace, cfg) -> tuple:
    """Return the perturbations of ``conform`` (validated; InputError on bad options)."""
    from ptoverify.conform.perturbed import perturbation, robust_box

    one = perturbation(
        cfg,
        delay=args.delay,
        quantum=args.quantum,
        velocity_noise=args.velocity_noise,
        seed=args.seed,
        a_ratio=args.a_ratio,
    )
    if args.robust and one is not None:
        raise InputError(
            "--robust runs the [robustness] box: give it without --delay, --quantum, "
            "--velocity-noise, --seed and --a-ratio"
        )
    found = robust_box(cfg) if args.robust else (() if one is None else (one,))
    if found and args.emit_grid:
        raise InputError("--emit-grid writes the probe set only: no --precision or perturbation")
    if found and not args.law:
        raise InputError("closed loops under perturbation need --law (a table has no closed loop)")
    return found


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
    if args.reference is not None:
        from ptoverify.conform.reflaw import with_reference

        cfg = with_reference(cfg, args.reference)
    if args.emit_grid:  # options that judge nothing there are bad input, never ignored (run 7)
        unused = [
            f
            for f, v in (("--tolerance", args.tolerance), ("--junit", args.junit))
            if v is not None
        ]
        if unused:
            raise InputError(
                f"--emit-grid writes the probe set only: {' and '.join(unused)} judge nothing"
            )
    rtol = conform.DEFAULT_RTOL if args.tolerance is None else args.tolerance
    if not 0 < rtol < 1:
        raise InputError(f"--tolerance must be in (0, 1), got {rtol:g}")
    _check_junit(args)
    from ptoverify.conform.precision import check_precision

    precision = check_precision(args.precision)
    perturbations = _conform_perturbations(args, cfg)
    if args.emit_grid and (perturbations or precision != "float64"):
        raise InputError("--emit-grid writes the probe set only: no --precision or perturbation")
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
            cfg,
            law=args.law,
            table=args.table,
            rtol=rtol,
            timeout=args.timeout,
            precision=precision,
            perturbations=perturbations,
        )
    elif args.table:
        result = conform.conform_table(args.table, cfg, rtol=rtol, precision=precision)
    else:  # the law runs in a child process; what it prints goes to stderr afterwards
        result = conform.conform_spec(
            args.law,
            cfg,
            rtol=rtol,
            timeout=args.timeout,
            precision=precision,
            perturbations=perturbations,
        )
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
