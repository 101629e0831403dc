"""Per-trajectory properties of the robustness study on mismatched plants.

Part of :mod:`ptoverify.studies.robust.maps` (which re-exports every public
name here, and whose docstring defines each property): the horizon, the
nominal law of a study and the measures of one batch of trajectories.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config, Plant
from ptoverify.model.laws import Law, make_law
from ptoverify.model.mintime import min_time
from ptoverify.model.reach import zonotope_steps_each
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import grid_overshoot, grid_settling
from ptoverify.sim.simulate import BatchResult, Mismatch, simulate_batch
from ptoverify.studies.properties import oscillating, stride_over_counts

__all__ = ["SETTLING", "LawSpec", "horizon_steps", "nominal_law", "trajectory_properties"]

#: The settling definition of the maps and the worst-case search (the sweep's, by name).
SETTLING = "box-0p01mm"


def horizon_steps(cfg: Config) -> int:
    """Return the horizon [samples]: twice the envelope at the slowest drive, + 60/a.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its box (the slowest a and w_max of the box).

    Returns
    -------
    int
        Samples simulated per trajectory.
    """
    p, box = cfg.plant, cfg.robustness
    w = p.w_max * box.w_max_ratio[0]
    a = p.a * box.a_ratio[0]
    return int(math.ceil((2.0 * p.position_range / w + 60.0 / a) / p.sample_time))


def _true_plant(plant: Plant, a_ratio: float, w_ratio: float) -> Plant:
    return replace(plant, a=plant.a * a_ratio, w_max=plant.w_max * w_ratio)


def _n_star(x1: NDArray, x2: NDArray, a_ratio: NDArray, w_ratio: NDArray, plant: Plant) -> NDArray:
    """N* of each state for its own true plant (a_ratio, w_max_ratio), nan where not found.

    One vectorized zonotope search for every mix of plants
    (:func:`ptoverify.model.reach.zonotope_steps_each`), started from the continuous
    bound ceil(t_f* / T) of the true plant (t_f* in the plant's dimensionless time,
    min_time of the unit plant; the start only changes the number of tests).
    """
    a, w = plant.a * a_ratio, plant.w_max * w_ratio
    unit = replace(plant, a=1.0, w_max=1.0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        tau = min_time(a * x1 / w, x2 / w, unit).t_f  # a t_f* [-]
        n0 = np.nan_to_num(np.ceil(tau / (a * plant.sample_time) - 1e-9), nan=1.0, posinf=1.0)
    steps = zonotope_steps_each(x1, x2, np.maximum(n0, 1.0), a, w, plant.sample_time)
    return np.where(steps >= 0, steps, np.nan).astype(float)


LawSpec = str | Callable[[Config], Law]


def nominal_law(spec: LawSpec, cfg: Config) -> Law:
    """Build the nominal law: a name for :func:`make_law`, or a factory ``f(cfg) -> Law``.

    Parameters
    ----------
    spec : str or callable
        Law name (``to``, ``pd``, ``pto``, ``pto-printed``) or a factory.
    cfg : Config
        Nominal configuration (the law's design).

    Returns
    -------
    Law
        The law.
    """
    return make_law(spec, cfg) if isinstance(spec, str) else spec(cfg)


def trajectory_properties(
    law_name: LawSpec,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    mismatch: Mismatch,
    *,
    steps: int | None = None,
    with_settling: bool | NDArray[np.bool_] = True,
    batch: BatchResult | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Simulate ``law_name`` (nominal design) on a mismatched plant and measure each state.

    Parameters
    ----------
    law_name : str or callable
        ``to``, ``pd``, ``pto`` or ``pto-printed``, or a factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration (the law's design and the box).
    x1, x2 : ndarray, shape (n,)
        Initial states [mm], [mm/s].
    mismatch : Mismatch
        The plant and measurement (a_ratio and w_max_ratio may be arrays of shape (n,)).
    steps : int, optional
        Horizon [samples]; default covers the slowest plant of the box.
    with_settling : bool or ndarray of bool, shape (n,)
        Also compute the settling ratios (needs t_f* and N* of each true plant),
        for every state or for the states of a mask (nan elsewhere).
    batch : BatchResult, optional
        The simulation of exactly these states, mismatch and horizon, when the
        caller already has it (it is measured, not simulated again).

    Returns
    -------
    dict
        Arrays of shape (n,): ``stride_overs`` [-], ``limit_cycle_mm`` [mm],
        ``overshoot_mm`` [mm] (nan where x0 is not at rest), ``settling_s`` [s],
        ``settling_ratio_nt`` and ``settling_ratio_tf`` [-] (see module docstring).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> cfg = paper_config()
    >>> out = trajectory_properties("pd", cfg, np.array([5.0]), np.array([0.0]), Mismatch())
    >>> float(out["stride_overs"][0]), bool(out["settling_ratio_nt"][0] > 1.0)
    (0.0, True)
    """
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    steps = horizon_steps(cfg) if steps is None else steps
    if batch is None:
        batch = simulate_batch(
            nominal_law(law_name, cfg), cfg.plant, x1, x2, steps, mismatch=mismatch
        )
    return _measure(batch, cfg, x1, x2, mismatch, with_settling, with_tf=True)


def _limit_cycle_mm(x1: NDArray) -> NDArray[np.float64]:
    """Peak |x1| [mm] of the last quarter of each trajectory that oscillates there, else 0."""
    window = max(20, (x1.shape[0] - 1) // 4)
    tail = x1[-window:]
    return np.where(oscillating(tail, 1e-3), np.abs(tail).max(axis=0), 0.0)


def _measure(
    b: BatchResult,
    cfg: Config,
    x1: NDArray,
    x2: NDArray,
    mismatch: Mismatch,
    with_settling: bool | NDArray[np.bool_],
    *,
    with_tf: bool,
) -> dict[str, NDArray[np.float64]]:
    """Measure the properties of :func:`trajectory_properties` on a simulated batch.

    ``with_tf`` False leaves ``settling_ratio_tf`` out (the study reads only the
    ratio to N*T; t_f* of each true plant is then not computed).
    """
    n = x1.size
    amp = _limit_cycle_mm(b.x1)
    rest = np.flatnonzero((x2 == 0.0) & (np.abs(x1) >= cfg.pto.d) & (x1 != 0.0))
    over = np.full(n, np.nan)
    if rest.size:  # the largest excursion beyond the origin, on the side opposite to x1_0
        over[rest] = grid_overshoot(b.x1[:, rest] if rest.size < n else b.x1, 0.0)
    out = {
        "stride_overs": stride_over_counts(b.x1, b.x2, b.region, cfg).astype(float),
        "limit_cycle_mm": amp,
        "overshoot_mm": over,
    }
    need = np.broadcast_to(np.asarray(with_settling, dtype=bool), (n,))
    if not need.any():
        return out
    T = cfg.plant.sample_time
    sel = np.flatnonzero(need)
    x1s, x2s = (b.x1, b.x2) if sel.size == n else (b.x1[:, sel], b.x2[:, sel])
    # the true state on the samples; the box's velocity band is the design a's (the one
    # box every law is judged by, whatever the true plant)
    t = np.arange(x1s.shape[0]) * T
    us = np.zeros((x1s.shape[0] - 1, x1s.shape[1]))  # not read on the samples
    settled = np.full(n, np.nan)
    settled[sel] = grid_settling(Trajectory(t, x1s, x2s, us, cfg.plant.a), None, SETTLING)
    settle = np.where(np.isnan(settled), np.inf, settled)
    ar = np.broadcast_to(np.asarray(mismatch.a_ratio, dtype=float), (n,))
    wr = np.broadcast_to(np.asarray(mismatch.w_max_ratio, dtype=float), (n,))
    n_star = np.full(n, np.nan)
    n_star[sel] = _n_star(x1[sel], x2[sel], ar[sel], wr[sel], cfg.plant)
    with np.errstate(divide="ignore", invalid="ignore"):
        out["settling_s"] = np.where(need, settle, np.nan)
        ratio_nt = np.where(n_star > 0, settle / (n_star * T), 0.0)
        out["settling_ratio_nt"] = np.where(need & ~np.isnan(n_star), ratio_nt, np.nan)
    if with_tf:
        t_f = np.full(n, np.nan)
        for key in set(zip(ar[need].tolist(), wr[need].tolist(), strict=True)):
            on = (ar == key[0]) & (wr == key[1]) & need
            t_f[on] = min_time(x1[on], x2[on], _true_plant(cfg.plant, *key)).t_f
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio_tf = np.where(t_f > 0, settle / t_f, 0.0)
            out["settling_ratio_tf"] = np.where(need & ~np.isnan(t_f), ratio_tf, np.nan)
    return out
