"""Phase-plane figures: Figs. 2-6 of the paper and the zone geometry.

Fig. 2 trajectories under +-w_max with l1, l2 (eqs. 8-11); Fig. 3 time-optimal
trajectories with saturation (eq. 12); Fig. 4 switching and linear zones (l1,
l2, l1*, l2*, |x1| < d, eqs. 13-14); Fig. 5 l1, l1* and the image l~1 (eq. 19
as printed, and the exact one-sample image); Fig. 6 a PTO trajectory from the
fourth quadrant with the region of each sample; the zone geometry with sampled
PTO trajectories.  Each function draws the results it is given (the curves
come from the pure functions of :mod:`ptoverify.model.curves`), on ``ax`` or a
new figure, and returns what it drew.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ptoverify.config import Config, Plant
from ptoverify.model.curves import h, level_curve_x1
from ptoverify.model.laws import Region
from ptoverify.report.plots.common import (
    REGION_STYLE,
    Arcs,
    finish,
    inner_legend,
    level_curve,
    new_axes,
    switching_curves,
)
from ptoverify.report.words import law_name

if TYPE_CHECKING:  # data types for annotations only: no simulator, no zone construction
    from ptoverify.model.zones import PTOZone
    from ptoverify.sim.simulate import BatchResult

__all__ = [
    "plot_fig2",
    "plot_fig3",
    "plot_zones",
    "plot_fig5",
    "plot_fig6",
    "zone_geometry_xlim",
    "plot_zone_geometry",
]


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
    ax = new_axes(ax)
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
    finish(ax, r"Fig. 2: trajectories under $\pm w_{\max}$ and the switching curve")
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
    ax = new_axes(ax)
    w = plant.w_max
    drawn: dict = {}
    lines = ax.plot(batch.x1, batch.x2, color="tab:blue", lw=0.8)
    lines[0].set_label("TO closed loop (sampled)")
    drawn["TO closed loop (sampled)"] = lines[0]
    switching_curves(ax, plant, drawn, lim=0.999 * w)
    for s in (1, -1):
        ln = ax.axhline(s * w, color="tab:red", ls="--", lw=1)
    ln.set_label("saturation |x2| = w_max")
    drawn["saturation |x2| = w_max"] = ln
    finish(ax, "Fig. 3: trajectories with velocity saturation (TO, eq. 12)")
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
    ax = new_axes(ax)
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    variant = zone.construction
    drawn: dict = {}
    drawn["linear zone |x1| < d"] = ax.axvspan(
        -d, d, color="tab:green", alpha=0.15, label="linear zone |x1| < d"
    )
    switching_curves(ax, cfg.plant, drawn, lim=w)
    neg, pos = np.linspace(-w, 0, 300), np.linspace(0, w, 300)
    if 0 < zone.omega0 < w:
        om = zone.omega0
        label = f"l1* (eq. 13), omega0 = {om:.4g} mm/s"
        level_curve(ax, a, om, neg, drawn, label, color="tab:orange", lw=1.6)
        level_curve(ax, a, om, pos, drawn, "l2* (eq. 14)", color="tab:orange", lw=1.6, ls="-.")
        fill = dict(color="tab:orange", alpha=0.25)
        drawn["switching zone"] = ax.fill_betweenx(
            neg,
            level_curve_x1(neg, a, w),
            level_curve_x1(neg, a, om),
            label=r"switching zone $\tilde S_P$, $\tilde S_N$",
            **fill,
        )
        ax.fill_betweenx(pos, level_curve_x1(pos, a, om), level_curve_x1(pos, a, w), **fill)
    else:
        drawn["no zone"] = ax.text(  # top right, clear of the legends (lower left, best)
            0.98,
            0.97,
            f"{variant}: omega0 = {zone.omega0:.4g} mm/s, no switching zone",
            transform=ax.transAxes,
            fontsize=7,
            ha="right",
            va="top",
            bbox={"facecolor": "white", "edgecolor": "0.5", "alpha": 0.9},
            zorder=5,
        )
    lim = _zone_xlim(cfg, zone.omega0)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-1.05 * w, 1.05 * w)
    finish(ax, f"Fig. 4: switching and linear zones ({variant})")
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
    ax = new_axes(ax)
    p = cfg.plant
    a, w, d, T = p.a, p.w_max, cfg.pto.d, p.T
    variant = zone.construction
    drawn: dict = {}
    neg = np.linspace(-w, 0, 300)
    level_curve(ax, a, w, neg, drawn, "l1 (eq. 9)", color="k", lw=1.8)
    (line,) = ax.plot(
        level_curve_x1(neg, a, w) - 2 * w * T,
        neg,
        color="tab:purple",
        ls="--",
        label=r"$\tilde l_1$ as printed (eq. 19)",
    )
    drawn["l~1 as printed (eq. 19)"] = line
    (line,) = ax.plot(
        *image, color="tab:purple", label=r"image of $l_1$ after $T$ under $-w_{\max}$"
    )
    drawn["image of l1 after T under -w_max"] = line
    if 0 < zone.omega0 < w:
        label = f"l1* ({variant}, omega0 = {zone.omega0:.4g} mm/s)"
        level_curve(ax, a, zone.omega0, neg, drawn, label, color="tab:orange", lw=1.6)
    if math.isfinite(zone.x20_tilde) and abs(zone.x20_tilde) <= w:
        label = f"(x~10, x~20) = ({d:g}, {zone.x20_tilde:.4g})"
        (pt,) = ax.plot([d], [zone.x20_tilde], "o", color="tab:red", label=label)
        drawn[label] = pt
    drawn["x1 = d"] = ax.axvline(d, color="tab:green", ls=":", label="x1 = d")
    lim = _zone_xlim(cfg, zone.omega0)
    ax.set_xlim(-0.5 * lim, lim)
    ax.set_ylim(-1.05 * w, 0.05 * w)
    finish(ax, rf"Fig. 5: $l_1$, $l_1^*$ and $\tilde l_1$ ({variant})")
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
    (line,) = ax.plot(x1, x2, color="0.4", lw=0.8, label=f"{law_name(law)} trajectory")
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
        f"Fig. 6: {law_name(law)} from ({x1[0]:g} mm, {x2[0]:g} mm/s), region of each sample",
        fontsize=9,
    )
    inner_legend(ax, fontsize=6, loc="lower left")
    return drawn


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
    ax = new_axes(ax, (8.0, 6.0))
    fig = ax.figure
    s = np.linspace(0.0, w, 400)
    l1 = level_curve_x1(-s, a, w)
    l1s = level_curve_x1(-s, a, om)
    xmax = x1_max or zone_geometry_xlim(zone, cfg)
    lines = {}
    (lines["l1"],) = ax.plot(l1, -s, "k-", lw=1.5, label="l1, l2 (eqs. 9, 11)")
    ax.plot(-l1, s, "k-", lw=1.5)
    (lines["l1*"],) = ax.plot(
        l1s,
        -s,
        "--",
        color="tab:orange",
        label=rf"$l_1^*$, $l_2^*$ corrected, $\omega_0$ = {om:.4g} mm/s",
    )
    ax.plot(-l1s, s, "--", color="tab:orange")
    ax.fill_betweenx(
        -s, l1, l1s, color="tab:orange", alpha=0.15, label=r"zones $\tilde S_P$, $\tilde S_N$"
    )
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
    ax.set_xlabel("position $x_1$ [mm]")
    ax.set_ylabel("velocity $x_2$ [mm/s]")
    ax.set_title(f"{cfg.name}: switching zone, T = {T * 1e3:g} ms, a = {a:.4g} rad/s")
    inner_legend(ax, fontsize=7, loc="upper right")
    ax.grid(True, alpha=0.3)
    return {"figure": fig, "ax": ax, "lines": lines, "zone": zone, "printed": printed}
