"""Figures of the collocation convergence study (matplotlib, Agg backend).

Kept apart from :mod:`ptoverify.ocp`, which returns data only; the suite's
``plots.py`` may absorb these functions.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ptoverify.ocp import ConvergenceStudy  # noqa: E402

__all__ = ["plot_convergence", "plot_switch_profiles"]


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


def plot_switch_profiles(study: ConvergenceStudy, state: int = 0, ax=None,
                         window: float = 0.15):
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
