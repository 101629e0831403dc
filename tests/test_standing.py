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
    return json.loads((ROOT / "reports" / "paper" / "results.json").read_text())


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
    q = "Tolerates a one-sample computation delay?"
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
