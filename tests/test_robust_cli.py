"""``ptoverify robust`` through the command line: JSON contract, counterexamples, errors, Dask.

Every test goes through :func:`ptoverify.cli.main` only.  A small configuration
(a 5 mm envelope, so a short horizon) and a small grid keep a run near a second.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import socket

import pytest
from conftest import ROBUST_SMALL

from ptoverify.cli import main
from ptoverify.studies.robust import LAWS, PROPERTIES

SMALL = ROBUST_SMALL
FAST = ["--grid", "3", "--generations", "3", "--population", "8", "--quiet"]


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def small_config(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("robust") / "small.toml"
    path.write_text(SMALL)
    return str(path)


@pytest.fixture(scope="module")
def study(small_config) -> dict:
    """One in-process run of PTO and PD on the small box."""
    code, out, err = _run(["robust", "--config", small_config, "--law", "pto", "--law", "pd",
                           *FAST, "--json"])  # fmt: skip
    assert code == 0, err
    return json.loads(out)


def test_json_has_the_design_keys(study):
    assert {"box", "margins", "worst", "maps", "timings_s"} <= set(study)
    assert study["box"]["a_ratio"] == [0.9, 1.25] and study["box"]["delay_samples"] == [0, 1]
    assert set(study["margins"]) == set(study["worst"]) == {"pto", "pd"}
    maps = study["maps"]
    cells = len(maps["a_ratio"]) * len(maps["w_max_ratio"]) * len(maps["delay_samples"])
    assert maps["delay_samples"] == [0, 1] and maps["states"] == 9 + 20
    for law in ("pto", "pd"):
        assert len(maps["laws"][law]) == cells
        for prop in PROPERTIES:
            w = study["worst"][law][prop]
            assert {"grid", "searched", "state", "params"} <= set(w), (law, prop)
            # the search starts from the grid's worst cells: never below them
            assert w["unbounded"] or w["searched"] >= w["grid"], (law, prop, w)
            assert 0.9 <= w["params"]["a_ratio"] <= 1.25 and w["params"]["delay_samples"] in (0, 1)
    assert set(study["timings_s"]) >= {"maps", "margins", "worst_case", "total"}
    assert study["backend"] == "in-process"


def _reproduce(config: str, law: str, w: dict) -> dict:
    x1, x2 = w["state"]
    p = w["params"]
    argv = ["simulate", "--config", config, "--law", law, "--x0", repr(x1), repr(x2),
            "--a-ratio", repr(p["a_ratio"]), "--w-max-ratio", repr(p["w_max_ratio"]),
            "--delay", str(p["delay_samples"]), "--quantum", repr(p["position_quantum"]),
            "--velocity-noise", repr(p["velocity_noise"]), "--seed", str(p["seed"]),
            "--json"]  # fmt: skip
    code, out, err = _run(argv)
    assert code == 0, err
    return json.loads(out)["properties"]


def test_counterexamples_reproduce_exactly_with_simulate(small_config, study):
    """Each worst case's state and parameters, given to `simulate --x0`, give the same value."""
    found = 0
    for law in ("pto", "pd"):
        for prop in PROPERTIES:
            w = study["worst"][law][prop]
            props = _reproduce(small_config, law, w)
            if w["unbounded"]:  # never settles: simulate says so too (inf -> null in JSON)
                assert props[prop] is None, (law, prop, props)
            else:
                assert props[prop] == w["searched"], (law, prop, props[prop], w["searched"])
            found += bool(w["unbounded"] or (w["searched"] or 0) > 0)
    limit_cycle = study["worst"]["pto"]["limit_cycle_mm"]
    assert limit_cycle["searched"] > 0, "PTO limit-cycles in this box (delay 1, a_ratio 1.25)"
    assert found >= 3


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    "argv, says",
    [
        (["robust", "--grid", "0"], "--grid"),
        (["robust", "--grid", "2"], "--grid must be in [3, 101]"),
        (["robust", "--generations", "-1"], "--generations"),
        (["robust", "--population", "2"], "--population"),
        (["robust", "--law", "bang-bang"], "--law"),
        (["robust", "--dask", "my-cluster"], "--dask must be 'local' or a scheduler address"),
        (["simulate", "--law", "pd", "--a-ratio", "1.1"], "need --x0 (got --a-ratio)"),
        (["simulate", "--law", "pd", "--delay", "1"], "need --x0 (got --delay)"),
        (["simulate", "--law", "pd", "--x0", "1", "0", "--a-ratio", "0"], "--a-ratio"),
        (["simulate", "--law", "pd", "--x0", "1", "0", "--delay", "-1"], "--delay"),
    ],
)
def test_bad_command_line_exit_2_one_line(argv, says):
    code, out, err = _run(argv)
    assert code == 2 and out == "", (code, out)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:"), err
    assert says in lines[0], lines[0]


@pytest.mark.parametrize(
    "line, key",
    [
        ("a_ratio_typo = [0.9, 1.1]", "robustness.a_ratio_typo"),
        ("a_ratio = [1.1, 1.3]", "robustness.a_ratio"),
        ("w_max_ratio = [0.9, 1.2]", "robustness.w_max_ratio"),
        ("delay_samples = [0, 1.5]", "robustness.delay_samples"),
        ("seed = -1", "robustness.seed"),
    ],
)
def test_bad_robustness_key_exit_2_names_it(tmp_path, line, key):
    path = tmp_path / "bad.toml"
    path.write_text(SMALL.split("[robustness]")[0] + "[robustness]\n" + line + "\n")
    code, out, err = _run(["robust", "--config", str(path), *FAST, "--json"])
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and key in err, err


def test_unreachable_scheduler_is_exit_1_one_line(small_config, monkeypatch):
    """A well-formed address where nothing listens: the run failed (1), the input was fine (2).

    The connection's time box cut to 1 s (the command's is 3 s): what is tested is the
    failure's form, not the box's length (``test_cluster``)."""
    import ptoverify.studies.cluster as cluster_mod

    real = cluster_mod.connect
    monkeypatch.setattr(cluster_mod, "connect", lambda address, timeout=1.0: real(address, timeout))
    address = f"tcp://127.0.0.1:{_free_port()}"
    code, out, err = _run(["robust", "--config", small_config, "--law", "pd", *FAST,
                           "--dask", address, "--json"])  # fmt: skip
    assert code == 1 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error: cannot reach"), err
    assert address in lines[0] and "Traceback" not in err


def _without_run_facts(res: dict) -> dict:
    return {k: v for k, v in res.items() if k not in ("timings_s", "backend")}


@pytest.mark.slow
def test_dask_local_equals_in_process(small_config):
    argv = ["robust", "--config", small_config, "--law", "pto", "--law", "to", *FAST, "--json"]
    code, here, err = _run(argv)
    assert code == 0, err
    code, there, err = _run([*argv, "--dask", "local"])
    assert code == 0, err
    here, there = json.loads(here), json.loads(there)
    assert there["backend"] == "local"
    assert _without_run_facts(here) == _without_run_facts(there)


def test_every_law_is_studied_by_default(small_config):
    """Without --law all four laws are in the maps (a minimal search keeps it fast)."""
    code, out, err = _run(["robust", "--config", small_config, "--grid", "3", "--generations",
                           "0", "--population", "5", "--quiet", "--json"])  # fmt: skip
    assert code == 0, err
    res = json.loads(out)
    assert tuple(res["maps"]["laws"]) == LAWS == tuple(res["worst"])
    assert math.isfinite(res["timings_s"]["total"])


WIDEST_BOX = """\
[robustness]
a_ratio = [0.1, 10.0]
w_max_ratio = [0.05, 1.0]
delay_samples = [0, 10]
position_quantum = 5.0
velocity_noise = 300.0
"""


def test_the_widest_box_is_bad_input_at_once(tmp_path):
    """Audit R8: the widest box the loader accepts is refused before any simulation."""
    import time

    from ptoverify.config import load_config
    from ptoverify.studies.robust.maps import MAX_BOX_WORK, RobustSettings, horizon_steps

    path = tmp_path / "widest.toml"
    path.write_text(PAPER_PLANT + WIDEST_BOX)
    cfg = load_config(path)
    # the work counted independently: every a_ratio, w_max_ratio and delay of the maps
    s = RobustSettings()
    cells = s.n_a * s.n_w * 11
    assert cells * horizon_steps(cfg) > MAX_BOX_WORK
    t0 = time.perf_counter()
    code, out, err = _run(["robust", "--config", str(path), "--grid", "3", "--generations",
                           "0", "--population", "5", "--quiet", "--json"])  # fmt: skip
    assert time.perf_counter() - t0 < 10.0
    assert code == 2 and out == "", (code, out)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:"), err
    assert "robustness.delay_samples" in lines[0] and f"{MAX_BOX_WORK:,}" in lines[0], lines[0]


def test_report_refuses_the_widest_box_before_any_stage(tmp_path):
    """``report`` checks the box's work before its stages run: exit 2 at once, no folder."""
    import time

    path = tmp_path / "widest.toml"
    path.write_text(PAPER_PLANT + WIDEST_BOX)
    out = tmp_path / "rep"
    t0 = time.perf_counter()
    code, stdout, err = _run(["report", "--config", str(path), "--out", str(out), "--quiet"])
    assert time.perf_counter() - t0 < 10.0, "the stages ran before the refusal"
    assert code == 2 and "robustness.delay_samples" in err and len(err.splitlines()) == 1, err
    assert not out.exists()


PAPER_PLANT = SMALL.split("[robustness]")[0].replace(
    "position_range = 5.0", "position_range = 50.0"
)


def test_box_work_limit_admits_the_default_box_at_every_accepted_plant(tmp_path):
    """The limit's justification: the default box at the longest horizon the loader allows
    (range / (w_max T) = 2000 samples, a T = 0.01) is within it, and one delay more is not."""
    from ptoverify.config import load_config
    from ptoverify.errors import InputError
    from ptoverify.studies.robust.maps import (
        MAX_BOX_WORK,
        RobustSettings,
        box_work,
        check_box_work,
    )

    a = 2.0 * math.pi * 30.0
    T = 0.01 / a * (1 + 1e-9)
    R = 2000.0 * 300.0 * T * (1 - 1e-9)
    text = PAPER_PLANT.replace("sample_time = 0.002", f"sample_time = {T!r}").replace(
        "position_range = 50.0", f"position_range = {R!r}"
    )
    path = tmp_path / "longest.toml"
    path.write_text(text)
    cfg = load_config(path)  # accepted by the loader
    cells, horizon = box_work(cfg)
    assert cells == 30 and cells * horizon <= MAX_BOX_WORK
    check_box_work(cfg, RobustSettings())
    path.write_text(text + "[robustness]\ndelay_samples = [0, 2]\n")
    wider = load_config(path)
    assert box_work(wider)[0] * box_work(wider)[1] > MAX_BOX_WORK
    with pytest.raises(InputError, match="robustness.delay_samples"):
        check_box_work(wider)
