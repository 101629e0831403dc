"""Minimum-time optimal control problems solved with CasADi and IPOPT.

Two independent numerical references for the closed form of
:mod:`ptoverify.model.mintime` (DESIGN.md, reference 2):

* :class:`TwoPhaseOCP` -- the input is fixed at -s w_max, then +s w_max; the
  phase durations t1, t2 >= 0 are the only variables and the state is exact
  inside each phase (the flow of eq. 7 as a CasADi expression).  The side s
  comes from the sign of the switching function (eqs. 9, 11) by default, or,
  with ``side="both"``, from solving both sides and keeping the converged,
  faster one.
* :class:`CollocationOCP` -- single-phase direct collocation (Radau, degree 3)
  over N intervals with a free final time, a piecewise-constant input
  |u| <= w_max per interval, and a valid lower bound on t_f.

Both problems are written in the dimensionless variables of eq. (1)::

    z1 = a x1 / w_max,   z2 = x2 / w_max,   v = u / w_max,   tau = a t
    dz1/dtau = z2,       dz2/dtau = -z2 + v,  |v| <= 1

so that one NLP (one ``nlpsol`` and one set of CasADi functions) serves every
plant and every state: the state enters as a parameter, the plant only through
the scaling.  The solvers are built once per process and per option set
(memoized with :func:`ptoverify.model.memo.memo`).  The two-phase solver starts from
its previous solution (warm; the 2x2 system has one solution, so the result
does not depend on the start); collocation starts cold by default (see
:class:`CollocationOCP`) so that a result does not depend on call order.

A solve that IPOPT does not finish with ``Solve_Succeeded`` returns
``success=False`` and the IPOPT status in ``status``; such a number is
unverified and must never be used as a reference.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.curves import switching_function
from ptoverify.model.memo import memo

__all__ = [
    "OCPResult",
    "TwoPhaseOCP",
    "CollocationOCP",
    "ConvergenceStudy",
    "convergence_study",
    "resimulate",
]

_IPOPT_QUIET = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes"}


@dataclass(frozen=True)
class OCPResult:
    """Result of one minimum-time OCP solve.

    Attributes
    ----------
    t_f : float
        Final (minimum) time [s]; NaN when the solver failed.
    t_switch : float
        Switch time [s] (two-phase: the first phase's duration; collocation:
        the switch located inside the interval whose input is fractional).
    status : str
        IPOPT return status (``"Solve_Succeeded"``), or ``"origin"`` for the
        trivial solve at the origin.
    success : bool
        True only when IPOPT converged to its tolerance.
    iterations : int
        IPOPT iterations.
    side : float
        +1 when the first arc is u = -w_max, -1 when it is +w_max, 0 at the origin.
    solve_time_s : float
        Wall time of the solve call [s].
    t : ndarray or None
        Collocation: the interval boundaries, shape (N + 1,) [s].
    u : ndarray or None
        Collocation: the input on each interval, shape (N,) [mm/s].
    resim_end : tuple of float or None
        Collocation: the state [mm], [mm/s] reached when ``u`` is applied to the
        exact plant (eq. 7) from the initial state.
    resim_error : float
        Collocation: distance of ``resim_end`` from the origin,
        hypot(x1, x2 / a) [mm]; NaN for the two-phase solver (exact flow).
    """

    t_f: float
    t_switch: float
    status: str
    success: bool
    iterations: int
    side: float
    solve_time_s: float = 0.0
    t: NDArray[np.float64] | None = field(default=None, repr=False)
    u: NDArray[np.float64] | None = field(default=None, repr=False)
    resim_end: tuple[float, float] | None = None
    resim_error: float = math.nan


def _check_state(x1: float, x2: float) -> tuple[float, float]:
    x1, x2 = float(x1), float(x2)
    if not (math.isfinite(x1) and math.isfinite(x2)):
        raise InputError(f"state ({x1}, {x2}) is not finite")
    return x1, x2


def _origin_result() -> OCPResult:
    return OCPResult(
        t_f=0.0,
        t_switch=0.0,
        status="origin",
        success=True,
        iterations=0,
        side=0.0,
        t=np.zeros(1),
        u=np.zeros(0),
        resim_end=(0.0, 0.0),
        resim_error=0.0,
    )


def _stats(solver: ca.Function) -> tuple[str, bool, int]:
    st = solver.stats()
    status = str(st.get("return_status", "unknown"))
    return status, status == "Solve_Succeeded", int(st.get("iter_count", -1))


def _scaled_flow(z1, z2, v, tau):
    """Exact dimensionless flow of eq. (7) under constant v for time tau."""
    g = -ca.expm1(-tau)  # 1 - e^{-tau}
    return z1 + v * tau + (z2 - v) * g, z2 - (z2 - v) * g


def _tau_lower_bound(z1: float, z2: float) -> float:
    """Return a valid lower bound on a t_f (dimensionless); see :class:`CollocationOCP`."""
    return max(abs(z1) / max(abs(z2), 1.0), math.log1p(abs(z2)), 1e-9)


# ---------------------------------------------------------------- two-phase
@memo(maxsize=None)
def _two_phase_solver(max_iter: int, tol: float) -> ca.Function:
    """Build the two-phase NLP once: variables (tau1, tau2), parameters (z1, z2, s, scale).

    The end-state constraints are divided by ``scale`` = 1 + |z1| + |z2| so that
    the tolerance is relative to the size of the state (round-off grows with it).
    """
    w = ca.SX.sym("tau", 2)
    p = ca.SX.sym("p", 4)
    z1, z2, s = p[0], p[1], p[2]
    y1, y2 = _scaled_flow(z1, z2, -s, w[0])
    y1, y2 = _scaled_flow(y1, y2, s, w[1])
    nlp = {"x": w, "p": p, "f": w[0] + w[1], "g": ca.vertcat(y1, y2) / p[3]}
    opts = {
        **_IPOPT_QUIET,
        "ipopt.max_iter": max_iter,
        "ipopt.tol": tol,
        "ipopt.constr_viol_tol": tol,
        "ipopt.mu_strategy": "adaptive",
        "ipopt.bound_relax_factor": 0.0,
    }
    return ca.nlpsol("two_phase", "ipopt", nlp, opts)


class TwoPhaseOCP:
    """Two-phase minimum-time OCP with exact arcs (CasADi + IPOPT).

    The input is -s w_max for t1, then +s w_max for t2; minimize t1 + t2
    subject to reaching the origin, t1, t2 >= 0.  The state after each arc is
    the exact flow of eq. (7).

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).
    side : {"switching", "both"}
        ``"switching"``: s = sign of the switching function (eqs. 9, 11), one
        solve, and the other side only if that one fails (a state within
        round-off of a curve); ``"both"``: solve s = +1 and s = -1 and keep the
        converged one with the smaller t_f (the wrong side is infeasible).
    max_iter : int
        IPOPT iteration cap (1 forces a failure, for tests).
    tol : float
        IPOPT tolerance on the dimensionless KKT conditions and constraints.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> res = TwoPhaseOCP(paper_config().plant).solve(5.0, 0.0)
    >>> res.success, 0.02 < res.t_f < 0.03
    (True, True)
    """

    def __init__(
        self, plant: Plant, side: str = "switching", max_iter: int = 100, tol: float = 1e-13
    ):
        if side not in ("switching", "both"):
            raise InputError(f"side must be 'switching' or 'both', got {side!r}")
        self.plant = plant
        self.side = side
        self._solver = _two_phase_solver(int(max_iter), float(tol))
        self._warm: dict[float, tuple[NDArray, NDArray]] = {}

    def _guess(self, z1: float, z2: float, s: float) -> NDArray[np.float64]:
        """Return initial durations: the previous solution, else a rough estimate."""
        if s in self._warm:
            return self._warm[s][0]
        # the valid lower bound of CollocationOCP for the first arc, a unit second arc;
        # independent of the closed form
        return np.array([1.0 + _tau_lower_bound(z1, z2), 1.0])

    def _solve_side(self, z1: float, z2: float, s: float) -> tuple[NDArray, str, bool, int]:
        x0 = self._guess(z1, z2, s)
        p = [z1, z2, s, 1.0 + abs(z1) + abs(z2)]
        sol = self._solver(x0=x0, p=p, lbx=0.0, ubx=np.inf, lbg=0.0, ubg=0.0)
        status, ok, it = _stats(self._solver)
        tau = np.asarray(sol["x"]).ravel()
        if ok:
            self._warm[s] = (tau, np.asarray(sol["lam_g"]).ravel())
        return tau, status, ok, it

    def solve(self, x1: float, x2: float) -> OCPResult:
        """Solve from the state (x1 [mm], x2 [mm/s]).

        Parameters
        ----------
        x1, x2 : float
            Initial position [mm] and velocity [mm/s].

        Returns
        -------
        OCPResult
            t_f and t_switch in seconds; ``success`` False when IPOPT failed.
        """
        x1, x2 = _check_state(x1, x2)
        if x1 == 0.0 and x2 == 0.0:
            return _origin_result()
        a, w = self.plant.a, self.plant.w_max
        z1, z2 = a * x1 / w, x2 / w
        start = time.perf_counter()
        sigma = float(switching_function(x1, x2, a, w))
        first = 1.0 if sigma > 0 or (sigma == 0 and x2 < 0) else -1.0
        sides = [first, -first]
        best = None
        iterations = 0
        statuses = []
        for s in sides:
            if self.side == "switching" and best is not None:
                break  # the other side only if the first one failed
            tau, status, ok, it = self._solve_side(z1, z2, s)
            iterations += it
            statuses.append(status)
            if ok and (best is None or tau.sum() < best[0].sum()):
                best = (tau, s, status)
        elapsed = time.perf_counter() - start
        if best is None:
            return OCPResult(
                t_f=math.nan,
                t_switch=math.nan,
                status=" / ".join(statuses),
                success=False,
                iterations=iterations,
                side=sides[0],
                solve_time_s=elapsed,
            )
        tau, s, status = best
        return OCPResult(
            t_f=float(tau.sum() / a),
            t_switch=float(tau[0] / a),
            status=status,
            success=True,
            iterations=iterations,
            side=s,
            solve_time_s=elapsed,
        )


# ---------------------------------------------------------------- collocation
@memo(maxsize=None)
def _collocation_solver(
    intervals: int, degree: int, max_iter: int, tol: float, control: str
) -> ca.Function:
    """Build the Radau collocation NLP once per (N, degree, options).

    Decision vector: [tau_f, v_0..v_{N-1}, Z (2 x (N (degree + 1) + 1)) column-major];
    parameters: the initial state (z1, z2).
    """
    n = intervals
    roots = [0.0, *ca.collocation_points(degree, "radau")]
    C = np.zeros((degree + 1, degree + 1))  # C[r, j]: d/ds of Lagrange poly r at root j
    D = np.zeros(degree + 1)  # D[r]: Lagrange poly r at s = 1
    for r in range(degree + 1):
        coef = np.poly1d([1.0])
        for j in range(degree + 1):
            if j != r:
                coef *= np.poly1d([1.0, -roots[j]]) / (roots[r] - roots[j])
        D[r] = coef(1.0)
        dcoef = np.polyder(coef)
        C[r, :] = [dcoef(t) for t in roots]

    tau_f = ca.MX.sym("tau_f")
    nu = degree if control == "points" else 1
    v = ca.MX.sym("v", n * nu)
    Z = ca.MX.sym("Z", 2, n * (degree + 1) + 1)
    p = ca.MX.sym("p", 2)
    h = 1.0 / n
    # one interval as an SX function, mapped over the grid (small, fast graph)
    zs = ca.SX.sym("zs", 2, degree + 1)
    vs = ca.SX.sym("vs", nu)
    ts = ca.SX.sym("ts")
    res = []
    for j in range(1, degree + 1):
        zp = ca.mtimes(zs, C[:, j])
        f = ca.vertcat(zs[1, j], -zs[1, j] + vs[j - 1 if nu > 1 else 0])
        res.append(zp - h * ts * f)
    end = ca.mtimes(zs, D)
    interval = ca.Function("interval", [zs, vs, ts], [ca.vertcat(*res), end])
    imap = interval.map(n)
    # the n blocks of degree + 1 columns side by side, and the first column of each
    # next block (the last: the end point): two slices, O(1) graph nodes
    Zk = Z[:, : n * (degree + 1)]
    coll, ends = imap(Zk, ca.reshape(v, nu, n), ca.repmat(tau_f, 1, n))
    starts = Z[:, degree + 1 :: degree + 1]
    g = ca.vertcat(Z[:, 0] - p, ca.vec(coll), ca.vec(ends - starts), Z[:, -1])
    x = ca.vertcat(tau_f, v, ca.vec(Z))
    nlp = {"x": x, "p": p, "f": tau_f, "g": g}
    opts = {
        **_IPOPT_QUIET,
        "ipopt.max_iter": max_iter,
        "ipopt.tol": tol,
        "ipopt.mu_strategy": "adaptive",
        "ipopt.bound_relax_factor": 0.0,
        # not expanded to SX: the graph is one mapped SX interval function, and
        # expanding it costs more at construction (0.4 s for the seven N of the
        # report's convergence study) than it saves in evaluations; the iterates
        # were the same to the last bit on the report's states (checked when changed)
        "expand": False,
    }
    return ca.nlpsol(f"radau{n}", "ipopt", nlp, opts)


def resimulate(t: NDArray, u: NDArray, x1: float, x2: float, a: float) -> tuple[float, float]:
    """Apply a piecewise-constant input to the exact plant (eq. 7).

    Parameters
    ----------
    t : ndarray, shape (N + 1,)
        Interval boundaries [s].
    u : ndarray, shape (N,)
        Input on each interval [mm/s].
    x1, x2 : float
        Initial state [mm], [mm/s].
    a : float
        Bandwidth [rad/s].

    Returns
    -------
    x1, x2 : float
        The state at t[-1].
    """
    dts = np.diff(t)
    # eq. (7) interval by interval, as :func:`ptoverify.model.plant.flow` computes it (the
    # same operations in the same order, on Python floats: the same roundings),
    # with 1 - e^{-a dt} for all intervals at once
    gs = (-np.expm1(-a * dts)).tolist()
    x1, x2 = float(x1), float(x2)
    for dt, uk, g in zip(dts.tolist(), np.asarray(u, dtype=float).tolist(), gs, strict=True):
        dv = x2 - uk
        x1, x2 = x1 + uk * dt + dv * g / a, x2 - dv * g
    return x1, x2


class CollocationOCP:
    """Single-phase Radau collocation of the minimum-time OCP.

    Radau IIA collocation of the given degree on N equal intervals of the
    scaled time s = t / t_f in [0, 1], free t_f, one input value per interval
    with |u| <= w_max, end state at the origin, and a lower bound on t_f that
    every trajectory satisfies (|x2| never exceeds max(|x2(0)|, w_max), and the
    velocity cannot reach 0 sooner than under -sign(x2) w_max)::

        t_f >= max(|x1| / max(|x2|, w_max), ln(1 + |x2| / w_max) / a).

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).
    intervals : int
        Number of collocation intervals N.
    degree : int
        Collocation degree (Radau points per interval).
    max_iter : int
        IPOPT iteration cap.
    tol : float
        IPOPT tolerance.
    warm_start : bool
        Start each solve from the previous converged solution (primal and
        dual) instead of the cold guess (a straight line to the origin, zero
        input).  Off by default: on random states it saved no time (median
        13.5 vs 11.5 iterations, N = 100) and it makes a result depend on the
        order of the calls; with it, a single-arc state after a two-arc one took
        239 iterations against 97 cold.
    """

    def __init__(
        self,
        plant: Plant,
        intervals: int = 100,
        degree: int = 3,
        max_iter: int = 500,
        tol: float = 1e-10,
        warm_start: bool = False,
        control: str = "points",
    ):
        if intervals < 1:
            raise InputError(f"intervals must be positive, got {intervals}")
        if control not in ("points", "interval"):
            raise InputError(f"control must be 'points' or 'interval', got {control!r}")
        self.plant = plant
        self.intervals = int(intervals)
        self.degree = int(degree)
        self.control = control
        self.warm_start = warm_start
        self._solver = _collocation_solver(
            self.intervals, self.degree, int(max_iter), float(tol), control
        )
        self._prev: dict[str, NDArray] | None = None
        n, d = self.intervals, self.degree
        self._nu = n * d if control == "points" else n
        self._nz = n * (d + 1) + 1
        self._nx = 1 + self._nu + 2 * self._nz
        roots = np.array(ca.collocation_points(d, "radau"))
        if control == "points":  # u_kj held for b_j h: same impulse as the quadrature
            edges = np.cumsum(radau_weights(roots))
            self._grid = (np.arange(n)[:, None] + edges[None, :]).ravel() / n
            self._grid = np.concatenate([[0.0], self._grid])
        else:
            self._grid = np.linspace(0.0, 1.0, n + 1)

    def _cold_guess(self, z1: float, z2: float, tau_lb: float) -> NDArray[np.float64]:
        """Straight line from the state to the origin, zero input, t_f a rough estimate."""
        s = np.linspace(1.0, 0.0, self._nz)
        Z = np.vstack([z1 * s, z2 * s])
        tau = max(2.0 * tau_lb, 1.0 + math.sqrt(abs(z1)) + math.log1p(abs(z2)))
        return np.concatenate([[tau], np.zeros(self._nu), Z.ravel(order="F")])

    def solve(self, x1: float, x2: float) -> OCPResult:
        """Solve from the state (x1 [mm], x2 [mm/s]).

        Parameters
        ----------
        x1, x2 : float
            Initial position [mm] and velocity [mm/s].

        Returns
        -------
        OCPResult
            t_f [s], the input profile (t, u), the re-simulation on the exact
            plant; ``success`` False when IPOPT failed.
        """
        x1, x2 = _check_state(x1, x2)
        if x1 == 0.0 and x2 == 0.0:
            return _origin_result()
        a, w = self.plant.a, self.plant.w_max
        z1, z2 = a * x1 / w, x2 / w
        tau_lb = _tau_lower_bound(z1, z2)
        lbx = np.full(self._nx, -np.inf)
        ubx = np.full(self._nx, np.inf)
        lbx[0] = tau_lb
        lbx[1 : 1 + self._nu] = -1.0
        ubx[1 : 1 + self._nu] = 1.0
        kwargs = {}
        if self.warm_start and self._prev is not None:
            x0 = self._prev["x"].copy()
            x0[0] = max(x0[0], 1.05 * tau_lb)
            kwargs = {"lam_x0": self._prev["lam_x"], "lam_g0": self._prev["lam_g"]}
        else:
            x0 = self._cold_guess(z1, z2, tau_lb)
        start = time.perf_counter()
        sol = self._solver(x0=x0, p=[z1, z2], lbx=lbx, ubx=ubx, lbg=0.0, ubg=0.0, **kwargs)
        elapsed = time.perf_counter() - start
        status, ok, it = _stats(self._solver)
        xs = np.asarray(sol["x"]).ravel()
        if ok:
            self._prev = {
                "x": xs,
                "lam_x": np.asarray(sol["lam_x"]).ravel(),
                "lam_g": np.asarray(sol["lam_g"]).ravel(),
            }
        t_f = xs[0] / a
        u = w * xs[1 : 1 + self._nu]
        t = t_f * self._grid
        end = resimulate(t, u, x1, x2, a)
        side, t_sw = _locate_switch(t, u / w)
        return OCPResult(
            t_f=float(t_f) if ok else math.nan,
            t_switch=t_sw if ok else math.nan,
            status=status,
            success=ok,
            iterations=it,
            side=side,
            solve_time_s=elapsed,
            t=t,
            u=u,
            resim_end=end,
            resim_error=float(math.hypot(end[0], end[1] / a)),
        )


def radau_weights(roots: NDArray) -> NDArray[np.float64]:
    """Quadrature weights b_j = int_0^1 l_j(s) ds of the collocation points (Radau IIA b).

    Parameters
    ----------
    roots : ndarray
        Collocation points in (0, 1].

    Returns
    -------
    ndarray
        Weights, summing to 1.
    """
    b = np.zeros(len(roots))
    for j, rj in enumerate(roots):
        poly = np.poly1d([1.0])
        for m, rm in enumerate(roots):
            if m != j:
                poly *= np.poly1d([1.0, -rm]) / (rj - rm)
        b[j] = np.polyint(poly)(1.0)
    return b


def _locate_switch(t: NDArray, v: NDArray) -> tuple[float, float]:
    """Side and switch time of a piecewise-constant bang-bang-like input v (|v| <= 1).

    The switch lies in the first interval whose input is not the first arc's
    level; a fractional value v = s (1 - 2 f) there is read as the fraction f
    of the interval spent on the first arc (equal impulse).
    """
    s = -math.copysign(1.0, v[0]) if v[0] != 0 else 1.0
    away = np.nonzero(s * v > -1.0 + 1e-6)[0]
    if away.size == 0:
        return s, float(t[-1])
    k = int(away[0])
    f = float(np.clip((1.0 - s * v[k]) / 2.0, 0.0, 1.0))
    return s, float(t[k] + f * (t[k + 1] - t[k]))


# ---------------------------------------------------------------- convergence
@dataclass(frozen=True)
class ConvergenceStudy:
    """Collocation t_f error against the number of intervals.

    Attributes
    ----------
    intervals : ndarray, shape (M,)
        The interval counts N.
    states : ndarray, shape (S, 2)
        Initial states [mm], [mm/s].
    t_f_exact : ndarray, shape (S,)
        Closed-form minimum times [s].
    t_switch_exact : ndarray, shape (S,)
        Closed-form switch times [s].
    t_f : ndarray, shape (S, M)
        Collocation t_f [s] (NaN where IPOPT failed).
    rel_error : ndarray, shape (S, M)
        |t_f - t_f_exact| / t_f_exact.
    resim_error : ndarray, shape (S, M)
        Re-simulation distance from the origin [mm].
    order_per_state : ndarray, shape (S,)
        Least-squares slope of -log(rel_error) against log(N), per state.
    order : float
        The same slope pooled over all states (common slope, per-state offsets).
    success : ndarray of bool, shape (S, M)
        IPOPT converged.
    profiles : dict
        (state index, N) -> (t [s], u [mm/s]) of the solves, for plotting.
    results : dict
        (state index, N) -> the :class:`OCPResult` of each (cold) solve, e.g. for
        ``verified_mintime(..., collocation=...)`` at the same N.
    """

    intervals: NDArray[np.int64]
    states: NDArray[np.float64]
    t_f_exact: NDArray[np.float64]
    t_switch_exact: NDArray[np.float64]
    t_f: NDArray[np.float64]
    rel_error: NDArray[np.float64]
    resim_error: NDArray[np.float64]
    order_per_state: NDArray[np.float64]
    order: float
    success: NDArray[np.bool_]
    profiles: dict = field(default_factory=dict, repr=False)
    results: dict = field(default_factory=dict, repr=False)


def _slope(logn: NDArray, loge: NDArray) -> float:
    ok = np.isfinite(loge)
    if ok.sum() < 2:
        return math.nan
    return float(-np.polyfit(logn[ok], loge[ok], 1)[0])


def convergence_study(
    plant: Plant,
    states,
    intervals=(10, 20, 40, 80, 100, 200, 400),
    degree: int = 3,
    control: str = "points",
) -> ConvergenceStudy:
    """Collocation t_f error vs N and the observed order of convergence.

    Parameters
    ----------
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).
    states : array_like, shape (S, 2)
        Initial states [mm], [mm/s] (not the origin).
    intervals : sequence of int
        Interval counts N.
    degree : int
        Radau degree.

    Returns
    -------
    ConvergenceStudy
        Errors, orders and the input profiles.
    """
    from ptoverify.model.mintime import min_time

    states = np.atleast_2d(np.asarray(states, dtype=float))
    ns = np.asarray(intervals, dtype=int)
    mt = min_time(states[:, 0], states[:, 1], plant)
    exact = np.asarray(mt.t_f, dtype=float)
    tf = np.full((len(states), len(ns)), np.nan)
    rs = np.full_like(tf, np.nan)
    ok = np.zeros(tf.shape, dtype=bool)
    profiles, results = {}, {}
    for j, n in enumerate(ns):
        ocp = CollocationOCP(
            plant, intervals=int(n), degree=degree, warm_start=False, control=control
        )
        for i, (x1, x2) in enumerate(states):
            r = ocp.solve(x1, x2)
            tf[i, j], rs[i, j], ok[i, j] = r.t_f, r.resim_error, r.success
            profiles[(i, int(n))] = (r.t, r.u)
            results[(i, int(n))] = r
    rel = np.abs(tf - exact[:, None]) / exact[:, None]
    with np.errstate(divide="ignore"):
        loge = np.log(np.where(rel > 0, rel, np.nan))
    logn = np.log(ns.astype(float))
    per_state = np.array([_slope(logn, row) for row in loge])
    # pooled: remove each state's mean, then one slope
    good = np.isfinite(loge)
    cent_e = loge - np.nanmean(np.where(good, loge, np.nan), axis=1, keepdims=True)
    cent_n = np.where(good, logn[None, :], np.nan)
    cent_n = cent_n - np.nanmean(cent_n, axis=1, keepdims=True)
    m = np.isfinite(cent_e) & np.isfinite(cent_n)
    spread = float(cent_n[m] @ cent_n[m])  # 0 with a single N: no slope
    order = float(-(cent_e[m] @ cent_n[m]) / spread) if spread > 0 else math.nan
    return ConvergenceStudy(
        intervals=ns,
        states=states,
        t_f_exact=exact,
        t_switch_exact=np.asarray(mt.t_switch, dtype=float),
        t_f=tf,
        rel_error=rel,
        resim_error=rs,
        order_per_state=per_state,
        order=order,
        success=ok,
        profiles=profiles,
        results=results,
    )
