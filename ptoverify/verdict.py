"""One verdict vocabulary and one definition of each shared tolerance.

Every gate of ``ptoverify check`` and every property of ``ptoverify conform``
is a :class:`Verdict`: a name, a status (``pass``, ``fail``, ``unverified`` or
``not_run``), the measured figure, its limit, how the two must compare, the
unit of both, and a sentence saying why.  ``unverified`` and ``not_run`` fail
closed: only ``pass`` passes.

Tolerances used by more than one module live here, defined once.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

__all__ = [
    "PASS",
    "FAIL",
    "UNVERIFIED",
    "NOT_RUN",
    "STATUSES",
    "Verdict",
    "at_most",
    "tie_band",
    "TIE_BAND_REL",
    "TIME_TIE_SAMPLES",
    "TIME_TIE_RULE",
    "time_order",
]

PASS, FAIL, UNVERIFIED, NOT_RUN = "pass", "fail", "unverified", "not_run"
STATUSES = (PASS, FAIL, UNVERIFIED, NOT_RUN)

#: Relative width of the band around a switching curve inside which a law's
#: output is a tie (either side's input is right): 1e-9 of the largest
#: velocity-like scale of the configuration, ``w_max + a position_range``.
TIE_BAND_REL = 1e-9


def tie_band(w_max: float, a: float, position_range: float) -> float:
    """Return the curve tie band ``1e-9 (w_max + a position_range)``.

    Parameters
    ----------
    w_max : float
        Velocity saturation [mm/s].
    a : float
        Bandwidth of the velocity loop [rad/s].
    position_range : float
        Half-width of the position envelope [mm].

    Returns
    -------
    float
        Band [mm/s] in the switching function's units.

    Examples
    --------
    >>> tie_band(300.0, 100.0, 50.0)
    5.3e-06
    """
    return TIE_BAND_REL * (w_max + a * position_range)


#: Two laws' times (settling, rise) tie when they are less than this many sample
#: periods T apart: a sampled loop acts once per sample, so a smaller difference
#: is not one it can be said to win.  Every "faster", "quicker", "beats" and
#: "ties" of the claims, the verdict table and the headline is decided by
#: :func:`time_order` under this rule.
TIME_TIE_SAMPLES = 1.0

#: The tie rule in words, as the report states it.
TIME_TIE_RULE = "two times tie when they are less than one sample period T apart"


def time_order(t_a: float | None, t_b: float | None, sample_time: float) -> int | None:
    """Order two times of one metric under the tie rule: -1 (a first), 0 (tie), +1.

    Parameters
    ----------
    t_a, t_b : float or None
        The two times [s]; None or NaN when undefined (a law never settles).
    sample_time : float
        The sample period T [s].

    Returns
    -------
    int or None
        0 when ``|t_a - t_b| < TIME_TIE_SAMPLES * T`` (:data:`TIME_TIE_RULE`;
        times on the sample grid tie only when equal), else -1 or +1; None when
        either time is undefined.

    Examples
    --------
    >>> time_order(0.0220, 0.0223, 0.002), time_order(0.020, 0.024, 0.002)
    (0, -1)
    >>> time_order(0.026, 0.024, 0.002), time_order(None, 0.02, 0.002)
    (1, None)
    """
    if t_a is None or t_b is None or math.isnan(t_a) or math.isnan(t_b):
        return None
    if math.isinf(t_a) or math.isinf(t_b):
        return 0 if t_a == t_b else (-1 if t_a < t_b else 1)
    # a relative guard: grid times one sample apart differ by T up to round-off
    if abs(t_a - t_b) < TIME_TIE_SAMPLES * sample_time * (1.0 - 1e-9):
        return 0
    return -1 if t_a < t_b else 1


@dataclass(frozen=True)
class Verdict:
    """Outcome of one gate or conformance property.

    Attributes
    ----------
    name : str
        Stable name (CI logs and other tools key on it).
    status : str
        ``pass``, ``fail``, ``unverified`` or ``not_run``.
    measured : float or None
        The measured figure (None when it could not be computed).
    limit : float or None
        The limit it is compared with.
    detail : str
        What was measured, against what, and why the limit.
    comparison : str
        How ``measured`` must relate to ``limit`` to pass: ``<=``, ``>=`` or ``<``.
    unit : str
        Unit of ``measured`` and ``limit`` (``"1"`` when dimensionless, ``""`` unknown).
    description : str
        What the gate or property checks, in one sentence (``""`` when not given).
    """

    name: str
    status: str
    measured: float | None
    limit: float | None
    detail: str
    comparison: str = "<="
    unit: str = ""
    description: str = ""

    @property
    def passed(self) -> bool:
        """Whether the status is ``pass`` (everything else fails closed)."""
        return self.status == PASS

    def to_json(self) -> dict[str, Any]:
        """Return a JSON-able dict; non-finite numbers become None.

        ``measured_unbounded`` says whether a None ``measured`` stands for +inf (a
        trajectory that never settles, say) rather than a value not computed.
        """
        d = asdict(self)
        d["measured_unbounded"] = self.measured is not None and self.measured == math.inf
        for key in ("measured", "limit"):
            v = d[key]
            d[key] = None if v is None or not math.isfinite(v) else float(v)
        return d


def at_most(
    name: str, measured: float | None, limit: float, detail: str, unit: str = ""
) -> Verdict:
    """Return ``pass`` when ``measured <= limit``, ``unverified`` when not computable.

    Parameters
    ----------
    name : str
        Gate or property name.
    measured : float or None
        Measured figure, in ``unit``.
    limit : float
        Limit, in ``unit``.
    detail : str
        What was measured and why the limit.
    unit : str
        Unit of both figures.

    Returns
    -------
    Verdict
        The verdict; NaN, infinity or None are ``unverified``.

    Examples
    --------
    >>> at_most("x", 1.0, 2.0, "d").status
    'pass'
    >>> at_most("x", float("nan"), 2.0, "d").status
    'unverified'
    """
    if measured is None or not math.isfinite(measured):
        return Verdict(name, UNVERIFIED, None, limit, detail + " (not computable)", "<=", unit)
    status = PASS if measured <= limit else FAIL
    return Verdict(name, status, float(measured), limit, detail, "<=", unit)
