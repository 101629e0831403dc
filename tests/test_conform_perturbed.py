"""``conform`` under perturbation (--delay, --quantum, --velocity-noise --seed, --a-ratio,
--robust), the [conform] pass limits and the float32 precision mode."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest

from ptoverify.cli import main
from ptoverify.config import PAPER_MAPPING, ConformLimits, config_from_mapping, paper_config
from ptoverify.conform.gate import conform_callable, conform_spec, format_result, reference_law
from ptoverify.conform.perturbed import (
    PERTURBED_PROPERTIES,
    Perturbation,
    perturbed_runs,
    robust_box,
)
from ptoverify.conform.precision import UNIT_ROUNDOFF_32, as_seen, float32_ties
from ptoverify.conform.userlaw import wrap_callable
from ptoverify.errors import ConfigError
from ptoverify.model.curves import level_residual
from ptoverify.model.laws import make_law
from ptoverify.sim.simulate import Mismatch, simulate_batch
from ptoverify.studies.properties import default_steps, initial_grid

SMALL = (11, 11, 20)
FEW = {"sweep": SMALL, "n_random": 2000, "n_band": 2000}
REF = "ptoverify.conform.gate:reference_law"


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------ the tests
def test_reference_with_a_built_in_delay_is_memory_under_delay_0(capsys, tmp_path):
    law = tmp_path / "delayed.py"
    law.write_text(
        "from ptoverify.conform.gate import reference_law\n"
        "_prev = [0.0]\n"
        "def law(x1, x2, cfg):\n"
        "    u = _prev[0]\n"
        "    _prev[0] = float(reference_law(float(x1), float(x2), cfg))\n"
        "    return u\n"
    )
    code, out, _ = run(capsys, "conform", "--law", f"{law}:law", "--delay", "0", "--json")
    res = json.loads(out)
    assert code == 1 and not res["conforms"]
    assert {f["property"] for f in res["failures"]} == {"pure-function"}
    assert "has memory" in res["failures"][0]["detail"]
    for name in PERTURBED_PROPERTIES:  # judged after the finding: not run, never a pass
        assert res["properties"][name]["status"] == "not_run"


def test_reference_under_one_sample_delay_conforms_to_itself_and_is_flagged():
    cfg = paper_config()
    r = conform_callable(
        reference_law, cfg, target="ref", perturbations=(Perturbation(delay_samples=1),), **FEW
    )
    assert r.conforms, r.failures
    # independently: the reference limit-cycles (or never settles) with a one-sample delay
    x1, x2, _ = initial_grid(cfg, *SMALL)
    res = simulate_batch(
        make_law("pto", cfg),
        cfg.plant,
        x1,
        x2,
        default_steps(cfg),
        mismatch=Mismatch(delay_samples=1),
    )
    unsettled = int((np.abs(res.x1[-1]) > 1e-3).sum())
    assert unsettled > 0
    (run_,) = r.perturbed
    cycle = {c.name: c for c in run_.comparisons}["no-limit-cycle"]
    assert cycle.reference >= unsettled and cycle.user == cycle.reference
    assert "no-limit-cycle under delay 1 sample" in r.reference_fails
    js = r.to_json()
    assert "no-limit-cycle under delay 1 sample" in js["perturbation"]["reference_fails"]
    first = format_result(r).splitlines()[0]
    assert first.startswith("CONFORMS") and "the reference itself fails" in first
    assert r.properties["perturbed-no-limit-cycle"].passed


def _strip(js: dict) -> dict:
    js = dict(js)
    js.pop("timings_s")
    return js


def test_perturbed_runs_are_deterministic_for_a_seed():
    cfg = paper_config()
    p = Perturbation(velocity_noise=2.0, seed=7, position_quantum=0.01)
    a = conform_callable(reference_law, cfg, perturbations=(p,), **FEW)
    b = conform_callable(reference_law, cfg, perturbations=(p,), **FEW)
    assert _strip(a.to_json()) == _strip(b.to_json())
    # the same noise sequence for both laws: the reference against itself is identical
    for c in a.perturbed[0].comparisons:
        assert c.user == c.reference or (math.isinf(c.user) and math.isinf(c.reference))
    # and the noise is applied: another seed moves the trajectories
    x1, x2, _ = initial_grid(cfg, *SMALL)
    law, steps = make_law("pto", cfg), default_steps(cfg)
    m7 = simulate_batch(law, cfg.plant, x1, x2, steps, mismatch=p.mismatch())
    m8 = simulate_batch(
        law, cfg.plant, x1, x2, steps, mismatch=Perturbation(velocity_noise=2.0, seed=8).mismatch()
    )
    assert not np.array_equal(m7.x1, m8.x1)


def test_a_worse_law_under_delay_fails_relative_to_the_reference():
    """The time-optimal bang-bang law as the 'user': its closed loop under a one-sample
    delay, counted independently, decides the comparison."""
    cfg = paper_config()
    to = make_law("to", cfg)

    def to_law(x1, x2, c):
        return to.vector(np.asarray(x1, float), np.asarray(x2, float))[0]

    user, _ = wrap_callable(to_law, cfg)
    p = Perturbation(delay_samples=1)
    runs, fails = perturbed_runs(user, cfg, (p,), sweep=SMALL)
    x1, x2, _ = initial_grid(cfg, *SMALL)
    steps = default_steps(cfg)
    counts = {}
    for name, law in (("user", to), ("reference", make_law("pto", cfg))):
        res = simulate_batch(law, cfg.plant, x1, x2, steps, mismatch=p.mismatch())
        counts[name] = int((np.abs(res.x1[-1]) > 1e-3).sum())
    cycle = {c.name: c for c in runs[0].comparisons}["no-limit-cycle"]
    assert cycle.user >= counts["user"] and cycle.reference >= counts["reference"]
    slack = math.ceil(0.01 * x1.size)
    assert cycle.passed == (cycle.user <= cycle.reference + slack)
    assert not runs[0].passed  # bang-bang with a delay chatters from more states
    assert any(f["property"].startswith("perturbed-") for f in fails)


def _raises_far_out(x1, x2, cfg):
    x1 = np.asarray(x1, dtype=float)
    if np.any(np.abs(x1) > 1.05 * cfg.plant.position_range):
        raise RuntimeError("state outside what this firmware handles")
    return reference_law(x1, x2, cfg)


def test_a_law_that_raises_only_under_perturbation_fails_closed():
    cfg = paper_config()
    r = conform_callable(_raises_far_out, cfg, perturbations=(Perturbation(a_ratio=0.1),), **FEW)
    assert not r.conforms
    assert any(f["property"] == "evaluation" and "a ratio 0.1" in f["detail"] for f in r.failures)
    for name in PERTURBED_PROPERTIES:
        assert r.properties[name].status == "fail"


def test_an_isolated_law_that_hangs_under_perturbation_is_unverified(tmp_path):
    law = tmp_path / "hang.py"
    law.write_text(
        "import time\nimport numpy as np\nfrom ptoverify.conform.gate import reference_law\n"
        "def law(x1, x2, cfg):\n"
        "    if np.any(np.abs(np.asarray(x1)) > 1.05 * cfg.plant.position_range):\n"
        "        time.sleep(3600)\n"
        "    return reference_law(x1, x2, cfg)\n"
    )
    # the nominal stages take about 2 s: a 6 s budget ends the hang (was 10 s, a call's own)
    r = conform_spec(
        f"{law}:law",
        paper_config(),
        timeout=6,
        perturbations=(Perturbation(a_ratio=0.1),),
        **FEW,
    )
    assert not r.conforms
    assert any(f["property"] == "isolation" for f in r.failures)
    for name in PERTURBED_PROPERTIES:
        assert r.properties[name].status in ("unverified", "fail")
        assert not r.properties[name].passed


def test_robust_runs_every_corner_of_the_box():
    cfg = paper_config()
    box = cfg.robustness
    corners = set(itertools.product(box.a_ratio, box.w_max_ratio, box.delay_samples))
    got = robust_box(cfg)
    assert {(p.a_ratio, p.w_max_ratio, p.delay_samples) for p in got} == corners
    assert all(p.position_quantum == box.position_quantum for p in got)
    r = conform_callable(reference_law, cfg, perturbations=got, **FEW)
    assert r.conforms and len(r.perturbed) == len(corners)
    assert len(r.to_json()["perturbation"]["runs"]) == len(corners)


@pytest.mark.parametrize(
    ("args", "text"),
    [
        (["--delay", "-1"], "--delay must be an integer in [0, 10]"),
        (["--delay", "11"], "--delay must be an integer in [0, 10]"),
        (["--quantum", "0"], "--quantum must be in (0,"),
        (["--quantum", "-0.1"], "--quantum must be in (0,"),
        (["--velocity-noise", "1"], "--velocity-noise needs --seed"),
        (["--velocity-noise", "0", "--seed", "1"], "--velocity-noise must be in (0,"),
        (["--seed", "3"], "--seed is the noise seed"),
        (["--a-ratio", "0"], "--a-ratio must be in [0.1, 10]"),
        (["--precision", "float16"], "--precision must be one of float64, float32"),
        (["--robust", "--delay", "1"], "--robust runs the [robustness] box"),
    ],
)
def test_bad_perturbation_options_are_one_line_exit_2(capsys, args, text):
    code, out, err = run(capsys, "conform", "--law", REF, *args)
    assert code == 2 and out == ""
    assert text in err and len(err.strip().splitlines()) == 1, err


def test_perturbation_with_a_table_is_bad_input(capsys, tmp_path):
    t = tmp_path / "t.csv"
    t.write_text("x1,x2,u\n0,0,0\n")
    code, _, err = run(capsys, "conform", "--table", str(t), "--delay", "1")
    assert code == 2 and "need --law" in err


# ------------------------------------------------------------------ [conform]
def test_conform_table_sets_the_settling_limit():
    base = paper_config()
    wide = config_from_mapping({**PAPER_MAPPING, "conform": {"settling_margin": 2.0}})
    assert wide.conform == ConformLimits(settling_margin=2.0)
    assert base.digest() == config_from_mapping(dict(PAPER_MAPPING)).digest()
    assert wide.digest() != base.digest()
    v0 = conform_callable(reference_law, base, **FEW).properties["settling-vs-discrete-limit"]
    v2 = conform_callable(reference_law, wide, **FEW).properties["settling-vs-discrete-limit"]
    # the reference's worst excess E (its own measured value) fixes both limits
    e_ref = v0.measured
    assert v0.limit == e_ref + max(2, math.ceil(0.5 * e_ref))
    assert v2.limit == e_ref + max(2, math.ceil(2.0 * e_ref))


@pytest.mark.parametrize(
    ("table", "text"),
    [
        ({"settling_margin": -1}, "conform.settling_margin"),
        ({"count_margin": 2}, "conform.count_margin"),
        ({"settling_min_samples": 1.5}, "conform.settling_min_samples"),
        ({"nope": 1}, "unknown config key 'conform.nope'"),
    ],
)
def test_bad_conform_table_is_a_config_error(table, text):
    with pytest.raises(ConfigError, match=text.replace(".", r"\.")):
        config_from_mapping({**PAPER_MAPPING, "conform": table})


# ------------------------------------------------------------------ float32
def test_float32_tie_band_holds_every_float32_side_flip():
    """Independent reference: evaluate each curve's residual in numpy float32 arithmetic
    (as firmware would); wherever its sign differs from the float64 residual at the state
    as seen, the state must lie in the derived tie band."""
    cfg = paper_config()
    a, w = cfg.plant.a, cfg.plant.w_max
    from ptoverify.conform.agreement import omega0_ref
    from ptoverify.model.curves import level_curve_x1

    om = omega0_ref(cfg)
    rng = np.random.default_rng(5)
    v = rng.uniform(-w, w, 200_000)
    flips = 0
    for level in (w, om):
        c = level_curve_x1(v, a, level)
        x1 = c * (1 + rng.normal(0, 3e-7, v.size))  # within a few float32 ulps of the curve
        y1, y2 = as_seen(x1, v, "float32")
        f1, f2 = y1.astype(np.float32), y2.astype(np.float32)
        s = np.abs(f2) / np.float32(level)
        hf = s - np.log1p(s)
        r32 = np.float32(a) * f1 + np.sign(f2) * np.float32(level) * hf
        r64 = level_residual(y1, y2, a, level)
        flip = (np.sign(r32) != np.sign(r64)) & (np.abs(y1) >= cfg.pto.d)
        flips += int(flip.sum())
        assert float32_ties(y1[flip], y2[flip], cfg, om).all()
    assert flips > 0  # the test exercised the band
    assert UNIT_ROUNDOFF_32 == 2.0**-24


def test_float32_reference_at_the_state_as_seen(capsys):
    """A law that rounds the state to float32 and then calls the double reference conforms
    under --precision float32 (exactly: u equals the reference at the state it saw), and
    fails the float64 agreement (where the rounding crosses a boundary)."""
    cfg = paper_config()

    def rounded(x1, x2, c):
        y1 = np.asarray(x1, dtype=np.float32).astype(float)
        y2 = np.asarray(x2, dtype=np.float32).astype(float)
        return reference_law(y1, y2, c)

    r32 = conform_callable(rounded, cfg, precision="float32", **FEW)
    assert r32.conforms, r32.failures
    assert r32.agreement["max_abs_du"] == 0.0
    r64 = conform_callable(rounded, cfg, **FEW)
    assert not r64.conforms and set(r64.failed_properties()) == {"agreement"}


@pytest.mark.slow
def test_assert_conforms_takes_perturbations_and_precision():
    from ptoverify.conform.testing import assert_conforms

    r = assert_conforms(REF, perturbations=(Perturbation(delay_samples=1),))
    assert r.precision == "float64" and len(r.perturbed) == 1
    assert "no-limit-cycle under delay 1 sample" in r.reference_fails
    # a failing law's message carries the summary line with the perturbation (a law that
    # fails at its first call: the line names the perturbations judged, whatever failed)
    with pytest.raises(AssertionError, match="under delay 1 sample"):
        assert_conforms(f"{__file__}:_broken_law", perturbations=(Perturbation(delay_samples=1),))
    # float32 says the implementation sees the state rounded to float32: the double
    # reference (which does not round) then disagrees where rounding crosses |x1| = d
    with pytest.raises(AssertionError, match="precision float32"):
        assert_conforms(REF, precision="float32")


def _broken_law(x1, x2, cfg):
    """Raise at every call, as firmware bindings that are not there (a failing law)."""
    raise RuntimeError("no firmware binding")
