"""Batched simulation of the robustness study against the simple per-case simulation.

``simulate_parts`` (several laws and mismatches in one run), ``simulate_asks``
(asks in runs) and ``run_together`` (searches side by side) must give each case exactly what
the case simulated alone gives: ``simulate_batch`` with its own mismatch, and
that in turn the independent scalar loop (``plant.flow`` per sample, a delay
line, a quantizer, ``law.scalar``).  The study's results must not depend on how
its simulations were grouped.
"""

import dataclasses
import json

import numpy as np
import pytest

from ptoverify.config import paper_config
from ptoverify.model.laws import Region, make_law
from ptoverify.model.plant import flow
from ptoverify.sim.lockstep import Ask, run_together, simulate_asks
from ptoverify.sim.simulate import BatchResult, Mismatch, simulate_batch, simulate_parts
from ptoverify.studies.robust import (
    RobustSettings,
    grid_worst,
    no_limit_cycle_margin,
    robust_maps,
    run_robust,
    worst_cases,
)

CFG = paper_config()
P = CFG.plant
LAWS = {name: make_law(name, CFG) for name in ("to", "pd", "pto", "pto-printed")}


def _scalar_loop(law, x0, steps, a_ratio, w_ratio, delay, q, noise):
    """One case, sample by sample: plant.flow of the true plant, a delay line, a quantizer."""
    a, w = P.a * a_ratio, P.w_max * w_ratio
    x = (float(x0[0]), float(x0[1]))
    xs, line, held = [x], [], None
    for k in range(steps):
        y1 = q * round(x[0] / q) if q else x[0]
        u, _ = law.scalar(float(y1), float(x[1] + noise[k]))
        line.append(u)
        held = line[0] if held is None else held
        if len(line) > delay:
            held = line.pop(0)
        x = flow(x[0], x[1], min(max(held, -w), w), P.sample_time, a)
        xs.append(x)
    return np.array(xs)


def _random_case(rng, n):
    """A random mismatch for n states (per-state ratios and delays, a shared measurement)."""
    return Mismatch(
        a_ratio=rng.uniform(0.5, 2.0, n),
        w_max_ratio=rng.uniform(0.8, 1.0, n),
        delay_samples=rng.integers(0, 3, n),
        position_quantum=float(rng.choice([0.0, 1e-3, 5e-3])),
        velocity_noise=float(rng.choice([0.0, 2.0])),
        seed=int(rng.integers(0, 100)),
    )


def simulate_segments(segments, plant, steps):
    """The parts of :func:`simulate_parts` side by side (columns in segment order)."""
    parts = simulate_parts(segments, plant, steps)
    return BatchResult(
        *(
            np.concatenate([getattr(p, f) for p in parts], axis=1)
            for f in ("x1", "x2", "u", "region")
        )
    )


def _assert_segments_run_alone(segments, steps):
    """simulate_parts gives each segment exactly its own simulate_batch run."""
    both = simulate_segments(segments, P, steps)
    at = 0
    for law, x1, x2, m in segments:
        alone = simulate_batch(law, P, x1, x2, steps, mismatch=m)
        cols = slice(at, at + x1.size)
        at += x1.size
        for f in ("x1", "x2", "u", "region"):
            assert np.array_equal(getattr(both, f)[:, cols], getattr(alone, f)), (law.name, f, m)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_segments_equal_each_case_alone_bit_for_bit(seed):
    """Random laws, states and mismatches (identity ones included) in one run."""
    rng = np.random.default_rng(seed)
    steps = 150
    segments = []
    for _ in range(6):
        law = LAWS[rng.choice(list(LAWS))]
        n = int(rng.integers(1, 6))
        x1 = rng.uniform(-50.0, 50.0, n) * rng.uniform(0.0, 1.0, n) ** 2
        x2 = rng.uniform(-300.0, 300.0, n) * rng.uniform(0.0, 1.0, n)
        m = None if rng.random() < 0.2 else _random_case(rng, n)
        segments.append((law, x1, x2, m))
    _assert_segments_run_alone(segments, steps)


@pytest.mark.parametrize("seed", [3, 4])
def test_segments_against_the_independent_scalar_loop(seed):
    rng = np.random.default_rng(seed)
    steps = 120
    segments, cases = [], []
    for name in ("pd", "pto", "to"):
        n = 3
        x1, x2 = rng.uniform(-40.0, 40.0, n), rng.uniform(-250.0, 250.0, n)
        m = _random_case(rng, n)
        segments.append((LAWS[name], x1, x2, m))
        cases += [(LAWS[name], (x1[i], x2[i]), m, i) for i in range(n)]
    both = simulate_segments(segments, P, steps)
    for j, (law, x0, m, i) in enumerate(cases):
        noise = (
            np.random.default_rng(m.seed).normal(0.0, m.velocity_noise, steps)
            if m.velocity_noise
            else np.zeros(steps)
        )
        ref = _scalar_loop(
            law,
            x0,
            steps,
            m.a_ratio[i],
            m.w_max_ratio[i],
            int(m.delay_samples[i]),
            m.position_quantum,
            noise,
        )
        np.testing.assert_allclose(both.x1[:, j], ref[:, 0], rtol=1e-9, atol=1e-9, err_msg=law.name)
        np.testing.assert_allclose(both.x2[:, j], ref[:, 1], rtol=1e-9, atol=1e-7, err_msg=law.name)


def test_run_together_merges_batches_and_stops_on_errors():
    """One batch per round, in job order; a failing batch stops every job waiting on it."""
    calls = []

    def batch_fn(xs):
        calls.append(list(xs))
        if any(x < 0 for x in xs):
            raise ValueError("negative")
        return [2 * x for x in xs]

    def job(k):
        return lambda ev: [ev([k, k + 10]), ev([k + 20])]

    got = run_together(batch_fn, [job(k) for k in (1, 2, 3)])
    assert got == [[[2 * k, 2 * k + 20], [2 * k + 40]] for k in (1, 2, 3)]
    assert calls == [[1, 11, 2, 12, 3, 13], [21, 22, 23]], "one batch per round, job order"
    with pytest.raises(ValueError, match="negative"):
        run_together(batch_fn, [lambda ev: ev([1]), lambda ev: ev([-1]), lambda ev: None])


def test_run_together_equals_the_jobs_one_by_one():
    """Jobs of different lengths (one finishes early, one asks nothing) get what the
    batch function alone gives them; the batches are fewer."""
    calls = []

    def batch_fn(xs):
        calls.append(len(xs))
        return [x**2 + 1 for x in xs]

    def job(k, rounds):
        def run(ev):
            x, out = k, []
            for _ in range(rounds):
                (x,) = ev([x % 97])
                out.append(x)
            return out

        return run

    jobs = [job(3, 4), job(5, 1), job(7, 0), job(11, 6)]
    alone = [j(batch_fn) for j in jobs]
    n_alone = len(calls)
    calls.clear()
    assert run_together(batch_fn, jobs) == alone
    assert len(calls) == 6 < n_alone


@pytest.mark.parametrize("round_states", [1, 5, 10_000])
def test_simulate_asks_does_not_depend_on_run_size(round_states):
    """Asks in runs of any size give each ask what simulate_batch gives it alone."""
    rng = np.random.default_rng(7)
    steps = 80
    asks = []
    for name in ("pd", "pto", "to", "pto", "pto-printed"):
        x1, x2 = rng.uniform(-30.0, 30.0, 3), rng.uniform(-200.0, 200.0, 3)
        asks.append(Ask(LAWS[name], x1, x2, _random_case(rng, 3), stage=name))
    seconds = {}
    got = simulate_asks(
        asks,
        P,
        steps,
        lambda k, b: (k, b.x1.copy(), b.region.copy()),
        round_states=round_states,
        seconds=seconds,
    )
    for k, (ask, (j, x1, region)) in enumerate(zip(asks, got, strict=True)):
        alone = simulate_batch(ask.law, P, ask.x1, ask.x2, steps, mismatch=ask.mismatch)
        assert j == k
        assert np.array_equal(x1, alone.x1) and np.array_equal(region, alone.region), k
    assert set(seconds) == {"pd", "pto", "to", "pto-printed"}
    assert all(v >= 0.0 for v in seconds.values())


TINY = RobustSettings(n1=5, n2=4, rest=4, n_a=3, n_w=2, search_iterations=2, search_population=6)


def _same(a, b) -> bool:
    """Equal, NaN included (as JSON text)."""
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_study_does_not_depend_on_round_size(monkeypatch):
    """Maps, margins and worst cases with runs of one state each equal the default runs."""
    import ptoverify.studies.robust.maps as maps_mod

    box = dataclasses.replace(CFG.robustness, velocity_noise=1.0, delay_samples=(0, 2))
    cfg = dataclasses.replace(CFG, robustness=box)
    s = dataclasses.replace(TINY, laws=("pd",))
    wide = run_robust(cfg, s).to_json()
    monkeypatch.setattr(maps_mod, "BATCH_STATES", 1)
    narrow = run_robust(cfg, s).to_json()
    for key in ("maps", "margins", "worst"):
        assert _same(wide[key], narrow[key]), key


def test_study_parts_equal_the_parts_run_alone():
    """run_robust's interleaved simulations give what each part gives run on its own."""
    s = dataclasses.replace(TINY, laws=("pto", "pd"))
    res = run_robust(CFG, s)
    assert _same(res.maps.to_json(), robust_maps(CFG, s).to_json())
    for law in s.laws:
        alone = no_limit_cycle_margin(law, CFG, s)
        assert res.margins[law].no_limit_cycle == alone
        starts = {p: grid_worst(res.maps.laws[law], p) for p in s.properties}
        alone = worst_cases(law, CFG, starts, s)
        assert _same(
            {p: w.to_json() for p, w in res.worst[law].items()},
            {p: w.to_json() for p, w in alone.items()},
        )


@pytest.mark.parametrize("n", [4, 400])
def test_one_family_in_one_call_equals_each_law_alone(n):
    """TO, PTO and PTO-printed (one laws.LawFamily) run as one evaluation per sample."""
    rng = np.random.default_rng(n)
    steps = 200
    segments = []
    for name in ("to", "pto", "pto-printed", "pto", "to"):
        x1 = rng.uniform(-50.0, 50.0, n) * rng.uniform(0.0, 1.0, n) ** 3  # many near 0
        x2 = rng.uniform(-300.0, 300.0, n) * rng.uniform(0.0, 1.0, n)
        x1[:2], x2[:2] = (0.0, CFG.pto.d), (0.0, 0.0)  # the origin; the linear zone's edge
        segments.append((LAWS[name], x1, x2, _random_case(rng, n)))
    assert LAWS["to"].family.key == LAWS["pto"].family.key == LAWS["pto-printed"].family.key
    both = simulate_segments(segments, P, steps)
    at = 0
    for law, x1, x2, m in segments:
        alone = simulate_batch(law, P, x1, x2, steps, mismatch=m)
        cols = slice(at, at + n)
        at += n
        for f in ("x1", "x2", "u", "region"):
            assert np.array_equal(getattr(both, f)[:, cols], getattr(alone, f)), (law.name, f)
    zone = (both.region == Region.ZONE_P) | (both.region == Region.ZONE_N)
    assert n < 100 or zone.any(), "the switching zone must act"


def test_long_delay_runs_and_mixed_delays_in_one_run():
    """States of one delay in long runs beside per-state delays, in one run."""
    long_run = 515  # states of one delay in a row
    rng = np.random.default_rng(9)
    steps = 60
    segments = []
    for delay in (2, None, 0, 1, None):
        n = long_run if delay is not None else 7
        m = _random_case(rng, n)
        if delay is not None:
            m = Mismatch(m.a_ratio, m.w_max_ratio, delay, m.position_quantum, 0.0, m.seed)
        x1 = rng.uniform(-40.0, 40.0, n)
        segments.append((LAWS["pd" if delay == 1 else "pto"], x1, -x1, m))
    _assert_segments_run_alone(segments, steps)
