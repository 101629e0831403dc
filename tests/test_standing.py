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
        "holds only with a = f (the bandwidth read as rad/s)",
    )
    claim["readings"][0]["verdict"] = "reproduced"
    assert claim_standing(claim)[0] == "holds"
    for r in claim["readings"]:
        r["verdict"] = "not reproduced"
    assert claim_standing(claim)[0] == "fails"


def test_claim_standing_counts_when_no_single_reading_decides():
    rs_ = [
        _reading("2pi*f", "reproduced", 0.02),
        _reading("2pi*f", "not reproduced", 0.05),
        _reading("f", "not reproduced", 0.02),
        _reading("f", "reproduced", 0.05),
    ]
    assert claim_standing({"readings": rs_}) == ("depends", "holds under 2 of 4 readings")


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
    assert f"(the bandwidth read in Hz) {first}" in text.replace("the corrected PTO", "PTO")
    v["settling_pd_s"], v["settling_pto_s"] = v["settling_pto_s"], v["settling_pd_s"]
    flipped = front._finding_settling(results_view(data))[0].replace("the corrected PTO", "PTO")
    other = "PTO settles first" if first == "PD settles first" else "PD settles first"
    assert f"(the bandwidth read in Hz) {other}" in flipped


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
    return {"settling": "2pct", "settling_description": "2 % band", "readings": readings}


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
    assert two_pi.startswith("a = 2 pi f") and "loses to PD" in two_pi
    assert hz.startswith("a = f") and "beats PD" in hz
    assert "no cascade P gains meet the constraints" in hz
    evidence = _rows(data)[VERSUS_QUESTION][2]
    assert "cascade P no tuning" in evidence and "settling definition 2pct" in evidence
    assert "PTO 20 ms (0.7692 N*T, 0.8333 t_f*)" in evidence  # 20 / 26, 20 / 24


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
    assert _rows(data)[VERSUS_QUESTION][1].startswith("a = 2 pi f")


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
