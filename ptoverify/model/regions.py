"""Vocabulary of the control laws: region codes and law families.

Part of :mod:`ptoverify.model.laws` (which re-exports every name here): the
code of the branch of a law that acted (:class:`Region`), the signature of a
law's vector path, and the family of laws that share one elementwise function
(:class:`LawFamily`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import NDArray

__all__ = ["Region", "LawFamily", "ArrayFn", "ScalarFn"]


class Region(IntEnum):
    """Branch of a law that produced the input."""

    ORIGIN = 0  #: the origin, u = 0
    BANG_P = 1  #: S_P or l1, u = +w_max (eq. 12)
    BANG_N = 2  #: S_N or l2, u = -w_max
    ZONE_P = 3  #: switching zone S~_P or l1*, u = +omega_c (eq. 28)
    ZONE_N = 4  #: switching zone S~_N or l2*, u = -omega_c (eq. 33)
    LINEAR = 5  #: linear (PD) input, unsaturated (eq. 34 or PD)
    SATURATED = 6  #: linear input clipped at +-w_max


ArrayFn = Callable[
    [NDArray[np.float64], NDArray[np.float64]], tuple[NDArray[np.float64], NDArray[np.int8]]
]
ScalarFn = Callable[[float, float], tuple[float, int]]


@dataclass(frozen=True)
class LawFamily:
    """Laws that are one elementwise function with different parameters.

    A batch that drives states with several laws of one family evaluates them
    in one call, each state with its law's parameters
    (:func:`ptoverify.sim.simulate.simulate_parts`).  A member's own
    ``vector`` is this function with its ``params``, so each state's input and
    region are those of its own law by construction.

    Attributes
    ----------
    key : tuple
        Laws with equal keys belong to one family (their ``vector`` is the same function).
    vector : callable
        ``vector(x1, x2, *params) -> (u, region)`` on float arrays, each parameter
        a float or an array of the states' shape.
    params : tuple of float
        This law's parameters.
    """

    key: tuple
    vector: Callable[..., tuple[NDArray[np.float64], NDArray[np.int8]]]
    params: tuple[float, ...]
