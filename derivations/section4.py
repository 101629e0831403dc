"""Section 4, the switching zone: eqs. (13)-(35), and their corrections.

What the text claims for (15)-(19), in plain words: rule (1) asks that a state
on the boundary l1* (fourth quadrant), held one sample T at u = -omega_m, land
still above l1.  The text then takes the one-step map (15) of the plant under
u = +omega_m from a point of l1, computes a x~1 + x~2 for the image (16),
inverts the velocity map (17), and concludes (18)-(19) that the images of l1
lie on the curve l~1: a x1 + x2 + omega_m ln(1 - x2/omega_m) = -2 a omega_m T.
Each of these claims is checked here against the exact one-step map of eq. (1)
(:func:`derivations.common.flow_T`).  Equations (20)-(27) are checked as
algebra given their printed predecessor; (28)-(33) are the level-omega_c curve
and its k, w substitution.  Records 15inv, 19c, 22c, 22W, 26W, 31W go beyond
the paper: the inverse map, the corrected curve, the corrected intersection
equation, and the Lambert-W roots.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from derivations.common import PlantNumbers, S, combine, flow_T, parsed, record_from, rhs
from derivations.printed import printed_text
from derivations.record import EquationRecord, definition, judge
from derivations.section3 import trajectory_residual

__all__ = [
    "records",
    "l1_x1",
    "one_step",
    "one_step_inverse",
    "preimage_l1",
    "corrected_b0",
    "root_22_W",
    "root_k_W",
    "intersection",
]

a, wm, w0, wc, T, d = (S[n] for n in ("a", "omega_m", "omega_0", "omega_c", "T", "d"))
x1, x2, tx1, tx2, tx10, tx20 = (S[n] for n in ("x1", "x2", "tx1", "tx2", "tx10", "tx20"))
y, b0, k, z, w = (S[n] for n in ("y", "b0", "k", "z", "w"))


def _plant(rng, n):
    av = rng.uniform(1.0, 500.0, n)
    return {a: av, wm: rng.uniform(1.0, 1000.0, n), T: rng.uniform(0.01, 2.0, n) / av}


def _l1_points(rng, n):
    """Plant parameters and a velocity x2 in (-omega_m, 0) (points of l1 via x1 = l1(x2))."""
    pts = _plant(rng, n)
    pts[x2] = -rng.uniform(0.01, 0.99, n) * pts[wm]
    return pts


def _free_state(rng, n):
    pts = _plant(rng, n)
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


def corrected_b0() -> dict[str, sp.Expr]:
    """Corrected eqs. (20)-(22): the intersection of the corrected l~1 with x1 = d.

    With y = -x20/omega_m and Y = y + 2 (e^{aT} - 1), the corrected (20) becomes
    ln(1 + Y) = Y - b0c, the form of eq. (22), with b0c below.

    Returns
    -------
    dict
        ``residual`` (corrected (20) divided by omega_m, in y), ``shift``
        (Y - y), ``b0c``, ``form22`` (ln(1 + Y) - (Y - b0c) in y).
    """
    return dict(_corrected_b0())


@lru_cache(maxsize=None)
def _corrected_b0() -> tuple[tuple[str, sp.Expr], ...]:
    r = preimage_l1().subs({x1: d, x2: -y * wm}) / wm
    shift = 2 * (sp.exp(a * T) - 1)
    b0c = a * d / wm + 2 * (sp.exp(a * T) - 1 - a * T)
    Y = y + shift
    return (
        ("residual", sp.expand(r)),
        ("shift", shift),
        ("b0c", b0c),
        ("form22", sp.log(1 + Y) - (Y - b0c)),
    )


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


def intersection(
    a_: float, w_max: float, T_: float, d_: float, corrected: bool
) -> dict[str, float]:
    """Intersection x~20 and boundary level omega0, printed or corrected chain (23), (27).

    Evaluates the Lambert-W closed forms (records 22W, 22c, 26W) in 30-digit arithmetic.

    Parameters
    ----------
    a_ : float
        Bandwidth [rad/s].
    w_max : float
        Velocity saturation [mm/s].
    T_ : float
        Sampling period [s].
    d_ : float
        Linear-zone half-width [mm].
    corrected : bool
        Use the corrected curve (record 19c) instead of the printed l~1 (eq. 19).

    Returns
    -------
    dict
        ``b0``, ``y``, ``x20`` [mm/s], ``k``, ``z``, ``omega0`` [mm/s] (NaN when no
        non-trivial root exists).
    """
    return dict(_intersection(a_, w_max, T_, d_, corrected))


@lru_cache(maxsize=32, typed=True)
def _intersection(
    a_: float, w_max: float, T_: float, d_: float, corrected: bool
) -> tuple[tuple[str, float], ...]:
    num = {a: a_, wm: w_max, T: T_, d: d_}
    with mpmath.workdps(30):
        if corrected:
            c = corrected_b0()
            bb = sp.N(c["b0c"].subs(num), 30)
            yy = sp.N(root_22_W(bb, -1) - c["shift"].subs(num), 30)
        else:
            bb = sp.N((a * d / wm + 2 * a * T).subs(num), 30)
            yy = sp.N(root_22_W(bb, -1), 30)
        x20 = -yy * w_max
        kk = 1 + a_ * d_ / x20
        if 0 < kk < 1:
            zz = sp.N(root_k_W(kk, -1), 30)
        elif kk > 1:
            zz = sp.N(root_k_W(kk, 0), 30)
        else:
            zz = sp.nan
        om0 = -x20 / zz if zz != 0 else sp.nan
    return (
        ("b0", float(bb)),
        ("y", float(yy)),
        ("x20", float(x20)),
        ("k", float(kk)),
        ("z", float(zz)),
        ("omega0", float(om0)),
    )


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
    j = judge((rhs(p15[0], tx1), rhs(p15[1], tx2)), (m1, m2), _free_state)
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
    j1 = judge(p16[1], lhs_plus, _free_state)
    n1, n2 = one_step(-1)
    j1m = judge(p16[1], sp.expand(a * n1 + n2), _free_state)
    j2 = judge(p16[2], p16[1].subs(x1, l1_x1(x2)), _l1_points)
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
    samp = _plant

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
            pts = _plant(rng, n)
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
        pts = _l1_points(rng, n)
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
    claim18 = judge((p18[0] - p18[-1]).subs(img[+1], simultaneous=True), sp.Integer(0), _l1_points)

    def state(ce):
        p = ce["point"]
        num = {S[key]: val for key, val in p.items()}
        return {
            "state_on_l1": [float(l1_x1(x2).subs(num)), p["x2"]],
            "image_under_plus_omega_m": [
                float(img[+1][tx1].subs(num)),
                float(img[+1][tx2].subs(num)),
            ],
        }

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
            extra=state,
        )
    ]
    r19 = p19.subs(img[+1], simultaneous=True)
    j_plus = judge(r19, sp.Integer(0), _l1_points)
    j_minus = judge(p19.subs(img[-1], simultaneous=True), sp.Integer(0), _l1_points)
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
            combine([j_plus, j_minus]),
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
            extra=state,
        )
    )
    # 19c: verify the preimage by mapping back, and its side
    c1 = pre.coeff(x1)  # pre is affine in x1
    x1_on = sp.cancel(-(pre - c1 * x1) / c1)
    n1, n2 = one_step(-1)
    m_img = (n1.subs(x1, x1_on), n2.subs(x1, x1_on))
    on_l1 = a * m_img[0] + m_img[1] + wm * sp.log(1 - m_img[1] / wm)
    j_on = judge(on_l1, sp.Integer(0), _l1_points)
    sigma = a * x1_on + x2 + wm * sp.log(1 - x2 / wm)
    j_side = judge(sigma > 0, sp.true, _l1_points, symbolic=False)
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


def _linear_root(residual: sp.Expr, var: sp.Symbol) -> sp.Expr:
    """Solve residual = 0 for var, residual linear in var or in 1/var (a definition).

    ``solve`` of the numerator over one denominator: the root is that of the
    residual where the denominator is nonzero (the judge checks it at random
    points).  Solving the numerator spares ``solve`` its test of whether the root
    zeroes a denominator, whose ``checksol`` imports ``sympy.physics.units``
    (~0.1 s) and simplifies; the root is the same.
    """
    return sp.solve(sp.numer(sp.together(residual)), var, simplify=False, check=False)[0]


def _rec_20_27() -> list[EquationRecord]:
    out = []
    (p19,) = parsed("19")
    p20, p21, (p22,), (p23,) = parsed("20"), parsed("21"), parsed("22"), parsed("23")
    p24, p25, (p26,), (p27,) = parsed("24"), parsed("25"), parsed("26"), parsed("27")
    (p13,) = parsed("13")
    inh = (
        " Verified as algebra relative to the printed predecessor; it inherits the "
        "erratum of (16)/(19) (see their inherits)."
    )

    def s20(rng, n):
        pts = _plant(rng, n)
        pts[tx10] = rng.uniform(0.0, 50.0, n)
        pts[tx20] = -rng.uniform(0.01, 5.0, n) * pts[wm]
        return pts

    ja = judge(p20[0], p19.subs({tx1: tx10, tx2: tx20}), s20)
    jb = judge(p20[1], p20[0] / wm, s20)
    out.append(
        record_from(
            "20",
            p20[0] / wm,
            ["(19) at the intersection (x~10, x~20)", "divide by omega_m"],
            combine([ja, jb]),
            "Line 1 is (19) at the intersection, line 2 is line 1 / omega_m." + inh,
        )
    )
    out.append(
        definition(
            "21", printed_text("21"), "Defines y = -x~20/omega_m and b0 = a x~10/omega_m + 2 a T."
        )
    )
    sub21 = {tx20: -y * wm, tx10: (b0 - 2 * a * T) * wm / a}
    d22 = p20[1].subs(sub21)

    def s22(rng, n):
        pts = _plant(rng, n)
        pts[y] = rng.uniform(-0.99, 10.0, n)
        pts[b0] = rng.uniform(0.0, 20.0, n)
        return pts

    out.append(
        record_from(
            "22",
            d22,
            ["substitute (21) into (20) line 2"],
            judge(p22, d22, s22),
            "Substitution of (21) into (20)." + inh,
        )
    )
    d23 = sp.solve(p21[0], tx20, simplify=False, check=False)[0]  # linear, no denominator
    out.append(
        record_from(
            "23",
            d23,
            ["solve y = -x~20/omega_m for x~20"],
            judge(rhs(p23, tx20), d23, s22),
            "Inverse of the definition of y." + inh,
        )
    )

    def s24(rng, n):
        pts = s20(rng, n)
        pts[w0] = rng.uniform(1.0, 1000.0, n)
        return pts

    ja = judge(p24[0], p13.subs({x1: tx10, x2: tx20}), s24)
    jb = judge(p24[1], p24[0] / w0, s24)
    out.append(
        record_from(
            "24",
            p24[0] / w0,
            ["(13) at (x~10, x~20)", "divide by omega0"],
            combine([ja, jb]),
            "l1* through the intersection point." + inh,
        )
    )
    out.append(
        definition("25", printed_text("25"), "Defines k = 1 + a x~10/x~20 and z = -x~20/omega0.")
    )
    d26 = p24[1].subs({tx10: (k - 1) * tx20 / a}).subs(tx20, -z * w0)

    def s26(rng, n):
        pts = _plant(rng, n)
        pts[w0] = rng.uniform(1.0, 1000.0, n)
        pts[k] = rng.uniform(-5.0, 5.0, n)
        pts[z] = rng.uniform(-0.99, 10.0, n)
        return pts

    out.append(
        record_from(
            "26",
            sp.expand(d26),
            ["substitute (25) into (24) line 2"],
            judge(p26, d26, s26),
            "Substitution of (25) into (24)." + inh,
        )
    )
    d27 = _linear_root(p25[1], w0)

    def s27(rng, n):
        pts = s20(rng, n)
        pts[z] = rng.uniform(0.01, 10.0, n)
        return pts

    out.append(
        record_from(
            "27",
            d27,
            ["solve z = -x~20/omega0 for omega0"],
            judge(rhs(p27, w0), d27, s27),
            "Inverse of the definition of z." + inh,
        )
    )
    return out


def _rec_28_35() -> list[EquationRecord]:
    out = []

    def s28(rng, n):
        pts = _free_state(rng, n)
        pts[wc] = rng.uniform(1.0, 1000.0, n)
        pts[x2] = rng.uniform(-0.99, 0.99, n) * pts[wc]
        return pts

    for id_, lvl in (("28", wc), ("33", -wc)):
        R = sp.expand_log(trajectory_residual(lvl).subs({S["x10"]: 0, S["x20"]: 0}), force=True)
        (p,) = parsed(id_)
        sgn = "+" if id_ == "28" else "-"
        out.append(
            record_from(
                id_,
                R,
                [f"eq. (8) for the input {sgn}omega_c, through the origin"],
                judge(p, R, s28),
                f"Trajectory of u = {sgn}omega_c through the origin.",
            )
        )
    p29, p30 = parsed("29"), parsed("30")
    (p28,) = parsed("28")
    ja = judge(p29[0] - p29[1], p28 / wc, s28)
    jb = judge(p29[2], p29[1], s28)
    out.insert(
        1,
        record_from(
            "29",
            p28 / wc,
            ["(28) divided by omega_c, rearranged", "factor -x2/omega_c"],
            combine([ja, jb]),
            "Rewriting of (28).",
        ),
    )
    out.insert(
        2,
        definition(
            "30",
            printed_text("30"),
            "Defines k = 1 + a x1/x2 and "
            "w = -x2/omega_c (the text says 'Equation (30) can be expressed "
            "as' where (29) is meant).",
        ),
    )
    d31 = (p29[0] - p29[2]).subs(x1, (k - 1) * x2 / a).subs(x2, -w * wc)

    def s31(rng, n):
        pts = _plant(rng, n)
        pts[wc] = rng.uniform(1.0, 1000.0, n)
        pts[k] = rng.uniform(-5.0, 5.0, n)
        pts[w] = rng.uniform(-0.99, 10.0, n)
        return pts

    (p31,) = parsed("31")
    out.insert(
        3,
        record_from(
            "31",
            sp.expand(d31),
            ["substitute (30) into (29)"],
            judge(p31, d31, s31),
            "Substitution of (30) into (29).",
        ),
    )
    d32 = _linear_root(p30[1], wc)
    (p32,) = parsed("32")

    def s32(rng, n):
        pts = _free_state(rng, n)
        pts[w] = rng.uniform(0.01, 10.0, n)
        return pts

    out.insert(
        4,
        record_from(
            "32",
            d32,
            ["solve w = -x2/omega_c for omega_c"],
            judge(rhs(p32, wc), d32, s32),
            "Inverse of the definition of w.",
        ),
    )
    out.append(definition("34", printed_text("34"), "The linear (PD) law of the zone S_L."))
    out.append(
        definition(
            "35",
            printed_text("35"),
            "The compound PTO law: a definition. Its "
            "omega0 inherits the (16)/(19) erratum; its zones are checked in "
            "(36).",
        )
    )
    return out


def _branch_signs(r: sp.Expr, branch: int, sampler) -> object:
    """Judge the sign pattern of a root: > 0 on W_{-1}, in (-1, 0) on W_0."""
    if branch == -1:
        return judge(sp.sign(r), sp.Integer(1), sampler, symbolic=False)
    return judge(
        (sp.sign(r), sp.sign(r + 1)), (sp.Integer(-1), sp.Integer(1)), sampler, symbolic=False
    )


def _rec_lambert() -> list[EquationRecord]:
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
    cb = corrected_b0()

    def sc(rng, n):
        pts = _plant(rng, n)
        pts[d] = rng.uniform(0.0, 50.0, n)
        pts[y] = rng.uniform(-0.99, 5.0, n)
        return pts

    j1 = judge(cb["form22"], cb["residual"], sc)
    out.append(
        record_from(
            "22c",
            cb["form22"],
            [
                "corrected (20): record 19c at (d, -y omega_m), divided by omega_m",
                "= ln(1 + Y) - (Y - b0c) with Y = y + 2 (exp(aT) - 1), "
                "b0c = a d/omega_m + 2 (exp(aT) - 1 - aT): the form of (22), root by record 22W",
            ],
            j1,
            "Corrected eqs. (20)-(22). Not in the paper.",
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


@lru_cache(maxsize=None)
def _symbolic_records() -> tuple[EquationRecord, ...]:
    """Build the records of eqs. (13)-(35) and extras without numbers (the costly part)."""
    return tuple(_rec_13_17() + _rec_18_19() + _rec_20_27() + _rec_28_35() + _rec_lambert())


def _at_plant_16(rec: EquationRecord, num: PlantNumbers) -> EquationRecord:
    """Add to the (16) erratum's counterexample the values at the given plant."""
    if rec.counterexample is None:
        return rec
    p16 = parsed("16")
    m1, m2 = one_step(+1)
    lhs_plus = sp.expand(a * m1 + m2)
    at = {a: num.a, wm: num.w_max, T: num.T, x2: -num.w_max / 2}
    at[x1] = float(l1_x1(x2).subs(at))
    ce = dict(rec.counterexample)
    ce["at_plant"] = {
        "point": {str(k_): float(v_) for k_, v_ in at.items()},
        "printed": float(p16[1].subs(at)),
        "derived": float(lhs_plus.subs(at)),
    }
    return dataclasses.replace(rec, counterexample=ce)


def _at_plant_27(rec: EquationRecord, num: PlantNumbers) -> EquationRecord:
    """Append to the note of (27) what both chains give at the given plant."""
    pr = intersection(num.a, num.w_max, num.T, num.d, corrected=False)
    co = intersection(num.a, num.w_max, num.T, num.d, corrected=True)
    wv = num.w_max
    nums = (
        f" At the plant (a = {num.a:.6g} rad/s, omega_m = {wv:.6g} mm/s, T = {num.T:.6g} s, "
        f"d = {num.d:.6g} mm) the printed chain gives x~20 = {pr['x20']:.6g} mm/s "
        + ("(|x~20| > omega_m: outside the saturation band) " if abs(pr["x20"]) > wv else "")
        + f"and omega0 = {pr['omega0']:.6g} mm/s "
        f"({'>' if pr['omega0'] > wv else '<='} omega_m); the corrected chain (19c, 22c) "
        f"gives x~20 = {co['x20']:.6g} mm/s and omega0 = {co['omega0']:.6g} mm/s."
    )
    return dataclasses.replace(rec, note=rec.note + nums)


@lru_cache(maxsize=8)
def records(numbers: PlantNumbers) -> tuple[EquationRecord, ...]:
    """Build the records of eqs. (13)-(35) and 15inv, 19c, 22c, 22W, 26W, 31W.

    Parameters
    ----------
    numbers : PlantNumbers
        Plant at which records 16 and 27 quote numeric examples (a [rad/s],
        w_max [mm/s], T [s], d [mm]).

    Returns
    -------
    tuple of EquationRecord
    """
    at = {"16": _at_plant_16, "27": _at_plant_27}
    return tuple(at[r.id](r, numbers) if r.id in at else r for r in _symbolic_records())
