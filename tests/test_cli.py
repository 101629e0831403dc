import json

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


@pytest.mark.parametrize("argv", [
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
])
def test_bad_input_exit_2_one_line(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:"), err


def test_bad_config_values(capsys, tmp_path):
    f = tmp_path / "c.toml"
    f.write_text('name = "x"\n[plant]\na = -1.0\nw_max = 1.0\nsample_time = 0.1\n'
                 'position_range = 1.0\n[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\n'
                 'k2 = 1.0\n')
    code, _, err = run(capsys, "mintime", "1", "0", "--config", str(f))
    assert code == 2 and "plant.a" in err and len(err.strip().splitlines()) == 1


def test_simulate_csv(capsys, tmp_path):
    out_file = tmp_path / "pd.csv"
    code, out, _ = run(capsys, "simulate", "--law", "pd", "--signal", "ramp", "--csv",
                       str(out_file))
    assert code == 0
    lines = out_file.read_text().splitlines()
    assert lines[0] == "t,r,x1,x2,e,u,region" and len(lines) == 202


def test_simulate_csv_unwritable(capsys, tmp_path):
    code, _, err = run(capsys, "simulate", "--law", "pd", "--csv",
                       str(tmp_path / "no" / "such" / "dir.csv"))
    assert code == 2 and "cannot write" in err
    assert not (tmp_path / "no").exists()


def test_simulate_json(capsys):
    code, out, _ = run(capsys, "simulate", "--law", "to", "--signal", "sine", "--json")
    data = json.loads(out)
    assert code == 0 and data["law"] == "to" and len(data["series"]["t"]) == 501


BAD_CONFIGS = {
    "not_toml": "this is [not toml",
    "unknown_key": '[plant]\na = 1.0\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n'
                   'colour = 2.0\n[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n',
    "nan": '[plant]\na = nan\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n'
           '[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n',
    "non_numeric": '[plant]\na = "fast"\nw_max = 1.0\nsample_time = 0.1\nposition_range = 1.0\n'
                   '[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n',
    "out_of_range": '[plant]\na = 1.0\nw_max = 1.0\nsample_time = -0.1\nposition_range = 1.0\n'
                    '[pd]\nkp = 1.0\nkd = 1.0\n[pto]\nd = 0.1\nk1 = 1.0\nk2 = 1.0\n',
}


@pytest.mark.parametrize("kind", sorted(BAD_CONFIGS))
@pytest.mark.parametrize("command", [["report", "--quiet"], ["check"], ["sweep", "--quiet"],
                                     ["zone"], ["derive"], ["simulate"], ["mintime", "1", "0"]])
def test_bad_config_every_command_exit_2_writes_nothing(capsys, tmp_path, monkeypatch, kind,
                                                        command):
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "bad.toml"
    cfg.write_text(BAD_CONFIGS[kind])
    extra = ["--out", str(tmp_path / "out")] if command[0] in ("report", "sweep") else []
    code = main([*command, "--config", str(cfg), *extra])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith("ptoverify: error:")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"], "something was written"


def test_every_command_help_has_an_example(capsys):
    from ptoverify.cli import COMMANDS

    for name, _ in COMMANDS:
        with pytest.raises(SystemExit) as exc:
            main([name, "--help"])
        assert exc.value.code == 0
        assert "example:" in capsys.readouterr().out, name
