"""Collect every stage's results into the report's JSON."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from ptoverify.config import Config

from .parts import _summary
from .pool import _run_in_pool, default_jobs
from .settings import SKIPPABLE
from .stages import _SKIP_STAGE, _STAGE_FUNCTIONS, _run_stage

if TYPE_CHECKING:
    from .settings import Progress


# ------------------------------------------------------------------ collect
def collect(
    cfg: Config,
    progress: Progress | None = None,
    skip: tuple[str, ...] = (),
    figdir: Path | None = None,
    jobs: int | None = None,
) -> dict[str, Any]:
    """Compute every result of the report, each once, and draw its figures.

    The stages (:data:`STAGES`) are independent: with ``jobs`` > 1 they run in
    this process and ``jobs`` - 1 fresh Python processes (spawned: no fork of
    solver or BLAS state), the workers taking the longest first, each stage
    drawing its own figures into ``figdir``; with ``jobs`` = 1 they run here, one
    after the other.  Both give the same results.

    Parameters
    ----------
    cfg : Config
        Configuration.
    progress : callable, optional
        ``progress(stage, fraction)`` as each stage ends.
    skip : tuple of str
        Stages of :data:`SKIPPABLE` to leave out (their results are None).
    figdir : Path, optional
        Folder the figures are drawn into (none are drawn without it).
    jobs : int, optional
        Processes, this one included (default :func:`default_jobs`, at most one per
        stage).

    Returns
    -------
    dict
        JSON-able results, plus private keys: ``_records`` (the derivation
        records), ``_files`` (the figure files written), ``_timings`` (each
        stage's wall time [s]) and ``_jobs`` (the processes used);
        :func:`write_report` drops them from the JSON.

    Raises
    ------
    InputError
        An unknown ``skip`` stage or ``jobs`` < 1, a ``[robustness]`` box or a proof
        over its work limit (checked before any stage runs).
    """
    from ptoverify.errors import InputError
    from ptoverify.studies.checks import GATES, ROBUST_GATES, summarize

    bad = sorted(set(skip) - set(SKIPPABLE))
    if bad:
        raise InputError(f"--skip: unknown stage '{bad[0]}' (choose from {', '.join(SKIPPABLE)})")
    if jobs is not None and jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {jobs}")
    names = [n for n in _STAGE_FUNCTIONS if n not in {_SKIP_STAGE[s] for s in skip}]

    def check_work() -> None:  # the robustness box and the proofs are bounded: say so first
        if "robust" not in skip:
            from ptoverify.studies.robust.maps import RobustSettings, check_box_work

            from .settings import ROBUST_SETTINGS

            check_box_work(cfg, RobustSettings(**ROBUST_SETTINGS))
        from ptoverify.model.lawbox import law_spec
        from ptoverify.studies.prove.run import Resolution, check_provable

        for law in ("pto", "pd"):
            check_provable(cfg, Resolution(), law_spec(law, cfg))

    jobs = min(jobs or default_jobs(), len(names))
    done: dict[str, tuple[dict[str, Any], float]] = {}

    def finished(name: str, result: tuple[dict[str, Any], float]) -> None:
        done[name] = result
        if progress:
            progress(name, len(done) / len(names))

    if figdir is not None:  # every stage draws into it, whichever starts first
        figdir.mkdir(parents=True, exist_ok=True)
    if jobs == 1:
        check_work()
        for name in names:
            finished(name, _run_stage(name, cfg, figdir))
    else:  # the workers start while the work is checked; no stage starts before
        _run_in_pool(names, cfg, figdir, jobs, finished, before=check_work)

    out: dict[str, Any] = {"derivations": None, "robust": None, "tuning": None, "charts": None}
    files: list[Path] = []
    traces: list[str] = []
    checks = []
    for name in names:
        part = done[name][0]
        files += part.pop("_files", [])
        traces += part.pop("_traces", [])
        checks += part.pop("_checks", [])
        out.update(part)
    order = [*GATES, *ROBUST_GATES]
    checks.sort(key=lambda v: order.index(v.name))
    out["checks"] = [c.to_json() for c in checks]
    out["skipped"] = sorted(set(skip))
    out["summary"] = _summary(out, summarize(checks))
    for kind, group in (
        ("gates_nominal", [c for c in checks if c.name not in ROBUST_GATES]),
        ("gates_perturbed", [c for c in checks if c.name in ROBUST_GATES]),
    ):
        out["summary"][kind] = summarize(group)
    out["_files"] = files
    out["_traces"] = traces
    out["_timings"] = {name: done[name][1] for name in names}
    out["_jobs"] = jobs
    return out
