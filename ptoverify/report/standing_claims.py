"""A Section 6 claim's standing: holds, fails or depends, and the readings that decide it.

Read off the claims' readings in ``results.json`` (each with its reading
dimensions and verdict), never typed in; :mod:`ptoverify.report.standing` shows it
in the reviewer's verdict table.

Catalogue
---------
READING_WORDS   how each reading dimension's value reads in words
SHORT_WORDS     the same, shortened for the verdict table (:func:`short_legend` explains them)
reading_words   one reading dimension's value in words (a by its value in rad/s)
short_legend    what the verdict table's short reading words stand for
claim_standing  holds / fails / depends, naming the readings it holds and fails with
bandwidth_hz    the configuration's bandwidth [Hz], None when it gives a in rad/s
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from itertools import combinations
from typing import Any

from ptoverify.report.render import fmt, qty
from ptoverify.report.words import plural

__all__ = [
    "READING_WORDS",
    "SHORT_WORDS",
    "reading_words",
    "short_legend",
    "claim_standing",
    "bandwidth_hz",
]

#: How each reading dimension of a claim reads in words.
READING_WORDS: dict[str, dict[Any, str]] = {
    "a": {
        "2pi*f": "a = 2 pi f (the bandwidth read in Hz)",
        "f": "a = f (the bandwidth read as rad/s)",
    },
    "pto": {"corrected": "the corrected PTO", "printed": "the PTO as printed"},
    "tracking": {
        "feed-forward": "feed-forward",
        "none": "no feed-forward",
        "error": "the law on the error without feed-forward",
    },
    "gains": {},
    "band": {},
}

#: The short words of the verdict table, where they differ from :data:`READING_WORDS`
#: (:func:`short_legend` says what each stands for).
SHORT_WORDS: dict[str, dict[Any, str]] = {
    "pto": {"corrected": "corrected PTO", "printed": "printed PTO"},
    "tracking": {"feed-forward": "FF", "none": "no FF", "error": "error law"},
}


def reading_words(
    dim: str, value: Any, bandwidth_hz: float | None = None, short: bool = False
) -> str:
    """Return one reading dimension's value in words (``a = f (the bandwidth read as rad/s)``).

    Parameters
    ----------
    dim : str
        The dimension (``a``, ``band``, ``pto``, ``tracking``, ``gains``).
    value : Any
        Its value in the claims' ``reading``.
    bandwidth_hz : float, optional
        The configuration's bandwidth [Hz]: a reading of a then names its value
        (``a = 2 pi x 30 = 188.5 rad/s``).
    short : bool
        The verdict table's short words (:data:`SHORT_WORDS`; a reading of a by its
        value alone, ``a = 188.5 rad/s``), which :func:`short_legend` explains.

    Returns
    -------
    str

    Examples
    --------
    >>> reading_words("a", "2pi*f", 30.0)
    'a = 2 pi x 30 Hz = 188.5 rad/s'
    >>> reading_words("a", "f", 30.0), reading_words("band", 0.05)
    ('a = 30 rad/s (30 Hz read as rad/s)', 'the 5 % band')
    >>> reading_words("a", "f", 30.0, short=True), reading_words("tracking", "none", short=True)
    ('a = 30 rad/s', 'no FF')
    """
    if short:
        if dim == "a" and bandwidth_hz is not None and value in ("2pi*f", "f"):
            scale = 2 * math.pi if value == "2pi*f" else 1.0
            return f"a = {qty(scale * bandwidth_hz, 'rad/s')}"
        if value in SHORT_WORDS.get(dim, {}):
            return SHORT_WORDS[dim][value]
    if dim == "a" and bandwidth_hz is not None and value in ("2pi*f", "f"):
        if value == "2pi*f":
            return f"a = 2 pi x {fmt(bandwidth_hz)} Hz = {qty(2 * math.pi * bandwidth_hz, 'rad/s')}"
        return f"a = {qty(bandwidth_hz, 'rad/s')} ({fmt(bandwidth_hz)} Hz read as rad/s)"
    if dim == "reading":  # a whole reading, by its label
        return str(value)
    words = READING_WORDS.get(dim, {})
    if value in words:
        return words[value]
    if dim == "band" and isinstance(value, float):
        return f"the {fmt(100 * value)} % band"
    if dim == "gains" and value is None:
        return "the paper's gains"
    if dim == "gains":
        return f"tuning {value}"
    return f"{dim} = {fmt(value)}"


def claim_standing(
    claim: Mapping, bandwidth_hz: float | None = None, short: bool = False
) -> tuple[str, str]:
    """Return ``(standing, condition)`` of one claim: holds, fails or depends.

    A claim that depends names the readings it holds under and those it fails
    under, each as the fewest reading dimensions that decide it (:func:`_deciding`),
    all computed from the readings' verdicts.

    Parameters
    ----------
    claim : Mapping
        One entry of ``results.json``'s ``claims`` (``readings``, each with its
        ``reading`` dimensions and ``verdict``).
    bandwidth_hz : float, optional
        The configuration's bandwidth [Hz], to name the readings of a by value.
    short : bool
        Name the readings in the verdict table's short words (:func:`reading_words`).

    Returns
    -------
    tuple of str
        ``holds`` (every reading reproduces it), ``fails`` (none does) or
        ``depends``; the condition of a claim that depends reads ``holds with
        ...; fails with ...``.

    Examples
    --------
    >>> r = lambda a, v: {"reading": {"a": a, "band": 0.02}, "verdict": v}
    >>> claim_standing({"readings": [r("2pi*f", "not reproduced"), r("f", "reproduced")]})[1]
    'holds with a = f (the bandwidth read as rad/s); fails with a = 2 pi f (the bandwidth read in Hz)'
    """
    readings = list(claim["readings"])
    ok = [r["verdict"] == "reproduced" for r in readings]
    if readings and all(ok):
        return "holds", f"under all {plural(len(readings), 'reading')} tried"
    if not any(ok):
        return "fails", f"under all {plural(len(readings), 'reading')} tried"
    holds, fails = _deciding(readings, ok)

    def say(cubes: list[dict[str, Any]]) -> str:
        words = [[reading_words(d, v, bandwidth_hz, short) for d, v in c.items()] for c in cubes]
        if len(words) == 1:
            return " and ".join(words[0])
        return " or ".join(f"({' and '.join(w)})" if len(w) > 1 else w[0] for w in words)

    return "depends", f"holds with {say(holds)}; fails with {say(fails)}"


def _deciding(
    readings: list[Mapping], ok: list[bool]
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Return the readings a claim holds and fails under, each in the fewest deciding dimensions.

    The smallest set of the dimensions that vary whose values decide the verdict
    (every reading with the same values has the same verdict); the holding and the
    failing value combinations, a dimension left out of a combination when every
    one of its values gives the same verdict there.
    """
    dims = list(dict.fromkeys(k for r in readings for k in r["reading"]))
    value = [
        {d: _key(r["reading"][d] if d in r["reading"] else None) for d in dims} for r in readings
    ]
    varying = [d for d in dims if len({v[d] for v in value}) > 1]
    for k in range(1, len(varying) + 1):
        for subset in combinations(varying, k):
            groups: dict[tuple, list[bool]] = {}
            for v, good in zip(value, ok, strict=True):
                groups.setdefault(tuple(v[d] for d in subset), []).append(good)
            if all(all(g) or not any(g) for g in groups.values()):
                domains = [list(dict.fromkeys(key[i] for key in groups)) for i in range(k)]
                return tuple(  # type: ignore[return-value]
                    [
                        {d: _unkey(x) for d, x in zip(subset, cube, strict=True) if x is not _ANY}
                        for cube in _merge(
                            [key for key, g in groups.items() if all(g) == want], domains
                        )
                    ]
                    for want in (True, False)
                )
    # readings alike in every dimension yet of different verdicts: name them by label
    return (
        [{"reading": r["label"]} for r, g in zip(readings, ok, strict=True) if g],
        [{"reading": r["label"]} for r, g in zip(readings, ok, strict=True) if not g],
    )


def _key(value: Any) -> Any:
    return tuple(value) if isinstance(value, (list, tuple)) else value


def _unkey(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


#: A dimension a merged combination of readings leaves free.
_ANY = object()


def _merge(cubes: list[tuple], domains: list[list]) -> list[tuple]:
    """Return the fewest value combinations, some dimensions left free, that cover ``cubes``.

    A dimension is left free (:data:`_ANY`) in a combination when every one of its
    values gives the same verdict there (prime combinations, as Quine-McCluskey
    finds them); a greedy cover then picks the primes that cover most readings.
    """
    full = set(cubes)
    level, primes = set(full), set()
    while level:
        merged_from, nxt = set(), set()
        for c in level:
            for i, domain in enumerate(domains):
                if c[i] is _ANY or len(domain) < 2:
                    continue
                sibs = {c[:i] + (v,) + c[i + 1 :] for v in domain}
                if sibs <= level:
                    merged_from |= sibs
                    nxt.add(c[:i] + (_ANY,) + c[i + 1 :])
        primes |= level - merged_from
        level = nxt

    def covers(p: tuple, m: tuple) -> bool:
        return all(x is _ANY or x == y for x, y in zip(p, m, strict=True))

    left, chosen = set(full), []
    order = {c: k for k, c in enumerate(cubes)}
    while left:
        best = max(
            primes,
            key=lambda p: (
                sum(covers(p, m) for m in left),
                sum(x is _ANY for x in p),
                -min((order[m] for m in full if covers(p, m)), default=0),
            ),
        )
        chosen.append(best)
        left = {m for m in left if not covers(best, m)}
    return sorted(chosen, key=lambda p: min(order[m] for m in full if covers(p, m)))


def short_legend(bandwidth_hz: float | None) -> str:
    """Return what the verdict table's short reading words stand for, in one sentence.

    Parameters
    ----------
    bandwidth_hz : float or None
        The configuration's bandwidth [Hz] (None: a is given in rad/s, one reading).

    Returns
    -------
    str

    Examples
    --------
    >>> short_legend(30.0).split("; ")[0]
    'a = 188.5 rad/s reads the bandwidth in Hz (2 pi x 30 Hz)'
    """
    parts = []
    if bandwidth_hz is not None:
        parts += [
            f"{reading_words('a', '2pi*f', bandwidth_hz, short=True)} reads the bandwidth in Hz "
            f"(2 pi x {fmt(bandwidth_hz)} Hz)",
            f"{reading_words('a', 'f', bandwidth_hz, short=True)} reads {fmt(bandwidth_hz)} Hz "
            "as rad/s",
        ]
    parts += [
        f"{SHORT_WORDS[dim][v]}: {READING_WORDS[dim][v]}"
        for dim in SHORT_WORDS
        for v in SHORT_WORDS[dim]
        if SHORT_WORDS[dim][v].lower() not in READING_WORDS[dim][v].lower()
    ]
    return "; ".join(parts)


def bandwidth_hz(res: Mapping) -> float | None:
    """Return the configuration's bandwidth [Hz] (None: the configuration gives a in rad/s).

    Parameters
    ----------
    res : Mapping
        The results.

    Returns
    -------
    float or None
    """
    plant = res["environment"]["config"]["plant"]
    return plant["bandwidth_hz"] if "bandwidth_hz" in plant else None
