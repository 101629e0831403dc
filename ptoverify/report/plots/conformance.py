"""Figures of ``conform --report``: the |u - u_ref| maps and the user law's responses.

Drawn from the evidence :func:`ptoverify.conform.evidence.conform_with_evidence`
computed: nothing here runs the user's law.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.colors import LogNorm

from ptoverify.report.plots.common import finish, folder, new_axes, new_figure, tracking, write_png

if TYPE_CHECKING:  # data types for annotations only
    from ptoverify.sim.simulate import SimResult

__all__ = ["plot_du_map", "plot_conform_response", "save_conform_figures"]


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
    ax = new_axes(ax)
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
    cbar = ax.figure.colorbar(
        drawn["mesh"], ax=ax, label=r"largest $|u - u_{\mathrm{ref}}|$ in cell [mm/s]"
    )
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
    ax.set_xlabel("position $x_1$ [mm]")
    ax.set_ylabel("velocity $x_2$ [mm/s]")
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
    ax = new_axes(ax)
    drawn: dict = {}
    if quantity == "position":
        (drawn["your law"],) = ax.plot(user.t, user.x1, color="tab:blue", lw=1.8, label="your law")
        (drawn["reference PTO"],) = ax.plot(
            ref.t, ref.x1, color="tab:green", lw=1.2, ls="--", label="reference PTO (eq. 35)"
        )
        (drawn["r"],) = ax.plot(user.t, user.r, color="k", lw=0.8, ls=":", label="reference r")
        ylab = "position $x_1$ [mm]"
    else:
        (drawn["difference"],) = ax.plot(
            user.t, user.x1 - ref.x1, color="tab:red", lw=1.2, label="x1 (your law) - x1 (ref.)"
        )
        ylab = "$x_1$ difference [mm]"
    finish(
        ax,
        f"{user.signal} response ({tracking(user)}), {quantity}",
        xlab="time $t$ [s]",
        ylab=ylab,
    )
    return drawn


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
    outdir = folder(outdir)
    out: dict[str, Path] = {}
    maps = evidence.maps
    if evidence.judged:
        top = max([m.max for m in maps] + [10.0 * maps[0].tolerance])
        fig = new_figure((13.0, 5.0))
        for m, ax in zip(maps, np.atleast_1d(fig.subplots(1, len(maps))), strict=True):
            plot_du_map(m, evidence.boundaries, ax, vmax=top, marks=marks)
        out["du_map"] = write_png(fig, outdir / "du_map.png")
    for name, resp in (evidence.responses or {}).items():
        fig = new_figure((6.4, 5.6))
        a1, a2 = fig.subplots(2, 1, sharex=True)
        plot_conform_response(resp.user, resp.reference, "position", a1)
        plot_conform_response(resp.user, resp.reference, "difference", a2)
        out[f"response_{name}"] = write_png(fig, outdir / f"response_{name}.png")
    return out
