"""The baselines tuned fairly, and the paper's claim that PTOS "cannot be directly used".

PTOS (alpha, k) and the cascade P loop (kp) are tuned by ``ptoverify tune``
itself (:func:`ptoverify.studies.tune.fair_tunings`: the search, constraints and
bounds that tune PD and PTO): the 2 % settling time of the Section 6 step is
minimized subject to the step's overshoot between samples <= a bound, a stable
sampled linear loop and no limit cycle on the gates' grid.

The claim (Section 1: "the PTOS and its various improvements on the double
integrator system cannot be directly used") is tested under each reading of a
(2 pi 30 rad/s and 30 rad/s): PTOS is measured at its configured gains and at
its best tuning under each of the fair comparison's overshoot bounds (the PTO's
and the PD's overshoot at the paper's gains): stride-overs of the switching
curve (the linear region |x1| <= y_l playing the PTO's linear zone), limit
cycles and unsettled states on the grid, overshoot and settling of the step.
PTOS is *usable* at a setting when it has no limit cycle, settles from every
grid state, never strides over, and meets the bound.  The claim is
``reproduced`` under a reading when PTOS is usable at none of its settings,
``not reproduced`` otherwise.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.baselines import ptos_design
from ptoverify.model.laws import make_law
from ptoverify.studies.properties import law_properties
from ptoverify.studies.tune import response_metrics

__all__ = [
    "PTOSMeasure",
    "PTOSClaim",
    "ptos_claim",
    "READINGS",
    "reading_config",
    "fair_configs",
]

#: Readings of the printed bandwidth: a = 2 pi f, or a = f taken as rad/s.
READINGS = ("2pi", "hz")


@dataclass(frozen=True)
class PTOSMeasure:
    """PTOS at one setting under one reading.

    Attributes
    ----------
    reading : str
        ``2pi`` (a = 2 pi f) or ``hz`` (a = f rad/s).
    a : float
        Bandwidth [rad/s].
    setting : str
        ``configured``, or ``tuned <bound name>`` (alpha and k tuned by
        :func:`ptoverify.studies.tune.fair_tunings`).
    alpha, k, y_l : float
        Discount [-], velocity-loop gain [1/s], linear-region half-width [mm].
    bound_mm : float
        Overshoot bound of the step [mm].
    stride_overs, states_with_stride_over, limit_cycles, not_settled, overshoots : int
        Grid properties (:class:`ptoverify.studies.properties.LawProperties`).
    max_overshoot_grid_mm : float
        Largest overshoot of the grid's rest states [mm].
    step_overshoot_mm, step_settling_2pct_s, step_settling_0p01mm_s : float
        The Section 6 step [mm], [s], [s].
    pto_settling_2pct_s : float
        The corrected PTO's 2 % settling of the step at the paper's gains [s].
    usable : bool
        The module docstring's criterion.
    """

    reading: str
    a: float
    setting: str
    alpha: float
    k: float
    y_l: float
    bound_mm: float
    stride_overs: int
    states_with_stride_over: int
    limit_cycles: int
    not_settled: int
    overshoots: int
    max_overshoot_grid_mm: float
    step_overshoot_mm: float
    step_settling_2pct_s: float
    step_settling_0p01mm_s: float
    pto_settling_2pct_s: float
    usable: bool


@dataclass(frozen=True)
class PTOSClaim:
    """The claim's measures and its verdict under each reading.

    Attributes
    ----------
    measures : tuple of PTOSMeasure
        Every setting under every reading.
    verdicts : tuple of (str, str)
        (reading, ``reproduced`` | ``not reproduced``).
    seconds : float
        Wall time [s].
    """

    measures: tuple[PTOSMeasure, ...]
    verdicts: tuple[tuple[str, str], ...]
    seconds: float

    def to_json(self) -> dict:
        """Return a JSON-able dict."""
        from dataclasses import asdict

        return {
            "claim": 'PTOS "cannot be directly used" on the plant with bandwidth and saturation',
            "measures": [asdict(m) for m in self.measures],
            "verdicts": dict(self.verdicts),
            "usable_settings": [f"{m.reading}: {m.setting}" for m in self.measures if m.usable],
            "seconds": self.seconds,
        }


def reading_config(cfg: Config, reading: str) -> Config:
    """Return the configuration under a reading of the bandwidth (``2pi``, ``hz``).

    Parameters
    ----------
    cfg : Config
        Configuration; its ``bandwidth_hz`` (if given in Hz) is read.
    reading : str
        ``2pi``: a = 2 pi f (the configuration as loaded); ``hz``: a = f rad/s.

    Returns
    -------
    Config
        The configuration of that reading.
    """
    if reading not in READINGS:
        raise InputError(f"reading must be one of {', '.join(READINGS)}, got {reading!r}")
    if reading == "2pi" or cfg.bandwidth_hz is None:
        return cfg
    return cfg.with_plant(a=cfg.bandwidth_hz)


def _measure(
    cfg: Config, reading: str, setting: str, bound: float, pto_ts: float, grid: tuple
) -> PTOSMeasure:
    p = ptos_design(cfg)
    lin = replace(cfg, pto=replace(cfg.pto, d=min(p.y_l, cfg.plant.position_range)))
    props = law_properties(make_law("ptos", cfg), lin, n1=grid[0], n2=grid[1], rest=grid[2])
    m = response_metrics(cfg, "ptos", "step")
    usable = (
        props.limit_cycles == 0
        and props.not_settled == 0
        and props.stride_overs == 0
        and m["overshoot_mm"] <= bound
        and math.isfinite(m["settling_2pct_s"])
    )
    return PTOSMeasure(
        reading,
        cfg.plant.a,
        setting,
        p.alpha,
        p.k,
        p.y_l,
        bound,
        props.stride_overs,
        props.states_with_stride_over,
        props.limit_cycles,
        props.not_settled,
        props.overshoots,
        props.max_overshoot_mm,
        m["overshoot_mm"],
        m["settling_2pct_s"],
        m["settling_0p01mm_s"],
        pto_ts,
        usable,
    )


def ptos_claim(
    cfg: Config,
    *,
    maxiter: int = 20,
    popsize: int = 8,
    grid: tuple[int, int, int] = (101, 101, 200),
) -> PTOSClaim:
    """Test the claim under both readings (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (its bandwidth in Hz gives the two readings).
    maxiter, popsize : int
        Effort of each tuning (:class:`ptoverify.studies.tune.TuneBudget`).
    grid : tuple of int
        (n1, n2, rest) of the properties' grid (default: the gates' grid).

    Returns
    -------
    PTOSClaim
        Measures and verdicts.
    """
    from ptoverify.studies.tune import TuneBudget, fair_tunings

    t0 = time.perf_counter()
    measures, verdicts = [], []
    budget = TuneBudget(maxiter=maxiter, popsize=popsize)
    for reading in READINGS:
        c = reading_config(cfg, reading)
        ft = fair_tunings(c, budget, ("ptos",))
        bounds = ft.bounds
        pto_ts = ft.paper["pto"]["settling_2pct_s"]
        rows = [_measure(c, reading, "configured", bounds["pto-paper"], pto_ts, grid)]
        for name, b in bounds.items():
            if ("ptos", name) in ft.results:
                t = ft.results[("ptos", name)]
                rows.append(_measure(t.config, reading, f"tuned {name}", b, pto_ts, grid))
        measures += rows
        verdicts.append(
            (reading, "not reproduced" if any(r.usable for r in rows) else "reproduced")
        )
    return PTOSClaim(tuple(measures), tuple(verdicts), time.perf_counter() - t0)


def fair_configs(
    cfg: Config, laws: tuple[str, ...], bound: str = "pto-paper", *, budget: Any = None
) -> dict[str, Config]:
    """Each law's best tuning on the step under one shared overshoot bound.

    Every law with gains from :func:`ptoverify.studies.tune.fair_tunings` (one
    search for all), under the bound named ``bound``
    (:data:`ptoverify.studies.tune.FAIR_BOUNDS`: the PTO's or the PD's overshoot at
    the paper's gains).  TO and the printed PTO have no gains: their
    configuration is ``cfg``.

    Parameters
    ----------
    cfg : Config
        Configuration (plant, the paper's gains).
    laws : tuple of str
        Law names.
    bound : str
        ``pto-paper`` or ``pd-paper``.
    budget : TuneBudget, optional
        Search effort (:class:`ptoverify.studies.tune.TuneBudget`; default its defaults).

    Returns
    -------
    dict
        Law name -> the configuration holding its tuned gains.
    """
    from ptoverify.studies.tune import BOUNDS, FAIR_BOUNDS, TuneBudget, fair_tunings

    if bound not in FAIR_BOUNDS:
        raise InputError(f"bound must be one of {', '.join(FAIR_BOUNDS)}, got {bound!r}")
    tunable = tuple(law for law in laws if law in BOUNDS)
    fair = fair_tunings(cfg, budget or TuneBudget(), tunable, (bound,))
    # a law with no feasible tuning keeps its configured gains
    return {law: fair.config(law, bound) if (law, bound) in fair.results else cfg for law in laws}
