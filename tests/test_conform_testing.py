"""``ptoverify.testing.assert_conforms`` is isolated like the CLI (issue 27, item 2).

Each case writes a user's test file that calls ``assert_conforms`` on a hostile
law and runs a real inner pytest on it in a subprocess (with a hard timeout):
the inner test must FAIL with a clear message, never pass, skip or hang, and
the inner run must go on to its end (its summary line is printed).
"""

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ptoverify.conform.testing import law_spec
from ptoverify.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
HARD_S = 120  #: limit of one inner pytest run [s]

HEADER = """\
import os, time
import numpy as np
import pytest
from ptoverify.conform.gate import reference_law
from ptoverify.testing import assert_conforms
"""

CASES = {
    "os_exit_0": ("os._exit(0)", "{}", "exited with code 0"),
    "hang": ("time.sleep(10_000)", "{'timeout': 4}", "timeout"),
    "memory": ("bytearray(64 << 30)", "{}", "MemoryError"),
    "pytest_skip": ("pytest.skip('not today')", "{}", "Skipped"),
    # audit R2: a KeyboardInterrupt from the law is the law's, not the user pressing Ctrl-C
    "keyboard_interrupt": ("raise KeyboardInterrupt", "{}", "the law raised KeyboardInterrupt"),
    "frozen_config": (
        "object.__setattr__(cfg.plant, 'w_max', 1e9)",
        "{}",
        "changed its configuration argument (cfg.plant.w_max",
    ),
}


def inner_pytest(tmp_path: Path, statement: str, kwargs: str) -> subprocess.CompletedProcess:
    test = tmp_path / "test_user_law.py"
    test.write_text(
        HEADER
        + textwrap.dedent(
            f"""
            def law(x1, x2, cfg):
                {statement}
                return reference_law(x1, x2, cfg)

            def test_law_conforms():
                assert_conforms(law, **{kwargs})

            def test_the_run_goes_on():
                assert True
            """
        )
    )
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfEs", str(test)],
        capture_output=True,
        text=True,
        timeout=HARD_S,
        cwd=tmp_path,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
    )


FAST = ("os_exit_0", "pytest_skip", "keyboard_interrupt")  #: the rest is marked slow


@pytest.mark.parametrize(
    "name", [n if n in FAST else pytest.param(n, marks=pytest.mark.slow) for n in sorted(CASES)]
)
def test_hostile_law_fails_the_users_test(tmp_path, name):
    statement, kwargs, words = CASES[name]
    p = inner_pytest(tmp_path, statement, kwargs)
    out = p.stdout + p.stderr
    assert p.returncode == 1, f"inner pytest exit {p.returncode}:\n{out[-2000:]}"
    assert re.search(r"1 failed, 1 passed in", out), out[-2000:]
    assert "FAILED test_user_law.py::test_law_conforms" in out, out[-2000:]
    assert "does not conform" in out and words in out, out[-3000:]


def module_level(x1, x2, cfg):
    """A module-level law (loadable by name)."""
    return 0.0


def test_law_spec_names_module_level_functions_and_refuses_closures():
    assert law_spec(module_level) == f"{__name__}:module_level" or law_spec(module_level).endswith(
        "test_conform_testing.py:module_level"
    )
    assert law_spec("pkg.mod:f") == "pkg.mod:f"

    def closure(x1, x2, cfg):
        return 0.0

    for bad in (closure, lambda x1, x2, cfg: 0.0, 3):
        with pytest.raises(InputError, match="module-level function"):
            law_spec(bad)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"timeout": float("inf")},
        {"timeout": float("nan")},
        {"timeout": 0},
        {"rtol": -1.0},
        {"rtol": float("nan")},
        {"memory_limit": -1},
    ],
    ids=str,
)
def test_bad_limits_are_bad_input_before_the_law_runs(kwargs):
    """An unbounded timeout could hang the user's run; a bad limit is an error at once (R3)."""
    from ptoverify.conform.testing import assert_conforms
    from ptoverify.errors import InputError

    with pytest.raises(InputError, match="assert_conforms: "):
        assert_conforms("examples/my_pto.py:pto", **kwargs)


@pytest.mark.parametrize("perturbations", [("x", 3), 5, (None,)], ids=str)
def test_assert_conforms_r6_perturbations_garbage(perturbations):
    """Audit run 6, assert_conforms/r6-perturbations-garbage: perturbations that are not
    Perturbation objects gave AttributeError ('str' object has no attribute 'mismatch')
    after the law had run; they are bad input before it runs."""
    from ptoverify.conform.testing import assert_conforms
    from ptoverify.errors import InputError

    with pytest.raises(InputError, match="assert_conforms: perturbations"):
        assert_conforms("examples/my_pto.py:pto", perturbations=perturbations)
