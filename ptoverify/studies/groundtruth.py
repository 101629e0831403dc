"""Ground truth: minimum-time answers that are checked a posteriori, or null.

One home for what a *verified* minimum-time answer is, used alike by
``ptoverify mintime``, the report's ground-truth section and the OCP gates of
``ptoverify check``.  IPOPT's ``Solve_Succeeded`` is necessary, not enough: a
solver can converge to its tolerance and still answer wrongly (at a state of
1e-300 mm its tolerance is the whole problem).  So each OCP answer is checked
against the exact plant (eq. 7) before it counts:

* two-phase: the two arcs (-s w_max for t_switch, then +s w_max until t_f),
  propagated by the exact flow, must end within ``TWO_PHASE_MISS_REL`` x the
  state's scale of the origin;
* collocation: the piecewise-constant input, re-simulated on the exact plant,
  must end within ``COLLOCATION_RESIM_REL`` x the state's scale of the origin.

The scale of a state is |x1| + |x2| / a [mm] (the distance the velocity alone
carries the position); distances from the origin are hypot(x1, x2 / a) [mm].
An answer that fails its check is reported with ``success`` False and a status
beginning ``inaccurate:``: converged but inaccurate is null, never truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ptoverify.config import Config, Plant
from ptoverify.errors import InputError
from ptoverify.model.mintime import DiscreteMinTime, MinTime, discrete_min_steps, min_time
from ptoverify.model.ocp import CollocationOCP, OCPResult, TwoPhaseOCP, resimulate
from ptoverify.model.plant import flow

__all__ = [
    "GroundTruth",
    "verified_mintime",
    "verify_two_phase",
    "verify_collocation",
    "state_scale",
    "TWO_PHASE_MISS_REL",
    "COLLOCATION_RESIM_REL",
    "MAX_INTERVALS",
    "ENVELOPE_FACTOR",
]

#: Largest miss of the propagated two-phase arcs, relative to the state's scale: the
#: arcs are exact, so only IPOPT's tolerance (1e-13 on the dimensionless problem) and
#: round-off of eq. (7) remain; 1e-6 leaves seven orders of margin and still rejects an
#: answer that converged at the scale of its tolerance.
TWO_PHASE_MISS_REL = 1e-6
#: Largest distance of the re-simulated collocation input from the origin, relative to
#: the state's scale: collocation smears the switch over one interval, so the end misses
#: by O(1/N^2) of the scale; 1e-2 accepts N >= about 10 and rejects a coarse grid whose
#: polynomial state is not the plant's.
COLLOCATION_RESIM_REL = 1e-2
#: Largest number of collocation intervals accepted from a user.
MAX_INTERVALS = 2000
#: States beyond this multiple of the envelope (position_range, w_max) are rejected.
ENVELOPE_FACTOR = 1e3


def state_scale(x1: float, x2: float, plant: Plant) -> float:
    """Return the scale |x1| + |x2| / a of a state [mm].

    Parameters
    ----------
    x1, x2 : float
        Position [mm] and velocity [mm/s].
    plant : Plant
        The plant (a [rad/s]).

    Returns
    -------
    float
        The scale [mm]; 0 only at the origin.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> state_scale(5.0, 0.0, paper_config().plant)
    5.0
    """
    return abs(x1) + abs(x2) / plant.a


def verify_two_phase(res: OCPResult, x1: float, x2: float, plant: Plant) -> OCPResult:
    """Check a two-phase answer by propagating its arcs with the exact flow.

    Parameters
    ----------
    res : OCPResult
        Answer of :class:`~ptoverify.model.ocp.TwoPhaseOCP` from (x1, x2).
    x1, x2 : float
        Initial position [mm] and velocity [mm/s] it was solved from.
    plant : Plant
        The plant (a [rad/s], w_max [mm/s]).

    Returns
    -------
    OCPResult
        ``res`` unchanged when it did not converge, or converged and its arcs end
        within ``TWO_PHASE_MISS_REL`` x :func:`state_scale` of the origin; otherwise
        a copy with ``success`` False and status ``inaccurate: ...``.
    """
    scale = state_scale(x1, x2, plant)
    if not res.success or scale == 0.0:
        return res
    y1, y2 = flow(x1, x2, -res.side * plant.w_max, res.t_switch, plant.a)
    z1, z2 = flow(y1, y2, res.side * plant.w_max, res.t_f - res.t_switch, plant.a)
    miss = float(np.hypot(z1, z2 / plant.a))
    if miss <= TWO_PHASE_MISS_REL * scale:
        return res
    return replace(res, success=False, status=f"inaccurate: arcs end {miss:.3g} mm from the origin")


def verify_collocation(res: OCPResult, x1: float, x2: float, plant: Plant) -> OCPResult:
    """Check a collocation answer by its re-simulation on the exact plant.

    Parameters
    ----------
    res : OCPResult
        Answer of :class:`~ptoverify.model.ocp.CollocationOCP` from (x1, x2), carrying
        ``resim_error`` [mm] (its input applied to eq. 7).
    x1, x2 : float
        Initial position [mm] and velocity [mm/s] it was solved from.
    plant : Plant
        The plant (a [rad/s]).

    Returns
    -------
    OCPResult
        ``res`` unchanged when it did not converge, or converged and its
        re-simulation ends within ``COLLOCATION_RESIM_REL`` x :func:`state_scale`
        of the origin; otherwise a copy with ``success`` False and status
        ``inaccurate: ...``.
    """
    scale = state_scale(x1, x2, plant)
    if not res.success or scale == 0.0:
        return res
    err = res.resim_error
    if math.isfinite(err) and err <= COLLOCATION_RESIM_REL * scale:
        return res
    return replace(
        res, success=False, status=f"inaccurate: re-simulation ends {err:.3g} mm from the origin"
    )


def _verified(value: float, ok: bool) -> float | None:
    return float(value) if ok else None


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """Minimum time from one state by every reference, each checked or null.

    Attributes
    ----------
    x0 : tuple of float
        Initial position [mm] and velocity [mm/s].
    intervals : int
        Collocation intervals N.
    sample_time : float
        Sample time T [s] of the discrete-time limit.
    closed_form : MinTime
        Closed-form minimum time and switch time (scalars) [s].
    two_phase : OCPResult
        Two-phase OCP answer after :func:`verify_two_phase`.
    collocation : OCPResult
        Collocation answer after :func:`verify_collocation`.
    discrete : DiscreteMinTime
        N*, the discrete-time limit (exact LPs, sequence verified by simulation).
    """

    x0: tuple[float, float]
    intervals: int
    sample_time: float
    closed_form: MinTime
    two_phase: OCPResult
    collocation: OCPResult
    discrete: DiscreteMinTime

    @property
    def analytic_s(self) -> float:
        """Closed-form minimum time t_f* [s]."""
        return float(self.closed_form.t_f)

    @property
    def two_phase_s(self) -> float | None:
        """Verified two-phase minimum time [s], None when not verified."""
        return _verified(self.two_phase.t_f, self.two_phase.success)

    @property
    def collocation_s(self) -> float | None:
        """Verified collocation minimum time [s], None when not verified."""
        return _verified(self.collocation.t_f, self.collocation.success)

    @property
    def discrete_s(self) -> float | None:
        """N* T [s], None when N* was not established."""
        return _verified(self.discrete.time_s, self.discrete.success)

    def to_json(self) -> dict[str, Any]:
        """Return the ``ptoverify mintime --json`` object (DESIGN.md keys plus status keys).

        Returns
        -------
        dict
            ``x0``, ``analytic_s``, ``switch_time_s``, ``two_phase_s``,
            ``collocation_s``, ``collocation_intervals``, ``discrete_steps``,
            ``discrete_s``, ``two_phase_switch_time_s``, ``two_phase_status``,
            ``two_phase_iterations``, ``collocation_status``,
            ``collocation_iterations``, ``collocation_resim_error_mm``,
            ``discrete_status``, ``sample_time_s``; an unverified number is None.
        """
        tp, co, dm = self.two_phase, self.collocation, self.discrete
        return {
            "x0": [self.x0[0], self.x0[1]],
            "analytic_s": self.analytic_s,
            "switch_time_s": float(self.closed_form.t_switch),
            "two_phase_s": self.two_phase_s,
            "collocation_s": self.collocation_s,
            "collocation_intervals": self.intervals,
            "discrete_steps": dm.steps if dm.success else None,
            "discrete_s": self.discrete_s,
            "two_phase_switch_time_s": _verified(tp.t_switch, tp.success),
            "two_phase_status": tp.status,
            "two_phase_iterations": tp.iterations,
            "collocation_status": co.status,
            "collocation_iterations": co.iterations,
            "collocation_resim_error_mm": _verified(co.resim_error, co.success),
            "discrete_status": dm.status,
            "sample_time_s": self.sample_time,
        }


def verified_mintime(
    x1: float,
    x2: float,
    cfg: Config,
    *,
    intervals: int = 100,
    max_iter: int | None = None,
    collocation: OCPResult | None = None,
) -> GroundTruth:
    """Minimum time from (x1, x2) by the closed form, both OCPs and N*, each checked.

    A reference whose solver did not converge, whose answer fails its a-posteriori
    check (status ``inaccurate: ...``), or an N* search that failed, is null in
    :meth:`GroundTruth.to_json` with its status: unverified, never truth.

    Parameters
    ----------
    x1, x2 : float
        Initial position [mm] and velocity [mm/s].  States beyond
        ``ENVELOPE_FACTOR`` x the envelope (|x1| > 1000 position_range or
        |x2| > 1000 w_max) are rejected; N* is searched up to 20000 samples and
        is null with ``discrete_status`` ``not_found`` beyond.
    cfg : Config
        Configuration (its plant).
    intervals : int
        Collocation intervals N, in [1, ``MAX_INTERVALS``].
    max_iter : int, optional
        Cap on IPOPT iterations (default: the solvers' own caps).
    collocation : OCPResult, optional
        The answer of a default :class:`~ptoverify.model.ocp.CollocationOCP` with
        ``intervals`` from this state, already solved (e.g.
        :attr:`ptoverify.model.ocp.ConvergenceStudy.results`): it is checked like a fresh
        one instead of solving the same NLP again.  Its input must re-simulate to
        its recorded end state from (x1, x2) (else ``ValueError``: an answer from
        another state or N); not with ``max_iter``.

    Returns
    -------
    GroundTruth
        Every reference, checked.

    Raises
    ------
    InputError
        A non-finite state, a state far outside the envelope, or ``intervals``
        outside [1, ``MAX_INTERVALS``].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> gt = verified_mintime(5.0, 0.0, paper_config(), intervals=20)
    >>> abs(gt.two_phase_s - gt.analytic_s) < 1e-9 * gt.analytic_s
    True
    """
    plant = cfg.plant
    x1, x2 = float(x1), float(x2)
    if not (math.isfinite(x1) and math.isfinite(x2)):
        raise InputError(f"state ({x1}, {x2}) is not finite")
    limit1, limit2 = ENVELOPE_FACTOR * plant.position_range, ENVELOPE_FACTOR * plant.w_max
    if abs(x1) > limit1 or abs(x2) > limit2:
        raise InputError(
            f"state ({x1:g}, {x2:g}) is far outside the envelope "
            f"(|x1| <= {limit1:g} mm, |x2| <= {limit2:g} mm/s accepted)"
        )
    if not 1 <= intervals <= MAX_INTERVALS:
        raise InputError(
            f"collocation intervals (--intervals) must be in [1, {MAX_INTERVALS}], got {intervals}"
        )
    caps = {} if max_iter is None else {"max_iter": max_iter}
    tp = TwoPhaseOCP(plant, **caps).solve(x1, x2)
    if collocation is None or (x1 == 0.0 and x2 == 0.0):
        co = CollocationOCP(plant, intervals=intervals, **caps).solve(x1, x2)
    else:
        co = collocation
        if max_iter is not None or co.u is None or co.u.size != 3 * intervals:
            raise ValueError("collocation: not a default N-interval answer (or max_iter given)")
        if resimulate(co.t, co.u, x1, x2, plant.a) != co.resim_end:
            raise ValueError(f"collocation: not an answer from ({x1:g}, {x2:g})")
    return GroundTruth(
        x0=(x1, x2),
        intervals=int(intervals),
        sample_time=plant.sample_time,
        closed_form=min_time(x1, x2, plant),
        two_phase=verify_two_phase(tp, x1, x2, plant),
        collocation=verify_collocation(co, x1, x2, plant),
        discrete=discrete_min_steps(x1, x2, plant),
    )
