"""The baselines tuned fairly, and the paper's claim that PTOS "cannot be directly used".

:func:`tune_baseline` tunes PTOS (alpha, k) or the cascade P loop (kp) under
the constraints ``ptoverify tune`` applies to PD and PTO: the 2 % settling time
of the Section 6 step is minimized (``scipy.optimize.differential_evolution``,
fixed seed) subject to the step's overshoot between samples <= a bound and a
stable sampled linear loop (spectral radius < 1,
:func:`ptoverify.model.poles.spectral_radii`); the best candidates, in order,
are then checked for limit cycles on the gates' grid
(:func:`ptoverify.studies.properties.law_properties`) until one passes.

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

import numpy as np
from scipy.optimize import differential_evolution

from ptoverify.config import CascadeGains, Config, PTOSGains
from ptoverify.errors import InputError
from ptoverify.model.baselines import cascade_gain, ptos_design
from ptoverify.model.laws import make_law
from ptoverify.model.poles import spectral_radii
from ptoverify.studies.properties import law_properties
from ptoverify.studies.tune import response_metrics

__all__ = [
    "BaselineTuning",
    "tune_baseline",
    "baseline_linear_gains",
    "PTOSMeasure",
    "PTOSClaim",
    "ptos_claim",
    "READINGS",
    "reading_config",
    "fair_configs",
]

#: Search ranges: PTOS alpha [-] and log10(k / a); cascade log10(kp / a).
SEARCH = {
    "ptos": ((0.05, 1.0), (math.log10(0.25), math.log10(20.0))),
    "ptos-ideal": ((0.05, 1.0),),  # k = a: the profile is the velocity command itself
    "cascade-p": ((-2.0, 0.7),),
}
#: Readings of the printed bandwidth: a = 2 pi f, or a = f taken as rad/s.
READINGS = ("2pi", "hz")


def baseline_linear_gains(cfg: Config, law: str) -> tuple[float, float]:
    """Gains (k_x1 [1/s], k_x2 [-]) of a law's linear loop u = -k_x1 x1 - k_x2 x2.

    Parameters
    ----------
    cfg : Config
        Configuration.
    law : str
        ``pd``, ``pto``, ``pto-printed``, ``ptos`` or ``cascade-p``.

    Returns
    -------
    tuple of float
        The linear loop's gains.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> baseline_linear_gains(paper_config(), "pd")
    (356.0, 1.15)
    """
    if law == "pd":
        return cfg.pd.kp, cfg.pd.kd
    if law in ("pto", "pto-printed"):
        return cfg.pto.k1, cfg.pto.k2
    if law == "ptos":
        return ptos_design(cfg).linear_gains()
    if law == "cascade-p":
        return cascade_gain(cfg), 0.0
    raise InputError(f"law {law!r} has no linear loop")


def _with_params(cfg: Config, law: str, x: np.ndarray) -> Config:
    """Return the configuration of one search point (in SEARCH coordinates)."""
    a = cfg.plant.a
    if law == "ptos":
        return replace(cfg, ptos=PTOSGains(alpha=float(x[0]), k=float(a * 10.0 ** x[1])))
    if law == "ptos-ideal":
        return replace(cfg, ptos=PTOSGains(alpha=float(x[0]), k=None))
    return replace(cfg, cascade=CascadeGains(kp=float(a * 10.0 ** x[0])))


@dataclass(frozen=True)
class BaselineTuning:
    """Best gains of a baseline under the fair constraints.

    Attributes
    ----------
    law : str
        ``ptos`` or ``cascade-p`` (the law built from ``config``).
    config : Config
        The configuration holding the best gains (``ptos`` or ``cascade``).
    max_overshoot_mm : float
        The overshoot bound [mm].
    settling_2pct_s, settling_0p01mm_s : float
        Step settling times at the best gains [s] (NaN: none feasible).
    overshoot_mm : float
        Step overshoot at the best gains [mm].
    feasible : bool
        Whether a candidate met every constraint.
    evaluations : int
        Candidates evaluated.
    seconds : float
        Wall time [s].
    """

    law: str
    config: Config
    max_overshoot_mm: float
    settling_2pct_s: float
    settling_0p01mm_s: float
    overshoot_mm: float
    feasible: bool
    evaluations: int
    seconds: float

    def gains(self) -> tuple[float, ...]:
        """Return (alpha [-], k [1/s]) for PTOS, (kp [1/s],) for cascade P."""
        if self.law == "ptos":
            return ptos_design(self.config).alpha, ptos_design(self.config).k
        return (cascade_gain(self.config),)


def tune_baseline(
    cfg: Config,
    law: str,
    max_overshoot: float,
    *,
    seed: int = 0,
    maxiter: int = 20,
    popsize: int = 8,
    grid: tuple[int, int, int] = (41, 41, 40),
) -> BaselineTuning:
    """Tune a baseline's gains on the step (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (plant).
    law : str
        ``ptos`` (alpha and k), ``ptos-ideal`` (alpha; k = a: the velocity loop
        treated as ideal, u the profile itself) or ``cascade-p`` (kp).
    max_overshoot : float
        Overshoot bound of the step [mm].
    seed : int
        Seed of differential evolution.
    maxiter, popsize : int
        Differential-evolution generations and population factor.
    grid : tuple of int
        (n1, n2, rest) of the limit-cycle check's grid.

    Returns
    -------
    BaselineTuning
        The best feasible candidate (``feasible`` False if none).

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> t = tune_baseline(paper_config(), "cascade-p", 0.0, maxiter=3, popsize=4)
    >>> t.feasible and t.overshoot_mm <= 0.0
    True
    """
    if law not in SEARCH:
        raise InputError(f"tune_baseline: law must be one of {', '.join(SEARCH)}, got {law!r}")
    t0 = time.perf_counter()
    search, law = law, "ptos" if law == "ptos-ideal" else law
    p = cfg.plant
    seen: dict[tuple, tuple[float, dict]] = {}

    def cost(x: np.ndarray) -> float:
        key = tuple(float(v) for v in x)
        if key not in seen:
            c = _with_params(cfg, search, x)
            gains = baseline_linear_gains(c, law)
            if spectral_radii(p.a, p.sample_time, *gains)[0] >= 1.0:
                seen[key] = (math.inf, {})
            else:
                m = response_metrics(c, law, "step")
                ok = m["overshoot_mm"] <= max_overshoot and math.isfinite(m["settling_2pct_s"])
                seen[key] = (m["settling_2pct_s"] if ok else math.inf, m)
        return seen[key][0]

    differential_evolution(
        cost, SEARCH[search], seed=seed, maxiter=maxiter, popsize=popsize, tol=0.0, polish=False
    )
    order = sorted((v, k) for k, (v, _) in seen.items() if math.isfinite(v))
    for _, key in order[:20]:
        c = _with_params(cfg, search, np.array(key))
        props = law_properties(make_law(law, c), c, n1=grid[0], n2=grid[1], rest=grid[2])
        if props.limit_cycles == 0 and props.not_settled == 0:
            m = seen[key][1]
            return BaselineTuning(
                law,
                c,
                max_overshoot,
                m["settling_2pct_s"],
                m["settling_0p01mm_s"],
                m["overshoot_mm"],
                True,
                len(seen),
                time.perf_counter() - t0,
            )
    nan = math.nan
    return BaselineTuning(
        law, cfg, max_overshoot, nan, nan, nan, False, len(seen), time.perf_counter() - t0
    )


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
        ``configured``, or ``tuned <search> <bound name>`` (search ``ptos-ideal``:
        alpha with k = a; ``ptos``: alpha and k).
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
        Effort of each tuning (:func:`tune_baseline`).
    grid : tuple of int
        (n1, n2, rest) of the properties' grid (default: the gates' grid).

    Returns
    -------
    PTOSClaim
        Measures and verdicts.
    """
    t0 = time.perf_counter()
    measures, verdicts = [], []
    for reading in READINGS:
        c = reading_config(cfg, reading)
        paper = {law: response_metrics(c, law, "step") for law in ("pto", "pd")}
        bounds = {
            "pto-paper": paper["pto"]["overshoot_mm"],
            "pd-paper": paper["pd"]["overshoot_mm"],
        }
        pto_ts = paper["pto"]["settling_2pct_s"]
        rows = [_measure(c, reading, "configured", bounds["pto-paper"], pto_ts, grid)]
        for name, b in bounds.items():
            for search in ("ptos-ideal", "ptos"):
                t = tune_baseline(c, search, b, maxiter=maxiter, popsize=popsize)
                if t.feasible:
                    rows.append(
                        _measure(t.config, reading, f"tuned {search} {name}", b, pto_ts, grid)
                    )
        measures += rows
        verdicts.append(
            (reading, "not reproduced" if any(r.usable for r in rows) else "reproduced")
        )
    return PTOSClaim(tuple(measures), tuple(verdicts), time.perf_counter() - t0)


def fair_configs(
    cfg: Config, laws: tuple[str, ...], bound: str = "pto-paper", *, maxiter: int = 20
) -> dict[str, Config]:
    """Each law's best tuning on the step under one shared overshoot bound.

    PD and PTO from :func:`ptoverify.studies.tune.fair_tunings`, PTOS and the
    cascade P loop from :func:`tune_baseline`, under the bound named ``bound``
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
    maxiter : int
        Generations of the baselines' searches.

    Returns
    -------
    dict
        Law name -> the configuration holding its tuned gains.
    """
    from ptoverify.studies.tune import FAIR_BOUNDS, fair_tunings

    if bound not in FAIR_BOUNDS:
        raise InputError(f"bound must be one of {', '.join(FAIR_BOUNDS)}, got {bound!r}")
    fair = fair_tunings(cfg)
    out = {}
    for law in laws:
        if law in ("pd", "pto"):
            out[law] = fair.config(law, bound)
        elif law in ("ptos", "cascade-p"):
            t = tune_baseline(cfg, law, fair.bounds[bound], maxiter=maxiter)
            out[law] = t.config if t.feasible else cfg
        else:
            out[law] = cfg
    return out
