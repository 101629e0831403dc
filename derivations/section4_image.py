"""Section 4, eqs. (13)-(19): the boundary curves and the one-sample image of l1.

What the text claims for (15)-(19), in plain words: rule (1) asks that a state
on the boundary l1* (fourth quadrant), held one sample T at u = -omega_m, land
still above l1.  The text then takes the one-step map (15) of the plant under
u = +omega_m from a point of l1, computes a x~1 + x~2 for the image (16),
inverts the velocity map (17), and concludes (18)-(19) that the images of l1
lie on the curve l~1: a x1 + x2 + omega_m ln(1 - x2/omega_m) = -2 a omega_m T.
Each of these claims is checked here against the exact one-step map of eq. (1)
(:func:`derivations.common.flow_T`).  Records 15inv (the inverse map) and 19c
(the corrected curve: the preimage of l1 under one -omega_m sample) go beyond
the paper.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from derivations.common import S, combine, flow_T, parsed, record_from, rhs
from derivations.printed import printed_text
from derivations.record import EquationRecord, definition, judge

__all__ = [
    "records",
    "l1_x1",
    "one_step",
    "one_step_inverse",
    "preimage_l1",
    "plant_points",
    "l1_points",
    "state_points",
]

a, wm, T = (S[n] for n in ("a", "omega_m", "T"))
x1, x2, tx1, tx2 = (S[n] for n in ("x1", "x2", "tx1", "tx2"))


def plant_points(rng: np.random.Generator, n: int) -> dict[sp.Symbol, np.ndarray]:
    """Random plants: a in [1, 500] rad/s, omega_m in [1, 1000] mm/s, aT in [0.01, 2]."""
    av = rng.uniform(1.0, 500.0, n)
    return {a: av, wm: rng.uniform(1.0, 1000.0, n), T: rng.uniform(0.01, 2.0, n) / av}


def l1_points(rng: np.random.Generator, n: int) -> dict[sp.Symbol, np.ndarray]:
    """Plants and a velocity x2 in (-omega_m, 0) (points of l1 via x1 = l1(x2))."""
    pts = plant_points(rng, n)
    pts[x2] = -rng.uniform(0.01, 0.99, n) * pts[wm]
    return pts


def state_points(rng: np.random.Generator, n: int) -> dict[sp.Symbol, np.ndarray]:
    """Plants and a state: x1 in [-50, 50] mm, |x2| < 0.99 omega_m."""
    pts = plant_points(rng, n)
    pts[x2] = rng.uniform(-0.99, 0.99, n) * pts[wm]
    pts[x1] = rng.uniform(-50.0, 50.0, n)
    return pts


def l1_x1(v: sp.Expr, level: sp.Expr = wm) -> sp.Expr:
    """Position on the level curve a x1 + x2 + level ln(1 - x2/level) = 0 at x2 = v."""
    return -(v + level * sp.log(1 - v / level)) / a


def one_step(sign: int = +1) -> tuple[sp.Expr, sp.Expr]:
    """One-step map (15): state after one sample T at u = sign*omega_m, from (x1, x2).

    Parameters
    ----------
    sign : {+1, -1}
        Sign of the held input.

    Returns
    -------
    tx1, tx2 : sympy.Expr
    """
    return flow_T(sign * wm, x1, x2)


@lru_cache(maxsize=None)
def one_step_inverse(sign: int = +1) -> tuple[sp.Expr, sp.Expr]:
    """Inverse of the one-step map, (x1, x2) from (tx1, tx2) (eq. 17 for sign = +1).

    Parameters
    ----------
    sign : {+1, -1}
        Sign of the held input.

    Returns
    -------
    x1, x2 : sympy.Expr
    """
    m1, m2 = one_step(sign)
    # the map is affine, m = J x + c: x = J^-1 (tx - c); x1 over its denominator a
    J = sp.Matrix([[m1.diff(x1), m1.diff(x2)], [m2.diff(x1), m2.diff(x2)]])
    if J.has(x1, x2):
        raise ArithmeticError("the one-step map is not affine in the state")
    c = sp.Matrix([m1, m2]).subs({x1: 0, x2: 0})
    sol = J.LUsolve(sp.Matrix([tx1, tx2]) - c)
    num, den = sp.fraction(sp.together(sp.expand(sol[0])))
    return sp.collect(num, a) / den, sp.expand(sol[1])


@lru_cache(maxsize=None)
def preimage_l1() -> sp.Expr:
    """Corrected l~1: states that reach l1 after one sample of u = -omega_m.

    The residual of l1 (eq. 9) evaluated at the image of (x1, x2) under one step
    of -omega_m; zero exactly on the preimage curve.

    Returns
    -------
    sympy.Expr
        a x1 + x2 - a omega_m T + omega_m ln(2 - (1 + x2/omega_m) e^{-aT}).
    """
    m1, m2 = one_step(-1)
    r = a * m1 + m2 + wm * sp.log(1 - m2 / wm)
    return sp.expand(r.replace(sp.log, lambda z: sp.log(sp.factor(z))))


def _rec_13_17() -> list[EquationRecord]:
    out = [
        definition(
            "13",
            printed_text("13"),
            "Boundary curve l1* chosen by the paper: the "
            "level-omega0 curve through the origin (eq. 9 with omega_m -> omega0); "
            "omega0 is fixed by eqs. (24)-(27).",
        ),
        definition(
            "14",
            printed_text("14"),
            "Boundary curve l2*: eq. (11) with omega_m -> omega0 (mirror image of l1*).",
        ),
    ]
    m1, m2 = one_step(+1)
    p15 = parsed("15")
    j = judge((rhs(p15[0], tx1), rhs(p15[1], tx2)), (m1, m2), state_points)
    out.append(
        record_from(
            "15",
            (m1, m2),
            ["exact flow of eq. (1) (dsolve) over one sample T with u = +omega_m held"],
            j,
            "The printed one-step map is the exact map under u = +omega_m, as the text says. "
            "Rule (1) however concerns the next sample under u = -omega_m.",
        )
    )
    # (16): line 1 against the map it claims to use, line 2 as algebra on l1
    p16 = parsed("16")
    lhs_plus = sp.expand(a * m1 + m2)
    j1 = judge(p16[1], lhs_plus, state_points)
    n1, n2 = one_step(-1)
    j1m = judge(p16[1], sp.expand(a * n1 + n2), state_points)
    j2 = judge(p16[2], p16[1].subs(x1, l1_x1(x2)), l1_points)
    corrected = "a*tx1 + tx2 - (a*x1 + x2 + a*omega_m*T)"
    inherits = [
        "17: unchanged for the +omega_m map of (15); if the -omega_m map of rule (1) is meant, "
        "(15) and (17) change to x2 = (tx2 + omega_m*(1 - exp(-a*T)))*exp(a*T)",
        "18: with the +omega_m map the chain ends at a*tx1 + tx2 = -omega_m*log(1 - tx2/omega_m)"
        ": the image of l1 is l1 itself (l1 is a +omega_m trajectory) - the construction is "
        "vacuous",
        "19: the curve rule (1) needs is the preimage of l1 under one -omega_m sample, "
        "a*x1 + x2 - a*omega_m*T + omega_m*log(2 - (1 + x2/omega_m)*exp(-a*T)) = 0 (record "
        "19c); it lies right of l1 (in S_N), the printed l~1 lies left of l1 (in S_P)",
        "20: a*d + x20 - a*omega_m*T + omega_m*log(2 - (1 + x20/omega_m)*exp(-a*T)) = 0",
        "21-22: same form ln(1 + Y) = Y - b0 with Y = y + 2*(exp(a*T) - 1) and "
        "b0 = a*d/omega_m + 2*(exp(a*T) - 1 - a*T) (record 22c)",
        "23: x~20 = -(Y* - 2*(exp(a*T) - 1))*omega_m",
        "24-27: same algebra, but the intersection point, k, z* and omega0 change (values "
        "at the plant in the note of 27)",
        "36, 35: the zone S~_P and the law use the omega0 of the corrected chain",
    ]
    jj = combine([j1, j2])
    out.append(
        record_from(
            "16",
            (lhs_plus, p16[2]),
            [
                "a*tx1 + tx2 under the +omega_m map of (15): " + sp.sstr(lhs_plus),
                f"printed line 1 against the +omega_m map: {j1.verdict}",
                f"printed line 1 against the -omega_m map instead: {j1m.verdict} (the sign of "
                "line 1 is that of u = -omega_m)",
                f"line 2 from line 1 with (x1, x2) on l1 (eq. 9): {j2.verdict}",
            ],
            jj,
            "Line 1 must follow from the map (15) it cites (u = +omega_m)"
            + (
                "; it is the -omega_m result instead: a*omega_m*T enters with the wrong sign."
                if j1m.verdict == "verified"
                else "."
            ),
            corrected=corrected,
            inherits=inherits,
        )
    )
    p17 = parsed("17")
    i1, i2 = one_step_inverse(+1)
    samp = plant_points

    def samp17(rng, n):
        pts = samp(rng, n)
        pts[tx2] = rng.uniform(-0.99, 0.99, n) * pts[wm]
        return pts

    j = judge(rhs(p17[0], x2), i2, samp17)
    out.append(
        record_from(
            "17",
            i2,
            ["solve the velocity line of the +omega_m map (15) for x2"],
            j,
            "Inverse of the velocity map (15).",
        )
    )
    # extra: full inverse, both signs, verified by composition
    js = []
    inv = {}
    for sgn in (+1, -1):
        j1_, j2_ = one_step_inverse(sgn)
        inv[sgn] = (j1_, j2_)
        f1, f2 = one_step(sgn)
        comp = (
            f1.subs({x1: j1_, x2: j2_}, simultaneous=True),
            f2.subs({x1: j1_, x2: j2_}, simultaneous=True),
        )

        def samp_inv(rng, n):
            pts = plant_points(rng, n)
            pts[tx1] = rng.uniform(-50, 50, n)
            pts[tx2] = rng.uniform(-0.99, 0.99, n) * pts[wm]
            return pts

        js.append(judge(comp, (tx1, tx2), samp_inv))
    out.append(
        record_from(
            "15inv",
            (inv[1][0], inv[1][1], inv[-1][0], inv[-1][1]),
            [
                "solve the one-step map for (x1, x2), u = +omega_m (first pair) and -omega_m (second)",
                "composition map(inverse(tx)) = tx checked",
            ],
            combine(js),
            "Inverse of the one-step map (15) for both input signs. Not in the paper.",
            printed_str="(not in the paper)",
        )
    )
    return out


def _rec_18_19() -> list[EquationRecord]:
    p16, p17, p18 = parsed("16"), parsed("17"), parsed("18")
    (p19,) = parsed("19")

    def samp_tx(rng, n):
        pts = l1_points(rng, n)
        e = np.exp(-pts[a] * pts[T])
        pts[tx2] = pts[x2] * e + pts[wm] * (1 - e)  # images of x2 < 0 under (15)
        return pts

    steps, js = [], []
    first = p16[2].subs(x2, rhs(p17[0], x2))
    j = judge(p18[1], first, samp_tx)
    js.append(j)
    steps.append(f"line 1 = (16) line 2 with (17) substituted: {j.verdict}")
    for i in range(2, len(p18)):
        j = judge(p18[i], p18[i - 1], samp_tx)
        js.append(j)
        steps.append(f"line {i} = line {i - 1}: {j.verdict}")
    algebra = combine(js)
    # the claim: images of l1 under the exact map satisfy the final relation
    img = {}
    for sgn in (+1, -1):
        m1, m2 = one_step(sgn)
        img[sgn] = {tx1: m1.subs(x1, l1_x1(x2)), tx2: m2.subs(x1, l1_x1(x2))}
    claim18 = judge((p18[0] - p18[-1]).subs(img[+1], simultaneous=True), sp.Integer(0), l1_points)

    def state_under(sgn: int):
        """Return the extra fields: the state on l1 and its image one sample later under sgn."""

        def state(ce):
            p = ce["point"]
            num = {S[key]: val for key, val in p.items()}
            return {
                "state_on_l1": [float(l1_x1(x2).subs(num)), p["x2"]],
                f"image_under_{'plus' if sgn > 0 else 'minus'}_omega_m": [
                    float(img[sgn][tx1].subs(num)),
                    float(img[sgn][tx2].subs(num)),
                ],
            }

        return state

    steps.append(
        f"claim: images of l1 under the exact +omega_m map satisfy the last line: {claim18.verdict}"
    )
    out = [
        record_from(
            "18",
            "a*tx1 + tx2 + omega_m*log(1 - tx2/omega_m) = 0 on the image of "
            "l1 under the +omega_m map (15)",
            steps,
            combine([algebra, claim18]),
            f"Each line of (18) follows from its predecessor and (16), (17) as "
            f"printed (algebra: {algebra.verdict}); the result inherits the sign "
            f"error of (16): the image of l1 under (15) is l1 itself.",
            corrected="a*tx1 + tx2 + omega_m*log(1 - tx2/omega_m)",
            inherits=[
                "19: l~1 coincides with l1 under the +omega_m map",
                "20-27: see the inherits of (16)",
            ],
            extra=state_under(+1),
        )
    ]
    r19 = p19.subs(img[+1], simultaneous=True)
    j_plus = judge(r19, sp.Integer(0), l1_points)
    j_minus = judge(p19.subs(img[-1], simultaneous=True), sp.Integer(0), l1_points)
    pre = preimage_l1()
    out.append(
        record_from(
            "19",
            pre,
            [
                "the printed l~1 evaluated at images of l1 points under the exact +omega_m map: "
                f"{j_plus.verdict}",
                f"... and under the exact -omega_m map: {j_minus.verdict}",
                "rule (1) needs the states whose next sample under -omega_m lands on l1: the preimage "
                "of l1, derived as the l1 residual of the -omega_m one-step image (record 19c)",
            ],
            # the -omega_m image first: the sample rule (1) concerns, and a counterexample
            # of (19)'s own (under +omega_m (19) is (18) rearranged, so (18)'s point and values)
            combine([j_minus, j_plus]),
            "Claim: the one-step images of l1 form l~1. "
            + ("False for either input sign. " if j_minus.verdict == "erratum" else "")
            + "On l~1 the "
            "l1 residual equals -2 a omega_m T < 0, i.e. l~1 lies left of l1 (in S_P), on the "
            "opposite side from the switching zone.",
            corrected=sp.sstr(pre),
            inherits=[
                "20-23: corrected intersection with x1 = d from record 19c (records 22c)",
                "24-27: same algebra with the corrected intersection point",
            ],
            extra=state_under(-1 if j_minus.verdict == "erratum" else +1),
        )
    )
    # 19c: verify the preimage by mapping back, and its side
    c1 = pre.coeff(x1)  # pre is affine in x1
    x1_on = sp.cancel(-(pre - c1 * x1) / c1)
    n1, n2 = one_step(-1)
    m_img = (n1.subs(x1, x1_on), n2.subs(x1, x1_on))
    on_l1 = a * m_img[0] + m_img[1] + wm * sp.log(1 - m_img[1] / wm)
    j_on = judge(on_l1, sp.Integer(0), l1_points)
    sigma = a * x1_on + x2 + wm * sp.log(1 - x2 / wm)
    j_side = judge(sigma > 0, sp.true, l1_points, symbolic=False)
    out.append(
        record_from(
            "19c",
            pre,
            [
                "residual of l1 (eq. 9) at the -omega_m one-step image of (x1, x2), simplified",
                f"points of this curve reach l1 after one -omega_m sample: {j_on.verdict}",
                f"the curve lies right of l1 (l1 residual > 0) for x2 < 0: {j_side.verdict}",
            ],
            combine([j_on, j_side]),
            "Corrected l~1: the preimage of l1 under one sample of u = -omega_m. Not in the paper.",
            printed_str="(not in the paper)",
        )
    )
    return out


def records() -> list[EquationRecord]:
    """Build the records of eqs. (13)-(19) and 15inv, 19c.

    Returns
    -------
    list of EquationRecord
        Without the numbers at a plant (added by :func:`derivations.section4.records`).
    """
    return _rec_13_17() + _rec_18_19()
