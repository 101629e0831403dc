"""The entry point: the parser of every command, main(), exit codes and error lines."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from ptoverify import __version__
from ptoverify.errors import ClusterError, InputError, SolverError
from ptoverify.outdir import (
    ENVIRONMENT_ERRNOS,
    OutputBusy,
    Terminated,
    guarded_std_streams,
    os_error,
    sigterm_raises,
)

from .basic import _add_check, _add_derive, _add_mintime, _add_simulate, _add_zone
from .common import _Parser, mark_negative_numbers
from .outputs import _add_conform, _add_report
from .studies import _add_design, _add_penalty, _add_prove, _add_robust, _add_sweep, _add_tune

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
        args = build_parser().parse_args(mark_negative_numbers(argv))
        debug = bool(getattr(args, "debug", False))
        with sigterm_raises():
            code = int(args.handler(args))
        sys.stdout.flush()  # a write that fails shows here, inside the handlers below
        return code
    except Terminated as exc:
        return _stopped(exc)
    except OutputBusy as exc:
        _say(f"error: {_one_line(exc)}")
        return 1
    except (SolverError, ClusterError) as exc:  # the input was fine; the run could not be done
        _say(f"error: {_one_line(exc)}")
        return 1
    except InputError as exc:
        _say(f"error: {_one_line(exc)}")
        return 2
    except KeyboardInterrupt as exc:
        return _stopped(exc)
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


def _signal_cause(exc: BaseException) -> BaseException | None:
    """Return the Ctrl-C or SIGTERM an exception was raised from, or None.

    A signal that lands while a compiled module initializes comes back as that
    module's ImportError (pybind11: "initialization failed"), the interrupt
    its cause: the run was interrupted, it did not fail.
    """
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, (KeyboardInterrupt, Terminated)):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _stopped(signal: BaseException) -> int:
    """Say that the run was stopped by SIGTERM or Ctrl-C; return 143 or 130."""
    if isinstance(signal, Terminated):
        _say("error: terminated (SIGTERM); nothing written")
        return 143
    _say("error: interrupted")
    return 130


def _internal(exc: Exception, debug: bool) -> int:
    cause = _signal_cause(exc)
    if cause is not None:
        return _stopped(cause)
    if debug:
        raise exc
    _say(
        f"internal error: {type(exc).__name__}: {_one_line(exc)[:300]} "
        "(a bug; rerun with --debug for the traceback)"
    )
    return 1


if __name__ == "__main__":
    sys.exit(main())
