"""The verdict, the headline findings and the summary of the gates."""

from __future__ import annotations

import html
from typing import Any

from ptoverify.report.render import (
    Block,
    findings,
    fmt,
    link,
    qty,
    table,
)
from ptoverify.report.standing import ratio_phrase
from ptoverify.report.words import gate_words, plain, plural
from ptoverify.verdict import time_order

from .common import (
    _GATE_UNITS,
    _claim_qty,
    _downstream_ids,
    _ms,
    measured_quantity,
)


# ------------------------------------------------------------------ headline
def headline_findings(res: dict[str, Any]) -> list[tuple[str, str, str]]:
    """Return the report's headline: at most six one-sentence findings, each from the results.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).

    Returns
    -------
    list of (str, str, str)
        ``(sentence, anchor, link text)``: the sentence carries its key number
        with its unit; the anchor names the section holding the evidence.
    """
    out = [
        _finding_errata(res),
        _finding_zone(res),
        _finding_settling(res),
        _finding_claims(res),
        _finding_robust(res),
        _finding_gates(res),
    ]
    return [f for f in out if f is not None][:6]


def _finding_errata(res: dict[str, Any]) -> tuple[str, str, str] | None:
    recs = res["derivations"]
    err = [r for r in recs if r["verdict"] == "erratum"]
    checked = sum(r["verdict"] in ("verified", "erratum") for r in recs)
    if not err:
        return (
            f"All {checked} checked printed equations are verified (0 errata).",
            "derivations",
            "derivations",
        )
    first = err[0]
    down = _downstream_ids(first["inherits"])
    tail = (
        f"; the first, eq. ({first['id']}), changes {len(down)} downstream equation groups "
        f"({'; '.join(down)})"
        if down
        else f"; the first is eq. ({first['id']})"
    )
    return (
        f"{len(err)} of {checked} checked printed equations are errata "
        f"(eqs. {', '.join(r['id'] for r in err)}){tail}.",
        "errata",
        "errata with counterexamples",
    )


def _finding_zone(res: dict[str, Any]) -> tuple[str, str, str] | None:
    z = res["zone"]
    pr, co = z["printed"], z["corrected"]
    w_max = res["environment"]["config"]["plant"]["w_max"]
    where = (
        f"exceeds w_max = {qty(w_max, 'mm/s')}, so the zone is empty"
        if pr["omega0"] is not None and pr["omega0"] > w_max
        else f"{'meets' if pr['valid'] else 'violates'} the no-stride-over principle"
    )
    return (
        f"The switching zone as printed is {'valid' if pr['valid'] else 'invalid'}: "
        f"omega0 = {qty(pr['omega0'], 'mm/s')} {where}; the corrected construction gives "
        f"omega0 = {qty(co['omega0'], 'mm/s')} ({'valid' if co['valid'] else 'invalid'}, "
        f"{fmt(co['grid_violations'])} violations in {fmt(co['grid_points'])} grid "
        "states).",
        "zone",
        "zone geometry",
    )


def _finding_settling(res: Any) -> tuple[str, str, str] | None:
    """State which law settles the step first, under each reading of a and at best tuning.

    Both numbers stand in the same sentence, so the finding cannot overstate.
    """
    from ptoverify.report.standing import bandwidth_hz, reading_words, step_readings

    from .studies import sweep_definition_words

    step = step_readings(res)
    if not step:
        return None
    T = res["environment"]["config"]["plant"]["sample_time"]  # noqa: N806 - the paper's symbol
    parts = []
    for a, r in step.items():
        v = r["values"]
        pd, pto = v["settling_pd_s"], v["settling_pto_s"]
        order = time_order(pto, pd, T)
        if order is None:
            continue
        first = {
            -1: "the corrected PTO settles first",
            0: "PD and the corrected PTO tie (less than one sample apart)",
            1: "PD settles first",
        }[order]
        parts.append(
            f"under {reading_words('a', a, bandwidth_hz(res))} {first} "
            f"(PD {_ms(pd)}, PTO {_ms(pto)})"
        )
    if not parts:
        return None
    text = "At the paper's gains the 5 mm step's 2 % settling depends on the reading: " + (
        "; ".join(parts)
    )
    t = res["tuning"]
    if t is not None:
        from ptoverify.report.standing import time_verdict

        tuned = [
            f"at overshoot <= {qty(t['bounds_mm'][name], 'mm')} the PTO "
            f"{time_verdict(by['pto']['settling_2pct_s'], by['pd']['settling_2pct_s'], T)}, "
            f"PD {_ms(by['pd']['settling_2pct_s'])} vs PTO {_ms(by['pto']['settling_2pct_s'])}"
            for name, by in t["best"].items()
            if "pd" in by and "pto" in by
        ]
        if tuned:
            a0 = reading_words("a", next(iter(step)), bandwidth_hz(res))
            text += f"; at each law's best tuning ({a0}): " + "; ".join(tuned)
    sw = res["sweep"]["laws"]
    if "pd" in sw and "pto" in sw:
        pd, pto = sw["pd"]["percentiles_ratio_nt"], sw["pto"]["percentiles_ratio_nt"]
        grid = res["sweep"]["grid"]
        tf_pd = sw["pd"]["percentiles_ratio_tf"]
        tf_pto = sw["pto"]["percentiles_ratio_tf"]
        worst_x1 = sw["pto"]["worst_state_nt"][0]
        text += (
            f". Over the envelope ({grid[0]} x {grid[1]} states, paper's gains, settling "
            f"definition {sweep_definition_words(res['sweep'])}) "
            f"settling / (N* T) has median PD {fmt(pd['p50'])} [-], PTO {fmt(pto['p50'])} [-] "
            f"and settling / t_f* median PD {fmt(tf_pd['p50'])} [-], PTO {fmt(tf_pto['p50'])} [-]; "
            f"the PTO's worst ratio {fmt(pto['max'])} [-] starts at x1 = {fmt(worst_x1)} mm"
        )
        reach = res["environment"]["config"]["plant"]["position_range"]
        if abs(worst_x1) < 0.05 * reach:
            text += " (a small move: N* is a few samples there, and one sample more weighs much)"
    if t is not None:
        fl = t["floor"]
        text += (
            f". The 5 mm step's floors: t_f* = {_ms(fl['tf_s'])} (continuous), N* T = "
            f"{_ms(fl['nt_s'])} (sampled)"
        )
    return (text + ".", "sweep", "responses and suboptimality maps")


def _finding_claims(res: Any) -> tuple[str, str, str] | None:
    from ptoverify.report.standing import bandwidth_hz, claim_standing, reading_words

    cl = res["claims"]
    fail = [c for c in cl if claim_standing(c)[0] == "fails"]
    depends = [c for c in cl if claim_standing(c)[0] == "depends"]
    text = (
        f"Of {len(cl)} Section 6 claims, {len(fail)} fail under every reading tried and "
        f"{len(depends)} hold under some readings only (see the verdict table)"
    )
    c31 = next((c for c in cl if c["id"] == "step-pd-31-percent"), None)
    if c31 is not None and c31["measured"] is not None:
        more = c31["measured"]
        text += (
            f"; the headline claim that PD needs {qty(c31['paper_value'], '%')} more settling "
            f"time than the PTO measures PD needing {qty(abs(more), '%')} "
            f"{'more' if more >= 0 else 'less'} at the paper's gains "
            f"({reading_words('a', '2pi*f', bandwidth_hz(res))})"
        )
        t = res["tuning"]
        c31t = next(
            (c for c in (t["claims"] if t else ()) if c["id"] == "step-pd-31-percent"), None
        )
        if c31t is not None:
            best = [r for r in c31t["readings"] if "best-tuned" in r["label"]]
            if best:
                from ptoverify.report.standing import time_verdict

                T = res["environment"]["config"]["plant"]["sample_time"]  # noqa: N806
                text += "; at both laws' best tuning, " + "; ".join(
                    f"at overshoot <= {qty(r['reading']['bound_mm'], 'mm')} the PTO "
                    f"{time_verdict(v['settling_pto_s'], v['settling_pd_s'], T)}, "
                    f"PD {_ms(v['settling_pd_s'])} vs PTO {_ms(v['settling_pto_s'])}"
                    for r in best
                    for v in [r["values"]]
                )
    return (text + ".", "claims", "claims with every reading")


def c31_paper(res: dict[str, Any]) -> float | None:
    """Return the paper's value of the 31 % claim [%] from the claims results.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).

    Returns
    -------
    float or None
    """
    c = next((c for c in res["claims"] if c["id"] == "step-pd-31-percent"), None)
    return None if c is None else c["paper_value"]


def _finding_robust(res: Any) -> tuple[str, str, str] | None:
    rob = res["robust"]
    if rob is None or "pto" not in rob["margins"]:
        return None
    m = rob["margins"]["pto"]
    d1, nd = m["linear_loop_a_ratio_stable_delay1"], m["linear_loop_a_ratio_stable"]
    text = f"Without delay the PTO's linear zone is stable for a_true / a_design {ratio_phrase(nd)}"
    if "pd" in rob["margins"]:
        pd = rob["margins"]["pd"]
        text += f" (PD: {ratio_phrase(pd['linear_loop_a_ratio_stable'])})"
    text += "; with a one-sample computation delay it is " + (
        f"stable for a_true / a_design {ratio_phrase(d1)}"
        if d1
        else "unstable even at the design bandwidth"
    )
    if "pd" in rob["margins"]:
        text += f" (PD: {ratio_phrase(rob['margins']['pd']['linear_loop_a_ratio_stable_delay1'])})"
    return (text + ".", "robustness", "robustness")


def _finding_gates(res: Any) -> tuple[str, str, str]:
    s = res["summary"]
    nom, per = s["gates_nominal"], s["gates_perturbed"]
    failed = [gate_words(c["name"]) for c in res["checks"] if c["status"] != "pass"]
    text = (
        f"{nom['pass']} of {nom['total']} verification gates pass on the nominal plant"
        + (
            f"; on the perturbed plant (the model mismatch of the robustness section) "
            f"{per['pass']} of {plural(per['total'], 'gate')} pass"
            if per["total"]
            else "; the gates under perturbation were not run (robustness skipped)"
        )
        + (f" (not passing: {', '.join(failed)})" if failed else "")
    )
    rob = res["robust"]
    if rob is not None and "pto" in rob["margins"]:
        if rob["margins"]["pto"]["linear_loop_a_ratio_stable_delay1"] is None:
            text += "; with one sample of computation delay the PTO's linear zone is unstable"
    return (text + ".", "summary", "gate table")


def headline(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Return the opening: the headline findings with the step responses beside them.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of Block
    """
    key = "fig07_step_position"
    return [
        findings(
            headline_findings(res),
            figures.get(key, ""),
            "Step responses of TO, PD, PTO (corrected) and PTO as printed (5 mm step)",
        )
    ]


def summary(res: dict[str, Any]) -> list[Block]:
    """Gates with measured values and limits in their units, errata and failing claims."""
    rows = [
        [
            c["name"],
            "perturbed plant" if c["name"].startswith("robust-") else "nominal plant",
            plain(c["description"]),
            c["status"],
            "unbounded"
            if c["measured_unbounded"]
            else qty(c["measured"], _GATE_UNITS.get(c["unit"], c["unit"])),
            c["comparison"],
            qty(c["limit"], _GATE_UNITS.get(c["unit"], c["unit"])),
        ]
        for c in res["checks"]
    ]
    blocks = [
        table(["gate", "plant", "what it checks", "status", "measured", "must be", "limit"], rows),
        Block(
            "p",
            text="[-] marks a dimensionless number (a relative error, a count ratio or "
            "a spectral radius).",
        ),
    ]
    err = [r for r in res["derivations"] if r["verdict"] == "erratum"]
    if err:
        blocks.append(
            Block(
                "raw",
                text="Errata: "
                + ", ".join(f"eq. ({r['id']})" for r in err)
                + " ([errata](#errata))",
                html="<p>Errata: "
                + ", ".join(
                    f'<a href="#erratum-{html.escape(r["id"])}">eq. ({html.escape(r["id"])})</a>'
                    for r in err
                )
                + "</p>",
            )
        )
    from ptoverify.report.standing import bandwidth_hz, claim_standing

    hz = bandwidth_hz(res)
    bad = [c for c in res["claims"] if claim_standing(c, hz)[0] != "holds"]
    if bad:
        rows = []
        for c in bad:
            vals = [r["measured"] for r in c["readings"] if r["measured"] is not None]
            ok = sum(r["verdict"] == "reproduced" for r in c["readings"])
            rows.append(
                [
                    c["claim"],
                    claim_standing(c, hz)[0],
                    measured_quantity(c),
                    _claim_qty(c["paper_value"], c["unit"]),
                    _claim_qty(c["measured"], c["unit"]),
                    f"{_claim_qty(min(vals), c['unit'])} to {_claim_qty(max(vals), c['unit'])}"
                    if vals
                    else "n/a",
                    f"{ok} of {len(c['readings'])} readings",
                ]
            )
        blocks.append(
            Block(
                "p",
                text=f"Section 6 claims that fail under every reading tried "
                f"({sum(claim_standing(c, hz)[0] == 'fails' for c in bad)}) or hold under some "
                f"readings only ({sum(claim_standing(c, hz)[0] == 'depends' for c in bad)}). "
                "'measured' is the primary reading (feed-forward, a = 2 pi f, corrected PTO), "
                "between samples; the range spans every reading.",
            )
        )
        blocks.append(
            table(
                [
                    "claim",
                    "standing",
                    "what is measured",
                    "paper",
                    "measured",
                    "range over readings",
                    "reproducing",
                ],
                rows,
            )
        )
        blocks.append(link("claims", "All claims with every reading"))
    return blocks
