"""Minimum time to the origin: closed form (continuous time).

The time-optimal input of eq. (1) is bang-bang with at most one switch (the
system is normal with real eigenvalues 0 and -a).  Right of the switching
curve (sigma > 0) it is -w_max until the state meets l1, then +w_max to the
origin; left of it the mirror image.  Writing the problem in the frame
y = s x (s = +1 right of the curve, -1 left), eliminating the first arc's
duration between eq. (10) and l1 (eq. 9) gives the switch velocity q on l1::

    w^2 - q^2 = w (w + y2) exp(-(a y1 + y2) / w),     q <= 0

and the two arc durations::

    t2 = ln(1 - q/w) / a                         (second arc, along l1)
    t1 = [ln(1 - q/w) + (a y1 + y2) / w] / a     (first arc, eq. 7 eliminated)

For w + y2 > 0 the right side is evaluated as w^2 (1 - e^{-g}) with
g = a y1 / w + h(y2 / w), h(r) = r - ln(1 + r), without cancellation near the
origin; for y2 <= -w (a state faster than saturation) the first form has no
cancellation.  Both hold for any |x2|, including |x2| >= w_max.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.curves import h
from ptoverify.model.reach import DiscreteLimit

__all__ = [
    "MinTime",
    "min_time",
    "DiscreteMinTime",
    "ZOHReach",
    "discrete_min_steps",
    "discrete_min_steps_batch",
    "DiscreteLimit",
    "TABLE_COLUMNS",
    "read_states",
    "batch_table",
]


@dataclass(frozen=True)
class MinTime:
    """Closed-form minimum time and its switch, per state (arrays).

    Attributes
    ----------
    t_f : ndarray
        Minimum time to the origin [s].
    t_switch : ndarray
        Duration of the first arc, i.e. the time of the switch [s] (0 on a curve).
    side : ndarray
        +1 where the first arc is u = -w_max (right of the curve), -1 where it is
        u = +w_max; 0 at the origin.
    q : ndarray
        Velocity at the switch [mm/s] (on l1 for side +1, on l2 for side -1).
    """

    t_f: NDArray[np.float64]
    t_switch: NDArray[np.float64]
    side: NDArray[np.float64]
    q: NDArray[np.float64]


def min_time(x1: ArrayLike, x2: ArrayLike, plant: Plant) -> MinTime:
    """Closed-form minimum time and switch time from any state.

    Parameters
    ----------
    x1, x2 : array_like
        Initial position [mm] and velocity [mm/s]; any finite values, broadcast.
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).

    Returns
    -------
    MinTime
        Arrays of the broadcast shape.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> mt = min_time(5.0, 0.0, paper_config().plant)
    >>> 0.02 < float(mt.t_f) < 0.03, float(mt.t_switch) < float(mt.t_f)
    (True, True)
    """
    x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
    t_f, t_switch, side, q = (
        v.reshape(x1.shape) for v in _min_time(x1.ravel(), x2.ravel(), plant.a, plant.w_max)
    )
    return MinTime(t_f=t_f, t_switch=t_switch, side=side, q=q)


def _min_time(x1: NDArray, x2: NDArray, a: float, w: float) -> tuple[NDArray, ...]:
    """:func:`min_time` on 1-D float arrays of one shape: (t_f, t_switch, side, q)."""
    sigma = a * x1 + np.sign(x2) * w * h(np.abs(x2) / w)  # switching_function, eqs. (9), (11)
    pos = sigma > 0
    pos |= ~(pos | (sigma < 0)) & (x2 < 0)  # on the curve: the side of x2
    side = np.where(pos, 1.0, -1.0)
    y1, y2 = side * x1, side * x2
    rho = y2 / w
    fast = rho <= -1.0
    with np.errstate(all="ignore"):
        g = a * y1 / w + h(np.where(fast, 0.0, rho))
        q2 = -(w * w) * np.expm1(-g)
        fi = np.flatnonzero(fast)  # y2 <= -w: the form without cancellation
        if fi.size:
            y1f, y2f = y1[fi], y2[fi]
            q2[fi] = w * w - w * (w + y2f) * np.exp(-(a * y1f + y2f) / w)
    q = -np.sqrt(np.maximum(q2, 0.0))
    lq = np.log1p(-q / w)
    t2 = lq / a
    t1 = np.maximum((lq + (a * y1 + y2) / w) / a, 0.0)
    t_f, q = t1 + t2, side * q
    origin = np.flatnonzero((x1 == 0) & (x2 == 0))
    if origin.size:
        for v in (t_f, t1, side, q):
            v[origin] = 0.0
    return t_f, t1, side, q


# ---------------------------------------------------------------- discrete-time limit
@dataclass(frozen=True)
class DiscreteMinTime:
    """Fewest ZOH samples to the origin and an input sequence that does it.

    Attributes
    ----------
    steps : int
        N*, the fewest samples after which the sampled plant is exactly at the
        origin with |u_k| <= w_max (0 at the origin; -1 when not found).
    time_s : float
        N* T [s] (NaN when not found).
    u : ndarray, shape (N*,)
        An input sequence [mm/s] that reaches the origin in N* samples.
    status : str
        ``"optimal"`` (N* found, N* - 1 infeasible, sequence verified by exact
        simulation), ``"origin"``, or a failure: ``"not_found"`` (no N <=
        n_max), ``"lp_failed: ..."``, ``"unverified: ..."``,
        ``"below_continuous_bound"`` (N* T < t_f*, which theory excludes).
    end : tuple of float
        State [mm], [mm/s] reached by simulating ``u`` on the exact plant.
    t_f_continuous : float
        The closed-form continuous minimum time t_f* [s] the search started from.
    lp_solves : int
        Number of linear programs solved.
    below : tuple of (int, str) or None
        (N, status) of the LP the search solved at N = N* - 1 (``"infeasible"``,
        ``"boundary"`` or ``"lp_failed: ..."``), None when it solved none there; a
        check of N* - 1 can read it instead of solving the same LP again.
    """

    steps: int
    time_s: float
    u: NDArray[np.float64]
    status: str
    end: tuple[float, float]
    t_f_continuous: float
    lp_solves: int
    below: tuple[int, str] | None = None

    @property
    def success(self) -> bool:
        """True when N* is established (``"optimal"`` or ``"origin"``)."""
        return self.status in ("optimal", "origin")


_END_TOL_X1 = 1e-9  # mm: required end position error of the verified sequence
_END_TOL_X2 = 1e-6  # mm/s: required end velocity error
_U_TOL = 1e-9  # relative overshoot of |u| <= w_max tolerated after polishing


class ZOHReach:
    """Reachability generators Ad^m Bd of the ZOH plant, reused across states.

    x_N = Ad^N x0 + sum_k Ad^(N-1-k) Bd u_k, with (eq. 15 sampled, a = bandwidth)
    Ad^m = [[1, (1 - e^{-a T m}) / a], [0, e^{-a T m}]], written in the
    dimensionless rows (a x1 / w_max, x2 / w_max) and inputs v = u / w_max so
    that every linear program has two equality rows and unit bounds.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], sample_time T [s]).
    """

    def __init__(self, plant: Plant):
        from ptoverify.model.plant import zoh_matrices

        self.plant = plant
        _, bd = zoh_matrices(plant.a, plant.sample_time)
        self._bd = bd.ravel()
        self._gen = np.zeros((2, 0))

    def _powers(self, m: NDArray) -> tuple[NDArray, NDArray]:
        """Return (1 - e^{-a T m}) / a and e^{-a T m} for integer m >= 0."""
        at = self.plant.a * self.plant.sample_time
        return -np.expm1(-at * m) / self.plant.a, np.exp(-at * m)

    def generators(self, n: int) -> NDArray[np.float64]:
        """Dimensionless columns for u_0..u_{n-1}, shape (2, n)."""
        if self._gen.shape[1] < n:
            m = np.arange(max(n, 2 * self._gen.shape[1]), dtype=float)
            p12, p22 = self._powers(m)
            b1, b2 = self._bd
            a = self.plant.a
            self._gen = np.vstack([a * (b1 + p12 * b2), p22 * b2])  # diag(a/w, 1/w) Ad^m Bd w
        return self._gen[:, n - 1 :: -1] if n > 0 else np.zeros((2, 0))

    def free(self, x1: float, x2: float, n: int) -> NDArray[np.float64]:
        """Dimensionless Ad^n x0."""
        p12, p22 = self._powers(np.float64(n))
        a, w = self.plant.a, self.plant.w_max
        return np.array([a / w * (x1 + p12 * x2), p22 * x2 / w])

    def feasible(self, x1: float, x2: float, n: int) -> tuple[bool, NDArray | None, str]:
        """Whether n samples reach the origin with |u| <= w_max, by an LP (HiGHS).

        Parameters
        ----------
        x1, x2 : float
            Initial state [mm], [mm/s].
        n : int
            Number of samples, n >= 1.

        Returns
        -------
        feasible : bool
        u : ndarray or None
            A polished input sequence [mm/s] (exact to round-off) when feasible.
        status : str
            ``"feasible"``, ``"infeasible"``, ``"boundary"`` (the LP is feasible
            only within its tolerance: treated as infeasible) or ``"lp_failed: ..."``.
        """
        from scipy.optimize import linprog

        A = self.generators(n)
        b = -self.free(x1, x2, n)
        res = linprog(np.zeros(n), A_eq=A, b_eq=b, bounds=(-1.0, 1.0), method="highs-ds")
        if res.status == 2:
            return False, None, "infeasible"
        if res.status != 0:
            return False, None, f"lp_failed: {res.message}"
        v = _polish(A, b, np.asarray(res.x, dtype=float))
        # HiGHS accepts A v = b to an absolute 1e-7: a state that small (or a sequence too
        # short to steer both components) passes its test without reaching the origin.
        # The polished sequence must solve A v = b to round-off (backward error), else
        # this n is feasible only within the LP's tolerance.
        slack = 64 * np.finfo(float).eps * (np.abs(A) @ np.abs(v) + np.abs(b))
        if np.max(np.abs(v)) > 1.0 + _U_TOL or np.any(np.abs(A @ v - b) > slack):
            return False, None, "boundary"
        return True, np.clip(v, -1.0, 1.0) * self.plant.w_max, "feasible"


def _polish(A: NDArray, b: NDArray, v: NDArray) -> NDArray[np.float64]:
    """Solve A v = b to round-off, moving only the inputs not at their bounds."""
    v = v.copy()
    slack = 1.0 - np.abs(v)
    free = np.nonzero(slack > 1e-9)[0]
    if free.size < 2:  # pad with the inputs closest to interior
        free = np.argsort(-slack)[:2]
    v[np.setdiff1d(np.arange(v.size), free)] = np.sign(v[np.setdiff1d(np.arange(v.size), free)])
    for _ in range(3):
        r = b - A @ v
        v[free] += np.linalg.lstsq(A[:, free], r, rcond=None)[0]
    return v


def _simulate_zoh(x1: float, x2: float, u: NDArray, plant: Plant) -> tuple[float, float]:
    from ptoverify.model.plant import flow

    for uk in u:
        x1, x2 = flow(x1, x2, uk, plant.sample_time, plant.a)
    return float(x1), float(x2)


def discrete_min_steps(
    x1: float,
    x2: float,
    plant: Plant,
    n_max: int = 20000,
    reach: ZOHReach | None = None,
    confirm: bool = True,
) -> DiscreteMinTime:
    """Fewest ZOH samples N* to reach the origin exactly, |u_k| <= w_max.

    Linear-programming feasibility (scipy HiGHS, two equality rows from the
    reachability matrix) with exponential search and bisection over N.  No
    sampled input beats the continuous optimum, N* T >= t_f*, so the search
    starts at ceil(t_f* / T); feasibility is monotone in N (u = 0 holds the
    origin).  The returned sequence is polished to round-off and verified by
    simulating the exact plant (eq. 7): |x1| <= 1e-9 mm, |x2| <= 1e-6 mm/s.

    Parameters
    ----------
    x1, x2 : float
        Initial position [mm] and velocity [mm/s]; any finite values.
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], sample_time T [s]).
    n_max : int
        Largest N tried.
    reach : ZOHReach, optional
        Precomputed generators of this plant (reuse across states).
    confirm : bool
        Also solve the LP at N* - 1 and check that it is infeasible.

    Returns
    -------
    DiscreteMinTime
        N*, N* T [s], the sequence and the status.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> plant = paper_config().plant
    >>> d = discrete_min_steps(5.0, 0.0, plant)
    >>> d.status, d.time_s >= float(min_time(5.0, 0.0, plant).t_f)
    ('optimal', True)
    """
    x1, x2 = float(x1), float(x2)
    if not (math.isfinite(x1) and math.isfinite(x2)):
        raise InputError(f"state ({x1}, {x2}) is not finite")
    tf = float(min_time(x1, x2, plant).t_f)
    if x1 == 0.0 and x2 == 0.0:
        return DiscreteMinTime(0, 0.0, np.zeros(0), "origin", (0.0, 0.0), 0.0, 0)
    reach = reach if reach is not None and reach.plant == plant else ZOHReach(plant)
    n0 = max(1, math.ceil(tf / plant.sample_time - 1e-9))
    solves = 0

    def fail(status: str) -> DiscreteMinTime:
        return DiscreteMinTime(-1, math.nan, np.zeros(0), status, (x1, x2), tf, solves)

    if n0 > n_max:
        return fail(f"not_found: N* > n_max = {n_max}")
    lo, hi, u_hi, step = n0 - 1, n0, None, 1
    lo_status = None  # LP status at lo, None while lo is only assumed infeasible
    while True:  # exponential search for a feasible N
        ok, u, st = reach.feasible(x1, x2, hi)
        solves += 1
        if st.startswith("lp_failed"):
            return fail(st)
        if ok:
            u_hi = u
            break
        lo, hi, step, lo_status = hi, hi + step, 2 * step, st
        if hi > n_max:
            return fail(f"not_found: N* > n_max = {n_max}")
    while hi - lo > 1:  # bisection: lo infeasible, hi feasible
        mid = (lo + hi) // 2
        ok, u, st = reach.feasible(x1, x2, mid)
        solves += 1
        if st.startswith("lp_failed"):
            return fail(st)
        if ok:
            hi, u_hi = mid, u
        else:
            lo, lo_status = mid, st
    status = "optimal"
    if confirm and hi == n0 and hi > 1:  # N* - 1 was assumed, not solved: check it
        ok, _, st = reach.feasible(x1, x2, hi - 1)
        solves += 1
        lo_status = "feasible" if ok else st
        if ok:
            status = "below_continuous_bound"
        elif st.startswith("lp_failed"):
            status = st
    end = _simulate_zoh(x1, x2, u_hi, plant)
    if abs(end[0]) > _END_TOL_X1 or abs(end[1]) > _END_TOL_X2:
        status = f"unverified: end state ({end[0]:.3g} mm, {end[1]:.3g} mm/s)"
    below = None if lo_status is None else (hi - 1, lo_status)
    return DiscreteMinTime(hi, hi * plant.sample_time, u_hi, status, end, tf, solves, below)


def discrete_min_steps_batch(
    x1: ArrayLike, x2: ArrayLike, plant: Plant, n_max: int = 20000
) -> DiscreteLimit:
    """N* for many states at once: exact 2-D zonotope membership, vectorized.

    The production path for many states (:mod:`ptoverify.model.reach`: the states
    that reach the origin in N ZOH samples with |u_k| <= w_max form a 2-D
    zonotope, tested facet by facet; N* by exponential search and bisection on
    N from ceil(t_f* / T), per state).  No LP and no input sequence:
    :func:`discrete_min_steps` (linear programs) is its independent reference.
    A state counts as reaching the origin in N samples if it does so with
    |u_k| <= (1 + 1e-9) w_max (:data:`ptoverify.model.reach.MARGIN`, the LP's own
    acceptance rule), so states on a boundary in exact arithmetic are inside.

    Parameters
    ----------
    x1, x2 : array_like
        Initial positions [mm] and velocities [mm/s], finite; broadcast.
    plant : Plant
        The plant (a [rad/s], w_max [mm/s], sample_time T [s]).
    n_max : int
        Largest N tried [samples]; N* = -1 beyond.

    Returns
    -------
    DiscreteLimit
        ``steps`` (N*, int64, -1 where > n_max) and ``time_s`` (N* T [s], NaN
        where not found), of the broadcast shape.

    Raises
    ------
    InputError
        A state that is not finite.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> plant = paper_config().plant
    >>> d = discrete_min_steps_batch([5.0, 0.0], [0.0, 0.0], plant)
    >>> d.steps.tolist() == [discrete_min_steps(5.0, 0.0, plant).steps, 0]
    True
    """
    from dataclasses import replace

    from ptoverify.model.reach import zonotope_steps

    x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
    if not (np.isfinite(x1).all() and np.isfinite(x2).all()):
        raise InputError("a state is not finite")
    shape = x1.shape
    t_f = min_time(x1, x2, plant).t_f
    n0 = np.maximum(np.ceil(t_f.ravel() / plant.sample_time - 1e-9), 1.0)
    n0 = np.minimum(n0, n_max + 1.0).astype(np.int64)  # beyond n_max: not found
    d = zonotope_steps(x1.ravel(), x2.ravel(), n0, plant, n_max)
    return replace(
        d,
        steps=d.steps.reshape(shape),
        time_s=d.time_s.reshape(shape),
        below_bound=d.below_bound.reshape(shape),
    )


# ---------------------------------------------------------------- batch queries
TABLE_COLUMNS = ("x1", "x2", "analytic_s", "switch_time_s", "discrete_steps", "discrete_s")
FAR_FACTOR = 1e3  # states beyond 1000 x the envelope are rejected (as `mintime X1 X2`)


def read_states(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Read initial states from a CSV file whose header names columns x1, x2.

    Other columns are ignored; blank lines are skipped.

    Parameters
    ----------
    path : str or Path
        A regular file.

    Returns
    -------
    x1, x2 : ndarray
        Positions [mm] and velocities [mm/s], one per data row.

    Raises
    ------
    InputError
        Not a regular file, unreadable, empty, no x1/x2 column, no rows, or a
        row with a missing field or a field that is not a finite number (its
        line named).
    """
    from ptoverify.tables import read_columns

    (x1, x2), _ = read_columns(path, ("x1", "x2"), what="states file")
    return x1, x2


def batch_table(path: str | Path, cfg) -> dict[str, NDArray]:
    """``mintime --states``: closed form and exact N* for every state of a CSV.

    No solver: t_f* and the switch time by :func:`min_time`, N* by
    :func:`discrete_min_steps_batch` (zonotopes; N* searched up to 20000
    samples, as the single-state command).

    Parameters
    ----------
    path : str or Path
        CSV with a header naming columns x1 [mm], x2 [mm/s] (:func:`read_states`).
    cfg : Config
        Configuration (its plant).

    Returns
    -------
    dict of str to ndarray
        The columns :data:`TABLE_COLUMNS`: x1 [mm], x2 [mm/s], analytic_s [s],
        switch_time_s [s], discrete_steps (int, -1 where N* > 20000) and
        discrete_s [s] (NaN there).

    Raises
    ------
    InputError
        A bad file or row (:func:`read_states`), or a state beyond 1000 x the
        envelope (|x1| > 1000 position_range or |x2| > 1000 w_max), its line named.
    """
    from ptoverify.tables import read_columns

    plant = cfg.plant
    (x1, x2), lines = read_columns(path, ("x1", "x2"), what="states file")
    far = np.flatnonzero(
        (np.abs(x1) > FAR_FACTOR * plant.position_range) | (np.abs(x2) > FAR_FACTOR * plant.w_max)
    )
    if far.size:
        k = int(far[0])
        raise InputError(
            f"states file '{path}' line {lines[k]}: state ({x1[k]:g}, {x2[k]:g}) is far outside the "
            f"envelope (|x1| <= {FAR_FACTOR * plant.position_range:g} mm, "
            f"|x2| <= {FAR_FACTOR * plant.w_max:g} mm/s accepted)"
        )
    mt = min_time(x1, x2, plant)
    dm = discrete_min_steps_batch(x1, x2, plant)
    return dict(zip(TABLE_COLUMNS, (x1, x2, mt.t_f, mt.t_switch, dm.steps, dm.time_s), strict=True))
