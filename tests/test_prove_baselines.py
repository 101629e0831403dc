"""``prove`` for the baselines: the cascade P loop proved soundly, PTOS refused.

The cascade P loop's enclosure (model.lawbox, PD's with kd = 0) is checked
against exact rational arithmetic (fractions): u = sat(-kp x1) is monotone in
x1, so its exact range over a box is [sat(-kp x1hi), sat(-kp x1lo)], computed
in Fractions from the float box ends and kp; the enclosure must contain it at
seeded random boxes and at edge boxes (points, ulp-wide boxes, boxes on and
around the saturation edges x1 = +-w_max / kp, the origin, the whole envelope),
and a box flagged linear must be unsaturated in exact arithmetic.  The proof's
bound is checked against simulation of the law it names.
"""

from __future__ import annotations

import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from ptoverify.config import PAPER_MAPPING, config_from_mapping, paper_config
from ptoverify.errors import InputError
from ptoverify.model.baselines import cascade_law
from ptoverify.model.lawbox import enclose, law_spec
from ptoverify.sim.simulate import simulate_batch
from ptoverify.studies.prove import run_prove
from ptoverify.studies.prove.certificate import certificate_arrays, check_certificate
from ptoverify.studies.prove.run import prove_law

ROOT = Path(__file__).resolve().parents[1]


def _exact_range(x1lo: float, x1hi: float, kp: float, w: float) -> tuple[Fraction, Fraction]:
    """[min, max] of sat(-kp x1) over [x1lo, x1hi], exactly."""
    k, wf = Fraction(kp), Fraction(w)

    def sat(v):
        return max(-wf, min(wf, v))

    return sat(-k * Fraction(x1hi)), sat(-k * Fraction(x1lo))


def _boxes(cfg, rng, n):
    """Random boxes (a third centred on a saturation edge or the origin) and edge boxes."""
    w, kp, R = cfg.plant.w_max, law_spec("cascade-p", cfg).g1, cfg.plant.position_range
    edge = w / kp
    c1 = rng.uniform(-R, R, n)
    k = rng.integers(0, 3, n)
    c1 = np.where(k == 0, rng.choice([-edge, edge], n), np.where(k == 1, 0.0, c1))
    h1 = 10.0 ** rng.uniform(-12, 1, n)
    lo, hi = c1 - h1, c1 + h1
    special_lo = [edge, -edge, np.nextafter(edge, 0), -R, 0.0, np.nextafter(-edge, -np.inf)]
    special_hi = [edge, -edge, np.nextafter(edge, np.inf), R, 0.0, np.nextafter(-edge, 0)]
    lo = np.concatenate([lo, special_lo])
    hi = np.concatenate([hi, special_hi])
    x2lo = rng.uniform(-w, w, lo.size)
    x2hi = np.minimum(x2lo + 10.0 ** rng.uniform(-6, 2, lo.size), w)
    return lo, hi, x2lo, x2hi


@pytest.mark.parametrize("section", [{}, {"cascade": {"kp": 123.456789}}])
def test_cascade_enclosure_contains_the_exact_range(section):
    cfg = config_from_mapping({**PAPER_MAPPING, **section})
    spec = law_spec("cascade-p", cfg)
    kp, w = spec.g1, cfg.plant.w_max
    assert spec.g2 == 0.0 and spec.d == np.inf
    rng = np.random.default_rng(25)
    box = _boxes(cfg, rng, 4000)
    enc = enclose(spec, box)
    law = cascade_law(cfg)
    for i in range(box[0].size):
        lo, hi = _exact_range(box[0][i], box[1][i], kp, w)
        assert Fraction(enc.lo[i]) <= lo and hi <= Fraction(enc.hi[i]), (i, box[0][i], box[1][i])
        if enc.linear[i]:  # flagged linear: unsaturated over the whole box, exactly
            assert -Fraction(w) <= lo and hi <= Fraction(w)
            assert abs(Fraction(kp) * Fraction(box[0][i])) <= Fraction(w)
            assert abs(Fraction(kp) * Fraction(box[1][i])) <= Fraction(w)
    # and the float law at the box ends lies inside too (the law the proof speaks of)
    u_lo, _ = law(box[1], box[3])
    u_hi, _ = law(box[0], box[2])
    assert np.all((enc.lo <= u_lo) & (u_hi <= enc.hi))
    # not vacuous: tight to a few ulps of the exact range away from the clip
    tight = np.abs(enc.hi - enc.lo) <= np.abs(kp * (box[1] - box[0])) + 1e-9 * w
    assert tight.mean() > 0.99


def test_cascade_proof_bound_covers_simulation_and_its_certificate_checks():
    cfg = paper_config()
    proof = prove_law(cfg, "cascade-p", n_random=500)
    assert proof.property("input-bound").status == "proved"
    assert proof.simulation_over_bound == 0
    law = cascade_law(cfg)
    rng = np.random.default_rng(3)
    x1 = rng.uniform(-50, 50, 20_000)
    x2 = rng.uniform(-300, 300, 20_000)
    b = simulate_batch(law, cfg.plant, x1, x2, int(proof.bound_samples) + 2)
    (p11, p12), (_, p22) = proof.target.P
    q = p11 * b.x1**2 + 2 * p12 * b.x1 * b.x2 + p22 * b.x2**2
    inside = q <= proof.target.c * (1 + 1e-9)
    first = np.where(inside.any(axis=0), inside.argmax(axis=0), np.inf)
    g = proof.grid
    i = np.clip(np.searchsorted(g.e1, x1, "right") - 1, 0, g.shape[0] - 1)
    j = np.clip(np.searchsorted(g.e2, x2, "right") - 1, 0, g.shape[1] - 1)
    bound = proof.bound[j * g.shape[0] + i]
    proved = np.isfinite(bound)
    assert proved.mean() > 0.99
    assert not np.any(proved & (first > bound)), "a state needed more samples than its bound"
    data = certificate_arrays(proof, cfg)
    assert str(data["law"]) == "cascade-p"
    assert check_certificate(data, cfg, samples=20).ok
    other = config_from_mapping({**PAPER_MAPPING, "cascade": {"kp": 60.0}})
    assert not check_certificate(data, other, samples=5).ok  # another kp: not this law


def test_ptos_has_no_certified_enclosure():
    with pytest.raises(InputError, match="ptos.*no certified enclosure"):
        law_spec("ptos", paper_config())
    with pytest.raises(InputError, match="no certified enclosure"):
        run_prove(paper_config(), laws=("ptos",))


def test_cli_prove_ptos_is_one_line_bad_input(tmp_path):
    out = tmp_path / "proof"
    p = subprocess.run(
        [sys.executable, "-m", "ptoverify", "prove", "--law", "ptos", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert p.returncode == 2 and p.stdout == "" and not out.exists()
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:")
    assert "no certified enclosure" in lines[0]
