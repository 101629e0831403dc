"""The gate registry: the context gates share, the decorator that registers a gate."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any

from ptoverify.config import Config
from ptoverify.errors import SolverError
from ptoverify.verdict import UNVERIFIED, Verdict

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

    # Not a memo (model.memo): a lazy attribute of this one run's context, computed at
    # most once per context and dropped with it; named_properties' memo is keyed on cfg.
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
