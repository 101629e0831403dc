"""The numeric side of the commands whose work is more than one library call.

The command line (:mod:`ptoverify.cli`) parses, calls one function per command
and formats.  Where a command's work composes several numeric steps, the
composition lives here, in the numeric layer (no printing, no files, no
argument parsing): ``simulate`` -> :func:`run_simulation`, ``zone`` ->
:func:`run_zone`.  ``mintime`` calls :func:`ptoverify.groundtruth.verified_mintime`,
``check`` :func:`ptoverify.checks.run_checks`, ``sweep``
:func:`ptoverify.sweep.run_sweep` directly.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ptoverify.config import Config, Plant
from ptoverify.errors import InputError
from ptoverify.exact import exact_metrics
from ptoverify.laws import make_law
from ptoverify.simulate import SimResult, reference, simulate

__all__ = [
    "SimulationRun",
    "run_simulation",
    "run_regulation",
    "run_robust_study",
    "run_zone",
    "mintime_states",
    "MAX_DURATION_S",
]

#: Longest simulated time accepted from a user [s].
MAX_DURATION_S = 100.0


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
        A duration outside (0, ``MAX_DURATION_S``] s or shorter than one sample.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> run = run_simulation(paper_config(), "pd", "step", duration=0.01)
    >>> run.summary()["samples"]
    6
    """
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
    fn = make_law(law, cfg)
    res = simulate(fn, cfg.plant, ref, duration=duration, feedforward=feedforward)
    return SimulationRun(res, fn.note, cfg.plant)


def run_zone(cfg: Config, *, verify: bool = True, outcome: bool = True) -> dict[str, Any]:
    """Return the ``ptoverify zone --json`` object.

    Parameters
    ----------
    cfg : Config
        Configuration.
    verify : bool
        Run the 2-D grid verification of the corrected zone.
    outcome : bool
        Add ``outcome``: the closed loop of both PTO variants.

    Returns
    -------
    dict
        :func:`ptoverify.zones.zone_summary`, plus ``outcome``
        (:func:`ptoverify.properties.zone_outcome`) when asked.
    """
    from ptoverify.properties import zone_outcome
    from ptoverify.zones import zone_summary

    result = zone_summary(cfg, verify=verify)
    if outcome:
        result["outcome"] = zone_outcome(cfg)
    return result


def mintime_states(path: str, cfg: Config) -> dict[str, np.ndarray]:
    """Return the ``mintime --states`` columns for the states of a CSV file.

    Parameters
    ----------
    path : str
        CSV with columns x1 [mm], x2 [mm/s].
    cfg : Config
        Configuration (the plant).

    Returns
    -------
    dict
        :func:`ptoverify.mintime.batch_table`: ``x1``, ``x2``, ``analytic_s``,
        ``switch_time_s``, ``discrete_steps``, ``discrete_s``.
    """
    from ptoverify.mintime import batch_table

    return batch_table(path, cfg)


def run_regulation(
    cfg: Config,
    law: str,
    x0: tuple[float, float],
    *,
    duration: float | None = None,
    a_ratio: float = 1.0,
    w_max_ratio: float = 1.0,
    delay_samples: int = 0,
    position_quantum: float = 0.0,
    velocity_noise: float = 0.0,
    seed: int = 0,
) -> dict[str, Any]:
    """Regulate from ``x0`` to the origin, optionally on a mismatched plant (``simulate --x0``).

    The law is built from ``cfg`` (the design); the plant and measurement follow
    the mismatch (:class:`ptoverify.simulate.Mismatch`).  The properties are those
    of ``ptoverify robust`` (:func:`ptoverify.robust.trajectory_properties`), so a
    counterexample it reports is reproduced here number for number.

    Parameters
    ----------
    cfg : Config
        Nominal configuration.
    law : str
        Law name.
    x0 : tuple of float
        Initial state (x1 [mm], x2 [mm/s]).
    duration : float, optional
        Simulated time [s]; default the robustness horizon.
    a_ratio, w_max_ratio : float
        True a over design a [-]; drive saturation over w_max [-].
    delay_samples : int
        Computation delay [samples].
    position_quantum : float
        Encoder resolution [mm].
    velocity_noise : float
        Velocity-measurement noise standard deviation [mm/s].
    seed : int
        Noise seed.

    Returns
    -------
    dict
        ``law``, ``x0``, ``mismatch``, ``samples``, ``final_state``,
        ``properties`` and ``series`` (``t``, ``x1``, ``x2``, ``u``, ``region``).
    """
    from ptoverify.robust import horizon_steps, trajectory_properties
    from ptoverify.simulate import Mismatch, simulate_batch

    for name, value, lo, hi in (
        ("--a-ratio", a_ratio, 0.01, 100.0),
        ("--w-max-ratio", w_max_ratio, 1e-3, 1.0),
        ("--quantum", position_quantum, 0.0, cfg.plant.position_range),
        ("--velocity-noise", velocity_noise, 0.0, cfg.plant.w_max),
    ):
        if not lo <= value <= hi:
            raise InputError(f"{name} must be in [{lo:g}, {hi:g}], got {value:g}")
    if not 0 <= delay_samples <= 100:
        raise InputError(f"--delay must be in [0, 100] samples, got {delay_samples}")
    p = cfg.plant
    if abs(x0[0]) > 1e3 * p.position_range or abs(x0[1]) > 1e3 * p.w_max:
        raise InputError(f"--x0 ({x0[0]:g}, {x0[1]:g}) is far outside the envelope")
    steps = horizon_steps(cfg)
    if duration is not None:
        if not p.sample_time <= duration <= MAX_DURATION_S:
            raise InputError(
                f"--duration must be in [{p.sample_time:g}, {MAX_DURATION_S:g}] s, got {duration:g}"
            )
        steps = int(round(duration / p.sample_time))
    m = Mismatch(
        a_ratio=a_ratio,
        w_max_ratio=w_max_ratio,
        delay_samples=delay_samples,
        position_quantum=position_quantum,
        velocity_noise=velocity_noise,
        seed=seed,
    )
    fn = make_law(law, cfg)
    b = simulate_batch(fn, p, [x0[0]], [x0[1]], steps, mismatch=m)
    props = trajectory_properties(
        law, cfg, np.array([x0[0]]), np.array([x0[1]]), m, steps=steps, batch=b
    )
    t = np.arange(steps + 1) * p.sample_time
    return {
        "law": law,
        "note": fn.note,
        "x0": [float(x0[0]), float(x0[1])],
        "mismatch": m.to_json(),
        "samples": steps + 1,
        "final_state": [float(b.x1[-1, 0]), float(b.x2[-1, 0])],
        "properties": {k: float(v[0]) for k, v in props.items()},
        "series": {
            "t": t,
            "x1": b.x1[:, 0],
            "x2": b.x2[:, 0],
            "u": np.append(b.u[:, 0], np.nan),
            "region": np.append(b.region[:, 0], -1),
        },
    }


def run_robust_study(
    cfg: Config,
    *,
    grid: int = 15,
    dask: str | None = None,
    laws: tuple[str, ...] | None = None,
    generations: int = 12,
    population: int = 24,
    progress: Callable[[str, float], None] | None = None,
) -> dict[str, Any]:
    """Return the ``ptoverify robust --json`` object.

    Parameters
    ----------
    cfg : Config
        Nominal configuration with its ``[robustness]`` box.
    grid : int
        Initial states per axis of the maps.
    dask : str, optional
        Scheduler address or ``local`` (None: in-process).
    laws : tuple of str, optional
        Laws studied (default: to, pd, pto, pto-printed).
    generations, population : int
        Differential-evolution generations and candidates per generation of
        each worst-case search.
    progress : callable, optional
        ``progress(stage, fraction)``.

    Returns
    -------
    dict
        ``box``, ``margins``, ``worst``, ``maps``, ``most_robust``, ``timings_s``, ``backend``.
    """
    from ptoverify.robust import LAWS, RobustSettings, run_robust

    settings = RobustSettings(
        n1=grid,
        n2=grid,
        laws=laws or LAWS,
        search_iterations=generations,
        search_population=population,
    )
    return run_robust(cfg, settings, dask=dask, progress=progress).to_json()
