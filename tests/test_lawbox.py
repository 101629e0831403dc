"""Law enclosures over boxes contain the point law (the suite's own laws).

1.2e5 seeded points in random boxes, a third of them boxes centred on a region
boundary: the switching curves at w_max and at omega0 (eqs. 9, 11, 13, 14),
the linear-zone edges |x1| = d, the saturation lines of the linear law and the
origin.  The reference is the law's vector path (``make_law``).  The omega_c
enclosure is checked against an arb root of its defining equation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from flint import arb, ctx

from ptoverify.config import paper_config
from ptoverify.model.lawbox import enclose, law_spec, omega_c_iv
from ptoverify.model.laws import make_law

LAWS = ["pd", "pto", "pto-printed", "to"]


def _boundary_points(spec, rng, n):
    """Points on every region boundary of the law (float evaluations)."""
    w, a = spec.w_max, spec.a
    x2 = rng.uniform(-w, w, n)
    kind = rng.integers(0, 5, n)
    levels = np.where(kind == 1, spec.omega0 if spec.has_zone else w, w)
    curve = -np.sign(x2) * levels * (np.abs(x2) / levels - np.log1p(np.abs(x2) / levels)) / a
    edge = rng.choice([-1.0, 1.0], n) * (spec.d if math.isfinite(spec.d) else 0.3)
    sat = (rng.choice([-1.0, 1.0], n) * w - spec.g2 * x2) / max(spec.g1, 1.0)
    x1 = np.select([kind <= 1, kind == 2, kind == 3], [curve, edge, sat], 0.0)
    x2 = np.where(kind == 4, 0.0, x2)
    return x1, x2


@pytest.mark.parametrize("name", LAWS)
def test_enclosure_contains_point_law(name):
    cfg = paper_config()
    spec, law = law_spec(name, cfg), make_law(name, cfg)
    rng = np.random.default_rng(100 + LAWS.index(name))
    n = 10_000
    c1, c2 = rng.uniform(-3, 3, n), rng.uniform(-300, 300, n)
    b1, b2 = _boundary_points(spec, rng, n // 2)
    c1[: n // 2], c2[: n // 2] = b1, b2
    h1, h2 = 10.0 ** rng.uniform(-6, 0, n), 10.0 ** rng.uniform(-4, 2, n)
    box = (c1 - h1, c1 + h1, c2 - h2, c2 + h2)
    enc = enclose(spec, box)
    assert np.all(enc.lo <= enc.hi), "empty enclosure"
    assert np.all((enc.lo >= -cfg.plant.w_max) & (enc.hi <= cfg.plant.w_max))
    bad = 0
    for _ in range(3):
        p1, p2 = rng.uniform(box[0], box[1]), rng.uniform(box[2], box[3])
        u, _r = law(p1, p2)
        bad += int(np.count_nonzero((u < enc.lo) | (u > enc.hi)))
    for x1, x2 in ((box[0], box[2]), (box[1], box[3]), (c1, c2)):  # corners, centres
        u, _r = law(x1, x2)
        bad += int(np.count_nonzero((u < enc.lo) | (u > enc.hi)))
    assert bad == 0, f"{name}: the point law left its enclosure at {bad} points"


@pytest.mark.parametrize("name", LAWS)
def test_straddling_boxes_take_both_sides(name):
    """A box around a boundary point encloses both neighbouring pieces."""
    cfg = paper_config()
    spec, law = law_spec(name, cfg), make_law(name, cfg)
    rng = np.random.default_rng(21)
    x1, x2 = _boundary_points(spec, rng, 2000)
    h = 1e-3
    enc = enclose(spec, (x1 - h, x1 + h, x2 - h, x2 + h))
    for dx in (-h, h):
        u, _r = law(x1 + dx, x2 + dx)
        assert np.all((u >= enc.lo) & (u <= enc.hi)), f"{name}: a side of a boundary is missed"


def test_linear_flag_means_unsaturated_linear():
    cfg = paper_config()
    spec = law_spec("pto", cfg)
    rng = np.random.default_rng(9)
    c1, c2 = rng.uniform(-0.6, 0.6, 20_000), rng.uniform(-150, 150, 20_000)
    h1, h2 = 10.0 ** rng.uniform(-4, -1, 20_000), 10.0 ** rng.uniform(-2, 1, 20_000)
    box = (c1 - h1, c1 + h1, c2 - h2, c2 + h2)
    enc = enclose(spec, box)
    assert enc.linear.any()
    p1, p2 = rng.uniform(box[0], box[1]), rng.uniform(box[2], box[3])
    u, region = make_law("pto", cfg)(p1[enc.linear], p2[enc.linear])
    np.testing.assert_array_equal(
        region, 5, err_msg="a linear-flagged box holds a non-linear state"
    )


def test_outside_law_is_monotone():
    """The premise of the corner enclosure: u nonincreasing in x1 and x2 outside |x1| < d."""
    cfg = paper_config()
    for name in ("pto", "pto-printed", "to"):
        law = make_law(name, cfg)
        rng = np.random.default_rng(2)
        x1 = rng.uniform(-3, 3, 50_000)
        x1 = np.where(np.abs(x1) < cfg.pto.d, np.sign(x1) * (cfg.pto.d + 1e-3), x1)
        x2 = rng.uniform(-300, 300, 50_000)
        dx = 10.0 ** rng.uniform(-5, 0, 50_000)
        u0, _ = law(x1, x2)
        u1, _ = law(x1, x2 + 50 * dx)
        same_side = np.sign(x1 + dx) == np.sign(x1)
        u2, _ = law(np.where(same_side, x1 + dx, x1), x2)
        assert np.all(u1 <= u0) and np.all(u2 <= u0), f"{name} is not monotone outside |x1| < d"


def test_omega_c_encloses_arb_root():
    cfg = paper_config()
    spec = law_spec("pto", cfg)
    rng = np.random.default_rng(10)
    x2 = -rng.uniform(20, 300, 3000)
    # a state on the curve of a random level in (omega0, w_max): x1 = level h(|x2|/level) / a
    lev = rng.uniform(spec.omega0, spec.w_max, 3000)
    x1 = lev * (-x2 / lev - np.log1p(-x2 / lev)) / spec.a
    lo, hi = omega_c_iv(spec, x1, x2)
    with ctx.workprec(200):
        for p, q, a_, b_ in zip(x1.tolist(), x2.tolist(), lo.tolist(), hi.tolist()):
            v = arb(-q)

            def g(om, p=p, v=v):
                om = arb(om)
                return arb(spec.a) * arb(p) - om * (v / om - (v / om).log1p())

            # the residual changes sign over [lo, hi]: the root is inside
            assert g(a_) <= 0 or a_ == spec.omega0, "omega_c lower bound above the root"
            assert g(b_) >= 0 or b_ == spec.w_max, "omega_c upper bound below the root"
    assert np.median(hi - lo) < 1e-6, "omega_c enclosure uselessly wide"


def test_shrunk_law_enclosure_is_caught():
    """Raising the lower bound by 1e-9 loses the upper-right corners' inputs."""
    cfg = paper_config()
    spec, law = law_spec("pto", cfg), make_law("pto", cfg)
    rng = np.random.default_rng(12)
    c1, c2 = rng.uniform(-3, 3, 5000), rng.uniform(-300, 300, 5000)
    box = (c1 - 1e-3, c1 + 1e-3, c2 - 0.1, c2 + 0.1)
    enc = enclose(spec, box)
    u, _r = law(box[1], box[3])
    assert np.all(u >= enc.lo)
    missed = np.count_nonzero(u < enc.lo + 1e-9)
    assert missed > 0.9 * u.size, "a shrunk law enclosure went unnoticed"
