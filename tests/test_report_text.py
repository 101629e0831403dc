"""The report's words: no internal ids or config jargon in prose, counts in the right number,
law display names in figure titles, equations that scroll inside their cells, and each
erratum's own counterexample (a repeated one is said, never copied)."""

import json
import re
from pathlib import Path

import pytest

from ptoverify.report.render import CSS, render_html
from ptoverify.report.words import claim_quantity, claim_title, law_name, plain, plural

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def committed():
    """The sections rebuilt from the committed report's results.json and records, with the
    Section 6 claims computed afresh."""
    import derivations
    from ptoverify.config import paper_config
    from ptoverify.report.collect import build_sections, results_view
    from ptoverify.studies.claims import evaluate_claims

    folder = ROOT / "reports" / "paper"
    data = json.loads((folder / "results.json").read_text())
    data.setdefault("charts", None)
    # the claims' sentences as this code writes them (the committed ones may be older)
    data["claims"] = [c.to_json() for c in evaluate_claims(paper_config())]
    records = [derivations.EquationRecord.from_json(r) for r in data["derivations"]]
    figures = {Path(f).stem: f for f in data["meta"]["figures"]}
    return data, build_sections(results_view(data), figures, records)


def _texts(sections):
    """Every paragraph, raw text and table cell of the sections, with its section's anchor."""
    for anchor, _title, blocks in sections:
        for b in blocks:
            if b.kind == "raw" and b.html.startswith("<pre>"):
                continue  # a command line to copy: the CLI's own names
            if b.kind in ("p", "raw", "img"):
                yield anchor, b.text
            elif b.kind == "table":
                yield anchor, " | ".join(b.headers)
                for row in b.rows:
                    yield anchor, " | ".join(row)


# ---------------------------------------------------------------- plurals and names
@pytest.mark.parametrize(
    ("count", "noun", "want"),
    [
        (1, "sample", "1 sample"),
        (1.0, "sign reversal", "1 sign reversal"),
        (0, "sample", "0 samples"),
        (2, "stride-over", "2 stride-overs"),
        (15, "sample", "15 samples"),
        (0.5, "sample", "0.5 samples"),
    ],
)
def test_plural_agrees_with_its_count(count, noun, want):
    assert plural(count, noun) == want


def test_a_negative_more_reads_as_less_and_the_number_says_what_it_is():
    from ptoverify.report.words import claim_measured_words

    def claim(name, v, unit):
        return {"measured": v, "unit": unit, "readings": [{"values": {"x_s": 9.0, name: v}}]}

    assert claim_measured_words(claim("pd_more_percent", -36.41, "%")) == "PD 36.41 % less"
    assert claim_measured_words(claim("pd_more_percent", 31.0, "%")) == "PD 31 % more"
    assert claim_measured_words(claim("phase_delay_deg", 0.38, "deg")) == "phase delay 0.38 deg"
    assert claim_measured_words(claim("error_reversals", 1.0, "reversals")) == "1 sign reversal"
    assert claim_measured_words({"measured": None, "unit": "s", "readings": []}) == "n/a"


def test_claim_quantity_counts_in_words_and_times_in_ms():
    assert claim_quantity(1.0, "reversals") == "1 sign reversal"
    assert claim_quantity(3.0, "reversals") == "3 sign reversals"
    assert claim_quantity(0.01614, "s") == "16.14 ms"


def test_every_law_has_one_display_name_used_by_the_plots():
    from ptoverify.report.plots.charts import LAW_COLOURS
    from ptoverify.report.plots.common import STYLE

    for law, style in STYLE.items():
        assert style["label"] == law_name(law)
    for law, (_colour, label) in LAW_COLOURS.items():
        assert label == law_name(law)
    assert law_name("pto-printed") == "PTO as printed" and law_name("mine") == "mine"


def test_config_jargon_reads_in_words():
    assert "[" not in plain("No limit cycle anywhere in the [robustness] box (true a)")
    assert plain("limit from [robustness] settling_ratio_limit").endswith("settling ratio limit")


def test_plot_titles_name_the_law_and_count_in_the_right_number():
    """A panel of the robustness maps for the printed PTO at one sample of delay."""
    from ptoverify.report.plots import plot_robust_map

    ars, wrs = [0.8, 1.0], [0.9, 1.0]
    cells = [
        {"a_ratio": a, "w_max_ratio": w, "delay_samples": 1, "limit_cycle_states": 1}
        for w in wrs
        for a in ars
    ]
    maps = {
        "a_ratio": ars,
        "w_max_ratio": wrs,
        "delay_samples": [1],
        "laws": {"pto-printed": cells},
    }
    mesh = plot_robust_map(maps, "pto-printed", "limit_cycle_states", 1)["map"]
    title = mesh.axes.get_title()
    assert title == "PTO as printed, a delay of 1 sample", title


# ---------------------------------------------------------------- the committed results
#: Words a reader of the report should never meet.
JARGON = (
    r"\[robustness\]",
    r"true ties",
    r"\b1 (samples|reversals|sign reversals|stride-overs|readings|gates)\b",
    r"delay 1 samples",
    r"\bpto-printed\b",
    r"\bposition_range\b",
    r"see the settling definitions",
)


@pytest.mark.slow
def test_no_internal_ids_jargon_or_wrong_plurals_in_the_report(committed):
    data, sections = committed
    ids = [c["id"] for c in data["claims"]]
    bad = []
    for anchor, text in _texts(sections):
        if anchor == "environment":  # the configuration's own keys, shown as such
            continue
        bare = re.sub(r"\]\([^)]*\)|traces/[\w.-]+|figures/[\w.-]+|`[^`]*`", "", text)
        bad += [f"{anchor}: {p!r} in {text[:120]!r}" for p in JARGON if re.search(p, bare)]
        bad += [f"{anchor}: claim id {i!r}" for i in ids if re.search(rf"\b{re.escape(i)}\b", bare)]
    assert not bad, "\n".join(bad[:20])


@pytest.mark.slow
def test_a_claim_that_depends_names_both_sides(committed):
    from ptoverify.report.collect import results_view
    from ptoverify.report.standing import reviewer_rows

    data, _ = committed
    for claim, standing, cond, *_ in reviewer_rows(results_view(data)):
        if standing == "depends":
            assert cond.startswith("holds with ") and "; fails with " in cond, (claim, cond)


@pytest.mark.slow
def test_one_standing_word_per_claim_in_the_verdict_and_the_summary(committed):
    """The summary's claims table says holds / fails / depends as the verdict table does,
    never a second vocabulary (ambiguous, not reproduced) for the same claim; the verdict's
    measured numbers never read as a negative 'more'."""
    data, sections = committed
    by = {a: blocks for a, _t, blocks in sections}
    tables = lambda a: [b for b in by[a] if b.kind == "table"]  # noqa: E731
    reviewer = next(t for t in tables("verdict") if t.headers[1] == "standing")
    verdict = {row[0]: row[1] for row in reviewer.rows}
    summary = next(t for t in tables("summary") if t.headers[0] == "claim")
    assert summary.headers[1] == "standing"
    titles = {c["claim"]: claim_title(c) for c in data["claims"]}
    assert summary.rows
    for row in summary.rows:
        assert row[1] in ("fails", "depends"), row
        assert verdict[titles[row[0]]] == row[1], (row[0], row[1], verdict[titles[row[0]]])
    assert not [r for r in reviewer.rows if r[4].startswith("-")], reviewer.rows


@pytest.mark.slow
def test_the_verdict_names_a_settling_band_not_where_the_suite_uses_it(committed):
    from ptoverify.sim.settling import DEFINITIONS

    _data, sections = committed
    every = [
        f"{a}: {t[:80]}"
        for a, t in _texts(sections)
        for d in DEFINITIONS.values()
        if d.description in t
    ]
    assert not every, every
    texts = [t for a, t in _texts(sections) if a == "verdict"]
    assert any("settled: abs(e) <= 2 % of the reference's size" in t for t in texts)


@pytest.mark.slow
def test_the_robustness_section_says_why_its_worst_settling_differs_from_the_sweep(committed):
    """One quantity, two values (the nominal robustness cell, the sweep's worst): the text
    gives both and says each is the worst of its own grid."""
    from ptoverify.report.render import fmt

    data, sections = committed
    texts = " ".join(t for a, t in _texts(sections) if a == "robustness")
    worst = data["sweep"]["laws"]["pto"]["worst_ratio_nt"]
    nominal = next(
        c["settling_ratio_nt"]["max"]
        for c in data["robust"]["maps"]["laws"]["pto"]
        if (c["a_ratio"], c["w_max_ratio"], c["delay_samples"]) == (1, 1, 0)
    )
    assert nominal != worst
    assert f"PTO (corrected) {fmt(nominal)} from" in texts and f"{fmt(worst)} from" in texts
    assert "each is the worst of its own grid" in texts


# ---------------------------------------------------------------- equations
def test_equations_scroll_inside_their_cells():
    """Every equation sits in a div.eq that scrolls sideways; the equation tables are fixed to
    the page width, header and body cells alike."""
    assert re.search(r"\.eq\{[^}]*overflow-x:auto", CSS)
    assert re.search(
        r"table\.derivations,\.erratum-block table\.forms\{table-layout:fixed;width:100%\}", CSS
    )
    assert "table.derivations th,table.derivations td" in CSS


def test_derivation_and_errata_cells_wrap_each_equation():
    import derivations
    from ptoverify.report.sections import derivations as derivation_section
    from ptoverify.report.sections import errata

    data = json.loads((ROOT / "reports" / "paper" / "results.json").read_text())
    records = [derivations.EquationRecord.from_json(r) for r in data["derivations"][:12]]
    html = "".join(b.html for b in derivation_section({}, records) if b.kind == "raw")
    cells = re.findall(r"<td><div class=\"eq\">", html)
    assert len(cells) == 2 * len(records)
    err = [r for r in data["derivations"] if r["verdict"] == "erratum"]
    recs = [derivations.EquationRecord.from_json(r) for r in err]
    page = render_html([("errata", "Errata", errata({"derivations": err}, recs))], "t")
    assert page.count('<table class="forms">') == len(err)
    assert "<td><math" not in page, "an equation outside its scrolling wrapper"


def test_the_tilde_is_drawn_whether_or_not_the_mathml_was_rendered_beforehand():
    """Eq. (15)'s x~1 draws as x with a tilde, never as 'tx1', on either path."""
    import derivations
    from ptoverify.report.sections import derivations as derivation_section
    from ptoverify.report.sections import render_records

    data = json.loads((ROOT / "reports" / "paper" / "results.json").read_text())
    recs = [
        derivations.EquationRecord.from_json(r)
        for r in data["derivations"]
        if r["id"] in ("15", "17")
    ]
    for rendered in (None, render_records(recs)):
        page = "".join(b.html for b in derivation_section({}, recs, rendered) if b.kind == "raw")
        assert "<mi>tx</mi>" not in page
        assert page.count('<mover accent="true"><mi>x</mi><mo>~</mo></mover>') >= 2


# ---------------------------------------------------------------- errata counterexamples
def test_a_repeated_counterexample_is_said_not_copied():
    from ptoverify.report.sections import errata
    from ptoverify.report.sections.equations import same_counterexample

    ce = {
        "point": {"a": 100.0, "T": 0.002, "omega_m": 300.0, "x2": -10.0},
        "printed": [2.0],
        "derived": [0.0],
    }
    other = {**ce, "printed": [3.0]}
    recs = [
        {"id": "18", "counterexample": ce},
        {"id": "19", "counterexample": dict(ce)},
        {"id": "20", "counterexample": other},
    ]
    assert same_counterexample(recs) == {"19": "18"}
    full = [
        {
            **r,
            "verdict": "erratum",
            "note": "n",
            "printed": "x1",
            "derived": "x2",
            "corrected": None,
            "inherits": [],
        }
        for r in recs
    ]
    blocks = errata({"derivations": full}, [])
    text = "\n".join(b.text for b in blocks)
    assert "No counterexample of its own: the one computed for it is eq. (18)'s" in text
    assert sum(b.kind == "table" for b in blocks) == 2, "18 and 20 show theirs; 19 does not repeat"


def test_eq19_has_a_counterexample_of_its_own():
    """Eq. (19)'s counterexample is computed for (19): the printed l~1 at the image of a state
    of l1 after one sample under -omega_m (the sample rule (1) concerns), not (18)'s."""
    from derivations.section4_image import records

    by = {r.id: r for r in records()}
    c18, c19 = by["18"].counterexample, by["19"].counterexample
    assert by["19"].verdict == "erratum" and c19 is not None
    assert c19 != c18 and "image_under_minus_omega_m" in c19
    assert c19["printed"] != c18["printed"] and abs(c19["printed"][0]) > 1.0


def test_a_form_with_words_draws_its_formula_as_mathematics():
    """Eq. (18)'s derived form, a formula followed by where it holds, is MathML (the words as
    text), in the derivations table as in its erratum; no form is shown as code."""
    import derivations
    from ptoverify.report.sections import derivations as derivation_section
    from ptoverify.report.sections import errata

    data = json.loads((ROOT / "reports" / "paper" / "results.json").read_text())
    rec = next(r for r in data["derivations"] if r["id"] == "18")
    assert " = 0 on " in rec["derived"], "the form this test is about changed"
    r18 = derivations.EquationRecord.from_json(rec)
    ml = r18.to_mathml()["derived"]
    assert "<mo>=</mo><mn>0</mn></mtd>" in ml and "<mtext>on the image of l1" in ml
    assert "*" not in re.sub(r"<mtext>.*?</mtext>", "", ml), "source text left in the MathML"
    table = "".join(b.html for b in derivation_section({}, [r18]) if b.kind == "raw")
    row = re.search(r'<tr id="eq-18".*?</tr>', table).group(0)
    assert row.count("<math") == 2 and "<code>" not in row
    page = render_html([("e", "E", errata({"derivations": [rec]}, [r18]))], "t")
    assert "<code>" not in page
    # a form that is not one formula (a chain with a side condition) stays plain, readable text
    from ptoverify.report.sections.equations import readable

    form = "x_l1(x2) <= x1 <= x_l1*(x2), x2 < 0"  # eq. (36)'s zone
    chain = derivations.EquationRecord.from_json({**rec, "derived": form})
    assert chain.to_mathml()["derived"] == ""
    assert readable(chain.derived) == "x_l1(x2) \u2264 x1 \u2264 x_l1*(x2), x2 < 0"
