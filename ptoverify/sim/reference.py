"""Reference signals r(t) of the closed loop: step, ramp and sine (Section 6).

Catalogue
---------
Reference  a step, ramp or sine with its derivative and duration
SIGNALS    the Section 6 references
reference  a Section 6 reference with any of its parameters changed
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ptoverify.errors import InputError

__all__ = ["Reference", "SIGNALS", "reference"]


@dataclass(frozen=True)
class Reference:
    """A reference signal r(t) with its derivative: a step, a ramp or a sine.

    Build one with :meth:`step`, :meth:`ramp` or :meth:`sine`; the Section 6
    ones are in :data:`SIGNALS`.  Bad values raise
    :class:`~ptoverify.errors.InputError`.

    Attributes
    ----------
    name : str
        ``step``, ``ramp`` or ``sine``.
    amplitude : float
        Step height, ramp end value (its target) or sine amplitude [mm], finite, nonzero.
    frequency : float or None
        Sine frequency [Hz], > 0 (None for a step or a ramp).
    speed : float or None
        Ramp speed [mm/s], > 0; the ramp moves toward its target at this speed
        and then holds it (None for a step or a sine).
    duration : float
        Simulated time [s], > 0: the default of :func:`simulate`, and in a
        :class:`SimResult` the time actually simulated.

    Examples
    --------
    >>> ref = Reference.ramp(speed=100.0, target=-20.0)
    >>> ref.target, ref.duration
    (-20.0, 0.45)
    >>> [float(v) for v in ref.r(np.array([0.0, 0.1, 0.3]))]
    [0.0, -10.0, -20.0]
    """

    name: str
    amplitude: float
    frequency: float | None = None
    speed: float | None = None
    duration: float = 0.2

    def __post_init__(self) -> None:
        """Validate the signal; raise InputError on bad values."""
        if self.name not in ("step", "ramp", "sine"):
            raise InputError(f"unknown signal '{self.name}' (choose from step, ramp, sine)")
        if not (math.isfinite(self.amplitude) and self.amplitude != 0.0):
            raise InputError(
                f"{self.name} amplitude must be finite and nonzero, got {self.amplitude!r} mm"
            )
        need = {"sine": ("frequency", "Hz"), "ramp": ("speed", "mm/s")}.get(self.name)
        for field, unit in (("frequency", "Hz"), ("speed", "mm/s")):
            value = getattr(self, field)
            if need is not None and field == need[0]:
                if value is None or not (math.isfinite(value) and value > 0.0):
                    raise InputError(
                        f"{self.name} {field} must be finite and > 0, got {value!r} {unit}"
                    )
            elif value is not None:
                raise InputError(f"a {self.name} has no {field}")
        if not (math.isfinite(self.duration) and self.duration > 0.0):
            raise InputError(f"duration must be finite and > 0, got {self.duration!r} s")

    @classmethod
    def step(cls, height: float = 5.0, *, duration: float = 0.2) -> Reference:
        """Step of ``height`` [mm] at t = 0, simulated for ``duration`` [s].

        Parameters
        ----------
        height : float
            Step height [mm], nonzero.
        duration : float
            Simulated time [s] (Section 6: 0.2 s; give more for steps much
            longer than w_max * 0.1 s).

        Returns
        -------
        Reference
            The step.
        """
        return cls("step", float(height), duration=float(duration))

    @classmethod
    def ramp(
        cls, speed: float = 200.0, target: float = 30.0, *, duration: float | None = None
    ) -> Reference:
        """Ramp from 0 toward ``target`` [mm] at ``speed`` [mm/s], then held.

        Parameters
        ----------
        speed : float
            Ramp speed [mm/s], > 0.
        target : float
            End value [mm], nonzero (negative: the ramp goes down).
        duration : float, optional
            Simulated time [s]; default the ramp's time |target| / speed plus
            0.25 s (Section 6: 0.15 + 0.25 = 0.4 s).

        Returns
        -------
        Reference
            The ramp.
        """
        if duration is None and speed > 0.0 and math.isfinite(target / speed):
            duration = abs(target) / speed + 0.25
        return cls("ramp", float(target), speed=float(speed), duration=_num(duration))

    @classmethod
    def sine(
        cls, amplitude: float = 5.0, frequency: float = 5.0, *, duration: float | None = None
    ) -> Reference:
        """Sine r = amplitude sin(2 pi frequency t).

        Parameters
        ----------
        amplitude : float
            Amplitude [mm], nonzero.
        frequency : float
            Frequency [Hz], > 0.  The phase metrics fit whole periods, so
            1 / (frequency T) should be a whole number of samples.
        duration : float, optional
            Simulated time [s]; default five periods (Section 6: 1 s).

        Returns
        -------
        Reference
            The sine.
        """
        if duration is None and frequency > 0.0:
            duration = 5.0 / frequency
        return cls("sine", float(amplitude), frequency=float(frequency), duration=_num(duration))

    @property
    def target(self) -> float | None:
        """Final value of a step or ramp [mm]; None for a sine."""
        return None if self.name == "sine" else self.amplitude

    def r(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the reference position [mm] at times t [s]."""
        if self.name == "step":
            return np.full_like(t, self.amplitude)
        if self.name == "ramp":
            s = math.copysign(1.0, self.amplitude)
            return s * np.minimum(self.speed * t, abs(self.amplitude)) + 0.0  # no -0.0
        return self.amplitude * np.sin(2.0 * math.pi * self.frequency * t)

    def r_dot(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return the reference velocity [mm/s] at times t [s] (0 for the step)."""
        if self.name == "step":
            return np.zeros_like(t)
        if self.name == "ramp":
            v = math.copysign(self.speed, self.amplitude)
            return np.where(self.speed * t < abs(self.amplitude), v, 0.0)
        omega = 2.0 * math.pi * self.frequency
        return self.amplitude * omega * np.cos(omega * t)

    def to_json(self) -> dict:
        """Return the reference as a dict (units in the keys)."""
        return {
            "signal": self.name,
            "amplitude_mm": self.amplitude,
            "frequency_hz": self.frequency,
            "speed_mm_s": self.speed,
            "target_mm": self.target,
            "duration_s": self.duration,
        }


def _num(x: float | None) -> float:
    return math.nan if x is None else float(x)


SIGNALS: dict[str, Reference] = {
    "step": Reference.step(5.0, duration=0.2),
    "ramp": Reference.ramp(200.0, 30.0, duration=0.4),
    "sine": Reference.sine(5.0, 5.0, duration=1.0),
}
"""The Section 6 references: 5 mm step, ramp to 30 mm at 200 mm/s, 5 mm 5 Hz sine."""


_OPTIONS = {
    "step": ("step",),
    "ramp": ("ramp_speed", "ramp_to"),
    "sine": ("amplitude", "frequency"),
}


def reference(
    name: str,
    *,
    step: float | None = None,
    ramp_speed: float | None = None,
    ramp_to: float | None = None,
    amplitude: float | None = None,
    frequency: float | None = None,
) -> Reference:
    """Return the Section 6 reference ``name``, with any of its parameters changed.

    The keywords are those of ``ptoverify simulate`` (``--step``, ``--ramp-speed``,
    ``--ramp-to``, ``--amplitude``, ``--frequency``); one that does not belong to
    ``name`` raises :class:`~ptoverify.errors.InputError`.  With none given this is
    the Section 6 reference of :data:`SIGNALS`.

    Parameters
    ----------
    name : str
        ``step``, ``ramp`` or ``sine``.
    step : float, optional
        Step height [mm] (Section 6: 5).
    ramp_speed, ramp_to : float, optional
        Ramp speed [mm/s] and end value [mm] (Section 6: 200, 30).
    amplitude, frequency : float, optional
        Sine amplitude [mm] and frequency [Hz] (Section 6: 5, 5).

    Returns
    -------
    Reference
        The reference; its duration is the default of its constructor.

    Examples
    --------
    >>> reference("sine", frequency=2.0)
    Reference(name='sine', amplitude=5.0, frequency=2.0, speed=None, duration=2.5)
    """
    if name not in SIGNALS:
        raise InputError(f"unknown signal '{name}' (choose from step, ramp, sine)")
    given = {
        "step": step,
        "ramp_speed": ramp_speed,
        "ramp_to": ramp_to,
        "amplitude": amplitude,
        "frequency": frequency,
    }
    for key, value in given.items():
        if value is not None and key not in _OPTIONS[name]:
            raise InputError(f"--{key.replace('_', '-')} does not apply to the {name}")
    base = SIGNALS[name]
    if all(given[k] is None for k in _OPTIONS[name]):
        return base
    if name == "step":
        return Reference.step(step)
    if name == "ramp":
        return Reference.ramp(
            base.speed if ramp_speed is None else ramp_speed,
            base.amplitude if ramp_to is None else ramp_to,
        )
    return Reference.sine(
        base.amplitude if amplitude is None else amplitude,
        base.frequency if frequency is None else frequency,
    )
