"""The uncertainty box of ``ptoverify robust``: the configuration's ``[robustness]`` table.

Vocabulary, like :mod:`ptoverify.config` (which holds a :class:`Robustness` in
:attr:`ptoverify.config.Config.robustness` and re-exports both names); kept
apart so the configuration module stays small.  Ranges: a_ratio within
[0.1, 10] and containing 1, w_max_ratio within [0.05, 1], delay_samples within
[0, 10], position_quantum <= 0.1 position_range, velocity_noise <= w_max,
settling_ratio_limit in [1, 1e6], seed in [0, 2^32).  The work a box asks of
``robust`` is bounded separately (:func:`ptoverify.studies.robust.maps.check_box_work`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ptoverify.errors import ConfigError

__all__ = ["Robustness", "robustness_from_mapping"]


def _number(section: str, key: str, value: Any) -> float:
    where = f"{section}.{key}"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"config key '{where}' must be a number, got {value!r}")
    try:
        value = float(value)
    except OverflowError:  # a TOML integer beyond the float range (e.g. 400 digits)
        raise ConfigError(
            f"config key '{where}' must be finite, got an integer of "
            f"{value.bit_length()} bits, beyond the float range"
        ) from None
    if not math.isfinite(value):
        raise ConfigError(f"config key '{where}' must be finite, got {value!r}")
    return value


@dataclass(frozen=True)
class Robustness:
    """The uncertainty box of ``ptoverify robust`` (table ``[robustness]``).

    The law is always built from the nominal configuration; only the simulated
    plant and the measurement change within the box.

    Attributes
    ----------
    a_ratio : tuple of float
        Range of true a over design a [-]; must contain 1.
    w_max_ratio : tuple of float
        Range of the drive's saturation over the law's w_max [-], in (0, 1].
    delay_samples : tuple of int
        Range of the computation delay [samples]: the input computed from x_k is
        applied at k + delay.
    position_quantum : float
        Encoder resolution [mm] (0: exact measurement).
    velocity_noise : float
        Standard deviation of Gaussian velocity-measurement noise [mm/s].
    settling_ratio_limit : float
        Limit of the ``robust-settling`` gate: the worst settling time over
        N*T of the true plant, anywhere in the box [-].
    seed : int
        Seed of the noise and of the worst-case search.
    """

    a_ratio: tuple[float, float] = (0.8, 1.25)
    w_max_ratio: tuple[float, float] = (0.9, 1.0)
    delay_samples: tuple[int, int] = (0, 1)
    position_quantum: float = 0.001
    velocity_noise: float = 0.0
    settling_ratio_limit: float = 10.0
    seed: int = 0

    def to_mapping(self) -> dict[str, Any]:
        """Return the box as a plain dict (the TOML layout)."""
        return {
            "a_ratio": list(self.a_ratio),
            "w_max_ratio": list(self.w_max_ratio),
            "delay_samples": list(self.delay_samples),
            "position_quantum": self.position_quantum,
            "velocity_noise": self.velocity_noise,
            "settling_ratio_limit": self.settling_ratio_limit,
            "seed": self.seed,
        }


def _pair(key: str, value: Any, lo: float, hi: float, *, integer: bool = False) -> tuple:
    where = f"robustness.{key}"
    if not isinstance(value, list) or len(value) != 2:
        raise ConfigError(f"config key '{where}' must be a list [low, high], got {value!r}")
    if integer:
        if any(isinstance(v, bool) or not isinstance(v, int) for v in value):
            raise ConfigError(f"config key '{where}' must hold integers, got {value!r}")
        out = (int(value[0]), int(value[1]))
    else:
        out = (_number("robustness", key, value[0]), _number("robustness", key, value[1]))
    if not lo <= out[0] <= out[1] <= hi:
        raise ConfigError(
            f"config key '{where}' must satisfy {lo:g} <= low <= high <= {hi:g}, got {value!r}"
        )
    return out


def robustness_from_mapping(raw: Any, plant: dict[str, float]) -> Robustness:
    """Validate the ``[robustness]`` table (every key optional; defaults of :class:`Robustness`).

    Parameters
    ----------
    raw : dict
        The parsed table.
    plant : dict
        The validated ``[plant]`` numbers (w_max [mm/s], position_range [mm]).

    Returns
    -------
    Robustness
        The box.

    Raises
    ------
    ConfigError
        On unknown keys, wrong types or out-of-range values (the key is named).

    Examples
    --------
    >>> robustness_from_mapping({"a_ratio": [0.5, 2.0]}, {"w_max": 300.0,
    ...     "position_range": 50.0}).a_ratio
    (0.5, 2.0)
    """
    if not isinstance(raw, dict):
        raise ConfigError(f"config key 'robustness' must be a table [robustness], got {raw!r}")
    base = Robustness()
    known = set(base.to_mapping())
    for key in raw:
        if key not in known:
            raise ConfigError(f"unknown config key 'robustness.{key}'")
    a_ratio = _pair("a_ratio", raw.get("a_ratio", list(base.a_ratio)), 0.1, 10.0)
    if not a_ratio[0] <= 1.0 <= a_ratio[1]:
        raise ConfigError(f"config key 'robustness.a_ratio' must contain 1, got {list(a_ratio)}")
    w_ratio = _pair("w_max_ratio", raw.get("w_max_ratio", list(base.w_max_ratio)), 0.05, 1.0)
    delay = _pair(
        "delay_samples", raw.get("delay_samples", list(base.delay_samples)), 0, 10, integer=True
    )
    scalars = {}
    if "position_quantum" not in raw:  # the default never exceeds its own limit
        raw = {**raw, "position_quantum": min(base.position_quantum, 0.1 * plant["position_range"])}
    limits = {
        "position_quantum": (0.0, 0.1 * plant["position_range"]),
        "velocity_noise": (0.0, plant["w_max"]),
        "settling_ratio_limit": (1.0, 1e6),
    }
    for key, (lo, hi) in limits.items():
        v = _number("robustness", key, raw.get(key, getattr(base, key)))
        if not lo <= v <= hi:
            raise ConfigError(
                f"config key 'robustness.{key}' must be in [{lo:g}, {hi:g}], got {v!r}"
            )
        scalars[key] = v
    seed = raw.get("seed", base.seed)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**32:
        raise ConfigError(
            f"config key 'robustness.seed' must be an integer in [0, 2^32), got {seed!r}"
        )
    return Robustness(
        a_ratio=a_ratio, w_max_ratio=w_ratio, delay_samples=delay, seed=seed, **scalars
    )
