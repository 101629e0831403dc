"""A plain, vectorized copy of the reference PTO law, with seeded faults (mutation suite).

The copy is written from the equations, independently of ``ptoverify.model.curves``
and ``ptoverify.model.laws``: every curve is its own function with the paper's ln
form, omega_c uses scipy's Lambert W with a Newton polish, and each fault is
a flag that makes one small edit.  ``make_law(faults)`` returns a callable
``u = f(x1, x2, cfg)`` for ``ptoverify conform``.  Only omega0 is taken from
``ptoverify.model.zones`` (a design parameter a team reads from ``ptoverify zone``).

``mutation_score()`` runs ``conform`` on every mutant and returns the score
(``tests/test_conform_table_probes.py`` also evaluates each mutant at the
states of ``conform --emit-grid`` and gates the table);
``python tests/pto_mutants.py`` prints it (the tests only assert).
"""

from __future__ import annotations

import numpy as np
from scipy.special import lambertw

from ptoverify.model.zones import zone_for_law

#: fault flag -> what the edit does (the mutation suite runs one flag per mutant)
MUTANTS: dict[str, str] = {
    "l1_sign": "sign of the log term flipped in l1 (eq. 9)",
    "l2_sign": "sign of the log term flipped in l2 (eq. 11)",
    "l1s_sign": "sign of the log term flipped in l1* (eq. 13)",
    "l2s_sign": "sign of the log term flipped in l2* (eq. 14)",
    "omega_c_sign": "sign flipped in the omega_c curve: m = +a x1 / x2 (eqs. 28, 30)",
    "log10": "ln replaced by log10 everywhere",
    "omega0_up": "omega0 10 % too large",
    "omega0_down": "omega0 10 % too small",
    "wrong_branch": "omega_c from the W_0 branch instead of W_-1 (eq. 31)",
    "mirror_swap": "mirror zone tests in swapped quadrants (x2 signs swapped in S~_P, S~_N)",
    "no_saturation": "saturation missing in the linear zone (eq. 34 unclipped)",
    "delay": "one-sample input delay (stateful: returns the previous call's u)",
    "d_doubled": "linear-zone half-width d doubled",
    "k_swapped": "k1 and k2 swapped",
    "boundary_tie": "wrong region exactly on the linear-zone edge: |x1| <= d instead of < d",
    "bang_sign_q4": "bang-bang sign inverted in the fourth quadrant (x1 > 0, x2 < 0)",
    "bisect_loose": "omega_c by bisection with a loose tolerance of 1e-2 on z (eq. 31)",
    "zone_constant": "u = +-omega0 in the zone (omega_c not computed)",
    "a_hz": "bandwidth in Hz used as rad/s in the curves (a / 2 pi)",
    "k2_sign": "sign of the damping term flipped: -k1 x1 + k2 x2",
    "zone_n_sign": "mirror zone returns +omega_c (sign error in eq. 33)",
    "pd_gains": "linear zone uses the PD gains kp, kd instead of k1, k2",
    "slow_band_x1": "bang-bang input 5 % low for 30.2 < |x1| < 31.4 mm (between grid columns)",
    "slow_band_x2": "bang-bang input 5 % low for 101 < |x2| < 109 mm/s, |x1| > 2 mm",
    "tie_asym": "within the tie band of l2* (x2 > 0) the bang branch -w_max, not the zone "
    "(the mirrored tie on l1* keeps the zone: the old examples/my_pto.py fault)",
    "latch": "a latch: once a call has seen |x2| > 0.95 w_max at |x1| > 40 mm, u is 0.1 % low",
    "cache": "an LRU cache of 64 entries keyed by the state rounded to 0.5 mm, 5 mm/s",
    "debounce": "a debounce: a sign change of u at an array index is held for one call",
    "call_count": "u 0.1 % high after the 50th call (a call counter)",
}

#: faults that give the law memory: ``conform`` must name them ``pure-function``
MEMORY = ("delay", "latch", "cache", "debounce", "call_count")

#: numerical variants that are not faults: each must conform (no false rejections)
BENIGN: dict[str, str] = {
    "faithful": "the copy without faults",
    "float32": "output rounded to float32 (firmware single precision)",
    "bisect_exact": "omega_c by bisection to the last bit instead of Lambert W",
}


def _ln(x, f):
    return np.log10(x) if "log10" in f else np.log(x)


def _l1(x1, x2, a, w, f):
    """Eq. (9), x2 <= 0: a x1 + x2 + w ln(1 - x2 / w)."""
    s = -1.0 if "l1_sign" in f else 1.0
    return a * x1 + x2 + s * w * _ln(1.0 - x2 / w, f)


def _l2(x1, x2, a, w, f):
    """Eq. (11), x2 >= 0: a x1 + x2 - w ln(1 + x2 / w)."""
    s = -1.0 if "l2_sign" in f else 1.0
    return a * x1 + x2 - s * w * _ln(1.0 + x2 / w, f)


def _l1s(x1, x2, a, om, f):
    """Eq. (13), x2 <= 0: a x1 + x2 + omega0 ln(1 - x2 / omega0)."""
    s = -1.0 if "l1s_sign" in f else 1.0
    return a * x1 + x2 + s * om * _ln(1.0 - x2 / om, f)


def _l2s(x1, x2, a, om, f):
    """Eq. (14), x2 >= 0: a x1 + x2 - omega0 ln(1 + x2 / omega0)."""
    s = -1.0 if "l2s_sign" in f else 1.0
    return a * x1 + x2 - s * om * _ln(1.0 + x2 / om, f)


def _root_z(k, f):
    """Non-trivial root of ln(1 + z) = k z (eqs. 26, 31), 0 < k < 1."""
    if "bisect_loose" in f or "bisect_exact" in f:
        tol = 1e-2 if "bisect_loose" in f else 0.0
        lo, hi = 1.0 - k, 1.0 / k**2 + 1.0  # g(z) = ln(1+z) - k z: > 0, < 0
        for _ in range(2000):
            mid = 0.5 * (lo + hi)
            active = (hi - lo > tol) & (mid > lo) & (mid < hi)
            if not np.any(active):
                break
            pos = (_ln(1.0 + mid, f) - k * mid) > 0
            lo = np.where(active & pos, mid, lo)
            hi = np.where(active & ~pos, mid, hi)
        return 0.5 * (lo + hi)
    branch = 0 if "wrong_branch" in f else -1
    z = -1.0 - np.real(lambertw(-k * np.exp(-k), branch)) / k
    for _ in range(2):  # Newton polish on ln(1+z) - k z
        z = z - (_ln(1.0 + z, f) - k * z) / (1.0 / (1.0 + z) - k)
    return z


def _omega_c(x1, x2, a, f):
    """Level of the curve through the state, eqs. (28)-(33): |x2| / z*, m = -a x1 / x2."""
    m = (a if "omega_c_sign" in f else -a) * x1 / x2
    with np.errstate(all="ignore"):
        k = 1.0 - m
        z = _root_z(np.where((k > 0) & (k < 1), k, 0.5), f)
        z = np.where((k > 0) & (k < 1), z, 0.0)
        return np.abs(x2) / z


_OMEGA0: list = [None, None]  # (cfg, omega0) of the last configuration seen


def _omega0(cfg):
    """omega0 of the corrected zone [mm/s], read once per configuration object.

    A pure function of ``cfg`` (a frozen dataclass): the copy is called every
    sample of a closed loop, and ``zone_for_law`` at each call cost more than
    the law's own arithmetic.
    """
    if _OMEGA0[0] is not cfg:
        _OMEGA0[:] = [cfg, zone_for_law(cfg, "corrected").omega0]
    return _OMEGA0[1]


def _pto(x1, x2, cfg, f):
    p, s = cfg.plant, cfg.pto
    a, w = p.a, p.w_max
    if "a_hz" in f:
        a = a / (2.0 * np.pi)
    d = 2.0 * s.d if "d_doubled" in f else s.d
    k1, k2 = (s.k2, s.k1) if "k_swapped" in f else (s.k1, s.k2)
    if "pd_gains" in f:
        k1, k2 = cfg.pd.kp, cfg.pd.kd
    om = _omega0(cfg)
    om *= 1.1 if "omega0_up" in f else 0.9 if "omega0_down" in f else 1.0
    neg, nonneg = np.minimum(x2, 0.0), np.maximum(x2, 0.0)
    with np.errstate(all="ignore"):
        sig = np.where(x2 <= 0, _l1(x1, neg, a, w, f), _l2(x1, nonneg, a, w, f))
        r0 = np.where(x2 <= 0, _l1s(x1, neg, a, om, f), _l2s(x1, nonneg, a, om, f))
    pos = (sig < 0) | ((sig == 0) & (x2 < 0))
    u = np.where(pos, w, -w)
    if "bang_sign_q4" in f:
        u = np.where((x1 > 0) & (x2 < 0), -u, u)
    lo, hi = (x2 > 0, x2 < 0) if "mirror_swap" in f else (x2 < 0, x2 > 0)
    zp = lo & (sig > 0) & (r0 <= 0)
    zn = hi & (sig < 0) & (r0 >= 0)
    inz = zp | zn
    if np.any(inz):
        wc = om if "zone_constant" in f else np.clip(_omega_c(x1[inz], x2[inz], a, f), om, w)
        sign_n = 1.0 if "zone_n_sign" in f else -1.0
        u = u.copy()
        u[inz] = np.where(zp[inz], wc, sign_n * wc)
    if "tie_asym" in f:
        band = 1e-9 * (w + a * p.position_range)
        u = np.where((x2 > 0) & (sig < 0) & (np.abs(r0) <= band), -w, u)
    bang = np.abs(u) == w
    if "slow_band_x1" in f:
        u = np.where(bang & (np.abs(x1) > 30.2) & (np.abs(x1) < 31.4), 0.95 * u, u)
    if "slow_band_x2" in f:
        band2 = (np.abs(x2) > 101.0) & (np.abs(x2) < 109.0) & (np.abs(x1) > 2.0)
        u = np.where(bang & band2, 0.95 * u, u)
    lin = np.abs(x1) <= d if "boundary_tie" in f else np.abs(x1) < d
    damp = k2 if "k2_sign" in f else -k2
    ul = -k1 * x1 + damp * x2
    if "no_saturation" not in f:
        ul = np.clip(ul, -w, w)
    u = np.where(lin, ul, u)
    u = np.where((x1 == 0) & (x2 == 0), 0.0, u)
    if "float32" in f:
        u = u.astype(np.float32).astype(float)
    return u


class _Delayed:
    """One-sample input delay: each call returns the previous call's u (0 at first)."""

    def __init__(self, inner):
        self.inner, self.prev = inner, None

    def __call__(self, x1, x2, cfg):
        u = self.inner(x1, x2, cfg)
        out = (
            self.prev
            if self.prev is not None and np.shape(self.prev) == np.shape(u)
            else np.zeros_like(u)
        )
        self.prev = u
        return out


class _Latch:
    """Scales u by 0.999 for good once a call has seen a fast state far out."""

    def __init__(self, inner):
        self.inner, self.on = inner, False

    def __call__(self, x1, x2, cfg):
        u = self.inner(x1, x2, cfg)
        out = u * 0.999 if self.on else u
        w = cfg.plant.w_max
        self.on |= bool(np.any((np.abs(x2) > 0.95 * w) & (np.abs(x1) > 40.0)))
        return out


class _Cache:
    """LRU cache of 64 entries keyed by the rounded state (nearby states share u)."""

    def __init__(self, inner):
        from collections import OrderedDict

        self.inner, self.store = inner, OrderedDict()

    def one(self, a, b, cfg):
        key = (round(a / 0.5), round(b / 5.0))
        if key in self.store:
            self.store.move_to_end(key)
            return self.store[key]
        u = float(self.inner(a, b, cfg))
        self.store[key] = u
        if len(self.store) > 64:
            self.store.popitem(last=False)
        return u

    def __call__(self, x1, x2, cfg):
        if np.ndim(x1) == 0:
            return self.one(float(x1), float(x2), cfg)
        u = self.inner(x1, x2, cfg)  # vectorized for speed; the cache overrides hits
        out = np.array(u, dtype=float, copy=True)
        for i, (a, b) in enumerate(zip(np.ravel(x1).tolist(), np.ravel(x2).tolist())):
            key = (round(a / 0.5), round(b / 5.0))
            if key in self.store:
                self.store.move_to_end(key)
                out.flat[i] = self.store[key]
            else:
                self.store[key] = float(out.flat[i])
                if len(self.store) > 64:
                    self.store.popitem(last=False)
        return out


class _Debounce:
    """A sign change of u at an array index (same shape as the last call) waits one call."""

    def __init__(self, inner):
        self.inner, self.prev = inner, None

    def __call__(self, x1, x2, cfg):
        u = self.inner(x1, x2, cfg)
        prev, self.prev = self.prev, u
        if prev is None or np.shape(prev) != np.shape(u):
            return u
        return np.where(np.sign(u) * np.sign(prev) < 0, prev, u)


class _CallCount:
    """u 0.1 % high after the 50th call."""

    def __init__(self, inner):
        self.inner, self.calls = inner, 0

    def __call__(self, x1, x2, cfg):
        self.calls += 1
        u = self.inner(x1, x2, cfg)
        return u * 1.001 if self.calls > 50 else u


_STATEFUL = {
    "delay": lambda inner: _Delayed(inner),
    "latch": _Latch,
    "cache": _Cache,
    "debounce": _Debounce,
    "call_count": _CallCount,
}


def make_law(faults=()):
    """Return the copy with the given fault flags as ``u = f(x1, x2, cfg)``.

    Parameters
    ----------
    faults : iterable of str
        Keys of :data:`MUTANTS` or :data:`BENIGN` (``faithful`` is no flag).

    Returns
    -------
    callable
        Vectorized law (a float for scalar input), stateful for :data:`MEMORY` faults.
    """
    f = frozenset(faults) - {"faithful"}
    unknown = f - set(MUTANTS) - set(BENIGN)
    if unknown:
        raise KeyError(f"unknown fault {sorted(unknown)}")

    def law(x1, x2, cfg):
        x1a, x2a = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        u = _pto(np.atleast_1d(x1a), np.atleast_1d(x2a), cfg, f).reshape(x1a.shape)
        return float(u) if u.ndim == 0 else u

    for name, wrap in _STATEFUL.items():
        if name in f:
            law = wrap(law)
    return law


def faithful(x1, x2, cfg):
    """The copy without faults (for ``--law tests/pto_mutants.py:faithful``)."""
    return make_law()(x1, x2, cfg)


def mutation_score(cfg=None, sweep=(11, 11, 20), grid=None):
    """Run ``conform`` on every mutant; return (killed, total, {name: failed properties}).

    Parameters
    ----------
    cfg : Config, optional
        Configuration (default: the paper's).
    sweep : (n1, n2, rest)
        Closed-loop sweep grid.
    grid : (x1, x2), optional
        Agreement grid [mm], [mm/s]; default ``conformance_grid(cfg)``, built once for
        all mutants (what ``conform_callable`` would build for each).

    Returns
    -------
    killed, total : int
        Mutants rejected, mutants run.
    detail : dict
        Mutant -> list of the properties that failed (empty: survived).
    """
    from ptoverify.config import paper_config
    from ptoverify.conform.agreement import conformance_grid
    from ptoverify.conform.gate import conform_callable

    cfg = paper_config() if cfg is None else cfg
    grid = conformance_grid(cfg) if grid is None else grid
    detail = {}
    for name in MUTANTS:
        r = conform_callable(make_law([name]), cfg, target=name, sweep=sweep, grid=grid)
        detail[name] = [] if r.conforms else r.failed_properties()
    killed = sum(bool(v) for v in detail.values())
    return killed, len(detail), detail


if __name__ == "__main__":
    import time

    t0 = time.perf_counter()
    k, n, det = mutation_score()
    for name, props in det.items():
        print(f"{name:<14} {'KILLED' if props else 'SURVIVED':<9} {', '.join(props)}")
    print(f"mutation score {k}/{n} in {time.perf_counter() - t0:.1f} s")
