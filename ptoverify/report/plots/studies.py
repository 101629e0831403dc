"""Figures of the studies: sweep and robustness heat maps, tuning fronts, collocation.

The sweep's maps of settling time over t_f* or N* T (:func:`plot_sweep`), the
robustness maps over the parameter box (:func:`plot_robust_map`), the fair
tuning's Pareto fronts (:func:`plot_pareto`) and the collocation convergence
study (:func:`plot_convergence`, :func:`plot_switch_profiles`), each drawn on
``ax`` or a new figure from results the caller computed; the ``save_*``
functions write each family's PNGs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.colors import ListedColormap
from numpy.typing import NDArray

from ptoverify.report.plots.common import (
    folder,
    inner_legend,
    new_axes,
    new_figure,
    save_figure,
    write_png,
)
from ptoverify.report.plots.pareto import plot_pareto
from ptoverify.report.words import law_name, plural
from ptoverify.sim.settling import DEFINITIONS

if TYPE_CHECKING:  # data types for annotations only: no solver, no sweep
    from ptoverify.model.ocp import ConvergenceStudy
    from ptoverify.studies.sweep import SweepResult

__all__ = [
    "plot_sweep",
    "save_sweep",
    "ROBUST_MAPS",
    "plot_robust_map",
    "save_robust",
    "save_tuning",
    "plot_convergence",
    "plot_switch_profiles",
    "save_ground_truth",
]


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
    ax = new_axes(ax)
    ls = res.laws[law]
    ratio = ls.ratio_tf if which == "tf" else ls.ratio_nt
    den = "$t_f^*$" if which == "tf" else "$N^* T$"
    box, st = DEFINITIONS["box-0p01mm"], res.settings
    named = (st.band, st.hold, st.velocity_band) == (box.band_mm, box.hold_s, None)
    definition = box.name if named else f"a {st.band:g} mm box"
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
        for label in ax.clabel(drawn["contours"], fmt="%g", fontsize=6):
            label.set_in_layout(False)  # on lines inside the axes: no part of the layout
    wr = ls.worst_state_tf if which == "tf" else ls.worst_state_nt
    worst = ls.worst_ratio_tf if which == "tf" else ls.worst_ratio_nt
    if math.isfinite(wr[0]):
        (drawn["worst"],) = ax.plot(*wr, "r*", ms=10, label=f"worst ratio {worst:.2f}")
    if colorbar:
        clipped = bool(finite.size) and float(finite.max()) > vmax
        drawn["colorbar"] = ax.figure.colorbar(
            drawn["mesh"],
            ax=ax,
            label=_sweep_label(which, vmax if clipped else None),
            extend="max" if clipped else "neither",
        )
    ax.set_xlabel("initial position $x_1$ [mm]")
    ax.set_ylabel("initial velocity $x_2$ [mm/s]")
    ax.set_title(
        f"{law_name(law)}: settling ({definition}) / {den}; grey: never settles "
        f"({100 * (1 - ls.fraction_settled):.0f} %)",
        fontsize=8,
    )
    if "worst" in drawn:
        inner_legend(ax, fontsize=7, loc="upper right")
    return drawn


def _floor_of(ratios: NDArray[np.float64]) -> float:
    """Bottom of a ratio map's colour scale: its least finite value, at most 1 (0.9 if none)."""
    return min(1.0, float(ratios.min())) if ratios.size else 0.9


def _sweep_label(which: str, clip: float | None = None) -> str:
    """Colour-bar label; says where the scale clips (the arrow's colour is every larger value)."""
    text = f"settling time / {'$t_f^*$' if which == 'tf' else '$N^* T$'} [-]"
    return text if clip is None else f"{text}; clipped at {clip:.3g} (99th percentile)"


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
    outdir = folder(outdir)
    files: list[Path] = []
    laws = list(res.laws)
    cols = 2 if len(laws) > 1 else 1
    rows = math.ceil(len(laws) / cols)
    for which in ("tf", "nt"):
        ratios = [r.ratio_tf if which == "tf" else r.ratio_nt for r in res.laws.values()]
        finite = np.concatenate([r[np.isfinite(r)] for r in ratios])
        vmax = max(2.0, float(np.percentile(finite, 99))) if finite.size else 2.0
        fig = new_figure((5.3 * cols + 1.0, 4.2 * rows))
        grid = fig.add_gridspec(rows, cols)
        panels = [fig.add_subplot(grid[k // cols, k % cols]) for k in range(len(laws))]
        for ax, law in zip(panels, laws, strict=True):
            scale = {"vmin": _floor_of(finite), "vmax": vmax}
            mesh = plot_sweep(res, law, which, ax, **scale, colorbar=False)["mesh"]
        clipped = bool(finite.size) and float(finite.max()) > vmax
        fig.colorbar(
            mesh,
            ax=panels,
            label=_sweep_label(which, vmax if clipped else None),
            extend="max" if clipped else "neither",
        )
        files.append(write_png(fig, outdir / f"sweep_ratio_{which}.png"))
    return files


#: Quantities of the robustness heat maps: cell key, colour-bar label, file stem.
ROBUST_MAPS = (
    ("limit_cycle_states", "states ending in a limit cycle [count]", "robust_limit_cycles"),
    ("settling_ratio_nt", "worst settling / ($N^* T$) [-]", "robust_settling_nt"),
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
    ax = new_axes(ax)
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
        colour = "w" if dark else "k"  # (inside its cell: no part of the layout)
        ax.text(j, i, text, ha="center", va="center", fontsize=7, color=colour, in_layout=False)
    ax.set_xticks(range(len(ars)), [f"{r:.3g}" for r in ars], fontsize=7)
    ax.set_yticks(range(len(wrs)), [f"{r:.3g}" for r in wrs], fontsize=7)
    ax.set_xlabel(r"$a_{\mathrm{true}}/a_{\mathrm{design}}$ [-]")
    ax.set_ylabel(r"$w_{\max,\mathrm{true}}/w_{\max}$ [-]")
    lag = f"a delay of {plural(delay, 'sample')}" if delay else "no delay"
    ax.set_title(f"{law_name(law)}, {lag}", fontsize=9)
    return {"map": mesh}


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
    outdir = folder(outdir)
    laws, delays = list(maps["laws"]), list(maps["delay_samples"])
    files = []
    for key, label, stem in ROBUST_MAPS:
        vals = [_robust_cell_value(c, key) for law in laws for c in maps["laws"][law]]
        finite = [v for v in vals if math.isfinite(v)]
        vmax = max(max(finite, default=1.0), 1.0)
        fig = new_figure((3.8 * len(delays) + 1.2, 2.9 * len(laws)))
        panels = fig.subplots(len(laws), len(delays), squeeze=False)
        for (r, c), ax in np.ndenumerate(panels):
            mesh = plot_robust_map(maps, laws[r], key, delays[c], ax, vmax=vmax)["map"]
            if r < len(laws) - 1:
                ax.set_xlabel("")
            if c > 0:
                ax.set_ylabel("")
        fig.colorbar(mesh, ax=panels.ravel().tolist(), label=label)
        files.append(write_png(fig, outdir / f"{stem}.png"))
    return files


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
    outdir = folder(outdir)
    path = outdir / "tuning_pareto.png"
    return [save_figure(path, lambda ax: plot_pareto(tuning, ax))]


# ------------------------------------------------------------ collocation study
def plot_convergence(study: ConvergenceStudy, ax=None) -> dict:
    """Plot the relative t_f error against N, one line per state.

    Parameters
    ----------
    study : ConvergenceStudy
        Output of :func:`ptoverify.model.ocp.convergence_study`.
    ax : matplotlib Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    dict
        Legend label -> Line2D: one ``x0 = (x1 mm, x2 mm/s)`` line per state
        (N [-] against |t_f - t_f*| / t_f* [-]) and the ``slope -2`` guide.
    """
    ax = new_axes(ax, (6.0, 4.0))
    drawn: dict = {}
    n = study.intervals.astype(float)
    markers = "osD^v<>"
    for k, ((x1, x2), err) in enumerate(zip(study.states, study.rel_error, strict=True)):
        label = f"x0 = ({x1:g} mm, {x2:g} mm/s)"
        (drawn[label],) = ax.loglog(
            n, err, marker=markers[k % len(markers)], ms=7 - k, lw=1.2, alpha=0.8, label=label
        )
    ref = np.nanmax(study.rel_error[:, 0]) * (n / n[0]) ** -2.0
    (drawn["slope -2"],) = ax.loglog(n, ref, "k--", lw=0.8, label="slope -2")
    ax.set_xlabel("collocation intervals $N$ [-]")
    ax.set_ylabel(r"$|t_f - t_f^*|\,/\,t_f^*$ [-]")
    with np.errstate(invalid="ignore"):
        rises = bool(np.any(np.diff(study.rel_error, axis=1) > 0))
    ax.set_title(
        f"Radau collocation: log-log slope {study.order:.2f} over all N"
        + (" (the error is not monotone in N)" if rises else ""),
        fontsize=9,
    )
    ax.grid(True, which="both", lw=0.3)
    inner_legend(ax, fontsize=7)
    return drawn


def plot_switch_profiles(
    study: ConvergenceStudy, state: int = 0, ax=None, window: float = 0.15
) -> dict:
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
    dict
        Legend label -> Line2D: ``N = n`` (the input u [mm/s] against t [s],
        one per number of intervals with a solution), ``switch (closed form)``
        and ``t_f* (closed form)``.
    """
    ax = new_axes(ax, (6.0, 4.0))
    drawn: dict = {}
    tf = float(study.t_f_exact[state])
    ts = float(study.t_switch_exact[state])
    x1, x2 = study.states[state]
    for n in study.intervals:
        t, u = study.profiles[(state, int(n))]
        if t is None or u is None or len(u) == 0:
            continue
        label = f"N = {n}"
        (drawn[label],) = ax.step(t, np.append(u, u[-1]), where="post", lw=0.9, label=label)
    for at, ls, label in ((ts, "--", "switch (closed form)"), (tf, ":", "t_f* (closed form)")):
        drawn[label] = ax.axvline(at, color="k", lw=0.6, ls=ls, label=label)
    ax.set_xlim(max(0.0, ts - window * tf), min(ts + window * tf, 1.02 * tf))
    ax.set_xlabel("time $t$ [s]")
    ax.set_ylabel("input $u$ [mm/s]")
    ax.set_title(f"collocation input near the switch, x0 = ({x1:g} mm, {x2:g} mm/s)")
    ax.grid(True, lw=0.3)
    inner_legend(ax, fontsize=7)
    return drawn


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
    outdir = folder(outdir)
    return [
        save_figure(outdir / "convergence.png", lambda ax: plot_convergence(study, ax)),
        save_figure(
            outdir / "collocation_switch.png", lambda ax: plot_switch_profiles(study, 0, ax)
        ),
    ]


def save_proof_map(proof: Any, path: str | Path) -> Path:
    """Draw the certified bound of a proof per cell (``prove --out``, the report).

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
    ratio = proof.ratio_nt
    two = ratio is not None and bool(np.isfinite(ratio).any())
    fig = new_figure((13.0, 4.8) if two else (7.5, 4.8))
    ax = fig.add_subplot(1, 2, 1) if two else fig.add_subplot()
    e1, e2 = proof.grid.e1, proof.grid.e2
    n1, n2 = proof.grid.shape
    if two:  # the certified suboptimality map: bound / N* per cell
        rx = fig.add_subplot(1, 2, 2)
        rz = np.ma.masked_invalid(np.asarray(ratio, dtype=float).reshape(n2, n1))
        rm = rx.pcolormesh(e1, e2, rz, cmap="magma", shading="flat")
        fig.colorbar(rm, ax=rx, label="certified samples to the target / $N^*$ [-]")
        rx.set_xlabel("position $x_1$ [mm]")
        rx.set_ylabel("velocity $x_2$ [mm/s]")
        rx.set_title("certified suboptimality (blank: unproven or near the origin)", fontsize=9)
    bound = np.asarray(proof.bound, dtype=float).reshape(n2, n1)
    z = np.ma.masked_invalid(bound)
    mesh = ax.pcolormesh(e1, e2, z, cmap="viridis", shading="flat")
    bad = ~np.isfinite(bound)
    if bad.any():
        ax.pcolormesh(
            e1, e2, np.ma.masked_where(~bad, np.ones_like(bound)), cmap="Reds", vmin=0, vmax=1
        )
    fig.colorbar(mesh, ax=ax, label="certified samples to the target ellipse [samples]")
    ax.set_xlabel("position $x_1$ [mm]")
    ax.set_ylabel("velocity $x_2$ [mm/s]")
    ax.set_title(f"{law_name(proof.law)}: certified bound per cell (red: unproven)")
    return write_png(fig, path)
