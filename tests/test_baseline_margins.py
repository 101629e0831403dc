"""The baselines' a_true / a_design margins (studies.robust.law_margins) and the report's rows.

Reference: tests/linear_loop_reference.py (closed-form ZOH, gains read off the
equations by hand, eigenvalues of the sampled loop).
"""

import json

import pytest
from linear_loop_reference import check_interval, hand_gains

from ptoverify.config import PAPER_MAPPING, config_from_mapping, paper_config
from ptoverify.report.collect.parts import BASELINES, _baseline_margins
from ptoverify.report.results import Results
from ptoverify.report.sections.robust_rows import baseline_margin_rows
from ptoverify.studies.robust import RobustSettings, law_margins

A = paper_config().plant.a


@pytest.mark.parametrize(
    "law, section",
    [
        ("cascade-p", {}),
        ("cascade-p", {"cascade": {"kp": 360.0}}),  # with delay: a finite lower end
        ("ptos", {}),
        ("ptos", {"ptos": {"alpha": 0.8, "k": 3.0 * A}}),  # a velocity-error term
        ("ptos", {"ptos": {"alpha": 1.0, "k": 6.0 * A}}),
    ],
)
def test_linear_margins_against_independent_eigenvalues(law, section):
    cfg = config_from_mapping({**PAPER_MAPPING, **section})
    m = law_margins(law, cfg, limit_cycles=False)
    assert m.no_limit_cycle is None
    k = hand_gains(law, cfg)
    T = cfg.plant.sample_time
    check_interval(m.linear.interval, *k, cfg.plant.a, T, 0)
    check_interval(m.linear_delay1.interval, *k, cfg.plant.a, T, 1)


def test_some_gains_give_finite_ends():
    """The parametrized cases reach finite ends on both sides (the test above can fail)."""
    ptos = config_from_mapping({**PAPER_MAPPING, "ptos": {"alpha": 0.8, "k": 3.0 * A}})
    hi = law_margins("ptos", ptos, limit_cycles=False).linear.interval[1]
    casc = config_from_mapping({**PAPER_MAPPING, "cascade": {"kp": 360.0}})
    lo = law_margins("cascade-p", casc, limit_cycles=False).linear_delay1.interval[0]
    assert hi is not None and lo is not None


def test_report_rows_for_the_baselines():
    cfg = paper_config()
    s = RobustSettings(n1=5, n2=5, rest=3)
    bm = _baseline_margins(cfg, s)
    assert tuple(bm) == BASELINES
    assert bm["ptos"]["gains"] == {"alpha": cfg.ptos.alpha, "k": A}
    assert bm["cascade-p"]["gains"] == {"kp": A / 4.0}
    for law in BASELINES:
        want = law_margins(law, cfg, s, limit_cycles=False).to_json()
        assert {k: v for k, v in bm[law].items() if k != "gains"} == want
    tuned = {
        "law": "cascade-p",
        "gains": {"kp": 120.0},
        "infeasible": "",
        "a_ratio_stable": [None, 2.5],
        "a_ratio_stable_delay1": None,
    }
    infeasible = {**tuned, "law": "ptos", "infeasible": "no gains"}
    other = {**tuned, "law": "pd"}
    data = {
        "robust": {"baseline_margins": json.loads(json.dumps(bm))},
        "tuning": {
            "versus": {
                "readings": [
                    {"reading": "2pi", "laws": [tuned, infeasible, other]},
                    {"reading": "hz", "laws": [tuned]},
                ]
            }
        },
    }
    rows = baseline_margin_rows(Results(data))
    labels = [r[0] for r in rows]
    assert len(rows) == 3 and labels[0].startswith("PTOS") and labels[1].startswith("cascade P")
    assert "configured gains" in labels[0] and "configured gains" in labels[1]
    assert "fair-tuned" in labels[2] and "120" in labels[2]
    assert rows[2][1] == "up to 2.5, with no lower limit down to the searched 0.1"
    assert rows[2][2] == "unstable at the design point"
    assert all(r[3].startswith("not simulated") for r in rows)
    data["tuning"] = None
    assert len(baseline_margin_rows(Results(data))) == 2
