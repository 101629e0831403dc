"""Figures 2-14 of the paper and the sweep's heat maps (the only matplotlib module).

Plots draw; they do not compute.  Every plot function takes results computed
by the caller (``SimResult``, ``BatchResult``, ``PTOZone``, ``SweepResult``,
``ConvergenceStudy``, or plain arrays) and an optional ``ax`` (a new figure when
None), and returns what it drew: a dict from legend label to artist.  As
python-control's ``time_response_plot`` takes a ``TimeResponseData``, nothing
here simulates, builds a law or constructs a zone; the curves l1, l2, l1*, l2*
come from the pure functions of :mod:`ptoverify.model.curves`.  The report's collect
step (:func:`ptoverify.report.collect.collect`) computes the inputs once.  Nothing is
shown; the backend is Agg unless the caller chose another one first.

Speed (the report's thirty figures): the ``save_*`` functions draw each figure
once on an Agg canvas outside pyplot, at first-guess margins kept only when
nothing is clipped or overlapping (:func:`save_drawing`; tight layout and a
second draw otherwise), with unhinted text (:data:`RENDER_RC`), the garbage
collector paused for the batch, and write the PNG with :func:`png_bytes`.
Figures of one layout (Figs. 2-14; the two sweep maps; the two robustness
maps) are drawn on one kept figure, a :class:`FigureSheet`, whose axes and
ticks are built once and cleared between PNGs (the same pixels as a new
figure).  Every canvas of a size shares one renderer that remembers font
metrics, shaped strings and glyph bitmaps (the same pixels as Matplotlib's).

Figures: Fig. 2 trajectories under +-w_max with l1, l2 (eqs. 8-11); Fig. 3
time-optimal trajectories with saturation (eq. 12); Fig. 4 switching and
linear zones (l1, l2, l1*, l2*, |x1| < d, eqs. 13-14); Fig. 5 l1, l1* and the
image l~1 (eq. 19 as printed, and the exact one-sample image); Fig. 6 a PTO
trajectory from the fourth quadrant with the region of each sample; Figs. 7-8
step position and error; Figs. 9-11 ramp position, velocity, error; Figs.
12-14 sine position, velocity, state trajectories.  Each response figure
shows TO, PD, PTO (corrected) and PTO as printed.
"""

from __future__ import annotations

import functools
import gc
import math
import os
import struct
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

if "MPLBACKEND" not in os.environ:
    matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends import backend_agg  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.font_manager import findfont, get_font  # noqa: E402
from matplotlib.ft2font import FT2Font  # noqa: E402
from matplotlib.text import Text  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from ptoverify.config import Config, Plant  # noqa: E402
from ptoverify.model.curves import h, level_curve_x1  # noqa: E402
from ptoverify.model.laws import Region  # noqa: E402
from ptoverify.sim.metrics import TIGHT_BAND  # noqa: E402

if TYPE_CHECKING:  # data types for annotations only: no simulator, no zone construction
    from ptoverify.model.ocp import ConvergenceStudy
    from ptoverify.model.zones import PTOZone
    from ptoverify.sim.simulate import BatchResult, SimResult
    from ptoverify.studies.sweep import SweepResult

__all__ = [
    "FigureInputs",
    "plot_fig2",
    "plot_fig3",
    "plot_zones",
    "plot_fig5",
    "plot_fig6",
    "plot_response",
    "plot_state_trajectories",
    "plot_sweep",
    "plot_zone_geometry",
    "plot_convergence",
    "plot_switch_profiles",
    "save_figure",
    "save_drawing",
    "FigureSheet",
    "png_bytes",
    "save_all",
    "save_sweep",
    "save_ground_truth",
    "plot_robust_map",
    "save_robust",
    "plot_pareto",
    "save_tuning",
]

DPI = 110
SIZE = (6.4, 4.2)
#: First-guess margins (left, right, bottom, top) [inch] of a SIZE figure: what tight
#: layout gives on the paper's widest tick labels (see ``_write``).
MARGINS = (0.84, 0.26, 0.6, 0.36)
#: rcParams of the saved PNGs: unhinted glyphs (as in Matplotlib's own image tests), laid
#: out and rendered about 2.5x faster than with the TrueType hinter, same shapes.
RENDER_RC = {"text.hinting": "no_hinting"}
#: zlib level of the PNGs (:func:`png_bytes`): the fastest, as small as Pillow's level 6.
PNG_COMPRESSION = 1
STYLE = {
    "to": dict(color="tab:red", lw=1.0, label="TO"),
    "pd": dict(color="tab:blue", lw=1.3, label="PD"),
    "pto": dict(color="tab:green", lw=1.6, label="PTO (corrected zone)"),
    "pto-printed": dict(color="tab:orange", lw=1.2, ls="--", label="PTO (as printed)"),
}
REGION_STYLE = {
    Region.BANG_P: ("tab:red", "S_P: +w_max"),
    Region.BANG_N: ("tab:purple", "S_N: -w_max"),
    Region.ZONE_P: ("tab:orange", "zone: +omega_c"),
    Region.ZONE_N: ("tab:olive", "zone: -omega_c"),
    Region.LINEAR: ("tab:green", "linear zone"),
    Region.SATURATED: ("tab:cyan", "linear, clipped"),
    Region.ORIGIN: ("k", "origin"),
}
Arcs = tuple[NDArray[np.float64], NDArray[np.float64]]


def _ax(ax):
    if ax is None:
        _, ax = plt.subplots(figsize=SIZE)
    return ax


def _curve(ax, a: float, omega: float, x2, drawn: dict, label: str, **kw) -> None:
    (line,) = ax.plot(level_curve_x1(x2, a, omega), x2, label=label, **kw)
    drawn[label] = line


def _switching(ax, plant: Plant, drawn: dict, *, lim: float | None = None) -> None:
    a, w = plant.a, plant.w_max
    top = w if lim is None else lim
    neg, pos = np.linspace(-top, 0, 300), np.linspace(0, top, 300)
    _curve(ax, a, w, neg, drawn, "l1 (eq. 9), x2 <= 0", color="k", lw=1.8)
    _curve(ax, a, w, pos, drawn, "l2 (eq. 11), x2 >= 0", color="k", lw=1.8, ls="-.")


def _finish(
    ax, title: str, drawn: dict, xlab="position x1 [mm]", ylab="velocity x2 [mm/s]"
) -> None:
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")


def plot_fig2(plant: Plant, plus: Arcs, minus: Arcs, ax=None) -> dict:
    """Fig. 2: trajectories under u = +-w_max (eqs. 8, 10) and the curves l1, l2.

    Parameters
    ----------
    plant : Plant
        Plant (a [rad/s], w_max [mm/s]) for the curves l1, l2.
    plus, minus : tuple of ndarray, each shape (n_t, n_traj)
        (x1 [mm], x2 [mm/s]) of open-loop trajectories under u = +w_max and
        u = -w_max, one column per trajectory (the caller evaluates the flow).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    a, w = plant.a, plant.w_max
    drawn: dict = {}
    for (x1, x2), col, lab in (
        (plus, "tab:blue", "u = +w_max (eq. 8)"),
        (minus, "tab:cyan", "u = -w_max (eq. 10)"),
    ):
        lines = ax.plot(np.asarray(x1), np.asarray(x2), color=col, lw=0.8)
        lines[0].set_label(lab)
        drawn[lab] = lines[0]
    neg, pos = np.linspace(-0.999 * w, 0, 200), np.linspace(0, 0.999 * w, 200)
    l1 = {"neg": w * h(-neg / w) / a, "pos": w * h(-pos / w) / a}  # eq. (9) solved for x1
    l2 = {"neg": -w * h(neg / w) / a, "pos": -w * h(pos / w) / a}  # eq. (11) solved for x1
    for x1, x2, lab, kw in (
        (l1["neg"], neg, "l1, x2 <= 0 (kept)", dict(color="k", lw=2)),
        (l1["pos"], pos, "l1, x2 > 0 (runs away)", dict(color="k", lw=1, ls=":")),
        (l2["pos"], pos, "l2, x2 >= 0 (kept)", dict(color="0.3", lw=2, ls="-.")),
        (l2["neg"], neg, "l2, x2 < 0 (runs away)", dict(color="0.3", lw=1, ls=":")),
    ):
        (drawn[lab],) = ax.plot(x1, x2, label=lab, **kw)
    span = max(float(np.max(np.abs(plus[0][0]))), float(np.max(np.abs(minus[0][0]))))
    ax.set_xlim(-span * 1.5, span * 1.5)
    _finish(ax, "Fig. 2: trajectories under +-w_max and the switching curve", drawn)
    return drawn


def plot_fig3(batch: BatchResult, plant: Plant, ax=None) -> dict:
    """Fig. 3: sampled time-optimal trajectories with the saturation |x2| <= w_max.

    Parameters
    ----------
    batch : BatchResult
        Sampled TO closed-loop trajectories, one column per initial state.
    plant : Plant
        Plant (a [rad/s], w_max [mm/s]) for l1, l2 and the saturation lines.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist (``TO closed loop (sampled)`` is the first trajectory).
    """
    ax = _ax(ax)
    w = plant.w_max
    drawn: dict = {}
    lines = ax.plot(batch.x1, batch.x2, color="tab:blue", lw=0.8)
    lines[0].set_label("TO closed loop (sampled)")
    drawn["TO closed loop (sampled)"] = lines[0]
    _switching(ax, plant, drawn, lim=0.999 * w)
    for s in (1, -1):
        ln = ax.axhline(s * w, color="tab:red", ls="--", lw=1)
    ln.set_label("saturation |x2| = w_max")
    drawn["saturation |x2| = w_max"] = ln
    _finish(ax, "Fig. 3: trajectories with velocity saturation (TO, eq. 12)", drawn)
    return drawn


def _zone_xlim(cfg: Config, omega0: float) -> float:
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    reach = (
        float(level_curve_x1(-w, a, omega0)) if 0 < omega0 < w else float(level_curve_x1(-w, a, w))
    )
    return max(4 * d, 1.3 * reach)


def plot_zones(zone: PTOZone, cfg: Config, ax=None) -> dict:
    """Fig. 4: switching zone (l1 to l1*, l2 to l2*) and linear zone |x1| < d.

    Parameters
    ----------
    zone : PTOZone
        The zone to draw (its ``construction`` names the figure).
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], d [mm]).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist; ``no zone`` when omega0 is not in (0, w_max).
    """
    ax = _ax(ax)
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    variant = zone.construction
    drawn: dict = {}
    drawn["linear zone |x1| < d"] = ax.axvspan(
        -d, d, color="tab:green", alpha=0.15, label="linear zone |x1| < d"
    )
    _switching(ax, cfg.plant, drawn, lim=w)
    neg, pos = np.linspace(-w, 0, 300), np.linspace(0, w, 300)
    if 0 < zone.omega0 < w:
        om = zone.omega0
        label = f"l1* (eq. 13), omega0 = {om:.4g} mm/s"
        _curve(ax, a, om, neg, drawn, label, color="tab:orange", lw=1.6)
        _curve(ax, a, om, pos, drawn, "l2* (eq. 14)", color="tab:orange", lw=1.6, ls="-.")
        fill = dict(color="tab:orange", alpha=0.25)
        drawn["switching zone"] = ax.fill_betweenx(
            neg,
            level_curve_x1(neg, a, w),
            level_curve_x1(neg, a, om),
            label="switching zone S~_P, S~_N",
            **fill,
        )
        ax.fill_betweenx(pos, level_curve_x1(pos, a, om), level_curve_x1(pos, a, w), **fill)
    else:
        drawn["no zone"] = ax.text(
            0.02,
            0.04,
            f"{variant}: omega0 = {zone.omega0:.4g} mm/s, no switching zone",
            transform=ax.transAxes,
            fontsize=7,
        )
    lim = _zone_xlim(cfg, zone.omega0)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-1.05 * w, 1.05 * w)
    _finish(ax, f"Fig. 4: switching and linear zones ({variant})", drawn)
    return drawn


def plot_fig5(zone: PTOZone, cfg: Config, image: Arcs, ax=None) -> dict:
    """Fig. 5: l1, l1* and the one-sample image l~1 of l1 (eq. 19 and exact).

    Parameters
    ----------
    zone : PTOZone
        Zone whose l1* and (x~10, x~20) are drawn.
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    image : tuple of ndarray
        (x1 [mm], x2 [mm/s]): points of l1 moved one sample T under u = -w_max
        (the caller evaluates the flow).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    p = cfg.plant
    a, w, d, T = p.a, p.w_max, cfg.pto.d, p.T
    variant = zone.construction
    drawn: dict = {}
    neg = np.linspace(-w, 0, 300)
    _curve(ax, a, w, neg, drawn, "l1 (eq. 9)", color="k", lw=1.8)
    (line,) = ax.plot(
        level_curve_x1(neg, a, w) - 2 * w * T,
        neg,
        color="tab:purple",
        ls="--",
        label="l~1 as printed (eq. 19)",
    )
    drawn[line.get_label()] = line
    (line,) = ax.plot(*image, color="tab:purple", label="image of l1 after T under -w_max")
    drawn[line.get_label()] = line
    if 0 < zone.omega0 < w:
        label = f"l1* ({variant}, omega0 = {zone.omega0:.4g} mm/s)"
        _curve(ax, a, zone.omega0, neg, drawn, label, color="tab:orange", lw=1.6)
    if math.isfinite(zone.x20_tilde) and abs(zone.x20_tilde) <= w:
        label = f"(x~10, x~20) = ({d:g}, {zone.x20_tilde:.4g})"
        (pt,) = ax.plot([d], [zone.x20_tilde], "o", color="tab:red", label=label)
        drawn[label] = pt
    drawn["x1 = d"] = ax.axvline(d, color="tab:green", ls=":", label="x1 = d")
    lim = _zone_xlim(cfg, zone.omega0)
    ax.set_xlim(-0.5 * lim, lim)
    ax.set_ylim(-1.05 * w, 0.05 * w)
    _finish(ax, f"Fig. 5: l1, l1* and l~1 ({variant})", drawn)
    return drawn


def plot_fig6(zone: PTOZone, cfg: Config, batch: BatchResult, law: str, ax=None) -> dict:
    """Fig. 6: a trajectory from the fourth quadrant, each sample marked by region.

    Parameters
    ----------
    zone : PTOZone
        The zone the law uses (drawn as in Fig. 4).
    cfg : Config
        Configuration.
    batch : BatchResult
        The closed-loop trajectory (first column) with its region codes.
    law : str
        Law name for the labels (``pto`` or ``pto-printed``).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist; one ``sample in ...`` entry per region visited.
    """
    drawn = plot_zones(zone, cfg, ax)
    ax = drawn["l1 (eq. 9), x2 <= 0"].axes
    x1, x2 = batch.x1[:, 0], batch.x2[:, 0]
    (line,) = ax.plot(x1, x2, color="0.4", lw=0.8, label=f"{law} trajectory")
    drawn[line.get_label()] = line
    reg = batch.region[:, 0]
    lo, hi = ax.get_xlim()
    ax.set_xlim(min(lo, 1.15 * min(x1[0], 0)), max(hi, 1.15 * max(x1[0], 0)))
    for code, (col, lab) in REGION_STYLE.items():
        k = np.flatnonzero(reg == code)
        if k.size:
            key = f"sample in {lab}"
            drawn[key] = ax.scatter(x1[k], x2[k], s=14, color=col, zorder=3, label=key)
    ax.set_title(
        f"Fig. 6: {law} from ({x1[0]:g} mm, {x2[0]:g} mm/s), region of each sample", fontsize=9
    )
    ax.legend(fontsize=6, loc="lower left")
    return drawn


_FIGNUM = {
    ("step", "position"): 7,
    ("step", "error"): 8,
    ("ramp", "position"): 9,
    ("ramp", "velocity"): 10,
    ("ramp", "error"): 11,
    ("sine", "position"): 12,
    ("sine", "velocity"): 13,
}
_QUANT = {
    "position": ("x1", "position x1 [mm]"),
    "velocity": ("x2", "velocity x2 [mm/s]"),
    "error": ("e", "error r - x1 [mm]"),
}


def _tracking(res: SimResult) -> str:
    return "feed-forward" if res.feedforward else "no feed-forward"


def plot_response(
    sims: Mapping[str, SimResult], quantity: str = "position", ax=None, *, cfg: Config | None = None
) -> dict:
    """Figs. 7-13: position, velocity or error of every law on one reference.

    Parameters
    ----------
    sims : mapping of str to SimResult
        Responses by law name (``to``, ``pd``, ``pto``, ``pto-printed``), all on
        the same reference; signal and tracking are read from the results.
    quantity : {"position", "velocity", "error"}
        What to draw against time.
    ax : matplotlib Axes, optional
        Where to draw.
    cfg : Config, optional
        Configuration: the linear zone +-d [mm] on error plots and a [rad/s] in
        the title.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    attr, ylab = _QUANT[quantity]
    drawn: dict = {}
    for name, res in sims.items():
        (line,) = ax.plot(res.t, getattr(res, attr), **STYLE[name])
        drawn[STYLE[name]["label"]] = line
    first = next(iter(sims.values()))
    if quantity in ("position", "velocity"):
        ref = first.r if quantity == "position" else first.r_dot
        (line,) = ax.plot(first.t, ref, color="k", lw=0.8, ls=":", label="reference")
        drawn["reference"] = line
    else:
        bands = [(TIGHT_BAND, f"tight band +-{TIGHT_BAND:g} mm", dict(color="0.5", ls=":"))]
        if cfg is not None:
            d = cfg.pto.d
            zone = dict(color="tab:green", ls="--")
            bands.insert(0, (d, f"linear zone +-d = +-{d:g} mm", zone))
            if first.signal != "sine":
                ax.set_ylim(-3 * d, 3 * d)
        for level, label, kw in bands:
            for s in (1, -1):
                line = ax.axhline(s * level, lw=0.7, **kw)
            line.set_label(label)
            drawn[label] = line
    fig = _FIGNUM.get((first.signal, quantity))
    num = f"Fig. {fig}: " if fig else ""
    plant = f", a = {cfg.plant.a:.4g} rad/s" if cfg is not None else ""
    _finish(
        ax,
        f"{num}{first.signal} response: {quantity} ({_tracking(first)}{plant})",
        drawn,
        xlab="time t [s]",
        ylab=ylab,
    )
    return drawn


def plot_state_trajectories(sims: Mapping[str, SimResult], ax=None) -> dict:
    """Fig. 14: state trajectories (x1, x2) of every law, with the reference (r, r').

    Parameters
    ----------
    sims : mapping of str to SimResult
        Responses by law name, all on the same reference.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    drawn: dict = {}
    for name, res in sims.items():
        (line,) = ax.plot(res.x1, res.x2, **{**STYLE[name], "lw": 0.8})
        drawn[STYLE[name]["label"]] = line
    res = next(iter(sims.values()))
    (line,) = ax.plot(res.r, res.r_dot, color="k", ls=":", lw=0.8, label="reference (r, r')")
    drawn["reference"] = line
    _finish(ax, f"Fig. 14: state trajectories, {res.signal} ({_tracking(res)})", drawn)
    return drawn


def plot_sweep(
    res: SweepResult,
    law: str,
    which: str = "tf",
    ax=None,
    *,
    vmin: float | None = None,
    vmax: float | None = None,
    colorbar: bool = True,
) -> dict:
    """Heat map of a law's settling time over t_f* (``tf``) or N* T (``nt``).

    Parameters
    ----------
    res : SweepResult
        Output of :func:`ptoverify.studies.sweep.run_sweep`.
    law : str
        Law name.
    which : {"tf", "nt"}
        Denominator: continuous t_f* or discrete N* T.
    ax : matplotlib Axes, optional
        Where to draw.
    vmin : float, optional
        Bottom of the colour scale [-] (default: the least ratio, at most 1).
    vmax : float, optional
        Top of the colour scale [-] (default: the 99th percentile, at least 2).
    colorbar : bool
        Draw the panel's colour bar (False when the caller draws one for several
        panels on the same scale).

    Returns
    -------
    dict
        ``mesh`` (ratio), ``unsettled`` (grey cells where the law never settles),
        ``contours`` (iso-ratio lines at 1.5, 2 and 4 where in range),
        ``worst`` (marker at the worst state), ``colorbar`` (when drawn).
    """
    ax = _ax(ax)
    ls = res.laws[law]
    ratio = ls.ratio_tf if which == "tf" else ls.ratio_nt
    den = "t_f*" if which == "tf" else "N* T"
    drawn: dict = {}
    finite = ratio[np.isfinite(ratio)]
    if vmax is None:
        vmax = max(2.0, float(np.nanpercentile(finite, 99))) if finite.size else 2.0
    cells = _cells(ax, res.x1, res.x2)
    drawn["mesh"] = cells(
        np.ma.masked_invalid(ratio),
        cmap="viridis",
        vmin=vmin if vmin is not None else _floor_of(finite),
        vmax=vmax,
    )
    bad = ~np.isfinite(ls.settle_time)
    drawn["unsettled"] = cells(
        np.ma.masked_where(~bad, bad.astype(float)), cmap=ListedColormap(["0.6"])
    )
    for layer, shown in ((drawn["mesh"], finite.size > 0), (drawn["unsettled"], bad.any())):
        layer.set_visible(bool(shown))  # an all-masked layer paints nothing: not drawn
    levels = [v for v in (1.5, 2.0, 4.0) if finite.size and finite.min() < v < finite.max()]
    if levels:  # iso-ratio lines: where the law is within 50 %, 2x, 4x of the floor
        drawn["contours"] = ax.contour(
            res.x1,
            res.x2,
            np.ma.masked_invalid(ratio),
            levels=levels,
            colors="white",
            linewidths=0.6,
        )
        ax.clabel(drawn["contours"], fmt="%g", fontsize=6)
    wr = ls.worst_state_tf if which == "tf" else ls.worst_state_nt
    worst = ls.worst_ratio_tf if which == "tf" else ls.worst_ratio_nt
    if math.isfinite(wr[0]):
        (drawn["worst"],) = ax.plot(*wr, "r*", ms=10, label=f"worst ratio {worst:.2f}")
    if colorbar:
        drawn["colorbar"] = ax.figure.colorbar(drawn["mesh"], ax=ax, label=_sweep_label(which))
    ax.set_xlabel("initial position x1 [mm]")
    ax.set_ylabel("initial velocity x2 [mm/s]")
    ax.set_title(
        f"{law}: settling (0.01 mm) / {den}; grey: never settles "
        f"({100 * (1 - ls.fraction_settled):.0f} %)",
        fontsize=8,
    )
    if "worst" in drawn:
        ax.legend(fontsize=7, loc="upper right")
    return drawn


def _floor_of(ratios: NDArray[np.float64]) -> float:
    """Bottom of a ratio map's colour scale: its least finite value, at most 1 (0.9 if none)."""
    return min(1.0, float(ratios.min())) if ratios.size else 0.9


def _sweep_label(which: str) -> str:
    return f"settling time / {'t_f*' if which == 'tf' else 'N* T'} [-]"


def _cells(ax, x1: NDArray[np.float64], x2: NDArray[np.float64]) -> Callable:
    """Return a function drawing values at the grid's nodes as cells centred on them.

    ``x1`` and ``x2`` are a meshgrid (x1 along columns).  On an evenly spaced grid the
    cells are an image (one texture, not a quadrilateral per cell); otherwise a
    pcolormesh with nearest shading.  Either way a cell spans half-way to its
    neighbours.
    """
    c1, c2 = x1[0], x2[:, 0]
    even = all(
        v.size > 1 and np.allclose(np.diff(v), (v[-1] - v[0]) / (v.size - 1), rtol=1e-9, atol=0)
        for v in (c1, c2)
    )
    if not even:
        return lambda z, **kw: ax.pcolormesh(x1, x2, z, shading="nearest", **kw)
    h1, h2 = (c1[1] - c1[0]) / 2, (c2[1] - c2[0]) / 2
    extent = (c1[0] - h1, c1[-1] + h1, c2[0] - h2, c2[-1] + h2)
    return lambda z, **kw: ax.imshow(
        z, origin="lower", extent=extent, aspect="auto", interpolation="nearest", **kw
    )


# ------------------------------------------------------------ zone geometry
_ZONE_MARKERS = {
    Region.BANG_P: ("^", "tab:red"),
    Region.BANG_N: ("v", "tab:blue"),
    Region.ZONE_P: ("s", "tab:orange"),
    Region.ZONE_N: ("s", "tab:cyan"),
    Region.LINEAR: ("o", "tab:green"),
    Region.SATURATED: ("D", "tab:olive"),
    Region.ORIGIN: ("x", "k"),
}


def zone_geometry_xlim(zone: PTOZone, cfg: Config) -> float:
    """Half-width of the zone-geometry figure's x1 axis [mm]: 4 d or 1.3 l1*(-w_max).

    Parameters
    ----------
    zone : PTOZone
        The corrected zone (its omega0 [mm/s]; w_max when not usable).
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], d [mm]).

    Returns
    -------
    float
        The half-width [mm]; the caller picks trajectory starts inside it.
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    om = zone.omega0 if zone.usable else w
    return max(4 * cfg.pto.d, 1.3 * float(level_curve_x1(-w, a, om)))


def plot_zone_geometry(
    zone: PTOZone,
    printed: PTOZone,
    cfg: Config,
    batch: BatchResult,
    ax=None,
    x1_max: float | None = None,
) -> dict:
    """Draw the zone geometry and sampled PTO trajectories.

    Parameters
    ----------
    zone : PTOZone
        The corrected zone (l1*, l2* and the zones S~_P, S~_N).
    printed : PTOZone
        The printed construction (how far the printed curve (19) is drawn).
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    batch : BatchResult
        Sampled PTO trajectories, one column per initial state, with regions.
    ax : matplotlib Axes, optional
        Axes to draw on; a new figure when None.
    x1_max : float, optional
        Half-width of the x1 axis [mm]; default :func:`zone_geometry_xlim`.

    Returns
    -------
    dict
        ``figure``, ``ax``, ``lines`` (name -> Line2D: ``l1``, ``l1*``, ``eq19``,
        ``trajectories``), ``zone`` and ``printed`` (the zones drawn).
    """
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    om = zone.omega0 if zone.usable else w
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 6))
    fig = ax.figure
    s = np.linspace(0.0, w, 400)
    l1 = level_curve_x1(-s, a, w)
    l1s = level_curve_x1(-s, a, om)
    xmax = x1_max or zone_geometry_xlim(zone, cfg)
    lines = {}
    (lines["l1"],) = ax.plot(l1, -s, "k-", lw=1.5, label="l1, l2 (eqs. 9, 11)")
    ax.plot(-l1, s, "k-", lw=1.5)
    (lines["l1*"],) = ax.plot(
        l1s, -s, "--", color="tab:orange", label=f"l1*, l2* corrected, omega0 = {om:.4g} mm/s"
    )
    ax.plot(-l1s, s, "--", color="tab:orange")
    ax.fill_betweenx(-s, l1, l1s, color="tab:orange", alpha=0.15, label="zones S~_P, S~_N")
    ax.fill_betweenx(s, -l1s, -l1, color="tab:orange", alpha=0.15)
    # printed curve (19): a x1 + x2 + w ln(1 - x2/w) = -2 a w T
    top = -printed.x20_tilde if np.isfinite(printed.x20_tilde) else w
    s19 = np.linspace(0.0, max(w, top), 400)
    x19 = (-2 * a * w * T + s19 - w * np.log1p(s19 / w)) / a
    (lines["eq19"],) = ax.plot(x19, -s19, ":", color="tab:purple", label="printed curve (19)")
    ax.axvspan(-d, d, color="tab:green", alpha=0.08, label=f"linear zone |x1| < {d:g} mm")
    traj = ax.plot(batch.x1, batch.x2, "-", color="0.6", lw=0.7)
    lines["trajectories"] = traj[0]
    for reg, (mk, col) in _ZONE_MARKERS.items():
        sel = batch.region == reg
        if sel.any():
            ax.plot(
                batch.x1[:-1][sel],
                batch.x2[:-1][sel],
                mk,
                color=col,
                ms=3,
                ls="none",
                label=f"sample: {reg.name}",
            )
    ax.set_xlim(-xmax, xmax)
    ax.set_ylim(-1.1 * w, 1.1 * w)
    ax.set_xlabel("position x1 [mm]")
    ax.set_ylabel("velocity x2 [mm/s]")
    ax.set_title(f"{cfg.name}: switching zone, T = {T * 1e3:g} ms, a = {a:.4g} rad/s")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, alpha=0.3)
    return {"figure": fig, "ax": ax, "lines": lines, "zone": zone, "printed": printed}


# ------------------------------------------------------------ collocation study
def plot_convergence(study: ConvergenceStudy, ax=None):
    """Plot the relative t_f error against N, one line per state.

    Parameters
    ----------
    study : ConvergenceStudy
        Output of :func:`ptoverify.model.ocp.convergence_study`.
    ax : matplotlib Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    ax : matplotlib Axes
        The axes drawn on.
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4))
    n = study.intervals.astype(float)
    for (x1, x2), err in zip(study.states, study.rel_error, strict=True):
        ax.loglog(n, err, "o-", ms=3, label=f"x0 = ({x1:g} mm, {x2:g} mm/s)")
    ref = np.nanmax(study.rel_error[:, 0]) * (n / n[0]) ** -2.0
    ax.loglog(n, ref, "k--", lw=0.8, label="slope -2")
    ax.set_xlabel("collocation intervals N [-]")
    ax.set_ylabel("|t_f - t_f*| / t_f* [-]")
    ax.set_title(f"Radau collocation, observed order {study.order:.2f}")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    return ax


def plot_switch_profiles(study: ConvergenceStudy, state: int = 0, ax=None, window: float = 0.15):
    """Plot the collocation input near the switch for each N (smearing, chattering).

    Parameters
    ----------
    study : ConvergenceStudy
        Output of :func:`ptoverify.model.ocp.convergence_study`.
    state : int
        Row of ``study.states`` to draw.
    ax : matplotlib Axes, optional
        Axes to draw on (a new figure when None).
    window : float
        Half-width of the time window around the exact switch, as a fraction
        of t_f* [-].

    Returns
    -------
    ax : matplotlib Axes
        The axes drawn on.
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4))
    tf = float(study.t_f_exact[state])
    ts = float(study.t_switch_exact[state])
    x1, x2 = study.states[state]
    for n in study.intervals:
        t, u = study.profiles[(state, int(n))]
        if t is None or u is None or len(u) == 0:
            continue
        ax.step(t, np.append(u, u[-1]), where="post", lw=0.9, label=f"N = {n}")
    ax.axvline(ts, color="k", lw=0.6, ls="--", label="switch (closed form)")
    ax.axvline(tf, color="k", lw=0.6, ls=":", label="t_f* (closed form)")
    ax.set_xlim(max(0.0, ts - window * tf), min(ts + window * tf, 1.02 * tf))
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("input u [mm/s]")
    ax.set_title(f"collocation input near the switch, x0 = ({x1:g} mm, {x2:g} mm/s)")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    return ax


# ------------------------------------------------------------ files
@dataclass(frozen=True)
class FigureInputs:
    """Everything Figs. 2-14 and the zone-geometry figure draw, computed by the caller.

    Attributes
    ----------
    cfg : Config
        Configuration the results were computed for.
    open_loop : dict of str to tuple of ndarray
        ``+w_max`` and ``-w_max``: open-loop trajectories (x1 [mm], x2 [mm/s]),
        each of shape (n_t, n_traj) (Fig. 2).
    to_batch : BatchResult
        Sampled TO trajectories from the envelope's edge (Fig. 3).
    zones : dict of str to PTOZone
        ``corrected`` and ``printed``: the zones the PTO laws use (Figs. 4-6).
    l1_image : tuple of ndarray
        Points of l1 moved one sample under -w_max (x1 [mm], x2 [mm/s]) (Fig. 5).
    fig6 : dict of str to BatchResult
        ``pto`` and ``pto-printed``: a trajectory from the fourth quadrant (Fig. 6).
    sims : dict of (str, bool) to dict of str to SimResult
        (signal, feedforward) -> law name -> response (Figs. 7-14).
    geometry : BatchResult
        Sampled corrected-PTO trajectories for the zone-geometry figure.
    """

    cfg: Config
    open_loop: dict[str, Arcs]
    to_batch: BatchResult
    zones: dict[str, PTOZone]
    l1_image: Arcs
    fig6: dict[str, BatchResult]
    sims: dict[tuple[str, bool], dict[str, SimResult]]
    geometry: BatchResult


def _gc_paused(fn: Callable) -> Callable:
    """Run ``fn`` (a function writing several figures) with the cyclic garbage collector off.

    Matplotlib's artists hold reference cycles, so drawing a batch of figures
    triggers full collections, each walking every object the caller holds (the
    report's results): about 10 % of the report's figure stage.  The batch's
    garbage (about 80 MB for the report) goes at the first collection after it.
    """

    @functools.wraps(fn)
    def run(*args, **kwargs):
        if not gc.isenabled():
            return fn(*args, **kwargs)
        gc.disable()
        try:
            return fn(*args, **kwargs)
        finally:
            gc.enable()

    return run


def save_figure(
    path: str | Path,
    draw: Callable,
    size: tuple[float, float] = SIZE,
    margins: tuple[float, float, float, float] = MARGINS,
) -> Path:
    """Draw on a new figure and write it as a PNG (dpi 110), see :func:`save_drawing`.

    Parameters
    ----------
    path : str or Path
        The file to write (its folder must exist).
    draw : callable
        ``draw(ax)`` draws on the figure's axes.
    size : tuple of float
        Figure size [inch].
    margins : tuple of float
        First guess of the (left, right, bottom, top) margins [inch].

    Returns
    -------
    Path
        The file written.
    """
    return save_drawing(path, lambda fig: draw(fig.add_subplot()), size, margins)


def save_drawing(
    path: str | Path,
    draw: Callable[[Figure], object],
    size: tuple[float, float],
    margins: tuple[float, float, float, float] = MARGINS,
    spacing: tuple[float, float] | None = None,
) -> Path:
    """Draw a figure once and write it as a PNG; tight layout only when the guess fails.

    The first attempt places the axes at the given margins and spacing, titles at
    the axes' top, and draws once.  It is written when :func:`_fits`: nothing
    drawn within ``FIT_GAP[0]`` of the figure's edge (so nothing is clipped) nor
    farther than ``FIT_GAP[1]`` from it (no gross waste), no y offset text under
    a title and, with several axes, no axes' ticks, labels or title over
    another's.  Otherwise (a configuration with wider tick labels, say) the
    figure is drawn anew the usual way: Matplotlib's tight layout and title
    placement, then a second draw.  The guesses are what tight layout gives on
    the paper's figures, so the layout pass (a second walk over every tick and
    text) is saved there and the picture is the same up to the margins.

    Parameters
    ----------
    path : str or Path
        The file to write (its folder must exist).
    draw : callable
        ``draw(fig)`` adds the axes to the (empty) figure and draws on them.
    size : tuple of float
        Figure size [inch].
    margins : tuple of float
        First guess of the (left, right, bottom, top) margins [inch].
    spacing : tuple of float, optional
        First guess of (wspace, hspace) between subplots [-] (fractions of the
        mean axes width and height).

    Returns
    -------
    Path
        The file written.
    """
    with matplotlib.rc_context({**RENDER_RC, "axes.titley": 1.0}):
        fig = _figure(size)
        draw(fig)
        w, h = size
        left, right, bottom, top = margins
        wspace, hspace = spacing or (None, None)
        fig.subplots_adjust(
            left / w, bottom / h, 1 - right / w, 1 - top / h, wspace=wspace, hspace=hspace
        )
        fig.canvas.draw()
        done = _fits(fig)
    if not done:
        fig = _figure(size)
        with matplotlib.rc_context(RENDER_RC):
            draw(fig)
            _write(fig, path)
    else:
        _png(fig, path)
    return Path(path)


class _Renderer(RendererAgg):
    """Agg renderer remembering each font's line metrics (Matplotlib's hook for them).

    ``Text`` lays out every label with its font's ascender, descender and line
    gap, read from the font's tables at each layout; here once per font, size
    and dpi, by the same rule (OS/2 typo metrics, else hhea).
    """

    _metrics: dict = {}
    _glyphs: dict = {}
    #: Matplotlib 3.11 draws text glyph by glyph from a shaped layout, which is
    #: remembered here per string, font and size.  This follows its private text
    #: path, so it is used only on the 3.11 series it was checked against (pixel
    #: for pixel, tests/test_plots.py); other versions draw as Matplotlib does.
    _shaped = matplotlib.__version__.startswith("3.11.") and all(
        hasattr(owner, name)
        for owner, name in (
            (backend_agg, "get_hinting_flag"),
            (backend_agg, "RenderMode"),
            (FT2Font, "_layout"),
            (FT2Font, "_set_transform"),
            (FT2Font, "_render_glyph"),
        )
    )

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if ismath or not self._shaped:
            return super().draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)
        features = mtext.get_fontfeatures() if mtext is not None else None
        language = mtext.get_language() if mtext is not None else None
        flags = backend_agg.get_hinting_flag()
        key = (s, hash(prop), self.dpi, flags, repr(features), repr(language))
        glyphs = self._glyphs.get(key)
        if glyphs is None:
            font = self._prepare_font(prop)
            size = prop.get_size_in_points()
            items = font._layout(s, flags=flags, features=features, language=language)
            glyphs = [(i.ft_object, size, i.glyph_index, 0, 1, i.x, i.y) for i in items]
            if len(self._glyphs) > 20_000:  # a bound for long-lived processes
                self._glyphs.clear()
            self._glyphs[key] = glyphs
        self._blit(gc, x, y, angle, glyphs)
        return None

    _bitmaps: dict = {}

    def _blit(self, gc, x: float, y: float, angle: float, glyphs: list) -> None:
        """Draw shaped glyphs as Matplotlib's Agg renderer does, each bitmap rendered once.

        A glyph's bitmap depends on its font, size, rotation and the sub-pixel
        part (1/64 px) of its position; the whole-pixel part only moves it.
        Positions, transform and rendering flags are Matplotlib's (3.11).
        """
        cos, sin = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        matrix = (0x10000 * np.array([[cos, -sin], [sin, cos]])).round().astype(int)
        flags = backend_agg.get_hinting_flag()
        smooth = gc.get_antialiased()
        mode = backend_agg.RenderMode.NORMAL if smooth else backend_agg.RenderMode.MONO
        height = self.height
        for font, size, index, _, _, dx, dy in glyphs:
            tx = round(0x40 * (x + dx * cos - dy * sin))
            ty = round(0x40 * (height - y + dx * sin + dy * cos))
            key = (font, size, self.dpi, index, angle, flags, smooth, tx & 63, ty & 63)
            hit = self._bitmaps.get(key)
            if hit is None:
                font.set_size(size, self.dpi)
                font._set_transform(matrix, [tx, ty])
                bitmap = font._render_glyph(index, flags, mode)
                buffer = np.array(bitmap.buffer, copy=True)
                if not smooth:
                    buffer *= 0xFF
                if len(self._bitmaps) > 50_000:
                    self._bitmaps.clear()
                hit = self._bitmaps[key] = (buffer, bitmap.left - (tx >> 6), bitmap.top - (ty >> 6))
            buffer, left, top = hit
            self._renderer.draw_text_image(
                buffer, left + (tx >> 6), int(height) - (top + (ty >> 6)) + buffer.shape[0], 0, gc
            )

    def _get_font_height_metrics(self, prop) -> tuple:
        key = (hash(prop), prop.get_size_in_points(), self.dpi)
        found = self._metrics.get(key)
        if found is None:
            font = get_font(findfont(prop))
            found = (None, None, None)
            for name, gap, asc, desc in (
                ("OS/2", "sTypoLineGap", "sTypoAscender", "sTypoDescender"),
                ("hhea", "lineGap", "ascent", "descent"),
            ):
                table = font.get_sfnt_table(name)
                if table is not None:
                    scale = (
                        prop.get_size_in_points()
                        * self.dpi
                        / 72
                        / font.get_sfnt_table("head")["unitsPerEm"]
                    )
                    found = (table[asc] * scale, -table[desc] * scale, table[gap] * scale)
                    break
            self._metrics[key] = found
        return found


class _Canvas(FigureCanvasAgg):
    """An Agg canvas drawing with the one renderer kept per pixel size.

    Matplotlib caches text metrics per renderer, so figures of one size share
    the layout of every label they have in common.  ``draw`` clears the
    renderer first; the saved figures are written before the next one draws.
    """

    _renderers: dict[tuple[int, int, float], _Renderer] = {}

    def get_renderer(self) -> _Renderer:
        w, h = self.get_width_height(physical=True)
        key = (w, h, self.figure.dpi)
        renderer = self._renderers.get(key)
        if renderer is None:
            renderer = self._renderers[key] = _Renderer(*key)
        self.renderer = renderer
        return renderer


def _figure(size: tuple[float, float]) -> Figure:
    """Make a figure on its own Agg canvas, outside pyplot (nothing to register or close)."""
    fig = Figure(figsize=size, dpi=DPI)
    _Canvas(fig)
    return fig


class FigureSheet:
    """A figure kept for a family of PNGs of one layout, its axes cleared between them.

    The axes and their ticks (the costliest part of a fresh figure: a tick is
    two lines, two texts and a grid line, each styled anew) are built once by
    ``build(fig) -> list of Axes``; each :meth:`save` removes what the last
    drawing added (lines, collections, images, texts, legend), resets the data
    and view limits, the colour cycle and the title and label styles, then
    ``draw(axes)`` draws and the PNG is written as by :func:`save_drawing`
    (first-guess margins, a fresh figure with tight layout when they do not
    fit).  The picture is the one a fresh figure gives, pixel for pixel
    (``tests/test_plots.py``), when the family's drawings style the ticks and
    the grid alike (kept between drawings; the grid is switched off).  Colour bars go through :meth:`colorbar`, which
    updates the one already drawn.

    Parameters
    ----------
    size : tuple of float
        Figure size [inch].
    build : callable
        ``build(fig)`` adds the axes to the (empty) figure and returns them.
    margins : tuple of float
        First guess of the (left, right, bottom, top) margins [inch].
    spacing : tuple of float, optional
        First guess of (wspace, hspace) between subplots [-].

    Examples
    --------
    >>> import tempfile
    >>> sheet = FigureSheet(SIZE, lambda fig: [fig.add_subplot()])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     paths = [sheet.save(f"{d}/{k}.png", lambda axes: axes[0].plot([0, k])) for k in (1, 2)]
    ...     [p.stat().st_size > 0 for p in paths]
    [True, True]
    """

    def __init__(
        self,
        size: tuple[float, float],
        build: Callable[[Figure], list],
        margins: tuple[float, float, float, float] = MARGINS,
        spacing: tuple[float, float] | None = None,
    ):
        self.size, self.build, self.margins, self.spacing = size, build, margins, spacing
        self.fig: Figure | None = None
        self.axes: list = []
        self._styles: list = []
        self._bars: dict = {}

    def colorbar(self, mappable, cax, label: str):
        """Draw ``mappable``'s colour bar in ``cax`` (update it when the sheet drew one there)."""
        bar = self._bars.get(cax)
        if bar is None or cax.figure is not self.fig:
            bar = cax.figure.colorbar(mappable, cax=cax, label=label)
            if cax.figure is self.fig:
                self._bars[cax] = bar
            return bar
        bar.update_normal(mappable)
        bar.set_label(label)
        return bar

    def save(self, path: str | Path, draw: Callable[[list], object]) -> Path:
        """Draw on the sheet's axes and write the PNG; return its path."""
        with matplotlib.rc_context({**RENDER_RC, "axes.titley": 1.0}):
            if self.fig is None:
                self.fig = _figure(self.size)
                self.axes = list(self.build(self.fig))
                self._styles = [_text_styles(ax) for ax in self.axes]
                w, h = self.size
                left, right, bottom, top = self.margins
                wspace, hspace = self.spacing or (None, None)
                self.fig.subplots_adjust(
                    left / w, bottom / h, 1 - right / w, 1 - top / h, wspace=wspace, hspace=hspace
                )
            else:
                for ax, styles in zip(self.axes, self._styles):
                    if ax not in self._bars:
                        _clear(ax, styles)
            draw(self.axes)
            self.fig.canvas.draw()
            done = _fits(self.fig)
        if done:
            _png(self.fig, path)
            return Path(path)
        fig = _figure(self.size)
        with matplotlib.rc_context(RENDER_RC):
            draw(list(self.build(fig)))
            _write(fig, path)
        return Path(path)


def _text_styles(ax) -> list:
    """Return copies of the style of an axes' title and axis labels (see :func:`_clear`)."""
    styles = []
    for text in (ax.title, ax.xaxis.label, ax.yaxis.label):
        copy = Text()
        copy.update_from(text)
        styles.append((text, copy))
    return styles


def _clear(ax, styles: list) -> None:
    """Remove what was drawn on ``ax`` and reset it to the state it was built in.

    Kept: the axes, their ticks, the tick parameters and the grid's style (a drawing
    that shows a grid sets it again; the family's drawings style it alike).
    """
    for art in [*ax.collections, *ax.images, *ax.lines, *ax.patches]:
        art.remove()
    for art in [*ax.texts, *ax.artists]:  # after the collections: contour labels go with them
        art.remove()
    if ax.legend_ is not None:
        ax.legend_.remove()
    ax.containers.clear()
    for text, style in styles:
        text.update_from(style)
        text.set_text("")
    if any(t.gridline.get_visible() for t in (ax.xaxis.majorTicks[0], ax.yaxis.majorTicks[0])):
        ax.grid(False)
    ax.set_prop_cycle(None)
    ax.dataLim.set_points(Bbox.null().get_points())
    ax.ignore_existing_data_limits = True
    ax.set_autoscale_on(True)
    ax.relim()
    ax.autoscale_view()


def _write(fig: Figure, path: str | Path) -> None:
    """Tight layout, one draw, write the PNG."""
    with matplotlib.rc_context(RENDER_RC):
        fig.tight_layout()
        fig.set_layout_engine(None)  # margins are set; a placeholder engine would redraw
        fig.canvas.draw()
    _png(fig, path)


#: Distance from the outermost pixel drawn to the figure's edge that a first-guess
#: layout keeps [inch]: at least 0.05 (nothing clipped), at most 0.5 (no gross waste);
#: tight layout keeps 0.15.
FIT_GAP = (0.05, 0.5)


def _fits(fig: Figure) -> bool:
    """Whether a drawn figure keeps :data:`FIT_GAP` and nothing covers a title or another axes."""
    px = np.asarray(fig.canvas.buffer_rgba()).view(np.uint32)[..., 0]  # a pixel per word
    ink = px != px[0, 0]  # the corner is background at any sane margin
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size == 0:
        return True
    h, w = ink.shape
    lo, hi = (g * fig.dpi for g in FIT_GAP)
    gaps = (cols[0], w - 1 - cols[-1], rows[0], h - 1 - rows[-1])
    if not all(lo <= g <= hi for g in gaps):
        return False
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        off = ax.yaxis.offsetText
        if ax.title.get_text() and off.get_visible() and off.get_text():
            if off.get_window_extent(renderer).overlaps(ax.title.get_window_extent(renderer)):
                return False
    if len(fig.axes) > 1:
        boxes = [
            Bbox.union([ax.bbox] + [t.get_window_extent(renderer) for t in _drawn_texts(ax)])
            for ax in fig.axes
            if ax.get_visible()
        ]
        return not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1 :])
    return True


def _drawn_texts(ax) -> list:
    """Return the title, axis labels, offset texts and tick labels an axes showed when drawn.

    Read from the draw (the ticks it placed in view), not laid out again as
    ``Axes.get_tightbbox`` would: a fifth of a multi-panel figure's time.
    """
    texts = [ax.title]
    for axis in (ax.xaxis, ax.yaxis):
        if not axis.get_visible():
            continue
        texts += [axis.label, axis.offsetText]
        lo, hi = sorted(axis.get_view_interval())
        tol = 1e-9 * max(abs(lo), abs(hi))
        for tick in axis.get_major_ticks() + axis.get_minor_ticks():
            if lo - tol <= tick.get_loc() <= hi + tol:
                texts += [tick.label1, tick.label2]
    return [t for t in texts if t.get_visible() and t.get_text()]


def _png(fig: Figure, path: str | Path) -> None:
    """Write the drawn canvas as a PNG (RGB when opaque), see :func:`png_bytes`."""
    rgba = np.asarray(fig.canvas.buffer_rgba())
    img = rgba[..., :3] if rgba[..., 3].min() == 255 else rgba
    Path(path).write_bytes(png_bytes(img, fig.dpi))


def png_bytes(img: NDArray[np.uint8], dpi: float = DPI) -> bytes:
    """Encode an image as PNG: every row filtered "Up", zlib level :data:`PNG_COMPRESSION`.

    A plot's rows mostly repeat the row above, so the Up filter leaves runs of
    zeros that deflate's fastest level packs as tightly as an encoder choosing
    a filter per row (Pillow's), in about a third of the time.

    Parameters
    ----------
    img : ndarray of uint8, shape (h, w, 3) or (h, w, 4)
        RGB or (straight) RGBA pixels, top row first.
    dpi : float
        Resolution written in the pHYs chunk [1/inch].

    Returns
    -------
    bytes
        The PNG file.

    Examples
    --------
    >>> png_bytes(np.zeros((1, 2, 3), np.uint8))[1:4]
    b'PNG'
    """
    h, w, c = img.shape
    if img.dtype != np.uint8 or c not in (3, 4):
        raise ValueError(f"need uint8 RGB or RGBA pixels, got {img.dtype} with {c} channels")
    rows = np.empty((h, 1 + w * c), np.uint8)
    rows[:, 0] = 2  # filter type Up: each byte minus the one above (mod 256)
    flat = img.reshape(h, w * c)
    rows[0, 1:] = flat[0]
    np.subtract(flat[1:], flat[:-1], out=rows[1:, 1:])

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    ppm = round(dpi / 0.0254)  # pixels per metre
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2 if c == 3 else 6, 0, 0, 0)),
            chunk(b"pHYs", struct.pack(">IIB", ppm, ppm, 1)),
            chunk(b"IDAT", zlib.compress(rows, PNG_COMPRESSION)),
            chunk(b"IEND", b""),
        )
    )


def _folder(outdir: str | Path) -> Path:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    return outdir


@_gc_paused
def save_sweep(res: SweepResult, outdir: str | Path) -> list[Path]:
    """Write the sweep's heat maps (one PNG per denominator, a panel per law).

    The panels of one PNG share their colour scale (one colour bar), so the laws
    compare by eye.

    Parameters
    ----------
    res : SweepResult
        Output of :func:`ptoverify.studies.sweep.run_sweep`.
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        ``sweep_ratio_tf.png`` and ``sweep_ratio_nt.png``.
    """
    outdir = _folder(outdir)
    files: list[Path] = []
    laws = list(res.laws)
    cols = 2 if len(laws) > 1 else 1
    rows = math.ceil(len(laws) / cols)
    size = (5.3 * cols + 1.0, 4.2 * rows)

    def build(fig):
        grid = fig.add_gridspec(rows, cols + 1, width_ratios=(1.0,) * cols + (0.05,))
        panels = [fig.add_subplot(grid[k // cols, k % cols]) for k in range(len(laws))]
        return [*panels, fig.add_subplot(grid[:, -1])]

    sheet = FigureSheet(size, build, (0.84, 0.7, 0.6, 0.34), (0.3, 0.23))
    for which in ("tf", "nt"):
        ratios = [r.ratio_tf if which == "tf" else r.ratio_nt for r in res.laws.values()]
        finite = np.concatenate([r[np.isfinite(r)] for r in ratios])
        vmax = max(2.0, float(np.percentile(finite, 99))) if finite.size else 2.0
        scale = {"vmin": _floor_of(finite), "vmax": vmax}

        def draw(axes, which=which, scale=scale):
            for ax, law in zip(axes, laws):
                mesh = plot_sweep(res, law, which, ax, **scale, colorbar=False)["mesh"]
            sheet.colorbar(mesh, axes[-1], _sweep_label(which))

        files.append(sheet.save(outdir / f"sweep_ratio_{which}.png", draw))
    return files


#: Quantities of the robustness heat maps: cell key, colour-bar label, file stem.
ROBUST_MAPS = (
    ("limit_cycle_states", "states ending in a limit cycle [count]", "robust_limit_cycles"),
    ("settling_ratio_nt", "worst settling / (N* T) [-]", "robust_settling_nt"),
)


def _robust_cell_value(cell: Mapping, key: str) -> float:
    v = cell.get(key)
    if isinstance(v, Mapping):
        v = v.get("max")
    return math.nan if v is None else float(v)


def plot_robust_map(
    maps: Mapping, law: str, key: str, delay: int, ax=None, *, vmax: float | None = None
) -> dict:
    """Heat map of one property over a_ratio x w_max_ratio at one computation delay.

    Parameters
    ----------
    maps : mapping
        The ``maps`` of :meth:`ptoverify.studies.robust.RobustResult.to_json`: axes
        ``a_ratio``, ``w_max_ratio``, ``delay_samples`` and per law the cells
        (order delay, w_max_ratio, a_ratio).
    law : str
        Law name.
    key : str
        Cell key: a count (``limit_cycle_states``) or a property with ``max``
        (``settling_ratio_nt``).
    delay : int
        Computation delay [samples].
    ax : matplotlib Axes, optional
        Where to draw.
    vmax : float, optional
        Top of the colour scale.

    Returns
    -------
    dict
        ``{"map": QuadMesh}``.
    """
    ax = _ax(ax)
    ars, wrs = list(maps["a_ratio"]), list(maps["w_max_ratio"])
    cells = [c for c in maps["laws"][law] if c["delay_samples"] == delay]
    z = np.full((len(wrs), len(ars)), np.nan)
    for c in cells:
        z[wrs.index(c["w_max_ratio"]), ars.index(c["a_ratio"])] = _robust_cell_value(c, key)
    xi, yi = np.arange(len(ars) + 1) - 0.5, np.arange(len(wrs) + 1) - 0.5
    mesh = ax.pcolormesh(xi, yi, np.ma.masked_invalid(z), cmap="magma_r", vmin=0, vmax=vmax)
    top = vmax if vmax is not None else (np.nanmax(z) if np.isfinite(z).any() else 1.0)
    missing = "never" if key == "settling_ratio_nt" else "n/a"  # null max: some state never settles
    ax.set_facecolor("0.85")
    for (i, j), v in np.ndenumerate(z):
        text = missing if not np.isfinite(v) else f"{v:.3g}"
        dark = np.isfinite(v) and v > 0.6 * top
        ax.text(j, i, text, ha="center", va="center", fontsize=7, color="w" if dark else "k")
    ax.set_xticks(range(len(ars)), [f"{r:.3g}" for r in ars], fontsize=7)
    ax.set_yticks(range(len(wrs)), [f"{r:.3g}" for r in wrs], fontsize=7)
    ax.set_xlabel("a_true / a_design [-]")
    ax.set_ylabel("w_max,true / w_max [-]")
    ax.set_title(f"{law}, delay {delay} sample{'s' if delay != 1 else ''}", fontsize=9)
    return {"map": mesh}


@_gc_paused
def save_robust(maps: Mapping, outdir: str | Path) -> list[Path]:
    """Write the robustness heat maps: one PNG per quantity, a panel per law and delay.

    Parameters
    ----------
    maps : mapping
        The ``maps`` of :meth:`ptoverify.studies.robust.RobustResult.to_json`.
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        ``robust_limit_cycles.png`` and ``robust_settling_nt.png``.
    """
    outdir = _folder(outdir)
    laws, delays = list(maps["laws"]), list(maps["delay_samples"])
    size = (3.8 * len(delays) + 1.2, 2.9 * len(laws))
    ratios = (1.0,) * len(delays) + (0.07,)  # the panels, then the colour bar

    def build(fig):
        grid = fig.add_gridspec(len(laws), len(delays) + 1, width_ratios=ratios)
        panels = [fig.add_subplot(grid[r, c]) for r in range(len(laws)) for c in range(len(delays))]
        return [*panels, fig.add_subplot(grid[:, -1])]

    sheet = FigureSheet(size, build, (0.75, 0.75, 0.55, 0.33), (0.25, 0.23))
    files = []
    for key, label, stem in ROBUST_MAPS:
        vals = [_robust_cell_value(c, key) for law in laws for c in maps["laws"][law]]
        finite = [v for v in vals if math.isfinite(v)]
        vmax = max(max(finite, default=1.0), 1.0)

        def draw(axes, key=key, label=label, vmax=vmax):
            for k, ax in enumerate(axes[:-1]):
                r, c = divmod(k, len(delays))
                mesh = plot_robust_map(maps, laws[r], key, delays[c], ax, vmax=vmax)["map"]
                if r < len(laws) - 1:
                    ax.set_xlabel("")
                if c > 0:
                    ax.set_ylabel("")
            sheet.colorbar(mesh, axes[-1], label)

        files.append(sheet.save(outdir / f"{stem}.png", draw))
    return files


def plot_pareto(tuning: Mapping, ax=None) -> dict:
    """Settling-vs-overshoot Pareto fronts of PD and PTO on the step, with the floor.

    Parameters
    ----------
    tuning : mapping
        :func:`ptoverify.studies.claims.fair_comparison`: ``fronts`` (law -> candidates
        with ``overshoot_mm`` [mm] and ``settling_2pct_s`` [s]), ``best`` (bound
        -> law -> candidate), ``paper`` (law -> metrics at the paper's gains),
        ``bounds_mm`` (bound -> [mm]) and ``floor`` (``tf_s``, ``nt_s``,
        ``band_entry_s`` [s]).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Legend label -> artist.
    """
    ax = _ax(ax)
    drawn: dict = {}
    colors = {"pd": "tab:orange", "pto": "tab:green"}
    for law, front in tuning["fronts"].items():
        col = colors.get(law, "tab:blue")
        pts = sorted(
            (c["overshoot_mm"], 1e3 * c["settling_2pct_s"])
            for c in front
            if c.get("settling_2pct_s") is not None and c.get("overshoot_mm") is not None
        )
        if pts:
            x, y = np.array(pts).T
            (drawn[f"{law} front"],) = ax.step(x, y, where="post", color=col, marker=".", ms=3)
        bests = [b[law] for b in tuning["best"].values() if law in b]
        drawn[f"{law} best per bound"] = ax.scatter(
            [b["overshoot_mm"] for b in bests],
            [1e3 * b["settling_2pct_s"] for b in bests],
            color=col,
            marker="*",
            s=140,
            zorder=3,
        )
        p = tuning["paper"].get(law, {})
        if p.get("settling_2pct_s") is not None:
            drawn[f"{law} paper gains"] = ax.scatter(
                [p["overshoot_mm"]], [1e3 * p["settling_2pct_s"]], color=col, marker="s", zorder=3
            )
    fl = tuning["floor"]
    drawn["t_f* (exact arrival)"] = ax.axhline(1e3 * fl["tf_s"], color="k", ls="--", lw=1)
    drawn["N* T (sampled arrival)"] = ax.axhline(1e3 * fl["nt_s"], color="k", ls=":", lw=1)
    drawn["least 2 % band entry"] = ax.axhline(1e3 * fl["band_entry_s"], color="0.5", lw=1)
    for name, bound in tuning["bounds_mm"].items():
        drawn[f"bound: {name}"] = ax.axvline(bound, color="0.6", lw=0.8, ls="-.")
    ax.set_xlabel("overshoot, between samples [mm]")
    ax.set_ylabel("2 % settling time of the step [ms]")
    ax.set_ylim(bottom=0)
    ax.legend(list(drawn.values()), list(drawn), fontsize=7)
    ax.grid(alpha=0.3)
    return drawn


@_gc_paused
def save_tuning(tuning: Mapping, outdir: str | Path) -> list[Path]:
    """Write ``tuning_pareto.png`` (:func:`plot_pareto`).

    Parameters
    ----------
    tuning : mapping
        :func:`ptoverify.studies.claims.fair_comparison` (as :func:`plot_pareto`).
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        The file written.
    """
    outdir = _folder(outdir)
    path = outdir / "tuning_pareto.png"
    return [save_figure(path, lambda ax: plot_pareto(tuning, ax), margins=(0.84, 0.26, 0.6, 0.15))]


@_gc_paused
def save_all(inputs: FigureInputs, outdir: str | Path) -> list[Path]:
    """Write Figs. 2-14 and the zone-geometry figure as PNGs; return their paths.

    Zone figures come for both constructions; response figures for ramp and
    sine for both feed-forward readings (suffix ``_noff`` without).

    Parameters
    ----------
    inputs : FigureInputs
        The results to draw.
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        The files written.
    """
    outdir = _folder(outdir)
    cfg, fi = inputs.cfg, inputs
    files: list[Path] = []
    sheet = FigureSheet(SIZE, lambda fig: [fig.add_subplot()])  # Figs. 2-14: one layout

    def one(name: str, draw: Callable, size: tuple[float, float] = SIZE) -> None:
        path = outdir / f"{name}.png"
        if size == SIZE:
            files.append(sheet.save(path, lambda axes: draw(axes[0])))
        else:
            files.append(save_figure(path, draw, size))

    one("fig02_trajectories", lambda ax: plot_fig2(cfg.plant, *fi.open_loop.values(), ax))
    one("fig03_saturation", lambda ax: plot_fig3(fi.to_batch, cfg.plant, ax))
    for v in ("corrected", "printed"):
        z = fi.zones[v]
        one(f"fig04_zones_{v}", lambda ax, z=z: plot_zones(z, cfg, ax))
        one(f"fig05_l1_image_{v}", lambda ax, z=z: plot_fig5(z, cfg, fi.l1_image, ax))
    for law, v in (("pto", "corrected"), ("pto-printed", "printed")):
        b, z = fi.fig6[law], fi.zones[v]
        one(f"fig06_trajectory_{law}", lambda ax, z=z, b=b, law=law: plot_fig6(z, cfg, b, law, ax))
    step = fi.sims[("step", True)]
    one("fig07_step_position", lambda ax: plot_response(step, "position", ax, cfg=cfg))
    one("fig08_step_error", lambda ax: plot_response(step, "error", ax, cfg=cfg))
    for ff, sfx in ((True, ""), (False, "_noff")):
        ramp, sine = fi.sims[("ramp", ff)], fi.sims[("sine", ff)]
        for num, q in ((9, "position"), (10, "velocity"), (11, "error")):
            one(
                f"fig{num:02d}_ramp_{q}{sfx}",
                lambda ax, q=q, s=ramp: plot_response(s, q, ax, cfg=cfg),
            )
        for num, q in ((12, "position"), (13, "velocity")):
            one(
                f"fig{num:02d}_sine_{q}{sfx}",
                lambda ax, q=q, s=sine: plot_response(s, q, ax, cfg=cfg),
            )
        one(f"fig14_sine_states{sfx}", lambda ax, s=sine: plot_state_trajectories(s, ax))
    one(
        "zone_geometry",
        lambda ax: plot_zone_geometry(
            fi.zones["corrected"], fi.zones["printed"], cfg, fi.geometry, ax
        ),
        (7.5, 5.0),
    )
    return files


@_gc_paused
def save_ground_truth(study: ConvergenceStudy, outdir: str | Path) -> list[Path]:
    """Write the collocation convergence and switch-profile figures; return the paths.

    Parameters
    ----------
    study : ConvergenceStudy
        Output of :func:`ptoverify.model.ocp.convergence_study`.
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        ``convergence.png`` and ``collocation_switch.png``.
    """
    outdir = _folder(outdir)
    return [
        save_figure(outdir / "convergence.png", lambda ax: plot_convergence(study, ax)),
        save_figure(
            outdir / "collocation_switch.png", lambda ax: plot_switch_profiles(study, 0, ax)
        ),
    ]


# ------------------------------------------------------------ conform --report
__all__ += ["plot_du_map", "plot_conform_response", "save_conform_figures"]


def plot_du_map(
    du_map,
    bounds,
    ax=None,
    *,
    vmin: float | None = None,
    vmax: float | None = None,
    marks: Mapping[str, tuple[float, float]] | None = None,
) -> dict:
    """Heat map of the largest |u - u_ref| per cell, with the region boundaries.

    Parameters
    ----------
    du_map : DuMap
        Output of :func:`ptoverify.conform.evidence.du_map` (cell edges [mm],
        [mm/s], largest |du| per cell [mm/s], NaN where no state was judged).
    bounds : Boundaries
        Output of :func:`ptoverify.conform.evidence.boundaries`: the curves l1,
        l2, l1*, l2* (x1 [mm], x2 [mm/s]) and d [mm].
    ax : matplotlib Axes, optional
        Where to draw.
    vmin, vmax : float, optional
        Colour scale [mm/s] (logarithmic; cells below vmin take its colour).
    marks : mapping of str to (float, float), optional
        Label -> state [mm, mm/s] to mark (e.g. the first failing state).

    Returns
    -------
    dict
        Label -> artist; ``mesh`` and ``colorbar`` included.
    """
    from matplotlib.colors import LogNorm

    ax = _ax(ax)
    tol = du_map.tolerance
    vmin = 1e-6 * tol if vmin is None else vmin
    vmax = max(10.0 * tol, du_map.max) if vmax is None else vmax
    cells = np.ma.masked_invalid(np.maximum(du_map.du_max, vmin))
    drawn: dict = {}
    drawn["mesh"] = ax.pcolormesh(
        du_map.x1_edges,
        du_map.x2_edges,
        cells,
        cmap="inferno",
        norm=LogNorm(vmin=vmin, vmax=vmax),
    )
    cbar = ax.figure.colorbar(drawn["mesh"], ax=ax, label="largest |u - u_ref| in cell [mm/s]")
    cbar.ax.axhline(tol, color="tab:cyan", lw=2)
    drawn["colorbar"] = cbar
    styles = {
        "l1": dict(color="w", lw=1.0),
        "l2": dict(color="w", lw=1.0, ls="-."),
        "l1*": dict(color="tab:cyan", lw=1.0),
        "l2*": dict(color="tab:cyan", lw=1.0, ls="-."),
    }
    for label, (c1, c2) in bounds.curves.items():
        (drawn[label],) = ax.plot(c1, c2, label=label, **styles.get(label, {}))
    for s in (1, -1):
        line = ax.axvline(s * bounds.d, color="tab:green", lw=1.0, ls="--")
    line.set_label(f"linear zone |x1| < d = {bounds.d:g} mm")
    drawn["linear zone"] = line
    for (label, (m1, m2)), marker in zip((marks or {}).items(), ("X", "P", "D")):
        (drawn[label],) = ax.plot(
            m1, m2, marker, color="tab:red", mec="w", ms=9, ls="none", label=label
        )
    ax.set_xlim(du_map.x1_edges[0], du_map.x1_edges[-1])
    ax.set_ylim(du_map.x2_edges[0], du_map.x2_edges[-1])
    ax.set_xlabel("position x1 [mm]")
    ax.set_ylabel("velocity x2 [mm/s]")
    ax.set_title(
        f"|u - u_ref| ({du_map.name}); cyan tick: tolerance {tol:.3g} mm/s; grey: no state",
        fontsize=8,
    )
    ax.set_facecolor("0.8")  # cells without a judged state
    ax.legend(fontsize=6, loc="lower left", framealpha=0.9)
    return drawn


def plot_conform_response(
    user: SimResult, ref: SimResult, quantity: str = "position", ax=None
) -> dict:
    """Draw a response of the user law next to the reference PTO law's.

    Parameters
    ----------
    user, ref : SimResult
        The user law's and the reference law's responses to the same reference.
    quantity : {"position", "difference"}
        x1 of both with r, or x1_user - x1_ref [mm].
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    drawn: dict = {}
    if quantity == "position":
        (drawn["your law"],) = ax.plot(user.t, user.x1, color="tab:blue", lw=1.8, label="your law")
        (drawn["reference PTO"],) = ax.plot(
            ref.t, ref.x1, color="tab:green", lw=1.2, ls="--", label="reference PTO (eq. 35)"
        )
        (drawn["r"],) = ax.plot(user.t, user.r, color="k", lw=0.8, ls=":", label="reference r")
        ylab = "position x1 [mm]"
    else:
        (drawn["difference"],) = ax.plot(
            user.t, user.x1 - ref.x1, color="tab:red", lw=1.2, label="x1 (your law) - x1 (ref.)"
        )
        ylab = "x1 difference [mm]"
    _finish(
        ax,
        f"{user.signal} response ({_tracking(user)}), {quantity}",
        drawn,
        xlab="time t [s]",
        ylab=ylab,
    )
    return drawn


@_gc_paused
def save_conform_figures(
    evidence, outdir: str | Path, marks: Mapping[str, tuple[float, float]] | None = None
) -> dict[str, Path]:
    """Write the figures of ``conform --report``.

    Parameters
    ----------
    evidence : ConformEvidence
        Output of :func:`ptoverify.conform.evidence.conform_with_evidence`.
    outdir : str or Path
        Folder (created if missing).
    marks : mapping of str to (float, float), optional
        States to mark on the maps [mm, mm/s].

    Returns
    -------
    dict of str to Path
        ``du_map`` (when a state was judged) and, when the law has responses, ``response_step``,
        ``response_ramp``, ``response_sine``.
    """
    outdir = _folder(outdir)
    out: dict[str, Path] = {}
    maps = evidence.maps
    if evidence.judged:
        top = max([m.max for m in maps] + [10.0 * maps[0].tolerance])
        fig, axes = plt.subplots(1, len(maps), figsize=(13.0, 5.0))
        try:
            for m, ax in zip(maps, np.atleast_1d(axes)):
                plot_du_map(m, evidence.boundaries, ax, vmax=top, marks=marks)
            _write(fig, outdir / "du_map.png")
        finally:
            plt.close(fig)
        out["du_map"] = outdir / "du_map.png"
    for name, resp in (evidence.responses or {}).items():
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 5.6), sharex=True)
        try:
            plot_conform_response(resp.user, resp.reference, "position", a1)
            plot_conform_response(resp.user, resp.reference, "difference", a2)
            _write(fig, outdir / f"response_{name}.png")
        finally:
            plt.close(fig)
        out[f"response_{name}"] = outdir / f"response_{name}.png"
    return out


def save_proof_map(proof, path: str | Path) -> Path:
    """Draw the certified bound of a proof per cell (``prove --out``).

    Parameters
    ----------
    proof : LawProof
        Output of :func:`ptoverify.studies.prove.run.prove_law`.
    path : str or Path
        PNG file to write.

    Returns
    -------
    Path
        The file written.
    """
    fig = Figure(figsize=(7.5, 4.8))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    e1, e2 = proof.grid.e1, proof.grid.e2
    n1, n2 = proof.grid.shape
    z = np.ma.masked_invalid(np.where(np.isfinite(proof.bound), proof.bound, np.nan)).reshape(
        n2, n1
    )
    mesh = ax.pcolormesh(e1, e2, z, cmap="viridis", shading="flat")
    bad = ~np.isfinite(proof.bound.reshape(n2, n1))
    if bad.any():
        ax.pcolormesh(
            e1, e2, np.ma.masked_where(~bad, np.ones_like(z.data)), cmap="Reds", vmin=0, vmax=1
        )
    fig.colorbar(mesh, ax=ax, label="certified samples to the target ellipse")
    ax.set_xlabel("x1 [mm]")
    ax.set_ylabel("x2 [mm/s]")
    ax.set_title(f"{proof.law}: certified bound per cell (red: unproven)")
    path = Path(path)
    fig.savefig(path, dpi=110)
    return path
