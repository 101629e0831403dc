"""Metrics between samples against independent dense evaluations of the exact flow.

The reference trajectory is ``plant.flow`` evaluated on a uniform grid of
``PER`` points per sample (independent of ``exact``'s root finding), and, for
the overshoot, scipy's DOP853 with an event at x2 = 0.  A crossing found on the
dense grid brackets the true one within one dense spacing, so crossing times
must agree within that spacing.
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp
from scipy.optimize import curve_fit

from ptoverify import exact
from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.laws import make_law
from ptoverify.plant import flow
from ptoverify.simulate import Reference, reference, simulate

CFG = paper_config()
PLANT = CFG.plant
PER = 10_000  # dense points per sample


def dense(res, per=PER):
    """Exact flow at ``per`` uniform points per sample, plus the last sample."""
    h = np.diff(res.t)
    s = h[:, None] * (np.arange(per) / per)[None, :]
    x1, x2 = flow(res.x1[:-1, None], res.x2[:-1, None], res.u[:-1, None], s, PLANT.a)
    t = res.t[:-1, None] + s
    return (
        np.append(t.ravel(), res.t[-1]),
        np.append(x1.ravel(), res.x1[-1]),
        np.append(x2.ravel(), res.x2[-1]),
    )


def dense_settling(t, e, band):
    out = np.flatnonzero(np.abs(e) > band)
    if out.size == 0:
        return 0.0
    return math.nan if out[-1] == t.size - 1 else t[out[-1] + 1] - t[0]


def dense_first(t, mask):
    k = np.flatnonzero(mask)
    return t[k[0]] - t[0] if k.size else math.nan


def close_or_both_nan(x, y, atol, what):
    if math.isnan(x) or math.isnan(y):
        assert math.isnan(x) and math.isnan(y), f"{what}: exact {x} vs dense {y}"
    else:
        assert_allclose(x, y, rtol=0, atol=atol, err_msg=what)


RESPONSES = {}


def response(law, sig):
    """Simulated responses, cached per (law, signal)."""
    key = (law, sig if isinstance(sig, str) else repr(sig))
    if key not in RESPONSES:
        RESPONSES[key] = simulate(make_law(law, CFG), PLANT, sig)
    return RESPONSES[key]


# a ramp whose end (30 / 170 s) falls inside a sample interval
RAMP_OFF_GRID = Reference.ramp(speed=170.0, target=30.0, duration=0.4)
CASES = [
    ("pd", "step"),
    ("to", "step"),
    ("pto", "step"),
    ("pto-printed", "step"),
    ("pd", "ramp"),
    ("pto", "ramp"),
    ("pto", RAMP_OFF_GRID),
]


@pytest.mark.parametrize(
    ("law", "sig"), CASES, ids=["pd-step", "to-step", "pto-step", "pto-printed-step",
                                "pd-ramp", "pto-ramp", "pto-ramp-off-grid"]
)  # fmt: skip
def test_step_ramp_metrics_match_dense_flow(law, sig):
    res = response(law, sig)
    ref = reference(sig) if isinstance(sig, str) else sig
    m = exact.exact_metrics(res, PLANT, ref, d=CFG.pto.d)
    t, x1, _ = dense(res)
    dt = PLANT.sample_time / PER
    e = ref.r(t) - x1
    target = float(ref.r(np.array([res.t[-1]]))[0])
    # overshoot: the dense maximum is below the exact one by at most x1'' dt^2 / 8
    ov = max(0.0, float(np.max(x1 - target)))
    curv = PLANT.a * 2 * PLANT.w_max  # bound on |x1''| = |x2'| [mm/s^2]
    ex = m.values["overshoot_mm"].exact
    assert ex >= ov - 1e-12, "exact overshoot below the dense maximum"
    assert_allclose(ex, ov, rtol=0, atol=curv * dt**2 / 8 + 1e-12, err_msg="overshoot")
    for key, band in (("settling_2pct_s", 0.02 * abs(ref.amplitude)), ("settling_0p01mm_s", 0.01)):
        close_or_both_nan(m.values[key].exact, dense_settling(t, e, band), dt * 1.001, key)
    lo, hi = 0.1 * target, 0.9 * target
    rise = dense_first(t, x1 >= hi) - dense_first(t, x1 >= lo)
    close_or_both_nan(m.values["rise_time_s"].exact, rise, 2 * dt * 1.001, "rise time")
    lz = dense_first(t, np.abs(e) <= CFG.pto.d)
    close_or_both_nan(m.values["linear_zone_s"].exact, lz, dt * 1.001, "linear zone")


@pytest.mark.parametrize("law", ["pd", "pto"])
def test_sine_metrics_match_dense_flow_and_curve_fit(law):
    res = response(law, "sine")
    ref = reference("sine")
    m = exact.exact_metrics(res, PLANT, ref, d=CFG.pto.d, v_max=50.0)
    per = 2_000  # 1e6 points over the second
    t, x1, x2 = dense(res, per)
    dt = PLANT.sample_time / per
    e = ref.r(t) - x1
    for key, band in (("settling_2pct_s", 0.02 * ref.amplitude), ("settling_0p01mm_s", 0.01)):
        close_or_both_nan(m.values[key].exact, dense_settling(t, e, band), dt * 1.001, key)
    # the zone with a velocity condition: the e'' = 0 pieces of the sine path
    inside = (np.abs(e) <= CFG.pto.d) & (np.abs(x2 - ref.r_dot(t)) <= 50.0)
    close_or_both_nan(m.values["linear_zone_s"].exact, dense_first(t, inside), dt * 1.001, "zone")
    # phase: an independent nonlinear fit of the dense output over the same whole periods
    f = ref.frequency
    n_per = math.floor((res.t[-1] - 1.0 / f) * f + 1e-9)
    sel = t >= res.t[-1] - n_per / f
    w = 2 * math.pi * f

    def model(tt, amp, ph, c):
        return amp * np.sin(w * tt + ph) + c

    (amp, ph, _), _ = curve_fit(model, t[sel], x1[sel], p0=[ref.amplitude, 0.0, 0.0])
    delay = -math.degrees(ph) if amp > 0 else 180.0 - math.degrees(ph)
    assert_allclose(m.values["phase_delay_deg"].exact, delay, atol=1e-4, err_msg="phase delay")
    assert_allclose(m.details["amplitude_ratio"], abs(amp) / ref.amplitude, rtol=1e-6)


def test_fast_sine_many_extrema_per_sample_match_dense():
    """Random ZOH data under a sine with w T up to 6 rad: several extrema of e and e'
    per sample, found on the closed-form monotone pieces, against a dense grid."""
    rng = np.random.default_rng(12)
    per = 20_000
    checked = 0
    for _ in range(40):
        n, a, T = 6, rng.uniform(5.0, 400.0), rng.uniform(1e-3, 0.02)
        f = rng.uniform(0.5, 6.0) / (2 * math.pi * T)
        sig = exact.Signal("sine", rng.uniform(0.5, 3.0), f)
        u = rng.uniform(-1.0, 1.0, n) * sig.amplitude * sig.omega * 1.5
        x1, x2 = np.empty(n + 1), np.empty(n + 1)
        x1[0], x2[0] = rng.normal(0, sig.amplitude), rng.normal(0, sig.amplitude * sig.omega)
        for k in range(n):
            x1[k + 1], x2[k + 1] = flow(x1[k], x2[k], u[k], T, a)
        t = T * np.arange(n + 1)
        tr = exact.Trajectory.from_samples(t, x1, x2, u, a)
        s = T * np.arange(per) / per
        td = (t[:-1, None] + s).ravel()
        y1, y2 = flow(x1[:-1, None], x2[:-1, None], u[:, None], s, a)
        e = sig.r(td) - y1.ravel()
        e2 = y2.ravel() - sig.r_dot(td)
        e_end = abs(sig.r(t[-1]) - x1[-1])
        band = max(float(np.quantile(np.abs(e), 0.3)), 1.05 * e_end)  # settles, with exits
        vmax = float(np.quantile(np.abs(e2), 0.5))
        td, e = np.append(td, t[-1]), np.append(e, sig.r(t[-1]) - x1[-1])
        e2 = np.append(e2, x2[-1] - sig.r_dot(t[-1]))
        dt = T / per
        ex = exact.settling_time(tr, sig, band)
        close_or_both_nan(ex, dense_settling(td, e, band), dt * 1.001, "settling, fast sine")
        inside = (np.abs(e) <= band) & (np.abs(e2) <= vmax)
        lz = exact.linear_zone_time(tr, sig, band, v_max=vmax)
        close_or_both_nan(lz, dense_first(td, inside), dt * 1.001, "zone, fast sine")
        checked += not math.isnan(ex)
    assert checked == 40


def test_overshoot_matches_dop853_event_peak():
    """Independent solver: DOP853 per sample with an event at x2 = 0."""
    res = response("pd", "step")
    a, best = PLANT.a, -math.inf
    for k in range(res.t.size - 1):
        u = res.u[k]

        def rhs(_t, x, u=u):
            return [x[1], -a * x[1] + a * u]

        def ev(_t, x):
            return x[1]

        sol = solve_ivp(
            rhs, (0.0, res.t[k + 1] - res.t[k]), [res.x1[k], res.x2[k]], method="DOP853",
            rtol=1e-12, atol=1e-14, events=ev,
        )  # fmt: skip
        cands = [sol.y[0, -1], *sol.y_events[0][:, 0]] if sol.y_events[0].size else [sol.y[0, -1]]
        best = max(best, *cands)
    ex, tp = exact.overshoot(exact.Trajectory.from_result(res, PLANT), 5.0)
    assert_allclose(ex, best - 5.0, rtol=0, atol=1e-9, err_msg="overshoot vs DOP853 peak")
    assert res.t[0] < tp < res.t[-1]


samples = st.lists(st.floats(-300.0, 300.0), min_size=1, max_size=25)


@settings(max_examples=80, deadline=None)
@given(
    u=samples,
    x10=st.floats(-5.0, 5.0),
    x20=st.floats(-300.0, 300.0),
    a=st.floats(5.0, 500.0),
    T=st.floats(1e-4, 0.02),
    target=st.floats(-3.0, 3.0),
    band=st.floats(1e-3, 1.0),
)
def test_exact_bounds_grid_on_random_samples(u, x10, x20, a, T, target, band):
    """Overshoot >= its grid value; grid settling <= exact + T; grid zone >= exact."""
    n = len(u)
    x1, x2 = np.empty(n + 1), np.empty(n + 1)
    x1[0], x2[0] = x10, x20
    for k in range(n):
        x1[k + 1], x2[k + 1] = flow(x1[k], x2[k], u[k], T, a)
    t = T * np.arange(n + 1)
    m = exact.metrics_from_arrays(t, x1, x2, u, a, ("step", target), d=band, band=band)
    ov = m.values["overshoot_mm"]
    assert ov.exact >= ov.grid >= 0.0
    st_ = m.values["settling_0p01mm_s"]
    if not math.isnan(st_.grid):
        assert not math.isnan(st_.exact)
        assert st_.grid <= st_.exact + T * (1 + 1e-9), "grid settles later than one sample after"
    else:
        assert math.isnan(st_.exact)
    lz = m.values["linear_zone_s"]
    if not math.isnan(lz.grid):
        assert lz.exact <= lz.grid + 1e-15, "the continuous state enters no later than a sample"


def test_closed_form_crossings():
    """A free exponential decay: every metric has a closed form."""
    t = np.linspace(0.0, 0.3, 61)
    x1, x2 = 1 - np.exp(-20 * t), 20 * np.exp(-20 * t)
    m = exact.metrics_from_arrays(t, x1, x2, np.zeros(60), 20.0, ("step", 1.0), d=0.5)
    v = m.exact()
    assert_allclose(v["settling_2pct_s"], math.log(50) / 20, rtol=1e-14, err_msg="settling 2%")
    assert_allclose(v["settling_0p01mm_s"], math.log(100) / 20, rtol=1e-14, err_msg="0.01 mm")
    assert_allclose(v["rise_time_s"], math.log(9) / 20, rtol=1e-14, err_msg="rise")
    assert_allclose(v["linear_zone_s"], math.log(2) / 20, rtol=1e-14, err_msg="zone")
    assert v["overshoot_mm"] == 0.0
    assert "settling_2pct_s" in m.differing()  # grid 0.2 s vs ln(50)/20 = 0.1956 s
    assert math.isnan(v["phase_delay_deg"])


def test_sine_phase_of_a_pure_first_order_lag():
    """Steady state of x2' = a(u - x2), u = A w cos(wt): exact phase atan(w / a)."""
    a, f, T = 40.0, 5.0, 1e-3
    w = 2 * math.pi * f
    t = np.arange(0, 2001) * T
    # the ZOH response to u_k = r'(t_k) is not a pure lag; build samples from the
    # continuous steady state instead and hold u so that the samples are exact
    gain = 1 / math.sqrt(1 + (w / a) ** 2)
    lag = math.atan(w / a)
    x1 = gain * np.sin(w * t - lag)
    x2 = gain * w * np.cos(w * t - lag)
    # u_k reproducing x2_{k+1} from x2_k under the exact flow
    g = -np.expm1(-a * T)
    u = (x2[1:] - x2[:-1] * (1 - g)) / g
    x1s = np.empty_like(x1)
    x1s[0] = x1[0]
    for k in range(t.size - 1):
        x1s[k + 1] = flow(x1s[k], x2[k], u[k], T, a)[0]
    tr = exact.Trajectory.from_samples(t, x1s, x2, u, a)
    ph, ratio, (ta, tb) = exact.sine_phase(tr, exact.Signal("sine", 1.0, f))
    assert (tb - ta) * f == pytest.approx(round((tb - ta) * f))
    # the held input perturbs the pure lag by O((wT)^2): half a sample of delay at most
    assert abs(ph - math.degrees(lag)) < math.degrees(w * T), "phase of the lag"
    assert abs(ratio - gain) < 2 * w * T


def test_ramp_split_at_its_end():
    sig = exact.as_signal(RAMP_OFF_GRID)
    assert sig.cuts == (30.0 / 170.0,)
    assert sig.r(np.array([0.1, 1.0])).tolist() == [17.0, 30.0]


def test_bad_input_is_input_error():
    with pytest.raises(InputError):
        exact.Trajectory.from_samples([0.0, 0.0], [0, 0], [0, 0], [0], 10.0)
    with pytest.raises(InputError):
        exact.Trajectory.from_samples([0.0, 1.0], [0, np.nan], [0, 0], [0], 10.0)
    with pytest.raises(InputError):
        exact.Trajectory.from_samples([0.0, 1.0], [0, 0], [0, 0], [0, 0, 0], 10.0)
    with pytest.raises(InputError):
        exact.Signal("chirp", 1.0)
    # a sine's frequency is read from the result's own reference, never guessed
    res = response("pd", "sine")
    np.testing.assert_equal(
        exact.exact_metrics(res, PLANT).exact(),
        exact.exact_metrics(res, PLANT, res.reference).exact(),
        err_msg="metrics with the result's own reference vs the explicit one",
    )
    bare = SimpleNamespace(t=res.t, x1=res.x1, x2=res.x2, u=res.u, r=res.r, signal="sine")
    with pytest.raises(InputError):
        exact.exact_metrics(bare, PLANT)
    with pytest.raises(InputError):  # fewer than one sample per period
        exact.metrics_from_arrays([0, 1.0], [0, 0], [0, 0], [0], 10.0, ("sine", 1.0, 2.0))


def test_duck_typed_result_and_inferred_reference():
    res = response("pto", "ramp")
    m1 = exact.exact_metrics(res, PLANT, d=CFG.pto.d)
    m2 = exact.exact_metrics(res, PLANT.a, reference("ramp"), d=CFG.pto.d)
    assert m1.signal == m2.signal == exact.Signal("ramp", 30.0, 200.0)
    assert set(m1.exact()) == set(exact.METRIC_KEYS)
    for k in exact.METRIC_KEYS:
        a, b = m1.values[k].exact, m2.values[k].exact
        assert (math.isnan(a) and math.isnan(b)) or a == b, k


@pytest.mark.parametrize("sig", ["step", "sine"])
def test_json_metrics_follow_design_keys(sig):
    import json

    res = response("to", sig)
    j = exact.exact_metrics(res, PLANT, reference(sig)).json_metrics()
    keys = {"overshoot_mm", "settling_2pct_s", "settling_0p01mm_s", "rise_time_s"}
    assert set(j) == (keys | {"phase_delay_deg"} if sig == "sine" else keys)
    json.dumps(j, allow_nan=False)  # undefined values are null, not NaN


def test_trajectory_state_is_the_flow_between_samples():
    res = response("pto", "step")
    tr = exact.Trajectory.from_result(res, PLANT)
    x1, x2 = tr.state(res.t)
    assert_allclose(x1, res.x1, rtol=0, atol=1e-12, err_msg="x1 at the samples")
    mid = res.t[:-1] + 0.3 * np.diff(res.t)
    y1, y2 = flow(res.x1[:-1], res.x2[:-1], res.u[:-1], mid - res.t[:-1], PLANT.a)
    z1, z2 = tr.state(mid)
    assert_allclose(z1, y1, rtol=1e-15, atol=1e-15, err_msg="x1 between samples")
    assert_allclose(z2, y2, rtol=1e-15, atol=1e-12, err_msg="x2 between samples")
