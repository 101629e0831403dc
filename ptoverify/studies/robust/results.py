"""The robustness study's results: frozen dataclasses, each with its JSON.

``to_json`` gives the objects of ``ptoverify robust --json`` (DESIGN.md: keys
``box``, ``margins``, ``worst``, ``maps``, ``timings_s``); non-finite numbers are
left to the caller (:meth:`ptoverify.studies.robust.study.RobustResult.to_json`
writes them as null).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = [
    "PropertyMax",
    "MapCell",
    "RobustMaps",
    "Start",
    "CaseParams",
    "WorstCase",
    "Margin",
    "LawMargins",
    "MostRobust",
]


@dataclass(frozen=True)
class PropertyMax:
    """The largest value of one property over a map cell's states.

    Attributes
    ----------
    max : float
        The largest value (unit of the property: [-] counts and ratios, [mm]
        amplitudes); nan when no state has a value.
    state : tuple of float
        The state that reached it, (x1 [mm], x2 [mm/s]).
    median, p95 : float or None
        Median and 95th percentile over the cell (the settling ratio only) [-].
    """

    max: float
    state: tuple[float, float]
    median: float | None = None
    p95: float | None = None

    def to_json(self) -> dict[str, Any]:
        """Return ``max``, ``state`` (and ``median``, ``p95`` where computed)."""
        out: dict[str, Any] = {"max": self.max, "state": list(self.state)}
        if self.median is not None:
            out["median"], out["p95"] = self.median, self.p95
        return out


@dataclass(frozen=True)
class MapCell:
    """One cell of a robustness map: a perturbation, summarized over the states.

    Attributes
    ----------
    a_ratio : float
        True a over design a [-].
    w_max_ratio : float
        Drive limit over the law's w_max [-].
    delay_samples : int
        Computation delay [samples].
    stride_overs, limit_cycle_mm, overshoot_mm, settling_ratio_nt : PropertyMax
        The worst state of each property: stride-overs [-], limit-cycle amplitude
        [mm], overshoot from rest [mm], settling / N*T [-].
    states_with_stride_over : int
        States with at least one stride-over.
    limit_cycle_states : int
        States that end in a limit cycle.
    not_settled : int
        States that never settle within the horizon.
    """

    a_ratio: float
    w_max_ratio: float
    delay_samples: int
    stride_overs: PropertyMax
    limit_cycle_mm: PropertyMax
    overshoot_mm: PropertyMax
    settling_ratio_nt: PropertyMax
    states_with_stride_over: int
    limit_cycle_states: int
    not_settled: int

    def prop(self, name: str) -> PropertyMax:
        """Return the summary of the property ``name`` (one of ``PROPERTIES``).

        Parameters
        ----------
        name : str
            ``stride_overs``, ``limit_cycle_mm``, ``overshoot_mm`` or ``settling_ratio_nt``.

        Returns
        -------
        PropertyMax
            Its worst state in this cell.
        """
        return {
            "stride_overs": self.stride_overs,
            "limit_cycle_mm": self.limit_cycle_mm,
            "overshoot_mm": self.overshoot_mm,
            "settling_ratio_nt": self.settling_ratio_nt,
        }[name]

    def to_json(self) -> dict[str, Any]:
        """Return the cell as ``ptoverify robust --json`` shows it in ``maps.laws``."""
        return {
            "a_ratio": self.a_ratio,
            "w_max_ratio": self.w_max_ratio,
            "delay_samples": self.delay_samples,
            "stride_overs": self.stride_overs.to_json(),
            "limit_cycle_mm": self.limit_cycle_mm.to_json(),
            "overshoot_mm": self.overshoot_mm.to_json(),
            "settling_ratio_nt": self.settling_ratio_nt.to_json(),
            "states_with_stride_over": self.states_with_stride_over,
            "limit_cycle_states": self.limit_cycle_states,
            "not_settled": self.not_settled,
        }


@dataclass(frozen=True)
class RobustMaps:
    """Every law on a grid of perturbations times a grid of initial states.

    Attributes
    ----------
    a_ratio, w_max_ratio : tuple of float
        The grid's axes [-].
    delay_samples : tuple of int
        The delays of the box [samples].
    states : int
        Initial states per cell.
    laws : dict
        Law name -> its cells (tuple of :class:`MapCell`), in the order delay,
        w_max_ratio, a_ratio.
    """

    a_ratio: tuple[float, ...]
    w_max_ratio: tuple[float, ...]
    delay_samples: tuple[int, ...]
    states: int
    laws: dict[str, tuple[MapCell, ...]]

    def to_json(self) -> dict[str, Any]:
        """Return the ``maps`` object of ``ptoverify robust --json``."""
        return {
            "a_ratio": list(self.a_ratio),
            "w_max_ratio": list(self.w_max_ratio),
            "delay_samples": list(self.delay_samples),
            "states": self.states,
            "laws": {law: [c.to_json() for c in cells] for law, cells in self.laws.items()},
        }


@dataclass(frozen=True)
class Start:
    """A starting point of the worst-case search: a map cell's worst state.

    Attributes
    ----------
    state : tuple of float
        (x1 [mm], x2 [mm/s]).
    value : float
        The property's value there (its unit).
    a_ratio, w_max_ratio : float
        The cell's perturbation [-].
    delay_samples : int
        The cell's delay [samples].
    """

    state: tuple[float, float]
    value: float
    a_ratio: float
    w_max_ratio: float
    delay_samples: int


@dataclass(frozen=True)
class CaseParams:
    """The perturbation of a worst case: the full mismatch to reproduce it.

    Attributes
    ----------
    a_ratio, w_max_ratio : float or None
        True a over design a, drive limit over w_max [-] (None: nothing evaluated).
    delay_samples : int
        Computation delay [samples].
    position_quantum : float
        Encoder resolution [mm].
    velocity_noise : float
        Standard deviation of the noise on the measured x2 [mm/s].
    seed : int
        Seed of the noise.
    """

    a_ratio: float | None
    w_max_ratio: float | None
    delay_samples: int
    position_quantum: float
    velocity_noise: float
    seed: int

    def to_json(self) -> dict[str, Any]:
        """Return the ``params`` object of a worst case."""
        return {
            "a_ratio": self.a_ratio,
            "w_max_ratio": self.w_max_ratio,
            "delay_samples": self.delay_samples,
            "position_quantum": self.position_quantum,
            "velocity_noise": self.velocity_noise,
            "seed": self.seed,
        }


@dataclass(frozen=True)
class WorstCase:
    """The worst value of one property found for one law: grid, then search.

    Attributes
    ----------
    grid : float or None
        The grid's worst value (unit of the property; None: no cell had a value).
    grid_unbounded : bool
        The grid's worst is infinite (e.g. a state never settles).
    searched : float or None
        The worst over every trajectory of the search and the grid's worst cell
        (inf: see ``unbounded``, null in the JSON; None: nothing evaluated).
    unbounded : bool
        The searched worst is infinite.
    state : tuple of float or None
        Where: (x1 [mm], x2 [mm/s]).
    params : CaseParams
        The perturbation there.
    evaluations : int
        Trajectories the law's searches simulated (all properties).
    """

    grid: float | None
    grid_unbounded: bool
    searched: float | None
    unbounded: bool
    state: tuple[float, float] | None
    params: CaseParams
    evaluations: int

    def to_json(self) -> dict[str, Any]:
        """Return the worst case as ``ptoverify robust --json`` shows it in ``worst``."""
        return {
            "grid": self.grid,
            "grid_unbounded": self.grid_unbounded,
            "searched": self.searched,
            "unbounded": self.unbounded,
            "state": None if self.state is None else list(self.state),
            "params": self.params.to_json(),
            "evaluations": self.evaluations,
        }


@dataclass(frozen=True)
class Margin:
    """An interval of a_true / a_design around 1 where a property holds.

    Attributes
    ----------
    interval : tuple or None
        (lo, hi) [-], each endpoint the last ratio where it holds, None where it
        holds past the searched range; None when it fails at the design point or
        does not apply.
    note : str
        Why there is no interval ("" when there is one).
    """

    interval: tuple[float | None, float | None] | None
    note: str = ""

    def to_json(self) -> list[float | None] | None:
        """Return ``[lo, hi]`` or None."""
        return None if self.interval is None else list(self.interval)


@dataclass(frozen=True)
class LawMargins:
    """The margins of one law.

    Attributes
    ----------
    linear : Margin
        Sampled linear loop stable (eigenvalues) [-].
    linear_delay1 : Margin
        The same with a one-sample computation delay [-].
    no_limit_cycle : Margin or None
        No limit cycle from any grid state (simulated) [-]; None: not computed.
    """

    linear: Margin
    linear_delay1: Margin
    no_limit_cycle: Margin | None = None

    def to_json(self) -> dict[str, Any]:
        """Return the law's object in ``margins`` of ``ptoverify robust --json``."""
        out = {
            "linear_loop_a_ratio_stable": self.linear.to_json(),
            "linear_loop_note": self.linear.note,
            "linear_loop_a_ratio_stable_delay1": self.linear_delay1.to_json(),
            "linear_loop_note_delay1": self.linear_delay1.note,
        }
        if self.no_limit_cycle is not None:
            out["no_limit_cycle_a_ratio"] = self.no_limit_cycle.to_json()
            out["no_limit_cycle_note"] = self.no_limit_cycle.note
        return out


@dataclass(frozen=True)
class MostRobust:
    """Which law's linear loop tolerates the widest bandwidth error.

    Attributes
    ----------
    law : str or None
        The law with the widest interval (None: no law has one).
    log_width : dict
        Law -> ln(hi / lo) of its linear interval [-].
    """

    law: str | None
    log_width: dict[str, float]

    def to_json(self) -> dict[str, Any]:
        """Return ``law`` and ``log_width``."""
        return {"law": self.law, "log_width": dict(self.log_width)}
