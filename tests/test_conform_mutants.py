"""Mutation suite: ``conform`` must reject every seeded fault of the PTO copy.

The copy (``tests/pto_mutants.py``) is written from the equations; each mutant
is one fault flag.  The benign variants (the faithful copy, float32 output,
omega_c by exact bisection) must conform, so the gate is not rejecting
everything.  The score is computed once per session by ``mutation_score``
(``PYTHONPATH=. python tests/pto_mutants.py`` prints it).
"""

import numpy as np
import pytest
from pto_mutants import BENIGN, MEMORY, MUTANTS, make_law, mutation_score

from ptoverify.conform.agreement import agreement
from ptoverify.conform.gate import conform_callable, conformance_grid

SWEEP = (11, 11, 20)  # 141 closed-loop states: every mutant is killed well inside this grid

# faults that change the dynamics: the closed loop alone (without agreement) must see them
DYNAMIC = {"l1_sign", "l2_sign", "k_swapped", "k2_sign", "bang_sign_q4"}


@pytest.fixture(scope="module")
def paper_grid():
    """The paper's default agreement grid, built once (read-only: no test may alter it)."""
    from ptoverify.config import paper_config

    x1, x2 = conformance_grid(paper_config())
    x1.flags.writeable = x2.flags.writeable = False
    return x1, x2


@pytest.fixture(scope="module")
def score(paper_grid):
    from ptoverify.config import paper_config

    return mutation_score(paper_config(), sweep=SWEEP, grid=paper_grid)


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
    # a law with memory has no u(x) to compare: its finding is pure-function; a fault only at
    # curve ties (excluded from the agreement) is seen by odd symmetry; the rest disagree
    expected = (
        "pure-function" if name in MEMORY else "odd-symmetry" if name == "tie_asym" else "agreement"
    )
    assert expected in props, f"{name}: {expected} did not see it ({props})"


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(DYNAMIC))
def test_dynamic_faults_seen_by_closed_loop(score, name):
    closed_loop = {"no-stride-over", "no-limit-cycle", "input-bound", "settling-vs-discrete-limit"}
    assert closed_loop & set(score[2][name]), f"{name}: closed loop alone passes"


@pytest.mark.slow
def test_no_saturation_breaks_input_bound(score):
    assert "input-bound" in score[2]["no_saturation"]


@pytest.mark.parametrize("name", MEMORY)
def test_memory_is_a_pure_function_finding(paper_cfg, name):
    """Latch, cache, debounce, counter, delay: found before any other property runs."""
    r = conform_callable(make_law([name]), paper_cfg, sweep=(3, 3, 2), n_random=1000)
    assert r.failed_properties() == ["pure-function"], r.failures[:2]
    assert "has memory or is not deterministic" in r.failures[0]["detail"]
    assert r.properties["agreement"].status == "not_run"


def test_memory_in_scalar_mode(paper_cfg):
    """A call counter behind a float-only interface (scalar mode) is found too."""
    inner = make_law(["call_count"])

    def law(x1, x2, cfg):
        if not isinstance(x1, float):
            raise TypeError("floats only")
        return float(inner(x1, x2, cfg))

    r = conform_callable(law, paper_cfg, sweep=(3, 3, 2), n_random=1000)
    assert r.mode == "scalar" and r.failed_properties() == ["pure-function"]


@pytest.mark.parametrize("name", ["slow_band_x1", "slow_band_x2"])
def test_band_faults_between_grid_points(paper_cfg, name):
    """5 % slow in a band the grid steps over: the grid alone passes, conform does not."""
    cfg = paper_cfg
    x1, x2 = conformance_grid(cfg)
    law = make_law([name])
    alone, _ = agreement(x1, x2, law(x1, x2, cfg), cfg)
    assert alone["pass"], "the fixed grid alone already sees the band (test is moot)"
    r = conform_callable(law, cfg, sweep=(3, 3, 2))
    fail = next(f for f in r.failures if f["property"] == "agreement")
    s1, s2 = np.abs(fail["state"])
    in_band = 30.2 < s1 < 31.4 if name == "slow_band_x1" else (101 < s2 < 109 and s1 > 2)
    assert in_band, f"failure state {fail['state']} not in the band"
    assert r.agreement["sources"]["random"] >= 100_000


def test_tie_asymmetry_is_odd_symmetry_finding(paper_cfg):
    r = conform_callable(make_law(["tie_asym"]), paper_cfg, sweep=(3, 3, 2), n_random=1000)
    assert r.failed_properties() == ["odd-symmetry"]
    assert "curve tie" in r.failures[0]["detail"]


@pytest.mark.parametrize("name", sorted(BENIGN))
def test_benign_variants_conform(paper_cfg, paper_grid, name):
    r = conform_callable(make_law([name]), paper_cfg, target=name, sweep=SWEEP, grid=paper_grid)
    assert r.conforms, f"benign variant {name} ({BENIGN[name]}) rejected: {r.failures[:2]}"
    assert r.mode == "vectorized"
