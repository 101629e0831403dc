"""``ptoverify conform --report DIR``: a complete, atomic, readable report of a user's law."""

import contextlib
import csv
import io
import json
import re
import textwrap
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.conform.evidence import SIGNAL_METRICS, du_map
from ptoverify.conform.gate import reference_law
from ptoverify.report.conform_report import state
from ptoverify.sim.runs import run_simulation

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"

#: Python reprs that must never reach a reader
REPR = re.compile(
    r"\{'|\['|\('|np\.float|array\(|\bNone\b|\bTrue\b|\bFalse\b|\bnan\b|\binf\b|"
    r"Verdict\(|SimResult\(|<ptoverify|object at 0x"
)
#: a number in a table cell
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(\.\d+)?(e[-+]?\d+)?(?![\w.])")
#: units (or an explicit count) that make a number readable
UNIT = re.compile(r"\b(mm/s|mm|s|deg|rad/s|samples|count|states)\b|x w_max")
#: columns whose numbers are dimensionless ratios or counts, said so in the header or text
DIMENSIONLESS = {
    "states",
    "excluded (ties)",
    "violations",
    "median",
    "95th percentile",
    "max",
    "never settled",
}

#: columns that name a row (a property, region, law or metric), not a figure
LABELS = {"property", "region", "law", "item", "why", "perturbation"}
#: rows of the summary table that hold names, not figures
TEXT_ROWS = {"law", "evaluated as", "configuration", "precision", "perturbation"}


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def md_tables(text: str):
    """(headers, rows) of every Markdown table."""
    tables, lines = [], text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("| ") and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
            split = lambda s: [c.strip() for c in re.split(r"(?<!\\)\|", s)[1:-1]]  # noqa: E731
            headers, rows = split(lines[i]), []
            i += 2
            while i < len(lines) and lines[i].startswith("| "):
                rows.append(split(lines[i]))
                i += 1
            tables.append((headers, rows))
        else:
            i += 1
    return tables


def check_complete(out: Path) -> dict:
    """Files exist, every referenced image exists, JSON parses, no repr, units on numbers."""
    for name in ("index.html", "report.md", "results.json", ".ptoverify"):
        assert (out / name).is_file(), name
    html = (out / "index.html").read_text()
    md = (out / "report.md").read_text()
    res = json.loads((out / "results.json").read_text())
    images = re.findall(r'<img src="([^"]+)"', html)
    assert images and images == re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    for src in images:
        assert (out / src).is_file() and (out / src).stat().st_size > 1000, src
    assert sorted(set(images)) == res["meta"]["figures"]
    assert "http://" not in html and "https://" not in html and "<script" not in html
    for text in (html, md):
        hit = REPR.search(text)
        assert hit is None, text[max(0, hit.start() - 80) : hit.end() + 80]
    for headers, rows in md_tables(md):
        for row in rows:
            if row[0] in TEXT_ROWS:
                continue
            for head, cell in zip(headers, row):
                label = head in LABELS or head.endswith(": metric")
                if not NUMBER.search(cell) or head in DIMENSIONLESS or label:
                    continue
                assert UNIT.search(cell), f"number without unit: {head!r} = {cell!r}"
    marker = json.loads((out / ".ptoverify").read_text())
    assert set(marker["files"]) >= {"index.html", "report.md", "results.json", *images}
    return res


def check_map_is_the_agreement(res: dict) -> None:
    """The largest map cell (or state outside it) is the agreement's largest |du|."""
    env = res["evidence"]["maps"]["envelope"]
    top = max(env["max_abs_du_mm_s"], env["outside_max_abs_du_mm_s"])
    assert_allclose(top, res["conform"]["agreement"]["max_abs_du"], rtol=0, atol=0)
    judged = res["conform"]["agreement"]["points"] - res["conform"]["agreement"]["excluded"]
    assert env["states"] + env["outside"] == judged == res["evidence"]["judged_states"]


# ------------------------------------------------------------------ tables (fast)
@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    """The states ``conform --emit-grid`` writes, read back with the csv module (once)."""
    grid = tmp_path_factory.mktemp("emit") / "grid.csv"
    assert main(["conform", "--emit-grid", str(grid)]) == 0
    with open(grid, newline="") as fh:
        rows = list(csv.DictReader(fh))
    x1 = np.array([float(r["x1"]) for r in rows])
    x2 = np.array([float(r["x2"]) for r in rows])
    x1.flags.writeable = x2.flags.writeable = False  # shared by the module's tests
    return x1, x2


def write_table(tmp_path, cfg, emitted, mutate=None):
    x1, x2 = emitted
    u = reference_law(x1, x2, cfg)
    if mutate is not None:
        u = mutate(x1, x2, u)
    table = tmp_path / "table.csv"
    with open(table, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["x1", "x2", "u"])
        w.writerows(zip(map(repr, x1.tolist()), map(repr, x2.tolist()), map(repr, u.tolist())))
    return table, x1, x2


def test_table_report_conforms_and_says_no_responses(capsys, tmp_path, paper_cfg, emitted):
    table, x1, _ = write_table(tmp_path, paper_cfg, emitted)
    out = tmp_path / "rep"
    code, stdout, err = run(capsys, "conform", "--table", str(table), "--report", str(out))
    assert code == 0, (stdout[-2000:], err)
    res = check_complete(out)
    assert res["conform"]["conforms"] is True
    assert res["meta"]["figures"] == ["figures/du_map.png"]
    md = (out / "report.md").read_text()
    assert md.startswith("# Conformance of") and "CONFORMS" in md.splitlines()[0]
    assert "No step, ramp or sine responses: a --table gives u only at its states" in md
    assert "Settling / (N* T): needs a callable law (--law)." in md
    check_map_is_the_agreement(res)
    assert (
        res["evidence"]["maps"]["envelope"]["states"]
        == x1.size - res["conform"]["agreement"]["excluded"]
    )


def test_table_mutant_report_shows_hot_cells(capsys, tmp_path, paper_cfg, emitted):
    """u 5 % low in a band of x1: the hot cells are exactly that band, the first state named."""
    band = (29.5, 30.5)  # holds the grid column x1 = 30 mm

    def slow_band(x1, x2, u):
        return np.where((np.abs(x1) > band[0]) & (np.abs(x1) < band[1]), 0.95 * u, u)

    table, x1, x2 = write_table(tmp_path, paper_cfg, emitted, slow_band)
    out = tmp_path / "rep"
    code, stdout, _ = run(capsys, "conform", "--table", str(table), "--report", str(out), "--json")
    assert code == 1
    data = json.loads(stdout)
    assert data["report"] == str(out / "index.html")
    res = check_complete(out)
    first = data["failures"][0]
    assert first["property"] == "agreement"
    html = (out / "index.html").read_text()
    assert (
        "DOES NOT CONFORM" in html
        and f"First failing property: agreement at {state(first['state'])}" in html
    )
    check_map_is_the_agreement(res)
    env = res["evidence"]["maps"]["envelope"]
    hot = env["hot_cells"]
    assert hot and env["cells_over_tolerance"] > 0
    cell_w = 2 * paper_cfg.plant.position_range / env["cells"][0]
    for c in hot:  # every hot cell overlaps the faulty band (mirrored)
        lo, hi = sorted(map(abs, c["x1_mm"]))
        assert lo < band[1] + cell_w and hi > band[0] - cell_w, c
    # independently binned: the cells over the tolerance are those holding a faulty state
    R, w, n = paper_cfg.plant.position_range, paper_cfg.plant.w_max, env["cells"][0]
    u_ref = reference_law(x1, x2, paper_cfg)
    bad = (np.abs(x1) > band[0]) & (np.abs(x1) < band[1]) & (0.05 * np.abs(u_ref) > 3e-4)
    c = np.clip(np.floor((x1[bad] + R) / (2 * R / n)), 0, n - 1)
    r = np.clip(np.floor((x2[bad] + w) / (2 * w / n)), 0, n - 1)
    assert env["cells_over_tolerance"] == np.unique(r * n + c).size


# ------------------------------------------------------------------ bad input (fast)
def law_with_side_effect(tmp_path) -> tuple[str, Path]:
    flag = tmp_path / "imported"
    path = tmp_path / "law.py"
    path.write_text(
        textwrap.dedent(
            f"""
            from pathlib import Path
            Path({str(flag)!r}).write_text("x")
            def law(x1, x2, cfg):
                return 0.0
            """
        )
    )
    return f"{path}:law", flag


@pytest.mark.parametrize("kind", ["file", "foreign", "empty"])
def test_bad_report_path_is_exit_2_before_computing(capsys, tmp_path, kind):
    spec, flag = law_with_side_effect(tmp_path)
    if kind == "file":
        target = tmp_path / "report.txt"
        target.write_text("not a folder")
    elif kind == "foreign":
        target = tmp_path / "notes"
        target.mkdir()
        (target / "mine.txt").write_text("keep me")
    else:
        target = ""
    code, out, err = run(capsys, "conform", "--law", spec, "--report", str(target))
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1, (code, out, err)
    assert lines[0].startswith("ptoverify: error:") and "--report" in lines[0]
    assert not flag.exists(), "the law was loaded before --report was validated"
    if kind == "foreign":
        assert sorted(p.name for p in target.iterdir()) == ["mine.txt"]
    assert not list(tmp_path.glob(".*tmp-*")), "a temporary folder was left behind"


def test_report_with_emit_grid_is_bad_input(capsys, tmp_path):
    code, out, err = run(
        capsys, "conform", "--emit-grid", str(tmp_path / "g.csv"), "--report", str(tmp_path / "r")
    )
    assert code == 2 and "--report needs --law or --table" in err
    assert not (tmp_path / "g.csv").exists() and not (tmp_path / "r").exists()


# ------------------------------------------------------------------ maps (fast)
def test_du_map_is_the_cellwise_maximum():
    """Against a brute-force loop over cells (edges inclusive on the window border)."""
    rng = np.random.default_rng(3)
    x1, x2 = rng.uniform(-12, 12, 5000), rng.uniform(-3, 3, 5000)
    du = rng.exponential(1.0, 5000)
    m = du_map(x1, x2, du, 10.0, 2.0, 2.5, cells=7)
    e1, e2 = np.linspace(-10, 10, 8), np.linspace(-2, 2, 8)
    for r in range(7):
        for c in range(7):
            hi1 = (x1 < e1[c + 1]) | ((c == 6) & (x1 <= e1[c + 1]))
            hi2 = (x2 < e2[r + 1]) | ((r == 6) & (x2 <= e2[r + 1]))
            sel = (x1 >= e1[c]) & hi1 & (x2 >= e2[r]) & hi2
            assert m.counts[r, c] == sel.sum()
            if sel.any():
                assert m.du_max[r, c] == du[sel].max()
            else:
                assert np.isnan(m.du_max[r, c])
    out = (np.abs(x1) > 10) | (np.abs(x2) > 2)
    assert m.outside == out.sum() and m.outside_max == du[out].max()
    hot = m.hot_cells(3)
    assert [c["max_abs_du_mm_s"] for c in hot] == sorted(du[~out][du[~out] > 2.5])[::-1][:3]


# ------------------------------------------------------------------ callables (isolated)
def check_responses(res: dict, cfg, *, agree_mm: float) -> None:
    """The reference columns equal ``simulate --law pto`` (another path); yours within agree_mm."""
    resp = res["evidence"]["responses"]
    assert set(resp) == {"step", "ramp", "sine"}
    for name, r in resp.items():
        metrics, _ = run_simulation(cfg, "pto", name).metrics()
        # only the metrics that mean something for the signal (no ramp or sine settling)
        assert set(r["reference"]) == set(SIGNAL_METRICS[name]) <= set(metrics), name
        assert r["reference"] == {k: metrics[k] for k in SIGNAL_METRICS[name]}, name
        assert r["max_abs_dx1_mm"] <= agree_mm, (name, r["max_abs_dx1_mm"])
    assert {f"figures/response_{n}.png" for n in resp} <= set(res["meta"]["figures"])


@pytest.fixture(scope="module")
def example_report(tmp_path_factory):
    """``conform --law examples/my_pto.py:pto --report DIR``, once: (exit code, stdout, DIR).

    Read by the report's test and by the command line's human output test: ``--report``
    adds a folder, not another verdict or first line.
    """
    out = tmp_path_factory.mktemp("example") / "review"
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(
            ["conform", "--law", f"{ROOT / 'examples' / 'my_pto.py'}:pto", "--report", str(out)]
        )
    return code, stdout.getvalue(), out


@pytest.mark.slow
def test_example_law_conforms_cli(example_report):
    code, out, _ = example_report
    assert code == 0, out
    first = out.splitlines()[0]
    assert first.startswith("CONFORMS") and "mode scalar: " in first
    assert "truth value" not in first and ": )" not in first


@pytest.mark.slow
def test_example_law_report(example_report, paper_cfg):
    code, stdout, out = example_report
    assert code == 0, stdout[-2000:]
    assert stdout.splitlines()[0].startswith("CONFORMS")
    res = check_complete(out)
    assert res["conform"]["conforms"] is True and res["conform"]["mode"] == "scalar"
    html = (out / "index.html").read_text()
    assert "<h1>Conformance of" in html and ": CONFORMS (float64; perturbation: none)</h1>" in html
    assert "settling" not in json.dumps(res["evidence"]["responses"]["ramp"]["user"])
    assert "settling" not in json.dumps(res["evidence"]["responses"]["sine"]["user"])
    check_map_is_the_agreement(res)
    check_responses(res, paper_cfg, agree_mm=1e-9)
    s = res["evidence"]["settling"]
    assert s["states"] > 100 and 1.0 <= s["user"]["median"] <= s["user"]["max"]
    # the report's worst excess is the property's measured value
    assert (
        s["worst_excess_samples"]
        == res["conform"]["properties"]["settling-vs-discrete-limit"]["measured"]
    )


@pytest.mark.slow
def test_mutant_report_names_the_first_failing_state(capsys, tmp_path, paper_cfg):
    law = tmp_path / "mutant.py"
    law.write_text(
        f"import sys\nsys.path.insert(0, {str(TESTS)!r})\n"
        "from pto_mutants import make_law\nlaw = make_law(['omega0_up'])\n"
    )
    out = tmp_path / "review"
    code, stdout, _ = run(capsys, "conform", "--law", f"{law}:law", "--report", str(out), "--json")
    assert code == 1
    data = json.loads(stdout)
    res = check_complete(out)
    assert res["conform"]["failures"] == data["failures"]
    first = data["failures"][0]
    md = (out / "report.md").read_text()
    head = md.split("## Properties")[0]
    assert "DOES NOT CONFORM" in head and f"fails {first['property']}" in head
    assert f"First failing property: {first['property']} at {state(first['state'])}" in head
    check_map_is_the_agreement(res)
    zoom = res["evidence"]["maps"]["zoom"]
    worst = data["agreement"]["worst"]["state"]
    top = zoom["hot_cells"][0]
    assert top["max_abs_du_mm_s"] == data["agreement"]["max_abs_du"]
    assert top["x1_mm"][0] <= worst[0] <= top["x1_mm"][1]
    assert top["x2_mm_s"][0] <= worst[1] <= top["x2_mm_s"][1]
    check_responses(res, paper_cfg, agree_mm=np.inf)


def test_law_that_raises_gets_a_report_without_map(capsys, tmp_path):
    """An evaluation finding: no state judged, so no map (and the report says why)."""
    path = tmp_path / "raising.py"
    path.write_text(
        "def law(x1, x2, cfg):\n"
        "    if x1 > 49.9:\n"
        "        raise ValueError('boom')\n"
        "    return -300.0 if x1 > 0 else 300.0\n"
    )
    out = tmp_path / "review"
    code, stdout, _ = run(capsys, "conform", "--law", f"{path}:law", "--report", str(out))
    assert code == 1
    res = check_complete(out)
    first = res["conform"]["failures"][0]
    assert first["property"] == "evaluation" and first["state"][0] > 49.9
    md = (out / "report.md").read_text()
    assert "No map of |u - u_ref|: no state was judged" in md
    assert "figures/du_map.png" not in res["meta"]["figures"]
    assert f"First failing property: evaluation at {state(first['state'])}" in md


@pytest.mark.slow
def test_report_under_delay_shows_precision_perturbation_and_warnings(capsys, tmp_path):
    out = tmp_path / "delay"
    code, stdout, _ = run(
        capsys,
        "conform",
        "--law",
        "ptoverify.conform.gate:reference_law",
        "--delay",
        "1",
        "--precision",
        "float32",
        "--report",
        str(out),
    )
    res = check_complete(out)
    first = stdout.splitlines()[0]
    assert "precision float32" in first and "under delay 1 sample" in first
    assert "the reference itself fails" in first
    md = (out / "report.md").read_text()
    assert md.splitlines()[0].endswith("(float32; perturbation: delay 1 sample)")
    rd = res["evidence"]["reference_delay"]
    assert rd["delay_samples"] == 1 and 0 < rd["cycling"] <= rd["states"]
    assert f"from {rd['cycling']} of {rd['states']} initial states" in md
    assert "WARNING: under the perturbations judged, the reference law itself fails" in md
    runs = res["conform"]["perturbation"]["runs"]
    assert len(runs) == 1 and "no-limit-cycle" in runs[0]["reference_fails"]
    assert "## Closed loop under perturbation" in md and "## Pass limits and why" in md
    # the limits shown are the configuration's [conform] values
    assert "E_ref + max(2, ceil(0.5 x E_ref))" in md
    assert code == (0 if res["conform"]["conforms"] else 1)


def test_report_with_a_wrong_function_name_lists_the_callables(capsys, tmp_path):
    out = tmp_path / "r"
    code, _, err = run(
        capsys, "conform", "--law", f"{ROOT / 'examples' / 'my_pto.py'}:ptoo", "--report", str(out)
    )
    assert code == 2 and "(callables defined there: pto)" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
