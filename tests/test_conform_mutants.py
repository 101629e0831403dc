"""Mutation suite: ``conform`` must reject every seeded fault of the PTO copy.

The copy (``tests/pto_mutants.py``) is written from the equations; each mutant
is one fault flag.  The benign variants (the faithful copy, float32 output,
omega_c by exact bisection) must conform, so the gate is not rejecting
everything.  The score is computed once per session by ``mutation_score``
(``PYTHONPATH=. python tests/pto_mutants.py`` prints it).
"""

import pytest
from pto_mutants import BENIGN, MUTANTS, make_law, mutation_score

from ptoverify.conform import conform_callable

SWEEP = (11, 11, 20)  # 141 closed-loop states: every mutant is killed well inside this grid

# faults that change the dynamics: the closed loop alone (without agreement) must see them
DYNAMIC = {"l1_sign", "l2_sign", "k_swapped", "k2_sign", "bang_sign_q4"}


@pytest.fixture(scope="module")
def score(request):
    from ptoverify.config import paper_config

    return mutation_score(paper_config(), sweep=SWEEP)


def test_at_least_twenty_mutants():
    assert len(MUTANTS) >= 20


@pytest.mark.slow
def test_mutation_score_all_killed(score):
    killed, total, detail = score
    survivors = [name for name, props in detail.items() if not props]
    assert killed == total, f"surviving mutants: {survivors}"


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(MUTANTS))
def test_mutant_rejected(score, name):
    props = score[2][name]
    assert props, f"mutant {name} ({MUTANTS[name]}) conforms: a gap in the gate"
    # every mutant differs from the reference where the grid has points; the delay has no
    # u(x) to compare (a law with memory), its finding is pure-function
    expected = "pure-function" if name == "delay" else "agreement"
    assert expected in props, f"{name}: {expected} did not see it ({props})"


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(DYNAMIC))
def test_dynamic_faults_seen_by_closed_loop(score, name):
    closed_loop = {"no-stride-over", "no-limit-cycle", "input-bound", "settling-vs-discrete-limit"}
    assert closed_loop & set(score[2][name]), f"{name}: closed loop alone passes"


@pytest.mark.slow
def test_no_saturation_breaks_input_bound(score):
    assert "input-bound" in score[2]["no_saturation"]


@pytest.mark.slow
def test_delay_is_not_a_pure_function(score):
    assert "pure-function" in score[2]["delay"]


@pytest.mark.parametrize("name", sorted(BENIGN))
def test_benign_variants_conform(paper_cfg, name):
    r = conform_callable(make_law([name]), paper_cfg, target=name, sweep=SWEEP)
    assert r.conforms, f"benign variant {name} ({BENIGN[name]}) rejected: {r.failures[:2]}"
    assert r.mode == "vectorized"
