"""Conformance of a third-party PTO implementation to the reference law, eq. (35).

``ptoverify conform`` judges a user's law ``u = f(x1, x2, cfg)`` (a Python
callable) or a table of its values (CSV, columns x1, x2, u) against the
reference ``make_law("pto", cfg)`` (corrected omega0) and, for a callable, by
the closed-loop properties that ``ptoverify check`` gates.  Every property is
a :class:`ptoverify.verdict.Verdict`; the law conforms only when every one is
``pass`` (``fail``, ``unverified`` and ``not_run`` fail closed).

Decisions (also in ``ptoverify conform --help``):

Loading and isolation
    ``MODULE:FUNCTION`` imports exactly the named module; ``path/file.py:FUNCTION``
    loads exactly that file (:func:`ptoverify.conform.userlaw.load_callable`).  From the
    command line (:func:`conform_spec`) the law is loaded and called in a child
    process (multiprocessing ``spawn``), its stdout/stderr captured, its address
    space limited (RLIMIT_AS, 4 GiB, where the OS has it), the whole conformance
    bounded by ``--timeout`` (default 120 s) and each batch by 10 s + 1 ms per
    state.  A timeout, a signal, any exit of the child (code 0 included) or a
    lost pipe is the finding ``isolation``: every property not evaluated yet is
    ``unverified``.  :func:`conform_callable` runs a callable in this process
    (fast path for the reference and tests).
Interface errors versus findings
    The interface is bad input (exit 2): import error, missing attribute, not
    callable, wrong signature, a non-number or a wrong shape returned.  Values
    at states are findings (exit 1, naming the state): the law raises, returns
    NaN or an infinity (``evaluation``), or is not a deterministic function of
    the state (``pure-function``).
Vectorized or scalar
    The law is called with arrays of 8 probe states; if that returns a float
    array equal to element-wise calls to 1e-12 w_max it is used vectorized,
    otherwise in a scalar loop.  The output says which and why.
Determinism (``pure-function``, every mode)
    On ``N_DETERMINISM`` states (grid states, 200 of them curve ties, and
    random states): the same batch twice, shuffled, and in chunks of 1, 2, 3,
    5, 8, 13, 21 and 34 states must give bit-identical u, and once more after all other
    calls.  A latch, a cache, a debounce, a delay or a call counter shows here;
    after this finding the other properties are ``not_run``.
Agreement (:mod:`ptoverify.conform.agreement`) where the law is used
    |u - u_ref| <= ``rtol`` w_max (default 1e-6) at the probe set
    (:func:`ptoverify.conform.agreement.probe_set`, what ``--emit-grid`` writes): the
    conformance grid, ``N_RANDOM`` = 100000 seeded random states (one jittered
    state in each cell of a 200 x 200 lattice over the envelope, the rest
    uniform) and ``N_BAND`` = 80000 seeded states in a band around l1/l2,
    l1*/l2* and |x1| = d; for a callable also at every state the closed-loop
    and settling sweeps visit (their u is the law's, already computed).  Points outside |x1| < d within
    ``verdict.tie_band`` of l1/l2 or l1*/l2* are excluded and counted.  The
    largest disc of the envelope with no probed state is reported (``gap``).
Odd symmetry
    u(-x) = -u(x) to the agreement tolerance on the grid, curve ties included:
    on a mirrored tie the law must pick the mirrored branch.
Closed loop (callable only)
    The sweep of ``check`` (101 x 101 + 200 states vectorized, 21 x 21 + 40
    scalar) with :mod:`ptoverify.studies.properties`' definitions: stride-overs, limit
    cycles or not settled within 1e-3 mm, |u| <= w_max; settling against the
    discrete-time limit N* (worst excess <= E_ref + max(2, ceil(E_ref / 2))
    samples, E_ref the reference's worst; ``unverified`` if N* is unknown).
Tables
    Regular files only, parsed in chunks.  States beyond 1000 x the envelope
    are bad input (as ``mintime``).  ``coverage``: the table must hold every
    state of the probe set (each within ``MATCH_TOL`` = 1e-6 of position_range
    and w_max per axis, so a state rounded to float32 still counts), or else
    fill the envelope: a state in every cell of the 200 x 200 lattice
    (0.5 mm x 3 mm/s for the paper) and ``MIN_PER_REGION`` judged states (100;
    the origin 1) in every region the reference has on the grid; otherwise
    "insufficient coverage" (exit 1).  Either way a fault confined to a band
    two lattice cells wide (1 mm of x1 or 6 mm/s of x2 for the paper) holds
    probed states.  Agreement and |u| <= w_max are judged at the table's
    states; odd symmetry at the grid states whose exact mirror the table also
    holds (``not_run`` if none); the closed-loop properties need a callable
    and are ``not_run``.  The reference is evaluated at the
    table's x1, x2 as written: firmware that rounds the state must write back
    the state it evaluated.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import (
    DEFAULT_RTOL,
    LATTICE,
    MATCH_TOL,
    N_BAND,
    N_RANDOM,
    RANDOM_SEED,
    agreement,
    conformance_grid,
    failure,
    grid_csv,
    largest_gap,
    probe_set,
    read_table,
    reference,
    region_counts,
    table_coverage,
    ties,
)
from ptoverify.conform.isolation import MEMORY_LIMIT_BYTES, IsolatedLaw, LawAborted
from ptoverify.conform.userlaw import (
    DEFAULT_TIMEOUT_S,
    LawFault,
    UserLaw,
    load_callable,
    wrap_callable,
)
from ptoverify.model.laws import Law, Region
from ptoverify.verdict import FAIL, NOT_RUN, PASS, UNVERIFIED, Verdict

__all__ = [
    "reference_law",
    "reference_law_scalar",
    "load_callable",
    "UserLaw",
    "IsolatedLaw",
    "wrap_callable",
    "LawFault",
    "LawAborted",
    "conformance_grid",
    "grid_csv",
    "read_table",
    "agreement",
    "closed_loop",
    "as_law",
    "settling_states",
    "determinism",
    "ConformResult",
    "conform_callable",
    "conform_spec",
    "conform_table",
    "format_result",
    "DEFAULT_RTOL",
    "DEFAULT_TIMEOUT_S",
    "N_RANDOM",
    "N_BAND",
    "N_DETERMINISM",
    "MIN_PER_REGION",
    "PROPERTIES",
]

_BAND_MM = 1e-3  #: settling / oscillation band [mm], as properties
N_DETERMINISM = 2000  #: states of the determinism check
_CHUNKS = (1, 2, 3, 5, 8, 13, 21, 34)  #: chunk sizes of the determinism check, cycled
MIN_PER_REGION = 100  #: judged table states per reference region (the origin: 1)

#: every property of a callable, in the order they are evaluated
PROPERTIES = (
    "pure-function",
    "agreement",
    "input-bound-grid",
    "odd-symmetry",
    "no-stride-over",
    "no-limit-cycle",
    "input-bound",
    "settling-vs-discrete-limit",
)
_CLOSED = PROPERTIES[4:]


# ------------------------------------------------------------------ reference
def reference_law(x1, x2, cfg: Config):
    """Evaluate the reference PTO law (corrected omega0) as a user-style callable.

    Parameters
    ----------
    x1, x2 : float or array_like
        State [mm], [mm/s].
    cfg : Config
        Configuration.

    Returns
    -------
    float or ndarray
        u [mm/s]; a float for scalar inputs.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> reference_law(0.1, 0.0, paper_config())
    -32.300000000000004
    """
    u, _ = reference(cfg)(x1, x2)
    return float(u) if np.ndim(u) == 0 else u


def reference_law_scalar(x1: float, x2: float, cfg: Config) -> float:
    """Evaluate the reference PTO law on Python floats only (exercises scalar mode)."""
    if not isinstance(x1, float) or not isinstance(x2, float):
        raise TypeError("scalar law: x1 and x2 must be floats")
    return reference(cfg).scalar(x1, x2)[0]


# ------------------------------------------------------------------ determinism
def _determinism_states(cfg: Config, grid: tuple[NDArray, NDArray]) -> tuple[NDArray, NDArray]:
    """Probe-like states: grid points on/near curves and edges, and random states."""
    rng = np.random.default_rng(RANDOM_SEED + 1)
    g1, g2 = grid
    tie = ties(g1, g2, cfg)
    pick = np.concatenate(
        [
            rng.choice(np.flatnonzero(tie), min(200, int(tie.sum())), replace=False),
            rng.choice(g1.size, min(N_DETERMINISM // 2, g1.size), replace=False),
        ]
    )
    n = N_DETERMINISM - pick.size
    R, w = cfg.plant.position_range, cfg.plant.w_max
    x1 = np.concatenate([g1[pick], rng.uniform(-R, R, n)])
    x2 = np.concatenate([g2[pick], rng.uniform(-w, w, n)])
    return x1, x2


def determinism(user, x1: NDArray, x2: NDArray) -> tuple[NDArray, list[dict]]:
    """Call the law on the same states twice, shuffled and in chunks; all must agree.

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The law.
    x1, x2 : ndarray
        States [mm], [mm/s].

    Returns
    -------
    u : ndarray
        u of the first pass [mm/s] (kept for the re-check after all other calls).
    failures : list of dict
        One ``pure-function`` failure at the first differing state, or none.
    """
    first = user(x1, x2)
    perm = np.random.default_rng(RANDOM_SEED + 2).permutation(x1.size)
    shuffled = np.empty_like(first)
    shuffled[perm] = user(x1[perm], x2[perm])
    chunked, i, k = np.empty_like(first), 0, 0
    while i < x1.size:
        j = min(x1.size, i + _CHUNKS[k % len(_CHUNKS)])
        chunked[i:j] = user(x1[i:j], x2[i:j])
        i, k = j, k + 1
    passes = (("a second call", user(x1, x2)), ("a shuffled call", shuffled))
    passes += (("calls in chunks of " + "/".join(map(str, _CHUNKS)), chunked),)
    for how, other in passes:
        fails = _differs(first, other, x1, x2, how)
        if fails:
            return first, fails
    return first, []


def _differs(first, other, x1, x2, how: str) -> list[dict]:
    diff = first != other
    if not diff.any():
        return []
    i = int(np.argmax(diff))
    return [
        failure(
            "pure-function",
            (x1[i], x2[i]),
            f"has memory or is not deterministic: u = {float(first[i])!r} mm/s at the first "
            f"call, {float(other[i])!r} mm/s at {how} ({int(diff.sum())} of {x1.size} "
            "states differ)",
        )
    ]


# ------------------------------------------------------------------ closed loop
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


def _settle_steps(X1: NDArray, band: float) -> NDArray[np.float64]:
    """First sample after which |x1| <= band for good (inf if not at the end)."""
    bad = np.abs(X1) > band
    n = X1.shape[0]
    last_bad = np.where(bad.any(axis=0), n - np.argmax(bad[::-1], axis=0), 0)
    return np.where(bad[-1], np.inf, last_bad.astype(float))


@functools.lru_cache(maxsize=8)
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
    s_ref = _settle_steps(res.x1, _BAND_MM)
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
    s = _settle_steps(res.x1, _BAND_MM)
    excess = s - ref["n_star"]
    e_ref = ref["e_ref"]
    limit = e_ref + max(2.0, math.ceil(e_ref / 2.0))
    worst = float(np.max(excess))
    ratio = float(np.max(s / np.maximum(ref["n_star"], 1.0)))
    v = Verdict(
        name,
        PASS if worst <= limit else FAIL,
        worst,
        limit,
        f"worst (settling samples - N*) over {s.size} states (settling: |x1| <= "
        f"{_BAND_MM:g} mm for good); reference worst {e_ref:g} samples; limit E_ref + "
        f"max(2, ceil(E_ref/2)); worst ratio t_s / (N* T) = {ratio:.3g} "
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


def settling_states(cfg: Config, x1_user: NDArray) -> dict:
    """Per-state settling of the settling sweep: the user law, the reference and N*.

    Parameters
    ----------
    cfg : Config
        Configuration.
    x1_user : ndarray, shape (steps + 1, n)
        Positions [mm] of the user law's settling sweep (the second
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
        "s_user": _settle_steps(np.asarray(x1_user, dtype=float), _BAND_MM),
        "s_ref": ref["s_ref"],
        "band_mm": _BAND_MM,
        "sample_time_s": cfg.plant.sample_time,
    }


def _grid_sizes(mode: str, sweep: tuple[int, int, int] | None) -> tuple[int, int, int]:
    if sweep is not None:
        return sweep
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
    n1, n2, rest = _grid_sizes(user.mode, sweep)
    x1, x2, _ = initial_grid(cfg, n1, n2, rest)
    steps = default_steps(cfg)
    try:
        res = simulate_batch(law, cfg.plant, x1, x2, steps)
    except LawFault as fault:
        detail = f"closed-loop simulation stopped: {fault.message}"
        props = {n: Verdict(n, FAIL, None, None, detail) for n in _CLOSED}
        return props, [failure("evaluation", fault.state, detail)]
    visited.append(res)
    w = cfg.plant.w_max
    stride, _ = crossing_masks(res.x1, res.x2, res.region, cfg)
    osc = oscillating(res.x1[-max(20, steps // 4) :], _BAND_MM)
    unsettled = np.abs(res.x1[-1]) > _BAND_MM
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
            f"{_BAND_MM:g} mm ({int(unsettled.sum())})",
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


def _odd_symmetry(user, x1: NDArray, x2: NDArray, u: NDArray, cfg: Config, rtol: float):
    """u(-x) = -u(x) on the grid, curve ties included, to the agreement tolerance."""
    tol = rtol * cfg.plant.w_max
    um = user(-x1, -x2)
    err = np.abs(u + um)
    bad = err > tol
    tie = ties(x1, x2, cfg)
    v = Verdict(
        "odd-symmetry",
        FAIL if bad.any() else PASS,
        float(err.max()),
        tol,
        f"max |u(x) + u(-x)| over {x1.size} grid states, {int(tie.sum())} of them curve "
        "ties (a mirrored tie must take the mirrored branch); the plant is odd, so the "
        "law must be",
        "<=",
        "mm/s",
    )
    fails = []
    if bad.any():
        i = int(np.argmax(bad))
        on = " (a curve tie)" if tie[i] else ""
        fails.append(
            failure(
                "odd-symmetry",
                (x1[i], x2[i]),
                f"u(x) = {u[i]:.10g}, u(-x) = {um[i]:.10g} mm/s{on}",
            )
        )
    return v, fails


def _input_bound(x1, x2, u, cfg: Config, where: str) -> tuple[Verdict, list[dict]]:
    w = cfg.plant.w_max
    over = np.abs(u) > w
    v = Verdict(
        "input-bound-grid",
        FAIL if over.any() else PASS,
        float(np.abs(u).max()) if u.size else 0.0,
        w,
        f"max |u| {where}; limit w_max",
        "<=",
        "mm/s",
    )
    fails = []
    if over.any():
        i = int(np.argmax(over))
        fails.append(
            failure(
                "input-bound-grid",
                (x1[i], x2[i]),
                f"|u| = {abs(u[i]):.10g} mm/s > w_max = {w:g} mm/s {where}",
            )
        )
    return v, fails


def _agreement_verdict(agree: dict) -> Verdict:
    return Verdict(
        "agreement",
        PASS if agree["pass"] else FAIL,
        agree["max_abs_du"],
        agree["tolerance_mm_s"],
        f"max |u - u_ref| over {agree['points']} states ({agree['excluded']} curve ties "
        f"excluded): {', '.join(f'{k} {v}' for k, v in agree.get('sources', {}).items())}",
        "<=",
        "mm/s",
    )


# ------------------------------------------------------------------ result
@dataclass
class ConformResult:
    """Outcome of ``ptoverify conform`` (the JSON object, see :meth:`to_json`).

    Attributes
    ----------
    conforms : bool
        True when every property is ``pass`` and nothing failed.
    mode : str
        ``vectorized``, ``scalar`` or ``table``.
    target : str
        The ``--law`` spec or ``--table`` path.
    mode_reason : str
        Why the mode was chosen.
    agreement : dict
        Agreement with the reference (:func:`ptoverify.conform.agreement.agreement`),
        with ``sources`` (states per source) and ``gap`` (largest unprobed disc).
    properties : dict of str to Verdict
        Every property, in evaluation order.
    failures : list of dict
        Each with ``property``, ``state`` [x1, x2] (the first that shows it, or
        None for ``isolation``), ``detail``.
    timings_s : dict
        Wall time per phase [s].
    unverified : list of str
        Properties that could not be evaluated (``unverified``).
    law_output : str
        What an isolated law printed (stdout and stderr), first and last 2000 characters.
    """

    conforms: bool
    mode: str
    target: str
    mode_reason: str
    agreement: dict
    properties: dict
    failures: list[dict]
    timings_s: dict = field(default_factory=dict)
    config: str = ""
    law_output: str = ""

    @property
    def unverified(self) -> list[str]:
        """Names of the properties whose status is ``unverified``."""
        return [k for k, v in self.properties.items() if v.status == UNVERIFIED]

    def to_json(self) -> dict:
        """Return the JSON object printed by ``--json``."""
        return {
            "conforms": self.conforms,
            "mode": self.mode,
            "target": self.target,
            "mode_reason": self.mode_reason,
            "config": self.config,
            "agreement": self.agreement,
            "properties": {k: v.to_json() for k, v in self.properties.items()},
            "failures": self.failures,
            "unverified": self.unverified,
            "timings_s": self.timings_s,
        }

    def failed_properties(self) -> list[str]:
        """Names of the failing properties, in order, without repeats."""
        return list(dict.fromkeys(f["property"] for f in self.failures))


def _judge(user, failures: list[dict], cfg: Config, rtol, sweep, grid, n_random, n_band, keep=None):
    """Evaluate every property in order; returns (props, agreement, timings).

    ``keep`` (a dict) receives the judged states ``states`` = (x1, x2, u) and the
    per-state ``settling`` (:func:`settling_states`) when they were computed.
    """
    props: dict[str, Verdict] = {}
    agree: dict = {"pass": False, "detail": "not run"}
    timings: dict[str, float] = {}
    blocked = next((f for f in failures if f["property"] in ("evaluation", "pure-function")), None)
    if blocked is None:
        t = time.perf_counter()
        d1, d2 = _determinism_states(cfg, grid)
        try:
            u_det, f = determinism(user, d1, d2)
        except LawFault as fault:
            f = [failure("evaluation", fault.state, fault.message)]
        failures += f
        blocked = f[0] if f else None
        timings["determinism"] = time.perf_counter() - t
    if blocked is not None:
        why = f"not run: {blocked['property']} failed ({blocked['detail']})"
        agree = {"pass": False, "detail": why}
        return {n: Verdict(n, NOT_RUN, None, None, why) for n in PROPERTIES[1:]}, agree, timings
    props["pure-function"] = Verdict(
        "pure-function",
        PASS,
        0,
        0,
        f"{N_DETERMINISM} states called twice, shuffled and in chunks gave identical u",
        "<=",
        "1",
    )
    t = time.perf_counter()
    probes = probe_set(cfg, grid=grid, n_random=n_random, n_band=n_band)
    g1, g2 = probes["grid"]
    xs = [p[0] for p in probes.values()]
    us, sources = [], {k: int(p[0].size) for k, p in probes.items()}
    try:
        u_grid = user(g1, g2)
        us = [u_grid] + [user(*probes[k]) for k in ("random", "band")]
        ys = [p[1] for p in probes.values()]
        props["input-bound-grid"], f = _input_bound(g1, g2, u_grid, cfg, "on the grid")
        failures += f
        props["odd-symmetry"], f = _odd_symmetry(user, g1, g2, u_grid, cfg, rtol)
        failures += f
    except LawFault as fault:
        failures.append(failure("evaluation", fault.state, fault.message))
        for n in ("agreement", "input-bound-grid", "odd-symmetry"):
            props.setdefault(n, Verdict(n, FAIL, None, None, fault.message))
        us = []
    timings["agreement_grid_random"] = time.perf_counter() - t
    t = time.perf_counter()
    visited: list = []
    cl, f = closed_loop(user, cfg, sweep=sweep, visited=visited)
    props.update(cl)
    failures += f
    timings["closed_loop"] = time.perf_counter() - t
    n_settle = _settling_reference(cfg)["x1"].size
    if keep is not None and len(visited) == 2 and visited[1].x1.shape[1] == n_settle:
        keep["settling"] = settling_states(cfg, visited[1].x1)
    t = time.perf_counter()
    if us:
        for res, label in zip(visited, ("sweep", "settling")):
            xs.append(res.x1[:-1].ravel())
            ys.append(res.x2[:-1].ravel())
            us.append(res.u.ravel())
            sources[label] = res.u.size
        x1, x2, u = np.concatenate(xs), np.concatenate(ys), np.concatenate(us)
        if keep is not None:
            keep["states"] = (x1, x2, u)
        agree, f = agreement(x1, x2, u, cfg, rtol)
        agree["sources"] = sources
        agree["gap"] = largest_gap(x1, x2, cfg)
        failures += f
        props["agreement"] = _agreement_verdict(agree)
    try:
        props["pure-function"], f = _recheck(user, d1, d2, u_det, props["pure-function"])
    except LawFault as fault:
        f = [failure("evaluation", fault.state, f"at the determinism re-check: {fault.message}")]
    failures += f
    timings["agreement"] = time.perf_counter() - t
    return props, agree, timings


def _recheck(user, d1, d2, u_det, v: Verdict) -> tuple[Verdict, list[dict]]:
    """Call the law at the determinism states once more, after every other call."""
    f = _differs(u_det, user(d1, d2), d1, d2, f"the end (after {user.calls} calls)")
    if f:
        return Verdict(v.name, FAIL, 1, 0, f[0]["detail"], "<=", "1"), f
    return v, []


def _finish(user, props, failures, agree, timings, t0, cfg, target, output="") -> ConformResult:
    ordered = {n: props[n] for n in PROPERTIES if n in props}
    timings["total"] = time.perf_counter() - t0
    ok = not failures and all(v.passed for v in ordered.values()) and agree.get("pass", False)
    return ConformResult(
        ok,
        user.mode,
        target,
        user.reason,
        agree,
        ordered,
        failures,
        {k: round(v, 4) for k, v in timings.items()},
        cfg.name,
        _clip(output),
    )


def conform_callable(
    fn: Callable,
    cfg: Config,
    *,
    target: str = "",
    rtol: float = DEFAULT_RTOL,
    sweep: tuple[int, int, int] | None = None,
    grid: tuple[NDArray, NDArray] | None = None,
    n_random: int = N_RANDOM,
    n_band: int = N_BAND,
) -> ConformResult:
    """Judge a law ``u = f(x1, x2, cfg)`` in this process (no isolation).

    Parameters
    ----------
    fn : callable
        The law.
    cfg : Config
        Configuration.
    target : str
        Name shown in the output.
    rtol : float
        Agreement tolerance relative to w_max.
    sweep : (n1, n2, rest), optional
        Closed-loop sweep grid (see :func:`closed_loop`).
    grid : (x1, x2), optional
        Agreement grid; default :func:`conformance_grid`.
    n_random, n_band : int
        Seeded random states over the envelope, and around the curves and
        |x1| = d (:func:`ptoverify.conform.agreement.probe_set`).

    Returns
    -------
    ConformResult
        The verdict; InputError for interface errors.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> r = conform_callable(reference_law, paper_config(), sweep=(5, 5, 4))
    >>> r.conforms, r.mode
    (True, 'vectorized')
    """
    t0 = time.perf_counter()
    user, failures = wrap_callable(fn, cfg)
    timings = {"detect": time.perf_counter() - t0}
    grid = conformance_grid(cfg) if grid is None else grid
    props, agree, t = _judge(user, failures, cfg, rtol, sweep, grid, n_random, n_band)
    timings.update(t)
    return _finish(user, props, failures, agree, timings, t0, cfg, target)


def conform_spec(
    spec: str,
    cfg: Config,
    *,
    rtol: float = DEFAULT_RTOL,
    timeout: float = DEFAULT_TIMEOUT_S,
    sweep: tuple[int, int, int] | None = None,
    grid: tuple[NDArray, NDArray] | None = None,
    n_random: int = N_RANDOM,
    n_band: int = N_BAND,
    keep: dict | None = None,
    after: Callable | None = None,
    memory_limit: int | None = MEMORY_LIMIT_BYTES,
) -> ConformResult:
    """Judge ``MODULE:FUNCTION`` or ``file.py:FUNCTION`` isolated in a child process.

    Parameters
    ----------
    spec : str
        The law to load (its code runs only in the child).
    cfg : Config
        Configuration.
    rtol : float
        Agreement tolerance relative to w_max.
    timeout : float
        Budget for the whole conformance [s] (each batch also gets 10 s + 1 ms
        per state).
    sweep, grid, n_random, n_band
        As :func:`conform_callable`.
    keep : dict, optional
        Receives the evidence behind the verdict: ``states`` (x1, x2, u of every
        judged state), ``settling`` (:func:`settling_states`), and what ``after``
        returned (``after``) or why it could not run (``after_error``).
    after : callable, optional
        ``after(law)`` is called with the live isolated law once every property
        is judged (inside the same child process and ``timeout``), e.g. to
        simulate responses for a report.  A fault or an abort there is recorded
        in ``keep["after_error"]`` and changes no property.
    memory_limit : int or None
        Address-space limit of the law's process [bytes].

    Returns
    -------
    ConformResult
        The verdict; a hang, crash or exit of the law is the failure
        ``isolation`` and leaves the properties not yet evaluated ``unverified``.
    """
    t0 = time.perf_counter()
    with IsolatedLaw(
        spec, cfg, timeout=timeout, memory_limit=memory_limit
    ) as user:  # the child is killed on every path
        return _judge_isolated(
            user, spec, cfg, t0, rtol, sweep, grid, n_random, n_band, keep, after
        )


def _judge_isolated(user, spec, cfg, t0, rtol, sweep, grid, n_random, n_band, keep, after):
    grid = conformance_grid(cfg) if grid is None else grid  # while the child loads
    try:
        user.ready()
    except LawAborted as ab:
        return _aborted(None, {}, [], ab, {}, t0, cfg, spec, user.close())
    failures = list(user.init_failures)
    timings = {"detect": time.perf_counter() - t0}
    props: dict[str, Verdict] = {}
    try:
        props, agree, t = _judge(user, failures, cfg, rtol, sweep, grid, n_random, n_band, keep)
        timings.update(t)
    except LawAborted as ab:
        return _aborted(user, props, failures, ab, timings, t0, cfg, spec, user.close())
    if after is not None:
        keep = {} if keep is None else keep
        try:
            keep["after"] = after(user)
        except (LawFault, LawAborted) as exc:
            keep["after_error"] = exc.message
    return _finish(user, props, failures, agree, timings, t0, cfg, spec, user.close())


def _aborted(user, props, failures, ab, timings, t0, cfg, target, output) -> ConformResult:
    """Build the result after a hang, crash or exit of the isolated law (rest unverified)."""
    failures.append({"property": "isolation", "state": None, "detail": ab.message})
    why = f"could not be evaluated: {ab.message}"
    for n in PROPERTIES:
        props.setdefault(n, Verdict(n, UNVERIFIED, None, None, why))
    timings["total"] = time.perf_counter() - t0
    mode = "unknown" if user is None else user.mode
    reason = "the law's process ended before its mode was known" if user is None else user.reason
    agree = {"pass": False, "detail": why}
    return ConformResult(
        False,
        mode,
        target,
        reason,
        agree,
        {n: props[n] for n in PROPERTIES},
        failures,
        {k: round(v, 4) for k, v in timings.items()},
        cfg.name,
        _clip(output),
    )


def _clip(text: str, n: int = 2000) -> str:
    """Keep the first and last n characters of what the law printed."""
    if len(text) <= 2 * n:
        return text
    return f"{text[:n]}\n[... {len(text) - 2 * n} characters left out ...]\n{text[-n:]}"


def _coverage(agree: dict, cov: dict, cfg: Config) -> Verdict:
    """Judge coverage: the probe set held, or the lattice filled and every region populated."""
    need = region_counts(*conformance_grid(cfg), cfg)
    have = {k: v["points"] - v["excluded"] for k, v in agree["regions"].items()}
    short = []
    for name in need:
        want = 1 if name == Region.ORIGIN.name else MIN_PER_REGION
        if have.get(name, 0) < want:
            short.append(f"{name} {have.get(name, 0)} < {want}")
    rule = (
        f"the table must hold the {cov['probes']} states of --emit-grid (within "
        f"{MATCH_TOL:g} of position_range and w_max), or else a state in each of the "
        f"{LATTICE} x {LATTICE} cells of the envelope and {MIN_PER_REGION} judged states in "
        f"each region of {', '.join(need)} (the origin 1)"
    )
    if cov["missing"] == 0:
        detail = f"holds all {cov['probes']} states of --emit-grid"
        return Verdict("coverage", PASS, 0, 0, detail, "<=", "states missing")
    m = cov["first_missing"]
    held = (
        f"{cov['missing']} of {cov['probes']} states of --emit-grid missing (first "
        f"({m[0]:.10g}, {m[1]:.10g}))"
    )
    if cov["empty_cells"] == 0 and not short:
        detail = f"{held}, but the table fills all {cov['cells']} cells and every region"
        return Verdict("coverage", PASS, 0, 0, detail, "<=", "cells empty")
    gaps = []
    if cov["empty_cells"]:
        e = cov["first_empty"]
        gaps.append(
            f"{cov['empty_cells']} of {cov['cells']} cells empty (first centred at "
            f"({e[0]:.4g}, {e[1]:.4g}))"
        )
    if short:
        gaps.append("too few states in " + ", ".join(short))
    detail = f"insufficient coverage: {held}; {'; '.join(gaps)}; {rule}"
    return Verdict("coverage", FAIL, cov["missing"], 0, detail, "<=", "states missing")


def _table_symmetry(x1, x2, u, rows, cfg: Config, rtol: float) -> tuple[Verdict, list[dict]]:
    """u(-x) = -u(x) at the grid states whose exact mirror the table also holds."""
    name = "odd-symmetry"
    tol = rtol * cfg.plant.w_max
    mirror = rows[::-1]  # the grid is sorted and symmetric: state i mirrors state n-1-i
    ok = (rows >= 0) & (mirror >= 0)
    i, j = rows[ok], mirror[ok]
    exact = (x1[i] == -x1[j]) & (x2[i] == -x2[j])
    i, j = i[exact], j[exact]
    if not i.size:
        why = "no grid state and its exact mirror in the table (needs the --emit-grid states)"
        return Verdict(name, NOT_RUN, None, None, why), []
    err = np.abs(u[i] + u[j])
    bad = err > tol
    tie = ties(x1[i], x2[i], cfg)
    v = Verdict(
        name,
        FAIL if bad.any() else PASS,
        float(err.max()),
        tol,
        f"max |u(x) + u(-x)| over {i.size} table states whose mirror the table holds, "
        f"{int(tie.sum())} of them curve ties (a mirrored tie must take the mirrored branch)",
        "<=",
        "mm/s",
    )
    if not bad.any():
        return v, []
    k = int(np.argmax(bad))
    on = " (a curve tie)" if tie[k] else ""
    a, b = int(i[k]), int(j[k])
    return v, [failure(name, (x1[a], x2[a]), f"u(x) = {u[a]:.10g}, u(-x) = {u[b]:.10g} mm/s{on}")]


def conform_table(
    path: str | Path, cfg: Config, *, rtol: float = DEFAULT_RTOL, keep: dict | None = None
) -> ConformResult:
    """Judge a table x1, x2, u (CSV) against the reference where it has points.

    Parameters
    ----------
    path : str or Path
        CSV with columns x1, x2, u (a regular file).
    cfg : Config
        Configuration.
    rtol : float
        Agreement tolerance relative to w_max.
    keep : dict, optional
        Receives ``states`` = (x1, x2, u), the table's states and values.

    Returns
    -------
    ConformResult
        ``coverage``, ``agreement``, ``input-bound-grid`` and ``odd-symmetry``
        (at mirrored grid states); closed-loop properties ``not_run``.
    """
    t0 = time.perf_counter()
    x1, x2, u = read_table(path, cfg)
    t_read = time.perf_counter() - t0
    if keep is not None:
        keep["states"] = (x1, x2, u)
    agree, failures = agreement(x1, x2, u, cfg, rtol)
    agree["sources"] = {"table": int(x1.size)}
    cov = table_coverage(x1, x2, cfg)
    agree["coverage"] = {k: v for k, v in cov.items() if k != "grid_rows"}
    props = {"coverage": _coverage(agree, cov, cfg), "agreement": _agreement_verdict(agree)}
    if not props["coverage"].passed:
        failures.insert(
            0, {"property": "coverage", "state": None, "detail": props["coverage"].detail}
        )
    props["input-bound-grid"], f = _input_bound(x1, x2, u, cfg, "at the table's states")
    failures += f
    props["odd-symmetry"], f = _table_symmetry(x1, x2, u, cov["grid_rows"], cfg, rtol)
    failures += f
    for name in _CLOSED:
        props[name] = Verdict(name, NOT_RUN, None, None, "needs a callable law (--law)")
    ok = not failures and agree["pass"] and props["coverage"].passed
    total = time.perf_counter() - t0
    return ConformResult(
        ok,
        "table",
        str(path),
        f"table of {x1.size} states",
        agree,
        props,
        failures,
        {"read": round(t_read, 4), "total": round(total, 4)},
        cfg.name,
    )


def format_result(r: ConformResult) -> str:
    """Human-readable report: verdict, agreement per region, properties, failures."""
    why = f": {r.mode_reason}" if r.mode_reason else ""
    lines = [f"{'CONFORMS' if r.conforms else 'DOES NOT CONFORM'}: {r.target} (mode {r.mode}{why})"]
    a = r.agreement
    if "regions" in a:
        src = ", ".join(f"{k} {v}" for k, v in a.get("sources", {}).items())
        lines.append(
            f"agreement with reference PTO: {a['points']} states ({src}), {a['excluded']} "
            f"excluded (within {a['tie_band_mm_s']:.3g} mm/s of l1/l2/l1*/l2*), "
            f"tolerance {a['tolerance_mm_s']:.3g} mm/s ({a['rtol']:g} w_max), "
            f"max |du| = {a['max_abs_du']:.3g} mm/s"
        )
        for name, e in a["regions"].items():
            s = e["state"]
            where = "" if s is None else f" at ({s[0]:.10g}, {s[1]:.10g})"
            lines.append(
                f"  {'ok  ' if e['pass'] else 'FAIL'} {name:<10} {e['points']:>8} "
                f"states ({e['excluded']} excluded) max |du| = "
                f"{e['max_abs_du']:.3g} mm/s{where}"
            )
        if "gap" in a:
            g = a["gap"]
            lines.append(
                f"  largest unprobed disc: centre ({g['center'][0]:.4g}, {g['center'][1]:.4g}), "
                f"half-widths {g['half_width_mm']:.3g} mm x {g['half_width_mm_s']:.3g} mm/s"
            )
    elif a.get("detail"):
        lines.append(f"agreement: {a['detail']}")
    for name, v in r.properties.items():
        lines.append(f"  {v.status.upper():<10} {name:<28} {v.detail}")
    for f in r.failures:
        at = "" if f["state"] is None else f" at state ({f['state'][0]:.10g}, {f['state'][1]:.10g})"
        lines.append(f"FAILED {f['property']}{at}: {f['detail']}")
    lines.append(f"time {r.timings_s.get('total', 0.0):.2f} s")
    return "\n".join(lines)
