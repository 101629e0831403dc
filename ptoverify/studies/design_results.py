"""Results of ``ptoverify design``: each law at a design point, the points, the chart.

Part of :mod:`ptoverify.studies.design` (which re-exports every name here):
the frozen dataclasses the design study returns, with their JSON.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

__all__ = ["LawAtPoint", "DesignPoint", "DesignChart"]


@dataclass(frozen=True)
class LawAtPoint:
    """One law at one design point.

    Attributes
    ----------
    law, note : str
        Law name and its one-line description at this point.
    k_x1, k_x2 : float
        Linear-loop gains [1/s], [-] (NaN: no linear loop, TO).
    median_ratio_nt, worst_ratio_nt : float
        Median and worst settling / N*T over the grid's states [-] (inf: some
        state never settles; NaN: no state settles for the median).
    fraction_settled : float
        Share of the grid's states that settle [-].
    margin_lo, margin_hi : float
        Stable interval of a_true / a_design of the linear loop [-] (0 / inf:
        stable past the searched range [0.1, 10]; NaN: unstable at 1 or none).
    margin_delay_lo, margin_delay_hi : float
        The same with a one-sample delay [-].
    radius_delay1 : float
        Spectral radius of the delayed linear loop at a_true = a_design [-].
    gains_from : str
        ``configured``, ``tuned`` (the step's 2 % settling minimized under the
        chart's overshoot bound, :func:`tuned_law_config`) or ``tuning infeasible``
        (no gains met the constraints: the configured ones are measured).
    """

    law: str
    note: str
    k_x1: float
    k_x2: float
    median_ratio_nt: float
    worst_ratio_nt: float
    fraction_settled: float
    margin_lo: float
    margin_hi: float
    margin_delay_lo: float
    margin_delay_hi: float
    radius_delay1: float
    gains_from: str = "configured"


@dataclass(frozen=True)
class DesignPoint:
    """Every law at one (T, bandwidth).

    Attributes
    ----------
    sample_time : float
        T [s].
    bandwidth_hz : float
        Bandwidth as given [Hz].
    a : float
        Bandwidth under the reading [rad/s].
    laws : tuple of LawAtPoint
        One per law asked, in order.
    pto_zone_usable, pto_zone_degenerate : bool
        The corrected PTO zone exists (0 < omega0 < w_max) / lies inside the linear zone.
    pto_zone_reason : str
        Why, in words.
    fastest : str
        Law with the least median settling / N*T ("" if none settles).
    fastest_by : float
        Runner-up's median ratio over the fastest's [-] (>= 1; inf: no runner-up settles).
    pto_beats, pto_loses_to : tuple of str
        Laws whose median settling / N*T is above / below the PTO's (a law that
        never settles from some state is beaten by a PTO that always does, and
        beats one that does not); empty without ``pto``.
    seconds : float
        Wall time of the point [s] (not compared between runs).
    """

    sample_time: float
    bandwidth_hz: float
    a: float
    laws: tuple[LawAtPoint, ...]
    pto_zone_usable: bool
    pto_zone_degenerate: bool
    pto_zone_reason: str
    fastest: str
    fastest_by: float
    pto_beats: tuple[str, ...]
    pto_loses_to: tuple[str, ...]
    seconds: float

    def law(self, name: str) -> LawAtPoint:
        """Return the :class:`LawAtPoint` of ``name``."""
        for r in self.laws:
            if r.law == name:
                return r
        raise KeyError(name)


@dataclass(frozen=True)
class DesignChart:
    """A design chart: points over sample_times x bandwidths (row-major: T outer).

    Attributes
    ----------
    config_name : str
        The base configuration.
    reading : str
        ``2pi`` or ``hz``.
    sample_times : tuple of float
        T [s].
    bandwidths_hz : tuple of float
        Bandwidths [Hz].
    laws : tuple of str
        Laws.
    grid : int
        Envelope grid per axis.
    tuned_overshoot : float or None
        Overshoot bound [mm] of the per-point tunings; None: configured gains.
    points : tuple of DesignPoint
        len(sample_times) x len(bandwidths_hz) points.
    backend : str
        ``in-process`` or the dask address.
    seconds : float
        Wall time [s].
    """

    config_name: str
    reading: str
    sample_times: tuple[float, ...]
    bandwidths_hz: tuple[float, ...]
    laws: tuple[str, ...]
    grid: int
    tuned_overshoot: float | None
    points: tuple[DesignPoint, ...]
    backend: str
    seconds: float

    def to_json(self, *, timings: bool = True) -> dict[str, Any]:
        """Return a JSON-able dict (inf and NaN as strings; ``timings`` False drops wall times)."""

        def clean(v):
            if isinstance(v, float) and not math.isfinite(v):
                return str(v)
            if isinstance(v, dict):
                return {k: clean(x) for k, x in v.items() if timings or k != "seconds"}
            if isinstance(v, (list, tuple)):
                return [clean(x) for x in v]
            return v

        out = {
            "config": self.config_name,
            "reading": self.reading,
            "sample_times_s": list(self.sample_times),
            "bandwidths_hz": list(self.bandwidths_hz),
            "laws": list(self.laws),
            "grid": self.grid,
            "tuned_overshoot_mm": self.tuned_overshoot,
            "points": [clean(asdict(p)) for p in self.points],
            "backend": self.backend,
        }
        if timings:
            out["seconds"] = self.seconds
        return out

    def to_csv(self) -> str:
        """Return one CSV row per (point, law)."""
        cols = [f for f in LawAtPoint.__dataclass_fields__ if f != "note"]
        lines = [",".join(["sample_time_s", "bandwidth_hz", "a", "pto_zone_usable", *cols])]
        for p in self.points:
            for r in p.laws:
                row = [p.sample_time, p.bandwidth_hz, p.a, p.pto_zone_usable]
                row += [getattr(r, c) for c in cols]
                lines.append(",".join(str(v) for v in row))
        return "\n".join(lines) + "\n"
