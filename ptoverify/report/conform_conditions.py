"""The conformance report's formatting and its conditions: precision, perturbation, limits.

Part of ``conform --report`` (:mod:`ptoverify.report.conform_report` writes the
folder): how numbers and states are printed, the title block's precision and
perturbation, the pass limits with their reasons (``[conform]`` in the
configuration), and the closed loops under perturbation next to the reference's.
"""

from __future__ import annotations

import math
from typing import Any

from ptoverify.config import Config
from ptoverify.conform.result import ConformResult
from ptoverify.report.render import Block

__all__ = ["quantity", "state", "precision_text", "perturbation_text", "limits", "perturbed"]


def _table(headers: list[str], rows: list[list[str]]) -> Block:
    return Block("table", headers=tuple(headers), rows=tuple(tuple(r) for r in rows))


def _p(text: str) -> Block:
    return Block("p", text=text)


def quantity(v: Any, unit: str = "", digits: int = 4) -> str:
    """Format a number with its unit at readable precision; ``n/a`` when undefined.

    Parameters
    ----------
    v : float, int or None
        The value.
    unit : str
        Its unit (empty: dimensionless, printed bare).
    digits : int
        Significant digits.

    Returns
    -------
    str

    Examples
    --------
    >>> quantity(0.000123456, "mm/s"), quantity(None, "s"), quantity(12, "samples")
    ('0.0001235 mm/s', 'n/a', '12 samples')
    """
    if v is None or isinstance(v, bool):
        return "n/a"
    v = float(v)
    if not math.isfinite(v):
        return "never" if v == math.inf and unit in ("samples", "s") else "n/a"
    text = f"{v:.{digits}g}"
    return f"{text} {unit}" if unit else text


def state(s: Any) -> str:
    """Format a state [mm, mm/s] with 10 significant digits (enough to reproduce it).

    Parameters
    ----------
    s : sequence of 2 floats or None
        The state x1 [mm], x2 [mm/s].

    Returns
    -------
    str

    Examples
    --------
    >>> state([0.50000005, -115.0]), state(None)
    ('x1 = 0.50000005 mm, x2 = -115 mm/s', 'n/a')
    """
    if s is None:
        return "n/a"
    return f"x1 = {float(s[0]):.10g} mm, x2 = {float(s[1]):.10g} mm/s"


def precision_text(precision: str) -> str:
    """Return the precision mode in words (the title block's row).

    Parameters
    ----------
    precision : str
        ``float64`` or ``float32``.

    Returns
    -------
    str
    """
    if precision == "float32":
        return (
            "float32: the reference is evaluated at the state rounded to float32; states within "
            "float32 resolution of a region boundary are ties (either side accepted)"
        )
    return "float64 (the law judged as a double-precision function of the state)"


def perturbation_text(result: ConformResult) -> str:
    """Return the perturbations judged in words (the title block's row).

    Parameters
    ----------
    result : ConformResult
        The verdict.

    Returns
    -------
    str
    """
    r = result
    if not r.perturbations:
        return "none: nominal loop only (conform --delay/--quantum/--velocity-noise/--a-ratio/--robust)"
    return "; ".join(p.text() for p in r.perturbations)


def limits(result: ConformResult, cfg: Config) -> list[Block]:
    """Return the section "Pass limits and why" (values from ``cfg.conform``).

    Parameters
    ----------
    result : ConformResult
        The verdict (its agreement tolerance).
    cfg : Config
        Configuration (``[conform]``).

    Returns
    -------
    list of Block
    """
    r = result
    lim = cfg.conform
    a = r.agreement
    tol = (
        f"{quantity(a['tolerance_mm_s'], 'mm/s')} ({quantity(a['rtol'])} x w_max)"
        if "tolerance_mm_s" in a
        else "rtol x w_max"
    )
    rows = [
        [
            "agreement",
            f"|u - u_ref| <= {tol} (conform --tolerance)",
            "far above double round-off of u (1e-16 w_max) and far below anything a drive "
            "can resolve, so any real difference in the law shows; curve ties excluded",
        ],
        [
            "settling-vs-discrete-limit",
            f"worst excess over N* <= E_ref + max({lim.settling_min_samples}, "
            f"ceil({quantity(lim.settling_margin)} x E_ref)) samples",
            "E_ref is what the verified reference itself needs beyond the discrete-time "
            "limit; a law that agrees within the tolerance can still switch a sample "
            "later near a curve and pay a few samples, but a systematically slower law "
            "fails",
        ],
        [
            "closed-loop counts",
            "0 count of stride-overs, limit cycles and samples with |u| > w_max",
            "the reference has none on the nominal loop, so any is a defect of the law",
        ],
        [
            "under perturbation",
            f"counts <= reference + ceil({quantity(lim.count_margin)} x states); "
            "|u| > w_max samples <= reference; settling as above against the reference's "
            "worst under the same perturbation",
            "relative: the reference itself may fail there (a one-sample delay), so the "
            "law is judged against it, with room for marginal states to flip",
        ],
    ]
    return [
        _p(
            "Every limit and why. The settling and perturbation margins are configurable in "
            "the configuration's [conform] table (settling_margin, settling_min_samples, "
            "count_margin); the values used are shown."
        ),
        _table(["property", "limit", "why"], rows),
    ]


def perturbed(result: ConformResult) -> list[Block]:
    """Return the section "Closed loop under perturbation".

    Parameters
    ----------
    result : ConformResult
        The verdict (its perturbed runs).

    Returns
    -------
    list of Block
    """
    r = result
    if not r.perturbed:
        if r.perturbations:
            return [_p("The closed loops under perturbation were not run (see the properties).")]
        return [
            _p(
                "No perturbation was judged (nominal loop only). conform --delay N, --quantum MM, "
                "--velocity-noise MM_S --seed S, --a-ratio R or --robust compare your law's "
                "closed loop with the reference's under the same perturbation."
            )
        ]
    rows = []
    for run in r.perturbed:
        for c in run.comparisons:
            rows.append(
                [
                    run.perturbation.text(),
                    c.name,
                    "pass" if c.passed else "fail",
                    quantity(c.user, c.unit),
                    quantity(c.reference, c.unit),
                    quantity(c.limit, c.unit),
                    "yes" if c.reference_fails else "no",
                    state(c.state) if c.state is not None else "none",
                ]
            )
    return [
        _p(
            f"Both laws from the same {r.perturbed[0].states} initial states, "
            f"{r.perturbed[0].steps} samples, under the same perturbation and the same noise "
            "sequence. Counts are initial states (samples for input-bound); settling is in "
            "samples under definition 0p001mm."
        ),
        _table(
            [
                "perturbation",
                "property",
                "status",
                "your law",
                "reference",
                "limit",
                "reference fails",
                "first state where yours is worse",
            ],
            rows,
        ),
    ]
