"""Grids of initial states over the envelope, exactly symmetric, and their mirror pairs.

Part of :mod:`ptoverify.studies.sweep` (which re-exports every name here); the
robustness maps and ``conform`` use the same grids.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Plant

__all__ = ["grid_states", "even_points", "mirror_pairs"]


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


def mirror_pairs(x1: NDArray, x2: NDArray) -> tuple[NDArray[np.intp], NDArray[np.intp]] | None:
    """Pair states with their mirrors through the origin, for simulating half of them.

    Parameters
    ----------
    x1, x2 : ndarray, shape (n,)
        States [mm], [mm/s].

    Returns
    -------
    (reps, where) or None
        ``reps``: the indices of one state of each mirrored pair (the first; a
        state at the origin is its own mirror); ``where[k]``: the position in
        ``reps`` of state k or of its mirror, so ``v[where]`` spreads values
        measured at ``reps`` to every state.  None when some state's exact
        mirror (-x1, -x2) is not among the states.

    Examples
    --------
    >>> reps, where = mirror_pairs(np.array([1.0, 0.0, -1.0]), np.array([2.0, 0.0, -2.0]))
    >>> reps.tolist(), where.tolist()
    ([0, 1], [0, 1, 0])
    """
    n = x1.size
    if np.array_equal(x1[::-1], -x1) and np.array_equal(x2[::-1], -x2):
        # states listed as their own mirror image (grid_states): pairs k, n - 1 - k
        half = (n + 1) // 2
        k = np.arange(n, dtype=np.intp)
        return k[:half], np.minimum(k, n - 1 - k)
    at = {(a, b): k for k, (a, b) in enumerate(zip(x1.tolist(), x2.tolist(), strict=True))}
    mirror = [at.get((-a, -b)) for a, b in zip(x1.tolist(), x2.tolist(), strict=True)]
    if any(m is None for m in mirror):
        return None
    first = np.minimum(np.arange(n), np.array(mirror, dtype=np.intp))
    reps, where = np.unique(first, return_inverse=True)
    return reps.astype(np.intp), where.astype(np.intp)
