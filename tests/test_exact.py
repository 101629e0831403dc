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
from scipy.optimize import brentq, curve_fit

from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law
from ptoverify.model.plant import flow
from ptoverify.sim import exact, settling
from ptoverify.sim.simulate import Reference, reference, simulate


def settle(tr, sig, band):
    """Exact settling time [s] of one record to |e| <= band [mm] (settling.settling_time)."""
    d = settling.SettlingDefinition("test", "a test band", band_mm=band)
    return float(settling.settling_time(tr, sig, d).time[0])


def overshoot_peak(tr, target):
    """(overshoot [mm], peak time [s]) of one record (settling.overshoot)."""
    ov = settling.overshoot(tr, target)
    return float(ov.value[0]), float(ov.t_peak[0])


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
        ex = settle(tr, sig, band)
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
    ex, tp = overshoot_peak(exact.Trajectory.from_result(res, PLANT), 5.0)
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


def test_settling_and_overshoot_are_those_of_exact_metrics():
    """The lean evaluation gives exact_metrics' values bit for bit (NaN where it does),
    for every law and signal, at the paper's gains and at far-off ones (the sine's
    overshoot is undefined: NaN)."""
    from ptoverify.studies.tune import tuned_config

    cfgs = [
        CFG,
        tuned_config(CFG, "pd", {"kp": 2900.0, "kd": 0.0}),
        tuned_config(CFG, "pd", {"kp": 12.0, "kd": 3.9}),
        tuned_config(CFG, "pto", {"d": 0.3, "k1": 2500.0, "k2": 0.05}),
    ]
    seen_nan = False
    for cfg in cfgs:
        for law in ("to", "pd", "pto"):
            for sig in ("step", "ramp", "sine"):
                res = simulate(make_law(law, cfg), cfg.plant, sig)
                full = exact.exact_metrics(res, cfg.plant, res.reference).exact()
                lean = exact.settling_and_overshoot(res, cfg.plant, res.reference)
                assert set(lean) == {"overshoot_mm", "settling_2pct_s", "settling_0p01mm_s"}
                for k, v in lean.items():
                    assert (math.isnan(v) and math.isnan(full[k])) or v == full[k], (law, sig, k)
                    seen_nan |= math.isnan(v)
    assert seen_nan


def test_settling_and_overshoot_of_many_responses_are_each_alone():
    """Responses measured side by side give each response's own values bit for bit (laws
    whose responses settle, never settle and overshoot, every signal); a response with a
    non-finite sample is refused as it is alone, and so are responses on different grids."""
    from dataclasses import replace

    from ptoverify.studies.tune import tuned_config

    cfgs = [
        CFG,
        tuned_config(CFG, "pd", {"kp": 2900.0, "kd": 0.0}),
        tuned_config(CFG, "pd", {"kp": 12.0, "kd": 3.9}),
        tuned_config(CFG, "pto", {"d": 0.3, "k1": 2500.0, "k2": 0.05}),
    ]
    for sig in ("step", "ramp", "sine"):
        runs = [
            simulate(make_law(law, c), c.plant, sig) for c in cfgs for law in ("to", "pd", "pto")
        ]
        many = exact.settling_and_overshoot_many(runs, CFG.plant)
        for res, got in zip(runs, many, strict=True):
            alone = exact.settling_and_overshoot(res, CFG.plant, res.reference)
            assert set(got) == set(alone)
            for k, v in alone.items():
                assert (math.isnan(v) and math.isnan(got[k])) or v == got[k], (sig, k)
    bad = replace(runs[0], x1=np.where(np.arange(runs[0].x1.size) == 3, np.nan, runs[0].x1))
    with pytest.raises(InputError, match="non-finite"):
        exact.settling_and_overshoot(bad, CFG.plant)
    with pytest.raises(InputError, match="non-finite"):
        exact.settling_and_overshoot_many([runs[1], bad], CFG.plant)
    short = simulate(make_law("pd", CFG), CFG.plant, "sine", duration=0.1)
    with pytest.raises(InputError, match="one sample grid"):
        exact.settling_and_overshoot_many([runs[0], short], CFG.plant)


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


# ------------------------------------------------- settling of many records at once
BAND1, BAND2 = 0.01, PLANT.a * 0.01  # the sweep's box [mm], [mm/s]
PER_SWEEP = 2_000  # dense points per sample for the batch settling


def dense_last_out(x1, x2, u, a, T, b1, b2, per=PER_SWEEP):
    """Time of the last dense point outside the box per record (-1 if none; NaN if the end is out).

    plant.flow at ``per`` uniform points per sample.  Intervals are skipped only
    when an elementary bound certifies them inside: x2(s) is a convex combination
    of x2k and u, so |x2(s)| <= V = max(|x2k|, |u|), and x1 is V-Lipschitz from
    both ends, so |x1(s)| <= (|x1k| + |x1k+1| + T V) / 2.
    """
    steps, n = u.shape
    v = np.maximum(np.abs(x2[:-1]), np.abs(u))
    sure = (v <= b2) & (0.5 * (np.abs(x1[:-1]) + np.abs(x1[1:]) + T * v) <= b1)
    end_out = (np.abs(x1[-1]) > b1) | (np.abs(x2[-1]) > b2)
    sure[:, end_out] = True  # nothing to evaluate: the record ends outside
    kk, cc = np.nonzero(~sure)
    s = T * np.arange(per) / per
    last = np.full(n, -1.0)
    for i in range(0, kk.size, 256):
        k, c = kk[i : i + 256], cc[i : i + 256]
        y1, y2 = flow(x1[k, c][:, None], x2[k, c][:, None], u[k, c][:, None], s[None, :], a)
        out = (np.abs(y1) > b1) | (np.abs(y2) > b2)
        j = per - 1 - out[:, ::-1].argmax(axis=1)
        tt = np.where(out.any(axis=1), k * T + s[j], -1.0)
        np.maximum.at(last, c, tt)
    return np.where(end_out, np.nan, last)


@pytest.fixture(scope="module")
def sweep_records():
    """400 states of the sweep's grid (20 x 20), and 6 states of its 200 x 200 grid with
    excursions between in-band samples; the sweep's horizon; every law's records."""
    from ptoverify.sim.simulate import simulate_batch
    from ptoverify.studies.sweep import SweepSettings, grid_states, run_sweep

    res = run_sweep(CFG, SweepSettings(n1=20, n2=20))
    G1, G2 = grid_states(PLANT, 200, 200)
    pick = [(86, 99), (87, 99), (88, 99), (44, 95), (98, 91), (155, 108)]  # (x2 index, x1 index)
    x1 = np.concatenate([res.x1.ravel(), [G1[i, j] for i, j in pick]])
    x2 = np.concatenate([res.x2.ravel(), [G2[i, j] for i, j in pick]])
    recs = {law: simulate_batch(make_law(law, CFG), PLANT, x1, x2, res.steps) for law in res.laws}
    return res, recs


@pytest.mark.parametrize("law", ["pd", "pto", "pto-printed", "to"])
def test_batch_settling_matches_dense_flow_on_sweep_records(sweep_records, law):
    """Last exit from the box vs the last dense point outside it (2,000 per sample).

    The true last exit lies after the last dense point outside and, unless an
    excursion is shorter than the dense spacing, before the next dense point.
    With the sweep's hold, both readings agree on which states settle, and the
    sweep's own values are these.
    """
    res, recs = sweep_records
    b, T = recs[law], PLANT.sample_time
    dt = T / PER_SWEEP
    st0 = exact.settling_times_batch(b.x1, b.x2, b.u, PLANT.a, T, BAND1, BAND2)
    ref = dense_last_out(b.x1, b.x2, b.u, PLANT.a, T, BAND1, BAND2)
    assert np.array_equal(np.isnan(st0.time), np.isnan(ref)), f"{law}: which records end outside"
    ok = np.isfinite(ref)
    got, lo = st0.time[ok], np.maximum(ref[ok], 0.0)
    assert np.all(got >= lo - 1e-12), f"{law}: exact exit before a dense point outside"
    hi = np.where(ref[ok] < 0, 0.0, ref[ok] + dt)
    assert_allclose(got, hi, rtol=0, atol=dt * 1.001, err_msg=f"{law}: settling vs dense flow")
    # with the hold, as the sweep reads it
    hold = res.settings.hold
    st = exact.settling_times_batch(b.x1, b.x2, b.u, PLANT.a, T, BAND1, BAND2, hold)
    tail = res.steps * T - np.where(ref < 0, 0.0, ref + dt)
    clear = np.abs(tail - hold) > 2 * dt  # not decided within the dense spacing
    assert np.array_equal(np.isnan(st.time)[clear], ~(tail >= hold)[clear]), "hold rule"
    n = res.x1.size
    assert np.array_equal(res.laws[law].settle_time.ravel(), st.time[:n], equal_nan=True)
    assert np.array_equal(res.laws[law].grid.settle_time.ravel(), st.grid[:n], equal_nan=True)
    if law == "pd":  # the picked 200 x 200 states leave the box between in-band samples
        later = st0.time[n : n + 3] > st0.grid[n : n + 3]
        dense_later = ref[n : n + 3] > st0.grid[n : n + 3]
        assert later.all() and dense_later.all(), "PD excursions after the grid's settled sample"
    if law == "pto-printed":
        assert (ref[n + 3 : n + 5] > st0.grid[n + 3 : n + 5]).all(), "dense sees the excursions"
        assert (st0.time[n + 3 : n + 5] > st0.grid[n + 3 : n + 5]).all()


def test_batch_settling_grid_bounds_on_sweep_records(sweep_records):
    """grid - T < exact (the sample before the grid value is outside) and grid <= T ceil(exact / T)
    (every sample from the exact time on is inside); exact > grid only with an excursion
    between samples, which the dense reference confirms."""
    _, recs = sweep_records
    T = PLANT.sample_time
    for law, b in recs.items():
        st = exact.settling_times_batch(b.x1, b.x2, b.u, PLANT.a, T, BAND1, BAND2)
        ok = np.isfinite(st.time)
        assert np.array_equal(ok, np.isfinite(st.grid)), f"{law}: same records settle (no hold)"
        ex, gr = st.time[ok], st.grid[ok]
        assert np.all((ex > gr - T) | (gr == 0.0)), f"{law}: exact more than a sample early"
        assert np.all(gr <= T * np.ceil(ex / T - 1e-9) + 1e-15), f"{law}: grid after exact's sample"
        # the grid reading: the first sample from which every later sample is inside
        out = (np.abs(b.x1) > BAND1) | (np.abs(b.x2) > BAND2)
        k = [
            next((i for i in range(out.shape[0]) if not out[i:, j].any()), -1)
            for j in range(out.shape[1])
        ]
        want = np.where(np.array(k) >= 0, np.array(k) * T, np.nan)
        assert np.array_equal(want, st.grid, equal_nan=True), f"{law}: grid settling"


def _excursion_record(x11):
    """Sample 0 outside (x2), samples 1.. inside from (x11, 1.8); -9.66 mm/s on interval 1."""
    a, T = PLANT.a, PLANT.sample_time
    x1, x2 = np.empty(6), np.empty(6)
    x1[1], x2[1] = x11, 1.8
    x1[0], x2[0] = flow(x1[1], x2[1], 0.0, -T, a)  # backward flow under u = 0
    u = np.array([0.0, -9.66, 0.0, 0.0, 0.0])
    for k in range(1, 5):
        x1[k + 1], x2[k + 1] = flow(x1[k], x2[k], u[k], T, a)
    return x1, x2, u


def test_batch_settling_constructed_excursion_between_in_band_samples():
    """x1 peaks above the band inside interval 1 while samples 1 and 2 are inside:
    the exact settling is the re-entry on x1's falling side (brentq on plant.flow),
    later than the grid's (sample 1); from x1 = 0 there is no excursion."""
    a, T = PLANT.a, PLANT.sample_time
    x1, x2, u = _excursion_record(0.0095)
    assert abs(x2[0]) > BAND2 and np.all(np.abs(x1[1:]) <= BAND1), "construction"
    assert np.all(np.abs(x2[1:]) <= BAND2), "construction: samples 1.. inside"
    s_dense = T * np.linspace(0, 1, 20001)
    y1 = flow(x1[1], x2[1], u[1], s_dense, a)[0]
    assert y1.max() > BAND1 * 1.01, "construction: the excursion leaves the band"
    i = int(np.argmax(y1))
    s_ref = brentq(lambda s: flow(x1[1], x2[1], u[1], s, a)[0] - BAND1, s_dense[i], T, xtol=1e-18)
    st = exact.settling_times_batch(x1, x2, u, a, T, BAND1, BAND2)
    assert st.grid[0] == T
    assert_allclose(st.time[0], T + s_ref, rtol=0, atol=1e-15, err_msg="re-entry time")
    assert st.time[0] > st.grid[0]
    x1m, x2m, um = _excursion_record(0.0)  # the same, 0.0095 mm lower: no excursion
    assert np.all(np.abs(x1m[1:]) <= BAND1) and np.all(np.abs(x2m[1:]) <= BAND2)
    assert flow(x1m[1], x2m[1], um[1], s_dense, a)[0].max() <= BAND1
    st = exact.settling_times_batch(x1m, x2m, um, a, T, BAND1, BAND2)
    x2_cross = brentq(lambda s: flow(x1m[0], x2m[0], 0.0, s, a)[1] - BAND2, 0.0, T, xtol=1e-18)
    assert_allclose(st.time[0], x2_cross, rtol=0, atol=1e-15, err_msg="x2 re-entry")
    assert st.grid[0] == T and st.time[0] < T


def test_batch_settling_agrees_with_single_record_settling_time():
    """Position band only (velocity band huge): the batch equals ``settling_time`` of the
    regulation error e = 0 - x1 (pieces and brentq, another path) on PD and PTO records."""
    from ptoverify.sim.simulate import simulate_batch

    rng = np.random.default_rng(3)
    x1s, x2s = rng.uniform(-50, 50, 30), rng.uniform(-300, 300, 30)
    T = PLANT.sample_time
    for law in ("pd", "pto"):
        b = simulate_batch(make_law(law, CFG), PLANT, x1s, x2s, 300)
        st = exact.settling_times_batch(b.x1, b.x2, b.u, PLANT.a, T, BAND1, 1e300)
        t = T * np.arange(301)
        for j in range(x1s.size):
            tr = exact.Trajectory.from_samples(t, b.x1[:, j], b.x2[:, j], b.u[:, j], PLANT.a)
            one = settle(tr, exact.Signal("step", 0.0), BAND1)
            close_or_both_nan(st.time[j], one, 1e-13, f"{law} record {j}")


def test_batch_settling_hold_and_bad_input():
    """A free decay: closed-form exits; the hold rule in seconds (exact) and samples (grid)."""
    a, T = 10.0, 0.1
    t = np.arange(11) * T
    x1, x2 = -0.5 * np.exp(-a * t), 5.0 * np.exp(-a * t)
    st = exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 0.01, 1.0, hold=0.6)
    assert_allclose(st.time[0], math.log(50) / a, rtol=1e-14, err_msg="x1 exit ln(50)/a")
    assert st.grid[0] == pytest.approx(0.4) and math.isnan(
        exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 0.01, 1.0, hold=0.61).time[0]
    ), "tail 1.0 - 0.391 = 0.609 s < 0.61 s"
    assert math.isnan(
        exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 0.01, 1.0, hold=0.61).grid[0]
    ), "grid: 6 samples of tail < 7"
    end_out = exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 1e-9, 1.0)
    assert math.isnan(end_out.time[0]) and math.isnan(end_out.grid[0])
    inside = exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 1.0, 10.0)
    assert inside.time[0] == 0.0 == inside.grid[0]
    with pytest.raises(InputError):
        exact.settling_times_batch(x1, x2, np.zeros(11), a, T, 0.01, 1.0)
    with pytest.raises(InputError):
        exact.settling_times_batch(x1, x2, np.zeros(10), a, T, 0.0, 1.0)
