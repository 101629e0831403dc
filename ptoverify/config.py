"""Configuration: frozen dataclasses, TOML loading, validation, paper defaults.

The configuration format is the one in ``shared/DESIGN.md``::

    name = "paper"
    [plant]
    bandwidth_hz = 30.0      # or a = 188.49... (rad/s); exactly one of the two
    w_max = 300.0            # mm/s
    sample_time = 0.002      # s
    position_range = 50.0    # mm
    [pd]
    kp = 356.0
    kd = 1.15
    [pto]
    d = 0.5                  # mm
    k1 = 323.0
    k2 = 3.6

Every rejection is a :class:`~ptoverify.errors.ConfigError` whose message
names the key and the value.  Ranges: a, w_max, position_range <= 1e6;
1e-7 <= sample_time <= 1 s and 0.01 <= a T <= 20 (the plant's time constant
at most 100 samples); position_range / (w_max T) <= 2000 samples to cross the
range at full speed (the work of zone, check, sweep, robust and report grows
with both; README "Limits"); 0 <= d <= position_range;
gains 0 <= kp T, k1 T <= 1e4 and 0 <= kd, k2 <= 1e4 (far beyond the sampled
stability limits, so unstable gains reach the gates; see ``_check_gains``).
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from ptoverify.conform_limits import ConformLimits, conform_limits_from_mapping
from ptoverify.errors import ConfigError
from ptoverify.robustness import Robustness, _number, robustness_from_mapping

__all__ = [
    "Plant",
    "PDGains",
    "PTOSettings",
    "Config",
    "paper_config",
    "load_config",
    "config_from_mapping",
    "Robustness",
    "robustness_from_mapping",
    "LAW_NAMES",
    "BASELINE_NAMES",
    "ALL_LAW_NAMES",
    "PTOSGains",
    "CascadeGains",
    "ConformLimits",
    "conform_limits_from_mapping",
]

#: The laws the suite implements (:func:`ptoverify.model.laws.make_law`), here so that naming
#: them (the command line's choices) loads no numerics.
LAW_NAMES: tuple[str, ...] = ("to", "pd", "pto", "pto-printed")
#: The baselines a servo engineer compares against (:mod:`ptoverify.model.baselines`).
BASELINE_NAMES: tuple[str, ...] = ("ptos", "cascade-p")
#: Every law :func:`ptoverify.model.laws.make_law` builds.
ALL_LAW_NAMES: tuple[str, ...] = LAW_NAMES + BASELINE_NAMES
#: Defaults of ``ptoverify design`` (:mod:`ptoverify.studies.design`): laws, T [s], bandwidth [Hz].
DESIGN_LAWS: tuple[str, ...] = ("pd", "pto", "ptos", "cascade-p")
DESIGN_SAMPLE_TIMES: tuple[float, ...] = (0.00025, 0.0005, 0.001, 0.002, 0.004, 0.008)
DESIGN_BANDWIDTHS_HZ: tuple[float, ...] = (8.0, 15.0, 30.0, 60.0, 100.0)  # a T >= 0.01 at 0.25 ms
DESIGN_GRID = 10  #: envelope states per axis of a design point (even: the origin is off the grid)


_HASH_KEY = "_hash"  #: instance key of a remembered hash (not a field: eq, repr, asdict skip it)


def _hash_once(cls: type) -> type:
    """Make a frozen dataclass compute its hash once per instance.

    The dataclass's own hash (of the tuple of its fields) is remembered in the
    instance the first time it is asked for: the fields of a frozen dataclass do
    not change, and a configuration is a memo key (:mod:`ptoverify.model.memo`)
    and a law's ``functools.lru_cache`` key at every call, where hashing the
    nested fields again cost more than the law.  Equality, ``repr``,
    :func:`dataclasses.asdict` and :func:`dataclasses.replace` see only the
    fields.  The remembered value is left out of the state that :mod:`pickle`
    and :mod:`copy` take (a string's hash differs between processes), so an
    unpickled configuration computes its own.

    Parameters
    ----------
    cls : type
        A frozen dataclass (``@dataclass(frozen=True)`` already applied).

    Returns
    -------
    type
        ``cls`` with ``__hash__`` and ``__getstate__`` replaced.
    """
    field_hash = cls.__hash__

    def __hash__(self) -> int:
        try:
            return self.__dict__[_HASH_KEY]
        except KeyError:
            value = field_hash(self)
            object.__setattr__(self, _HASH_KEY, value)
            return value

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state.pop(_HASH_KEY, None)
        return state

    __hash__.__doc__ = field_hash.__doc__
    cls.__hash__ = __hash__
    cls.__getstate__ = __getstate__
    return cls


@_hash_once
@dataclass(frozen=True)
class Plant:
    """Plant of eq. (1), sampled with zero-order hold.

    Attributes
    ----------
    a : float
        Velocity-loop bandwidth [rad/s]; x2' = -a x2 + a u.
    w_max : float
        Velocity saturation |u| <= w_max [mm/s] (the paper's omega_m).
    sample_time : float
        Sampling period T [s].
    position_range : float
        Half-width of the position envelope [mm].
    """

    a: float
    w_max: float
    sample_time: float
    position_range: float

    @property
    def T(self) -> float:  # noqa: N802 - the paper's symbol
        """Sampling period T [s] (alias of ``sample_time``)."""
        return self.sample_time


@_hash_once
@dataclass(frozen=True)
class PDGains:
    """Gains of the PD law u = kp (r - x1) - kd x2.

    Attributes
    ----------
    kp : float
        Proportional gain [1/s].
    kd : float
        Derivative gain on velocity [-].
    """

    kp: float = 356.0
    kd: float = 1.15


@_hash_once
@dataclass(frozen=True)
class PTOSettings:
    """Settings of the PTO law, eq. (35).

    Attributes
    ----------
    d : float
        Half-width of the linear zone |x1| < d [mm].
    k1 : float
        Linear-zone position gain of eq. (34) [1/s].
    k2 : float
        Linear-zone velocity gain of eq. (34) [-].
    """

    d: float = 0.5
    k1: float = 323.0
    k2: float = 3.6


@_hash_once
@dataclass(frozen=True)
class PTOSGains:
    """Settings of the PTOS baseline (table ``[ptos]``, optional).

    Attributes
    ----------
    alpha : float
        Deceleration discount of the square-root profile, 0 < alpha <= 1 [-].
    k : float or None
        Velocity-loop gain k [1/s] the profile is designed for (Workman's k2);
        None: the plant's own a (then u is the profile itself).
    """

    alpha: float = 0.9
    k: float | None = None


@_hash_once
@dataclass(frozen=True)
class CascadeGains:
    """Gain of the cascade P baseline (table ``[cascade]``, optional).

    Attributes
    ----------
    kp : float or None
        Position gain [1/s] of u = sat(-kp x1); None: a / 4 (the continuous
        loop x1'' + a x1' + a kp x1 = 0 critically damped).
    """

    kp: float | None = None


@_hash_once
@dataclass(frozen=True)
class Config:
    """A full configuration: plant, PD gains and PTO settings.

    Attributes
    ----------
    name : str
        Name of the configuration (names the report folder).
    plant : Plant
        The plant and its sampling.
    pd : PDGains
        PD gains.
    pto : PTOSettings
        PTO settings.
    robustness : Robustness
        The uncertainty box of ``ptoverify robust``.
    ptos : PTOSGains
        PTOS baseline settings.
    cascade : CascadeGains
        Cascade P baseline gain.
    conform : ConformLimits
        Pass limits of ``ptoverify conform``.
    bandwidth_hz : float or None
        The bandwidth as given in Hz, when the file gave it in Hz.
    """

    name: str
    plant: Plant
    pd: PDGains = field(default_factory=PDGains)
    pto: PTOSettings = field(default_factory=PTOSettings)
    bandwidth_hz: float | None = None
    robustness: Robustness = field(default_factory=Robustness)
    ptos: PTOSGains = field(default_factory=PTOSGains)
    cascade: CascadeGains = field(default_factory=CascadeGains)
    conform: ConformLimits = field(default_factory=ConformLimits)

    def with_plant(self, **changes: float) -> Config:
        """Return a copy with plant fields replaced (``a``, ``w_max``...)."""
        return replace(
            self,
            plant=replace(self.plant, **changes),
            bandwidth_hz=None if "a" in changes else self.bandwidth_hz,
        )

    def digest(self) -> str:
        """Return a SHA-256 hex digest of the configuration (its TOML layout).

        Output folders record it, so a default folder is never replaced by the
        output of another configuration.

        Examples
        --------
        >>> paper_config().digest() == paper_config().digest()
        True
        """
        text = json.dumps(self.to_mapping(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def to_mapping(self) -> dict[str, Any]:
        """Return the configuration as a plain dict (the TOML layout)."""
        p = self.plant
        plant: dict[str, Any] = {}
        if self.bandwidth_hz is not None:
            plant["bandwidth_hz"] = self.bandwidth_hz
        else:
            plant["a"] = p.a
        plant.update(w_max=p.w_max, sample_time=p.sample_time, position_range=p.position_range)
        out = {
            "name": self.name,
            "plant": plant,
            "pd": {"kp": self.pd.kp, "kd": self.pd.kd},
            "pto": {"d": self.pto.d, "k1": self.pto.k1, "k2": self.pto.k2},
            "robustness": self.robustness.to_mapping(),
        }
        # the baselines' tables only when set (so a configuration without them keeps its digest)
        for key, obj in (("ptos", self.ptos), ("cascade", self.cascade)):
            given = {k: v for k, v in asdict(obj).items() if v is not None}
            if obj != type(obj)():
                out[key] = given
        if self.conform != ConformLimits():  # only when set (the digest of others is kept)
            out["conform"] = self.conform.to_mapping()
        return out


PAPER_MAPPING: dict[str, Any] = {
    "name": "paper",
    "plant": {"bandwidth_hz": 30.0, "w_max": 300.0, "sample_time": 0.002, "position_range": 50.0},
    "pd": {"kp": 356.0, "kd": 1.15},
    "pto": {"d": 0.5, "k1": 323.0, "k2": 3.6},
}

_SECTIONS = {
    "plant": ({"w_max", "sample_time", "position_range"}, {"bandwidth_hz", "a"}),
    "pd": ({"kp", "kd"}, set()),
    "pto": ({"d", "k1", "k2"}, set()),
}


def paper_config() -> Config:
    """Return the paper's Section 6 configuration (the default).

    Examples
    --------
    >>> cfg = paper_config()
    >>> round(cfg.plant.a, 4), cfg.plant.w_max, cfg.pto.d
    (188.4956, 300.0, 0.5)
    """
    return config_from_mapping(PAPER_MAPPING)


def _positive(section: str, key: str, value: float) -> None:
    if value <= 0:
        raise ConfigError(f"config key '{section}.{key}' must be > 0, got {value!r}")


def _section(data: dict[str, Any], name: str) -> dict[str, float]:
    if name not in data:
        raise ConfigError(f"config section '[{name}]' is missing")
    raw = data[name]
    if not isinstance(raw, dict):
        raise ConfigError(f"config key '{name}' must be a table [{name}], got {raw!r}")
    required, optional = _SECTIONS[name]
    for key in raw:
        if key not in required | optional:
            raise ConfigError(f"unknown config key '{name}.{key}'")
    for key in sorted(required):
        if key not in raw:
            raise ConfigError(f"config key '{name}.{key}' is missing")
    return {key: _number(name, key, value) for key, value in raw.items()}


#: Ranges beyond which the suite's computations are not meaningful (or would not fit in memory):
#: they are rejected as out of range, each naming the key.
LIMITS = {
    "a": 1e6,
    "w_max": 1e6,
    "position_range": 1e6,
    "sample_time": (1e-7, 1.0),
    "aT": (0.01, 20.0),
    "samples_across_range": 2000.0,
    "gain_T": 1e4,
    "gain": 1e4,
}


def _check_gains(pd: dict[str, float], pto: dict[str, float], T: float) -> None:  # noqa: N803
    """Reject gains outside their documented ranges (the key is named).

    Position gains kp, k1 [1/s]: 0 <= k T <= 1e4.  Velocity gains kd, k2 [-]:
    0 <= k <= 1e4.  The sampled loops become unstable far inside these
    ranges (with a fast velocity loop, u = -kp x1 - kd x2 is unstable for
    kp T > 2 (1 + kd); the velocity loop alone for kd > coth(a T / 2)), so
    unstable gains stay reachable and fail their gates, while every product
    the checks form (gain x range x samples) stays finite.  Negative gains
    make the law push away from the target; they are rejected.
    """
    for section, values in (("pd", pd), ("pto", pto)):
        for key, scaled in (("kp", True), ("kd", False), ("k1", True), ("k2", False)):
            if key not in values:
                continue
            value = values[key]
            if value < 0:
                raise ConfigError(f"config key '{section}.{key}' must be >= 0, got {value!r}")
            if scaled and value * T > LIMITS["gain_T"]:
                raise ConfigError(
                    f"config key '{section}.{key}' must be <= {LIMITS['gain_T']:g} / sample_time "
                    f"= {LIMITS['gain_T'] / T:g} 1/s, got {value!r}"
                )
            if not scaled and value > LIMITS["gain"]:
                raise ConfigError(
                    f"config key '{section}.{key}' must be <= {LIMITS['gain']:g}, got {value!r}"
                )


def _check_scales(a: float, plant: dict[str, float], a_key: str) -> None:
    """Reject plants outside the ranges of :data:`LIMITS` (the key is named)."""
    if a > LIMITS["a"]:
        raise ConfigError(f"config key '{a_key}' gives a = {a:g} rad/s, above {LIMITS['a']:g}")
    for key in ("w_max", "position_range"):
        if plant[key] > LIMITS[key]:
            raise ConfigError(
                f"config key 'plant.{key}' must be <= {LIMITS[key]:g}, got {plant[key]!r}"
            )
    lo, hi = LIMITS["sample_time"]
    T = plant["sample_time"]  # noqa: N806
    if not lo <= T <= hi:
        raise ConfigError(
            f"config key 'plant.sample_time' must be in [{lo:g}, {hi:g}] s, got {T!r}"
        )
    lo, hi = LIMITS["aT"]
    if not lo <= a * T <= hi:
        raise ConfigError(
            f"config key 'plant.sample_time' gives a T = {a * T:g}, outside "
            f"[{lo:g}, {hi:g}] (the sampling is too fast or too slow for the "
            f"bandwidth)"
        )
    n = plant["position_range"] / (plant["w_max"] * T)
    if n > LIMITS["samples_across_range"]:
        raise ConfigError(
            f"config key 'plant.position_range' needs {n:.3g} samples to cross "
            f"at w_max, above {LIMITS['samples_across_range']:g}"
        )


def config_from_mapping(data: dict[str, Any]) -> Config:
    """Validate a parsed TOML mapping and build a :class:`Config`.

    Parameters
    ----------
    data : dict
        The mapping, in the TOML layout of ``shared/DESIGN.md``.

    Returns
    -------
    Config
        The validated configuration.

    Raises
    ------
    ConfigError
        On unknown keys, missing sections or keys, non-numbers, NaN,
        infinities and out-of-range values; the message names the key.
    """
    for key in data:
        if key not in {"name", "robustness", "ptos", "cascade", "conform", *_SECTIONS}:
            raise ConfigError(f"unknown config key '{key}'")
    name = data.get("name", "custom")
    if (
        not isinstance(name, str)
        or not name
        or not name.isascii()
        or not all(c.isalnum() or c in "-_." for c in name)
        or name.startswith(".")
    ):
        raise ConfigError(
            f"config key 'name' must be a non-empty word of letters, digits, "
            f"'-', '_' or '.', got {name!r}"
        )
    plant = _section(data, "plant")
    pd = _section(data, "pd")
    pto = _section(data, "pto")
    has_hz, has_a = "bandwidth_hz" in plant, "a" in plant
    if has_hz == has_a:
        raise ConfigError(
            "config section '[plant]' needs exactly one of 'plant.bandwidth_hz' and 'plant.a'"
        )
    bandwidth_hz = plant.get("bandwidth_hz")
    if has_hz:
        _positive("plant", "bandwidth_hz", plant["bandwidth_hz"])
        a = 2.0 * math.pi * plant["bandwidth_hz"]
    else:
        _positive("plant", "a", plant["a"])
        a = plant["a"]
    for key in ("w_max", "sample_time", "position_range"):
        _positive("plant", key, plant[key])
    _check_scales(a, plant, "plant.bandwidth_hz" if has_hz else "plant.a")
    _check_gains(pd, pto, plant["sample_time"])
    if pto["d"] < 0:
        raise ConfigError(f"config key 'pto.d' must be >= 0, got {pto['d']!r}")
    if pto["d"] > plant["position_range"]:
        raise ConfigError(
            f"config key 'pto.d' must be <= plant.position_range "
            f"({plant['position_range']!r}), got {pto['d']!r}"
        )
    return Config(
        name=name,
        plant=Plant(
            a=a,
            w_max=plant["w_max"],
            sample_time=plant["sample_time"],
            position_range=plant["position_range"],
        ),
        pd=PDGains(kp=pd["kp"], kd=pd["kd"]),
        pto=PTOSettings(d=pto["d"], k1=pto["k1"], k2=pto["k2"]),
        bandwidth_hz=bandwidth_hz,
        robustness=robustness_from_mapping(data.get("robustness", {}), plant),
        ptos=PTOSGains(**_ptos_table(data, a, plant["w_max"], plant["sample_time"])),
        cascade=CascadeGains(**_baseline_table(data, "cascade", plant["sample_time"])),
        conform=conform_limits_from_mapping(data.get("conform", {})),
    )


#: The optional baseline tables: key -> (lowest, highest, whether scaled by 1/T, strict low).
_BASELINE_KEYS = {
    "ptos": {"alpha": (0.0, 1.0, False, True), "k": (0.0, None, True, True)},
    "cascade": {"kp": (0.0, None, True, False)},
}


def _ptos_table(data: dict[str, Any], a: float, w_max: float, T: float) -> dict[str, float]:  # noqa: N803
    """Validate ``[ptos]``; also that its linear-region edge 2 a w_max / (alpha k^2) is finite.

    With alpha k^2 so small that Workman's k1 = alpha k^2 / 2 [1/s^2] underflows (or the
    edge y_l = a w_max / k1 [mm] overflows), no PTOS law exists to compute: the keys are
    named (audit run 7).
    """
    out = _baseline_table(data, "ptos", T)
    alpha, k = out.get("alpha", PTOSGains.alpha), out.get("k", a)
    k1 = alpha * k * k / 2.0
    if not (k1 > 0.0 and math.isfinite(a * w_max / k1)):
        raise ConfigError(
            f"config keys 'ptos.alpha' and 'ptos.k' (alpha = {alpha!r}, k = {k!r} 1/s) give a "
            "PTOS linear region |x1| <= 2 a w_max / (alpha k^2) that is not a finite number "
            "(alpha k^2 underflows): raise them"
        )
    return out


def _baseline_table(data: dict[str, Any], name: str, T: float) -> dict[str, float]:  # noqa: N803
    """Validate an optional ``[ptos]`` / ``[cascade]`` table (the key is named)."""
    raw = data.get(name, {})
    if not isinstance(raw, dict):
        raise ConfigError(f"config key '{name}' must be a table [{name}], got {raw!r}")
    out = {}
    for key, value in raw.items():
        if key not in _BASELINE_KEYS[name]:
            raise ConfigError(f"unknown config key '{name}.{key}'")
        lo, hi, scaled, strict = _BASELINE_KEYS[name][key]
        v = _number(name, key, value)
        hi = LIMITS["gain_T"] / T if scaled else hi
        if v < lo or (strict and v == lo) or v > hi:
            low = f"> {lo:g}" if strict else f">= {lo:g}"
            raise ConfigError(f"config key '{name}.{key}' must be {low} and <= {hi:g}, got {v!r}")
        out[key] = v
    return out


def load_config(path: str | Path | None) -> Config:
    """Load and validate a TOML configuration file.

    Parameters
    ----------
    path : str, Path or None
        The file; None gives :func:`paper_config`.

    Returns
    -------
    Config
        The validated configuration.

    Raises
    ------
    ConfigError
        When the file is missing, unreadable, not TOML, or invalid.
    """
    if path is None:
        return paper_config()
    if str(path).strip() == "":
        raise ConfigError("config file name is empty")
    path = Path(path)
    if path.exists() and not path.is_file():
        raise ConfigError(f"config file '{path}' is not a regular file")
    try:
        if path.stat().st_size > 1 << 20:
            raise ConfigError(f"config file '{path}' is larger than 1 MiB")
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise ConfigError(f"config file '{path}' does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"config file '{path}' cannot be read: {exc}") from None
    try:
        data = tomllib.loads(text)
    except ValueError as exc:  # TOMLDecodeError, or an integer over Python's 4300 digits
        raise ConfigError(f"config file '{path}' is not valid TOML: {exc}") from None
    return config_from_mapping(data)
