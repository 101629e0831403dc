"""Nothing is left running and nothing is left on disk, however ``conform`` ends (issue 27).

Every run here is the real command line in a subprocess, tagged with an
environment variable so that every process it started (the law's child and
anything the law forks) can be found in /proc by that tag, whatever its parent.
"""

import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from ptoverify.conform.isolation import remove_stale_logs

ROOT = Path(__file__).resolve().parents[1]
PROC = Path("/proc")
pytestmark = pytest.mark.skipif(not PROC.is_dir(), reason="needs /proc to find processes")

#: ``{marker}``: a file the law creates when it starts looping (outside the run's TMPDIR);
#: it loops from its fourth call on, in the mode detection (what it answered before is moot)
LOOPING = """\
from pathlib import Path
n = [0]
def f(x1, x2, cfg):
    n[0] += 1
    if n[0] > 3:
        Path({marker!r}).touch()
        while True:
            pass
    return 0.0
"""

FORKING = """\
import subprocess
from ptoverify.conform.gate import reference_law
subprocess.Popen(["sleep", "300"])  # a grandchild that would hold any inherited pipe
def f(x1, x2, cfg):
    return reference_law(x1, x2, cfg)
"""

#: audit R1: a double-forked grandchild in a new session (it escapes any process group)
DAEMON = """\
import os, signal, time
def daemon():
    if os.fork() == 0:
        os.setsid()
        if os.fork() == 0:
            time.sleep(300)
        os._exit(0)
"""
DAEMON_THEN = {
    "raise": DAEMON + "def f(x1, x2, cfg):\n    daemon()\n    raise ValueError('boom')\n",
    # the run's end by its timeout: the law hangs after starting the daemon
    "hang": DAEMON + "def f(x1, x2, cfg):\n    daemon()\n    time.sleep(300)\n",
    # the law kills its own parent (the supervisor): its tree is lost, the token is not
    "kill-parent": DAEMON
    + "def f(x1, x2, cfg):\n    daemon()\n    time.sleep(0.5)\n"
    + "    os.kill(os.getppid(), signal.SIGKILL)\n    time.sleep(300)\n",
}


def tagged(tag: str) -> list[int]:
    """Pids of live (not zombie) processes whose environment carries ``tag``."""
    pids = []
    for entry in PROC.iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if tag.encode() not in (entry / "environ").read_bytes():
                continue
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state not in ("Z", "X"):
            pids.append(int(entry.name))
    return pids


def start(tmp_path, body: str, *extra: str, **kw) -> tuple[subprocess.Popen, str, Path]:
    law = tmp_path / "law.py"
    law.write_text(body)
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    tag = f"PTOVERIFY_TEST_RUN={uuid.uuid4().hex}"
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(tmpdir))
    env[tag.split("=")[0]] = tag.split("=")[1]
    argv = [sys.executable, "-m", "ptoverify", "conform", "--law", f"{law}:f", *extra]
    proc = subprocess.Popen(argv, env=env, cwd=tmp_path, **kw)
    return proc, tag, tmpdir


def wait_for(predicate, limit: float) -> bool:
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.1)
    return predicate()


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT])
def test_killed_conform_leaves_no_process_and_no_file(tmp_path, sig):
    marker = tmp_path / "looping"
    proc, tag, tmpdir = start(
        tmp_path,
        LOOPING.format(marker=str(marker)),
        "--timeout",
        "600",
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        # the law's child is up and looping (CPU time grows) before the kill
        assert wait_for(lambda: len(tagged(tag)) >= 2, 60), "the law's process never started"
        assert wait_for(marker.exists, 60), "the law never started looping"
        time.sleep(0.3)
        proc.send_signal(sig)
        proc.wait(10)
        left = [] if wait_for(lambda: not tagged(tag), 5.0) else tagged(tag)
        assert not left, f"processes of the run still alive 5 s after {sig.name}: {left}"
        assert not list(tmpdir.iterdir()), f"files left: {list(tmpdir.iterdir())}"
    finally:
        for pid in tagged(tag):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("name", sorted(DAEMON_THEN))
def test_a_setsid_grandchild_does_not_outlive_the_run(tmp_path, name):
    """Audit R1: the run ends (exit 1), then nothing of it is left within 5 s."""
    proc, tag, tmpdir = start(
        tmp_path,
        DAEMON_THEN[name],
        "--timeout",
        "4",
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        assert proc.wait(120) == 1
        left = [] if wait_for(lambda: not tagged(tag), 5.0) else tagged(tag)
        assert not left, f"processes of the run still alive 5 s after its end: {left}"
        assert not list(tmpdir.iterdir()), f"files left: {list(tmpdir.iterdir())}"
    finally:
        for pid in tagged(tag):
            os.kill(pid, signal.SIGKILL)


def test_sigkilled_conform_takes_a_setsid_grandchild_down(tmp_path):
    """Audit R1: SIGKILL of conform while the law loops; its daemon was reparented to the
    supervisor (a subreaper), which kills it on its own death signal."""
    body = DAEMON + "def f(x1, x2, cfg):\n    daemon()\n    while True:\n        pass\n"
    proc, tag, tmpdir = start(
        tmp_path, body, "--timeout", "600", stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        # conform, the supervisor, the worker and the daemon (its first parent exited)
        assert wait_for(lambda: len(tagged(tag)) >= 4, 60), f"not started: {tagged(tag)}"
        time.sleep(0.5)
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
        left = [] if wait_for(lambda: not tagged(tag), 5.0) else tagged(tag)
        assert not left, f"processes of the run still alive 5 s after SIGKILL: {left}"
        assert not list(tmpdir.iterdir()), f"files left: {list(tmpdir.iterdir())}"
    finally:
        for pid in tagged(tag):
            os.kill(pid, signal.SIGKILL)


def test_a_forking_law_does_not_hold_the_pipeline(tmp_path):
    """`conform | cat` ends when conform ends; the law's grandchild is killed with its group."""
    proc, tag, tmpdir = start(
        tmp_path,
        FORKING,
        "--json",
        "--timeout",
        "120",
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    try:
        out, err = proc.communicate(timeout=120)  # EOF on both pipes: nobody holds them
        assert proc.returncode == 0, err[-500:]
        assert wait_for(lambda: not tagged(tag), 5.0), f"left running: {tagged(tag)}"
        assert not list(tmpdir.iterdir())
    finally:
        for pid in tagged(tag):
            os.kill(pid, signal.SIGKILL)


def test_stale_named_logs_of_dead_runs_are_removed(tmp_path):
    old = tmp_path / "ptoverify-law-abc123.log"
    new = tmp_path / "ptoverify-law-def456.log"
    other = tmp_path / "someone-else.log"
    for p in (old, new, other):
        p.write_text("")
    past = time.time() - 7200
    os.utime(old, (past, past))
    os.utime(other, (past, past))
    assert remove_stale_logs(tmp_path, max_age_s=3600) == 1
    assert not old.exists() and new.exists() and other.exists()
