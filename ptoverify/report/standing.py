"""The paper's standing in one screen: a verdict for the reviewer and one for the drive engineer.

Both tables are read off the results (:class:`ptoverify.report.results.Results`),
never typed in: every number they show is a field of ``results.json``.

- :func:`reviewer_rows`: every Section 6 claim as *holds*, *fails* or *depends*; a
  claim that depends names the reading it depends on (the bandwidth reading of a,
  the band, the PTO variant, the tracking, the tuning) when one of them decides it.
- :func:`engineer_rows`: adopt or not, and under which conditions: which zone, the
  settling time against PD at the paper's gains under both readings of a and at the
  best tuning, delay and bandwidth tolerance, the closed-loop properties, and the
  corrected PTO against fair-tuned PD, PTOS and the cascade P loop under both
  readings of a (:func:`versus_row`).

Catalogue
---------
claim_standing  holds / fails / depends, with what it depends on
reviewer_rows   the reviewer's table rows
engineer_rows   the drive engineer's table rows (question, answer, evidence)
versus_row      the PTO against fair-tuned PD, PTOS and cascade P (standing_versus)
versus_bound    the baselines' shared overshoot bound, and why it differs with a
versus_note     the baselines' row in full, for the note under the verdict table
adoption        the one-sentence recommendation
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ptoverify.report.render import fmt, qty
from ptoverify.report.standing_claims import (
    READING_WORDS,
    bandwidth_hz,
    claim_standing,
    reading_words,
)
from ptoverify.report.standing_versus import (
    VERSUS_QUESTION,
    bound_words,
    versus_bound,
    versus_note,
    versus_row,
    versus_verdict,
)
from ptoverify.report.words import (
    LAW_WORDS,
    claim_measured_words,
    claim_quantity,
    claim_title,
    law_name,
    plural,
)
from ptoverify.verdict import TIME_TIE_RULE, time_order

__all__ = [
    "claim_standing",
    "reviewer_rows",
    "engineer_rows",
    "adoption",
    "versus_row",
    "versus_bound",
    "versus_note",
    "versus_verdict",
    "tuned_delay_row",
    "READING_WORDS",
    "LAW_WORDS",
    "VERSUS_QUESTION",
    "TIE_NOTE",
    "time_verdict",
    "claim_quantity",
    "ratio_phrase",
]


def reviewer_rows(res: Mapping, short: bool = False) -> list[list[str]]:
    """Rows ``[claim, standing, condition, paper, measured]`` for every claim.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).
    short : bool
        Name the readings in the verdict table's short words
        (:func:`ptoverify.report.standing_claims.short_legend`).

    Returns
    -------
    list of list of str
        One row per claim; ``measured`` is the primary reading's value with its unit
        and what it is (:func:`ptoverify.report.words.claim_measured_words`).
    """
    rows = []
    hz = bandwidth_hz(res)
    for c in res["claims"]:
        standing, cond = claim_standing(c, hz, short)
        unit = c["unit"]
        rows.append(
            [
                claim_title(c),
                standing,
                cond,
                claim_quantity(c["paper_value"], unit)
                if c["paper_value"] is not None
                else "qualitative",
                claim_measured_words(c) if c["measured"] is not None else "see the claims table",
            ]
        )
    return rows


def step_readings(res: Mapping) -> dict[str, Mapping]:
    """Return the 31 % claim's readings at the paper's gains, 2 % band, corrected PTO, by a.

    Parameters
    ----------
    res : Mapping
        The results.

    Returns
    -------
    dict
        Reading of a (``2pi*f``, ``f``) -> that reading's record.
    """
    out: dict[str, Mapping] = {}
    for c in res["claims"]:
        if c["id"] != "step-pd-31-percent":
            continue
        for r in c["readings"]:
            rd = r["reading"]
            if rd["band"] == 0.02 and rd["pto"] == "corrected" and rd["gains"] is None:
                out.setdefault(rd["a"], r)
    return out


def _ms(seconds: float | None) -> str:
    return "never" if seconds is None else qty(1e3 * seconds, "ms")


#: The tie rule as the verdict table states it (the one rule of
#: :func:`ptoverify.verdict.time_order`, which the claims' verdicts use too).
TIE_NOTE = (
    f"Ties: {TIME_TIE_RULE}; every 'beats', 'ties', 'loses', 'settles first' and every "
    "claim of a quicker or shorter time in this report is decided by that one rule."
)


def time_verdict(pto: float | None, other: float | None, sample: float, name: str = "PD") -> str:
    """Return the PTO's time against another law's under the tie rule: beats, ties or loses.

    Parameters
    ----------
    pto, other : float or None
        The two times [s] (None: that law never settles).
    sample : float
        T [s].
    name : str
        The other law's display name.

    Returns
    -------
    str
        ``beats PD``, ``ties PD (less than one sample apart)``, ``loses to PD``, or
        no verdict; decided by :func:`ptoverify.verdict.time_order`.

    Examples
    --------
    >>> time_verdict(0.02225, 0.02231, 0.002), time_verdict(0.020, 0.030, 0.002)
    ('ties PD (less than one sample apart)', 'beats PD')
    """
    order = time_order(pto, other, sample)
    if order is None:
        return "no verdict (a law never settles)"
    if order == 0:
        return f"ties {name} (less than one sample apart)"
    return f"beats {name}" if order < 0 else f"loses to {name}"


def _faster(pto: float | None, pd: float | None, sample: float) -> str:
    return time_verdict(pto, pd, sample)


def engineer_rows(res: Mapping, short: bool = False) -> list[list[str]]:
    """Rows ``[question, answer, evidence]`` a drive engineer acts on.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).
    short : bool
        The verdict table's short cells: readings in short words
        (:func:`ptoverify.report.standing_claims.short_legend`), the evidence
        without what the answer already says; :func:`versus_note` holds the rest.

    Returns
    -------
    list of list of str
    """
    cfg = res["environment"]["config"]
    T = cfg["plant"]["sample_time"]  # noqa: N806 - the paper's symbol
    z = res["zone"]
    pr, co = z["printed"], z["corrected"]
    rows = [
        [
            "Which switching zone?",
            "the corrected one" if co["valid"] else "neither is valid",
            f"printed omega0 = {qty(pr['omega0'], 'mm/s')} "
            f"({'valid' if pr['valid'] else 'invalid'}); corrected omega0 = "
            f"{qty(co['omega0'], 'mm/s')} ({'valid' if co['valid'] else 'invalid'})",
        ]
    ]
    hz = bandwidth_hz(res)
    step = step_readings(res)
    if step:
        parts, verdicts = [], []
        for a, r in step.items():
            v = r["values"]
            verdicts.append(_faster(v["settling_pto_s"], v["settling_pd_s"], T))
            parts.append(
                f"{reading_words('a', a, hz, short)}: PTO {_ms(v['settling_pto_s'])}, "
                f"PD {_ms(v['settling_pd_s'])}"
            )
        answer = (
            verdicts[0]
            if len(set(verdicts)) == 1
            else "depends on the reading of a: "
            + "; ".join(
                f"{reading_words('a', a, hz, short)}: {w}"
                for a, w in zip(step, verdicts, strict=True)
            )
        )
        rows.append(
            ["Faster than PD at the paper's gains (step, 2 % band)?", answer, "; ".join(parts)]
        )
    t = res["tuning"]
    if t is not None:
        parts, verdicts = [], []
        for name, by in t["best"].items():
            if "pd" in by and "pto" in by:
                pd, pto = by["pd"]["settling_2pct_s"], by["pto"]["settling_2pct_s"]
                verdicts.append(_faster(pto, pd, T))
                parts.append(f"overshoot <= {bound_words(t, name)}: PTO {_ms(pto)}, PD {_ms(pd)}")
        if parts:
            answer = verdicts[0] if len(set(verdicts)) == 1 else "; ".join(verdicts)
            rows.append(
                ["At each law's best tuning (same overshoot bound)?", answer, "; ".join(parts)]
            )
    rob = res["robust"]
    if rob is not None and "pto" in rob["margins"]:
        m = rob["margins"]["pto"]
        d1 = m["linear_loop_a_ratio_stable_delay1"]
        rows.append(
            [
                "Tolerates a one-sample computation delay (paper's gains)?",
                "yes" if d1 is not None else "no: needs delay compensation or lower gains",
                "PTO linear zone with one sample of delay: "
                + (
                    f"stable for a_true / a_design {ratio_phrase(d1)}"
                    if d1
                    else m["linear_loop_note_delay1"]
                ),
            ]
        )
        nd = m["linear_loop_a_ratio_stable"]
        pd_nd = (
            rob["margins"]["pd"]["linear_loop_a_ratio_stable"] if "pd" in rob["margins"] else None
        )
        pto_words = (
            "" if short else f"PTO linear loop stable for a_true / a_design {ratio_phrase(nd)}; "
        )
        rows.append(
            [
                "Tolerates a bandwidth other than the design value?",
                f"a_true / a_design {ratio_phrase(nd)}" if nd else m["linear_loop_note"],
                f"{pto_words}PD{': a_true / a_design ' if short else ' '}{ratio_phrase(pd_nd)}",
            ]
        )
    loops = res["poles"]["loops"]
    if "linear" in loops and "pd" in loops:
        lin, pd = loops["linear"], loops["pd"]
        rows.append(
            [
                "Stability margins of the linear loops (sampled, nominal plant)?",
                _thinner(lin, pd),
                f"PTO linear zone: {_margins(lin, short)}; PD: {_margins(pd, short)}",
            ]
        )
    p = res["properties"]["pto"] if "pto" in res["properties"] else None
    if p is not None:
        clean = p["stride_overs"] == 0 and p["limit_cycles"] == 0 and p["chattering"] == 0
        rows.append(
            [
                "Stride-overs, limit cycles, chattering (sampled grid)?",
                ("none found" if clean else "found") + _proved_stride(res),
                f"{p['states']} grid states: {p['stride_overs']} stride-overs, "
                f"{p['limit_cycles']} limit cycles, {p['chattering']} chattering"
                + ("" if short else " (sampled: see the proofs for the continuum where they ran)"),
            ]
        )
    rows.append(versus_row(res, short))
    delay = tuned_delay_row(res, short)
    if delay:
        rows.append(delay)
    return rows


def tuned_delay_row(res: Mapping, short: bool = False) -> list[str] | None:
    """Return the row on the tuned gains under computation delay (None: tuning skipped).

    Each law's linear loop at its fair tuning (``tuning.versus``, first reading of a),
    with the whole samples of computation delay it tolerates
    (:func:`ptoverify.model.poles.delay_margin_samples`).

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).
    short : bool
        The verdict table's short cells (the advice and the per-law words left out).

    Returns
    -------
    list of str or None
        ``[question, answer, evidence]``.
    """
    t = res["tuning"]
    if t is None or "versus" not in t:
        return None
    r = t["versus"]["readings"][0]
    tuned = [x for x in r["laws"] if not x["infeasible"]]
    if not tuned:
        return None

    def words(n: int) -> str:
        return "unstable even without delay" if n < 0 else plural(n, "sample")

    unstable = [x for x in tuned if x["delay_margin_samples"] < 1]
    answer = (
        "yes: every tuned loop tolerates at least one sample"
        if not unstable
        else "no: "
        + ", ".join(law_name(x["law"]) for x in unstable)
        + (" is" if len(unstable) == 1 else " are each")
        + " unstable at the best tuning with one sample of delay"
        + ("" if short else " (tune with the delay in the loop, or compensate it)")
    )
    evidence = "; ".join(
        f"{law_name(x['law'])}: {'' if short else 'tolerates '}{words(x['delay_margin_samples'])}"
        for x in tuned
    )
    return ["Do the tuned gains tolerate a one-sample computation delay?", answer, evidence]


def _proved_stride(res: Mapping) -> str:
    """Return what the proofs add about stride-overs of the corrected PTO ("" if none ran)."""
    pr = res["proofs"] if "proofs" in res else None
    if not pr or "pto" not in pr:
        return ""
    prop = pr["pto"]["properties"]["no-stride-over-strict"]
    if prop["status"] == "proved":
        return "; no stride-over is proved for every state of the envelope"
    return f"; no stride-over is {prop['status']} over the continuum (see the proofs)"


def _thinner(lin: Mapping, pd: Mapping) -> str:
    """Say which linear loop has the thinner margins (gain, phase, delay), or that it is mixed."""
    keys = ("gain_margin_db", "phase_margin_deg", "delay_margin_samples")
    if all(lin[k] < pd[k] for k in keys):
        return "thinner in the PTO's linear zone than in PD on gain, phase and delay"
    if all(lin[k] > pd[k] for k in keys):
        return "thicker in the PTO's linear zone than in PD on gain, phase and delay"
    return "mixed: see the margins of each loop"


def _margins(loop: Mapping, short: bool = False) -> str:
    """Gain margin [dB], phase margin [deg] and delay margin [samples] of one loop."""
    n = loop["delay_margin_samples"]
    delay = (
        "unstable without delay"
        if n < 0
        else f"tolerates {plural(n, 'sample')} of computation delay"
    )
    if short:
        return f"{qty(loop['gain_margin_db'], 'dB')}, {qty(loop['phase_margin_deg'], 'deg')}, " + (
            "unstable without delay" if n < 0 else f"{plural(n, 'sample')} of delay"
        )
    return (
        f"gain margin {qty(loop['gain_margin_db'], 'dB')}, phase margin "
        f"{qty(loop['phase_margin_deg'], 'deg')}, {delay}"
    )


def ratio_interval(iv: Any) -> str:
    """Return an a_true / a_design interval in words (an open end: no limit found).

    Parameters
    ----------
    iv : sequence or None
        ``[lo, hi]`` of a_true / a_design [-], an end None where the search found no limit.

    Returns
    -------
    str
    """
    if not iv:
        return "no interval (unstable at the design point)"
    lo, hi = iv
    if lo is None and hi is None:
        return "anywhere in the searched [0.1, 10]"
    if lo is None:
        return f"up to {fmt(hi)}, with no lower limit down to the searched 0.1"
    if hi is None:
        return f"from {fmt(lo)}, with no upper limit up to the searched 10"
    return f"[{fmt(lo)}, {fmt(hi)}]"


def ratio_phrase(iv: Any) -> str:
    """Return what follows "a_true / a_design" in a sentence: ``in [lo, hi]``, ``up to hi (...)``.

    Parameters
    ----------
    iv : sequence or None
        As :func:`ratio_interval`.

    Returns
    -------
    str

    Examples
    --------
    >>> ratio_phrase([0.5, 1.2]), ratio_phrase([None, 1.5])
    ('in [0.5, 1.2]', 'up to 1.5, with no lower limit down to the searched 0.1')
    """
    text = ratio_interval(iv)
    return f"in {text}" if text.startswith("[") else text


def adoption(res: Mapping) -> str:
    """Return the one-sentence recommendation for a drive engineer.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).

    Returns
    -------
    str
        Adopt or not, and the conditions, from the rows of :func:`engineer_rows`.
    """
    rows = {r[0]: r[1] for r in engineer_rows(res)}
    zone = rows["Which switching zone?"]
    parts = ["use the corrected zone" if zone == "the corrected one" else "no valid zone"]
    tuned = rows.get("At each law's best tuning (same overshoot bound)?")
    paper = rows.get("Faster than PD at the paper's gains (step, 2 % band)?")
    if tuned:
        parts.append(f"at this design point the tuned PTO {tuned.replace('PD', 'a tuned PD')}")
    elif paper:
        parts.append(f"at the paper's gains the PTO {paper}")
    versus = rows.get(VERSUS_QUESTION, "")
    if "loses" in versus:
        parts.append(f"against fair-tuned laws it {versus}")
    delay = rows.get("Tolerates a one-sample computation delay (paper's gains)?")
    if delay and delay != "yes":
        parts.append("it needs delay compensation")
    skipped = [s for s in ("tuning", "robust") if res[s] is None]
    if skipped:
        parts.append(f"not judged here: {' and '.join(skipped)} (skipped)")
    care = any(w in p for p in parts for w in ("loses", "depends", "needs", "not judged"))
    verdict = (
        "Do not adopt"
        if zone != "the corrected one"
        else ("Adopt only with care" if care else "Adopt")
    )
    return f"{verdict}: " + "; ".join(parts) + "."
