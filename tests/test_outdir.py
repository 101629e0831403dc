"""Output folders: validated before computing, manifest-protected, config-bound defaults,
stale temporaries removed, SIGTERM cleaned up, concurrent publishes serialized."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

from ptoverify.cli import main
from ptoverify.errors import InputError
from ptoverify.outdir import (
    MARKER,
    OutputBusy,
    check_target,
    make_temp,
    publish,
    read_marker,
    remove_stale,
)

ROOT = Path(__file__).resolve().parents[1]


def _write_output(target: Path, payload: str = "x", config_hash: str | None = "h1", default=False):
    check_target(target, config_hash=config_hash, default=default)
    tmp = make_temp(target)
    (tmp / "result.txt").write_text(payload)
    (tmp / "figures").mkdir()
    (tmp / "figures" / "a.png").write_bytes(b"png")
    publish(tmp, target, config_hash=config_hash, name="t", default=default)


def _leftovers(parent: Path, name: str) -> list[str]:
    return [p.name for p in parent.iterdir() if p.name.startswith(f".{name}.")]


def test_manifest_lists_what_was_written(tmp_path):
    out = tmp_path / "out"
    _write_output(out)
    marker = read_marker(out)
    assert sorted(marker["files"]) == ["figures", "figures/a.png", "result.txt"]
    assert marker["config_hash"] == "h1"
    _write_output(out, "second")  # replacing an output of its own is allowed
    assert (out / "result.txt").read_text() == "second"
    assert _leftovers(tmp_path, "out") == []


def test_foreign_files_are_never_deleted(tmp_path, capsys):
    out = tmp_path / "out"
    _write_output(out)
    (out / "notes.txt").write_text("mine")
    (out / "sub").mkdir()
    (out / "sub" / "deep.txt").write_text("mine too")
    (out / "figures" / "extra.csv").write_text("1")
    with pytest.raises(InputError, match=r"notes\.txt.*sub") as exc:
        check_target(out)
    assert "figures/extra.csv" in str(exc.value) and "sub/deep.txt" not in str(exc.value)
    # a publish that slipped past the early check is refused too, and its temp removed
    tmp = make_temp(out)
    with pytest.raises(InputError, match="did not write"):
        publish(tmp, out)
    assert not tmp.exists()
    assert (out / "notes.txt").read_text() == "mine" and (out / "sub" / "deep.txt").exists()
    # the command line refuses before computing: exit 2, one line, files kept
    assert main(["sweep", "--grid", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("ptoverify: error:") and "notes.txt" in err[0]
    assert (out / "notes.txt").exists()


def test_legacy_marker_protects_unknown_files(tmp_path):
    out = tmp_path / "old"
    (out / "figures").mkdir(parents=True)
    (out / MARKER).write_text("written by ptoverify; this folder may be replaced by it\n")
    for f in ("index.html", "report.md", "results.json", "figures/x.png"):
        (out / f).write_text("r")
    check_target(out)  # what old ptoverify versions wrote: replaceable
    (out / "todo.md").write_text("mine")
    with pytest.raises(InputError, match="todo.md"):
        check_target(out)


def test_default_folder_keeps_other_configurations(tmp_path):
    out = tmp_path / "reports" / "paper"
    _write_output(out, config_hash="aaa", default=True)
    _write_output(out, config_hash="aaa", default=True)  # same configuration: replaced
    with pytest.raises(InputError, match="different configuration.*--out"):
        check_target(out, config_hash="bbb", default=True)
    check_target(out, config_hash="bbb", default=False)  # named explicitly: on purpose


def test_committed_report_marker_matches_the_paper_config():
    from ptoverify.config import paper_config

    marker = read_marker(ROOT / "reports" / "paper")
    assert marker and marker.get("config_hash") == paper_config().digest(), (
        "reports/paper/.ptoverify must record the paper configuration's hash"
    )
    check_target(
        ROOT / "reports" / "paper", config_hash=paper_config().digest(), default=True
    )  # no foreign files in the committed report


def test_unusable_out_fails_before_computing(tmp_path, monkeypatch, capsys):
    (tmp_path / "afile").write_text("x")
    monkeypatch.chdir(tmp_path)
    for out, why in [
        ("/proc/nope", "/proc"),
        (str(tmp_path / "afile" / "sub"), "not a directory"),
        (".", "current folder"),
        (str(tmp_path.parent), "current folder"),
        ("afile", "not a directory"),
    ]:
        t0 = time.perf_counter()
        assert main(["report", "--out", out]) == 2, out
        assert time.perf_counter() - t0 < 3.0, f"{out}: refused only after computing"
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and why in err[0], (out, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_stale_temporaries_of_dead_runs_are_removed(tmp_path):
    out = tmp_path / "out"
    dead = _dead_pid()
    stale = tmp_path / f".out.tmp-{dead}-abc"
    stale.mkdir()
    (stale / MARKER).write_text("{}")
    (stale / "half.json").write_text("{")
    empty_backup = tmp_path / f".out.old-{dead}-def"
    empty_backup.mkdir()
    alive = tmp_path / f".out.tmp-{os.getppid()}-ghi"  # a live process: kept
    alive.mkdir()
    (alive / MARKER).write_text("{}")
    foreign = tmp_path / f".out.tmp-{dead}-jkl"  # no marker, not empty: not ours, kept
    foreign.mkdir()
    (foreign / "x").write_text("x")
    _write_output(out)
    assert not stale.exists() and not empty_backup.exists()
    assert alive.exists() and foreign.exists()
    assert remove_stale(out) == []


_SIGTERM_SCRIPT = textwrap.dedent(
    """
    import sys, time
    import ptoverify.report.plots as plots
    from ptoverify.cli import main

    def slow_save(res, folder):
        (folder / "partial.png").write_bytes(b"x")
        time.sleep(60)
        return []

    plots.save_sweep = slow_save
    sys.exit(main(["sweep", "--grid", "2", "--quiet", "--out", sys.argv[1]]))
    """
)


@pytest.mark.slow
def test_sigterm_cleans_up_and_exits_143(tmp_path):
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(
        [sys.executable, "-c", _SIGTERM_SCRIPT, str(out)],
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not any((p / "partial.png").exists() for p in tmp_path.glob(".out.tmp-*")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the run never started writing"
            time.sleep(0.02)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=20)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:") and "SIGTERM" in lines[0]
    assert list(tmp_path.iterdir()) == [], "SIGTERM left files behind"


def _publish_one(args):
    target, i = args
    target = Path(target)
    try:
        tmp = make_temp(target)
        (tmp / "id.txt").write_text(str(i))
        (tmp / "pad.txt").write_text("x" * 1000)
        publish(tmp, target, config_hash="same", lock_timeout=30.0)
        return "ok"
    except OutputBusy as exc:
        return f"busy: {exc}"
    except Exception as exc:  # the test reports any other outcome as a failure
        return f"{type(exc).__name__}: {exc}"


def test_concurrent_publishes_serialize(tmp_path):
    target = tmp_path / "out"
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=8) as pool:
        outcomes = list(pool.map(_publish_one, [(str(target), i) for i in range(24)]))
    assert time.perf_counter() - t0 < 60
    bad = [o for o in outcomes if o != "ok" and not o.startswith("busy:")]
    assert bad == [], bad
    assert outcomes.count("ok") >= 1
    # one complete output in place, nothing else left next to it
    assert sorted(p.name for p in target.iterdir()) == [MARKER, "id.txt", "pad.txt"]
    assert int((target / "id.txt").read_text()) in range(24)
    assert json.loads((target / MARKER).read_text())["files"] == ["id.txt", "pad.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_report_default_folder_refuses_another_configuration(tmp_path, monkeypatch, capsys):
    """A config copied from the README keeps name = "paper": with other gains, `report`
    without --out must not replace reports/paper/ (exit 2 at once, asks for --out)."""
    from ptoverify.config import paper_config

    monkeypatch.chdir(tmp_path)
    committed = tmp_path / "reports" / "paper"
    _write_output(committed, "committed", config_hash=paper_config().digest(), default=True)
    toml = tmp_path / "my.toml"
    toml.write_text(
        'name = "paper"\n[plant]\nbandwidth_hz = 30.0\nw_max = 300.0\nsample_time = 0.002\n'
        "position_range = 50.0\n[pd]\nkp = 356.0\nkd = 1.15\n[pto]\nd = 0.5\nk1 = 300.0\n"
        "k2 = 3.6\n"
    )
    t0 = time.perf_counter()
    assert main(["report", "--config", str(toml), "--quiet"]) == 2
    assert time.perf_counter() - t0 < 3.0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "different configuration" in err[0] and "--out" in err[0]
    assert (committed / "result.txt").read_text() == "committed"


def test_write_atomic_never_replaces_a_device_or_fifo(tmp_path, capsys):
    """The rename of an atomic write replaced /dev/full (run as root) with a regular file."""
    from ptoverify.cli import main

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    targets = [fifo] + [Path(p) for p in ("/dev/null", "/dev/full") if Path(p).exists()]
    for target in targets:
        before = target.lstat()
        assert main(["simulate", "--law", "pd", "--duration", "0.01", "--csv", str(target)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "not a regular file" in err and str(target) in err
        after = target.lstat()
        assert (after.st_mode, after.st_ino, after.st_rdev) == (
            before.st_mode,
            before.st_ino,
            before.st_rdev,
        )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo"]  # no temporary file left


@pytest.mark.parametrize(
    "shell, code",
    [
        ('"$0" -m ptoverify mintime 1 0 --json >&-', 0),  # stdout closed: was an internal error
        ('"$0" -m ptoverify zone --config /nonexistent.toml 2>&-', 2),  # stderr closed: was 1
        ('"$0" -m ptoverify mintime nan 0 >&- 2>&-', 2),
    ],
)
def test_a_stream_closed_before_the_run_keeps_the_exit_code(shell, code):
    """``>&-`` leaves sys.stdout/stderr None: the output is discarded, the verdict kept."""
    done = subprocess.run(["bash", "-c", shell, sys.executable], capture_output=True, timeout=60)
    assert done.returncode == code
    assert b"Traceback" not in done.stderr and b"internal error" not in done.stderr


def test_make_temp_on_a_full_disk_leaves_nothing(tmp_path, monkeypatch):
    """On a full disk the temporary folder fits but its marker does not: it was left behind."""
    import errno

    from ptoverify import outdir
    from ptoverify.errors import InputError

    real = Path.write_text

    def full(self, *args, **kwargs):
        if self.name == outdir.MARKER:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(InputError, match="ENOSPC"):
        outdir.make_temp(tmp_path / "out")
    assert list(tmp_path.iterdir()) == []
