"""Soundness of the outward-rounded interval arithmetic against exact arb arithmetic.

Every enclosure is checked at seeded random points against python-flint
``arb`` at 200 bits (the reference: exact for + - * of floats, rigorous balls
for / and ln).  A point passes only if the float interval contains the whole
arb ball (certain comparisons).  Over this file: 1.2e5 points.  The last tests
shrink an enclosure by 1e-9 and check that the same comparison catches it.
"""

from __future__ import annotations

import numpy as np
import pytest
from flint import arb, ctx

from ptoverify.model import intervals as iv
from ptoverify.model import zohmaps as zm

N = 20_000  # points per operation


def _outside(lo, hi, exact) -> int:
    """Count the points whose arb value is not certainly inside [lo, hi]."""
    bad = 0
    with ctx.workprec(200):
        for a, b, x in zip(lo.tolist(), hi.tolist(), exact):
            if not (arb(a) <= x and x <= arb(b)):
                bad += 1
    return bad


def _floats(rng, n):
    """Floats of mixed signs and magnitudes 1e-8 .. 1e4."""
    return rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-8, 4, n)


@pytest.mark.parametrize("op", ["add", "sub", "mul", "div"])
def test_arithmetic_encloses_exact(op):
    rng = np.random.default_rng(11 + len(op))
    x, y = _floats(rng, N), _floats(rng, N)
    if op == "div":
        y = np.abs(y)
    lo, hi = getattr(iv, op)((x, x), (y, y))
    with ctx.workprec(200):
        f = {
            "add": lambda a, b: a + b,
            "sub": lambda a, b: a - b,
            "mul": lambda a, b: a * b,
            "div": lambda a, b: a / b,
        }[op]
        exact = [f(arb(a), arb(b)) for a, b in zip(x.tolist(), y.tolist())]
    assert _outside(lo, hi, exact) == 0, f"{op}: an exact result lies outside its enclosure"


def test_log1p_encloses_arb():
    rng = np.random.default_rng(3)
    r = np.concatenate(
        [
            rng.uniform(-0.999, 1.0, N // 2),
            10.0 ** rng.uniform(-12, 6, N // 4),
            -(10.0 ** rng.uniform(-12, -0.01, N // 4)),
        ]
    )
    lo, hi = iv.log1p_point(r)
    with ctx.workprec(200):
        exact = [arb(v).log1p() for v in r.tolist()]
    assert _outside(lo, hi, exact) == 0, "log1p enclosure misses the arb value"
    assert np.all(hi - lo <= 1e-14 * np.maximum(1.0, np.abs(lo))), "log1p enclosure too wide"


def test_h_encloses_arb():
    rng = np.random.default_rng(4)
    r = np.concatenate([10.0 ** rng.uniform(-9, 3, N // 2), rng.uniform(0.2, 0.3, N // 2)])
    lo, hi = iv.h_point(r)
    with ctx.workprec(200):
        exact = [arb(v) - arb(v).log1p() for v in r.tolist()]
    assert _outside(lo, hi, exact) == 0, "h enclosure misses the arb value"


def _exact_image(a, T, x1, x2, u, j):  # noqa: N803
    """The j-step ZOH image of a point in arb (closed form, eq. 7)."""
    with ctx.workprec(200):
        e = (-arb(a) * arb(T) * j).exp()
        y2 = arb(u) + (arb(x2) - arb(u)) * e
        y1 = arb(x1) + arb(u) * arb(T) * j + (arb(x2) - arb(u)) * (1 - e) / arb(a)
    return y1, y2


def test_step_images_enclose_exact_images():
    rng = np.random.default_rng(5)
    a, T, K = 188.49555921538757, 0.002, 12  # noqa: N806
    maps = zm.step_maps(arb(a), T, K)
    n = N // 2
    c1, c2 = rng.uniform(-50, 50, n), rng.uniform(-300, 300, n)
    h1, h2 = 10.0 ** rng.uniform(-4, 0, n), 10.0 ** rng.uniform(-2, 2, n)
    box = (c1 - h1, c1 + h1, c2 - h2, c2 + h2)
    u = rng.choice([-300.0, 300.0], n)
    j = rng.integers(0, K + 1, n)
    img = zm.affine_image(maps, j, box, (u, u))
    # corners (where the image box is tight) and interior points
    corner = rng.integers(0, 2, (2, n))
    p1 = np.where(corner[0] == 1, box[1], box[0])
    p2 = np.where(corner[1] == 1, box[3], box[2])
    q1, q2 = rng.uniform(box[0], box[1]), rng.uniform(box[2], box[3])
    bad = 0
    for x1, x2 in ((p1, p2), (q1, q2)):
        ex = [_exact_image(a, T, *v) for v in zip(x1.tolist(), x2.tolist(), u.tolist(), j)]
        bad += _outside(img[0], img[1], [e[0] for e in ex])
        bad += _outside(img[2], img[3], [e[1] for e in ex])
    assert bad == 0, "an exact ZOH image lies outside the image enclosure"


def test_a_interval_maps_enclose_every_a():
    rng = np.random.default_rng(6)
    T, K = 0.002, 5  # noqa: N806
    maps = zm.step_maps(zm.a_ball(150.0, 240.0), T, K)
    for a in rng.uniform(150.0, 240.0, 200).tolist():
        with ctx.workprec(200):
            for j in range(K + 1):
                e = (-arb(a) * arb(T) * j).exp()
                assert maps.e[0][j] <= float(e.lower()) and float(e.upper()) <= maps.e[1][j]
                p = (1 - e) / arb(a)
                assert arb(maps.p[0][j]) <= p and p <= arb(maps.p[1][j]), f"p_{j} at a = {a}"


def test_linear_powers_enclose_arb_matrix_powers():
    a, T, g = 188.49555921538757, 0.002, (323.0, 3.6)  # noqa: N806
    maps = zm.step_maps(arb(a), T, 8, gains=g)
    rng = np.random.default_rng(7)
    x1, x2 = rng.uniform(-0.5, 0.5, 2000), rng.uniform(-80, 80, 2000)
    j = rng.integers(0, 9, 2000)
    img = zm.linear_image(maps, j, (x1, x1, x2, x2))
    exact1, exact2 = [], []
    with ctx.workprec(200):
        for p, q, k in zip(x1.tolist(), x2.tolist(), j.tolist()):
            y1, y2 = arb(p), arb(q)
            for _ in range(k):  # one exact ZOH step with the linear input
                uu = -arb(g[0]) * y1 - arb(g[1]) * y2
                y1, y2 = _exact_image(a, T, y1, y2, uu, 1)
            exact1.append(y1)
            exact2.append(y2)
    assert _outside(img[0], img[1], exact1) + _outside(img[2], img[3], exact2) == 0


def test_shrunk_enclosures_are_caught():
    rng = np.random.default_rng(8)
    r = rng.uniform(0.3, 5.0, 2000)
    lo, hi = iv.log1p_point(r)
    with ctx.workprec(200):
        exact = [arb(v).log1p() for v in r.tolist()]
    assert _outside(lo, hi, exact) == 0
    assert _outside(lo + 1e-9, hi, exact) == r.size, "a raised lower bound went unnoticed"
    assert _outside(lo, hi - 1e-9, exact) == r.size, "a lowered upper bound went unnoticed"
    # the image box of a box is tight at corners: shrinking it by 1e-9 loses them
    a, T = 188.49555921538757, 0.002  # noqa: N806
    maps = zm.step_maps(arb(a), T, 1)
    x1, x2 = rng.uniform(-40, 40, 500), rng.uniform(-300, 300, 500)
    box = (x1, x1 + 0.5, x2, x2 + 3.0)
    u = np.full(500, 300.0)
    img = zm.affine_image(maps, np.ones(500, dtype=int), box, (u, u))
    ex = [_exact_image(a, T, p, q, 300.0, 1)[0] for p, q in zip(box[0].tolist(), x2.tolist())]
    assert _outside(img[0], img[1], ex) == 0
    assert _outside(img[0] + 1e-9, img[1], ex) == 500, "a shrunk image box went unnoticed"


def test_arb_interval_is_outward():
    with ctx.workprec(200):
        for x in (arb(1) / 3, arb(2).sqrt(), -arb.pi(), arb(2).log()):
            lo, hi = iv.arb_interval(x)
            assert arb(lo) <= x and x <= arb(hi)
            assert hi - lo <= 4e-16 * abs(hi), "conversion widened by more than an ulp or two"
