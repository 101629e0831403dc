"""Tests of the penalty against move size (studies/penalty.py).

References: the closed-form minimum time t_f* (the TO law arrives near it),
the exact N* (no law beats it), and the CSV / JSON of one result against each other.
"""

import csv
import io
import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from ptoverify.config import ALL_LAW_NAMES, paper_config
from ptoverify.studies.penalty import penalty_curves

CFG = paper_config()


@pytest.fixture(scope="module")
def result():
    return penalty_curves(CFG)


def test_sizes_span_the_range(result):
    s = result.sizes_mm
    assert s.size >= 40 and s[0] == 0.01 and s[-1] == CFG.plant.position_range
    assert np.all(np.diff(np.log(s)) > 0)
    assert [c.law for c in result.curves] == list(ALL_LAW_NAMES)


def test_to_arrives_at_t_f_star_at_large_moves(result):
    """TO's arrival is within 2 T of t_f*, so its ratio -> 1 as moves grow.

    The sampled TO switches at the first sample past l1 (late by < T, which
    makes it arrive earlier, by < T) and arrival is read on the samples (late by
    < T): |arrival - t_f*| < 2 T.  Moves with t_f* >= 10 T.
    """
    T = CFG.plant.sample_time
    to = next(c for c in result.curves if c.law == "to")
    big = result.t_f_s >= 10 * T
    assert big.sum() >= 10
    dev = np.abs(to.arrival_s[big] - result.t_f_s[big])
    assert np.all(dev < 2 * T), dev / T
    ratio = to.arrival_s[big] / result.t_f_s[big]
    assert abs(ratio[-1] - 1.0) < 2 * T / result.t_f_s[big][-1] < 0.03
    # TO limit-cycles: it never settles to 0.01 mm (the named settling definition)
    assert np.all(np.isnan(to.settling_s[1:]))


def _fastest_reach(s: float) -> float:
    """Least time to reach x1 = 0 from (s, 0) at all (u = -w_max throughout, any final speed)."""
    a, w = CFG.plant.a, CFG.plant.w_max
    return brentq(lambda t: w * (t - (1 - math.exp(-a * t)) / a) - s, 0.0, 10.0, xtol=1e-15)


def test_no_law_arrives_before_the_fastest_reach(result):
    """Arrival (on the samples) is never before full-speed reach of x1 = 0 (closed form, brentq)."""
    lim = np.array([_fastest_reach(s - 0.01) for s in result.sizes_mm[1:]])
    for c in result.curves:
        assert np.all(c.arrival_s[1:] >= lim * (1 - 1e-12)), c.law
    pto = next(c for c in result.curves if c.law == "pto")
    big = result.t_f_s > 10 * CFG.plant.sample_time
    assert np.all(pto.arrival_s[big] > result.t_f_s[big]), "PTO arrives after t_f*"


def test_ratios_are_settling_over_the_limits(result):
    for c in result.curves:
        fin = np.isfinite(c.ratio_nt)
        assert np.all(c.ratio_nt[fin] == c.settling_s[fin] / result.nt_s[fin]), c.law


def test_csv_matches_json(result):
    js = result.to_json()
    rows = list(csv.DictReader(io.StringIO(result.to_csv())))
    assert len(rows) == len(result.curves) * result.sizes_mm.size
    for row in rows[:: max(1, len(rows) // 37)]:
        i = js["sizes_mm"].index(float(row["size_mm"]))
        want = js["laws"][row["law"]]["settling_s"][i]
        got = float(row["settling_s"]) if row["settling_s"] else None
        assert got == want
        assert int(row["n_star"]) == js["n_star"][i]


def test_tuned_configs_change_the_law():
    from dataclasses import replace

    from ptoverify.config import CascadeGains

    fast = replace(CFG, cascade=CascadeGains(kp=150.0))
    res = penalty_curves(CFG, ("cascade-p",), count=6, configs={"cascade-p": fast})
    base = penalty_curves(CFG, ("cascade-p",), count=6)
    assert "150" in res.curves[0].note and not math.isclose(
        res.curves[0].settling_s[-1], base.curves[0].settling_s[-1]
    )


def test_cli_penalty(tmp_path, capsys):
    from ptoverify.cli import main

    out = tmp_path / "pen"
    assert main(["penalty", "--laws", "pd", "to", "--count", "5", "--json", "--out", str(out)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert list(res["laws"]) == ["pd", "to"] and len(res["sizes_mm"]) == 5
    assert json.loads((out / "penalty.json").read_text())["laws"] == res["laws"]
    assert main(["penalty", "--count", "1"]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error: --count")
