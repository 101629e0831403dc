"""An independent reference for the linear-loop a_true / a_design margins (tests only).

The ZOH plant x2' = -r a x2 + r a u in closed form (not the suite's
``zoh_matrices``), the loop u = -k_x1 x1 - k_x2 x2 with the gains read off each
law's equations by hand (not ``linear_loop_gains``), and the spectral radius of
the sampled loop, with or without a one-sample computation delay.
"""

import math

import numpy as np


def hand_gains(law: str, cfg) -> tuple[float, float]:
    """(k_x1 [1/s], k_x2 [-]) of a law's linear loop, from its equations."""
    a = cfg.plant.a
    if law == "pd":
        return cfg.pd.kp, cfg.pd.kd
    if law == "pto":
        return cfg.pto.k1, cfg.pto.k2
    if law == "cascade-p":
        return (a / 4.0 if cfg.cascade.kp is None else cfg.cascade.kp), 0.0
    if law == "ptos":  # u = (k/a) (alpha k / 2) (-x1) - (k/a - 1) x2 in the linear region
        k = a if cfg.ptos.k is None else cfg.ptos.k
        return (k / a) * cfg.ptos.alpha * k / 2.0, k / a - 1.0
    raise ValueError(law)


def radius(k_x1: float, k_x2: float, a_true: float, T: float, delay: int) -> float:
    """Spectral radius of the sampled linear loop on the plant with bandwidth a_true."""
    e = math.exp(-a_true * T)
    ad = np.array([[1.0, (1.0 - e) / a_true], [0.0, e]])
    bd = np.array([T - (1.0 - e) / a_true, 1.0 - e])
    k = np.array([k_x1, k_x2])
    if delay == 0:
        m = ad - np.outer(bd, k)
    else:
        m = np.zeros((3, 3))
        m[:2, :2], m[:2, 2], m[2, :2] = ad, bd, -k
    return float(np.max(np.abs(np.linalg.eigvals(m))))


def check_interval(interval, k_x1, k_x2, a, T, delay, span=(0.1, 10.0)):
    """Assert ``interval`` is where the loop is stable: inside stable, just past a finite end not."""
    if interval is None:  # unstable at the design point
        assert radius(k_x1, k_x2, a, T, delay) >= 1.0
        return
    lo, hi = interval
    inner = np.geomspace(span[0] if lo is None else lo, span[1] if hi is None else hi, 60)
    for r in inner[1:-1]:
        assert radius(k_x1, k_x2, r * a, T, delay) < 1.0, r
    for end, out in ((lo, 1.0 - 1e-6), (hi, 1.0 + 1e-6)):
        if end is not None:
            assert (
                radius(k_x1, k_x2, end * (1.0 - 1e-9 if out > 1 else 1.0 + 1e-9) * a, T, delay)
                < 1.0
            )
            assert radius(k_x1, k_x2, end * out * a, T, delay) >= 1.0 - 1e-12
