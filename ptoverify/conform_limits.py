"""The pass limits of ``ptoverify conform``: the configuration's ``[conform]`` table.

Vocabulary, like :mod:`ptoverify.config` (which holds a :class:`ConformLimits`
in :attr:`ptoverify.config.Config.conform` and re-exports both names); kept
apart so the configuration module stays small.  Why these limits: README,
"Gating your own implementation" ("Pass limits").
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from ptoverify.errors import ConfigError
from ptoverify.robustness import _number  # the one TOML number check (config uses it too)

__all__ = ["ConformLimits", "conform_limits_from_mapping", "CONFORM_REFERENCES"]

#: the laws ``conform`` can judge against (``[conform] reference``, ``conform --reference``)
CONFORM_REFERENCES = ("pto", "ptos", "cascade-p")


@dataclass(frozen=True)
class ConformLimits:
    """Pass limits of ``ptoverify conform`` (table ``[conform]``; README "Conformance").

    Attributes
    ----------
    settling_margin : float
        Settling may exceed the reference's worst by this fraction of it [-]
        (``settling-vs-discrete-limit``: the excess over N*; under a
        perturbation: the settling samples), in [0, 10].
    settling_min_samples : int
        ... and always by at least this many samples [samples], in [0, 1000].
    count_margin : float
        Under a perturbation, a count property (states that limit-cycle, stride
        over or exceed w_max) may exceed the reference's count by this fraction
        of the initial states [-], in [0, 1].
    reference : str
        The reference law the implementation is judged against, one of
        :data:`CONFORM_REFERENCES`: ``pto`` (the corrected PTO, default), ``ptos``
        or ``cascade-p`` (the baselines, with the configuration's ``[ptos]`` or
        ``[cascade]`` gains).
    """

    settling_margin: float = 0.5
    settling_min_samples: int = 2
    count_margin: float = 0.01
    reference: str = "pto"

    def settling_limit(self, reference_worst: float) -> float:
        """Return the settling limit [samples] for the reference's worst [samples].

        Examples
        --------
        >>> ConformLimits().settling_limit(38.0)
        57.0
        """
        extra = max(
            float(self.settling_min_samples), math.ceil(self.settling_margin * reference_worst)
        )
        return reference_worst + extra

    def to_mapping(self) -> dict[str, Any]:
        """Return the limits as a plain dict (the TOML layout)."""
        return asdict(self)


def conform_limits_from_mapping(raw: Any) -> ConformLimits:
    """Validate the ``[conform]`` table (every key optional; defaults of :class:`ConformLimits`).

    Parameters
    ----------
    raw : dict
        The parsed table.

    Returns
    -------
    ConformLimits
        The limits.

    Raises
    ------
    ConfigError
        On unknown keys, wrong types or out-of-range values (the key is named).

    Examples
    --------
    >>> conform_limits_from_mapping({"settling_margin": 1.0}).settling_margin
    1.0
    """
    if not isinstance(raw, dict):
        raise ConfigError(f"config key 'conform' must be a table [conform], got {raw!r}")
    base = ConformLimits()
    for key in raw:
        if key not in base.to_mapping():
            raise ConfigError(f"unknown config key 'conform.{key}'")
    out: dict[str, Any] = {}
    for key, hi in (("settling_margin", 10.0), ("count_margin", 1.0)):
        v = _number("conform", key, raw.get(key, getattr(base, key)))
        if not 0.0 <= v <= hi:
            raise ConfigError(f"config key 'conform.{key}' must be in [0, {hi:g}], got {v!r}")
        out[key] = v
    ref = raw.get("reference", base.reference)
    if ref not in CONFORM_REFERENCES:
        raise ConfigError(
            f"config key 'conform.reference' must be one of {', '.join(CONFORM_REFERENCES)}, "
            f"got {ref!r}"
        )
    n = raw.get("settling_min_samples", base.settling_min_samples)
    if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= 1000:
        raise ConfigError(
            f"config key 'conform.settling_min_samples' must be an integer in [0, 1000], got {n!r}"
        )
    return ConformLimits(settling_min_samples=int(n), reference=ref, **out)
