"""Evaluate every claim at every reading of the paper and at fair tuning."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from typing import TYPE_CHECKING

from ptoverify.config import Config
from ptoverify.model.memo import memo
from ptoverify.sim import metrics as mt
from ptoverify.studies.tune import (
    FairTunings,
    TuneBudget,
    fair_tunings,
)

from .catalogue import CLAIMS
from .measure import _Ctx
from .sentences import TUNED_CLAIMS
from .types import ClaimResult, Reading, ReadingResult, tie_words

if TYPE_CHECKING:
    from .measure import _Claim


def _readings(cfg: Config, dims: tuple[str, ...]) -> list[Reading]:
    a_opts = ["2pi*f", "f"] if cfg.bandwidth_hz is not None else ["given"]
    opts = {
        "a": a_opts,
        "ff": ["feed-forward", "none", "error"],
        "pto": ["corrected", "printed"],
        "band": [mt.STEP_FRACTION, 0.05],
    }
    axes = [opts[d] if d in dims else [None] for d in ("a", "ff", "pto", "band")]
    return [Reading(a, ff, pto, band) for a, ff, pto, band in itertools.product(*axes)]


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _overall(verdicts: set[str]) -> str:
    return verdicts.pop() if len(verdicts) == 1 else "ambiguous"


def _tuned_readings(cfg: Config, cl: _Claim, ft: FairTunings) -> list[tuple[Reading, dict]]:
    """Return the tuned readings of a claim, each with its laws' configurations."""
    base = _readings(cfg, cl.dims)[0]
    pto_bound = ft.bounds["pto-paper"]
    out = [
        (
            replace(base, gains="pd-retuned", bound_mm=pto_bound),
            {"pd": ft.config("pd", "pto-paper")},
        )
    ]
    for name, bound in ft.bounds.items():
        out.append(
            (
                replace(base, gains=f"best@{name}", bound_mm=bound),
                {"pd": ft.config("pd", name), "pto": ft.config("pto", name)},
            )
        )
    return out


def _evaluate(
    cfg: Config, cl: _Claim, paper: dict[str, float | None], ft: FairTunings | None = None
) -> ClaimResult:
    todo = [(rd, None) for rd in _readings(cfg, cl.dims)]
    if ft is not None and cl.id in TUNED_CLAIMS:
        todo += _tuned_readings(cfg, cl, ft)
    results = []
    for rd, law_cfg in todo:
        exact = _Ctx(cfg, rd, paper, law_cfg=law_cfg)
        measured, values, ok, detail = cl.measure(exact, cl)
        grid = _Ctx(cfg, rd, paper, grid=True, law_cfg=law_cfg)
        measured_g, values_g, ok_g, _ = cl.measure(grid, cl)
        if exact.ties:
            detail += "; less than one sample apart, a tie: " + ", ".join(
                tie_words(t) for t in exact.ties
            )
        results.append(
            ReadingResult(
                rd,
                rd.label(cfg),
                _finite(measured),
                values,
                "reproduced" if ok else "not reproduced",
                detail,
                _finite(measured_g),
                values_g,
                "reproduced" if ok_g else "not reproduced",
                tuple(exact.ties),
            )
        )
    p = results[0]
    plain = [r for r in results if r.reading.gains is None]
    tuned = [r for r in results if r.reading.gains is not None]
    return ClaimResult(
        cl.id,
        cl.section,
        cl.signal,
        cl.claim,
        cl.paper_value,
        cl.unit,
        cl.rule,
        _overall({r.verdict for r in plain}),
        p.measured,
        p.detail,
        tuple(results),
        p.measured_grid,
        _overall({r.verdict_grid for r in plain}),
        _overall({r.verdict for r in tuned}) if tuned else "",
    )


@memo(maxsize=8)
def _evaluate_all(
    cfg: Config, claims: tuple[_Claim, ...], tuned: bool = False, budget: TuneBudget | None = None
) -> tuple[ClaimResult, ...]:
    # paper values by id: the claims evaluated, over the registry's (a claim may quote another's)
    paper = {c.id: c.paper_value for c in CLAIMS} | {c.id: c.paper_value for c in claims}
    ft = fair_tunings(cfg, budget) if tuned else None
    return tuple(_evaluate(cfg, cl, paper, ft) for cl in claims)


def evaluate_claims(
    cfg: Config,
    claims: tuple[_Claim, ...] | None = None,
    *,
    tuned: bool = False,
    budget: TuneBudget | None = None,
) -> list[ClaimResult]:
    """Evaluate every claim under every reading (cached per configuration).

    Parameters
    ----------
    cfg : Config
        Configuration; its bandwidth, when given in Hz, opens the a-reading.
    claims : tuple of registry entries, optional
        The entries to evaluate; default :data:`CLAIMS`.  An entry with another
        ``paper_value`` (``dataclasses.replace``) is judged against that value.
    tuned : bool
        Also judge the claims of :data:`TUNED_CLAIMS` at the best tuning of
        both laws (:func:`ptoverify.studies.tune.fair_tunings`: minutes, memoized):
        readings with ``gains`` set, summarized in ``verdict_tuned``.
        ``ptoverify check`` leaves this off (see :data:`TUNED_CLAIMS`).
    budget : TuneBudget, optional
        Search effort of the tunings (default :class:`~ptoverify.studies.tune.TuneBudget`).

    Returns
    -------
    list of ClaimResult
        One per claim, in order (a new list over cached, frozen results).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.studies.claims import VERDICTS
    >>> res = evaluate_claims(paper_config())
    >>> all(r.verdict in VERDICTS for r in res)
    True
    """
    cl = CLAIMS if claims is None else tuple(claims)
    return list(_evaluate_all(cfg, cl, tuned, budget))
