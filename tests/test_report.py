"""The report: atomic, reproducible, escaped, renders in a browser, and the committed
``reports/paper/results.json`` matches a fresh computation."""

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.report.collect import SKIPPABLE, write_report
from ptoverify.report.render import Block, render_html

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def two_reports(tmp_path_factory):
    """A full report in a pool of two processes, and the quick report (``skip`` robust,
    tuning, charts) rendered from its results.

    The sections read results.json alone, so the quick folder is the full run's
    results with the skipped stages' keys null, their gates left out and the gate
    counts recounted, rendered as ``write_report`` renders (one report computed, not
    two).  That results do not depend on the process layout is checked against the
    committed report, computed in one process (``--jobs 1``):
    :func:`test_committed_report_matches_fresh_computation`."""
    base = tmp_path_factory.mktemp("rep")
    full = write_report(paper_config(), base / "one", jobs=2)
    return full, _quick_from(full, base / "two")


def _quick_from(full: Path, out: Path) -> Path:
    """Render the report ``report --skip robust,tuning,charts`` writes, from ``full``'s results."""
    import derivations
    from ptoverify.report.collect import build_sections, render_pages, results_view
    from ptoverify.studies.checks import ROBUST_GATES

    data = json.loads((full / "results.json").read_text())
    for key in SKIPPABLE:
        data[key] = None
    data["skipped"] = sorted(SKIPPABLE)
    data["checks"] = [c for c in data["checks"] if c["name"] not in ROBUST_GATES]

    def count(checks):
        n = {s: sum(c["status"] == s for c in checks) for s in ("pass", "fail", "unverified")}
        return {"total": len(checks), **n, "ok": n["pass"] == len(checks)}

    data["summary"].update(
        gates=count(data["checks"]), gates_nominal=count(data["checks"]), gates_perturbed=count([])
    )
    out.mkdir()
    shutil.copytree(full / "figures", out / "figures")
    figures = {Path(f).stem: f for f in data["meta"]["figures"]}
    records = [derivations.EquationRecord.from_json(r) for r in data["derivations"]]
    sections = build_sections(results_view(data), figures, records)
    page, md = render_pages(sections, "quick", data["meta"]["traces"])
    (out / "results.json").write_text(json.dumps(data, indent=1, sort_keys=True))
    (out / "index.html").write_text(page)
    (out / "report.md").write_text(md)
    return out


def _without_meta(path: Path) -> dict:
    data = json.loads((path / "results.json").read_text())
    data["meta"].pop("generated")
    return data


@pytest.mark.slow
def test_report_folder_complete_and_reproducible(two_reports):
    one, two = two_reports
    for f in ("index.html", "report.md", "results.json"):
        assert (one / f).stat().st_size > 1000, f
    figs = sorted((one / "figures").glob("*.png"))
    assert len(figs) >= 20 and all(f.stat().st_size > 5000 for f in figs)
    # the paper's figures 2 to 14 and the zone's geometry, each a readable size
    nums = {int(f.name[3:5]) for f in figs if f.name.startswith("fig")}
    assert nums == set(range(2, 15)), f"figures written: {sorted(nums)}"
    assert "zone_geometry.png" in {f.name for f in figs}
    paper = [f for f in figs if f.name.startswith("fig") or f.name == "zone_geometry.png"]
    assert all(10_000 < f.stat().st_size < 400_000 for f in paper), "a figure's size"
    a, b = _without_meta(one), _without_meta(two)
    assert b["skipped"] == sorted(SKIPPABLE) and b["robust"] is None and b["tuning"] is None
    # the full sweep: 200 x 200 states of the envelope, every law (run here, not twice)
    assert a["sweep"]["grid"] == [200, 200]
    assert set(a["sweep"]["laws"]) == {"to", "pd", "pto", "pto-printed"}
    data = a
    for key in (
        "derivations",
        "ground_truth",
        "zone",
        "poles",
        "properties",
        "claims",
        "sweep",
        "checks",
        "summary",
        "environment",
        "responses",
        "robust",
        "tuning",
    ):
        assert data.get(key) is not None, key
    html_text = (one / "index.html").read_text()
    assert html_text.count("<math") > 30 and "<script" not in html_text
    for rel in data["meta"]["figures"]:
        assert rel in html_text and (one / rel).exists(), rel
    assert not list(one.parent.glob(".*tmp*")), "temporary folder left behind"


def _leaves(obj, path=""):
    """Numbers and verdict-like strings of a results tree, by path."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _leaves(v, f"{path}[{i}]")
    elif isinstance(obj, (bool, int, float)) or obj is None:
        yield path, obj
    elif path.endswith(("verdict", "status", ".id", ".name", ".valid")):
        yield path, obj


@pytest.mark.slow
def test_committed_report_matches_fresh_computation(two_reports):
    """reports/paper/results.json (regenerate: `ptoverify report --out reports/paper --jobs 1`) holds
    the numbers a fresh run computes: same structure, every number within 1e-6 relative
    (round-off across BLAS builds), every verdict and status identical."""
    committed = ROOT / "reports" / "paper" / "results.json"
    assert committed.exists(), "run: ptoverify report --out reports/paper --jobs 1"
    old = json.loads(committed.read_text())
    new = _without_meta(two_reports[0])
    old["meta"].pop("generated")
    # the committed report is computed in one process, the fresh one in a pool of two:
    # their agreement is also the check that results do not depend on the process layout
    assert (old["meta"].pop("jobs"), new["meta"].pop("jobs")) == (1, 2), (
        "regenerate with: ptoverify report --out reports/paper --jobs 1"
    )
    for d in (old, new):
        d.pop("environment")
    old_leaves, new_leaves = dict(_leaves(old)), dict(_leaves(new))
    assert old_leaves.keys() == new_leaves.keys(), "results.json structure is stale"
    for path, v in new_leaves.items():
        o = old_leaves[path]
        if isinstance(v, float) and isinstance(o, (int, float)) and not isinstance(o, bool):
            assert o == pytest.approx(v, rel=1e-6, abs=1e-12), f"stale number at {path}"
        else:
            assert o == v, f"stale value at {path}"


def test_html_escapes_text():
    page = render_html(
        [
            (
                "s",
                "<b>title</b>",
                [
                    Block("p", text="<script>alert(1)</script>"),
                    Block("table", headers=("<h>",), rows=(("a&b",),)),
                ],
            )
        ],
        "t<i>",
    )
    assert "<script>" not in page and "&lt;script&gt;" in page and "a&amp;b" in page
    assert "<b>title</b>" not in page


def test_unwritable_out_is_a_clean_error(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code = main(["report", "--out", str(blocker / "sub"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("ptoverify: error:") and len(err.splitlines()) == 1
    code = main(["report", "--out", str(blocker), "--quiet"])
    assert code == 2


def test_failed_run_leaves_nothing(tmp_path, monkeypatch):
    """An error in the middle of the run (here: a bad figure folder) leaves no folder."""
    import ptoverify.report.collect.write as rep

    def boom(*args, **kwargs):
        raise RuntimeError("interrupted")

    monkeypatch.setattr(rep, "collect", boom)
    with pytest.raises(RuntimeError):
        write_report(paper_config(), tmp_path / "out")
    assert list(tmp_path.iterdir()) == []


def _chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.browser
@pytest.mark.slow
def test_report_renders_in_headless_chromium(two_reports, tmp_path):
    browser = _chromium()
    if browser is None:
        pytest.skip(
            "chromium is not installed (.ci/run installs Debian's chromium): "
            "browser rendering NOT verified"
        )
    index = two_reports[0] / "index.html"
    flags = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={tmp_path / 'profile'}",
    ]
    probe = (
        "<script>window.onload=()=>{const imgs=[...document.images];"
        "const ok=imgs.filter(i=>i.complete&&i.naturalWidth>0).length;"
        "const m=[...document.querySelectorAll('math')];"
        "const mh=m.filter(e=>e.getBoundingClientRect().height>0).length;"
        "const rows=document.querySelectorAll('#summary table tr').length;"
        "const li=[...document.querySelectorAll('#findings ol.findings li')];"
        "const fv=li.filter(e=>e.getBoundingClientRect().height>0&&e.innerText.length>40).length;"
        "const raw=/\\{'|np\\.float64|array\\(|\\[np\\./.test(document.body.innerText)?1:0;"
        "const W=document.documentElement.clientWidth;"
        "const wide=[...document.querySelectorAll('td,th')].filter("
        "c=>c.getBoundingClientRect().right>W+1).length;"
        # an equation wider than its cell must scroll inside it (div.eq), never be clipped
        # by the cell or run past it
        "const clip=m.filter(e=>{const c=e.closest('td,th');if(!c)return false;"
        "const cr=c.getBoundingClientRect();const right=Math.max(e.getBoundingClientRect()"
        ".right,...[...e.querySelectorAll('*')].map(x=>x.getBoundingClientRect().right));"
        "if(right<=cr.right+1)return false;const w=e.closest('.eq');"
        "return !(w&&getComputedStyle(w).overflowX==='auto'"
        "&&w.getBoundingClientRect().right<=cr.right+1&&w.scrollWidth>w.clientWidth);}).length;"
        # the title, the intro and the verdict to the end of its last table: the first screen
        "const vs=document.getElementById('verdict');const vt=[...vs.querySelectorAll('table')];"
        "const vh=vt.length?Math.ceil(vt[vt.length-1].getBoundingClientRect().bottom"
        "+window.scrollY):-1;"
        # single-panel figures share a row: none drawn at less than 45 % of the content width
        "const cw=vs.clientWidth;const hf=[...document.querySelectorAll('.figs figure.half img')];"
        "const narrow=hf.filter(i=>i.getBoundingClientRect().width<0.45*cw).length;"
        "document.title=`IMAGES ${ok}/${imgs.length} MATH ${mh}/${m.length} ROWS ${rows} "
        "FINDINGS ${fv}/${li.length} RAW ${raw} WIDE ${wide} CLIP ${clip} VERDICT ${vh} "
        "HALF ${narrow}/${hf.length}`;"
        "}</script>"
    )
    probe_page = index.parent / "probe.html"
    probe_page.write_text(index.read_text().replace("</body>", probe + "</body>"))
    try:
        dom = subprocess.run(
            [
                browser,
                *flags,
                "--window-size=1280,1000",
                "--virtual-time-budget=5000",
                "--dump-dom",
                probe_page.as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        ).stdout
        shot = tmp_path / "shot.png"
        subprocess.run(
            [browser, *flags, "--window-size=1200,1600", f"--screenshot={shot}", index.as_uri()],
            capture_output=True,
            timeout=120,
            check=False,
            cwd=tmp_path,
        )
    finally:
        probe_page.unlink()
    title = dom.split("<title>")[1].split("</title>")[0]
    parts = title.split()
    loaded, total = map(int, parts[1].split("/"))
    math_h, math_n = map(int, parts[3].split("/"))
    assert total >= 20 and loaded == total, title
    assert math_n > 30 and math_h == math_n, title
    assert int(parts[5]) >= 12, title
    shown, n_findings = map(int, parts[7].split("/"))
    assert 4 <= n_findings <= 6 and shown == n_findings, f"headline findings not rendered: {title}"
    assert parts[9] == "0", f"raw Python text on the page: {title}"
    assert parts[11] == "0", f"table cells wider than a 1280 px page: {title}"
    assert parts[13] == "0", f"equations clipped or running out of their cells: {title}"
    assert 0 < int(parts[15]) <= 1000, (
        f"the verdict is not on the first 1280 x 1000 screen: {title}"
    )
    narrow, halves = map(int, parts[17].split("/"))
    assert halves >= 10 and narrow == 0, f"single-panel figures not paired across the page: {title}"
    png = shot.read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 50_000, "blank screenshot"
    # a non-blank page: many distinct pixel rows (decode via matplotlib, already a dependency)
    import matplotlib.image as mpimg
    import numpy as np

    img = mpimg.imread(shot)
    assert np.std(img[..., :3]) > 0.05, "screenshot is blank"
    assert os.path.getsize(shot) > 0


# ---------------------------------------------------------------- readability
#: Text that only a Python repr would put on the page.
REPR_MARKERS = ("{'", "[np.", "np.float64", "np.int64", "array(", "object at 0x", "<built-in")


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return token == "n/a"
    return True


def _bare_number(cell: str) -> bool:
    """A cell of numbers only (no unit word): '1.5', '(0.25, -200.5)', 'n/a' does not count."""
    tokens = [t for t in re.split(r"[(),;\s]+", cell) if t]
    return any(t != "n/a" for t in tokens) and all(_is_number(t) for t in tokens)


def unit_problems(sections) -> list[str]:
    """Table cells holding a bare number in a column whose header names no unit."""
    bad = []
    for anchor, _title, blocks in sections:
        for b in blocks:
            if b.kind != "table":
                continue
            for row in b.rows:
                for head, cell in zip(b.headers, row, strict=True):
                    if _bare_number(cell) and not re.search(r"\[[^\]]+\]", head):
                        bad.append(f"{anchor}: column '{head}' cell '{cell}'")
    return bad


def _sections(folder: Path):
    """The sections of a written report rebuilt from its results.json and records."""
    import derivations
    from ptoverify.report.collect import build_sections, results_view

    data = json.loads((folder / "results.json").read_text())
    records = [derivations.EquationRecord.from_json(r) for r in data["derivations"]]
    figures = {Path(f).stem: f for f in data["meta"]["figures"]}
    return build_sections(results_view(data), figures, records)


@pytest.mark.slow
def test_no_python_repr_anywhere(two_reports):
    for folder in two_reports:
        for name in ("index.html", "report.md"):
            text = (folder / name).read_text()
            found = [m for m in REPR_MARKERS if m in text]
            assert not found, f"{folder.name}/{name} shows Python reprs: {found}"


@pytest.mark.slow
def test_every_number_in_every_table_has_a_unit(two_reports):
    for folder in two_reports:
        problems = unit_problems(_sections(folder))
        assert not problems, "numbers without a unit:\n" + "\n".join(problems[:20])


@pytest.mark.slow
def test_report_sections_present_and_findings_first(two_reports):
    full, quick = (f / "index.html" for f in two_reports)
    html_text = full.read_text()
    assert html_text.index('id="findings"') < html_text.index('id="summary"')
    assert html_text.count('<li id="finding-') in range(4, 7)
    for anchor in ("errata", "robustness", "tuning"):
        assert f'id="{anchor}"' in html_text, anchor
    assert "robust_limit_cycles.png" in html_text and "tuning_pareto.png" in html_text
    assert "ptoverify simulate --law" in html_text or "counterexample" not in html_text
    q = quick.read_text()
    assert "report --skip robust" in q and "report --skip tuning" in q


def test_unit_check_catches_a_bare_number():
    """The units check is not vacuous: a unitless numeric column is reported."""
    from ptoverify.report.render import table

    ok = table(["t [s]", "x"], [[1.5, "1.5 mm"]])
    bad = table(["t", "x"], [[1.5, "(1, 2)"]])
    assert unit_problems([("s", "", [ok])]) == []
    assert len(unit_problems([("s", "", [bad])])) == 2


def test_unknown_skip_stage_is_an_input_error(tmp_path, capsys):
    assert main(["report", "--out", str(tmp_path / "r"), "--skip", "robust,bogus"]) == 2
    err = capsys.readouterr().err
    assert "bogus" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "r").exists()


def test_worst_case_command_line_runs(capsys):
    """The command the robustness section prints is one `ptoverify simulate` accepts."""
    import shlex

    from ptoverify.report.sections import simulate_command

    cmd = simulate_command(
        "pto",
        {
            "state": [3.25, -120.5],
            "params": {"a_ratio": 0.85, "w_max_ratio": 0.95, "delay_samples": 1, "seed": 0},
        },
    )
    argv = shlex.split(cmd)
    assert argv[:2] == ["ptoverify", "simulate"]
    assert main([*argv[1:], "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["x0"] == [3.25, -120.5]


def test_robust_map_places_each_cell():
    """The heat map's cell (w_max ratio i, a ratio j) holds that cell's value."""
    import numpy as np

    from ptoverify.report.plots import plot_robust_map

    ars, wrs = [0.8, 1.0, 1.25], [0.9, 1.0]
    cells = [
        {"a_ratio": a, "w_max_ratio": w, "delay_samples": 0, "limit_cycle_states": 10 * i + j}
        for i, w in enumerate(wrs)
        for j, a in enumerate(ars)
    ]
    maps = {"a_ratio": ars, "w_max_ratio": wrs, "delay_samples": [0], "laws": {"pd": cells}}
    mesh = plot_robust_map(maps, "pd", "limit_cycle_states", 0)["map"]
    z = np.asarray(mesh.get_array()).reshape(len(wrs), len(ars))
    np.testing.assert_array_equal(z, [[0, 1, 2], [10, 11, 12]], err_msg="cell placement")


def test_jobs_below_one_is_an_input_error(tmp_path, capsys):
    assert main(["report", "--out", str(tmp_path / "r"), "--jobs", "0"]) == 2
    err = capsys.readouterr().err
    assert "--jobs" in err and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_pool_stage_error_keeps_its_type_and_names_the_stage():
    """A stage that raises in a worker process raises here, same type, with its stage."""
    from ptoverify.report.collect.pool import _run_in_pool

    with pytest.raises(KeyError) as info:
        _run_in_pool(["no such stage"], paper_config(), None, 2, lambda *a: None)
    assert "no such stage" in str(info.value)
    notes = getattr(info.value, "__notes__", [])
    assert any("no such stage" in n and "worker process" in n for n in notes), notes


def test_pool_stage_error_in_this_process_names_the_stage():
    """The last of the jobs is this process: its stage's error names the stage and where."""
    from ptoverify.report.collect.pool import _run_in_pool

    ran = []
    with pytest.raises(KeyError) as info:  # the worker takes "poles", this process the other
        _run_in_pool(["poles", "not a stage"], paper_config(), None, 2, lambda n, r: ran.append(n))
    notes = getattr(info.value, "__notes__", [])
    assert any("not a stage" in n and "this process" in n for n in notes), notes


def test_pool_checks_before_any_stage():
    """``before`` raising (a work limit) stops the run before any stage starts or finishes."""
    from ptoverify.errors import InputError
    from ptoverify.report.collect.pool import _run_in_pool

    ran = []

    def refuse():
        raise InputError("over the limit")

    with pytest.raises(InputError, match="over the limit"):
        _run_in_pool(
            ["poles", "proofs"], paper_config(), None, 2, lambda n, r: ran.append(n), refuse
        )
    assert ran == []


def _descendants(pid: int) -> set[int]:
    """The live descendants of a process (Linux /proc)."""
    out: set[int] = set()
    todo = [pid]
    while todo:
        p = todo.pop()
        for task in Path(f"/proc/{p}/task").glob("*"):
            try:
                kids = [int(c) for c in (task / "children").read_text().split()]
            except OSError:
                continue
            out.update(kids)
            todo += kids
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
@pytest.mark.parametrize("sig, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_report_pool_interrupted_cleans_up(tmp_path, sig, code):
    """SIGTERM to the command, or Ctrl-C to its process group, while the pool's workers
    compute their stages: one line, exit 143 / 130 within seconds, no folder left, no worker left
    running."""
    import signal
    import sys
    import time

    out = tmp_path / "out"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "ptoverify.cli", "report", "--out", str(out), "--jobs", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        text=True,
        cwd=tmp_path,
        start_new_session=True,
    )
    workers: set[int] = set()
    try:
        deadline = time.monotonic() + 300
        # the pool's two workers (and the resource tracker) are at work on their stages
        while not (any(tmp_path.glob(".out.tmp-*")) and len(_descendants(proc.pid)) >= 2):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the pool never started"
            time.sleep(0.05)
        time.sleep(1.0)  # inside their stages' work, not at start-up
        workers = _descendants(proc.pid)
        assert len(workers) >= 2, workers
        if sig == "SIGTERM":
            proc.send_signal(signal.SIGTERM)
        else:
            os.killpg(proc.pid, signal.SIGINT)  # what a terminal's Ctrl-C does
        t_sig = time.monotonic()
        _, err = proc.communicate(timeout=60)
        waited = time.monotonic() - t_sig
    finally:
        proc.kill()
    assert proc.returncode == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptoverify: error:"), err
    # the workers are stopped, not waited for: their stages run for tens of seconds more
    assert waited < 10.0, f"the command took {waited:.1f} s to stop"
    deadline = time.monotonic() + 10
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in workers), "a worker outlived the command"
    assert list(tmp_path.iterdir()) == [], "the run left files behind"


# ------------------------------------------------------------------ typed, traced results
def _texts_shown(folder: Path) -> list[str]:
    """Every table cell and headline sentence of a written report, rebuilt from its JSON."""
    from ptoverify.report import sections as rs
    from ptoverify.report.collect import results_view

    data = json.loads((folder / "results.json").read_text())
    texts = [s for s, _, _ in rs.headline_findings(results_view(data))]
    for _anchor, _title, blocks in _sections(folder):
        for b in blocks:
            if b.kind == "table":
                texts += [str(c) for row in b.rows for c in row]
    return texts


@pytest.mark.slow
def test_every_number_in_tables_and_headline_traces_to_results_json(two_reports):
    from traceability import untraced

    for folder in two_reports:
        data = json.loads((folder / "results.json").read_text())
        texts = _texts_shown(folder)
        assert len(texts) > 200, "the check must see the report's tables"
        bad = untraced(texts, data)
        assert not bad, "numbers shown that no results.json field holds:\n" + "\n".join(
            f"{n}: {t[:120]}" for n, t in bad[:20]
        )


def test_traceability_flags_a_number_no_field_holds():
    from traceability import untraced

    results = {"step": {"settling_s": 0.03771}, "note": "PD takes 36.4 % more"}
    assert untraced(["37.71 ms", "PD takes 36.4 % more"], results) == []
    assert untraced(["37.72 ms"], results) == [("37.72", "37.72 ms")]
    assert untraced(["worst 4.5 [-]"], results) == [("4.5", "worst 4.5 [-]")]


@pytest.mark.slow
def test_a_renamed_result_field_fails_the_report_not_a_blank_cell(two_reports):
    """The class of the 'never' table: a section asks for a field the results do not hold."""
    from ptoverify.report.collect import build_sections, results_view
    from ptoverify.report.results import MissingField

    data = json.loads((two_reports[0] / "results.json").read_text())
    step = data["responses"]["pd"]["step"]
    step["settling_tight_s"] = step.pop("settling_0p01mm_s")
    with pytest.raises(MissingField, match=r"results\.responses\.pd\.step has no field"):
        build_sections(results_view(data), {}, [])


@pytest.mark.slow
def test_results_json_follows_its_schema(two_reports):
    import jsonschema

    schema = json.loads((ROOT / "ptoverify" / "report" / "results.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)  # once: validate() checks it each call
    validator = jsonschema.Draft202012Validator(schema)
    for folder in (*two_reports, ROOT / "reports" / "paper"):
        data = json.loads((folder / "results.json").read_text())
        validator.validate(data)
    data = json.loads((two_reports[0] / "results.json").read_text())
    data["sweep"]["laws"]["pto"]["worst_ratio_nt"] = "4.5"
    with pytest.raises(jsonschema.ValidationError):
        validator.validate(data)


def test_results_view_is_strict_and_read_only():
    from ptoverify.report.results import MissingField, Results

    r = Results({"a": {"b": [1, {"c": None}]}})
    assert r.a.b[1].c is None and r["a"]["b"][0] == 1
    with pytest.raises(MissingField, match=r"results\.a\.b\[1\] has no field 'd'"):
        _ = r.a.b[1].d
    with pytest.raises(MissingField):
        r.a.get("b")  # no defaults: a renamed field can never read as missing
    with pytest.raises(AttributeError):
        r.a = 1
