"""Penalty against move size: how much slower than the limit each law is, per move.

Point-to-point moves from rest: the state (s, 0) regulated to the origin, for
log-spaced sizes s from 0.01 mm to the position range.  For each law:

* **settling** (the suite's 0.01 mm definition, as ``ptoverify sweep``): the
  last exit of the exact trajectory between samples from the box
  |x1| <= 0.01 mm, |x2| <= a 0.01 mm/s, with a settled tail of at least 0.05 s
  (:func:`ptoverify.sim.settling.settling_time` under ``box-0p01mm``); NaN where the law never
  settles (the sampled TO law limit-cycles, so it never does);
* **arrival**: the first sample time k T at which the position has reached or
  passed the target (x1_k s <= 0, or |x1_k| <= 0.01 mm): reaching, not staying,
  so it is defined for TO too; it is late by less than T;

beside the continuous minimum time t_f* (:func:`ptoverify.model.mintime.min_time`)
and the discrete limit N* T (:func:`ptoverify.model.mintime.discrete_min_steps_batch`),
and their ratios.  A move of 0.01 mm starts on the band's edge: it is settled at 0.
"""

from __future__ import annotations

import csv
import io
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import ALL_LAW_NAMES, Config
from ptoverify.errors import InputError
from ptoverify.model.laws import make_law
from ptoverify.model.mintime import discrete_min_steps_batch, min_time
from ptoverify.sim.exact import TIGHT_BAND
from ptoverify.sim.flow import Trajectory
from ptoverify.sim.settling import DEFINITIONS, settling_time
from ptoverify.sim.simulate import simulate_batch

__all__ = ["PenaltyCurve", "PenaltyResult", "penalty_curves", "move_sizes", "SETTLING_DEFINITION"]

#: The settling definition of the curves, by name (:data:`ptoverify.sim.settling.DEFINITIONS`):
#: the sweep's box, |x1| <= 0.01 mm and |x2| <= a 0.01 mm/s held 0.05 s.
SETTLING_DEFINITION = "box-0p01mm"
HOLD_S = DEFINITIONS[SETTLING_DEFINITION].hold_s  #: shortest settled tail [s]
HORIZON_FACTOR = 4.0  #: horizon in units of the largest t_f* (the sweep's), plus the hold


@dataclass(frozen=True)
class PenaltyCurve:
    """One law's penalty curve (arrays over the move sizes of :class:`PenaltyResult`).

    Attributes
    ----------
    law, note : str
        Law name and its one-line description.
    settling_s : ndarray
        Settling time (``SETTLING_DEFINITION``) [s]; NaN: not settled in the horizon.
    arrival_s : ndarray
        First sample time at or past the target [s]; NaN: never in the horizon.
    ratio_nt : ndarray
        settling_s / (N* T) [-].
    ratio_tf : ndarray
        settling_s / t_f* [-].
    """

    law: str
    note: str
    settling_s: NDArray[np.float64]
    arrival_s: NDArray[np.float64]
    ratio_nt: NDArray[np.float64]
    ratio_tf: NDArray[np.float64]


@dataclass(frozen=True)
class PenaltyResult:
    """Penalty curves of several laws over move sizes.

    Attributes
    ----------
    config_name : str
        Name of the configuration.
    sizes_mm : ndarray
        Move sizes s [mm] (from (s, 0) to the origin).
    t_f_s : ndarray
        Continuous minimum time t_f* [s].
    n_star : ndarray of int
        Fewest ZOH samples N* [-] (-1: not found).
    nt_s : ndarray
        N* T [s].
    curves : tuple of PenaltyCurve
        One per law, in the order asked.
    settling : str
        The settling definition.
    horizon_s : float
        Simulated time [s].
    seconds : float
        Wall time of the computation [s].
    setting : str
        Whose gains: ``configured``, or the tuning's name.
    """

    config_name: str
    sizes_mm: NDArray[np.float64]
    t_f_s: NDArray[np.float64]
    n_star: NDArray[np.int64]
    nt_s: NDArray[np.float64]
    curves: tuple[PenaltyCurve, ...]
    settling: str
    horizon_s: float
    seconds: float
    setting: str = "configured"

    def to_json(self) -> dict[str, Any]:
        """Return the curves as a JSON-able dict (NaN as None)."""

        def col(v) -> list:
            return [None if not math.isfinite(x) else float(x) for x in np.asarray(v, float)]

        return {
            "config": self.config_name,
            "setting": self.setting,
            "settling_definition": self.settling,
            "horizon_s": self.horizon_s,
            "sizes_mm": col(self.sizes_mm),
            "t_f_s": col(self.t_f_s),
            "n_star": [int(n) for n in self.n_star],
            "nt_s": col(self.nt_s),
            "laws": {
                c.law: {
                    "note": c.note,
                    "settling_s": col(c.settling_s),
                    "arrival_s": col(c.arrival_s),
                    "ratio_nt": col(c.ratio_nt),
                    "ratio_tf": col(c.ratio_tf),
                }
                for c in self.curves
            },
            "seconds": self.seconds,
        }

    def to_csv(self) -> str:
        """Return the curves as CSV text: one row per (law, size)."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(
            ["law", "size_mm", "t_f_s", "n_star", "nt_s", "settling_s", "arrival_s"]
            + ["ratio_nt", "ratio_tf"]
        )
        for c in self.curves:
            for i, s in enumerate(self.sizes_mm.tolist()):
                row = [self.t_f_s[i], self.n_star[i], self.nt_s[i], c.settling_s[i]]
                row += [c.arrival_s[i], c.ratio_nt[i], c.ratio_tf[i]]
                w.writerow([c.law, repr(s)] + [_cell(v) for v in row])
        return buf.getvalue()

    def write_csv(self, path: str | Path) -> Path:
        """Write :meth:`to_csv` to ``path`` and return it."""
        path = Path(path)
        path.write_text(self.to_csv())
        return path


def _cell(v: Any) -> str:
    """CSV cell: integers as such, NaN empty, floats by repr."""
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return "" if not math.isfinite(float(v)) else repr(float(v))


def move_sizes(cfg: Config, count: int = 40, smallest: float = TIGHT_BAND) -> NDArray[np.float64]:
    """Log-spaced move sizes from ``smallest`` to the position range.

    Parameters
    ----------
    cfg : Config
        Configuration (position_range [mm]).
    count : int
        Number of sizes, >= 2.
    smallest : float
        Smallest move [mm], 0 < smallest < position_range.

    Returns
    -------
    ndarray, shape (count,)
        Sizes [mm].

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> [round(s, 6) for s in move_sizes(paper_config(), 3).tolist()]
    [0.01, 0.707107, 50.0]
    """
    r = cfg.plant.position_range
    if count < 2 or not 0.0 < smallest < r:
        raise InputError(f"move sizes: need count >= 2 and 0 < smallest < {r:g} mm")
    s = np.geomspace(smallest, r, count)
    s[0], s[-1] = smallest, r  # exact ends
    return s


def penalty_curves(
    cfg: Config,
    laws: tuple[str, ...] = ALL_LAW_NAMES,
    *,
    count: int = 40,
    configs: dict[str, Config] | None = None,
    setting: str = "configured",
) -> PenaltyResult:
    """Settling and arrival of each law against move size (module docstring).

    Parameters
    ----------
    cfg : Config
        Configuration (plant; each law's gains unless ``configs`` overrides).
    laws : tuple of str
        Law names (:func:`ptoverify.model.laws.make_law`).
    count : int
        Number of move sizes (:func:`move_sizes`).
    configs : dict, optional
        Law name -> the configuration its law is built from (e.g. its best
        tuning); the plant simulated is always ``cfg``'s.
    setting : str
        Name of whose gains these are (recorded).

    Returns
    -------
    PenaltyResult
        The curves.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> res = penalty_curves(paper_config(), ("pd",), count=4)
    >>> bool(np.all(res.curves[0].settling_s[1:] >= res.t_f_s[1:]))
    True
    """
    t0 = time.perf_counter()
    plant = cfg.plant
    T, a = plant.sample_time, plant.a
    s = move_sizes(cfg, count)
    zero = np.zeros_like(s)
    t_f = min_time(s, zero, plant).t_f
    lim = discrete_min_steps_batch(s, zero, plant)
    steps = math.ceil(HORIZON_FACTOR * float(t_f.max()) / T) + math.ceil(HOLD_S / T - 1e-9)
    curves = []
    for name in laws:
        law = make_law(name, (configs or {}).get(name, cfg))
        b = simulate_batch(law, plant, s, zero, steps)
        t = np.arange(b.x1.shape[0]) * T
        st = settling_time(Trajectory(t, b.x1, b.x2, b.u, a), None, SETTLING_DEFINITION)
        reached = (b.x1 * s <= 0.0) | (np.abs(b.x1) <= TIGHT_BAND)
        arrival = np.where(reached.any(axis=0), reached.argmax(axis=0) * T, np.nan)
        with np.errstate(invalid="ignore", divide="ignore"):
            r_nt, r_tf = st.time / lim.time_s, st.time / t_f
        curves.append(PenaltyCurve(law.name, law.note, st.time, arrival, r_nt, r_tf))
    return PenaltyResult(
        cfg.name,
        s,
        t_f,
        lim.steps,
        lim.time_s,
        tuple(curves),
        SETTLING_DEFINITION,
        steps * T,
        time.perf_counter() - t0,
        setting,
    )
