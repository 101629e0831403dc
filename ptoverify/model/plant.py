"""The plant of eq. (1): exact flow under a constant input and ZOH matrices.

x1' = x2, x2' = -a x2 + a u.  Under a constant u the flow is eq. (7)::

    x2(t) = u + (x20 - u) e^{-a t}
    x1(t) = x10 + u t + (x20 - u)(1 - e^{-a t}) / a

evaluated here with ``expm1`` so that it is exact to round-off for small a t.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant

__all__ = ["flow", "step", "zoh_matrices"]


def flow(
    x1: ArrayLike, x2: ArrayLike, u: ArrayLike, t: ArrayLike, a: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Exact state after time t under a constant input, eq. (7).

    Parameters
    ----------
    x1, x2 : array_like
        Initial position [mm] and velocity [mm/s]; broadcast together.
    u : array_like
        Constant input [mm/s].
    t : array_like
        Elapsed time [s], t >= 0.
    a : float
        Bandwidth [rad/s].

    Returns
    -------
    x1, x2 : ndarray
        The state at time t.

    Examples
    --------
    >>> x1, x2 = flow(0.0, 0.0, 300.0, 1e9, 188.5)
    >>> float(x2)
    300.0
    """
    x1, x2, u, t = (np.asarray(v, dtype=float) for v in (x1, x2, u, t))
    g = -np.expm1(-a * t)  # 1 - e^{-a t}
    dv = x2 - u
    return x1 + u * t + dv * g / a, x2 - dv * g


def step(
    x1: ArrayLike, x2: ArrayLike, u: ArrayLike, plant: Plant
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One-sample map of the ZOH plant: hold u for T, eq. (15).

    Parameters
    ----------
    x1, x2 : array_like
        State at the sample [mm], [mm/s].
    u : array_like
        Input held over the sample [mm/s].
    plant : Plant
        The plant (a, T).

    Returns
    -------
    x1, x2 : ndarray
        The state one sample later.
    """
    return flow(x1, x2, u, plant.sample_time, plant.a)


def zoh_matrices(a: ArrayLike, T: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:  # noqa: N803
    """Zero-order-hold matrices Ad, Bd of the sampled plant.

    x[k+1] = Ad x[k] + Bd u[k], exact for u constant over [kT, (k+1)T).

    Parameters
    ----------
    a : float or array_like, shape (n,)
        Bandwidth [rad/s]; an array gives one pair of matrices per value.
    T : float
        Sampling period [s].

    Returns
    -------
    Ad : ndarray, shape (2, 2), or (n, 2, 2) for an array of a
    Bd : ndarray, shape (2, 1), or (n, 2, 1) for an array of a

    Examples
    --------
    >>> Ad, Bd = zoh_matrices(188.5, 0.002)
    >>> Ad.shape, Bd.shape
    ((2, 2), (2, 1))
    >>> zoh_matrices([188.5, 94.2], 0.002)[0].shape
    (2, 2, 2)
    """
    a = np.asarray(a, dtype=float)
    g = -np.expm1(-a * T)  # 1 - e^{-aT}
    one, zero = np.ones_like(a), np.zeros_like(a)
    Ad = np.stack([np.stack([one, g / a], -1), np.stack([zero, 1.0 - g], -1)], -2)
    Bd = np.stack([T - g / a, g], -1)[..., None]
    return Ad, Bd
