"""Figures are drawn headless, draw exactly the results they are given, compute nothing."""

import ast
import gc
import io
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure
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


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


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


def test_plotting_works_headless(tmp_path):
    """With no display and no MPLBACKEND, importing plots selects Agg and writes a PNG;
    importing it loads no simulator, no zone construction, no solver."""
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "DISPLAY")}
    env["PYTHONPATH"] = str(ROOT)
    png = tmp_path / "x.png"
    code = (
        "import sys, matplotlib\n"
        "from ptoverify.report import plots\n"
        "print(matplotlib.get_backend().lower())\n"
        "loaded = [m for m in ('ptoverify.sim.simulate', 'ptoverify.model.zones', 'ptoverify.studies.sweep',\n"
        "    'ptoverify.model.mintime', 'ptoverify.model.ocp', 'ptoverify.model.plant') if m in sys.modules]\n"
        "print(','.join(loaded) or 'none')\n"
        f"plots.save_figure({str(png)!r}, lambda ax: ax.plot([0, 1], [1, 0]))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    backend, loaded = out.stdout.split()
    assert backend == "agg", backend
    assert loaded == "none", f"importing plots loaded {loaded}"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plots_import_no_simulator_law_factory_or_zone_construction():
    """plots.py names no computing function (imports under TYPE_CHECKING are types)."""
    tree = ast.parse((ROOT / "ptoverify" / "report" / "plots.py").read_text())
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
        assert fn not in names, f"plots.py calls {fn}"


@pytest.mark.parametrize(
    ("quantity", "attr"), [("position", "x1"), ("velocity", "x2"), ("error", "e")]
)
def test_response_draws_the_results_given(sims, quantity, attr):
    _, ax = plt.subplots()
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
    assert_array_equal(d["pto trajectory"].get_ydata(), b.x2[:, 0], err_msg="trajectory")
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
    assert gc.isenabled(), "the garbage collector is back on after the batch"

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


@pytest.mark.parametrize(("scale", "relaid"), [(100.0, False), (1e5, True)])
def test_saved_figure_is_never_clipped(tmp_path, monkeypatch, scale, relaid):
    """Tick labels as wide as the paper's keep the first-guess margins (one draw); much
    wider ones (another configuration) are laid out anew.  Either way nothing drawn is
    nearer the edge than FIT_GAP[0] nor farther than FIT_GAP[1]."""
    laid = []
    tight = Figure.tight_layout
    monkeypatch.setattr(Figure, "tight_layout", lambda fig: laid.append(fig) or tight(fig))
    t = np.linspace(0.0, 1.0, 50)

    def draw(ax):
        ax.plot(t, -3 * scale * t)
        ax.set_title("a title")
        ax.set_xlabel("time t [s]")
        ax.set_ylabel("position x1 [mm]")

    path = plots.save_figure(tmp_path / "f.png", draw)
    assert bool(laid) == relaid
    lo, hi = plots.FIT_GAP
    for side, gap in zip(("left", "right", "bottom", "top"), _ink_gaps(path), strict=True):
        assert lo <= gap <= hi, f"{side}: {gap:.3f} in"


@pytest.mark.parametrize(("scale", "relaid"), [(1.0, False), (1e3, True)])
def test_panels_never_overlap(tmp_path, monkeypatch, scale, relaid):
    """Side-by-side panels keep the guessed spacing unless one's tick labels reach into
    the other; the figure written has no two panels' decorations overlapping."""
    laid, figs = [], []
    tight = Figure.tight_layout
    monkeypatch.setattr(Figure, "tight_layout", lambda fig: laid.append(fig) or tight(fig))

    def draw(fig):
        figs.append(fig)
        for ax, k in zip(fig.subplots(1, 2), (1.0, scale), strict=True):
            ax.plot([0.0, 1.0], [0.0, -300 * k])  # only the right panel's labels vary
            ax.set_title("panel")
            ax.set_ylabel("y [mm]")

    plots.save_drawing(tmp_path / "f.png", draw, (8.0, 3.0), spacing=(0.26, 0.2))
    assert bool(laid) == relaid
    r = figs[-1].canvas.get_renderer()
    left, right = (ax.get_tightbbox(r, bbox_extra_artists=[]) for ax in figs[-1].axes)
    assert left.x1 < right.x0, "the right panel's tick labels clear the left panel"


def test_title_never_covers_the_offset_text(tmp_path):
    """A y offset text under a wide title sends the figure to Matplotlib's title placement."""
    figs = []
    title = "a title wide enough to reach over the offset text at the top left of the axes"

    def draw(fig):
        figs.append(fig)
        ax = fig.add_subplot()
        ax.plot([0.0, 1.0], [1000.0, 1000.001])
        ax.set_title(title, fontsize=10)

    plots.save_drawing(tmp_path / "f.png", draw, plots.SIZE)
    boxes = []
    for fig in figs:
        ax, r = fig.axes[0], fig.canvas.get_renderer()
        assert ax.yaxis.offsetText.get_text(), "the data need an offset"
        boxes.append((ax.yaxis.offsetText.get_window_extent(r), ax.title.get_window_extent(r)))
    assert len(figs) == 2 and boxes[0][0].overlaps(boxes[0][1]), "first guess overlapped"
    assert not boxes[1][0].overlaps(boxes[1][1]), "final figure: title above the offset"


@pytest.mark.slow
def test_save_all_writes_figures_2_to_14(tmp_path):
    from ptoverify.report.collect import figure_inputs

    files = plots.save_all(figure_inputs(paper_config()), tmp_path)
    nums = {int(f.name[3:5]) for f in files if f.name.startswith("fig")}
    assert nums == set(range(2, 15)), f"figures written: {sorted(nums)}"
    assert "zone_geometry.png" in {f.name for f in files}
    for f in files:
        assert f.exists() and f.stat().st_size > 10_000, f"{f.name} is too small"
        assert f.stat().st_size < 400_000, f"{f.name} is too large for a report"


@pytest.mark.parametrize("shape", [(1, 1, 3), (2, 5, 4), (37, 61, 3), (40, 23, 4)])
def test_png_bytes_round_trip(shape):
    """Pillow (an independent decoder) reads back every byte and the resolution."""
    img = np.random.default_rng(sum(shape)).integers(0, 256, shape, dtype=np.uint8)
    back = Image.open(io.BytesIO(plots.png_bytes(img, 110.0)))
    assert back.mode == ("RGB" if shape[2] == 3 else "RGBA")
    assert_array_equal(np.asarray(back), img)
    assert back.info["dpi"] == pytest.approx((110.0, 110.0), abs=0.01)


def test_saved_png_holds_the_drawn_pixels(tmp_path):
    figs = []

    def draw(fig):
        figs.append(fig)
        ax = fig.add_subplot()
        ax.imshow(np.random.default_rng(0).random((30, 40)), cmap="viridis")
        ax.set_title("noise")

    path = plots.save_drawing(tmp_path / "f.png", draw, plots.SIZE)
    drawn = np.asarray(figs[-1].canvas.buffer_rgba())[..., :3]
    assert_array_equal(np.asarray(Image.open(path)), drawn)


def _pixels(path):
    return np.asarray(Image.open(path))


def test_sheet_draws_each_figure_as_a_fresh_one(tmp_path, sims):
    """Figures drawn one after another on one kept FigureSheet are, pixel for pixel, the
    figures drawn on new ones: nothing (limits, colour cycle, title style, legend,
    fills, texts, grid) leaks from one drawing into the next."""

    def fixed_view(ax):  # explicit limits, fills, texts, markers, a larger title
        ax.fill_betweenx([-1.0, 1.0], [0.0, 0.5], [1.0, 2.0], alpha=0.2, label="fill")
        ax.scatter([0.2, 0.4], [0.1, -0.3], color="tab:red", label="marks")
        ax.text(0.5, 0.5, "a note")
        ax.set_xlim(-3.0, 4.0)
        ax.set_title("explicit limits", fontsize=12)
        ax.legend(loc="lower left")

    draws = [
        lambda ax: plots.plot_response(sims, "position", ax, cfg=CFG),
        fixed_view,
        lambda ax: plots.plot_response(sims, "error", ax, cfg=CFG),
        lambda ax: ax.plot([0.0, 1.0], [5.0, 7.0]),  # default colour, untitled, autoscaled
        lambda ax: plots.plot_state_trajectories(sims, ax),
    ]
    sheet = plots.FigureSheet(plots.SIZE, lambda fig: [fig.add_subplot()])
    for k, draw in enumerate(draws):
        kept = sheet.save(tmp_path / f"kept{k}.png", lambda axes, draw=draw: draw(axes[0]))
        new = plots.save_figure(tmp_path / f"new{k}.png", draw)
        assert_array_equal(_pixels(kept), _pixels(new), err_msg=f"drawing {k}")


def test_sheet_colour_bar_and_contour_labels_as_fresh(tmp_path):
    """A kept multi-panel sheet with a shared colour bar (updated, not redrawn) and
    labelled contours gives the pixels of a new sheet for each drawing."""
    x1, x2 = np.meshgrid(np.linspace(-1.0, 1.0, 30), np.linspace(-2.0, 2.0, 20))

    def build(fig):
        grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 0.05))
        return [fig.add_subplot(grid[0, k]) for k in range(3)]

    def drawing(scale, label):
        def draw(axes, sheet):
            for ax, p in zip(axes[:2], (1.0, 2.0), strict=True):
                z = scale * (x1**2 + p * x2**2)
                img = ax.imshow(z, origin="lower", extent=(-1, 1, -2, 2), aspect="auto")
                img.set_clim(0.0, scale * 9.0)
                ax.clabel(ax.contour(x1, x2, z, levels=[scale, 2 * scale]), fmt="%g")
                ax.set_title(f"scale {scale:g}")
            sheet.colorbar(img, axes[2], label)

        return draw

    kept = plots.FigureSheet((9.0, 3.5), build, (0.6, 0.8, 0.5, 0.3), (0.3, 0.2))
    for k, (scale, label) in enumerate(((1.0, "ratio [-]"), (40.0, "count [-]"))):
        draw = drawing(scale, label)
        a = kept.save(tmp_path / f"kept{k}.png", lambda axes, d=draw: d(axes, kept))
        new = plots.FigureSheet((9.0, 3.5), build, (0.6, 0.8, 0.5, 0.3), (0.3, 0.2))
        b = new.save(tmp_path / f"new{k}.png", lambda axes, d=draw, s=new: d(axes, s))
        assert_array_equal(_pixels(a), _pixels(b), err_msg=f"drawing {k}")


def test_kept_renderer_draws_as_matplotlib(tmp_path, sims):
    """The saved figures' renderer (kept per size, text layouts and font metrics
    remembered) gives Matplotlib's own Agg pixels, drawing after drawing."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    def draw(ax, k):
        plots.plot_response(sims, ("position", "error")[k % 2], ax, cfg=CFG)
        ax.text(0.5, 0.5, f"rotated {k}", rotation=30, fontsize=6 + 3 * k)
        ax.set_ylabel(f"label {k} [mm]", fontsize=9 + k)

    for k in range(3):
        with plt.rc_context(plots.RENDER_RC):
            ours = plots.FigureSheet(plots.SIZE, lambda fig: [fig.add_subplot()])
            path = ours.save(tmp_path / f"ours{k}.png", lambda axes, k=k: draw(axes[0], k))
            fig = Figure(figsize=plots.SIZE, dpi=plots.DPI)
            FigureCanvasAgg(fig)
            ax = fig.add_subplot()
            ax.set_position(ours.axes[0].get_position())
            draw(ax, k)
            fig.canvas.draw()
        theirs = np.asarray(fig.canvas.buffer_rgba())[..., :3]
        assert_array_equal(_pixels(path), theirs, err_msg=f"drawing {k}")
