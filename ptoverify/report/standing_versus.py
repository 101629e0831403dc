"""The corrected PTO against fair-tuned PD, PTOS and cascade P: the verdict table's row.

Read off ``tuning.versus`` (:func:`ptoverify.studies.versus.versus`); every number is
a field of ``results.json``.  :mod:`ptoverify.report.standing` puts the row in the
drive engineer's table and re-exports these names.

Catalogue
---------
VERSUS_QUESTION the row's question
bound_words     a shared overshoot bound: its value and what it is
versus_verdict  beats / ties / loses against one fair-tuned law
versus_bound    the shared overshoot bound, and why its value differs with a
versus_row      the row: per reading of a, the verdict against each law
versus_note     the row in full, for the note under the verdict table
"""

from __future__ import annotations

from collections.abc import Mapping

from ptoverify.report.render import fmt, qty
from ptoverify.report.standing_claims import bandwidth_hz, reading_words
from ptoverify.report.words import law_name
from ptoverify.verdict import time_order

__all__ = [
    "VERSUS_QUESTION",
    "bound_words",
    "versus_verdict",
    "versus_bound",
    "versus_row",
    "versus_note",
]


def _ms(seconds: float | None) -> str:
    return "never" if seconds is None else qty(1e3 * seconds, "ms")


#: The question of the baselines' row.
VERSUS_QUESTION = "Faster than fair-tuned PD, PTOS and the cascade P loop (step)?"


def versus_verdict(
    diff: float | None, other: Mapping, pto: Mapping, sample: float, short: bool = False
) -> str:
    """Return the PTO's verdict against one fair-tuned law: beats, ties, loses, or no verdict.

    Parameters
    ----------
    diff : float or None
        The PTO's settling minus the other law's [s] (None: one has no tuning).
    other, pto : Mapping
        The two tuned laws (``law``, ``infeasible``) of ``tuning.versus``.
    sample : float
        T [s]: a tie under :func:`ptoverify.verdict.time_order` (less than one sample apart).
    short : bool
        A tie without the rule's words (the verdict table states the rule once).

    Returns
    -------
    str
        E.g. ``beats PTOS by 1.264 ms``.
    """
    name = law_name(other["law"])
    if pto["infeasible"]:
        return f"no verdict against {name} (no PTO gains meet the constraints)"
    if other["infeasible"] or diff is None:
        return f"no {name} gains meet the constraints"
    order = time_order(diff, 0.0, sample)
    if order == 0:
        if short:
            return f"ties {name} ({_ms(abs(diff))} apart)"
        return f"ties {name} (less than one sample apart: {_ms(abs(diff))})"
    return f"{'beats' if order < 0 else 'loses to'} {name} by {_ms(abs(diff))}"


def _settling_words(name: str, description: str) -> str:
    """Return a named settling definition as its band in words (the description if unknown)."""
    from ptoverify.sim.settling import DEFINITIONS

    d = DEFINITIONS.get(name)
    return d.band_text() if d is not None else description


def bound_words(t: Mapping, name: str) -> str:
    """Return a shared overshoot bound as its value and what it is: ``0 mm (the PTO's ...)``.

    Parameters
    ----------
    t : Mapping
        The tuning results (``bounds_mm`` [mm], ``bound_meaning``).
    name : str
        The bound's name (:data:`ptoverify.studies.tune.FAIR_BOUNDS`).

    Returns
    -------
    str
    """
    return f"{qty(t['bounds_mm'][name], 'mm')} ({t['bound_meaning'][name]})"


def _reading_a_words(res: Mapping, r: Mapping, several: bool, short: bool) -> str:
    """Return one reading of ``tuning.versus`` as its a in words."""
    if not several:
        return f"a = {qty(r['a'], 'rad/s')} (the configuration's)"
    rd = {"2pi": "2pi*f", "hz": "f"}.get(r["reading"], r["reading"])
    return reading_words("a", rd, bandwidth_hz(res), short)


def versus_bound(res: Mapping, short: bool = False) -> str:
    """Say what the baselines' shared overshoot bound is, and why its value differs with a.

    The bound (``tuning.versus.bound``, a name of
    :data:`ptoverify.studies.tune.FAIR_BOUNDS`, its meaning in
    ``tuning.bound_meaning``) is taken under each reading of a, so it is a function
    of the plant of that reading: the sentence gives each reading's value and says
    whether they differ.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`; tuning not skipped).
    short : bool
        Readings of a in the verdict table's short words.

    Returns
    -------
    str
        E.g. ``overshoot bound = the PTO's overshoot at the paper's gains, taken under
        each reading of a (so it differs): 0 mm at a = 188.5 rad/s, ...``.
    """
    t = res["tuning"]
    v = t["versus"]
    rs = v["readings"]
    values = ", ".join(
        f"{qty(r['bound_mm'], 'mm')} at {_reading_a_words(res, r, len(rs) > 1, short)}" for r in rs
    )
    meaning = t["bound_meaning"][v["bound"]]
    if len(rs) == 1:
        return f"overshoot bound = {meaning}: {values}"
    differ = len({r["bound_mm"] for r in rs}) > 1
    return (
        f"overshoot bound = {meaning}, taken under each reading of a "
        f"({'so it differs with a' if differ else 'the same under each'}): {values}"
    )


def versus_row(res: Mapping, short: bool = False) -> list[str]:
    """Return the row saying whether the corrected PTO beats fair-tuned PD, PTOS, cascade P.

    Read off ``tuning.versus`` (:func:`ptoverify.studies.versus.versus`): under each
    reading of a, every law tuned by ``tune`` under the same overshoot bound; the
    verdict per law and reading, with the settling times in ms under the named
    definition, and each over N* T.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).
    short : bool
        The verdict table's short cells: readings in short words, the evidence the
        times alone (:func:`versus_note`, under the table, has the overshoot bound
        and why it differs with a, the floors and the settling definition).

    Returns
    -------
    list of str
        ``[question, answer, evidence]``.
    """
    t = res["tuning"]
    if t is None or "versus" not in t:
        return [VERSUS_QUESTION, "not compared: the tuning was skipped", "no tuned results"]
    v = t["versus"]
    answers, evidence = [], []
    for r in v["readings"]:
        laws = {x["law"]: x for x in r["laws"]}
        pto = laws["pto"]
        verdicts = [  # in the laws' order (results.json sorts the keys of pto_minus)
            versus_verdict(r["pto_minus"][x["law"]], x, pto, r["sample_time"], short)
            for x in r["laws"]
            if x["law"] != "pto"
        ]
        words = _reading_a_words(res, r, len(v["readings"]) > 1, short)
        answers.append(f"{words}: {', '.join(verdicts)}")
        times = ", ".join(
            f"{law_name(x['law'])} "
            + (
                "no tuning"
                if x["infeasible"]
                else _ms(x["settling_s"])
                + ("" if short else f" ({fmt(x['ratio_nt'])} N*T, {fmt(x['ratio_tf'])} t_f*)")
            )
            for x in r["laws"]
        )
        if short:
            evidence.append(f"{words}: {times}")
            continue
        evidence.append(
            f"{words}, overshoot <= {qty(r['bound_mm'], 'mm')}: {times}; "
            f"N*T = {_ms(r['nt_s'])}, t_f* = {_ms(r['tf_s'])}"
        )
    if not short:
        evidence.append(f"settled: {_settling_words(v['settling'], v['settling_description'])}")
    return [VERSUS_QUESTION, "; ".join(answers), "; ".join(evidence)]


def versus_note(res: Mapping) -> str:
    """Return the note under the verdict table: the baselines' row in full, with its bound.

    Parameters
    ----------
    res : Mapping
        The results (:class:`ptoverify.report.results.Results`).

    Returns
    -------
    str
        "" when the tuning was skipped; else the full evidence of :func:`versus_row`
        (each law's time over N* T and t_f*, the floors, the settling definition)
        and :func:`versus_bound`.
    """
    t = res["tuning"]
    if t is None or "versus" not in t:
        return ""
    return f"The fair-tuned comparison in full: {versus_bound(res)}. {versus_row(res)[2]}."
