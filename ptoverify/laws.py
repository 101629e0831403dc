"""Control laws: time-optimal (eq. 12), PD, and the region bookkeeping.

A law is a :class:`Law`: calling it with arrays of states returns the input
and the region code of each state; ``law.scalar(x1, x2)`` is the cheap path
for one state given as Python floats.  Every law returns |u| <= w_max.

Region codes (:class:`Region`) name the branch of the law that acted, so a
simulation can say which region every sample used.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config
from ptoverify.curves import switching_function
from ptoverify.errors import InputError

__all__ = ["Region", "Law", "to_law", "pd_law", "make_law", "LAW_NAMES", "h_scalar"]


class Region(IntEnum):
    """Branch of a law that produced the input."""

    ORIGIN = 0       #: the origin, u = 0
    BANG_P = 1       #: S_P or l1, u = +w_max (eq. 12)
    BANG_N = 2       #: S_N or l2, u = -w_max
    ZONE_P = 3       #: switching zone S~_P or l1*, u = +omega_c (eq. 28)
    ZONE_N = 4       #: switching zone S~_N or l2*, u = -omega_c (eq. 33)
    LINEAR = 5       #: linear (PD) input, unsaturated (eq. 34 or PD)
    SATURATED = 6    #: linear input clipped at +-w_max


ArrayFn = Callable[[NDArray[np.float64], NDArray[np.float64]],
                   tuple[NDArray[np.float64], NDArray[np.int8]]]
ScalarFn = Callable[[float, float], tuple[float, int]]


@dataclass(frozen=True)
class Law:
    """A feedback law u = f(x1, x2), vectorized and scalar.

    Attributes
    ----------
    name : str
        Name (``to``, ``pd``, ``pto``, ``pto-printed``).
    vector : callable
        ``vector(x1, x2) -> (u, region)`` on float arrays.
    scalar : callable
        ``scalar(x1, x2) -> (u, region)`` on Python floats.
    w_max : float
        Saturation [mm/s] the law respects.
    note : str
        What the law is, in one line (says when a variant falls back).
    """

    name: str
    vector: ArrayFn
    scalar: ScalarFn
    w_max: float
    note: str = ""

    def __call__(self, x1: ArrayLike, x2: ArrayLike) -> tuple[NDArray[np.float64],
                                                               NDArray[np.int8]]:
        """Evaluate the law on arrays; returns (u [mm/s], region codes)."""
        x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        return self.vector(x1, x2)


_H_COEF = tuple((-1.0) ** n / n for n in range(25, 1, -1))   # Horner order, highest first


def h_scalar(r: float) -> float:
    """Return r - ln(1 + r) for a Python float, exact near 0 (see ``curves.h``)."""
    if -0.2 < r < 0.2:
        acc = 0.0
        for c in _H_COEF:
            acc = acc * r + c
        return acc * r * r
    return r - math.log1p(r)


def sigma_scalar(x1: float, x2: float, a: float, omega: float) -> float:
    """Scalar :func:`ptoverify.curves.level_residual`."""
    if x2 > 0:
        return a * x1 + omega * h_scalar(x2 / omega)
    if x2 < 0:
        return a * x1 - omega * h_scalar(-x2 / omega)
    return a * x1


def _bang(sigma: NDArray[np.float64], x2: NDArray[np.float64], w: float):
    """Time-optimal input from the switching function: S_P u l1 -> +w, S_N u l2 -> -w."""
    pos = (sigma < 0) | ((sigma == 0) & (x2 < 0))
    u = np.where(pos, w, -w)
    region = np.where(pos, Region.BANG_P, Region.BANG_N).astype(np.int8)
    return u, region


def to_law(cfg: Config) -> Law:
    """Time-optimal feedback law, eq. (12).

    u = +w_max in S_P and on l1, -w_max in S_N and on l2, 0 at the origin, where
    S_P / S_N are the sides of the switching curve l1 - o - l2 (eqs. 9, 11).

    Parameters
    ----------
    cfg : Config
        Configuration (plant a, w_max).

    Returns
    -------
    Law
        The TO law.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = to_law(paper_config())
    >>> law.scalar(5.0, 0.0)
    (-300.0, 2)
    """
    a, w = cfg.plant.a, cfg.plant.w_max

    def vector(x1, x2):
        u, region = _bang(switching_function(x1, x2, a, w), x2, w)
        origin = (x1 == 0) & (x2 == 0)
        return np.where(origin, 0.0, u), np.where(origin, Region.ORIGIN, region).astype(np.int8)

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        if x1 == 0.0 and x2 == 0.0:
            return 0.0, int(Region.ORIGIN)
        s = sigma_scalar(x1, x2, a, w)
        if s < 0 or (s == 0 and x2 < 0):
            return w, int(Region.BANG_P)
        return -w, int(Region.BANG_N)

    return Law("to", vector, scalar, w, "time-optimal bang-bang, eq. (12)")


def saturate_linear(v: NDArray[np.float64], w: float):
    """Clip a linear input to +-w; region LINEAR where unclipped, SATURATED where clipped."""
    u = np.clip(v, -w, w)
    region = np.where(np.abs(v) > w, Region.SATURATED, Region.LINEAR).astype(np.int8)
    return u, region


def pd_law(cfg: Config) -> Law:
    """PD law u = sat(-kp x1 - kd x2), saturated at +-w_max.

    In tracking, x1 is the position error x1 - r, so u = kp (r - x1) - kd x2.
    The paper does not say that its PD is saturated; the plant's input is
    limited to |u| <= w_max (eq. 1), so the input is clipped there.

    Parameters
    ----------
    cfg : Config
        Configuration (w_max, kp [1/s], kd [-]).

    Returns
    -------
    Law
        The PD law.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> pd_law(paper_config()).scalar(0.1, 0.0)
    (-35.6, 5)
    """
    w, kp, kd = cfg.plant.w_max, cfg.pd.kp, cfg.pd.kd

    def vector(x1, x2):
        return saturate_linear(-kp * x1 - kd * x2, w)

    def scalar(x1: float, x2: float) -> tuple[float, int]:
        v = -kp * x1 - kd * x2
        if v > w:
            return w, int(Region.SATURATED)
        if v < -w:
            return -w, int(Region.SATURATED)
        return v, int(Region.LINEAR)

    return Law("pd", vector, scalar, w, f"PD u = sat(-{kp:g} x1 - {kd:g} x2)")


_FACTORIES: dict[str, Callable[[Config], Law]] = {"to": to_law, "pd": pd_law}
LAW_NAMES: tuple[str, ...] = ("to", "pd", "pto", "pto-printed")


def make_law(name: str, cfg: Config) -> Law:
    """Build a law by name: ``to``, ``pd``, ``pto`` or ``pto-printed``.

    Parameters
    ----------
    name : str
        Law name.
    cfg : Config
        Configuration.

    Returns
    -------
    Law
        The law.
    """
    if name not in _FACTORIES:
        raise InputError(f"unknown law '{name}' (choose from {', '.join(LAW_NAMES)})")
    return _FACTORIES[name](cfg)
