"""Conformance under perturbation: the user's law against the reference in real conditions.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions).  ``--delay N``, ``--quantum MM``, ``--velocity-noise MM_S --seed S``
and ``--a-ratio R`` (or ``--robust``: the corners of the configuration's
``[robustness]`` box) make a :class:`Perturbation`.  For each one the
closed-loop sweep of the nominal properties (the same initial states) is
simulated twice by the suite's one simulator
(:func:`ptoverify.sim.simulate.simulate_batch` with a
:class:`~ptoverify.sim.simulate.Mismatch`): once with the user's law and once
with the reference law, under the same perturbation and the same noise
sequence (one seeded sequence per run, shared by every state and both laws).

The verdict is relative, property by property (:class:`Comparison`): the
user's law may be no worse than the reference by more than a stated margin
(``[conform]`` in the configuration, :class:`ptoverify.config.ConformLimits`):

``no-stride-over``, ``no-limit-cycle``
    initial states that stride over l1/l2 at least once, or that oscillate or
    are not settled (|x1| <= 0.001 mm, settling definition ``0p001mm``) at the
    end: user <= reference + ceil(count_margin n) (n initial states; default
    1 %: a law that agrees to 1e-6 w_max can still flip a marginal state of a
    loop that limit-cycles).
``input-bound``
    samples with |u| > w_max: user <= reference (no margin: the bound is the
    drive's, whatever the loop does).
``settling``
    over the initial states from which the reference settles: the user's
    worst settling [samples] <= the reference's worst + max(settling_min_samples,
    ceil(settling_margin x the reference's worst)) (as the nominal settling
    property; never settled is inf and fails).

Where the reference itself fails a property under a perturbation (it strides
over, limit-cycles, exceeds w_max, or fails to settle from some state: e.g. it
limit-cycles with a one-sample delay), the :class:`Comparison` says so
(``reference_fails``), and so do the JSON, the report and the summary line: a
law that conforms there is only as good as the reference.

A law that raises, returns a non-number or hangs during a perturbed run fails
the run's comparisons (``evaluation``) or ends the conformance (``isolation``):
never a pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import failure, reference
from ptoverify.conform.closedloop import BAND_MM, SETTLING, as_law, settle_samples, sweep_sizes
from ptoverify.conform.perturbation import Perturbation, perturbation, robust_box
from ptoverify.conform.userlaw import LawFault
from ptoverify.model.memo import memo
from ptoverify.sim.simulate import BatchResult
from ptoverify.verdict import FAIL, PASS, Verdict

__all__ = [
    "Perturbation",
    "Comparison",
    "PerturbedRun",
    "PERTURBED_PROPERTIES",
    "perturbation",
    "robust_box",
    "perturbed_runs",
    "perturbed_verdicts",
    "reference_loop",
    "LoopMeasures",
]

_NAMES = ("no-stride-over", "no-limit-cycle", "input-bound", "settling")
#: the verdicts under perturbation, in order (one per property, worst perturbation)
PERTURBED_PROPERTIES = tuple(f"perturbed-{n}" for n in _NAMES)


@dataclass(frozen=True)
class Comparison:
    """One property of the user's law against the reference's, under one perturbation.

    Attributes
    ----------
    name : str
        ``no-stride-over``, ``no-limit-cycle``, ``input-bound`` or ``settling``.
    user, reference : float
        Measured on each law: a count of initial states (samples for
        ``input-bound``), or the worst settling [samples] (inf: never).
    limit : float
        The user's value must be <= this [same unit].
    unit : str
        ``states``, ``samples``.
    reference_fails : bool
        The reference itself fails the property (absolutely) under this perturbation.
    passed : bool
        ``user <= limit``.
    detail : str
        What was counted and the margin.
    state : tuple of float or None
        First initial state [mm, mm/s] where the user's law is worse (None: none).
    """

    name: str
    user: float
    reference: float
    limit: float
    unit: str
    reference_fails: bool
    passed: bool
    detail: str
    state: tuple[float, float] | None = None

    def to_json(self) -> dict:
        """Return the comparison as a JSON object (inf as None)."""

        def num(v: float) -> float | None:
            return float(v) if math.isfinite(v) else None

        return {
            "name": self.name,
            "user": num(self.user),
            "reference": num(self.reference),
            "limit": num(self.limit),
            "unit": self.unit,
            "reference_fails": self.reference_fails,
            "pass": self.passed,
            "detail": self.detail,
            "state": None if self.state is None else list(self.state),
        }


@dataclass(frozen=True)
class PerturbedRun:
    """Both laws' closed loops under one perturbation.

    Attributes
    ----------
    perturbation : Perturbation
        The perturbation.
    states : int
        Initial states of the sweep [-].
    steps : int
        Samples simulated [-].
    comparisons : tuple of Comparison
        One per property, in the order of :data:`PERTURBED_PROPERTIES`.
    error : str
        Why the user's law could not be simulated (empty: it was).
    """

    perturbation: Perturbation
    states: int
    steps: int
    comparisons: tuple[Comparison, ...]
    error: str = ""

    @property
    def passed(self) -> bool:
        """Whether the user's law is no worse than the reference on every property."""
        return not self.error and all(c.passed for c in self.comparisons)

    @property
    def reference_fails(self) -> list[str]:
        """Properties the reference itself fails under this perturbation."""
        return [c.name for c in self.comparisons if c.reference_fails]

    def to_json(self) -> dict:
        """Return the run as a JSON object."""
        return {
            "perturbation": self.perturbation.to_json(),
            "states": self.states,
            "steps": self.steps,
            "pass": self.passed,
            "reference_fails": self.reference_fails,
            "comparisons": [c.to_json() for c in self.comparisons],
            "error": self.error,
        }


@dataclass(frozen=True, eq=False)
class LoopMeasures:
    """Per-state closed-loop measures of one law under one perturbation.

    Attributes
    ----------
    stride : ndarray of bool, shape (n,)
        Initial states that stride over l1/l2 at least once.
    cycle : ndarray of bool, shape (n,)
        Initial states that oscillate or are not settled at the end.
    over : int
        Samples with |u| > w_max [-].
    settle : ndarray, shape (n,)
        Settling samples under ``SETTLING`` [samples] (inf: never).
    u_max : float
        Largest |u| [mm/s].
    """

    stride: NDArray[np.bool_]
    cycle: NDArray[np.bool_]
    over: int
    settle: NDArray[np.float64]
    u_max: float


def _measure(res: BatchResult, cfg: Config, p: Perturbation) -> LoopMeasures:
    from ptoverify.studies.properties import crossing_masks, oscillating

    steps = res.u.shape[0]
    stride, _ = crossing_masks(res.x1, res.x2, res.region, cfg)
    osc = oscillating(res.x1[-max(20, steps // 4) :], BAND_MM)
    unsettled = np.abs(res.x1[-1]) > BAND_MM
    au = np.abs(res.u)
    return LoopMeasures(
        stride.any(axis=0),
        osc | unsettled,
        int((au > cfg.plant.w_max).sum()),
        settle_samples(res, cfg.plant, p.a_ratio),
        float(au.max()) if au.size else 0.0,
    )


def _states(cfg: Config, sizes: tuple[int, int, int]) -> tuple[NDArray, NDArray, int]:
    from ptoverify.studies.properties import default_steps, initial_grid

    x1, x2, _ = initial_grid(cfg, *sizes)
    return x1, x2, default_steps(cfg)


@memo(maxsize=16)
def reference_loop(cfg: Config, p: Perturbation, sizes: tuple[int, int, int]) -> LoopMeasures:
    """Measure the reference under ``p`` on the sweep ``sizes`` (cached).

    Parameters
    ----------
    cfg : Config
        Configuration.
    p : Perturbation
        The perturbation.
    sizes : (n1, n2, rest)
        The sweep (:func:`ptoverify.studies.properties.initial_grid`).

    Returns
    -------
    LoopMeasures
        Per initial state: strides over, cycles, settling samples; samples over w_max.
    """
    from ptoverify.sim.simulate import simulate_batch

    x1, x2, steps = _states(cfg, sizes)
    res = simulate_batch(reference(cfg), cfg.plant, x1, x2, steps, mismatch=p.mismatch())
    return _measure(res, cfg, p)


def _compare(user: LoopMeasures, ref: LoopMeasures, x1, x2, cfg: Config) -> tuple[Comparison, ...]:
    lim = cfg.conform
    n = x1.size
    slack = math.ceil(lim.count_margin * n)
    out = []

    def first(mask) -> tuple[float, float] | None:
        if not mask.any():
            return None
        i = int(np.argmax(mask))
        return float(x1[i]), float(x2[i])

    for name, u_m, r_m, what in (
        ("no-stride-over", user.stride, ref.stride, "initial states that stride over l1/l2"),
        (
            "no-limit-cycle",
            user.cycle,
            ref.cycle,
            f"initial states that oscillate or are not settled within {BAND_MM:g} mm at the end",
        ),
    ):
        cu, cr = int(u_m.sum()), int(r_m.sum())
        out.append(
            Comparison(
                name,
                cu,
                cr,
                cr + slack,
                "states",
                cr > 0,
                cu <= cr + slack,
                f"{what}: yours {cu}, reference {cr} of {n}; limit reference + "
                f"ceil({lim.count_margin:g} x {n}) = {cr + slack}",
                first(u_m & ~r_m),
            )
        )
    out.append(
        Comparison(
            "input-bound",
            user.over,
            ref.over,
            ref.over,
            "samples",
            ref.over > 0,
            user.over <= ref.over,
            f"samples with |u| > w_max = {cfg.plant.w_max:g} mm/s (largest |u| yours "
            f"{user.u_max:.10g}, reference {ref.u_max:.10g} mm/s); limit: the reference's",
            None,
        )
    )
    ok = np.isfinite(ref.settle)
    never = int((~ok).sum())
    if not ok.any():
        out.append(
            Comparison(
                "settling",
                math.inf,
                math.inf,
                math.inf,
                "samples",
                True,
                True,
                f"the reference settles from none of the {n} states (definition {SETTLING}): "
                "nothing to compare (no-limit-cycle judges these states)",
                None,
            )
        )
        return tuple(out)
    r_worst = float(ref.settle[ok].max())
    limit = lim.settling_limit(r_worst)
    su = user.settle[ok]
    u_worst = float(su.max())
    out.append(
        Comparison(
            "settling",
            u_worst,
            r_worst,
            limit,
            "samples",
            never > 0,
            u_worst <= limit,
            f"worst settling (definition {SETTLING}: |x1| <= {BAND_MM:g} mm for good, on the "
            f"samples) over the {int(ok.sum())} of {n} states from which the reference "
            f"settles; limit reference + max({lim.settling_min_samples}, "
            f"ceil({lim.settling_margin:g} x reference))"
            + (f"; the reference never settles from {never} states" if never else ""),
            first(ok & (user.settle > limit)),
        )
    )
    return tuple(out)


def perturbed_runs(
    user, cfg: Config, perturbations: tuple[Perturbation, ...], *, sweep=None
) -> tuple[list[PerturbedRun], list[dict]]:
    """Simulate the user's law and the reference under each perturbation and compare.

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The wrapped law.
    cfg : Config
        Configuration (``[conform]`` holds the margins).
    perturbations : tuple of Perturbation
        The perturbations.
    sweep : (n1, n2, rest), optional
        Initial states (:func:`ptoverify.studies.properties.initial_grid`); default
        the nominal closed-loop sweep.

    Returns
    -------
    runs : list of PerturbedRun
        One per perturbation.
    failures : list of dict
        ``perturbed-<property>`` (first state where the user's law is worse) or
        ``evaluation`` (the law failed during a run).
    """
    from ptoverify.sim.simulate import simulate_batch

    sizes = sweep_sizes(user.mode, sweep)
    x1, x2, steps = _states(cfg, sizes)
    law = as_law(user, cfg)
    runs, fails = [], []
    for p in perturbations:
        ref = reference_loop(cfg, p, sizes)
        try:
            res = simulate_batch(law, cfg.plant, x1, x2, steps, mismatch=p.mismatch())
        except LawFault as fault:
            why = f"closed-loop simulation under {p.text()} stopped: {fault.message}"
            fails.append(failure("evaluation", fault.state, why))
            comps = tuple(
                Comparison(n, math.nan, math.nan, math.nan, "", False, False, why) for n in _NAMES
            )
            runs.append(PerturbedRun(p, x1.size, steps, comps, why))
            continue
        comps = _compare(_measure(res, cfg, p), ref, x1, x2, cfg)
        runs.append(PerturbedRun(p, x1.size, steps, comps))
        for c in comps:
            if not c.passed:
                s = c.state if c.state is not None else (math.nan, math.nan)
                f = failure(f"perturbed-{c.name}", s, f"under {p.text()}: {c.detail}")
                if c.state is None:
                    f["state"] = None
                fails.append(f)
    return runs, fails


def perturbed_verdicts(runs: list[PerturbedRun]) -> dict[str, Verdict]:
    """One verdict per property: pass when every run passes; the worst run is shown.

    Parameters
    ----------
    runs : list of PerturbedRun
        The runs.

    Returns
    -------
    dict of str to Verdict
        Keyed by :data:`PERTURBED_PROPERTIES`; measured and limit are the
        worst run's (the first failing one, else the closest to its limit).
    """
    out = {}
    for k, name in enumerate(_NAMES):
        key = f"perturbed-{name}"
        comps = [(r, r.comparisons[k]) for r in runs]
        bad = [(r, c) for r, c in comps if not c.passed]

        def room(rc):
            c = rc[1]
            return c.limit - c.user if math.isfinite(c.limit - c.user) else math.inf

        r, c = bad[0] if bad else min(comps, key=room)
        ref_fails = [x.perturbation.text() for x, cc in comps if cc.reference_fails]
        note = (
            f"; the reference itself fails {name} under: {'; '.join(ref_fails)}"
            if ref_fails
            else ""
        )
        detail = (
            f"{len(runs) - len(bad)} of {len(runs)} perturbations no worse than the "
            f"reference; shown: {r.perturbation.text()}: {c.detail}{note}"
        )
        out[key] = Verdict(
            key,
            FAIL if bad else PASS,
            c.user if math.isfinite(c.user) else None,
            c.limit if math.isfinite(c.limit) else None,
            detail,
            "<=",
            c.unit or "1",
        )
    return out
