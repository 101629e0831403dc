"""The corrected PTO against fair-tuned PD, PTOS and the cascade P loop, under both readings of a.

At the configuration's design point, under each reading of the printed bandwidth
(:data:`ptoverify.studies.ptos_claim.READINGS`: a = 2 pi f and a = f rad/s), every
law with gains is tuned by ``ptoverify tune`` itself
(:func:`ptoverify.studies.tune.fair_tunings`: one search, one set of constraints)
under one shared bound: the step's overshoot between samples may not exceed the
corrected PTO's at the paper's gains (:data:`ptoverify.studies.tune.FAIR_BOUNDS`
``pto-paper``, the paper's premise of "the same overshoot").  Each tuned law is
measured on the Section 6 step: its settling time under the named definition
:data:`SETTLING` (:data:`ptoverify.sim.settling.DEFINITIONS`, the tuner's
objective), and that time over the step's floors N* T and t_f*.  The comparison
records, for each other law, the PTO's settling minus the other's [s]; the
report reads its verdict (beats, ties, loses; :func:`ptoverify.verdict.time_order`) off these numbers.

A law whose tuning finds no gains meeting the constraints is recorded with the
reason and no numbers.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.model.baselines import linear_loop_gains
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.model.poles import delay_margin_samples
from ptoverify.sim.settling import definition
from ptoverify.sim.simulate import reference
from ptoverify.studies.ptos_claim import READINGS, reading_config
from ptoverify.studies.robust.margins import law_margins
from ptoverify.studies.tune import TuneBudget, fair_tunings

__all__ = ["SETTLING", "VERSUS_LAWS", "TunedLaw", "ReadingVersus", "Versus", "versus"]

#: The settling definition of the comparison (the tuner's objective, ``settling_2pct``).
SETTLING = "2pct"
#: The laws compared: the corrected PTO first, then those it is compared against.
VERSUS_LAWS = ("pto", "pd", "ptos", "cascade-p")
#: The shared overshoot bound (a name of :data:`ptoverify.studies.tune.FAIR_BOUNDS`).
BOUND = "pto-paper"


@dataclass(frozen=True)
class TunedLaw:
    """One law at its best tuning on the step.

    Attributes
    ----------
    law : str
        Law name.
    gains : dict
        The tuned gains (:data:`ptoverify.studies.tune.BOUNDS` names; units there);
        empty when infeasible.
    settling_s : float or None
        Settling time of the step under :data:`SETTLING` [s]; None: infeasible.
    overshoot_mm : float or None
        Overshoot of the step between samples [mm].
    ratio_nt : float or None
        settling_s / (N* T) [-].
    ratio_tf : float or None
        settling_s / t_f* [-].
    infeasible : str
        Why no gains meet the constraints ("" when tuned).
    delay_margin_samples : int or None
        Whole samples of computation delay the tuned linear loop tolerates
        (:func:`ptoverify.model.poles.delay_margin_samples`; -1: unstable without
        delay) [samples]; None: infeasible.
    a_ratio_stable : tuple of (float or None) or None
        The interval of a_true / a_design around 1 where the tuned linear loop
        stays stable (:func:`ptoverify.studies.robust.linear_loop_margin`; an
        endpoint None: beyond the searched [0.1, 10]) [-]; None: unstable at the
        design point, or infeasible.
    a_ratio_stable_delay1 : tuple of (float or None) or None
        The same with a one-sample computation delay [-].
    """

    law: str
    gains: dict[str, float]
    settling_s: float | None
    overshoot_mm: float | None
    ratio_nt: float | None
    ratio_tf: float | None
    infeasible: str = ""
    delay_margin_samples: int | None = None
    a_ratio_stable: tuple[float | None, float | None] | None = None
    a_ratio_stable_delay1: tuple[float | None, float | None] | None = None


@dataclass(frozen=True)
class ReadingVersus:
    """The comparison under one reading of a.

    Attributes
    ----------
    reading : str
        ``2pi`` (a = 2 pi f) or ``hz`` (a = f rad/s).
    a : float
        The plant's bandwidth under that reading [rad/s].
    sample_time : float
        T [s] (two times less than one sample apart tie: :data:`ptoverify.verdict.TIME_TIE_RULE`).
    bound_mm : float
        The shared overshoot bound [mm].
    nt_s, tf_s : float
        The step's floors: N* T (fewest ZOH samples) and t_f* (continuous) [s].
    laws : tuple of TunedLaw
        Each law of :data:`VERSUS_LAWS`, tuned.
    pto_minus : dict
        Other law -> the PTO's settling minus that law's [s] (None when either is
        infeasible); negative: the PTO settles first.
    """

    reading: str
    a: float
    sample_time: float
    bound_mm: float
    nt_s: float
    tf_s: float
    laws: tuple[TunedLaw, ...]
    pto_minus: dict[str, float | None]

    def law(self, name: str) -> TunedLaw:
        """Return the tuned law called ``name``."""
        return next(t for t in self.laws if t.law == name)


@dataclass(frozen=True)
class Versus:
    """The comparison under every reading.

    Attributes
    ----------
    settling : str
        The settling definition's name (:data:`SETTLING`).
    settling_description : str
        Its one-line description (:data:`ptoverify.sim.settling.DEFINITIONS`).
    bound : str
        The shared bound's name (:data:`BOUND`).
    readings : tuple of ReadingVersus
        One per reading of a.
    budget : TuneBudget
        The search effort of the tunings.
    seconds : float
        Wall time [s].
    """

    settling: str
    settling_description: str
    bound: str
    readings: tuple[ReadingVersus, ...]
    budget: TuneBudget
    seconds: float

    def to_json(self) -> dict[str, Any]:
        """Return a JSON-able dict (the report's ``tuning.versus``; None for no number)."""

        def clean(v: Any) -> Any:
            if isinstance(v, float) and not math.isfinite(v):
                return None
            if isinstance(v, dict):
                return {k: clean(x) for k, x in v.items()}
            if isinstance(v, (list, tuple)):
                return [clean(x) for x in v]
            return v

        return clean(
            {
                "settling": self.settling,
                "settling_description": self.settling_description,
                "bound": self.bound,
                "readings": [asdict(r) for r in self.readings],
                "budget": asdict(self.budget),
                "seconds": self.seconds,
            }
        )


def _floors(cfg: Config) -> tuple[float, float]:
    """N* T and t_f* [s] of the Section 6 step from rest."""
    step = reference("step").amplitude
    nt = float(discrete_min_steps_batch([-step], [0.0], cfg.plant).time_s[0])
    tf = float(min_time(np.array([-step]), np.array([0.0]), cfg.plant).t_f[0])
    return nt, tf


def _ratio(t: float | None, floor: float) -> float | None:
    return None if t is None or not floor > 0 else t / floor


def versus(cfg: Config, budget: TuneBudget | None = None) -> Versus:
    """Compare the corrected PTO with fair-tuned PD, PTOS and cascade P (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (plant, the paper's gains; its bandwidth in Hz opens the
        second reading, else only ``2pi`` is compared).
    budget : TuneBudget, optional
        Search effort of the tunings (default :class:`~ptoverify.studies.tune.TuneBudget`).

    Returns
    -------
    Versus
        Every law tuned under every reading, with the PTO's differences.
    """
    t0 = time.perf_counter()
    budget = budget or TuneBudget()
    readings = READINGS if cfg.bandwidth_hz is not None else READINGS[:1]
    out = []
    for rd in readings:
        c = reading_config(cfg, rd)
        ft = fair_tunings(c, budget, VERSUS_LAWS, (BOUND,))
        nt, tf = _floors(c)
        laws = []
        for law in VERSUS_LAWS:
            r = ft.results.get((law, BOUND))
            if r is None:
                laws.append(TunedLaw(law, {}, None, None, None, None, ft.infeasible[(law, BOUND)]))
                continue
            ts = r.best.settling_2pct_s
            gains = linear_loop_gains(law, r.config)  # every law compared has a linear loop
            margin = delay_margin_samples(c.plant.a, c.plant.sample_time, *gains)
            robust = law_margins(law, r.config, limit_cycles=False)
            laws.append(
                TunedLaw(
                    law,
                    dict(r.best.gains),
                    ts,
                    r.best.overshoot_mm,
                    _ratio(ts, nt),
                    _ratio(ts, tf),
                    delay_margin_samples=margin,
                    a_ratio_stable=robust.linear.interval,
                    a_ratio_stable_delay1=robust.linear_delay1.interval,
                )
            )
        pto = laws[0].settling_s
        minus = {
            t.law: (None if pto is None or t.settling_s is None else pto - t.settling_s)
            for t in laws[1:]
        }
        out.append(
            ReadingVersus(
                rd, c.plant.a, c.plant.sample_time, ft.bounds[BOUND], nt, tf, tuple(laws), minus
            )
        )
    d = definition(SETTLING)
    return Versus(SETTLING, d.description, BOUND, tuple(out), budget, time.perf_counter() - t0)
