"""``ptoverify mintime --states IN.csv [--out OUT.csv | --json]``, through ``cli.main`` only.

References: the closed form ``min_time`` (same function, so equality is exact)
and, for N*, the LP search ``discrete_min_steps`` (independent of the
zonotopes the command uses).
"""

import csv
import json
import math

import numpy as np
import pytest

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.model.mintime import discrete_min_steps, min_time

PLANT = paper_config().plant


def write(path, text: str):
    path.write_text(text)
    return str(path)


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def states(tmp_path):
    rng = np.random.default_rng(4)
    x1 = np.r_[rng.uniform(-50, 50, 8), 0.0, 40000.0]
    x2 = np.r_[rng.uniform(-300, 300, 8), 0.0, 0.0]  # the origin; N* > 20000 samples
    lines = ["x2,label,x1"] + [
        f"{b!r},s{i},{a!r}" for i, (a, b) in enumerate(zip(x1.tolist(), x2.tolist()))
    ]
    lines.insert(3, "")  # a blank line is skipped
    return write(tmp_path / "in.csv", "\n".join(lines) + "\n"), x1, x2


def test_round_trip_csv(states, tmp_path, capsys):
    path, x1, x2 = states
    out = tmp_path / "out.csv"
    code, stdout, err = run(["mintime", "--states", path, "--out", str(out)], capsys)
    assert code == 0 and err == "" and str(out) in stdout
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == [
        "x1",
        "x2",
        "analytic_s",
        "switch_time_s",
        "discrete_steps",
        "discrete_s",
    ]
    assert len(rows) == x1.size
    mt = min_time(x1, x2, PLANT)
    for i, r in enumerate(rows):
        assert float(r["x1"]) == x1[i] and float(r["x2"]) == x2[i], "states round-trip exactly"
        assert float(r["analytic_s"]) == mt.t_f[i] and float(r["switch_time_s"]) == mt.t_switch[i]
        if i == x1.size - 1:  # beyond n_max = 20000 samples: empty, as the LP's null
            assert r["discrete_steps"] == r["discrete_s"] == ""
            assert not discrete_min_steps(x1[i], x2[i], PLANT).success
            continue
        lp = discrete_min_steps(x1[i], x2[i], PLANT)
        assert int(r["discrete_steps"]) == lp.steps, f"N* at row {i} (LP reference)"
        assert float(r["discrete_s"]) == pytest.approx(lp.time_s, rel=1e-15)


def test_json_equals_csv(states, tmp_path, capsys):
    path, x1, _ = states
    code, stdout, _ = run(["mintime", "--states", path, "--json"], capsys)
    assert code == 0
    rows = json.loads(stdout)["states"]
    code, text, _ = run(["mintime", "--states", path], capsys)  # CSV on stdout
    assert code == 0
    table = list(csv.DictReader(text.splitlines()))
    assert len(rows) == len(table) == x1.size
    for j, t in zip(rows, table, strict=True):
        for k, v in j.items():
            assert (v is None and t[k] == "") or float(t[k]) == v, k
    assert rows[-1]["discrete_steps"] is None and rows[-2]["discrete_steps"] == 0


BAD = {
    "text": ("x1,x2\n1,2\n3,abc\n", "line 3"),
    "nan": ("x1,x2\n1,2\n\n3,4\nnan,4\n", "line 5"),
    "inf": ("x1,x2\n1,-inf\n", "line 2"),
    "far": ("x1,x2\n1,2\n50001,0\n", "line 3"),
    "far-velocity": ("x1,x2\n1,2\n0,-300001\n", "line 3"),
    "missing-column": ("x1,v\n1,2\n", "x2"),
    "missing-field": ("x1,x2\n1,2\n3\n", "line 3"),
    "empty": ("", "empty"),
    "header-only": ("x1,x2\n", "no rows"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_rows_exit_2_nothing_written(case, tmp_path, capsys):
    text, where = BAD[case]
    out = tmp_path / "out.csv"
    path = write(tmp_path / "in.csv", text)
    code, stdout, err = run(["mintime", "--states", path, "--out", str(out)], capsys)
    assert code == 2 and stdout == ""
    assert err.startswith("ptoverify: error:") and err.count("\n") == 1 and where in err, err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def test_not_a_regular_file(tmp_path, capsys):
    for target in (tmp_path, tmp_path / "missing.csv"):
        code, _, err = run(["mintime", "--states", str(target), "--json"], capsys)
        assert code == 2 and err.startswith("ptoverify: error:") and str(target) in err


def test_argument_combinations(states, tmp_path, capsys):
    path = states[0]
    for argv in (
        ["mintime", "1", "2", "--states", path],
        ["mintime", "--states", path, "--json", "--out", str(tmp_path / "o.csv")],
        ["mintime", "1", "2", "--out", str(tmp_path / "o.csv")],
        ["mintime"],
    ):
        code, _, err = run(argv, capsys)
        assert code == 2 and err.startswith("ptoverify: error:"), argv
    assert not (tmp_path / "o.csv").exists()


def test_far_limit_matches_single_state_command(tmp_path, capsys):
    """The batch accepts exactly what `mintime X1 X2` accepts (1000 x the envelope)."""
    edge = 1e3 * PLANT.position_range
    path = write(tmp_path / "in.csv", f"x1,x2\n{edge!r},0\n")
    code, stdout, _ = run(["mintime", "--states", path, "--json"], capsys)
    assert code == 0 and json.loads(stdout)["states"][0]["x1"] == edge
    code, _, _ = run(["mintime", "--", repr(math.nextafter(edge, math.inf)), "0"], capsys)
    assert code == 2
