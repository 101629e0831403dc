"""README and CI agree: .ci/run runs exactly the README's test command."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text()
    block = re.search(r"```bash\n(.*?)```", readme, re.S).group(1)
    commands = [ln for ln in block.splitlines() if ln and not ln.startswith("#")]
    assert len(commands) == 2, "README opens with exactly two set-up commands"
    assert commands[0].endswith("ptoverify report")
    assert commands[1] in (ROOT / ".ci" / "run").read_text()


def test_readme_documents_every_command_and_gate(capsys):
    import pytest

    from ptoverify.checks import GATES
    from ptoverify.cli import main

    with pytest.raises(SystemExit):
        main(["--help"])
    block = capsys.readouterr().out.split("COMMAND\n", 1)[1].split("\n\n", 1)[0]
    commands = [line.split()[0] for line in block.splitlines() if line.startswith("    ")]
    assert len(commands) >= 8, commands
    readme = (ROOT / "README.md").read_text()
    for name in commands:
        assert f"`ptoverify {name}" in readme, name
    for gate in GATES:
        assert f"`{gate}`" in readme, gate
