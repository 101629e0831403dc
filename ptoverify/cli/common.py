"""Shared pieces of the command line: the parser class, number options, JSON output."""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path
from typing import Any

from ptoverify.config import Config, load_config
from ptoverify.errors import InputError
from ptoverify.outdir import check_writable
from ptoverify.outdir import write_atomic as _write_atomic


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors become one-line :class:`InputError`.

    Negative numbers as positionals (``-5``, ``-1e2``, ``-.5``, ``-5.``) are marked
    by :func:`mark_negative_numbers` before parsing, so no option lookalike stops them.
    """

    def error(self, message: str):  # noqa: D102
        # "ptoverify: error: mintime: ...", not "ptoverify: error: ptoverify mintime: ..."
        where = self.prog.removeprefix("ptoverify").strip()
        raise InputError(f"{where}: {message}" if where else message)


#: A float literal with a leading minus: a negative number, never an option.
_NEGATIVE = re.compile(r"-(\d+\.?\d*([eE][-+]?\d+)?|\.\d+([eE][-+]?\d+)?|inf|nan)", re.I)


def mark_negative_numbers(argv: list[str]) -> list[str]:
    """Return ``argv`` with each negative number literal led by a space.

    argparse treats an argument that starts with ``-`` as an option; one that
    starts with a space is a value, and :func:`float` ignores the space.  This is
    how ``ptoverify mintime -5 0`` and ``--x0 -1e2 0`` parse with public argparse.

    Parameters
    ----------
    argv : list of str
        The command line after the program name.

    Returns
    -------
    list of str
        The same arguments, negative number literals marked.

    Examples
    --------
    >>> mark_negative_numbers(["mintime", "-5", "-1e2", "--json", "-x"])
    ['mintime', ' -5', ' -1e2', '--json', '-x']
    """
    return [f" {a}" if _NEGATIVE.fullmatch(a) else a for a in argv]


def finite_float(text: str) -> float:
    """Parse a finite float (rejects NaN and infinities)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text.strip()!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text.strip()!r}")
    return value


def positive_int(text: str) -> int:
    """Parse a positive integer."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text.strip()!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive: {text.strip()!r}")
    return value


def _seed_int(text: str) -> int:
    """Parse a seed: an integer in [0, 2^32), the range of ``robustness.seed``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text.strip()!r}") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"must be in [0, 2^32): {text.strip()!r}")
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
    parent = path.absolute().parent
    if not parent.is_dir():
        why = "is not a folder" if parent.exists() else "does not exist"
        raise InputError(f"--junit '{args.junit}': folder '{path.parent}' {why}")
    check_writable(path)  # a read-only folder fails here, not after the gates ran
