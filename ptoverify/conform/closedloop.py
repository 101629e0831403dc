"""Closed-loop properties of a user law under ``conform`` (nominal loop).

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions).  The sweep of ``check`` with :mod:`ptoverify.studies.properties`'
definitions: stride-overs, limit cycles or not settled, |u| <= w_max, and
settling against the discrete-time limit N*.

Settling is the settling definition ``SETTLING`` = ``"0p001mm"`` of
:data:`ptoverify.sim.settling.DEFINITIONS` (|x1| <= 0.001 mm), read on the
sample grid (:attr:`ptoverify.sim.settling.Settling.grid`): the first sample
from which every later sample is in the band, in samples; never settled is
inf.  The settling limit is :meth:`ptoverify.config.ConformLimits.settling_limit`
of the reference's worst excess over N* (``[conform]`` in the configuration:
by default E_ref + max(2, ceil(E_ref / 2)) samples).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import failure, reference
from ptoverify.conform.userlaw import LawFault
from ptoverify.model.laws import Law
from ptoverify.model.memo import memo
from ptoverify.sim.settling import DEFINITIONS
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict

__all__ = [
    "SETTLING",
    "CLOSED_PROPERTIES",
    "as_law",
    "settle_samples",
    "settling_states",
    "closed_loop",
    "sweep_sizes",
]

SETTLING = "0p001mm"  #: the settling definition of the closed-loop properties (by name)
BAND_MM = DEFINITIONS[SETTLING].band_mm  #: its band [mm] (also the oscillation band)
#: the closed-loop properties, in the order they are evaluated
CLOSED_PROPERTIES = (
    "no-stride-over",
    "no-limit-cycle",
    "input-bound",
    "settling-vs-discrete-limit",
)


def as_law(user, cfg: Config) -> Law:
    """Wrap a user law as a :class:`Law` whose regions are the reference's (geometry).

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The wrapped law (an isolated law is called through its child process).
    cfg : Config
        Configuration.

    Returns
    -------
    Law
        Named ``user``; ``vector`` and ``scalar`` return (u [mm/s], region code).
    """
    ref = reference(cfg)

    def vector(x1, x2):
        u = user(x1, x2).reshape(np.shape(x1))
        return u, ref.vector(x1, x2)[1]

    def scalar(x1, x2):
        return user.scalar(x1, x2), ref.scalar(x1, x2)[1]

    return Law("user", vector, scalar, cfg.plant.w_max, "third-party law under conform")


def _first(mask: NDArray[np.bool_]) -> tuple[int, int] | None:
    """(sample, trajectory) of the first trajectory (grid order) where mask holds."""
    cols = mask.any(axis=0)
    if not cols.any():
        return None
    j = int(np.argmax(cols))
    return int(np.argmax(mask[:, j])), j


def settle_samples(res, plant, a_ratio: float = 1.0) -> NDArray[np.float64]:
    """Settling samples of a batch under the definition ``SETTLING`` (sample grid).

    Parameters
    ----------
    res : BatchResult
        Trajectories to the origin (:func:`ptoverify.sim.simulate.simulate_batch`).
    plant : Plant
        The design plant (sample time T [s], a [rad/s]).
    a_ratio : float
        True a over design a of the simulated plant [-] (the flow between samples).

    Returns
    -------
    ndarray, shape (n,)
        First sample from which every later sample has |x1| <= the band
        [samples]; inf where the record ends outside it.
    """
    from ptoverify.sim.flow import Trajectory
    from ptoverify.sim.settling import settling_time

    T = plant.sample_time
    t = np.arange(res.x1.shape[0]) * T
    tr = Trajectory.from_samples(t, res.x1, res.x2, res.u, plant.a * a_ratio)
    grid = settling_time(tr, None, SETTLING).grid
    return np.where(np.isnan(grid), np.inf, np.rint(grid / T))


@memo(maxsize=8)
def _settling_reference(cfg: Config) -> dict:
    """Settling sweep states, their N*, and the reference's settling steps (cached)."""
    from ptoverify.model.mintime import discrete_min_steps_batch
    from ptoverify.sim.simulate import simulate_batch
    from ptoverify.studies.properties import default_steps, initial_grid

    x1, x2, _ = initial_grid(cfg, 11, 11, 20)
    dm = discrete_min_steps_batch(x1, x2, cfg.plant)
    n_star = dm.steps.astype(float)  # -1 where N* > n_max
    steps = default_steps(cfg)
    res = simulate_batch(reference(cfg), cfg.plant, x1, x2, steps)
    s_ref = settle_samples(res, cfg.plant)
    ok = n_star >= 0
    e_ref = float(np.max(s_ref[ok] - n_star[ok])) if ok.any() else math.inf
    failed = [(float(x1[i]), float(x2[i]), "not_found") for i in np.flatnonzero(~ok)]
    return {
        "x1": x1,
        "x2": x2,
        "n_star": n_star,
        "steps": steps,
        "s_ref": s_ref,
        "e_ref": e_ref,
        "failed": failed,
    }


def _settling(law: Law, cfg: Config, visited: list) -> tuple[Verdict, list[dict]]:
    from ptoverify.sim.simulate import simulate_batch

    name = "settling-vs-discrete-limit"
    ref = _settling_reference(cfg)
    if ref["failed"] or not math.isfinite(ref["e_ref"]):
        s = ref["failed"][0] if ref["failed"] else (0.0, 0.0, "reference unsettled")
        detail = f"N* could not be established at ({s[0]:g}, {s[1]:g}): {s[2]}"
        return Verdict(name, UNVERIFIED, None, None, detail, "<=", "samples"), [
            failure(name, s[:2], detail)
        ]
    res = simulate_batch(law, cfg.plant, ref["x1"], ref["x2"], ref["steps"])
    visited.append(res)
    s = settle_samples(res, cfg.plant)
    excess = s - ref["n_star"]
    e_ref = ref["e_ref"]
    lim = cfg.conform
    limit = lim.settling_limit(e_ref)
    worst = float(np.max(excess))
    ratio = float(np.max(s / np.maximum(ref["n_star"], 1.0)))
    v = Verdict(
        name,
        PASS if worst <= limit else FAIL,
        worst,
        limit,
        f"worst (settling samples - N*) over {s.size} states (settling definition "
        f"{SETTLING}: |x1| <= {BAND_MM:g} mm for good, on the samples); reference worst "
        f"{e_ref:g} samples; limit E_ref + max({lim.settling_min_samples}, "
        f"ceil({lim.settling_margin:g} E_ref)) ([conform]); worst ratio t_s / (N* T) = {ratio:.3g} "
        f"(T = {cfg.plant.sample_time:g} s)",
        "<=",
        "samples",
    )
    fails = []
    if worst > limit:
        i = int(np.argmax(excess > limit))
        fails.append(
            failure(
                name,
                (ref["x1"][i], ref["x2"][i]),
                f"settles in {s[i]:g} samples, N* = {ref['n_star'][i]:g} (reference "
                f"{ref['s_ref'][i]:g}); excess {excess[i]:g} > {limit:g} samples",
            )
        )
    return v, fails


def settling_states(cfg: Config, user_run) -> dict:
    """Per-state settling of the settling sweep: the user law, the reference and N*.

    Parameters
    ----------
    cfg : Config
        Configuration.
    user_run : BatchResult
        The user law's settling sweep (the second
        :class:`~ptoverify.sim.simulate.BatchResult` that :func:`closed_loop` visits).

    Returns
    -------
    dict
        ``x1``, ``x2`` initial states [mm], [mm/s]; ``n_star`` (N*, -1 where
        unknown), ``s_user`` and ``s_ref`` (settling samples, |x1| <= ``band_mm``
        for good; inf if never); ``band_mm`` [mm]; ``sample_time_s`` [s].
    """
    ref = _settling_reference(cfg)
    return {
        "x1": ref["x1"],
        "x2": ref["x2"],
        "n_star": ref["n_star"],
        "s_user": settle_samples(user_run, cfg.plant),
        "s_ref": ref["s_ref"],
        "band_mm": BAND_MM,
        "definition": SETTLING,
        "sample_time_s": cfg.plant.sample_time,
    }


def sweep_sizes(mode: str, sweep: tuple[int, int, int] | None) -> tuple[int, int, int]:
    """Return the closed-loop sweep (n1, n2, rest): ``sweep``, else by the law's mode.

    Parameters
    ----------
    mode : str
        ``vectorized`` (101 x 101 + 200) or ``scalar`` (21 x 21 + 40).
    sweep : (n1, n2, rest) or None
        An explicit sweep.

    Returns
    -------
    tuple of int
    """
    if sweep is not None:
        n1, n2, rest = sweep
        return int(n1), int(n2), int(rest)  # a memo key (model.memo): plain ints
    return (101, 101, 200) if mode == "vectorized" else (21, 21, 40)


def _count(name: str, count: int, where: str, detail: str) -> Verdict:
    return Verdict(name, PASS if count == 0 else FAIL, count, 0, f"{detail} {where}", "<=", "1")


def closed_loop(
    user, cfg: Config, *, sweep: tuple[int, int, int] | None = None, visited: list | None = None
) -> tuple[dict[str, Verdict], list[dict]]:
    """Closed-loop properties of a user law, as ``check`` gates them.

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The wrapped law.
    cfg : Config
        Configuration.
    sweep : (n1, n2, rest), optional
        Sweep grid (:func:`ptoverify.studies.properties.initial_grid`); default
        101 x 101 + 200 vectorized, 21 x 21 + 40 scalar.
    visited : list, optional
        Receives the :class:`~ptoverify.sim.simulate.BatchResult` of each sweep
        (the states the law was used at, for the agreement).

    Returns
    -------
    properties : dict of str to Verdict
        ``no-stride-over``, ``no-limit-cycle``, ``input-bound`` (closed loop),
        ``settling-vs-discrete-limit``.
    failures : list of dict
        Failing properties with the first initial state that shows each.
    """
    from ptoverify.sim.simulate import simulate_batch
    from ptoverify.studies.properties import (
        crossing_masks,
        default_steps,
        initial_grid,
        oscillating,
    )

    visited = [] if visited is None else visited
    law = as_law(user, cfg)
    n1, n2, rest = sweep_sizes(user.mode, sweep)
    x1, x2, _ = initial_grid(cfg, n1, n2, rest)
    steps = default_steps(cfg)
    try:
        res = simulate_batch(law, cfg.plant, x1, x2, steps)
    except LawFault as fault:
        detail = f"closed-loop simulation stopped: {fault.message}"
        props = {n: Verdict(n, FAIL, None, None, detail) for n in CLOSED_PROPERTIES}
        return props, [failure("evaluation", fault.state, detail)]
    visited.append(res)
    w = cfg.plant.w_max
    stride, _ = crossing_masks(res.x1, res.x2, res.region, cfg)
    osc = oscillating(res.x1[-max(20, steps // 4) :], BAND_MM)
    unsettled = np.abs(res.x1[-1]) > BAND_MM
    over = np.abs(res.u) > w
    where = f"over {x1.size} initial states x {steps} samples"
    at_end = np.zeros((steps + 1, x1.size), dtype=bool)
    at_end[-1] = osc | unsettled
    checks = (
        (
            "no-stride-over",
            stride,
            "stride-overs (sample outside zone and linear zone whose next sample is "
            "strictly across l1/l2 and outside the linear zone)",
            "stride-over",
        ),
        (
            "no-limit-cycle",
            at_end,
            f"states with sustained oscillation ({int(osc.sum())}) or not settled within "
            f"{BAND_MM:g} mm ({int(unsettled.sum())})",
            "sustained oscillation or not settled",
        ),
        (
            "input-bound",
            over,
            f"samples with |u| > w_max = {w:g} mm/s (max {float(np.abs(res.u).max()):.10g})",
            "|u| > w_max",
        ),
    )
    props, fails = {}, []
    for name, mask, detail, what in checks:
        count = int(mask.sum())
        props[name] = _count(name, count, where, detail)
        hit = _first(mask)
        if hit is not None:
            k, j = hit
            fails.append(
                failure(
                    name,
                    (x1[j], x2[j]),
                    f"{what} (first from initial state ({x1[j]:.6g}, {x2[j]:.6g}), sample "
                    f"{k}: ({res.x1[k, j]:.6g}, {res.x2[k, j]:.6g})); {count} in all",
                    sample=k,
                    at=[float(res.x1[k, j]), float(res.x2[k, j])],
                )
            )
    name = "settling-vs-discrete-limit"
    try:
        props[name], f = _settling(law, cfg, visited)
    except LawFault as fault:
        detail = f"settling simulation stopped: {fault.message}"
        props[name] = Verdict(name, FAIL, None, None, detail, "<=", "samples")
        f = [failure("evaluation", fault.state, detail)]
    return props, fails + f
