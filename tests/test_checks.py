import json

from ptoverify.checks import FAIL, GATES, PASS, UNVERIFIED, run_checks, summarize
from ptoverify.cli import main


def test_core_gates_pass_on_paper(paper_cfg):
    names = ["zoh-vs-integrator", "roots-closed-form-vs-bisection",
             "mintime-closed-form-vs-propagation", "mintime-closed-form-vs-two-phase",
             "discrete-limit-consistency"]
    results = run_checks(paper_cfg, names)
    assert [r.name for r in results] == names
    for r in results:
        assert r.status == PASS, r


def test_forced_solver_failure_is_unverified(paper_cfg, capsys):
    """A real IPOPT run capped at 1 iteration does not converge: unverified, exit 1."""
    results = run_checks(paper_cfg, ["mintime-closed-form-vs-two-phase",
                                     "mintime-closed-form-vs-collocation"], max_iter=1)
    assert all(r.status == UNVERIFIED and r.measured is None for r in results), results
    assert not summarize(results)["ok"]
    code = main(["check", "--gate", "mintime-closed-form-vs-collocation", "--max-iter", "1",
                 "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 1 and data["checks"][0]["status"] == UNVERIFIED
    assert data["summary"]["unverified"] == 1


def test_exception_in_gate_fails_closed(paper_cfg):
    """A gate that cannot compute (here: an invalid configuration object) is unverified."""
    broken = paper_cfg.with_plant(a=float("nan"))
    r = GATES["mintime-closed-form-vs-two-phase"](broken)
    assert r.status in (UNVERIFIED, FAIL) and r.status != PASS


def test_unknown_gate_is_bad_input(capsys):
    assert main(["check", "--gate", "no-such-gate"]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error:")
