"""The gates of ``ptoverify check``: each verification as pass / fail / unverified.

A gate is a function ``gate(ctx) -> Verdict`` of a :class:`GateContext` (the
configuration and the run's options, e.g. an IPOPT iteration cap); calling a
registered gate with a bare :class:`~ptoverify.config.Config` runs it with the
default options.  It measures one number in a stated unit, compares it with a
limit derived from the method (round-off, sampling, the paper's own principle),
and says why in ``detail``.  A gate whose reference
cannot be computed (a solver that does not converge, an exception) is
``unverified``, and ``unverified`` fails the run: the gate fails closed.

The paper's errata and Section 6 claims that do not reproduce are findings of
the report, not gate failures; a configuration whose loops are unstable when
sampled, or whose zone cannot be built, fails its gates.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InputError, SolverError
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict, at_most

__all__ = [
    "CheckResult",
    "GATES",
    "GATE_UNITS",
    "GateContext",
    "ROBUST_GATES",
    "ROBUST_STUDY_GATES",
    "PROOF_INTERVAL_GATE",
    "proof_interval_verdict",
    "robust_verdicts",
    "run_checks",
    "summarize",
]

#: Former name of the gates' result type, kept for compatibility: it *is* :class:`Verdict`.
CheckResult = Verdict


@dataclasses.dataclass
class GateContext:
    """What a gate sees: the configuration and the options of this run.

    Results shared by several gates (the corrected PTO's closed-loop properties)
    are computed once per context, so one ``run_checks`` call simulates them once.

    Attributes
    ----------
    cfg : Config
        Configuration under test.
    max_iter : int or None
        Cap on IPOPT iterations (None: the solvers' own caps).
    given_pto_properties : LawProperties or None
        The corrected PTO's properties on the default grid when the caller has
        them already (the report's properties section), else computed here.
    """

    cfg: Config
    max_iter: int | None = None
    given_pto_properties: Any = None

    def solver_caps(self) -> dict[str, int]:
        """Return keyword arguments capping IPOPT (empty without a cap)."""
        return {} if self.max_iter is None else {"max_iter": self.max_iter}

    @functools.cached_property
    def pto_properties(self):
        """Closed-loop properties of the corrected PTO law over the default grid."""
        if self.given_pto_properties is not None:
            return self.given_pto_properties
        from ptoverify.model.laws import make_law
        from ptoverify.studies.properties import law_properties

        return law_properties(make_law("pto", self.cfg), self.cfg)


Gate = Callable[[Config | GateContext], Verdict]
GATES: dict[str, Gate] = {}
#: Unit of each gate's measured figure and limit (``"1"``: dimensionless).
GATE_UNITS: dict[str, str] = {}


def gate(name: str, unit: str) -> Callable[[Callable[[GateContext], Verdict]], Gate]:
    """Register a gate under ``name`` measuring in ``unit``; exceptions make it ``unverified``.

    Parameters
    ----------
    name : str
        Stable gate name.
    unit : str
        Unit of the measured figure and its limit (``"1"`` when dimensionless).

    Returns
    -------
    callable
        Decorator registering ``fn(ctx) -> Verdict`` in :data:`GATES`.
    """

    def wrap(fn: Callable[[GateContext], Verdict]) -> Gate:
        @functools.wraps(fn)
        def safe(ctx: Config | GateContext) -> Verdict:
            if isinstance(ctx, Config):
                ctx = GateContext(ctx)
            try:
                res = fn(ctx)
            except SolverError as exc:
                res = Verdict(name, UNVERIFIED, None, None, f"solver failed: {exc}")
            except Exception as exc:  # noqa: BLE001 - a gate fails closed on any fault
                res = Verdict(
                    name,
                    UNVERIFIED,
                    None,
                    None,
                    f"could not be computed: {type(exc).__name__}: {exc}",
                )
            return dataclasses.replace(res, unit=unit, description=description)

        description = (fn.__doc__ or "").strip().splitlines()[0] if fn.__doc__ else ""
        GATES[name] = safe
        GATE_UNITS[name] = unit
        return safe

    return wrap


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


# ------------------------------------------------------------ derivation gate
@gate("derivation-identities-vs-numerics", "1")
def _derivations(ctx: GateContext) -> Verdict:
    """SymPy results (flow by dsolve, min-time closed form) lambdified against the numerics."""
    import sympy as sp

    from derivations.common import S, flow
    from derivations.section3 import min_time_closed_form
    from ptoverify.model.mintime import min_time
    from ptoverify.model.plant import flow as flow_num

    cfg = ctx.cfg
    p = cfg.plant
    a, w, t, u, x10, x20 = (S[n] for n in ("a", "omega_m", "t", "u", "x10", "x20"))
    fx1, fx2 = (sp.lambdify((x10, x20, u, t, a), e, "numpy") for e in flow(u))
    rng = np.random.default_rng(31)
    y1, y2 = _random_states(cfg, 500, 32, 1.5)
    uu = rng.uniform(-p.w_max, p.w_max, 500)
    tt = rng.uniform(0, 5 * p.T, 500)
    n1, n2 = flow_num(y1, y2, uu, tt, p.a)
    e_flow = max(
        np.max(np.abs(fx1(y1, y2, uu, tt, p.a) - n1) / (1 + np.abs(n1))),
        np.max(np.abs(fx2(y1, y2, uu, tt, p.a) - n2) / (1 + np.abs(n2))),
    )
    # the SymPy closed form is evaluated in 50-digit arithmetic: as printed by SymPy it
    # subtracts nearly equal numbers near x2 = -omega_m, which the numerics avoid
    import mpmath

    mt_sym = min_time_closed_form()
    f_tf = sp.lambdify((S["x1"], S["x2"], a, w), mt_sym["t_f"], "mpmath")
    mt = min_time(y1, y2, p)
    r1, r2 = mt.side * y1, mt.side * y2  # the SymPy form is for sigma >= 0
    e_tf = 0.0
    with mpmath.workdps(50):
        for i in np.flatnonzero(r2 > -p.w_max)[:200]:  # its logarithms need x2 > -omega_m
            ref = f_tf(mpmath.mpf(r1[i]), mpmath.mpf(r2[i]), mpmath.mpf(p.a), mpmath.mpf(p.w_max))
            e_tf = max(e_tf, abs(float(mpmath.re(ref)) - mt.t_f[i]) / mt.t_f[i])
    worst = max(e_flow, e_tf)
    return at_most(
        "derivation-identities-vs-numerics",
        worst,
        1e-12,
        f"max relative difference of the lambdified SymPy flow of eq. (1) "
        f"({e_flow:.1e}, 500 states) and of the SymPy minimum time evaluated in 50 "
        f"digits ({e_tf:.1e}, 200 states) from the float64 numerics; limit 1e-12: "
        "round-off of the numerics",
    )


# ------------------------------------------------------------ PTO / zone / pole gates
@gate("zone-corrected-valid", "1")
def _zone_valid(ctx: GateContext) -> Verdict:
    """Check that the corrected zone exists, acts, and holds on the grid."""
    from ptoverify.model.zones import corrected_zone

    cfg = ctx.cfg
    z = corrected_zone(cfg)
    if not z.valid:
        measured = float(z.grid_violations) if (z.grid_violations or 0) > 0 else None
        return Verdict(
            "zone-corrected-valid", FAIL, measured, 0.0, f"no valid corrected zone: {z.reason}"
        )
    return Verdict(
        "zone-corrected-valid",
        PASS if z.grid_violations == 0 else FAIL,
        float(z.grid_violations),
        0.0,
        f"omega0 = {z.omega0:.6g} mm/s; principle violations on the 2-D grid "
        f"of {z.grid_points} source states outside l1*/l2* (limit 0)",
    )


@gate("no-stride-over", "1")
def _no_stride(ctx: GateContext) -> Verdict:
    """Corrected PTO: no sampled state strides over the switching zone."""
    pr = ctx.pto_properties
    return at_most(
        "no-stride-over",
        float(pr.stride_overs),
        0.0,
        f"stride-overs of the corrected PTO over {pr.states} initial states x "
        f"{pr.steps} samples (a sample outside the zone and linear zone whose next "
        "sample is strictly across l1/l2 and outside the linear zone)",
    )


@gate("proof-no-stride-over", "1")
def _proof_no_stride(ctx: GateContext) -> Verdict:
    """Corrected PTO: no stride-over proved for every state of the envelope (interval proof)."""
    from ptoverify.studies.prove import nominal_proof

    proof = nominal_proof(ctx.cfg)
    p, relaxed = proof.property("no-stride-over-strict"), proof.property("no-stride-over-relaxed")
    measured = 1.0 if p.status == "refuted" else 1.0 - p.coverage
    return at_most(
        "proof-no-stride-over",
        measured,
        0.0,
        f"fraction of the envelope where no stride-over is not proved in the strict reading "
        f"(no crossing of l1/l2 from the bang-bang region, the corrected zone's design): "
        f"{p.status}; relaxed reading (landing in the linear zone allowed): {relaxed.status}, "
        f"coverage {relaxed.coverage:.6f} ({proof.cells} cells, ptoverify prove)",
    )


@gate("proof-reach", "1")
def _proof_reach(ctx: GateContext) -> Verdict:
    """Corrected PTO: certified reach of the target ellipse on at least 99.7 % of the envelope."""
    from ptoverify.studies.prove import nominal_proof

    proof = nominal_proof(ctx.cfg)
    p = proof.property("reach")
    sound = proof.target.certified and proof.simulation_over_bound == 0
    return at_most(
        "proof-reach",
        1.0 - p.coverage if sound else 1.0,
        0.003,
        f"fraction of the envelope without a certified bound to the target ellipse ({p.status}; "
        f"the rest leaves |x1| <= position_range); bound {proof.bound_samples} samples vs "
        f"simulated worst {proof.simulated_worst_samples}; "
        f"{proof.simulation_over_bound} simulated states over their bound"
        + ("" if proof.target.certified else f"; {proof.target.reason}"),
    )


@gate("no-limit-cycle", "1")
def _no_limit_cycle(ctx: GateContext) -> Verdict:
    """Corrected PTO: no sustained oscillation at the end of the horizon."""
    pr = ctx.pto_properties
    return at_most(
        "no-limit-cycle",
        float(pr.limit_cycles + pr.not_settled),
        0.0,
        f"states of {pr.states} with sustained oscillation ({pr.limit_cycles}) or "
        f"not settled within {pr.band:g} mm ({pr.not_settled}) after {pr.steps} "
        "samples, corrected PTO",
    )


def _loop_gate(name: str, which: str, cfg: Config) -> Verdict:
    from ptoverify.model.poles import all_loop_poles

    lp = all_loop_poles(cfg)[which]
    radius = max(lp.sampled_moduli)
    if lp.pole_mismatch > 1e-9:
        return Verdict(
            name,
            UNVERIFIED,
            radius,
            1.0,
            f"python-control and numpy disagree on the sampled poles by {lp.pole_mismatch:.2e}",
        )
    status = PASS if radius < 1.0 else FAIL
    return Verdict(
        name,
        status,
        radius,
        1.0,
        comparison="<",
        detail=f"largest |z| of the ZOH-sampled {which} loop, gains {lp.gains}, "
        f"T = {cfg.plant.T:g} s (python-control, cross-checked with numpy "
        f"eigenvalues to {lp.pole_mismatch:.1e}); must be < 1; gain margin "
        f"{lp.gain_margin:.3g}",
    )


@gate("pd-sampled-stable", "1")
def _pd_stable(ctx: GateContext) -> Verdict:
    """Check that the PD loop sampled with ZOH at T is stable."""
    cfg = ctx.cfg
    return _loop_gate("pd-sampled-stable", "pd", cfg)


@gate("linear-zone-sampled-stable", "1")
def _linear_stable(ctx: GateContext) -> Verdict:
    """Check that the linear-zone loop (eq. 37) sampled with ZOH at T is stable."""
    cfg = ctx.cfg
    return _loop_gate("linear-zone-sampled-stable", "linear", cfg)


# ------------------------------------------------------------ Section 6 gate
@gate("claims-computed", "1")
def _claims_computed(ctx: GateContext) -> Verdict:
    """Every Section 6 claim has a verdict computed from simulation under every reading.

    The verdicts themselves (reproduced or not) are findings of the report, not
    gate failures; this gate fails when a claim could not be measured.
    """
    from ptoverify.studies.claims import evaluate_claims

    cfg = ctx.cfg
    allowed = {"reproduced", "not reproduced", "ambiguous"}
    results = evaluate_claims(cfg)

    def measured(values: dict) -> bool:
        return any(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            for v in values.values()
        )

    missing = [
        c.id
        for c in results
        if c.verdict not in allowed
        or not c.readings
        or any(not measured(r.values) or r.verdict not in allowed for r in c.readings)
    ]
    readings = sum(len(c.readings) for c in results)
    return at_most(
        "claims-computed",
        float(len(missing)),
        0.0,
        f"{len(results)} claims, {readings} claim-readings simulated; claims "
        f"without computed values: {', '.join(missing) or 'none'}",
    )


def run_checks(
    cfg: Config,
    names: list[str] | None = None,
    *,
    max_iter: int | None = None,
    robust: bool = False,
    context: GateContext | None = None,
) -> list[Verdict]:
    """Run the gates (all, or the named ones) in registration order.

    Parameters
    ----------
    cfg : Config
        Configuration under test.
    names : list of str, optional
        Only these gates.
    max_iter : int, optional
        Cap on IPOPT iterations (to exercise the fail-closed path: a capped solver
        that does not converge makes its gate ``unverified``).
    robust : bool
        Also run :data:`ROBUST_GATES` (naming one in ``names`` runs it too).
    context : GateContext, optional
        The context to run in (results the caller shares with the gates);
        default ``GateContext(cfg, max_iter=max_iter)``.

    Returns
    -------
    list of Verdict
        One per gate run, each with its unit.

    Raises
    ------
    InputError
        A name that is not a gate.
    """
    known = (*GATES, *ROBUST_GATES)
    if names is not None:
        unknown = [g for g in names if g not in known]
        if unknown:
            raise InputError(f"unknown gate '{unknown[0]}' (choose from {', '.join(known)})")
    ctx = context if context is not None else GateContext(cfg, max_iter=max_iter)
    out = [fn(ctx) for name, fn in GATES.items() if names is None or name in names]
    wanted = [g for g in ROBUST_GATES if (names is None and robust) or (names and g in names)]
    if set(wanted) & set(ROBUST_STUDY_GATES):
        out += [v for v in robust_verdicts(cfg) if v.name in wanted]
    if PROOF_INTERVAL_GATE in wanted:
        out.append(proof_interval_verdict(cfg))
    return out


#: Gates judged from the robustness study (``ptoverify robust``) over ``[robustness]``.
ROBUST_STUDY_GATES = ("robust-no-limit-cycle", "robust-settling")
#: The interval proof over the ``[robustness]`` box's a_ratio (``ptoverify prove --a-interval``).
PROOF_INTERVAL_GATE = "proof-reach-a-interval"
#: Gates over the uncertainty box of ``[robustness]`` (``check --robust``), not run by default.
ROBUST_GATES = (*ROBUST_STUDY_GATES, PROOF_INTERVAL_GATE)


def proof_interval_verdict(cfg: Config) -> Verdict:
    """Judge the corrected PTO's certified reach for every a in the robustness box (fails closed).

    The proof (:func:`ptoverify.studies.prove.interval_proof`) covers every
    constant a in ``[robustness] a_ratio`` x the plant's a.  The measured figure
    is the fraction of the envelope without a certified bound to the target
    ellipse; 1 when the target is not certified or a simulated state needs more
    samples than its cell's bound.  A proof that raises is ``unverified``.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its ``[robustness]`` box.

    Returns
    -------
    Verdict
        ``proof-reach-a-interval`` (limit 0.003, as ``proof-reach``).
    """
    name, limit = PROOF_INTERVAL_GATE, 0.003
    desc = (
        "Corrected PTO: certified reach of the target ellipse on at least 99.7 % of the "
        "envelope for every constant a in the [robustness] box's a_ratio (interval proof)."
    )
    lo, hi = cfg.robustness.a_ratio
    try:
        from ptoverify.studies.prove import interval_proof

        proof = interval_proof(cfg)
        reach = proof.property("reach")
        strict = proof.property("no-stride-over-strict")
        relaxed = proof.property("no-stride-over-relaxed")
    except Exception as exc:  # noqa: BLE001 - a gate fails closed on any fault
        why = f"could not be computed: {type(exc).__name__}: {exc}"
        return Verdict(name, UNVERIFIED, None, limit, why, "<=", "1", desc)
    sound = proof.target.certified and proof.simulation_over_bound == 0
    detail = (
        f"fraction of the envelope without a certified bound to the target ellipse for every "
        f"a in [{lo:g}, {hi:g}] x a ({reach.status}; {len(proof.balls)} sub-intervals); bound "
        f"{proof.bound_samples} samples vs simulated worst {proof.simulated_worst_samples} "
        f"over 9 values of a; {proof.simulation_over_bound} simulated states over their bound; "
        f"no stride-over: strict {strict.status}, relaxed {relaxed.status}"
        + ("" if proof.target.certified else f"; {proof.target.reason}")
    )
    v = at_most(name, 1.0 - reach.coverage if sound else 1.0, limit, detail, "1")
    return dataclasses.replace(v, description=desc)


def robust_verdicts(cfg: Config) -> list[Verdict]:
    """Run the robustness study for the corrected PTO and judge it (fails closed).

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its ``[robustness]`` box.

    Returns
    -------
    list of Verdict
        ``robust-no-limit-cycle`` and ``robust-settling``
        (:func:`ptoverify.studies.robust.robust_gates`); both ``unverified`` when the
        study could not be computed.
    """
    from ptoverify.studies.robust import GATE_LAW, RobustSettings, robust_gates, run_robust

    settings = RobustSettings(
        laws=(GATE_LAW,), properties=("limit_cycle_mm", "settling_ratio_nt"), margins=False
    )
    try:
        return robust_gates(run_robust(cfg, settings))
    except Exception as exc:  # noqa: BLE001 - a gate fails closed on any fault
        why = f"could not be computed: {type(exc).__name__}: {exc}"
        return [
            Verdict("robust-no-limit-cycle", UNVERIFIED, None, 0.0, why, "<=", "mm"),
            Verdict(
                "robust-settling",
                UNVERIFIED,
                None,
                cfg.robustness.settling_ratio_limit,
                why,
                "<=",
                "1",
            ),
        ]


def summarize(results: list[Verdict]) -> dict[str, Any]:
    """Count statuses; ``ok`` is True only when every gate passed."""
    counts = {s: sum(r.status == s for r in results) for s in (PASS, FAIL, UNVERIFIED)}
    return {"total": len(results), **counts, "ok": counts[PASS] == len(results)}
