"""The encoder-quantum and velocity-noise sweeps (``ptoverify.studies.robust.drive``)."""

import math

import numpy as np
import pytest

from ptoverify.config import paper_config
from ptoverify.model.laws import make_law
from ptoverify.model.plant import flow
from ptoverify.studies.robust.drive import drive_sweeps
from ptoverify.studies.robust.maps import RobustSettings, horizon_steps, map_states

CFG = paper_config()


def reference_run(law, x1, x2, q, steps):
    """The sampled loop by hand: the law on the quantized position, the exact ZOH flow."""
    p = CFG.plant
    xs1, xs2 = [x1], [x2]
    for _ in range(steps):
        seen = q * round(x1 / q) if q > 0 else x1
        u, _ = law.scalar(seen, x2)
        u = min(max(u, -p.w_max), p.w_max)
        x1, x2 = (float(v) for v in flow(x1, x2, u, p.sample_time, p.a))
        xs1.append(x1)
        xs2.append(x2)
    return np.array(xs1), np.array(xs2)


def settled_at(x1, x2, hold_steps):
    """First sample from which every later sample is in the 0.01 mm box; None if never."""
    box = (np.abs(x1) <= 0.01) & (np.abs(x2) <= CFG.plant.a * 0.01)
    last = x1.size - 1
    for k in range(last + 1):
        if box[k:].all():
            return k if last - k >= hold_steps else None
    return None


@pytest.mark.parametrize("law", ["pd", "pto"])
def test_quantum_point_is_the_hand_loop(law):
    """Residual, settled count and longest settling equal a hand-written loop's, state by state."""
    q = 0.02
    out = drive_sweeps(CFG, laws=(law,), quanta=(q,), noises=(), grid=3)
    (pt,) = out.points
    x1, x2 = map_states(CFG, RobustSettings(n1=3, n2=3))
    steps = horizon_steps(CFG)
    hold = math.ceil(0.05 / CFG.plant.sample_time - 1e-9)
    residual, never, longest = 0.0, 0, -1.0
    f = make_law(law, CFG)
    for a, b in zip(x1, x2, strict=True):
        r1, r2 = reference_run(f, float(a), float(b), q, steps)
        residual = max(residual, float(np.abs(r1[-max(20, steps // 4) :]).max()))
        k = settled_at(r1, r2, hold)
        if k is None:
            never += 1
        else:
            longest = max(longest, k * CFG.plant.sample_time)
    assert pt.residual_mm == pytest.approx(residual, rel=1e-9, abs=1e-12), "residual [mm]"
    assert pt.not_settled == never
    assert pt.worst_settling_s == pytest.approx(longest, abs=1e-12), "longest settling [s]"


def test_pd_at_rest_within_half_a_quantum():
    """A PD law at rest under a quantized encoder stops where its reading is 0: |x1| <= q / 2."""
    out = drive_sweeps(CFG, laws=("pd",), quanta=(0.001, 0.005), noises=(), grid=5)
    for p in out.points:
        assert p.residual_mm <= p.position_quantum_mm / 2 + 1e-12, p


def test_noise_sweep_is_seeded_and_grows_with_the_noise():
    a = drive_sweeps(CFG, laws=("pto",), quanta=(), noises=(0.3, 10.0), grid=3, seed=1)
    b = drive_sweeps(CFG, laws=("pto",), quanta=(), noises=(0.3, 10.0), grid=3, seed=1)
    c = drive_sweeps(CFG, laws=("pto",), quanta=(), noises=(0.3, 10.0), grid=3, seed=2)
    assert a == b, "the same seed gives the same sweep"
    assert a.points[1].residual_mm != c.points[1].residual_mm, "another seed, another noise"
    assert a.points[1].residual_mm > a.points[0].residual_mm, "more noise, more jitter"
    assert a.to_json()["points"][1]["velocity_noise_mm_s"] == 10.0
