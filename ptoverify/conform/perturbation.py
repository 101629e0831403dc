"""The perturbations of ``conform``: what the drive sees that the nominal loop does not.

``--delay N``, ``--quantum MM``, ``--velocity-noise MM_S --seed S`` and
``--a-ratio R`` make one :class:`Perturbation` (:func:`perturbation` validates
them: one-line InputErrors); ``--robust`` makes the corners of the
configuration's ``[robustness]`` box (:func:`robust_box`).
:mod:`ptoverify.conform.perturbed` runs the closed loops under them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.sim.simulate import Mismatch

__all__ = ["Perturbation", "perturbation", "robust_box", "MAX_DELAY", "A_RATIO_RANGE"]

MAX_DELAY = 10  #: largest --delay [samples] (as the [robustness] box)
A_RATIO_RANGE = (0.1, 10.0)  #: accepted --a-ratio [-] (as the [robustness] box)


@dataclass(frozen=True)
class Perturbation:
    """What the drive sees that the nominal loop does not.

    Attributes
    ----------
    delay_samples : int
        Computation delay [samples]: u computed from x_k acts from k + delay.
    position_quantum : float
        Encoder resolution [mm] (0: exact).
    velocity_noise : float
        Standard deviation of Gaussian noise on the measured x2 [mm/s] (0: none).
    seed : int
        Seed of the noise sequence (one sequence per run, shared by both laws).
    a_ratio : float
        True bandwidth over design bandwidth a [-].
    w_max_ratio : float
        The drive saturates at ``w_max_ratio * w_max`` [-] (``--robust`` only).
    """

    delay_samples: int = 0
    position_quantum: float = 0.0
    velocity_noise: float = 0.0
    seed: int = 0
    a_ratio: float = 1.0
    w_max_ratio: float = 1.0

    def mismatch(self) -> Mismatch:
        """Return the simulator's :class:`~ptoverify.sim.simulate.Mismatch`."""
        return Mismatch(
            a_ratio=self.a_ratio,
            w_max_ratio=self.w_max_ratio,
            delay_samples=self.delay_samples,
            position_quantum=self.position_quantum,
            velocity_noise=self.velocity_noise,
            seed=self.seed,
        )

    def text(self) -> str:
        """Return the perturbation in words, e.g. ``delay 1 sample, a ratio 0.8``.

        Examples
        --------
        >>> Perturbation(delay_samples=1, velocity_noise=0.5, seed=3).text()
        'delay 1 sample, velocity noise 0.5 mm/s (seed 3)'
        """
        parts = []
        if self.delay_samples:
            s = "" if self.delay_samples == 1 else "s"
            parts.append(f"delay {self.delay_samples} sample{s}")
        if self.position_quantum:
            parts.append(f"quantum {self.position_quantum:g} mm")
        if self.velocity_noise:
            parts.append(f"velocity noise {self.velocity_noise:g} mm/s (seed {self.seed})")
        if self.a_ratio != 1.0:
            parts.append(f"a ratio {self.a_ratio:g}")
        if self.w_max_ratio != 1.0:
            parts.append(f"drive limit {self.w_max_ratio:g} w_max")
        return ", ".join(parts) or "none (nominal loop)"

    def to_json(self) -> dict:
        """Return the perturbation as a JSON object (units in the keys)."""
        return {
            "delay_samples": self.delay_samples,
            "position_quantum_mm": self.position_quantum,
            "velocity_noise_mm_s": self.velocity_noise,
            "seed": self.seed,
            "a_ratio": self.a_ratio,
            "w_max_ratio": self.w_max_ratio,
            "text": self.text(),
        }


def perturbation(
    cfg: Config,
    *,
    delay: int | None = None,
    quantum: float | None = None,
    velocity_noise: float | None = None,
    seed: int | None = None,
    a_ratio: float | None = None,
) -> Perturbation | None:
    """Validate the perturbation options of ``conform`` (None when none is given).

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm] and w_max [mm/s] bound the options).
    delay : int, optional
        ``--delay`` [samples], in [0, 10].
    quantum : float, optional
        ``--quantum`` [mm], in (0, 0.1 position_range].
    velocity_noise : float, optional
        ``--velocity-noise`` [mm/s], in (0, w_max]; needs ``seed``.
    seed : int, optional
        ``--seed``, in [0, 2^32); only with ``velocity_noise``.
    a_ratio : float, optional
        ``--a-ratio`` [-], in [0.1, 10].

    Returns
    -------
    Perturbation or None

    Raises
    ------
    InputError
        One line naming the option and the accepted range.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> perturbation(paper_config(), delay=1).delay_samples
    1
    """
    if all(v is None for v in (delay, quantum, velocity_noise, seed, a_ratio)):
        return None
    out = {}
    if delay is not None:
        if isinstance(delay, bool) or int(delay) != delay or not 0 <= delay <= MAX_DELAY:
            raise InputError(f"--delay must be an integer in [0, {MAX_DELAY}] samples, got {delay}")
        out["delay_samples"] = int(delay)
    if quantum is not None:
        hi = 0.1 * cfg.plant.position_range
        if not (math.isfinite(quantum) and 0.0 < quantum <= hi):
            raise InputError(f"--quantum must be in (0, {hi:g}] mm, got {quantum:g}")
        out["position_quantum"] = float(quantum)
    if velocity_noise is not None:
        hi = cfg.plant.w_max
        if not (math.isfinite(velocity_noise) and 0.0 < velocity_noise <= hi):
            raise InputError(
                f"--velocity-noise must be in (0, {hi:g}] mm/s, got {velocity_noise:g}"
            )
        if seed is None:
            raise InputError("--velocity-noise needs --seed S (the noise sequence is seeded)")
        out["velocity_noise"] = float(velocity_noise)
    if seed is not None:
        if velocity_noise is None:
            raise InputError("--seed is the noise seed: it needs --velocity-noise")
        if not 0 <= seed < 2**32:
            raise InputError(f"--seed must be an integer in [0, 2^32), got {seed}")
        out["seed"] = int(seed)
    if a_ratio is not None:
        lo, hi = A_RATIO_RANGE
        if not (math.isfinite(a_ratio) and lo <= a_ratio <= hi):
            raise InputError(f"--a-ratio must be in [{lo:g}, {hi:g}], got {a_ratio:g}")
        out["a_ratio"] = float(a_ratio)
    return Perturbation(**out)


def robust_box(cfg: Config) -> tuple[Perturbation, ...]:
    """Return the corners of the configuration's ``[robustness]`` box (``conform --robust``).

    Every combination of the ends of ``a_ratio``, ``w_max_ratio`` and
    ``delay_samples`` (up to 8), each with the box's ``position_quantum`` and
    ``velocity_noise`` (seed ``seed``).  The interior is not searched
    (``ptoverify robust`` does that for the reference laws).

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    tuple of Perturbation
        Distinct corners, in order.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> len(robust_box(paper_config()))
    8
    """
    b = cfg.robustness
    out: list[Perturbation] = []
    for a in dict.fromkeys(b.a_ratio):
        for w in dict.fromkeys(b.w_max_ratio):
            for d in dict.fromkeys(b.delay_samples):
                p = Perturbation(
                    delay_samples=int(d),
                    position_quantum=b.position_quantum,
                    velocity_noise=b.velocity_noise,
                    seed=b.seed,
                    a_ratio=float(a),
                    w_max_ratio=float(w),
                )
                if p not in out:
                    out.append(p)
    return tuple(out)
