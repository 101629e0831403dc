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

from . import ground, loop  # noqa: F401 - registers the gates, in this order
from .registry import GATE_UNITS, GATES, CheckResult, Gate, GateContext, gate
from .run import (
    PROOF_INTERVAL_GATE,
    ROBUST_GATES,
    ROBUST_STUDY_GATES,
    proof_interval_verdict,
    robust_verdicts,
    run_checks,
    summarize,
)

__all__ = [
    "CheckResult",
    "GATES",
    "GATE_UNITS",
    "Gate",
    "GateContext",
    "PROOF_INTERVAL_GATE",
    "ROBUST_GATES",
    "ROBUST_STUDY_GATES",
    "gate",
    "proof_interval_verdict",
    "robust_verdicts",
    "run_checks",
    "summarize",
]
