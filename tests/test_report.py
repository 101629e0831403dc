"""The report: atomic, reproducible, escaped, renders in a browser, and the committed
``reports/paper/results.json`` matches a fresh computation."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.render import Block, render_html
from ptoverify.report import write_report

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def two_reports(tmp_path_factory):
    base = tmp_path_factory.mktemp("rep")
    cfg = paper_config()
    return write_report(cfg, base / "one"), write_report(cfg, base / "two")


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
    assert _without_meta(one) == _without_meta(two), "two runs differ beyond the timestamp"
    data = _without_meta(one)
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
    ):
        assert key in data, key
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
    """reports/paper/results.json (regenerate: `ptoverify report --out reports/paper`) holds
    the numbers a fresh run computes: same structure, every number within 1e-6 relative
    (round-off across BLAS builds), every verdict and status identical."""
    committed = ROOT / "reports" / "paper" / "results.json"
    assert committed.exists(), "run: ptoverify report --out reports/paper"
    old = json.loads(committed.read_text())
    new = _without_meta(two_reports[0])
    old["meta"].pop("generated")
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
    import ptoverify.report as rep

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
        "document.title=`IMAGES ${ok}/${imgs.length} MATH ${mh}/${m.length} ROWS ${rows}`;"
        "}</script>"
    )
    probe_page = index.parent / "probe.html"
    probe_page.write_text(index.read_text().replace("</body>", probe + "</body>"))
    try:
        dom = subprocess.run(
            [browser, *flags, "--virtual-time-budget=5000", "--dump-dom", probe_page.as_uri()],
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
    png = shot.read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 50_000, "blank screenshot"
    # a non-blank page: many distinct pixel rows (decode via matplotlib, already a dependency)
    import matplotlib.image as mpimg
    import numpy as np

    img = mpimg.imread(shot)
    assert np.std(img[..., :3]) > 0.05, "screenshot is blank"
    assert os.path.getsize(shot) > 0
