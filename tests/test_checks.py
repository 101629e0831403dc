import json

from ptoverify.cli import main
from ptoverify.studies.checks import GATES, run_checks, summarize
from ptoverify.verdict import FAIL, PASS, UNVERIFIED


def test_core_gates_pass_on_paper(paper_cfg):
    names = [
        "zoh-vs-integrator",
        "roots-closed-form-vs-bisection",
        "mintime-closed-form-vs-propagation",
        "mintime-closed-form-vs-two-phase",
        "discrete-limit-consistency",
    ]
    results = run_checks(paper_cfg, names)
    assert [r.name for r in results] == names
    for r in results:
        assert r.status == PASS, r


def test_forced_solver_failure_is_unverified(paper_cfg, capsys):
    """A real IPOPT run capped at 1 iteration does not converge: unverified, exit 1."""
    results = run_checks(
        paper_cfg,
        ["mintime-closed-form-vs-two-phase", "mintime-closed-form-vs-collocation"],
        max_iter=1,
    )
    assert all(r.status == UNVERIFIED and r.measured is None for r in results), results
    assert not summarize(results)["ok"]
    code = main(
        ["check", "--gate", "mintime-closed-form-vs-collocation", "--max-iter", "1", "--json"]
    )
    data = json.loads(capsys.readouterr().out)
    assert code == 1 and data["checks"][0]["status"] == UNVERIFIED
    assert data["summary"]["unverified"] == 1


def test_exception_in_gate_fails_closed(paper_cfg):
    """A gate that cannot compute (here: an invalid configuration object) is unverified."""
    broken = paper_cfg.with_plant(a=float("nan"))
    r = GATES["mintime-closed-form-vs-two-phase"](broken)
    assert r.status == UNVERIFIED and r.measured is None, r


def test_unknown_gate_is_bad_input(capsys):
    assert main(["check", "--gate", "no-such-gate"]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error:")


def test_unstable_sampled_loop_fails_its_gate(paper_cfg):
    """Gains that meet Section 5's Lyapunov conditions but are unstable when sampled fail."""
    from dataclasses import replace

    cfg = replace(
        paper_cfg, pd=replace(paper_cfg.pd, kp=5000.0), pto=replace(paper_cfg.pto, k1=5000.0)
    )
    results = {
        r.name: r for r in run_checks(cfg, ["pd-sampled-stable", "linear-zone-sampled-stable"])
    }
    assert results["pd-sampled-stable"].status == FAIL
    assert results["linear-zone-sampled-stable"].status == FAIL
    assert results["pd-sampled-stable"].measured > 1.0


def test_zone_that_cannot_be_built_fails(paper_cfg):
    from dataclasses import replace

    cfg = replace(paper_cfg, pto=replace(paper_cfg.pto, d=0.0))
    r = run_checks(cfg, ["zone-corrected-valid"])[0]
    assert r.status != PASS, r
