"""Figures are drawn headless, draw exactly the results they are given, compute nothing."""

import ast
import os
import re
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from PIL import Image

from ptoverify.config import paper_config
from ptoverify.model.curves import level_residual
from ptoverify.model.laws import LAW_NAMES, make_law
from ptoverify.model.plant import flow
from ptoverify.model.zones import zone_for_law
from ptoverify.report import plots
from ptoverify.sim.simulate import simulate, simulate_batch
from ptoverify.studies.sweep import SweepSettings, run_sweep

ROOT = Path(__file__).resolve().parents[1]
CFG = paper_config()


@pytest.fixture(scope="module")
def sims():
    """Every law's sine response, then its arrays replaced by random data.

    A plot that re-simulated instead of drawing its input would draw the true
    response, not these arrays.
    """
    rng = np.random.default_rng(5)
    out = {}
    for name in LAW_NAMES:
        res = simulate(make_law(name, CFG), CFG.plant, "sine", feedforward=False)
        n = res.t.size
        out[name] = replace(res, x1=rng.normal(size=n), x2=rng.normal(size=n), e=rng.normal(size=n))
    return out


def _batch(law: str, x1, x2, steps: int = 40):
    return simulate_batch(make_law(law, CFG), CFG.plant, x1, x2, steps)


def _run(code: str, **env_set) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "DISPLAY")}
    env.update(PYTHONPATH=str(ROOT), **env_set)
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )


def test_plotting_works_headless(tmp_path):
    """With no display and no MPLBACKEND, plots write a PNG without pyplot; importing
    them loads no simulator, no zone construction, no solver."""
    png = tmp_path / "x.png"
    code = (
        "import sys\n"
        "from ptoverify.report import plots\n"
        "loaded = [m for m in ('ptoverify.sim.simulate', 'ptoverify.model.zones', 'ptoverify.studies.sweep',\n"
        "    'ptoverify.model.mintime', 'ptoverify.model.ocp', 'ptoverify.model.plant',\n"
        "    'matplotlib.pyplot') if m in sys.modules]\n"
        f"plots.save_figure({str(png)!r}, lambda ax: ax.plot([0, 1], [1, 0]))\n"
        "print(','.join(loaded) or 'none', 'matplotlib.pyplot' in sys.modules)\n"
    )
    out = _run(code)
    assert out.returncode == 0, out.stderr
    loaded, pyplot = out.stdout.split()
    assert loaded == "none", f"importing plots loaded {loaded}"
    assert pyplot == "False", "drawing and saving imported pyplot"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("how", ["use", "env"])
def test_import_keeps_the_backend_the_caller_chose(tmp_path, how):
    """A caller's svg backend (chosen by matplotlib.use or MPLBACKEND) stays svg after
    importing plots and writing a figure; the PNG is still written."""
    png = tmp_path / "x.png"
    code = (
        "import matplotlib\n"
        + ("matplotlib.use('svg')\n" if how == "use" else "")
        + "before = matplotlib.get_backend()\n"
        "from ptoverify.report import plots\n"
        "after_import = matplotlib.get_backend()\n"
        f"plots.save_figure({str(png)!r}, lambda ax: ax.plot([0, 1], [1, 0]))\n"
        "print(before, after_import, matplotlib.get_backend())\n"
    )
    out = _run(code, **({"MPLBACKEND": "svg"} if how == "env" else {}))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["svg", "svg", "svg"], out.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plots_import_no_simulator_law_factory_or_zone_construction():
    """The plotting modules name no computing function (TYPE_CHECKING imports are types)."""
    files = sorted((ROOT / "ptoverify" / "report" / "plots").glob("*.py"))
    assert len(files) > 1, "the plots package and its modules"
    tree = ast.Module(
        body=[n for f in files for n in ast.parse(f.read_text()).body], type_ignores=[]
    )
    typing_only = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            typing_only |= {id(n) for n in ast.walk(node)}
    imported = {
        (node.module, alias.name)
        for node in ast.walk(tree)
        if isinstance(node, ast.ImportFrom) and id(node) not in typing_only
        for alias in node.names
    }
    modules = {m for m, _ in imported}
    forbidden = {
        "ptoverify.sim.simulate",
        "ptoverify.model.zones",
        "ptoverify.model.plant",
        "ptoverify.model.mintime",
    }
    assert not modules & forbidden, modules & forbidden
    assert ("ptoverify.model.laws", "make_law") not in imported
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    for fn in ("simulate", "simulate_batch", "make_law", "corrected_zone", "zone_for_law", "flow"):
        assert fn not in names, f"a plotting module calls {fn}"


@pytest.mark.parametrize(
    ("quantity", "attr"), [("position", "x1"), ("velocity", "x2"), ("error", "e")]
)
def test_response_draws_the_results_given(sims, quantity, attr):
    ax = plots.new_axes()
    d = plots.plot_response(sims, quantity, ax, cfg=CFG)
    for name, res in sims.items():
        line = d[plots.STYLE[name]["label"]]
        assert line.axes is ax
        assert_array_equal(line.get_xdata(), res.t, err_msg=f"{name}: time axis")
        assert_array_equal(line.get_ydata(), getattr(res, attr), err_msg=f"{name}: {attr}")
    if quantity == "position":
        assert_array_equal(d["reference"].get_ydata(), sims["pd"].r, err_msg="reference r")
    if quantity == "error":
        assert abs(d[f"linear zone +-d = +-{CFG.pto.d:g} mm"].get_ydata()[0]) == CFG.pto.d
    assert "[s]" in ax.get_xlabel() and "[mm" in ax.get_ylabel()
    assert "sine" in ax.get_title() and "no feed-forward" in ax.get_title()


def test_state_trajectories_draw_x1_against_x2(sims):
    d = plots.plot_state_trajectories(sims)
    for name, res in sims.items():
        line = d[plots.STYLE[name]["label"]]
        assert_array_equal(line.get_xdata(), res.x1, err_msg=f"{name}: x1")
        assert_array_equal(line.get_ydata(), res.x2, err_msg=f"{name}: x2")
    assert_array_equal(d["reference"].get_ydata(), sims["to"].r_dot, err_msg="reference r'")


def test_fig2_draws_the_arcs_and_curves_on_eq_9_11():
    p = CFG.plant
    t = np.linspace(0, 6 / p.a, 50)[:, None]
    x10 = np.linspace(-20, 20, 3)
    plus = flow(x10, np.full(3, -0.5 * p.w_max), p.w_max, t, p.a)
    minus = flow(x10, np.full(3, 0.5 * p.w_max), -p.w_max, t, p.a)
    d = plots.plot_fig2(p, plus, minus)
    ax = d["u = +w_max (eq. 8)"].axes
    drawn = [np.column_stack(ln.get_data()) for ln in ax.get_lines()]
    for arcs in (plus, minus):
        for j in range(3):
            arc = np.column_stack([arcs[0][:, j], arcs[1][:, j]])
            assert any(a.shape == arc.shape and np.array_equal(a, arc) for a in drawn)
    x, y = d["l1, x2 <= 0 (kept)"].get_data()
    assert_allclose(level_residual(x, y, p.a, p.w_max), 0, atol=1e-9, err_msg="l1 on eq. (9)")
    x, y = d["l2, x2 >= 0 (kept)"].get_data()
    assert_allclose(level_residual(-x, -y, p.a, p.w_max), 0, atol=1e-9, err_msg="l2, eq. (11)")


def test_fig3_and_fig6_draw_the_batch_and_its_regions():
    p = CFG.plant
    b = _batch("to", [40.0, -30.0], [0.0, 100.0])
    d = plots.plot_fig3(b, p)
    lines = d["TO closed loop (sampled)"].axes.get_lines()
    assert_array_equal(lines[0].get_xdata(), b.x1[:, 0], err_msg="first trajectory x1")
    assert_array_equal(lines[1].get_ydata(), b.x2[:, 1], err_msg="second trajectory x2")
    assert d["saturation |x2| = w_max"].get_ydata()[0] == pytest.approx(-p.w_max)

    zone = zone_for_law(CFG, "corrected")
    b = _batch("pto", [4 * CFG.pto.d], [-p.w_max / 3], 60)
    d = plots.plot_fig6(zone, CFG, b, "pto")
    assert_array_equal(
        d["PTO (corrected) trajectory"].get_ydata(), b.x2[:, 0], err_msg="trajectory"
    )
    reg = b.region[:, 0]
    for code, (_, lab) in plots.REGION_STYLE.items():
        key = f"sample in {lab}"
        assert (key in d) == bool(np.any(reg == code)), key
        if key in d:
            k = np.flatnonzero(reg == code)
            assert_array_equal(
                d[key].get_offsets(), np.column_stack([b.x1[k, 0], b.x2[k, 0]]), err_msg=key
            )
    assert "sample in zone: +omega_c" in d or "sample in zone: -omega_c" in d


def test_zone_figures_draw_the_zone_given():
    p = CFG.plant
    zc, zp = zone_for_law(CFG, "corrected"), zone_for_law(CFG, "printed")
    d = plots.plot_zones(zc, CFG)
    key = next(k for k in d if k.startswith("l1* (eq. 13)"))
    x, y = d[key].get_data()
    assert_allclose(
        level_residual(x, y, p.a, zc.omega0), 0, atol=1e-9, err_msg="l1* at the zone's omega0"
    )
    assert "switching zone" in d and "linear zone |x1| < d" in d
    other = replace(zc, omega0=0.5 * zc.omega0)  # a different zone is drawn, not recomputed
    drawn = plots.plot_zones(other, CFG)
    x, y = next(v for k, v in drawn.items() if k.startswith("l1* (eq. 13)")).get_data()
    assert_allclose(level_residual(x, y, p.a, other.omega0), 0, atol=1e-9, err_msg="other l1*")
    assert "no zone" in plots.plot_zones(zp, CFG), "printed omega0 > w_max: no zone drawn"

    neg = np.linspace(-p.w_max, 0, 30)
    image = (neg * 0.1, neg)  # any arrays: drawn as given
    d = plots.plot_fig5(zc, CFG, image)
    line = d["image of l1 after T under -w_max"]
    assert_array_equal(line.get_xdata(), image[0], err_msg="image x1")
    assert "l~1 as printed (eq. 19)" in d
    point = next(v for k, v in d.items() if k.startswith("(x~10, x~20)"))
    assert point.get_ydata()[0] == zc.x20_tilde


def test_sweep_heat_map(tmp_path):
    res = run_sweep(paper_config(), SweepSettings(n1=6, n2=6, laws=("to", "pd")))
    d = plots.plot_sweep(res, "pd", "nt")
    assert {"mesh", "unsettled", "colorbar"} <= set(d)
    ratio = res.laws["pd"].ratio_nt
    drawn = np.ma.masked_invalid(d["mesh"].get_array()).reshape(ratio.shape)
    assert_array_equal(drawn.filled(np.nan), np.where(np.isfinite(ratio), ratio, np.nan))
    if "worst" in d:
        assert_allclose(
            np.ravel(d["worst"].get_data()), res.laws["pd"].worst_state_nt, err_msg="worst"
        )
    x1, x2 = res.x1[0], res.x2[:, 0]
    h1, h2 = (x1[1] - x1[0]) / 2, (x2[1] - x2[0]) / 2
    assert_allclose(
        d["mesh"].get_extent(),
        [x1[0] - h1, x1[-1] + h1, x2[0] - h2, x2[-1] + h2],
        err_msg="each cell centred on its state, spanning half-way to its neighbours",
    )
    shared = plots.plot_sweep(res, "pd", "nt", vmin=0.5, vmax=7.0, colorbar=False)
    assert shared["mesh"].get_clim() == (0.5, 7.0) and "colorbar" not in shared
    files = plots.save_sweep(res, tmp_path)
    assert [f.name for f in files] == ["sweep_ratio_tf.png", "sweep_ratio_nt.png"]

    uneven = replace(res, x1=np.sign(res.x1) * res.x1**2 / np.abs(res.x1).max())
    d = plots.plot_sweep(uneven, "pd", "nt")
    edges = d["mesh"].get_coordinates()[0, :, 0]
    mid = uneven.x1[0]
    assert_allclose(edges[1:-1], (mid[1:] + mid[:-1]) / 2, err_msg="uneven grid: mid-way edges")
    drawn = np.ma.masked_invalid(d["mesh"].get_array()).reshape(ratio.shape)
    assert_array_equal(drawn.filled(np.nan), np.where(np.isfinite(ratio), ratio, np.nan))


def _ink_gaps(path: Path) -> list[float]:
    """Distance from the outermost non-background pixel to each edge [inch] (l, r, b, t)."""
    px = np.asarray(Image.open(path).convert("RGB")).astype(int)
    ink = np.any(px != px[0, 0], axis=2)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    h, w = ink.shape
    gaps = (cols[0], w - 1 - cols[-1], h - 1 - rows[-1], rows[0])
    return [g / plots.DPI for g in gaps]


#: Least and largest distance [inch] from what a saved figure draws to its edge: nothing
#: clipped (constrained layout pads by 3/72 inch), no gross waste.
GAPS = (0.02, 0.5)


@pytest.mark.parametrize("scale", [1.0, 100.0, 1e5, 1e9])
def test_saved_figure_is_never_clipped(tmp_path, scale):
    """Whatever the width of the tick labels, nothing drawn touches the PNG's edge and
    no side is grossly wasted (read back by Pillow, an independent decoder)."""
    t = np.linspace(0.0, 1.0, 50)

    def draw(ax):
        ax.plot(t, -3 * scale * t)
        ax.set_title("a title")
        ax.set_xlabel("time t [s]")
        ax.set_ylabel("position x1 [mm]")

    path = plots.save_figure(tmp_path / "f.png", draw)
    with Image.open(path) as img:
        assert img.size == (round(plots.SIZE[0] * plots.DPI), round(plots.SIZE[1] * plots.DPI))
    lo, hi = GAPS
    for side, gap in zip(("left", "right", "bottom", "top"), _ink_gaps(path), strict=True):
        assert lo <= gap <= hi, f"{side}: {gap:.3f} in"


@pytest.mark.parametrize("scale", [1.0, 1e3, 1e6])
def test_panels_never_overlap(tmp_path, scale):
    """Side-by-side panels: the right panel's tick labels, however wide, clear the left
    panel's decorations in the figure written."""
    figs = []

    def draw(fig):
        figs.append(fig)
        for ax, k in zip(fig.subplots(1, 2), (1.0, scale), strict=True):
            ax.plot([0.0, 1.0], [0.0, -300 * k])  # only the right panel's labels vary
            ax.set_title("panel")
            ax.set_ylabel("y [mm]")

    plots.save_drawing(tmp_path / "f.png", draw, (8.0, 3.0))
    left, right = (ax.get_tightbbox() for ax in figs[-1].axes)
    assert left.x1 < right.x0, "the right panel's tick labels clear the left panel"


def test_title_never_covers_the_offset_text(tmp_path):
    """A y offset text under a wide title: the title is placed above it."""
    figs = []
    title = "a title wide enough to reach over the offset text at the top left of the axes"

    def draw(fig):
        figs.append(fig)
        ax = fig.add_subplot()
        ax.plot([0.0, 1.0], [1000.0, 1000.001])
        ax.set_title(title, fontsize=10)

    plots.save_drawing(tmp_path / "f.png", draw, plots.SIZE)
    ax = figs[-1].axes[0]
    assert ax.yaxis.offsetText.get_text(), "the data need an offset"
    off, head = ax.yaxis.offsetText.get_window_extent(), ax.title.get_window_extent()
    assert not off.overlaps(head), "title above the offset"


def test_saved_png_is_the_figure_drawn(tmp_path):
    """The PNG holds the pixels Matplotlib's Agg canvas draws for the figure, at DPI."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = plots.new_figure()
    ax = fig.add_subplot()
    ax.imshow(np.random.default_rng(0).random((30, 40)), cmap="viridis")
    ax.set_title("noise")
    before = dict(matplotlib.rcParams)
    path = plots.write_png(fig, tmp_path / "f.png")
    assert dict(matplotlib.rcParams) == before, "the caller's rcParams are back"
    canvas = FigureCanvasAgg(fig)
    with matplotlib.rc_context(plots.RENDER_RC):
        canvas.draw()
    drawn = np.asarray(canvas.buffer_rgba())
    with Image.open(path) as img:
        assert img.info["dpi"] == pytest.approx((plots.DPI, plots.DPI), abs=0.01)
        assert_array_equal(np.asarray(img.convert("RGBA")), drawn)


def test_pareto_inset_draws_the_fronts_gap_it_is_given():
    """The inset draws ``fronts_gap`` as given (the plot computes nothing), and is absent
    when there is no gap."""
    from matplotlib.figure import Figure

    cand = {"overshoot_mm": 0.0, "settling_2pct_s": 0.03, "omega0": None, "gains": {}}
    tuning = {
        "fronts": {"pd": [cand], "pto": [cand]},
        "best": {},
        "paper": {},
        "bounds_mm": {},
        "floor": {"tf_s": 0.02, "nt_s": 0.021, "band_entry_s": 0.019},
        "fronts_gap": {
            "law": "pto",
            "minus": "pd",
            "overshoot_mm": [0.0, 0.5, 1.25],
            "gap_s": [1e-3, -2e-3, 0.0],
        },
    }
    ax = Figure().add_subplot()
    plots.plot_pareto(tuning, ax)
    (inset,) = ax.child_axes
    (line,) = inset.get_lines()[:1]
    assert_array_equal(np.unique(line.get_xdata()), [0.0, 0.5, 1.25])
    assert set(np.round(line.get_ydata(), 12)) == {1.0, -2.0, 0.0}  # [ms]
    assert "PTO (corrected) front - PD front" in inset.get_title()
    ax = Figure().add_subplot()
    plots.plot_pareto(tuning | {"fronts_gap": None}, ax)
    assert not ax.child_axes


#: A symbol written as plain text where a reader expects mathematics: a subscript or a
#: star (w_max, a_true, t_f*, N* T) outside $...$.
_PLAIN_MATH = re.compile(r"[A-Za-z]_[A-Za-z{]|[A-Za-z]\*")


def _labels(fig) -> list[str]:
    """Every axis label, title and legend entry of a figure (colour bars included)."""
    out = []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
        legend = ax.get_legend()
        if legend is not None:
            out += [t.get_text() for t in legend.get_texts()]
    return [t for t in out if t]


def test_robust_map_and_charts_write_symbols_as_mathematics(tmp_path):
    """The robustness maps' axes (w_max,true / w_max, a_true / a_design), the sweep's and the
    penalty chart's N* T and t_f* are mathtext, which Matplotlib renders (savefig parses it)."""
    from matplotlib.figure import Figure

    maps = {
        "a_ratio": [0.5, 1.0],
        "w_max_ratio": [0.9, 1.0],
        "delay_samples": [0],
        "laws": {
            "pd": [
                {"delay_samples": 0, "w_max_ratio": w, "a_ratio": a, "limit_cycle_states": 0}
                for w in (0.9, 1.0)
                for a in (0.5, 1.0)
            ]
        },
    }
    ax = Figure().add_subplot()
    plots.plot_robust_map(maps, "pd", "limit_cycle_states", 0, ax)
    assert ax.get_ylabel() == r"$w_{\max,\mathrm{true}}/w_{\max}$ [-]"
    assert ax.get_xlabel() == r"$a_{\mathrm{true}}/a_{\mathrm{design}}$ [-]"
    files = plots.save_robust(maps, tmp_path)
    assert all(f.stat().st_size > 1000 for f in files)
    ax.figure.savefig(tmp_path / "one.png")  # a mathtext error raises here
    for text in _labels(ax.figure):
        bare = re.sub(r"\$[^$]*\$", "", text)
        assert not _PLAIN_MATH.search(bare), f"plain-text symbol in {text!r}"
