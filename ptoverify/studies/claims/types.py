"""The claims' result types, verdicts and tolerances."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from ptoverify.config import Config
from ptoverify.studies.tune import (
    FAIR_BOUNDS,
)

VERDICTS = ("reproduced", "not reproduced", "ambiguous")


PHASE_FLOOR_DEG = 1.0


PERCENT_FLOOR = 5.0


REL_TOL = 0.20


MUCH = 2.0


_FLOORS = {"deg": (PHASE_FLOOR_DEG, "1 deg"), "%": (PERCENT_FLOOR, "5 points")}


_SIM_TRACKING = {"feed-forward": "feedforward", "none": "none", "error": "error"}


@dataclass(frozen=True)
class Reading:
    """One reading of the paper's ambiguities.

    Attributes
    ----------
    a : str
        ``2pi*f`` (a = 2 pi f rad/s), ``f`` (a = f rad/s) or ``given``.
    tracking : str or None
        ``feed-forward``, ``none`` or ``error`` (None: does not apply).
    pto : str or None
        ``corrected`` or ``printed`` (None: does not apply).
    band : float or None
        Settling band as a fraction of the step [-] (None: does not apply).
    gains : str or None
        None: the paper's gains.  ``pd-retuned``: the PD tuned to the PTO's
        paper-gain overshoot, the PTO at the paper's gains.  ``best@pto-paper``,
        ``best@pd-paper``: both laws at their best tuning under the shared
        overshoot bound of that name (:data:`ptoverify.studies.tune.FAIR_BOUNDS`).
    bound_mm : float or None
        The overshoot bound of a tuned reading [mm].
    """

    a: str = "given"
    tracking: str | None = None
    pto: str | None = None
    band: float | None = None
    gains: str | None = None
    bound_mm: float | None = None

    def label(self, cfg: Config) -> str:
        """Describe the reading in words, with the value of a."""
        parts = [
            f"a = {_a_value(cfg, self.a):.4g} rad/s"
            + {"2pi*f": " (2 pi f)", "f": " (f in rad/s)"}.get(self.a, "")
        ]
        if self.tracking is not None:
            parts.append(
                {
                    "feed-forward": "feed-forward",
                    "none": "no feed-forward",
                    "error": "law on the error, no feed-forward",
                }[self.tracking]
            )
        if self.pto is not None:
            parts.append(f"PTO {self.pto}")
        if self.band is not None:
            parts.append(f"band {100 * self.band:g} %")
        if self.gains == "pd-retuned":
            parts.append(
                f"PD retuned to overshoot <= {self.bound_mm:.4g} mm (the PTO's), PTO paper gains"
            )
        elif self.gains is not None:
            meaning = FAIR_BOUNDS[self.gains.removeprefix("best@")]
            parts.append(f"both laws best-tuned, overshoot <= {self.bound_mm:.4g} mm ({meaning})")
        return ", ".join(parts)

    def to_json(self) -> dict:
        """Return the reading as a dict."""
        return {
            "a": self.a,
            "tracking": self.tracking,
            "pto": self.pto,
            "band": self.band,
            "gains": self.gains,
            "bound_mm": self.bound_mm,
        }


@dataclass(frozen=True)
class ReadingResult:
    """A claim measured under one reading.

    Attributes
    ----------
    reading : Reading
        The reading.
    label : str
        The reading in words.
    measured : float or None
        The headline measured number (None for a qualitative claim).
    values : dict
        Every computed number the verdict used, by name (units in the names).
    verdict : str
        ``reproduced`` or ``not reproduced``.
    detail : str
        The comparison, in words with the numbers.
    measured_grid : float or None
        The headline number with every time metric read on the sample grid.
    values_grid : dict
        ``values`` with every time metric read on the sample grid.
    verdict_grid : str
        The verdict the same rule gives on the grid values (grid values tie
        only when equal).
    ties : tuple of str
        Ties met by a comparison of times under the tie rule (the claim's strict
        inequality then does not hold), e.g. ``rise_time_pto_s = rise_time_pd_s``.
    """

    reading: Reading
    label: str
    measured: float | None
    values: dict
    verdict: str
    detail: str
    measured_grid: float | None = None
    values_grid: dict = field(default_factory=dict)
    verdict_grid: str = ""
    ties: tuple[str, ...] = ()

    @property
    def differs_on_grid(self) -> bool:
        """Whether the verdict on the sample grid would differ from the exact one."""
        return bool(self.verdict_grid) and self.verdict_grid != self.verdict

    def to_json(self) -> dict:
        """Return a JSON-able dict."""
        return {
            "reading": self.reading.to_json(),
            "label": self.label,
            "measured": self.measured,
            "values": dict(self.values),
            "verdict": self.verdict,
            "detail": self.detail,
            "measured_grid": self.measured_grid,
            "values_grid": dict(self.values_grid),
            "verdict_grid": self.verdict_grid,
            "verdict_differs_on_grid": self.differs_on_grid,
            "ties": list(self.ties),
        }


@dataclass(frozen=True)
class ClaimResult:
    """A claim of Section 6 or the conclusion, with its verdict.

    Attributes
    ----------
    id : str
        Stable identifier.
    section : str
        Where the paper says it (``6.1``, ``6.2``, ``6.3``, ``7``).
    signal : str
        ``step``, ``ramp``, ``sine``.
    claim : str
        The claim, in the paper's words (quoted where possible).
    paper_value : float or None
        The paper's number, where it gives one.
    unit : str
        Unit of ``paper_value`` and ``measured``.
    rule : str
        The tolerance rule that decides the verdict.
    verdict : str
        Overall: the readings' common verdict, ``ambiguous`` when they differ.
    measured : float or None
        Headline value under the primary reading.
    detail : str
        The primary reading's detail.
    readings : tuple of ReadingResult
        Every reading, the primary first.
    measured_grid : float or None
        Headline value under the primary reading, time metrics on the sample grid.
    verdict_grid : str
        Overall verdict from the readings' grid verdicts.
    verdict_tuned : str
        Common verdict of the tuned readings (``Reading.gains`` set), ``ambiguous``
        when they differ; "" when they were not computed.  ``verdict`` and
        ``verdict_grid`` are over the paper-gain readings only, so asking for
        the tuned readings never changes them.
    """

    id: str
    section: str
    signal: str
    claim: str
    paper_value: float | None
    unit: str
    rule: str
    verdict: str
    measured: float | None
    detail: str
    readings: tuple[ReadingResult, ...]
    measured_grid: float | None = None
    verdict_grid: str = ""
    verdict_tuned: str = ""

    @property
    def differs_on_grid(self) -> bool:
        """Whether any reading's verdict, or the overall one, differs on the sample grid."""
        return self.verdict_grid != self.verdict or any(r.differs_on_grid for r in self.readings)

    def to_json(self) -> dict:
        """Return a JSON-able dict."""
        return {
            "id": self.id,
            "section": self.section,
            "signal": self.signal,
            "claim": self.claim,
            "paper_value": self.paper_value,
            "unit": self.unit,
            "rule": self.rule,
            "verdict": self.verdict,
            "measured": self.measured,
            "detail": self.detail,
            "readings": [r.to_json() for r in self.readings],
            "measured_grid": self.measured_grid,
            "verdict_grid": self.verdict_grid,
            "verdict_differs_on_grid": self.differs_on_grid,
            "verdict_tuned": self.verdict_tuned,
        }


# ------------------------------------------------------------------ simulation cache
def _a_value(cfg: Config, which: str) -> float:
    if which == "f" and cfg.bandwidth_hz is not None:
        return float(cfg.bandwidth_hz)
    return cfg.plant.a


Outcome = tuple[float | None, dict, bool, str]


def numeric_verdict(measured: float, paper: float, floor: float) -> bool:
    """Return True when |measured - paper| <= max(20 % |paper|, floor)."""
    return math.isfinite(measured) and abs(measured - paper) <= max(REL_TOL * abs(paper), floor)


def _more_or_less(percent: float) -> str:
    """Say a signed percentage in words: '36.4 % less' or '0.2 % more' (never '-36.4 % more')."""
    if not math.isfinite(percent):
        return "an undefined amount of"
    return f"{abs(percent):.1f} % {'more' if percent >= 0 else 'less'} time"


#: A tie as :meth:`measure._Ctx.less` records it: ``<metric>_<law>_s = <metric>_<law>_s``.
_TIE = re.compile(r"^(\w+?)_(to|pd|pto)_s = (\w+?)_(to|pd|pto)_s\b")


def tie_words(tie: str) -> str:
    """Say a recorded tie in words: ``rise_time_pto_s = rise_time_pd_s`` -> ``rise time: PTO ties PD``.

    Parameters
    ----------
    tie : str
        One entry of a reading's ``ties``.

    Returns
    -------
    str

    Examples
    --------
    >>> tie_words("rise_time_pto_s = rise_time_pd_s (less than one sample apart)")
    'rise time: PTO ties PD'
    """
    m = _TIE.match(tie)
    if m is None:
        return tie
    return f"{m.group(1).replace('_', ' ')}: {m.group(2).upper()} ties {m.group(4).upper()}"
