"""Robustness in a drive's terms: short sweeps of encoder quantum and velocity noise.

What a drive engineer asks after "does it work on the nominal plant": how coarse
may the encoder be, and how noisy the velocity measurement, before the law
stops holding its position?  For each law (built from the nominal
configuration) and each point of a short sweep -- the encoder quantum q with
no noise, then the velocity noise sigma at the configuration's quantum -- every
state of a small envelope grid (plus moves from rest) is simulated on the
nominal plant, the law seeing ``q round(x1 / q)`` and ``x2 + noise``
(:class:`ptoverify.sim.simulate.Mismatch`, one seeded noise sequence per run),
and measured on the true state:

* ``residual_mm``: the largest |x1| over the last quarter of the horizon, worst
  over the states: the standstill error or jitter the axis keeps;
* ``not_settled``: states that never settle under the named definition
  :data:`SETTLING` (``box-0p01mm``: |x1| <= 0.01 mm, |x2| <= a 0.01 mm/s held
  50 ms, read on the samples: :func:`ptoverify.sim.settling.grid_settling`);
* ``worst_settling_s``: the longest settling time over the states that settle.

Nothing here is tuned: the sweep shows where each law's standstill degrades.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import grid_settling
from ptoverify.sim.simulate import Mismatch, simulate_batch
from ptoverify.studies.robust.maps import (
    RobustSettings,
    horizon_steps,
    map_states,
    nominal_law,
)

__all__ = [
    "SETTLING",
    "QUANTA_MM",
    "NOISES_MM_S",
    "DrivePoint",
    "DriveSweeps",
    "drive_sweeps",
]

#: The settling definition of the sweeps (the robustness maps', by name).
SETTLING = "box-0p01mm"
#: Encoder quanta swept [mm]: exact, 1 um, 5 um, 20 um, 50 um (d = 0.5 mm at the paper's values).
QUANTA_MM = (0.0, 0.001, 0.005, 0.02, 0.05)
#: Velocity noise levels swept (standard deviation) [mm/s].
NOISES_MM_S = (0.3, 1.0, 3.0, 10.0)


@dataclass(frozen=True)
class DrivePoint:
    """One law at one measurement condition.

    Attributes
    ----------
    law : str
        Law name.
    position_quantum_mm : float
        Encoder quantum the law sees [mm] (0: exact).
    velocity_noise_mm_s : float
        Standard deviation of the noise on the measured x2 [mm/s].
    residual_mm : float
        Largest |x1| over the last quarter of the horizon, worst state [mm].
    not_settled : int
        States that never settle under :data:`SETTLING` [-].
    worst_settling_s : float
        Longest settling time of the states that settle [s] (nan: none settles).
    """

    law: str
    position_quantum_mm: float
    velocity_noise_mm_s: float
    residual_mm: float
    not_settled: int
    worst_settling_s: float


@dataclass(frozen=True)
class DriveSweeps:
    """The measurement sweeps of every law.

    Attributes
    ----------
    settling : str
        Name of the settling definition (:data:`ptoverify.sim.settling.DEFINITIONS`).
    states : int
        Initial states per point [-].
    horizon_s : float
        Simulated time per trajectory [s].
    seed : int
        Seed of the noise sequences.
    base_quantum_mm : float
        The configuration's quantum, held during the noise sweep [mm].
    points : tuple of DrivePoint
        Per law: the quantum sweep (no noise), then the noise sweep.
    """

    settling: str
    states: int
    horizon_s: float
    seed: int
    base_quantum_mm: float
    points: tuple[DrivePoint, ...]

    def to_json(self) -> dict[str, Any]:
        """Return the JSON form (``results.json`` key ``robust.drive``).

        Returns
        -------
        dict
            The attributes, ``points`` as a list of dicts (NaN as None).
        """

        def clean(v: Any) -> Any:
            return None if isinstance(v, float) and not math.isfinite(v) else v

        return {
            "settling": self.settling,
            "states": self.states,
            "horizon_s": self.horizon_s,
            "seed": self.seed,
            "base_quantum_mm": self.base_quantum_mm,
            "points": [{k: clean(v) for k, v in p.__dict__.items()} for p in self.points],
        }


def _point(law: str, cfg: Config, x1, x2, steps: int, mismatch: Mismatch) -> DrivePoint:
    """Simulate one law from every state under ``mismatch`` and measure it."""
    b = simulate_batch(nominal_law(law, cfg), cfg.plant, x1, x2, steps, mismatch=mismatch)
    tail = b.x1[-max(20, steps // 4) :]
    t = np.arange(steps + 1) * cfg.plant.sample_time
    settled = grid_settling(Trajectory(t, b.x1, b.x2, b.u, cfg.plant.a), None, SETTLING)
    ok = ~np.isnan(settled)
    return DrivePoint(
        law=law,
        position_quantum_mm=float(mismatch.position_quantum),
        velocity_noise_mm_s=float(mismatch.velocity_noise),
        residual_mm=float(np.abs(tail).max()),
        not_settled=int((~ok).sum()),
        worst_settling_s=float(settled[ok].max()) if ok.any() else math.nan,
    )


def drive_sweeps(
    cfg: Config,
    laws: tuple[str, ...] = ("pd", "pto"),
    quanta: tuple[float, ...] = QUANTA_MM,
    noises: tuple[float, ...] = NOISES_MM_S,
    grid: int = 7,
    seed: int = 0,
) -> DriveSweeps:
    """Sweep the encoder quantum and the velocity noise for each law.

    Parameters
    ----------
    cfg : Config
        Nominal configuration (its ``[robustness]`` quantum is held during the
        noise sweep).
    laws : tuple of str
        Laws (names of :func:`ptoverify.model.laws.make_law`).
    quanta : tuple of float
        Encoder quanta [mm], each >= 0.
    noises : tuple of float
        Velocity noise standard deviations [mm/s], each >= 0.
    grid : int
        The envelope grid is ``grid`` x ``grid`` states, plus 20 moves from rest [-].
    seed : int
        Seed of the noise sequence (one per run, shared by the states).

    Returns
    -------
    DriveSweeps
        One point per law and condition.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> out = drive_sweeps(paper_config(), laws=("pd",), quanta=(0.0,), noises=(), grid=3)
    >>> out.points[0].not_settled, out.points[0].residual_mm < 0.01
    (0, True)
    """
    x1, x2 = map_states(cfg, RobustSettings(n1=grid, n2=grid))
    steps = horizon_steps(cfg)
    q0 = float(cfg.robustness.position_quantum)
    points = []
    for law in laws:
        for q in quanta:
            points.append(_point(law, cfg, x1, x2, steps, Mismatch(position_quantum=q)))
        for v in noises:
            mm = Mismatch(position_quantum=q0, velocity_noise=v, seed=seed)
            points.append(_point(law, cfg, x1, x2, steps, mm))
    return DriveSweeps(
        settling=SETTLING,
        states=int(x1.size),
        horizon_s=steps * cfg.plant.sample_time,
        seed=seed,
        base_quantum_mm=q0,
        points=tuple(points),
    )
