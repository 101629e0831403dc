"""The gates of the closed loop: derivations, zone, stride-over, proofs, cycles, poles, claims."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ptoverify.config import Config
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict, at_most

from .ground import _random_states
from .registry import gate

if TYPE_CHECKING:
    from .registry import GateContext


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
