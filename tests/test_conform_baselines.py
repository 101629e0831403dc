"""``conform --reference ptos|cascade-p``: the baselines as references, same fail-closed gate.

The implementations judged are examples/my_baselines.py: scalar copies written
from the equations (not from the suite's code), two correct and two with one
wrong constant each.  They run through the command line (``ptoverify.cli.main`` in
this process; each law in its isolated child, as ``ptoverify conform`` runs it).
"""

import contextlib
import io
import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from ptoverify.cli import main
from ptoverify.config import PAPER_MAPPING, config_from_mapping, paper_config
from ptoverify.conform.agreement import band_states, ties
from ptoverify.conform.gate import conform_callable, conformance_grid
from ptoverify.conform.reflaw import has_curves, linear_edge, reference, with_reference
from ptoverify.errors import ConfigError, InputError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "my_baselines.py"


def _example():
    import importlib.util

    spec = importlib.util.spec_from_file_location("my_baselines_example", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def cli(capsys, monkeypatch):
    """``ptoverify conform ... --json`` through ``ptoverify.cli.main``, run from the checkout.

    In this process (the law still runs in its isolated child): the command line is
    what is tested here, not the interpreter's start-up.  Returns the exit code,
    stdout and stderr as ``returncode``, ``stdout``, ``stderr``.
    """
    monkeypatch.chdir(ROOT)  # the specs name examples/my_baselines.py relative to it

    def run(*argv, config=None):
        extra = [] if config is None else ["--config", str(config)]
        capsys.readouterr()
        code = main(["conform", *argv, *extra, "--json"])
        out, err = capsys.readouterr()
        return SimpleNamespace(returncode=code, stdout=out, stderr=err)

    return run


@pytest.fixture(scope="module")
def ptos_report(tmp_path_factory):
    """``conform --law examples/my_baselines.py:ptos --reference ptos --json --report DIR``, once.

    Read by the command line test of ``ptos`` and by the report test: ``--report`` adds
    a folder, not another verdict.  Returns (exit code, stdout, stderr, DIR).
    """
    review = tmp_path_factory.mktemp("ptos") / "review"
    argv = ["--law", f"{EXAMPLE}:ptos", "--reference", "ptos", "--json", "--report", str(review)]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["conform", *argv])
    return code, out.getvalue(), err.getvalue(), review


@pytest.mark.parametrize(
    "fn, ref, conforms",
    [
        ("ptos", "ptos", True),
        ("ptos_no_half", "ptos", False),
        ("cascade_p", "cascade-p", True),
        ("cascade_p_hz", "cascade-p", False),
    ],
)
def test_examples_through_the_command_line(cli, request, fn, ref, conforms):
    if fn == "ptos":  # the run the report test reads too
        code, out, err, _ = request.getfixturevalue("ptos_report")
        p = SimpleNamespace(returncode=code, stdout=out, stderr=err)
    else:
        p = cli("--law", f"examples/my_baselines.py:{fn}", "--reference", ref)
    assert p.returncode == (0 if conforms else 1), p.stderr
    data = json.loads(p.stdout)
    assert data["conforms"] is conforms and data["reference"] == ref
    agree = data["agreement"]
    assert agree["excluded"] == 0  # a continuous reference has no curve ties
    if conforms:
        assert agree["max_abs_du"] <= agree["tolerance_mm_s"]
        assert all(v["status"] == "pass" for v in data["properties"].values())
    else:
        assert data["properties"]["agreement"]["status"] == "fail"
        assert any(f["property"] == "agreement" for f in data["failures"])


def _baseline_config():
    """Gains away from the defaults: PTOS with k > a (its square-root branch acts), kp set."""
    a = paper_config().plant.a
    m = {**PAPER_MAPPING, "ptos": {"alpha": 0.7, "k": 2.5 * a}, "cascade": {"kp": 80.0}}
    return config_from_mapping(m)


def test_copies_follow_the_configured_gains():
    """At other gains the correct copies still conform and the wrong ones do not."""
    ex, cfg = _example(), _baseline_config()
    sweep = (11, 11, 10)
    r = conform_callable(ex.ptos, with_reference(cfg, "ptos"), sweep=sweep)
    regions = r.agreement["regions"]
    # the square-root branch is judged where it acts unclipped (k > a), not only its edge
    assert regions["ZONE_P"]["points"] + regions["ZONE_N"]["points"] > 1000
    assert r.conforms and r.reference == "ptos"
    bad = conform_callable(ex.ptos_no_half, with_reference(cfg, "ptos"), sweep=sweep)
    assert not bad.conforms and "agreement" in bad.failed_properties()
    r = conform_callable(ex.cascade_p, with_reference(cfg, "cascade-p"), sweep=sweep)
    assert r.conforms
    # the reference selection matters: a correct PTOS is not a cascade P loop
    cross = conform_callable(ex.ptos, with_reference(cfg, "cascade-p"), sweep=sweep)
    assert not cross.conforms and "agreement" in cross.failed_properties()


def test_reference_law_and_edges_against_hand_computation():
    cfg = paper_config()
    a, w = cfg.plant.a, cfg.plant.w_max
    alpha = cfg.ptos.alpha
    # k = a: k1 = alpha a^2 / 2, y_l = a w / k1 = 2 w / (alpha a)
    assert math.isclose(
        linear_edge(with_reference(cfg, "ptos")), 2 * w / (alpha * a), rel_tol=1e-14
    )
    assert math.isclose(linear_edge(with_reference(cfg, "cascade-p")), w / (a / 4), rel_tol=1e-14)
    assert linear_edge(cfg) == cfg.pto.d and has_curves(cfg)
    x1 = np.array([0.3, -2.0, 4.0, -40.0])
    u, _ = reference(with_reference(cfg, "cascade-p"))(x1, np.zeros(4))
    np.testing.assert_allclose(u, np.clip(-(a / 4) * x1, -w, w), rtol=1e-15)
    u, _ = reference(with_reference(cfg, "ptos"))(x1, np.zeros(4))
    np.testing.assert_allclose(u, np.clip(-(alpha * a / 2) * x1, -w, w), rtol=1e-14)


def test_baseline_probes_crowd_its_edge_and_have_no_ties():
    for name in ("ptos", "cascade-p"):
        cfg = with_reference(paper_config(), name)
        g1, g2 = conformance_grid(cfg)
        assert not ties(g1, g2, cfg).any() and not has_curves(cfg)
        edge = linear_edge(cfg)
        assert np.any(g1 == edge) and np.any(g1 == -edge)
        b1, _ = band_states(cfg, 8000)
        near = np.abs(np.abs(b1) - edge) <= max(2 * cfg.pto.d, 0.02 * cfg.plant.position_range)
        assert near.mean() > 0.2  # the n/4 edge band sits at the baseline's edge


def test_reference_is_bad_input_when_unknown(cli, tmp_path):
    with pytest.raises(InputError, match="--reference"):
        with_reference(paper_config(), "pd")
    with pytest.raises(ConfigError, match="conform.reference"):
        config_from_mapping({**PAPER_MAPPING, "conform": {"reference": "xyz"}})
    p = cli("--law", "examples/my_baselines.py:ptos", "--reference", "xyz")
    assert p.returncode == 2 and p.stdout == "" and "ptoverify: error:" in p.stderr
    cfgfile = tmp_path / "c.toml"
    cfgfile.write_text(_paper_toml() + '\n[conform]\nreference = "xyz"\n')
    p = cli("--law", "examples/my_baselines.py:ptos", config=cfgfile)
    assert p.returncode == 2 and "conform.reference" in p.stderr and p.stdout == ""


def _paper_toml() -> str:
    return (
        'name = "paper"\n[plant]\nbandwidth_hz = 30.0\nw_max = 300.0\nsample_time = 0.002\n'
        "position_range = 50.0\n[pd]\nkp = 356.0\nkd = 1.15\n[pto]\nd = 0.5\nk1 = 323.0\n"
        "k2 = 3.6\n"
    )


def test_config_table_selects_the_reference(tmp_path, capsys):
    cfgfile = tmp_path / "c.toml"
    cfgfile.write_text(_paper_toml() + '\n[conform]\nreference = "cascade-p"\n')
    grid = tmp_path / "grid.csv"
    assert main(["conform", "--emit-grid", str(grid), "--config", str(cfgfile)]) == 0
    data = np.loadtxt(grid, delimiter=",", skiprows=1)
    ex, cfg = (
        _example(),
        config_from_mapping({**PAPER_MAPPING, "conform": {"reference": "cascade-p"}}),
    )
    for fn, code in ((ex.cascade_p, 0), (ex.cascade_p_hz, 1)):
        u = [fn(float(a), float(b), cfg) for a, b in data]
        table = tmp_path / f"{fn.__name__}.csv"
        table.write_text(
            "x1,x2,u\n" + "".join(f"{a!r},{b!r},{c!r}\n" for (a, b), c in zip(data.tolist(), u))
        )
        capsys.readouterr()
        assert main(["conform", "--table", str(table), "--config", str(cfgfile), "--json"]) == code
        out = json.loads(capsys.readouterr().out)
        assert out["reference"] == "cascade-p" and out["conforms"] is (code == 0)


def test_report_names_the_baseline(ptos_report):
    code, _, _, out = ptos_report
    assert code == 0
    md = (out / "report.md").read_text()
    assert "reference ptos law" in md and "| reference law | ptos |" in md.replace("  ", " ")


def test_ptos_table_filling_the_lattice_is_covered(tmp_path, capsys):
    """A PTOS table on the lattice (not the probe set): its zone regions have no area at k = a."""
    from ptoverify.conform.agreement import random_states
    from ptoverify.conform.probes import LATTICE

    ex = _example()
    cfg = with_reference(paper_config(), "ptos")
    x1, x2 = random_states(cfg, 2 * LATTICE * LATTICE)
    u = [ex.ptos(a, b, cfg) for a, b in zip(x1.tolist(), x2.tolist())]

    def write(path, keep):
        path.write_text(
            "x1,x2,u\n"
            + "".join(
                f"{a!r},{b!r},{c!r}\n"
                for a, b, c, k in zip(x1.tolist(), x2.tolist(), u, keep.tolist())
                if k
            )
        )
        return str(path)

    full = write(tmp_path / "lattice.csv", np.ones(x1.size, dtype=bool))
    assert main(["conform", "--table", full, "--reference", "ptos", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["properties"]["coverage"]["status"] == "pass" and out["conforms"]
    # the rule still bites: half the envelope is not enough
    half = write(tmp_path / "half.csv", x1 < 0)
    assert main(["conform", "--table", half, "--reference", "ptos", "--json"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["properties"]["coverage"]["status"] == "fail"


@pytest.mark.parametrize(
    ("table", "name"),
    [
        ({"cascade": {"kp": 0.0}}, "cascade-p"),  # u = sat(0 x1): no clip anywhere
        ({"cascade": {"kp": 1e-300}}, "cascade-p"),  # clip starts 3e302 mm out
        ({"ptos": {"alpha": 1e-300}}, "ptos"),  # y_l about 3e300 mm
    ],
)
def test_baseline_edge_beyond_the_envelope_is_the_envelope(table, name):
    # audit run 7: [cascade] kp = 0 (accepted) made linear_edge divide by zero, an internal
    # error of `conform --reference cascade-p` and of `--emit-grid`
    cfg = with_reference(config_from_mapping({**PAPER_MAPPING, **table}), name)
    R, w = cfg.plant.position_range, cfg.plant.w_max
    assert linear_edge(cfg) == R
    g1, g2 = conformance_grid(cfg)
    assert np.isfinite(g1).all() and np.isfinite(g2).all()
    # the whole envelope is in the linear region: the reference is the linear law there
    x1 = np.linspace(-R, R, 11)
    u, _ = reference(cfg)(x1, np.zeros_like(x1))
    assert np.all(np.abs(u) < w)


def test_cli_emit_grid_with_zero_cascade_gain(cli, tmp_path):
    cfgfile = tmp_path / "c.toml"
    cfgfile.write_text(_paper_toml() + "\n[cascade]\nkp = 0\n")
    out = tmp_path / "g.csv"
    p = cli("--emit-grid", str(out), "--reference", "cascade-p", config=cfgfile)
    assert p.returncode == 0, p.stderr
    assert "internal error" not in p.stderr and out.stat().st_size > 0
