"""The proof certificate and its independent check (``prove --out`` / ``--check``).

A certificate is a set of arrays (``certificate.npz``): the grid edges, per
sub-interval of a its bounds, macro-step lengths, image boxes and input
enclosures, the target (P, c), and the law's parameters.  The check shares no
code with the prover beyond the configuration and the point law's formulas:

1. the target is re-certified in arb from its own closed-loop matrix;
2. every cell's bound is re-derived from the stored images: bound >= k + the
   largest bound of the cells its image meets (found by slicing the grid), or
   the image is inside the ellipse (corners, outward-rounded floats), or the
   cell is;
3. on a seeded sample of cells (every cell with ``full=True``), corner and
   centre states are stepped k samples exactly in arb under the law evaluated
   in arb, for a at both ends and the middle of each sub-interval, and each
   must land in the stored image box (and the law in the stored input bounds).
Any failure is an inconsistency (``prove --check`` exits 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from flint import arb, arb_mat, ctx

from ptoverify.config import Config
from ptoverify.errors import InputError

__all__ = ["certificate_arrays", "CertificateCheck", "check_certificate"]

_PREC = 200  #: arb precision of the check [bits]


def certificate_arrays(proof, cfg: Config) -> dict[str, np.ndarray]:
    """Return the arrays of a law's certificate.

    Parameters
    ----------
    proof : LawProof
        A proof (:func:`ptoverify.studies.prove.run.prove_law`).
    cfg : Config
        The configuration it was made with.

    Returns
    -------
    dict of ndarray
        Arrays for ``np.savez``.
    """
    from ptoverify.model.lawbox import law_spec  # the law's parameters, as proved

    balls = proof.balls
    return {
        "law": np.array(proof.law),
        "T": np.array(cfg.plant.sample_time),
        "e1": proof.grid.e1,
        "e2": proof.grid.e2,
        "bound": proof.bound,
        "a_lo": np.array([b.a_lo for b in balls]),
        "a_hi": np.array([b.a_hi for b in balls]),
        "ball_bound": np.stack([b.bound for b in balls]),
        "k": np.stack([b.k for b in balls]),
        "image": np.stack([np.stack(b.image) for b in balls]),
        "u_lo": balls[0].u_lo,
        "u_hi": balls[0].u_hi,
        "P": np.array(proof.target.P),
        "c": np.array(proof.target.c),
        "certified": np.array(proof.target.certified),
        "law_params": np.array(_params(law_spec(proof.law, cfg))),
    }


def _params(spec) -> list[float]:
    return [spec.a, spec.w_max, spec.d, spec.g1, spec.g2, spec.omega0]


@dataclass(frozen=True)
class CertificateCheck:
    """Outcome of an independent certificate check.

    Attributes
    ----------
    ok : bool
        No inconsistency found.
    problems : tuple of str
        What failed (first few).
    cells_checked : int
        Cells whose bounds were re-derived [-].
    cells_stepped : int
        Cells whose images were re-computed in arb [-].
    """

    ok: bool
    problems: tuple
    cells_checked: int
    cells_stepped: int

    def to_json(self) -> dict:
        """Plain JSON object."""
        return {
            "ok": self.ok,
            "problems": list(self.problems),
            "cells_checked": self.cells_checked,
            "cells_stepped": self.cells_stepped,
        }


def _acl(a: arb, T: float, g1: float, g2: float) -> arb_mat:  # noqa: N803
    """Closed-loop matrix of the sampled linear loop, from the flow eq. (7) in arb."""
    e = (-a * arb(T)).exp()
    ad = arb_mat([[1, (1 - e) / a], [0, e]])
    bd = arb_mat([[arb(T) - (1 - e) / a], [1 - e]])
    return ad - bd * arb_mat([[arb(g1), arb(g2)]])


def _target_ok(data, problems: list) -> None:
    """Re-certify the target in arb."""
    a, w, d, g1, g2, _ = data["law_params"].tolist()
    P = data["P"].tolist()  # noqa: N806
    c = float(data["c"])
    with ctx.workprec(_PREC):
        p = arb_mat([[arb(v) for v in r] for r in P])
        det = p[0, 0] * p[1, 1] - p[0, 1] * p[1, 0]
        if not (p[0, 0] > 0 and det > 0):
            problems.append("target: P is not positive definite")
            return
        inv = [[p[1, 1] / det, -p[0, 1] / det], [-p[1, 0] / det, p[0, 0] / det]]
        gg = arb(g1) ** 2 * inv[0][0] + 2 * arb(g1) * arb(g2) * inv[0][1] + arb(g2) ** 2 * inv[1][1]
        if not arb(c) * gg <= arb(w) ** 2:
            problems.append("target: the ellipse may leave the unsaturated region")
        if math.isfinite(d) and not arb(c) * inv[0][0] < arb(d) ** 2:
            problems.append("target: the ellipse may leave the linear zone |x1| < d")
        T = float(data["T"])  # noqa: N806
        for lo, hi in zip(data["a_lo"].tolist(), data["a_hi"].tolist(), strict=True):
            ball = arb(lo).union(arb(hi))
            m = _acl(ball, T, g1, g2)
            q = p - m.transpose() * p * m
            if not (q[0, 0] > 0 and q[0, 0] * q[1, 1] - q[0, 1] * q[1, 0] > 0):
                problems.append(f"target: decrease not certified for a in [{lo:g}, {hi:g}]")


def _inside_target(data, x1lo, x1hi, x2lo, x2hi) -> np.ndarray:
    """Boxes inside the ellipse: every corner, with a relative margin for rounding."""
    (p11, p12), (_, p22) = data["P"].tolist()
    c = float(data["c"])
    ok = np.ones(x1lo.shape, dtype=bool)
    for x1 in (x1lo, x1hi):
        for x2 in (x2lo, x2hi):
            q = p11 * x1 * x1 + 2 * p12 * x1 * x2 + p22 * x2 * x2
            # |error| of these few operations < 1e-14 of the sum of |terms|
            err = 1e-14 * (p11 * x1 * x1 + 2 * abs(p12 * x1 * x2) + p22 * x2 * x2)
            ok &= q + err <= c
    return ok


def _bounds_ok(data, problems: list) -> int:
    """Re-derive every cell's bound from the stored images (grid slicing)."""
    e1, e2 = data["e1"], data["e2"]
    n1, n2 = e1.size - 1, e2.size - 1
    i = np.tile(np.arange(n1), n2)
    j = np.repeat(np.arange(n2), n1)
    in_t = _inside_target(data, e1[i], e1[i + 1], e2[j], e2[j + 1]) & bool(data["certified"])
    bad = 0
    for q in range(data["k"].shape[0]):
        b = data["ball_bound"][q]
        grid = b.reshape(n2, n1)
        img = data["image"][q]
        k = data["k"][q]
        to_t = _inside_target(data, *img) & bool(data["certified"])
        cells = np.flatnonzero(np.isfinite(b) & ~((b == 0) & in_t) & ~(to_t & (b >= k)))
        y1lo, y1hi, y2lo, y2hi = img[:, cells]
        inside = (e1[0] <= y1lo) & (y1hi <= e1[-1]) & (e2[0] <= y2lo) & (y2hi <= e2[-1])
        bad += int(np.count_nonzero(~inside))
        cells = cells[inside]
        y1lo, y1hi, y2lo, y2hi = img[:, cells]
        i0 = np.maximum(np.searchsorted(e1, y1lo, "left") - 1, 0)
        i1 = np.minimum(np.searchsorted(e1, y1hi, "right") - 1, n1 - 1)
        j0 = np.maximum(np.searchsorted(e2, y2lo, "left") - 1, 0)
        j1 = np.minimum(np.searchsorted(e2, y2hi, "right") - 1, n2 - 1)
        # the largest bound over each rectangle of cells: one sliding-window maximum
        # per rectangle shape (a handful of shapes), read at the rectangle's corner
        worst = np.empty(cells.size)
        shapes = np.stack([j1 - j0 + 1, i1 - i0 + 1], axis=1)
        for hh, ww in np.unique(shapes, axis=0).tolist():
            sel = (shapes[:, 0] == hh) & (shapes[:, 1] == ww)
            win = np.lib.stride_tricks.sliding_window_view(grid, (hh, ww)).max(axis=(2, 3))
            worst[sel] = win[j0[sel], i0[sel]]
        bad += int(np.count_nonzero(~(b[cells] >= k[cells] + worst)))
        if not np.all(data["bound"] >= b):
            problems.append("bound: the overall bound is below a sub-interval's")
    if bad:
        problems.append(f"bound: {bad} cells' bounds are not implied by their images")
    return int(np.isfinite(data["bound"]).sum())


def _sigma(a: arb, x1: arb, x2: arb, level: float):
    """Switching function in arb, or None when the sign of x2 is uncertain."""
    lv = arb(level)
    if x2 > 0 or x2 < 0:
        r = abs(x2) / lv
        h = r - r.log1p()
        return a * x1 + (lv * h if x2 > 0 else -lv * h)
    if x2 == 0:
        return a * x1
    return None


def _omega_c(a: arb, x1: arb, x2: arb, om: float, w: float):
    """clip(omega_c, omega0, w_max) by certified bisection in arb."""
    lo, hi = arb(om), arb(w)
    ax, v = a * abs(x1), abs(x2)
    for _ in range(60):
        mid = (lo + hi) / 2
        g = ax - mid * (v / mid - (v / mid).log1p())
        if g < 0:
            lo = mid
        elif g > 0:
            hi = mid
        else:
            break
    return lo.union(hi)


def _law(params, x1: arb, x2: arb):
    """Return the law's input at a state in arb; None when its branch is not certain."""
    a, w, d, g1, g2, om = params
    aa = arb(a)
    if x1 == 0 and x2 == 0:
        return arb(0)
    if not math.isfinite(d) or abs(x1) < d:
        v = -arb(g1) * x1 - arb(g2) * x2
        if v > w:
            return arb(w)
        if v < -w:
            return arb(-w)
        if abs(v) <= w:
            return v
        return None
    if not abs(x1) >= d:
        return None
    s = _sigma(aa, x1, x2, w)
    if s is None or not (s > 0 or s < 0):
        return None
    if not math.isnan(om):
        so = _sigma(aa, x1, x2, om)
        if so is None:
            return None
        if x2 < 0 and s > 0:
            if so <= 0:
                return _omega_c(aa, x1, x2, om, w)
            if not so > 0:
                return None
        if x2 > 0 and s < 0:
            if so >= 0:
                return -_omega_c(aa, x1, x2, om, w)
            if not so < 0:
                return None
    return arb(w) if s < 0 else arb(-w)


def _stepped_ok(data, cfg: Config, cells, problems: list) -> None:
    """Step corner and centre states of ``cells`` exactly in arb; compare with the images."""
    params = data["law_params"].tolist()
    T = arb(float(data["T"]))  # noqa: N806
    e1, e2 = data["e1"], data["e2"]
    n1 = e1.size - 1
    bad_img = bad_u = 0
    with ctx.workprec(_PREC):
        for c in cells:
            i, j = c % n1, c // n1
            pts = [(e1[i + f], e2[j + g]) for f in (0, 1) for g in (0, 1)]
            pts.append((0.5 * (e1[i] + e1[i + 1]), 0.5 * (e2[j] + e2[j + 1])))
            for x1f, x2f in pts:
                u0 = _law(params, arb(x1f), arb(x2f))
                if u0 is not None and not (
                    arb(data["u_lo"][c]) <= u0 and u0 <= arb(data["u_hi"][c])
                ):
                    bad_u += 1
                for q in range(data["k"].shape[0]):
                    lo, hi = float(data["a_lo"][q]), float(data["a_hi"][q])
                    for a in {lo, hi, 0.5 * (lo + hi)}:
                        y = _run(params, arb(a), T, arb(x1f), arb(x2f), int(data["k"][q][c]))
                        if y is None:
                            continue
                        box = data["image"][q][:, c]
                        inside = arb(box[0]) <= y[0] and y[0] <= arb(box[1])
                        inside = inside and arb(box[2]) <= y[1] and y[1] <= arb(box[3])
                        if not inside:
                            bad_img += 1
    if bad_u:
        problems.append(f"input: {bad_u} states' inputs lie outside the stored enclosure")
    if bad_img:
        problems.append(f"image: {bad_img} exact images lie outside their stored boxes")


def _run(params, a: arb, T: arb, x1: arb, x2: arb, k: int):  # noqa: N803
    """K exact samples of the loop (eq. 7) in arb; None if a branch is uncertain."""
    e = (-a * T).exp()
    for _ in range(k):
        u = _law(params, x1, x2)
        if u is None:
            return None
        x1, x2 = x1 + u * T + (x2 - u) * (1 - e) / a, u + (x2 - u) * e
    return x1, x2


#: Each array of a certificate: NumPy dtype kinds allowed, and its number of dimensions.
_LAYOUT = {
    "law": ("U", 0),
    "T": ("f", 0),
    "e1": ("f", 1),
    "e2": ("f", 1),
    "bound": ("f", 1),
    "a_lo": ("f", 1),
    "a_hi": ("f", 1),
    "ball_bound": ("f", 2),
    "k": ("iu", 2),
    "image": ("f", 3),
    "u_lo": ("f", 1),
    "u_hi": ("f", 1),
    "P": ("f", 2),
    "c": ("f", 0),
    "certified": ("b", 0),
    "law_params": ("f", 1),
}


def _structure_ok(data, cfg: Config, problems: list[str]) -> bool:
    """Check keys, dtypes, shapes, and that the law and its parameters are the configuration's.

    A certificate is only as good as the law it speaks of: one whose ``law`` is not a
    law of the suite, or whose parameters differ from those the configuration gives
    that law, is inconsistent, whatever its bounds say.
    """
    from ptoverify.model.lawbox import law_spec

    for key, (kinds, ndim) in _LAYOUT.items():
        if key not in data:
            problems.append(f"array '{key}' missing")
        elif np.asarray(data[key]).dtype.kind not in kinds or np.ndim(data[key]) != ndim:
            v = np.asarray(data[key])
            problems.append(f"array '{key}' has dtype {v.dtype} and {v.ndim} dimensions")
    if problems:
        return False
    n = (data["e1"].size - 1) * (data["e2"].size - 1)
    m = data["a_lo"].size
    shapes = {
        "bound": (n,),
        "u_lo": (n,),
        "u_hi": (n,),
        "a_hi": (m,),
        "ball_bound": (m, n),
        "k": (m, n),
        "image": (m, 4, n),
        "P": (2, 2),
        "law_params": (6,),
    }
    for key, shape in shapes.items():
        if data[key].shape != shape:
            problems.append(f"array '{key}' has shape {data[key].shape}, expected {shape}")
    if problems:
        return False
    name = str(data["law"])
    try:
        want = _params(law_spec(name, cfg))
    except (KeyError, ValueError, InputError):
        problems.append(f"law '{name}' is not a law this configuration can prove")
        return False
    if not np.array_equal(data["law_params"], np.array(want, dtype=float), equal_nan=True):
        problems.append(
            f"the parameters of law '{name}' differ from this configuration's "
            f"({data['law_params'].tolist()} vs {want})"
        )
    if float(data["T"]) != cfg.plant.sample_time:
        problems.append(f"T = {float(data['T'])} s, the configuration's is {cfg.plant.sample_time}")
    return not problems


def check_certificate(
    data, cfg: Config, *, full: bool = False, samples: int = 200, seed: int = 0
) -> CertificateCheck:
    """Check a certificate by the independent path of the module docstring.

    Parameters
    ----------
    data : mapping of ndarray
        The certificate's arrays (``np.load`` of ``certificate.npz``).
    cfg : Config
        Configuration (for consistency of the law's parameters).
    full : bool
        Step every proved cell in arb (slow) instead of a seeded sample.
    samples : int
        Cells stepped when not ``full``.
    seed : int
        Seed of the sample.

    Returns
    -------
    CertificateCheck
        The outcome.
    """
    problems: list[str] = []
    if not _structure_ok(data, cfg, problems):
        return CertificateCheck(False, tuple(problems), 0, 0)
    if bool(data["certified"]):
        _target_ok(data, problems)
    checked = _bounds_ok(data, problems)
    proved = np.flatnonzero(np.isfinite(data["bound"]))
    if full:
        cells = proved
    else:
        rng = np.random.default_rng(seed)
        cells = (
            rng.choice(proved, size=min(samples, proved.size), replace=False)
            if proved.size
            else proved
        )
    _stepped_ok(data, cfg, cells.tolist(), problems)
    return CertificateCheck(not problems, tuple(problems), checked, int(len(cells)))
