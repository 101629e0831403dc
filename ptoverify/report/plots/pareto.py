"""The tuning's Pareto fronts: settling against overshoot, with the floor and the fronts' gap."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ptoverify.report.plots.common import inner_legend, new_axes
from ptoverify.report.words import law_name

__all__ = ["plot_pareto"]


def plot_pareto(tuning: Mapping, ax=None) -> dict:
    """Settling-vs-overshoot Pareto fronts of PD and PTO on the step, with the floor.

    Parameters
    ----------
    tuning : mapping
        :func:`ptoverify.studies.claims.fair_comparison`: ``fronts`` (law -> candidates
        with ``overshoot_mm`` [mm] and ``settling_2pct_s`` [s]), ``best`` (bound
        -> law -> candidate), ``paper`` (law -> metrics at the paper's gains),
        ``bounds_mm`` (bound -> [mm]), ``floor`` (``tf_s``, ``nt_s``,
        ``band_entry_s`` [s]) and ``fronts_gap`` (the PTO's front minus the PD's:
        ``overshoot_mm`` [mm], ``gap_s`` [s], or ``None``), drawn as an inset.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Legend label -> artist.
    """
    ax = new_axes(ax)
    drawn: dict = {}
    colors = {
        "pd": "tab:orange",
        "pto": "tab:green",
        "ptos": "tab:purple",
        "cascade-p": "tab:brown",
    }
    offscale: list[tuple[float, float, str, str]] = []  # (overshoot, ms, colour, what)
    ys: list[float] = []
    for k, (law, front) in enumerate(tuning["fronts"].items()):
        col, name = colors.get(law, "tab:blue"), law_name(law)
        pts = sorted(
            (c["overshoot_mm"], 1e3 * c["settling_2pct_s"])
            for c in front
            if c.get("settling_2pct_s") is not None and c.get("overshoot_mm") is not None
        )
        if pts:
            x, y = np.array(pts).T
            ys += list(y)
            # the first front wide and pale, later ones narrower on top: equal fronts stay visible
            (drawn[f"{name}: front"],) = ax.step(
                x, y, where="post", color=col, lw=max(3.5 - 1.2 * k, 1.0), alpha=0.75,
                marker=".", ms=3, zorder=2 + k,
            )  # fmt: skip
        bests = [b[law] for b in tuning["best"].values() if law in b]
        ys += [1e3 * b["settling_2pct_s"] for b in bests]
        drawn[f"{name}: best per bound"] = ax.scatter(
            [b["overshoot_mm"] for b in bests],
            [1e3 * b["settling_2pct_s"] for b in bests],
            color=col,
            marker="*",
            s=140,
            edgecolor="k",
            lw=0.4,
            zorder=6,
        )
        p = tuning["paper"].get(law, {})
        if p.get("settling_2pct_s") is not None:
            px, py = p["overshoot_mm"], 1e3 * p["settling_2pct_s"]
            drawn[f"{name}: paper's gains"] = ax.scatter(
                [px], [py], color=col, marker="s", zorder=6
            )
            offscale.append((px, py, col, f"{name}, paper's gains: {py:.1f} ms"))
    fl = tuning["floor"]
    drawn["t_f* (exact arrival)"] = ax.axhline(1e3 * fl["tf_s"], color="k", ls="--", lw=1)
    drawn["N* T (sampled arrival)"] = ax.axhline(1e3 * fl["nt_s"], color="k", ls=":", lw=1)
    drawn["least 2 % band entry"] = ax.axhline(1e3 * fl["band_entry_s"], color="0.5", lw=1)
    for name, bound in tuning["bounds_mm"].items():
        law = name.removesuffix("-paper")
        what = f"{law_name(law)}'s at the paper's gains" if law != name else name
        drawn[f"overshoot bound: {what}"] = ax.axvline(bound, color="0.6", lw=0.8, ls="-.")
    # zoom on the fronts and the floor; a point above is marked at the top edge
    floor = 1e3 * min(fl["tf_s"], fl["nt_s"], fl["band_entry_s"])
    top = 1e3 * fl["nt_s"]
    if ys:  # the fronts' bulk; a few slow candidates may run off the top
        top = max(top, float(np.percentile(ys, 90)))
    top *= 1.08
    ax.set_ylim(0.97 * floor, top)
    for px, py, col, what in offscale:
        if py > top:
            ax.annotate(
                what, (px, top), xytext=(4, -14), textcoords="offset points", fontsize=7,
                color=col, arrowprops={"arrowstyle": "-|>", "color": col}, annotation_clip=False,
            )  # fmt: skip
    ax.set_xlabel("overshoot, between samples [mm]")
    ax.set_ylabel("2 % settling time of the step [ms]")
    inner_legend(ax, list(drawn.values()), list(drawn), fontsize=6, loc="upper right")
    ax.grid(alpha=0.3)
    _front_difference_inset(tuning["fronts_gap"], ax)
    return drawn


def _front_difference_inset(gap, ax) -> None:
    """Inset: the PTO's front minus the PD's (``fronts_gap``; the fronts overlap at full scale)."""
    if gap is None:
        return
    x, y = np.asarray(gap["overshoot_mm"]), 1e3 * np.asarray(gap["gap_s"])
    ins = ax.inset_axes([0.1, 0.42, 0.42, 0.3])
    ins.step(x, y, where="post", color="tab:green", lw=1.2)
    ins.axhline(0.0, color="k", lw=0.6)
    ins.set_title(f"{law_name(gap['law'])} front - {law_name(gap['minus'])} front [ms]", fontsize=7)
    ins.tick_params(labelsize=6)
    ins.set_xlabel("overshoot [mm]", fontsize=6)
    ins.grid(alpha=0.3)
