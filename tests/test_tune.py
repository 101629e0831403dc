"""Tuning: a brute-force reference, constraints re-checked independently, TOML round trip."""

import dataclasses
import functools
import json
import math

import numpy as np
import pytest
from conftest import zoh_reference
from scipy.linalg import expm

from ptoverify import cli
from ptoverify.config import config_from_mapping, load_config, paper_config
from ptoverify.errors import InfeasibleError, InputError
from ptoverify.model.laws import make_law
from ptoverify.model.mintime import discrete_min_steps, min_time
from ptoverify.sim.exact import exact_metrics
from ptoverify.sim.simulate import simulate
from ptoverify.studies.claims import fair_comparison
from ptoverify.studies.properties import law_properties
from ptoverify.studies.tune import (
    BOUNDS,
    Candidate,
    TuneBudget,
    fair_tunings,
    front_gap,
    pareto_front,
    tune,
    worst_ratio_nt,
)

#: the smallest search that still exercises every step (shared, memoized, with test_claims)
SMALL = TuneBudget(maxiter=2, popsize=5, d_grid=2, d_refine=0)

CFG = paper_config()
# a slower, coarser plant: few samples per response, so a brute-force grid is cheap
SLOW = config_from_mapping(
    {
        "name": "slow",
        "plant": {"a": 60.0, "w_max": 200.0, "sample_time": 0.004, "position_range": 20.0},
        "pd": {"kp": 50.0, "kd": 0.5},
        "pto": {"d": 1.0, "k1": 60.0, "k2": 1.0},
    }
)


def _spectral_radius(a, T, k1, k2):
    """Spectral radius of Ad - Bd K, (Ad, Bd) by scipy's ``cont2discrete`` (once per a, T)."""
    Ad, Bd = zoh_reference(float(a), float(T))
    return np.abs(np.linalg.eigvals(Ad - Bd @ np.array([[k1, k2]]))).max()


def _settling(cfg, kp, kd):
    """Independent evaluation: simulate, then the exact metrics of that response."""
    c = dataclasses.replace(cfg, pd=dataclasses.replace(cfg.pd, kp=kp, kd=kd))
    if _spectral_radius(cfg.plant.a, cfg.plant.T, kp, kd) >= 1.0:
        return math.inf
    res = simulate(make_law("pd", c), c.plant, "step")
    v = exact_metrics(res, c.plant).exact()["settling_2pct_s"]
    return v if math.isfinite(v) else math.inf


@pytest.mark.slow
def test_pd_tune_matches_brute_force_grid():
    kps = np.geomspace(*BOUNDS["pd"]["kp"], 25)
    kds = np.linspace(*BOUNDS["pd"]["kd"], 21)
    grid = np.array([[_settling(SLOW, kp, kd) for kd in kds] for kp in kps])
    i, j = np.unravel_index(np.argmin(grid), grid.shape)
    r = tune(SLOW, "pd", "step", maxiter=40)
    # the search is continuous: it must do at least as well as the grid's best cell ...
    assert r.best.objective <= grid[i, j] * (1 + 1e-9), (r.best.gains, kps[i], kds[j])
    # ... and its value is what an independent simulation of its gains gives
    again = _settling(SLOW, r.best.gains["kp"], r.best.gains["kd"])
    assert again == pytest.approx(r.best.objective, rel=1e-12)
    # and it lies within one grid cell of a grid cell at most one cell-value worse
    near = grid[max(i - 1, 0) : i + 2, max(j - 1, 0) : j + 2]
    assert r.best.objective <= near.min() + 1e-12


def test_constraints_hold_when_resimulated_independently():
    bound = 0.01
    r = tune(CFG, "pd", "step", max_overshoot=bound, maxiter=15)
    g = r.best.gains
    assert _spectral_radius(CFG.plant.a, CFG.plant.T, g["kp"], g["kd"]) < 1.0
    cfg = r.config
    assert (cfg.pd.kp, cfg.pd.kd) == (g["kp"], g["kd"])
    res = simulate(make_law("pd", cfg), cfg.plant, "step")
    m = exact_metrics(res, cfg.plant).exact()
    assert m["overshoot_mm"] <= bound
    # between samples, not on the grid: the exact overshoot bounds the grid's
    assert m["overshoot_mm"] >= exact_metrics(res, cfg.plant).grid()["overshoot_mm"]
    assert law_properties(make_law("pd", cfg), cfg, n1=41, n2=41, rest=40).limit_cycles == 0


@pytest.fixture(scope="module")
def pd_tuned():
    """One short PD search on the paper's plant (two tests read it; tune is deterministic)."""
    return tune(CFG, "pd", "step", maxiter=5)


def test_tuned_config_round_trips_through_toml(tmp_path, pd_tuned):
    r = pd_tuned
    path = tmp_path / "tuned.toml"
    path.write_text(r.toml())
    loaded = load_config(path)
    assert loaded.pd == r.config.pd and loaded.plant == r.config.plant and loaded.pto == CFG.pto
    res = simulate(make_law("pd", loaded), loaded.plant, "step")
    m = exact_metrics(res, loaded.plant).exact()
    assert m["settling_2pct_s"] == r.best.settling_2pct_s
    assert m["overshoot_mm"] == r.best.overshoot_mm


def test_pareto_front_is_nondominated(pd_tuned):
    r = pd_tuned
    front = r.front
    assert front, "an empty front"
    for a in front:
        for b in front:
            dominated = (
                b.overshoot_mm <= a.overshoot_mm
                and b.settling_2pct_s <= a.settling_2pct_s
                and (b.overshoot_mm, b.settling_2pct_s) != (a.overshoot_mm, a.settling_2pct_s)
            )
            assert not dominated, (a, b)
    assert pareto_front(front) == front


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"law": "to"}, "law"),
        ({"law": "pd", "objective": "fastest"}, "objective"),
        ({"law": "pd", "max_overshoot": -1.0}, "overshoot"),
        ({"law": "pd", "signal": "chirp"}, "signal"),
    ],
)
def test_bad_arguments_are_input_errors(kwargs, word):
    with pytest.raises(InputError, match=word):
        tune(CFG, **kwargs)


# ---------------------------------------------------------------- worst_ratio_nt
def _worst_ratio_reference(cfg, law_name, n1, n2):
    """The same definition, evaluated independently: a scalar ZOH loop and LP N*."""
    p = cfg.plant
    T, a, band = p.sample_time, p.a, 0.01
    M = np.zeros((3, 3))
    M[:2, :2] = [[0.0, 1.0], [0.0, -a]]
    M[1, 2] = a
    E = expm(M * T)
    Ad, Bd = E[:2, :2], E[:2, 2]
    law = make_law(law_name, cfg)
    xs = np.linspace(-p.position_range, p.position_range, n1)
    vs = np.linspace(-p.w_max, p.w_max, n2)
    t_f = max(float(min_time(x, v, p).t_f) for x in xs for v in vs)
    hold = math.ceil(0.05 / T - 1e-9)
    steps = math.ceil(4.0 * t_f / T) + hold
    worst = 0.0
    for v in vs:
        for x in xs:
            n_star = discrete_min_steps(x, v, p).steps
            s, last_out = np.array([x, v]), 0
            for k in range(steps + 1):
                if abs(s[0]) > band or abs(s[1]) > a * band:
                    last_out = k + 1
                u, _ = law.scalar(float(s[0]), float(s[1]))
                s = Ad @ s + Bd * u
            if steps - last_out < hold:
                return math.inf
            worst = max(worst, last_out / n_star)
    return worst


@pytest.mark.parametrize("law", ["pd", "pto"])
def test_worst_ratio_nt_matches_an_independent_evaluation(law):
    got = worst_ratio_nt(CFG, law, n1=4, n2=4)
    assert got == pytest.approx(_worst_ratio_reference(CFG, law, 4, 4), rel=1e-12)
    assert got >= 1.0 - 1e-12  # no law beats the discrete-time limit by a whole sample


def test_worst_ratio_nt_is_infinite_when_a_state_never_settles():
    # kd = 0 with a large kp: the sampled loop is unstable and never settles
    bad = dataclasses.replace(CFG, pd=dataclasses.replace(CFG.pd, kp=2000.0, kd=0.0))
    assert _spectral_radius(CFG.plant.a, CFG.plant.T, 2000.0, 0.0) > 1.0
    assert worst_ratio_nt(bad, "pd", n1=4, n2=4) == math.inf


def test_tune_worst_ratio_objective_is_that_of_its_gains():
    small = functools.partial(worst_ratio_nt, n1=6, n2=6)
    r = tune(CFG, "pd", "step", objective="worst_ratio_nt", maxiter=2, popsize=5, worst_ratio=small)
    assert r.best.feasible and r.best.verified
    assert r.best.objective == worst_ratio_nt(r.config, "pd", n1=6, n2=6)
    # the search's best is no worse than any feasible candidate it evaluated
    for c in r.front:
        if c.feasible:
            assert r.best.objective <= c.objective


# ---------------------------------------------------------------- CLI round trip
def _cli(capsys, *argv):
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_cli_tune_config_reproduced_by_simulate(capsys, tmp_path):
    bound = 0.02
    out = _cli(
        capsys, "tune", "--law", "pd", "--max-overshoot", str(bound), "--maxiter", "3", "--json"
    )
    res = json.loads(out)
    path = tmp_path / "tuned.toml"
    path.write_text(res["config_toml"])
    sim = json.loads(
        _cli(capsys, "simulate", "--config", str(path), "--law", "pd", "--signal", "step", "--json")
    )
    m = sim["metrics"]
    assert m["settling_2pct_s"] == res["best"]["settling_2pct_s"]
    assert m["overshoot_mm"] == res["best"]["overshoot_mm"] <= bound
    # the text form prints the same configuration after one comment line
    text = _cli(capsys, "tune", "--law", "pd", "--max-overshoot", str(bound), "--maxiter", "3")
    assert text.split("\n", 1)[1] == res["config_toml"]


@pytest.mark.slow
def test_tuned_pto_config_reproduced_by_simulate(capsys, tmp_path):
    ft = fair_tunings(CFG, SMALL)
    r = ft.results[("pto", "pd-paper")]
    path = tmp_path / "pto.toml"
    path.write_text(r.toml())
    assert load_config(path).pto == r.config.pto
    sim = json.loads(
        _cli(
            capsys, "simulate", "--config", str(path), "--law", "pto", "--signal", "step", "--json"
        )
    )
    assert sim["metrics"]["settling_2pct_s"] == r.best.settling_2pct_s
    assert sim["metrics"]["overshoot_mm"] == r.best.overshoot_mm <= ft.bounds["pd-paper"]


# ---------------------------------------------------------------- fair comparison
@pytest.mark.slow
def test_fair_comparison_bounds_constraints_and_floor():
    fc = fair_comparison(CFG, SMALL)
    # the bounds are the paper-gain overshoots, measured independently here
    for law, name in (("pto", "pto-paper"), ("pd", "pd-paper")):
        res = simulate(make_law(law, CFG), CFG.plant, "step")
        assert fc["bounds_mm"][name] == exact_metrics(res, CFG.plant).exact()["overshoot_mm"]
    step = abs(simulate(make_law("pd", CFG), CFG.plant, "step").reference.amplitude)
    assert fc["floor"]["nt_s"] == discrete_min_steps(-step, 0.0, CFG.plant).steps * CFG.plant.T
    assert fc["floor"]["band_entry_s"] < fc["floor"]["tf_s"] <= fc["floor"]["nt_s"]
    # band entry: full input from rest reaches 98 % of the step exactly then (closed form)
    a, w, tb = CFG.plant.a, CFG.plant.w_max, fc["floor"]["band_entry_s"]
    assert w * (tb - (1 - math.exp(-a * tb)) / a) == pytest.approx(0.98 * step, abs=1e-9)
    for name, bound in fc["bounds_mm"].items():
        for law in ("pd", "pto"):
            b = fc["best"][name][law]
            cfg = fair_tunings(CFG, SMALL).config(law, name)
            res = simulate(make_law(law, cfg), cfg.plant, "step")
            m = exact_metrics(res, cfg.plant).exact()
            assert m["overshoot_mm"] <= bound  # the constraint, re-simulated
            assert m["settling_2pct_s"] == b["settling_2pct_s"] >= fc["floor"]["band_entry_s"]
            assert b["worst_ratio_nt"] == worst_ratio_nt(cfg, law)
            assert b["verified"]
    for law, front in fc["fronts"].items():
        o = [c["overshoot_mm"] for c in front]
        s = [c["settling_2pct_s"] for c in front]
        assert o == sorted(o) and s == sorted(s, reverse=True), law
    # the inset's gap is the two fronts' difference, read off the fronts by their definition
    gap = fc["fronts_gap"]
    assert gap["law"] == "pto" and gap["minus"] == "pd" and len(gap["overshoot_mm"]) >= 1

    def least(law, x):  # least settling on the law's front with overshoot <= x
        return min(c["settling_2pct_s"] for c in fc["fronts"][law] if c["overshoot_mm"] <= x)

    for x, g in zip(gap["overshoot_mm"], gap["gap_s"], strict=True):
        assert g == least("pto", x) - least("pd", x)
    assert {c["id"] for c in fc["claims"]} == {
        "step-pd-31-percent",
        "step-pto-steadier-quicker",
        "conclusion-vs-to-and-pd",
        "conclusion-quicker-response",
    }
    for c in fc["claims"]:
        assert c["sentence"] and len(c["readings"]) == 3, c["id"]
    json.dumps(fc, allow_nan=True)


# ---------------------------------------------------------------- speed without change
def test_spectral_radii_are_the_sampled_loop_radius():
    """The batched radii (poles.spectral_radii, which the tuning screens with) equal the
    eigenvalues of SciPy's ZOH loop for every gain pair, and the one-pair function."""
    from ptoverify.model.poles import sampled_spectral_radius, spectral_radii

    rng = np.random.default_rng(8)
    k1, k2 = 10 ** rng.uniform(0, 3.6, 300), rng.uniform(-1, 10, 300)
    for a, T in ((CFG.plant.a, CFG.plant.T), (60.0, 0.004)):
        got = spectral_radii(a, T, k1, k2)
        want = [_spectral_radius(a, T, p, q) for p, q in zip(k1, k2)]
        np.testing.assert_allclose(got, want, rtol=1e-9)
        assert sampled_spectral_radius(a, T, k1[7], k2[7]) == got[7]


def test_grid_counts_are_the_gate_properties(monkeypatch):
    from ptoverify.config import Config, PDGains, Plant, PTOSettings
    from ptoverify.model.laws import pto_law
    from ptoverify.studies import tune as tune_mod
    from ptoverify.studies.tune import grid as grid_mod

    for cfg, law in ((CFG, "pto"), (CFG, "pd"), (CFG, "to")):
        lp = law_properties(make_law(law, cfg), cfg)
        cycles, strides = tune_mod.grid_counts(cfg, law)
        assert cycles == lp.limit_cycles
        assert strides == (lp.stride_overs if law == "pto" else 0)
    assert tune_mod.grid_counts(CFG, "to")[0] > 0, "the sampled TO law chatters"
    # a PTO without its zone on plants where that strides over (the gate's own failing
    # case), on grids that are and are not exactly symmetric
    monkeypatch.setattr(grid_mod, "make_law", lambda name, c: pto_law(c, None))
    for position_range in (20.0, 25.0):
        stride_cfg = Config(
            "stride",
            Plant(a=100.0, w_max=100.0, sample_time=0.003, position_range=position_range),
            PDGains(kp=50.0, kd=0.5),
            PTOSettings(d=0.3, k1=50.0, k2=1.0),
        )
        lp = law_properties(pto_law(stride_cfg, None), stride_cfg)
        assert lp.stride_overs > 0
        assert tune_mod.grid_counts(stride_cfg, "pto") == (lp.limit_cycles, lp.stride_overs)


def test_limit_cycle_band_is_the_gate_default():
    import inspect

    from ptoverify.studies.tune import LIMIT_CYCLE_BAND

    assert inspect.signature(law_properties).parameters["band"].default == LIMIT_CYCLE_BAND


@pytest.mark.parametrize(
    "law, d",
    [("pd", None), ("pto", 0.3), ("pto", 1.0), ("pto", 2.3), ("ptos", None), ("cascade-p", None)],
)
def test_screen_agrees_with_the_simulate_json_path(law, d):
    from ptoverify.studies.tune import measure as tune_mod
    from ptoverify.studies.tune import screen as screen_mod

    rng = np.random.default_rng(9)
    if law == "pd":
        batch = [{"kp": 10 ** rng.uniform(1, 3.45), "kd": rng.uniform(0, 4)} for _ in range(60)]
    elif law == "ptos":
        batch = [{"alpha": rng.uniform(0.05, 1), "k": 10 ** rng.uniform(1, 3.3)} for _ in range(60)]
    elif law == "cascade-p":
        batch = [{"kp": 10 ** rng.uniform(0, 3)} for _ in range(60)]
    else:
        batch = [
            {"d": d, "k1": 10 ** rng.uniform(1, 3.45), "k2": rng.uniform(0, 10)} for _ in range(60)
        ]
    batch = [{k: float(v) for k, v in g.items()} for g in batch]
    raws = screen_mod.StepScreen(CFG, law, True)(batch)
    feasible = 0
    for g, raw in zip(batch, raws):
        for bound in (0.05, 1.0):
            ref = tune_mod.evaluate(CFG, law, g, max_overshoot=bound)
            cand = screen_mod.screened_candidate(
                CFG, law, g, raw, objective="settling_2pct", max_overshoot=bound, worst_ratio=None
            )
            assert cand.feasible == ref.feasible, (g, cand.reason, ref.reason)
            feasible += ref.feasible
        if math.isfinite(ref.overshoot_mm):
            assert raw.overshoot_mm == pytest.approx(ref.overshoot_mm, abs=1e-12)
        for a, b in (
            (raw.settling_2pct_s, ref.settling_2pct_s),
            (raw.settling_0p01mm_s, ref.settling_0p01mm_s),
        ):
            assert (math.isnan(a) and math.isnan(b)) or a == pytest.approx(b, abs=1e-12)
    assert feasible > 0


@pytest.mark.parametrize("law", ["pd", "pto", "ptos", "cascade-p"])
def test_evaluate_batch_is_each_gain_set_on_the_simulate_json_path(law, monkeypatch):
    """Gain sets evaluated side by side are each what evaluate() gives alone, and every
    measured number is that of the simulate --json path (response_metrics) bit for bit:
    over the whole search box (unstable loops, overshoots past the bound, PTO d values
    with different zones), on the step and (PD, PTO) the ramp; the memo and the fallback
    that measures each response alone give the same candidates."""
    from ptoverify.studies.tune import measure as tune_mod

    rng = np.random.default_rng(11)
    box = tune_mod.BOUNDS[law]
    batch = []
    for i in range(24):
        g = {}
        for k, (lo, hi) in box.items():
            u = rng.uniform()
            g[k] = float(lo * (hi / lo) ** u if k in tune_mod.LOG_GAINS else lo + (hi - lo) * u)
        if "d" in g:
            g["d"] = (0.3, 0.8, 2.0)[i % 3]
        batch.append(g)
    batch.append(dict(batch[0]))  # a repeat
    for signal in ("step", "ramp") if law in ("pd", "pto") else ("step",):
        opts = {"signal": signal, "max_overshoot": 0.05}
        got = tune_mod.evaluate_batch(CFG, law, batch, **opts)
        measured = 0
        for g, c in zip(batch, got, strict=True):
            assert c.to_json() == tune_mod.evaluate(CFG, law, g, **opts).to_json()
            if c.reason == "sampled linear loop unstable":
                continue
            m = tune_mod.response_metrics(tune_mod.tuned_config(CFG, law, g), law, signal)
            for k in ("overshoot_mm", "settling_2pct_s", "settling_0p01mm_s"):
                v = getattr(c, k)
                assert (math.isnan(v) and math.isnan(m[k])) or v == m[k], (g, signal, k)
            measured += 1
        assert measured > 0
        memo: dict = {}
        first = tune_mod.evaluate_batch(CFG, law, batch, **opts, memo=memo)
        again = tune_mod.evaluate_batch(CFG, law, batch, **opts, memo=memo)
        assert [c.to_json() for c in first] == [c.to_json() for c in again]
        assert [c.to_json() for c in first] == [c.to_json() for c in got]

    def refuse(*args, **kwargs):
        raise InputError("one response refused")

    monkeypatch.setattr(tune_mod, "settling_and_overshoot_many", refuse)
    alone = tune_mod.evaluate_batch(CFG, law, batch, **opts)
    assert [c.to_json() for c in alone] == [c.to_json() for c in got]


def test_side_by_side_searches_are_the_searches_one_by_one(monkeypatch):
    from ptoverify.studies.tune import search as search_mod

    kw = {
        "max_overshoot": 0.05,
        "maxiter": 4,
        "popsize": 4,
        "d_grid": 3,
        "d_refine": 1,
        "polish": 4,
    }
    together = tune(CFG, "pto", "step", **kw)

    def one_by_one(batch_fn, jobs):
        return [job(batch_fn) for job in jobs]

    monkeypatch.setattr(search_mod, "run_together", one_by_one)
    alone = tune(CFG, "pto", "step", **kw)
    assert together.best == alone.best and together.front == alone.front
    assert together.evaluations == alone.evaluations


@pytest.mark.slow
def test_fair_tunings_are_the_tunings_one_by_one():
    ft = fair_tunings(CFG, SMALL)
    for (law, name), r in ft.results.items():
        alone = tune(
            CFG,
            law,
            "step",
            max_overshoot=ft.bounds[name],
            seed=SMALL.seed,
            maxiter=SMALL.maxiter,
            popsize=SMALL.popsize,
            d_grid=SMALL.d_grid,
            d_refine=SMALL.d_refine,
            polish=SMALL.polish,
            find_runner_up=False,
        )
        assert r.best == alone.best and r.front == alone.front, (law, name)


def test_reported_numbers_are_those_of_simulate_json():
    from ptoverify.studies.tune import evaluate, response_metrics, tuned_config

    r = tune(CFG, "pd", "step", max_overshoot=0.02, maxiter=3, popsize=5)
    for c in [r.best, r.runner_up, *r.front]:
        if c is None:
            continue
        got = (c.settling_2pct_s, c.overshoot_mm, c.settling_0p01mm_s)
        ref = evaluate(CFG, "pd", c.gains, max_overshoot=0.02)
        assert got == (ref.settling_2pct_s, ref.overshoot_mm, ref.settling_0p01mm_s)
        # every metric of the simulate --json path, bit for bit
        m = response_metrics(tuned_config(CFG, "pd", c.gains), "pd", "step")
        assert got == (m["settling_2pct_s"], m["overshoot_mm"], m["settling_0p01mm_s"])


def test_tune_is_deterministic():
    a = tune(CFG, "pto", "step", max_overshoot=0.0, maxiter=3, popsize=4, d_grid=2, d_refine=1)
    b = tune(CFG, "pto", "step", max_overshoot=0.0, maxiter=3, popsize=4, d_grid=2, d_refine=1)
    assert a.best == b.best and a.front == b.front and a.evaluations == b.evaluations


def test_batched_worst_ratios_are_worst_ratio_nt():
    from ptoverify.studies.tune.measure import tuned_config, worst_ratios

    rng = np.random.default_rng(12)
    for law in ("pd", "pto"):
        if law == "pd":
            gs = [{"kp": 10 ** rng.uniform(1.5, 3.3), "kd": rng.uniform(0.2, 3)} for _ in range(6)]
        else:
            gs = [
                {
                    "d": rng.choice([0.5, 1.0]),
                    "k1": 10 ** rng.uniform(1.5, 3.3),
                    "k2": rng.uniform(0.2, 5),
                }
                for _ in range(6)
            ]
        gs = [{k: float(v) for k, v in g.items()} for g in gs]
        want = [worst_ratio_nt(tuned_config(CFG, law, g), law, n1=4, n2=4) for g in gs]
        assert worst_ratios(CFG, law, gs, 4, 4) == want


# ---------------------------------------------------------------- the baselines
def _slope_gains(cfg, law):
    """The law's linear-loop gains read off the law itself (unclipped, near the origin)."""
    fn = make_law(law, cfg)
    h1, h2 = 1e-6, 1e-6
    u, _ = fn(np.array([h1, 0.0]), np.array([0.0, h2]))
    return -u[0] / h1, -u[1] / h2


@pytest.mark.slow
def test_cascade_tune_matches_brute_force_grid():
    """One gain: a fine grid of kp is the reference; the tuning does at least as well."""
    bound = 0.0
    kps = np.geomspace(*BOUNDS["cascade-p"]["kp"], 200)
    best = math.inf
    for kp in kps:
        c = dataclasses.replace(SLOW, cascade=dataclasses.replace(SLOW.cascade, kp=float(kp)))
        if _spectral_radius(c.plant.a, c.plant.T, kp, 0.0) >= 1.0:
            continue
        m = exact_metrics(simulate(make_law("cascade-p", c), c.plant, "step"), c.plant).exact()
        if m["overshoot_mm"] <= bound and math.isfinite(m["settling_2pct_s"]):
            best = min(best, m["settling_2pct_s"])
    r = tune(SLOW, "cascade-p", "step", max_overshoot=bound, maxiter=20)
    assert math.isfinite(best)
    assert r.best.objective <= best * (1 + 1e-9), (r.best.gains, best)


@pytest.mark.parametrize("law", ["ptos", "cascade-p"])
def test_baseline_tuning_reproduced_by_simulate(capsys, tmp_path, law):
    """`tune --law <baseline>`: its TOML, simulated by `simulate`, gives its numbers."""
    bound = 0.02
    out = _cli(
        capsys, "tune", "--law", law, "--max-overshoot", str(bound), "--maxiter", "4", "--json"
    )
    res = json.loads(out)
    path = tmp_path / "tuned.toml"
    path.write_text(res["config_toml"])
    cfg = load_config(path)
    sim = json.loads(
        _cli(capsys, "simulate", "--config", str(path), "--law", law, "--signal", "step", "--json")
    )
    m = sim["metrics"]
    assert m["settling_2pct_s"] == res["best"]["settling_2pct_s"]
    assert m["overshoot_mm"] == res["best"]["overshoot_mm"] <= bound
    # the constraints, re-checked independently: the loop's slope gains on scipy's ZOH
    # plant, and the gates' limit-cycle count
    assert _spectral_radius(cfg.plant.a, cfg.plant.T, *_slope_gains(cfg, law)) < 1.0
    assert law_properties(make_law(law, cfg), cfg, n1=41, n2=41, rest=40).limit_cycles == 0
    # the other laws' gains are the configuration's
    assert (cfg.pd, cfg.pto) == (CFG.pd, CFG.pto)


@pytest.mark.slow
def test_fair_tunings_of_the_baselines_are_tune_alone():
    """The baselines in fair_tunings: the same search and bounds as ``tune`` run alone."""
    ft = fair_tunings(CFG, SMALL, ("ptos", "cascade-p"))
    assert set(ft.results) | set(ft.infeasible) == {
        (law, b) for law in ("ptos", "cascade-p") for b in ft.bounds
    }
    for (law, name), r in ft.results.items():
        alone = tune(
            CFG,
            law,
            "step",
            max_overshoot=ft.bounds[name],
            seed=SMALL.seed,
            maxiter=SMALL.maxiter,
            popsize=SMALL.popsize,
            polish=SMALL.polish,
            find_runner_up=False,
        )
        assert r.best == alone.best, (law, name)
        assert r.best.overshoot_mm <= ft.bounds[name]


def test_infeasible_tuning_is_recorded_not_raised():
    """No gains can settle: the 5 mm step needs 0.5 s at w_max = 10 mm/s, its record is 0.2 s."""
    slow = SLOW.with_plant(w_max=10.0)
    with pytest.raises(InfeasibleError, match="no cascade-p gains"):
        tune(slow, "cascade-p", "step", max_overshoot=0.0, maxiter=2, popsize=4)
    ft = fair_tunings(slow, TuneBudget(maxiter=2, popsize=4), ("cascade-p",))
    assert not ft.results and set(ft.infeasible) == {("cascade-p", b) for b in ft.bounds}
    assert all("no cascade-p gains" in v for v in ft.infeasible.values())


def test_fair_tunings_name_their_bounds():
    with pytest.raises(InputError, match="bounds must be among"):
        fair_tunings(CFG, SMALL, ("pd",), ("nope",))
    with pytest.raises(InputError, match="bounds must be among"):
        fair_tunings(CFG, SMALL, ("pd",), ())


def test_front_gap_is_the_difference_of_the_fronts_everywhere():
    """front_gap against a brute-force reference: at random overshoot bounds x, the least
    settling time of *all* candidates with overshoot <= x (the front's definition) minus the
    other's, read at the last breakpoint at or left of x."""
    rng = np.random.default_rng(7)
    for trial in range(200):
        pools = [
            [
                Candidate({}, s, s, s, o, True)
                for o, s in zip(
                    rng.choice(np.arange(0.0, 2.0, 0.125), n),  # ties in overshoot happen
                    rng.uniform(0.02, 0.05, n),
                    strict=True,
                )
            ]
            for n in rng.integers(1, 12, 2)
        ]
        fa, fb = pareto_front(pools[0]), pareto_front(pools[1])
        g = front_gap("a", fa, "b", fb)
        lo = max(min(c.overshoot_mm for c in p) for p in pools)
        hi = min(max(c.overshoot_mm for c in f) for f in (fa, fb))
        if hi < lo:
            assert g is None, trial
            continue
        assert g.overshoot_mm == tuple(sorted(g.overshoot_mm)) and g.overshoot_mm[0] == lo
        for x in np.concatenate([rng.uniform(lo, hi, 20), [lo, hi]]):
            want = min(c.settling_2pct_s for c in pools[0] if c.overshoot_mm <= x) - min(
                c.settling_2pct_s for c in pools[1] if c.overshoot_mm <= x
            )
            k = np.searchsorted(g.overshoot_mm, x, side="right") - 1
            assert g.gap_s[k] == want, (trial, x)
    assert front_gap("a", [], "b", fb) is None
