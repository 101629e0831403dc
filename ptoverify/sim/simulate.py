"""Sampled-data closed loop, exact between samples (ZOH flow, no Euler).

At each sample t_k = k T the law sees an error state and its input is held
for one period; the plant moves by its exact flow (eq. 7)::

    e1_k = x1_k - r_k,   e2_k = x2_k - f_e * r'_k
    u_k  = sat(f_u * r'_k + law(e1_k, e2_k))
    x_{k+1} = flow(x_k, u_k, T)

The paper does not say how its laws, written for regulation to the origin,
track a moving reference; ``tracking`` selects the reading:

* ``feedforward`` (f_e = f_u = 1): the law sees the error state and the
  reference velocity is fed forward (for a ramp the error then obeys the
  plant's own dynamics);
* ``none`` (f_e = f_u = 0): the law sees (x1 - r, x2), nothing is added: a
  moving set-point;
* ``error`` (f_e = 1, f_u = 0): the law sees the error state, nothing is
  added: the textbook PD on the error e and its derivative.

For a step (r' = 0) the three coincide.  The Section 6 references
(:data:`SIGNALS`) are a 5 mm step, a ramp from 0 to 30 mm at 200 mm/s and a
5 mm, 5 Hz sine; :class:`Reference` builds any other step, ramp or sine.
Every :class:`SimResult` carries the :class:`Reference` it tracked and its
tracking mode, so nothing downstream reads a global to learn what was
simulated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.laws import Law

__all__ = [
    "TRACKING",
    "Reference",
    "reference",
    "SIGNALS",
    "SimResult",
    "simulate",
    "BatchResult",
    "Mismatch",
    "simulate_batch",
    "simulate_segments",
]


TRACKING = ("feedforward", "none", "error")
"""Tracking modes of :func:`simulate` (see the module docstring)."""


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


@dataclass(frozen=True)
class SimResult:
    """A sampled closed-loop response; arrays of length n + 1 (samples 0..n).

    Attributes
    ----------
    law : str
        Name of the law simulated.
    reference : Reference
        The reference tracked (signal, amplitude [mm], frequency [Hz], ramp
        speed [mm/s], target [mm]); its ``duration`` is the time simulated [s].
    tracking : str
        Tracking mode, one of :data:`TRACKING`.
    t : ndarray
        Sample times [s].
    r, r_dot : ndarray
        Reference [mm] and its velocity [mm/s].
    x1, x2 : ndarray
        Position [mm] and velocity [mm/s] at the samples.
    e : ndarray
        Control error r - x1 [mm].
    u : ndarray
        Input held from each sample to the next [mm/s] (the last is computed, not applied).
    region : ndarray of int8
        :class:`~ptoverify.model.laws.Region` code of each sample.
    """

    law: str
    reference: Reference
    tracking: str
    t: NDArray[np.float64]
    r: NDArray[np.float64]
    r_dot: NDArray[np.float64]
    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    e: NDArray[np.float64]
    u: NDArray[np.float64]
    region: NDArray[np.int8]

    @property
    def signal(self) -> str:
        """Name of the reference signal (``step``, ``ramp``, ``sine``)."""
        return self.reference.name

    @property
    def feedforward(self) -> bool:
        """Whether the reference velocity was added to the input."""
        return self.tracking == "feedforward"

    def columns(self) -> dict[str, NDArray]:
        """Return the time series as named columns (for CSV and JSON)."""
        return {
            "t": self.t,
            "r": self.r,
            "x1": self.x1,
            "x2": self.x2,
            "e": self.e,
            "u": self.u,
            "region": self.region,
        }


def simulate(
    law: Law,
    plant: Plant,
    signal: str | Reference = "step",
    *,
    duration: float | None = None,
    tracking: str | None = None,
    feedforward: bool | None = None,
) -> SimResult:
    """Simulate the sampled closed loop tracking a reference from rest at 0.

    Parameters
    ----------
    law : Law
        Feedback law.
    plant : Plant
        Plant and sample time.
    signal : str or Reference
        ``step``, ``ramp``, ``sine`` (Section 6) or any :class:`Reference`.
    duration : float, optional
        Simulated time [s]; default the reference's.
    tracking : str, optional
        ``feedforward`` (default), ``none`` or ``error`` (module docstring).
    feedforward : bool, optional
        Older spelling: True is ``tracking="feedforward"``, False is
        ``tracking="none"``.  Give ``tracking`` or ``feedforward``, not both.

    Returns
    -------
    SimResult
        The response at the samples, with its reference and tracking mode.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import pd_law
    >>> cfg = paper_config()
    >>> res = simulate(pd_law(cfg), cfg.plant, "step")
    >>> bool(abs(res.e[-1]) < 1e-6), res.tracking
    (True, 'feedforward')
    >>> res = simulate(pd_law(cfg), cfg.plant, Reference.sine(2.0, 2.0), tracking="error")
    >>> res.reference.frequency, res.reference.duration
    (2.0, 2.5)
    """
    if feedforward is not None:
        if tracking is not None:
            raise TypeError("give tracking or feedforward, not both")
        tracking = "feedforward" if feedforward else "none"
    tracking = "feedforward" if tracking is None else tracking
    if tracking not in TRACKING:
        raise InputError(f"unknown tracking '{tracking}' (choose from {', '.join(TRACKING)})")
    ref = reference(signal) if isinstance(signal, str) else signal
    if duration is not None:
        ref = replace(ref, duration=float(duration))
    n = int(round(ref.duration / plant.sample_time))
    t = np.arange(n + 1) * plant.sample_time
    r, r_dot = ref.r(t), ref.r_dot(t)
    zero = np.zeros_like(r_dot)
    e2_off = zero if tracking == "none" else r_dot  # what the law subtracts from x2
    u_add = r_dot if tracking == "feedforward" else zero  # what is added to the law's output
    w, a, T = plant.w_max, plant.a, plant.sample_time
    g = -math.expm1(-a * T)
    law_scalar = law.scalar
    # the loop on Python floats (the same IEEE double arithmetic as on numpy scalars,
    # operation for operation, without their per-operation overhead)
    rs, offs, adds = r.tolist(), e2_off.tolist(), u_add.tolist()
    x1, x2, u, region = [0.0] * (n + 1), [0.0] * (n + 1), [0.0] * (n + 1), [0] * (n + 1)
    x1k = x2k = 0.0
    for k in range(n + 1):
        v, region[k] = law_scalar(x1k - rs[k], x2k - offs[k])
        uk = u[k] = min(max(v + adds[k], -w), w)
        if k < n:
            dv = x2k - uk
            x1k = x1[k + 1] = x1k + uk * T + dv * g / a
            x2k = x2[k + 1] = x2k - dv * g
    x1a = np.array(x1, dtype=float)
    return SimResult(
        law.name,
        ref,
        tracking,
        t,
        r,
        r_dot,
        x1a,
        np.array(x2, dtype=float),
        r - x1a,
        np.array(u, dtype=float),
        np.array(region, dtype=np.int8),
    )


@dataclass(frozen=True)
class Mismatch:
    """How the simulated plant and measurement differ from the design.

    The law is always the nominal one; only the plant it drives and what it
    measures change.  The identity mismatch (the default) reproduces the
    nominal loop bit for bit.

    Attributes
    ----------
    a_ratio : float or ndarray, shape (n,)
        True bandwidth over design bandwidth a [-], per state or shared.
    w_max_ratio : float or ndarray, shape (n,)
        The drive saturates at ``w_max_ratio * w_max`` [-] (at or below what the
        law assumes); the commanded input is recorded unclipped.
    delay_samples : int or ndarray of int, shape (n,)
        Computation delay, per state or shared: the input computed from x_k is
        applied from sample k + delay.  Before the first computed input acts, the loop holds the
        input computed from the initial state (the controller was already running).
    position_quantum : float
        Encoder resolution [mm]: the law sees ``q round(x1 / q)`` (0: exact).
    velocity_noise : float
        Standard deviation of Gaussian noise on the measured x2 [mm/s] (0: none).
        One sequence (seeded) is drawn per run and added to every state of the
        batch, so a state's trajectory does not depend on the batch it ran in.
    seed : int
        Seed of the noise sequence.
    """

    a_ratio: float | NDArray[np.float64] = 1.0
    w_max_ratio: float | NDArray[np.float64] = 1.0
    delay_samples: int | NDArray[np.int64] = 0
    position_quantum: float = 0.0
    velocity_noise: float = 0.0
    seed: int = 0

    @property
    def is_identity(self) -> bool:
        """Whether this is the nominal loop (no mismatch of any kind)."""
        return (
            np.all(np.asarray(self.a_ratio) == 1.0)
            and np.all(np.asarray(self.w_max_ratio) == 1.0)
            and np.all(np.asarray(self.delay_samples) == 0)
            and self.position_quantum == 0.0
            and self.velocity_noise == 0.0
        )

    def to_json(self) -> dict:
        """Return the mismatch as a JSON-able dict (arrays as lists)."""

        def num(v):
            v = np.asarray(v, dtype=float)
            return float(v) if v.ndim == 0 else v.tolist()

        return {
            "a_ratio": num(self.a_ratio),
            "w_max_ratio": num(self.w_max_ratio),
            "delay_samples": np.asarray(self.delay_samples, dtype=int).tolist(),
            "position_quantum": float(self.position_quantum),
            "velocity_noise": float(self.velocity_noise),
            "seed": int(self.seed),
        }


@dataclass(frozen=True)
class BatchResult:
    """Regulation to the origin from many initial states.

    Attributes
    ----------
    x1, x2 : ndarray, shape (steps + 1, n)
        States at the samples [mm], [mm/s].
    u : ndarray, shape (steps, n)
        Inputs [mm/s].
    region : ndarray of int8, shape (steps, n)
        Region codes.
    mismatch : Mismatch or None
        The plant/measurement mismatch simulated (None: the nominal loop).
    """

    x1: NDArray[np.float64]
    x2: NDArray[np.float64]
    u: NDArray[np.float64]
    region: NDArray[np.int8]
    mismatch: Mismatch | None = None


def simulate_batch(
    law: Law,
    plant: Plant,
    x1: ArrayLike,
    x2: ArrayLike,
    steps: int,
    *,
    mismatch: Mismatch | None = None,
    out: BatchResult | None = None,
) -> BatchResult:
    """Simulate the sampled loop to the origin from many initial states at once.

    Parameters
    ----------
    law : Law
        Feedback law (its vectorized path is used).
    plant : Plant
        Design plant and sample time (the law's).
    x1, x2 : array_like, shape (n,)
        Initial states [mm], [mm/s].
    steps : int
        Number of samples.
    mismatch : Mismatch, optional
        True plant and measurement relative to ``plant`` (see :class:`Mismatch`);
        None or the identity is the nominal loop, bit for bit.
    out : BatchResult, optional
        A result whose arrays are no longer needed (e.g. the previous chunk's in a
        loop over chunks of states): the nominal loop writes into them when their
        shapes and types fit, which spares the page faults of fresh arrays; the
        values are the same.  Ignored otherwise.

    Returns
    -------
    BatchResult
        The trajectories; ``u`` is the commanded input of each sample.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import pd_law
    >>> cfg = paper_config()
    >>> b = simulate_batch(pd_law(cfg), cfg.plant, [5.0], [0.0], 300)
    >>> bool(abs(b.x1[-1, 0]) < 1e-6)
    True
    >>> slow = simulate_batch(pd_law(cfg), cfg.plant, [5.0], [0.0], 300,
    ...                       mismatch=Mismatch(a_ratio=0.8, delay_samples=1))
    >>> bool(abs(slow.x1[-1, 0]) < 1e-3), bool(slow.x1[40, 0] != b.x1[40, 0])
    (True, True)
    """
    if mismatch is not None and not mismatch.is_identity:
        return replace(
            _simulate_mismatch([(law, x1, x2, mismatch)], plant, steps), mismatch=mismatch
        )
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    n = x1.shape[0]
    if out is not None and _fits(out, steps, n):
        X1, X2, U, R = out.x1, out.x2, out.u, out.region
    else:
        X1, X2 = np.empty((steps + 1, n)), np.empty((steps + 1, n))
        U, R = np.empty((steps, n)), np.empty((steps, n), dtype=np.int8)
    X1[0], X2[0] = x1, x2
    T, a = plant.sample_time, plant.a
    g = -np.expm1(-a * np.float64(T))  # 1 - e^{-aT}, as plant.flow computes it
    dv = np.empty(n)
    for k in range(steps):
        U[k], R[k] = law(X1[k], X2[k])
        # plant.flow in place, the same roundings: x1 + u T + (x2 - u) g / a, x2 - (x2 - u) g
        np.subtract(X2[k], U[k], out=dv)
        dv *= g
        np.subtract(X2[k], dv, out=X2[k + 1])
        np.multiply(U[k], T, out=X1[k + 1])
        X1[k + 1] += X1[k]
        dv /= a
        X1[k + 1] += dv
    return BatchResult(X1, X2, U, R, mismatch)


def _fits(b: BatchResult, steps: int, n: int) -> bool:
    """Whether ``b``'s arrays can hold a nominal run of ``steps`` samples of ``n`` states."""
    arrays = ((b.x1, steps + 1, np.float64), (b.x2, steps + 1, np.float64))
    arrays += ((b.u, steps, np.float64), (b.region, steps, np.int8))
    return all(
        type(v) is np.ndarray
        and v.shape == (rows, n)
        and v.dtype == dt
        and v.flags.c_contiguous
        and v.flags.writeable
        for v, rows, dt in arrays
    )


DELAY_RUN = 512  #: states of one delay in a row read by a row slice, not a gather [-]

Segment = tuple[Law, ArrayLike, ArrayLike, Mismatch | None]
"""One group of :func:`simulate_segments`: (law, x1 [mm], x2 [mm/s], mismatch)."""


def simulate_segments(
    segments: list[Segment],
    plant: Plant,
    steps: int,
) -> BatchResult:
    """Run several :func:`simulate_batch` calls as one: each segment its law, states and mismatch.

    Each state's trajectory is bit for bit the one ``simulate_batch(law, plant, x1,
    x2, steps, mismatch=mismatch)`` gives for its segment (a segment with no or the
    identity mismatch is the nominal loop), but the samples are advanced for all
    states at once and consecutive segments of the same law, or of laws of one
    :class:`~ptoverify.model.laws.LawFamily` (the TO and PTO laws of a plant), share
    one evaluation per sample, so many small batches cost one run's per-sample
    overhead.

    Parameters
    ----------
    segments : list of (Law, array_like, array_like, Mismatch or None)
        Per segment: the law, initial states x1 [mm] and x2 [mm/s] of shape (n_i,),
        and the mismatch (per-state arrays of shape (n_i,) allowed).
    plant : Plant
        Design plant and sample time (the laws').
    steps : int
        Number of samples.

    Returns
    -------
    BatchResult
        The trajectories of all states, segment after segment (``mismatch`` None).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import pd_law, to_law
    >>> cfg = paper_config()
    >>> m = Mismatch(a_ratio=0.9, delay_samples=1)
    >>> both = simulate_segments([(pd_law(cfg), [5.0], [0.0], None),
    ...                           (to_law(cfg), [5.0], [0.0], m)], cfg.plant, 100)
    >>> one = simulate_batch(to_law(cfg), cfg.plant, [5.0], [0.0], 100, mismatch=m)
    >>> bool((both.x1[:, 1] == one.x1[:, 0]).all())
    True
    """
    return _simulate_mismatch(segments, plant, steps)


def _kin(a: Law, b: Law) -> bool:
    """Whether two laws are of one family (evaluated in one call, laws.LawFamily)."""
    return a.family is not None and b.family is not None and a.family.key == b.family.key


def _simulate_mismatch(
    segments: list[Segment],
    plant: Plant,
    steps: int,
) -> BatchResult:
    """Run the loop of :func:`simulate_batch` with true plants and measurement models.

    Vectorized over the states of all segments, each state with its own true a,
    drive limit and delay, each segment with its own quantizer and noise; the
    per-sample work is a fixed sequence of in-place array operations (the same
    roundings as ``plant.flow`` and ``np.clip``), so a state's trajectory does not
    depend on the batch it runs in.  An identity segment is the nominal loop of
    :func:`simulate_batch`: no clipping (its limit is +inf), no measurement model.
    """
    T = plant.sample_time
    segs = []
    start = 0
    for law, s1, s2, m in segments:
        s1 = np.atleast_1d(np.asarray(s1, dtype=float))
        s2 = np.atleast_1d(np.asarray(s2, dtype=float))
        k = s1.shape[0]
        nominal = m is None or m.is_identity
        m = m or Mismatch()
        delay = np.broadcast_to(np.asarray(m.delay_samples), (k,))
        if np.any(delay < 0) or m.position_quantum < 0 or m.velocity_noise < 0:
            raise InputError("mismatch: delay, quantum and noise must be >= 0")
        noisy = m.velocity_noise > 0
        segs.append(
            {
                "law": law,
                "x1": s1,
                "x2": s2,
                "sl": slice(start, start + k),
                "a": plant.a * np.broadcast_to(np.asarray(m.a_ratio, dtype=float), (k,)),
                "w": np.full(k, np.inf)
                if nominal
                else plant.w_max * np.broadcast_to(np.asarray(m.w_max_ratio, dtype=float), (k,)),
                "delay": delay,
                "q": float(m.position_quantum),
                "noise": np.random.default_rng(m.seed).normal(0.0, m.velocity_noise, steps)
                if noisy
                else None,
                # without noise the law sees x2 + 0.0 (the nominal loop: x2), which is x2
                # bit for bit unless x2 is -0.0; x2 - dv is -0.0 only where x2 is, so
                # checking the initial states suffices
                "add_zero": not nominal
                and not noisy
                and bool(np.any((s2 == 0.0) & np.signbit(s2))),
            }
        )
        start += k
    n = start
    X1, X2 = np.empty((steps + 1, n)), np.empty((steps + 1, n))
    U, R = np.empty((steps, n)), np.empty((steps, n), dtype=np.int8)
    cat = (
        (lambda key: np.concatenate([g[key] for g in segs])) if segs else (lambda key: np.empty(0))
    )
    X1[0], X2[0] = cat("x1"), cat("x2")
    a, w_true = cat("a"), cat("w")
    delay = cat("delay").astype(np.int64) if segs else np.zeros(0, np.int64)
    w_neg = -w_true
    g = -np.expm1(-a * T)
    # one law evaluation per run of consecutive segments of the same law, or of laws
    # of one family (laws.LawFamily: each state with its law's parameters); the law
    # sees the raw samples where no segment of the run measures them otherwise
    calls = []
    for seg in segs:
        law = seg["law"]
        if calls and (calls[-1][1][-1]["law"] is law or _kin(calls[-1][1][-1]["law"], law)):
            calls[-1][1].append(seg)
        else:
            calls.append((law, [seg]))
    plan = []
    for law, run in calls:
        sl = slice(run[0]["sl"].start, run[-1]["sl"].stop)
        raw1 = all(seg["q"] == 0 for seg in run)
        raw2 = all(seg["noise"] is None and not seg["add_zero"] for seg in run)
        if all(seg["law"] is law for seg in run):
            fn, params = law.vector, ()
        else:  # the family's function, its parameters one per state
            fn = law.family.vector
            params = tuple(
                np.concatenate(
                    [np.full(seg["x1"].shape[0], seg["law"].family.params[i]) for seg in run]
                )
                for i in range(len(law.family.params))
            )
        plan.append((fn, sl, [seg for seg in run if not raw2], raw1, raw2, params))
    # the quantizer q round(x1 / q), once per sample over consecutive segments of one
    # q: elementwise the same division, rounding and product as segment by segment;
    # states with q = 0 see x1 (copied, as the law's input for them may be y1 too)
    q_runs: list[list] = []
    for seg in segs:
        if q_runs and q_runs[-1][2] == seg["q"]:
            q_runs[-1][1] = seg["sl"].stop
        else:
            q_runs.append([seg["sl"].start, seg["sl"].stop, seg["q"]])
    quantize = any(q > 0 for _, _, q in q_runs)
    q_runs = [(slice(lo, hi), q) for lo, hi, q in q_runs]
    # the delay line: sample k applies U[k - delay] (U[0] before it: the controller
    # was running and held what x_0 commands); per distinct delay, a mask of its states
    values = np.unique(delay).tolist() if n else [0]
    base, mixed = int(values[0]), len(values) > 1
    runs: list[tuple[int, int, int]] = []  # long runs of one delay: (start, stop, delay)
    if mixed:  # a gather U[max(k - delay, 0), state] (no masked operations: on an
        # irregular mask they cost several times a gather), but a row slice for
        # each long run of states of one delay
        edges = [0, *(np.flatnonzero(np.diff(delay)) + 1).tolist(), n]
        runs = [
            (lo, hi, int(delay[lo]))
            for lo, hi in zip(edges[:-1], edges[1:], strict=True)
            if hi - lo >= DELAY_RUN
        ]
        cols = np.arange(n, dtype=np.intp)
        if runs:  # the others, gathered then put in place
            rest = np.ones(n, dtype=bool)
            for lo, hi, _ in runs:
                rest[lo:hi] = False
            cols = np.flatnonzero(rest)
        delay_i = delay[cols].astype(np.intp)
        offset = cols - delay_i * n  # k n + offset once k >= every delay
        d_max = int(delay_i.max()) if cols.size else 0
        w_neg_g = w_neg[cols] if runs else w_neg
        flat_u = U.reshape(-1)
        pick = np.empty(cols.size, dtype=np.intp)
        gathered = np.empty(cols.size)
    y1, y2 = np.empty(n), np.empty(n)
    uk, dv = np.empty(n), np.empty(n)
    for k in range(steps):
        x1k, x2k = X1[k], X2[k]
        uk_row, rk_row = U[k], R[k]
        if quantize:
            for ss, q in q_runs:
                if q > 0:  # q * round(x1 / q)
                    yq = y1[ss]
                    np.divide(x1k[ss], q, out=yq)
                    np.rint(yq, out=yq)
                    yq *= q
                else:
                    y1[ss] = x1k[ss]
        for vector, sl, run, raw1, raw2, params in plan:
            if not raw2:
                for seg in run:
                    ss = seg["sl"]
                    if seg["noise"] is not None:
                        np.add(x2k[ss], seg["noise"][k], out=y2[ss])
                    elif seg["add_zero"]:
                        np.add(x2k[ss], 0.0, out=y2[ss])
                    else:
                        y2[ss] = x2k[ss]
            uk_row[sl], rk_row[sl] = vector(
                x1k[sl] if raw1 else y1[sl], x2k[sl] if raw2 else y2[sl], *params
            )
        # uk = np.clip(applied, -w_true, w_true), the applied input picked per delay
        if mixed:  # U[max(k - delay, 0), state]
            for lo, hi, dl in runs:
                np.maximum(U[max(k - dl, 0), lo:hi], w_neg[lo:hi], out=uk[lo:hi])
            if cols.size:
                if k >= d_max:
                    np.add(offset, k * n, out=pick)
                else:
                    np.subtract(k, delay_i, out=pick)
                    np.maximum(pick, 0, out=pick)
                    pick *= n
                    pick += cols
                np.take(flat_u, pick, out=gathered)
                if runs:
                    np.maximum(gathered, w_neg_g, out=gathered)
                    uk[cols] = gathered
                else:
                    np.maximum(gathered, w_neg, out=uk)
        else:
            np.maximum(U[max(k - base, 0)], w_neg, out=uk)
        np.minimum(uk, w_true, out=uk)
        # plant.flow of the true plant: x2 - (x2 - u) g,  x1 + u T + (x2 - u) g / a
        np.subtract(x2k, uk, out=dv)
        dv *= g
        np.subtract(x2k, dv, out=X2[k + 1])
        x1n = X1[k + 1]
        np.multiply(uk, T, out=x1n)
        x1n += x1k
        dv /= a
        x1n += dv
    return BatchResult(X1, X2, U, R, None)
