"""Section 5, stability: eqs. (36)-(39) and the Lyapunov argument after (39).

(36): which side of l1 and l1* each inequality selects, for omega0 below and
above omega_m.  (37): the closed loop of the linear zone, derived as A - B K.
(39): dV/dt along (37), derived as grad V . (A - B K) x.  Record ``39L``
checks the argument printed after (39) (positivity, LaSalle, Hurwitz); it is a
continuous-time statement without saturation.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from derivations.common import PlantNumbers, S, combine, parsed, record_from, rhs
from derivations.record import EquationRecord, definition, judge

__all__ = ["records", "closed_loop_matrix", "lyapunov_derivative", "zoh_spectral_radius"]

a, wm, w0, T = S["a"], S["omega_m"], S["omega_0"], S["T"]
x1, x2, k1, k2 = S["x1"], S["x2"], S["k1"], S["k2"]


def closed_loop_matrix() -> sp.Matrix:
    """Closed-loop matrix of the linear zone, eq. (37): A - B K.

    x' = A x + B u with A = [[0, 1], [0, -a]], B = [0, a]^T (eq. 1) and
    u = -K x, K = [k1, k2] (eq. 34).

    Returns
    -------
    sympy.Matrix, shape (2, 2)
    """
    A = sp.Matrix([[0, 1], [0, -a]])
    B = sp.Matrix([0, a])
    K = sp.Matrix([[k1, k2]])
    return A - B * K


def lyapunov_derivative() -> sp.Expr:
    """dV/dt of V = a k1 x1^2 + x2^2 (eq. 38) along eq. (37).

    Returns
    -------
    sympy.Expr
        grad V . (A - B K) x, expanded.
    """
    V = a * k1 * x1**2 + x2**2
    xv = sp.Matrix([x1, x2])
    grad = sp.Matrix([[V.diff(x1), V.diff(x2)]])
    return sp.expand((grad * closed_loop_matrix() * xv)[0])


def zoh_spectral_radius(a_: float, T_: float, k1_: float, k2_: float) -> float:
    """Spectral radius of the ZOH-sampled linear zone, Ad - Bd K.

    Ad = e^{A T}, Bd = int_0^T e^{A s} ds B, from the SymPy matrix exponential
    (Van Loan's block form).

    Parameters
    ----------
    a_ : float
        Bandwidth [rad/s].
    T_ : float
        Sampling period [s].
    k1_, k2_ : float
        PD gains of eq. (34) [1/s], [-].

    Returns
    -------
    float
        max |eigenvalue|; < 1 means the sampled, unsaturated loop is stable.
    """
    M = _zoh_closed_loop().subs({a: a_, T: T_, k1: k1_, k2: k2_})
    return float(max(abs(complex(ev)) for ev in np.linalg.eigvals(np.array(M, dtype=float))))


@lru_cache(maxsize=None)
def _zoh_closed_loop() -> sp.Matrix:
    """Ad - Bd K in the symbols a, T, k1, k2.

    Ad = e^{A T} and Bd = int_0^T e^{A s} ds B are read off one matrix exponential,
    exp([[A, B], [0, 0]] T) = [[Ad, Bd], [0, 1]] (Van Loan).
    """
    A = sp.Matrix([[0, 1], [0, -a]])
    B = sp.Matrix([0, a])
    Z = sp.zeros(3, 3)
    Z[:2, :2], Z[:2, 2] = A, B
    E = (Z * T).exp()
    Ad, Bd = E[:2, :2], E[:2, 2]
    return sp.ImmutableMatrix(Ad - Bd * sp.Matrix([[k1, k2]]))


def _rec_36() -> EquationRecord:
    p = parsed("36")
    inside = sp.Piecewise((1, sp.And(*p)), (0, True))
    x_l1 = -(x2 + wm * sp.log(1 - x2 / wm)) / a
    x_l1s = -(x2 + w0 * sp.log(1 - x2 / w0)) / a
    between = sp.Piecewise((1, sp.And(x1 >= x_l1, x1 <= x_l1s)), (0, True))

    def sampler(lo, hi):
        def draw(rng, n):
            av = rng.uniform(1.0, 500.0, n)
            wv = rng.uniform(1.0, 1000.0, n)
            v = -rng.uniform(0.01, 0.99, n) * wv
            ov = rng.uniform(lo, hi, n) * wv
            xa = -(v + wv * np.log1p(-v / wv)) / av
            xb = -(v + ov * np.log1p(-v / ov)) / av
            xv = xa + rng.uniform(-1.0, 2.0, n) * (xb - xa)
            return {a: av, wm: wv, w0: ov, x2: v, x1: xv}

        return draw

    j_lo = judge(inside, between, sampler(0.02, 0.98), symbolic=False)
    j_hi = judge(inside, sp.Integer(0), sampler(1.02, 20.0), symbolic=False)
    return record_from(
        "36",
        "x_l1(x2) <= x1 <= x_l1*(x2), x2 < 0",
        [
            "x_l1(x2) = -(x2 + omega_m ln(1 - x2/omega_m))/a and x_l1*(x2) likewise with omega0",
            "for omega0 < omega_m: l1* lies right of l1; indicator of (36) equals the indicator "
            f"of the band between them: {j_lo.verdict}",
            "for omega0 > omega_m (what the printed chain (20)-(27) can yield; see 27 for "
            f"the plant's value): the set (36) is empty in the fourth quadrant: {j_hi.verdict}",
        ],
        combine([j_lo, j_hi]),
        "The first inequality selects the side right of (above) l1, the second the side left "
        "of (below) l1*; together the band between l1 and l1*, as claimed, provided omega0 < "
        "omega_m. With omega0 > omega_m the zone is empty.",
    )


def _rec_36_claim(num: PlantNumbers) -> EquationRecord:
    """Judge the claim that one -omega_m sample from l1* (x1 > d) stays above l1."""
    from derivations.section4 import intersection, l1_x1, one_step

    x1_star = l1_x1(x2, w0)
    n1, n2 = one_step(-1)
    img = {x1: n1.subs(x1, x1_star), x2: n2.subs(x1, x1_star)}
    resid = (a * x1 + x2 + wm * sp.log(1 - x2 / wm)).subs(img, simultaneous=True)
    av, wv, Tv, dv = num.a, num.w_max, num.T, num.d
    # numpy's functions by name (numpy.log), without lambdify's "from numpy import *"
    f_x1 = sp.lambdify((x2, a, w0), x1_star, modules=[{"numpy": np}], printer=NumPyPrinter)

    def sampler(om0):
        def draw(rng, n):
            v = -rng.uniform(0.001, 0.999, 10 * n) * wv
            with np.errstate(all="ignore"):
                keep = f_x1(v, av, om0) > dv  # the claim is for x1 > d only
            v = v[keep][:n]
            full = np.ones_like(v)
            return {x2: v, a: av * full, wm: wv * full, T: Tv * full, w0: om0 * full}

        return draw

    pr = intersection(av, wv, Tv, dv, corrected=False)
    co = intersection(av, wv, Tv, dv, corrected=True)
    j_pr = judge(sp.sign(resid), sp.Integer(1), sampler(pr.omega0), symbolic=False)
    j_co = judge(sp.sign(resid), sp.Integer(1), sampler(co.omega0), symbolic=False)
    return record_from(
        "36Z",
        f"sign of the l1 residual one -omega_m sample after l1*: {sp.sstr(resid)}",
        [
            "state on l1* (level omega0) with x1 > d, |x2| < omega_m; one exact "
            "sample of u = -omega_m; l1 residual of the image must be > 0",
            f"printed chain (omega0 = {pr.omega0:.6g} mm/s): {j_pr.verdict}"
            f" ({j_pr.n_points} states of l1* with x1 > d in the band)",
            f"corrected chain (omega0 = {co.omega0:.6g} mm/s): "
            f"{j_co.verdict} ({j_co.n_points} states)",
        ],
        j_pr,
        "Claim of rule (1) and of Section 5 ('l1* lies above l~1 when |x1| > d'"
        "): from l1*, one -omega_m sample does not stride over l1. Judged at "
        f"the plant (a = {av:.6g} rad/s, omega_m = {wv:.6g} mm/s, T = {Tv:.6g} s, "
        f"d = {dv:.6g} mm) for the omega0 of the printed chain. "
        + (
            f"With it, no state of l1* with x1 > d has |x2| < omega_m (l1* "
            f"reaches x1 = d at x2 = {pr.x20_tilde:.6g} mm/s), so the claim has no "
            "admissible instance (and by 36 the zone is empty for omega0 > "
            "omega_m). "
            if j_pr.n_points == 0
            else ""
        )
        + f"With the corrected omega0 (19c, 22c): {j_co.verdict}.",
        printed_str="(claim in Sections 4-5)",
    )


def _rec_37_39() -> list[EquationRecord]:
    out = []
    Acl = closed_loop_matrix()
    xv = sp.Matrix([x1, x2])
    f = Acl * xv
    p37 = parsed("37")

    def samp(rng, n):
        return {
            a: rng.uniform(1, 500, n),
            k1: rng.uniform(-500, 500, n),
            k2: rng.uniform(-10, 10, n),
            x1: rng.uniform(-50, 50, n),
            x2: rng.uniform(-1000, 1000, n),
        }

    j = judge((rhs(p37[0], S["dx1"]), rhs(p37[1], S["dx2"])), tuple(f), samp)
    out.append(
        record_from(
            "37",
            tuple(f),
            [
                "A = [[0, 1], [0, -a]], B = [0, a]^T from eq. (1); u = -k1 x1 - k2 x2 (eq. 34)",
                f"A - B K = {sp.sstr(Acl.tolist())}",
            ],
            j,
            "Closed loop of the linear zone (no saturation).",
        )
    )
    out.append(definition("38", "V - (a*k1*x1**2 + x2**2)", "Lyapunov candidate."))
    p39 = parsed("39")
    Vd = lyapunov_derivative()
    j = combine([judge(p39[1], Vd, samp), judge(p39[2], Vd, samp)])
    out.append(
        record_from(
            "39",
            Vd,
            ["dV/dt = grad V . (A - B K) x"],
            j,
            "Both lines of (39) compared with the derived derivative.",
        )
    )
    return out


@lru_cache(maxsize=None)
def _rec_39_lasalle() -> EquationRecord:
    Acl = closed_loop_matrix()
    s = sp.Symbol("s")
    charpoly = sp.expand((s * sp.eye(2) - Acl).det())
    # LaSalle: largest invariant set in {dV/dt = 0} = {x2 = 0} (1 + k2 > 0)
    # a linear system without denominators: solve's simplify and check (which import
    # sympy.physics.units, ~0.1 s) have nothing to do
    eqs = [x2, (Acl * sp.Matrix([x1, x2]))[1]]
    inv = sp.solve(eqs, [x1, x2], dict=True, simplify=False, check=False)
    inv_ok = inv == [{x1: 0, x2: 0}]
    # Hurwitz at random (k1 > 0, 1 + k2 > 0): max real part of eigenvalues < 0
    ev = list(Acl.eigenvals())
    re_max = sp.Max(*[sp.re(e) for e in ev])

    def samp(rng, n):
        return {
            a: rng.uniform(1, 500, n),
            k1: np.exp(rng.uniform(-5, 7, n)),
            k2: -1 + np.exp(rng.uniform(-5, 3, n)),
        }

    j_h = judge(sp.sign(re_max), sp.Integer(-1), samp, symbolic=False)
    V = a * k1 * x1**2 + x2**2

    def samp_x(rng, n):
        pts = samp(rng, n)
        pts.update({x1: rng.uniform(-50, 50, n), x2: rng.uniform(-1000, 1000, n)})
        return pts

    j_v = judge(sp.sign(V), sp.Integer(1), samp_x, symbolic=False)
    j = combine([j_h, j_v]) if inv_ok else judge(sp.Integer(1), sp.Integer(0), samp)
    return record_from(
        "39L",
        f"charpoly = {sp.sstr(charpoly)}; invariant set in {{x2 = 0}}: {inv}",
        [
            f"characteristic polynomial {sp.sstr(charpoly)}: Hurwitz iff "
            "a k1 > 0 and a (1 + k2) > 0, the paper's conditions",
            f"LaSalle: solving x2 = 0, dx2/dt = 0 gives {inv} (only the origin)",
            "V > 0 away from 0 and eigenvalues in the open left half plane at "
            "random k1 > 0, k2 > -1",
        ],
        j,
        "The claim after (39): V > 0, dV/dt <= 0 for k1 > 0, 1 + k2 > 0, hence "
        "asymptotic stability. Holds, but the printed reason 'x2 = 0 => x1 = 0' "
        "is not true pointwise (any (x1, 0) has x2 = 0); what holds is LaSalle: "
        "the only trajectory staying in {x2 = 0} is the origin, since there "
        "dx2/dt = -a k1 x1. This is a continuous-time statement for the "
        "unsaturated loop: it says nothing about the ZOH-sampled loop nor about "
        "saturation, so it is local and not a proof for the implemented law.",
        printed_str="(claim after eq. 39)",
    )


def _at_plant_39L(rec: EquationRecord, num: PlantNumbers) -> EquationRecord:
    """Append to the note of 39L the sampled-loop and saturation numbers at the plant."""
    rho = zoh_spectral_radius(num.a, num.T, num.k1, num.k2)
    u_peak = num.k1 * num.d + abs(num.k2) * num.w_max
    note = (
        f" At the plant (a = {num.a:.6g} rad/s, T = {num.T:.6g} s, k1 = {num.k1:.6g} 1/s, "
        f"k2 = {num.k2:.6g}): spectral radius of Ad - Bd K = {rho:.6g} "
        f"({'<' if rho < 1 else '>='} 1); |u| reaches k1 d + |k2| omega_m = {u_peak:.6g} "
        f"mm/s inside |x1| < d ({'above' if u_peak > num.w_max else 'within'} omega_m = "
        f"{num.w_max:.6g} mm/s)."
    )
    return dataclasses.replace(rec, note=rec.note + note)


@lru_cache(maxsize=None)
def _symbolic_records() -> tuple[EquationRecord, ...]:
    return tuple([_rec_36()] + _rec_37_39())


@lru_cache(maxsize=8)
def records(numbers: PlantNumbers) -> tuple[EquationRecord, ...]:
    """Build the records of eqs. (36)-(39) and the stability claims 36Z, 39L.

    Parameters
    ----------
    numbers : PlantNumbers
        Plant at which 36Z is judged and 39L quotes the sampled loop (a [rad/s],
        w_max [mm/s], T [s], d [mm], k1 [1/s], k2 [-]).

    Returns
    -------
    tuple of EquationRecord
    """
    sym = _symbolic_records()
    return (
        sym[0],
        _rec_36_claim(numbers),
        *sym[1:],
        _at_plant_39L(_rec_39_lasalle(), numbers),
    )
