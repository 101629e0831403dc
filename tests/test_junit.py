"""JUnit XML: one testcase per gate/property, failures carry the figures, unverified fails."""

import json
import xml.etree.ElementTree as ET
from pathlib import Path

from ptoverify.cli import main
from ptoverify.conform.junit import conform_verdicts, junit_xml
from ptoverify.verdict import Verdict


def _cases(xml_text):
    root = ET.fromstring(xml_text)
    suite = root.find("testsuite")
    out = {}
    for tc in suite.findall("testcase"):
        kids = list(tc)
        out[tc.get("name")] = (kids[0].tag, kids[0].get("message"), kids[0].text) if kids else None
    return root, suite, out


def test_every_status_maps_and_nothing_unverified_passes():
    verdicts = [
        Verdict("good", "pass", 0.0, 1.0, "fine", "<=", "mm"),
        Verdict("bad", "fail", 2.5, 1.0, "too big", "<=", "mm/s"),
        Verdict("lost", "unverified", None, 1.0, "solver failed"),
        Verdict("skipped", "not_run", None, None, "not run"),
    ]
    xml = junit_xml(verdicts, "suite", {"bad": (1.25, -300.0)}, {"config": "paper"})
    root, suite, cases = _cases(xml)
    assert list(cases) == ["good", "bad", "lost", "skipped"]
    assert cases["good"] is None
    tag, msg, text = cases["bad"]
    assert tag == "failure" and text == "too big"
    for part in ("2.5 mm/s", "<= 1 mm/s", "1.25 mm", "-300 mm/s"):
        assert part in msg, (part, msg)
    assert cases["lost"][0] == "error" and cases["skipped"][0] == "error"
    assert suite.get("tests") == "4" and suite.get("failures") == "1"
    assert suite.get("errors") == "2" and suite.get("skipped") == "0"
    assert suite.find("properties/property").get("value") == "paper"
    assert root.get("tests") == "4"


def test_check_junit_matches_json(tmp_path, capsys):
    out = tmp_path / "check.xml"
    gates = ["pd-sampled-stable", "linear-zone-sampled-stable"]
    args = ["check", "--json", "--junit", str(out)] + [x for g in gates for x in ("--gate", g)]
    code = main(args)
    checks = json.loads(capsys.readouterr().out)["checks"]
    _, suite, cases = _cases(out.read_text())
    assert list(cases) == [c["name"] for c in checks]
    for c in checks:
        assert (cases[c["name"]] is None) == (c["status"] == "pass"), c
    assert code == (0 if all(c["status"] == "pass" for c in checks) else 1)


def test_check_junit_failing_config(tmp_path, capsys):
    from ptoverify.config import paper_config

    cfg = paper_config()
    toml = tmp_path / "unstable.toml"
    text = (
        'name = "unstable"\n[plant]\nbandwidth_hz = 30.0\nw_max = 300.0\n'
        "sample_time = 0.002\nposition_range = 50.0\n[pd]\nkp = 5000.0\nkd = 1.15\n"
        f"[pto]\nd = {cfg.pto.d}\nk1 = 5000.0\nk2 = 3.6\n"
    )
    toml.write_text(text)
    out = tmp_path / "check.xml"
    code = main(
        ["check", "--config", str(toml), "--gate", "pd-sampled-stable", "--junit", str(out)]
    )
    capsys.readouterr()
    _, suite, cases = _cases(out.read_text())
    assert code == 1 and cases["pd-sampled-stable"][0] == "failure"
    assert "required < 1" in cases["pd-sampled-stable"][1]


def test_junit_path_checked_before_computing(tmp_path, capsys):
    assert main(["check", "--junit", str(tmp_path / "nope" / "x.xml")]) == 2
    assert main(["check", "--junit", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all("--junit" in e for e in err)


def test_conform_verdicts_carry_regions_properties_and_states():
    result = {
        "conforms": False,
        "agreement": {
            "tolerance_mm_s": 3e-4,
            "regions": {
                "BANG_P": {
                    "points": 10,
                    "excluded": 0,
                    "max_abs_du": 15.0,
                    "pass": False,
                    "state": [30.5, -100.0],
                },
                "LINEAR": {
                    "points": 10,
                    "excluded": 0,
                    "max_abs_du": 0.0,
                    "pass": True,
                    "state": [0.1, 0.0],
                },
            },
        },
        "properties": {
            "odd-symmetry": {"status": "pass", "measured": 0.0, "limit": 3e-4, "detail": "ok"},
            "no-limit-cycle": {
                "status": "unverified",
                "measured": None,
                "limit": 0,
                "detail": "crashed",
            },
        },
        "failures": [{"property": "no-limit-cycle", "state": [1.0, 2.0], "detail": "x"}],
    }
    verdicts, states = conform_verdicts(result)
    by = {v.name: v for v in verdicts}
    assert by["agreement/BANG_P"].status == "fail" and states["agreement/BANG_P"] == [30.5, -100.0]
    assert by["agreement/LINEAR"].passed and "agreement/LINEAR" not in states
    assert by["no-limit-cycle"].status == "unverified" and states["no-limit-cycle"] == [1.0, 2.0]
    _, suite, cases = _cases(junit_xml(verdicts, "ptoverify.conform.gate", states))
    assert cases["agreement/BANG_P"][0] == "failure" and "30.5 mm" in cases["agreement/BANG_P"][1]
    assert cases["no-limit-cycle"][0] == "error"
    # a negative result that no property carries is still a red suite
    quiet = {**result, "agreement": {"regions": {}, "pass": True}, "properties": {}}
    v2, _ = conform_verdicts(quiet)
    assert any(not v.passed for v in v2)


def test_not_run_is_skipped_only_when_asked():
    v = [
        Verdict("a", "pass", 0.0, 1.0, ""),
        Verdict("cl", "not_run", None, None, "needs a callable"),
    ]
    _, suite, cases = _cases(junit_xml(v, "s"))
    assert cases["cl"][0] == "error" and suite.get("errors") == "1"
    _, suite, cases = _cases(junit_xml(v, "s", skip_not_run=True))
    assert (
        cases["cl"][0] == "skipped" and suite.get("errors") == "0" and suite.get("skipped") == "1"
    )


def test_junit_unwritable_folder_refused_before_any_gate(monkeypatch, capsys):
    # /sys refuses new files even to root (os.access would say yes to root): the probe
    # must really create one; no gate may run first (audit run 7: 18 s of gates, then exit 2)
    import ptoverify.studies.checks as checks

    def no_gates(*a, **k):
        raise AssertionError("a gate ran before the --junit folder was probed")

    monkeypatch.setattr(checks, "run_checks", no_gates)
    assert main(["check", "--junit", "/sys/ptoverify-junit.xml"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "/sys/ptoverify-junit.xml" in err[0]
    assert not Path("/sys/ptoverify-junit.xml").exists()
