"""Robustness margins: how far a_true / a_design may stray from 1.

Two margins per law: the interval of a_true / a_design around 1 where the
sampled *linear* loop (PD, or the PTO's linear zone, eq. 34) stays stable
(eigenvalues, to 1e-12 relative), with and without a one-sample delay; and the
interval where no state of the maps' grid ends in a limit cycle (simulated
through :func:`ptoverify.studies.robust.maps.evaluate_probes`, every state).
:func:`most_robust` names the law with the widest linear interval.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ptoverify.config import Config
from ptoverify.errors import InputError
from ptoverify.model.baselines import linear_loop_gains
from ptoverify.model.laws import Law
from ptoverify.model.plant import zoh_matrices
from ptoverify.sim.lockstep import Ask
from ptoverify.sim.simulate import Mismatch
from ptoverify.studies.robust.maps import (
    LawSpec,
    Probe,
    RobustSettings,
    evaluate_probes,
    map_states,
    nominal_law,
)
from ptoverify.studies.robust.results import LawMargins, Margin, MostRobust

__all__ = [
    "MARGIN_RANGE",
    "linear_loop_radii",
    "linear_loop_margin",
    "no_limit_cycle_margin",
    "margin_job",
    "law_margins",
    "most_robust",
]

MARGIN_RANGE = (0.1, 10.0)  #: a_true / a_design searched for margins [-]
MARGIN_RTOL = 1e-12  #: relative accuracy of the linear margin endpoints (the contract asks 1e-6)


EDGE_CHUNK = 64  #: scan points of :func:`_edge` tested per stacked eigenvalue call


def _edge(
    stable: Callable[[NDArray], NDArray[np.bool_]],
    toward: float,
    *,
    grid: int = 400,
    rtol: float = MARGIN_RTOL,
) -> float | None:
    """Where ``stable`` first fails going from 1 toward ``toward`` (None: never in range).

    Scans a geometric grid of ``grid`` points from 1 to ``toward``
    (:data:`EDGE_CHUNK` points per call of ``stable``, which tests an array of
    ratios; the points beyond the first failure cannot change the edge), then
    narrows the first stable/unstable pair to ``rtol`` relative by multisection
    (:data:`EDGE_CHUNK` points per call).
    """
    pts = np.geomspace(1.0, toward, grid)
    for at in range(1, grid, EDGE_CHUNK):
        bad = np.flatnonzero(~stable(pts[at : at + EDGE_CHUNK]))
        if bad.size:
            j = at + int(bad[0])
            lo, hi = float(pts[j - 1]), float(pts[j])  # pts[0] is 1.0
            while abs(hi - lo) > rtol * min(abs(lo), abs(hi)):
                # multisection: EDGE_CHUNK geometric points inside (lo, hi) in one call;
                # the bracket becomes the last stable one before the first unstable one
                inner = np.geomspace(lo, hi, EDGE_CHUNK + 2)[1:-1]
                fails = np.flatnonzero(~stable(inner))
                i = int(fails[0]) if fails.size else inner.size
                new = (
                    float(inner[i - 1]) if i > 0 else lo,
                    float(inner[i]) if i < inner.size else hi,
                )
                if new == (lo, hi):  # the bracket is as narrow as floats allow
                    break
                lo, hi = new
            return lo
    return None


def linear_loop_radii(
    law: str, cfg: Config, a_ratio: ArrayLike, *, delay_samples: int = 0
) -> NDArray[np.float64]:
    """Spectral radius of the sampled linear loop at each a_true / a_design.

    The loop of :func:`linear_loop_margin`: ``Ad - Bd K`` of the ZOH plant of
    the true a (as :func:`ptoverify.model.poles.sampled_spectral_radius` forms it), or
    with a one-sample delay ``[[Ad, Bd], [-K, 0]]``; all ratios in one stacked
    eigenvalue call, each matrix as alone (LAPACK's ``geev`` per matrix).

    Parameters
    ----------
    law : str
        ``pd``, ``pto`` or ``pto-printed`` (a law with a linear loop).
    cfg : Config
        Nominal configuration (a [rad/s], T [s], the gains).
    a_ratio : array_like, shape (n,)
        a_true / a_design [-].
    delay_samples : int
        0 or 1 [samples].

    Returns
    -------
    ndarray, shape (n,)
        Largest |z| [-]; < 1 means stable.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> (linear_loop_radii("pd", paper_config(), [1.0, 10.0]) < 1.0).tolist()
    [True, False]
    """
    gains = linear_loop_gains(law, cfg)
    if gains is None or delay_samples not in (0, 1):
        raise InputError(
            f"linear_loop_radii: no linear loop for {law!r} with delay {delay_samples}"
        )
    ratios = np.atleast_1d(np.asarray(a_ratio, dtype=float))
    if ratios.size == 0:
        return np.empty(0)
    K = np.array([gains])  # noqa: N806
    Ad, Bd = zoh_matrices(cfg.plant.a * ratios, cfg.plant.sample_time)  # noqa: N806
    if delay_samples == 0:
        mats = Ad - Bd @ K
    else:  # [[Ad, Bd], [-K, 0]] for every ratio
        mats = np.zeros((ratios.size, 3, 3))
        mats[:, :2, :2], mats[:, :2, 2:] = Ad, Bd
        mats[:, 2, :2] = -K
    return np.abs(np.linalg.eigvals(mats)).max(axis=-1)


def linear_loop_margin(law: str, cfg: Config, *, delay_samples: int = 0) -> Margin:
    """Largest interval of a_true / a_design around 1 where the sampled linear loop is stable.

    The linear loop is PD's u = -kp x1 - kd x2 or the PTO's linear zone
    u = -k1 x1 - k2 x2 (eq. 34), unsaturated, on the ZOH plant with the true a
    and the design T; stable means spectral radius < 1 (:func:`linear_loop_radii`).
    With a one-sample computation delay the loop state is (x1, x2, u_{k-1}):
    z_{k+1} = [[Ad, Bd], [-K, 0]] z_k.

    Parameters
    ----------
    law : str
        Law name (TO has no linear loop).
    cfg : Config
        Nominal configuration.
    delay_samples : int
        0 or 1 [samples].

    Returns
    -------
    Margin
        ``interval`` (lo, hi) [-] with each endpoint the last stable ratio to 1e-12
        relative (None where stability reaches past the searched range [0.1, 10]),
        or None with a ``note`` when there is no linear loop or it is unstable at
        the design point.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> lo, hi = linear_loop_margin("pd", paper_config()).interval
    >>> lo is None and hi > 1.0
    True
    """
    if delay_samples not in (0, 1):
        raise InputError(f"linear_loop_margin: delay_samples must be 0 or 1, got {delay_samples}")
    if linear_loop_gains(law, cfg) is None:
        return Margin(None, "no linear loop")

    def stable(ratios: NDArray) -> NDArray[np.bool_]:
        return linear_loop_radii(law, cfg, ratios, delay_samples=delay_samples) < 1.0

    if not stable(np.array([1.0]))[0]:
        return Margin(None, "unstable at the design point")
    return Margin((_edge(stable, MARGIN_RANGE[0]), _edge(stable, MARGIN_RANGE[1])))


def no_limit_cycle_margin(
    law: LawSpec, cfg: Config, settings: RobustSettings | None = None, *, rtol: float = 1e-3
) -> Margin:
    """Interval of a_true / a_design around 1 with no limit cycle from any grid state.

    Saturation, delay and measurement stay nominal (ratio 1, no delay, exact
    measurement) so the interval isolates the bandwidth error.  The property is
    checked on the map's state grid (every state simulated); the endpoints come
    from a 40-point geometric scan of each side (stopping at its first failure)
    then a 16-section of the bracket to ``rtol`` relative (:func:`_edges`).

    Parameters
    ----------
    law : str or callable
        Law name, or a factory ``f(cfg) -> Law``.
    cfg : Config
        Nominal configuration.
    settings : RobustSettings, optional
        The state grid.
    rtol : float
        Relative accuracy of the endpoints [-].

    Returns
    -------
    Margin
        ``interval`` (lo, hi) [-] (None endpoints beyond [0.1, 10]), or None with a
        ``note`` when the nominal loop already has a limit cycle.
    """
    s = settings or RobustSettings()
    job = margin_job(nominal_law(law, cfg), cfg, s, rtol=rtol)
    return job(lambda probes: evaluate_probes(cfg, probes))


def law_margins(
    law: str, cfg: Config, settings: RobustSettings | None = None, *, limit_cycles: bool = True
) -> LawMargins:
    """Return the margins of one law at the configuration's gains, without maps or search.

    What :func:`ptoverify.studies.robust.run_robust` records per law
    (:func:`linear_loop_margin` without and with a one-sample delay, and
    :func:`no_limit_cycle_margin`), for a law the study does not map: the
    report's rows for the baselines.

    Parameters
    ----------
    law : str
        Law name.
    cfg : Config
        Nominal configuration (its gains are the law's).
    settings : RobustSettings, optional
        The state grid of the no-limit-cycle margin.
    limit_cycles : bool
        Also compute the no-limit-cycle margin (simulated); False: the two
        eigenvalue margins only.

    Returns
    -------
    LawMargins
        ``no_limit_cycle`` None when not computed.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> m = law_margins("cascade-p", paper_config(), limit_cycles=False)
    >>> m.linear.interval is not None, m.no_limit_cycle is None
    (True, True)
    """
    nlc = no_limit_cycle_margin(law, cfg, settings) if limit_cycles else None
    return LawMargins(
        linear_loop_margin(law, cfg), linear_loop_margin(law, cfg, delay_samples=1), nlc
    )


SCAN_CHUNK = 8  #: scan points of each side tested per step of :func:`_edges`
MARGIN_PROBE_RATIOS = 16  #: ratios per probe of a margin scan


def margin_job(
    fn: Law, cfg: Config, s: RobustSettings, *, rtol: float = 1e-3
) -> Callable[[Callable[[list[Probe]], list[dict[str, NDArray]]]], Margin]:
    """:func:`no_limit_cycle_margin` as a job of :func:`ptoverify.sim.lockstep.run_together`.

    Parameters
    ----------
    fn : Law
        The nominal law.
    cfg : Config
        Nominal configuration.
    s : RobustSettings
        The state grid.
    rtol : float
        Relative accuracy of the endpoints [-].

    Returns
    -------
    callable
        ``job(ev) -> margin``, ``ev(probes)`` measuring probes
        (:func:`ptoverify.studies.robust.maps.evaluate_probes`).
    """
    x1, x2 = map_states(cfg, s)
    n = x1.size

    def job(ev: Callable[[list[Probe]], list[dict[str, NDArray]]]) -> Margin:
        def clean(ratios: NDArray) -> NDArray[np.bool_]:
            """No limit cycle from any grid state, for each ratio."""
            step = MARGIN_PROBE_RATIOS
            parts = [ratios[i : i + step] for i in range(0, ratios.size, step)]
            probes = [
                Probe(
                    Ask(
                        fn,
                        np.tile(x1, r.size),
                        np.tile(x2, r.size),
                        Mismatch(a_ratio=np.repeat(r, n)),
                        stage="margins",
                    ),
                    settle=False,
                    cycles_only=True,
                )
                for r in parts
            ]
            lc = [p["limit_cycle_mm"].reshape(-1, n) for p in ev(probes)]
            return ~(np.concatenate(lc) > 0).any(axis=1)

        if not clean(np.array([1.0]))[0]:
            return Margin(None, "limit cycles nominally")
        return Margin(_edges(clean, grid=40, rtol=rtol))

    return job


def _edges(
    holds: Callable[[NDArray], NDArray[np.bool_]],
    *,
    grid: int,
    rtol: float,
    split: int = 16,
    chunk: int = SCAN_CHUNK,
) -> tuple[float | None, float | None]:
    """Both edges around 1 within :data:`MARGIN_RANGE` where ``holds`` stays true.

    ``holds(ratios)`` says whether the property holds at each ratio.  The same
    edge as :func:`_edge`: the first failing point of a ``grid``-point geometric
    scan from 1 outward, then the bracket narrowed to ``rtol``.  The scan
    advances both sides ``chunk`` points at a time and stops a side at its first
    failure; each narrowing round tests ``split - 1`` interior points of every
    bracket at once (the bracket shrinks ``split``-fold per round).
    """
    sides = [np.geomspace(1.0, end, grid)[1:] for end in MARGIN_RANGE]
    bad_at: list[int | None] = [None, None]
    at = 0
    while True:
        todo = [i for i in (0, 1) if bad_at[i] is None and at < sides[i].size]
        if not todo:
            break
        chunks = [sides[i][at : at + chunk] for i in todo]
        flags = holds(np.concatenate(chunks))
        pos = 0
        for i, c in zip(todo, chunks, strict=True):
            bad = np.flatnonzero(~flags[pos : pos + c.size])
            pos += c.size
            if bad.size:
                bad_at[i] = at + int(bad[0])
        at += chunk
    brackets: list[list[float] | None] = []
    for pts, j in zip(sides, bad_at, strict=True):
        brackets.append(
            None if j is None else [1.0 if j == 0 else float(pts[j - 1]), float(pts[j])]
        )
    live = [b for b in brackets if b is not None]
    while any(abs(b[1] - b[0]) > rtol * min(abs(b[0]), abs(b[1])) for b in live):
        # geometric interior points of each bracket, from its ok end to its failing end
        inner = [b[0] * (b[1] / b[0]) ** (np.arange(1, split) / split) for b in live]
        f = holds(np.concatenate(inner))
        for k, b in enumerate(live):
            fk = f[k * (split - 1) : (k + 1) * (split - 1)]
            bad = np.flatnonzero(~fk)
            pts = inner[k]
            if bad.size == 0:
                b[0] = float(pts[-1])
            else:
                j = int(bad[0])
                b[0], b[1] = (b[0] if j == 0 else float(pts[j - 1])), float(pts[j])
    lo, hi = (None if b is None else b[0] for b in brackets)
    return lo, hi


def most_robust(margins: dict[str, LawMargins]) -> MostRobust:
    """Which law's linear loop tolerates the widest bandwidth error (log-width of the interval).

    Parameters
    ----------
    margins : dict
        Law -> its margins (only ``linear`` is read).

    Returns
    -------
    MostRobust
        ``law`` and ``log_width`` per law (ln(hi/lo) [-], endpoints beyond the
        searched range taken at the range's ends); ``law`` None when no law has
        a margin.

    Examples
    --------
    >>> m = lambda iv: LawMargins(Margin(iv), Margin(None))
    >>> most_robust({"pd": m((0.5, 2.0)), "to": m(None)}).law
    'pd'
    """
    widths: dict[str, float] = {}
    for law, m in margins.items():
        iv = m.linear.interval
        if iv is None:
            continue
        lo = iv[0] if iv[0] is not None else MARGIN_RANGE[0]
        hi = iv[1] if iv[1] is not None else MARGIN_RANGE[1]
        widths[law] = math.log(hi / lo)
    if not widths:
        return MostRobust(None, {})
    return MostRobust(max(widths, key=widths.get), widths)
