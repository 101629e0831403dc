"""Conformance of a third-party PTO implementation to the reference law, eq. (35).

``ptoverify conform`` judges a user's law ``u = f(x1, x2, cfg)`` (a Python
callable) or a table of its values (CSV, columns x1, x2, u) against the
reference ``make_law("pto", cfg)`` (corrected omega0) and, for a callable, by
the closed-loop properties that ``ptoverify check`` gates.

Decisions (also in ``ptoverify conform --help``):

Loading
    ``MODULE:FUNCTION`` imports exactly the named module with
    :func:`importlib.import_module` (it must be importable from ``sys.path`` as
    it stands; nothing is added to the path).  ``path/to/file.py:FUNCTION``
    (the part before the last ``:`` ends in ``.py``) loads exactly that file
    with :func:`importlib.util.spec_from_file_location`.  No path is ever
    searched for.  Loading runs the user's code.  FUNCTION may be dotted
    (``Class.method``).
Interface errors versus findings
    Everything about the *interface* is bad input (exit 2): the module cannot be
    imported, the attribute is missing or not callable, its signature does not
    take (x1, x2, cfg), it returns something that is not a number (scalar mode)
    or an array of the wrong shape.  Everything about the *values at states* is
    a finding (exit 1, naming the state): the function raises at a state,
    returns NaN or an infinity there, or is not a pure function of the state
    (two calls at the same state differ, e.g. a law with memory or a delay).
    A law with memory has no u(x) to compare or to simulate state by state in a
    batch, so after that finding the other properties are ``not_run``.
Vectorized or scalar
    The law is called with arrays of 8 probe states; if that returns a float
    array of the same shape that agrees with element-wise calls on Python floats
    to 1e-12 w_max, the law is used vectorized, otherwise it is wrapped in a
    scalar loop.  The output says which and why.
Agreement (:mod:`ptoverify.agreement`)
    On the conformance grid (:func:`conformance_grid`, what ``--emit-grid``
    writes) or the table's points: |u - u_ref| <= ``rtol`` w_max, default
    rtol = 1e-6 (float32 implementations round at ~6e-8 relative, so they pass
    with headroom, while every seeded fault of the mutation suite is at least
    two orders of magnitude above).  Reported per reference
    region: largest |du|, its state, count of points.  Points outside the
    linear zone within ``tie_band`` (1e-9 (w_max + a position_range) mm/s, the
    tolerance of ``properties``) of a computed curve, l1/l2 or l1*/l2*, are
    excluded and counted: there a float tie can flip the region and u jumps
    by up to 2 w_max.  The linear-zone edge |x1| = d, x2 = 0 and the origin
    are exact comparisons in floats, so no point near them is excluded.
Closed loop (callable only)
    The sweep of ``check`` (:func:`ptoverify.properties.initial_grid`, 101 x 101
    + 200 rest states, vectorized; 21 x 21 + 40 in scalar mode, where every
    state and sample is a Python call) with the same definitions as
    :mod:`ptoverify.properties`: stride-overs (sources in a switching zone are
    judged by the reference's zone geometry, since a user law has no region
    codes), limit cycles and states not settled within 1e-3 mm, |u| <= w_max.
    Odd symmetry u(-x) = -u(x) on the grid to the agreement tolerance (as
    ``check``'s odd-symmetry gate for every law).
Settling against N* T
    On a settling sweep (11 x 11 + 20 rest states) N* is the discrete-time
    limit (fewest ZOH samples to the origin).  The settling step s is the
    first sample after which |x1| stays within 1e-3 mm.  The excess s - N* of
    the reference is computed for the same states; a law passes when its
    worst excess is at most E_ref + max(2, ceil(E_ref / 2)) samples, with
    E_ref the reference's worst excess: the reference passes with that margin,
    an implementation that agrees to tolerance moves its settling sample by at
    most one where a trajectory grazes the band, and a law that loses more
    than half again what the reference loses to the discrete optimum fails.
    If N* cannot be established for a state, the property is ``unverified``
    and the law does not conform (fail closed).
Tables
    Only the agreement and |u| <= w_max are judged where the table has points;
    the closed-loop properties need a callable and are reported ``not_run``.
    The reference is evaluated at the table's x1, x2 as written, so an
    implementation that rounds the state (float32 firmware) must write back
    the state it evaluated: near a curve, a rounded state can lie on the other
    side, where u differs by up to 2 w_max.
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

from ptoverify.agreement import (
    DEFAULT_RTOL,
    FAIL,
    NOT_RUN,
    PASS,
    UNVERIFIED,
    agreement,
    conformance_grid,
    failure,
    grid_csv,
    input_bound,
    read_table,
    reference,
    ties,
)
from ptoverify.config import Config
from ptoverify.laws import Law
from ptoverify.userlaw import LawFault, UserLaw, load_callable, wrap_callable

__all__ = [
    "reference_law",
    "reference_law_scalar",
    "load_callable",
    "UserLaw",
    "wrap_callable",
    "LawFault",
    "conformance_grid",
    "grid_csv",
    "read_table",
    "agreement",
    "closed_loop",
    "ConformResult",
    "conform_callable",
    "conform_table",
    "format_result",
    "DEFAULT_RTOL",
]

_BAND_MM = 1e-3  #: settling / oscillation band [mm], as properties


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


# ------------------------------------------------------------------ closed loop
def _as_law(user: UserLaw, cfg: Config) -> Law:
    """Wrap a user law as a :class:`Law` whose regions are the reference's (geometry)."""
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


def _sweep_analysis(res, x1: NDArray, cfg: Config, band: float, window: int) -> dict:
    """Masks of :func:`ptoverify.properties.law_properties` (same definitions)."""
    from ptoverify.properties import _oscillating, crossing_masks

    w = cfg.plant.w_max
    X1 = res.x1
    stride, _ = crossing_masks(res.x1, res.x2, res.region, cfg)
    osc = _oscillating(X1[-window:], band)
    unsettled = np.abs(X1[-1]) > band
    return {
        "stride": stride,
        "osc": osc,
        "unsettled": unsettled,
        "over": np.abs(res.u) > w,
        "max_u": float(np.abs(res.u).max()),
    }


def _settle_steps(X1: NDArray, band: float) -> NDArray[np.float64]:
    """First sample after which |x1| <= band for good (inf if not at the end)."""
    bad = np.abs(X1) > band
    n = X1.shape[0]
    last_bad = np.where(bad.any(axis=0), n - np.argmax(bad[::-1], axis=0), 0)
    return np.where(bad[-1], np.inf, last_bad.astype(float))


@functools.lru_cache(maxsize=8)
def _settling_reference(cfg: Config) -> dict:
    """Settling sweep states, their N*, and the reference's settling steps (cached)."""
    from ptoverify.mintime import discrete_min_steps_batch
    from ptoverify.properties import default_steps, initial_grid
    from ptoverify.simulate import simulate_batch

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


def _settling(law: Law, cfg: Config) -> tuple[dict, list[dict]]:
    from ptoverify.simulate import simulate_batch

    ref = _settling_reference(cfg)
    T = cfg.plant.sample_time
    if ref["failed"] or not math.isfinite(ref["e_ref"]):
        s = ref["failed"][0] if ref["failed"] else (math.nan, math.nan, "reference unsettled")
        prop = {
            "status": UNVERIFIED,
            "measured": None,
            "limit": None,
            "detail": f"N* could not be established at ({s[0]:g}, {s[1]:g}): {s[2]}",
        }
        return prop, [failure("settling-vs-discrete-limit", s[:2], prop["detail"])]
    res = simulate_batch(law, cfg.plant, ref["x1"], ref["x2"], ref["steps"])
    s = _settle_steps(res.x1, _BAND_MM)
    excess = s - ref["n_star"]
    e_ref = ref["e_ref"]
    limit = e_ref + max(2.0, math.ceil(e_ref / 2.0))
    worst = float(np.max(excess))
    ratio = float(np.max(s / np.maximum(ref["n_star"], 1.0)))
    prop = {
        "status": PASS if worst <= limit else FAIL,
        "measured": worst,
        "limit": limit,
        "detail": f"worst (settling samples - N*) over {s.size} states (settling: |x1| <= "
        f"{_BAND_MM:g} mm for good); reference worst {e_ref:g} samples; "
        f"limit E_ref + max(2, ceil(E_ref/2)); worst ratio t_s / (N* T) = "
        f"{ratio:.3g}",
        "sample_time_s": T,
        "worst_ratio_to_nstar": ratio,
    }
    fails = []
    if worst > limit:
        i = int(np.argmax(excess > limit))
        fails.append(
            failure(
                "settling-vs-discrete-limit",
                (ref["x1"][i], ref["x2"][i]),
                f"settles in {s[i]:g} samples, N* = {ref['n_star'][i]:g} (reference "
                f"{ref['s_ref'][i]:g}); excess {excess[i]:g} > {limit:g} samples",
            )
        )
    return prop, fails


def _grid_sizes(mode: str, sweep: tuple[int, int, int] | None) -> tuple[int, int, int]:
    if sweep is not None:
        return sweep
    return (101, 101, 200) if mode == "vectorized" else (21, 21, 40)


def closed_loop(
    user: UserLaw, cfg: Config, *, sweep: tuple[int, int, int] | None = None
) -> tuple[dict, list[dict]]:
    """Closed-loop properties of a user law, as ``check`` gates them.

    Parameters
    ----------
    user : UserLaw
        The wrapped law.
    cfg : Config
        Configuration.
    sweep : (n1, n2, rest), optional
        Sweep grid (:func:`ptoverify.properties.initial_grid`); default
        101 x 101 + 200 vectorized, 21 x 21 + 40 scalar.

    Returns
    -------
    properties : dict
        ``no-stride-over``, ``no-limit-cycle``, ``input-bound`` (closed loop),
        ``settling-vs-discrete-limit``: each status, measured, limit, detail.
    failures : list of dict
        Failing properties with the first initial state that shows each.
    """
    from ptoverify.properties import default_steps, initial_grid
    from ptoverify.simulate import simulate_batch

    law = _as_law(user, cfg)
    n1, n2, rest = _grid_sizes(user.mode, sweep)
    x1, x2, _ = initial_grid(cfg, n1, n2, rest)
    steps = default_steps(cfg)
    window = max(20, steps // 4)
    try:
        res = simulate_batch(law, cfg.plant, x1, x2, steps)
    except LawFault as fault:
        detail = f"closed-loop simulation stopped: {fault.message}"
        return (
            {"evaluation": {"status": FAIL, "measured": None, "limit": None, "detail": detail}},
            [failure("evaluation", fault.state, detail)],
        )
    m = _sweep_analysis(res, x1, cfg, _BAND_MM, window)
    where = f"over {x1.size} initial states x {steps} samples"
    props, fails = {}, []

    def add(name: str, count: int, mask, detail: str, what: str):
        props[name] = {
            "status": PASS if count == 0 else FAIL,
            "measured": count,
            "limit": 0,
            "detail": f"{detail} {where}",
        }
        hit = _first(mask)
        if hit is not None:
            k, j = hit
            fails.append(
                failure(
                    name,
                    (x1[j], x2[j]),
                    f"{what} (first from initial state ({x1[j]:.6g}, "
                    f"{x2[j]:.6g}), sample {k}: ({res.x1[k, j]:.6g}, "
                    f"{res.x2[k, j]:.6g})); {count} in all",
                    sample=k,
                    at=[float(res.x1[k, j]), float(res.x2[k, j])],
                )
            )

    add(
        "no-stride-over",
        int(m["stride"].sum()),
        m["stride"],
        "stride-overs (sample outside zone and linear zone whose next sample is strictly "
        "across l1/l2 and outside the linear zone)",
        "stride-over",
    )
    cyc = m["osc"] | m["unsettled"]
    at_end = np.zeros((steps + 1, x1.size), dtype=bool)
    at_end[-1] = cyc
    add(
        "no-limit-cycle",
        int(m["osc"].sum() + m["unsettled"].sum()),
        at_end,
        f"states with sustained oscillation ({int(m['osc'].sum())}) or not settled within "
        f"{_BAND_MM:g} mm ({int(m['unsettled'].sum())})",
        "sustained oscillation or not settled",
    )
    add(
        "input-bound",
        int(m["over"].sum()),
        m["over"],
        f"samples with |u| > w_max = {cfg.plant.w_max:g} mm/s (max {m['max_u']:.10g})",
        "|u| > w_max",
    )
    try:
        props["settling-vs-discrete-limit"], f = _settling(law, cfg)
    except LawFault as fault:
        detail = f"settling simulation stopped: {fault.message}"
        props["settling-vs-discrete-limit"] = {
            "status": FAIL,
            "measured": None,
            "limit": None,
            "detail": detail,
        }
        f = [failure("evaluation", fault.state, detail)]
    fails += f
    return props, fails


def _odd_symmetry(
    user: UserLaw, x1: NDArray, x2: NDArray, u: NDArray, cfg: Config, rtol: float
) -> tuple[dict, list[dict]]:
    """u(-x) = -u(x) on the grid (tie points excluded), to the agreement tolerance."""
    tol = rtol * cfg.plant.w_max
    um = user(-x1, -x2)
    err = np.where(ties(x1, x2, cfg), 0.0, np.abs(u + um))
    bad = err > tol
    prop = {
        "status": FAIL if bad.any() else PASS,
        "measured": float(err.max()),
        "limit": tol,
        "detail": f"max |u(x) + u(-x)| [mm/s] over {x1.size} grid states (curve ties "
        "excluded); the plant is odd, so the law must be",
    }
    fails = []
    if bad.any():
        i = int(np.argmax(bad))
        fails.append(
            failure(
                "odd-symmetry", (x1[i], x2[i]), f"u(x) = {u[i]:.10g}, u(-x) = {um[i]:.10g} mm/s"
            )
        )
    return prop, fails


@dataclass
class ConformResult:
    """Outcome of ``ptoverify conform`` (the JSON object, see :meth:`to_json`).

    Attributes
    ----------
    conforms : bool
        True when every judged property passes.
    mode : str
        ``vectorized``, ``scalar`` or ``table``.
    target : str
        The ``--law`` spec or ``--table`` path.
    mode_reason : str
        Why the mode was chosen.
    agreement : dict
        Per-region agreement with the reference (:func:`agreement`).
    properties : dict
        Name -> status, measured, limit, detail.
    failures : list of dict
        Each with ``property``, ``state`` [x1, x2] (the first that shows it), ``detail``.
    timings_s : dict
        Wall time per phase [s].
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

    def to_json(self) -> dict:
        """Return the JSON object printed by ``--json``."""
        return {
            "conforms": self.conforms,
            "mode": self.mode,
            "target": self.target,
            "mode_reason": self.mode_reason,
            "config": self.config,
            "agreement": self.agreement,
            "properties": self.properties,
            "failures": self.failures,
            "timings_s": self.timings_s,
        }

    def failed_properties(self) -> list[str]:
        """Names of the failing properties, in order, without repeats."""
        return list(dict.fromkeys(f["property"] for f in self.failures))


def conform_callable(
    fn: Callable,
    cfg: Config,
    *,
    target: str = "",
    rtol: float = DEFAULT_RTOL,
    sweep: tuple[int, int, int] | None = None,
    grid: tuple[NDArray, NDArray] | None = None,
) -> ConformResult:
    """Judge a user law ``u = f(x1, x2, cfg)`` against the reference PTO law.

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
        Agreement states; default :func:`conformance_grid`.

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
    timings = {}
    user, failures = wrap_callable(fn, cfg)
    timings["detect"] = time.perf_counter() - t0
    x1, x2 = conformance_grid(cfg) if grid is None else grid
    props: dict[str, dict] = {}
    agree: dict = {"pass": False, "detail": "not run: the law failed at a probe state"}
    memory = any(f["property"] == "pure-function" for f in failures)
    if memory:
        agree = {
            "pass": False,
            "detail": "not run: the law has memory, so u is not a "
            "function of the state and there is nothing to compare state by state",
        }
        for name in (
            "input-bound-grid",
            "odd-symmetry",
            "no-stride-over",
            "no-limit-cycle",
            "input-bound",
            "settling-vs-discrete-limit",
        ):
            props[name] = {"status": NOT_RUN, "detail": "the law has memory (pure-function)"}
    elif not any(f["property"] == "evaluation" for f in failures):
        t = time.perf_counter()
        try:
            u = user(x1, x2)
        except LawFault as fault:
            failures.append(failure("evaluation", fault.state, fault.message))
            agree = {"pass": False, "detail": f"not run: {fault.message}"}
        else:
            agree, f = agreement(x1, x2, u, cfg, rtol)
            failures += f
            props["input-bound-grid"], f = input_bound(x1, x2, u, cfg, "on the grid")
            failures += f
            try:
                props["odd-symmetry"], f = _odd_symmetry(user, x1, x2, u, cfg, rtol)
            except LawFault as fault:
                props["odd-symmetry"] = {"status": FAIL, "detail": fault.message}
                f = [failure("evaluation", fault.state, fault.message)]
            failures += f
        timings["agreement"] = time.perf_counter() - t
        t = time.perf_counter()
        cl, f = closed_loop(user, cfg, sweep=sweep)
        props.update(cl)
        failures += f
        timings["closed_loop"] = time.perf_counter() - t
    props.setdefault(
        "pure-function",
        {"status": PASS, "detail": "two calls at 8 probe states returned the same u"},
    )
    if any(f["property"] == "pure-function" for f in failures):
        props["pure-function"] = {
            "status": FAIL,
            "detail": "two calls at the same state returned different u",
        }
    timings["total"] = time.perf_counter() - t0
    ok = not failures and agree.get("pass", False)
    return ConformResult(
        ok,
        user.mode,
        target,
        user.reason,
        agree,
        props,
        failures,
        {k: round(v, 4) for k, v in timings.items()},
        cfg.name,
    )


def conform_table(path: str | Path, cfg: Config, *, rtol: float = DEFAULT_RTOL) -> ConformResult:
    """Judge a table x1, x2, u (CSV) against the reference where it has points.

    Parameters
    ----------
    path : str or Path
        CSV with columns x1, x2, u.
    cfg : Config
        Configuration.
    rtol : float
        Agreement tolerance relative to w_max.

    Returns
    -------
    ConformResult
        Agreement and |u| <= w_max; closed-loop properties ``not_run``.
    """
    t0 = time.perf_counter()
    x1, x2, u = read_table(path)
    agree, failures = agreement(x1, x2, u, cfg, rtol)
    props = {}
    props["input-bound-grid"], f = input_bound(x1, x2, u, cfg, "at the table's points")
    failures += f
    for name in (
        "odd-symmetry",
        "no-stride-over",
        "no-limit-cycle",
        "input-bound",
        "settling-vs-discrete-limit",
    ):
        props[name] = {"status": NOT_RUN, "detail": "needs a callable law (--law)"}
    ok = not failures and agree["pass"]
    return ConformResult(
        ok,
        "table",
        str(path),
        f"table of {x1.size} points",
        agree,
        props,
        failures,
        {"total": round(time.perf_counter() - t0, 4)},
        cfg.name,
    )


def format_result(r: ConformResult) -> str:
    """Human-readable report: verdict, agreement per region, properties, failures."""
    lines = [
        f"{'CONFORMS' if r.conforms else 'DOES NOT CONFORM'}: {r.target} "
        f"(mode {r.mode}: {r.mode_reason})"
    ]
    a = r.agreement
    if "regions" in a:
        lines.append(
            f"agreement with reference PTO: {a['points']} points, {a['excluded']} "
            f"excluded (within {a['tie_band_mm_s']:.3g} mm/s of l1/l2/l1*/l2*), "
            f"tolerance {a['tolerance_mm_s']:.3g} mm/s ({a['rtol']:g} w_max), "
            f"max |du| = {a['max_abs_du']:.3g} mm/s"
        )
        for name, e in a["regions"].items():
            where = (
                "" if e["state"] is None else f" at ({e['state'][0]:.10g}, {e['state'][1]:.10g})"
            )
            lines.append(
                f"  {'ok  ' if e['pass'] else 'FAIL'} {name:<10} {e['points']:>6} "
                f"points ({e['excluded']} excluded) max |du| = "
                f"{e['max_abs_du']:.3g} mm/s{where}"
            )
    else:
        lines.append(f"agreement: {a.get('detail', '')}")
    for name, pr in r.properties.items():
        lines.append(f"  {pr['status'].upper():<10} {name:<28} {pr.get('detail', '')}")
    for f in r.failures:
        lines.append(
            f"FAILED {f['property']} at state ({f['state'][0]:.10g}, "
            f"{f['state'][1]:.10g}): {f['detail']}"
        )
    lines.append(f"time {r.timings_s.get('total', 0.0):.2f} s")
    return "\n".join(lines)
