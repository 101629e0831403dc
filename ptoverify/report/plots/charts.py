"""The penalty against move size and the coarse design chart, drawn from ``results.json``.

plot_penalty   settling time and its ratio to N* T against move size, per law
plot_design    the fastest law at each (T, bandwidth), its lead, and where the PTO's
               zone degenerates or its linear zone is unstable with one sample of delay
save_charts    both figures of the report's charts stage
save_penalty   one penalty figure under a given file stem
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.colors import ListedColormap

from ptoverify.report.plots.common import folder, inner_legend, save_drawing
from ptoverify.report.words import law_name, setting_words

__all__ = ["plot_penalty", "plot_design", "save_charts", "save_penalty", "LAW_COLOURS"]

#: Colour and label of each law in these figures.
LAW_COLOURS = {
    law: (colour, law_name(law))
    for law, colour in (
        ("to", "tab:red"),
        ("pd", "tab:blue"),
        ("pto", "tab:green"),
        ("ptos", "tab:purple"),
        ("cascade-p", "tab:brown"),
    )
}


def _col(values) -> np.ndarray:
    return np.array([np.nan if v is None else float(v) for v in values])


def plot_penalty(penalty: Mapping, axes) -> dict:
    """Draw settling time [ms] (left) and settling / (N* T) (right) against move size.

    Parameters
    ----------
    penalty : Mapping
        :func:`ptoverify.report.charts.penalty_results` (``sizes_mm``, ``t_f_s``,
        ``nt_s``, ``laws`` -> ``settling_s``, ``ratio_nt``; None where not settled).
    axes : sequence of two matplotlib Axes
        Where to draw.

    Returns
    -------
    dict
        Legend label -> Line2D (left panel).
    """
    left, right = axes
    s = _col(penalty["sizes_mm"])
    drawn: dict = {}
    (drawn["t_f*"],) = left.loglog(s, 1e3 * _col(penalty["t_f_s"]), "k-", lw=1.0, label="$t_f^*$")
    (drawn["N* T"],) = left.loglog(s, 1e3 * _col(penalty["nt_s"]), "k:", lw=1.0, label="$N^* T$")
    for law, c in penalty["laws"].items():
        colour, label = LAW_COLOURS.get(law, ("grey", law_name(law)))
        (drawn[label],) = left.loglog(
            s, 1e3 * _col(c["settling_s"]), color=colour, lw=1.3, label=label
        )
        right.semilogx(s, _col(c["ratio_nt"]), color=colour, lw=1.3, label=label)
    right.axhline(1.0, color="k", ls=":", lw=1.0)
    left.set_xlabel("move size [mm]")
    left.set_ylabel(f"settling time ({penalty['settling_definition']}) [ms]")
    right.set_xlabel("move size [mm]")
    right.set_ylabel("settling / ($N^* T$) [-]")
    left.set_title(setting_words(penalty["setting"]), fontsize=9)
    right.set_title("ratio to the sampled limit (not settled: no point)", fontsize=9)
    for ax in axes:
        ax.grid(True, which="both", lw=0.3)
    inner_legend(left, fontsize=7)
    return drawn


def plot_design(design: Mapping, ax) -> dict:
    """Draw the fastest law per (T, bandwidth) cell, its lead, and the PTO's warnings.

    Each cell is coloured by the law with the least median settling / (N* T) and
    labelled with it and the runner-up's ratio over it; ``Z`` marks a cell where
    the PTO's corrected zone is unusable or degenerate, ``D`` one where its linear
    zone is unstable with one sample of delay.

    Parameters
    ----------
    design : Mapping
        :func:`ptoverify.report.charts.design_results`.
    ax : matplotlib Axes
        Where to draw.

    Returns
    -------
    dict
        Law label -> a legend patch handle (the laws that are fastest somewhere).
    """
    from matplotlib.patches import Patch

    ts, fs = design["sample_times_s"], design["bandwidths_hz"]
    laws = list(design["laws"])
    colours = [LAW_COLOURS.get(law, ("grey", law))[0] for law in laws] + ["lightgrey"]
    code = np.full((len(ts), len(fs)), len(laws), dtype=float)
    for p in design["points"]:
        i, j = ts.index(p["sample_time"]), fs.index(p["bandwidth_hz"])
        if p["fastest"] in laws:
            code[i, j] = laws.index(p["fastest"])
        by = p["fastest_by"]
        lead = f"x{by:.3g}" if isinstance(by, (int, float)) else ""
        short = LAW_COLOURS.get(p["fastest"], ("", p["fastest"] or "none"))[1].split(" (")[0]
        pto = next((r for r in p["laws"] if r["law"] == "pto"), None)
        marks = ""
        if not p["pto_zone_usable"] or p["pto_zone_degenerate"]:
            marks += "Z"
        rho = pto["radius_delay1"] if pto is not None else None
        if isinstance(rho, (int, float)) and rho >= 1.0:
            marks += "D"
        label = f"{short}\n{lead} {marks}".strip()  # in its cell: no part of the layout
        ax.text(j, i, label, ha="center", va="center", fontsize=7, in_layout=False)
    ax.imshow(
        code, cmap=ListedColormap(colours), vmin=-0.5, vmax=len(laws) + 0.5, aspect="auto",
        alpha=0.55,
    )  # fmt: skip
    ax.set_xticks(range(len(fs)), [f"{f:g}" for f in fs])
    ax.set_yticks(range(len(ts)), [f"{1e3 * t:g}" for t in ts])
    ax.set_xlabel(r"bandwidth $f$ [Hz] ($a = 2\pi f$)")
    ax.set_ylabel("sample time $T$ [ms]")
    ax.set_title(
        "fastest law by median settling / (N* T); Z: PTO zone unusable or degenerate; "
        "D: PTO linear zone unstable with one sample of delay",
        fontsize=7,
    )
    used = sorted({int(c) for c in code.ravel() if c < len(laws)})
    handles = {
        LAW_COLOURS[laws[k]][1]: Patch(color=colours[k], alpha=0.55, label=LAW_COLOURS[laws[k]][1])
        for k in used
    }
    ax.legend(handles=list(handles.values()), fontsize=7, loc="upper left", bbox_to_anchor=(1, 1))
    return handles


def save_penalty(penalty: Mapping, outdir: str | Path, stem: str) -> list[Path]:
    """Write ``<stem>.png`` (:func:`plot_penalty`).

    Parameters
    ----------
    penalty : Mapping
        :func:`ptoverify.report.charts.penalty_results`.
    outdir : str or Path
        Folder (created if missing).
    stem : str
        File stem (a key of the report's CAPTIONS).

    Returns
    -------
    list of Path
        The file written.
    """
    path = folder(outdir) / f"{stem}.png"
    return [save_drawing(path, lambda fig: plot_penalty(penalty, fig.subplots(1, 2)), (9.6, 4.0))]


def save_charts(charts: Mapping, outdir: str | Path) -> list[Path]:
    """Write ``penalty_moves.png`` and ``design_chart.png`` of the report's charts stage.

    Parameters
    ----------
    charts : Mapping
        ``penalty`` (:func:`ptoverify.report.charts.penalty_results`) and ``design``
        (:func:`ptoverify.report.charts.design_results`).
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        The files written.
    """
    out = save_penalty(charts["penalty"], outdir, "penalty_moves")
    path = folder(outdir) / "design_chart.png"
    out.append(save_drawing(path, lambda fig: plot_design(charts["design"], fig.add_subplot()),
                            (8.0, 4.6)))  # fmt: skip
    return out
