"""Figure of the switching-zone geometry (Section 4, Figs. 4-5), computed.

Draws l1, l2 (eqs. 9, 11), the corrected l1*, l2* (eqs. 13, 14), the printed
curve (19), the zones S~_P / S~_N, the linear zone |x1| < d, and sampled
trajectories of the corrected PTO law with the region of every sample marked.
Headless (Agg); the function takes ``ax=None`` and returns what it drew.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ptoverify.config import Config  # noqa: E402
from ptoverify.curves import level_curve_x1  # noqa: E402
from ptoverify.laws import Region, make_law  # noqa: E402
from ptoverify.simulate import simulate_batch  # noqa: E402
from ptoverify.zones import corrected_zone, printed_zone  # noqa: E402

__all__ = ["plot_zone_geometry"]

_MARKERS = {Region.BANG_P: ("^", "tab:red"), Region.BANG_N: ("v", "tab:blue"),
            Region.ZONE_P: ("s", "tab:orange"), Region.ZONE_N: ("s", "tab:cyan"),
            Region.LINEAR: ("o", "tab:green"), Region.SATURATED: ("D", "tab:olive"),
            Region.ORIGIN: ("x", "k")}


def plot_zone_geometry(cfg: Config, ax=None, starts: tuple[tuple[float, float], ...] | None = None,
                       steps: int = 60, x1_max: float | None = None) -> dict:
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
    lines["l1"], = ax.plot(l1, -s, "k-", lw=1.5, label="l1, l2 (eqs. 9, 11)")
    ax.plot(-l1, s, "k-", lw=1.5)
    lines["l1*"], = ax.plot(l1s, -s, "--", color="tab:orange",
                            label=f"l1*, l2* corrected, omega0 = {om:.4g} mm/s")
    ax.plot(-l1s, s, "--", color="tab:orange")
    ax.fill_betweenx(-s, l1, l1s, color="tab:orange", alpha=0.15, label="zones S~_P, S~_N")
    ax.fill_betweenx(s, -l1s, -l1, color="tab:orange", alpha=0.15)
    # printed curve (19): a x1 + x2 + w ln(1 - x2/w) = -2 a w T
    s19 = np.linspace(0.0, max(w, -zp.x20_tilde if np.isfinite(zp.x20_tilde) else w), 400)
    x19 = (-2 * a * w * T + s19 - w * np.log1p(s19 / w)) / a
    lines["eq19"], = ax.plot(x19, -s19, ":", color="tab:purple", label="printed curve (19)")
    ax.axvspan(-d, d, color="tab:green", alpha=0.08, label=f"linear zone |x1| < {d:g} mm")
    if starts is None:
        x0 = np.linspace(1.2, 0.9 * xmax / max(d, 1e-9), 4) * d
        starts = tuple((float(v), 0.0) for v in x0) + ((float(xmax * 0.9), -w),)
        starts = starts + tuple((-x, -v) for x, v in starts)
    res = simulate_batch(make_law("pto", cfg), cfg.plant, [p[0] for p in starts],
                         [p[1] for p in starts], steps)
    for j in range(len(starts)):
        ax.plot(res.x1[:, j], res.x2[:, j], "-", color="0.6", lw=0.7)
    for reg, (mk, col) in _MARKERS.items():
        sel = res.region == reg
        if sel.any():
            ax.plot(res.x1[:-1][sel], res.x2[:-1][sel], mk, color=col, ms=3, ls="none",
                    label=f"sample: {reg.name}")
    ax.set_xlim(-xmax, xmax)
    ax.set_ylim(-1.1 * w, 1.1 * w)
    ax.set_xlabel("position x1 [mm]")
    ax.set_ylabel("velocity x2 [mm/s]")
    ax.set_title(f"{cfg.name}: switching zone, T = {T * 1e3:g} ms, a = {a:.4g} rad/s")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, alpha=0.3)
    return {"figure": fig, "ax": ax, "lines": lines, "zone": zc, "printed": zp}
