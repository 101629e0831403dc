"""The paper's response figures (Figs. 7-14) and every paper figure's file.

Figs. 7-8 step position and error; Figs. 9-11 ramp position, velocity, error;
Figs. 12-14 sine position, velocity, state trajectories.  Each response
figure shows TO, PD, PTO (corrected) and PTO as printed.  :func:`save_all`
writes Figs. 2-14 and the zone geometry from a :class:`FigureInputs` the
caller computed (:func:`ptoverify.report.collect.figure_inputs`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ptoverify.config import Config
from ptoverify.report.plots.common import (
    SIZE,
    STYLE,
    Arcs,
    finish,
    folder,
    new_axes,
    save_figure,
    tracking,
)
from ptoverify.report.plots.phase import (
    plot_fig2,
    plot_fig3,
    plot_fig5,
    plot_fig6,
    plot_zone_geometry,
    plot_zones,
)
from ptoverify.sim.metrics import TIGHT_BAND

if TYPE_CHECKING:  # data types for annotations only: no simulator, no zone construction
    from ptoverify.model.zones import PTOZone
    from ptoverify.sim.simulate import BatchResult, SimResult

__all__ = ["FigureInputs", "plot_response", "plot_state_trajectories", "save_all"]


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
    "position": ("x1", "position $x_1$ [mm]"),
    "velocity": ("x2", "velocity $x_2$ [mm/s]"),
    "error": ("e", "error $r - x_1$ [mm]"),
}


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
    ax = new_axes(ax)
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
    finish(
        ax,
        f"{num}{first.signal} response: {quantity} ({tracking(first)}{plant})",
        xlab="time $t$ [s]",
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
    ax = new_axes(ax)
    drawn: dict = {}
    for name, res in sims.items():
        (line,) = ax.plot(res.x1, res.x2, **{**STYLE[name], "lw": 0.8})
        drawn[STYLE[name]["label"]] = line
    res = next(iter(sims.values()))
    (line,) = ax.plot(res.r, res.r_dot, color="k", ls=":", lw=0.8, label="reference (r, r')")
    drawn["reference"] = line
    finish(ax, f"Fig. 14: state trajectories, {res.signal} ({tracking(res)})")
    return drawn


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
    outdir = folder(outdir)
    cfg, fi = inputs.cfg, inputs
    files: list[Path] = []

    def one(name: str, draw: Callable, size: tuple[float, float] = SIZE) -> None:
        files.append(save_figure(outdir / f"{name}.png", draw, size))

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
