"""The numeric side of the commands whose work is more than one library call.

The command line (:mod:`ptoverify.cli`) parses, calls one function per command
and formats.  Where a command's work composes several numeric steps, the
composition lives here, in the numeric layer (no printing, no files, no
argument parsing): ``simulate`` -> :func:`run_simulation`, ``zone`` ->
:func:`run_zone`.  ``mintime`` calls :func:`ptoverify.studies.groundtruth.verified_mintime`,
``check`` :func:`ptoverify.studies.checks.run_checks`, ``sweep``
:func:`ptoverify.studies.sweep.run_sweep` directly.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law
from ptoverify.sim.runs import MAX_DURATION_S, check_samples

__all__ = [
    "run_regulation",
    "run_robust_study",
    "run_zone",
    "mintime_states",
    "MAX_DURATION_S",
]


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
        :func:`ptoverify.model.zones.zone_summary`, plus ``outcome``
        (:func:`ptoverify.studies.properties.zone_outcome`) when asked.
    """
    from ptoverify.model.zones import zone_summary
    from ptoverify.studies.properties import zone_outcome

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
        :func:`ptoverify.model.mintime.batch_table`: ``x1``, ``x2``, ``analytic_s``,
        ``switch_time_s``, ``discrete_steps``, ``discrete_s``.
    """
    from ptoverify.model.mintime import batch_table

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
    the mismatch (:class:`ptoverify.sim.simulate.Mismatch`).  The properties are those
    of ``ptoverify robust`` (:func:`ptoverify.studies.robust.trajectory_properties`), so a
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
    from ptoverify.sim.simulate import Mismatch, simulate_batch
    from ptoverify.studies.robust import horizon_steps, trajectory_properties

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
    what = "the default horizon" if duration is None else f"--duration {duration:g} s"
    check_samples(steps * p.sample_time, p.sample_time, what)
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
    from ptoverify.studies.robust import LAWS, RobustSettings, run_robust

    settings = RobustSettings(
        n1=grid,
        n2=grid,
        laws=laws or LAWS,
        search_iterations=generations,
        search_population=population,
    )
    return run_robust(cfg, settings, dask=dask, progress=progress).to_json()
