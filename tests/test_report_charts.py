"""The report's penalty curves and coarse design chart (report/charts.py, its section, plots).

References: ``ptoverify design`` and ``ptoverify penalty`` run on their own (the
commands' JSON), the penalty module's own CSV writer, and counts recomputed here
from the chart's points.
"""

import copy
import json

import pytest

from ptoverify import cli
from ptoverify.config import paper_config
from ptoverify.report.charts import (
    CHART_BANDWIDTHS_HZ,
    CHART_LAWS,
    CHART_SAMPLE_TIMES,
    PENALTY_LAWS,
    chart_summary,
    design_results,
    penalty_results,
    write_penalty_csv,
)
from ptoverify.studies.penalty import penalty_curves

CFG = paper_config()


def _cli(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


#: The chart's corners, middle and the paper's cell (3 x 3 of its 5 x 5 cells): every law is
#: fastest somewhere on it, and it has cells whose zone is unusable, degenerate, and whose
#: loop is unstable under one sample of delay (each point is computed on its own, so its
#: cells are those of the whole chart).
SUB_SAMPLE_TIMES = (0.0005, 0.002, 0.008)
SUB_BANDWIDTHS_HZ = (5.0, 30.0, 100.0)


@pytest.fixture(scope="module")
def chart():
    """``design_results`` on the 3 x 3 sub-chart (the module's axes replaced for the call)."""
    import ptoverify.report.charts as charts

    assert set(SUB_SAMPLE_TIMES) <= set(CHART_SAMPLE_TIMES)
    assert set(SUB_BANDWIDTHS_HZ) <= set(CHART_BANDWIDTHS_HZ)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(charts, "CHART_SAMPLE_TIMES", SUB_SAMPLE_TIMES)
        m.setattr(charts, "CHART_BANDWIDTHS_HZ", SUB_BANDWIDTHS_HZ)
        res = design_results(CFG)
    sm = res["summary"]
    assert len(sm["fastest"]) == len(CHART_LAWS), "every law fastest somewhere"
    assert sm["pto_zone_unusable"] and sm["pto_zone_degenerate"] and sm["pto_delay_unstable"]
    return res


@pytest.mark.slow
def test_chart_cells_equal_ptoverify_design(chart, capsys):
    """Two cells of the coarse chart (one of them the paper's point) against the command."""
    assert len(CHART_SAMPLE_TIMES) * len(CHART_BANDWIDTHS_HZ) <= 30
    assert len(chart["points"]) == len(SUB_SAMPLE_TIMES) * len(SUB_BANDWIDTHS_HZ)
    for t, f in ((0.002, 30.0), (0.008, 5.0)):
        got = next(p for p in chart["points"] if (p["sample_time"], p["bandwidth_hz"]) == (t, f))
        res = _cli(capsys, "design", "--sample-times", str(t), "--bandwidths", str(f),
                   "--laws", *CHART_LAWS, "--json")  # fmt: skip
        ref = res["points"][0]
        ref.pop("seconds", None)
        assert got == ref
    assert chart["points"][chart["summary"]["paper_cell"]]["sample_time"] == CFG.plant.T


@pytest.mark.slow
def test_chart_summary_counts_the_points(chart):
    sm = chart["summary"]
    pts = chart["points"]
    assert sm["cells"] == len(pts)
    assert sum(f["cells"] for f in sm["fastest"].values()) == sum(bool(p["fastest"]) for p in pts)
    for law, f in sm["fastest"].items():
        mine = [p["fastest_by"] for p in pts if p["fastest"] == law]
        assert f["cells"] == len(mine)
        finite = [b for b in mine if isinstance(b, float)]
        assert f["by_max"] == (max(finite) if finite else None)
    assert sm["pto_zone_unusable"] == sum(not p["pto_zone_usable"] for p in pts)
    delayed = [p for p in pts for r in p["laws"] if r["law"] == "pto" and r["radius_delay1"] >= 1.0]
    assert sm["pto_delay_unstable"] == len(delayed)
    assert sm["pto_delay_unstable_cells"] == [
        [p["sample_time"], p["bandwidth_hz"]] for p in delayed
    ]


def test_chart_summary_flips_with_its_points():
    def point(fastest, by, usable, degenerate, rho, t=0.002, f=30.0):
        return {
            "sample_time": t,
            "bandwidth_hz": f,
            "fastest": fastest,
            "fastest_by": by,
            "pto_zone_usable": usable,
            "pto_zone_degenerate": degenerate,
            "laws": [{"law": "pto", "radius_delay1": rho}],
        }

    pts = [point("pd", 1.5, True, False, 0.9), point("pto", "inf", True, True, 1.2, f=60.0)]
    sm = chart_summary(pts, CFG)
    assert sm["fastest"] == {"pd": {"cells": 1, "by_max": 1.5}, "pto": {"cells": 1, "by_max": None}}
    assert (sm["pto_zone_degenerate"], sm["pto_delay_unstable"]) == (1, 1)
    assert sm["paper_cell"] == 0
    flipped = copy.deepcopy(pts)
    flipped[0]["laws"][0]["radius_delay1"] = 1.0
    flipped[1]["pto_zone_degenerate"] = False
    sm = chart_summary(flipped, CFG)
    assert (sm["pto_zone_degenerate"], sm["pto_delay_unstable"]) == (0, 2)


def test_penalty_is_that_of_ptoverify_penalty(capsys, tmp_path):
    got = penalty_results(CFG)
    ref = _cli(capsys, "penalty", "--laws", *PENALTY_LAWS, "--json")
    for k in ("sizes_mm", "t_f_s", "nt_s", "n_star", "laws", "settling_definition"):
        want = ref[k]
        if k == "laws":
            want = {law: dict(c, never_settled=got["laws"][law]["never_settled"])
                    for law, c in want.items()}  # fmt: skip
        assert got[k] == want, k
    for c in got["laws"].values():
        assert c["never_settled"] == sum(t is None for t in c["settling_s"])
    assert got["count"] == len(got["sizes_mm"]) >= 40
    # the report's CSV is the penalty module's own CSV, byte for byte
    path = write_penalty_csv(got, tmp_path / "p.csv")
    assert path.read_text() == penalty_curves(CFG, PENALTY_LAWS).to_csv()
