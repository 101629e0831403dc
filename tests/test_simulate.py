import dataclasses
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law
from ptoverify.model.plant import step as plant_step
from ptoverify.model.plant import zoh_matrices
from ptoverify.sim.simulate import (
    SIGNALS,
    TRACKING,
    Reference,
    reference,
    simulate,
    simulate_batch,
)


def test_simulate_matches_zoh_matrices(paper_cfg):
    """The loop reproduces x[k+1] = Ad x[k] + Bd u[k] with the logged inputs."""
    p = paper_cfg.plant
    for sig in SIGNALS:
        res = simulate(make_law("pd", paper_cfg), p, sig)
        Ad, Bd = zoh_matrices(p.a, p.T)
        X = np.c_[res.x1, res.x2]
        pred = X[:-1] @ Ad.T + res.u[:-1, None] * Bd[:, 0]
        assert_allclose(X[1:], pred, rtol=1e-12, atol=1e-10, err_msg=f"{sig}: ZOH recursion")
        assert np.all(np.abs(res.u) <= p.w_max)
        assert_allclose(res.e, res.r - res.x1, rtol=0, atol=0, err_msg="error definition")


def test_references():
    t = np.array([0.0, 0.1, 0.2])
    assert_allclose(SIGNALS["step"].r(t), 5.0, err_msg="step")
    assert_allclose(SIGNALS["ramp"].r(t), [0.0, 20.0, 30.0], err_msg="ramp saturates at 30 mm")
    assert_allclose(SIGNALS["sine"].r(np.array([0.05])), [5.0], err_msg="sine peak at T/4")


def test_batch_matches_single(paper_cfg):
    law = make_law("to", paper_cfg)
    p = paper_cfg.plant
    x1 = np.array([5.0, -3.0, 20.0])
    x2 = np.array([0.0, 100.0, -50.0])
    b = simulate_batch(law, p, x1, x2, 60)
    for j in range(3):
        y1, y2 = x1[j], x2[j]
        for k in range(60):
            u, _ = law.scalar(y1, y2)
            assert u == b.u[k, j]
            Ad, Bd = zoh_matrices(p.a, p.T)
            y1, y2 = Ad @ [y1, y2] + Bd[:, 0] * u
        assert_allclose(
            [y1, y2],
            [b.x1[-1, j], b.x2[-1, j]],
            rtol=1e-9,
            atol=1e-9,
            err_msg="batch vs one-by-one",
        )


def test_pd_step_settles_and_to_keeps_oscillating(paper_cfg):
    p = paper_cfg.plant
    pd = simulate(make_law("pd", paper_cfg), p, "step")
    to = simulate(make_law("to", paper_cfg), p, "step")
    assert abs(pd.e[-1]) < 1e-6
    tail = to.e[-50:]
    assert np.ptp(tail) > 1e-3 and np.sum(np.diff(np.sign(tail)) != 0) > 5


# ------------------------------------------------------------------ references and tracking
def _hand_loop(law, plant, r, r_dot, tracking):
    """The closed loop assembled by hand from plant.step, one sample at a time."""
    w = plant.w_max
    x1, x2 = 0.0, 0.0
    X1, U = [], []
    for k in range(r.size):
        e2 = x2 if tracking == "none" else x2 - r_dot[k]
        v, _ = law.scalar(x1 - r[k], e2)
        u = min(max(v + (r_dot[k] if tracking == "feedforward" else 0.0), -w), w)
        X1.append(x1)
        U.append(u)
        x1, x2 = (float(z) for z in plant_step(x1, x2, u, plant))
    return np.array(X1), np.array(U)


def _by_hand_reference(name, t):
    """Section 6 references written out here (not through Reference)."""
    if name == "ramp":
        return np.minimum(200.0 * t, 30.0), np.where(200.0 * t < 30.0, 200.0, 0.0)
    w = 2 * np.pi * 5.0
    return 5.0 * np.sin(w * t), 5.0 * w * np.cos(w * t)


@pytest.mark.parametrize("tracking", TRACKING)
@pytest.mark.parametrize("signal", ["ramp", "sine"])
@pytest.mark.parametrize("name", ["pd", "pto", "to"])
def test_tracking_modes_match_a_hand_assembled_loop(paper_cfg, name, signal, tracking):
    """Each tracking mode is the loop of the module docstring, built from plant.step."""
    law, p = make_law(name, paper_cfg), paper_cfg.plant
    res = simulate(law, p, signal, tracking=tracking, duration=0.1)
    r, r_dot = _by_hand_reference(signal, res.t)
    x1, u = _hand_loop(law, p, r, r_dot, tracking)
    # same flow formula in the same order: equal to round-off (TO/PTO switch on signs, so a
    # round-off difference could flip an input; none does over these 50 samples)
    assert_allclose(res.x1, x1, rtol=1e-12, atol=1e-12, err_msg=f"{name} {signal} {tracking}: x1")
    assert_allclose(res.u, u, rtol=1e-12, atol=1e-12, err_msg=f"{name} {signal} {tracking}: u")
    assert res.tracking == tracking
    assert res.reference == dataclasses.replace(SIGNALS[signal], duration=0.1), "reference carried"


def test_tracking_modes_differ_on_a_ramp_and_coincide_on_a_step(paper_cfg):
    """r' = 0 makes the three modes one loop; a ramp tells them apart (else the test is void)."""
    law, p = make_law("pd", paper_cfg), paper_cfg.plant
    step = [simulate(law, p, "step", tracking=m) for m in TRACKING]
    ramp = [simulate(law, p, "ramp", tracking=m) for m in TRACKING]
    assert all((s.x1 == step[0].x1).all() for s in step), "step: modes coincide"
    for i in range(3):
        for j in range(i):
            assert np.max(np.abs(ramp[i].x1 - ramp[j].x1)) > 0.1, (TRACKING[i], TRACKING[j])
    assert (simulate(law, p, "ramp", feedforward=False).x1 == ramp[1].x1).all(), "alias"
    with pytest.raises(TypeError):
        simulate(law, p, "ramp", feedforward=True, tracking="none")
    with pytest.raises(InputError):
        simulate(law, p, "ramp", tracking="feed forward")


def test_custom_references_closed_form():
    t = np.array([0.0, 0.05, 0.1, 0.3])
    s = Reference.step(-2.5)
    assert_allclose(s.r(t), -2.5, err_msg="step height")
    assert_allclose(s.r_dot(t), 0.0, err_msg="step velocity")
    ramp = Reference.ramp(speed=50.0, target=-4.0)
    assert_allclose(ramp.r(t), [0.0, -2.5, -4.0, -4.0], err_msg="ramp down to -4 mm at 50 mm/s")
    assert_allclose(ramp.r_dot(t), [-50.0, -50.0, 0.0, 0.0], err_msg="ramp velocity")
    assert ramp.target == -4.0 and ramp.duration == pytest.approx(0.08 + 0.25)
    sine = Reference.sine(amplitude=3.0, frequency=2.0)
    assert_allclose(sine.r(np.array([0.125])), [3.0], err_msg="2 Hz sine peaks at T/4")
    assert_allclose(sine.r_dot(np.array([0.0])), [3.0 * 4 * np.pi], err_msg="sine slope at 0")
    assert sine.target is None and sine.duration == 2.5, "default: five periods"
    json = sine.to_json()
    assert (json["signal"], json["amplitude_mm"], json["frequency_hz"]) == ("sine", 3.0, 2.0)
    tt = np.linspace(0.01, 0.5, 50)
    for ref in (ramp, sine):  # r_dot is the derivative of r (central differences, h = 1e-6 s)
        fd = (ref.r(tt + 1e-6) - ref.r(tt - 1e-6)) / 2e-6
        keep = np.abs(tt - 0.08) > 1e-5  # the ramp's corner
        assert_allclose(ref.r_dot(tt)[keep], fd[keep], rtol=1e-6, atol=1e-4, err_msg=ref.name)


@pytest.mark.parametrize(
    "make",
    [
        lambda: Reference.step(0.0),
        lambda: Reference.step(float("nan")),
        lambda: Reference.ramp(speed=0.0, target=5.0),
        lambda: Reference.ramp(speed=-1.0, target=5.0),
        lambda: Reference.ramp(speed=100.0, target=0.0),
        lambda: Reference.sine(amplitude=1.0, frequency=0.0),
        lambda: Reference.sine(amplitude=1.0, frequency=float("inf")),
        lambda: Reference.sine(amplitude=1.0, frequency=2.0, duration=-1.0),
        lambda: Reference("square", 1.0),
        lambda: Reference("step", 1.0, frequency=2.0),
    ],
)
def test_bad_references_are_input_errors(make):
    with pytest.raises(InputError):
        make()


def test_result_carries_its_reference(paper_cfg):
    ref = Reference.sine(amplitude=3.0, frequency=2.0)
    res = simulate(make_law("pd", paper_cfg), paper_cfg.plant, ref, duration=1.0, tracking="error")
    assert res.reference.frequency == 2.0 and res.reference.amplitude == 3.0
    assert res.reference.duration == 1.0 and res.t[-1] == pytest.approx(1.0), "time simulated"
    assert (res.signal, res.tracking, res.feedforward) == ("sine", "error", False)
    assert_allclose(res.r, ref.r(res.t), rtol=0, atol=0, err_msg="r from the reference carried")


def test_reference_overrides_section6_values():
    assert reference("step") is SIGNALS["step"], "no override: the Section 6 reference"
    assert reference("ramp", ramp_to=-12.0) == Reference.ramp(200.0, -12.0), "speed kept"
    assert reference("sine", amplitude=3.0) == Reference.sine(3.0, 5.0), "frequency kept"
    with pytest.raises(InputError, match="--frequency does not apply to the step"):
        reference("step", frequency=2.0)
    with pytest.raises(InputError):
        reference("square")


def test_cli_simulate_custom_sine(capsys):
    """--amplitude/--frequency reach the simulation: r is 3 sin(2 pi 2 t) over five periods."""
    argv = ["simulate", "--law", "pd", "--signal", "sine", "--amplitude", "3", "--frequency", "2"]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    t, r = np.array(out["series"]["t"]), np.array(out["series"]["r"])
    assert_allclose(t[-1], 2.5, rtol=1e-12, err_msg="default duration: five periods [s]")
    assert_allclose(r, 3.0 * np.sin(4 * np.pi * t), rtol=0, atol=1e-12, err_msg="r [mm]")
    assert sorted(out) == sorted(
        [
            "law",
            "signal",
            "feedforward",
            "note",
            "samples",
            "final_error_mm",
            "max_abs_error_second_half_mm",
            "metrics",
            "metrics_grid",
            "series",
        ]
    ), "JSON keys: the earlier ones plus metrics (DESIGN.md) and metrics_grid"
    assert set(out["metrics"]) == {
        "overshoot_mm",
        "settling_2pct_s",
        "settling_0p01mm_s",
        "rise_time_s",
        "phase_delay_deg",
    }
    assert main(["simulate", "--signal", "ramp", "--step", "3"]) == 2
    assert "does not apply" in capsys.readouterr().err


def _expm_zoh(a, T):
    """Ad, Bd of the ZOH plant from the matrix exponential of the augmented system."""
    from scipy.linalg import expm

    M = np.zeros((3, 3))
    M[0, 1], M[1, 1], M[1, 2] = 1.0, -a, a
    E = expm(M * T)
    return E[:2, :2], E[:2, 2]


@pytest.mark.parametrize("law_name", ["to", "pd", "pto"])
@pytest.mark.parametrize(("quantum", "noise"), [(0.0, 0.0), (1e-3, 0.0), (0.0, 2.0), (5e-3, 1.0)])
def test_one_simulator_against_expm_with_every_mismatch(paper_cfg, law_name, quantum, noise):
    """Each sample of a mismatched batch, checked on its own: the command is the law of the
    measured state (quantizer, seeded noise), the drive applies the command of sample
    k - delay clipped to the true limit, and the state moves by the true plant's ZOH
    matrices from scipy.linalg.expm (an independent reference for eq. 7)."""
    from ptoverify.sim.simulate import Mismatch

    p = paper_cfg.plant
    law = make_law(law_name, paper_cfg)
    rng = np.random.default_rng(11)
    n, steps = 400, 50
    x1, x2 = rng.uniform(-50.0, 50.0, n), rng.uniform(-300.0, 300.0, n)
    m = Mismatch(
        a_ratio=rng.uniform(0.5, 2.0, n),
        w_max_ratio=rng.uniform(0.5, 1.0, n),
        delay_samples=rng.integers(0, 4, n),
        position_quantum=quantum,
        velocity_noise=noise,
        seed=3,
    )
    b = simulate_batch(law, p, x1, x2, steps, mismatch=m)
    seq = np.random.default_rng(3).normal(0.0, noise, steps + 1) if noise else np.zeros(steps + 1)
    cols = np.arange(n)
    picked = range(0, n, 37)  # a spread of states, each with its own true a
    zoh = {j: _expm_zoh(p.a * m.a_ratio[j], p.T) for j in picked}
    for k in range(steps):
        y1 = quantum * np.round(b.x1[k] / quantum) if quantum else b.x1[k]
        u, region = law.vector(y1, b.x2[k] + seq[k])
        assert np.array_equal(b.u[k], u) and np.array_equal(b.region[k], region), k
        w = p.w_max * m.w_max_ratio
        applied = np.clip(b.u[np.maximum(k - m.delay_samples, 0), cols], -w, w)
        for j in picked:
            Ad, Bd = zoh[j]
            want = Ad @ [b.x1[k, j], b.x2[k, j]] + Bd * applied[j]
            got = [b.x1[k + 1, j], b.x2[k + 1, j]]
            assert_allclose(got, want, rtol=1e-11, atol=1e-9, err_msg=f"flow, k={k} j={j}")


def test_single_trajectory_is_the_batch_on_one_state(paper_cfg):
    """simulate() of a step is simulate_batch() of the law shifted by the step, bit for bit."""
    from ptoverify.model.laws import Law

    p = paper_cfg.plant
    for name in ("pd", "pto"):
        law = make_law(name, paper_cfg)
        res = simulate(law, p, "step")
        r = res.reference.amplitude
        shifted = Law(name, lambda x1, x2, law=law: law.vector(x1 - r, x2), law.scalar, law.w_max)
        b = simulate_batch(shifted, p, [0.0], [0.0], res.t.size - 1)
        assert np.array_equal(res.x1, b.x1[:, 0]) and np.array_equal(res.x2, b.x2[:, 0]), name
        assert np.array_equal(res.u[:-1], b.u[:, 0]), name


@pytest.mark.parametrize("tracking", ["feedforward", "none", "error"])
def test_loops_side_by_side_are_each_loop_alone(paper_cfg, tracking):
    """simulate_loops() with one gain set per loop gives, per loop, every array simulate()
    gives for the law built from that gain set alone, bit for bit (all laws with gains,
    each Section 6 reference; PTO gain sets at several d, so zones differ per loop)."""
    from ptoverify.model.laws import with_state_gains
    from ptoverify.sim.simulate import simulate_loops
    from ptoverify.studies.tune import tuned_config

    rng = np.random.default_rng(3)
    sets = {
        "pd": [{"kp": float(10 ** rng.uniform(1, 3.4)), "kd": float(rng.uniform(0, 4))}],
        "pto": [
            {"d": d, "k1": float(10 ** rng.uniform(1, 3.4)), "k2": float(rng.uniform(0, 5))}
            for d in (0.3, 0.5, 2.0)
        ],
        "ptos": [{"alpha": float(rng.uniform(0.05, 1)), "k": float(10 ** rng.uniform(1, 3))}],
        "cascade-p": [{"kp": float(10 ** rng.uniform(0, 3))}],
    }
    for law, gs in sets.items():
        gs = gs * 2 if len(gs) == 1 else gs  # at least two loops
        gs = [
            dict(g, **{k: v * (1 + 0.1 * i) for k, v in g.items() if k != "d"})
            for i, g in enumerate(gs)
        ]
        per_state = {k: np.array([g[k] for g in gs]) for k in gs[0]}
        for signal in ("step", "ramp", "sine"):
            runs = simulate_loops(
                with_state_gains(law, paper_cfg, per_state),
                paper_cfg.plant,
                len(gs),
                signal,
                tracking=tracking,
            )
            for g, got in zip(gs, runs, strict=True):
                one = make_law(law, tuned_config(paper_cfg, law, g))
                want = simulate(one, paper_cfg.plant, signal, tracking=tracking)
                for k, v in want.columns().items():
                    assert np.array_equal(v, got.columns()[k]), (law, signal, g, k)
                assert (got.reference, got.tracking) == (want.reference, want.tracking)


def test_segments_merged_per_law_equal_each_segment_alone():
    """simulate_parts runs segments of one law as one batch: bit for bit each alone."""
    from ptoverify.config import paper_config
    from ptoverify.model.laws import make_law
    from ptoverify.sim.simulate import Mismatch, simulate_batch, simulate_parts

    cfg = paper_config()
    rng = np.random.default_rng(7)
    laws = {name: make_law(name, cfg) for name in ("pd", "pto", "to")}
    segments = []
    for k in range(12):
        law = laws[("pd", "pto", "to")[k % 3]]
        n = int(rng.integers(1, 6))
        x1 = rng.uniform(-50, 50, n)
        x2 = rng.uniform(-300, 300, n)
        m = Mismatch(
            a_ratio=float(rng.uniform(0.8, 1.25)),
            w_max_ratio=float(rng.uniform(0.9, 1.0)),
            delay_samples=int(rng.integers(0, 3)),
            position_quantum=(0.0, 0.001)[k % 2],
            velocity_noise=0.5 if k == 5 else 0.0,
            seed=k,
        )
        segments.append((law, x1, x2, None if k == 0 else m))
    parts = simulate_parts(segments, cfg.plant, 150)
    assert len(parts) == len(segments)
    for (law, x1, x2, m), part in zip(segments, parts, strict=True):
        one = simulate_batch(law, cfg.plant, x1, x2, 150, mismatch=m)
        for f in ("x1", "x2", "u", "region"):
            np.testing.assert_array_equal(getattr(part, f), getattr(one, f), err_msg=f"segment {f}")


FINE_SAMPLED = """name = "fine"
[plant]
a = 100000.0
w_max = 300.0
sample_time = 1e-7
position_range = 0.06
[pd]
kp = 356.0
kd = 1.15
[pto]
d = 0.005
k1 = 323.0
k2 = 3.6
"""


@pytest.mark.parametrize(
    "extra",
    [
        [],  # the step's default 0.2 s: 2e6 samples
        ["--duration", "100", "--step", "0.01"],
        ["--x0", "0.01", "0", "--duration", "100"],
    ],
)
def test_simulation_longer_than_the_sample_limit_is_bad_input(tmp_path, capsys, extra):
    """A configuration the loader accepts (T = 1e-7 s) never makes simulate run unbounded."""
    from ptoverify.sim.runs import MAX_SAMPLES

    path = tmp_path / "fine.toml"
    path.write_text(FINE_SAMPLED)
    assert main(["simulate", "--config", str(path), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "samples" in err and f"{MAX_SAMPLES:,}" in err


def test_simulation_of_a_fine_sampled_plant_within_the_limit_runs(tmp_path, capsys):
    """The plant of the test above for 1e-3 s (1e4 samples): within the limit it runs
    (once, not once per rejected case)."""
    path = tmp_path / "fine.toml"
    path.write_text(FINE_SAMPLED)
    assert main(["simulate", "--config", str(path), "--step", "0.01", "--duration", "1e-3"]) == 0
