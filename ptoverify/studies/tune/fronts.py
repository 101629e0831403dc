"""Pareto fronts of the tunings: settling against overshoot, and one front minus another."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from ptoverify.studies.tune.measure import Candidate

__all__ = ["FrontGap", "front_gap", "pareto_front"]


def pareto_front(cands: list[Candidate]) -> list[Candidate]:
    """Return the candidates not dominated in (overshoot [mm], settling_2pct [s]).

    Parameters
    ----------
    cands : list of Candidate
        Candidates with finite overshoot and settling (others are ignored).

    Returns
    -------
    list of Candidate
        The front, by increasing overshoot.

    Examples
    --------
    >>> c = lambda o, s: Candidate({}, s, s, s, o, True)
    >>> [x.overshoot_mm for x in pareto_front([c(0, 3), c(1, 2), c(2, 2.5), c(3, 1)])]
    [0, 1, 3]
    """
    ok = [c for c in cands if math.isfinite(c.overshoot_mm) and math.isfinite(c.settling_2pct_s)]
    ok.sort(key=lambda c: (c.overshoot_mm, c.settling_2pct_s))
    front, best = [], math.inf
    for c in ok:
        if c.settling_2pct_s < best:
            front.append(c)
            best = c.settling_2pct_s
    return front


@dataclass(frozen=True)
class FrontGap:
    """One law's Pareto front minus another's, where both are defined.

    A front is a step function of the overshoot bound x: the least 2 % settling
    time of its points with overshoot at most x, constant between points.  The
    difference of two such functions is again one, given here exactly at its
    breakpoints (no resampling).

    Attributes
    ----------
    law, minus : str
        The fronts subtracted: ``law``'s settling minus ``minus``'s.
    overshoot_mm : tuple of float
        The breakpoints [mm], increasing: every point of either front from the
        larger of the two least overshoots to the smaller of the two largest.
    gap_s : tuple of float
        The difference [s] from each breakpoint up to the next (the last one holds
        at its own overshoot only); negative where ``law`` settles sooner.
    """

    law: str
    minus: str
    overshoot_mm: tuple[float, ...]
    gap_s: tuple[float, ...]

    def to_json(self) -> dict[str, Any]:
        """Return the gap as JSON (``law``, ``minus``, ``overshoot_mm`` [mm], ``gap_s`` [s])."""
        return dataclasses.asdict(self) | {
            "overshoot_mm": list(self.overshoot_mm),
            "gap_s": list(self.gap_s),
        }


def front_gap(
    law: str, front: list[Candidate], minus: str, other: list[Candidate]
) -> FrontGap | None:
    """Return ``front`` minus ``other``, both as step functions of the overshoot bound.

    Parameters
    ----------
    law, minus : str
        The laws' names (recorded in the result).
    front, other : list of Candidate
        Two Pareto fronts (:func:`pareto_front`: increasing overshoot [mm],
        decreasing 2 % settling [s]).

    Returns
    -------
    FrontGap or None
        ``None`` when either front is empty or their overshoot ranges do not overlap.

    Examples
    --------
    >>> c = lambda o, s: Candidate({}, s, s, s, o, True)
    >>> g = front_gap("a", [c(0, 5), c(2, 3)], "b", [c(1, 4), c(3, 1)])
    >>> g.overshoot_mm, g.gap_s
    ((1, 2), (1, -1))
    """
    if not front or not other:
        return None
    lo = max(front[0].overshoot_mm, other[0].overshoot_mm)
    hi = min(front[-1].overshoot_mm, other[-1].overshoot_mm)
    if not hi >= lo:
        return None
    xs = sorted({c.overshoot_mm for c in (*front, *other) if lo <= c.overshoot_mm <= hi})

    def value(f: list[Candidate], x: float) -> float:  # least settling at overshoot <= x
        return min(c.settling_2pct_s for c in f if c.overshoot_mm <= x)

    return FrontGap(law, minus, tuple(xs), tuple(value(front, x) - value(other, x) for x in xs))
