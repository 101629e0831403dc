"""The named settling definitions and the one settling time / overshoot (sim/settling.py).

References: a brute-force dense evaluation of the exact ZOH flow
(``ptoverify.model.plant.flow`` at many points per sample, not the piece
machinery under test): the true last exit lies after the last dense point
outside the box and at or before the next dense point, so the exact time must
lie in [t_d, t_d + dt] (dt the dense spacing), up to the root-finding accuracy.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law
from ptoverify.model.plant import flow
from ptoverify.sim.flow import Signal, Trajectory
from ptoverify.sim.settling import (
    DEFINITIONS,
    SettlingDefinition,
    definition,
    definitions_table,
    overshoot,
    settling_time,
)
from ptoverify.sim.simulate import simulate_batch

CFG = paper_config()
P = CFG.plant
PER = 400  # dense points per sample


def _dense(tr, sig, per=PER):
    """Times, e = r - x1 and e' = r' - x2 at per points per sample and the last sample."""
    t, h = tr.t[:-1], np.diff(tr.t)
    s = (np.arange(per) / per)[None, :, None] * h[:, None, None]
    y1, y2 = flow(tr.x1[:-1, None, :], tr.x2[:-1, None, :], tr.u[:, None, :], s, tr.a)
    td = (t[:, None] + s[:, :, 0]).ravel()
    n = tr.x1.shape[1]
    y1, y2 = y1.reshape(-1, n), y2.reshape(-1, n)
    td = np.append(td, tr.t[-1])
    y1, y2 = np.vstack([y1, tr.x1[-1:]]), np.vstack([y2, tr.x2[-1:]])
    return td, sig.r(td)[:, None] - y1, sig.r_dot(td)[:, None] - y2


def _dense_settling(td, e, e2, band, vband, hold):
    """Last dense time outside the box, per column (NaN: last point outside or short tail)."""
    out = np.abs(e) > band
    if math.isfinite(vband):
        out |= np.abs(e2) > vband
    rev = out[::-1]
    last = np.where(rev.any(axis=0), td.size - 1 - rev.argmax(axis=0), -1)
    ts = np.where(last >= 0, td[np.maximum(last, 0)], td[0])
    ended = last == td.size - 1
    return np.where(ended | (td[-1] - ts < hold), np.nan, ts - td[0])


def _check(tr, sig, d, dt, what):
    st = settling_time(tr, sig, d)
    td, e, e2 = _dense(tr, sig)
    size = abs(sig.amplitude)
    band = d.position_band(size) if (d.band_mm or size) else 0.0
    ref = _dense_settling(td, e, e2, band, d.velocity_band(tr.a), d.hold_s)
    both = np.isfinite(ref) & np.isfinite(st.time)
    # hold decided within one dense spacing: only disagreements at that edge are allowed
    edge = np.abs(tr.t[-1] - tr.t[0] - ref - d.hold_s) <= 2 * dt
    nan_ok = (np.isnan(ref) == np.isnan(st.time)) | edge
    assert nan_ok.all(), f"{what}: settled / not settled disagree"
    lo, hi = ref[both] - 1e-12, ref[both] + dt + 1e-12
    assert ((st.time[both] >= lo) & (st.time[both] <= hi)).all(), (
        f"{what}: exact settling outside the dense bracket, worst "
        f"{np.max(np.maximum(lo - st.time[both], st.time[both] - hi)):.3g} s"
    )
    return st


def test_regulation_box_against_dense_flow_on_random_states():
    """The sweep's box (position and velocity bands, hold) from random states, two laws."""
    rng = np.random.default_rng(23)
    steps = 120
    x1, x2 = rng.uniform(-3.0, 3.0, 300), rng.uniform(-300.0, 300.0, 300)
    box = DEFINITIONS["box-0p01mm"]
    for law in ("pd", "pto"):
        b = simulate_batch(make_law(law, CFG), P, x1, x2, steps)
        tr = Trajectory(np.arange(steps + 1) * P.sample_time, b.x1, b.x2, b.u, P.a)
        st = _check(tr, Signal("step", 0.0), box, P.sample_time / PER, law)
        assert np.isfinite(st.time).sum() > 100, "most states settle: the test has teeth"


def test_random_zoh_records_with_excursions_between_samples():
    """Random inputs (excursions between samples that are both inside), every kind of
    reference, bands chosen so that the records settle with exits."""
    rng = np.random.default_rng(5)
    a, T, n, k = 150.0, 0.004, 12, 200
    for sig in (Signal("step", 1.0), Signal("ramp", 1.0, 40.0), Signal("sine", 1.0, 9.0)):
        u = rng.uniform(-60.0, 60.0, (n, k))
        x1, x2 = np.empty((n + 1, k)), np.empty((n + 1, k))
        x1[0], x2[0] = rng.normal(1.0, 0.3, k), rng.normal(0.0, 40.0, k)
        for i in range(n):
            x1[i + 1], x2[i + 1] = flow(x1[i], x2[i], u[i], T, a)
        tr = Trajectory(np.arange(n + 1) * T, x1, x2, u, a)
        td, e, _ = _dense(tr, sig)
        band = float(np.quantile(np.abs(e), 0.6))
        for d in (
            SettlingDefinition("p", "test", band_mm=band),
            SettlingDefinition("pv", "test", band_mm=band, velocity_band_mm=0.2),
            SettlingDefinition("f", "test", band_fraction=band / abs(sig.amplitude)),
        ):
            st = _check(tr, sig, d, T / PER, f"{sig.kind} {d.name}")
            assert np.isfinite(st.time).any() and np.isnan(st.time).any(), "both outcomes occur"


def test_batch_equals_one_by_one():
    rng = np.random.default_rng(2)
    steps = 80
    x1, x2 = rng.uniform(-5.0, 5.0, 40), rng.uniform(-200.0, 200.0, 40)
    b = simulate_batch(make_law("pto", CFG), P, x1, x2, steps)
    t = np.arange(steps + 1) * P.sample_time
    for d in ("box-0p01mm", "0p01mm", "0p001mm"):
        whole = settling_time(Trajectory(t, b.x1, b.x2, b.u, P.a), None, d)
        ov = overshoot(Trajectory(t, b.x1, b.x2, b.u, P.a), 0.0)
        for j in range(x1.size):
            one = Trajectory(t, b.x1[:, j], b.x2[:, j], b.u[:, j], P.a)
            s1 = settling_time(one, None, d)
            assert np.array_equal(s1.time, whole.time[j : j + 1], equal_nan=True), (d, j)
            assert np.array_equal(s1.grid, whole.grid[j : j + 1], equal_nan=True), (d, j)
            o1 = overshoot(one, 0.0)
            assert o1.value[0] == ov.value[j] and o1.grid[0] == ov.grid[j], j


def test_overshoot_against_dense_flow():
    rng = np.random.default_rng(8)
    steps = 60
    x1, x2 = rng.uniform(-10.0, 10.0, 200), rng.uniform(-300.0, 300.0, 200)
    b = simulate_batch(make_law("pd", CFG), P, x1, x2, steps)
    tr = Trajectory(np.arange(steps + 1) * P.sample_time, b.x1, b.x2, b.u, P.a)
    ov = overshoot(tr, 0.0)
    td, e, _ = _dense(tr, Signal("step", 0.0))
    sgn = np.where(0.0 >= b.x1[0], 1.0, -1.0)
    dense = np.maximum((sgn * -e).max(axis=0), 0.0)  # x1 = -e
    dt = P.sample_time / PER
    slack = np.abs(b.x2).max(axis=0) * dt
    assert ((ov.value >= dense - 1e-12) & (ov.value <= dense + slack)).all(), "overshoot"
    assert (ov.value > 0).sum() > 20, "the case must overshoot"
    assert (ov.grid <= ov.value + 1e-15).all(), "the samples never exceed the continuous peak"


def test_definitions_listed_once_and_validated():
    assert list(DEFINITIONS) == [d.name for d in DEFINITIONS.values()]
    assert definition("2pct") is DEFINITIONS["2pct"]
    assert DEFINITIONS["2pct"].position_band(5.0) == pytest.approx(0.1)
    assert DEFINITIONS["box-0p01mm"].velocity_band(P.a) == pytest.approx(P.a * 0.01)
    with pytest.raises(InputError, match="unknown settling"):
        definition("3pct")
    with pytest.raises(InputError, match="band_mm or band_fraction"):
        SettlingDefinition("x", "both", band_mm=1.0, band_fraction=0.1)
    with pytest.raises(InputError, match="nonzero size"):
        DEFINITIONS["2pct"].position_band(0.0)


def test_readme_table_is_the_registry():
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = re.search(r"## Settling definitions\n(.*?)(\n## |\Z)", readme, re.S)
    assert section, "README has a 'Settling definitions' section"
    assert definitions_table() in section.group(1), "the README table equals the registry's"


def test_exponential_closed_form():
    """x1 = e^{-a t} with u = 0 is an exact ZOH record: |x1| <= b from ln(1/b) / a."""
    a, T = 20.0, 0.002
    t = np.arange(501) * T
    tr = Trajectory.from_samples(t, np.exp(-a * t), -a * np.exp(-a * t), np.zeros(500), a)
    st = settling_time(tr, None, "0p01mm")
    assert_allclose(st.time[0], math.log(100.0) / a, rtol=1e-12, err_msg="settling, closed form")
