"""One definition of a verified minimum-time answer, used by mintime, report and check."""

import dataclasses
import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ptoverify.model.ocp as ocp_mod
from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.errors import InputError
from ptoverify.model.ocp import CollocationOCP, convergence_study
from ptoverify.studies.checks import GATES
from ptoverify.studies.groundtruth import (
    COLLOCATION_RESIM_REL,
    state_scale,
    verified_mintime,
)
from ptoverify.verdict import UNVERIFIED


def end_state_by_ode(t, u, x1, x2, a):
    """Independent re-simulation: DOP853 on each interval of the piecewise-constant input."""
    y = np.array([x1, x2], dtype=float)
    for k in range(len(u)):
        sol = solve_ivp(
            lambda _, z, uk=u[k]: [z[1], -a * z[1] + a * uk],
            (t[k], t[k + 1]),
            y,
            rtol=1e-12,
            atol=1e-12,
            method="DOP853",
        )
        y = sol.y[:, -1]
    return y


def test_converged_but_inaccurate_collocation_is_null():
    """Three intervals: IPOPT converges, but the input misses the origin; the answer is null."""
    cfg = paper_config()
    x1, x2, n = 5.0, 0.0, 3
    raw = CollocationOCP(cfg.plant, intervals=n).solve(x1, x2)
    assert raw.success and raw.status == "Solve_Succeeded", "the premise: IPOPT converged"
    end = end_state_by_ode(raw.t, raw.u, x1, x2, cfg.plant.a)
    miss = float(np.hypot(end[0], end[1] / cfg.plant.a))
    assert miss > COLLOCATION_RESIM_REL * state_scale(x1, x2, cfg.plant), "premise: inaccurate"
    gt = verified_mintime(x1, x2, cfg, intervals=n)
    assert gt.collocation_s is None and gt.collocation.status.startswith("inaccurate")
    out = gt.to_json()
    assert out["collocation_s"] is None and out["collocation_resim_error_mm"] is None
    assert out["collocation_status"].startswith("inaccurate")
    # the closed form and the (accurate) two-phase answer stay
    assert out["two_phase_s"] == pytest.approx(out["analytic_s"], rel=1e-9)


def test_accurate_collocation_is_kept_and_its_resimulation_is_independent():
    cfg = paper_config()
    gt = verified_mintime(-20.0, 250.0, cfg, intervals=40)
    co = gt.collocation
    assert gt.collocation_s is not None
    end = end_state_by_ode(co.t, co.u, -20.0, 250.0, cfg.plant.a)
    assert np.hypot(end[0], end[1] / cfg.plant.a) == pytest.approx(co.resim_error, abs=1e-8)


def _perturbed_two_phase(monkeypatch, rel=1e-4):
    real = ocp_mod.TwoPhaseOCP.solve

    def solve(self, x1, x2):
        r = real(self, x1, x2)
        return dataclasses.replace(r, t_f=r.t_f * (1 + rel), t_switch=r.t_switch * (1 + rel))

    monkeypatch.setattr(ocp_mod.TwoPhaseOCP, "solve", solve)


def test_perturbed_two_phase_is_null_in_mintime_and_unverified_in_check(monkeypatch, capsys):
    """A converged two-phase answer 1e-4 off: mintime (function and CLI) and check agree."""
    _perturbed_two_phase(monkeypatch)
    cfg = paper_config()
    gt = verified_mintime(5.0, 0.0, cfg, intervals=20)
    assert gt.two_phase_s is None and gt.two_phase.status.startswith("inaccurate")
    assert main(["mintime", "5", "0", "--intervals", "20", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["two_phase_s"] is None and data["two_phase_switch_time_s"] is None
    assert data["two_phase_status"].startswith("inaccurate")
    r = GATES["mintime-closed-form-vs-two-phase"](cfg)
    assert r.status == UNVERIFIED and "inaccurate" in r.detail, r


def test_to_json_has_the_mintime_keys():
    out = verified_mintime(5.0, 0.0, paper_config(), intervals=20).to_json()
    assert list(out) == [
        "x0",
        "analytic_s",
        "switch_time_s",
        "two_phase_s",
        "collocation_s",
        "collocation_intervals",
        "discrete_steps",
        "discrete_s",
        "two_phase_switch_time_s",
        "two_phase_status",
        "two_phase_iterations",
        "collocation_status",
        "collocation_iterations",
        "collocation_resim_error_mm",
        "discrete_status",
        "sample_time_s",
    ]


@pytest.mark.parametrize(
    "x1,x2,kw",
    [(1e9, 0.0, {}), (0.0, 1e9, {}), (float("nan"), 0.0, {}), (1.0, 0.0, {"intervals": 2001})],
)
def test_bad_input_is_input_error(x1, x2, kw):
    with pytest.raises(InputError):
        verified_mintime(x1, x2, paper_config(), **kw)


def test_verified_mintime_reuses_a_convergence_study_answer():
    """An answer of the convergence study at the same N gives the same record as a fresh
    solve; an answer from another state is refused."""
    cfg = paper_config()
    states = np.array([[5.0, 0.0], [-12.0, 150.0]])
    study = convergence_study(cfg.plant, states, (20,))
    for i, (x1, x2) in enumerate(states):
        fresh = verified_mintime(x1, x2, cfg, intervals=20).to_json()
        reused = verified_mintime(x1, x2, cfg, intervals=20, collocation=study.results[(i, 20)])
        assert reused.to_json() == fresh
    with pytest.raises(ValueError, match="not an answer from"):
        verified_mintime(5.0, 0.0, cfg, intervals=20, collocation=study.results[(1, 20)])
    with pytest.raises(ValueError, match="not a default"):
        verified_mintime(5.0, 0.0, cfg, intervals=40, collocation=study.results[(0, 20)])
