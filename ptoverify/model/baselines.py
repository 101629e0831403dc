"""Baseline laws a servo engineer compares against: PTOS and the cascade P loop.

Both are :class:`ptoverify.model.laws.Law` objects built like the suite's other
laws (one vectorized path, its one-state call included; odd bit for bit, |u| <= w_max), and
:func:`ptoverify.model.laws.make_law` builds them by name (``ptos``,
``cascade-p``).  In tracking the simulator hands the law the error state and
adds the reference velocity to its output (velocity feed-forward), as for every
law.

PTOS on this plant (Workman's proximate time-optimal servomechanism)
--------------------------------------------------------------------
Workman's PTOS drives a double integrator y'' = acceleration with the
acceleration command k (f(e) - v): a velocity loop of gain k [1/s] around the
velocity profile f of the position error e.  Here the drive's velocity loop is
the plant itself: x2' = a (u - x2).  Commanding

    u = (k / a) f(e) - (k / a - 1) x2,       e = -x1,

makes x2' = k (f(e) - x2) exactly wherever u is not clipped: Workman's loop
with gain k.  With k = a (the default) u = f(e): the practitioner's reading in
which the velocity loop is treated as ideal and the profile is the velocity
command itself; k > a adds a velocity-error term of gain k / a - 1.

The profile (Workman), with A the deceleration it assumes and 0 < alpha <= 1
its discount::

    f(e) = (k1 / k) e                               for |e| <= y_l,
    f(e) = sign(e) (sqrt(2 alpha A |e|) - A / k)     for |e| >  y_l,

with k1 = alpha k^2 / 2 [1/s^2] and y_l = A / k1 [mm].  These two choices are
what continuity of f in value and slope at |e| = y_l requires (re-derived in
``derivations/baselines.py``): f(y_l) = A / k on both sides, slope alpha k / 2.

A = a w_max [mm/s^2].  Decelerating with u = -w_max from a velocity v >= 0 gives
x2' = -a (v + w_max): at least a w_max, reached as v -> 0, so a w_max is the
deceleration the plant guarantees along every approach to rest; the parabola
x2^2 = 2 a w_max |x1| is also the second-order osculation of the time-optimal
switching curve l1 (eq. 9) at the origin (also re-derived).

What this shows: the command at the edge, at rest, is (k / a) f(y_l) =
(k / a) (A / k) = A / a = w_max for every k.  At the default k = a (no velocity
term) the square-root branch therefore lies entirely beyond the saturation and
PTOS reduces to the cascade P loop u = sat(-(alpha a / 2) x1).  With k > a the
branch acts unclipped only while the velocity term -(k / a - 1) x2 pulls the
command back inside +-w_max, i.e. while approaching the target: the limit is on
the velocity command, not on the acceleration PTOS assumes.

DSPTOS (Choi et al.'s damping scheduling) is not built: it schedules the
damping of an acceleration-limited double integrator's linear loop between the
deceleration and settling phases; on this plant the limit is on the velocity
command and the paper gives no schedule, so an adaptation would invent both
the schedule and its parameters rather than reproduce the law.

Region codes: LINEAR (|x1| <= y_l, unclipped), SATURATED (clipped at
+-w_max), ZONE_P / ZONE_N (the square-root branch unclipped, u > 0 / u <= 0:
PTOS's proximate region, like the PTO's switching zone).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from ptoverify.config import Config, PDGains
from ptoverify.errors import InputError
from ptoverify.model.laws import (
    Law,
    Region,
    _state_gains_law,
    pd_law,
    register_law,
    saturate_linear,
)

__all__ = [
    "PTOSDesign",
    "ptos_design",
    "ptos_law",
    "ptos_state_gains",
    "cascade_gain",
    "cascade_law",
    "cascade_state_gains",
    "linear_loop_gains",
]


@dataclass(frozen=True)
class PTOSDesign:
    """The numbers of one PTOS law (module docstring).

    Attributes
    ----------
    alpha : float
        Deceleration discount [-].
    k : float
        Velocity-loop gain the profile is designed for [1/s].
    A : float
        Deceleration the profile assumes, a w_max [mm/s^2].
    k1 : float
        Workman's position gain alpha k^2 / 2 [1/s^2].
    y_l : float
        Half-width of the linear region, A / k1 [mm].
    slope : float
        Slope of the profile in the linear region, k1 / k [1/s].
    offset : float
        Offset A / k of the square-root branch [mm/s]; f(y_l) = offset.
    gain : float
        k / a, the factor on the profile in u [-].
    kv : float
        k / a - 1, the velocity-error gain [-].
    """

    alpha: float
    k: float
    A: float  # noqa: N815 - Workman's symbol
    k1: float
    y_l: float
    slope: float
    offset: float
    gain: float
    kv: float

    def linear_gains(self) -> tuple[float, float]:
        """Return (k_x1 [1/s], k_x2 [-]) of u = -k_x1 x1 - k_x2 x2 in the linear region."""
        return self.gain * self.slope, self.kv


def ptos_design(cfg: Config, *, alpha: float | None = None, k: float | None = None) -> PTOSDesign:
    """Return the PTOS numbers of a configuration (``[ptos]``, or the arguments).

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], ``ptos``).
    alpha : float, optional
        Discount [-] in place of ``cfg.ptos.alpha``.
    k : float, optional
        Velocity-loop gain [1/s] in place of ``cfg.ptos.k`` (whose None means a).

    Returns
    -------
    PTOSDesign
        The derived numbers.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> p = ptos_design(paper_config())
    >>> round(p.offset, 9), p.kv
    (300.0, 0.0)
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    alpha = cfg.ptos.alpha if alpha is None else float(alpha)
    k = (cfg.ptos.k if cfg.ptos.k is not None else a) if k is None else float(k)
    A = a * w  # noqa: N806
    k1 = alpha * k * k / 2.0
    return PTOSDesign(alpha, k, A, k1, A / k1, k1 / k, A / k, k / a, k / a - 1.0)


def ptos_law(cfg: Config, *, alpha: float | None = None, k: float | None = None) -> Law:
    """PTOS law u = sat((k/a) f(-x1) - (k/a - 1) x2) (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], ``ptos``).
    alpha : float, optional
        Discount [-] in place of the configuration's.
    k : float, optional
        Velocity-loop gain [1/s] in place of the configuration's.

    Returns
    -------
    Law
        ``ptos``, odd, |u| <= w_max.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> law = ptos_law(paper_config())
    >>> law.scalar(40.0, 0.0)
    (-300.0, 6)
    """
    p = ptos_design(cfg, alpha=alpha, k=k)
    numbers = _ptos_numbers(p.alpha, p.k, cfg.plant.a, cfg.plant.w_max)
    w = cfg.plant.w_max

    def vector(x1, x2):
        return _ptos_input(x1, x2, *numbers, w=w)

    note = (
        f"PTOS alpha = {p.alpha:g}, k = {p.k:.6g} 1/s, A = a w_max = {p.A:.6g} mm/s^2, "
        f"linear region |x1| <= {p.y_l:.6g} mm"
    )
    # scalar: the vector path on one state
    return Law("ptos", vector, None, cfg.plant.w_max, note)


def _ptos_numbers(alpha, k, a: float, w: float) -> tuple:
    """Return the numbers :func:`_ptos_input` reads, of alpha [-] and k [1/s] (floats or arrays).

    (y_l, slope, 2 alpha A, offset, -gain, kv): those of :func:`ptos_design` with the
    same arithmetic, so a per-state entry equals the law built from its gains bit
    for bit; computed once per law, not at every sample.
    """
    A = a * w  # noqa: N806 - Workman's symbol
    k1 = alpha * k * k / 2.0
    return A / k1, k1 / k, 2.0 * alpha * A, A / k, -(k / a), k / a - 1.0


def _ptos_input(x1, x2, y_l, slope, c, offset, neg_gain, kv, *, w: float):
    """PTOS input and region (module docstring) from :func:`_ptos_numbers`."""
    ax = np.abs(x1)
    lin = ax <= y_l
    with np.errstate(invalid="ignore"):
        prof = np.where(lin, slope * ax, np.sqrt(c * ax) - offset)  # f(|x1|) >= 0
    u, region = saturate_linear(neg_gain * np.copysign(prof, x1) - kv * x2, w)
    branch = ~lin & (region == Region.LINEAR)
    if branch.any():
        region[branch] = np.where(u[branch] > 0, Region.ZONE_P, Region.ZONE_N)
    return u, region


def ptos_state_gains(cfg: Config, gains: dict) -> Law:
    """Return PTOS with (alpha, k) one per state (:func:`~ptoverify.model.laws.with_state_gains`).

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s]).
    gains : dict
        ``alpha`` [-] and ``k`` [1/s], arrays of one shape.

    Returns
    -------
    Law
        For states of the gains' shape; state i acts as ``ptos_law`` with gains i.
    """
    g = (np.asarray(gains["alpha"], dtype=float), np.asarray(gains["k"], dtype=float))
    if g[0].shape != g[1].shape:
        raise InputError("per-state gains: alpha and k need one shape")
    w = cfg.plant.w_max
    numbers = _ptos_numbers(*g, cfg.plant.a, w)
    return _state_gains_law("ptos", partial(_ptos_input, w=w), numbers, w)


def cascade_state_gains(cfg: Config, gains: dict) -> Law:
    """Return the cascade P loop with kp one per state (:func:`~ptoverify.model.laws.with_state_gains`).

    Parameters
    ----------
    cfg : Config
        Configuration (w_max [mm/s]).
    gains : dict
        ``kp`` [1/s], an array.

    Returns
    -------
    Law
        For states of the gains' shape: the PD law's per-state path with kd = 0.
    """
    kp = np.asarray(gains["kp"], dtype=float)
    return replace(pd_law(cfg, gains=(kp, np.zeros_like(kp))), name="cascade-p")


def cascade_gain(cfg: Config) -> float:
    """Position gain [1/s] of the cascade P loop: ``cfg.cascade.kp``, or a / 4 if unset.

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    float
        kp [1/s].

    Examples
    --------
    >>> from ptoverify.config import config_from_mapping
    >>> from ptoverify.config import PAPER_MAPPING
    >>> cascade_gain(config_from_mapping({**PAPER_MAPPING, "cascade": {"kp": 50.0}}))
    50.0
    """
    return cfg.cascade.kp if cfg.cascade.kp is not None else cfg.plant.a / 4.0


def cascade_law(cfg: Config, *, kp: float | None = None) -> Law:
    """Cascade position loop u = sat(-kp x1) (a drive's P loop around its velocity loop).

    The PD law with kd = 0 (:func:`ptoverify.model.laws.pd_law`, the one code path
    of a saturated linear law), renamed.  Velocity feed-forward of the reference
    in tracking is the simulator's, as for every law.

    Parameters
    ----------
    cfg : Config
        Configuration (w_max [mm/s], ``cascade``).
    kp : float, optional
        Position gain [1/s] in place of :func:`cascade_gain`.

    Returns
    -------
    Law
        ``cascade-p``, odd, |u| <= w_max.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> cascade_law(paper_config(), kp=100.0).scalar(0.5, 7.0)
    (-50.0, 5)
    """
    kp = cascade_gain(cfg) if kp is None else float(kp)
    law = pd_law(replace(cfg, pd=PDGains(kp=kp, kd=0.0)))
    return replace(law, name="cascade-p", note=f"cascade P u = sat(-{kp:.6g} x1)")


def linear_loop_gains(law: str, cfg: Config) -> tuple[float, float] | None:
    """Return the gains (k_x1 [1/s], k_x2 [-]) of a law's linear loop u = -k_x1 x1 - k_x2 x2.

    The one place a law's linear loop is read off its configuration: PD (kp, kd),
    the PTO's linear zone (k1, k2; printed or corrected), PTOS's linear region
    (:meth:`PTOSDesign.linear_gains`), the cascade P loop (kp, 0); None for TO
    (no linear loop) and unknown names.

    Parameters
    ----------
    law : str
        Law name.
    cfg : Config
        Configuration.

    Returns
    -------
    tuple of float or None

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> linear_loop_gains("pd", paper_config()), linear_loop_gains("to", paper_config())
    ((356.0, 1.15), None)
    """
    if law == "pd":
        return cfg.pd.kp, cfg.pd.kd
    if law in ("pto", "pto-printed"):
        return cfg.pto.k1, cfg.pto.k2
    if law == "ptos":
        return ptos_design(cfg).linear_gains()
    if law == "cascade-p":
        return cascade_gain(cfg), 0.0
    return None


register_law("ptos", ptos_law, ptos_state_gains)
register_law("cascade-p", cascade_law, cascade_state_gains)
