"""The minimum-time problem's result type, shared checks, and the exact re-simulation."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ptoverify.errors import InputError

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
