"""The PTOS baseline on this plant, re-derived (``ptoverify.model.baselines``).

Not a paper equation: these records check the equations the suite's PTOS law
uses, each a claim derived here and judged by :func:`derivations.record.judge`
(symbolic proof, then random admissible points).

* ``PTOS-v``: the velocity command u = (k/a) f - (k/a - 1) x2 turns the plant's
  velocity loop (eq. 1) into Workman's x2' = k (f - x2).
* ``PTOS-y``: continuity of the profile in value and slope at the edge of the
  linear region, solved for (k1, y_l): k1 = alpha k^2 / 2, y_l = A / k1.
* ``PTOS-0`` / ``PTOS-1``: the value / slope of both branches at y_l agree.
* ``PTOS-A``: A = a omega_m: the least deceleration a (v + omega_m) over
  v >= 0, and the parabola x2^2 = 2 A x1 osculates the switching curve l1
  (eq. 9) at the origin to second order.
* ``PTOS-sat``: with k = a the branch's edge value A / k is omega_m: the
  square-root branch lies beyond the saturation.

Imports nothing from ``ptoverify``.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from derivations.common import S, uniform
from derivations.record import EquationRecord, judge

__all__ = ["records", "profile", "continuity_solution", "SYMBOLS"]

a, wm, x1, x2 = S["a"], S["omega_m"], S["x1"], S["x2"]
alpha, k, A, k1, e, y_l, v = sp.symbols("alpha k A k1 e y_l v", positive=True)
#: The symbols of this module (positive reals).
SYMBOLS = {"alpha": alpha, "k": k, "A": A, "k1": k1, "e": e, "y_l": y_l, "v": v}


def profile(e_: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """Workman's profile for e > 0: (linear branch, square-root branch) [mm/s].

    Parameters
    ----------
    e_ : sympy.Expr
        Position error e > 0 [mm].

    Returns
    -------
    tuple of sympy.Expr
        (k1 / k) e and sqrt(2 alpha A e) - A / k.
    """
    return k1 / k * e_, sp.sqrt(2 * alpha * A * e_) - A / k


def continuity_solution() -> dict[sp.Symbol, sp.Expr]:
    """Solve value and slope continuity at e = y_l for (k1, y_l).

    Returns
    -------
    dict
        {k1: ..., y_l: ...}, the unique solution with k1, y_l > 0.
    """
    lin, root = profile(e)
    eqs = [
        sp.Eq(lin.subs(e, y_l), root.subs(e, y_l)),
        sp.Eq(sp.diff(lin, e).subs(e, y_l), sp.diff(root, e).subs(e, y_l)),
    ]
    sols = sp.solve(eqs, [k1, y_l], dict=True)
    good = [s for s in sols if all(sp.ask(sp.Q.positive(val)) for val in s.values())]
    if len(good) != 1:
        raise ArithmeticError(f"continuity: expected one positive solution, got {sols}")
    return good[0]


def _sampler(rng, n):
    pts = {alpha: rng.uniform(0.05, 1.0, n), k: rng.uniform(1.0, 5000.0, n)}
    pts |= {A: rng.uniform(10.0, 1e6, n), x2: rng.uniform(-1e3, 1e3, n)}
    pts |= uniform(rng, n, a=(1.0, 5000.0), omega_m=(1.0, 1e4))
    pts[v] = rng.uniform(0.0, 1.0, n) * pts[wm]
    return pts


def _record(id_, printed, derived, steps, note, j) -> EquationRecord:
    return EquationRecord(
        id=id_,
        printed=sp.sstr(printed),
        derived=sp.sstr(derived),
        steps=list(steps),
        verdict=j.verdict,
        note=f"{note} Check: {j.reason}.",
        counterexample=j.counterexample,
    )


@lru_cache(maxsize=1)
def records() -> tuple[EquationRecord, ...]:
    """Every PTOS record (module docstring), each judged.

    Returns
    -------
    tuple of EquationRecord
        ``PTOS-v``, ``PTOS-y``, ``PTOS-0``, ``PTOS-1``, ``PTOS-A``, ``PTOS-sat``.

    Examples
    --------
    >>> sorted({r.verdict for r in records()})
    ['verified']
    """
    out = []
    f = sp.Symbol("f")
    u = k / a * f - (k / a - 1) * x2
    x2dot = -a * x2 + a * u  # eq. (1)
    j = judge(k * (f - x2), x2dot, lambda rng, n: _sampler(rng, n) | {f: rng.normal(0, 300, n)})
    steps = ["x2' = -a x2 + a u (eq. 1) with u = (k/a) f - (k/a - 1) x2"]
    out.append(_record("PTOS-v", k * (f - x2), x2dot, steps, "Workman's loop.", j))

    sol = continuity_solution()
    claimed = (alpha * k**2 / 2, 2 * A / (alpha * k**2))
    j = judge(claimed, (sol[k1], sol[y_l]), _sampler)
    steps = ["f_lin(y_l) = f_root(y_l) and f_lin'(y_l) = f_root'(y_l), solved for (k1, y_l)"]
    note = "k1 = alpha k^2/2 and y_l = A/k1 = 2 A/(alpha k^2) are what continuity fixes."
    out.append(_record("PTOS-y", claimed, (sol[k1], sol[y_l]), steps, note, j))

    lin, root = profile(e)
    at = {k1: claimed[0], y_l: claimed[1]}
    for id_, fn, what in (("PTOS-0", lambda z: z, "value"), ("PTOS-1", sp.diff, "slope")):
        left = (fn(lin, e) if what == "slope" else lin).subs(e, y_l).subs(at)
        right = (fn(root, e) if what == "slope" else root).subs(e, y_l).subs(at)
        j = judge(left, right, _sampler)
        steps = [f"{what} of both branches at e = y_l with k1, y_l of PTOS-y"]
        out.append(_record(id_, left, right, steps, f"The profile's {what} is continuous.", j))

    # l1, eq. (9): a x1 = x2 - omega_m ln(1 + x2/omega_m) for the decelerating branch
    curve = (v - wm * sp.log(1 + v / wm)) / a
    series = sp.series(curve, v, 0, 3).removeO()
    parabola = v**2 / (2 * a * wm)
    least = sp.minimum(a * (v + wm), v, sp.Interval(0, wm))  # deceleration with u = -omega_m
    j = judge((parabola, a * wm), (series, least), _sampler)
    steps = [
        "min over 0 <= v <= omega_m of a (v + omega_m), the deceleration with u = -omega_m",
        "series of l1's x1(v) to O(v^3) equals v^2 / (2 a omega_m)",
    ]
    note = "A = a omega_m: guaranteed deceleration; the parabola osculates l1 at the origin."
    out.append(_record("PTOS-A", (parabola, a * wm), (series, least), steps, note, j))

    edge = (k1 / k * y_l).subs(at).subs({A: a * wm, k: a})
    j = judge(edge, wm, _sampler)
    steps = ["f(y_l) = A / k with A = a omega_m and k = a"]
    note = "With k = a the square-root branch starts at the saturation: PTOS is a P loop."
    out.append(_record("PTOS-sat", edge, wm, steps, note, j))
    return tuple(out)
