"""Grids of initial states over the envelope, exactly symmetric, and their mirror pairs.

Part of :mod:`ptoverify.studies.sweep` (which re-exports every name here); the
robustness maps and ``conform`` use the same grids.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant

__all__ = ["grid_states", "even_points"]


def grid_states(plant: Plant, n1: int, n2: int) -> tuple[NDArray, NDArray]:
    """Even grid over the envelope, shape (n2, n1) each: (x1 [mm], x2 [mm/s]).

    Parameters
    ----------
    plant : Plant
        The plant (position_range [mm], w_max [mm/s]).
    n1, n2 : int
        Grid points along x1 and x2 [-].

    Returns
    -------
    x1, x2 : ndarray, shape (n2, n1)
        Positions [mm] and velocities [mm/s] (meshgrid, x1 along columns).
    """
    return np.meshgrid(even_points(plant.position_range, n1), even_points(plant.w_max, n2))


def even_points(r: float, n: int) -> NDArray[np.float64]:
    """Return n points from -r to r, evenly spaced and exactly symmetric: x[n-1-i] == -x[i].

    Each is r (2i - (n - 1)) / (n - 1): the numerator is an integer, and IEEE
    division and multiplication commute with the sign, so mirrored points are
    negatives bit for bit (``np.linspace`` is not: it adds i steps to -r).

    Parameters
    ----------
    r : float
        Half-width [mm] or [mm/s] (the points are in its unit).
    n : int
        Number of points [-] (one point is 0).

    Returns
    -------
    ndarray, shape (n,)
        The points, -r and r included.

    Examples
    --------
    >>> x = even_points(50.0, 200)
    >>> bool((x[::-1] == -x).all()), float(x[0]), float(x[-1])
    (True, -50.0, 50.0)
    """
    if n == 1:
        return np.zeros(1)
    return r * ((2.0 * np.arange(n) - (n - 1)) / (n - 1))
