"""README.md against the code: the set-up commands, commands and options, gates, the equations
``derive`` judges, paths, the git-ignored main-job folder, the configuration ranges."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_ci_runs_the_readme_test_command():
    block = re.search(r"```bash\n(.*?)```", README, re.S).group(1)
    commands = [ln for ln in block.splitlines() if ln and not ln.startswith("#")]
    assert len(commands) == 2, "README opens with exactly two set-up commands"
    assert commands[0].endswith("ptoverify report --out build/report")
    assert commands[1] in (ROOT / ".ci" / "run").read_text()


@pytest.mark.skipif(shutil.which("git") is None, reason="git not installed")
def test_main_job_writes_an_ignored_folder():
    probe = subprocess.run(
        ["git", "-C", str(ROOT), "check-ignore", "-q", "build/report/index.html"],
        capture_output=True,
    )
    if probe.returncode == 128:
        pytest.skip(f"not a git checkout: {probe.stderr.decode().strip()}")
    assert probe.returncode == 0, "build/report/ must be ignored by git (the clone stays clean)"
    tracked = subprocess.run(
        ["git", "-C", str(ROOT), "check-ignore", "-q", "reports/paper/index.html"]
    )
    assert tracked.returncode == 1, "the committed report must not be ignored"


def test_readme_documents_every_command_and_gate(capsys):
    import pytest

    from ptoverify.cli import main
    from ptoverify.studies.checks import GATES

    with pytest.raises(SystemExit):
        main(["--help"])
    block = capsys.readouterr().out.split("COMMAND\n", 1)[1].split("\n\n", 1)[0]
    commands = [line.split()[0] for line in block.splitlines() if line.startswith("    ")]
    assert len(commands) >= 8, commands
    for name in commands:
        assert f"`ptoverify {name}" in README, name
    for gate in GATES:
        assert f"`{gate}`" in README, gate


def _subparsers():
    import argparse

    from ptoverify.cli import build_parser

    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return parser, action.choices


def test_every_option_the_readme_names_exists():
    """Each `ptoverify CMD ...` snippet: CMD exists and each --option is in its --help."""
    parser, subs = _subparsers()
    snippets = re.findall(r"`(ptoverify [^`]+)`", README)
    assert len(snippets) > 15
    checked = 0
    for snip in snippets:
        words = snip.split()
        cmd = words[1]
        if cmd == "COMMAND":  # the placeholder: every command
            options = set.intersection(
                *({o for a in p._actions for o in a.option_strings} for p in subs.values())
            )
        elif cmd.startswith("-"):
            options = {o for a in parser._actions for o in a.option_strings}
        else:
            assert cmd in subs, f"README names unknown command {cmd!r} in `{snip}`"
            options = {o for a in subs[cmd]._actions for o in a.option_strings}
        for opt in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", snip):
            assert opt in options, f"`{snip}`: {cmd} has no option {opt}"
            checked += 1
    # bare options in prose, e.g. `--no-feedforward`, exist in some command
    every = {o for p in subs.values() for a in p._actions for o in a.option_strings}
    every |= {o for a in parser._actions for o in a.option_strings}
    for opt in re.findall(r"`(--[a-z][a-z0-9-]*)", README):
        assert opt in every, opt
    assert checked > 20


def test_equation_range_is_what_derive_judges():
    from derivations.printed import PRINTED

    numbers = sorted(int(k) for k in PRINTED if k.isdigit())
    m = re.search(r"re-derivation of eqs\. \((\d+)\)-\((\d+)\)", README)
    assert m, "README states the equations derive covers"
    assert (int(m.group(1)), int(m.group(2))) == (numbers[0], numbers[-1])
    assert numbers == list(range(numbers[0], numbers[-1] + 1)), "a gap in the catalogue"


def test_paths_resolve_inside_the_repository():
    assert "../" not in README, "links outside the repository (the paper is not in it)"
    targets = re.findall(r"\]\(([^)#]+)\)", README)  # links and images
    tokens = re.findall(
        r"`((?:examples|tests|ptoverify|derivations|reports/paper|\.ci)/[\w./-]*)`", README
    )
    assert targets and tokens
    for rel in targets + tokens:
        if rel.startswith(("http://", "https://")):
            continue
        path = (ROOT / rel).resolve()
        assert path.is_relative_to(ROOT), rel
        assert path.exists(), f"README names {rel}, which does not exist"


def test_configuration_ranges_match_the_loader():
    from ptoverify.config import LIMITS

    text = " ".join(README.split())

    def num(pattern):
        m = re.search(pattern, text)
        assert m, pattern
        return float(m.group(1))

    assert num(r"kp T, k1 T <= (\d[\d.]*(?:e[+-]?\d+)?)") == LIMITS["gain_T"]
    assert num(r"kd, k2 <= (\d[\d.]*(?:e[+-]?\d+)?)") == LIMITS["gain"]
    assert num(r"(\d[\d.]*(?:e[+-]?\d+)?) <= sample_time") == LIMITS["sample_time"][0]
    assert num(r"sample_time <= (\d[\d.]*(?:e[+-]?\d+)?) s") == LIMITS["sample_time"][1]
    assert num(r"with (\d[\d.]*(?:e[+-]?\d+)?) <= a T") == LIMITS["aT"][0]
    assert num(r"a T <= (\d[\d.]*(?:e[+-]?\d+)?);") == LIMITS["aT"][1]
    bound = num(r"a, w_max, position_range <= (\d[\d.]*(?:e[+-]?\d+)?)")
    assert all(LIMITS[k] == bound for k in ("a", "w_max", "position_range"))
