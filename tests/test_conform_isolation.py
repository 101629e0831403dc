"""``conform --law`` isolates user code: hangs, crashes and exits are findings, never a pass.

Every case runs the real command line in a subprocess with a hard timeout, so a
regression that hangs fails the test instead of the suite.
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HARD_S = 120  #: subprocess limit of every test here [s]


def cli(*argv, timeout=HARD_S):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run(
        [sys.executable, "-m", "ptoverify", *argv],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=ROOT,
    )
    return p.returncode, p.stdout, p.stderr


def law_file(tmp_path, body):
    """Write the law; only a law that calls the reference imports it (the rest load no more)."""
    head = "import os, time, signal\n"
    if "reference_law" in body:
        head += "from ptoverify.conform.gate import reference_law\n"
    path = tmp_path / "law.py"
    path.write_text(head + textwrap.dedent(body))
    return f"{path}:f"


CASES = {
    "exit0_in_call": (
        """
        def f(x1, x2, cfg):
            os._exit(0)
        """,
        "exited with code 0",
    ),
    "exit0_at_import": ("os._exit(0)\ndef f(x1, x2, cfg):\n    return 0.0\n", "exited with code 0"),
    "exit3_late": (
        """
        n = [0]
        def f(x1, x2, cfg):
            n[0] += 1
            if n[0] > 30:
                os._exit(3)
            return reference_law(x1, x2, cfg)
        """,
        "exited with code 3",
    ),
    "segfault": (
        """
        def f(x1, x2, cfg):
            os.kill(os.getpid(), signal.SIGSEGV)
        """,
        "killed by SIGSEGV",
    ),
    "sleep_forever": (
        """
        def f(x1, x2, cfg):
            time.sleep(10_000)
        """,
        "timeout",
    ),
    "sleep_after_50_calls": (
        """
        n = [0]
        def f(x1, x2, cfg):
            n[0] += 1
            if n[0] > 50:
                time.sleep(10_000)
            return reference_law(x1, x2, cfg)
        """,
        "timeout",
    ),
    "lost_pipe": (
        """
        def f(x1, x2, cfg):
            os.closerange(3, 256)
            return reference_law(x1, x2, cfg)
        """,
        "",
    ),
}


FAST = ("exit0_in_call", "segfault", "sleep_after_50_calls")  #: the rest is marked slow


@pytest.mark.parametrize(
    "name", [n if n in FAST else pytest.param(n, marks=pytest.mark.slow) for n in sorted(CASES)]
)
def test_child_failure_is_a_finding(tmp_path, name):
    body, words = CASES[name]
    spec = law_file(tmp_path, body)
    # a law that hangs ends in a timeout whatever the machine's speed: a short one will do
    limit = "2.5" if words == "timeout" else "6"
    code, out, err = cli("conform", "--law", spec, "--json", "--timeout", limit)
    assert code == 1, (code, out[-500:], err[-500:])
    data = json.loads(out)
    assert data["conforms"] is False and data["unverified"], "unevaluated properties listed"
    iso = [f for f in data["failures"] if f["property"] == "isolation"]
    assert len(iso) == 1 and words in iso[0]["detail"], iso


def test_human_output_names_the_isolation_failure(tmp_path):
    spec = law_file(tmp_path, CASES["exit0_at_import"][0])
    code, out, _ = cli("conform", "--law", spec, "--timeout", "30")
    assert code == 1 and out.startswith("DOES NOT CONFORM")
    lines = [line for line in out.splitlines() if line.startswith("FAILED")]
    assert len(lines) == 1 and lines[0].startswith("FAILED isolation: the law's process exited")


def test_keyboard_interrupt_in_mode_detection_is_the_laws_finding(tmp_path):
    """Audit R2: reported as the law raising it, without ptoverify's traceback, exit 1."""
    spec = law_file(tmp_path, "def f(x1, x2, cfg):\n    raise KeyboardInterrupt\n")
    code, out, err = cli("conform", "--law", spec, "--json", "--timeout", "30")
    assert code == 1, (code, out[-500:], err[-500:])
    data = json.loads(out)
    assert data["conforms"] is False
    details = [f["detail"] for f in data["failures"]]
    assert any(d.startswith("the law raised KeyboardInterrupt") for d in details), details
    assert not any("SIGINT" in d for d in details), details
    assert "Traceback" not in err and "userlaw.py" not in err, err[-2000:]


@pytest.mark.slow
def test_memory_hog_is_a_finding(tmp_path):
    """An allocation beyond the child's address-space limit is a finding, not a dead host."""
    spec = law_file(
        tmp_path,
        """
        def f(x1, x2, cfg):
            blob = bytearray(16 << 30)
            return reference_law(x1, x2, cfg)
        """,
    )
    code, out, err = cli("conform", "--law", spec, "--json", "--timeout", "30")
    assert code == 1, err[-500:]
    data = json.loads(out)
    assert not data["conforms"] and "MemoryError" in json.dumps(data["failures"])


@pytest.mark.slow
def test_import_error_stays_bad_input(tmp_path):
    spec = law_file(tmp_path, "raise ImportError('no bindings')\ndef f(x1, x2, cfg):\n    pass\n")
    code, out, err = cli("conform", "--law", spec, "--timeout", "30")
    assert code == 2 and out == "" and err.count("\n") == 1 and "no bindings" in err
