"""Metrics against analytic signals with known answers."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify import metrics as m
from ptoverify.laws import Region, make_law
from ptoverify.simulate import simulate

T = 0.002
t = np.arange(0, 1.0 + T / 2, T)


def test_settling_time_of_exponential():
    """e = e^{-t/tau} enters |e| <= b at tau ln(1/b); on samples, the first sample after it."""
    tau, b = 0.05, 0.02
    exact = tau * math.log(1 / b)
    ts = m.settling_time(t, np.exp(-t / tau), b)
    assert exact <= ts < exact + T, f"settling {ts} vs {exact}"
    assert math.isnan(m.settling_time(t, np.sin(40 * t), 0.5)), "never settles"
    assert math.isnan(m.settling_time(t, np.exp(-t / tau), b, hold=2.0)), "tail shorter than hold"
    assert m.settling_time(t, np.zeros_like(t), b) == 0.0


def test_overshoot_of_second_order_step():
    """Underdamped step: overshoot = exp(-pi zeta / sqrt(1 - zeta^2)) of the step (closed form)."""
    zeta, wn, step = 0.3, 60.0, 5.0
    tt = np.linspace(0, 1, 200001)  # fine grid: peak found to ~1e-8 relative
    wd = wn * math.sqrt(1 - zeta**2)
    x = step * (
        1
        - np.exp(-zeta * wn * tt)
        * (np.cos(wd * tt) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * tt))
    )
    expect = step * math.exp(-math.pi * zeta / math.sqrt(1 - zeta**2))
    assert_allclose(m.overshoot(x, step), expect, rtol=1e-6, err_msg="overshoot")
    assert m.overshoot(-x, -step) == pytest.approx(expect, rel=1e-6), "downward step"
    assert m.overshoot(step * (1 - np.exp(-tt)), step) == 0.0, "monotone: no overshoot"


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
    pd = m.summarize(simulate(make_law("pd", paper_cfg), paper_cfg.plant, "step"))
    to = m.summarize(simulate(make_law("to", paper_cfg), paper_cfg.plant, "step"))
    assert math.isfinite(pd["settling_2pct_s"]) and math.isfinite(pd["rise_time_s"])
    assert to["steady_amplitude_mm"] > m.TIGHT_BAND > pd["steady_amplitude_mm"]
    sine = m.summarize(simulate(make_law("pd", paper_cfg), paper_cfg.plant, "sine"))
    assert 0 < sine["phase_delay_deg"] < 45 and 0.5 < sine["amplitude_ratio"] < 2
    ramp = m.summarize(
        simulate(make_law("pd", paper_cfg), paper_cfg.plant, "ramp", feedforward=False)
    )
    kp, kd, v = paper_cfg.pd.kp, paper_cfg.pd.kd, 200.0
    # steady ramp without feed-forward: kp e = (1 + kd) v  =>  e = (1 + kd) v / kp
    assert_allclose(
        ramp["ramp_lag_mm"],
        (1 + kd) * v / kp,
        rtol=0.02,
        err_msg="PD ramp lag vs its steady-state value (2 %: transient tail)",
    )
