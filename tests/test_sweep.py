"""Sweep: batch results agree with single-state simulations; CLI contract."""

import json
import math
import os
import stat

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.model.laws import Region, make_law
from ptoverify.model.mintime import discrete_min_steps, min_time
from ptoverify.model.ocp import TwoPhaseOCP
from ptoverify.sim.exact import settling_times_batch
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import SettlingDefinition, grid_settling
from ptoverify.sim.simulate import simulate_batch
from ptoverify.studies.sweep import (
    SweepSettings,
    grid_states,
    run_sweep,
    settling_times,
)

SMALL = SweepSettings(n1=6, n2=5)


@pytest.fixture(scope="module")
def small():
    return run_sweep(paper_config(), SMALL)


def first_settled_sample(x1, x2, band, vband, hold_steps):
    """Reference by enumeration: the first sample k from which every later sample is in
    the box, held for at least ``hold_steps`` samples after it; -1 if none."""
    last = len(x1) - 1
    for k in range(last + 1):
        if all(abs(x1[j]) <= band and abs(x2[j]) <= vband for j in range(k, last + 1)):
            return k if last - k >= hold_steps else -1
    return -1


def test_grid_settling_definition():
    """The named definitions read on the samples: hand-checked records."""
    x1 = np.array([[1.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.005, 0.0, 0.02], [0.0, 0.0, 0.0]])
    x2 = np.zeros_like(x1)
    T, a = 0.5, 10.0
    box = SettlingDefinition("t", "test", band_mm=0.01, velocity_band_mm=0.1, hold_s=T)
    tr = Trajectory(np.arange(4) * T, x1, x2, np.zeros((3, 3)), a)
    got = grid_settling(tr, None, box)
    # last sample outside -> settles at the next one; never outside -> 0; short tail -> NaN
    assert_allclose(got, [T, 0.0, np.nan], err_msg="grid settling time [s]")
    for j in range(3):
        k = first_settled_sample(x1[:, j], x2[:, j], 0.01, a * 0.1, 1)
        assert (k * T if k >= 0 else None) == (None if np.isnan(got[j]) else got[j])


def test_small_sweep_agrees_with_single_state_runs(small):
    """Each grid state's settling times equal a one-state run's: the exact reading
    (``settling_times_batch`` on that one record), the grid reading (enumerated);
    ratios use t_f* and N* (LP reference)."""
    cfg = paper_config()
    p = cfg.plant
    vband = p.a * SMALL.band
    hold = math.ceil(SMALL.hold / p.T - 1e-9)
    rng = np.random.default_rng(0)
    for law in small.laws:
        for j in rng.choice(small.x1.size, 4, replace=False):
            x1, x2 = small.x1.flat[j], small.x2.flat[j]
            b = simulate_batch(make_law(law, cfg), p, [x1], [x2], small.steps)
            k = first_settled_sample(b.x1[:, 0], b.x2[:, 0], SMALL.band, vband, hold)
            one = settling_times_batch(b.x1, b.x2, b.u, p.a, p.T, SMALL.band, vband, SMALL.hold)
            ts, tg = small.laws[law].settle_time.flat[j], small.laws[law].grid.settle_time.flat[j]
            assert ts == one.time[0] or (math.isnan(ts) and math.isnan(one.time[0])), law
            if k < 0:
                assert math.isnan(tg), f"{law} at ({x1}, {x2}) should not settle on the grid"
                continue
            assert tg == pytest.approx(k * p.T, abs=1e-12), f"{law} grid time at ({x1},{x2})"
            if math.isnan(ts):
                continue
            tf = float(min_time(x1, x2, p).t_f)
            ns = discrete_min_steps(x1, x2, p).steps
            assert small.n_star.flat[j] == ns, "N* (zonotope) equals the LP reference"
            for r, t in ((small.laws[law], ts), (small.laws[law].grid, tg)):
                assert_allclose(r.ratio_tf.flat[j], t / tf, rtol=1e-12, err_msg=f"{law}: / t_f*")
                assert_allclose(
                    r.ratio_nt.flat[j], t / (ns * p.T), rtol=1e-12, err_msg=f"{law}: / N* T"
                )


def test_discrete_limit_bounds(small):
    """N* T >= t_f* (no sampled input beats the continuous optimum), within one sample + ."""
    ok = small.n_star > 0
    nt = small.n_star[ok] * small.sample_time
    assert np.all(nt >= small.t_f[ok] - 1e-12), "N* T >= t_f*"


def test_pd_settles_everywhere_and_to_chatters(small):
    """PD settles from every state, TO chatters; the PD ratios obey a physical lower bound.

    Reference t_f* by the two-phase OCP (an independent solver).  Settling at
    sample k means the state is in the band box B at t = kT, so kT is at least
    the time to reach B, which is at least t_f*(x0) - max over B of t_f* (from
    B the origin takes at most that long).  The median is recomputed from the
    per-state ratios.
    """
    assert small.laws["pd"].fraction_settled == 1.0
    assert small.laws["to"].fraction_settled < 0.5, "TO chatters around the origin"
    p = paper_config().plant
    ocp = TwoPhaseOCP(p)
    res = [ocp.solve(x1, x2) for x1, x2 in zip(small.x1.ravel(), small.x2.ravel())]
    assert all(r.success for r in res)
    tf = np.array([r.t_f for r in res])
    b1, b2 = np.meshgrid(
        np.linspace(-SMALL.band, SMALL.band, 21),
        np.linspace(-small.velocity_band, small.velocity_band, 21),
    )
    box = np.column_stack([b1.ravel(), b2.ravel()])
    box = box[np.any(box != 0, axis=1)]
    t_box = max(ocp.solve(x1, x2).t_f for x1, x2 in box[:: max(1, len(box) // 60)])
    t_box = max(t_box, float(np.max(min_time(box[:, 0], box[:, 1], p).t_f)))
    pd = small.laws["pd"]
    settle = pd.settle_time.ravel()
    assert np.all(settle >= tf - t_box - 1e-12), "PD settles faster than physically possible"
    assert_allclose(
        pd.ratio_tf.ravel(), settle / tf, rtol=1e-9, err_msg="PD ratio to t_f* (two-phase)"
    )
    assert_allclose(
        pd.median_ratio_tf,
        np.median(settle / tf),
        rtol=1e-9,
        err_msg="PD median ratio over the settled states",
    )


def test_sweep_json_keys(capsys):
    assert main(["sweep", "--json", "--grid", "4", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {
        "grid",
        "band_mm",
        "velocity_band_mm_s",
        "hold_s",
        "horizon_s",
        "laws",
        "timings_s",
        "skipped",
        "n_star_computed",
    } <= set(out)
    assert set(out["laws"]) == {"to", "pd", "pto", "pto-printed"}
    for r in out["laws"].values():
        assert {
            "fraction_settled",
            "median_ratio_tf",
            "median_ratio_nt",
            "worst_ratio_tf",
            "worst_state_tf",
            "worst_ratio_nt",
            "worst_state_nt",
            "percentiles_ratio_tf",
            "percentiles_ratio_nt",
            "worst_states_tf",
            "worst_states_nt",
        } <= set(r)
        assert set(r["percentiles_ratio_nt"]) == {"p50", "p95", "p99", "max"}
        assert {"fraction_settled", "median_ratio_tf", "percentiles_ratio_tf"} <= set(
            r["sample_grid"]
        ), "the sample-grid reading alongside"
        assert isinstance(r["excursions_after_grid"], int)
    assert "between samples" in out["settling"]


def test_percentiles_and_worst_states(small):
    """p50 <= p95 <= p99 <= max = the worst ratio; worst states listed worst first."""
    for r in [*small.laws.values(), *(v.grid for v in small.laws.values())]:
        for pct, worst, states, ratio in (
            (r.percentiles_tf, r.worst_ratio_tf, r.worst_states_tf, r.ratio_tf),
            (r.percentiles_nt, r.worst_ratio_nt, r.worst_states_nt, r.ratio_nt),
        ):
            ok = np.isfinite(ratio)
            if not ok.any():
                continue
            assert pct["p50"] <= pct["p95"] <= pct["p99"] <= pct["max"] == worst
            assert pct["p50"] == pytest.approx(np.median(ratio[ok]), rel=1e-12)
            assert [w[2] for w in states] == sorted(ratio[ok], reverse=True)[: len(states)]
            x1, x2, v = states[0]
            j = np.flatnonzero((small.x1 == x1) & (small.x2 == x2))
            assert ratio.flat[j[0]] == v, "worst state's ratio at that grid state"


def test_settling_chunks_do_not_change_results():
    cfg = paper_config()
    p = cfg.plant
    x1, x2 = np.linspace(-20, 20, 11), np.linspace(300, -300, 11)
    law = make_law("pto", cfg)
    a = settling_times(law, p, x1, x2, 200, 0.01, p.a * 0.01, 0.05, chunk=3)
    b = settling_times(law, p, x1, x2, 200, 0.01, p.a * 0.01, 0.05)
    assert np.array_equal(a.time, b.time, equal_nan=True)
    assert np.array_equal(a.grid, b.grid, equal_nan=True)


def test_exact_and_grid_readings_side_by_side(small):
    """Both readings are kept; grid - T < exact wherever both settle; exact > grid only
    for the counted excursions; the statistics of the grid reading are its own."""
    T = small.sample_time
    for name, r in small.laws.items():
        ex, gr = r.settle_time, r.grid.settle_time
        both = np.isfinite(ex) & np.isfinite(gr)
        assert np.all(ex[both] > gr[both] - T), f"{name}: exact more than a sample early"
        assert r.excursions_after_grid == int(np.count_nonzero(ex[both] > gr[both]))
        assert r.grid.grid is None
        if both.any():
            assert r.grid.median_ratio_tf == pytest.approx(np.median(r.grid.ratio_tf[both]))
    pd = small.laws["pd"]
    assert pd.median_ratio_tf < pd.grid.median_ratio_tf, "PD: exact exits precede the samples"


def test_grid_limit(capsys):
    assert main(["sweep", "--json", "--grid", "1001", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ptoverify: error:") and "1000" in err


def test_sweep_out_writes_atomically(tmp_path, capsys):
    """The replacing run sweeps one law: the folder's replacement is what it tests (the
    four laws' heat maps cost 1.4 s, one law's 0.5 s)."""
    out = tmp_path / "sw"
    assert main(["sweep", "--grid", "4", "--out", str(out), "--quiet"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [".ptoverify", "sweep.json", "sweep_ratio_nt.png", "sweep_ratio_tf.png"]
    assert all((out / n).stat().st_size > 5000 for n in names if n.endswith(".png"))
    first = (out / "sweep.json").read_text()
    argv = ["sweep", "--grid", "4", "--law", "pd", "--out", str(out), "--quiet"]
    assert main(argv) == 0, "replace"
    assert sorted(p.name for p in out.iterdir()) == names
    assert (out / "sweep.json").read_text() != first, "the folder holds the second run"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "no temp left"


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_sweep_unwritable_out(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        code = main(["sweep", "--grid", "4", "--out", str(locked / "x"), "--quiet"])
    finally:
        locked.chmod(stat.S_IRWXU)
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("ptoverify: error:") and err.count("\n") == 1
    assert not (locked / "x").exists()


def test_sweep_out_under_a_file(tmp_path, capsys):
    """A parent that is a file cannot hold the folder (fails even for root): one line, exit 2."""
    f = tmp_path / "file"
    f.write_text("x")
    code = main(["sweep", "--grid", "4", "--out", str(f / "sub"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("ptoverify: error:") and err.count("\n") == 1, err
    assert f.read_text() == "x"


def test_sweep_out_is_a_file(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["sweep", "--grid", "4", "--out", str(f)]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error:")


@pytest.mark.parametrize(("n1", "n2"), [(200, 200), (7, 5), (6, 1), (1, 1)])
def test_grid_is_even_and_exactly_symmetric(n1, n2):
    """The grid spans the envelope evenly (as linspace does, to round-off) and a state's
    mirror through the origin is on it bit for bit (what the sweep's mirrored half needs)."""
    p = paper_config().plant
    X1, X2 = grid_states(p, n1, n2)
    assert X1.shape == X2.shape == (n2, n1)
    for v, n, r in ((X1[0], n1, p.position_range), (X2[:, 0], n2, p.w_max)):
        ref = np.linspace(-r, r, n) if n > 1 else np.zeros(1)
        assert_allclose(v, ref, rtol=0, atol=4 * np.finfo(float).eps * r)
        assert np.array_equal(v[::-1], -v)
        if n > 1:
            assert v[0] == -r and v[-1] == r
    assert np.array_equal(X1.ravel()[::-1], -X1.ravel())
    assert np.array_equal(X2.ravel()[::-1], -X2.ravel())


@pytest.mark.parametrize("name", ["to", "pd", "pto", "pto-printed"])
def test_laws_are_odd_bit_for_bit(name):
    """u(-x) == -u(x) exactly, and the regions are each other's mirror (P and N swap), at
    random states of every scale and on the axes: the premise of simulating half of a
    symmetric grid (the sweep's settling times, tune.grid_counts' zone and crossings)."""
    cfg = paper_config()
    law = make_law(name, cfg)
    rng = np.random.default_rng(5)
    x1 = np.concatenate([rng.uniform(-60, 60, 30000) * s for s in (1, 1e-2, 1e-4, 1e-7)])
    x2 = np.concatenate([rng.uniform(-320, 320, 30000) * s for s in (1, 1e-2, 1e-4, 1e-7)])
    x1[::7], x2[::11] = 0.0, 0.0
    u, r = law.vector(x1, x2)
    u_m, r_m = law.vector(-x1, -x2)
    assert np.array_equal(u_m, -u)
    swap = {Region.BANG_P: Region.BANG_N, Region.ZONE_P: Region.ZONE_N}
    swap |= {n: p for p, n in swap.items()}
    mirror = np.array([swap.get(Region(c), Region(c)) for c in range(len(Region))])
    assert np.array_equal(r_m, mirror[r])


def test_horizon_over_the_limit_is_bad_input_at_once(tmp_path, capsys):
    """T = 1e-7 s (accepted by the loader) makes the 0.05 s hold 5e5 samples: exit 2, no run."""
    import dataclasses
    import time

    from ptoverify.studies.sweep import MAX_HORIZON_STEPS

    path = tmp_path / "fine.toml"
    path.write_text(
        'name = "fine"\n[plant]\na = 100000.0\nw_max = 300.0\nsample_time = 1e-7\n'
        "position_range = 0.06\n[pd]\nkp = 356.0\nkd = 1.15\n[pto]\nd = 0.005\nk1 = 323.0\n"
        "k2 = 3.6\n"
    )
    start = time.monotonic()
    assert main(["sweep", "--grid", "4", "--config", str(path), "--out", str(tmp_path / "o")]) == 2
    assert time.monotonic() - start < 10
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and f"{MAX_HORIZON_STEPS:,}" in err and "hold" in err
    assert not (tmp_path / "o").exists()
    # the same limit, just inside it: the paper's plant sampled 4 x finer runs
    cfg = paper_config()
    fine = dataclasses.replace(cfg, plant=dataclasses.replace(cfg.plant, sample_time=5e-4))
    res = run_sweep(fine, SweepSettings(n1=2, n2=2, laws=("pd",)))
    assert 0 < res.steps <= MAX_HORIZON_STEPS
