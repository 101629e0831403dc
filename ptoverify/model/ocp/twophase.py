"""The two-phase minimum-time problem (one switch), solved by IPOPT through CasADi."""

from __future__ import annotations

import math
import time

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.curves import switching_function
from ptoverify.model.memo import memo

from .types import _IPOPT_QUIET, OCPResult, _check_state, _origin_result, _stats


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
