"""Tests of ``ptoverify conform``: self-conformance, tables, detection, bad input, findings."""

import csv
import json
import re
import textwrap
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.conform.agreement import tie_band
from ptoverify.conform.gate import (
    LawFault,
    UserLaw,
    closed_loop,
    conform_callable,
    conform_spec,
    conformance_grid,
    format_result,
    reference_law,
    reference_law_scalar,
    wrap_callable,
)
from ptoverify.model.curves import level_residual
from ptoverify.model.laws import make_law
from ptoverify.model.zones import zone_for_law
from ptoverify.studies.properties import default_steps, initial_grid

ROOT = Path(__file__).resolve().parents[1]

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
@pytest.mark.slow
def test_independent_copy_conforms_cli(capsys):
    """The copy written from the equations (Lambert W, own curves) conforms, isolated."""
    law = f"{ROOT / 'tests' / 'pto_mutants.py'}:faithful"
    code, out, err = run(capsys, "conform", "--law", law, "--json", "--timeout", "300")
    assert code == 0, (out[-2000:], err)
    data = json.loads(out)
    assert data["conforms"] is True and data["mode"] == "vectorized"
    assert data["failures"] == [] and data["unverified"] == []
    # two implementations of omega_c (scipy's W_-1 + Newton vs the reference's): a few ulps
    assert data["agreement"]["max_abs_du"] <= 1e-9 * 300.0
    assert data["agreement"]["sources"]["random"] >= 100_000
    assert data["agreement"]["sources"]["sweep"] > 10_401
    assert set(data["properties"]) >= {
        "pure-function",
        "agreement",
        "odd-symmetry",
        "no-stride-over",
        "no-limit-cycle",
        "input-bound",
        "settling-vs-discrete-limit",
    }
    assert all(p["status"] == "pass" for p in data["properties"].values())


def test_reference_scalar_mode_detected(paper_cfg):
    """The reference on Python floats: judged state by state, and it conforms.

    The closed-loop sweep is 3 x 3 + 2 states (each state costs ~300 law calls one by
    one); the settling property still runs its own fixed 11 x 11 + 20 sweep, so every
    closed-loop property is judged in scalar mode."""
    grid = conformance_grid(paper_cfg, n=11, n_curve=11)
    r = conform_callable(
        reference_law_scalar, paper_cfg, sweep=(3, 3, 2), n_random=1000, n_band=2000, grid=grid
    )
    assert r.mode == "scalar" and "state by state" in r.mode_reason
    assert r.conforms, r.failures
    # scalar path of the same law: Newton for omega_c vs the vectorized W_-1 iteration,
    # both to a few ulps of |u| <= w_max: 1e-12 w_max
    assert_allclose(
        r.agreement["max_abs_du"],
        0.0,
        atol=1e-12 * paper_cfg.plant.w_max,
        err_msg="scalar vs vectorized reference u",
    )


# the example law's command line (human output): test_conform_report.py, which shares that run


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
# ------------------------------------------------------------------ independent references
def _zoh(cfg):
    """ZOH matrices of x1' = x2, x2' = a (u - x2) from scipy (not ptoverify.sim.simulate)."""
    from scipy.signal import cont2discrete

    a, T = cfg.plant.a, cfg.plant.sample_time
    A, B, *_ = cont2discrete(
        (np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]]), np.eye(2), np.zeros((2, 1))),
        T,
    )
    return A, B[:, 0]


def _sigma(x1, x2, a, level):
    """Level curve through the origin, eqs. (9)/(11) written out (not ptoverify.model.curves)."""
    with np.errstate(all="ignore"):
        neg = a * x1 + x2 + level * np.log(1.0 - np.minimum(x2, 0.0) / level)
        pos = a * x1 + x2 - level * np.log(1.0 + np.maximum(x2, 0.0) / level)
    return np.where(x2 <= 0, neg, pos)


def _time_optimal(x1, x2, cfg):
    """Sampled bang-bang law u = +-w_max by the side of l1 - o - l2: strides over."""
    a, w = cfg.plant.a, cfg.plant.w_max
    s = _sigma(np.asarray(x1, float), np.asarray(x2, float), a, w)
    return np.where((s < 0) | ((s == 0) & (np.asarray(x2) < 0)), w, -w)


def test_stride_over_count_against_independent_simulation(paper_cfg):
    """Stride-overs of sampled bang-bang control, counted from a scipy ZOH simulation."""
    from dataclasses import replace

    # at the paper's d, l1 and l2 stay inside |x1| < d: shrink d so that strides can happen
    cfg = replace(paper_cfg, pto=replace(paper_cfg.pto, d=0.02))
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    props, _ = closed_loop(UserLaw(_time_optimal, cfg, mode="vectorized"), cfg, sweep=(11, 11, 20))
    x1, x2, _ = initial_grid(cfg, 11, 11, 20)
    A, B = _zoh(cfg)
    om = zone_for_law(cfg, "corrected").omega0
    tol = 1e-9 * (w + a * cfg.plant.position_range)
    x, count = np.stack([x1, x2]), 0
    for _ in range(default_steps(cfg)):
        s0, r0 = _sigma(x[0], x[1], a, w), _sigma(x[0], x[1], a, om)
        zone = ((x[1] < 0) & (s0 > 0) & (r0 <= 0)) | ((x[1] > 0) & (s0 < 0) & (r0 >= 0))
        nxt = A @ x + np.outer(B, _time_optimal(x[0], x[1], cfg))
        s1 = _sigma(nxt[0], nxt[1], a, w)
        n_side = (s0 > 0) | ((s0 == 0) & (x[1] > 0))
        p_side = (s0 < 0) | ((s0 == 0) & (x[1] < 0))
        cross = (n_side & (s1 < -tol)) | (p_side & (s1 > tol))
        count += int(np.sum(cross & (np.abs(x[0]) >= d) & ~zone & (np.abs(nxt[0]) >= d)))
        x = nxt
    measured = props["no-stride-over"].measured
    assert count > 100, "sampled bang-bang control must stride over"
    # two simulators round differently; a trajectory grazing a curve may move one sample
    assert abs(measured - count) <= max(2, 0.01 * count), (measured, count)
    assert props["no-stride-over"].status == "fail"


def _lp_reaches_origin(x0, n, A, B, w):
    """Is the origin reachable in n ZOH samples with |u| <= w? (own LP, stacked rows)."""
    from scipy.optimize import linprog

    cols = [np.linalg.matrix_power(A, n - 1 - k) @ B for k in range(n)]
    res = linprog(
        np.zeros(n),
        A_eq=np.array(cols).T,
        b_eq=-np.linalg.matrix_power(A, n) @ x0,
        bounds=[(-w, w)] * n,
        method="highs",
    )
    return res.status == 0


def test_settling_property_against_independent_lp(paper_cfg):
    """The settling finding's numbers, re-derived by a scipy simulation and an own LP for N*."""
    cfg = paper_cfg

    def sluggish(x1, x2, cfg):
        u = reference_law(x1, x2, cfg)
        return np.where(np.abs(x1) >= 2 * cfg.pto.d, 0.5 * u, u)

    r = conform_callable(sluggish, cfg, sweep=SMALL, n_random=1000)
    assert r.properties["settling-vs-discrete-limit"].status == "fail"
    f = next(f for f in r.failures if f["property"] == "settling-vs-discrete-limit")
    s, n_star = map(
        float, re.search(r"settles in (\S+) samples, N\* = (\S+) ", f["detail"]).groups()
    )
    A, B = _zoh(cfg)
    x0, w = np.array(f["state"]), cfg.plant.w_max
    x, last_out = x0.copy(), 0
    for k in range(1, default_steps(cfg) + 1):
        x = A @ x + B * float(sluggish(x[0], x[1], cfg))
        if abs(x[0]) > 1e-3:
            last_out = k
    assert abs(last_out + 1 - s) <= 1, f"settling sample: scipy {last_out + 1}, conform {s}"
    n = int(n_star)
    assert _lp_reaches_origin(x0, n, A, B, w), "N* samples must reach the origin"
    assert not _lp_reaches_origin(x0, n - 1, A, B, w), "N* - 1 samples must not"


# ------------------------------------------------------------------ findings (exit 1)
def test_law_raising_at_a_state_is_a_finding(capsys, tmp_path):
    path = write_law(
        tmp_path,
        """
        def f(x1, x2, cfg):
            if x1 > 40.0:
                raise RuntimeError("table lookup out of range")
            from ptoverify.conform.gate import reference_law_scalar
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

    r = conform_callable(f, paper_cfg, sweep=SMALL, n_random=1000)
    assert r.failed_properties()[0] == "evaluation"
    assert r.failures[0]["state"][1] == 0.0 and "SystemExit" in r.failures[0]["detail"]


def test_nan_at_a_state_is_a_finding(paper_cfg):
    def f(x1, x2, cfg):
        u = reference_law(x1, x2, cfg)
        return np.where(np.abs(x2) > 299.0, np.nan, u)

    r = conform_callable(f, paper_cfg, sweep=SMALL, n_random=1000)
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
    assert props["no-limit-cycle"].status == "fail"
    assert any(f["property"] == "no-limit-cycle" for f in fails)


def test_human_output_names_failures(tmp_path, paper_cfg):
    path = write_law(
        tmp_path,
        """
        def f(x1, x2, cfg):
            from ptoverify.conform.gate import reference_law
            return 1.001 * reference_law(x1, x2, cfg)
        """,
    )
    r = conform_spec(f"{path}:f", paper_cfg, sweep=SMALL, n_random=1000, timeout=120)
    out = format_result(r)
    assert not r.conforms and r.mode == "vectorized"
    assert out.startswith("DOES NOT CONFORM")
    assert "FAILED agreement at state (" in out and "FAILED input-bound-grid at state (" in out


def test_user_output_is_captured(tmp_path, paper_cfg):
    path = write_law(
        tmp_path,
        """
        print("hello from import")
        def f(x1, x2, cfg):
            print("called")
            from ptoverify.conform.gate import reference_law
            return reference_law(x1, x2, cfg)
        """,
    )
    r = conform_spec(f"{path}:f", paper_cfg, sweep=SMALL, n_random=1000, timeout=120)
    assert r.conforms, r.failures
    assert r.law_output.startswith("hello from import\ncalled\n")
    assert "characters left out" in r.law_output  # long output: head and tail kept


# ------------------------------------------------------------------ bad input (exit 2)
@pytest.mark.parametrize(
    "spec",
    [
        "no_such_module_xyz:f",
        "ptoverify.conform.gate:no_such_function",
        "ptoverify.conform.gate:DEFAULT_RTOL",
        "ptoverify.conform.gate",
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
        ["conform", "--law", "ptoverify.conform.gate:reference_law", "--table", "x.csv"],
        ["conform", "--law", "ptoverify.conform.gate:reference_law", "--tolerance", "0"],
        ["conform", "--emit-grid", "/nonexistent/dir/grid.csv"],
    ],
)
def test_bad_arguments_exit_2(capsys, argv):
    assert one_line_error(*run(capsys, *argv))


def test_lawfault_carries_state():
    fault = LawFault((1.0, -2.0), "boom")
    assert fault.state == (1.0, -2.0) and str(fault) == "boom"


def test_reference_law_against_closed_form(paper_cfg):
    """u at a state of each region from the equations: bang, zone (omega_c by brentq), linear."""
    from scipy.optimize import brentq

    cfg = paper_cfg
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    k1, k2 = cfg.pto.k1, cfg.pto.k2
    om = zone_for_law(cfg, "corrected").omega0
    assert reference_law(-40.0, 0.0, cfg) == w and reference_law(40.0, 0.0, cfg) == -w
    for x1, x2 in ((0.3 * d, 2.0), (-0.9 * d, 1.0), (0.2 * d, -250.0)):
        assert reference_law(x1, x2, cfg) == pytest.approx(
            float(np.clip(-k1 * x1 - k2 * x2, -w, w)), rel=1e-12, abs=1e-12
        )
    x2 = -200.0
    l1 = -(x2 + w * np.log(1.0 - x2 / w)) / a  # eq. (9) solved for x1
    l1s = -(x2 + om * np.log(1.0 - x2 / om)) / a  # eq. (13)
    x1 = 0.5 * (l1 + l1s)
    assert abs(x1) >= d, "zone state outside the linear zone"
    omega_c = brentq(lambda g: a * x1 + x2 + g * np.log(1.0 - x2 / g), om, w, xtol=1e-14)
    assert_allclose(reference_law(x1, x2, cfg), omega_c, rtol=1e-12, err_msg="u in S~_P")
    assert_allclose(reference_law(-x1, -x2, cfg), -omega_c, rtol=1e-12, err_msg="u in S~_N")


def test_tolerance_option_is_used(capsys, tmp_path, paper_cfg):
    """float32 output passes at 1e-6 w_max and fails at 1e-9 w_max (rounding ~6e-8 relative)."""
    from ptoverify.conform.agreement import probe_set

    parts = probe_set(paper_cfg).values()
    x1, x2 = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
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
    from ptoverify.conform.userlaw import load_callable

    path = write_law(
        tmp_path,
        """
        class Drive:
            @staticmethod
            def law(x1, x2, cfg):
                from ptoverify.conform.gate import reference_law
                return reference_law(x1, x2, cfg)
        """,
    )
    fn = load_callable(f"{path}:Drive.law")
    assert fn(0.1, 0.0, paper_cfg) == reference_law(0.1, 0.0, paper_cfg)
