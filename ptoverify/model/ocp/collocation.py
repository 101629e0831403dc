"""The minimum-time problem by Radau direct collocation (IPOPT through CasADi)."""

from __future__ import annotations

import math
import time

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.memo import memo

from .twophase import _tau_lower_bound
from .types import _IPOPT_QUIET, OCPResult, _check_state, _origin_result, _stats, resimulate


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
