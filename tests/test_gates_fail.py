"""Every gate of ``ptoverify check`` is shown failing.

For each gate (the nominal ones and the robustness gates of ``check --robust``), its subject (the flow, a root, a law, a solver's answer, the zone
construction, the loop gains, the claims) is perturbed with monkeypatch, and the
gate must report ``fail`` or ``unverified``, never ``pass``.  Where the run is
cheap the same gate also passes unperturbed on the same configuration, so the
failure is the perturbation's doing.  A gate without a perturbation here fails
``test_every_gate_has_a_failing_perturbation``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable

import numpy as np
import pytest

import ptoverify.model.curves as curves_mod
import ptoverify.model.laws as laws_mod
import ptoverify.model.mintime as mintime_mod
import ptoverify.model.ocp as ocp_mod
import ptoverify.model.plant as plant_mod
import ptoverify.model.poles as poles_mod
import ptoverify.model.zones as zones_mod
import ptoverify.model.zones.margins as zone_margins
import ptoverify.studies.claims as claims_mod
import ptoverify.studies.robust as robust_mod
import ptoverify.studies.robust.trajectory as robust_trajectory_mod
from ptoverify.config import Config, PDGains, Plant, PTOSettings, Robustness, paper_config
from ptoverify.studies.checks import GATES, ROBUST_GATES, ROBUST_STUDY_GATES, run_checks
from ptoverify.verdict import FAIL, PASS, UNVERIFIED


@pytest.fixture(autouse=True)
def _fresh_memos():
    """Zones and properties are memoized per configuration: a perturbation must not see
    (or leave behind) a result computed without it."""
    from ptoverify.studies.properties import named_properties

    zones_mod.clear_caches()
    named_properties.cache_clear()
    yield
    zones_mod.clear_caches()
    named_properties.cache_clear()


#: gate name -> (perturb(monkeypatch, cfg) -> cfg, also check the unperturbed pass, slow)
PERTURBATIONS: dict[str, tuple[Callable, bool, bool]] = {}

#: A plant whose l1 reaches beyond the linear zone inside the envelope, so that a PTO law
#: without its switching zone strides over (at the paper's values l1 stays inside
#: |x1| < d for |x2| <= w_max and no law can stride over there).
STRIDE_CFG = Config(
    "stride",
    Plant(a=100.0, w_max=100.0, sample_time=0.003, position_range=20.0),
    PDGains(kp=50.0, kd=0.5),
    PTOSettings(d=0.3, k1=50.0, k2=1.0),
)


def perturbation(name: str, *, baseline: bool = True, slow: bool = False):
    """Register the perturbation of gate ``name``."""

    def wrap(fn):
        PERTURBATIONS[name] = (fn, baseline, slow)
        return fn

    return wrap


def _wrap_laws(monkeypatch, change):
    """Every law made by make_law returns change(u, x1, x2, cfg) instead of u."""
    real = laws_mod.make_law

    def make(name, cfg):
        law = real(name, cfg)

        def perturbed(x1, x2):
            u, region = law(x1, x2)
            return change(np.asarray(u, dtype=float), x1, x2, cfg), region

        return perturbed

    monkeypatch.setattr(laws_mod, "make_law", make)


@perturbation("zoh-vs-integrator")
def _(monkeypatch, cfg):
    real = plant_mod.step

    def step(x1, x2, u, p):
        y1, y2 = real(x1, x2, u, p)
        return y1 + 1e-7 * (1.0 + np.abs(y1)), y2  # a one-sample map off by 1e-7

    monkeypatch.setattr(plant_mod, "step", step)
    return cfg


@perturbation("roots-closed-form-vs-bisection")
def _(monkeypatch, cfg):
    real = curves_mod.root_22
    monkeypatch.setattr(curves_mod, "root_22", lambda b0: real(b0) * (1.0 + 1e-12))
    return cfg


@perturbation("mintime-closed-form-vs-propagation")
def _(monkeypatch, cfg):
    real = mintime_mod.min_time

    def min_time(x1, x2, plant):
        mt = real(x1, x2, plant)
        return dataclasses.replace(mt, t_switch=mt.t_switch * (1.0 + 1e-8))

    monkeypatch.setattr(mintime_mod, "min_time", min_time)
    return cfg


@perturbation("proof-reach", baseline=False)
def _(monkeypatch, cfg):
    # a linear zone that is unstable when sampled: no certified target, nothing proved
    return dataclasses.replace(cfg, pto=dataclasses.replace(cfg.pto, k2=6.0))


@perturbation("proof-no-stride-over", baseline=False)
def _(monkeypatch, cfg):
    # the PTO without its switching zone (TO outside the linear zone) strides over
    import math

    import ptoverify.studies.prove.run as prove_run

    real = prove_run.law_spec

    def spec(name, c):
        return dataclasses.replace(real(name, c), omega0=math.nan)

    monkeypatch.setattr(prove_run, "law_spec", spec)
    # on the plant where l1 leaves the linear zone (at the paper's values it cannot, and
    # the proof of a zone-less law there runs for minutes); with its zone it proves
    # (test_proof_no_stride_over_passes_on_the_stride_plant)
    return dataclasses.replace(STRIDE_CFG, name="no-zone")


@perturbation("input-bound")
def _(monkeypatch, cfg):
    _wrap_laws(monkeypatch, lambda u, x1, x2, c: 1.001 * u)
    return cfg


@perturbation("odd-symmetry")
def _(monkeypatch, cfg):
    _wrap_laws(monkeypatch, lambda u, x1, x2, c: u + 1e-6 * c.plant.w_max)
    return cfg


@perturbation("mintime-closed-form-vs-two-phase")
def _(monkeypatch, cfg):
    """A converged answer whose arcs are 1e-4 too long: the a-posteriori check rejects it."""
    real = ocp_mod.TwoPhaseOCP.solve

    def solve(self, x1, x2):
        r = real(self, x1, x2)
        return dataclasses.replace(r, t_f=r.t_f * (1 + 1e-4), t_switch=r.t_switch * (1 + 1e-4))

    monkeypatch.setattr(ocp_mod.TwoPhaseOCP, "solve", solve)
    return cfg


@perturbation("mintime-closed-form-vs-collocation", baseline=False)
def _(monkeypatch, cfg):
    real = ocp_mod.CollocationOCP.solve
    monkeypatch.setattr(
        ocp_mod.CollocationOCP,
        "solve",
        lambda self, x1, x2: (lambda r: dataclasses.replace(r, t_f=r.t_f * (1 + 1e-3)))(
            real(self, x1, x2)
        ),
    )
    return cfg


@perturbation("discrete-limit-consistency")
def _(monkeypatch, cfg):
    """An N* one sample too long: N* - 1 is then feasible."""
    real = mintime_mod.discrete_min_steps

    def discrete(x1, x2, plant, *args, **kwargs):
        d = real(x1, x2, plant, *args, **kwargs)
        return dataclasses.replace(
            d, steps=d.steps + 1, time_s=d.time_s + plant.sample_time, u=np.append(d.u, 0.0)
        )

    monkeypatch.setattr(mintime_mod, "discrete_min_steps", discrete)
    return cfg


@perturbation("derivation-identities-vs-numerics", baseline=False, slow=True)
def _(monkeypatch, cfg):
    real = plant_mod.flow
    monkeypatch.setattr(
        plant_mod,
        "flow",
        lambda x1, x2, u, t, a: (lambda y: (y[0] * (1 + 1e-9), y[1]))(real(x1, x2, u, t, a)),
    )
    return cfg


@perturbation("zone-corrected-valid", baseline=False)
def _(monkeypatch, cfg):
    """A construction that believes every omega0 meets the principle: the grid check objects."""
    real = zone_margins.principle_margin
    monkeypatch.setattr(
        zone_margins, "principle_margin", lambda *a, **k: np.asarray(real(*a, **k)) + 1e3
    )
    return cfg


@perturbation("no-stride-over", baseline=False)
def _(monkeypatch, cfg):
    """The PTO law without its switching zone, on a plant where that strides over."""
    real = laws_mod.make_law
    monkeypatch.setattr(
        laws_mod,
        "make_law",
        lambda name, c: laws_mod.pto_law(c, None) if name == "pto" else real(name, c),
    )
    return STRIDE_CFG


@perturbation("no-limit-cycle", baseline=False)
def _(monkeypatch, cfg):
    """The sampled time-optimal law in place of PTO: it chatters around the origin."""
    real = laws_mod.make_law
    monkeypatch.setattr(
        laws_mod, "make_law", lambda name, c: real("to" if name == "pto" else name, c)
    )
    return cfg


def _gain_times_20(monkeypatch, which):
    real = poles_mod.loop_poles

    def loop_poles(name, a, T, k_x1, k_x2):  # noqa: N803
        return real(name, a, T, k_x1 * (20.0 if name == which else 1.0), k_x2)

    monkeypatch.setattr(poles_mod, "loop_poles", loop_poles)


@perturbation("pd-sampled-stable")
def _(monkeypatch, cfg):
    _gain_times_20(monkeypatch, "pd")
    return cfg


@perturbation("linear-zone-sampled-stable")
def _(monkeypatch, cfg):
    _gain_times_20(monkeypatch, "linear")
    return cfg


@perturbation("claims-computed", baseline=False)
def _(monkeypatch, cfg):
    """One reading of one claim whose values could not be measured (NaN)."""
    real = claims_mod.evaluate_claims

    def evaluate(c):
        out = list(real(c))
        first = out[0]
        r0 = first.readings[0]
        bad = dataclasses.replace(r0, values={k: math.nan for k in r0.values}, measured=None)
        out[0] = dataclasses.replace(first, readings=(bad, *first.readings[1:]))
        return out

    monkeypatch.setattr(claims_mod, "evaluate_claims", evaluate)
    return cfg


#: A box where the corrected PTO passes both robustness gates (no delay; the settling
#: limit above the ratio of the states next to the origin, where N* is a few samples), so
#: that their failures below are the perturbations' doing.  At the paper's box (delay 0..1)
#: the PTO fails both: a finding, reported by ``check --robust``.
ROBUST_CFG = dataclasses.replace(
    paper_config(), robustness=Robustness(delay_samples=(0, 0), settling_ratio_limit=20.0)
)


def _pto_replaced_in_robust(monkeypatch, law):
    """The robustness study builds ``law(cfg)`` where it would build the PTO (nominal_law)."""
    real = robust_trajectory_mod.make_law
    monkeypatch.setattr(
        robust_trajectory_mod,
        "make_law",
        lambda name, c: law(c) if name == "pto" else real(name, c),
    )


@perturbation("proof-reach-a-interval", baseline=False)
def _(monkeypatch, cfg):
    """A linear zone that is unstable when sampled: no certified target over the a-interval.

    Judged over a_ratio [0.97, 1.03] (one sub-interval; the paper's [0.8, 1.25] takes six):
    the target fails at the nominal a already, so any box around it fails the gate.
    """
    box = dataclasses.replace(cfg.robustness, a_ratio=(0.97, 1.03))
    return dataclasses.replace(cfg, pto=dataclasses.replace(cfg.pto, k2=6.0), robustness=box)


@perturbation("robust-no-limit-cycle")
def _(monkeypatch, cfg):
    """The sampled time-optimal law in place of PTO: it chatters around the origin."""
    _pto_replaced_in_robust(monkeypatch, lambda c: laws_mod.make_law("to", c))
    return ROBUST_CFG


@perturbation("robust-settling")
def _(monkeypatch, cfg):
    """PTO with a dead band (u = 0) at 10 <= |x1| <= 30 mm, |x2| < 100 mm/s: it never settles."""

    def trapped(c):
        pto = laws_mod.make_law("pto", c)

        def vector(x1, x2):
            u, r = pto(x1, x2)
            trap = (np.abs(x1) >= 10.0) & (np.abs(x1) <= 30.0) & (np.abs(x2) < 100.0)
            return np.where(trap, 0.0, u), r

        def scalar(x1, x2):
            u, r = vector(np.array([x1]), np.array([x2]))
            return float(u[0]), int(r[0])

        return laws_mod.Law("trapped", vector, scalar, c.plant.w_max, "PTO with a dead band")

    _pto_replaced_in_robust(monkeypatch, trapped)
    return ROBUST_CFG


def _judge(name: str, cfg: Config):
    """The verdict of gate ``name`` (a robustness gate through ``run_checks``)."""
    if name in GATES:
        return GATES[name](cfg)
    (verdict,) = run_checks(cfg, [name])
    return verdict


@functools.cache
def _clean_robust_study(cfg: Config) -> dict:
    """The two robustness-study gates, unperturbed: one study judges both (run once)."""
    return {v.name: v for v in run_checks(cfg, list(ROBUST_STUDY_GATES))}


def _judge_clean(name: str, cfg: Config):
    """The verdict of gate ``name`` with nothing perturbed."""
    if name in ROBUST_STUDY_GATES:
        return _clean_robust_study(cfg)[name]
    return _judge(name, cfg)


def test_every_gate_has_a_failing_perturbation():
    gates = {*GATES, *ROBUST_GATES}
    missing = sorted(gates - set(PERTURBATIONS))
    assert not missing, f"gates without a failing-perturbation test: {missing}"
    assert not set(PERTURBATIONS) - gates, "perturbation of a gate that does not exist"


def test_robust_gates_fail_at_the_paper_box_and_fail_closed(monkeypatch):
    """At the paper's box the PTO fails both (delay 1); a study that raises is unverified."""
    cfg = paper_config()
    verdicts = run_checks(cfg, list(ROBUST_STUDY_GATES))
    assert [v.name for v in verdicts] == list(ROBUST_STUDY_GATES)
    assert all(v.status == FAIL for v in verdicts), verdicts
    assert verdicts[0].measured > 0.0, "limit cycle amplitude [mm]"

    def broken(*args, **kwargs):
        raise FloatingPointError("injected")

    monkeypatch.setattr(robust_mod, "run_robust", broken)
    verdicts = run_checks(cfg, list(ROBUST_STUDY_GATES))
    assert all(v.status == UNVERIFIED and "injected" in v.detail for v in verdicts), verdicts


def _params():
    for name, (_, _, slow) in PERTURBATIONS.items():
        yield pytest.param(name, id=name, marks=[pytest.mark.slow] if slow else [])


@pytest.mark.parametrize("name", list(_params()))
def test_gate_fails_when_its_subject_is_perturbed(monkeypatch, name):
    perturb, baseline, _ = PERTURBATIONS[name]
    cfg = paper_config()
    with monkeypatch.context() as m:
        cfg = perturb(m, cfg)
        r = _judge(name, cfg)
    assert r.status in (FAIL, UNVERIFIED), r
    assert r.name == name and r.unit, r
    if baseline:
        clean = _judge_clean(name, cfg)
        assert clean.status == PASS, clean


def test_proof_no_stride_over_passes_on_the_stride_plant():
    """The proof gate's perturbation is judged on STRIDE_CFG: with its zone, it passes there."""
    r = _judge("proof-no-stride-over", STRIDE_CFG)
    assert r.status == PASS, r
