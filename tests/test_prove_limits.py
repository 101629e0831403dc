"""``prove``'s work is estimated from the configuration and bounded up front (issue 28, R9, R10).

The estimate (:mod:`ptoverify.studies.prove.work`) is checked against the work the
proof really does: its cells and refined cells are counted exactly (equal to the
grid's and to the cells the proof's own first no-stride-over check leaves open), and
every box check the refinement makes stays within the guaranteed bound.  The audit's
configurations (a T = 20; every gain and d zero) are refused at once through the
real command line, and the paper's laws stay within the limits with margin.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ptoverify.studies.prove.run as prove_run
import ptoverify.studies.prove.stride as stride_mod
from ptoverify.config import config_from_mapping, paper_config
from ptoverify.errors import ConfigError, InputError
from ptoverify.model.lawbox import law_spec
from ptoverify.studies.prove import PROVE_LAWS, default_pieces
from ptoverify.studies.prove.ball import Resolution
from ptoverify.studies.prove.graph import make_grid
from ptoverify.studies.prove.run import prove_law
from ptoverify.studies.prove.work import (
    BOXES_PER_REFINED_CELL,
    MAX_PROOF_CELLS,
    MAX_PROOF_PIECES,
    MAX_PROOF_WORK,
    box_checks_bound,
    proof_work,
    sub_intervals,
)

#: The coarse grid of tests/test_prove.py (about 2,000 cells): cheap real proofs.
COARSE = Resolution(h1=0.2, h2=20.0, h1_max=5.0, h_edge=0.5, steps=40)

PAPER_TOML = """name = "{name}"
[plant]
bandwidth_hz = 30.0
w_max = 300.0
sample_time = {T}
position_range = 50.0
[pd]
kp = {kp}
kd = {kd}
[pto]
d = {d}
k1 = {k1}
k2 = {k2}
"""

#: The audit's R9 (a T = 20: sample_time 0.1061 s at the paper's a) and R10 (every gain and
#: d zero), with the paper's other values.
AUDIT = {
    "R9": dict(name="r9", T=0.1061, kp=356.0, kd=1.15, d=0.5, k1=323.0, k2=3.6),
    "R10": dict(name="r10", T=0.002, kp=0.0, kd=0.0, d=0.0, k1=0.0, k2=0.0),
}


@pytest.mark.parametrize("case", sorted(AUDIT))
def test_audit_configurations_are_refused_at_once_through_the_cli(tmp_path, case):
    """``ptoverify prove`` (the paper's four laws) on R9 / R10: exit 2 within seconds, one line
    naming the keys and the limit; it passed 10 GB (R9) or ran 751 s (R10) before."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(PAPER_TOML.format(**AUDIT[case]))
    t0 = time.perf_counter()
    res = subprocess.run(
        [sys.executable, "-m", "ptoverify", "prove", "--json", "--config", str(cfg)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    took = time.perf_counter() - t0
    assert res.returncode == 2, res.stderr
    assert res.stdout == ""
    err = res.stderr.strip()
    assert err.count("\n") == 0, err
    assert "plant.sample_time" in err and "pto.d" in err and f"{MAX_PROOF_WORK:,}" in err, err
    assert took < 15.0, f"refused only after {took:.1f} s"


def test_the_paper_laws_stay_within_the_limits_with_margin():
    """Every law prove covers at the paper's values, and pto over the default [robustness]
    box's a_ratio (check --robust's interval proof): at most 2/3 of the limits."""
    cfg = paper_config()
    a = cfg.plant.a
    lo, hi = cfg.robustness.a_ratio
    interval = sub_intervals(lo * a, hi * a, default_pieces((lo * a, hi * a)))
    runs = [(law, [(a, a)]) for law in (*PROVE_LAWS, "cascade-p")] + [("pto", interval)]
    for law, pieces in runs:
        w = proof_work(cfg, law_spec(law, cfg), Resolution(), pieces)
        assert w.cells <= MAX_PROOF_CELLS / 1.5, (law, w)
        assert w.estimate <= MAX_PROOF_WORK / 1.5, (law, w)
    assert len(interval) <= MAX_PROOF_PIECES


def _counted_proof(cfg, law, **kw):
    """Run prove_law counting every box the no-stride-over check evaluates.

    Returns the proof, the box checks and the cells the first check (the whole grid)
    leaves open, per sub-interval."""
    calls = []
    real = stride_mod._check

    def counting(spec, c, maps, boxes):
        s, r = real(spec, c, maps, boxes)
        calls.append((boxes[0].size, int((~s | ~r).sum())))
        return s, r

    mp = pytest.MonkeyPatch()
    mp.setattr(stride_mod, "_check", counting)
    mp.setattr(prove_run, "check_provable", lambda *a, **k: None)  # count the proof only
    try:
        proof = prove_law(cfg, law, n_random=0, **kw)
    finally:
        mp.undo()
    first = [open_ for n, open_ in calls if n == proof.cells]
    return proof, sum(n for n, _ in calls), first


@pytest.mark.parametrize(
    "law, pieces",
    [("to", 1), ("pto", 1), ("pd", 2)],
)
def test_the_estimate_counts_the_work_the_proof_does(law, pieces):
    """Cells and refined cells exact; box checks within the guaranteed bound and within the
    estimate; most of the estimate for a law whose refined cells fail on an area (to)."""
    cfg = paper_config()
    a = cfg.plant.a
    a_interval = (0.97 * a, 1.03 * a) if pieces > 1 else None
    lo, hi = a_interval or (a, a)
    w = proof_work(cfg, law_spec(law, cfg), COARSE, sub_intervals(lo, hi, pieces))
    proof, checks, first = _counted_proof(
        cfg, law, res=COARSE, a_interval=a_interval, pieces=pieces
    )
    assert w.cells == proof.cells
    assert list(w.refined) == first  # the proof refines exactly the cells counted
    assert w.pieces == pieces
    total_bound = sum(box_checks_bound(f, w.cells) for f in w.refined)
    assert checks <= total_bound, (checks, total_bound)
    assert max(w.refined) > 0
    # not guaranteed, but an upper bound in every case measured (README)
    assert checks <= w.pieces * w.estimate, (checks, w.estimate)
    if law == "to":  # its refined cells fail on areas: most of the estimate is real work
        assert checks >= 0.5 * w.estimate, (checks, w.estimate)


def test_the_guaranteed_bound_follows_the_refinement_rule():
    """64 children of the cell, 64 of each (<= cap), then <= cap x 64 per level, 8 levels."""
    per_cell = 64 + 64 * 64 + 6 * 256 * 64
    assert box_checks_bound(3, 10) == 10 + 3 * per_cell
    assert BOXES_PER_REFINED_CELL == 64 + 64 * 64


def test_too_many_sub_intervals_are_refused_before_any_work():
    cfg = paper_config()
    a = cfg.plant.a
    with pytest.raises(InputError, match=f"over the limit of {MAX_PROOF_PIECES}"):
        prove_law(cfg, "pd", a_interval=(0.5 * a, a), pieces=MAX_PROOF_PIECES + 1, n_random=0)


def test_a_fine_strip_wider_than_the_envelope_keeps_the_grid_increasing():
    """A low gain makes w_max / g1 exceed position_range: the edges were not increasing."""
    g = make_grid(2.0, 10.0, 3.0, 0.02, 5.0, 2.0)
    assert g.e1[0] == -2.0 and g.e1[-1] == 2.0
    assert (g.e1[1:] > g.e1[:-1]).all()
    assert g.shape[0] == 200  # all fine


def test_a_grid_over_the_cell_limit_is_refused_before_it_is_built():
    """PD with kp = 1: fine cells over the whole envelope, 600,000 of them."""
    cfg = paper_config()
    cfg = replace(cfg, pd=replace(cfg.pd, kp=1.0))
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=rf"proof cells .*over the limit of {MAX_PROOF_CELLS:,}"):
        prove_law(cfg, "pd", n_random=0)
    assert time.perf_counter() - t0 < 5.0


def _mapping(a, w_max, T, position_range, d_frac, gain):  # noqa: N803
    return {
        "name": "drawn",
        "plant": {"a": a, "w_max": w_max, "sample_time": T, "position_range": position_range},
        "pd": {"kp": gain / T, "kd": gain},
        "pto": {"d": d_frac * position_range, "k1": gain / T, "k2": gain},
    }


@settings(max_examples=12, deadline=None, derandomize=True)
@given(
    aT=st.floats(0.01, 20.0),
    w_max=st.floats(1.0, 3000.0),
    n_range=st.floats(2.0, 2000.0),
    d_frac=st.floats(0.0, 1.0),
    gain=st.sampled_from([0.0, 0.05, 0.5, 2.0]),
    law=st.sampled_from([*PROVE_LAWS, "cascade-p"]),
)
def test_every_accepted_configuration_is_estimated_or_refused_in_one_line(
    aT,  # noqa: N803
    w_max,
    n_range,
    d_frac,
    gain,
    law,
):
    """Across the accepted space the up-front check either accepts within the stated limits
    or refuses in one line naming the limit; never another exception, and quickly."""
    T = 0.002  # noqa: N806
    m = _mapping(aT / T, w_max, T, n_range * w_max * T, d_frac, gain)
    try:
        cfg = config_from_mapping(m)
    except ConfigError:
        return
    t0 = time.perf_counter()
    try:
        prove_run.check_provable(
            cfg, Resolution(), law_spec(law, cfg), [(cfg.plant.a, cfg.plant.a)]
        )
    except InputError as exc:
        msg = str(exc)
        assert msg.startswith("prove: ") and "\n" not in msg
        assert "limit" in msg or "d must be smaller" in msg or "proof cells" in msg, msg
    else:
        w = proof_work(cfg, law_spec(law, cfg), Resolution(), [(cfg.plant.a, cfg.plant.a)])
        assert w.cells <= MAX_PROOF_CELLS and w.estimate <= MAX_PROOF_WORK
        assert math.isfinite(w.estimate)
    assert time.perf_counter() - t0 < 10.0


def test_report_refuses_an_over_limit_proof_before_any_stage(tmp_path, capsys):
    """The report's proofs stage would run the refused proof: exit 2 at once, nothing written."""
    from ptoverify.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text(PAPER_TOML.format(**AUDIT["R10"]))
    out = tmp_path / "report"
    t0 = time.perf_counter()
    assert main(["report", "--config", str(cfg), "--out", str(out)]) == 2
    assert time.perf_counter() - t0 < 15.0
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and f"{MAX_PROOF_WORK:,}" in err, err
    assert not out.exists()


def test_refining_in_chunks_of_cells_gives_the_same_result():
    """The refinement runs a chunk of cells at a time (bounded memory); each cell is refined
    on its own, so chunks of 7 cells and one chunk of all give identical results."""
    from ptoverify.model.zohmaps import step_maps
    from ptoverify.studies.prove.ball import law_grid
    from ptoverify.studies.prove.stride import stride_check

    cfg = paper_config()
    spec = law_spec("to", cfg)
    boxes = law_grid(cfg, spec, COARSE, 0.0).boxes()
    maps = step_maps((cfg.plant.a, cfg.plant.a), cfg.plant.sample_time, 1)
    one, many = (stride_check(spec, cfg, maps, boxes, chunk=c) for c in (10**9, 7))
    assert one.leaves[0].size > 0 and one.depth == many.depth
    for field in ("strict", "relaxed", "strict_gap", "relaxed_gap"):
        assert (getattr(one, field) == getattr(many, field)).all(), field
    for q in range(4):
        assert (one.leaves[q] == many.leaves[q]).all()
