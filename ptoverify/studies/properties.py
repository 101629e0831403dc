"""Closed-loop properties of the laws over a grid of initial states, by simulation.

Every law is run with :func:`ptoverify.sim.simulate.simulate_batch` (exact ZOH
flow) from an ``n1`` x ``n2`` grid over the envelope |x1| <= position_range,
|x2| <= w_max (default 101 x 101 = 10,201 states) plus ``rest`` states at rest,
x2 = 0, d <= |x1| <= position_range (the step responses).

Definitions (sigma is the switching function of l1 - o - l2, eqs. 9, 11; tol =
:func:`ptoverify.verdict.tie_band` [mm/s]; d is the PTO linear-zone half-width,
used as the yardstick for every law):

stride-over
    A sample k with |x1_k| >= d, not in a switching zone (region not ZONE_P /
    ZONE_N), with sigma_k > 0 (or on l2) whose next sample has sigma < -tol and
    |x1_{k+1}| >= d; or the mirror (sigma_k < 0 or on l1, next sigma > tol).
    Under sampled TO every switch outside the linear zone is one.
crossing into the linear zone
    The same crossing, but the next sample lies inside |x1| < d (the case the
    strict reading of the principle forbids and the lenient one allows).
sustained oscillation (limit cycle)
    Over the last ``window`` samples, x1 (counting only samples with |x1| >
    ``band``) changes sign at least 4 times and the peak |x1| of the window's
    second half is at least half the peak of its first half (not decaying).
time to the linear zone
    First sample time with |x1| < d [s] (states that start there: 0).
chattering
    A sample whose region differs from both neighbours while the neighbours
    agree (A, B, A in consecutive samples).
overshoot
    For the rest states, max over k of -sgn(x1_0) x1_k beyond ``band`` [mm] (on
    the samples, as the robustness study reads it).
not settled
    NaN settling time under the definition ``0p001mm``
    (:data:`ptoverify.sim.settling.DEFINITIONS`; ``band`` at its default): the
    record ends outside |x1| <= band.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ptoverify.config import Config
from ptoverify.model.laws import Law, Region, make_law
from ptoverify.model.memo import memo
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import (
    DEFINITIONS,
    SettlingDefinition,
    definition,
    grid_overshoot,
    settling_time,
)
from ptoverify.sim.simulate import simulate_batch
from ptoverify.studies.crossings import (
    STRIDE_BLOCK,
    _crossings,
    crossing_masks,
    oscillating,
    stride_over_counts,
)

__all__ = [
    "LawProperties",
    "initial_grid",
    "default_steps",
    "law_properties",
    "all_properties",
    "named_properties",
    "zone_outcome",
    "oscillating",
    "crossing_masks",
    "stride_over_counts",
    "STRIDE_BLOCK",
]


@dataclass(frozen=True)
class LawProperties:
    """Closed-loop properties of one law over the grid (see module docstring).

    Attributes
    ----------
    law, note : str
        Law name and its one-line description.
    states, steps : int
        Number of initial states and of simulated samples.
    stride_overs : int
        Stride-overs counted over all samples of all states.
    states_with_stride_over : int
        Initial states whose trajectory strides over at least once.
    crossings_into_linear : int
        Crossings of l1/l2 that land inside the linear zone.
    limit_cycles : int
        States with sustained oscillation at the end of the horizon.
    not_settled : int
        States whose record ends outside |x1| <= ``band`` [mm] (NaN settling time).
    time_to_linear_max_s, time_to_linear_median_s : float
        Time to reach |x1| < d [s]; inf if some state never does.
    never_linear : int
        States that never reach |x1| < d.
    chattering : int
        Chattering samples (A, B, A region patterns).
    states_chattering : int
        States with at least one chattering sample.
    max_abs_u : float
        Largest |u| applied [mm/s].
    u_within_limit : bool
        max |u| <= w_max.
    overshoots : int
        Rest states whose response overshoots by more than ``band``.
    max_overshoot_mm : float
        Largest overshoot of the rest states [mm].
    zone_samples : int
        Samples that used the switching zone (ZONE_P / ZONE_N).
    entered_linear_from_bang : int
        States whose last sample before the linear zone was a bang region
        (they reached the linear zone without passing through the zone).
    max_entry_speed : float
        Largest |x2| at the first sample inside the linear zone, over the states
        that start outside it [mm/s].
    band : float
        Oscillation / settling band [mm].
    """

    law: str
    note: str
    states: int
    steps: int
    stride_overs: int
    states_with_stride_over: int
    crossings_into_linear: int
    limit_cycles: int
    not_settled: int
    time_to_linear_max_s: float
    time_to_linear_median_s: float
    never_linear: int
    chattering: int
    states_chattering: int
    max_abs_u: float
    u_within_limit: bool
    overshoots: int
    max_overshoot_mm: float
    zone_samples: int
    entered_linear_from_bang: int
    max_entry_speed: float
    band: float

    def to_json(self) -> dict:
        """Return the properties as a JSON-able dict."""
        return asdict(self)


def initial_grid(
    cfg: Config, n1: int = 101, n2: int = 101, rest: int = 200
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return initial states: an n1 x n2 envelope grid plus ``rest`` states at rest.

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm], w_max [mm/s], d [mm]).
    n1, n2 : int
        Grid points in x1 and x2.
    rest : int
        States at rest, half with x1 > 0 and half with x1 < 0, |x1| in [d, range].

    Returns
    -------
    x1, x2 : ndarray
        Initial states [mm], [mm/s].
    is_rest : ndarray of bool
        Which states are the rest states.
    """
    R, w, d = cfg.plant.position_range, cfg.plant.w_max, cfg.pto.d
    g1, g2 = np.meshgrid(np.linspace(-R, R, n1), np.linspace(-w, w, n2))
    r1 = np.linspace(max(d, 1e-3 * R), R, rest // 2)
    x1 = np.concatenate([g1.ravel(), r1, -r1])
    x2 = np.concatenate([g2.ravel(), np.zeros(2 * r1.size)])
    is_rest = np.concatenate([np.zeros(g1.size, bool), np.ones(2 * r1.size, bool)])
    return x1, x2, is_rest


def default_steps(cfg: Config) -> int:
    """Horizon: 2 R / w_max + 60 / a seconds, in samples (room to settle).

    Parameters
    ----------
    cfg : Config
        Configuration (position_range R [mm], w_max [mm/s], a [rad/s], T [s]).

    Returns
    -------
    int
        Number of samples [-].
    """
    p = cfg.plant
    return int(math.ceil((2.0 * p.position_range / p.w_max + 60.0 / p.a) / p.sample_time))


def law_properties(
    law: Law,
    cfg: Config,
    *,
    n1: int = 101,
    n2: int = 101,
    rest: int = 200,
    steps: int | None = None,
    band: float = DEFINITIONS["0p001mm"].band_mm,
    window: int | None = None,
) -> LawProperties:
    """Simulate ``law`` from the grid and measure the closed-loop properties.

    Parameters
    ----------
    law : Law
        The law (vectorized path).
    cfg : Config
        Configuration.
    n1, n2, rest : int
        Grid sizes (see :func:`initial_grid`).
    steps : int, optional
        Samples to simulate; default :func:`default_steps`.
    band : float
        Oscillation / settling / overshoot band [mm].
    window : int, optional
        Samples at the end examined for sustained oscillation; default steps // 4.

    Returns
    -------
    LawProperties
        The measured properties.
    """
    steps = default_steps(cfg) if steps is None else steps
    window = max(20, steps // 4) if window is None else window
    x1, x2, is_rest = initial_grid(cfg, n1, n2, rest)
    res = simulate_batch(law, cfg.plant, x1, x2, steps)
    return _measure(law, cfg, res, x1, x2, is_rest, steps, window, band)


def _measure(law, cfg, res, x1, x2, is_rest, steps, window, band) -> LawProperties:
    """Measure the properties of :func:`law_properties` on its grid run ``res``."""
    p = cfg.plant
    w, d, T = p.w_max, cfg.pto.d, p.sample_time
    X1, X2, R = res.x1, res.x2, res.region
    # the transitions of crossing_masks, counted without the (steps, n) masks
    _, j, cross, lands_out = _crossings(X1, X2, R, cfg)
    j_stride = j[cross & lands_out]
    zone_samples = int(np.count_nonzero(R == Region.ZONE_P) + np.count_nonzero(R == Region.ZONE_N))
    inside = np.abs(X1) < d
    first_in = np.where(inside.any(axis=0), inside.argmax(axis=0), -1)
    never = first_in < 0
    t_lin = np.where(never, np.inf, first_in * T)
    entered = first_in > 0  # started outside, entered later
    prev = R[np.maximum(first_in - 1, 0), np.arange(x1.size)]
    from_bang = entered & ((prev == Region.BANG_P) | (prev == Region.BANG_N))
    entry = np.where(entered, np.abs(X2[np.maximum(first_in, 0), np.arange(x1.size)]), 0.0)
    chat = (R[1:-1] != R[:-2]) & (R[1:-1] != R[2:]) & (R[:-2] == R[2:])
    osc = oscillating(X1[-window:], band)
    t = np.arange(X1.shape[0]) * T
    over = np.zeros(x1.size)  # only the states at rest can overshoot: past the origin,
    over[is_rest] = grid_overshoot(X1[:, is_rest], 0.0)  # on the samples, as robust reads it
    box = definition("0p001mm")
    if band != box.band_mm:
        box = SettlingDefinition("properties", "the properties' band", band_mm=band)
    settled = settling_time(Trajectory(t, X1, X2, res.u, p.a), None, box).time
    max_u = float(np.abs(res.u).max())
    return LawProperties(
        law=law.name,
        note=law.note,
        states=int(x1.size),
        steps=int(steps),
        stride_overs=int(j_stride.size),
        states_with_stride_over=int(np.unique(j_stride).size),
        crossings_into_linear=int(np.count_nonzero(cross & ~lands_out)),
        limit_cycles=int(osc.sum()),
        not_settled=int(np.isnan(settled).sum()),
        time_to_linear_max_s=float(t_lin.max()),
        time_to_linear_median_s=float(np.median(t_lin)),
        never_linear=int(never.sum()),
        chattering=int(chat.sum()),
        states_chattering=int(chat.any(axis=0).sum()),
        max_abs_u=max_u,
        u_within_limit=bool(max_u <= w),
        overshoots=int((over > band).sum()),
        max_overshoot_mm=float(max(over.max(), 0.0)),
        zone_samples=zone_samples,
        entered_linear_from_bang=int(from_bang.sum()),
        max_entry_speed=float(entry.max()),
        band=band,
    )


def all_properties(
    cfg: Config, laws: tuple[str, ...] = ("to", "pd", "pto", "pto-printed"), **kwargs
) -> dict[str, LawProperties]:
    """Run :func:`law_properties` for each named law.

    Parameters
    ----------
    cfg : Config
        Configuration.
    laws : tuple of str
        Law names.
    **kwargs
        Passed to :func:`law_properties`.

    Returns
    -------
    dict
        Law name -> :class:`LawProperties`.
    """
    if not kwargs:
        return {name: named_properties(cfg, name) for name in laws}
    return {name: law_properties(make_law(name, cfg), cfg, **kwargs) for name in laws}


@memo(maxsize=16)
def named_properties(cfg: Config, law: str) -> LawProperties:
    """Properties of the law called ``law`` on the default grid, once per configuration.

    Memoized on the frozen configuration: the report's properties section and
    the ``no-stride-over`` / ``no-limit-cycle`` gates share one simulation.
    ``named_properties.cache_clear()`` empties the memo.

    Parameters
    ----------
    cfg : Config
        Configuration.
    law : str
        Law name (:func:`ptoverify.model.laws.make_law`).

    Returns
    -------
    LawProperties
    """
    return law_properties(make_law(law, cfg), cfg)


def zone_outcome(cfg: Config, *, n1: int = 41, n2: int = 41, rest: int = 40) -> dict:
    """Judge the PTO variants by their closed-loop outcome (what the zone was for).

    Two questions, per law (``pto``: corrected zone; ``pto-printed``):

    * does the sampled state enter the zone (or reach the linear zone on the
      right side of l1/l2) before it crosses l1/l2?  Yes when there is no
      stride-over and no crossing into the linear zone;
    * does it reach the linear zone slowly enough to settle without overshoot?
      Yes when no rest state overshoots by more than the band and no state
      oscillates.

    Parameters
    ----------
    cfg : Config
        Configuration.
    n1, n2, rest : int
        Grid sizes (a coarser grid than :func:`law_properties`' default).

    Returns
    -------
    dict
        Per law: ``enters_zone_before_crossing``, ``settles_without_overshoot``,
        and the counts behind them.
    """
    out = {}
    for name in ("pto", "pto-printed"):
        p = law_properties(make_law(name, cfg), cfg, n1=n1, n2=n2, rest=rest)
        out[name] = {
            "note": p.note,
            "states": p.states,
            "enters_zone_before_crossing": p.stride_overs == 0 and p.crossings_into_linear == 0,
            "settles_without_overshoot": p.overshoots == 0 and p.limit_cycles == 0,
            "stride_overs": p.stride_overs,
            "crossings_into_linear": p.crossings_into_linear,
            "entered_linear_from_bang": p.entered_linear_from_bang,
            "zone_samples": p.zone_samples,
            "overshoots": p.overshoots,
            "max_overshoot_mm": p.max_overshoot_mm,
            "limit_cycles": p.limit_cycles,
            "max_entry_speed": p.max_entry_speed,
        }
    return out
