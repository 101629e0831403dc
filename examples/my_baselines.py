"""Third-party implementations of the two baselines, written as a drive team might.

Example inputs for ``ptoverify conform --reference ptos|cascade-p``; scalar, math
only, written from the equations (Workman's PTOS profile on this plant and the
saturated P position loop), not from the suite's code.  ``ptos`` and
``cascade_p`` conform; ``ptos_no_half`` and ``cascade_p_hz`` each carry one
wrong constant and do not.

Run::

    ptoverify conform --law examples/my_baselines.py:ptos --reference ptos
    ptoverify conform --law examples/my_baselines.py:cascade_p --reference cascade-p

PTOS (velocity loop of gain k [1/s] closed by the plant, A = a w_max the
deceleration the profile assumes, alpha its discount):

    e = -x1,  k1 = alpha k^2 / 2,  y_l = A / k1,
    f(e) = (k1 / k) e                          for |e| <= y_l,
    f(e) = sign(e) (sqrt(2 alpha A |e|) - A / k) otherwise,
    u = sat((k / a) f(e) - (k / a - 1) x2).

Cascade P: u = sat(-kp x1), kp = ``[cascade] kp`` or a / 4.
"""

from __future__ import annotations

import math


def _clip(u: float, w: float) -> float:
    """Saturate u to [-w, w] [mm/s]."""
    return max(-w, min(w, u))


def _ptos(x1: float, x2: float, cfg, half: float) -> float:
    """PTOS with Workman's k1 = alpha k^2 * half (half = 0.5 is Workman's)."""
    a, w = cfg.plant.a, cfg.plant.w_max
    alpha = cfg.ptos.alpha
    k = a if cfg.ptos.k is None else cfg.ptos.k
    acc = a * w  # deceleration the profile assumes [mm/s^2]
    k1 = alpha * k * k * half
    edge = acc / k1
    e = -x1
    if abs(e) <= edge:
        f = (k1 / k) * e
    else:
        f = math.copysign(math.sqrt(2.0 * alpha * acc * abs(e)) - acc / k, e)
    return _clip((k / a) * f - (k / a - 1.0) * x2, w)


def ptos(x1: float, x2: float, cfg) -> float:
    """PTOS on this plant [mm/s] (conforms to ``--reference ptos``)."""
    return _ptos(x1, x2, cfg, 0.5)


def ptos_no_half(x1: float, x2: float, cfg) -> float:
    """PTOS with k1 = alpha k^2 (the 1/2 dropped): twice the linear gain; does not conform."""
    return _ptos(x1, x2, cfg, 1.0)


def cascade_p(x1: float, x2: float, cfg) -> float:
    """Cascade P loop u = sat(-kp x1) [mm/s] (conforms to ``--reference cascade-p``)."""
    kp = cfg.plant.a / 4.0 if cfg.cascade.kp is None else cfg.cascade.kp
    return _clip(-kp * x1, cfg.plant.w_max)


def cascade_p_hz(x1: float, x2: float, cfg) -> float:
    """Cascade P with kp = a / 4 taken with a in Hz (a / (2 pi) / 4): does not conform."""
    kp = cfg.plant.a / (2.0 * math.pi) / 4.0 if cfg.cascade.kp is None else cfg.cascade.kp
    return _clip(-kp * x1, cfg.plant.w_max)
