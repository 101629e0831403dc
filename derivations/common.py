"""Shared pieces of the derivations: the plant's flow, samplers, record helpers.

The flow under a constant input (eq. 7) is obtained once, here, by ``dsolve``
of eq. (1); every later section uses it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from derivations.printed import SYMBOLS, printed, printed_text
from derivations.record import EquationRecord, Judgement

__all__ = [
    "PlantNumbers",
    "S",
    "flow",
    "flow_T",
    "linear_ode_solution",
    "switch_curve_x1",
    "uniform",
    "record_from",
    "rhs",
    "combine",
    "linear_root",
]

S = SYMBOLS


@dataclass(frozen=True)
class PlantNumbers:
    """Plant and law numbers at which the records quote numeric examples.

    The derivations are symbolic; a few records (16, 27, 36Z, 39L) also evaluate
    their result at one plant, to say what the printed chain gives there.  The
    caller passes that plant (``ptoverify`` passes its configuration's numbers);
    the derivations import nothing from ``ptoverify``.

    Attributes
    ----------
    a : float
        Velocity-loop bandwidth [rad/s].
    w_max : float
        Velocity saturation omega_m [mm/s].
    T : float
        Sampling period [s].
    d : float
        Half-width of the linear zone [mm].
    k1 : float
        Linear-zone position gain of eq. (34) [1/s].
    k2 : float
        Linear-zone velocity gain of eq. (34) [-].

    Examples
    --------
    >>> PlantNumbers(a=100.0, w_max=200.0, T=0.001, d=0.2, k1=150.0, k2=1.0).w_max
    200.0
    """

    a: float
    w_max: float
    T: float  # noqa: N815 - the paper's symbol
    d: float
    k1: float
    k2: float

    def __post_init__(self) -> None:
        for name in ("a", "w_max", "T"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"PlantNumbers.{name} must be a finite number > 0, got {v!r}")
        for name in ("d", "k1", "k2"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ValueError(f"PlantNumbers.{name} must be a finite number, got {v!r}")


@lru_cache(maxsize=None)
def _linear_ode_general() -> tuple[sp.Expr, tuple[sp.Symbol, ...]]:
    """Solve y' = alpha y + beta, y(s0) = y0 (constants, alpha != 0) by dsolve, once."""
    alpha = sp.Symbol("alpha", real=True, nonzero=True)
    beta, y0, s0, s = sp.symbols("beta y0 s0 s", real=True)
    Y = sp.Function("Y")
    # constant coefficients and forcing: the method of undetermined coefficients
    sol = sp.dsolve(
        sp.Eq(Y(s).diff(s), alpha * Y(s) + beta),
        Y(s),
        ics={Y(s0): y0},
        hint="nth_linear_constant_coeff_undetermined_coefficients",
        simplify=False,
    ).rhs
    return sol, (alpha, beta, y0, s0, s)


def linear_ode_solution(
    alpha: sp.Expr, beta: sp.Expr, y0: sp.Expr, s0: sp.Expr, s: sp.Expr
) -> sp.Expr:
    """Solution of the scalar linear ODE y' = alpha y + beta with y(s0) = y0, by dsolve.

    The ODE is solved once with symbolic constants; the velocity of eq. (1) and
    the costate lambda2 of the minimum principle are both of this form.

    Parameters
    ----------
    alpha, beta : sympy.Expr
        Constant coefficients (alpha nonzero).
    y0, s0 : sympy.Expr
        Initial value and initial time.
    s : sympy.Expr
        The independent variable.

    Returns
    -------
    sympy.Expr

    Examples
    --------
    >>> t = sp.Symbol("t", real=True)
    >>> linear_ode_solution(sp.Integer(-1), sp.Integer(0), sp.Integer(1), sp.Integer(0), t)
    exp(-t)
    """
    sol, syms = _linear_ode_general()
    return sol.xreplace(dict(zip(syms, (alpha, beta, y0, s0, s))))


@lru_cache(maxsize=None)
def _flow_general() -> tuple[sp.Expr, sp.Expr]:
    """Solve eq. (1) with constant input u and x(0) = (x10, x20).

    Eq. (1) is a cascade: the velocity equation x2' = -a x2 + a u is solved by
    dsolve (:func:`linear_ode_solution`), then the position x1' = x2 is its
    integral, x1(t) = x10 + int_0^t x2.  The position is returned expanded, the
    velocity as one fraction (``cancel``).
    """
    a, t, u, x10, x20 = (S[n] for n in ("a", "t", "u", "x10", "x20"))
    s = sp.Dummy("s")
    v = linear_ode_solution(-a, a * u, x20, sp.Integer(0), s)
    p = x10 + sp.integrate(v, (s, 0, t))
    return sp.expand(p), sp.cancel(v.subs(s, t))


def flow(
    u: sp.Expr, x10: sp.Expr | None = None, x20: sp.Expr | None = None, t: sp.Expr | None = None
) -> tuple[sp.Expr, sp.Expr]:
    """State after time t under constant input u, from eq. (1) by dsolve (eq. 7).

    Parameters
    ----------
    u : sympy.Expr
        Constant input [mm/s].
    x10, x20 : sympy.Expr, optional
        Initial state (default the symbols x10, x20).
    t : sympy.Expr, optional
        Elapsed time (default the symbol t).

    Returns
    -------
    x1, x2 : sympy.Expr
    """
    x1, x2 = _flow_general()
    sub = {
        S["u"]: u,
        S["x10"]: S["x10"] if x10 is None else x10,
        S["x20"]: S["x20"] if x20 is None else x20,
        S["t"]: S["t"] if t is None else t,
    }
    return x1.xreplace(sub), x2.xreplace(sub)


def flow_T(u: sp.Expr, x1: sp.Expr, x2: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """One sample (duration T) of the exact flow from (x1, x2) under input u.

    Parameters
    ----------
    u, x1, x2 : sympy.Expr
        Held input and state at the sample.

    Returns
    -------
    x1, x2 : sympy.Expr
        State one sample later.
    """
    return flow(u, x1, x2, S["T"])


def switch_curve_x1(x2: np.ndarray, a: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Position on the level-w curve l1-o-l2 through the origin at velocity x2 (floats).

    Only used to draw admissible sample points on a chosen side of a curve.
    """
    r = np.abs(x2) / w
    return -np.sign(x2) * w * (r - np.log1p(r)) / a


def uniform(
    rng: np.random.Generator, n: int, **ranges: tuple[float, float]
) -> dict[sp.Symbol, np.ndarray]:
    """Independent uniform draws, one array per named symbol."""
    return {S[k]: rng.uniform(lo, hi, n) for k, (lo, hi) in ranges.items()}


def rhs(residual: sp.Expr, lhs: sp.Symbol) -> sp.Expr:
    """Right-hand side of a printed ``lhs - rhs`` residual."""
    return sp.expand(lhs - residual)


def combine(judgements: Sequence[Judgement]) -> Judgement:
    """Combine several judgements: erratum wins, then unchecked, else verified."""
    for v in ("erratum", "unchecked"):
        for j in judgements:
            if j.verdict == v:
                return j
    n = sum(j.n_points for j in judgements)
    err = max(j.max_rel_err for j in judgements)
    sym = all(j.symbolic for j in judgements) or None
    reasons = "; ".join(j.reason for j in judgements)
    return Judgement("verified", sym, n, err, None, reasons)


def record_from(
    id_: str,
    derived: Any,
    steps: list[str],
    j: Judgement,
    note: str,
    corrected: str | None = None,
    inherits: list[str] | None = None,
    printed_str: str | None = None,
    extra: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
) -> EquationRecord:
    """Build a record whose verdict is the judgement's.

    Parameters
    ----------
    id_ : str
        Equation id.
    derived : sympy expression(s) or str
        The derived form.
    steps : list of str
        Derivation steps.
    j : Judgement
        The computed comparison; its verdict becomes the record's.
    note : str
        What was compared; the judgement's reason is appended.
    corrected, inherits
        Only kept when the verdict is ``erratum``.
    printed_str : str, optional
        Printed text (default: the transcription of ``id_``).
    extra : callable, optional
        Adds fields (e.g. the state) to the counterexample.

    Returns
    -------
    EquationRecord
    """
    if isinstance(derived, str):
        d = derived
    elif isinstance(derived, (tuple, list)):
        d = "; ".join(sp.sstr(e) for e in derived)
    else:
        d = sp.sstr(derived)
    ce = j.counterexample
    if ce is not None and extra is not None:
        ce = dict(ce, **extra(ce))
    err = j.verdict == "erratum"
    return EquationRecord(
        id=id_,
        printed=printed_text(id_) if printed_str is None else printed_str,
        derived=d,
        steps=list(steps),
        verdict=j.verdict,
        note=f"{note} Check: {j.reason}.",
        counterexample=ce,
        corrected=corrected if err else None,
        inherits=list(inherits or []) if err else [],
    )


def parsed(id_: str) -> tuple[sp.Basic, ...]:
    """Shorthand for :func:`derivations.printed.printed`."""
    return printed(id_)


def linear_root(residual: sp.Expr, var: sp.Symbol) -> sp.Expr:
    """Solve residual = 0 for var, residual linear in var or in 1/var (a definition).

    ``solve`` of the numerator over one denominator: the root is that of the
    residual where the denominator is nonzero (the judge checks it at random
    points).  Solving the numerator spares ``solve`` its test of whether the root
    zeroes a denominator, whose ``checksol`` imports ``sympy.physics.units``
    (~0.1 s) and simplifies; the root is the same.
    """
    return sp.solve(sp.numer(sp.together(residual)), var, simplify=False, check=False)[0]
