"""Write the report folder: sections, HTML, Markdown, results.json, traces."""

from __future__ import annotations

import datetime as _dt
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ptoverify.config import Config
from ptoverify.report.render import Section, render_html, render_markdown
from ptoverify.report.results import TOP_LEVEL, Results, wrap

from .run import collect
from .settings import PAPER_TITLE, _clean
from .stages import STAGES

if TYPE_CHECKING:
    from .settings import Progress


def downloads_intro(traces: list[str]) -> tuple[str, str]:
    """Return the paragraph under the title and the list of CSV traces to download.

    Parameters
    ----------
    traces : list of str
        The CSV traces written (relative paths).

    Returns
    -------
    intro, downloads : str
        Markdown-style text with links (the HTML renders them as links too): one
        line under the title (``results.json``); what the report verifies and the
        CSV traces, under the table of contents.
    """
    from ptoverify.report.words import law_name

    def words(stem: str) -> str:  # "pto-printed_ramp" -> "PTO as printed, ramp"
        law, _, signal = stem.rpartition("_")
        return f"{law_name(law)}, {signal}" if law else stem

    links = "; ".join(f"[{words(Path(t).stem)}]({t})" for t in traces)
    intro = (
        "Every number below is computed ([results.json](results.json) holds them all); the "
        "paper's values appear only as claims."
    )
    about = (
        f'This report verifies the PTO law of the paper "{PAPER_TITLE}" against its own '
        "equations, exact minimum times and simulation."
    )
    return intro, about + (f" CSV traces (t, r, x1, x2, e, u, region): {links}." if links else "")


def render_pages(sections: list, title: str, traces: list[str]) -> tuple[str, str]:
    """Render the report's HTML page and Markdown: the verdict first, then the contents.

    Parameters
    ----------
    sections : list of (str, str, list of Block)
        :func:`build_sections` (the verdict first).
    title : str
        Page title.
    traces : list of str
        The CSV traces written (relative paths), listed under the contents.

    Returns
    -------
    html, markdown : str
        ``index.html`` and ``report.md``.
    """
    intro, downloads = downloads_intro(traces)
    return (
        render_html(sections, title, intro, lead=1, downloads=downloads),
        render_markdown(sections, title, intro, lead=1, downloads=downloads),
    )


def results_view(public: dict[str, Any]) -> Results:
    """Return the strict view of ``results.json`` that the sections read.

    Parameters
    ----------
    public : dict
        The JSON object written to ``results.json``.

    Returns
    -------
    Results
        Read-only; a missing field raises, never renders as a blank.

    Raises
    ------
    ValueError
        When a key of :data:`ptoverify.report.results.TOP_LEVEL` is missing or an
        unknown one is present (a bug of the report, not bad input).
    """
    missing = [k for k in TOP_LEVEL if k not in public]
    extra = sorted(set(public) - set(TOP_LEVEL))
    if missing or extra:
        raise ValueError(f"results.json keys: missing {missing}, unexpected {extra}")
    return wrap(public)


def build_sections(
    res: Results,
    figures: dict[str, str],
    records: list | None = None,
    rendered: dict | None = None,
) -> list[Section]:
    """Turn the results into ordered sections ``(anchor, title, blocks)``.

    Parameters
    ----------
    res : Results
        The strict view of ``results.json`` (:func:`results_view`).
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    records : list of derivations.EquationRecord, optional
        The derivation records :func:`collect` made (``res["_records"]``); when
        None they are taken from ``res``.
    rendered : dict, optional
        :func:`ptoverify.report.sections.render_records` of them
        (``res["_rendered"]``), when already computed.

    Returns
    -------
    list of (str, str, list of Block)
    """
    from ptoverify.report import sections as rs

    recs = records if records is not None else res["_records"]
    parts = [
        ("verdict", "Verdict: the paper's standing", rs.verdict(res)),
        ("findings", "Headline findings", rs.headline(res, figures)),
        ("summary", "Summary: gates, errata, claims", rs.summary(res)),
        ("errata", "Errata in the paper", rs.errata(res, recs, rendered)),
        ("derivations", "Derivations: printed vs derived", rs.derivations(res, recs, rendered)),
        ("ground-truth", "Ground truth: minimum time", rs.ground_truth(res, figures)),
        ("zone", "Switching-zone geometry", rs.zone(res, figures)),
        ("poles", "Poles and stability", rs.poles(res)),
        ("properties", "Closed-loop properties over the grid", rs.properties(res)),
        ("claims", "Section 6 claims", rs.claims(res, figures)),
        ("sweep", "Suboptimality maps", rs.sweep(res, figures)),
        ("proofs", "Proved over the continuum", rs.proofs(res, figures)),
        ("robustness", "Robustness under model mismatch", rs.robustness(res, figures)),
        ("tuning", "Can any tuning reproduce the paper?", rs.tuning(res, figures)),
        ("charts", "Penalty by move size, and the design space", rs.charts(res, figures)),
        ("environment", "Environment", rs.environment(res)),
    ]
    return [(a, t if i < 2 else f"{i - 1}. {t}", b) for i, (a, t, b) in enumerate(parts)]


# ------------------------------------------------------------------ writing
def write_report(
    cfg: Config,
    out: str | Path | None = None,
    progress: Progress | None = None,
    skip: tuple[str, ...] = (),
    timings: dict[str, float] | None = None,
    jobs: int | None = None,
) -> Path:
    """Compute and write the report folder atomically.

    Parameters
    ----------
    cfg : Config
        Configuration.
    out : str or Path, optional
        Folder; default ``reports/<config name>``, which is never replaced by
        the report of another configuration (see :mod:`ptoverify.outdir`).
    progress : callable, optional
        Called with each stage's name.
    skip : tuple of str
        Stages of :data:`SKIPPABLE` to leave out (a quick report).
    timings : dict, optional
        Filled with the wall time of each stage [s] (its figures included).
    jobs : int, optional
        Worker processes (:func:`collect`; default :func:`default_jobs`).

    Returns
    -------
    Path
        The folder written (``index.html``, ``report.md``, ``results.json``,
        ``figures/*.png``).

    Raises
    ------
    InputError
        When the folder cannot be written.
    """
    from ptoverify.outdir import check_target, discard, make_temp, publish

    default = out is None
    out = check_target(
        Path("reports") / cfg.name if default else out, config_hash=cfg.digest(), default=default
    )
    tmp = make_temp(out)  # figures are drawn into it; it is renamed into place when complete
    try:
        res = collect(cfg, progress, skip, figdir=tmp / "figures", jobs=jobs)
        figures = {Path(f).stem: f"figures/{Path(f).name}" for f in res["_files"]}
        if timings is not None:
            timings.update(res["_timings"])
        public = _clean({k: v for k, v in res.items() if not k.startswith("_")})
        public["ground_truth"] = _clean(
            {k: v for k, v in res["ground_truth"].items() if not k.startswith("_")}
        )
        public["meta"] = {
            "name": cfg.name,
            "paper": PAPER_TITLE,
            "figures": sorted(figures.values()),
            "traces": res["_traces"],
            "jobs": res["_jobs"],  # processes the stages ran in
            "generated": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        title = f'Verification of "{PAPER_TITLE}" (configuration {cfg.name!r})'
        sections = build_sections(
            results_view(public), figures, res["_records"], res.get("_rendered")
        )
        (tmp / "results.json").write_text(
            json.dumps(public, indent=1, sort_keys=True, allow_nan=False) + "\n"
        )
        page, md = render_pages(sections, title, res["_traces"])
        (tmp / "index.html").write_text(page)
        (tmp / "report.md").write_text(md)
        publish(tmp, out, config_hash=cfg.digest(), name=cfg.name, default=default)
        tmp = None
    finally:
        discard(tmp)
    return out


def stderr_progress(quiet: bool) -> Progress | None:
    """Progress bar on stderr (:mod:`ptoverify.progress`) over :data:`STAGES`, or None."""
    from ptoverify.progress import stderr_bar

    return stderr_bar(quiet, STAGES)
