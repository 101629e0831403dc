"""The gates of the ground truth: flows, roots, minimum times, input bound, symmetry."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ptoverify.config import Config
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict, at_most

from .registry import gate

if TYPE_CHECKING:
    from .registry import GateContext


def _random_states(cfg: Config, n: int, seed: int, vmax: float = 1.0) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    p = cfg.plant
    return (
        rng.uniform(-p.position_range, p.position_range, n),
        rng.uniform(-vmax * p.w_max, vmax * p.w_max, n),
    )


# ------------------------------------------------------------------ core gates
@gate("zoh-vs-integrator", "1")
def _zoh_vs_integrator(ctx: GateContext) -> Verdict:
    """Exact one-sample map against an adaptive ODE integrator at rtol 1e-12."""
    from scipy.integrate import solve_ivp

    from ptoverify.model.plant import step

    cfg = ctx.cfg
    p = cfg.plant
    x1, x2 = _random_states(cfg, 40, 11, 1.5)
    u = np.random.default_rng(12).uniform(-p.w_max, p.w_max, 40)
    y1, y2 = step(x1, x2, u, p)
    err = 0.0
    for i in range(40):
        sol = solve_ivp(
            lambda _, y, ui=u[i]: [y[1], -p.a * y[1] + p.a * ui],
            (0, p.T),
            [x1[i], x2[i]],
            rtol=1e-12,
            atol=1e-12,
            method="DOP853",
        )
        scale = 1.0 + abs(x1[i]) + abs(x2[i]) * p.T
        err = max(
            err, abs(sol.y[0, -1] - y1[i]) / scale, abs(sol.y[1, -1] - y2[i]) / (1.0 + abs(x2[i]))
        )
    return at_most(
        "zoh-vs-integrator",
        err,
        1e-9,
        "max relative difference of the ZOH one-sample map (eq. 7/15) from "
        "DOP853 at rtol 1e-12 over 40 random states and inputs; limit 1e-9 is the "
        "integrator's accuracy, not the map's",
    )


@gate("roots-closed-form-vs-bisection", "1")
def _roots(ctx: GateContext) -> Verdict:
    """Lambert-W closed forms of eqs. (22), (26)/(31) against bisection to the last bit."""
    from ptoverify.model.curves import root_22, root_22_bisect, root_k, root_k_bisect

    rng = np.random.default_rng(13)
    b0 = np.concatenate([rng.uniform(0, 20, 2000), 10 ** rng.uniform(-12, 2, 2000)])
    m = np.concatenate([rng.uniform(0, 0.999, 2000), 10 ** rng.uniform(-12, -0.01, 2000)])
    e22 = np.max(np.abs(root_22(b0) - root_22_bisect(b0)) / root_22_bisect(b0))
    ek = np.max(np.abs(root_k(m) - root_k_bisect(m)) / root_k_bisect(m))
    return at_most(
        "roots-closed-form-vs-bisection",
        max(e22, ek),
        1e-13,
        f"max relative difference over 4,000 b0 (eq. 22: {e22:.1e}) and 4,000 "
        f"k = 1 - m in (0, 1) (eqs. 26, 31: {ek:.1e}); limit: a few hundred ulps",
    )


@gate("mintime-closed-form-vs-propagation", "1")
def _mintime_propagation(ctx: GateContext) -> Verdict:
    """Closed-form t_f and switch: the two arcs of the exact flow end at the origin."""
    from ptoverify.model.mintime import min_time
    from ptoverify.model.plant import flow

    cfg = ctx.cfg
    p = cfg.plant
    x1, x2 = _random_states(cfg, 20000, 14, 1.5)
    mt = min_time(x1, x2, p)
    y1, y2 = flow(x1, x2, -mt.side * p.w_max, mt.t_switch, p.a)
    z1, z2 = flow(y1, y2, mt.side * p.w_max, mt.t_f - mt.t_switch, p.a)
    # a miss of dz in position is a time error of about dz / |x2 near the end|; normalise by
    # the state's scale: round-off of eq. (7) over the two arcs
    miss = np.max(np.abs(z1) / (1 + np.abs(x1)) + np.abs(z2) / (p.w_max + np.abs(x2)))
    return at_most(
        "mintime-closed-form-vs-propagation",
        miss,
        1e-11,
        "max normalised distance from the origin after propagating the exact flow "
        "for the closed-form arc durations, 20,000 states with |x2| <= 1.5 w_max",
    )


@gate("input-bound", "mm/s")
def _input_bound(ctx: GateContext) -> Verdict:
    """|u| <= w_max for every law over a dense random cloud of states."""
    from ptoverify.model.laws import LAW_NAMES, make_law

    cfg = ctx.cfg
    x1, x2 = _random_states(cfg, 200000, 15, 2.0)
    x1 = np.concatenate([x1, x1 * 1e-3])
    x2 = np.concatenate([x2, x2 * 1e-3])
    worst, names = 0.0, []
    for name in LAW_NAMES:
        u, _ = make_law(name, cfg)(x1, x2)
        if not np.all(np.isfinite(u)):
            return Verdict(
                "input-bound",
                FAIL,
                math.inf,
                cfg.plant.w_max,
                f"law {name} returned a non-finite input",
            )
        worst = max(worst, float(np.max(np.abs(u))))
        names.append(name)
    return at_most(
        "input-bound",
        worst,
        cfg.plant.w_max,
        f"max |u| [mm/s] of {', '.join(names)} over 400,000 states (|x2| <= 2 w_max, "
        "also near the origin); limit w_max",
    )


@gate("odd-symmetry", "mm/s")
def _odd_symmetry(ctx: GateContext) -> Verdict:
    """u(-x) = -u(x) for every law (the plant is odd, so the laws must be)."""
    from ptoverify.model.laws import LAW_NAMES, make_law

    cfg = ctx.cfg
    x1, x2 = _random_states(cfg, 100000, 16, 1.5)
    worst = 0.0
    for name in LAW_NAMES:
        law = make_law(name, cfg)
        worst = max(worst, float(np.max(np.abs(law(x1, x2)[0] + law(-x1, -x2)[0]))))
    return at_most(
        "odd-symmetry",
        worst,
        1e-9 * cfg.plant.w_max,
        "max |u(x) + u(-x)| [mm/s] over 100,000 states for every law",
    )


# ------------------------------------------------------------ ground-truth gates
def _gt_states(cfg: Config, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    return _random_states(cfg, n, seed, 0.95)


def _ocp_vs_closed_form(
    name: str, cfg: Config, ocp, verify, n: int, seed: int, limit: float, detail: str
) -> Verdict:
    """Worst relative t_f difference of a verified OCP answer from the closed form.

    ``verify`` is the a-posteriori check of :mod:`ptoverify.studies.groundtruth` (the one
    definition of a verified answer): an answer that did not converge, or converged
    but fails its check, makes the gate ``unverified``.
    """
    from ptoverify.model.mintime import min_time

    x1, x2 = _gt_states(cfg, n, seed)
    mt = min_time(x1, x2, cfg.plant)
    worst = 0.0
    for i in range(n):
        res = verify(ocp.solve(float(x1[i]), float(x2[i])), float(x1[i]), float(x2[i]), cfg.plant)
        if not res.success:
            return Verdict(
                name,
                UNVERIFIED,
                None,
                limit,
                f"no verified answer at ({x1[i]:.4g}, {x2[i]:.4g}): {res.status}",
            )
        worst = max(worst, abs(res.t_f - mt.t_f[i]) / mt.t_f[i])
    return at_most(name, worst, limit, detail)


@gate("mintime-closed-form-vs-two-phase", "1")
def _two_phase(ctx: GateContext) -> Verdict:
    """CasADi two-phase OCP (IPOPT) against the closed-form minimum time."""
    from ptoverify.model.ocp import TwoPhaseOCP
    from ptoverify.studies.groundtruth import verify_two_phase

    cfg = ctx.cfg
    return _ocp_vs_closed_form(
        "mintime-closed-form-vs-two-phase",
        cfg,
        TwoPhaseOCP(cfg.plant, **ctx.solver_caps()),
        verify_two_phase,
        30,
        21,
        1e-9,
        "max relative t_f difference, two-phase OCP vs closed form, 30 random states "
        "in the envelope; limit 1e-9: IPOPT's tolerance on an exact flow",
    )


@gate("mintime-closed-form-vs-collocation", "1")
def _collocation(ctx: GateContext) -> Verdict:
    """CasADi Radau collocation (N = 100) against the closed-form minimum time."""
    from ptoverify.model.ocp import CollocationOCP
    from ptoverify.studies.groundtruth import verify_collocation

    cfg = ctx.cfg
    return _ocp_vs_closed_form(
        "mintime-closed-form-vs-collocation",
        cfg,
        CollocationOCP(cfg.plant, intervals=100, **ctx.solver_caps()),
        verify_collocation,
        8,
        22,
        5e-4,
        "max relative t_f difference, Radau-3 collocation with N = 100 vs closed form, 8 "
        "random states; limit 5e-4: the discretisation smears the switch over one interval "
        "(observed order ~2)",
    )


@gate("discrete-limit-consistency", "1")
def _discrete(ctx: GateContext) -> Verdict:
    """N*: N* T >= t_f*, the sequence reaches the origin, N* - 1 infeasible, zonotope = LP."""
    from ptoverify.model.mintime import (
        ZOHReach,
        discrete_min_steps,
        discrete_min_steps_batch,
        min_time,
    )

    cfg = ctx.cfg
    x1, x2 = _gt_states(cfg, 25, 23)
    reach = ZOHReach(cfg.plant)
    worst_gap, lp_steps = math.inf, []
    for i in range(len(x1)):
        dm = discrete_min_steps(float(x1[i]), float(x2[i]), cfg.plant)
        if not dm.success:
            return Verdict(
                "discrete-limit-consistency",
                UNVERIFIED,
                None,
                0.0,
                f"N* search failed at ({x1[i]:.4g}, {x2[i]:.4g}): {dm.status}",
                ">=",
            )
        t_f = float(min_time(x1[i], x2[i], cfg.plant).t_f)
        if dm.below is not None and dm.below[0] == dm.steps - 1:  # solved by the search
            why = dm.below[1]
            ok_prev = why == "feasible"
        else:
            ok_prev, _, why = reach.feasible(float(x1[i]), float(x2[i]), dm.steps - 1)
        if ok_prev:
            return Verdict(
                "discrete-limit-consistency",
                FAIL,
                None,
                0.0,
                f"N* - 1 = {dm.steps - 1} steps feasible at ({x1[i]:.4g}, {x2[i]:.4g})",
                ">=",
            )
        if why != "infeasible":
            return Verdict(
                "discrete-limit-consistency",
                UNVERIFIED,
                None,
                0.0,
                f"N* - 1 = {dm.steps - 1} steps at ({x1[i]:.4g}, {x2[i]:.4g}): "
                f"the LP was inconclusive ({why})",
                ">=",
            )
        if abs(dm.end[0]) > 1e-9 or abs(dm.end[1]) > 1e-6:
            return Verdict(
                "discrete-limit-consistency",
                FAIL,
                None,
                0.0,
                f"N* sequence ends at {dm.end} from ({x1[i]:.4g}, {x2[i]:.4g})",
                ">=",
            )
        worst_gap = min(worst_gap, (dm.time_s - t_f) / cfg.plant.T)
        lp_steps.append(dm.steps)
    zono = discrete_min_steps_batch(x1, x2, cfg.plant).steps  # the production path
    off = np.flatnonzero(zono != np.array(lp_steps))
    if off.size:
        i = int(off[0])
        return Verdict(
            "discrete-limit-consistency",
            FAIL,
            None,
            0.0,
            f"zonotope N* = {zono[i]} but LP N* = {lp_steps[i]} at ({x1[i]:.4g}, {x2[i]:.4g}) "
            f"({off.size} of {len(x1)} states disagree)",
            ">=",
        )
    res = Verdict(
        "discrete-limit-consistency",
        PASS if worst_gap >= 0 else FAIL,
        worst_gap,
        0.0,
        "min over 25 states of (N* T - t_f*) / T, which theory keeps >= 0; every "
        "N* sequence ends within 1e-9 mm, 1e-6 mm/s of the origin and N* - 1 "
        "samples are infeasible (LP status 'infeasible', not inconclusive); the zonotope "
        "N* (discrete_min_steps_batch, the production path) equals the LP's at every state",
        ">=",
    )
    return res
