"""Simulate a named law on a Section 6 reference: the path of ``ptoverify simulate``.

Catalogue
---------
SimulationRun   a simulated closed loop with the law's note and its summary figures
run_simulation  simulate a named law on a step, ramp or sine reference
run_loops       the same for loops of one law object side by side (many gain sets)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ptoverify.config import Config, Plant
from ptoverify.errors import InputError
from ptoverify.model.laws import Law, make_law
from ptoverify.sim.exact import exact_metrics
from ptoverify.sim.simulate import SimResult, reference, simulate_loops

__all__ = [
    "SimulationRun",
    "run_simulation",
    "run_loops",
    "check_samples",
    "MAX_DURATION_S",
    "MAX_SAMPLES",
]


#: Longest simulated time accepted from a user [s].
MAX_DURATION_S = 100.0

#: Most samples one user-requested simulation may take (about 15 s of one core; the
#: paper's 100 s at T = 2 ms is 50,000).  A fine sample time with a long default
#: duration (0.2 s at T = 1e-7 s is 2e6 samples) would otherwise run without bound.
MAX_SAMPLES = 100_000


def check_samples(duration: float, sample_time: float, what: str) -> int:
    """Return the number of samples of ``duration``; reject more than ``MAX_SAMPLES``.

    Parameters
    ----------
    duration : float
        Simulated time [s].
    sample_time : float
        Sample time T [s].
    what : str
        How the duration was chosen, named in the error (e.g. ``"--duration 3"``).

    Returns
    -------
    int
        ``round(duration / sample_time)`` samples.

    Raises
    ------
    InputError
        More than ``MAX_SAMPLES`` samples.
    """
    samples = duration / sample_time
    if samples > MAX_SAMPLES:
        raise InputError(
            f"{what} is {samples:.3g} samples of T = {sample_time:g} s, more than the limit "
            f"of {MAX_SAMPLES:,}: give a shorter --duration (at most {MAX_SAMPLES * sample_time:g} s)"
        )
    return int(round(samples))


@dataclass(frozen=True, eq=False)
class SimulationRun:
    """A simulated closed loop with the law's note and its summary figures.

    Attributes
    ----------
    result : SimResult
        The sampled closed-loop response.
    note : str
        What the law is (e.g. which omega0 the PTO law uses).
    plant : Plant
        The simulated plant (a [rad/s] for the flow between samples).
    """

    result: SimResult
    note: str
    plant: Plant

    def summary(self) -> dict[str, Any]:
        """Return the summary of ``ptoverify simulate --json`` (without the series).

        Returns
        -------
        dict
            ``law``, ``signal``, ``feedforward``, ``note``, ``samples``,
            ``final_error_mm`` [mm] and ``max_abs_error_second_half_mm`` [mm]
            (largest |r - x1| over the second half of the samples).
        """
        res = self.result
        tail = res.e[len(res.e) // 2 :]
        return {
            "law": res.law,
            "signal": res.signal,
            "feedforward": res.feedforward,
            "note": self.note,
            "samples": len(res.t),
            "final_error_mm": float(res.e[-1]),
            "max_abs_error_second_half_mm": float(np.abs(tail).max()),
        }

    def metrics(self) -> tuple[dict[str, float | None], dict[str, float | None]]:
        """Return the DESIGN.md metrics between samples and the same on the sample grid.

        Returns
        -------
        tuple of dict
            ``overshoot_mm`` [mm], ``settling_2pct_s``, ``settling_0p01mm_s``,
            ``rise_time_s`` [s], and ``phase_delay_deg`` [deg] for a sine (None where
            undefined): measured on the exact trajectory, then on the samples.
        """
        em = exact_metrics(self.result, self.plant, self.result.reference)
        return em.json_metrics(), em.json_metrics(grid=True)

    def to_json(self) -> dict[str, Any]:
        """Return the ``ptoverify simulate --json`` object: summary, metrics and ``series``."""
        metrics, grid = self.metrics()
        return {
            **self.summary(),
            "metrics": metrics,
            "metrics_grid": grid,
            "series": self.result.columns(),
        }


def run_simulation(
    cfg: Config,
    law: str,
    signal: str,
    *,
    duration: float | None = None,
    feedforward: bool = True,
    step: float | None = None,
    ramp_speed: float | None = None,
    ramp_to: float | None = None,
    amplitude: float | None = None,
    frequency: float | None = None,
) -> SimulationRun:
    """Simulate a named law on a Section 6 reference (``ptoverify simulate``).

    Parameters
    ----------
    cfg : Config
        Configuration.
    law : str
        Law name (``to``, ``pd``, ``pto``, ``pto-printed``).
    signal : str
        Reference (``step``, ``ramp``, ``sine``).
    duration : float, optional
        Simulated time [s], in [T, ``MAX_DURATION_S``]; default per signal.
    feedforward : bool
        Feed the reference velocity forward.
    step : float, optional
        Step height [mm] (default Section 6's 5 mm).
    ramp_speed, ramp_to : float, optional
        Ramp speed [mm/s] and target [mm] (default 200 mm/s to 30 mm).
    amplitude, frequency : float, optional
        Sine amplitude [mm] and frequency [Hz] (default 5 mm, 5 Hz).

    Returns
    -------
    SimulationRun
        The response, the law's note and the summary.

    Raises
    ------
    InputError
        A duration outside (0, ``MAX_DURATION_S``] s, shorter than one sample or longer
        than ``MAX_SAMPLES`` samples.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> run = run_simulation(paper_config(), "pd", "step", duration=0.01)
    >>> run.summary()["samples"]
    6
    """
    ref = _checked_reference(cfg, signal, duration, step, ramp_speed, ramp_to, amplitude, frequency)
    return _runs(cfg, make_law(law, cfg), 1, ref, duration, feedforward)[0]


def run_loops(
    cfg: Config,
    law: Law,
    loops: int,
    signal: str,
    *,
    duration: float | None = None,
    feedforward: bool = True,
) -> list[SimulationRun]:
    """Simulate ``loops`` closed loops of one law object side by side (:func:`run_simulation`'s path).

    :func:`run_simulation` is this with the named law and one loop: the same checks
    of the duration, the same simulation (:func:`ptoverify.sim.simulate.simulate_loops`,
    each loop's response the one it gives alone).  For measuring many gain sets of
    a law at once (a law with one gain set per loop,
    :func:`ptoverify.model.laws.with_state_gains`).

    Parameters
    ----------
    cfg : Config
        Configuration (the plant).
    law : Law
        The law, for ``loops`` states (loop i is state i).
    loops : int
        Number of loops, >= 1.
    signal : str
        Reference (``step``, ``ramp``, ``sine``; Section 6's).
    duration : float, optional
        Simulated time [s], as :func:`run_simulation`.
    feedforward : bool
        Feed the reference velocity forward.

    Returns
    -------
    list of SimulationRun
        One per loop, in order.

    Raises
    ------
    InputError
        A duration :func:`run_simulation` refuses.
    """
    ref = _checked_reference(cfg, signal, duration, None, None, None, None, None)
    return _runs(cfg, law, loops, ref, duration, feedforward)


def _checked_reference(
    cfg: Config,
    signal: str,
    duration: float | None,
    step: float | None,
    ramp_speed: float | None,
    ramp_to: float | None,
    amplitude: float | None,
    frequency: float | None,
):
    """Return the reference of :func:`run_simulation`'s arguments, after its checks."""
    if duration is not None:
        if not 0 < duration <= MAX_DURATION_S:
            raise InputError(f"--duration must be in (0, {MAX_DURATION_S:g}] s, got {duration:g}")
        if duration < cfg.plant.sample_time:
            raise InputError(
                f"--duration {duration:g} s is shorter than one sample "
                f"(T = {cfg.plant.sample_time:g} s)"
            )
    ref = reference(
        signal,
        step=step,
        ramp_speed=ramp_speed,
        ramp_to=ramp_to,
        amplitude=amplitude,
        frequency=frequency,
    )
    what = (
        f"--duration {duration:g} s"
        if duration is not None
        else f"the {signal}'s default duration {ref.duration:g} s"
    )
    check_samples(ref.duration if duration is None else duration, cfg.plant.sample_time, what)
    return ref


def _runs(
    cfg: Config, fn: Law, loops: int, ref, duration: float | None, feedforward: bool
) -> list[SimulationRun]:
    """Simulate ``loops`` loops of ``fn`` on ``ref``: the simulation of :func:`run_simulation`."""
    results = simulate_loops(fn, cfg.plant, loops, ref, duration=duration, feedforward=feedforward)
    return [SimulationRun(res, fn.note, cfg.plant) for res in results]
