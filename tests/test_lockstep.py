"""Batched simulation of the robustness study against the simple per-case simulation.

``simulate_segments`` (several laws and mismatches in one run) and
``run_lockstep`` (jobs gathered into rounds) must give each case exactly what
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
from ptoverify.sim.lockstep import Ask, run_lockstep
from ptoverify.sim.simulate import Mismatch, simulate_batch, simulate_segments
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


def _assert_segments_run_alone(segments, steps):
    """simulate_segments gives each segment exactly its own simulate_batch run."""
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


def test_lockstep_results_do_not_depend_on_rounds():
    """The same jobs in rounds of 1 state or all at once give the same trajectories."""
    rng = np.random.default_rng(7)
    steps = 80

    def job(law, x1, x2, m, rider):
        (b,) = yield [Ask(law, x1, x2, m, rider=rider)]
        (again,) = yield [Ask(law, b.x1[-1].copy(), b.x2[-1].copy(), m, rider=rider)]
        return np.concatenate([b.x1, again.x1[1:]])

    def jobs():
        out = []
        for i, name in enumerate(["pd", "pto", "to", "pto"]):
            x1, x2 = rng.uniform(-30.0, 30.0, 3), rng.uniform(-200.0, 200.0, 3)
            out.append((LAWS[name], x1, x2, _random_case(rng, 3), i % 2 == 1))
        return out

    cases = jobs()
    wide = run_lockstep([job(*c) for c in cases], P, steps)
    narrow = run_lockstep([job(*c) for c in cases], P, steps, round_states=1)
    assert wide.rounds < narrow.rounds
    for (law, x1, x2, m, _), a, b in zip(cases, wide.results, narrow.results, strict=True):
        assert np.array_equal(a, b)
        alone = simulate_batch(law, P, x1, x2, steps, mismatch=m)
        assert np.array_equal(a[: steps + 1], alone.x1)


@pytest.mark.parametrize("round_states", [1, 5, 10_000])
def test_lockstep_reusing_memory_gives_the_same_trajectories(round_states):
    """reuse=True (one memory for every round's trajectories) sends each job what fresh
    arrays give, also for asks of one yield simulated in different rounds (round_states
    1: the earlier ones are kept as copies while the job waits for the rest)."""
    rng = np.random.default_rng(11)
    steps = 60

    def job(law, x1, x2, m):
        kept = []
        for _ in range(3):  # three yields of two asks each; a copy of what it keeps
            a, b = yield [Ask(law, x1, x2, m), Ask(law, -x1, x2[::-1].copy(), m)]
            kept.append(np.concatenate([a.x1, a.x2, a.u, a.region, b.x1, b.region], axis=None))
            x1, x2 = a.x1[-1].copy(), b.x2[-1].copy()
        return np.concatenate(kept)

    cases = []
    for name in ("pd", "pto", "to", "pto-printed"):
        x1, x2 = rng.uniform(-30.0, 30.0, 3), rng.uniform(-200.0, 200.0, 3)
        cases.append((LAWS[name], x1, x2, _random_case(rng, 3)))
    fresh = run_lockstep([job(*c) for c in cases], P, steps, round_states=round_states)
    reused = run_lockstep([job(*c) for c in cases], P, steps, round_states=round_states, reuse=True)
    assert fresh.rounds == reused.rounds
    for a, b in zip(fresh.results, reused.results, strict=True):
        assert np.array_equal(a, b)


TINY = RobustSettings(n1=5, n2=4, rest=4, n_a=3, n_w=2, search_iterations=2, search_population=6)


def _same(a, b) -> bool:
    """Equal, NaN included (as JSON text)."""
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_study_does_not_depend_on_round_size(monkeypatch):
    """Maps, margins and worst cases with rounds of one ask each equal the default rounds."""
    import ptoverify.studies.robust as robust_mod

    box = dataclasses.replace(CFG.robustness, velocity_noise=1.0, delay_samples=(0, 2))
    cfg = dataclasses.replace(CFG, robustness=box)
    s = dataclasses.replace(TINY, laws=("pd",))
    wide = run_robust(cfg, s).to_json()
    monkeypatch.setattr(robust_mod, "BATCH_STATES", 1)
    narrow = run_robust(cfg, s).to_json()
    for key in ("maps", "margins", "worst"):
        assert _same(wide[key], narrow[key]), key


def test_study_parts_equal_the_parts_run_alone():
    """run_robust's interleaved simulations give what each part gives run on its own."""
    s = dataclasses.replace(TINY, laws=("pto", "pd"))
    res = run_robust(CFG, s)
    assert _same(res.maps, robust_maps(CFG, s))
    for law in s.laws:
        alone = no_limit_cycle_margin(law, CFG, s)
        assert _same({k: res.margins[law][k] for k in alone}, alone)
        starts = {p: grid_worst(res.maps["laws"][law], p) for p in s.properties}
        assert _same(res.worst[law], worst_cases(law, CFG, starts, s))


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
