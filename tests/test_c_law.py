"""The firmware example: the PTO law in C99, built by the system compiler, gated by
``conform --law`` in double precision (conforms), single precision judged as a float64
function (does not, and why) and single precision under ``--precision float32`` (conforms)."""

import contextlib
import io
import json
import shutil
from pathlib import Path

import pytest
from test_conform_report import check_complete, check_map_is_the_agreement, check_responses

from ptoverify.cli import main

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "c_law" / "c_pto.py"

pytestmark = pytest.mark.skipif(
    not any(shutil.which(c) for c in ("cc", "gcc", "clang")),
    reason="no C compiler (cc, gcc or clang) on PATH: the C firmware example is not gated",
)


def _conform(capsys, func, tmp_path, *extra):
    junit = tmp_path / f"{func}.xml"
    code = main(["conform", "--law", f"{SPEC}:{func}", "--json", "--junit", str(junit), *extra])
    return code, json.loads(capsys.readouterr().out), junit


@pytest.fixture(scope="module")
def double_build(tmp_path_factory):
    """One ``conform --json --junit --report`` of the double build, read by two tests.

    ``--report`` adds a folder, not another verdict (the report's run judges as
    ``conform`` does); returns (exit code, JSON result, JUnit file, report folder).
    """
    tmp = tmp_path_factory.mktemp("c_double")
    junit, review = tmp / "pto.xml", tmp / "review"
    argv = ["--json", "--junit", str(junit), "--report", str(review)]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["conform", "--law", f"{SPEC}:pto", *argv])
    return code, json.loads(out.getvalue()), junit, review


@pytest.mark.slow
def test_c_double_build_conforms(double_build):
    code, res, junit, _ = double_build
    assert code == 0 and res["conforms"], res["failures"]
    assert res["agreement"]["max_abs_du"] <= 1e-9 * 300.0, "double C port differs beyond round-off"
    assert junit.read_text().count("<testcase") == len(res["properties"]) + len(
        res["agreement"]["regions"]
    )


@pytest.mark.slow
def test_c_law_report(double_build, paper_cfg):
    """The double build's report: complete, conforming, the map and the responses."""
    code, _, _, review = double_build
    assert code == 0
    res = check_complete(review)
    assert res["conform"]["conforms"] is True
    check_map_is_the_agreement(res)
    check_responses(res, paper_cfg, agree_mm=1e-9)


@pytest.mark.slow
def test_c_single_build_fails_only_agreement(capsys, tmp_path):
    """float32 rounds the state: near |x1| = d and near the curves the region flips, so
    agreement at 1e-6 w_max fails there, while the closed loop keeps every property."""
    code, res, _ = _conform(capsys, "pto_single", tmp_path)
    assert code == 1 and not res["conforms"]
    failing = {f["property"] for f in res["failures"]}
    assert failing == {"agreement"}, failing
    bad_regions = {k for k, e in res["agreement"]["regions"].items() if not e["pass"]}
    assert bad_regions and bad_regions <= {"LINEAR", "SATURATED", "BANG_P", "BANG_N"}
    for name in bad_regions:  # the worst disagreement sits where float32 moves |x1| across d
        x1 = res["agreement"]["regions"][name]["state"][0]
        assert abs(abs(x1) - 0.5) <= 1e-6, (name, x1)
    others = {n: p for n, p in res["properties"].items() if n != "agreement"}
    assert res["properties"]["agreement"]["status"] == "fail"
    assert all(p["status"] == "pass" for p in others.values()), others


@pytest.mark.slow
def test_c_single_build_conforms_as_float32(capsys, tmp_path):
    """Under --precision float32 the reference is evaluated at the state the float build
    rounded to, and states within the derived float32 tie band of a boundary are ties: what
    is left is the float build's own arithmetic, which stays within 1e-6 w_max (no
    precision loss in log1p or in the omega_c root)."""
    code, res, _ = _conform(capsys, "pto_single", tmp_path, "--precision", "float32")
    assert code == 0 and res["conforms"], res["failures"]
    assert res["precision"] == "float32" and res["agreement"]["precision"] == "float32"
    a = res["agreement"]
    assert a["max_abs_du"] <= a["tolerance_mm_s"]
    # the float build really computes in float: far from the boundaries it differs from the
    # double reference by more than double round-off (else the mode would prove nothing)
    assert a["max_abs_du"] > 1e-9 * 300.0
    # ties (float64 curve ties and float32 ties) are a small fraction of the judged states
    assert 0 < a["excluded"] < 1e-2 * a["points"]


def test_c_source_is_c99_without_allocation_or_state():
    import re

    src = (ROOT / "examples" / "c_law" / "pto_law.c").read_text()
    for banned in ("malloc", "calloc", "realloc", "free(", "alloca("):
        assert banned not in src, banned
    file_scope_vars = re.findall(
        r"^(?:static\s+)?(?:const\s+)?(?:double|float|real|int)\s+\w+\s*(?:=|;|\[)", src, re.M
    )
    assert file_scope_vars == [], f"state between calls: {file_scope_vars}"


@pytest.mark.slow
def test_c_single_build_table_conforms_as_float32(tmp_path):
    """The --table route of the same float build: the emitted probe set evaluated by the
    float32 C law conforms under --precision float32 and not as a float64 function."""
    import importlib.util

    from ptoverify.config import paper_config
    from ptoverify.conform.agreement import grid_csv
    from ptoverify.conform.table import conform_table

    spec = importlib.util.spec_from_file_location("c_pto_for_test", SPEC)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cfg = paper_config()
    rows = grid_csv(cfg).splitlines()[1:]
    table = tmp_path / "fw.csv"
    with table.open("w") as fh:
        fh.write("x1,x2,u\n")
        for row in rows:
            x1, x2 = (float(v) for v in row.split(","))
            fh.write(f"{row},{mod.pto_single(x1, x2, cfg)!r}\n")
    r32 = conform_table(table, cfg, precision="float32")
    assert r32.conforms, r32.failures
    r64 = conform_table(table, cfg)
    assert not r64.conforms and set(r64.failed_properties()) == {"agreement"}
