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

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant
from ptoverify.curves import h, switching_function

__all__ = ["MinTime", "min_time"]


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
    a, w = plant.a, plant.w_max
    x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
    sigma = switching_function(x1, x2, a, w)
    side = np.where(sigma > 0, 1.0, np.where(sigma < 0, -1.0, np.where(x2 < 0, 1.0, -1.0)))
    y1, y2 = side * x1, side * x2
    rho = y2 / w
    fast = rho <= -1.0
    with np.errstate(all="ignore"):
        g = a * y1 / w + h(np.where(fast, 0.0, rho))
        q2_slow = -(w * w) * np.expm1(-g)
        q2_fast = w * w - w * (w + y2) * np.exp(-(a * y1 + y2) / w)
    q = -np.sqrt(np.maximum(np.where(fast, q2_fast, q2_slow), 0.0))
    lq = np.log1p(-q / w)
    t2 = lq / a
    t1 = np.maximum((lq + (a * y1 + y2) / w) / a, 0.0)
    origin = (x1 == 0) & (x2 == 0)
    zero = np.zeros_like(t1)
    return MinTime(t_f=np.where(origin, zero, t1 + t2), t_switch=np.where(origin, zero, t1),
                   side=np.where(origin, zero, side), q=np.where(origin, zero, side * q))
