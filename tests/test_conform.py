"""Tests of ``ptoverify conform``: self-conformance, tables, detection, bad input, findings."""

import csv
import json
import textwrap

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.agreement import tie_band
from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.conform import (
    LawFault,
    UserLaw,
    _as_law,
    closed_loop,
    conform_callable,
    conformance_grid,
    reference_law,
    reference_law_scalar,
    wrap_callable,
)
from ptoverify.curves import level_residual
from ptoverify.laws import make_law
from ptoverify.properties import law_properties
from ptoverify.zones import zone_for_law

SMALL = (11, 11, 20)  # closed-loop sweep for API tests (the CLI uses check's grid)


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, out, err):
    lines = err.strip().splitlines()
    return code == 2 and out == "" and len(lines) == 1 and lines[0].startswith("ptoverify: error:")


def write_law(tmp_path, body, name="userlaw.py"):
    path = tmp_path / name
    path.write_text("import numpy as np\nimport math\n" + textwrap.dedent(body))
    return path


# ------------------------------------------------------------------ acceptance
def test_reference_conforms_to_itself_cli(capsys):
    code, out, err = run(capsys, "conform", "--law", "ptoverify.conform:reference_law", "--json")
    assert code == 0, out
    data = json.loads(out)
    assert data["conforms"] is True and data["mode"] == "vectorized"
    assert data["failures"] == []
    # the reference is compared with itself: exactly zero difference, no rounding involved
    assert data["agreement"]["max_abs_du"] == 0.0
    assert {
        "no-stride-over",
        "no-limit-cycle",
        "input-bound",
        "settling-vs-discrete-limit",
        "odd-symmetry",
        "pure-function",
    } <= set(data["properties"])
    assert all(p["status"] == "pass" for p in data["properties"].values())


def test_reference_scalar_mode_detected(paper_cfg):
    r = conform_callable(reference_law_scalar, paper_cfg, sweep=SMALL)
    assert r.mode == "scalar" and "scalar loop" in r.mode_reason
    assert r.conforms, r.failures
    # scalar path of the same law: Newton for omega_c vs the vectorized W_-1 iteration,
    # both to a few ulps of |u| <= w_max: 1e-12 w_max
    assert_allclose(
        r.agreement["max_abs_du"],
        0.0,
        atol=1e-12 * paper_cfg.plant.w_max,
        err_msg="scalar vs vectorized reference u",
    )


@pytest.mark.slow
def test_example_law_conforms_cli(capsys):
    code, out, _ = run(capsys, "conform", "--law", "examples/my_pto.py:pto", "--json")
    assert code == 0, out
    data = json.loads(out)
    assert data["mode"] == "scalar" and data["conforms"] is True


def test_table_round_trip_conforms(capsys, tmp_path, paper_cfg):
    grid = tmp_path / "grid.csv"
    code, out, _ = run(capsys, "conform", "--emit-grid", str(grid))
    assert code == 0 and out == ""
    with open(grid, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["x1", "x2"]
    x1 = np.array([float(r["x1"]) for r in rows])
    x2 = np.array([float(r["x2"]) for r in rows])
    u = reference_law(x1, x2, paper_cfg)
    table = tmp_path / "table.csv"
    with open(table, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["x1", "x2", "u"])
        w.writerows(
            [repr(a), repr(b), repr(c)] for a, b, c in zip(x1.tolist(), x2.tolist(), u.tolist())
        )
    code, out, _ = run(capsys, "conform", "--table", str(table), "--json")
    assert code == 0, out
    data = json.loads(out)
    assert data["mode"] == "table" and data["conforms"] is True
    assert data["agreement"]["points"] == x1.size
    assert data["properties"]["no-stride-over"]["status"] == "not_run"


def test_table_disagreement_names_state(capsys, tmp_path, paper_cfg):
    x1, x2 = conformance_grid(paper_cfg)
    u = reference_law(x1, x2, paper_cfg)
    _, region = make_law("pto", paper_cfg)(x1, x2)
    i = int(np.flatnonzero(region == 3)[5])  # a ZONE_P point
    u[i] += 1e-3 * paper_cfg.plant.w_max
    table = tmp_path / "t.csv"
    table.write_text(
        "x1,x2,u\n"
        + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(x1.tolist(), x2.tolist(), u.tolist()))
    )
    code, out, _ = run(capsys, "conform", "--table", str(table))
    assert code == 1
    assert "FAILED agreement" in out and f"{x1[i]:.10g}" in out and "ZONE_P" in out


# ------------------------------------------------------------------ the grid
def test_grid_dense_near_every_boundary(paper_cfg):
    p = paper_cfg.plant
    a, w, R, d = p.a, p.w_max, p.position_range, paper_cfg.pto.d
    x1, x2 = conformance_grid(paper_cfg)
    band = tie_band(paper_cfg)
    om = zone_for_law(paper_cfg, "corrected").omega0
    assert np.all(np.abs(x1) <= R) and np.all(np.abs(x2) <= w)
    for level in (w, om):
        r = level_residual(x1, x2, a, level)
        for quadrant in (x2 < 0, x2 > 0):  # l1 / l1* and l2 / l2*
            near = quadrant & (np.abs(r) > band) & (np.abs(r) <= 100 * band)
            assert near.sum() >= 100, f"points just off the level-{level:g} curve"
            # at the paper's values l1, l2 stay inside |x1| < d for |x2| <= w_max (x1 =
            # x1 < d at x2 = -w_max, computed); l1*, l2* bound the zone outside it
            if level == om:
                assert (near & (np.abs(x1) >= d)).sum() >= 100, "zone boundary off |x1| < d"
    assert np.sum(np.abs(x1) == d) >= 100, "points exactly on |x1| = d"
    assert np.sum(np.abs(x2) == w) >= 100, "points exactly on |x2| = w_max"
    radius = np.hypot(x1 / d, x2 / w)
    assert np.any(radius == 0) and np.sum((radius > 0) & (radius < 1e-6)) >= 16, "origin"
    pts = set(zip(x1.tolist(), x2.tolist()))
    assert all((-a1, -a2) in pts for a1, a2 in list(pts)[:2000]), "grid is odd-symmetric"


# ------------------------------------------------------------------ same definitions as check
def test_closed_loop_counts_match_properties(paper_cfg):
    """conform's masks reproduce law_properties' counts (the same definitions as check)."""

    def slow_damping(x1, x2, cfg):  # k2 sign flipped: sustained oscillation
        u = reference_law(x1, x2, cfg)
        lin = np.abs(x1) < cfg.pto.d
        return np.where(lin, np.clip(-cfg.pto.k1 * x1 + cfg.pto.k2 * x2, -300, 300), u)

    for fn in (reference_law, slow_damping):
        user = UserLaw(fn, paper_cfg, mode="vectorized")
        props, _ = closed_loop(user, paper_cfg, sweep=(21, 21, 40))
        ref = law_properties(_as_law(user, paper_cfg), paper_cfg, n1=21, n2=21, rest=40)
        assert props["no-stride-over"]["measured"] == ref.stride_overs
        assert props["no-limit-cycle"]["measured"] == ref.limit_cycles + ref.not_settled
        assert ref.u_within_limit == (props["input-bound"]["measured"] == 0)


def test_settling_property_fires_alone(paper_cfg):
    """A law that halves the input beyond 2 d settles too slowly against N* T."""

    def sluggish(x1, x2, cfg):
        u = reference_law(x1, x2, cfg)
        return np.where(np.abs(x1) >= 2 * cfg.pto.d, 0.5 * u, u)

    r = conform_callable(sluggish, paper_cfg, sweep=SMALL)
    assert "settling-vs-discrete-limit" in r.failed_properties()
    ref = conform_callable(reference_law, paper_cfg, sweep=SMALL)
    s = ref.properties["settling-vs-discrete-limit"]
    # margin by construction: limit = E_ref + max(2, ceil(E_ref / 2)) samples
    assert s["limit"] - s["measured"] >= 2


# ------------------------------------------------------------------ findings (exit 1)
def test_law_raising_at_a_state_is_a_finding(capsys, tmp_path):
    path = write_law(
        tmp_path,
        """
        def f(x1, x2, cfg):
            if x1 > 40.0:
                raise RuntimeError("table lookup out of range")
            from ptoverify.conform import reference_law_scalar
            return reference_law_scalar(x1, x2, cfg)
        """,
    )
    code, out, err = run(capsys, "conform", "--law", f"{path}:f", "--json")
    assert code == 1, err
    data = json.loads(out)
    ev = [f for f in data["failures"] if f["property"] == "evaluation"]
    assert ev and ev[0]["state"][0] > 40.0 and "RuntimeError" in ev[0]["detail"]


def test_sys_exit_in_law_is_a_finding(paper_cfg):
    def f(x1, x2, cfg):
        if x2 == 0.0:
            raise SystemExit(3)  # firmware shim that "exits" on a bad state
        return reference_law(x1, x2, cfg)

    r = conform_callable(f, paper_cfg, sweep=SMALL)
    assert r.failed_properties()[0] == "evaluation"
    assert r.failures[0]["state"][1] == 0.0 and "SystemExit" in r.failures[0]["detail"]


def test_nan_at_a_state_is_a_finding(paper_cfg):
    def f(x1, x2, cfg):
        u = reference_law(x1, x2, cfg)
        return np.where(np.abs(x2) > 299.0, np.nan, u)

    r = conform_callable(f, paper_cfg, sweep=SMALL)
    assert not r.conforms and r.failed_properties()[0] == "evaluation"
    assert abs(r.failures[0]["state"][1]) > 299.0


def test_law_with_memory_is_a_finding(paper_cfg):
    calls = []

    def drifting(x1, x2, cfg):  # every call differs: the law has memory
        calls.append(1)
        return reference_law(x1, x2, cfg) * (1.0 + 1e-3 * len(calls))

    _, failures = wrap_callable(drifting, paper_cfg)
    assert [f["property"] for f in failures] == ["pure-function"]


def test_vectorized_delay_fails_closed_loop(paper_cfg):
    """A per-trajectory one-sample delay, simulated physically, leaves limit cycles."""
    prev = {}

    def delayed(x1, x2, cfg):
        u = reference_law(x1, x2, cfg)
        out = prev.get(np.shape(u), np.zeros_like(u))
        prev[np.shape(u)] = u
        return out

    props, fails = closed_loop(
        UserLaw(delayed, paper_cfg, mode="vectorized"), paper_cfg, sweep=SMALL
    )
    assert props["no-limit-cycle"]["status"] == "fail"
    assert any(f["property"] == "no-limit-cycle" for f in fails)


def test_human_output_names_failures(capsys, tmp_path):
    path = write_law(
        tmp_path,
        """
        def f(x1, x2, cfg):
            from ptoverify.conform import reference_law
            return 1.001 * reference_law(x1, x2, cfg)
        """,
    )
    code, out, _ = run(capsys, "conform", "--law", f"{path}:f")
    assert code == 1
    assert out.startswith("DOES NOT CONFORM")
    assert "FAILED agreement at state (" in out and "FAILED input-bound-grid at state (" in out


def test_user_prints_do_not_break_json(capsys, tmp_path):
    path = write_law(
        tmp_path,
        """
        print("hello from import")
        def f(x1, x2, cfg):
            print("called")
            from ptoverify.conform import reference_law
            return reference_law(x1, x2, cfg)
        """,
    )
    code, out, err = run(capsys, "conform", "--law", f"{path}:f", "--json")
    assert code == 0 and json.loads(out)["conforms"] is True
    assert "hello from import" in err


# ------------------------------------------------------------------ bad input (exit 2)
@pytest.mark.parametrize(
    "spec",
    [
        "no_such_module_xyz:f",
        "ptoverify.conform:no_such_function",
        "ptoverify.conform:DEFAULT_RTOL",
        "ptoverify.conform",
        "/nonexistent/law.py:f",
        ":f",
    ],
)
def test_bad_law_spec_exit_2(capsys, spec):
    assert one_line_error(*run(capsys, "conform", "--law", spec))


@pytest.mark.parametrize(
    "body",
    [
        "def f(x1, x2):\n    return 0.0\n",  # wrong signature
        "def f(x1, x2, cfg):\n    return 'fast'\n",  # not a number
        "def f(x1, x2, cfg):\n    return [0.0, 1.0]\n",  # wrong shape
        "raise ImportError('missing firmware bindings')\n",  # import fails
    ],
)
def test_bad_callable_exit_2(capsys, tmp_path, body):
    path = tmp_path / "bad.py"
    path.write_text(body)
    assert one_line_error(*run(capsys, "conform", "--law", f"{path}:f", "--json"))


@pytest.mark.parametrize(
    "text",
    [
        "",
        "x1,x2\n1,2\n",
        "x1,x2,u\n",
        "x1,x2,u\n1,2,abc\n",
        "x1,x2,u\n1,2,nan\n",
        "x1,x2,u\n1,inf,3\n",
        "x1,x2,u\n1,2\n",
    ],
)
def test_bad_table_exit_2(capsys, tmp_path, text):
    path = tmp_path / "t.csv"
    path.write_text(text)
    assert one_line_error(*run(capsys, "conform", "--table", str(path)))


@pytest.mark.parametrize(
    "argv",
    [
        ["conform"],
        ["conform", "--table", "/nonexistent.csv"],
        ["conform", "--law", "ptoverify.conform:reference_law", "--table", "x.csv"],
        ["conform", "--law", "ptoverify.conform:reference_law", "--tolerance", "0"],
        ["conform", "--emit-grid", "/nonexistent/dir/grid.csv"],
    ],
)
def test_bad_arguments_exit_2(capsys, argv):
    assert one_line_error(*run(capsys, *argv))


def test_lawfault_carries_state():
    fault = LawFault((1.0, -2.0), "boom")
    assert fault.state == (1.0, -2.0) and str(fault) == "boom"


def test_reference_law_doc(paper_cfg):
    # the user-style reference equals the Law object at a zone state (same code path)
    x1, x2 = 1.0, -290.0
    assert (
        reference_law(x1, x2, paper_cfg) == make_law("pto", paper_cfg).scalar(x1, x2)[0]
        or abs(reference_law(x1, x2, paper_cfg) - make_law("pto", paper_cfg).scalar(x1, x2)[0])
        <= 1e-12 * paper_config().plant.w_max
    )


def test_tolerance_option_is_used(capsys, tmp_path, paper_cfg):
    """float32 output passes at 1e-6 w_max and fails at 1e-9 w_max (rounding ~6e-8 relative)."""
    x1, x2 = conformance_grid(paper_cfg, n=11, n_curve=11)
    u = reference_law(x1, x2, paper_cfg).astype(np.float32).astype(float)
    table = tmp_path / "fw.csv"
    table.write_text(
        "x1,x2,u\n"
        + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(x1.tolist(), x2.tolist(), u.tolist()))
    )
    code, out, _ = run(capsys, "conform", "--table", str(table), "--json")
    assert code == 0 and json.loads(out)["agreement"]["rtol"] == 1e-6
    code, out, _ = run(capsys, "conform", "--table", str(table), "--json", "--tolerance", "1e-9")
    data = json.loads(out)
    assert code == 1 and data["failures"][0]["property"] == "agreement"
    assert data["agreement"]["tolerance_mm_s"] == 1e-9 * paper_cfg.plant.w_max


def test_dotted_attribute_and_file_path(tmp_path, paper_cfg):
    from ptoverify.userlaw import load_callable

    path = write_law(
        tmp_path,
        """
        class Drive:
            @staticmethod
            def law(x1, x2, cfg):
                from ptoverify.conform import reference_law
                return reference_law(x1, x2, cfg)
        """,
    )
    fn = load_callable(f"{path}:Drive.law")
    assert fn(0.1, 0.0, paper_cfg) == reference_law(0.1, 0.0, paper_cfg)
