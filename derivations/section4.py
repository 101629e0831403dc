"""Section 4, the switching zone: eqs. (13)-(35), and their corrections.

The records come from one module per part of the section, in the paper's order:

- :mod:`derivations.section4_image`: (13)-(19), the boundary curves and the
  one-sample image of l1 (records 15inv, 19c: the inverse map, the corrected
  curve);
- :mod:`derivations.section4_boundary`: (20)-(27), the intersection with x1 = d,
  its roots y* and z*, and the level omega0 of l1* (record 22c: the corrected
  chain; :func:`intersection` evaluates both chains at a plant);
- :mod:`derivations.section4_input`: (28)-(35), the suboptimal input omega_c and
  the compound law;
- :mod:`derivations.section4_lambert`: the Lambert-W closed forms of the roots of
  (22), (26), (31) (records 22W, 26W, 31W), which the paper finds by bisection.

This module assembles them, adds what records 16 and 27 say at the caller's
plant, and re-exports the public names.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import sympy as sp

from derivations import section4_boundary, section4_image, section4_input, section4_lambert
from derivations.common import PlantNumbers, S, parsed
from derivations.record import EquationRecord
from derivations.section4_boundary import Intersection, corrected_b0, intersection
from derivations.section4_image import l1_x1, one_step, one_step_inverse, preimage_l1
from derivations.section4_lambert import root_22_W, root_k_W

__all__ = [
    "records",
    "l1_x1",
    "one_step",
    "one_step_inverse",
    "preimage_l1",
    "corrected_b0",
    "root_22_W",
    "root_k_W",
    "Intersection",
    "intersection",
]

a, wm, T = (S[n] for n in ("a", "omega_m", "T"))
x1, x2 = S["x1"], S["x2"]


@lru_cache(maxsize=None)
def _symbolic_records() -> tuple[EquationRecord, ...]:
    """Build the records of eqs. (13)-(35) and extras without numbers (the costly part)."""
    return tuple(
        section4_image.records()
        + section4_boundary.records()
        + section4_input.records()
        + section4_lambert.records()
    )


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
        f"d = {num.d:.6g} mm) the printed chain gives x~20 = {pr.x20_tilde:.6g} mm/s "
        + ("(|x~20| > omega_m: outside the saturation band) " if abs(pr.x20_tilde) > wv else "")
        + f"and omega0 = {pr.omega0:.6g} mm/s "
        f"({'>' if pr.omega0 > wv else '<='} omega_m); the corrected chain (19c, 22c) "
        f"gives x~20 = {co.x20_tilde:.6g} mm/s and omega0 = {co.omega0:.6g} mm/s."
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
