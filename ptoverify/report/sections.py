"""The sections of the report, built from the JSON results as neutral blocks.

Each function takes the JSON results of :func:`ptoverify.report.collect.collect` (and
the figure paths) and returns a list of :class:`ptoverify.report.render.Block`.  No
number is typed in here: every figure shown is read from the results, with its
unit (``[-]`` marks a dimensionless number) and 4 significant digits (the full
values are in ``results.json``).  Nothing here computes: the derivation and
errata sections get the records the collect step made.
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Mapping
from typing import Any

from ptoverify.report.render import (
    Block,
    code,
    findings,
    fmt,
    image,
    link,
    qty,
    table,
)
from ptoverify.report.standing import ratio_interval

__all__ = [
    "headline_findings",
    "headline",
    "summary",
    "errata",
    "derivations",
    "ground_truth",
    "zone",
    "poles",
    "properties",
    "claims",
    "sweep",
    "robustness",
    "tuning",
    "environment",
    "measured_quantity",
]

LAW_WORDS = {
    "to": "TO",
    "pd": "PD",
    "pto": "PTO (corrected)",
    "pto-printed": "PTO as printed",
}
_MATH = '<math xmlns="http://www.w3.org/1998/Math/MathML" display="block">{}</math>'


def _law(name: str) -> str:
    return LAW_WORDS.get(name, name)


def _ms(seconds: float | None) -> str:
    """Show a time given in s in ms."""
    if seconds is None or not math.isfinite(seconds):
        return "never"
    return qty(1e3 * seconds, "ms")


#: Caption (a sentence, also the alt text) of each figure the report can show, by file stem.
CAPTIONS: dict[str, str] = {
    "fig02_trajectories": "Fig. 2: open-loop trajectories under u = +w_max and -w_max with the "
    "switching curves l1 and l2.",
    "fig03_saturation": "Fig. 3: sampled TO trajectories from the envelope's edge, with the "
    "velocity saturating at w_max.",
    "convergence": "Relative error of the collocation minimum time against the closed form, "
    "for each state, as the number of intervals N grows.",
    "collocation_switch": "The collocation input near the switch time, beside the closed-form "
    "bang-bang input.",
    "zone_geometry": "The switching zone: l1, l2, the corrected l1* and l2*, the printed curve "
    "(19), the linear zone, and sampled PTO trajectories coloured by region.",
    "fig04_zones_corrected": "Fig. 4 redrawn with the corrected construction: the switching zone "
    "between l1 and its widened curve, and the linear zone.",
    "fig04_zones_printed": "Fig. 4 as printed (eqs. 19-27): the zone the printed omega0 gives.",
    "fig05_l1_image_corrected": "Fig. 5, corrected: the image of l1 after one sample under "
    "-w_max lies inside the corrected zone.",
    "fig05_l1_image_printed": "Fig. 5 as printed: the image of l1 after one sample against the "
    "printed curve (19).",
    "fig06_trajectory_pto": "Fig. 6 with the corrected PTO: a fourth-quadrant trajectory enters "
    "the switching zone and slides to the linear zone.",
    "fig06_trajectory_pto-printed": "Fig. 6 with the PTO as printed: the same start; the printed "
    "zone is empty, so the law acts as TO outside the linear zone.",
    "fig07_step_position": "Fig. 7: position response of every law to the 5 mm step.",
    "fig08_step_error": "Fig. 8: position error of every law after the 5 mm step.",
    "fig09_ramp_position": "Fig. 9: position tracking of the ramp, with velocity feed-forward.",
    "fig09_ramp_position_noff": "Fig. 9: position tracking of the ramp, without feed-forward.",
    "fig10_ramp_velocity": "Fig. 10: velocity during the ramp, with feed-forward.",
    "fig10_ramp_velocity_noff": "Fig. 10: velocity during the ramp, without feed-forward.",
    "fig11_ramp_error": "Fig. 11: ramp tracking error, with feed-forward.",
    "fig11_ramp_error_noff": "Fig. 11: ramp tracking error, without feed-forward.",
    "fig12_sine_position": "Fig. 12: position tracking of the sine, with feed-forward.",
    "fig12_sine_position_noff": "Fig. 12: position tracking of the sine, without feed-forward.",
    "fig13_sine_velocity": "Fig. 13: velocity while tracking the sine, with feed-forward.",
    "fig13_sine_velocity_noff": "Fig. 13: velocity while tracking the sine, without feed-forward.",
    "fig14_sine_states": "Fig. 14: error and velocity-error phase portrait on the sine, with "
    "feed-forward.",
    "fig14_sine_states_noff": "Fig. 14: error and velocity-error phase portrait on the sine, "
    "without feed-forward.",
    "sweep_ratio_tf": "Settling time over the minimum time t_f*, per law, over the envelope of "
    "initial states (the colour scale says where it clips).",
    "sweep_ratio_nt": "Settling time over the sampled limit N* T, per law, over the envelope of "
    "initial states (the colour scale says where it clips).",
    "robust_limit_cycles": "States ending in a limit cycle, per law (rows) and delay (columns), "
    "over a_true / a_design and the w_max ratio.",
    "robust_settling_nt": "Worst settling / (N* T) over the states, per law and delay (never: "
    "some state never settles).",
    "proof_bound_pto": "Certified number of samples to reach the target ellipse from each cell "
    "of the envelope, corrected PTO (interval arithmetic; red: unproven).",
    "proof_bound_pd": "Certified number of samples to reach the target ellipse from each cell "
    "of the envelope, PD (interval arithmetic; red: unproven).",
    "tuning_pareto": "Settling against overshoot on the step: the Pareto fronts of PD and PTO "
    "over every candidate evaluated, the best tunings (stars), the paper's gains (squares) and "
    "the floor.",
}


def figure(figures: dict[str, str], key: str) -> list[Block]:
    """Return the figure ``key`` with its sentence caption (none when it was not drawn).

    Parameters
    ----------
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    key : str
        The figure's file stem; it must have a caption in :data:`CAPTIONS`.

    Returns
    -------
    list of Block
    """
    return image(figures, key, CAPTIONS[key])


# ------------------------------------------------------------------ verdict
def verdict(res: Any) -> list[Block]:
    """Show the paper's standing in one screen: the drive engineer's and the reviewer's verdicts.

    Parameters
    ----------
    res : Results
        The results (:class:`ptoverify.report.results.Results`).

    Returns
    -------
    list of Block
    """
    from ptoverify.report.standing import adoption, engineer_rows, reviewer_rows

    return [
        Block("p", text=adoption(res)),
        table(["question (drive engineer)", "answer", "evidence"], engineer_rows(res)),
        table(
            ["claim of the paper (reviewer)", "standing", "condition", "paper", "measured"],
            reviewer_rows(res),
        ),
        Block(
            "p",
            text="'holds': every reading tried reproduces the claim; 'fails': none does; "
            "'depends': some do, and the condition names what decides it. Readings: the "
            "bandwidth's a as 2 pi f or as f in rad/s, the settling band, the PTO's zone as "
            "printed or corrected, the tracking, the tuning (see section claims).",
        ),
    ]


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
    from ptoverify.report.standing import reading_words, step_readings

    step = step_readings(res)
    if not step:
        return None
    parts = []
    for a, r in step.items():
        v = r["values"]
        pd, pto = v["settling_pd_s"], v["settling_pto_s"]
        if pd is None or pto is None:
            continue
        fast = "PD" if pd < pto else "the corrected PTO"
        parts.append(
            f"under {reading_words('a', a)} {fast} settles first (PD {_ms(pd)}, PTO {_ms(pto)})"
        )
    if not parts:
        return None
    text = "At the paper's gains the 5 mm step's 2 % settling depends on the reading: " + (
        "; ".join(parts)
    )
    t = res["tuning"]
    if t is not None:
        tuned = [
            f"PD {_ms(by['pd']['settling_2pct_s'])} vs PTO {_ms(by['pto']['settling_2pct_s'])} "
            f"at overshoot <= {qty(t['bounds_mm'][name], 'mm')}"
            for name, by in t["best"].items()
            if "pd" in by and "pto" in by
        ]
        if tuned:
            text += "; at each law's best tuning (a = 2 pi f): " + "; ".join(tuned)
    sw = res["sweep"]["laws"]
    if "pd" in sw and "pto" in sw:
        pd, pto = sw["pd"]["percentiles_ratio_nt"], sw["pto"]["percentiles_ratio_nt"]
        grid = res["sweep"]["grid"]
        text += (
            f". Over the envelope ({grid[0]} x {grid[1]} states, paper's gains) settling / (N* T) "
            f"has median PD {fmt(pd['p50'])} [-], PTO {fmt(pto['p50'])} [-]"
        )
    return (text + ".", "sweep", "responses and suboptimality maps")


def _finding_claims(res: Any) -> tuple[str, str, str] | None:
    from ptoverify.report.standing import claim_standing

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
            f"{'more' if more >= 0 else 'less'} at the paper's gains (a = 2 pi f)"
        )
        t = res["tuning"]
        c31t = next(
            (c for c in (t["claims"] if t else ()) if c["id"] == "step-pd-31-percent"), None
        )
        if c31t is not None:
            best = [r for r in c31t["readings"] if "best-tuned" in r["label"]]
            if best:
                text += (
                    "; at both laws' best tuning they settle alike ("
                    + "; ".join(
                        f"PD {_ms(r['values']['settling_pd_s'])} vs PTO "
                        f"{_ms(r['values']['settling_pto_s'])}"
                        for r in best
                    )
                    + ")"
                )
    return (text + ".", "claims", "claims with every reading")


def _count(counts: Any, verdict: str) -> int:
    """Return how many claims have ``verdict`` (0 when the tally has no such verdict)."""
    return counts[verdict] if verdict in counts else 0


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


def _claim_value_sentence(c: dict[str, Any]) -> str:
    unit, scale = _display_unit(c["unit"])
    paper = f", paper {qty(c['paper_value'] * scale, unit)}" if c["paper_value"] is not None else ""
    return f"{c['id']} measures {qty(c['measured'] * scale, unit)}{paper}"


def _finding_robust(res: Any) -> tuple[str, str, str] | None:
    rob = res["robust"]
    if rob is None or "pto" not in rob["margins"]:
        return None
    m = rob["margins"]["pto"]
    d1, nd = m["linear_loop_a_ratio_stable_delay1"], m["linear_loop_a_ratio_stable"]
    text = f"Without delay the PTO's linear zone is stable for a_true / a_design in {ratio_interval(nd)}"
    if "pd" in rob["margins"]:
        pd = rob["margins"]["pd"]
        text += f" (PD: {ratio_interval(pd['linear_loop_a_ratio_stable'])})"
    text += "; with a one-sample computation delay it is " + (
        f"stable for {ratio_interval(d1)}" if d1 else "unstable even at the design bandwidth"
    )
    if "pd" in rob["margins"]:
        text += (
            f" (PD: {ratio_interval(rob['margins']['pd']['linear_loop_a_ratio_stable_delay1'])})"
        )
    return (text + ".", "robustness", "robustness")


def _finding_gates(res: Any) -> tuple[str, str, str]:
    s = res["summary"]
    nom, per = s["gates_nominal"], s["gates_perturbed"]
    failed = [c["name"] for c in res["checks"] if c["status"] != "pass"]
    text = (
        f"{nom['pass']} of {nom['total']} verification gates pass on the nominal plant"
        + (
            f"; under the [robustness] box's perturbations {per['pass']} of {per['total']} pass"
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


# ------------------------------------------------------------------ units
def _display_unit(unit: str) -> tuple[str, float]:
    """Return the unit a claim's number is shown in, and the factor from its stored unit."""
    if unit == "s":
        return "ms", 1e3
    if unit == "reversals":
        return "sign reversals", 1.0
    return unit, 1.0


def measured_quantity(c: dict[str, Any]) -> str:
    """Describe what a claim's 'measured' number is, in words with its unit.

    The name of the value that equals the headline number (units in the names:
    ``phase_delay_deg`` -> "phase delay [deg]"; times shown in ms).

    Parameters
    ----------
    c : dict
        A claim of ``results["claims"]``.

    Returns
    -------
    str
    """
    if c["measured"] is None:
        return "qualitative (no single number; see detail)"
    values = c["readings"][0]["values"] if c["readings"] else {}
    name = next(
        (k for k, v in values.items() if isinstance(v, (int, float)) and v == c["measured"]), ""
    )
    words = re.sub(r"_(mm_s|mm|s|deg|percent)$", "", name).replace("_", " ")
    unit, _ = _display_unit(c["unit"])
    return f"{words or 'value'} [{unit or '-'}]"


def _claim_qty(v: float | None, unit: str) -> str:
    if v is None:
        return "n/a"
    u, scale = _display_unit(unit)
    return qty(v * scale, u)


def _same(a: float | None, b: float | None) -> bool:
    if a is None or b is None:
        return a is b
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b), 1e-300)


# ------------------------------------------------------------------ summary
_GATE_UNITS = {"1": "-", "": "-"}


def summary(res: dict[str, Any]) -> list[Block]:
    """Gates with measured values and limits in their units, errata and failing claims."""
    s = res["summary"]
    rows = [
        [
            c["name"],
            "perturbed plant" if c["name"].startswith("robust-") else "nominal plant",
            c["description"],
            c["status"],
            qty(c["measured"], _GATE_UNITS.get(c["unit"], c["unit"])),
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
                text="Errata: " + ", ".join(f"eq. ({r['id']})" for r in err) + " (section errata)",
                html="<p>Errata: "
                + ", ".join(
                    f'<a href="#erratum-{html.escape(r["id"])}">eq. ({html.escape(r["id"])})</a>'
                    for r in err
                )
                + "</p>",
            )
        )
    bad = [c for c in res["claims"] if c["verdict"] != "reproduced"]
    if bad:
        rows = []
        for c in bad:
            vals = [r["measured"] for r in c["readings"] if r["measured"] is not None]
            ok = sum(r["verdict"] == "reproduced" for r in c["readings"])
            rows.append(
                [
                    c["claim"],
                    c["verdict"],
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
                text=f"Section 6 claims not reproduced ({_count(s['claim_verdicts'], 'not reproduced')}) "
                f"or holding under some readings only ({_count(s['claim_verdicts'], 'ambiguous')}). "
                "'measured' is the primary reading (feed-forward, a = 2 pi f, corrected PTO), "
                "between samples; the range spans every reading.",
            )
        )
        blocks.append(
            table(
                [
                    "claim",
                    "verdict",
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


# ------------------------------------------------------------------ errata
#: Units of the symbols of a counterexample (the paper's symbols; omega_m is w_max).
SYMBOL_UNITS = {
    "a": "rad/s",
    "T": "s",
    "omega_m": "mm/s",
    "omega_0": "mm/s",
    "x1": "mm",
    "x2": "mm/s",
    "tx1": "mm",
    "tx2": "mm/s",
    "x10": "mm",
    "x20": "mm/s",
    "d": "mm",
    "k1": "1/s",
    "k2": "-",
}
_LENGTH = {"x1", "tx1", "x10", "tx10", "d"}
_SPEED = {"x2", "tx2", "x20", "tx20", "omega_m", "omega_0", "omega_c"}


def _expr_unit(text: str) -> str:
    """Return the unit of an expression of the paper's symbols, by scaling the units (mm, s).

    Scales lengths by L and times by S (so speeds by L / S, a by 1 / S) and
    reads the exponents from the value's change at a generic point; "mm/s",
    "mm", "s", "rad/s", "-" or "" when the expression is not homogeneous.
    """
    try:
        import sympy as sp

        from derivations.printed import parse

        exprs = [parse(p) for p in text.split("; ")]
    except Exception:  # noqa: BLE001 - prose, not formulas
        return ""
    units = set()
    for e in exprs:
        if isinstance(e, sp.Equality) or not isinstance(e, sp.Expr):
            return ""
        syms = {s.name: s for s in e.free_symbols}
        base = {s: sp.Rational(3 + i, 7) for i, s in enumerate(sorted(syms.values(), key=str))}
        if "omega_m" in syms:
            base[syms["omega_m"]] = sp.Integer(50)

        def scaled(L: int, S: int, base=base, syms=syms) -> float:  # noqa: N803
            sub = {}
            for name, s in syms.items():
                f = L if name in _LENGTH else (sp.Rational(L, S) if name in _SPEED else 1)
                f = sp.Rational(1, S) if name == "a" else (S if name == "T" else f)
                sub[s] = base[s] * f
            return complex(e.xreplace(sub).evalf()).real  # numbers for symbols: xreplace

        try:
            v0, vl, vs = scaled(1, 1), scaled(2, 1), scaled(1, 2)
            p = math.log2(vl / v0)
            q = math.log2(vs / v0)
        except (ValueError, ZeroDivisionError, TypeError):
            return ""
        units.add((round(p, 6), round(q, 6)))
    if len(units) != 1:
        return ""
    return {(1, -1): "mm/s", (1, 0): "mm", (0, 1): "s", (0, -1): "rad/s", (0, 0): "-"}.get(
        units.pop(), ""
    )


def _downstream_ids(inherits: list[str]) -> list[str]:
    """Return the equation labels ('17', '20-27', '36, 35') that an erratum changes."""
    out = []
    for item in inherits:
        head, _, what = item.partition(":")
        if re.fullmatch(r"[\w\-, ]+", head.strip()) and not what.strip().startswith("unchanged"):
            out.append(head.strip())
    return out


def _eq_links(head: str, ids: set[str]) -> str:
    """HTML links for an equation label: each id or range end that has a record."""
    parts = []
    for tok in re.split(r"(, |-)", head):
        parts.append(
            f'<a href="#eq-{html.escape(tok)}">{html.escape(tok)}</a>'
            if tok in ids
            else html.escape(tok)
        )
    return "".join(parts)


def _counterexample_rows(ce: dict[str, Any], unit: str) -> tuple[list[str], list[list[str]]]:
    """Table rows of a counterexample: its point (with units), printed and derived values."""
    cols = [("random admissible point", ce)]
    if "at_plant" in ce and ce["at_plant"]:
        cols.append(("at this report's plant", ce["at_plant"]))
    names: list[str] = []
    for _, c in cols:
        names += [k for k in c["point"] if k not in names]
    extra = [k for k in ce if k not in ("point", "printed", "derived", "at_plant")]
    rows = []
    for n in names:
        u = SYMBOL_UNITS.get(n, "")
        rows.append(
            [
                f"{n}",
                *[
                    qty(c["point"][n], u) if u else fmt(c["point"][n]) + " (unit as in the paper)"
                    for _, c in cols
                ],
            ]
        )
    for n in extra:
        u = "mm, mm/s" if isinstance(ce[n], (list, tuple)) and len(ce[n]) == 2 else ""
        rows.append([n.replace("_", " "), f"{fmt(ce[n])} {u}".strip(), *["" for _ in cols[1:]]])
    for which in ("printed", "derived"):
        vals = [c[which] for _, c in cols]
        vals = [v[0] if isinstance(v, (list, tuple)) and len(v) == 1 else v for v in vals]
        rows.append(
            [
                f"{which} form, evaluated",
                *[
                    (qty(v, unit) if unit else fmt(v) + " (residual, unit as in the paper)")
                    for v in vals
                ],
            ]
        )
    return ["quantity", *[t for t, _ in cols]], rows


#: The paper's tilded symbols, named ``tx1``, ``tx20``, ... in the derivations.
_TILDE_MI = re.compile(r"<mi>tx</mi>")
_TILDE_TEXT = re.compile(r"\btx(\d+)")


def tilde_mathml(text: str) -> str:
    """Draw the derivations' ``tx`` symbols as x with a tilde (x~1 is the paper's tilde-x1).

    Parameters
    ----------
    text : str
        MathML from SymPy's presentation printer.

    Returns
    -------
    str

    Examples
    --------
    >>> tilde_mathml("<msub><mi>tx</mi><mi>1</mi></msub>")
    '<msub><mover accent="true"><mi>x</mi><mo>~</mo></mover><mi>1</mi></msub>'
    """
    return _TILDE_MI.sub('<mover accent="true"><mi>x</mi><mo>~</mo></mover>', text)


def tilde_text(text: str) -> str:
    """Write the derivations' ``tx1`` as ``x~1`` in plain text.

    Parameters
    ----------
    text : str
        A plain-text form.

    Returns
    -------
    str

    Examples
    --------
    >>> tilde_text("a*tx1 + tx20")
    'a*x~1 + x~20'
    """
    return _TILDE_TEXT.sub(r"x~\1", text)


def render_records(records: list) -> dict[str, dict[str, Any]]:
    """Render what the derivation sections show of each record (SymPy work, done once).

    Parameters
    ----------
    records : list of derivations.EquationRecord
        The derivation records.

    Returns
    -------
    dict
        Record id -> ``{"mathml": ..., "unit": ...}``: the MathML of each form
        (:meth:`derivations.EquationRecord.to_mathml`) and, for an erratum, the
        unit of its expressions ("" otherwise).  The report's derivations stage
        computes it beside the records, in the same worker process.
    """
    return {
        r.id: {
            "mathml": {k: tilde_mathml(v) for k, v in r.to_mathml().items()},
            "unit": (_expr_unit(r.derived) or _expr_unit(r.printed))
            if r.verdict == "erratum"
            else "",
        }
        for r in records
    }


def errata(res: dict[str, Any], records: list, rendered: dict | None = None) -> list[Block]:
    """Each erratum: printed and derived forms (MathML), counterexample, downstream links.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).
    records : list of derivations.EquationRecord
        The records the collect step derived (MathML of each form).
    rendered : dict, optional
        :func:`render_records` of them, when already computed.

    Returns
    -------
    list of Block
    """
    recs = {r.id: r for r in records}
    rendered = rendered if rendered is not None else render_records(records)
    ids = set(recs)
    err = [r for r in res["derivations"] if r["verdict"] == "erratum"]
    if not err:
        return [Block("p", text="No printed equation disagrees with its derivation.")]
    blocks = [
        Block(
            "p",
            text=f"{len(err)} printed equations disagree with their derivation from eq. (1). "
            "For each: the form as printed and as derived, a state where they differ, and the "
            "equations downstream that change with it.",
        )
    ]
    for r in err:
        done = rendered.get(r["id"], {})
        ml = done.get("mathml", {})
        unit = done.get("unit") or _expr_unit(r["derived"]) or _expr_unit(r["printed"])
        head, rows = _counterexample_rows(r["counterexample"] or {}, unit)
        tb = table(head, rows)
        forms = []
        for key, label in (
            ("printed", "printed"),
            ("derived", "derived"),
            ("corrected", "corrected"),
        ):
            if r[key]:
                m = ml.get(key, "")
                zero = key == "corrected" and "=" not in r[key]  # a residual: the curve is = 0
                if m:
                    body = _MATH.format(m + ("<mo>=</mo><mn>0</mn>" if zero else ""))
                else:
                    body = (
                        f"<code>{html.escape(tilde_text(r[key]) + (' = 0' if zero else ''))}</code>"
                    )
                forms.append(f"<tr><th>{label}</th><td>{body}</td></tr>")
        down = [i.split(":", 1) for i in r["inherits"]]
        lis = "".join(
            f"<li>eq. {_eq_links(h.strip(), ids)}: {html.escape(tilde_text(t.strip()))}</li>"
            if t
            else f"<li>{html.escape(h)}</li>"
            for h, *rest in down
            for t in [rest[0] if rest else ""]
        )
        inner = (
            f'<div class="erratum-block" id="erratum-{html.escape(r["id"])}">'
            f'<h3>Eq. ({html.escape(r["id"])}) <a href="#eq-{html.escape(r["id"])}">'
            "(in the derivations table)</a></h3>"
            f"<p>{html.escape(tilde_text(r['note']))}</p><table>{''.join(forms)}</table>"
            "<p>Counterexample (each row in its own unit):</p>"
        )
        md = (
            f"### Eq. ({r['id']})\n\n{tilde_text(r['note'])}\n\n"
            f"printed: `{tilde_text(r['printed'])}`\n\n"
            f"derived: `{tilde_text(r['derived'])}`\n\n"
            + (
                f"corrected: `{tilde_text(r['corrected'])}"
                f"{'' if '=' in r['corrected'] else ' = 0'}`\n\n"
                if r["corrected"]
                else ""
            )
            + "Counterexample (each row in its own unit):"
        )
        blocks.append(Block("raw", text=md, html=inner))
        blocks.append(tb)
        blocks.append(
            Block(
                "raw",
                text="Changes downstream:\n\n"
                + "\n".join(f"- eq. {tilde_text(i)}" for i in r["inherits"]),
                html=f"<p>Changes downstream:</p><ul>{lis}</ul></div>",
            )
        )
    return blocks


# ------------------------------------------------------------------ derivations
def inherited_errata(records: list) -> dict[str, str]:
    """Map each equation downstream of an erratum to that erratum's id.

    An equation whose own algebra is verified but whose input is an erratum's
    result (the printed chain (20)-(27) after (16)) is not "verified" as a
    result: it leads to a wrong value (the printed omega0).

    Parameters
    ----------
    records : list of derivations.EquationRecord
        The records (``id``, ``verdict``, ``inherits``).

    Returns
    -------
    dict
        Record id -> id of the first erratum it inherits from.

    Examples
    --------
    >>> from types import SimpleNamespace as R
    >>> recs = [R(id="16", verdict="erratum", inherits=["17: unchanged", "20-22: changes"]),
    ...         R(id="21", verdict="verified", inherits=[])]
    >>> inherited_errata(recs)
    {'20': '16', '21': '16', '22': '16'}
    """
    out: dict[str, str] = {}
    for r in records:
        if r.verdict != "erratum":
            continue
        for head in _downstream_ids(list(r.inherits)):
            for part in head.split(","):
                lo, _, hi = part.strip().partition("-")
                if lo.isdigit() and (not hi or hi.isdigit()):
                    for n in range(int(lo), int(hi or lo) + 1):
                        out.setdefault(str(n), r.id)
    return out


def derivations(res: dict[str, Any], records: list, rendered: dict | None = None) -> list[Block]:
    """Show printed next to derived (MathML), verdicts; each row anchored as ``eq-<id>``.

    ``records`` are the :class:`derivations.EquationRecord` objects the collect
    step derived (their JSON form is ``res["derivations"]``); they carry the
    SymPy expressions that render as MathML.  ``rendered`` is
    :func:`render_records` of them when already computed.
    """
    from derivations.record import N_CROSS, N_POINTS

    rendered = rendered or {}
    rows_html, rows_md = [], []
    tainted = inherited_errata(records)
    for r in records:
        ml = rendered[r.id]["mathml"] if r.id in rendered else r.to_mathml()
        verdict, css = r.verdict, r.verdict
        if r.verdict == "verified" and r.id in tainted:
            verdict = f"verified algebra; inherits the erratum of eq. ({tainted[r.id]})"
            css = "inherits"

        def cell(key: str, text: str, ml=ml) -> str:
            m = ml.get(key, "")
            return _MATH.format(m) if m else f"<code>{html.escape(text)}</code>"

        note = html.escape(r.note)
        if r.verdict == "erratum":
            note += f' <a href="#erratum-{html.escape(r.id)}">(counterexample, consequences)</a>'
        rows_html.append(
            f'<tr id="eq-{html.escape(r.id)}" class="{html.escape(css)}">'
            f"<td>{html.escape(r.id)}</td><td>{html.escape(verdict)}</td>"
            f"<td>{cell('printed', r.printed)}</td><td>{cell('derived', r.derived)}</td>"
            f"<td>{note}</td></tr>"
        )
        rows_md.append(
            "| "
            + " | ".join(
                c.replace("|", "\\|").replace("\n", " ")
                for c in (
                    r.id,
                    verdict,
                    f"`{tilde_text(r.printed)}`",
                    f"`{tilde_text(r.derived)}`",
                    tilde_text(r.note),
                )
            )
            + " |"
        )
    html_table = (
        '<table class="derivations"><thead><tr><th>eq.</th><th>verdict</th><th>printed</th>'
        "<th>derived</th><th>note</th></tr></thead><tbody>"
        + "".join(rows_html)
        + "</tbody></table>"
    )
    md = "| eq. | verdict | printed | derived | note |\n|---|---|---|---|---|\n" + "\n".join(
        rows_md
    )
    return [
        Block(
            "p",
            text="Each equation is re-derived with SymPy from eq. (1) and compared "
            "with its transcription: proved symbolically where SymPy can (then "
            f"cross-checked at {N_CROSS} random admissible points), otherwise "
            f"compared at {N_POINTS} random admissible points. Where a record quotes plant numbers (the "
            "printed zone chain, the linear-zone spectral radius) they are "
            "evaluated at this report's configuration.",
        ),
        Block("raw", text=md, html=html_table),
    ]


# ------------------------------------------------------------------ ground truth
def ground_truth(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Compare closed form vs two-phase vs collocation, convergence, N*."""
    gt = res["ground_truth"]
    rows = [
        [
            s["x0"],
            s["analytic_s"],
            s["switch_time_s"],
            s["two_phase_s"],
            s["two_phase_rel_error"],
            s["collocation_s"],
            s["collocation_rel_error"],
            s["discrete_steps"],
            s["discrete_s"],
            s["discrete_gap_samples"],
        ]
        for s in gt["states"]
    ]
    conv = gt["convergence"]
    return [
        Block(
            "p",
            text="Minimum time t_f* from each state: the closed form (SymPy-derived), the "
            "CasADi two-phase OCP (exact flow per arc), Radau-3 collocation with "
            "N = 100 intervals, and the discrete-time limit N* (fewest ZOH samples that reach "
            "the origin exactly). No sampled controller settles exactly in fewer than N* samples.",
        ),
        table(
            [
                "x0 [mm, mm/s]",
                "t_f* closed form [s]",
                "switch [s]",
                "two-phase [s]",
                "rel. error [-]",
                "collocation [s]",
                "rel. error [-]",
                "N* [samples]",
                "N* T [s]",
                "(N* T - t_f*) / T [samples]",
            ],
            rows,
        ),
        Block(
            "p",
            text=f"Collocation convergence over N = {fmt(conv['intervals'])} intervals: observed "
            f"order {fmt(conv['order'], 3)} [-] (per state {fmt(conv['order_per_state'], 3)} [-]).",
        ),
        *figure(figures, "fig02_trajectories"),
        *figure(figures, "fig03_saturation"),
        *figure(figures, "convergence"),
        *figure(figures, "collocation_switch"),
    ]


def zone(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show the printed and corrected construction with reasons."""
    z = res["zone"]
    rows = []
    for key in ("printed", "corrected", "corrected_lenient"):
        if key in z:
            v = z[key]
            rows.append(
                [
                    key.replace("_", " "),
                    v["omega0"],
                    v["x20_tilde"],
                    v["margin_mm_s"],
                    v["valid"],
                    v["degenerate"],
                    v["reason"],
                ]
            )
    blocks = [
        table(
            [
                "construction",
                "omega0 [mm/s]",
                "x20~ [mm/s]",
                "worst landing margin [mm/s]",
                "valid",
                "degenerate",
                "reason",
            ],
            rows,
        )
    ]
    blocks += figure(figures, "zone_geometry")
    for key in sorted(figures):
        if key.startswith(("fig04", "fig05", "fig06")):
            blocks += figure(figures, key)
    return blocks


def poles(res: dict[str, Any]) -> list[Block]:
    """Continuous and sampled poles, margins, the Lyapunov caveat."""
    rows = []
    for name, lp in res["poles"]["loops"].items():
        rows.append(
            [
                name,
                lp["gains"],
                lp["continuous_poles"],
                lp["continuous_zeta"],
                lp["sampled_moduli"],
                lp["gain_margin"],
                lp["phase_margin_deg"],
                lp["pole_mismatch"],
                lp["stable_sampled"],
                lp["lyapunov_conditions"],
            ]
        )
    ce = res["poles"]["lyapunov_counterexample"]
    scalars = {k: v for k, v in ce.items() if not isinstance(v, (Mapping, list, tuple))}
    return [
        table(
            [
                "loop",
                "gains (k1 or kp [1/s], k2 or kd [-])",
                "continuous poles (re, im) [rad/s]",
                "damping [-]",
                "sampled |z| [-]",
                "gain margin [-]",
                "phase margin [deg]",
                "|python-control - numpy| [-]",
                "sampled stable",
                "Section 5 conditions",
            ],
            rows,
        ),
        Block(
            "p",
            text="Section 5's conditions k1 > 0, 1 + k2 > 0 are a continuous-time "
            "statement; with sampling they do not imply stability: "
            + "; ".join(
                f"{k.replace('_', ' ')} = {_unit_from_name(k, v)}" for k, v in scalars.items()
            ),
        ),
    ]


def _unit_from_name(name: str, v: Any) -> str:
    """Show a value with the unit its key names (``_mm``, ``_s``, ``_deg``...)."""
    for suffix, unit in (
        ("_mm_s", "mm/s"),
        ("_mm", "mm"),
        ("_deg", "deg"),
        ("_s", "s"),
        ("_rad_s", "rad/s"),
        ("_percent", "%"),
    ):
        if name.endswith(suffix):
            return qty(v, unit)
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return qty(v, "-")
    return fmt(v)


#: Columns of the properties table: key, header with unit.
_PROPERTY_COLUMNS = (
    ("states", "states [count]"),
    ("stride_overs", "stride-overs [count]"),
    ("crossings_into_linear", "crossings into the linear zone [count]"),
    ("limit_cycles", "limit cycles [count]"),
    ("not_settled", "not settled [count]"),
    ("chattering", "chattering [count]"),
    ("overshoots", "overshoots [count]"),
    ("max_overshoot_mm", "max overshoot [mm]"),
    ("time_to_linear_max_s", "max time to linear zone [s]"),
    ("max_abs_u", "max |u| [mm/s]"),
)


def properties(res: dict[str, Any]) -> list[Block]:
    """Stride-overs, limit cycles, chattering, |u| over the grid."""
    rows = [
        [_law(law), *[p[k] for k, _ in _PROPERTY_COLUMNS]] for law, p in res["properties"].items()
    ]
    return [table(["law", *[h for _, h in _PROPERTY_COLUMNS]], rows)]


def claims(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Every claim: what is measured, paper value, value between samples and on the grid."""
    rows = []
    for c in res["claims"]:
        differs = not _same(c["measured"], c["measured_grid"])
        rows.append(
            [
                f"Sec. {c['section']}",
                c["signal"],
                c["claim"],
                measured_quantity(c),
                _claim_qty(c["paper_value"], c["unit"]),
                _claim_qty(c["measured"], c["unit"]),
                _claim_qty(c["measured_grid"], c["unit"]) if differs else "same",
                c["verdict"],
                c["verdict_grid"] or "n/a",
                c["detail"],
            ]
        )
    readings = []
    for c in res["claims"]:
        for r in c["readings"]:
            differs = not _same(r["measured"], r["measured_grid"])
            readings.append(
                [
                    c["id"],
                    r["label"],
                    _claim_qty(r["measured"], c["unit"]),
                    _claim_qty(r["measured_grid"], c["unit"]) if differs else "same",
                    r["verdict"],
                    r["verdict_grid"] or "n/a",
                    ", ".join(r["ties"] or []) or "none",
                ]
            )
    blocks = [
        Block(
            "p",
            text="'measured' is read on the exact trajectory between samples (the input is "
            "constant over a sample and the flow is closed form); where the value read on the "
            "2 ms sample grid differs it is shown next to it, with the verdict the same rule "
            "gives on the grid. Times are shown in ms.",
        ),
        table(
            [
                "paper section",
                "signal",
                "claim",
                "what is measured",
                "paper",
                "measured, between samples",
                "on the sample grid",
                "verdict",
                "verdict on the grid",
                "detail (primary reading)",
            ],
            rows,
        ),
        Block("p", text="Every reading of an ambiguous point is run and reported:"),
        table(
            [
                "claim",
                "reading",
                "measured",
                "on the sample grid",
                "verdict",
                "verdict on grid",
                "true ties",
            ],
            readings,
        ),
    ]
    resp = res["responses"]
    if resp:
        keys = (
            ("settling_2pct_s", "2 % settling"),
            ("settling_0p01mm_s", "0.01 mm settling"),
            ("rise_time_s", "10-90 % rise"),
            ("overshoot_mm", "overshoot"),
        )
        rows = []
        for law, by in resp.items():
            m = by["step"]
            cells = []
            for k, _ in keys:
                ex, gr = m[k], m[f"{k}_grid"]
                val = _ms(ex) if k.endswith("_s") else qty(ex, "mm")
                if gr is not None and not _same(ex, gr):
                    val += f" (grid {_ms(gr) if k.endswith('_s') else qty(gr, 'mm')})"
                cells.append(val)
            rows.append([_law(law), *cells])
        blocks += [
            Block(
                "p",
                text="Step response metrics under the primary reading, between samples "
                "(sample-grid value in parentheses where it differs):",
            ),
            table(["law", *[t for _, t in keys]], rows),
        ]
    for key in sorted(figures):
        if key.startswith(("fig07", "fig08", "fig09", "fig10", "fig11", "fig12", "fig13", "fig14")):
            blocks += figure(figures, key)
    return blocks


def sweep(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Settling time over t_f* and over N* T, per law, with percentiles."""
    sw = res["sweep"]
    rows = []
    for law, v in sw["laws"].items():
        ptf = v["percentiles_ratio_tf"] or {}
        pnt = v["percentiles_ratio_nt"] or {}
        rows.append(
            [
                _law(law),
                qty(100 * v["fraction_settled"], "%"),
                *[ptf[k] for k in ("p50", "p95", "p99", "max")],
                v["worst_state_tf"],
                *[pnt[k] for k in ("p50", "p95", "p99", "max")],
                v["worst_state_nt"],
            ]
        )
    blocks = [
        Block(
            "p",
            text=f"Grid of {sw['grid'][0]} x {sw['grid'][1]} initial states over the envelope, "
            f"horizon {sw['steps']} samples; settling time read between samples (0.01 mm band, "
            "staying there), divided by the continuous minimum time t_f* and by the sampled "
            "limit N* T (zonotope N*).",
        ),
        table(
            [
                "law",
                "settled [% of states]",
                "p50 t/t_f* [-]",
                "p95 t/t_f* [-]",
                "p99 t/t_f* [-]",
                "max t/t_f* [-]",
                "worst state [mm, mm/s]",
                "p50 t/(N* T) [-]",
                "p95 t/(N* T) [-]",
                "p99 t/(N* T) [-]",
                "max t/(N* T) [-]",
                "worst state [mm, mm/s]",
            ],
            rows,
        ),
    ]
    for key in sorted(figures):
        if key.startswith("sweep"):
            blocks += figure(figures, key)
    return blocks


# ------------------------------------------------------------------ proofs
_PROOF_WORDS = {
    "input-bound": "|u| <= w_max",
    "no-stride-over-strict": "no stride-over (strict: never beyond the w_max curve)",
    "no-stride-over-relaxed": "no stride-over (relaxed: the linear strip allowed)",
    "reach": "reaches the target ellipse within the certified bound",
}


def proofs(res: Any, figures: dict[str, str]) -> list[Block]:
    """Show what is proved for every initial state of the envelope, and what is not.

    Parameters
    ----------
    res : Results
        The results (``proofs``: per law the ``prove --json`` object).
    figures : dict
        Figure key -> relative path.

    Returns
    -------
    list of Block
    """
    pr = res["proofs"]
    blocks = [
        Block(
            "p",
            text="Proved over the continuum of initial states (|x1| <= position_range, "
            "|x2| <= w_max) with outward-rounded interval arithmetic and python-flint arb "
            "certificates (`ptoverify prove`): each property is proved, refuted with a "
            "certified counterexample, or unproven with the region where the proof fails. "
            "Coverage is the fraction of the envelope's area proved.",
        )
    ]
    rows = []
    for law, p in pr.items():
        for name, prop in p["properties"].items():
            region = prop["unproven_region"]
            where = (
                f"{region['cells']} cells in x1 {fmt(region['bounding_box'][0])} to "
                f"{fmt(region['bounding_box'][1])} mm, x2 {fmt(region['bounding_box'][2])} to "
                f"{fmt(region['bounding_box'][3])} mm/s"
                if region
                else "none"
            )
            rows.append(
                [
                    _law(law),
                    _PROOF_WORDS.get(name, name),
                    prop["status"],
                    qty(100 * prop["coverage"], "%"),
                    where,
                ]
            )
    blocks.append(table(["law", "property", "status", "coverage", "unproven where"], rows))
    rows = [
        [
            _law(law),
            f"{p['bound_samples']} samples" if p["bound_samples"] is not None else "n/a",
            f"{p['simulated_worst_samples']} samples"
            if p["simulated_worst_samples"] is not None
            else "n/a",
            f"{p['simulation_over_bound']} of {p['simulated_states']}",
            qty(p["suboptimality"]["certified_max_ratio_nt"], "-")
            + f" outside |x1| < {qty(p['suboptimality']['excluded_radius'], 'mm')}",
            str(p["cells"]),
        ]
        for law, p in pr.items()
    ]
    blocks.append(
        table(
            [
                "law",
                "certified worst samples to the ellipse",
                "simulated worst (same ellipse)",
                "simulated states over their cell's bound",
                "certified samples / N* over the envelope",
                "cells [count]",
            ],
            rows,
        )
    )
    for law in pr:
        blocks += figure(figures, f"proof_bound_{law}")
    return blocks


# ------------------------------------------------------------------ robustness
_PROP_WORDS = {
    "stride_overs": ("stride-overs", "count"),
    "limit_cycle_mm": ("limit-cycle amplitude", "mm"),
    "overshoot_mm": ("overshoot", "mm"),
    "settling_ratio_nt": ("settling / (N* T)", "-"),
}


def simulate_command(law: str, worst: dict[str, Any]) -> str:
    """Return the ``ptoverify simulate`` command line that reproduces a worst case.

    Parameters
    ----------
    law : str
        Law name.
    worst : dict
        ``state`` [mm, mm/s] and ``params`` of a ``robust`` worst case.

    Returns
    -------
    str
        The command (full float precision, so it reproduces exactly).

    Examples
    --------
    >>> simulate_command("pd", {"state": [1.0, -2.5], "params": {"a_ratio": 0.8}})
    'ptoverify simulate --law pd --x0 1.0 -2.5 --a-ratio 0.8'
    """
    flags = (
        ("a_ratio", "--a-ratio"),
        ("w_max_ratio", "--w-max-ratio"),
        ("delay_samples", "--delay"),
        ("position_quantum", "--quantum"),
        ("velocity_noise", "--velocity-noise"),
        ("seed", "--seed"),
    )
    x1, x2 = worst["state"]
    parts = ["ptoverify simulate", f"--law {law}", f"--x0 {float(x1)!r} {float(x2)!r}"]
    p = worst["params"] or {}
    parts += [f"{flag} {p[k]!r}" for k, flag in flags if k in p and p[k] is not None]
    return " ".join(parts)


def robustness(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show maps over the uncertainty box, margins, worst cases with reproducing commands.

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
    rob = res["robust"]
    if not rob:
        return [
            Block(
                "p",
                text="Not computed in this run (report --skip robust); "
                "`ptoverify robust` runs the study.",
            )
        ]
    box, st = rob["box"], rob["settings"]
    maps = rob["maps"]
    blocks = [
        Block(
            "p",
            text="Every law is built from the nominal configuration; only the simulated plant "
            "and the measurement change: true a / design a in "
            f"{fmt(box['a_ratio'])} [-], drive saturation / w_max in {fmt(box['w_max_ratio'])} "
            f"[-], computation delay {fmt(box['delay_samples'])} samples, encoder quantum "
            f"{qty(box['position_quantum'], 'mm')}, velocity noise {qty(box['velocity_noise'], 'mm/s')}. "
            f"Laws: {', '.join(_law(k) for k in maps['laws'])}. "
            f"Maps: {len(maps['a_ratio'])} x {len(maps['w_max_ratio'])} perturbations per delay, "
            f"{maps['states']} initial states each (settings: "
            f"{st['n1']} x {st['n2']} grid + {st['rest']} at rest, worst-case search "
            f"{st['search_iterations']} generations of {st['search_population']}; "
            "as `ptoverify robust` with this configuration).",
        )
    ]
    rows = []
    for law, m in rob["margins"].items():
        rows.append(
            [
                _law(law),
                ratio_interval(m["linear_loop_a_ratio_stable"])
                if m["linear_loop_a_ratio_stable"]
                else m["linear_loop_note"] or "n/a",
                ratio_interval(m["linear_loop_a_ratio_stable_delay1"])
                if m["linear_loop_a_ratio_stable_delay1"]
                else m["linear_loop_note_delay1"] or "n/a",
                ratio_interval(m["no_limit_cycle_a_ratio"])
                if m["no_limit_cycle_a_ratio"]
                else m["no_limit_cycle_note"] or "n/a",
            ]
        )
    best = rob["most_robust"]
    blocks += [
        Block(
            "p",
            text="Margins: the interval of a_true / a_design around 1 on which each "
            "property holds (endpoints to 1e-6 relative; 'beyond' where it reaches past the "
            "searched [0.1, 10]).",
        ),
        table(
            [
                "law",
                "linear loop stable",
                "linear loop stable, one-sample delay",
                "no limit cycle from any grid state",
            ],
            rows,
        ),
    ]
    if best["law"]:
        blocks.append(
            Block(
                "p",
                text=f"Most robust linear loop: {_law(best['law'])} (ln(hi / lo) of its "
                "stable interval: "
                + ", ".join(f"{_law(k)} {fmt(v)} [-]" for k, v in best["log_width"].items())
                + ").",
            )
        )
    blocks += figure(figures, "robust_limit_cycles") + figure(figures, "robust_settling_nt")
    wrows, cmds = [], []
    for law, by in rob["worst"].items():
        for prop, w in by.items():
            words, unit = _PROP_WORDS.get(prop, (prop, "-"))
            p = w["params"] or {}
            wrows.append(
                [
                    _law(law),
                    words,
                    "unbounded (never settles)" if w["grid_unbounded"] else qty(w["grid"], unit),
                    "unbounded (never settles)" if w["unbounded"] else qty(w["searched"], unit),
                    f"({fmt(w['state'][0])} mm, {fmt(w['state'][1])} mm/s)"
                    if w["state"]
                    else "n/a",
                    f"a ratio {fmt(p['a_ratio'])} [-], w_max ratio {fmt(p['w_max_ratio'])} "
                    f"[-], delay {fmt(p['delay_samples'])} samples",
                ]
            )
            bad = (
                w["searched"] is not None
                and w["searched"] > 0
                and prop in ("stride_overs", "limit_cycle_mm")
            )
            if bad and w["state"]:
                cmds.append(
                    f"# {_law(law)}: {words} {qty(w['searched'], unit)}\n"
                    + simulate_command(law, w)
                )
    blocks += [
        Block(
            "p",
            text="Worst cases: the grid's worst cell, then a seeded search over (initial "
            "state x perturbation) started from it; the searched value is never below the grid's.",
        ),
        table(["law", "property", "grid worst", "searched worst", "state", "perturbation"], wrows),
    ]
    if cmds:
        blocks += [
            Block(
                "p",
                text="Counterexamples (stride-over or limit cycle), reproducible "
                "with the paper's configuration (add --config as for this report):",
            ),
            code("\n".join(cmds)),
        ]
    return blocks


# ------------------------------------------------------------------ tuning
_GAIN_UNITS = {"kp": "1/s", "kd": "-", "d": "mm", "k1": "1/s", "k2": "-"}


def _gains(g: dict[str, float]) -> str:
    return "; ".join(f"{k} = {qty(v, _GAIN_UNITS.get(k, '-'))}" for k, v in g.items())


def tuning(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show PD and PTO at their best tuning under shared overshoot bounds.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part); ``tuning`` is
        :func:`ptoverify.studies.claims.fair_comparison`.
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of Block
    """
    t = res["tuning"]
    if not t:
        return [
            Block(
                "p",
                text="Not computed in this run (report --skip tuning); "
                "`ptoverify tune --law pd|pto` runs the search.",
            )
        ]
    fl, bud = t["floor"], t["budget"]
    bounds = "; ".join(
        f"{t['bound_meaning'][k]}: {qty(v, 'mm')}" for k, v in t["bounds_mm"].items()
    )
    blocks = [
        Block(
            "p",
            text="Is the paper's verdict an artefact of its gains? Each law minimizes its 2 % "
            "settling time of the step (between samples) under each shared overshoot bound ("
            f"{bounds}), with a stable sampled linear loop and, for the PTO, no stride-over and "
            "no limit cycle over the gate's grid (omega0 from the corrected construction for its "
            f"d). Differential evolution, seed {bud['seed']}, {bud['maxiter']} "
            f"generations, population factor {bud['popsize']} ({t['evaluations']} "
            "candidates; `ptoverify tune` searches longer). The floor of any 2 % settling time: "
            f"the least 2 % band entry {_ms(fl['band_entry_s'])}; the exact arrival needs "
            f"t_f* = {_ms(fl['tf_s'])} (continuous) and N* T = {_ms(fl['nt_s'])} (sampled).",
        )
    ]
    rows = []
    for law, m in t["paper"].items():
        rows.append(
            [
                "paper's gains",
                _law(law),
                "as configured",
                _ms(m["settling_2pct_s"]),
                qty(m["overshoot_mm"], "mm"),
                _ms(m["rise_time_s"]),
                _ms(m["settling_0p01mm_s"]),
                qty(m["worst_ratio_nt"], "-"),
            ]
        )
    for name, by in t["best"].items():
        for law, b in by.items():
            rows.append(
                [
                    f"best, overshoot <= {qty(t['bounds_mm'][name], 'mm')}",
                    _law(law),
                    _gains(b["gains"]),
                    _ms(b["settling_2pct_s"]),
                    qty(b["overshoot_mm"], "mm"),
                    _ms(b["rise_time_s"]),
                    _ms(b["settling_0p01mm_s"]),
                    qty(b["worst_ratio_nt"], "-"),
                ]
            )
    blocks += [
        table(
            [
                "tuning",
                "law",
                "gains",
                "2 % settling",
                "overshoot",
                "10-90 % rise",
                "0.01 mm settling",
                "worst settling / (N* T) over the envelope",
            ],
            rows,
        ),
        *figure(figures, "tuning_pareto"),
        Block("p", text="The paper's PD-vs-PTO claims judged at the best tuning of both laws:"),
        table(
            ["claim", "verdict at best tuning", "measured"],
            [[c["claim"], c["verdict"], c["sentence"]] for c in t["claims"]],
        ),
    ]
    return blocks


# ------------------------------------------------------------------ environment
#: Units of the configuration keys.
CONFIG_UNITS = {
    "plant.bandwidth_hz": "Hz",
    "plant.a": "rad/s",
    "plant.position_range": "mm",
    "plant.sample_time": "s",
    "plant.w_max": "mm/s",
    "pd.kp": "1/s",
    "pd.kd": "-",
    "pto.d": "mm",
    "pto.k1": "1/s",
    "pto.k2": "-",
    "robustness.a_ratio": "-",
    "robustness.w_max_ratio": "-",
    "robustness.delay_samples": "samples",
    "robustness.position_quantum": "mm",
    "robustness.velocity_noise": "mm/s",
    "robustness.seed": "-",
    "robustness.settling_ratio_limit": "-",
}


def environment(res: dict[str, Any]) -> list[Block]:
    """Versions, configuration (with units), commit, date."""
    env = res["environment"]
    rows = [[k, v] for k, v in env.items() if k != "config"]
    rows.append(["generated", res["meta"]["generated"]])
    cfg_rows = []
    for sec, vals in env["config"].items():
        for k, v in vals.items() if isinstance(vals, Mapping) else [("", vals)]:
            key = f"{sec}.{k}" if k else sec
            unit = CONFIG_UNITS.get(key)
            if isinstance(v, (int, float, list, tuple)) and not isinstance(v, bool):
                cell = qty(v, unit) if unit is not None else f"{fmt(v)} (unit not recorded)"
            else:
                cell = fmt(v)
            cfg_rows.append([key, cell])
    return [table(["item", "value"], rows), table(["configuration key", "value"], cfg_rows)]
