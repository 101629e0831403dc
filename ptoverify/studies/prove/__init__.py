"""Proofs over the continuum of initial states (``ptoverify prove``).

- :mod:`.target`: the certified target ellipse x' P x <= c (arb).
- :mod:`.graph`: the graded cell grid, macro-step images, longest-path bounds.
- :mod:`.stride`: no stride-over per cell (strict, relaxed), certified counterexamples.
- :mod:`.run`: :func:`prove_law`, one law's properties.
- :mod:`.work`: the proof's work, estimated from the configuration and checked up front.
- :mod:`.certificate`: the certificate's arrays and its independent check.
- :func:`run_prove`: every law, in-process or on a dask cluster; :class:`ProveRun`.
- :func:`nominal_proof`: the corrected PTO's nominal proof, memoized for the gates.
- :func:`interval_proof`: the same over the ``[robustness]`` box's a_ratio (``check --robust``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.lawbox import law_spec, require_enclosure
from ptoverify.model.memo import memo
from ptoverify.studies.prove.run import LawProof, Resolution, check_provable, prove_law
from ptoverify.studies.prove.work import sub_intervals

__all__ = [
    "ProveRun",
    "run_prove",
    "nominal_proof",
    "parse_a_interval",
    "PROVE_LAWS",
    "PIECE_RATIO",
    "DASK_BLOCK_CELLS",
]

#: Largest ratio a_hi / a_lo of a default sub-interval of ``--a-interval``: at the paper's
#: values 6 pieces of [0.8, 1.25] give the bound of 23 pieces of 2 % (92 samples) in 14 s
#: instead of 40 s (the coefficients' enclosures are tight in a, see model.zohmaps).
PIECE_RATIO = 1.08

#: Cells per job on a dask cluster: the paper's default grid (44,880 cells) is one block per
#: sub-interval (on the shared 2-core machine, 12 jobs of half a grid took longer than 6
#: whole ones); fine grids of millions of cells are split.
DASK_BLOCK_CELLS = 100_000

#: Laws ``prove`` covers, the reference PTO first.
PROVE_LAWS = ("pto", "pto-printed", "pd", "to")


@dataclass(frozen=True)
class ProveRun:
    """The result of ``ptoverify prove``.

    Attributes
    ----------
    proofs : tuple of LawProof
        One per law, the reference PTO first.
    a_interval : tuple of float
        The plant's a covered [rad/s].
    excursion : float
        Margin allowed beyond the envelope [mm].
    backend : str
        ``in-process`` or the dask scheduler used.
    elapsed_s : float
        Wall time of the run [s].
    """

    proofs: tuple
    a_interval: tuple
    excursion: float
    backend: str
    elapsed_s: float

    def to_json(self) -> dict:
        """Return the ``prove --json`` object: the reference law's keys, then every law's."""
        ref = self.proofs[0].to_json()
        ref["timings_s"] = dict(ref["timings_s"], total=round(self.elapsed_s, 3))
        return {
            **ref,
            "excursion_mm": self.excursion,
            "backend": self.backend,
            "laws": {p.law: p.to_json() for p in self.proofs},
        }


def parse_a_interval(text: str, a: float) -> tuple[float, float]:
    """Parse ``--a-interval LO,HI`` (ratios to the nominal a) into rad/s.

    Parameters
    ----------
    text : str
        ``LO,HI`` with 0 < LO <= 1 <= HI <= 10 (ratios a_true / a_design).
    a : float
        Nominal bandwidth [rad/s].

    Returns
    -------
    tuple of float
        (a_lo, a_hi) [rad/s].

    Examples
    --------
    >>> parse_a_interval("0.8,1.25", 100.0)
    (80.0, 125.0)
    """
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--a-interval must be LO,HI (two numbers), got {text!r}") from None
    if not (0.0 < lo <= 1.0 <= hi <= 10.0):
        raise InputError(f"--a-interval needs 0 < LO <= 1 <= HI <= 10, got {text!r}")
    return lo * a, hi * a


def default_pieces(a_interval: tuple[float, float] | None) -> int:
    """Return the default number of sub-intervals of an a-interval.

    Parameters
    ----------
    a_interval : tuple of float or None
        (a_lo, a_hi) [rad/s]; None: the nominal a.

    Returns
    -------
    int
        The fewest geometric pieces each at most :data:`PIECE_RATIO` wide (1 for a point).

    Examples
    --------
    >>> default_pieces((80.0, 125.0))
    6
    """
    if a_interval is None or not a_interval[1] > a_interval[0]:
        return 1
    return max(1, math.ceil(math.log(a_interval[1] / a_interval[0]) / math.log(PIECE_RATIO)))


def _dask_mapper(address: str):
    """Return a ``map``-like callable running jobs on a dask.distributed cluster."""
    from ptoverify.studies.cluster import check_dask_address, dask_map

    check_dask_address(address)

    def run(fn, jobs):
        return dask_map(address, fn, list(jobs))

    return run


def run_prove(
    cfg: Config,
    *,
    laws: tuple[str, ...] = PROVE_LAWS,
    a_interval: tuple[float, float] | None = None,
    pieces: int | None = None,
    excursion: float = 0.0,
    dask: str | None = None,
    res: Resolution | None = None,
    n_random: int = 20_000,
    block_cells: int | None = None,
) -> ProveRun:
    """Prove every law's properties over the envelope.

    Parameters
    ----------
    cfg : Config
        Configuration.
    laws : tuple of str
        Laws, the reference first (each of
        :data:`ptoverify.model.lawbox.ENCLOSED_LAWS`; ``ptos`` is InputError).
    a_interval : tuple of float, optional
        The plant's a [rad/s]; default the nominal a.
    pieces : int, optional
        Sub-intervals of the a-interval, geometric (default: each at most
        :data:`PIECE_RATIO` wide).
    excursion : float
        Margin beyond the envelope [mm], 0 <= excursion <= position_range.
    dask : str, optional
        Scheduler address or ``local``: the jobs (each a sub-interval and a block
        of cells) run there; the results equal the in-process run's exactly.
    res : Resolution, optional
        Grid settings.
    n_random : int
        Seeded random states simulated per law besides the cell centres.
    block_cells : int, optional
        Cells per job (default: all in-process, :data:`DASK_BLOCK_CELLS` on a cluster).

    Returns
    -------
    ProveRun
        The proofs.
    """
    if not 0.0 <= excursion <= cfg.plant.position_range:
        raise InputError(f"--excursion must be in [0, position_range], got {excursion:g}")
    for name in laws:  # before any work: a law without a certified enclosure is bad input
        require_enclosure(name)
    t0 = time.perf_counter()
    n = pieces or default_pieces(a_interval)
    res = res or Resolution()
    a_lo, a_hi = a_interval or (cfg.plant.a, cfg.plant.a)
    for name in laws:  # every law's work within the limits before any proof runs
        check_provable(cfg, res, law_spec(name, cfg), sub_intervals(a_lo, a_hi, n), excursion)
    mapper = _dask_mapper(dask) if dask else map
    proofs = tuple(
        prove_law(
            cfg,
            name,
            a_interval=a_interval,
            pieces=n,
            excursion=excursion,
            res=res,
            n_random=n_random,
            mapper=mapper,
            block_cells=block_cells or (DASK_BLOCK_CELLS if dask else None),
        )
        for name in laws
    )
    backend = f"dask:{dask}" if dask else "in-process"
    return ProveRun(proofs, (a_lo, a_hi), excursion, backend, time.perf_counter() - t0)


@memo(maxsize=4)
def nominal_proof(cfg: Config) -> LawProof:
    """Return the corrected PTO's nominal proof (memoized: the gates share it).

    Parameters
    ----------
    cfg : Config
        Configuration.

    Returns
    -------
    LawProof
        The proof of ``pto`` for the nominal a.
    """
    return prove_law(cfg, "pto", n_random=5_000)


@memo(maxsize=4)
def interval_proof(cfg: Config) -> LawProof:
    """Return the corrected PTO's proof over the ``[robustness]`` box's a_ratio (memoized).

    Parameters
    ----------
    cfg : Config
        Configuration; the plant's a is any constant in a_ratio x its a.

    Returns
    -------
    LawProof
        The proof of ``pto`` for the a-interval, :func:`default_pieces` sub-intervals.
    """
    lo, hi = cfg.robustness.a_ratio
    a_interval = (lo * cfg.plant.a, hi * cfg.plant.a)
    return prove_law(
        cfg, "pto", a_interval=a_interval, pieces=default_pieces(a_interval), n_random=5_000
    )
