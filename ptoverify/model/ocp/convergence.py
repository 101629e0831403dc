"""Convergence of the collocation minimum time towards the closed form."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant

from .collocation import CollocationOCP


# ---------------------------------------------------------------- convergence
@dataclass(frozen=True)
class ConvergenceStudy:
    """Collocation t_f error against the number of intervals.

    Attributes
    ----------
    intervals : ndarray, shape (M,)
        The interval counts N.
    states : ndarray, shape (S, 2)
        Initial states [mm], [mm/s].
    t_f_exact : ndarray, shape (S,)
        Closed-form minimum times [s].
    t_switch_exact : ndarray, shape (S,)
        Closed-form switch times [s].
    t_f : ndarray, shape (S, M)
        Collocation t_f [s] (NaN where IPOPT failed).
    rel_error : ndarray, shape (S, M)
        |t_f - t_f_exact| / t_f_exact.
    resim_error : ndarray, shape (S, M)
        Re-simulation distance from the origin [mm].
    order_per_state : ndarray, shape (S,)
        Least-squares slope of -log(rel_error) against log(N), per state.
    order : float
        The same slope pooled over all states (common slope, per-state offsets).
    success : ndarray of bool, shape (S, M)
        IPOPT converged.
    profiles : dict
        (state index, N) -> (t [s], u [mm/s]) of the solves, for plotting.
    results : dict
        (state index, N) -> the :class:`OCPResult` of each (cold) solve, e.g. for
        ``verified_mintime(..., collocation=...)`` at the same N.
    """

    intervals: NDArray[np.int64]
    states: NDArray[np.float64]
    t_f_exact: NDArray[np.float64]
    t_switch_exact: NDArray[np.float64]
    t_f: NDArray[np.float64]
    rel_error: NDArray[np.float64]
    resim_error: NDArray[np.float64]
    order_per_state: NDArray[np.float64]
    order: float
    success: NDArray[np.bool_]
    profiles: dict = field(default_factory=dict, repr=False)
    results: dict = field(default_factory=dict, repr=False)


def _slope(logn: NDArray, loge: NDArray) -> float:
    ok = np.isfinite(loge)
    if ok.sum() < 2:
        return math.nan
    return float(-np.polyfit(logn[ok], loge[ok], 1)[0])


def convergence_study(
    plant: Plant,
    states,
    intervals=(10, 20, 40, 80, 100, 200, 400),
    degree: int = 3,
    control: str = "points",
) -> ConvergenceStudy:
    """Collocation t_f error vs N and the observed order of convergence.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).
    states : array_like, shape (S, 2)
        Initial states [mm], [mm/s] (not the origin).
    intervals : sequence of int
        Interval counts N.
    degree : int
        Radau degree.

    Returns
    -------
    ConvergenceStudy
        Errors, orders and the input profiles.
    """
    from ptoverify.model.mintime import min_time

    states = np.atleast_2d(np.asarray(states, dtype=float))
    ns = np.asarray(intervals, dtype=int)
    mt = min_time(states[:, 0], states[:, 1], plant)
    exact = np.asarray(mt.t_f, dtype=float)
    tf = np.full((len(states), len(ns)), np.nan)
    rs = np.full_like(tf, np.nan)
    ok = np.zeros(tf.shape, dtype=bool)
    profiles, results = {}, {}
    for j, n in enumerate(ns):
        ocp = CollocationOCP(
            plant, intervals=int(n), degree=degree, warm_start=False, control=control
        )
        for i, (x1, x2) in enumerate(states):
            r = ocp.solve(x1, x2)
            tf[i, j], rs[i, j], ok[i, j] = r.t_f, r.resim_error, r.success
            profiles[(i, int(n))] = (r.t, r.u)
            results[(i, int(n))] = r
    rel = np.abs(tf - exact[:, None]) / exact[:, None]
    with np.errstate(divide="ignore"):
        loge = np.log(np.where(rel > 0, rel, np.nan))
    logn = np.log(ns.astype(float))
    per_state = np.array([_slope(logn, row) for row in loge])
    # pooled: remove each state's mean, then one slope
    good = np.isfinite(loge)
    cent_e = loge - np.nanmean(np.where(good, loge, np.nan), axis=1, keepdims=True)
    cent_n = np.where(good, logn[None, :], np.nan)
    cent_n = cent_n - np.nanmean(cent_n, axis=1, keepdims=True)
    m = np.isfinite(cent_e) & np.isfinite(cent_n)
    spread = float(cent_n[m] @ cent_n[m])  # 0 with a single N: no slope
    order = float(-(cent_e[m] @ cent_n[m]) / spread) if spread > 0 else math.nan
    return ConvergenceStudy(
        intervals=ns,
        states=states,
        t_f_exact=exact,
        t_switch_exact=np.asarray(mt.t_switch, dtype=float),
        t_f=tf,
        rel_error=rel,
        resim_error=rs,
        order_per_state=per_state,
        order=order,
        success=ok,
        profiles=profiles,
        results=results,
    )
