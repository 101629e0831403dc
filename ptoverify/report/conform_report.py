"""``conform --report DIR``: the conformance of a user's law as a report for a review.

The folder holds ``index.html`` (offline: no script, no CDN; images are local
files), ``report.md``, ``results.json`` (every figure at full precision: the
``conform --json`` object under ``conform``, the evidence under ``evidence``)
and ``figures/*.png``.  It is validated before anything is computed
(:func:`check_report_target`), written into a temporary folder and published
with one rename (:mod:`ptoverify.outdir`), so it is never half-written.

What it shows, in order: the verdict with the first failing property and
state, the precision and perturbations judged, and a warning when the
reference law itself limit-cycles with a one-sample delay; every property with
measured / limit / unit and its first failing state; the pass limits and why
(configurable under ``[conform]``); the agreement per reference region; the
map of |u - u_ref| with the region boundaries
(:mod:`ptoverify.conform.evidence`); the closed-loop properties and settling /
(N* T) (settling definition named); the closed loops under perturbation next
to the reference's; the step, ramp and sine responses next to the reference,
with the metrics that mean something for each signal (a ``--table`` has none,
and the report says so); every failure.

Numbers carry their unit and 4 significant digits; states that reproduce a
failure carry 10 (a state 5e-8 mm from |x1| = d must be told apart from d).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ptoverify.config import Config
from ptoverify.conform.closedloop import SETTLING
from ptoverify.conform.evidence import ConformEvidence
from ptoverify.conform.gate import ConformResult
from ptoverify.errors import InputError
from ptoverify.report.conform_conditions import (
    limits,
    perturbation_text,
    perturbed,
    precision_text,
    quantity,
    state,
)
from ptoverify.report.render import Block, Section, render_html, render_markdown
from ptoverify.sim.settling import DEFINITIONS

__all__ = ["check_report_target", "write_conform_report", "build_sections", "quantity", "state"]

#: The settling definition of ``ptoverify report``'s suboptimality maps (the sweep's box).
SWEEP_SETTLING = DEFINITIONS["box-0p01mm"]

#: display name of a Verdict unit
_UNITS = {"1": "count", "": "", "mm/s": "mm/s", "samples": "samples"}
_STATUS = {"pass": "pass", "fail": "fail", "unverified": "unverified", "not_run": "not run"}
_METRICS = (
    ("overshoot_mm", "overshoot", "mm"),
    ("rise_time_s", "rise time", "s"),
    ("settling_2pct_s", "settling (2 % band)", "s"),
    ("settling_0p01mm_s", "settling (0.01 mm band)", "s"),
    ("phase_delay_deg", "phase delay", "deg"),
)


def check_report_target(out: str | Path, cfg: Config) -> Path:
    """Validate ``--report DIR`` before computing (:func:`ptoverify.outdir.check_target`).

    Parameters
    ----------
    out : str or Path
        The report folder.
    cfg : Config
        Configuration (its hash is recorded in the folder's marker).

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    InputError
        As :func:`~ptoverify.outdir.check_target`, naming ``--report``.
    """
    from ptoverify.outdir import check_target

    try:
        return check_target(out, config_hash=cfg.digest())
    except InputError as exc:
        raise InputError(str(exc).replace("--out", "--report")) from None


# ------------------------------------------------------------------ sections
def _table(headers: list[str], rows: list[list[str]]) -> Block:
    return Block("table", headers=tuple(headers), rows=tuple(tuple(r) for r in rows))


def _p(text: str) -> Block:
    return Block("p", text=text)


def _first_failures(r: ConformResult) -> dict[str, dict]:
    """Return the first failure of each property (failures come in evaluation order)."""
    out: dict[str, dict] = {}
    for f in r.failures:
        out.setdefault(f["property"], f)
    return out


def _verdict(r: ConformResult, ev: ConformEvidence, cfg: Config) -> list[Block]:
    a = r.agreement
    if r.conforms:
        head = (
            f"CONFORMS: {r.target} agrees with the reference "
            + (
                "PTO law (eq. 35, corrected omega0)"
                if r.reference == "pto"
                else f"{r.reference} law (a baseline, with the configuration's gains)"
            )
            + f" and passes every property ({len(r.properties)} of {len(r.properties)})."
        )
    else:
        failing = r.failed_properties() or [
            n for n, v in r.properties.items() if v.status != "pass"
        ]
        head = f"DOES NOT CONFORM: {r.target} fails {', '.join(failing)}."
    blocks = [_p(head)]
    fails = r.reference_fails
    if fails:
        blocks.append(
            _p(
                f"WARNING: under the perturbations judged, the reference law itself fails "
                f"{'; '.join(fails)}. Your law was judged relative to it (no worse by more "
                "than the margins below), so conforming there means no worse than a "
                "reference that fails, not that the loop is sound."
            )
        )
    rd = ev.reference_delay
    if rd is not None and rd["cycling"]:
        blocks.append(
            _p(
                f"WARNING: the reference law itself limit-cycles or does not settle with a "
                f"{rd['delay_samples']}-sample computation delay from {rd['cycling']} of "
                f"{rd['states']} initial states (the closed-loop sweep of this gate). "
                "Conformance to it does not make a law delay-tolerant: compensate the delay, "
                f"and run conform --delay {rd['delay_samples']} to compare under it."
            )
        )
    if r.failures:
        f = r.failures[0]
        where = "" if f["state"] is None else f" at {state(f['state'])}"
        blocks.append(_p(f"First failing property: {f['property']}{where}: {f['detail']}"))
    rows = [
        ["law", r.target],
        ["reference law", r.reference],
        ["evaluated as", f"{r.mode} ({r.mode_reason})" if r.mode_reason else r.mode],
        ["precision", precision_text(r.precision)],
        ["perturbation", perturbation_text(r)],
        ["configuration", cfg.name],
        [
            "plant",
            f"a = {quantity(cfg.plant.a, 'rad/s')}, w_max = {quantity(cfg.plant.w_max, 'mm/s')}, "
            f"T = {quantity(cfg.plant.sample_time, 's')}, d = {quantity(cfg.pto.d, 'mm')}",
        ],
    ]
    if "tolerance_mm_s" in a:
        rows.append(
            [
                "agreement tolerance",
                f"{quantity(a['tolerance_mm_s'], 'mm/s')} ({quantity(a['rtol'])} x w_max)",
            ]
        )
        rows.append(["largest |u - u_ref|", quantity(a["max_abs_du"], "mm/s")])
        rows.append(
            ["states judged", f"{a['points']} states ({a['excluded']} curve ties excluded)"]
        )
    rows.append(["run time", quantity(r.timings_s.get("total"), "s")])
    blocks.append(_table(["item", "value"], rows))
    return blocks


def _properties(r: ConformResult) -> list[Block]:
    first = _first_failures(r)
    rows = []
    for name, v in r.properties.items():
        unit = _UNITS.get(v.unit, v.unit)
        f = first.get(name)
        rows.append(
            [
                name,
                _STATUS.get(v.status, v.status),
                quantity(v.measured, unit),
                f"{v.comparison} {quantity(v.limit, unit)}" if v.limit is not None else "n/a",
                unit or "dimensionless",
                "none" if f is None else state(f["state"]),
                v.detail,
            ]
        )
    blocks = [
        _p(
            "Each property passes only when measured and limit compare as stated; "
            "unverified and not run fail closed. 'count' is a number of states or samples."
        ),
        _table(
            ["property", "status", "measured", "limit", "unit", "first failing state", "what"],
            rows,
        ),
    ]
    return blocks


def _agreement(r: ConformResult) -> list[Block]:
    a = r.agreement
    if "regions" not in a:
        return [_p(f"Agreement: {a.get('detail', 'not run')}.")]
    rows = []
    for name, e in a["regions"].items():
        rows.append(
            [
                name,
                "pass" if e["pass"] else "fail",
                str(e["points"]),
                str(e["excluded"]),
                str(e["violations"]),
                quantity(e["max_abs_du"], "mm/s"),
                state(e["state"]),
            ]
        )
    src = ", ".join(f"{k} {v}" for k, v in a.get("sources", {}).items())
    return [
        _p(
            f"|u - u_ref| <= {quantity(a['tolerance_mm_s'], 'mm/s')} at every judged state, "
            f"per region of the reference law; states by source: {src}. States within "
            f"{quantity(a['tie_band_mm_s'], 'mm/s')} of a switching curve (outside |x1| < d) "
            "are ties and excluded."
        ),
        _table(
            [
                "region",
                "status",
                "states",
                "excluded (ties)",
                "violations",
                "largest |u - u_ref|",
                "at",
            ],
            rows,
        ),
    ]


def _map(r: ConformResult, ev: ConformEvidence, figures: dict[str, str]) -> list[Block]:
    if ev.judged == 0:
        why = r.agreement.get("detail", "no state was judged")
        return [_p(f"No map of |u - u_ref|: no state was judged ({why}).")]
    b = ev.boundaries
    zone = (
        f"l1*, l2* (eqs. 13, 14, omega0 = {quantity(b.omega0, 'mm/s')})"
        if b.omega0 is not None
        else "no switching zone (omega0 undefined)"
    )
    env, zoom = ev.maps
    blocks = [
        _p(
            f"Largest |u_user - u_reference| [mm/s] per cell ({env.du_max.shape[1]} x "
            f"{env.du_max.shape[0]} cells) over {ev.judged} judged states ({ev.excluded} curve "
            f"ties excluded), logarithmic colours (black: no difference); grey cells hold no judged state. Left: the "
            f"envelope; right: |x1| <= {quantity(b.zoom_x1, 'mm')}, where the regions meet. "
            f"Drawn: l1, l2 (eqs. 9, 11), {zone}, and the linear zone |x1| < d = "
            f"{quantity(b.d, 'mm')}. Largest cell: {quantity(env.max, 'mm/s')}; "
            f"{env.outside} judged states lie outside the envelope (largest |u - u_ref| there "
            f"{quantity(env.outside_max, 'mm/s')})."
        )
    ]
    if "du_map" in figures:
        blocks.append(Block("img", text="|u - u_ref| over the state plane", html=figures["du_map"]))
    for m in (env, zoom):
        hot = m.hot_cells()
        if not hot:
            blocks.append(
                _p(f"{m.name}: no cell exceeds the tolerance {quantity(m.tolerance, 'mm/s')}.")
            )
            continue
        rows = [
            [
                f"{quantity(c['x1_mm'][0], 'mm')} to {quantity(c['x1_mm'][1], 'mm')}",
                f"{quantity(c['x2_mm_s'][0], 'mm/s')} to {quantity(c['x2_mm_s'][1], 'mm/s')}",
                quantity(c["max_abs_du_mm_s"], "mm/s"),
                str(c["states"]),
            ]
            for c in hot
        ]
        blocks.append(
            _p(
                f"{m.name}: hottest cells ({int(np.sum(np.nan_to_num(m.du_max) > m.tolerance))} "
                f"cells exceed {quantity(m.tolerance, 'mm/s')}):"
            )
        )
        blocks.append(_table(["x1 range", "x2 range", "largest |u - u_ref|", "states"], rows))
    return blocks


def _closed_loop(r: ConformResult, ev: ConformEvidence) -> list[Block]:
    names = ("no-stride-over", "no-limit-cycle", "input-bound", "settling-vs-discrete-limit")
    rows = []
    for n in names:
        v = r.properties.get(n)
        if v is None:
            continue
        unit = _UNITS.get(v.unit, v.unit)
        rows.append(
            [
                n,
                _STATUS.get(v.status, v.status),
                quantity(v.measured, unit),
                quantity(v.limit, unit),
            ]
        )
    blocks = [_table(["property", "status", "measured", "limit"], rows)]
    s = ev.settling
    if s is None:
        blocks.append(_p(f"Settling / (N* T): {ev.settling_note}."))
        return blocks
    name = s["definition"] if "definition" in s else SETTLING
    blocks.append(
        _p(
            f"Settling time t_s (definition {name}: |x1| <= "
            f"{quantity(s['band_mm'], 'mm')} for good, read on the samples) divided by "
            f"the discrete-time limit N* T (T = {quantity(s['sample_time_s'], 's')}), over the "
            f"{s['states']} initial states of this gate's settling sweep with N* >= 1 "
            "(dimensionless; 1 is the fastest any sampled controller can be). Not the "
            "suboptimality maps of `ptoverify report`: those read settling under "
            f"{SWEEP_SETTLING.name} (|x1| <= {quantity(SWEEP_SETTLING.band_mm, 'mm')} and "
            f"|x2| <= a x {quantity(SWEEP_SETTLING.velocity_band_mm, 'mm')}, held "
            f"{quantity(1e3 * SWEEP_SETTLING.hold_s, 'ms')}) between the samples, over their own "
            "grid of the envelope, so the reference's median there differs from this one."
        )
    )
    rows = []
    for label, key in (("your law", "user"), ("reference law", "reference")):
        st = s[key]
        rows.append(
            [
                label,
                quantity(st["median"]),
                quantity(st["p95"]),
                quantity(st["max"]),
                str(st["unsettled"]),
            ]
        )
    blocks.append(_table(["law", "median", "95th percentile", "max", "never settled"], rows))
    blocks.append(
        _p(
            f"Worst excess of your law: {quantity(s['worst_excess_samples'], 'samples')} beyond "
            f"N*, from {state(s['worst_state'])}."
        )
    )
    return blocks


def _responses(ev: ConformEvidence, figures: dict[str, str]) -> list[Block]:
    if not ev.responses:
        return [_p(f"No step, ramp or sine responses: {ev.responses_note}.")]
    blocks = [
        _p(
            "The Section 6 references (5 mm step; ramp to 30 mm at 200 mm/s; 5 mm, 5 Hz "
            "sine; reference velocity fed forward), simulated with your law called through "
            "the same isolated process as the conformance, next to the reference law. "
            "Metrics are exact between samples, and only those that mean something for the "
            "signal: settling and rise for the step, the overshoot past the end value for "
            "the ramp (its settling from the start would measure the ramp), the phase delay "
            "for the sine (a sine does not settle)."
        )
    ]
    for name, resp in ev.responses.items():
        key = f"response_{name}"
        if key in figures:
            blocks.append(Block("img", text=f"{name} response", html=figures[key]))
        rows = []
        for k, label, unit in _METRICS:
            if k in resp.user_metrics or k in resp.reference_metrics:
                rows.append(
                    [
                        label,
                        quantity(resp.user_metrics.get(k), unit),
                        quantity(resp.reference_metrics.get(k), unit),
                    ]
                )
        rows.append(
            ["largest |x1 (yours) - x1 (reference)|", quantity(resp.max_abs_dx1_mm, "mm"), "0 mm"]
        )
        blocks.append(_table([f"{name}: metric", "your law", "reference law"], rows))
    return blocks


def _failures(r: ConformResult) -> list[Block]:
    if not r.failures:
        return [_p("No failures.")]
    rows = [[f["property"], state(f["state"]), f["detail"]] for f in r.failures]
    return [_table(["property", "first state that shows it", "detail"], rows)]


def build_sections(
    result: ConformResult, ev: ConformEvidence, cfg: Config, figures: dict[str, str]
) -> list[Section]:
    """Return the report's sections (anchor, title, blocks).

    Parameters
    ----------
    result : ConformResult
        The verdict.
    ev : ConformEvidence
        Maps, boundaries, responses and settling summary.
    cfg : Config
        Configuration.
    figures : dict of str to str
        Figure key -> relative path of the written PNG.

    Returns
    -------
    list of Section
    """
    r = result
    return [
        ("verdict", "Verdict", _verdict(r, ev, cfg)),
        ("properties", "Properties", _properties(r)),
        ("limits", "Pass limits and why", limits(r, cfg)),
        ("agreement", "Agreement per region", _agreement(r)),
        ("map", "Where your law differs: |u - u_ref|", _map(r, ev, figures)),
        ("closed-loop", "Closed loop and settling / N*T", _closed_loop(r, ev)),
        ("perturbed", "Closed loop under perturbation", perturbed(r)),
        ("responses", "Step, ramp and sine responses", _responses(ev, figures)),
        ("failures", "Failures", _failures(r)),
    ]


# ------------------------------------------------------------------ writing
def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def write_conform_report(
    result: ConformResult, ev: ConformEvidence, cfg: Config, target: Path
) -> Path:
    """Write the report folder atomically (temporary folder, then one rename).

    Parameters
    ----------
    result : ConformResult
        The verdict.
    ev : ConformEvidence
        Output of :func:`ptoverify.conform.evidence.conform_with_evidence`.
    cfg : Config
        Configuration.
    target : Path
        The folder, validated by :func:`check_report_target`.

    Returns
    -------
    Path
        ``target``.
    """
    from ptoverify import __version__
    from ptoverify.outdir import discard, make_temp, publish
    from ptoverify.report.plots import save_conform_figures

    r = result
    tmp = make_temp(target)
    try:
        marks = {}
        if r.failures and r.failures[0]["state"] is not None:
            marks[f"first failing state ({r.failures[0]['property']})"] = tuple(
                r.failures[0]["state"]
            )
        worst = r.agreement.get("worst")
        if worst is not None and not r.agreement.get("pass", True):
            marks["largest |u - u_ref|"] = tuple(worst["state"])
        written = save_conform_figures(ev, tmp / "figures", marks=marks)
        figures = {k: f"figures/{p.name}" for k, p in written.items()}
        sections = build_sections(r, ev, cfg, figures)
        verdict = "CONFORMS" if r.conforms else "DOES NOT CONFORM"
        title = (
            f"Conformance of {r.target}: {verdict} ({r.precision}; perturbation: "
            + ("; ".join(p.text() for p in r.perturbations) or "none")
            + ")"
        )
        (tmp / "index.html").write_text(render_html(sections, title), encoding="utf-8")
        (tmp / "report.md").write_text(render_markdown(sections, title), encoding="utf-8")
        results = {
            "conform": r.to_json(),
            "evidence": ev.to_json(),
            "law_output": r.law_output,
            "meta": {
                "ptoverify": __version__,
                "config": cfg.name,
                "config_hash": cfg.digest(),
                "figures": sorted(figures.values()),
            },
        }
        text = json.dumps(_jsonable(results), indent=1, allow_nan=False) + "\n"
        (tmp / "results.json").write_text(text, encoding="utf-8")
    except BaseException:
        discard(tmp)
        raise
    publish(tmp, target, config_hash=cfg.digest(), name=cfg.name)
    return target
