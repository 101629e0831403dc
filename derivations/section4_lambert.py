"""Lambert-W closed forms of the roots of eqs. (22), (26) and (31) (records 22W, 26W, 31W).

The paper solves ln(1 + y) = y - b0 (22) and ln(1 + z) = k z (26, 31) by
bisection.  Both have closed forms in the Lambert W function; the records here
derive them, substitute them back and check on which branch the root the zone
needs lies.  Not in the paper.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from derivations.common import S, combine, parsed, record_from
from derivations.record import EquationRecord, Judgement, judge

__all__ = ["records", "root_22_W", "root_k_W"]

y, b0, k, z, w = (S[n] for n in ("y", "b0", "k", "z", "w"))


def root_22_W(bb: sp.Expr = b0, branch: int = -1) -> sp.Expr:
    """Root of eq. (22), ln(1 + y) = y - b0, in Lambert W.

    1 + y = e^{y - b0}  =>  -(1 + y) e^{-(1 + y)} = -e^{-1 - b0}  =>
    y = -1 - W(-e^{-1 - b0}).  For b0 > 0 the argument lies in (-1/e, 0): branch
    W_{-1} gives y > 0, W_0 gives -1 < y < 0.

    Parameters
    ----------
    bb : sympy.Expr
        b0 (eq. 21).
    branch : {-1, 0}
        Lambert-W branch.

    Returns
    -------
    sympy.Expr
    """
    return -1 - sp.LambertW(-sp.exp(-1 - bb), branch)


def root_k_W(kk: sp.Expr = k, branch: int = -1) -> sp.Expr:
    """Non-trivial root of ln(1 + z) = k z, eqs. (26), (31), in Lambert W.

    v = 1 + z = e^{k (v - 1)}  =>  -k v e^{-k v} = -k e^{-k}  =>
    z = -1 - W(-k e^{-k}) / k.  The branch through -k gives the trivial z = 0;
    the other one gives the root: W_{-1} for 0 < k < 1 (z > 0), W_0 for k > 1
    (-1 < z < 0).

    Parameters
    ----------
    kk : sympy.Expr
        k (eqs. 25, 30).
    branch : {-1, 0}
        Lambert-W branch.

    Returns
    -------
    sympy.Expr
    """
    return -1 - sp.LambertW(-kk * sp.exp(-kk), branch) / kk


def _branch_signs(r: sp.Expr, branch: int, sampler) -> Judgement:
    """Judge the sign pattern of a root: > 0 on W_{-1}, in (-1, 0) on W_0."""
    if branch == -1:
        return judge(sp.sign(r), sp.Integer(1), sampler, symbolic=False)
    return judge(
        (sp.sign(r), sp.sign(r + 1)), (sp.Integer(-1), sp.Integer(1)), sampler, symbolic=False
    )


def records() -> list[EquationRecord]:
    """Build the records 22W, 26W and 31W.

    Returns
    -------
    list of EquationRecord
    """
    out = []
    (p22,) = parsed("22")

    def sb(rng, n):
        return {b0: np.exp(rng.uniform(np.log(1e-6), np.log(50.0), n))}

    js = []
    for br, cond in ((-1, "y > 0"), (0, "-1 < y < 0")):
        r = root_22_W(b0, br)
        # SymPy cannot reduce log(-W(x)) without branch information: decided numerically
        js.append(judge(p22.subs(y, r), sp.Integer(0), sb, symbolic=False))
        js.append(_branch_signs(r, br, sb))
    out.append(
        record_from(
            "22W",
            (root_22_W(b0, -1), root_22_W(b0, 0)),
            [
                "1 + y = exp(y - b0) => -(1 + y) exp(-(1 + y)) = -exp(-1 - b0)",
                "y = -1 - W(-exp(-1 - b0)); the argument is in (-1/e, 0) for b0 > 0",
                "branch W_{-1}: y > 0 (the root the zone needs); W_0: -1 < y < 0",
                "substitution into (22) and the branch signs checked at random b0 in (1e-6, 50)",
            ],
            combine(js),
            "Closed form of (22), which the paper solves by bisection.",
            printed_str="(not in the paper)",
        )
    )
    (p26,), (p31,) = parsed("26"), parsed("31")
    # (31) is (26) with w for z: with the root substituted both are the same expression
    # in k, judged at the same points, so each judgement is computed once
    done: dict[tuple[sp.Expr, int], list] = {}
    for id_, var, p_ in (("26W", z, p26), ("31W", w, p31)):
        js = []
        for br, lo, hi in ((-1, 0.01, 0.99), (0, 1.01, 20.0)):

            def sk(rng, n, lo=lo, hi=hi):
                return {k: rng.uniform(lo, hi, n)}

            r = root_k_W(k, br)
            resid = p_.subs(var, r)
            if (resid, br) not in done:
                done[resid, br] = [
                    judge(resid, sp.Integer(0), sk, symbolic=False),
                    _branch_signs(r, br, sk),
                ]
            js += done[resid, br]
        out.append(
            record_from(
                id_,
                (root_k_W(k, -1), root_k_W(k, 0)),
                [
                    f"v = 1 + {var}: v = exp(k (v - 1)) => -k v exp(-k v) = -k exp(-k)",
                    f"{var} = -1 - W(-k exp(-k))/k; the branch with W = -k gives the trivial root 0",
                    "non-trivial root: W_{-1} for 0 < k < 1 (root > 0), W_0 for k > 1 (-1 < root < 0)",
                    "substitution and the signs checked at random k on both ranges",
                ],
                combine(js),
                f"Closed form of ({id_[:2]}), which the paper solves by bisection.",
                printed_str="(not in the paper)",
            )
        )
    return out
