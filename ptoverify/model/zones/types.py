"""The switching zone's result type and readings."""

from __future__ import annotations

from dataclasses import dataclass, field

READINGS = ("strict", "lenient")


_NAN = float("nan")


@dataclass(frozen=True, kw_only=True)
class PTOZone:
    """A switching zone S~_P / S~_N (boundary l1*, l2*, eqs. 13-14) and its verdict.

    Attributes
    ----------
    construction : str
        ``printed`` (eqs. 19-27 as printed) or ``corrected``.
    omega0 : float
        Level of l1*, l2* [mm/s]; NaN when none exists.
    x20_tilde : float
        Velocity where l1* meets x1 = d [mm/s] (eq. 23 for the printed form); NaN
        when l1* never reaches x1 = d inside the envelope.
    b0, y_star, k, z_star : float
        Intermediate numbers of eqs. (21)-(26) [-] (corrected: b0 = a d / omega0,
        y* = z* = -x20_tilde / omega0, k from eq. 25).
    valid : bool
        0 < omega0 < w_max, the zone acts outside the linear zone, and the
        principle (module docstring) holds for ``reading``.
    degenerate : bool
        The zone lies entirely inside the linear zone |x1| < d (never acts).
    reason : str
        Why the verdict, in words with the numbers.
    feasible_intervals : tuple of (float, float)
        Intervals of omega0 [mm/s] in (0, w_max] where the principle holds.
    reading : str
        ``strict`` or ``lenient`` (module docstring).
    margin : float
        Worst landing residual sigma(F) over the sources [mm/s] (>= 0 holds).
    grid_violations : int or None
        Violations found on the 2-D verification grid (None: not run).
    grid_points : int or None
        Number of source states the grid checked (None: not run).
    d_min : float
        Smallest d [mm] for which some omega0 > 0 satisfies the principle
        (an infimum, reached as omega0 -> 0+).
    details : dict
        Extra numbers (JSON-able).
    """

    construction: str
    omega0: float
    x20_tilde: float
    b0: float
    y_star: float
    k: float
    z_star: float
    valid: bool
    degenerate: bool
    reason: str
    feasible_intervals: tuple[tuple[float, float], ...] = ()
    reading: str = "strict"
    margin: float = _NAN
    grid_violations: int | None = None
    grid_points: int | None = None
    d_min: float = _NAN
    details: dict = field(default_factory=dict)

    @property
    def usable(self) -> bool:
        """True when omega0 defines a non-empty zone, 0 < omega0 < w_max."""
        return bool(self.details.get("usable", False))

    def to_json(self) -> dict:
        """Return the zone as a JSON-able dict (DESIGN keys first)."""
        return {
            "omega0": self.omega0,
            "x20_tilde": self.x20_tilde,
            "valid": self.valid,
            "reason": self.reason,
            "construction": self.construction,
            "degenerate": self.degenerate,
            "reading": self.reading,
            "b0": self.b0,
            "y_star": self.y_star,
            "k": self.k,
            "z_star": self.z_star,
            "margin_mm_s": self.margin,
            "feasible_intervals": [list(iv) for iv in self.feasible_intervals],
            "grid_violations": self.grid_violations,
            "grid_points": self.grid_points,
            "d_min": self.d_min,
            **self.details,
        }
