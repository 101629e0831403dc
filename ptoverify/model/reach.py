"""Discrete-time limit N* for many states: 2-D zonotope membership.

In the dimensionless coordinates z = (a x1 / w_max, x2 / w_max) and inputs
v = u / w_max, the ZOH plant (eq. 15) is z+ = Ad z + b v with c = a T,
r = e^{-c}, g = 1 - r::

    Ad^m = [[1, 1 - r^m], [0, r^m]],      Ad^m b = (c - g r^m, g r^m) =: g_m.

The origin is reached in N samples with |v_k| <= 1 iff Ad^N z lies in the
zonotope Z_N = {sum_{m<N} v_m g_m : |v_m| <= 1} (the forward form of the
issue's "-A^N x0 against the zonotope of A^m B, m < N"; Z_N is centrally
symmetric, so the sign does not matter).  Nothing grows with N here:
||Ad^N|| stays bounded (eigenvalues 1 and r^N), every generator lies in
[0, c] x [0, g], and Z_N only lengthens (x-extent about N c, y-extent below 1).
The inverse form A^{-N} would grow like e^{a T N} (1e164 at N = 1000 on the
paper plant) and is not used.

Geometry.  Every g_m has a positive first component and its slope
g r^m / (c - g r^m) decreases with m, so the generators are sorted by angle
and the facet normals of Z_N are the generators' normals.  The upper boundary
of Z_N is the concave chain with vertices U_k = 2 C_k - C_N, k = 0..N, where
C_k = sum_{m<k} g_m = (k c - (1 - r^k), 1 - r^k) in closed form (no summation
round-off); the lower boundary is its reflection through the origin.  A point
p lies in Z_N iff p and -p both lie on or below the upper chain.  Below the
chain is one facet test, on the segment k whose x-range holds p_x: with
q = (p + C_N) / 2, k is where q_x falls in the N-independent increasing table
C_x (``numpy.searchsorted``), and the test is
g_k,x (q_y - C_k,y) - g_k,y (q_x - C_k,x) <= 0.  So one membership test costs
two binary searches in one shared table and a few products per state, for any
mix of N across the states.

Margin.  A state counts as reaching the origin in N samples iff it does so with
|u_k| <= (1 + MARGIN) w_max, MARGIN = 1e-9, i.e. iff Ad^N z / (1 + MARGIN) is in
Z_N.  This is the LP reference's own acceptance rule (its polished sequence may
exceed w_max by 1e-9 relative, ``mintime._U_TOL``), it is relative to Z_N's own
size (so it means the same for N = 2 and N = 500), and it is far above the
round-off of the test (about 1e-15 of the terms compared) and far below any
physical meaning.  States built on a boundary in exact arithmetic, e.g. the
bang-bang states whose continuous optimum switches on the sample grid (a
vertex of Z_N), are therefore counted as reaching the origin in that N
whatever the rounding of their construction.  Z_1 is a segment (all N* = 1
states lie on a line); there the test is |cross(g_0, p)| <= MARGIN |g_0| |p|
with |p_x| <= (1 + MARGIN) g_0,x.  The LP decides within its own feasibility
tolerance (HiGHS, 1e-7), so the two can differ only for states within about
1e-7 relative of a boundary; the tests build boundary states and move them
in and out by 1e-6.

Search.  The sets are nested in N (u = 0 holds the origin), so N* follows by
exponential search then bisection, per state and vectorized over states.
The search starts at n0 = max(1, ceil(t_f* / T - 1e-9)) (no sampled input
beats the continuous optimum, N* T >= t_f*); n0 - 1 is tested, not assumed:
where it is inside (only possible within the margin), the bisection restarts
from 0 and the state is flagged ``below_bound``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant

__all__ = [
    "MARGIN",
    "DiscreteLimit",
    "ZonotopeTable",
    "zonotope_table",
    "zonotope_steps",
    "zonotope_steps_each",
]

MARGIN = 1e-9  # relative: |u_k| <= (1 + MARGIN) w_max counts as within the bound
_BLOCK = 8192  # states per block (temporaries stay in the heap and the cache)


@dataclass(frozen=True)
class DiscreteLimit:
    """Fewest ZOH samples to the origin for many states (arrays).

    Attributes
    ----------
    steps : ndarray of int64
        N* [samples]; 0 at the origin; -1 where N* > ``n_max``.
    time_s : ndarray
        N* T [s]; NaN where not found.
    below_bound : ndarray of bool
        N* < ceil(t_f* / T - 1e-9): beats the continuous bound, possible only
        for states within the margin of a boundary (module docstring).
    n_max : int
        Largest N tried [samples].
    tests : int
        Membership tests evaluated (state x N pairs).
    """

    steps: NDArray[np.int64]
    time_s: NDArray[np.float64]
    below_bound: NDArray[np.bool_]
    n_max: int
    tests: int

    @property
    def found(self) -> NDArray[np.bool_]:
        """True where N* was found (N* <= n_max)."""
        return self.steps >= 0


class ZonotopeTable:
    """Closed-form generator tables of one plant for N <= ``n``.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], sample_time T [s]).
    n : int
        Largest N the table serves [samples].

    Attributes
    ----------
    cx, cy : ndarray, shape (n + 1,)
        C_k = sum_{m<k} g_m (dimensionless), k = 0..n.
    gx, gy : ndarray, shape (n + 1,)
        g_k = Ad^k b (dimensionless).
    rn : ndarray, shape (n + 1,)
        r^k = e^{-a T k}.
    """

    def __init__(self, plant: Plant, n: int):
        c = plant.a * plant.sample_time
        k = np.arange(n + 1, dtype=float)
        self.n = n
        self.rn = np.exp(-c * k)
        self.cy = -np.expm1(-c * k)  # 1 - r^k
        self.cx = c * k - self.cy  # strictly increasing: steps g_k,x > 0
        g = -math.expm1(-c)
        c_minus_g = c + math.expm1(-c)  # c - g > 0
        self.gy = g * self.rn
        self.gx = c_minus_g + g * (1.0 - self.rn)  # c - g r^k, no cancellation
        # segment lookup without a binary search: buckets of width c / 2 hold at
        # most one breakpoint wherever segments are longer than c / 2 (g r^k < c / 2);
        # the few "dense" buckets near k = 0 fall back to searchsorted
        self._h = 0.5 * c
        nb = int(math.ceil(self.cx[-1] / self._h)) + 2
        edges = np.searchsorted(self.cx, np.arange(nb + 1) * self._h, side="right") - 1
        self._first = edges[:-1]
        self._dense = np.diff(edges) > 1
        self._cxp = np.concatenate([self.cx, [np.inf, np.inf]])

    def _segment(self, q: NDArray) -> NDArray[np.int64]:
        """Index k with cx[k] <= q < cx[k + 1] (-1 below 0), as ``searchsorted``."""
        j = np.clip(q / self._h, 0.0, self._first.size - 1).astype(np.int64)
        k = self._first[j]
        k -= q < self.cx[k]  # q / h rounded up across a bucket edge
        cxp = self._cxp
        k += q >= cxp[k + 1]
        k += q >= cxp[k + 1]  # q / h rounded down across an edge that is a breakpoint
        dense = np.flatnonzero(self._dense[j])
        if dense.size:
            k[dense] = np.searchsorted(self.cx, q[dense], side="right") - 1
        return k

    def contains(self, z1: NDArray, z2: NDArray, n: NDArray) -> NDArray[np.bool_]:
        """Whether dimensionless states reach the origin in ``n`` samples.

        Parameters
        ----------
        z1, z2 : ndarray, shape (m,)
            a x1 / w_max and x2 / w_max [-].
        n : ndarray of int, shape (m,)
            Samples per state, 1 <= n <= ``self.n``.

        Returns
        -------
        ndarray of bool, shape (m,)
            Ad^n z in (1 + MARGIN) Z_n.
        """
        s = 1.0 / (1.0 + MARGIN)
        cxn, cyn = self.cx[n], self.cy[n]
        px = (z1 + cyn * z2) * s  # Ad^n z, scaled by the margin
        py = (self.rn[n] * z2) * s
        ok = np.abs(px) <= cxn
        top = n - 1
        for sign in (1.0, -1.0):
            qx = 0.5 * (sign * px + cxn)
            qy = 0.5 * (sign * py + cyn)
            k = self._segment(qx)
            np.clip(k, 0, top, out=k)
            ok &= self.gx[k] * (qy - self.cy[k]) - self.gy[k] * (qx - self.cx[k]) <= 0.0
        one = np.flatnonzero(n == 1)
        if one.size:  # Z_1 is a segment: colinear within the margin (angle)
            x, y = px[one] / s, py[one] / s
            gx, gy = self.gx[0], self.gy[0]
            ok[one] = (np.abs(gx * y - gy * x) <= MARGIN * math.hypot(gx, gy) * np.hypot(x, y)) & (
                np.abs(x) <= (1.0 + MARGIN) * gx
            )
        return ok


_TABLES: dict[tuple[float, float], ZonotopeTable] = {}


def zonotope_table(plant: Plant, n: int) -> ZonotopeTable:
    """Return a cached :class:`ZonotopeTable` of ``plant`` serving N <= n.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], T [s]).
    n : int
        Largest number of samples [-] the table must serve.

    Returns
    -------
    ZonotopeTable
        The generator tables.
    """
    key = (plant.a, plant.sample_time)
    tab = _TABLES.get(key)
    if tab is None or tab.n < n:
        size = 256
        while size < n:
            size *= 2
        if len(_TABLES) >= 16:  # many plants (e.g. a parameter sweep): drop the oldest
            del _TABLES[next(iter(_TABLES))]
        tab = _TABLES[key] = ZonotopeTable(plant, size)
    return tab


def zonotope_steps(
    x1: ArrayLike, x2: ArrayLike, n0: ArrayLike, plant: Plant, n_max: int = 20000
) -> DiscreteLimit:
    """N* of many states by zonotope membership, given a lower-bound guess.

    Parameters
    ----------
    x1, x2 : array_like
        Initial positions [mm] and velocities [mm/s], finite; broadcast, flattened.
    n0 : array_like of int
        Per-state first candidate [samples], >= 1 (ceil(t_f* / T); any
        value >= 1 gives the same N*, only the number of tests changes).
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], sample_time T [s]).
    n_max : int
        Largest N tried [samples].

    Returns
    -------
    DiscreteLimit
        N*, N* T and the search's diagnostics, flattened order.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> plant = paper_config().plant
    >>> d = zonotope_steps([5.0, 5.0], [0.0, 0.0], [1, 40], plant)  # any start: same N*
    >>> int(d.steps[0]) == int(d.steps[1]), bool(d.below_bound[1])
    (True, True)
    """
    x1, x2, n0 = np.broadcast_arrays(
        np.asarray(x1, dtype=float), np.asarray(x2, dtype=float), np.asarray(n0)
    )
    x1, x2, n0 = x1.ravel(), x2.ravel(), n0.ravel().astype(np.int64)
    steps = np.empty(x1.size, dtype=np.int64)
    below = np.zeros(x1.size, dtype=bool)
    tests = 0
    for i in range(0, x1.size, _BLOCK):
        sl = slice(i, i + _BLOCK)
        steps[sl], below[sl], t = _search(x1[sl], x2[sl], n0[sl], plant, n_max)
        tests += t
    time_s = np.where(steps >= 0, steps * plant.sample_time, np.nan)
    return DiscreteLimit(steps, time_s, below, n_max, tests)


def _search(x1: NDArray, x2: NDArray, n0: NDArray, plant: Plant, n_max: int):
    """Exponential search then bisection on one block: (steps, below_bound, tests)."""
    a, w = plant.a, plant.w_max
    z1, z2 = a * x1 / w, x2 / w
    n0 = np.clip(n0, 1, n_max + 1)  # n_max + 1: not found (n_max itself is tested)
    tab = zonotope_table(plant, int(min(n_max, 2 * n0.max() + 16)) if n0.size else 1)
    tests = 0

    def inside(idx: NDArray, n: NDArray) -> NDArray[np.bool_]:
        nonlocal tab, tests
        if n.size and n.max() > tab.n:
            tab = zonotope_table(plant, int(n.max()))
        tests += idx.size
        return tab.contains(z1[idx], z2[idx], n)

    steps, below = _bracket(x1, x2, n0, n_max, inside)
    return steps, below, tests


def _bracket(
    x1: NDArray, x2: NDArray, n0: NDArray, n_max: int, inside: Callable
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Search N* (n0 - 1, then up exponentially, then bisection): (steps, below_bound).

    ``inside(idx, n)`` says whether the states ``idx`` reach the origin in ``n``
    samples (the sets are nested in n).  N* T >= t_f* makes n0 - 1 infeasible;
    a state inside there is flagged ``below_bound`` and searched from 0.
    """
    origin = (x1 == 0.0) & (x2 == 0.0)
    lo = n0 - 1
    hi = n0.copy()
    found = np.zeros(x1.size, dtype=bool)
    below = np.zeros(x1.size, dtype=bool)
    idx = np.flatnonzero(~origin & (lo >= 1))
    if idx.size:
        bad = idx[inside(idx, lo[idx])]
        below[bad] = True
        lo[bad] = 0
        hi[bad] = n0[bad] - 1  # known inside
        found[bad] = True
    step = np.ones(x1.size, dtype=np.int64)
    act = np.flatnonzero(~origin & ~found & (n0 <= n_max))
    while act.size:  # exponential search for an N inside
        ok = inside(act, hi[act])
        found[act[ok]] = True
        out = act[~ok]
        lo[out] = hi[out]
        step[out] *= 2
        hi[out] = np.minimum(lo[out] + step[out], n_max)
        act = out[lo[out] < n_max]
    act = np.flatnonzero(found & (hi - lo > 1))
    while act.size:  # bisection: lo outside, hi inside
        mid = (lo[act] + hi[act]) // 2
        ok = inside(act, mid)
        hi[act[ok]] = mid[ok]
        lo[act[~ok]] = mid[~ok]
        act = act[hi[act] - lo[act] > 1]
    steps = np.where(found, hi, -1)
    steps[origin] = 0
    return steps, below


def _contains_each(z1: NDArray, z2: NDArray, n: NDArray, c: NDArray) -> NDArray[np.bool_]:
    """:meth:`ZonotopeTable.contains` with a plant per state (c = a T per state).

    The table's entries at the indices a state needs, in closed form from its own
    c (the same formulas as :class:`ZonotopeTable`); the segment of each state by
    a bisection on k between two bounds from cx_k = c k - (1 - r^k) in [c k - 1, c k].
    """
    s = 1.0 / (1.0 + MARGIN)
    nf = n.astype(float)
    cyn = -np.expm1(-c * nf)
    cxn = c * nf - cyn
    rn = np.exp(-c * nf)
    g = -np.expm1(-c)
    c_minus_g = c + np.expm1(-c)
    px = (z1 + cyn * z2) * s  # Ad^n z, scaled by the margin
    py = (rn * z2) * s
    ok = np.abs(px) <= cxn
    top = n - 1
    for sign in (1.0, -1.0):
        qx = 0.5 * (sign * px + cxn)
        qy = 0.5 * (sign * py + cyn)
        # the largest k in [0, n - 1] with cx_k <= qx (0 if none), as the table's
        # searchsorted: cx_k <= c k gives k >= floor(qx / c), cx_k >= c k - 1 gives
        # k <= (qx + 1) / c; one sample of slack on each side for the roundings
        with np.errstate(invalid="ignore", over="ignore"):
            lo = np.floor(np.clip(qx / c - 1.0, 0.0, top)).astype(np.int64)
            hi = np.floor(np.clip((qx + 1.0) / c + 1.0, 0.0, top)).astype(np.int64)
        lo = np.minimum(lo, top)
        live = np.flatnonzero(lo < hi)
        while live.size:
            mid = (lo[live] + hi[live] + 1) // 2
            cm = c[live]
            mf = mid.astype(float)
            at = cm * mf + np.expm1(-cm * mf) <= qx[live]  # cx_mid = c mid - (1 - r^mid)
            lo[live[at]] = mid[at]
            hi[live[~at]] = mid[~at] - 1
            live = live[lo[live] < hi[live]]
        kf = lo.astype(float)
        rk = np.exp(-c * kf)
        cyk = -np.expm1(-c * kf)
        cxk = c * kf - cyk
        gxk = c_minus_g + g * (1.0 - rk)
        ok &= gxk * (qy - cyk) - (g * rk) * (qx - cxk) <= 0.0
    one = np.flatnonzero(n == 1)
    if one.size:  # Z_1 is a segment: colinear within the margin (angle)
        x, y = px[one] / s, py[one] / s
        gx, gy = c_minus_g[one], g[one]
        ok[one] = (np.abs(gx * y - gy * x) <= MARGIN * np.hypot(gx, gy) * np.hypot(x, y)) & (
            np.abs(x) <= (1.0 + MARGIN) * gx
        )
    return ok


def zonotope_steps_each(
    x1: ArrayLike,
    x2: ArrayLike,
    n0: ArrayLike,
    a: ArrayLike,
    w_max: ArrayLike,
    sample_time: float,
    n_max: int = 20000,
) -> NDArray[np.int64]:
    """N* of many states, each for its own plant (a, w_max), by zonotope membership.

    :func:`zonotope_steps` when every state has a different plant (e.g. a
    robustness search over the true bandwidth and drive limit): the same
    membership test, margin and search, with the generator table of each state
    evaluated in closed form at the few indices the state needs instead of
    tabulated per plant.  Vectorized over states whatever the mix of plants.

    Parameters
    ----------
    x1, x2 : array_like
        Initial positions [mm] and velocities [mm/s], finite; broadcast, flattened.
    n0 : array_like of int
        Per-state first candidate [samples], >= 1 (e.g. ceil(t_f* / T); any
        value >= 1 gives the same N*, only the number of tests changes).
    a : array_like
        Bandwidth of each state's plant [rad/s], > 0.
    w_max : array_like
        Saturation of each state's plant [mm/s], > 0.
    sample_time : float
        Sampling period T [s].
    n_max : int
        Largest N tried [samples].

    Returns
    -------
    ndarray of int64
        N* [samples] (0 at the origin, -1 where N* > n_max), flattened order.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> p = paper_config().plant
    >>> one = zonotope_steps([5.0], [0.0], [1], p).steps
    >>> each = zonotope_steps_each([5.0, 5.0], [0.0, 0.0], [1, 1], [p.a, 2 * p.a], p.w_max, p.T)
    >>> bool(each[0] == one[0]), bool(each[1] < each[0])
    (True, True)
    """
    x1, x2, n0, a, w = np.broadcast_arrays(
        np.asarray(x1, dtype=float),
        np.asarray(x2, dtype=float),
        np.asarray(n0),
        np.asarray(a, dtype=float),
        np.asarray(w_max, dtype=float),
    )
    x1, x2, a, w = x1.ravel(), x2.ravel(), a.ravel(), w.ravel()
    n0 = np.clip(n0.ravel(), 1, n_max + 1).astype(np.int64)
    z1, z2, c = a * x1 / w, x2 / w, a * sample_time

    def inside(idx: NDArray, n: NDArray) -> NDArray[np.bool_]:
        return _contains_each(z1[idx], z2[idx], n, c[idx])

    return _bracket(x1, x2, n0, n_max, inside)[0]
