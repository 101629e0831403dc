"""The verification report: collect every result, render HTML + Markdown + JSON.

``collect(cfg)`` runs the derivations, the ground truth, the zone, the poles,
the closed-loop properties, the Section 6 claims, the sweep and the gates, and
returns one JSON-able dict (``results.json``).  ``build_sections`` turns it into
a list of sections made of neutral blocks (paragraphs, tables, figures, raw
fragments) that ``render_html`` and ``render_markdown`` print.  Every text that
reaches the HTML goes through :func:`html.escape`; equations are SymPy's MathML.

``write_report`` writes the folder atomically: everything goes to a temporary
sibling folder that is renamed into place only when complete.

Two runs give the same ``results.json`` except ``meta.generated``: wall-clock
timings are not part of the results.
"""

from __future__ import annotations

import datetime as _dt
import html
import json
import math
import platform
import subprocess
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ptoverify.config import Config

__all__ = [
    "collect",
    "build_sections",
    "render_html",
    "render_markdown",
    "write_report",
    "GROUND_TRUTH_STATES",
]

#: States of the ground-truth table [mm], [mm/s]: a step, moves with speed, on/near a
#: curve, beyond saturation, and near the origin.
GROUND_TRUTH_STATES: tuple[tuple[float, float], ...] = (
    (5.0, 0.0),
    (-5.0, 0.0),
    (50.0, 0.0),
    (-20.0, 150.0),
    (12.0, -250.0),
    (0.3, -80.0),
    (-40.0, -290.0),
    (0.05, 0.0),
)
CONVERGENCE_INTERVALS = (10, 20, 40, 80, 100, 200, 400)
_TIMING_KEYS = {"seconds", "timings", "solve_time_s", "elapsed_s", "wall_s"}

Progress = Callable[[str], None]


def _clean(obj: Any) -> Any:
    """JSON-safe copy: numpy to Python, NaN/inf to None, wall-clock timings dropped."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items() if k not in _TIMING_KEYS}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, np.generic):
        return _clean(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


# ------------------------------------------------------------------ collection
def _ground_truth(cfg: Config) -> dict[str, Any]:
    from ptoverify.groundtruth import verified_mintime
    from ptoverify.ocp import convergence_study

    p = cfg.plant
    scale = (p.position_range / 50.0, p.w_max / 300.0)
    states = [(x1 * scale[0], x2 * scale[1]) for x1, x2 in GROUND_TRUTH_STATES]
    rows = []
    for x1, x2 in states:
        gt = verified_mintime(x1, x2, cfg, intervals=100)  # checked a posteriori, as mintime
        mt, r2, rc, dm = gt.closed_form, gt.two_phase, gt.collocation, gt.discrete
        t_f = float(mt.t_f)
        rows.append(
            {
                "x0": [x1, x2],
                "analytic_s": t_f,
                "switch_time_s": float(mt.t_switch),
                "two_phase_s": r2.t_f if r2.success else None,
                "two_phase_status": r2.status,
                "two_phase_rel_error": abs(r2.t_f - t_f) / t_f if r2.success else None,
                "collocation_s": rc.t_f if rc.success else None,
                "collocation_status": rc.status,
                "collocation_rel_error": abs(rc.t_f - t_f) / t_f if rc.success else None,
                "collocation_resim_error_mm": rc.resim_error,
                "discrete_steps": dm.steps if dm.success else None,
                "discrete_status": dm.status,
                "discrete_s": dm.time_s if dm.success else None,
                "discrete_gap_samples": (dm.time_s - t_f) / p.T if dm.success else None,
            }
        )
    study = convergence_study(p, np.array(states[:4]), CONVERGENCE_INTERVALS)
    conv = {
        "intervals": list(CONVERGENCE_INTERVALS),
        "states": states[:4],
        "rel_error": study.rel_error,
        "order": study.order,
        "order_per_state": study.order_per_state,
        "success": study.success,
    }
    return {"states": rows, "convergence": conv, "_study": study}


def _poles(cfg: Config) -> dict[str, Any]:
    from ptoverify.poles import all_loop_poles, lyapunov_counterexample

    return {
        "loops": {k: v.to_json() for k, v in all_loop_poles(cfg).items()},
        "lyapunov_counterexample": lyapunov_counterexample(cfg),
    }


def _properties(cfg: Config) -> dict[str, Any]:
    from ptoverify.properties import all_properties

    return {k: v.to_json() for k, v in all_properties(cfg).items()}


def _environment(cfg: Config) -> dict[str, Any]:
    import casadi
    import control
    import scipy
    import sympy

    here = Path(__file__).resolve().parent
    try:
        commit = (
            subprocess.run(
                ["git", "rev-parse", "HEAD"],
                capture_output=True,
                text=True,
                cwd=here,
                timeout=5,
                check=False,
            ).stdout.strip()
            or None
        )
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            cwd=here,
            timeout=5,
            check=False,
        ).stdout.strip()
        if commit and dirty:
            commit += " (working tree modified)"
    except (OSError, subprocess.SubprocessError):
        commit = None
    ipopt_version = _ipopt_version(casadi)
    from ptoverify import __version__

    return {
        "python": platform.python_version(),
        "ptoverify": __version__,
        "casadi": casadi.__version__,
        "ipopt": ipopt_version,
        "sympy": sympy.__version__,
        "control": control.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "platform": platform.platform(),
        "git_commit": commit,
        "config": cfg.to_mapping(),
    }


def _ipopt_version(casadi) -> str:
    """IPOPT's version, read from the banner of a one-variable solve (bundled with CasADi)."""
    import io
    import re
    from contextlib import redirect_stdout

    x = casadi.SX.sym("x")
    buf = io.StringIO()
    try:
        with redirect_stdout(buf):
            casadi.nlpsol(
                "probe",
                "ipopt",
                {"x": x, "f": (x - 1) ** 2},
                {"ipopt.print_level": 5, "print_time": False},
            )(x0=0)
    except Exception:  # noqa: BLE001 - environment probe only
        return "unknown"
    m = re.search(r"Ipopt version (\S+)", buf.getvalue())
    return m.group(1).rstrip(",") if m else "bundled with casadi"


def collect(cfg: Config, progress: Progress | None = None) -> dict[str, Any]:
    """Compute every result of the report.

    Parameters
    ----------
    cfg : Config
        Configuration.
    progress : callable, optional
        ``progress(stage)`` before each stage.

    Returns
    -------
    dict
        JSON-able results, plus private keys (``_study``, ``_sweep``) with the
        objects the figures need; :func:`write_report` drops those from the JSON.
    """
    import derivations
    from ptoverify.checks import run_checks, summarize
    from ptoverify.claims import evaluate_claims
    from ptoverify.sweep import run_sweep
    from ptoverify.zones import zone_summary

    say = progress or (lambda stage: None)
    out: dict[str, Any] = {}
    say("derivations")
    p = cfg.plant
    plant = derivations.PlantNumbers(
        a=p.a, w_max=p.w_max, T=p.sample_time, d=cfg.pto.d, k1=cfg.pto.k1, k2=cfg.pto.k2
    )
    out["derivations"] = [r.to_json() for r in derivations.all_records(plant)]
    say("ground truth")
    out["ground_truth"] = _ground_truth(cfg)
    say("switching zone")
    out["zone"] = zone_summary(cfg)
    say("poles")
    out["poles"] = _poles(cfg)
    say("closed-loop properties")
    out["properties"] = _properties(cfg)
    say("Section 6 claims")
    out["claims"] = [c.to_json() for c in evaluate_claims(cfg)]
    say("suboptimality sweep")
    sweep = run_sweep(cfg)
    out["sweep"] = {
        "laws": {k: v.to_json() for k, v in sweep.laws.items()},
        "grid": list(sweep.x1.shape),
        "steps": sweep.steps,
        "velocity_band": sweep.velocity_band,
        "skipped": sweep.skipped,
        "settings": _settings_json(sweep.settings),
    }
    out["_sweep"] = sweep
    say("gates")
    checks = run_checks(cfg)
    out["checks"] = [c.to_json() for c in checks]
    out["summary"] = _summary(out, summarize(checks))
    out["environment"] = _environment(cfg)
    return out


def _settings_json(settings: Any) -> dict[str, Any]:
    from dataclasses import asdict, is_dataclass

    return asdict(settings) if is_dataclass(settings) else dict(vars(settings))


def _summary(out: dict[str, Any], gates: dict[str, Any]) -> dict[str, Any]:
    verdicts: dict[str, int] = {}
    for r in out["derivations"]:
        verdicts[r["verdict"]] = verdicts.get(r["verdict"], 0) + 1
    claims: dict[str, int] = {}
    for c in out["claims"]:
        claims[c["verdict"]] = claims.get(c["verdict"], 0) + 1
    return {
        "gates": gates,
        "derivation_verdicts": verdicts,
        "claim_verdicts": claims,
        "errata": [r["id"] for r in out["derivations"] if r["verdict"] == "erratum"],
        "claims_not_reproduced": [
            c["id"] for c in out["claims"] if c["verdict"] == "not reproduced"
        ],
        "claims_ambiguous": [c["id"] for c in out["claims"] if c["verdict"] == "ambiguous"],
        "printed_zone_valid": bool(out["zone"]["printed"]["valid"]),
        "corrected_zone_valid": bool(out["zone"]["corrected"]["valid"]),
        "corrected_omega0": out["zone"]["corrected"]["omega0"],
        "corrected_zone_margin_mm_s": out["zone"]["corrected"].get("margin_mm_s"),
    }


# ------------------------------------------------------------------ sections
@dataclass(frozen=True)
class Block:
    """A piece of a section: ``p`` text, ``table``, ``img``, or ``raw`` (html, md)."""

    kind: str
    text: str = ""
    headers: tuple[str, ...] = ()
    rows: tuple[tuple[str, ...], ...] = ()
    html: str = ""


def _fmt(v: Any, digits: int = 6) -> str:
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if not math.isfinite(v):
            return "n/a"
        return f"{v:.{digits}g}"
    if isinstance(v, (list, tuple)):
        return "(" + ", ".join(_fmt(x, digits) for x in v) + ")"
    return str(v)


def _table(headers: list[str], rows: list[list[Any]]) -> Block:
    return Block(
        "table", headers=tuple(headers), rows=tuple(tuple(_fmt(c) for c in r) for r in rows)
    )


def build_sections(
    res: dict[str, Any], figures: dict[str, str]
) -> list[tuple[str, str, list[Block]]]:
    """Turn the results into ordered sections ``(anchor, title, blocks)``.

    Parameters
    ----------
    res : dict
        Output of :func:`collect` (JSON part).
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of (str, str, list of Block)
    """
    from ptoverify import report_sections as rs

    return [
        ("summary", "1. Summary", rs.summary(res)),
        ("derivations", "2. Derivations: printed vs derived", rs.derivations(res)),
        ("ground-truth", "3. Ground truth: minimum time", rs.ground_truth(res, figures)),
        ("zone", "4. Switching-zone geometry", rs.zone(res, figures)),
        ("poles", "5. Poles and stability", rs.poles(res)),
        ("properties", "6. Closed-loop properties over the grid", rs.properties(res)),
        ("claims", "7. Section 6 claims", rs.claims(res, figures)),
        ("sweep", "8. Suboptimality maps", rs.sweep(res, figures)),
        ("environment", "9. Environment", rs.environment(res)),
    ]


_CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;
color:#222;line-height:1.4}table{border-collapse:collapse;margin:1em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.3em .5em;vertical-align:top;text-align:left}
th{background:#f0f0f0}.pass,.verified,.reproduced{background:#e6f4e6}
.fail,.erratum,.not-reproduced{background:#fbe3e3}.unverified,.ambiguous,.unchecked{background:#fff4d6}
img{max-width:100%;border:1px solid #ddd}figure{margin:1em 0}nav a{margin-right:1em}
math{font-size:1.05em}code{font-size:.85em}
table.derivations{table-layout:fixed;width:100%}table.derivations td{overflow-x:auto;
overflow-wrap:anywhere}table.derivations td:nth-child(-n+2){width:6em}"""

_STATUS_WORDS = {
    "pass",
    "fail",
    "unverified",
    "verified",
    "erratum",
    "unchecked",
    "definition",
    "reproduced",
    "not reproduced",
    "ambiguous",
}


def _html_block(b: Block) -> str:
    if b.kind == "p":
        return f"<p>{html.escape(b.text)}</p>"
    if b.kind == "raw":
        return b.html
    if b.kind == "img":
        return (
            f'<figure><img src="{html.escape(b.html)}" alt="{html.escape(b.text)}">'
            f"<figcaption>{html.escape(b.text)}</figcaption></figure>"
        )
    head = "".join(f"<th>{html.escape(h)}</th>" for h in b.headers)
    body = []
    for row in b.rows:
        cells = []
        for c in row:
            cls = f' class="{c.replace(" ", "-")}"' if c in _STATUS_WORDS else ""
            cells.append(f"<td{cls}>{html.escape(c)}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def render_html(sections: list[tuple[str, str, list[Block]]], title: str) -> str:
    """Render the sections as one offline HTML page (MathML, escaped text)."""
    nav = "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t, _ in sections)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1><nav>{nav}</nav>",
    ]
    for anchor, heading, blocks in sections:
        parts.append(f'<section id="{anchor}"><h2>{html.escape(heading)}</h2>')
        parts += [_html_block(b) for b in blocks]
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render_markdown(sections: list[tuple[str, str, list[Block]]], title: str) -> str:
    """Render the sections as Markdown (equations as plain text)."""
    lines = [f"# {title}", ""]
    for _anchor, heading, blocks in sections:
        lines += [f"## {heading}", ""]
        for b in blocks:
            if b.kind == "p":
                lines += [b.text, ""]
            elif b.kind == "raw":
                lines += [b.text, ""]
            elif b.kind == "img":
                lines += [f"![{b.text}]({b.html})", ""]
            else:
                lines.append("| " + " | ".join(_md_cell(h) for h in b.headers) + " |")
                lines.append("|" + "---|" * len(b.headers))
                lines += ["| " + " | ".join(_md_cell(c) for c in r) + " |" for r in b.rows]
                lines.append("")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ writing
def _figures(res: dict[str, Any], cfg: Config, figdir: Path) -> dict[str, str]:
    from ptoverify import plots

    files = plots.save_all(cfg, figdir)
    files += plots.save_sweep(res["_sweep"], figdir)
    files += plots.save_ground_truth(res["ground_truth"]["_study"], figdir)
    files += plots.save_zone_geometry(cfg, figdir)
    return {Path(f).stem: f"figures/{Path(f).name}" for f in files}


def write_report(
    cfg: Config, out: str | Path | None = None, progress: Progress | None = None
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
    res = collect(cfg, progress)  # nothing is written before this ends
    tmp = make_temp(out)
    try:
        if progress:
            progress("figures")
        figures = _figures(res, cfg, tmp / "figures")
        public = _clean({k: v for k, v in res.items() if not k.startswith("_")})
        public["ground_truth"] = _clean(
            {k: v for k, v in res["ground_truth"].items() if not k.startswith("_")}
        )
        public["meta"] = {
            "name": cfg.name,
            "figures": sorted(figures.values()),
            "generated": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        title = f"ptoverify verification report: {cfg.name}"
        sections = build_sections(public, figures)
        (tmp / "results.json").write_text(
            json.dumps(public, indent=1, sort_keys=True, allow_nan=False) + "\n"
        )
        (tmp / "index.html").write_text(render_html(sections, title))
        (tmp / "report.md").write_text(render_markdown(sections, title))
        publish(tmp, out, config_hash=cfg.digest(), name=cfg.name, default=default)
        tmp = None
    finally:
        discard(tmp)
    return out


#: The stages ``collect`` and ``write_report`` announce, in order.
STAGES = (
    "derivations",
    "ground truth",
    "switching zone",
    "poles",
    "closed-loop properties",
    "Section 6 claims",
    "suboptimality sweep",
    "gates",
    "figures",
)


def stderr_progress(quiet: bool) -> Progress | None:
    """Progress bar on stderr (:mod:`ptoverify.progress`) over :data:`STAGES`, or None."""
    from ptoverify.progress import stderr_bar

    return stderr_bar(quiet, STAGES)
