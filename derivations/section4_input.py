"""Section 4, eqs. (28)-(35): the suboptimal input omega_c and the compound law.

In the switching zone the law applies u = omega_c in [omega0, omega_m], the
level of the trajectory (28) through the state and the origin; (29)-(32) solve
it for omega_c (its root w has the Lambert-W closed form of record 31W), (33)
is the mirror image for S~_N, (34) the linear law of S_L and (35) the compound
law.
"""

from __future__ import annotations

import sympy as sp

from derivations.common import S, combine, linear_root, parsed, record_from, rhs
from derivations.printed import printed_text
from derivations.record import EquationRecord, definition, judge
from derivations.section3 import trajectory_residual
from derivations.section4_image import plant_points, state_points

__all__ = ["records"]

a, wm, wc, T = (S[n] for n in ("a", "omega_m", "omega_c", "T"))
x1, x2 = S["x1"], S["x2"]
k, w = S["k"], S["w"]


def records() -> list[EquationRecord]:
    """Build the records of eqs. (28)-(35).

    Returns
    -------
    list of EquationRecord
    """
    out = []

    def s28(rng, n):
        pts = state_points(rng, n)
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
        pts = plant_points(rng, n)
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
    d32 = linear_root(p30[1], wc)
    (p32,) = parsed("32")

    def s32(rng, n):
        pts = state_points(rng, n)
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
