"""Switching zone: printed construction, principle, corrected zone (Section 4)."""

import dataclasses
import functools
import json
import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from conftest import with_d, zoh_step
from numpy.testing import assert_allclose

from derivations.printed import SYMBOLS, printed
from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.model.curves import level_curve_x1, level_residual
from ptoverify.model.plant import flow
from ptoverify.model.zones import (
    PTOZone,
    corrected_zone,
    principle_margin,
    principle_violations,
    printed_zone,
    smallest_d,
)

PAPER = paper_config()
CONFIGS = {
    "paper": PAPER,
    "a30": PAPER.with_plant(a=30.0),
    "T1ms": PAPER.with_plant(sample_time=0.001),
    "d1": with_d(PAPER, 1.0),
}


@functools.lru_cache(maxsize=None)
def cz(name, reading="strict"):
    """Corrected zone of a named configuration, computed once per test session."""
    return corrected_zone(CONFIGS[name], reading=reading, verify=False)


def test_flow_matches_zoh_reference():
    rng = np.random.default_rng(1)
    x1, x2 = rng.uniform(-50, 50, 500), rng.uniform(-300, 300, 500)
    u = rng.choice([-300.0, 300.0, 37.0], 500)
    for a, T in ((PAPER.plant.a, 0.002), (30.0, 0.002), (PAPER.plant.a, 0.001)):
        ref = zoh_step(x1, x2, u, a, T)
        got = flow(x1, x2, u, T, a)
        # the scipy ZOH (expm) is accurate to a few ulps of the state size (50 mm, 300 mm/s)
        assert_allclose(got[0], ref[0], atol=1e-11, rtol=0, err_msg="x1 one-sample map")
        assert_allclose(got[1], ref[1], atol=1e-10, rtol=0, err_msg="x2 one-sample map")


def printed_chain_reference(a, w, T, d):
    """Eqs. (21)-(27) solved from their printed transcriptions (derivations.printed).

    Independent of ``ptoverify``: the linear equations by ``sympy.solve``, the
    transcendental (22) and (26) by 40-digit bisection (mpmath) on brackets that
    hold the non-trivial root: y > 0 for (22); z > 0 if 0 < k < 1 and
    -1 < z < 0 if k > 1 for (26).
    """
    S = SYMBOLS
    num = {S["a"]: a, S["omega_m"]: w, S["T"]: T, S["tx10"]: d}
    (_, r21b), (r22,), (r23,) = printed("21"), printed("22"), printed("23")
    (r25k, _), (r26,), (r27,) = printed("25"), printed("26"), printed("27")
    b0 = sp.solve(r21b.subs(num), S["b0"])[0]
    with mpmath.workdps(40):
        f22 = sp.lambdify(S["y"], r22.subs({**num, S["b0"]: b0}), "mpmath")
        y = mpmath.findroot(f22, (mpmath.mpf("1e-30"), 10 * (float(b0) + 2)), solver="bisect")
        x20 = sp.solve(r23.subs({**num, S["y"]: y}), S["tx20"])[0]
        k = sp.solve(r25k.subs({**num, S["tx20"]: x20}), S["k"])[0]
        f26 = sp.lambdify(S["z"], r26.subs(S["k"], k), "mpmath")
        lo, hi = (
            (mpmath.mpf("1e-30"), mpmath.mpf(1e6))
            if k < 1
            else (-1 + mpmath.mpf("1e-30"), -mpmath.mpf("1e-30"))
        )
        z = mpmath.findroot(f26, (lo, hi), solver="bisect")
        om = sp.solve(r27.subs({S["tx20"]: x20, S["z"]: z}), S["omega_0"])[0]
    return {k_: float(v) for k_, v in dict(b0=b0, y=y, x20=x20, k=k, z=z, omega0=om).items()}


@pytest.mark.parametrize("name", ["paper", "a30", "T1ms", "d1"])
def test_printed_numbers_vs_printed_equations(name):
    cfg = CONFIGS[name]
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    z = printed_zone(cfg)
    ref = printed_chain_reference(a, w, T, d)
    # references to 40 digits; the code's float64 chain (Lambert W near its branch
    # point, then a division) is accurate to ~1e-13 relative
    assert_allclose(z.b0, ref["b0"], rtol=1e-15, err_msg="b0, eq. (21)")
    assert_allclose(z.y_star, ref["y"], rtol=1e-12, err_msg="y*, eq. (22)")
    assert_allclose(z.x20_tilde, ref["x20"], rtol=1e-12, err_msg="x~20, eq. (23)")
    assert_allclose(z.k, ref["k"], rtol=1e-12, err_msg="k, eq. (25)")
    assert_allclose(z.z_star, ref["z"], rtol=1e-11, err_msg="z*, eq. (26)")
    assert_allclose(z.omega0, ref["omega0"], rtol=1e-11, err_msg="omega0, eq. (27)")


def test_printed_zone_paper_verdict():
    z = printed_zone(PAPER)
    w = PAPER.plant.w_max
    # the verdict: beyond the envelope, omega0 above w_max, so invalid
    assert z.x20_tilde < -w
    assert z.omega0 > w
    assert not z.valid and not z.usable
    assert "empty" in z.reason and "eq. (16)" in z.reason
    assert z.grid_violations is None and z.grid_points is None, "no grid run: None, not -1"


def test_zone_fields_are_keywords():
    z = printed_zone(PAPER)
    with pytest.raises(TypeError):
        PTOZone("printed", z.omega0)  # positional construction is refused
    assert dataclasses.replace(z, valid=True).valid


@pytest.mark.parametrize("name", ["paper", "a30", "T1ms", "d1"])
def test_printed_invalid_everywhere(name):
    z = printed_zone(CONFIGS[name])
    assert not z.valid
    assert z.omega0 > CONFIGS[name].plant.w_max, "printed omega0 above w_max"


def test_eq16_sign_error():
    """Under the +w_max flow of (15) the image of l1 stays on l1 (eq. 9), not on (19)."""
    a, w, T = PAPER.plant.a, PAPER.plant.w_max, PAPER.plant.sample_time
    x2 = -np.linspace(1.0, w, 50)
    x1 = level_curve_x1(x2, a, w)
    f1, f2 = zoh_step(x1, x2, w, a, T)
    res = a * f1 + f2 + w * np.log1p(-f2 / w)
    assert_allclose(res, 0.0, atol=1e-9, err_msg="image of l1 under +w_max is on l1")
    assert np.all(np.abs(res + 2 * a * w * T) > 100), "not on the printed curve (19)"
    # a x1 + x2 grows by a w T under +w_max (eq. 16 prints a decrease)
    assert_allclose(
        a * f1 + f2 - (a * x1 + x2),
        a * w * T,
        rtol=1e-9,
        err_msg="a x1 + x2 after one sample of +w_max",
    )


def brute_margin(cfg, omega0, x2, reading, n=2001):
    """Worst landing sigma at each velocity over a dense x1 grid, landing by scipy ZOH."""
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    R = cfg.plant.position_range
    out = []
    for v in x2:
        x1 = np.linspace(-R, R, n)
        sig = level_residual(x1, v, a, w)
        zone = (v < 0) & (sig >= 0) & (level_residual(x1, v, a, omega0) < 0)
        src = (np.abs(x1) >= d) & ((sig > 0) | ((sig == 0) & (v > 0))) & ~zone
        f1, f2 = zoh_step(x1[src], v, -w, a, T)
        r = level_residual(f1, f2, a, w)
        if reading == "lenient":
            r = np.where(np.abs(f1) >= d, r, np.inf)
        out.append(r.min() if r.size else np.inf)
    return np.array(out)


@pytest.mark.parametrize("reading", ["strict", "lenient"])
@pytest.mark.parametrize("name", ["paper", "a30"])
def test_margin_matches_brute_force(name, reading):
    cfg = CONFIGS[name]
    w = cfg.plant.w_max
    x2 = np.linspace(-w, w, 25)
    for omega0 in (0.05 * w, 0.3 * w, w):
        exact = principle_margin(cfg, omega0, x2, reading=reading)
        brute = brute_margin(cfg, omega0, x2, reading)
        # the exact margin is the infimum; the grid can only find larger values, within
        # one x1 step (2 R / 2000) times a [mm/s]
        step = cfg.plant.a * 2 * cfg.plant.position_range / 2000
        fin = np.isfinite(exact)
        assert np.array_equal(fin, np.isfinite(brute)), "same velocities have sources"
        assert np.all(brute[fin] >= exact[fin] - 1e-9), "exact margin is a lower bound"
        assert_allclose(
            brute[fin],
            exact[fin],
            atol=step * 1.01,
            rtol=0,
            err_msg=f"principle margin, omega0 = {omega0}",
        )


@pytest.mark.parametrize("name", ["paper", "a30", "T1ms", "d1"])
def test_corrected_zone_valid_and_largest(name):
    cfg = CONFIGS[name]
    w, a, T = cfg.plant.w_max, cfg.plant.a, cfg.plant.sample_time
    z = cz(name)
    assert z.valid and not z.degenerate, z.reason
    assert 0 < z.omega0 < w
    assert z.feasible_intervals and z.feasible_intervals[-1][0] == 0.0
    assert z.feasible_intervals[-1][1] >= z.omega0
    # just above the edge, some state on l1* strides over l1 (landing by scipy ZOH)
    om = z.feasible_intervals[-1][1] * 1.01
    s = np.linspace(1e-3, 1.0, 20001) * w
    x1 = level_curve_x1(-s, a, om)
    x1 = np.maximum(x1, cfg.pto.d)
    f1, f2 = zoh_step(x1, -s, -w, a, T)
    assert level_residual(f1, f2, a, w).min() < 0, "omega0 1% above the edge fails"
    # and at the chosen omega0 none does
    x1 = np.maximum(level_curve_x1(-s, a, z.omega0), cfg.pto.d)
    f1, f2 = zoh_step(x1, -s, -w, a, T)
    assert level_residual(f1, f2, a, w).min() > -1e-6, "chosen omega0 holds on l1*"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["paper", "a30", "T1ms", "d1"])
def test_corrected_zone_grid_verified(name):
    z = cz(name)
    bad, pts = principle_violations(CONFIGS[name], z.omega0)
    assert bad == 0 and pts > 100_000


def test_mirror_rule():
    """Rule 2: sources in S_P outside l2* under +w_max land on or below l2."""
    cfg = PAPER
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    om = cz("paper").omega0
    x1, x2 = np.meshgrid(np.linspace(-50, 50, 801), np.linspace(-w, w, 301))
    x1, x2 = x1.ravel(), x2.ravel()
    sig = level_residual(x1, x2, a, w)
    zone_n = (x2 > 0) & (sig <= 0) & (level_residual(x1, x2, a, om) > 0)
    src = (np.abs(x1) >= d) & ((sig < 0) | ((sig == 0) & (x2 < 0))) & ~zone_n
    f1, f2 = zoh_step(x1[src], x2[src], w, a, T)
    assert level_residual(f1, f2, a, w).max() <= 1e-6


def test_lenient_reading_needs_no_zone_at_paper():
    z = cz("paper", "lenient")
    assert z.degenerate and not z.valid
    assert z.feasible_intervals[-1][1] == PAPER.plant.w_max


def test_smallest_d_and_infeasible():
    cfg = PAPER
    dmin = smallest_d(cfg)
    assert 0 < dmin < cfg.pto.d
    lo = corrected_zone(with_d(cfg, 0.9 * dmin), verify=False)
    assert not lo.valid and not lo.feasible_intervals and "smallest d" in lo.reason
    assert_allclose(lo.d_min, dmin, rtol=1e-12, err_msg="d_min reported")
    hi = corrected_zone(with_d(cfg, 1.1 * dmin), verify=False)
    assert hi.feasible_intervals


def test_degenerate_large_d():
    z = corrected_zone(with_d(PAPER, 2.0), verify=False)
    assert z.degenerate and not z.valid
    assert "degenerate" in z.reason


def test_violations_counted_above_edge():
    cfg = PAPER
    z = cz("paper")
    bad, pts = principle_violations(cfg, 2 * z.omega0, n1=201, n2=201, n_band=51)
    assert bad > 0 and pts > 0


def test_cli_zone_json(capsys):
    assert main(["zone", "--json", "--no-verify"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("printed", "corrected", "d", "w_max"):
        assert key in out
    for key in ("omega0", "x20_tilde", "valid", "reason"):
        assert key in out["printed"] and key in out["corrected"]
    assert out["printed"]["valid"] is False and out["corrected"]["valid"] is True
    assert math.isclose(out["d"], PAPER.pto.d)


def test_cli_zone_bad_config(tmp_path, capsys):
    assert main(["zone", "--config", str(tmp_path / "missing.toml")]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error:")


def test_principle_margin_broadcasts_elementwise():
    """Rows of an (omega0 x velocity) call are the one-omega0 calls; paired arrays are the
    one-state calls (one evaluation, elementwise, for any shapes)."""
    rng = np.random.default_rng(2024)
    w = PAPER.plant.w_max
    x2 = np.concatenate([rng.uniform(-w, w, 700), [0.0, -0.0, -w, w]])
    om = np.array([0.0, 1e-6 * w, 0.2 * w, 0.7 * w, w, 2.0 * w])
    for reading in ("strict", "lenient"):
        rows = principle_margin(PAPER, om[:, None], x2, reading=reading)
        for k, o in enumerate(om):
            assert np.array_equal(rows[k], principle_margin(PAPER, float(o), x2, reading=reading))
        pair = principle_margin(PAPER, np.resize(om, x2.size), x2, reading=reading)
        want = [
            principle_margin(PAPER, float(o), x2[i : i + 1], reading=reading)[0]
            for i, o in enumerate(np.resize(om, x2.size))
        ]
        assert np.array_equal(pair, want)


def test_smallest_d_depends_on_the_plant_only():
    from ptoverify.config import PTOSettings
    from ptoverify.model.zones import clear_caches

    base = smallest_d(PAPER)
    clear_caches()
    other = dataclasses.replace(PAPER, pto=PTOSettings(d=3.7, k1=10.0, k2=0.1))
    assert smallest_d(other) == base


def test_corrected_zone_names_y_star_and_z_star_as_the_paper():
    """Corrected zone: z* = -x~20 / omega0 (eq. 26's ratio, where l1* meets x1 = d) and
    y* = -x~20 / w_max (eq. 22's); they differ unless omega0 = w_max."""
    cfg = paper_config()
    z = corrected_zone(cfg)
    w, a, d = cfg.plant.w_max, cfg.plant.a, cfg.pto.d
    assert_allclose(z.z_star, -z.x20_tilde / z.omega0, rtol=1e-12, err_msg="z* [-]")
    assert_allclose(z.y_star, -z.x20_tilde / w, rtol=1e-15, err_msg="y* [-]")
    assert z.y_star < z.z_star
    # l1* passes through (d, x~20): its level curve at x2 = x~20 is at x1 = d
    assert_allclose(level_curve_x1(z.x20_tilde, a, z.omega0), d, rtol=1e-9, err_msg="x1 [mm]")


@pytest.mark.parametrize("name", ["paper", "a30", "d1"])
@pytest.mark.parametrize("reading", ["strict", "lenient"])
def test_feasibility_floor_changes_no_decision(name, reading):
    """A worst-margin test against a floor skips refining the omega0 whose even grid is
    already below it: every decision is that of the full worst margin, and every omega0
    it refines has the full worst margin (scan of the construction, both readings)."""
    from ptoverify.model.zones.margins import _tol, _worst_margins

    cfg = CONFIGS[name]
    w = cfg.plant.w_max
    omegas = np.concatenate([[0.0], np.geomspace(1e-4 * w, w, 100), np.linspace(w / 200, w, 100)])
    tol = _tol(cfg)
    full = np.array(_worst_margins(cfg, omegas, reading))
    floored = np.array(_worst_margins(cfg, omegas, reading, floor=-tol))
    assert np.array_equal(full >= -tol, floored >= -tol)
    kept = floored >= -tol
    assert kept.any()
    if reading == "strict":  # (under the lenient reading these plants meet it everywhere)
        assert (~kept).any(), "some omega0 of the scan fails, so the floor skips some"
    assert np.array_equal(full[kept], floored[kept])


def _edge_one_halving_at_a_time(cfg, reading, good, bad):
    """The edge bisection as written before issue 23: one halving per evaluation."""
    from ptoverify.model.zones.corrected import _feasible_many
    from ptoverify.model.zones.margins import _tol, _worst_margins

    w = cfg.plant.w_max
    for _ in range(60):
        mid = 0.5 * (good + bad)
        ok = _worst_margins(cfg, np.array([mid]), reading)[0] >= -_tol(cfg)  # no floor
        assert ok == _feasible_many(cfg, np.array([mid]), reading, _tol(cfg))[0]
        good, bad = (mid, bad) if ok else (good, mid)
        if abs(good - bad) <= 1e-10 * w:
            break
    return good


@pytest.mark.parametrize("name", ["paper", "a30", "d1"])
def test_feasible_interval_edges_are_the_one_halving_bisection(name):
    """The construction's interval edges (two halvings per evaluation) are those of the
    bisection one halving at a time, bit for bit, from the scan's bracketing points."""
    cfg = CONFIGS[name]
    w, scan = cfg.plant.w_max, 200
    grid = np.unique(
        np.concatenate([np.geomspace(1e-4 * w, w, scan // 2), np.linspace(w / scan, w, scan // 2)])
    )
    z = cz(name)
    assert z.feasible_intervals, "the configuration has a feasible omega0"
    for lo, hi in z.feasible_intervals:
        for edge, inside in ((lo, True), (hi, False)):
            if edge in (0.0, w):
                continue
            # the scan's neighbours of the edge: the feasible one and the infeasible one
            j = int(np.searchsorted(grid, edge))
            good, bad = (grid[j], grid[j - 1]) if inside else (grid[j - 1], grid[j])
            assert _edge_one_halving_at_a_time(cfg, "strict", float(good), float(bad)) == edge
