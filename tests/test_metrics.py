"""Metrics against analytic signals with known answers."""

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.cli import main
from ptoverify.model.laws import Region, make_law
from ptoverify.model.plant import flow
from ptoverify.sim import exact
from ptoverify.sim import metrics as m
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import DEFINITIONS, SettlingDefinition, settling_time
from ptoverify.sim.simulate import SIGNALS, Reference, simulate

T = 0.002
t = np.arange(0, 1.0 + T / 2, T)


def test_settling_time_of_exponential():
    """x1 = e^{-a t} (u = 0, an exact ZOH record) enters |x1| <= b at ln(1/b) / a (closed
    form); on the samples, the first sample after it."""
    a, b = 20.0, 0.02
    tr = Trajectory.from_samples(t, np.exp(-a * t), -a * np.exp(-a * t), np.zeros(t.size - 1), a)
    closed = math.log(1 / b) / a
    st = settling_time(tr, None, SettlingDefinition("b", "test", band_mm=b))
    assert_allclose(st.time[0], closed, rtol=1e-12, err_msg="settling time, closed form")
    assert closed <= st.grid[0] < closed + T, f"grid settling {st.grid[0]} vs {closed}"
    tiny = SettlingDefinition("tiny", "test", band_mm=1e-30)
    assert math.isnan(settling_time(tr, None, tiny).time[0]), "ends outside: never settles"
    held = SettlingDefinition("held", "test", band_mm=b, hold_s=2.0)
    assert math.isnan(settling_time(tr, None, held).time[0]), "tail shorter than hold"
    rest = Trajectory.from_samples(t, 0 * t, 0 * t, np.zeros(t.size - 1), a)
    assert settling_time(rest, None, "0p01mm").time[0] == 0.0, "never outside: 0"


def test_oscillation_amplitude_and_reversals():
    e = 0.3 * np.sin(2 * np.pi * 25 * t)  # 25 whole periods
    assert_allclose(
        m.oscillation_amplitude(e),
        0.3,
        rtol=1e-3,
        err_msg="amplitude of a sampled sine (samples reach the peak within 0.3 %)",
    )
    assert m.sign_reversals(e, 0.01) == 49, "two reversals per period, 25 periods, minus one"
    assert m.sign_reversals(np.exp(-t), 0.01) == 0
    assert m.sign_reversals(1e-3 * np.sin(100 * t), 0.01) == 0, "wiggles inside the band"


def test_ramp_lag_of_first_order_tracking():
    """A first-order lag x' = (r - x)/tau of a ramp v t trails it by v tau."""
    tau, v = 0.01, 200.0
    r = np.minimum(v * t, 30.0)
    x = np.where(t < 0.15, v * (t - tau * (1 - np.exp(-t / tau))), np.nan)
    rd = np.where(v * t < 30.0, v, 0.0)
    lag = m.ramp_lag(t, np.nan_to_num(r - x), rd)
    assert_allclose(lag, v * tau, rtol=1e-3, err_msg="ramp lag = v tau after the transient")
    assert math.isnan(m.ramp_lag(t, r, np.zeros_like(t)))


@pytest.mark.parametrize("delay_deg", [0.0, 4.5, 8.1, -3.0, 170.0])
def test_phase_of_delayed_sine(delay_deg):
    """x = A sin(wt - phi) + C + harmonic: the fit returns phi exactly (orthogonal harmonics)."""
    f, amp = 5.0, 5.0
    r = amp * np.sin(2 * np.pi * f * t)
    x = (
        0.9 * amp * np.sin(2 * np.pi * f * t - math.radians(delay_deg))
        + 0.2
        + 0.1 * np.sin(2 * np.pi * 3 * f * t)
    )
    fr, fx = m.sine_fit(t, r, f, t_from=0.2), m.sine_fit(t, x, f, t_from=0.2)
    assert_allclose(m.phase_delay(fr, fx), delay_deg, atol=1e-9, err_msg="phase delay [deg]")
    assert_allclose(fx.amplitude / fr.amplitude, 0.9, rtol=1e-9, err_msg="amplitude ratio")
    assert_allclose(fx.offset, 0.2, atol=1e-9, err_msg="offset")
    assert_allclose(fx.residual_rms, 0.1 / math.sqrt(2), rtol=1e-9, err_msg="harmonic RMS")
    assert fx.periods == 4, "whole periods in [0.2, 1.0]"


def test_sine_fit_rejects_fractional_period():
    with pytest.raises(ValueError):
        m.sine_fit(t, t, 7.0)


def test_rise_time_of_exponential():
    """1 - e^{-t/tau}: 10-90 % rise time is tau ln 9 (within one sample)."""
    tau = 0.05
    rt = m.rise_time(t, 1 - np.exp(-t / tau), 1.0)
    assert abs(rt - tau * math.log(9)) <= T, f"rise time {rt}"


def test_linear_zone_and_switches():
    reg = np.array([Region.BANG_N, Region.ZONE_P, Region.ZONE_P, Region.LINEAR, Region.LINEAR])
    assert m.time_to_linear_zone(np.arange(5) * T, reg) == pytest.approx(3 * T)
    assert math.isnan(m.time_to_linear_zone(np.arange(2) * T, reg[:2]))
    u = np.array([-300, -300, 300, 300, -300, 0, 0, 300, 12.0])
    assert m.input_switches(u) == 3


def test_summarize_on_simulations(paper_cfg):
    """Summaries are finite where they should be, and PD settles while TO oscillates."""
    pd = m.summarize(simulate(make_law("pd", paper_cfg), paper_cfg.plant, "step"), paper_cfg.plant)
    to = m.summarize(simulate(make_law("to", paper_cfg), paper_cfg.plant, "step"), paper_cfg.plant)
    assert math.isfinite(pd["settling_2pct_s"]) and math.isfinite(pd["rise_time_s"])
    assert to["steady_amplitude_mm"] > m.TIGHT_BAND > pd["steady_amplitude_mm"]
    sine = m.summarize(
        simulate(make_law("pd", paper_cfg), paper_cfg.plant, "sine"), paper_cfg.plant
    )
    assert 0 < sine["phase_delay_deg"] < 45 and 0.5 < sine["amplitude_ratio"] < 2


def _closed_loop_pd(cfg):
    """Sampled PD loop x+ = Acl x + Bd v, ZOH by scipy's cont2discrete (independent of plant.py)."""
    from scipy.signal import cont2discrete

    a, T = cfg.plant.a, cfg.plant.sample_time
    Ad, Bd, *_ = cont2discrete(
        (np.array([[0.0, 1.0], [0.0, -a]]), np.array([[0.0], [a]]), np.eye(2), np.zeros((2, 1))),
        T,
        method="zoh",
    )
    K = np.array([[cfg.pd.kp, cfg.pd.kd]])
    return Ad - Bd @ K, Bd


def test_pd_ramp_lag_without_feedforward(paper_cfg):
    """Steady ramp, no feed-forward: u = kp e - kd x2 = v, x2 = v  =>  e = (1 + kd) v / kp.

    The sampled loop reaches this exactly (x_ss(k) = (v k T - e_ss, v) solves the ZOH
    recursion while the ramp moves), and the start-up transient is exact too: z_k = x_k -
    x_ss(k) = Acl^k z_0, so e_k = e_ss - (Acl^k z_0)_1 (linear loop, scipy's ZOH).  The
    metric must equal the mean of that over its window to round-off; and the closed form
    e_ss must hold within the largest transient left in the window, a tolerance derived
    from the loop (~1e-8 mm here), not a 2 % guess.  Valid while the PD does not saturate,
    which is asserted.
    """
    res = simulate(make_law("pd", paper_cfg), paper_cfg.plant, "ramp", tracking="none")
    assert np.max(np.abs(res.u)) < paper_cfg.plant.w_max, "linear range"
    kp, kd, v = paper_cfg.pd.kp, paper_cfg.pd.kd, res.reference.speed
    e_ss = (1 + kd) * v / kp
    Acl, _ = _closed_loop_pd(paper_cfg)
    moving = np.flatnonzero(res.r_dot > 0)
    k0 = moving[0] + int(np.ceil(0.5 * (moving[-1] - moving[0])))  # ramp_lag's default skip
    window = range(k0, moving[-1] + 1)
    z0 = np.array([e_ss, -v])  # x(0) = 0 minus x_ss(0) = (-e_ss, v)
    transient = np.array([(np.linalg.matrix_power(Acl, k) @ z0)[0] for k in window])
    lag = m.summarize(res, paper_cfg.plant)["ramp_lag_mm"]
    assert_allclose(lag, e_ss - transient.mean(), rtol=1e-12, atol=1e-12, err_msg="lag [mm]")
    bound = np.max(np.abs(transient))
    assert bound < 1e-6 * e_ss, "the window starts late enough for e_ss to be a sharp check"
    assert abs(lag - e_ss) <= bound + 1e-12 * e_ss, f"lag {lag} vs {e_ss} (bound {bound:.2e})"


@pytest.mark.parametrize("tracking", ["feedforward", "none", "error"])
def test_phase_delay_of_a_2hz_sine_is_the_sampled_frequency_response(paper_cfg, tracking):
    """A 3 mm, 2 Hz sine: summarize's grid phase delay is the loop's exact frequency response.

    In its linear range the sampled PD loop is x+ = Acl x + Bd (kp r + c r'), with c = 1 + kd
    (feed-forward), kd (law on the error) or 0 (no feed-forward; then the law sees x2 itself).
    For r = A sin(w k T) the steady output is Im(X1 e^{j w k T}), X1 = C (zI - Acl)^-1 Bd A
    (kp + j w c), z = e^{j w T}; after one period the transient is below round-off (asserted),
    so the fit over whole periods returns arg X1 to round-off.  A reading of the frequency
    from anywhere but the simulated reference (5 Hz, Section 6) fails this.
    """
    A, f = 3.0, 2.0
    res = simulate(
        make_law("pd", paper_cfg), paper_cfg.plant, Reference.sine(A, f), tracking=tracking
    )
    assert np.max(np.abs(res.u)) < paper_cfg.plant.w_max, "linear range"
    Acl, Bd = _closed_loop_pd(paper_cfg)
    assert np.max(np.abs(np.linalg.eigvals(Acl))) ** (1 / (f * paper_cfg.plant.T)) < 1e-30
    kp, kd, w = paper_cfg.pd.kp, paper_cfg.pd.kd, 2 * np.pi * f
    c = {"feedforward": 1 + kd, "error": kd, "none": 0.0}[tracking]
    z = np.exp(1j * w * paper_cfg.plant.T)
    X = np.linalg.solve(z * np.eye(2) - Acl, Bd[:, 0]) * A * (kp + 1j * w * c)
    expect = -math.degrees(np.angle(X[0]))
    got = m.summarize(res, paper_cfg.plant)
    assert_allclose(got["phase_delay_deg_grid"], expect, atol=1e-7, err_msg="phase delay [deg]")
    assert_allclose(got["amplitude_ratio_grid"], abs(X[0]) / A, rtol=1e-9, err_msg="gain")
    # between samples the output is the ZOH flow, not the samples' sinusoid: close, not equal
    assert abs(got["phase_delay_deg"] - expect) < 360 * f * paper_cfg.plant.T, "within a sample"


def test_summarize_of_a_sine_of_fractional_period(paper_cfg):
    """7 Hz at T = 2 ms is 71.4 samples a period: the continuous fit needs no whole number of
    samples, so the phase is measured; the sampled residual RMS (whole periods of samples) is NaN.
    """
    res = simulate(make_law("pd", paper_cfg), paper_cfg.plant, Reference.sine(1.0, 7.0))
    got = m.summarize(res, paper_cfg.plant)
    assert 0 < got["phase_delay_deg"] < 45 and math.isfinite(got["phase_delay_deg_grid"])
    assert math.isnan(got["fit_residual_rms_mm"]) and math.isnan(got["amplitude_ratio_grid"])


SECTION6 = [(law, sig) for law in ("to", "pd", "pto", "pto-printed") for sig in SIGNALS]


@pytest.mark.parametrize(("law", "sig"), SECTION6)
def test_summarize_time_metrics_between_samples(paper_cfg, law, sig):
    """Every Section 6 response: the exact overshoot is >= the samples' (the samples are points
    of the continuous trajectory), a settling time is within one sample before its grid twin
    (the last exit happens in the interval before the first settled sample), and the linear-zone
    entry is within one sample before the first sample the law reports linear.
    """
    res = simulate(make_law(law, paper_cfg), paper_cfg.plant, sig)
    d = {"to": None, "pd": math.inf}.get(law, paper_cfg.pto.d)
    s = m.summarize(res, paper_cfg.plant, d=d)
    T = paper_cfg.plant.T
    if sig != "sine":
        assert s["overshoot_mm"] >= s["overshoot_mm_grid"] >= 0.0
    for key in ("settling_0p01mm_s", "settling_2pct_s", "linear_zone_s"):
        if key in s and math.isfinite(s[key + "_grid"]):
            assert s[key + "_grid"] - T <= s[key] <= s[key + "_grid"], f"{key} {s[key]}"
    grid_zone = m.time_to_linear_zone(res.t, res.region)
    if d is not None:
        assert s["linear_zone_s_grid"] == grid_zone or (
            math.isnan(grid_zone) and math.isnan(s["linear_zone_s_grid"])
        )


def test_sample_grid_metrics_have_one_definition():
    """metrics' rise time is exact.py's grid twin; the bands are the registry's."""
    assert m.rise_time is exact.grid_rise_time
    assert (m.TIGHT_BAND, m.STEP_FRACTION) == (exact.TIGHT_BAND, exact.STEP_FRACTION)
    assert m.TIGHT_BAND == DEFINITIONS["0p01mm"].band_mm
    assert m.STEP_FRACTION == DEFINITIONS["2pct"].band_fraction


def _dense(res, a, per):
    """The exact flow at ``per`` uniform points per sample (plant.flow, not exact.py)."""
    h = np.diff(res.t)
    s = h[:, None] * (np.arange(per) / per)[None, :]
    x1, _ = flow(res.x1[:-1, None], res.x2[:-1, None], res.u[:-1, None], s, a)
    return np.append((res.t[:-1, None] + s).ravel(), res.t[-1]), np.append(x1.ravel(), res.x1[-1])


@pytest.mark.parametrize(("law", "sig"), [("pd", "step"), ("pto-printed", "ramp")])
def test_simulate_json_metrics_between_samples(capsys, paper_cfg, law, sig):
    """``simulate --json`` carries ``metrics`` (DESIGN.md keys) measured between samples, and
    ``metrics_grid`` on the samples; both against an independent dense evaluation of the flow
    (10^4 points per sample): a dense crossing brackets the true one within one dense spacing,
    and the dense maximum is below the true one by at most max|x2| times half that spacing.
    """
    assert main(["simulate", "--law", law, "--signal", sig, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["metrics"]) == {
        "overshoot_mm",
        "settling_2pct_s",
        "settling_0p01mm_s",
        "rise_time_s",
    }
    assert set(out["metrics_grid"]) == set(out["metrics"])
    res = simulate(make_law(law, paper_cfg), paper_cfg.plant, sig)
    per = 10_000
    t, x1 = _dense(res, paper_cfg.plant.a, per)
    dt = paper_cfg.plant.T / per
    target = res.reference.target
    e = res.reference.r(t) - x1
    got, grid = out["metrics"], out["metrics_grid"]
    ov = max(0.0, float(np.max(x1 - target)))
    assert ov <= got["overshoot_mm"] <= ov + np.max(np.abs(res.x2)) * dt, "overshoot"
    assert got["overshoot_mm"] > grid["overshoot_mm"] + 1e-6, "the peak is between samples"
    for key, band in (("settling_2pct_s", 0.02 * abs(target)), ("settling_0p01mm_s", 0.01)):
        out_idx = np.flatnonzero(np.abs(e) > band)
        dense_ts = t[out_idx[-1] + 1] if out_idx.size else 0.0  # never outside: 0
        assert dense_ts - dt <= got[key] <= dense_ts, key
        out_k = np.flatnonzero(np.abs(res.e) > band)  # the first sample after the last out
        assert grid[key] == (res.t[out_k[-1] + 1] if out_k.size else 0.0), key
    lo, hi = (np.argmax(x1 >= f * target) for f in (0.1, 0.9))
    assert abs(got["rise_time_s"] - (t[hi] - t[lo])) <= dt, "rise time"
    assert grid["rise_time_s"] == m.rise_time(res.t, res.x1, target)
