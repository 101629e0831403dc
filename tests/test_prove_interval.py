"""``ptoverify prove --a-interval``: enclosures over an interval of a, the bound, the gate.

References are independent of the prover: the exact ZOH map and closed-loop
powers evaluated in python-flint ``arb`` at single values of a drawn from the
interval, and ``simulate_batch`` (floats) with the law designed for the
nominal a driving a plant with another constant a.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import assert_same_proof, cell_states
from flint import arb, arb_mat, ctx

from ptoverify.config import paper_config
from ptoverify.model import zohmaps as zm
from ptoverify.model.laws import make_law
from ptoverify.sim.simulate import simulate_batch
from ptoverify.studies.checks import PROOF_INTERVAL_GATE, run_checks
from ptoverify.studies.prove import default_pieces, interval_proof
from ptoverify.studies.prove.ball import Resolution
from ptoverify.verdict import PASS, UNVERIFIED, tie_band

T = 0.002
A0 = paper_config().plant.a
LO, HI = 0.8 * A0, 1.25 * A0


def _exact(a, x1, x2, u, j):
    """The exact j-step ZOH image in arb (eq. 7), one value of a."""
    with ctx.workprec(200):
        e = (-arb(a) * arb(T) * j).exp()
        y2 = arb(u) + (arb(x2) - arb(u)) * e
        y1 = arb(x1) + arb(u) * arb(T) * j + (arb(x2) - arb(u)) * (1 - e) / arb(a)
    return y1, y2


def _inside(lo, hi, ball) -> bool:
    return bool(arb(lo) <= ball and ball <= arb(hi))


def test_interval_affine_images_enclose_every_a():
    rng = np.random.default_rng(11)
    lo, hi = 0.97 * A0, 1.05 * A0
    maps = zm.step_maps(zm.a_ball(lo, hi), T, 60)
    n = 400
    c1, c2 = rng.uniform(-50, 50, n), rng.uniform(-300, 300, n)
    h1, h2 = 10.0 ** rng.uniform(-3, 0, n), 10.0 ** rng.uniform(-1, 1.5, n)
    box = (c1 - h1, c1 + h1, c2 - h2, c2 + h2)
    u = rng.choice([-300.0, 300.0], n)
    j = rng.integers(0, 61, n)
    img = zm.affine_image(maps, j, box, (u, u))
    a = rng.uniform(lo, hi, n)
    a[:20], a[20:40] = lo, hi  # the ends, where the corners are tight
    f1, f2 = rng.uniform(0, 1, (2, n))
    f1[:60], f2[:60] = rng.integers(0, 2, (2, 60))  # corners
    bad = 0
    for q in range(n):
        x1 = box[0][q] + f1[q] * (box[1][q] - box[0][q])
        x2 = box[2][q] + f2[q] * (box[3][q] - box[2][q])
        y1, y2 = _exact(float(a[q]), float(x1), float(x2), float(u[q]), int(j[q]))
        bad += not _inside(img[0][q], img[1][q], y1)
        bad += not _inside(img[2][q], img[3][q], y2)
    assert bad == 0, "an exact image at some a of the interval lies outside the enclosure"


def test_interval_images_are_tight_at_the_ends():
    """At a = a_hi the lower-left corner's image is the box's lower corner: 1e-9 inwards loses it."""
    lo, hi = 0.97 * A0, 1.05 * A0
    maps = zm.step_maps((lo, hi), T, 5)  # the interval itself: exact ends
    box = tuple(np.array([v]) for v in (-10.0, -9.5, 100.0, 120.0))
    u = np.array([300.0])
    img = zm.affine_image(maps, np.array([5]), box, (u, u))
    # x1_j = x1 + t u + p (x2 - u) with x2 - u < 0: smallest where p is largest, at a_lo
    y1, y2 = _exact(lo, -10.0, 100.0, 300.0, 5)
    assert _inside(img[0][0], img[1][0], y1) and _inside(img[2][0], img[3][0], y2)
    assert not _inside(img[0][0] + 1e-9, img[1][0], y1), "x1's lower end is not tight"
    _, y2hi = _exact(hi, -9.5, 120.0, 300.0, 5)  # u + e (x2 - u), x2 - u < 0: smallest e, a_hi
    assert not _inside(img[2][0], img[3][0] - 1e-9, y2hi), "x2's upper end is not tight"


def test_interval_closed_loop_powers_enclose_every_a():
    g1, g2 = 323.0, 3.6
    lo, hi = 0.9 * A0, 1.1 * A0
    maps = zm.step_maps((lo, hi), T, 80, gains=(g1, g2))
    rng = np.random.default_rng(12)
    for a in [lo, hi, *rng.uniform(lo, hi, 12).tolist()]:
        with ctx.workprec(200):
            x = arb(a)
            e = (-x * arb(T)).exp()
            q = (1 - e) / x
            acl = arb_mat([[1, q], [0, e]]) - arb_mat([[arb(T) - q], [1 - e]]) * arb_mat(
                [[arb(g1), arb(g2)]]
            )
            power = arb_mat([[1, 0], [0, 1]])
            for j in range(81):
                for r in range(2):
                    for c in range(2):
                        assert _inside(maps.lin[0][j, r, c], maps.lin[1][j, r, c], power[r, c]), (
                            f"Acl^{j}[{r},{c}] at a = {a}"
                        )
                power = power * acl


@pytest.fixture(scope="module")
def proof():
    return interval_proof(paper_config())


def _cell_bound(proof, x1, x2):
    g = proof.grid
    i = np.clip(np.searchsorted(g.e1, x1, "right") - 1, 0, g.shape[0] - 1)
    j = np.clip(np.searchsorted(g.e2, x2, "right") - 1, 0, g.shape[1] - 1)
    return proof.bound[j * g.shape[0] + i]


def test_interval_bound_covers_simulation_at_every_a(proof):
    """Seeded states, plants with a across the interval (ends included), law designed for a0."""
    cfg = paper_config()
    law = make_law("pto", cfg)
    rng = np.random.default_rng(13)
    n = 20_000
    x1 = rng.uniform(-cfg.plant.position_range, cfg.plant.position_range, n)
    x2 = rng.uniform(-cfg.plant.w_max, cfg.plant.w_max, n)
    bound = _cell_bound(proof, x1, x2)
    proved = np.isfinite(bound)
    (p11, p12), (_, p22) = proof.target.P
    worst = 0
    for a in (LO, 0.87 * A0, 0.95 * A0, A0, 1.06 * A0, 1.17 * A0, HI):
        b = simulate_batch(law, cfg.with_plant(a=a).plant, x1, x2, proof.bound_samples + 2)
        q = p11 * b.x1**2 + 2 * p12 * b.x1 * b.x2 + p22 * b.x2**2
        inside = q <= proof.target.c * (1 + 1e-9)
        first = np.where(inside.any(axis=0), inside.argmax(axis=0), np.inf)
        over = np.count_nonzero(proved & (first > bound))
        assert over == 0, f"a = {a / A0:.3f} a0: {over} states needed more than their bound"
        worst = max(worst, int(first[proved].max()))
    assert proof.bound_samples >= worst
    assert proof.bound_samples - worst <= 3, (proof.bound_samples, worst)
    assert proof.property("reach").coverage >= 0.997
    assert proof.a_interval == (LO, HI) and len(proof.balls) == default_pieces((LO, HI))


def test_interval_strict_stride_over_is_refuted_by_a_real_crossing(proof):
    """The counterexample, re-checked here: the law's input at x0, one exact step in arb."""
    cfg = paper_config()
    strict = proof.property("no-stride-over-strict")
    assert strict.status == "refuted"
    assert proof.property("no-stride-over-relaxed").status == "proved"
    cex = strict.counterexample
    assert cex.confirmed_by_simulation and LO <= cex.a_plant <= HI
    x1, x2 = cex.x0
    u, _ = make_law("pto", cfg)(np.array([x1]), np.array([x2]))
    assert float(u[0]) == cex.u
    y1, y2 = _exact(cex.a_plant, x1, x2, cex.u, 1)
    w, tol = cfg.plant.w_max, tie_band(cfg.plant.w_max, A0, cfg.plant.position_range)
    with ctx.workprec(200):

        def sigma(p, v):  # a0 x1 + sgn(x2) w h(|x2| / w), eq. (9)
            r = abs(v) / w
            h = w * (r - r.log1p())
            return arb(A0) * p + (h if v > 0 else -h)

        s0, s1 = sigma(arb(x1), arb(x2)), sigma(y1, y2)
        assert (s0 > 0 and s1 < -tol) or (s0 < 0 and s1 > tol)
    assert abs(x1) >= cfg.pto.d


def test_interval_gate_passes_at_the_paper_box_and_fails_closed(monkeypatch, proof):
    """Its failure on a faulty configuration (k2 = 6: the sampled linear zone unstable) is
    ``test_gates_fail``'s ``proof-reach-a-interval`` perturbation, the same run."""
    import ptoverify.studies.prove as prove_mod

    (v,) = run_checks(paper_config(), [PROOF_INTERVAL_GATE])
    assert v.status == PASS and v.unit == "1" and v.description, v
    assert v.measured == pytest.approx(1.0 - proof.property("reach").coverage)

    def broken(cfg):
        raise FloatingPointError("injected")

    monkeypatch.setattr(prove_mod, "interval_proof", broken)
    (v,) = run_checks(paper_config(), [PROOF_INTERVAL_GATE])
    assert v.status == UNVERIFIED and "injected" in v.detail


def test_cell_blocks_give_the_whole_grid_result_exactly():
    """Blocks of cells proved apart, then joined: equal to one block (pto, two sub-intervals)."""
    from ptoverify.studies.prove.run import prove_law

    cfg = paper_config()
    coarse = Resolution(h1=0.2, h2=20.0, h1_max=5.0, h_edge=0.5, steps=40)  # ~2,000 cells
    kw = dict(a_interval=(A0, 1.03 * A0), pieces=2, n_random=0, res=coarse)
    whole = prove_law(cfg, "pto", **kw)
    split = prove_law(cfg, "pto", block_cells=701, **kw)
    assert_same_proof(whole, split)
    assert whole.property("no-stride-over-strict").status == "refuted"  # leaves were compared


def test_min_time_lower_bound_is_below_the_closed_form_minimum_time():
    """1e5 seeded states and boxes, plants with a <= a_hi: the bound <= t_f* (closed form)."""
    from ptoverify.model.mintime import min_time
    from ptoverify.studies.prove.run import min_time_lower

    cfg = paper_config()
    w, r = cfg.plant.w_max, cfg.plant.position_range
    rng = np.random.default_rng(14)
    n = 100_000
    x1, x2 = rng.uniform(-r, r, n), rng.uniform(-w, w, n)
    x2[:200] = rng.choice([-w, w], 200)  # the velocity's edges
    h1, h2 = rng.uniform(0, 0.5, n), rng.uniform(0, 20, n)
    box = (x1 - h1, x1 + h1, np.maximum(x2 - h2, -w), np.minimum(x2 + h2, w))
    points = (x1, x1, x2, x2)
    for a in (LO, A0, HI):
        t_f = min_time(x1, x2, cfg.with_plant(a=a).plant).t_f
        for b in (points, box):
            t = min_time_lower(b, HI, w)
            assert np.all(t <= t_f), f"a = {a:.1f}: a lower bound above t_f*"
        # and it is tighter than |x1| / w_max where the state moves away from the origin
        away = (x1 * x2 > 0) & (np.abs(x1) > 1.0)
        assert np.all(min_time_lower(points, HI, w)[away] > np.abs(x1[away]) / w)


def test_interval_bound_covers_every_cell_at_both_ends(proof):
    """Every cell's corners and four seeded states inside it (225,000 states), stepped
    with the exact ZOH map (model.plant.step) at a_lo and a_hi.

    The states of ``conftest.cell_states``: each proved cell is met at its four corners
    and inside (a million uniform states left 12 % of the cells without one).
    """
    from ptoverify.model.plant import step

    cfg = paper_config()
    law = make_law("pto", cfg)
    (p11, p12), (_, p22) = proof.target.P
    level = proof.target.c * (1 + 1e-9)
    x1, x2, bound = cell_states(proof.grid, proof.bound, 4, seed=15)
    assert np.isfinite(bound).sum() > 5 * np.isfinite(proof.bound).sum()
    for a in (LO, HI):
        plant = cfg.with_plant(a=a).plant
        live = np.flatnonzero(np.isfinite(bound))
        y1, y2 = x1[live], x2[live]
        for k in range(proof.bound_samples + 1):
            inside = p11 * y1 * y1 + 2 * p12 * y1 * y2 + p22 * y2 * y2 <= level
            assert np.all(inside | (k < bound[live])), f"a = {a:.1f}: outside at its bound {k}"
            live, y1, y2 = live[~inside], y1[~inside], y2[~inside]
            u, _r = law(y1, y2)
            y1, y2 = step(y1, y2, u, plant)
        assert live.size == 0, f"a = {a:.1f}: a proved state never entered the ellipse"
