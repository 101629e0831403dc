import json
import subprocess
import sys
from pathlib import Path

import pytest

from ptoverify.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_mintime_json(capsys):
    code, out, err = run(capsys, "mintime", "5", "0", "--json")
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["x0"] == [5.0, 0.0]
    assert 0 < data["switch_time_s"] < data["analytic_s"]


@pytest.mark.parametrize(
    "argv",
    [
        ["mintime", "abc", "0"],
        ["mintime", "nan", "0"],
        ["mintime", "1", "inf"],
        ["mintime", "1"],
        ["mintime", "1e12", "0"],
        ["simulate", "--law", "nope"],
        ["simulate", "--signal", "square"],
        ["simulate", "--duration", "-1"],
        ["nosuchcommand"],
        [],
        ["mintime", "1", "0", "--config", "/nonexistent/file.toml"],
        # a seed outside [0, 2^32) (robustness.seed's range): -1 with noise was an internal error
        ["simulate", "--x0", "1", "0", "--velocity-noise", "1", "--seed", "-1"],
        ["simulate", "--x0", "1", "0", "--seed", str(2**80)],
        ["tune", "--law", "pd", "--seed", "-1"],
        ["tune", "--law", "pd", "--seed", str(2**32)],
        # prove options that were silently ignored (exit 0 after a full proof)
        ["prove", "--full"],
        ["prove", "--a-interval", ""],
        # an empty --emit-grid fell through to --law None: an internal error
        ["conform", "--emit-grid", ""],
        ["conform", "--table", " "],
    ],
)
def test_bad_input_exit_2_one_line(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:"), err


def test_bad_config_values(capsys, tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(
        'name = "x"\n[plant]\na = -1.0\nw_max = 1.0\nsample_time = 0.1\n'
        "position_range = 1.0\n[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\n"
        "k2 = 1.0\n"
    )
    code, _, err = run(capsys, "mintime", "1", "0", "--config", str(f))
    assert code == 2 and "plant.a" in err and len(err.strip().splitlines()) == 1


def test_simulate_csv(capsys, tmp_path):
    out_file = tmp_path / "pd.csv"
    code, out, _ = run(
        capsys, "simulate", "--law", "pd", "--signal", "ramp", "--csv", str(out_file)
    )
    assert code == 0
    lines = out_file.read_text().splitlines()
    assert lines[0] == "t,r,x1,x2,e,u,region" and len(lines) == 202


def test_simulate_csv_unwritable(capsys, tmp_path):
    code, _, err = run(
        capsys, "simulate", "--law", "pd", "--csv", str(tmp_path / "no" / "such" / "dir.csv")
    )
    assert code == 2 and "cannot write" in err
    assert not (tmp_path / "no").exists()


def test_simulate_json(capsys):
    code, out, _ = run(capsys, "simulate", "--law", "to", "--signal", "sine", "--json")
    data = json.loads(out)
    assert code == 0 and data["law"] == "to" and len(data["series"]["t"]) == 501


BAD_CONFIGS = {
    "not_toml": "this is [not toml",
    "unknown_key": "[plant]\na = 1.0\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n"
    "colour = 2.0\n[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n",
    "nan": "[plant]\na = nan\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n"
    "[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n",
    "non_numeric": '[plant]\na = "fast"\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n'
    "[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n",
    "out_of_range": "[plant]\na = 1.0\nw_max = 1.0\nsample_time = -0.1\nposition_range = 1.0\n"
    "[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n",
}


@pytest.mark.parametrize("kind", sorted(BAD_CONFIGS))
@pytest.mark.parametrize(
    "command",
    [
        ["report", "--quiet"],
        ["check"],
        ["sweep", "--quiet"],
        ["zone"],
        ["derive"],
        ["simulate"],
        ["mintime", "1", "0"],
    ],
)
def test_bad_config_every_command_exit_2_writes_nothing(
    capsys, tmp_path, monkeypatch, kind, command
):
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "bad.toml"
    cfg.write_text(BAD_CONFIGS[kind])
    extra = ["--out", str(tmp_path / "out")] if command[0] in ("report", "sweep") else []
    code = main([*command, "--config", str(cfg), *extra])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("ptoverify: error:")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"], "something was written"


def command_names(capsys) -> list[str]:
    """The commands as ``ptoverify --help`` lists them (tests use nothing of cli but main)."""
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    block = out.split("COMMAND\n", 1)[1].split("\n\n", 1)[0]
    return [line.split()[0] for line in block.splitlines() if line.startswith("    ")]


def test_every_command_help_has_an_example(capsys):
    names = command_names(capsys)
    assert "mintime" in names and "check" in names, names
    for name in names:
        with pytest.raises(SystemExit) as exc:
            main([name, "--help"])
        assert exc.value.code == 0
        assert "example" in capsys.readouterr().out.lower(), name


MORE_BAD = {
    "inf": ("w_max = 300.0", "w_max = inf"),
    "both_a_and_hz": ("bandwidth_hz = 30.0", "bandwidth_hz = 30.0\na = 3.0"),
    "d_negative": ("d = 0.5", "d = -0.5"),
    "d_beyond_range": ("d = 0.5", "d = 60.0"),
    "huge_w_max": ("w_max = 300.0", "w_max = 1e300"),
    "tiny_T": ("sample_time = 0.002", "sample_time = 1e-300"),
    "huge_T": ("sample_time = 0.002", "sample_time = 1e300"),
    "missing_section": ("[pd]\nkp = 356.0\nkd = 1.15\n", ""),
}
GOOD_TEXT = (
    'name = "x"\n[plant]\nbandwidth_hz = 30.0\nw_max = 300.0\nsample_time = 0.002\n'
    "position_range = 50.0\n[pd]\nkp = 356.0\nkd = 1.15\n[pto]\nd = 0.5\nk1 = 323.0\n"
    "k2 = 3.6\n"
)


@pytest.mark.parametrize("kind", sorted(MORE_BAD))
def test_more_bad_configs_in_a_subprocess_no_traceback(tmp_path, kind):
    """A real process: one line on stderr, exit 2, no traceback, for each class."""
    import subprocess
    import sys

    old, new = MORE_BAD[kind]
    assert old in GOOD_TEXT
    cfg = tmp_path / "c.toml"
    cfg.write_text(GOOD_TEXT.replace(old, new))
    proc = subprocess.run(
        [sys.executable, "-m", "ptoverify", "simulate", "--law", "pd", "--config", str(cfg)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("path", ["/dev/zero", ".", ""])
def test_config_that_is_not_a_file(capsys, path):
    assert main(["mintime", "1", "0", "--config", path]) == 2
    assert capsys.readouterr().err.startswith("ptoverify: error: config file")


@pytest.mark.parametrize("x1", ["-1e2", "-5.", "-.5", "-5"])
def test_negative_float_positionals(capsys, x1):
    assert main(["mintime", x1, "0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["x0"][0] == float(x1)


def test_out_refuses_to_replace_a_foreign_folder(capsys, tmp_path):
    victim = tmp_path / "thesis"
    victim.mkdir()
    (victim / "thesis.tex").write_text("precious")
    code = main(["sweep", "--grid", "2", "--quiet", "--out", str(victim)])
    assert code == 2 and "not a ptoverify output" in capsys.readouterr().err
    assert (victim / "thesis.tex").read_text() == "precious"


def test_out_replaces_its_own_previous_output(capsys, tmp_path):
    out = tmp_path / "a" / "b" / "sweep"
    # one law: the replacement of a folder is what is tested, not the sweep's figures
    assert main(["sweep", "--grid", "2", "--law", "pd", "--quiet", "--out", str(out)]) == 0
    first = sorted(p.name for p in out.iterdir())
    assert ".ptoverify" in first and "sweep.json" in first
    assert main(["sweep", "--grid", "3", "--law", "pd", "--quiet", "--out", str(out)]) == 0
    assert json.loads((out / "sweep.json").read_text())["grid"]["states"] == 9
    assert sorted(p.name for p in out.parent.iterdir()) == ["sweep"], "leftovers"


def test_empty_csv_and_short_duration_rejected(capsys):
    assert main(["simulate", "--law", "pd", "--csv", ""]) == 2
    assert main(["simulate", "--law", "pd", "--duration", "1e-9"]) == 2


def test_mintime_converged_but_inaccurate_ocp_is_not_truth(capsys):
    """At a state of 1e-300 mm IPOPT 'succeeds' at the scale of its tolerance; the a posteriori
    propagation check reports null with an 'inaccurate' status, never a number."""
    assert main(["mintime", "1e-300", "1e-300", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["analytic_s"] > 0
    assert data["two_phase_s"] is None and data["two_phase_status"].startswith("inaccurate")


def test_internal_error_is_exit_1_one_line_not_bad_input(capsys, monkeypatch):
    """An injected bug in a numeric function is an internal error (exit 1), not exit 2."""
    import ptoverify.studies.groundtruth as gt

    def broken(*args, **kwargs):
        return 1 / 0

    monkeypatch.setattr(gt, "min_time", broken)
    code, out, err = run(capsys, "mintime", "5", "0", "--json")
    assert code == 1 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("ptoverify: internal error: ZeroDivisionError: division by zero")
    assert "--debug" in lines[0] and "Traceback" not in err


@pytest.mark.parametrize(
    "signal_exc, code, words",
    [(KeyboardInterrupt, 130, "interrupted"), ("terminated", 143, "terminated (SIGTERM)")],
)
def test_an_import_failed_by_a_signal_is_the_signal(capsys, monkeypatch, signal_exc, code, words):
    """Ctrl-C or SIGTERM while a compiled module initializes comes back as its ImportError
    (pybind11's "initialization failed", the signal its cause): the run was stopped (130, 143),
    not an internal error; a chain without a signal stays an internal error."""
    import ptoverify.studies.groundtruth as gt
    from ptoverify.outdir import Terminated

    cause = Terminated() if signal_exc == "terminated" else signal_exc()

    def stopped(*args, **kwargs):
        try:
            raise cause
        except BaseException as exc:
            raise ImportError("initialization failed") from exc

    monkeypatch.setattr(gt, "min_time", stopped)
    got, out, err = run(capsys, "mintime", "5", "0", "--json")
    assert (got, out, err) == (
        code,
        "",
        f"ptoverify: error: {words}" + ("; nothing written\n" if code == 143 else "\n"),
    )

    def unrelated(*args, **kwargs):
        try:
            raise ValueError("a bug's first error")
        except ValueError as exc:
            raise ImportError("initialization failed") from exc

    monkeypatch.setattr(gt, "min_time", unrelated)
    got, _, err = run(capsys, "mintime", "5", "0", "--json")
    assert got == 1 and err.startswith("ptoverify: internal error: ImportError"), err


def test_ctrl_c_inside_source_text_exec_is_exit_130(tmp_path):
    """Ctrl-C that lands inside code run from source text (``exec`` of a string, as
    ``dataclasses`` does at every import) is exit 130 under ``python -m`` too.

    CPython remembers a plain KeyboardInterrupt that ends a string's code, even when it
    is caught, and a ``-m`` run then dies by SIGINT (returncode -2) after its handler
    printed and returned 130: the report's Ctrl-C test saw it about once in ten runs.
    A real SIGINT, raised by the process itself while a string is executed."""
    code = (
        "import os, signal, sys\n"
        "import importlib\n"
        "m = importlib.import_module('ptoverify.cli.main')\n"
        "def handler(args):\n"
        "    exec('import os, signal\\nos.kill(os.getpid(), signal.SIGINT)\\n'"
        " + 'for _ in range(10**6): pass\\n', {})\n"
        "    return 0\n"
        "class P:\n"
        "    def parse_args(self, argv):\n"
        "        import argparse\n"
        "        return argparse.Namespace(handler=handler, debug=False)\n"
        "m.build_parser = P\n"
        "sys.exit(m.main(['mintime', '0', '0']))\n"
    )
    (tmp_path / "fake_cli.py").write_text(code)
    proc = subprocess.run(
        [sys.executable, "-m", "fake_cli"], capture_output=True, text=True, cwd=tmp_path, timeout=60
    )
    assert proc.returncode == 130, (proc.returncode, proc.stderr)
    assert proc.stderr == "ptoverify: error: interrupted\n"


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_shows_the_traceback(capsys, monkeypatch, where):
    import ptoverify.studies.groundtruth as gt

    monkeypatch.setattr(gt, "min_time", lambda *a, **k: 1 / 0)
    argv = ["mintime", "5", "0"]
    argv = ["--debug", *argv] if where == "before" else [*argv, "--debug"]
    with pytest.raises(ZeroDivisionError):
        main(argv)


def test_debug_in_a_subprocess_prints_a_traceback(tmp_path):
    """A real process: without --debug one line, with it the traceback; exit 1 both ways."""
    import subprocess
    import sys

    code = (
        "import sys, ptoverify.studies.groundtruth as g\n"
        "g.min_time = lambda *a, **k: 1 / 0\n"
        "from ptoverify.cli import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    for flag, want_trace in (([], False), (["--debug"], True)):
        proc = subprocess.run(
            [sys.executable, "-c", code, *flag, "mintime", "5", "0"],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert proc.returncode == 1, proc.stderr
        assert ("Traceback" in proc.stderr) == want_trace, proc.stderr
        assert "ZeroDivisionError" in proc.stderr


def test_version(capsys):
    import re

    import ptoverify

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out == f"ptoverify {ptoverify.__version__}\n"
    assert re.fullmatch(r"\d+\.\d+\.\d+", ptoverify.__version__)


def test_usage_error_has_one_prefix(capsys):
    code, out, err = run(capsys, "mintime", "1", "2", "--intervals", "many")
    assert code == 2 and out == ""
    assert err.startswith("ptoverify: error: mintime: ") and "ptoverify mintime" not in err


def test_cli_imports_no_solver_and_no_simulator():
    """The cli package parses, calls and formats: it imports no solver, simulator or law
    directly (its modules' imports of each other's helpers aside)."""
    import ast
    from pathlib import Path

    import ptoverify

    files = sorted((Path(ptoverify.__file__).parent / "cli").glob("*.py"))
    assert len(files) > 2, "the cli package and its modules"
    names = set()
    for node in (n for f in files for n in ast.walk(ast.parse(f.read_text()))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f"{node.module}.{a.name}" for a in node.names)
    forbidden = {
        "casadi",
        "scipy",
        "ptoverify.model.ocp",
        "ptoverify.sim.simulate",
        "ptoverify.model.mintime",
        "ptoverify.model.plant",
        "ptoverify.studies.properties",
        "ptoverify.model.zones",
    }
    assert not names & forbidden, names & forbidden
    private = [n for n in names if n.rsplit(".", 1)[-1][:1] == "_" and "__" not in n]
    assert not private, private


def test_building_the_parser_loads_no_numerics():
    """The command line is parsed before any worker starts: it must not pay for SciPy or the laws."""
    import subprocess
    import sys

    code = (
        "import sys\nfrom ptoverify.cli import build_parser\n"
        "build_parser().parse_args(['report', '--jobs', '2'])\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('scipy', 'ptoverify')"
        " and m in ('scipy', 'ptoverify.model.laws', 'ptoverify.model.curves')))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


# ------------------------------------------------------------------ OS errors and file modes
def _subprocess(argv, stdout=subprocess.PIPE, timeout=120):
    import os
    import subprocess as sp
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    return sp.run(
        [sys.executable, "-m", "ptoverify", *argv],
        stdout=stdout,
        stderr=sp.PIPE,
        text=True,
        timeout=timeout,
        env=dict(os.environ, PYTHONPATH=str(root)),
    )


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize(
    "argv",
    [["mintime", "5", "0", "--json"], ["zone"], ["simulate", "--law", "pd"]],
    ids=lambda a: a[0],
)
def test_stdout_on_a_full_device_is_exit_2_naming_it(argv):
    with open("/dev/full", "w") as full:
        p = _subprocess(argv, stdout=full)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2, p.stderr
    assert lines == ["ptoverify: error: cannot write 'standard output': No space left on "
                     "device (ENOSPC)"], p.stderr  # fmt: skip


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "--law", "pd", "--csv", "{long}.csv"],
        ["conform", "--emit-grid", "{long}.csv"],
        ["report", "--out", "{long}"],
        ["sweep", "--out", "{long}"],
        ["report", "--out", "{deep}"],
    ],
    ids=["csv", "emit-grid", "report", "sweep", "path-max"],
)
def test_overlong_names_are_exit_2_naming_the_file(capsys, tmp_path, argv):
    long = str(tmp_path / ("n" * 300))
    deep = str(tmp_path / "/".join(["d" * 250] * 20))  # beyond PATH_MAX (4096)
    argv = [a.format(long=long, deep=deep) for a in argv]
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "", err
    assert err.count("\n") == 1 and "File name too long (ENAMETOOLONG)" in err, err
    assert "nnnnnnnnnn" in err or "dddddddddd" in err, "the file is named"
    assert list(tmp_path.iterdir()) == []


def test_environment_os_error_without_a_file_names_the_output(capsys, monkeypatch, tmp_path):
    """ENOSPC deep inside a writer (no file name on the error) names the output option."""
    import errno

    import ptoverify.commands as commands

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(commands, "mintime_states", full)
    states = tmp_path / "s.csv"
    states.write_text("x1,x2\n1,0\n")
    code, out, err = run(capsys, "mintime", "--states", str(states), "--out", "o.csv")
    assert code == 2 and out == ""
    assert (
        err.strip()
        == "ptoverify: error: cannot write '--out o.csv': No space left on device (ENOSPC)"
    )


def test_other_os_errors_stay_internal_errors(capsys, monkeypatch):
    """Only the environment's errors (ENOSPC, ENAMETOOLONG, EACCES, ...) are exit 2."""
    import errno

    import ptoverify.studies.groundtruth as gt

    def bug(*args, **kwargs):
        raise OSError(errno.EBADF, "Bad file descriptor")

    monkeypatch.setattr(gt, "min_time", bug)
    code, out, err = run(capsys, "mintime", "5", "0")
    assert code == 1 and err.startswith("ptoverify: internal error: OSError")


@pytest.fixture
def umask_022():
    import os

    old = os.umask(0o022)
    yield
    os.umask(old)


@pytest.mark.parametrize(
    "argv",
    [
        ["conform", "--emit-grid", "{f}"],
        ["simulate", "--law", "pd", "--csv", "{f}"],
        ["simulate", "--law", "pd", "--x0", "1", "0", "--csv", "{f}"],
        ["check", "--gate", "zoh-vs-integrator", "--junit", "{f}"],
    ],
    ids=["emit-grid", "csv", "csv-x0", "junit"],
)
def test_written_files_respect_the_umask(capsys, tmp_path, umask_022, argv):
    f = tmp_path / "out.file"
    code, _, err = run(capsys, *[a.format(f=f) for a in argv])
    assert code in (0, 1), err
    assert oct(f.stat().st_mode & 0o777) == oct(0o644), "mode is 0666 less the umask 022"
    assert [p.name for p in tmp_path.iterdir()] == ["out.file"], "no temporary left"


@pytest.mark.parametrize("cmd", [["check"], ["conform", "--table", "t.csv"]])
def test_junit_under_a_file_names_it_as_no_folder(capsys, tmp_path, cmd):
    """Audit run 7: ``--junit afile/j.xml`` with ``afile`` a file said "does not exist"."""
    (tmp_path / "afile").write_text("x")
    code, out, err = run(capsys, *cmd, "--junit", str(tmp_path / "afile" / "j.xml"))
    err = err.strip().splitlines()
    assert code == 2 and out == "" and len(err) == 1
    assert "is not a folder" in err[0] and (tmp_path / "afile").read_text() == "x"


@pytest.mark.parametrize(
    "extra",
    [["--junit", "{d}/j.xml"], ["--tolerance", "1e-3"], ["--robust"], ["--delay", "1"]],
    ids=["junit", "tolerance", "robust", "delay"],
)
def test_emit_grid_refuses_options_that_judge_nothing(capsys, tmp_path, extra):
    """Audit run 7: ``--emit-grid`` with ``--junit`` or ``--tolerance`` ended 0, the option
    ignored (no JUnit file); with ``--robust`` the message spoke of a table."""
    extra = [a.format(d=tmp_path) for a in extra]
    code, out, err = run(capsys, "conform", "--emit-grid", str(tmp_path / "g.csv"), *extra)
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1, err
    assert "--emit-grid writes the probe set only" in lines[0], err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["mintime", "--states", "{d}/s.csv", "--intervals", "50"], "--intervals"),
        (["prove", "--check", "{d}/c.npz", "--law", "pd"], "--law"),
        (["prove", "--check", "{d}/c.npz", "--a-interval", "0.9,1.1"], "--a-interval"),
        (["prove", "--check", "{d}/c.npz", "--out", "{d}/pr"], "--out"),
        (["prove", "--check", "{d}/c.npz", "--excursion", "1"], "--excursion"),
    ],
    ids=["mintime-states-intervals", "check-law", "check-a-interval", "check-out", "check-exc"],
)
def test_options_a_mode_ignores_are_bad_input(capsys, tmp_path, argv, flag):
    """Audit run 7: these options were accepted and ignored (exit 0, nothing of them done)."""
    (tmp_path / "s.csv").write_text("x1,x2\n1,0\n")
    (tmp_path / "c.npz").write_bytes(b"")
    before = sorted(p.name for p in tmp_path.iterdir())
    code, out, err = run(capsys, *[a.format(d=tmp_path) for a in argv])
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1 and flag in lines[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
