"""The reference law of ``conform`` and what every part of it shares.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions): the reference law, the float64 curve tie band, omega0 of the
reference's switching zone, and (re-exported from :mod:`ptoverify.conform.findings`) the
failure entry every property reports.

The reference is ``make_law(cfg.conform.reference, cfg)``: the corrected PTO
(``pto``, default) or a baseline (``ptos``, ``cascade-p``,
:mod:`ptoverify.model.baselines`, with the configuration's gains), chosen by
``[conform] reference`` or ``conform --reference`` (:func:`with_reference`).
The baselines are continuous in the state (PTOS's profile is continuous in
value and slope at its linear-region edge, and a clip is continuous), so they
have no curve ties: :func:`has_curves` is False for them, :func:`omega0_ref` is
None, and :func:`linear_edge` (the edge the probes crowd) is their linear
region's half-width instead of the PTO's d.
"""

from __future__ import annotations

from dataclasses import replace

from ptoverify import verdict
from ptoverify.config import Config
from ptoverify.conform.findings import failure
from ptoverify.conform_limits import CONFORM_REFERENCES
from ptoverify.errors import InputError
from ptoverify.model.laws import Law, make_law
from ptoverify.model.memo import memo

__all__ = [
    "DEFAULT_RTOL",
    "reference",
    "tie_band",
    "omega0_ref",
    "failure",
    "with_reference",
    "has_curves",
    "linear_edge",
]

DEFAULT_RTOL = 1e-6  #: agreement tolerance relative to w_max


@memo(maxsize=8)
def reference(cfg: Config) -> Law:
    """Return ``make_law(cfg.conform.reference, cfg)``, built once per configuration.

    Parameters
    ----------
    cfg : Config
        Configuration (the memo's key); ``cfg.conform.reference`` names the law.

    Returns
    -------
    Law
        The reference law (the PTO with its corrected omega0, or a baseline), u [mm/s].
    """
    return make_law(cfg.conform.reference, cfg)


def with_reference(cfg: Config, name: str) -> Config:
    """Return ``cfg`` judging against the reference law ``name`` (``conform --reference``).

    Parameters
    ----------
    cfg : Config
        Configuration.
    name : str
        One of ``pto``, ``ptos``, ``cascade-p``.

    Returns
    -------
    Config
        ``cfg`` with ``conform.reference = name``.

    Raises
    ------
    InputError
        For another name.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> with_reference(paper_config(), "ptos").conform.reference
    'ptos'
    """
    if name not in CONFORM_REFERENCES:
        raise InputError(
            f"--reference must be one of {', '.join(CONFORM_REFERENCES)}, got {name!r}"
        )
    return replace(cfg, conform=replace(cfg.conform, reference=name))


def has_curves(cfg: Config) -> bool:
    """Return True when the reference switches on the curves l1/l2 (the PTO), False for a baseline.

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    bool
    """
    return cfg.conform.reference == "pto"


def linear_edge(cfg: Config) -> float:
    """Return the half-width [mm] of the reference's linear region |x1| <= edge.

    The PTO's d, PTOS's y_l (:func:`ptoverify.model.baselines.ptos_design`), or
    w_max / kp for the cascade P loop (where its clip starts at rest).  A baseline's
    edge beyond the envelope is position_range (the whole envelope is linear; with
    ``[cascade] kp = 0`` there is no edge at all, audit run 7).

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    float
        [mm].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> linear_edge(paper_config())
    0.5
    """
    from ptoverify.model.baselines import cascade_gain, ptos_design

    name = cfg.conform.reference
    R = cfg.plant.position_range  # noqa: N806
    if name == "ptos":
        return min(ptos_design(cfg).y_l, R)
    if name == "cascade-p":
        kp = cascade_gain(cfg)
        return R if kp * R <= cfg.plant.w_max else cfg.plant.w_max / kp
    return cfg.pto.d


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
        Level of l1*, l2* [mm/s]; None for a baseline reference.
    """
    from ptoverify.model.zones import zone_for_law

    if not has_curves(cfg):
        return None
    z = zone_for_law(cfg, "corrected")
    ok = z.usable and not z.degenerate and 0.0 < z.omega0 < cfg.plant.w_max
    return float(z.omega0) if ok else None
