"""The evidence behind a ``conform`` verdict, for ``conform --report`` (numeric layer).

:func:`conform_with_evidence` runs the conformance exactly as ``conform`` does
(:func:`ptoverify.conform.gate.conform_spec` for a ``--law``, isolated in its child
process; :func:`ptoverify.conform.gate.conform_table` for a ``--table``) and keeps
what a reviewer needs to see why the law conforms or not.  Nothing here draws
or writes (:mod:`ptoverify.report.conform_report` does).

Decisions:

Map of |u - u_ref|
    Every state the agreement judged (for a law: the conformance grid, the
    100000 random states and every sample of the closed-loop sweeps; for a
    table: its states), curve ties excluded as the agreement excludes them, is
    binned into cells and each cell shows the largest |u - u_ref| [mm/s] in
    it; cells without a judged state stay blank.  Two windows: the whole
    envelope (|x1| <= position_range, |x2| <= w_max) and a zoom on the curves
    (|x1| <= max(4 d, 1.3 x the widest of l1, l1*), where the switching and
    linear zones are).  The largest cell of the envelope map, or of the states
    outside it (counted), is the agreement's max |du|.
Region boundaries
    l1, l2 (level w_max, eqs. 9, 11) and l1*, l2* (level omega0 of the
    corrected zone, eqs. 13, 14) from :func:`ptoverify.model.curves.level_curve_x1`,
    omega0 from :mod:`ptoverify.model.zones` (via :func:`ptoverify.conform.agreement.omega0_ref`,
    the level the reference law uses); the linear zone |x1| < d.
Responses
    The Section 6 step, ramp and sine (:data:`ptoverify.sim.simulate.SIGNALS`,
    feed-forward tracking) of the user law, simulated with
    :func:`ptoverify.sim.simulate.simulate` calling the law through the same child
    process as the conformance, next to the reference law's; metrics exact
    between samples (:func:`ptoverify.sim.exact.exact_metrics`).  A table has no
    responses (u is known only at its states).
Settling against N* T
    Over the settling sweep of the ``settling-vs-discrete-limit`` property
    (states with N* >= 1): settling samples / N* (= t_s / (N* T)), median,
    95th percentile and maximum for the user law and the reference.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import omega0_ref, reference, reference_values
from ptoverify.conform.gate import ConformResult, as_law, conform_spec, conform_table
from ptoverify.model.curves import level_curve_x1
from ptoverify.sim.exact import exact_metrics
from ptoverify.sim.simulate import SIGNALS, SimResult, simulate

__all__ = [
    "DuMap",
    "Boundaries",
    "Response",
    "ConformEvidence",
    "du_map",
    "boundaries",
    "user_responses",
    "settling_summary",
    "conform_with_evidence",
    "reference_delay_cycles",
    "CELLS",
    "SIGNAL_METRICS",
]

CELLS = 121  #: cells per axis of each |u - u_ref| map
#: The response metrics that mean something for each Section 6 signal: a step's
#: settling and rise; a ramp's overshoot past its end value (its "settling" from the
#: record's start measures the ramp, not the law); a sine's phase delay (a sine never
#: settles).
SIGNAL_METRICS = {
    "step": ("overshoot_mm", "rise_time_s", "settling_2pct_s", "settling_0p01mm_s"),
    "ramp": ("overshoot_mm",),
    "sine": ("phase_delay_deg",),
}
_CHUNK = 1_000_000  #: states per reference evaluation


@dataclass(frozen=True, eq=False)
class DuMap:
    """Largest |u - u_ref| per cell over a window of the state plane.

    Attributes
    ----------
    name : str
        ``envelope`` or ``zoom``.
    x1_edges, x2_edges : ndarray
        Cell edges [mm], [mm/s].
    du_max : ndarray, shape (len(x2_edges) - 1, len(x1_edges) - 1)
        Largest |u - u_ref| of the judged states in each cell [mm/s]; NaN where
        no state was judged.
    counts : ndarray of int
        Judged states per cell.
    tolerance : float
        Agreement tolerance [mm/s].
    outside : int
        Judged states outside the window.
    outside_max : float
        Largest |u - u_ref| among them [mm/s] (0 when none).
    """

    name: str
    x1_edges: NDArray[np.float64]
    x2_edges: NDArray[np.float64]
    du_max: NDArray[np.float64]
    counts: NDArray[np.int64]
    tolerance: float
    outside: int
    outside_max: float

    @property
    def max(self) -> float:
        """Largest cell value [mm/s] (0 for an empty map)."""
        return float(np.nanmax(self.du_max)) if np.any(self.counts) else 0.0

    def hot_cells(self, k: int = 5) -> list[dict]:
        """Return the ``k`` cells with the largest |u - u_ref| that exceed the tolerance.

        Returns
        -------
        list of dict
            ``x1_mm`` and ``x2_mm_s`` (cell ranges), ``max_abs_du_mm_s``, ``states``.
        """
        flat = np.where(np.isnan(self.du_max), -1.0, self.du_max).ravel()
        order = np.argsort(flat, kind="stable")[::-1][:k]
        out = []
        for i in order:
            if flat[i] <= self.tolerance:
                break
            r, c = np.unravel_index(int(i), self.du_max.shape)
            out.append(
                {
                    "x1_mm": [float(self.x1_edges[c]), float(self.x1_edges[c + 1])],
                    "x2_mm_s": [float(self.x2_edges[r]), float(self.x2_edges[r + 1])],
                    "max_abs_du_mm_s": float(flat[i]),
                    "states": int(self.counts[r, c]),
                }
            )
        return out

    def to_json(self) -> dict:
        """Summary for ``results.json`` (the cells themselves are in the figure)."""
        return {
            "window_x1_mm": [float(self.x1_edges[0]), float(self.x1_edges[-1])],
            "window_x2_mm_s": [float(self.x2_edges[0]), float(self.x2_edges[-1])],
            "cells": [int(self.du_max.shape[1]), int(self.du_max.shape[0])],
            "states": int(self.counts.sum()),
            "empty_cells": int((self.counts == 0).sum()),
            "max_abs_du_mm_s": self.max,
            "cells_over_tolerance": int(np.sum(np.nan_to_num(self.du_max) > self.tolerance)),
            "hot_cells": self.hot_cells(),
            "outside": self.outside,
            "outside_max_abs_du_mm_s": self.outside_max,
        }


def du_map(
    x1: NDArray,
    x2: NDArray,
    du: NDArray,
    x1_lim: float,
    x2_lim: float,
    tolerance: float,
    *,
    name: str = "envelope",
    cells: int = CELLS,
) -> DuMap:
    """Bin |u - u_ref| of judged states into cells, keeping each cell's largest.

    Parameters
    ----------
    x1, x2 : ndarray
        Judged states [mm], [mm/s].
    du : ndarray
        |u - u_ref| at them [mm/s].
    x1_lim, x2_lim : float
        Window |x1| <= x1_lim [mm], |x2| <= x2_lim [mm/s].
    tolerance : float
        Agreement tolerance [mm/s] (kept for the hot cells).
    name : str
        Name of the window.
    cells : int
        Cells per axis.

    Returns
    -------
    DuMap
        The map.

    Examples
    --------
    >>> m = du_map(np.array([-0.5, 0.9]), np.array([0.0, 0.0]), np.array([1.0, 2.0]), 1, 1, 0.5,
    ...            cells=2)
    >>> m.max, m.counts.tolist()
    (2.0, [[0, 0], [1, 1]])
    """
    e1, e2 = np.linspace(-x1_lim, x1_lim, cells + 1), np.linspace(-x2_lim, x2_lim, cells + 1)
    inside = (np.abs(x1) <= x1_lim) & (np.abs(x2) <= x2_lim)
    c = np.clip(np.searchsorted(e1, x1[inside], side="right") - 1, 0, cells - 1)
    r = np.clip(np.searchsorted(e2, x2[inside], side="right") - 1, 0, cells - 1)
    flat = r * cells + c
    best = np.full(cells * cells, -1.0)
    np.maximum.at(best, flat, du[inside])
    counts = np.bincount(flat, minlength=cells * cells).reshape(cells, cells)
    best = np.where(best < 0, np.nan, best).reshape(cells, cells)
    out = du[~inside]
    return DuMap(name, e1, e2, best, counts, tolerance, int(out.size), float(out.max(initial=0.0)))


@dataclass(frozen=True, eq=False)
class Boundaries:
    """The region boundaries of the reference law, computed for drawing.

    Attributes
    ----------
    curves : dict of str to (ndarray, ndarray)
        Label -> (x1 [mm], x2 [mm/s]) of l1, l2 (eqs. 9, 11) and, when the
        reference has a switching zone, l1*, l2* (eqs. 13, 14).
    d : float
        Half-width of the linear zone |x1| < d [mm] (a baseline reference: its
        linear region's, :func:`ptoverify.conform.reflaw.linear_edge`).
    omega0 : float or None
        Level of l1*, l2* [mm/s] (None: no switching zone).
    zoom_x1 : float
        Half-width of the zoom window [mm].
    """

    curves: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]]
    d: float
    omega0: float | None
    zoom_x1: float


def boundaries(cfg: Config, points: int = 400) -> Boundaries:
    """Compute l1, l2, l1*, l2* and the linear zone of the reference law.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], d [mm]).
    points : int
        Points per curve.

    Returns
    -------
    Boundaries
        The curves, d, omega0 and the zoom half-width.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> b = boundaries(paper_config())
    >>> sorted(b.curves), b.d
    (['l1', 'l1*', 'l2', 'l2*'], 0.5)
    """
    from ptoverify.conform.reflaw import linear_edge

    a, w, d = cfg.plant.a, cfg.plant.w_max, linear_edge(cfg)
    neg, pos = np.linspace(-w, 0.0, points), np.linspace(0.0, w, points)
    curves = {
        "l1": (level_curve_x1(neg, a, w), neg),
        "l2": (level_curve_x1(pos, a, w), pos),
    }
    om = omega0_ref(cfg)
    if om is not None:
        curves["l1*"] = (level_curve_x1(neg, a, om), neg)
        curves["l2*"] = (level_curve_x1(pos, a, om), pos)
    widest = max(float(np.max(np.abs(c[0]))) for c in curves.values())
    zoom = min(cfg.plant.position_range, max(4.0 * d, 1.3 * widest))
    return Boundaries(curves, d, om, zoom)


@dataclass(frozen=True, eq=False)
class Response:
    """One Section 6 response of the user law next to the reference law's.

    Attributes
    ----------
    user, reference : SimResult
        The user law's and the reference law's responses (same reference signal).
    user_metrics, reference_metrics : dict
        ``simulate --json`` metrics, exact between samples ([mm], [s], [deg]), only
        those of :data:`SIGNAL_METRICS` for the signal.
    max_abs_dx1_mm : float
        Largest |x1_user - x1_ref| over the samples [mm].
    """

    user: SimResult
    reference: SimResult
    user_metrics: dict
    reference_metrics: dict
    max_abs_dx1_mm: float

    def to_json(self) -> dict:
        """Metrics and the position difference (the series are in the figures)."""
        return {
            "signal": self.user.signal,
            "tracking": self.user.tracking,
            "duration_s": float(self.user.reference.duration),
            "user": self.user_metrics,
            "reference": self.reference_metrics,
            "max_abs_dx1_mm": self.max_abs_dx1_mm,
        }


def user_responses(user, cfg: Config) -> dict[str, Response]:
    """Simulate the user law and the reference on the Section 6 step, ramp and sine.

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The wrapped law (an isolated law is called through its child process).
    cfg : Config
        Configuration.

    Returns
    -------
    dict of str to Response
        By signal name (``step``, ``ramp``, ``sine``).
    """
    law, ref = as_law(user, cfg), reference(cfg)
    out = {}
    for name in SIGNALS:
        ru, rr = simulate(law, cfg.plant, name), simulate(ref, cfg.plant, name)
        keys = SIGNAL_METRICS.get(name, ())
        mu = exact_metrics(ru, cfg.plant, ru.reference).json_metrics()
        mr = exact_metrics(rr, cfg.plant, rr.reference).json_metrics()
        out[name] = Response(
            ru,
            rr,
            {k: mu.get(k) for k in keys},
            {k: mr.get(k) for k in keys},
            float(np.max(np.abs(ru.x1 - rr.x1))),
        )
    return out


def reference_delay_cycles(cfg: Config, delay: int = 1) -> dict:
    """How often the reference law itself limit-cycles with a computation delay.

    The reference's closed loop on the vectorized sweep of ``conform``
    (:func:`ptoverify.studies.properties.initial_grid`, 101 x 101 + 200 states)
    with ``delay`` samples of delay, measured as the perturbed comparison
    measures it (:mod:`ptoverify.conform.perturbed`).

    Parameters
    ----------
    cfg : Config
        Configuration.
    delay : int
        Computation delay [samples].

    Returns
    -------
    dict
        ``delay_samples``, ``states`` and ``cycling`` (initial states that
        oscillate or are not settled at the end), ``unsettled`` (never settled
        under definition ``settling``).
    """
    from ptoverify.conform.closedloop import SETTLING, sweep_sizes
    from ptoverify.conform.perturbed import Perturbation, reference_loop

    sizes = sweep_sizes("vectorized", None)
    loop = reference_loop(cfg, Perturbation(delay_samples=delay), sizes)
    return {
        "delay_samples": delay,
        "states": int(loop.cycle.size),
        "cycling": int(loop.cycle.sum()),
        "unsettled": int(np.isinf(loop.settle).sum()),
        "settling": SETTLING,
    }


def _stats(ratio: NDArray) -> dict:
    finite = ratio[np.isfinite(ratio)]
    if not finite.size:
        return {"median": None, "p95": None, "max": None, "unsettled": int(ratio.size)}
    return {
        "median": float(np.median(finite)),
        "p95": float(np.percentile(finite, 95)),
        "max": float(finite.max()),
        "unsettled": int(ratio.size - finite.size),
    }


def settling_summary(settling: dict) -> dict:
    """Settling / (N* T) of the user law and the reference over the settling sweep.

    Parameters
    ----------
    settling : dict
        :func:`ptoverify.conform.gate.settling_states`.

    Returns
    -------
    dict
        ``states`` (with N* >= 1), ``band_mm`` [mm], ``sample_time_s`` [s],
        ``user`` and ``reference``: median, p95, max of t_s / (N* T) [-] and
        ``unsettled``; ``worst_excess_samples`` and ``worst_state`` [mm, mm/s]
        of the user law (settling samples - N*).
    """
    n_star = np.asarray(settling["n_star"], dtype=float)
    ok = n_star >= 1
    su, sr = settling["s_user"][ok], settling["s_ref"][ok]
    excess = su - n_star[ok]
    i = int(np.argmax(excess)) if excess.size else None
    return {
        "states": int(ok.sum()),
        "band_mm": settling["band_mm"],
        "sample_time_s": settling["sample_time_s"],
        "user": _stats(su / n_star[ok]),
        "reference": _stats(sr / n_star[ok]),
        "worst_excess_samples": None if i is None else float(excess[i]),
        "worst_state": None
        if i is None
        else [float(settling["x1"][ok][i]), float(settling["x2"][ok][i])],
    }


@dataclass(frozen=True, eq=False)
class ConformEvidence:
    """Everything ``conform --report`` shows beyond the :class:`ConformResult`.

    Attributes
    ----------
    maps : list of DuMap
        |u - u_ref| over the envelope and over the zoom window.
    judged, excluded : int
        States judged by the agreement, and curve ties left out of the maps.
    boundaries : Boundaries
        Region boundaries of the reference law.
    responses : dict of str to Response or None
        Step, ramp and sine responses (None for a table or when they could not run).
    responses_note : str
        Why there are no responses (empty when there are).
    settling : dict or None
        :func:`settling_summary` (None when not computed).
    settling_note : str
        Why there is no settling summary.
    reference_delay : dict or None
        :func:`reference_delay_cycles` with a one-sample delay.
    """

    maps: list[DuMap]
    judged: int
    excluded: int
    boundaries: Boundaries
    responses: dict[str, Response] | None
    responses_note: str
    settling: dict | None
    settling_note: str
    reference_delay: dict | None = None

    def to_json(self) -> dict:
        """JSON-able summary (``results.json`` key ``evidence``)."""
        b = self.boundaries
        return {
            "maps": {m.name: m.to_json() for m in self.maps},
            "judged_states": self.judged,
            "excluded_curve_ties": self.excluded,
            "boundaries": {"d_mm": b.d, "omega0_mm_s": b.omega0, "zoom_x1_mm": b.zoom_x1},
            "responses": None
            if self.responses is None
            else {k: r.to_json() for k, r in self.responses.items()},
            "responses_note": self.responses_note,
            "settling": self.settling,
            "settling_note": self.settling_note,
            "reference_delay": self.reference_delay,
        }


def _maps(
    states, cfg: Config, bounds: Boundaries, tol: float, precision: str = "float64", values=None
) -> tuple[list[DuMap], int, int]:
    """Both maps from the judged states (ties excluded, as the agreement does).

    ``values``: the agreement's (u_ref, region, tie) at those states, if it kept them.
    """
    if states is None:
        x1 = x2 = du = np.zeros(0)
        excluded = 0
    else:
        x1, x2, u = (np.asarray(s, dtype=float) for s in states)
        if values is None:
            values = reference_values(x1, x2, cfg, _CHUNK, precision)
        u_ref, _, tie = values
        du = np.abs(u - u_ref)
        excluded = int(tie.sum())
        x1, x2, du = x1[~tie], x2[~tie], du[~tie]
    R, w = cfg.plant.position_range, cfg.plant.w_max
    maps = [
        du_map(x1, x2, du, R, w, tol, name="envelope"),
        du_map(x1, x2, du, bounds.zoom_x1, w, tol, name="zoom"),
    ]
    return maps, int(x1.size), excluded


def conform_with_evidence(
    cfg: Config,
    *,
    law: str | None = None,
    table: str | Path | None = None,
    rtol: float,
    timeout: float,
    precision: str = "float64",
    perturbations: tuple = (),
) -> tuple[ConformResult, ConformEvidence]:
    """Run ``conform`` on a ``--law`` or a ``--table`` and keep the report's evidence.

    Parameters
    ----------
    cfg : Config
        Configuration.
    law : str, optional
        ``MODULE:FUNCTION`` or ``path/file.py:FUNCTION`` (run isolated).
    table : str or Path, optional
        CSV with columns x1, x2, u (exactly one of ``law`` and ``table``).
    rtol : float
        Agreement tolerance relative to w_max.
    timeout : float
        Budget of the isolated law [s] (responses included).
    precision : str
        ``float64`` or ``float32`` (:mod:`ptoverify.conform.precision`).
    perturbations : tuple of Perturbation
        Closed loops under perturbation (:mod:`ptoverify.conform.perturbed`; ``law`` only).

    Returns
    -------
    result : ConformResult
        The verdict, identical to ``conform`` without ``--report``.
    evidence : ConformEvidence
        Maps, boundaries, responses and settling summary.
    """
    keep: dict[str, Any] = {}
    if table is not None:
        result = conform_table(table, cfg, rtol=rtol, keep=keep, precision=precision)
        note = (
            "a --table gives u only at its states, and a closed loop needs u wherever the "
            "trajectory goes: no responses (run --law for them)"
        )
        settle_note = "needs a callable law (--law)"
    else:
        result = conform_spec(
            law,
            cfg,
            rtol=rtol,
            timeout=timeout,
            keep=keep,
            after=lambda user: user_responses(user, cfg),
            precision=precision,
            perturbations=perturbations,
        )
        note, settle_note = "", ""
        if "after" not in keep:
            why = keep.get("after_error") or "the conformance stopped before they could run"
            note = f"not simulated: {why}"
        if "settling" not in keep:
            prop = result.properties.get("settling-vs-discrete-limit")
            settle_note = "not computed" + (f": {prop.detail}" if prop is not None else "")
    bounds = boundaries(cfg)
    tol = rtol * cfg.plant.w_max
    maps, judged, excluded = _maps(
        keep.get("states"), cfg, bounds, tol, precision, keep.get("reference")
    )
    settling = settling_summary(keep["settling"]) if "settling" in keep else None
    evidence = ConformEvidence(
        maps,
        judged,
        excluded,
        bounds,
        keep.get("after"),
        note,
        settling,
        settle_note,
        reference_delay_cycles(cfg, 1),
    )
    return result, evidence
