"""Run the gates (nominal and robust) and summarize their verdicts."""

from __future__ import annotations

import dataclasses
from typing import Any

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict, at_most

from .registry import GATES, GateContext


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
