"""Settling times of a batch of trajectories, exactly between samples."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.errors import InputError
from ptoverify.sim.flow import (
    Trajectory,
    as_float_array,
)
from ptoverify.sim.settling import (
    SettlingDefinition,
    settling_time,
)

from .response import _named


@dataclass(frozen=True)
class BatchSettling:
    """Settling times of many regulation records, between samples and on the grid.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Exact settling time [s] from the record's start: the last exit of the
        continuous trajectory from the box |x1| <= band_x1, |x2| <= band_x2
        (0 if never outside); NaN when the record ends outside or the settled
        tail is shorter than ``hold``.
    grid : ndarray, shape (n,)
        Sample-grid settling time [s]: k T for the first sample k after the last
        sample outside the box (:func:`ptoverify.sim.settling.grid_settling`); NaN likewise,
        with the hold counted in whole samples, ceil(hold / T).
    accuracy : float
        Bound on the error of :attr:`time` [s] (see :func:`settling_times_batch`).
    """

    time: NDArray[np.float64]
    grid: NDArray[np.float64]
    accuracy: float


def settling_times_batch(
    x1: ArrayLike,
    x2: ArrayLike,
    u: ArrayLike,
    a: float,
    T: float,  # noqa: N803
    band_x1: float,
    band_x2: float,
    hold: float = 0.0,
) -> BatchSettling:
    """Exact last exit from a band box for many ZOH records at once (regulation).

    The box is |x1| <= band_x1 and |x2| <= band_x2.  The last time outside the
    box is the later of the last exits of x1 and of x2 from their own bands,
    found separately:

    * x2(s) = u + (x2k - u) e^{-a s} is monotone on each sample, so it leaves its
      band between samples only if a sample is outside: its last exit is in the
      interval after the last sample outside, at the closed-form
      s = ln((x2k - u)/(L - u)) / a, L = +-band_x2.
    * x1 is convex or concave on each sample (x1'' = x2' has one sign), with an
      interior extremum only where x2 changes sign, at s* = ln((u - x2k)/u) / a.
      Its last exit is in the latest interval that has a point outside -- its
      first sample, or an excursion x1(s*) outside the band between two samples
      that are both inside -- on the monotone piece after that point, found by
      safeguarded Newton on eq. (7) to 4 ulps of T.

    Parameters
    ----------
    x1, x2 : array_like, shape (steps + 1, n) or (steps + 1,)
        Position [mm] and velocity [mm/s] at the samples t_k = k T.
    u : array_like, shape (steps, n) or (steps,)
        Input held on [t_k, t_k+1) [mm/s].
    a : float
        Bandwidth [rad/s].
    T : float
        Sample period [s].
    band_x1 : float
        Position band [mm], > 0.
    band_x2 : float
        Velocity band [mm/s], > 0.
    hold : float
        Shortest settled tail that counts [s]: settled only if
        t_end - time >= hold - 1e-9 T (the grid value: whole samples,
        ceil(hold / T - 1e-9), as ``ptoverify.studies.sweep``).

    Returns
    -------
    BatchSettling
        ``time`` (between samples) and ``grid`` (on the samples), shape (n,),
        and ``accuracy`` = 4 eps T (Newton's stopping width) + 4 eps t_end
        (round-off of k T + s) [s]; the x1 crossing also moves with the
        round-off of eq. (7), about 8 eps X / |x2| for X the size of its terms.
        Where both are finite, grid - T < time (the sample before the grid
        value is outside the box) and grid <= T ceil(time / T) (every sample
        from the exact time on is inside); time > grid only when the
        trajectory leaves the box between samples after the grid value.

    Examples
    --------
    >>> a, T = 10.0, 0.1
    >>> t = np.arange(11) * T
    >>> x2 = 5.0 * np.exp(-a * t)  # u = 0: x1 = 0.5 (1 - e^{-a t}) - 0.5
    >>> x1 = -0.5 * np.exp(-a * t)
    >>> st = settling_times_batch(x1, x2, np.zeros(10), a, T, 0.01, 1.0)
    >>> round(float(st.time[0]), 6), float(st.grid[0])  # ln(50) / 10, then the sample after
    (0.391202, 0.4)
    """
    x1, x2, u = as_float_array(x1), as_float_array(x2), as_float_array(u)
    if x1.ndim == 1:
        x1, x2, u = x1[:, None], x2[:, None], u[:, None]
    steps = x1.shape[0] - 1
    if steps < 1 or x2.shape != x1.shape or u.shape != (steps, x1.shape[1]):
        raise InputError("x1, x2 must be (steps + 1, n) and u (steps, n), steps >= 1")
    if not (band_x1 > 0 and band_x2 > 0 and a > 0 and T > 0 and hold >= 0):
        raise InputError("bands, a and T must be positive and hold >= 0")
    vb = None if math.isinf(band_x2) else band_x2 / a
    box = _named(
        SettlingDefinition("custom", "box", band_mm=band_x1, velocity_band_mm=vb, hold_s=hold)
    )
    tr = Trajectory(np.arange(steps + 1) * T, x1, x2, u, float(a))
    st = settling_time(tr, None, box)
    return BatchSettling(st.time, st.grid, st.accuracy)
