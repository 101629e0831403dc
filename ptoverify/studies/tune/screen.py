"""The step screen: many gain sets' step responses in one simulation.

:class:`StepScreen` measures what :func:`ptoverify.studies.tune.measure.evaluate`
measures, in batches (per-state gains); it agrees with that path to round-off, and
:func:`ptoverify.studies.tune.tune` re-measures on that path every candidate it
reports.  ``benchmarks/verify_screen.py`` checks the two on 1e5 seeded gain sets
plus every corner of each law's search box, batch sizes 1 to 5000, within 1e-12
(mm, s), and measures the screen's speed-up (``benchmarks/README.md``); the suite
repeats the check on 360 gain sets (``tests/test_tune.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.laws import Law, with_state_gains
from ptoverify.model.poles import spectral_radii
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import overshoot, settling_time
from ptoverify.sim.simulate import reference, simulate_batch
from ptoverify.studies.tune.measure import (
    BOUNDS,
    Candidate,
    gains_key,
    linear_gains,
    tuned_config,
    worst_ratio_nt,
)

__all__ = []


@dataclass(frozen=True)
class ScreenedResponse:
    """A gain set's step response as the screen measured it (no bound or objective yet).

    Attributes
    ----------
    reason : str
        Why it cannot be measured ("" if measured).
    overshoot_mm : float
        Overshoot between samples [mm].
    settling_2pct_s, settling_0p01mm_s : float
        Settling times [s] (nan: not measured or never settles).
    omega0 : float or None
        The PTO's zone level for its d [mm/s].
    """

    reason: str  # why it cannot be measured ("" if measured)
    overshoot_mm: float
    settling_2pct_s: float
    settling_0p01mm_s: float
    omega0: float | None


class StepScreen:
    """Step responses of gain sets of one law, measured in batches and memoized.

    A call measures every new gain set of its argument in one simulation: the
    Section 6 step (:data:`ptoverify.sim.simulate.SIGNALS`) as one
    :func:`ptoverify.sim.simulate.simulate_batch` run of the law with per-state gains
    (:func:`ptoverify.model.laws.with_state_gains`; each PTO candidate acts with the zone
    of its own d), in absolute coordinates with the law fed x1 - r as
    :func:`ptoverify.sim.simulate.simulate` does.  Overshoot and settling are read
    between samples (:func:`ptoverify.sim.settling.overshoot`, and
    :func:`ptoverify.sim.settling.settling_time` under ``2pct`` and ``0p01mm``); the latter only with
    ``tight``.  These agree with :func:`evaluate` (the scalar simulation and
    :mod:`ptoverify.sim.exact`, the path of ``simulate --json``) to round-off, not bit
    for bit: :func:`tune` re-measures on that path every candidate it reports.
    Tunings of one law on one configuration may share a screen.

    Parameters
    ----------
    cfg : Config
        Base configuration (plant; the law's other settings).
    law : str
        A key of :data:`ptoverify.studies.tune.measure.BOUNDS` (pd, pto, ptos, cascade-p).
    tight : bool
        Also measure the 0.01 mm settling time.
    """

    def __init__(self, cfg: Config, law: str, tight: bool):
        self.cfg, self.law, self.tight = cfg, law, tight
        self.memo: dict[tuple, ScreenedResponse] = {}

    def __call__(self, batch: Sequence[dict[str, float]]) -> list[ScreenedResponse]:
        new = {gains_key(g): g for g in batch if gains_key(g) not in self.memo}
        if new:
            self.memo.update(zip(new, self._measure(list(new.values())), strict=True))
        return [self.memo[gains_key(g)] for g in batch]

    def _measure(self, batch: list[dict[str, float]]) -> list[ScreenedResponse]:
        cfg, law = self.cfg, self.law
        p = cfg.plant
        a, T, nan = p.a, p.sample_time, math.nan
        g = np.array([linear_gains(cfg, law, gains) for gains in batch], dtype=float)
        g = g.reshape(-1, 2)
        rho = spectral_radii(a, T, g[:, 0], g[:, 1])
        out: list[ScreenedResponse | None] = [None] * len(batch)
        omega0: dict[float | None, float | None] = {}  # the PTO's zone level per d
        failed: dict[float | None, str] = {}  # d whose zone cannot be built, and why
        live = []
        for i, gains in enumerate(batch):
            d = gains.get("d")
            if rho[i] >= 1.0:
                out[i] = ScreenedResponse("sampled linear loop unstable", nan, nan, nan, None)
                continue
            if law == "pto" and d not in omega0 and d not in failed:
                from ptoverify.model.zones import zone_for_law

                try:
                    z = zone_for_law(tuned_config(cfg, law, gains), "corrected")
                    omega0[d] = float(z.omega0) if z.omega0 is not None else None
                except InputError as exc:
                    failed[d] = str(exc)
            if d in failed:
                out[i] = ScreenedResponse(failed[d], nan, nan, nan, None)
                continue
            live.append(i)
        if not live:
            return out  # type: ignore[return-value]
        ref = reference("step")
        r = ref.amplitude
        steps = int(round(ref.duration / T))  # as simulate()
        per_state = {k: np.array([batch[i][k] for i in live]) for k in BOUNDS[law]}
        base = with_state_gains(law, cfg, per_state)
        # the law sees x1 - r, as simulate() feeds it for a step (r' = 0)
        shifted = Law(base.name, lambda x1, x2: base.vector(x1 - r, x2), base.scalar, base.w_max)
        zeros = np.zeros(len(live))
        res = simulate_batch(shifted, p, zeros, zeros, steps)
        X1, X2, U = res.x1, res.x2, res.u
        finite = np.isfinite(X1).all(axis=0) & np.isfinite(X2).all(axis=0)
        with np.errstate(invalid="ignore", over="ignore"):
            tr = Trajectory(np.arange(steps + 1) * T, X1, X2, U, a)
            ov = overshoot(tr, r).value
            st2 = settling_time(tr, ("step", r), "2pct").time
            st01 = (
                settling_time(tr, ("step", r), "0p01mm").time
                if self.tight
                else np.full(len(live), nan)
            )
        for j, i in enumerate(live):
            if finite[j]:
                om = omega0.get(batch[i].get("d"))
                out[i] = ScreenedResponse("", float(ov[j]), float(st2[j]), float(st01[j]), om)
            else:
                out[i] = ScreenedResponse("non-finite sample data", nan, nan, nan, None)
        return out  # type: ignore[return-value]


def screened_candidate(
    cfg: Config,
    law: str,
    gains: dict[str, float],
    raw: ScreenedResponse,
    *,
    objective: str,
    max_overshoot: float | None,
    worst_ratio: Callable[[Config, str], float] | None,
    ratio: float | None = None,
) -> Candidate:
    """Return the candidate of a screened response: :func:`evaluate`'s rules on its numbers.

    Parameters
    ----------
    cfg : Config
        Base configuration.
    law : str
        A key of :data:`ptoverify.studies.tune.measure.BOUNDS` (pd, pto, ptos, cascade-p).
    gains : dict
        The gains (see :func:`ptoverify.studies.tune.measure.tuned_config`).
    raw : ScreenedResponse
        The screened response.
    objective : str
        One of :data:`ptoverify.studies.tune.measure.OBJECTIVES`.
    max_overshoot : float or None
        Overshoot bound [mm].
    worst_ratio : callable or None
        ``f(cfg, law) -> worst settling / N*T`` [-] (default
        :func:`ptoverify.studies.tune.measure.worst_ratio_nt`).
    ratio : float, optional
        Its worst settling / N*T [-] when computed already (``worst_ratio_nt``).

    Returns
    -------
    Candidate
        The candidate (``verified`` False).
    """
    nan = math.nan
    if raw.reason:
        return Candidate(gains, math.inf, nan, nan, nan, False, reason=raw.reason)
    o = raw.overshoot_mm
    if max_overshoot is not None and not o <= max_overshoot:
        value, reason = math.inf, f"overshoot {o:.4g} mm > {max_overshoot:.4g} mm"
    else:
        reason = ""
        if objective == "worst_ratio_nt":
            if ratio is None:
                ratio = (worst_ratio or worst_ratio_nt)(tuned_config(cfg, law, gains), law)
            value = ratio
        else:
            value = raw.settling_2pct_s if objective == "settling_2pct" else raw.settling_0p01mm_s
        if not math.isfinite(value):
            reason, value = "does not settle", math.inf
    return Candidate(
        gains,
        value,
        raw.settling_2pct_s,
        raw.settling_0p01mm_s,
        o,
        not reason,
        reason=reason,
        omega0=raw.omega0,
    )


#: Window and band of the gates' limit-cycle test (the defaults of
#: :func:`ptoverify.studies.properties.law_properties`; a test holds them equal).
