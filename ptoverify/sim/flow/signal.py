"""References r(t) and trajectories of the sampled loop, with the exact flow between samples."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.errors import InputError


@dataclass(frozen=True)
class Signal:
    """A reference r(t) for t >= 0: step, ramp or sine.

    Attributes
    ----------
    kind : str
        ``step`` (r = amplitude), ``ramp`` (r = sign(A) min(|rate| t, |A|)) or
        ``sine`` (r = amplitude sin(2 pi rate t)).
    amplitude : float
        Step height, ramp end value or sine amplitude [mm].
    rate : float
        Ramp speed [mm/s] or sine frequency [Hz]; unused for a step.

    Examples
    --------
    >>> Signal("ramp", 30.0, 200.0).r(np.array([0.1, 0.2])).tolist()
    [20.0, 30.0]
    """

    kind: str
    amplitude: float
    rate: float = 0.0

    def __post_init__(self) -> None:
        """Validate the kind and the numbers."""
        if self.kind not in ("step", "ramp", "sine"):
            raise InputError(f"unknown reference kind '{self.kind}' (step, ramp, sine)")
        if not (math.isfinite(self.amplitude) and math.isfinite(self.rate)):
            raise InputError("reference amplitude and rate must be finite")
        if self.kind in ("ramp", "sine") and self.rate == 0.0:
            raise InputError(f"a {self.kind} needs a nonzero rate")

    @property
    def omega(self) -> float:
        """Angular frequency of the sine part [rad/s] (0 unless a sine)."""
        return 2.0 * math.pi * abs(self.rate) if self.kind == "sine" else 0.0

    @property
    def cuts(self) -> tuple[float, ...]:
        """Times [s] where r' jumps (the ramp's end)."""
        return (abs(self.amplitude / self.rate),) if self.kind == "ramp" else ()

    def r(self, t: ArrayLike) -> NDArray[np.float64]:
        """Return r(t) [mm] at times t [s]."""
        t = np.asarray(t, dtype=float)
        if self.kind == "step":
            return np.full_like(t, self.amplitude)
        if self.kind == "ramp":
            return math.copysign(1.0, self.amplitude) * np.minimum(
                abs(self.rate) * t, abs(self.amplitude)
            )
        return self.amplitude * np.sin(self.omega * t)

    def slope(self, t: ArrayLike) -> NDArray[np.float64]:
        """Return the slope of r's linear part [mm/s] (the ramp's speed while it moves)."""
        t = np.asarray(t, dtype=float)
        if self.kind != "ramp":
            return np.zeros_like(t)
        moving = abs(self.rate) * t < abs(self.amplitude)
        return np.where(moving, math.copysign(abs(self.rate), self.amplitude), 0.0)

    def r_dot(self, t: ArrayLike) -> NDArray[np.float64]:
        """Return r'(t) [mm/s]; at the ramp's end, the right derivative (0)."""
        t = np.asarray(t, dtype=float)
        w = self.omega
        return self.slope(t) + self.amplitude * w * np.cos(w * t) * (self.kind == "sine")


def as_signal(ref: Any) -> Signal:
    """Read a reference from a :class:`Signal`, a Reference-like object or a tuple.

    Parameters
    ----------
    ref : Signal, object or tuple
        A :class:`Signal`; any object with ``name`` (or ``kind``), ``amplitude``
        and ``rate`` (or ``speed``, ``frequency``) attributes, as
        ``ptoverify.sim.simulate.Reference``; or a tuple
        ``(kind, amplitude[, rate])``.

    Returns
    -------
    Signal

    Examples
    --------
    >>> as_signal(("sine", 5.0, 5.0)).omega == 10 * math.pi
    True
    """
    if isinstance(ref, Signal):
        return ref
    if isinstance(ref, tuple):
        return Signal(*ref)
    kind = getattr(ref, "kind", None) or getattr(ref, "name", None)
    if kind is None or not hasattr(ref, "amplitude"):
        raise InputError(f"cannot read a reference from {type(ref).__name__}")
    rate = next(
        (v for n in ("rate", "speed", "frequency") if (v := getattr(ref, n, None)) is not None),
        0.0,
    )
    return Signal(str(kind), float(ref.amplitude), float(rate))


def as_float_array(x: ArrayLike) -> NDArray[np.float64]:
    """Return x as a float array.

    Parameters
    ----------
    x : array_like
        Values [any unit].

    Returns
    -------
    ndarray
        The values as float64.
    """
    return np.asarray(x, dtype=float)


@dataclass(frozen=True)
class Trajectory:
    """The exact continuous trajectory of a sampled response (ZOH, eq. 7).

    Attributes
    ----------
    t : ndarray, shape (n + 1,)
        Sample times [s], increasing.
    x1, x2 : ndarray, shape (n + 1,)
        Position [mm] and velocity [mm/s] at the samples.
    u : ndarray, shape (n,)
        Input held on [t_k, t_k+1) [mm/s].
    a : float
        Bandwidth [rad/s].

    Examples
    --------
    >>> tr = Trajectory.from_samples([0.0, 0.1], [0.0, 0.0], [0.0, 0.0], [0.0], 10.0)
    >>> tr.intervals
    1
    """

    t: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    u: NDArray[np.float64]
    a: float

    @classmethod
    def from_samples(
        cls, t: ArrayLike, x1: ArrayLike, x2: ArrayLike, u: ArrayLike, a: float
    ) -> Trajectory:
        """Validate and wrap sample arrays (u may carry one trailing unused value).

        x1 and x2 have shape (n + 1,) for one trajectory or (n + 1, k) for k
        trajectories on the same sample times; u then has shape (n,) or (n, k)
        (or one trailing row more).
        """
        t, x1, x2, u = as_float_array(t), as_float_array(x1), as_float_array(x2), as_float_array(u)
        n = t.size - 1
        if n < 1 or t.ndim != 1 or x1.shape[:1] != t.shape or x2.shape != x1.shape:
            raise InputError("t must be 1-D of length >= 2 and x1, x2 of one shape, t's rows")
        if x1.ndim > 2 or u.shape not in ((n, *x1.shape[1:]), (n + 1, *x1.shape[1:])):
            raise InputError("u must hold one input per interval (n or n + 1 values)")
        u = u[:n]
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x1)) and np.all(np.isfinite(x2))):
            raise InputError("non-finite sample data")
        if not (np.all(np.isfinite(u)) and np.all(np.diff(t) > 0)):
            raise InputError("u must be finite and t strictly increasing")
        if not (math.isfinite(a) and a > 0):
            raise InputError(f"bandwidth a must be positive, got {a}")
        return cls(t, x1, x2, u, float(a))

    @classmethod
    def from_result(cls, res: Any, plant: Any) -> Trajectory:
        """Wrap a SimResult-like object (t, x1, x2, u) and a plant (``a``, or a float)."""
        a = plant if isinstance(plant, (int, float)) else plant.a
        return cls.from_samples(res.t, res.x1, res.x2, res.u, float(a))

    @property
    def intervals(self) -> int:
        """Number of sample intervals n."""
        return self.t.size - 1

    @property
    def period(self) -> float:
        """Median sample period [s]."""
        return float(np.median(np.diff(self.t)))

    def state(self, tq: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Exact state at times tq in [t_0, t_n] (eq. 7 from the last sample).

        Parameters
        ----------
        tq : array_like
            Times [s].

        Returns
        -------
        x1, x2 : ndarray
            Position [mm] and velocity [mm/s].
        """
        tq = as_float_array(tq)
        k = np.clip(np.searchsorted(self.t, tq, side="right") - 1, 0, self.intervals - 1)
        return zoh_flow(self.x1[k], self.x2[k], self.u[k], tq - self.t[k], self.a)


def zoh_flow(x1, x2, u, s, a):
    """Exact ZOH flow of eq. (7) over offsets s (broadcasting).

    Parameters
    ----------
    x1, x2 : array_like
        State at the start [mm], [mm/s].
    u : array_like
        Held input [mm/s].
    s : array_like
        Time offsets [s].
    a : float or array_like
        Bandwidth [rad/s].

    Returns
    -------
    x1, x2 : ndarray
        State after s [mm], [mm/s].
    """
    g = -np.expm1(-a * s)
    dv = x2 - u
    return x1 + u * s + dv * g / a, x2 - dv * g
