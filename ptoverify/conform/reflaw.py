"""The reference law of ``conform`` and what every part of it shares.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions): the reference PTO law (``make_law("pto", cfg)``, corrected
omega0), the float64 curve tie band, omega0 of the reference's switching zone
and the failure entry every property reports.
"""

from __future__ import annotations

from ptoverify import verdict
from ptoverify.config import Config
from ptoverify.model.laws import Law, make_law
from ptoverify.model.memo import memo

__all__ = ["DEFAULT_RTOL", "reference", "tie_band", "omega0_ref", "failure"]

DEFAULT_RTOL = 1e-6  #: agreement tolerance relative to w_max


@memo(maxsize=8)
def reference(cfg: Config) -> Law:
    """Return ``make_law("pto", cfg)``, built once per configuration.

    Parameters
    ----------
    cfg : Config
        Configuration (the memo's key).

    Returns
    -------
    Law
        The reference law (corrected omega0), u [mm/s].
    """
    return make_law("pto", cfg)


def tie_band(cfg: Config) -> float:
    """Return the exclusion band of ``verdict.tie_band`` for ``cfg`` [mm/s].

    Parameters
    ----------
    cfg : Config
        Configuration (w_max [mm/s], a [rad/s], position_range [mm]).

    Returns
    -------
    float
        1e-9 (w_max + a position_range) [mm/s].
    """
    p = cfg.plant
    return verdict.tie_band(p.w_max, p.a, p.position_range)


def omega0_ref(cfg: Config) -> float | None:
    """Return omega0 [mm/s] the reference uses, None when it has no switching zone.

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    float or None
        Level of l1*, l2* [mm/s].
    """
    from ptoverify.model.zones import zone_for_law

    z = zone_for_law(cfg, "corrected")
    ok = z.usable and not z.degenerate and 0.0 < z.omega0 < cfg.plant.w_max
    return float(z.omega0) if ok else None


def failure(prop: str, state, detail: str, **extra) -> dict:
    """Return a failure entry: property, state [x1, x2], detail (and extra keys).

    Parameters
    ----------
    prop : str
        The property (or ``evaluation``, ``isolation``).
    state : sequence of 2 floats
        The first state that shows it, x1 [mm], x2 [mm/s].
    detail : str
        What failed.
    **extra
        More keys (``sample``, ``at``).

    Returns
    -------
    dict
    """
    return {
        "property": prop,
        "state": [float(state[0]), float(state[1])],
        "detail": detail,
        **extra,
    }
