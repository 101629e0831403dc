"""Conformance of a third-party PTO implementation to the reference law, eq. (35).

``ptoverify conform`` judges a user's law ``u = f(x1, x2, cfg)`` (a Python
callable) or a table of its values (CSV, columns x1, x2, u) against the
reference ``make_law("pto", cfg)`` (corrected omega0) and, for a callable, by
the closed-loop properties that ``ptoverify check`` gates.  With
``--reference ptos`` or ``--reference cascade-p`` (``[conform] reference``) the
reference is that baseline (:mod:`ptoverify.model.baselines`, the
configuration's gains) and everything below is the same gate, except that a
baseline is continuous, so no state is a curve tie, and the probes crowd its
linear region's edge (:mod:`ptoverify.conform.reflaw`).  Every property is
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
Precision (:mod:`ptoverify.conform.precision`)
    ``float64`` (default) or ``float32``: in float32 the reference is evaluated
    at the state rounded to float32, and states within the derived float32 tie
    band of a region boundary are excluded and counted.
Under perturbation (:mod:`ptoverify.conform.perturbed`, callable only)
    With a delay, quantum, velocity noise (seeded) or a-ratio, or the corners of
    the ``[robustness]`` box, the closed loops of the law and the reference run
    from the same states under the same perturbation and noise; the law may be
    no worse than the reference by more than the ``[conform]`` margins on each
    property, and where the reference itself fails, the result says so.
Closed loop (callable only)
    The sweep of ``check`` (101 x 101 + 200 states vectorized, 21 x 21 + 40
    scalar) with :mod:`ptoverify.studies.properties`' definitions: stride-overs, limit
    cycles or not settled within 1e-3 mm, |u| <= w_max; settling (definition
    ``0p001mm``) against the discrete-time limit N* (worst excess <= E_ref +
    max(2, ceil(E_ref / 2)) samples by default (``[conform]``), E_ref the
    reference's worst; ``unverified`` if N* is unknown).
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

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import (
    DEFAULT_RTOL,
    LATTICE,
    MATCH_TOL,
    N_BAND,
    N_RANDOM,
    agreement,
    conformance_grid,
    failure,
    grid_csv,
    largest_gap,
    probe_set,
    read_table,
    reference,
    ties,
)
from ptoverify.conform.closedloop import (
    CLOSED_PROPERTIES,
    as_law,
    closed_loop,
    settling_states,
)
from ptoverify.conform.determinism import (
    N_DETERMINISM,
    determinism,
    determinism_states,
    differs,
)
from ptoverify.conform.isolation import MEMORY_LIMIT_BYTES, IsolatedLaw, LawAborted
from ptoverify.conform.perturbed import (
    PERTURBED_PROPERTIES,
    Perturbation,
    perturbed_runs,
    perturbed_verdicts,
)
from ptoverify.conform.result import (
    ConformResult,
    agreement_verdict,
    clip_output,
    format_result,
    input_bound,
    summary_line,
)
from ptoverify.conform.table import MIN_PER_REGION, conform_table, judge_table
from ptoverify.conform.userlaw import (
    DEFAULT_TIMEOUT_S,
    LawFault,
    UserLaw,
    load_callable,
    wrap_callable,
)
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
    "judge_table",
    "format_result",
    "summary_line",
    "DEFAULT_RTOL",
    "DEFAULT_TIMEOUT_S",
    "N_RANDOM",
    "N_BAND",
    "N_DETERMINISM",
    "MIN_PER_REGION",
    "PROPERTIES",
    "PERTURBED_PROPERTIES",
    "Perturbation",
    "MATCH_TOL",
    "LATTICE",
]


#: every property of a callable, in the order they are evaluated
PROPERTIES = (
    "pure-function",
    "agreement",
    "input-bound-grid",
    "odd-symmetry",
    "no-stride-over",
    "no-limit-cycle",
    "input-bound",
    *CLOSED_PROPERTIES,
)


# ------------------------------------------------------------------ reference
def reference_law(x1, x2, cfg: Config):
    """Evaluate the reference law (PTO, corrected omega0, unless ``[conform] reference``).

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
    """Evaluate the reference law on Python floats only (exercises scalar mode)."""
    if not isinstance(x1, float) or not isinstance(x2, float):
        raise TypeError("scalar law: x1 and x2 must be floats")
    return reference(cfg).scalar(x1, x2)[0]


# ------------------------------------------------------------------ properties
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


@dataclass(frozen=True)
class _Options:
    """What a conformance judges beyond the law: tolerances, states, precision, perturbations."""

    rtol: float = DEFAULT_RTOL
    sweep: tuple[int, int, int] | None = None
    grid: tuple[NDArray, NDArray] | None = None
    n_random: int = N_RANDOM
    n_band: int = N_BAND
    precision: str = "float64"
    perturbations: tuple[Perturbation, ...] = ()

    def names(self) -> tuple[str, ...]:
        """Every property judged, in order."""
        return PROPERTIES + (PERTURBED_PROPERTIES if self.perturbations else ())


def _judge(user, failures: list[dict], cfg: Config, opt: _Options, keep=None):
    """Evaluate every property in order; returns (props, agreement, timings, runs).

    ``keep`` (a dict) receives the judged states ``states`` = (x1, x2, u), the
    reference's values there ``reference`` (:func:`agreement`) and the per-state
    ``settling`` (:func:`settling_states`) when they were computed.
    """
    props: dict[str, Verdict] = {}
    agree: dict = {"pass": False, "detail": "not run"}
    timings: dict[str, float] = {}
    grid = conformance_grid(cfg) if opt.grid is None else opt.grid
    blocked = next((f for f in failures if f["property"] in ("evaluation", "pure-function")), None)
    if blocked is None:
        t = time.perf_counter()
        d1, d2 = determinism_states(cfg, grid)
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
        props = {n: Verdict(n, NOT_RUN, None, None, why) for n in opt.names()[1:]}
        return props, agree, timings, []
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
    probes = probe_set(cfg, grid=grid, n_random=opt.n_random, n_band=opt.n_band)
    g1, g2 = probes["grid"]
    xs = [p[0] for p in probes.values()]
    us, sources = [], {k: int(p[0].size) for k, p in probes.items()}
    try:
        u_grid = user(g1, g2)
        us = [u_grid] + [user(*probes[k]) for k in ("random", "band")]
        ys = [p[1] for p in probes.values()]
        props["input-bound-grid"], f = input_bound(g1, g2, u_grid, cfg, "on the grid")
        failures += f
        props["odd-symmetry"], f = _odd_symmetry(user, g1, g2, u_grid, cfg, opt.rtol)
        failures += f
    except LawFault as fault:
        failures.append(failure("evaluation", fault.state, fault.message))
        for n in ("agreement", "input-bound-grid", "odd-symmetry"):
            props.setdefault(n, Verdict(n, FAIL, None, None, fault.message))
        us = []
    timings["agreement_grid_random"] = time.perf_counter() - t
    t = time.perf_counter()
    visited: list = []
    cl, f = closed_loop(user, cfg, sweep=opt.sweep, visited=visited)
    props.update(cl)
    failures += f
    timings["closed_loop"] = time.perf_counter() - t
    if keep is not None and len(visited) == 2:
        keep["settling"] = settling_states(cfg, visited[1])
    runs: list = []
    if opt.perturbations:
        t = time.perf_counter()
        runs, f = perturbed_runs(user, cfg, opt.perturbations, sweep=opt.sweep)
        props.update(perturbed_verdicts(runs))
        failures += f
        timings["perturbed"] = time.perf_counter() - t
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
        agree, f = agreement(x1, x2, u, cfg, opt.rtol, precision=opt.precision, keep=keep)
        agree["sources"] = sources
        agree["gap"] = largest_gap(x1, x2, cfg)
        failures += f
        props["agreement"] = agreement_verdict(agree)
    try:
        props["pure-function"], f = _recheck(user, d1, d2, u_det, props["pure-function"])
    except LawFault as fault:
        f = [failure("evaluation", fault.state, f"at the determinism re-check: {fault.message}")]
    failures += f
    timings["agreement"] = time.perf_counter() - t
    return props, agree, timings, runs


def _recheck(user, d1, d2, u_det, v: Verdict) -> tuple[Verdict, list[dict]]:
    """Call the law at the determinism states once more, after every other call."""
    f = differs(u_det, user(d1, d2), d1, d2, f"the end (after {user.calls} calls)")
    if f:
        return Verdict(v.name, FAIL, 1, 0, f[0]["detail"], "<=", "1"), f
    return v, []


def _finish(user, props, failures, agree, timings, t0, cfg, target, opt, runs, output=""):
    ordered = {n: props[n] for n in opt.names() if n in props}
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
        clip_output(output),
        opt.precision,
        tuple(runs),
        opt.perturbations,
        cfg.conform.reference,
    )


def _options(rtol, sweep, grid, n_random, n_band, precision, perturbations) -> _Options:
    from ptoverify.conform.precision import check_precision

    return _Options(
        rtol, sweep, grid, n_random, n_band, check_precision(precision), tuple(perturbations)
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
    precision: str = "float64",
    perturbations: tuple[Perturbation, ...] = (),
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
    precision : str
        ``float64`` or ``float32``: what the implementation computes in
        (:mod:`ptoverify.conform.precision`).
    perturbations : tuple of Perturbation
        Closed loops to compare with the reference's
        (:mod:`ptoverify.conform.perturbed`); none by default.

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
    opt = _options(rtol, sweep, grid, n_random, n_band, precision, perturbations)
    user, failures = wrap_callable(fn, cfg)
    timings = {"detect": time.perf_counter() - t0}
    props, agree, t, runs = _judge(user, failures, cfg, opt)
    timings.update(t)
    return _finish(user, props, failures, agree, timings, t0, cfg, target, opt, runs)


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
    precision: str = "float64",
    perturbations: tuple[Perturbation, ...] = (),
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
    sweep, grid, n_random, n_band, precision, perturbations
        As :func:`conform_callable`.
    keep : dict, optional
        Receives the evidence behind the verdict: ``states`` (x1, x2, u of every
        judged state), ``reference`` (u_ref, region, tie there), ``settling``
        (:func:`settling_states`), and what ``after``
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
    opt = _options(rtol, sweep, grid, n_random, n_band, precision, perturbations)
    with IsolatedLaw(
        spec, cfg, timeout=timeout, memory_limit=memory_limit
    ) as user:  # the child is killed on every path
        return _judge_isolated(user, spec, cfg, t0, opt, keep, after)


def _judge_isolated(user, spec, cfg, t0, opt: _Options, keep, after):
    if opt.grid is None:  # while the child loads
        opt = replace(opt, grid=conformance_grid(cfg))
    try:
        user.ready()
    except LawAborted as ab:
        return _aborted(None, {}, [], ab, {}, t0, cfg, spec, opt, user.close())
    failures = list(user.init_failures)
    timings = {"detect": time.perf_counter() - t0}
    props: dict[str, Verdict] = {}
    try:
        props, agree, t, runs = _judge(user, failures, cfg, opt, keep)
        timings.update(t)
    except LawAborted as ab:
        return _aborted(user, props, failures, ab, timings, t0, cfg, spec, opt, user.close())
    if after is not None:
        keep = {} if keep is None else keep
        try:
            keep["after"] = after(user)
        except (LawFault, LawAborted) as exc:
            keep["after_error"] = exc.message
    return _finish(user, props, failures, agree, timings, t0, cfg, spec, opt, runs, user.close())


def _aborted(user, props, failures, ab, timings, t0, cfg, target, opt, output) -> ConformResult:
    """Build the result after a hang, crash or exit of the isolated law (rest unverified)."""
    failures.append({"property": "isolation", "state": None, "detail": ab.message})
    why = f"could not be evaluated: {ab.message}"
    for n in opt.names():
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
        {n: props[n] for n in opt.names()},
        failures,
        {k: round(v, 4) for k, v in timings.items()},
        cfg.name,
        clip_output(output),
        opt.precision,
        (),
        opt.perturbations,
        cfg.conform.reference,
    )
