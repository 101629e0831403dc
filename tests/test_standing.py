"""The verdict table and the headline findings: each flips when its evidence flips.

The base is the committed report's ``results.json`` (the paper's defaults); each
test changes the one piece of evidence a finding rests on, as another
configuration would, and checks that the sentence follows it.
"""

import copy
import json
from pathlib import Path

import pytest

from ptoverify.report.collect import results_view
from ptoverify.report.sections import front
from ptoverify.report.standing import adoption, claim_standing, engineer_rows, reviewer_rows

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def base():
    data = json.loads((ROOT / "reports" / "paper" / "results.json").read_text())
    # a committed report from before the charts stage reads as one that skipped it
    data.setdefault("charts", None)
    return data


def _rows(data):
    return {r[0]: r for r in engineer_rows(results_view(data))}


def _reading(a, verdict, band=0.02):
    return {"reading": {"a": a, "band": band, "pto": "corrected"}, "verdict": verdict}


def test_claim_standing_names_the_deciding_reading():
    claim = {"readings": [_reading("2pi*f", "not reproduced"), _reading("f", "reproduced")]}
    assert claim_standing(claim) == (
        "depends",
        "holds with a = f (the bandwidth read as rad/s); "
        "fails with a = 2 pi f (the bandwidth read in Hz)",
    )
    # with the configuration's bandwidth, each reading of a is named by its value
    assert claim_standing(claim, 30.0)[1] == (
        "holds with a = 30 rad/s (30 Hz read as rad/s); fails with a = 2 pi x 30 Hz = 188.5 rad/s"
    )
    claim["readings"][0]["verdict"] = "reproduced"
    assert claim_standing(claim)[0] == "holds"
    for r in claim["readings"]:
        r["verdict"] = "not reproduced"
    assert claim_standing(claim) == ("fails", "under all 2 readings tried")


def test_claim_standing_names_two_dimensions_when_no_single_one_decides():
    """Verdicts decided by a and the band together: the condition names both, per side."""
    rs_ = [
        _reading("2pi*f", "reproduced", 0.02),
        _reading("2pi*f", "not reproduced", 0.05),
        _reading("f", "not reproduced", 0.02),
        _reading("f", "reproduced", 0.05),
    ]
    standing, cond = claim_standing({"readings": rs_})
    assert standing == "depends"
    holds, fails = cond.split("; ")
    assert holds == (
        "holds with (a = 2 pi f (the bandwidth read in Hz) and the 2 % band) or "
        "(a = f (the bandwidth read as rad/s) and the 5 % band)"
    )
    assert fails == (
        "fails with (a = 2 pi f (the bandwidth read in Hz) and the 5 % band) or "
        "(a = f (the bandwidth read as rad/s) and the 2 % band)"
    )


def test_claim_standing_leaves_out_a_dimension_that_does_not_matter_on_one_side():
    """Only a = 2 pi f with the 2 % band holds; each failing alternative leaves one
    dimension out (every value of it fails there)."""
    rs_ = [
        _reading("2pi*f", "reproduced", 0.02),
        _reading("2pi*f", "not reproduced", 0.05),
        _reading("f", "not reproduced", 0.02),
        _reading("f", "not reproduced", 0.05),
    ]
    cond = claim_standing({"readings": rs_})[1]
    assert cond.startswith("holds with a = 2 pi f (the bandwidth read in Hz) and the 2 % band;")
    fails = cond.split("; ")[1].removeprefix("fails with ").split(" or ")
    assert len(fails) == 2 and all(" and " not in f for f in fails), cond


@pytest.mark.parametrize("seed", range(20))
def test_claim_standing_condition_reproduces_every_verdict(seed):
    """Random verdicts over a 2 x 3 x 2 reading grid: every reading matches exactly one side
    of the condition, the side of its own verdict (the condition is computed, never typed)."""
    import random

    from ptoverify.report.standing_claims import reading_words

    rng = random.Random(seed)
    rs_ = [
        {
            "reading": {"a": a, "tracking": tr, "pto": p},
            "verdict": rng.choice(["reproduced", "not reproduced"]),
        }
        for a in ("2pi*f", "f")
        for tr in ("feed-forward", "none", "error")
        for p in ("corrected", "printed")
    ]
    standing, cond = claim_standing({"readings": rs_})
    if standing != "depends":
        return
    holds, fails = (side.split(" with ", 1)[1] for side in cond.split("; "))

    def alternatives(side):
        alts = side.split(" or ")
        return [(a[1:-1] if a.startswith("(") else a).split(" and ") for a in alts]

    for r in rs_:
        words = {reading_words(d, v) for d, v in r["reading"].items()}
        in_holds = any(set(alt) <= words for alt in alternatives(holds))
        in_fails = any(set(alt) <= words for alt in alternatives(fails))
        assert in_holds == (r["verdict"] == "reproduced") and in_fails != in_holds, (r, cond)


def test_reviewer_table_has_every_claim(base):
    rows = reviewer_rows(results_view(base))
    assert len(rows) == len(base["claims"])
    assert {r[1] for r in rows} <= {"holds", "fails", "depends"}


def test_invalid_corrected_zone_flips_adoption(base):
    data = copy.deepcopy(base)
    assert adoption(results_view(data)).startswith("Adopt")
    data["zone"]["corrected"]["valid"] = False
    assert adoption(results_view(data)).startswith("Do not adopt")


def test_tuned_comparison_flips_with_the_tuned_times(base):
    data = copy.deepcopy(base)
    T = data["environment"]["config"]["plant"]["sample_time"]
    for by in data["tuning"]["best"].values():
        by["pto"]["settling_2pct_s"] = by["pd"]["settling_2pct_s"] - 3 * T
    assert _rows(data)["At each law's best tuning (same overshoot bound)?"][1] == "beats PD"
    for by in data["tuning"]["best"].values():
        by["pto"]["settling_2pct_s"] = by["pd"]["settling_2pct_s"] + 3 * T
    assert _rows(data)["At each law's best tuning (same overshoot bound)?"][1] == "loses to PD"


def test_delay_row_and_gate_finding_follow_the_delay_margin(base):
    data = copy.deepcopy(base)
    m = data["robust"]["margins"]["pto"]
    m["linear_loop_a_ratio_stable_delay1"] = None
    q = "Tolerates a one-sample computation delay (paper's gains)?"
    assert _rows(data)[q][1].startswith("no")
    gates = front._finding_gates(results_view(data))[0]
    assert "with one sample of computation delay the PTO's linear zone is unstable" in gates
    m["linear_loop_a_ratio_stable_delay1"] = [0.5, 1.2]
    assert _rows(data)[q][1] == "yes"
    assert "delay" not in front._finding_gates(results_view(data))[0]
    assert "needs delay compensation" not in adoption(results_view(data))


def test_settling_finding_names_who_settles_first_under_each_reading(base):
    data = copy.deepcopy(base)
    text = front._finding_settling(results_view(data))[0]
    c = next(c for c in data["claims"] if c["id"] == "step-pd-31-percent")
    prim = next(
        r
        for r in c["readings"]
        if r["reading"]["a"] == "2pi*f"
        and r["reading"]["band"] == 0.02
        and r["reading"]["pto"] == "corrected"
        and r["reading"]["gains"] is None
    )
    v = prim["values"]
    first = "PD settles first" if v["settling_pd_s"] < v["settling_pto_s"] else "PTO settles first"
    assert f"188.5 rad/s {first}" in text.replace("the corrected PTO", "PTO")
    v["settling_pd_s"], v["settling_pto_s"] = v["settling_pto_s"], v["settling_pd_s"]
    flipped = front._finding_settling(results_view(data))[0].replace("the corrected PTO", "PTO")
    other = "PTO settles first" if first == "PD settles first" else "PD settles first"
    assert f"188.5 rad/s {other}" in flipped


def test_claims_finding_says_more_or_less(base):
    data = copy.deepcopy(base)
    c = next(c for c in data["claims"] if c["id"] == "step-pd-31-percent")
    c["measured"] = -20.0
    assert "needing 20 % less" in front._finding_claims(results_view(data))[0]
    c["measured"] = 25.0
    assert "needing 25 % more" in front._finding_claims(results_view(data))[0]


def test_errata_finding_counts_only_changed_equations(base):
    data = copy.deepcopy(base)
    first = next(r for r in data["derivations"] if r["verdict"] == "erratum")
    first["inherits"] = ["17: unchanged for the map", "18: changes", "20-27: change"]
    text = front._finding_errata(results_view(data))[0]
    assert "changes 2 downstream equation groups (18; 20-27)" in text


# ---------------------------------------------------------------- the baselines' row
def _versus(T, diffs_by_reading, infeasible=()):
    """A ``tuning.versus`` block: the PTO's settling minus each law's, per reading.

    Settling times are built from the differences (PTO at 20 ms); ``infeasible``
    names (reading, law) pairs whose tuning found no gains.
    """
    readings = []
    for rd, diffs in diffs_by_reading.items():
        pto_t = 0.02
        laws = [
            {
                "law": "pto",
                "settling_s": pto_t,
                "ratio_nt": pto_t / 0.026,
                "ratio_tf": pto_t / 0.024,
                "infeasible": "",
                "delay_margin_samples": 0,
            }
        ]
        minus = {}
        for law, d in diffs.items():
            bad = (rd, law) in infeasible
            t = None if bad else pto_t - d
            laws.append(
                {
                    "law": law,
                    "settling_s": t,
                    "ratio_nt": None if bad else t / 0.026,
                    "ratio_tf": None if bad else t / 0.024,
                    "infeasible": "tune: no gains" if bad else "",
                    "delay_margin_samples": None if bad else 1,
                }
            )
            minus[law] = None if bad else d
        readings.append(
            {
                "reading": rd,
                "a": 188.5,
                "sample_time": T,
                "bound_mm": 0.0,
                "nt_s": 0.026,
                "tf_s": 0.024,
                "laws": laws,
                "pto_minus": minus,
            }
        )
    return {
        "settling": "2pct",
        "settling_description": "2 % band",
        "bound": "pto-paper",
        "readings": readings,
    }


def test_versus_row_flips_with_each_difference(base):
    from ptoverify.report.standing import VERSUS_QUESTION

    data = copy.deepcopy(base)
    T = data["environment"]["config"]["plant"]["sample_time"]
    laws = ("pd", "ptos", "cascade-p")
    data["tuning"]["versus"] = _versus(T, {"2pi": dict.fromkeys(laws, -3 * T)})
    row = _rows(data)[VERSUS_QUESTION]
    assert "beats PD by" in row[1] and "beats PTOS by" in row[1] and "beats cascade P" in row[1]
    assert "loses" not in adoption(results_view(data))
    # the PTO slower than PTOS by 3 samples: that verdict, and only it, flips
    data["tuning"]["versus"] = _versus(
        T, {"2pi": {"pd": -3 * T, "ptos": 3 * T, "cascade-p": -3 * T}}
    )
    row = _rows(data)[VERSUS_QUESTION]
    assert "loses to PTOS by" in row[1] and "beats PD by" in row[1]
    assert "loses to PTOS" in adoption(results_view(data))
    assert adoption(results_view(data)).startswith("Adopt only with care")
    # within one sample: a tie
    data["tuning"]["versus"] = _versus(T, {"2pi": dict.fromkeys(laws, 0.5 * T)})
    assert _rows(data)[VERSUS_QUESTION][1].count("ties") == 3


def test_versus_row_names_each_reading_and_infeasible_tunings(base):
    from ptoverify.report.standing import VERSUS_QUESTION

    data = copy.deepcopy(base)
    T = data["environment"]["config"]["plant"]["sample_time"]
    data["tuning"]["versus"] = _versus(
        T,
        {"2pi": {"pd": 2 * T, "cascade-p": -9 * T}, "hz": {"pd": -2 * T, "cascade-p": 0.0}},
        infeasible={("hz", "cascade-p")},
    )
    answer = _rows(data)[VERSUS_QUESTION][1]
    two_pi, hz = answer.split("; ")
    assert two_pi.startswith("a = 2 pi x 30 Hz = 188.5 rad/s") and "loses to PD" in two_pi
    assert hz.startswith("a = 30 rad/s (30 Hz read as rad/s)") and "beats PD" in hz
    assert "no cascade P gains meet the constraints" in hz
    evidence = _rows(data)[VERSUS_QUESTION][2]
    assert (
        "cascade P no tuning" in evidence
        and "settled: abs(e) <= 2 % of the reference's size" in evidence
    )
    assert "PTO (corrected) 20 ms (0.7692 N*T, 0.8333 t_f*)" in evidence  # 20 / 26, 20 / 24


def test_versus_row_with_one_reading_names_the_configured_a(base):
    """A configuration given in rad/s has one reading: the row names its a, not a reading."""
    from ptoverify.report.standing import VERSUS_QUESTION

    data = copy.deepcopy(base)
    T = data["environment"]["config"]["plant"]["sample_time"]
    data["tuning"]["versus"] = _versus(T, {"2pi": {"pd": -3 * T}})
    data["tuning"]["versus"]["readings"][0]["a"] = 123.0
    answer = _rows(data)[VERSUS_QUESTION][1]
    assert answer.startswith("a = 123 rad/s (the configuration's): beats PD")
    data["tuning"]["versus"] = _versus(T, {"2pi": {"pd": -3 * T}, "hz": {"pd": 3 * T}})
    assert _rows(data)[VERSUS_QUESTION][1].startswith("a = 2 pi x 30 Hz")


def test_versus_row_says_when_tuning_was_skipped(base):
    from ptoverify.report.standing import VERSUS_QUESTION

    data = copy.deepcopy(base)
    data["tuning"] = None
    assert _rows(data)[VERSUS_QUESTION][1].startswith("not compared")


def test_tuned_delay_row_follows_the_tuned_loops_margins(base):
    data = copy.deepcopy(base)
    q = "Do the tuned gains tolerate a one-sample computation delay?"
    laws = data["tuning"]["versus"]["readings"][0]["laws"]
    for x in laws:
        x["delay_margin_samples"] = 2
    assert _rows(data)[q][1].startswith("yes")
    laws[0]["delay_margin_samples"] = 0
    answer = _rows(data)[q][1]
    assert answer.startswith("no: ") and "PTO" in answer
    laws[0]["delay_margin_samples"] = -1
    assert "unstable even without delay" in _rows(data)[q][2]


# ---------------------------------------------------------------- one tie rule
@pytest.mark.parametrize("samples", [-2.5, -1.01, -0.99, -0.5, 0.0, 0.3, 0.99, 1.01, 3.0])
def test_claims_verdict_table_and_headline_share_one_tie_rule(base, samples):
    """The PTO's time minus PD's, in samples: the claims' comparison (a claim of a quicker
    PTO), the verdict table's and the baselines' row, and the headline all decide beats /
    ties / loses alike, by the rule the report states (ptoverify.verdict.TIME_TIE_RULE)."""
    from ptoverify.config import paper_config
    from ptoverify.report.standing import TIE_NOTE, time_verdict, versus_verdict
    from ptoverify.sim.exact import Compared
    from ptoverify.studies.claims.measure import _Ctx
    from ptoverify.verdict import TIME_TIE_RULE

    cfg = paper_config()
    T = cfg.plant.sample_time
    pd = 0.0236
    pto = pd + samples * T
    expect = "ties" if abs(samples) < 1 else ("beats" if samples < 0 else "loses")
    # the claims: "PTO quicker than PD" holds only when it beats PD; a tie is recorded
    for grid in (False, True):
        ctx = _Ctx.__new__(_Ctx)
        ctx.cfg, ctx.grid, ctx.ties = cfg, grid, []
        times = {"pto": Compared(pto, pto, 0.0, 1e-15), "pd": Compared(pd, pd, 0.0, 1e-15)}
        ctx.metric = lambda law, signal, key, times=times: times[law]
        quicker = ctx.less("pto", "pd", "step", "settling_2pct_s", ("a", "b"))
        assert quicker == (expect == "beats") and bool(ctx.ties) == (expect == "ties")
    # the verdict table's rows
    assert time_verdict(pto, pd, T).startswith(
        {"beats": "beats", "ties": "ties", "loses": "loses"}[expect]
    )
    row = versus_verdict(pto - pd, {"law": "pd", "infeasible": ""}, {"infeasible": ""}, T)
    assert row.startswith(expect if expect != "loses" else "loses to")
    # the headline: who settles first under the primary reading
    data = copy.deepcopy(base)
    data["environment"]["config"]["plant"]["sample_time"] = T
    c = next(c for c in data["claims"] if c["id"] == "step-pd-31-percent")
    for r in c["readings"]:
        r["values"]["settling_pd_s"], r["values"]["settling_pto_s"] = pd, pto
    text = front._finding_settling(results_view(data))[0]
    said = {"beats": "the corrected PTO settles first", "ties": "tie (less than one sample apart)"}
    assert said.get(expect, "PD settles first") in text
    # and the rule is stated where the verdicts are shown
    assert TIME_TIE_RULE in TIE_NOTE


def test_the_tie_rule_is_stated_beside_the_verdicts_and_the_claims(base):
    from ptoverify.report.sections import claims, verdict
    from ptoverify.verdict import TIME_TIE_RULE

    for blocks in (verdict(results_view(base)), claims(results_view(base), {})):
        assert any(TIME_TIE_RULE in b.text for b in blocks)


def test_the_margins_answer_names_the_thinner_loop_and_flips():
    from ptoverify.report.standing import _thinner

    thin = {"gain_margin_db": 3.4, "phase_margin_deg": 54.6, "delay_margin_samples": 0}
    thick = {"gain_margin_db": 13.2, "phase_margin_deg": 60.7, "delay_margin_samples": 1}
    assert _thinner(thin, thick).startswith("thinner in the PTO's linear zone")
    assert _thinner(thick, thin).startswith("thicker in the PTO's linear zone")
    assert _thinner({**thin, "phase_margin_deg": 70.0}, thick).startswith("mixed")


# ---------------------------------------------------------------- the shared bound, explained
def test_versus_row_says_what_the_bound_is_and_why_it_differs_with_a(base):
    """The verdict's baselines' row names the bound's meaning (a function of the reading's
    plant: the PTO's own overshoot at the paper's gains) and each reading's value; equal
    values read as the same, different ones as differing with a."""
    from ptoverify.report.standing import versus_bound, versus_row

    data = copy.deepcopy(base)
    t = data["tuning"]
    meaning = t["bound_meaning"][t["versus"]["bound"]]
    rs_ = t["versus"]["readings"]
    assert len(rs_) == 2
    rs_[0]["bound_mm"], rs_[1]["bound_mm"] = 0.0, 0.125
    text = versus_bound(results_view(data), short=True)
    assert text.startswith(f"overshoot bound = {meaning}, taken under each reading of a")
    assert "so it differs with a): 0 mm at a = 188.5 rad/s, 0.125 mm at a = 30 rad/s" in text
    # the verdict shows the row short (times only) and, in the note right under its
    # tables, the full row with the bound explained
    from ptoverify.report.sections import verdict

    assert "overshoot bound" not in versus_row(results_view(data), short=True)[2]
    texts = [b.text for b in verdict(results_view(data))]
    (note,) = [t_ for t_ in texts if t_.startswith("The fair-tuned comparison in full: ")]
    assert "(so it differs with a): 0 mm at " in note and ", 0.125 mm at " in note
    rs_[1]["bound_mm"] = 0.0
    text = versus_bound(results_view(data))
    assert "the same under each" in text and "differs" not in text


def test_short_verdict_words_are_explained_under_the_table(base):
    """Every short reading word the verdict table uses is in the legend under it."""
    from ptoverify.report.sections import verdict
    from ptoverify.report.standing_claims import READING_WORDS, SHORT_WORDS

    blocks = verdict(results_view(base))
    cells = " ".join(c for b in blocks if b.kind == "table" for r in b.rows for c in r)
    legend = next(b.text for b in blocks if "Short words: " in b.text)
    for dim, words in SHORT_WORDS.items():
        for value, word in words.items():
            plain_ = word.lower() in READING_WORDS[dim][value].lower()  # says itself
            if word in cells and not plain_:
                assert f"{word}: {READING_WORDS[dim][value]}" in legend, word
    assert "a = 188.5 rad/s reads the bandwidth in Hz" in legend
    assert all(b.css.startswith("verdict") for b in blocks if b.kind == "table")
