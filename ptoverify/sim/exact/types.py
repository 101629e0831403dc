"""The exact metrics' result types, keys and tolerances."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ptoverify.sim.flow import (
    Signal,
)
from ptoverify.sim.settling import (
    DEFINITIONS,
)

TIGHT_BAND = DEFINITIONS["0p01mm"].band_mm


"""Tight settling band [mm] (2 % of the paper's linear zone d = 0.5 mm)."""


STEP_FRACTION = DEFINITIONS["2pct"].band_fraction


"""Classical settling band as a fraction of the reference's size [-]."""


TIME_TOL_SAMPLES = 0.01


"""Time metrics differ when |exact - grid| > 0.01 T (T the median sample period)."""


POSITION_TOL = 1e-4


"""Overshoot differs when |exact - grid| > 1e-4 mm (1 % of the tight band)."""


PHASE_TOL_DEG = 0.01


"""Phase delay differs when |exact - grid| > 0.01 deg."""


METRIC_KEYS = (
    "overshoot_mm",
    "settling_2pct_s",
    "settling_0p01mm_s",
    "rise_time_s",
    "phase_delay_deg",
    "linear_zone_s",
)


"""Keys of :meth:`ExactMetrics.exact` (the first five are ``simulate --json`` ``metrics``)."""


@dataclass(frozen=True)
class Compared:
    """A metric on the exact trajectory and on the sample grid.

    Attributes
    ----------
    exact : float
        Between samples (the value to report) [unit of the metric].
    grid : float
        On the samples t_k only.
    tol : float
        Tolerance of :attr:`differs`, same unit.
    accuracy : float
        Bound on the error of :attr:`exact` from root finding and round-off,
        same unit (0 when the value is decided without a root, NaN when the
        metric is undefined); see :func:`metrics_from_arrays`.  Two exact values
        closer than the sum of their accuracies are a true tie
        (:meth:`compare`).
    """

    exact: float
    grid: float
    tol: float
    accuracy: float = 0.0

    @property
    def delta(self) -> float:
        """Return exact - grid (NaN when either is undefined)."""
        return self.exact - self.grid

    @property
    def differs(self) -> bool:
        """True when |exact - grid| > tol, or exactly one of them is NaN."""
        ne, ng = math.isnan(self.exact), math.isnan(self.grid)
        if ne or ng:
            return ne != ng
        return abs(self.exact - self.grid) > self.tol

    def compare(self, other: Compared, *, grid: bool = False) -> int | None:
        """Order two values of one metric: -1 (self smaller), 0 (true tie), +1.

        Exact values tie when |self - other| <= self.accuracy + other.accuracy
        (neither can be told from the other to the precision they are computed
        to); grid values tie only when equal (they are sample times).

        Parameters
        ----------
        other : Compared
            The other response's value of the same metric.
        grid : bool
            Compare the grid values instead of the exact ones.

        Returns
        -------
        int or None
            -1, 0 or +1; None when either value is NaN (undefined, never settled).

        Examples
        --------
        >>> Compared(0.1, 0.1, 0.0, 1e-12).compare(Compared(0.1 + 1e-13, 0.1, 0.0, 1e-12))
        0
        """
        x, y = (self.grid, other.grid) if grid else (self.exact, other.exact)
        if math.isnan(x) or math.isnan(y):
            return None
        tie = 0.0 if grid else self.accuracy + other.accuracy
        return 0 if abs(x - y) <= tie else (-1 if x < y else 1)


@dataclass(frozen=True)
class ResponseMetrics:
    """The ``simulate --json`` ``metrics`` of one response (DESIGN.md).

    Attributes
    ----------
    overshoot_mm : float
        Overshoot past the final value [mm] (NaN for a sine).
    settling_2pct_s : float
        Settling time under the ``2pct`` definition [s] (NaN: never settles).
    settling_0p01mm_s : float
        Settling time under the ``0p01mm`` definition [s] (NaN: never settles).
    rise_time_s : float
        10-90 % rise time [s] (NaN unless a step or ramp).
    phase_delay_deg : float or None
        Phase delay of x1 behind a sine [deg]; None unless the reference is a sine.
    """

    overshoot_mm: float
    settling_2pct_s: float
    settling_0p01mm_s: float
    rise_time_s: float
    phase_delay_deg: float | None = None

    def to_json(self) -> dict[str, float | None]:
        """Return the JSON object: one key per field (NaN as None; no phase unless a sine)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "phase_delay_deg" and v is None:
                continue
            out[f.name] = None if v is None or math.isnan(v) else float(v)
        return out


@dataclass(frozen=True)
class ExactMetrics:
    """Metrics of one response, exact and on the grid, by key (:data:`METRIC_KEYS`).

    Attributes
    ----------
    signal : Signal
        The reference the metrics were measured against.
    values : dict of str to Compared
        ``overshoot_mm``, ``settling_2pct_s``, ``settling_0p01mm_s``,
        ``rise_time_s``, ``phase_delay_deg``, ``linear_zone_s`` (NaN where
        undefined for the signal).
    details : dict of str to float
        ``t_peak_s`` (time of the overshoot), ``band_2pct_mm``,
        ``amplitude_ratio`` and ``fit_from_s`` / ``fit_to_s`` (sine window).
    """

    signal: Signal
    values: dict[str, Compared]
    details: dict[str, float]

    def exact(self) -> dict[str, float]:
        """Exact values by key (for ``simulate --json`` ``metrics``)."""
        return {k: v.exact for k, v in self.values.items()}

    def grid(self) -> dict[str, float]:
        """Sample-grid values by key."""
        return {k: v.grid for k, v in self.values.items()}

    def json_metrics(self, *, grid: bool = False) -> dict[str, float | None]:
        """Return ``simulate --json`` ``metrics`` (DESIGN.md): exact values, None if undefined.

        Keys ``overshoot_mm``, ``settling_2pct_s``, ``settling_0p01mm_s``,
        ``rise_time_s``, and ``phase_delay_deg`` for a sine only.  With
        ``grid=True`` the same keys hold the sample-grid values
        (``simulate --json`` ``metrics_grid``).
        """
        return self.response(grid=grid).to_json()

    def response(self, *, grid: bool = False) -> ResponseMetrics:
        """Return the ``simulate --json`` metrics as a :class:`ResponseMetrics`.

        Parameters
        ----------
        grid : bool
            The sample-grid values instead of the exact ones.

        Returns
        -------
        ResponseMetrics
            The five metrics (phase only for a sine).
        """
        pick = self.grid() if grid else self.exact()
        phase = pick["phase_delay_deg"] if self.signal.kind == "sine" else None
        return ResponseMetrics(
            pick["overshoot_mm"],
            pick["settling_2pct_s"],
            pick["settling_0p01mm_s"],
            pick["rise_time_s"],
            phase,
        )

    def differing(self) -> list[str]:
        """Keys whose exact and grid values differ beyond tolerance."""
        return [k for k, v in self.values.items() if v.differs]
