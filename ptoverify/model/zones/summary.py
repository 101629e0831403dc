"""The zone each law uses, and the summary of both constructions."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ptoverify.config import Config, PTOSettings
from ptoverify.model.memo import memo

from .corrected import _corrected_zone, _feasible_intervals, _smallest_d, _zone_key, corrected_zone
from .printed import printed_zone

if TYPE_CHECKING:
    from .types import PTOZone


def zone_for_law(cfg: Config, variant: str) -> PTOZone:
    """Zone the ``pto`` (``corrected``) or ``pto-printed`` (``printed``) law uses.

    Memoized on what a zone depends on (the plant and d), so laws that differ
    only in gains (a tuning search) share one construction.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).
    variant : str
        ``corrected`` or ``printed``.

    Returns
    -------
    PTOZone
        The zone (not grid-verified).
    """
    return _zone_for_law(_zone_key(cfg), variant)


@memo(maxsize=256)
def _zone_for_law(cfg: Config, variant: str) -> PTOZone:
    return corrected_zone(cfg, verify=False) if variant == "corrected" else printed_zone(cfg)


def clear_caches() -> None:
    """Empty the memos of this module (zones, feasible intervals, d_min per configuration)."""
    for fn in (_corrected_zone, _feasible_intervals, _smallest_d, _zone_for_law):
        fn.cache_clear()


def zone_summary(cfg: Config, *, verify: bool = True) -> dict:
    """Return the ``ptoverify zone --json`` object (DESIGN.md keys plus extras).

    Parameters
    ----------
    cfg : Config
        Configuration.
    verify : bool
        Run the 2-D grid checks.

    Returns
    -------
    dict
        ``printed``, ``corrected`` (each ``omega0``, ``x20_tilde``, ``valid``,
        ``reason`` and more), ``corrected_lenient`` (the lenient reading), ``d``,
        ``w_max`` [mm/s], ``a`` [rad/s], ``sample_time`` [s].
    """
    p: PTOSettings = cfg.pto
    return {
        "printed": printed_zone(cfg).to_json(),
        "corrected": corrected_zone(cfg, verify=verify).to_json(),
        "corrected_lenient": corrected_zone(cfg, reading="lenient", verify=verify).to_json(),
        "d": p.d,
        "w_max": cfg.plant.w_max,
        "a": cfg.plant.a,
        "sample_time": cfg.plant.sample_time,
    }
