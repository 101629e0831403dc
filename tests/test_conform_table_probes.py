"""``conform --table`` sees what ``--law`` sees: the emitted probe set, and its coverage rule.

Every table here is built as a firmware team would: ``conform --emit-grid``
through the CLI, the law (the reference, or a mutant of ``tests/pto_mutants.py``)
evaluated at the emitted states in file order, in batches of 1000 rows.  The
reference, the band mutants and the tables of the coverage rule are written as
CSV (columns x1, x2, u) and judged by ``conform --table`` through
``ptoverify.cli.main``.  The other mutants' values are judged by
:func:`ptoverify.conform.table.judge_table`, the judgement ``conform --table``
makes after reading the file, at the emitted states: the CSV round trip is exact
(every number written as its repr), which
:func:`test_judging_in_memory_is_judging_the_file` checks on a mutant.
"""

import contextlib
import io
import json

import numpy as np
import pytest
from pto_mutants import BENIGN, MUTANTS, make_law

from ptoverify.cli import main
from ptoverify.cli.common import to_jsonable
from ptoverify.config import paper_config
from ptoverify.conform import agreement as agreement_mod
from ptoverify.conform.agreement import (
    LATTICE,
    N_BAND,
    N_RANDOM,
    conformance_grid,
    probe_set,
    table_coverage,
    tie_band,
)
from ptoverify.conform.gate import conform_callable, reference_law
from ptoverify.conform.table import judge_table
from ptoverify.model.curves import level_curve_x1
from ptoverify.model.laws import Region
from ptoverify.model.laws import make_law as make_ref

BANDS = ("slow_band_x1", "slow_band_x2")


def in_band(name, state):
    s1, s2 = np.abs(state)
    return 30.2 < s1 < 31.4 if name == "slow_band_x1" else (101 < s2 < 109 and s1 > 2)


@pytest.fixture(scope="module")
def emitted_file(tmp_path_factory):
    """The file ``conform --emit-grid`` writes (once per module: every test reads it only)."""
    path = tmp_path_factory.mktemp("emit") / "grid.csv"
    assert main(["conform", "--emit-grid", str(path)]) == 0
    return path


@pytest.fixture(scope="module")
def emitted(emitted_file):
    """The states ``conform --emit-grid`` writes (x1 [mm], x2 [mm/s]), read back from the file."""
    with open(emitted_file) as fh:
        assert fh.readline().strip() == "x1,x2"
    data = np.loadtxt(emitted_file, delimiter=",", skiprows=1)
    x1, x2 = data[:, 0].copy(), data[:, 1].copy()
    x1.flags.writeable = x2.flags.writeable = False  # shared by the module's tests
    return x1, x2


@pytest.fixture(scope="module")
def emitted_rows(emitted_file):
    """The data lines of the emitted file, as text (``x1,x2``), in file order."""
    with open(emitted_file) as fh:
        return fh.read().splitlines()[1:]


def evaluate(law, x1, x2, cfg, batch=1000):
    """Evaluate as firmware does: the rows in file order, a batch at a time."""
    return np.concatenate(
        [
            np.atleast_1d(law(x1[i : i + batch], x2[i : i + batch], cfg))
            for i in range(0, x1.size, batch)
        ]
    )


def write(path, x1, x2, u):
    """Write the table x1, x2, u; each number as Python's repr (the shortest exact round trip)."""
    return write_rows(path, [f"{a!r},{b!r}" for a, b in zip(x1.tolist(), x2.tolist())], u)


def write_rows(path, rows, u):
    """Write the table: each state's text ``x1,x2`` as given (the emitted file's), then ``u``."""
    assert len(rows) == u.size
    with open(path, "w") as fh:
        fh.write("x1,x2,u\n")
        fh.writelines(f"{r},{v!r}\n" for r, v in zip(rows, u.tolist()))
    return path


def conform_json(capsys, table):
    code = main(["conform", "--table", str(table), "--json"])
    out, _ = capsys.readouterr()
    return code, json.loads(out)


@pytest.fixture(scope="module")
def mutant_table(tmp_path_factory, emitted, emitted_rows):
    """``judge(name)``: (exit code, JSON) of the table of a variant, as ``conform --table``.

    The variant of ``tests/pto_mutants.py`` evaluated at the emitted states (as
    firmware does); ``judge(name, cli=True)`` writes the table from the emitted
    rows and runs ``conform --table --json``, ``judge(name)`` judges the same
    values with :func:`judge_table` and formats them as ``--json`` does.  Each
    variant judged once per route and module.
    """
    done, cfg = {}, paper_config()

    def judge(name, cli=False):
        if (name, cli) not in done:
            x1, x2 = emitted
            u = evaluate(make_law([name]), x1, x2, cfg)
            if cli:
                path = write_rows(tmp_path_factory.mktemp("table") / f"{name}.csv", emitted_rows, u)
                out = io.StringIO()
                with contextlib.redirect_stdout(out):
                    code = main(["conform", "--table", str(path), "--json"])
                path.unlink()  # 10 MB each
                done[name, cli] = code, json.loads(out.getvalue())
            else:
                r = judge_table(x1, x2, u, cfg, source=f"{name}.csv")
                data = json.loads(json.dumps(to_jsonable(r.to_json()), allow_nan=False))
                done[name, cli] = (0 if r.conforms else 1), data
        return done[name, cli]

    return judge


# ------------------------------------------------------------------ the probe set
def test_emitted_file_is_the_probe_set(emitted, paper_cfg):
    """Grid, 100,000 random states and the band, in that order, exactly (repr round trip)."""
    x1, x2 = emitted
    parts = probe_set(paper_cfg)
    assert [k for k in parts] == ["grid", "random", "band"]
    assert parts["random"][0].size == N_RANDOM and parts["band"][0].size <= N_BAND
    assert np.array_equal(x1, np.concatenate([p[0] for p in parts.values()]))
    assert np.array_equal(x2, np.concatenate([p[1] for p in parts.values()]))
    assert 150_000 <= x1.size <= 400_000, "a practical file: a few 10^5 rows"
    R, w = paper_cfg.plant.position_range, paper_cfg.plant.w_max
    assert np.all(np.abs(x1) <= R) and np.all(np.abs(x2) <= w)


def test_random_states_fill_every_lattice_cell(paper_cfg):
    """One jittered state in each of the LATTICE^2 cells, in the cell's middle 80 %."""
    R, w = paper_cfg.plant.position_range, paper_cfg.plant.w_max
    r1, r2 = probe_set(paper_cfg)["random"]
    f1 = (r1[: LATTICE**2] / R + 1.0) * 0.5 * LATTICE
    f2 = (r2[: LATTICE**2] / w + 1.0) * 0.5 * LATTICE
    cells = np.floor(f1).astype(int) * LATTICE + np.floor(f2).astype(int)
    assert np.array_equal(np.sort(cells), np.arange(LATTICE**2))
    for f in (f1, f2):
        frac = f - np.floor(f)
        assert frac.min() >= 0.1 - 1e-9 and frac.max() <= 0.9 + 1e-9


def test_band_states_hug_the_curves_and_edges(paper_cfg):
    """Every band state lies within max(2 d, 0.02 R) of l1/l2, l1*/l2* or x1 = +-d, some at 1e-5 mm."""
    p, d = paper_cfg.plant, paper_cfg.pto.d
    from ptoverify.conform.agreement import omega0_ref

    b1, b2 = probe_set(paper_cfg)["band"]
    om = omega0_ref(paper_cfg)
    dist = np.minimum.reduce(
        [
            np.abs(b1 - level_curve_x1(b2, p.a, p.w_max)),
            np.abs(b1 - level_curve_x1(b2, p.a, om)),
            np.abs(np.abs(b1) - d),
        ]
    )
    hi = max(2 * d, 0.02 * p.position_range)
    assert dist.max() <= hi * (1 + 1e-9)
    assert np.sum(dist < 1e-5) > 1000 and np.sum(dist > 0.1 * hi) > 5000
    assert dist.min() > 0.0 and tie_band(paper_cfg) > 0.0


def test_callable_route_probes_the_same_set(paper_cfg):
    r = conform_callable(reference_law, paper_cfg, sweep=(3, 3, 2))
    src = r.agreement["sources"]
    parts = probe_set(paper_cfg)
    for k in ("grid", "random", "band"):
        assert src[k] == parts[k][0].size
    assert r.conforms


# ------------------------------------------------------------------ the table route
def test_reference_at_emitted_states_conforms(capsys, tmp_path, emitted, paper_cfg, emitted_rows):
    x1, x2 = emitted
    u = evaluate(reference_law, x1, x2, paper_cfg)
    code, data = conform_json(capsys, write_rows(tmp_path / "ref.csv", emitted_rows, u))
    assert code == 0 and data["conforms"], data["failures"][:2]
    assert data["properties"]["coverage"]["status"] == "pass"
    assert data["agreement"]["coverage"]["missing"] == 0
    assert data["properties"]["odd-symmetry"]["status"] == "pass"


@pytest.mark.parametrize("name", BANDS)
def test_band_mutant_killed_through_table(mutant_table, name):
    """5 % slow between grid columns: caught at the emitted random/band states."""
    code, data = mutant_table(name, cli=True)
    assert code == 1 and not data["conforms"]
    fail = next(f for f in data["failures"] if f["property"] == "agreement")
    assert in_band(name, fail["state"]), fail


@pytest.mark.parametrize("name", BANDS)
def test_band_mutant_on_grid_only_is_insufficient_coverage(capsys, tmp_path, paper_cfg, name):
    """The old hole: a table of the fixed grid alone no longer conforms."""
    x1, x2 = conformance_grid(paper_cfg)
    u = evaluate(make_law([name]), x1, x2, paper_cfg)
    code, data = conform_json(capsys, write(tmp_path / "g.csv", x1, x2, u))
    assert data["properties"]["agreement"]["status"] == "pass", "the grid alone sees it (moot)"
    assert code == 1 and data["failures"][0]["property"] == "coverage"
    assert "insufficient coverage" in data["failures"][0]["detail"]


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(MUTANTS) - set(BANDS)))
def test_every_mutant_killed_through_table(mutant_table, name):
    """Memory faults show too: the batches make a stateful law disagree with itself."""
    code, data = mutant_table(name)
    assert code == 1 and not data["conforms"], f"{name} ({MUTANTS[name]}) conforms by table"
    props = {f["property"] for f in data["failures"]}
    assert props & {"agreement", "odd-symmetry", "input-bound-grid"}, props
    if name == "tie_asym":  # ties are excluded from agreement: the mirror sees it
        assert "odd-symmetry" in props and "curve tie" in data["failures"][0]["detail"]


def test_tie_asymmetry_killed_through_table(mutant_table):
    code, data = mutant_table("tie_asym")
    assert code == 1 and [f["property"] for f in data["failures"]] == ["odd-symmetry"]


@pytest.mark.parametrize("name", ["slow_band_x1", "tie_asym"])
def test_judging_in_memory_is_judging_the_file(mutant_table, name):
    """The file route and :func:`judge_table` give the same verdict, failures and figures."""
    (code, data), (code_cli, data_cli) = mutant_table(name), mutant_table(name, cli=True)
    assert code == code_cli == 1
    for key in ("timings_s", "target"):
        data.pop(key), data_cli.pop(key)
    assert data == data_cli


@pytest.mark.parametrize("name", sorted(set(BENIGN) - {"faithful"}))
def test_benign_variants_conform_through_table(mutant_table, name):
    code, data = mutant_table(name)
    assert code == 0, data["failures"][:2]


# ------------------------------------------------------------------ the coverage rule
def test_shuffled_float32_states_still_hold_the_probe_set(emitted, paper_cfg):
    """Rows in any order, states rounded to float32 (6e-8 relative): every probe is held."""
    x1, x2 = emitted
    perm = np.random.default_rng(3).permutation(x1.size)
    f1 = x1.astype(np.float32).astype(float)[perm]
    f2 = x2.astype(np.float32).astype(float)[perm]
    cov = table_coverage(f1, f2, paper_cfg)
    assert cov["missing"] == 0 and cov["empty_cells"] == 0
    exact = table_coverage(x1[perm], x2[perm], paper_cfg)
    g = exact["grid_rows"]
    gx1, gx2 = probe_set(paper_cfg)["grid"]
    assert np.array_equal(x1[perm][g], gx1) and np.array_equal(x2[perm][g], gx2)


def test_missing_probe_is_named(emitted, paper_cfg):
    x1, x2 = emitted
    k = x1.size - 7  # a band state
    keep = np.arange(x1.size) != k
    cov = table_coverage(x1[keep], x2[keep], paper_cfg)
    assert cov["missing"] == 1 and cov["first_missing"] == [x1[k], x2[k]]


def test_fixed_point_states_pass_by_filling_the_lattice(capsys, tmp_path, emitted, paper_cfg):
    """States rounded to Q15 of the envelope miss the probes but fill every cell: conforms."""
    R, w = paper_cfg.plant.position_range, paper_cfg.plant.w_max
    x1, x2 = emitted
    q1 = np.round(x1 / R * 2**15) / 2**15 * R
    q2 = np.round(x2 / w * 2**15) / 2**15 * w
    u = evaluate(reference_law, q1, q2, paper_cfg)
    code, data = conform_json(capsys, write(tmp_path / "q.csv", q1, q2, u))
    cov = data["agreement"]["coverage"]
    assert cov["missing"] > 0 and cov["empty_cells"] == 0
    assert code == 0 and "fills all" in data["properties"]["coverage"]["detail"]


def test_uniform_sample_leaves_cells_empty(capsys, tmp_path, paper_cfg):
    """30,000 uniform states: cells left empty (Poisson: ~40000 e^-0.75) is insufficient."""
    R, w = paper_cfg.plant.position_range, paper_cfg.plant.w_max
    rng = np.random.default_rng(7)
    x1, x2 = rng.uniform(-R, R, 30_000), rng.uniform(-w, w, 30_000)
    x1[0] = x2[0] = 0.0
    code, data = conform_json(
        capsys, write(tmp_path / "u.csv", x1, x2, reference_law(x1, x2, paper_cfg))
    )
    assert code == 1 and "cells empty" in data["failures"][0]["detail"]


def test_dropping_a_region_is_insufficient_even_with_cells_filled(
    capsys, tmp_path, emitted, paper_cfg, emitted_rows
):
    x1, x2 = emitted
    keep = make_ref("pto", paper_cfg)(x1, x2)[1] != Region.ZONE_P
    u = reference_law(x1[keep], x2[keep], paper_cfg)
    code, data = conform_json(
        capsys, write_rows(tmp_path / "z.csv", [r for r, k in zip(emitted_rows, keep) if k], u)
    )
    assert code == 1 and "ZONE_P 0 < 100" in data["properties"]["coverage"]["detail"]


def test_large_random_table_fills_cells_but_misses_probes(paper_cfg):
    """A million random rows: every cell filled, almost no probe held (1e-6 matching)."""
    R, w = paper_cfg.plant.position_range, paper_cfg.plant.w_max
    rng = np.random.default_rng(9)
    x1, x2 = rng.uniform(-R, R, 1_000_000), rng.uniform(-w, w, 1_000_000)
    cov = table_coverage(x1, x2, paper_cfg)
    assert cov["missing"] > 0.9 * cov["probes"] and cov["empty_cells"] == 0
    assert agreement_mod.MATCH_TOL == 1e-6
