"""Figures 2-14 of the paper and the sweep's heat maps (the only matplotlib module).

Every plot function takes ``ax=None`` (a new figure when None), draws on it
and returns what it drew: a dict from legend label to artist.  Nothing is
shown; the backend is Agg unless the caller chose another one first.

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

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

if "MPLBACKEND" not in os.environ:
    matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

from ptoverify.config import Config  # noqa: E402
from ptoverify.curves import h, level_curve_x1  # noqa: E402
from ptoverify.laws import LAW_NAMES, Region, make_law  # noqa: E402
from ptoverify.metrics import TIGHT_BAND  # noqa: E402
from ptoverify.plant import flow  # noqa: E402
from ptoverify.simulate import SimResult, simulate, simulate_batch  # noqa: E402
from ptoverify.zones import corrected_zone, printed_zone  # noqa: E402

if TYPE_CHECKING:
    from ptoverify.ocp import ConvergenceStudy

__all__ = [
    "plot_fig2",
    "plot_fig3",
    "plot_zones",
    "plot_fig5",
    "plot_fig6",
    "plot_response",
    "plot_state_trajectories",
    "plot_sweep",
    "save_all",
    "save_sweep",
    "plot_zone_geometry",
    "plot_convergence",
    "plot_switch_profiles",
    "save_ground_truth",
    "save_zone_geometry",
]

DPI = 110
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


def _ax(ax):
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.2))
    return ax


def _curve(ax, a: float, omega: float, x2, drawn: dict, label: str, **kw) -> None:
    (line,) = ax.plot(level_curve_x1(x2, a, omega), x2, label=label, **kw)
    drawn[label] = line


def _switching(ax, cfg: Config, drawn: dict, *, lim: float | None = None) -> None:
    a, w = cfg.plant.a, cfg.plant.w_max
    top = w if lim is None else lim
    neg, pos = np.linspace(-top, 0, 300), np.linspace(0, top, 300)
    _curve(ax, a, w, neg, drawn, "l1 (eq. 9), x2 <= 0", color="k", lw=1.8)
    _curve(ax, a, w, pos, drawn, "l2 (eq. 11), x2 >= 0", color="k", lw=1.8, ls="-.")


def plot_fig2(cfg: Config, ax=None) -> dict:
    """Fig. 2: trajectories under u = +-w_max (eqs. 8, 10) and the curves l1, l2.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s]).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    a, w = cfg.plant.a, cfg.plant.w_max
    drawn: dict = {}
    t = np.linspace(0, 6 / a, 200)
    span = 4 * w / a
    for x10 in np.linspace(-span, span, 7):
        for u, x20, col, lab in (
            (w, -0.95 * w, "tab:blue", "u = +w_max (eq. 8)"),
            (-w, 0.95 * w, "tab:cyan", "u = -w_max (eq. 10)"),
        ):
            x1, x2 = flow(x10, x20, u, t, a)
            (line,) = ax.plot(x1, x2, color=col, lw=0.8)
            drawn.setdefault(lab, line).set_label(lab)
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
    ax.set_xlim(-span * 1.5, span * 1.5)
    _finish(ax, "Fig. 2: trajectories under +-w_max and the switching curve", drawn)
    return drawn


def _finish(
    ax, title: str, drawn: dict, xlab="position x1 [mm]", ylab="velocity x2 [mm/s]"
) -> None:
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")


def plot_fig3(cfg: Config, ax=None, *, steps: int | None = None) -> dict:
    """Fig. 3: sampled time-optimal trajectories with the saturation |x2| <= w_max.

    Parameters
    ----------
    cfg : Config
        Configuration.
    ax : matplotlib Axes, optional
        Where to draw.
    steps : int, optional
        Samples simulated (default 3 t_f* of the farthest start).

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    p = cfg.plant
    drawn: dict = {}
    R, w = p.position_range, p.w_max
    x10 = np.array([R, R, 0.6 * R, -R, -0.6 * R, -R, 0.3 * R, -0.3 * R])
    x20 = np.array([0.0, -0.8 * w, 0.9 * w, 0.0, -0.9 * w, 0.8 * w, 0.0, 0.0])
    n = steps or int(math.ceil(3 * (2 * R / w + 3 / p.a) / p.T))
    b = simulate_batch(make_law("to", cfg), p, x10, x20, n)
    for j in range(x10.size):
        (line,) = ax.plot(b.x1[:, j], b.x2[:, j], color="tab:blue", lw=0.8)
        drawn["TO closed loop (sampled)"] = line
    line.set_label("TO closed loop (sampled)")
    _switching(ax, cfg, drawn, lim=0.999 * w)
    for s in (1, -1):
        ln = ax.axhline(s * w, color="tab:red", ls="--", lw=1)
    ln.set_label("saturation |x2| = w_max")
    drawn["saturation |x2| = w_max"] = ln
    _finish(ax, "Fig. 3: trajectories with velocity saturation (TO, eq. 12)", drawn)
    return drawn


def _zone(cfg: Config, variant: str):
    from ptoverify.zones import zone_for_law

    return zone_for_law(cfg, variant)


def _zone_xlim(cfg: Config, omega0: float) -> float:
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    reach = (
        float(level_curve_x1(-w, a, omega0)) if 0 < omega0 < w else float(level_curve_x1(-w, a, w))
    )
    return max(4 * d, 1.3 * reach)


def plot_zones(cfg: Config, variant: str = "corrected", ax=None) -> dict:
    """Fig. 4: switching zone (l1 to l1*, l2 to l2*) and linear zone |x1| < d.

    Parameters
    ----------
    cfg : Config
        Configuration.
    variant : {"corrected", "printed"}
        Which zone construction (``ptoverify.zones``).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    z = _zone(cfg, variant)
    drawn: dict = {}
    drawn["linear zone |x1| < d"] = ax.axvspan(
        -d, d, color="tab:green", alpha=0.15, label="linear zone |x1| < d"
    )
    _switching(ax, cfg, drawn, lim=w)
    neg, pos = np.linspace(-w, 0, 300), np.linspace(0, w, 300)
    if 0 < z.omega0 < w:
        om = z.omega0
        _curve(
            ax,
            a,
            om,
            neg,
            drawn,
            f"l1* (eq. 13), omega0 = {om:.4g} mm/s",
            color="tab:orange",
            lw=1.6,
        )
        _curve(ax, a, om, pos, drawn, "l2* (eq. 14)", color="tab:orange", lw=1.6, ls="-.")
        drawn["switching zone"] = ax.fill_betweenx(
            neg,
            level_curve_x1(neg, a, w),
            level_curve_x1(neg, a, om),
            color="tab:orange",
            alpha=0.25,
            label="switching zone S~_P, S~_N",
        )
        ax.fill_betweenx(
            pos,
            level_curve_x1(pos, a, om),
            level_curve_x1(pos, a, w),
            color="tab:orange",
            alpha=0.25,
        )
    else:
        drawn["no zone"] = ax.text(
            0.02,
            0.04,
            f"{variant}: omega0 = {z.omega0:.4g} mm/s, no switching zone",
            transform=ax.transAxes,
            fontsize=7,
        )
    lim = _zone_xlim(cfg, z.omega0)
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-1.05 * w, 1.05 * w)
    _finish(ax, f"Fig. 4: switching and linear zones ({variant})", drawn)
    return drawn


def plot_fig5(cfg: Config, variant: str = "corrected", ax=None) -> dict:
    """Fig. 5: l1, l1* and the one-sample image l~1 of l1 (eq. 19 and exact).

    Parameters
    ----------
    cfg : Config
        Configuration.
    variant : {"corrected", "printed"}
        Zone whose l1* is drawn.
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
    z = _zone(cfg, variant)
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
    f1, f2 = flow(level_curve_x1(neg, a, w), neg, -w, T, a)
    (line,) = ax.plot(f1, f2, color="tab:purple", label="image of l1 after T under -w_max")
    drawn[line.get_label()] = line
    if 0 < z.omega0 < w:
        _curve(
            ax,
            a,
            z.omega0,
            neg,
            drawn,
            f"l1* ({variant}, omega0 = {z.omega0:.4g} mm/s)",
            color="tab:orange",
            lw=1.6,
        )
    if math.isfinite(z.x20_tilde) and abs(z.x20_tilde) <= w:
        (pt,) = ax.plot(
            [d],
            [z.x20_tilde],
            "o",
            color="tab:red",
            label=f"(x~10, x~20) = ({d:g}, {z.x20_tilde:.4g})",
        )
        drawn[pt.get_label()] = pt
    drawn["x1 = d"] = ax.axvline(d, color="tab:green", ls=":", label="x1 = d")
    lim = _zone_xlim(cfg, z.omega0)
    ax.set_xlim(-0.5 * lim, lim)
    ax.set_ylim(-1.05 * w, 0.05 * w)
    _finish(ax, f"Fig. 5: l1, l1* and l~1 ({variant})", drawn)
    return drawn


def plot_fig6(
    cfg: Config,
    law: str = "pto",
    ax=None,
    *,
    x0: tuple[float, float] | None = None,
    steps: int = 60,
) -> dict:
    """Fig. 6: a trajectory from the fourth quadrant, each sample marked by region.

    Parameters
    ----------
    cfg : Config
        Configuration.
    law : str
        ``pto`` or ``pto-printed``.
    ax : matplotlib Axes, optional
        Where to draw.
    x0 : tuple of float, optional
        Initial state (x1 [mm], x2 [mm/s]); default (4 d, -w_max / 3).
    steps : int
        Samples simulated.

    Returns
    -------
    dict
        Label -> artist.
    """
    variant = "printed" if law == "pto-printed" else "corrected"
    drawn = plot_zones(cfg, variant, ax)
    ax = drawn["l1 (eq. 9), x2 <= 0"].axes
    x0 = x0 or (4 * cfg.pto.d, -cfg.plant.w_max / 3)
    b = simulate_batch(make_law(law, cfg), cfg.plant, [x0[0]], [x0[1]], steps)
    (line,) = ax.plot(b.x1[:, 0], b.x2[:, 0], color="0.4", lw=0.8, label=f"{law} trajectory")
    drawn[line.get_label()] = line
    reg = b.region[:, 0]
    lo, hi = ax.get_xlim()
    ax.set_xlim(min(lo, 1.15 * min(x0[0], 0)), max(hi, 1.15 * max(x0[0], 0)))
    for code, (col, lab) in REGION_STYLE.items():
        k = np.flatnonzero(reg == code)
        if k.size:
            key = f"sample in {lab}"
            drawn[key] = ax.scatter(b.x1[k, 0], b.x2[k, 0], s=14, color=col, zorder=3, label=key)
    ax.set_title(
        f"Fig. 6: {law} from ({x0[0]:g} mm, {x0[1]:g} mm/s), region of each sample", fontsize=9
    )
    ax.legend(fontsize=6, loc="lower left")
    return drawn


def _sims(cfg: Config, signal: str, feedforward: bool) -> dict[str, SimResult]:
    return {
        name: simulate(make_law(name, cfg), cfg.plant, signal, feedforward=feedforward)
        for name in LAW_NAMES
    }


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


def plot_response(
    cfg: Config,
    signal: str,
    quantity: str = "position",
    ax=None,
    *,
    feedforward: bool = True,
    sims: dict | None = None,
) -> dict:
    """Figs. 7-13: position, velocity or error of every law on a reference.

    Parameters
    ----------
    cfg : Config
        Configuration.
    signal : {"step", "ramp", "sine"}
        Reference.
    quantity : {"position", "velocity", "error"}
        What to draw against time.
    ax : matplotlib Axes, optional
        Where to draw.
    feedforward : bool
        Reading: reference velocity fed forward.
    sims : dict, optional
        Precomputed responses by law name.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    sims = sims or _sims(cfg, signal, feedforward)
    attr, ylab = _QUANT[quantity]
    drawn: dict = {}
    for name, res in sims.items():
        (line,) = ax.plot(res.t, getattr(res, attr), **STYLE[name])
        drawn[STYLE[name]["label"]] = line
    any_res = next(iter(sims.values()))
    if quantity in ("position", "velocity"):
        ref = any_res.r if quantity == "position" else any_res.r_dot
        (line,) = ax.plot(any_res.t, ref, color="k", lw=0.8, ls=":", label="reference")
        drawn["reference"] = line
    else:
        d = cfg.pto.d
        for s in (1, -1):
            ld = ax.axhline(s * d, color="tab:green", ls="--", lw=0.7)
            lb = ax.axhline(s * TIGHT_BAND, color="0.5", ls=":", lw=0.7)
        ld.set_label(f"linear zone +-d = +-{d:g} mm")
        lb.set_label(f"tight band +-{TIGHT_BAND:g} mm")
        drawn[ld.get_label()], drawn[lb.get_label()] = ld, lb
        ax.set_ylim(-3 * d, 3 * d) if signal != "sine" else None
    ff = "feed-forward" if feedforward else "no feed-forward"
    fig = _FIGNUM.get((signal, quantity))
    num = f"Fig. {fig}: " if fig else ""
    _finish(
        ax,
        f"{num}{signal} response: {quantity} ({ff}, a = {cfg.plant.a:.4g} rad/s)",
        drawn,
        xlab="time t [s]",
        ylab=ylab,
    )
    return drawn


def plot_state_trajectories(
    cfg: Config,
    signal: str = "sine",
    ax=None,
    *,
    feedforward: bool = True,
    sims: dict | None = None,
) -> dict:
    """Fig. 14: state trajectories (x1, x2) of every law, with the reference (r, r').

    Parameters
    ----------
    cfg : Config
        Configuration.
    signal : str
        Reference (default the sine of Sec. 6.3).
    ax : matplotlib Axes, optional
        Where to draw.
    feedforward : bool
        Reading: reference velocity fed forward.
    sims : dict, optional
        Precomputed responses by law name.

    Returns
    -------
    dict
        Label -> artist.
    """
    ax = _ax(ax)
    sims = sims or _sims(cfg, signal, feedforward)
    drawn: dict = {}
    for name, res in sims.items():
        (line,) = ax.plot(res.x1, res.x2, **{**STYLE[name], "lw": 0.8})
        drawn[STYLE[name]["label"]] = line
    res = next(iter(sims.values()))
    (line,) = ax.plot(res.r, res.r_dot, color="k", ls=":", lw=0.8, label="reference (r, r')")
    drawn["reference"] = line
    ff = "feed-forward" if feedforward else "no feed-forward"
    _finish(ax, f"Fig. 14: state trajectories, {signal} ({ff})", drawn)
    return drawn


def plot_sweep(res, law: str, which: str = "tf", ax=None, *, vmax: float | None = None) -> dict:
    """Heat map of a law's settling time over t_f* (``tf``) or N* T (``nt``).

    Parameters
    ----------
    res : SweepResult
        Output of :func:`ptoverify.sweep.run_sweep`.
    law : str
        Law name.
    which : {"tf", "nt"}
        Denominator: continuous t_f* or discrete N* T.
    ax : matplotlib Axes, optional
        Where to draw.
    vmax : float, optional
        Top of the colour scale [-] (default: the 99th percentile, at least 2).

    Returns
    -------
    dict
        ``mesh`` (ratio), ``unsettled`` (grey cells where the law never settles),
        ``worst`` (marker at the worst state), ``colorbar``.
    """
    ax = _ax(ax)
    ls = res.laws[law]
    ratio = ls.ratio_tf if which == "tf" else ls.ratio_nt
    den = "t_f*" if which == "tf" else "N* T"
    drawn: dict = {}
    finite = ratio[np.isfinite(ratio)]
    if vmax is None:
        vmax = max(2.0, float(np.nanpercentile(finite, 99))) if finite.size else 2.0
    drawn["mesh"] = ax.pcolormesh(
        res.x1,
        res.x2,
        np.ma.masked_invalid(ratio),
        shading="nearest",
        cmap="viridis",
        vmin=min(1.0, finite.min()) if finite.size else 0.9,
        vmax=vmax,
    )
    bad = ~np.isfinite(ls.settle_time)
    drawn["unsettled"] = ax.pcolormesh(
        res.x1,
        res.x2,
        np.ma.masked_where(~bad, bad.astype(float)),
        shading="nearest",
        cmap=ListedColormap(["0.6"]),
    )
    wr = ls.worst_state_tf if which == "tf" else ls.worst_state_nt
    worst = ls.worst_ratio_tf if which == "tf" else ls.worst_ratio_nt
    if math.isfinite(wr[0]):
        (drawn["worst"],) = ax.plot(*wr, "r*", ms=10, label=f"worst ratio {worst:.2f}")
    drawn["colorbar"] = ax.figure.colorbar(drawn["mesh"], ax=ax, label=f"settling time / {den} [-]")
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


def _save(fig, path: Path, out: list[Path]) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    out.append(path)


def save_sweep(res, outdir: str | Path) -> list[Path]:
    """Write the sweep's heat maps (one PNG per denominator, a panel per law).

    The panels of one PNG share their colour scale, so the laws compare by eye.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    laws = list(res.laws)
    cols = 2 if len(laws) > 1 else 1
    rows = math.ceil(len(laws) / cols)
    for which in ("tf", "nt"):
        ratios = [r.ratio_tf if which == "tf" else r.ratio_nt for r in res.laws.values()]
        finite = np.concatenate([r[np.isfinite(r)] for r in ratios])
        vmax = max(2.0, float(np.percentile(finite, 99))) if finite.size else 2.0
        fig, axes = plt.subplots(rows, cols, figsize=(5.6 * cols, 4.2 * rows), squeeze=False)
        for ax, law in zip(axes.flat, laws, strict=False):
            plot_sweep(res, law, which, ax, vmax=vmax)
        for ax in list(axes.flat)[len(laws) :]:
            ax.set_visible(False)
        _save(fig, outdir / f"sweep_ratio_{which}.png", files)
    return files


def save_all(cfg: Config, outdir: str | Path) -> list[Path]:
    """Write Figs. 2-14 as PNGs (dpi 110) and return their paths.

    Zone figures come for both constructions; response figures for ramp and
    sine for both feed-forward readings (suffix ``_noff`` without).

    Parameters
    ----------
    cfg : Config
        Configuration.
    outdir : str or Path
        Folder (created if missing).

    Returns
    -------
    list of Path
        The files written.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []

    def one(name: str, draw) -> None:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        draw(ax)
        _save(fig, outdir / f"{name}.png", files)

    one("fig02_trajectories", lambda ax: plot_fig2(cfg, ax))
    one("fig03_saturation", lambda ax: plot_fig3(cfg, ax))
    for v in ("corrected", "printed"):
        one(f"fig04_zones_{v}", lambda ax, v=v: plot_zones(cfg, v, ax))
        one(f"fig05_l1_image_{v}", lambda ax, v=v: plot_fig5(cfg, v, ax))
    for law in ("pto", "pto-printed"):
        one(f"fig06_trajectory_{law}", lambda ax, law=law: plot_fig6(cfg, law, ax))
    step = _sims(cfg, "step", True)
    one("fig07_step_position", lambda ax: plot_response(cfg, "step", "position", ax, sims=step))
    one("fig08_step_error", lambda ax: plot_response(cfg, "step", "error", ax, sims=step))
    for ff, sfx in ((True, ""), (False, "_noff")):
        ramp, sine = _sims(cfg, "ramp", ff), _sims(cfg, "sine", ff)
        for num, q in ((9, "position"), (10, "velocity"), (11, "error")):
            one(
                f"fig{num:02d}_ramp_{q}{sfx}",
                lambda ax, q=q, ff=ff, s=ramp: plot_response(
                    cfg, "ramp", q, ax, feedforward=ff, sims=s
                ),
            )
        for num, q in ((12, "position"), (13, "velocity")):
            one(
                f"fig{num:02d}_sine_{q}{sfx}",
                lambda ax, q=q, ff=ff, s=sine: plot_response(
                    cfg, "sine", q, ax, feedforward=ff, sims=s
                ),
            )
        one(
            f"fig14_sine_states{sfx}",
            lambda ax, ff=ff, s=sine: plot_state_trajectories(
                cfg, "sine", ax, feedforward=ff, sims=s
            ),
        )
    return files


def save_ground_truth(study, outdir: str | Path) -> list[Path]:
    """Write the collocation convergence and switch-profile figures; return the paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    plot_convergence(study, ax)
    _save(fig, outdir / "convergence.png", files)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    plot_switch_profiles(study, 0, ax)
    _save(fig, outdir / "collocation_switch.png", files)
    return files


def save_zone_geometry(cfg: Config, outdir: str | Path) -> list[Path]:
    """Write the zone-geometry figure with sampled trajectories; return the path."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    plot_zone_geometry(cfg, ax)
    _save(fig, outdir / "zone_geometry.png", files)
    return files


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


def plot_zone_geometry(
    cfg: Config,
    ax=None,
    starts: tuple[tuple[float, float], ...] | None = None,
    steps: int = 60,
    x1_max: float | None = None,
) -> dict:
    """Draw the zone geometry and sampled PTO trajectories.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    ax : matplotlib Axes, optional
        Axes to draw on; a new figure when None.
    starts : tuple of (x1, x2), optional
        Initial states [mm], [mm/s] of the trajectories; default a few states
        right of l1* and their mirror images.
    steps : int
        Samples per trajectory.
    x1_max : float, optional
        Half-width of the x1 axis [mm]; default 4 d or l1* at -w_max, whichever is larger.

    Returns
    -------
    dict
        ``figure``, ``ax``, ``lines`` (name -> Line2D), ``zone`` and ``printed``
        (:class:`~ptoverify.zones.PTOZone`).
    """
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    zc, zp = corrected_zone(cfg, verify=False), printed_zone(cfg)
    om = zc.omega0 if zc.usable else w
    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 6))
    fig = ax.figure
    s = np.linspace(0.0, w, 400)
    l1 = level_curve_x1(-s, a, w)
    l1s = level_curve_x1(-s, a, om)
    xmax = x1_max or max(4 * d, 1.3 * float(l1s[-1]))
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
    s19 = np.linspace(0.0, max(w, -zp.x20_tilde if np.isfinite(zp.x20_tilde) else w), 400)
    x19 = (-2 * a * w * T + s19 - w * np.log1p(s19 / w)) / a
    (lines["eq19"],) = ax.plot(x19, -s19, ":", color="tab:purple", label="printed curve (19)")
    ax.axvspan(-d, d, color="tab:green", alpha=0.08, label=f"linear zone |x1| < {d:g} mm")
    if starts is None:
        x0 = np.linspace(1.2, 0.9 * xmax / max(d, 1e-9), 4) * d
        starts = tuple((float(v), 0.0) for v in x0) + ((float(xmax * 0.9), -w),)
        starts = starts + tuple((-x, -v) for x, v in starts)
    res = simulate_batch(
        make_law("pto", cfg), cfg.plant, [p[0] for p in starts], [p[1] for p in starts], steps
    )
    for j in range(len(starts)):
        ax.plot(res.x1[:, j], res.x2[:, j], "-", color="0.6", lw=0.7)
    for reg, (mk, col) in _ZONE_MARKERS.items():
        sel = res.region == reg
        if sel.any():
            ax.plot(
                res.x1[:-1][sel],
                res.x2[:-1][sel],
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
    return {"figure": fig, "ax": ax, "lines": lines, "zone": zc, "printed": zp}


# ------------------------------------------------------------ collocation study
def plot_convergence(study: ConvergenceStudy, ax=None):
    """Plot the relative t_f error against N, one line per state.

    Parameters
    ----------
    study : ConvergenceStudy
        Output of :func:`ptoverify.ocp.convergence_study`.
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
        Output of :func:`ptoverify.ocp.convergence_study`.
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
