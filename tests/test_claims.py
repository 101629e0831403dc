"""Claims registry: every claim present, verdicts computed, measured values not typed in."""

import json
import math

import pytest

from ptoverify import claims as cl
from ptoverify.config import paper_config
from ptoverify.laws import make_law
from ptoverify.metrics import settling_time
from ptoverify.simulate import simulate

REQUIRED = {
    "step-to-oscillation",
    "step-pd-31-percent",
    "step-pto-steadier-quicker",
    "ramp-to-oscillation",
    "ramp-pd-lag",
    "ramp-pto-smooth",
    "sine-to-no-delay-oscillates",
    "sine-pto-delay",
    "sine-pd-delay",
    "sine-pto-vs-pd",
    "conclusion-vs-to-and-pd",
}


@pytest.fixture(scope="module")
def results():
    return cl.evaluate_claims(paper_config())


def test_every_issue_claim_present_with_a_verdict(results):
    ids = {r.id for r in results}
    assert REQUIRED <= ids, f"missing claims: {REQUIRED - ids}"
    assert len(ids) == len(results), "claim ids are unique"
    for r in results:
        assert r.verdict in cl.VERDICTS, r.id
        assert r.readings and all(
            x.verdict in ("reproduced", "not reproduced") for x in r.readings
        ), r.id
        agree = {x.verdict for x in r.readings}
        expect = agree.pop() if len(agree) == 1 else "ambiguous"
        assert r.verdict == expect, f"{r.id}: overall verdict follows the readings"
        assert r.detail and r.rule and r.claim, r.id
        json.dumps(r.to_json(), allow_nan=True)


def test_paper_numbers_are_claims(results):
    by = {r.id: r for r in results}
    assert by["sine-pto-delay"].paper_value == 4.5
    assert by["sine-pd-delay"].paper_value == 8.1
    assert by["sine-pto-vs-pd"].paper_value == 55.5
    assert by["step-pd-31-percent"].paper_value == 31.0


def test_readings_cover_the_ambiguities(results):
    """a in Hz or rad/s everywhere; feed-forward on ramp/sine; PTO printed/corrected with PTO."""
    by = {r.id: r for r in results}
    for r in results:
        assert {x.reading.a for x in r.readings} == {"2pi*f", "f"}, r.id
    assert {x.reading.tracking for x in by["sine-pd-delay"].readings} == {
        "feed-forward",
        "none",
        "error",
    }
    assert {x.reading.pto for x in by["sine-pto-delay"].readings} == {"corrected", "printed"}
    assert {x.reading.tracking for x in by["step-to-oscillation"].readings} == {None}
    first = by["sine-pto-delay"].readings[0].reading
    assert (first.a, first.tracking, first.pto) == ("2pi*f", "feed-forward", "corrected"), (
        "primary reading"
    )
    one = cl.evaluate_claims(paper_config().with_plant(a=100.0))
    assert all({x.reading.a for x in r.readings} == {"given"} for r in one), (
        "a config giving a in rad/s has a single a-reading"
    )


def test_measured_value_is_recomputed_from_simulation(results):
    """The headline number equals an independent recomputation, and moves with the plant."""
    cfg = paper_config()
    by = {r.id: r for r in results}
    pd = simulate(make_law("pd", cfg), cfg.plant, "step")
    pto = simulate(make_law("pto", cfg), cfg.plant, "step")
    ts_pd, ts_pto = (settling_time(r.t, r.e, 0.02 * 5.0) for r in (pd, pto))
    assert by["step-pd-31-percent"].measured == pytest.approx(100 * (ts_pd / ts_pto - 1), rel=1e-12)
    other = {r.id: r for r in cl.evaluate_claims(cfg.with_plant(w_max=250.0))}
    changed = [
        i for i in REQUIRED if by[i].measured is not None and other[i].measured != by[i].measured
    ]
    assert len(changed) >= 5, f"measured values must follow the simulation; changed: {changed}"
    for i in REQUIRED:
        m = by[i].measured
        assert m is None or math.isfinite(m), i


def test_numeric_rule():
    assert cl.numeric_verdict(5.3, 4.5, 1.0) and not cl.numeric_verdict(5.6, 4.5, 1.0)
    assert cl.numeric_verdict(9.7, 8.1, 1.0) and not cl.numeric_verdict(9.8, 8.1, 1.0)
    assert not cl.numeric_verdict(math.nan, 4.5, 1.0)


def test_cached():
    """Speed is measured in benchmarks/; here only that a second call reuses the results."""
    cfg = paper_config().with_plant(w_max=280.0)
    first = cl.evaluate_claims(cfg)
    again = cl.evaluate_claims(cfg)
    assert all(a is b for a, b in zip(first, again, strict=True)), "cache"


def test_error_tracking_reading_matches_simulate_for_a_step(paper_cfg):
    """With r' = 0 the local 'error' loop is the feed-forward loop of simulate (same flow)."""
    from ptoverify.claims import _simulate_error_tracking

    for name in ("pd", "pto"):
        law = make_law(name, paper_cfg)
        ref = simulate(law, paper_cfg.plant, "step")
        loc = _simulate_error_tracking(law, paper_cfg.plant, "step")
        assert (loc.x1 == ref.x1).all() and (loc.u == ref.u).all(), name
