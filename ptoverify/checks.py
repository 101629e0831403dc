"""The gates of ``ptoverify check``: each verification as pass / fail / unverified.

A gate is a function ``gate(ctx) -> CheckResult``.  It measures one number,
compares it with a limit derived from the method (round-off, sampling, the
paper's own principle), and says why in ``detail``.  A gate whose reference
cannot be computed (a solver that does not converge, an exception) is
``unverified``, and ``unverified`` fails the run: the gate fails closed.

The paper's errata and Section 6 claims that do not reproduce are findings of
the report, not gate failures; a configuration whose loops are unstable when
sampled, or whose zone cannot be built, fails its gates.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import SolverError

__all__ = ["CheckResult", "GATES", "run_checks", "summarize"]

PASS, FAIL, UNVERIFIED = "pass", "fail", "unverified"


@dataclass(frozen=True)
class CheckResult:
    """Outcome of one gate.

    Attributes
    ----------
    name : str
        Gate name (stable; CI logs and other tools key on it).
    status : str
        ``pass``, ``fail`` or ``unverified``.
    measured : float or None
        The measured figure (None when it could not be computed).
    limit : float or None
        The limit it is compared with.
    detail : str
        What was measured, against what, and why the limit.
    """

    name: str
    status: str
    measured: float | None
    limit: float | None
    detail: str

    def to_json(self) -> dict[str, Any]:
        """Return a JSON-able dict."""
        d = asdict(self)
        for key in ("measured", "limit"):
            v = d[key]
            d[key] = None if v is None or not math.isfinite(v) else float(v)
        return d


def _at_most(name: str, measured: float, limit: float, detail: str) -> CheckResult:
    if measured is None or not math.isfinite(measured):
        return CheckResult(name, UNVERIFIED, None, limit, detail + " (not computable)")
    return CheckResult(name, PASS if measured <= limit else FAIL, float(measured), limit, detail)


Gate = Callable[[Config], CheckResult]
GATES: dict[str, Gate] = {}


def gate(name: str) -> Callable[[Callable[[Config], CheckResult]], Gate]:
    """Register a gate under ``name``; exceptions make it ``unverified``."""

    def wrap(fn: Callable[[Config], CheckResult]) -> Gate:
        @functools.wraps(fn)
        def safe(cfg: Config) -> CheckResult:
            try:
                return fn(cfg)
            except SolverError as exc:
                return CheckResult(name, UNVERIFIED, None, None, f"solver failed: {exc}")
            except Exception as exc:  # noqa: BLE001 - a gate fails closed on any fault
                return CheckResult(name, UNVERIFIED, None, None,
                                   f"could not be computed: {type(exc).__name__}: {exc}")

        GATES[name] = safe
        return safe

    return wrap


def _random_states(cfg: Config, n: int, seed: int, vmax: float = 1.0) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    p = cfg.plant
    return (rng.uniform(-p.position_range, p.position_range, n),
            rng.uniform(-vmax * p.w_max, vmax * p.w_max, n))


# ------------------------------------------------------------------ core gates
@gate("zoh-vs-integrator")
def _zoh_vs_integrator(cfg: Config) -> CheckResult:
    """Exact one-sample map against an adaptive ODE integrator at rtol 1e-12."""
    from scipy.integrate import solve_ivp

    from ptoverify.plant import step

    p = cfg.plant
    x1, x2 = _random_states(cfg, 40, 11, 1.5)
    u = np.random.default_rng(12).uniform(-p.w_max, p.w_max, 40)
    y1, y2 = step(x1, x2, u, p)
    err = 0.0
    for i in range(40):
        sol = solve_ivp(lambda _, y, ui=u[i]: [y[1], -p.a * y[1] + p.a * ui], (0, p.T),
                        [x1[i], x2[i]], rtol=1e-12, atol=1e-12, method="DOP853")
        scale = 1.0 + abs(x1[i]) + abs(x2[i]) * p.T
        err = max(err, abs(sol.y[0, -1] - y1[i]) / scale,
                  abs(sol.y[1, -1] - y2[i]) / (1.0 + abs(x2[i])))
    return _at_most("zoh-vs-integrator", err, 1e-9,
                    "max relative difference of the ZOH one-sample map (eq. 7/15) from "
                    "DOP853 at rtol 1e-12 over 40 random states and inputs; limit 1e-9 is the "
                    "integrator's accuracy, not the map's")


@gate("roots-closed-form-vs-bisection")
def _roots(cfg: Config) -> CheckResult:
    """Lambert-W closed forms of eqs. (22), (26)/(31) against bisection to the last bit."""
    from ptoverify.curves import root_22, root_22_bisect, root_k, root_k_bisect

    rng = np.random.default_rng(13)
    b0 = np.concatenate([rng.uniform(0, 20, 2000), 10 ** rng.uniform(-12, 2, 2000)])
    m = np.concatenate([rng.uniform(0, 0.999, 2000), 10 ** rng.uniform(-12, -0.01, 2000)])
    e22 = np.max(np.abs(root_22(b0) - root_22_bisect(b0)) / root_22_bisect(b0))
    ek = np.max(np.abs(root_k(m) - root_k_bisect(m)) / root_k_bisect(m))
    return _at_most("roots-closed-form-vs-bisection", max(e22, ek), 1e-13,
                    f"max relative difference over 4,000 b0 (eq. 22: {e22:.1e}) and 4,000 "
                    f"k = 1 - m in (0, 1) (eqs. 26, 31: {ek:.1e}); limit: a few hundred ulps")


@gate("mintime-closed-form-vs-propagation")
def _mintime_propagation(cfg: Config) -> CheckResult:
    """Closed-form t_f and switch: the two arcs of the exact flow end at the origin."""
    from ptoverify.mintime import min_time
    from ptoverify.plant import flow

    p = cfg.plant
    x1, x2 = _random_states(cfg, 20000, 14, 1.5)
    mt = min_time(x1, x2, p)
    y1, y2 = flow(x1, x2, -mt.side * p.w_max, mt.t_switch, p.a)
    z1, z2 = flow(y1, y2, mt.side * p.w_max, mt.t_f - mt.t_switch, p.a)
    # a miss of dz in position is a time error of about dz / |x2 near the end|; normalise by
    # the state's scale: round-off of eq. (7) over the two arcs
    miss = np.max(np.abs(z1) / (1 + np.abs(x1)) + np.abs(z2) / (p.w_max + np.abs(x2)))
    return _at_most("mintime-closed-form-vs-propagation", miss, 1e-11,
                    "max normalised distance from the origin after propagating the exact flow "
                    "for the closed-form arc durations, 20,000 states with |x2| <= 1.5 w_max")


@gate("input-bound")
def _input_bound(cfg: Config) -> CheckResult:
    """|u| <= w_max for every law over a dense random cloud of states."""
    from ptoverify.laws import LAW_NAMES, make_law

    x1, x2 = _random_states(cfg, 200000, 15, 2.0)
    x1 = np.concatenate([x1, x1 * 1e-3])
    x2 = np.concatenate([x2, x2 * 1e-3])
    worst, names = 0.0, []
    for name in LAW_NAMES:
        u, _ = make_law(name, cfg)(x1, x2)
        if not np.all(np.isfinite(u)):
            return CheckResult("input-bound", FAIL, math.inf, cfg.plant.w_max,
                               f"law {name} returned a non-finite input")
        worst = max(worst, float(np.max(np.abs(u))))
        names.append(name)
    return _at_most("input-bound", worst, cfg.plant.w_max,
                    f"max |u| [mm/s] of {', '.join(names)} over 400,000 states (|x2| <= 2 w_max, "
                    "also near the origin); limit w_max")


@gate("odd-symmetry")
def _odd_symmetry(cfg: Config) -> CheckResult:
    """u(-x) = -u(x) for every law (the plant is odd, so the laws must be)."""
    from ptoverify.laws import LAW_NAMES, make_law

    x1, x2 = _random_states(cfg, 100000, 16, 1.5)
    worst = 0.0
    for name in LAW_NAMES:
        law = make_law(name, cfg)
        worst = max(worst, float(np.max(np.abs(law(x1, x2)[0] + law(-x1, -x2)[0]))))
    return _at_most("odd-symmetry", worst, 1e-9 * cfg.plant.w_max,
                    "max |u(x) + u(-x)| [mm/s] over 100,000 states for every law")


def run_checks(cfg: Config, names: list[str] | None = None) -> list[CheckResult]:
    """Run the gates (all, or the named ones) in registration order.

    Parameters
    ----------
    cfg : Config
        Configuration under test.
    names : list of str, optional
        Only these gates.

    Returns
    -------
    list of CheckResult
    """
    return [fn(cfg) for name, fn in GATES.items() if names is None or name in names]


def summarize(results: list[CheckResult]) -> dict[str, Any]:
    """Count statuses; ``ok`` is True only when every gate passed."""
    counts = {s: sum(r.status == s for r in results) for s in (PASS, FAIL, UNVERIFIED)}
    return {"total": len(results), **counts, "ok": counts[PASS] == len(results)}
