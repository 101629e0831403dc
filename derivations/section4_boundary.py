"""Section 4, eqs. (20)-(27): the intersection with x1 = d and the boundary l1*.

Equations (20)-(27) are checked as algebra given their printed predecessor:
(19) at the intersection (x~10, x~20) = (d, x~20), the substitutions (21) and
(25), the roots y* of (22) and z* of (26), and omega0 = -x~20/z* (27).  Record
22c goes beyond the paper: the same construction from the corrected curve
(record 19c), which has the form of (22) again.  :func:`intersection` evaluates
both chains at one plant.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import mpmath
import sympy as sp

from derivations.common import S, combine, linear_root, parsed, record_from, rhs
from derivations.printed import printed_text
from derivations.record import EquationRecord, definition, judge
from derivations.section4_image import plant_points, preimage_l1
from derivations.section4_lambert import root_22_W, root_k_W

__all__ = ["records", "corrected_b0", "Intersection", "intersection"]

a, wm, w0, T, d = (S[n] for n in ("a", "omega_m", "omega_0", "T", "d"))
x1, x2, tx1, tx2, tx10, tx20 = (S[n] for n in ("x1", "x2", "tx1", "tx2", "tx10", "tx20"))
y, b0, k, z = (S[n] for n in ("y", "b0", "k", "z"))


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


@dataclass(frozen=True)
class Intersection:
    """The chain (21)-(27) at one plant: where l1* meets x1 = d, and its level omega0.

    Attributes
    ----------
    b0 : float
        b0 of eq. (21), a d/omega_m + 2 a T [-]; in the corrected chain, b0 of
        record 22c, a d/omega_m + 2 (e^{aT} - 1 - aT).
    y_star : float
        y*, the root y > 0 of eq. (22) [-]; y* = -x~20/omega_m (eq. 21).  In the
        corrected chain, Y* - 2 (e^{aT} - 1) with Y* the root of record 22c.
    x20_tilde : float
        x~20 = -y* omega_m, eq. (23) [mm/s].
    k : float
        k = 1 + a d / x~20, eq. (25) [-].
    z_star : float
        z*, the non-trivial root of eq. (26) [-]; NaN when there is none (k = 1).
    omega0 : float
        omega0 = -x~20 / z*, eq. (27) [mm/s]; NaN when there is none.
    """

    b0: float
    y_star: float
    x20_tilde: float
    k: float
    z_star: float
    omega0: float


def intersection(a_: float, w_max: float, T_: float, d_: float, corrected: bool) -> Intersection:
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
    Intersection
        b0, y*, x~20 [mm/s], k, z*, omega0 [mm/s] (NaN when no non-trivial
        root exists).
    """
    return _intersection(a_, w_max, T_, d_, corrected)


@lru_cache(maxsize=32, typed=True)
def _intersection(a_: float, w_max: float, T_: float, d_: float, corrected: bool) -> Intersection:
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
    return Intersection(
        b0=float(bb),
        y_star=float(yy),
        x20_tilde=float(x20),
        k=float(kk),
        z_star=float(zz),
        omega0=float(om0),
    )


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
        pts = plant_points(rng, n)
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
        pts = plant_points(rng, n)
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
        pts = plant_points(rng, n)
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
    d27 = linear_root(p25[1], w0)

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


def _rec_22c() -> EquationRecord:
    cb = corrected_b0()

    def sc(rng, n):
        pts = plant_points(rng, n)
        pts[d] = rng.uniform(0.0, 50.0, n)
        pts[y] = rng.uniform(-0.99, 5.0, n)
        return pts

    j1 = judge(cb["form22"], cb["residual"], sc)
    return record_from(
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


def records() -> list[EquationRecord]:
    """Build the records of eqs. (20)-(27) and 22c.

    Returns
    -------
    list of EquationRecord
    """
    return _rec_20_27() + [_rec_22c()]
