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

from .common import finite_float, positive_int, print_json, to_jsonable, write_atomic
from .main import COMMANDS, build_parser, main

__all__ = [
    "COMMANDS",
    "build_parser",
    "finite_float",
    "main",
    "positive_int",
    "print_json",
    "to_jsonable",
    "write_atomic",
]
