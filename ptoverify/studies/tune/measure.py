"""Measuring one set of gains: the response, the constraints, the worst settling / N*T.

Every candidate :func:`ptoverify.studies.tune.tune` reports is measured here, on the
``simulate --json`` path (:func:`response_metrics`); the grid properties in
:mod:`ptoverify.studies.tune.grid`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ptoverify.config import CascadeGains, Config, PDGains, PTOSettings, PTOSGains
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law, with_state_gains
from ptoverify.model.memo import memo
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.model.poles import spectral_radii
from ptoverify.sim.exact import settling_and_overshoot, settling_and_overshoot_many
from ptoverify.studies.sweep import SweepSettings, grid_states, settling_times

OBJECTIVES = ("settling_2pct", "settling_0p01mm", "worst_ratio_nt")
#: Search ranges: gains [1/s] and [-], d [mm]; kp, k1 and k are searched in log10.
#: The baselines (:mod:`ptoverify.model.baselines`): PTOS's discount alpha [-] and
#: velocity-loop gain k [1/s] (its linear-region gains and kv = k / a - 1 follow
#: from them, Workman's continuity), the cascade P loop's kp [1/s].  Their ranges
#: hold the plants of ``design``'s default chart (a from 5 to 630 rad/s).
BOUNDS: dict[str, dict[str, tuple[float, float]]] = {
    "pd": {"kp": (10.0, 3000.0), "kd": (0.0, 4.0)},
    "pto": {"d": (0.2, 5.0), "k1": (10.0, 3000.0), "k2": (0.0, 10.0)},
    "ptos": {"alpha": (0.05, 1.0), "k": (1.0, 10000.0)},
    "cascade-p": {"kp": (0.3, 3000.0)},
}
#: The searched gains kept in log10 (search coordinates, normalized units).
LOG_GAINS = frozenset({"kp", "k1", "k", "d"})
PENALTY = 1e3  #: objective of an infeasible candidate [s or -]; above any feasible value
#: Most candidates re-measured on the simulate --json path while looking for the best.
MAX_REMEASURED = 200

__all__ = [
    "OBJECTIVES",
    "BOUNDS",
    "PENALTY",
    "WORST_GRID",
    "LOG_GAINS",
    "Candidate",
    "tuned_config",
    "response_metrics",
    "worst_ratio_nt",
    "evaluate",
    "evaluate_batch",
]


@dataclass(frozen=True)
class Candidate:
    """One evaluated set of gains.

    Attributes
    ----------
    gains : dict
        ``kp``, ``kd`` (PD) or ``d``, ``k1``, ``k2`` (PTO) [1/s], [-], [mm];
        ``alpha``, ``k`` (PTOS) [-], [1/s]; ``kp`` (cascade P) [1/s].
    objective : float
        The objective's value ([s] for settling, [-] for worst_ratio_nt); inf if infeasible.
    settling_2pct_s, settling_0p01mm_s : float
        Settling times of the signal's response [s] (nan: never settles).
    overshoot_mm : float
        Overshoot of the response [mm].
    feasible : bool
        Whether every constraint checked so far holds.
    verified : bool
        Whether the grid properties (no limit cycle, no stride-over) were checked and hold.
    reason : str
        Why it is infeasible ("" when feasible).
    omega0 : float or None
        The PTO's zone level [mm/s] for its d.
    """

    gains: dict[str, float]
    objective: float
    settling_2pct_s: float
    settling_0p01mm_s: float
    overshoot_mm: float
    feasible: bool
    verified: bool = False
    reason: str = ""
    omega0: float | None = None

    def to_json(self) -> dict[str, Any]:
        """Return the candidate as a JSON-able dict (non-finite numbers as None)."""
        d = dataclasses.asdict(self)
        for k, v in d.items():
            if isinstance(v, float) and not math.isfinite(v):
                d[k] = None
        return d


def tuned_config(cfg: Config, law: str, gains: dict[str, float]) -> Config:
    """Return ``cfg`` with the law's gains replaced (its section: pd, pto, ptos, cascade).

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        A key of :data:`BOUNDS`.
    gains : dict
        ``kp``, ``kd`` [1/s], [-] (PD), ``d`` [mm], ``k1`` [1/s], ``k2`` [-] (PTO),
        ``alpha`` [-], ``k`` [1/s] (PTOS) or ``kp`` [1/s] (cascade P).

    Returns
    -------
    Config
        The configuration the tuned law is built from.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> tuned_config(paper_config(), "pd", {"kp": 100.0, "kd": 0.5}).pd
    PDGains(kp=100.0, kd=0.5)
    """
    if law == "pd":
        return dataclasses.replace(cfg, pd=PDGains(kp=gains["kp"], kd=gains["kd"]))
    if law == "ptos":
        return dataclasses.replace(cfg, ptos=PTOSGains(alpha=gains["alpha"], k=gains["k"]))
    if law == "cascade-p":
        return dataclasses.replace(cfg, cascade=CascadeGains(kp=gains["kp"]))
    return dataclasses.replace(cfg, pto=PTOSettings(d=gains["d"], k1=gains["k1"], k2=gains["k2"]))


def linear_gains(cfg: Config, law: str, gains: dict[str, float]) -> tuple[float, float]:
    """Return the gains (k_x1 [1/s], k_x2 [-]) of the law's linear loop u = -k_x1 x1 - k_x2 x2.

    :func:`ptoverify.model.baselines.linear_loop_gains` of the configuration
    holding ``gains`` (:func:`tuned_config`).

    Parameters
    ----------
    cfg : Config
        Base configuration (the plant's a for PTOS).
    law : str
        A key of :data:`BOUNDS`.
    gains : dict
        The law's gains (see :func:`tuned_config`).

    Returns
    -------
    tuple of float
        Position gain [1/s] and velocity gain [-].
    """
    from ptoverify.model.baselines import linear_loop_gains

    return linear_loop_gains(law, tuned_config(cfg, law, gains))


def response_metrics(cfg: Config, law: str, signal: str) -> dict[str, float]:
    """Settling (2 % and 0.01 mm), overshoot and rise time of ``law`` on ``signal``.

    Measured between samples, on the exact trajectory (:mod:`ptoverify.sim.exact`),
    exactly as ``ptoverify simulate --json`` reports them in ``metrics``.

    Parameters
    ----------
    cfg : Config
        Configuration the law is built from.
    law : str
        Law name.
    signal : str
        ``step``, ``ramp`` or ``sine``.

    Returns
    -------
    dict
        ``settling_2pct_s`` [s], ``settling_0p01mm_s`` [s], ``overshoot_mm`` [mm],
        ``rise_time_s`` [s]; NaN where undefined (never settles).
    """
    from ptoverify.sim.runs import run_simulation

    m, _ = run_simulation(cfg, law, signal).metrics()  # the very path of simulate --json
    return {k: math.nan if v is None else float(v) for k, v in m.items()}


def _settling_overshoot(
    cfg: Config, law: str, batch: Sequence[dict[str, float]], signal: str
) -> list[dict[str, float] | InputError]:
    """Overshoot and settling times of :func:`response_metrics` per gain set, bit for bit.

    Its simulation (:func:`ptoverify.sim.runs.run_loops`, the loops side by side with
    :func:`~ptoverify.model.laws.with_state_gains`: each entry is ``make_law``'s law of its
    gains) and its exact evaluation, each response as alone
    (:func:`ptoverify.sim.exact.settling_and_overshoot_many`); an InputError in the place
    of a response that evaluation refuses.
    """
    from ptoverify.sim.runs import run_loops

    per_state = {k: np.array([g[k] for g in batch], dtype=float) for k in BOUNDS[law]}
    fn = with_state_gains(law, cfg, per_state)
    runs = [r.result for r in run_loops(cfg, fn, len(batch), signal)]
    try:
        return settling_and_overshoot_many(runs, cfg.plant)
    except InputError:  # some response refused (non-finite samples): each on its own
        return [_or_error(settling_and_overshoot, res, cfg.plant) for res in runs]


def _refused(gains: dict[str, float], reason: str) -> Candidate:
    """Return the infeasible candidate of gains that cannot be measured, with why."""
    return Candidate(gains, math.inf, math.nan, math.nan, math.nan, False, reason=reason)


def _or_error(fn: Callable, *args: Any) -> Any:
    """Return ``fn(*args)``, or the InputError it raises."""
    try:
        return fn(*args)
    except InputError as exc:
        return exc


#: Default state grid of :func:`worst_ratio_nt` (n1 x n2 over the envelope).  Even
#: counts keep the origin (N* = 0) off the grid, as the sweep's.
WORST_GRID = (20, 20)


@memo(maxsize=16)
def _envelope(plant, n1: int, n2: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int]:
    """States, N* T [s], horizon and hold [samples] of the grid; once per plant and grid."""
    s = SweepSettings()
    X1, X2 = grid_states(plant, n1, n2)
    T = plant.sample_time
    t_f = min_time(X1, X2, plant).t_f
    hold = math.ceil(s.hold / T - 1e-9)
    steps = math.ceil(s.horizon_factor * float(t_f.max()) / T) + hold
    n_star = discrete_min_steps_batch(X1.ravel(), X2.ravel(), plant).steps
    nt = np.where(n_star > 0, n_star * T, np.nan)
    return X1.ravel(), X2.ravel(), nt, steps, hold


def worst_ratio_nt(
    cfg: Config, law: str, *, n1: int = WORST_GRID[0], n2: int = WORST_GRID[1]
) -> float:
    """Worst settling time / (N* T) of ``law`` over an n1 x n2 grid of the envelope.

    The suboptimality the paper is about, with the sweep's definitions
    (:mod:`ptoverify.studies.sweep`): settled = |x1| <= 0.01 mm and |x2| <= a 0.01 mm/s
    from a sample on, for at least the hold (0.05 s), read on the sample grid
    (:func:`~ptoverify.studies.sweep.settling_times`); N* the fewest ZOH samples to the
    origin (:func:`~ptoverify.model.mintime.discrete_min_steps_batch`, computed once
    per plant and grid).  A law that does not settle from some grid state has
    an infinite worst ratio (the tuner treats it as infeasible).  Every state of
    the grid is simulated.

    Parameters
    ----------
    cfg : Config
        Configuration the law is built from.
    law : str
        Law name.
    n1, n2 : int
        Grid points along x1 [mm] and x2 [mm/s] over |x1| <= position_range,
        |x2| <= w_max.

    Returns
    -------
    float
        max over the grid of settling / (N* T) [-]; inf if a state never settles.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> worst_ratio_nt(paper_config(), "pd", n1=4, n2=4) >= 1.0
    True
    """
    if n1 < 2 or n2 < 2:
        raise InputError("worst_ratio_nt: the grid needs at least 2 points per axis")
    p = cfg.plant
    x1, x2, nt, steps, hold = _envelope(p, n1, n2)
    st = settling_times(
        make_law(law, cfg),
        p,
        x1,
        x2,
        steps,
        SweepSettings().band,
        p.a * SweepSettings().band,
        hold * p.sample_time,
    ).grid  # the sweep's sample-grid reading (its between-samples twin differs by < T)
    ok = np.isfinite(nt)
    if not np.isfinite(st[ok]).all():
        return math.inf
    return float(np.max(st[ok] / nt[ok]))


def worst_ratios(
    cfg: Config, law: str, batch: Sequence[dict[str, float]], n1: int, n2: int
) -> list[float]:
    """:func:`worst_ratio_nt` of many gain sets, the states of several in one simulation.

    Each gain set's grid states are simulated with a law whose gains are one per
    state (:func:`ptoverify.model.laws.with_state_gains`); the evaluation is per state, so
    every value is that of :func:`worst_ratio_nt` for the gain set alone.

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        ``pd`` or ``pto``.
    batch : sequence of dict
        Gain sets (see :func:`tuned_config`).
    n1, n2 : int
        Grid points along x1 and x2 (:func:`worst_ratio_nt`).

    Returns
    -------
    list of float
        Worst settling / (N* T) [-] per gain set; inf where a state never settles.
    """
    p = cfg.plant
    x1, x2, nt, steps, hold = _envelope(p, n1, n2)
    ok = np.isfinite(nt)
    m = x1.size
    keys = tuple(BOUNDS[law])
    band = SweepSettings().band
    per = max(1, 4096 // m)  # gain sets per simulation (sweep.settling_times' chunk)
    out = []
    for i in range(0, len(batch), per):
        part = batch[i : i + per]
        gains = {k: np.repeat([g[k] for g in part], m) for k in keys}
        st = settling_times(
            with_state_gains(law, cfg, gains),
            p,
            np.tile(x1, len(part)),
            np.tile(x2, len(part)),
            steps,
            band,
            p.a * band,
            hold * p.sample_time,
            chunk=m * len(part),
        ).grid.reshape(len(part), m)
        for row in st:
            out.append(float(np.max(row[ok] / nt[ok])) if np.isfinite(row[ok]).all() else math.inf)
    return out


def gains_key(g: dict[str, float]) -> tuple:
    """Return a hashable key of a gain set (its items, sorted by name).

    Parameters
    ----------
    g : dict
        Gain name -> value.

    Returns
    -------
    tuple
        ``((name, value), ...)``.
    """
    return tuple(sorted(g.items()))


def evaluate(
    cfg: Config,
    law: str,
    gains: dict[str, float],
    *,
    signal: str = "step",
    objective: str = "settling_2pct",
    max_overshoot: float | None = None,
    worst_ratio: Callable[[Config, str], float] | None = None,
    memo: dict | None = None,
) -> Candidate:
    """Evaluate one set of gains under the cheap constraints (not the grid properties).

    :func:`evaluate_batch` of the one gain set.

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        ``pd`` or ``pto``.
    gains : dict
        The gains (see :func:`tuned_config`).
    signal : str
        Reference of the response.
    objective : str
        One of :data:`OBJECTIVES`.
    max_overshoot : float, optional
        Overshoot bound [mm].
    worst_ratio : callable, optional
        ``f(cfg, law) -> worst settling / N*T`` for ``objective="worst_ratio_nt"``;
        default :func:`worst_ratio_nt` on its default grid.
    memo : dict, optional
        Keeps the response metrics by (signal, gains), for evaluations that may repeat.

    Returns
    -------
    Candidate
        The candidate (``verified`` False).
    """
    return evaluate_batch(
        cfg,
        law,
        [gains],
        signal=signal,
        objective=objective,
        max_overshoot=max_overshoot,
        worst_ratio=worst_ratio,
        memo=memo,
    )[0]


def evaluate_batch(
    cfg: Config,
    law: str,
    batch: Sequence[dict[str, float]],
    *,
    signal: str = "step",
    objective: str = "settling_2pct",
    max_overshoot: float | None = None,
    worst_ratio: Callable[[Config, str], float] | None = None,
    memo: dict | None = None,
) -> list[Candidate]:
    """Evaluate gain sets under the cheap constraints, their responses in one simulation.

    Each gain set is judged on its own (stability of the sampled linear loop, the
    PTO's zone for its d, the response's overshoot and settling); the responses of
    those that get that far are simulated side by side (:func:`_settling_overshoot`),
    each the ``simulate --json`` response of its gains alone, so every candidate is
    the one its gains give alone.

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        A key of :data:`BOUNDS`.
    batch : sequence of dict
        The gain sets (see :func:`tuned_config`).
    signal : str
        Reference of the responses.
    objective : str
        One of :data:`OBJECTIVES`.
    max_overshoot : float, optional
        Overshoot bound [mm].
    worst_ratio : callable, optional
        ``f(cfg, law) -> worst settling / N*T`` for ``objective="worst_ratio_nt"``;
        default :func:`worst_ratio_nt` on its default grid.
    memo : dict, optional
        Keeps the response metrics by (signal, gains), for evaluations that may repeat.

    Returns
    -------
    list of Candidate
        One per gain set, in order (``verified`` False).
    """
    p = cfg.plant
    out: list[Candidate | None] = [None] * len(batch)
    tcfgs: dict[int, Config] = {}
    omega0s: dict[int, float | None] = {}
    for i, gains in enumerate(batch):
        tcfg = tuned_config(cfg, law, gains)
        if spectral_radii(p.a, p.sample_time, *linear_gains(cfg, law, gains))[0] >= 1.0:
            out[i] = _refused(gains, "sampled linear loop unstable")
            continue
        omega0 = None
        if law == "pto":
            from ptoverify.model.zones import zone_for_law

            try:
                z = zone_for_law(tcfg, "corrected")
            except InputError as exc:
                out[i] = _refused(gains, str(exc))
                continue
            omega0 = float(z.omega0) if z.omega0 is not None else None
        tcfgs[i], omega0s[i] = tcfg, omega0
    keys = {i: (signal, gains_key(batch[i])) for i in tcfgs}
    known = {} if memo is None else memo
    todo = list({keys[i]: i for i in tcfgs if keys[i] not in known}.values())  # first of each
    metrics: dict[tuple, dict[str, float] | InputError] = {}
    if todo:
        try:
            ms = _settling_overshoot(cfg, law, [batch[i] for i in todo], signal)
        except InputError as exc:  # the simulation's checks (the same for every gain set)
            metrics.update((keys[i], exc) for i in todo)
        else:
            new = {keys[i]: m for i, m in zip(todo, ms, strict=True)}
            metrics.update(new)
            if memo is not None:  # (a refused response is not kept: evaluate kept none)
                memo.update((k, m) for k, m in new.items() if not isinstance(m, InputError))
    for i, tcfg in tcfgs.items():
        gains = batch[i]
        m = metrics[keys[i]] if keys[i] in metrics else known[keys[i]]
        if isinstance(m, InputError):
            out[i] = _refused(gains, str(m))
            continue
        if max_overshoot is not None and not m["overshoot_mm"] <= max_overshoot:
            value = math.inf
            reason = f"overshoot {m['overshoot_mm']:.4g} mm > {max_overshoot:.4g} mm"
        else:
            reason = ""
            if objective == "worst_ratio_nt":
                value = (worst_ratio or worst_ratio_nt)(tcfg, law)
            else:
                value = m[f"{objective}_s"]
            if not math.isfinite(value):
                reason, value = "does not settle", math.inf
        out[i] = Candidate(
            gains,
            value,
            m["settling_2pct_s"],
            m["settling_0p01mm_s"],
            m["overshoot_mm"],
            not reason,
            reason=reason,
            omega0=omega0s[i],
        )
    return out  # type: ignore[return-value]
