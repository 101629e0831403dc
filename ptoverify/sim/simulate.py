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

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Plant
from ptoverify.errors import InputError
from ptoverify.model.laws import Law
from ptoverify.sim.reference import SIGNALS, Reference, reference

__all__ = [
    "RUN_BYTES",
    "chunk_states",
    "TRACKING",
    "Reference",
    "reference",
    "SIGNALS",
    "SimResult",
    "simulate",
    "simulate_loops",
    "BatchResult",
    "Mismatch",
    "simulate_batch",
    "simulate_parts",
]


TRACKING = ("feedforward", "none", "error")
"""Tracking modes of :func:`simulate` (see the module docstring)."""


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
    return simulate_loops(
        law, plant, 1, signal, duration=duration, tracking=tracking, feedforward=feedforward
    )[0]


def simulate_loops(
    law: Law,
    plant: Plant,
    loops: int,
    signal: str | Reference = "step",
    *,
    duration: float | None = None,
    tracking: str | None = None,
    feedforward: bool | None = None,
) -> list[SimResult]:
    """Simulate ``loops`` closed loops side by side, each tracking the reference from rest.

    :func:`simulate` is this with one loop.  The law is evaluated on the states of
    all loops at once, loop i being state i of its batch (a law with one gain set
    per state, :func:`ptoverify.model.laws.with_state_gains`, drives loop i with gain
    set i).  Every step of the loop is elementwise over the states, so each loop's
    response is the one :func:`simulate` gives for it alone.

    Parameters
    ----------
    law : Law
        Feedback law for ``loops`` states.
    plant : Plant
        Plant and sample time.
    loops : int
        Number of loops, >= 1.
    signal : str or Reference
        ``step``, ``ramp``, ``sine`` (Section 6) or any :class:`Reference`.
    duration : float, optional
        Simulated time [s]; default the reference's.
    tracking : str, optional
        ``feedforward`` (default), ``none`` or ``error`` (module docstring).
    feedforward : bool, optional
        Older spelling of ``tracking`` (see :func:`simulate`).

    Returns
    -------
    list of SimResult
        One response per loop, in order (their ``t``, ``r`` and ``r_dot`` are one
        shared array each).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> from ptoverify.model.laws import with_state_gains
    >>> cfg = paper_config()
    >>> law = with_state_gains("pd", cfg, {"kp": [100.0, 200.0], "kd": [0.1, 0.2]})
    >>> a, b = simulate_loops(law, cfg.plant, 2, "step")
    >>> bool(a.x1[10] < b.x1[10])
    True
    """
    if feedforward is not None:
        if tracking is not None:
            raise TypeError("give tracking or feedforward, not both")
        tracking = "feedforward" if feedforward else "none"
    tracking = "feedforward" if tracking is None else tracking
    if tracking not in TRACKING:
        raise InputError(f"unknown tracking '{tracking}' (choose from {', '.join(TRACKING)})")
    if loops < 1:
        raise InputError(f"loops must be >= 1, got {loops}")
    ref = reference(signal) if isinstance(signal, str) else signal
    if duration is not None:
        ref = replace(ref, duration=float(duration))
    n = int(round(ref.duration / plant.sample_time))
    t = np.arange(n + 1) * plant.sample_time
    r, r_dot = ref.r(t), ref.r_dot(t)
    zero = np.zeros_like(r_dot)
    e2_off = zero if tracking == "none" else r_dot  # what the law subtracts from x2
    u_add = r_dot if tracking == "feedforward" else zero  # what is added to the law's output
    w = plant.w_max

    def controller(k: int, y1: NDArray, y2: NDArray) -> tuple[NDArray, NDArray]:
        v, region = law.vector(y1 - r[k], y2 - e2_off[k])
        return np.minimum(np.maximum(v + u_add[k], -w), w), region  # np.clip(., -w, w)

    X1, X2, U, R = _loop(controller, plant, np.zeros(loops), np.zeros(loops), n, Mismatch())
    out = []
    for j in range(loops):
        x1 = X1[:, j].copy()
        out.append(
            SimResult(
                law.name,
                ref,
                tracking,
                t,
                r,
                r_dot,
                x1,
                X2[:, j].copy(),
                r - x1,
                U[:, j].copy(),
                R[:, j].copy(),
            )
        )
    return out


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
) -> BatchResult:
    """Simulate the sampled loop to the origin from many initial states at once.

    This is the suite's one simulator: :func:`simulate` (one state tracking a
    reference) and :func:`simulate_parts` (several laws and mismatches) run
    the same loop.

    Parameters
    ----------
    law : Law
        Feedback law (its vectorized path).
    plant : Plant
        Design plant and sample time (the law's).
    x1, x2 : array_like, shape (n,)
        Initial states [mm], [mm/s].
    steps : int
        Number of samples.
    mismatch : Mismatch, optional
        True plant and measurement relative to ``plant`` (see :class:`Mismatch`);
        None is the identity: the nominal loop.

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
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float))
    m = Mismatch() if mismatch is None else mismatch

    def controller(k: int, y1: NDArray, y2: NDArray) -> tuple[NDArray, NDArray]:
        return law.vector(y1, y2)

    X1, X2, U, R = _loop(controller, plant, x1, x2, int(steps), m)
    return BatchResult(X1, X2, U[:-1], R[:-1], mismatch)


def _loop(
    controller: Callable[[int, NDArray, NDArray], tuple[NDArray, NDArray]],
    plant: Plant,
    x1: NDArray,
    x2: NDArray,
    steps: int,
    m: Mismatch,
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Step the sampled loop for a batch of states: the one simulator loop.

    At each sample k the controller sees the measured state (``m``'s quantizer
    and noise), its command is recorded in row k of U, and the drive applies
    the command of sample max(k - delay, 0) (per state), clipped to the true
    limit ``w_max_ratio * w_max``, for one period of the true plant (bandwidth
    ``a_ratio * a``), exactly (eq. 7).  The command at the last sample is
    computed but not applied.  Returns X1, X2 of shape (steps + 1, n) [mm],
    [mm/s], U [mm/s] and R (region codes) of shape (steps + 1, n).
    """
    n = x1.shape[0]
    if x2.shape != (n,) or x1.ndim != 1:
        raise InputError("x1 and x2 must be 1-D arrays of one length")
    if steps < 0:
        raise InputError(f"steps must be >= 0, got {steps}")
    delay = np.broadcast_to(np.asarray(m.delay_samples), (n,)).astype(np.intp)
    if np.any(delay < 0) or m.position_quantum < 0 or m.velocity_noise < 0:
        raise InputError("mismatch: delay, quantum and noise must be >= 0")
    T = plant.sample_time
    a = plant.a * np.broadcast_to(np.asarray(m.a_ratio, dtype=float), (n,))
    w = plant.w_max * np.broadcast_to(np.asarray(m.w_max_ratio, dtype=float), (n,))
    g = -np.expm1(-a * T)  # 1 - e^{-aT}, as plant.flow computes it
    q = float(m.position_quantum)
    noisy = m.velocity_noise > 0
    noise = (
        np.random.default_rng(m.seed).normal(0.0, m.velocity_noise, steps + 1) if noisy else None
    )
    X1, X2 = np.empty((steps + 1, n)), np.empty((steps + 1, n))
    U, R = np.empty((steps + 1, n)), np.empty((steps + 1, n), dtype=np.int8)
    X1[0], X2[0] = x1, x2
    held = _held_inputs(U, delay)
    lo = -w
    for k in range(steps + 1):
        y1 = q * np.rint(X1[k] / q) if q > 0 else X1[k]
        U[k], R[k] = controller(k, y1, X2[k] + noise[k] if noisy else X2[k])
        if k == steps:
            break
        # clipped to the true limit (np.clip's arithmetic, without its per-call dispatch)
        uk = np.minimum(np.maximum(U[k] if held is None else held(k), lo), w)
        dv = (X2[k] - uk) * g  # plant.flow: x1 + u T + (x2 - u) g / a, x2 - (x2 - u) g
        X2[k + 1] = X2[k] - dv
        X1[k + 1] = X1[k] + uk * T + dv / a
    return X1, X2, U, R


def _held_inputs(U: NDArray, delay: NDArray) -> Callable[[int], NDArray] | None:
    """Return ``k -> U[max(k - delay, 0), state]`` per state (None: no delay anywhere).

    The command each state's drive applies at sample k, gathered from the flattened
    array at max(k - delay, 0) n + state = max((k - delay) n + state, state): the same
    selection as ``U[np.maximum(k - delay, 0), np.arange(n)]`` at half its cost.
    """
    if not np.any(delay):
        return None
    n = delay.shape[0]
    flat, cols = U.reshape(-1), np.arange(n)
    start = cols - delay * n
    return lambda k: flat.take(np.maximum(start + k * n, cols))


#: Most bytes of one trajectory array [bytes] a study that only reduces trajectories (counts,
#: maxima) lets one run allocate.  Below glibc's largest dynamic mmap threshold (32 MiB), a
#: freed run's arrays are reused by the next run instead of being mapped afresh: fresh
#: memory is zeroed by the kernel, 2 MiB at a time where NumPy asks for huge pages, and
#: that cost 12 s of the report's tuning stage in whole-grid runs (issue 23, measured).
RUN_BYTES = 24 * 2**20


def chunk_states(steps: int, run_bytes: int = RUN_BYTES) -> int:
    """Return how many states one run of ``steps`` samples may hold (at least 1).

    Each state's trajectory does not depend on the others in its batch, so a study
    that reduces trajectories may simulate its states in runs of this size and
    add the results up: the same numbers, in less fresh memory.

    Parameters
    ----------
    steps : int
        Samples per trajectory.
    run_bytes : int
        Most bytes of one (steps + 1, n) float64 array [bytes].

    Returns
    -------
    int
        States per run.

    Examples
    --------
    >>> chunk_states(1167), chunk_states(10**9)
    (2693, 1)
    """
    return max(1, int(run_bytes) // (8 * (int(steps) + 1)))


Segment = tuple[Law, ArrayLike, ArrayLike, Mismatch | None]
"""One group of :func:`simulate_parts`: (law, x1 [mm], x2 [mm/s], mismatch)."""


def simulate_parts(
    segments: list[Segment],
    plant: Plant,
    steps: int,
) -> list[BatchResult]:
    """Run :func:`simulate_batch` for each segment; one result per segment.

    The segments of one law and one noise-free measurement model run as one batch
    (each state's trajectory does not depend on the batch it runs in); each result
    is a view of that batch's arrays, so nothing is copied.

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
    list of BatchResult
        The trajectories of each segment, in order (``mismatch`` None).
    """
    if not segments:
        return []
    # segments of one law and one noise-free measurement model run as one batch, their
    # a ratio, drive limit and delay per state (a state's trajectory does not depend on
    # the batch it runs in); a noisy segment keeps its own call (its own noise stream)
    groups: dict[tuple, list[int]] = {}
    for i, (law, _s1, _s2, m) in enumerate(segments):
        m = m or Mismatch()
        key = (id(law), m.position_quantum) if m.velocity_noise == 0 else ("noisy", i)
        groups.setdefault(key, []).append(i)
    parts: dict[int, BatchResult] = {}
    for members in groups.values():
        law = segments[members[0]][0]
        s1 = [np.atleast_1d(np.asarray(segments[i][1], dtype=float)) for i in members]
        s2 = [np.atleast_1d(np.asarray(segments[i][2], dtype=float)) for i in members]
        ms = [segments[i][3] or Mismatch() for i in members]
        if len(members) == 1:
            parts[members[0]] = simulate_batch(law, plant, s1[0], s2[0], steps, mismatch=ms[0])
            continue

        def per_state(field: str, dtype: type) -> NDArray:
            return np.concatenate(
                [
                    np.broadcast_to(np.asarray(getattr(m, field), dtype=dtype), x.shape)
                    for m, x in zip(ms, s1, strict=True)
                ]
            )

        merged = Mismatch(
            a_ratio=per_state("a_ratio", float),
            w_max_ratio=per_state("w_max_ratio", float),
            delay_samples=per_state("delay_samples", np.int64),
            position_quantum=ms[0].position_quantum,
        )
        run = simulate_batch(
            law, plant, np.concatenate(s1), np.concatenate(s2), steps, mismatch=merged
        )
        start = 0
        for i, x in zip(members, s1, strict=True):
            sl = slice(start, start + x.shape[0])
            parts[i] = BatchResult(run.x1[:, sl], run.x2[:, sl], run.u[:, sl], run.region[:, sl])
            start += x.shape[0]
    return [parts[i] for i in range(len(segments))]
