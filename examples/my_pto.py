"""A third-party PTO implementation, written as a drive team might: scalar, math only.

This file is an example input for ``ptoverify conform``; it does not import the
reference law.  The switching zone's level omega0 is a design parameter that a
team takes from ``ptoverify zone --json`` (key ``corrected.omega0``); here it is
read from the same computation so that the example follows any ``--config``.

Run::

    ptoverify conform --law examples/my_pto.py:pto

omega_c (eq. 28) is found by bisection on the level itself, to the last bit,
instead of the reference's Lambert-W closed form.
"""

from __future__ import annotations

import functools
import math


@functools.lru_cache(maxsize=8)
def _omega0(cfg) -> float:
    """Level of l1*, l2* [mm/s] (from the corrected zone construction)."""
    from ptoverify.model.zones import corrected_zone

    return corrected_zone(cfg, verify=False).omega0


def _residual(x1: float, x2: float, a: float, omega: float) -> float:
    """Level-omega curve through the origin: eq. (9)/(13) for x2 <= 0, (11)/(14) for x2 > 0."""
    if x2 <= 0.0:
        return a * x1 + x2 + omega * math.log1p(-x2 / omega)
    return a * x1 + x2 - omega * math.log1p(x2 / omega)


def _omega_c(x1: float, x2: float, a: float, lo: float, hi: float) -> float:
    """Level omega in [lo, hi] of the curve through (x1, x2), eq. (28)/(33), by bisection."""
    f_lo = _residual(x1, x2, a, lo)
    if f_lo == 0.0:  # exactly on l1* / l2*: the same branch on both sides (odd symmetry)
        return lo
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        f_mid = _residual(x1, x2, a, mid)
        if (f_mid > 0) == (f_lo > 0):
            lo, f_lo = mid, f_mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def pto(x1: float, x2: float, cfg) -> float:
    """PTO input u [mm/s] at state x1 [mm], x2 [mm/s], eq. (35) with eq. (34).

    Parameters
    ----------
    x1, x2 : float
        Position error [mm] and velocity [mm/s].
    cfg : ptoverify.config.Config
        Plant (a, w_max) and PTO settings (d, k1, k2).

    Returns
    -------
    float
        u with |u| <= w_max.
    """
    a, w = cfg.plant.a, cfg.plant.w_max
    d, k1, k2 = cfg.pto.d, cfg.pto.k1, cfg.pto.k2
    if x1 == 0.0 and x2 == 0.0:
        return 0.0
    if abs(x1) < d:  # linear zone, eq. (34), saturated
        return max(-w, min(w, -k1 * x1 - k2 * x2))
    sigma = _residual(x1, x2, a, w)
    om = _omega0(cfg)
    if x2 < 0 and sigma > 0 and _residual(x1, x2, a, om) <= 0:  # S~_P u l1*
        return _omega_c(x1, x2, a, om, w)
    if x2 > 0 and sigma < 0 and _residual(x1, x2, a, om) >= 0:  # S~_N u l2*
        return -_omega_c(x1, x2, a, om, w)
    if sigma < 0 or (sigma == 0 and x2 < 0):  # S_P u l1
        return w
    return -w
