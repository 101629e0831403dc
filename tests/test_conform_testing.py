"""``ptoverify.testing.assert_conforms`` is isolated like the CLI (issue 27, item 2).

A user's test file holds one test per hostile law, each calling ``assert_conforms``
on it, and a last test that passes; one real inner pytest runs that file in a
subprocess (with a hard timeout).  Each case's inner test must FAIL with a clear
message (in its own failure report), never pass, skip or hang, and the inner run
must go on to its end: every hostile test failed, the last one passed, the
summary line printed.  One inner run for all the cases (a module fixture) rather
than one per case: each law still runs in its own child process, and a law that
broke the run (a ``KeyboardInterrupt`` or ``pytest.skip`` reaching the inner
pytest, an exit of it) would now also show as the other cases missing.
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

#: the user's imports; each law imports the reference where it calls it, after its hostile
#: statement, so a law's process loads the reference only if the law gets that far
HEADER = """\
import os, time
import numpy as np
import pytest
from ptoverify.testing import assert_conforms
"""

CASES = {
    "os_exit_0": ("os._exit(0)", "{}", "exited with code 0"),
    "hang": ("time.sleep(10_000)", "{'timeout': 2.5}", "timeout"),
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


def user_test_file(names) -> str:
    """The user's test file: for each case a law and a test gating it, then a passing test."""
    body = HEADER
    for name in names:
        statement, kwargs, _ = CASES[name]
        body += textwrap.dedent(
            f"""

            def law_{name}(x1, x2, cfg):
                {statement}
                from ptoverify.conform.gate import reference_law
                return reference_law(x1, x2, cfg)

            def test_law_conforms_{name}():
                assert_conforms(law_{name}, **{kwargs})
            """
        )
    return body + "\n\ndef test_the_run_goes_on():\n    assert True\n"


@pytest.fixture(scope="module")
def inner_run(tmp_path_factory):
    """One inner pytest over every case: (exit code, output, failure report per test name)."""
    tmp_path = tmp_path_factory.mktemp("inner")
    test = tmp_path / "test_user_law.py"
    test.write_text(user_test_file(sorted(CASES)))
    p = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfEs", str(test)],
        capture_output=True,
        text=True,
        timeout=HARD_S,
        cwd=tmp_path,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
    )
    out = p.stdout + p.stderr
    # pytest's failure reports: "____ test_name ____" up to the next one or the summary
    heads = list(re.finditer(r"^_{3,} (test_\w+) _{3,}$", p.stdout, re.M))
    ends = [m.start() for m in heads[1:]] + [p.stdout.find("short test summary info")]
    reports = {m.group(1): p.stdout[m.end() : end] for m, end in zip(heads, ends)}
    return p.returncode, out, reports


FAST = ("os_exit_0", "pytest_skip", "keyboard_interrupt")  #: the rest is marked slow


@pytest.mark.parametrize(
    "name", [n if n in FAST else pytest.param(n, marks=pytest.mark.slow) for n in sorted(CASES)]
)
def test_hostile_law_fails_the_users_test(inner_run, name):
    code, out, reports = inner_run
    _, _, words = CASES[name]
    assert code == 1, f"inner pytest exit {code}:\n{out[-2000:]}"
    assert re.search(rf"\b{len(CASES)} failed, 1 passed in", out), out[-2000:]
    assert f"FAILED test_user_law.py::test_law_conforms_{name}" in out, out[-2000:]
    report = reports.get(f"test_law_conforms_{name}", "")
    # the AssertionError's message: its "E" lines (not the source pytest shows above them)
    message = "\n".join(line for line in report.splitlines() if line.startswith("E "))
    assert "does not conform" in message and words in message, report[-3000:] or out[-3000:]


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
