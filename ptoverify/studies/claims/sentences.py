"""What the claims judged at fair tuning say, in words."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from .types import _more_or_less

if TYPE_CHECKING:
    from .types import ClaimResult, ReadingResult


# ------------------------------------------------------------------ tuned sentences
def _us(x: float) -> str:
    """Milliseconds to the microsecond: tuned laws differ by tens of microseconds."""
    return "never" if not math.isfinite(x) else f"{1e3 * x:.3f} ms"


def _setting(r: ReadingResult) -> str:
    if r.reading.gains == "pd-retuned":
        return f"PD retuned to the PTO's overshoot ({r.reading.bound_mm:.3g} mm)"
    return f"both laws best-tuned under overshoot <= {r.reading.bound_mm:.3g} mm"


def _say_31(c: ClaimResult, rs: list[ReadingResult]) -> str:
    parts = [
        f"{_setting(r)}: PD {_us(r.values['settling_pd_s'])} vs PTO "
        f"{_us(r.values['settling_pto_s'])}, so PD needs {_more_or_less(r.values['pd_more_percent'])} "
        f"({r.verdict})"
        for r in rs
    ]
    return (
        f"The paper says PD needs {c.paper_value:g} % more settling time than the PTO; measured: "
        + "; ".join(parts)
        + "."
    )


def _say_settling(what: str) -> Callable[[ClaimResult, list[ReadingResult]], str]:
    def say(c: ClaimResult, rs: list[ReadingResult]) -> str:
        parts = []
        for r in rs:
            a, b = r.values["settling_pto_s"], r.values["settling_pd_s"]
            holds = "holds" if a < b and "settling" not in " ".join(r.ties) else "does not hold"
            parts.append(f"{_setting(r)}: PTO {_us(a)} vs PD {_us(b)} (2 % settling), {holds}")
        return f"{what}: " + "; ".join(parts) + f"; claim verdict {c.verdict_tuned}."

    return say


def _say_rise(c: ClaimResult, rs: list[ReadingResult]) -> str:
    parts = [
        f"{_setting(r)}: 10-90 % rise PTO {_us(r.values['rise_time_pto_s'])} vs PD "
        f"{_us(r.values['rise_time_pd_s'])} ({r.verdict})"
        for r in rs
    ]
    return "Quicker dynamic response: " + "; ".join(parts) + "."


#: Claims also judged at the best tuning of both laws (``evaluate_claims(tuned=True)``),
#: with the sentence that states the result with its numbers.  ``ptoverify check``
#: does not compute them: its claims-computed gate checks that every claim is
#: measurable, which the paper-gain readings already show in seconds, while the
#: tunings take minutes (the report computes them once, memoized).
TUNED_CLAIMS: dict[str, Callable[[ClaimResult, list[ReadingResult]], str]] = {
    "step-pd-31-percent": _say_31,
    "step-pto-steadier-quicker": _say_settling("Quicker dynamic process (Sec. 6.1)"),
    "conclusion-vs-to-and-pd": _say_settling("Shorter adjustment time"),
    "conclusion-quicker-response": _say_rise,
}
