"""Trace every number a report shows to a field of its ``results.json``.

A number in a table cell or a headline sentence traces when some numeric
leaf v of ``results.json`` prints as that number through the report's own
formatter (:func:`ptoverify.report.render.fmt`, 2 to 6 significant digits), at
a display scale the report uses: as is, in ms (x 1e3), in % (x 100), or as the
integer count it is.  Table headers and equation identifiers are labels, not
results, and are not checked.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Iterator

from ptoverify.report.render import fmt

#: Display scales: as stored, s -> ms, fraction -> %, mm -> um.
SCALES = (1.0, 1e3, 100.0)
#: A number as the report prints it (no sign: a minus is matched on the magnitude).
NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?(?:e[+-]?\d+)?)(?![\w.])")


#: Labels that name a place in the paper, not a result: "Sec. 6.1", "eq. (16)", "eqs. 20-27".
LABELS = re.compile(r"\b(?:Sec|Fig|eqs?)\.\s*\(?\d+(?:[.\-]\d+)*\)?", re.IGNORECASE)


def leaves(obj) -> Iterator[float]:
    """Every finite number of a JSON tree (booleans excluded)."""
    if isinstance(obj, dict):
        for v in obj.values():
            yield from leaves(v)
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            yield from leaves(v)
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool) and math.isfinite(obj):
        yield float(obj)


def renderings(values: Iterable[float]) -> set[str]:
    """Every string the report could print for these values (magnitudes only)."""
    out: set[str] = set()
    for v in set(values):
        for s in SCALES:
            x = abs(v * s)
            for digits in (2, 3, 4, 5, 6):
                out.add(fmt(x, digits))
            if x == int(x):
                out.add(str(int(x)))
    return out


def strings(obj) -> Iterator[str]:
    """Every string leaf of a JSON tree (computed prose, e.g. a claim's detail)."""
    if isinstance(obj, dict):
        for v in obj.values():
            yield from strings(v)
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            yield from strings(v)
    elif isinstance(obj, str):
        yield obj


def untraced(texts: Iterable[str], results: dict) -> list[tuple[str, str]]:
    """(number, text) for each number in ``texts`` that no field of ``results`` prints as.

    A text that is itself a string field of ``results`` (a computed sentence
    stored with the results) traces whole.
    """
    known = renderings(leaves(results))
    verbatim = set(strings(results))
    bad = []
    for text in texts:
        if text in verbatim:
            continue
        for m in NUMBER.finditer(LABELS.sub("", text)):
            if m.group(1) not in known:
                bad.append((m.group(1), text))
    return bad
