"""The sections of the studies: ground truth, zone, poles, properties, claims and sweep."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ptoverify.conform.closedloop import SETTLING as CONFORM_SETTLING
from ptoverify.report.render import (
    Block,
    fmt,
    qty,
    table,
)
from ptoverify.report.standing import TIE_NOTE
from ptoverify.report.words import claim_title
from ptoverify.sim.settling import DEFINITIONS

from .common import _claim_qty, _law, _ms, _same, figure, measured_quantity


# ------------------------------------------------------------------ ground truth
def ground_truth(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Compare closed form vs two-phase vs collocation, convergence, N*."""
    gt = res["ground_truth"]
    rows = [
        [
            s["x0"],
            s["analytic_s"],
            s["switch_time_s"],
            s["two_phase_s"],
            s["two_phase_rel_error"],
            s["collocation_s"],
            s["collocation_rel_error"],
            s["discrete_steps"],
            s["discrete_s"],
            s["discrete_gap_samples"],
        ]
        for s in gt["states"]
    ]
    conv = gt["convergence"]
    return [
        Block(
            "p",
            text="Minimum time t_f* from each state: the closed form (SymPy-derived), the "
            "CasADi two-phase OCP (exact flow per arc), Radau-3 collocation with "
            "N = 100 intervals, and the discrete-time limit N* (fewest ZOH samples that reach "
            "the origin exactly). No sampled controller settles exactly in fewer than N* samples.",
        ),
        table(
            [
                "x0 [mm, mm/s]",
                "t_f* closed form [s]",
                "switch [s]",
                "two-phase [s]",
                "rel. error [-]",
                "collocation [s]",
                "rel. error [-]",
                "N* [samples]",
                "N* T [s]",
                "(N* T - t_f*) / T [samples]",
            ],
            rows,
        ),
        Block("p", text=_convergence_sentence(conv)),
        *figure(figures, "fig02_trajectories"),
        *figure(figures, "fig03_saturation"),
        *figure(figures, "convergence"),
        *figure(figures, "collocation_switch"),
    ]


def zone(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show the printed and corrected construction with reasons."""
    z = res["zone"]
    rows = []
    for key in ("printed", "corrected", "corrected_lenient"):
        if key in z:
            v = z[key]
            rows.append(
                [
                    key.replace("_", " "),
                    v["omega0"],
                    v["x20_tilde"],
                    v["margin_mm_s"],
                    v["valid"],
                    v["degenerate"],
                    v["reason"],
                ]
            )
    blocks = [
        table(
            [
                "construction",
                "omega0 [mm/s]",
                "x20~ [mm/s]",
                "worst landing margin [mm/s]",
                "valid",
                "degenerate",
                "reason",
            ],
            rows,
        )
    ]
    blocks += figure(figures, "zone_geometry")
    for key in sorted(figures):
        if key.startswith(("fig04", "fig05", "fig06")):
            blocks += figure(figures, key)
    return blocks


def poles(res: dict[str, Any]) -> list[Block]:
    """Continuous and sampled poles, margins, the Lyapunov caveat."""
    rows = []
    for name, lp in res["poles"]["loops"].items():
        rows.append(
            [
                name,
                lp["gains"],
                lp["continuous_poles"],
                lp["continuous_zeta"],
                lp["sampled_moduli"],
                qty(lp["gain_margin_db"], "dB"),
                lp["phase_margin_deg"],
                lp["delay_margin_samples"],
                lp["pole_mismatch"],
                lp["stable_sampled"],
                lp["lyapunov_conditions"],
            ]
        )
    ce = res["poles"]["lyapunov_counterexample"]
    scalars = {k: v for k, v in ce.items() if not isinstance(v, (Mapping, list, tuple))}
    return [
        table(
            [
                "loop",
                "gains (k1 or kp [1/s], k2 or kd [-])",
                "continuous poles (re, im) [rad/s]",
                "damping [-]",
                "sampled |z| [-]",
                "gain margin",
                "phase margin [deg]",
                "delay margin [samples]",
                "|python-control - numpy| [-]",
                "sampled stable",
                "Section 5 conditions",
            ],
            rows,
        ),
        Block(
            "p",
            text="Section 5's conditions k1 > 0, 1 + k2 > 0 are a continuous-time "
            "statement; with sampling they do not imply stability: "
            + "; ".join(
                f"{k.replace('_', ' ')} = {_unit_from_name(k, v)}" for k, v in scalars.items()
            ),
        ),
    ]


def _convergence_sentence(conv: Any) -> str:
    """Say how the collocation error falls with N, and where it is not monotone."""
    ns, errs = list(conv["intervals"]), [list(r) for r in conv["rel_error"]]
    rising = [
        ns[j + 1]
        for j in range(len(ns) - 1)
        if any(r[j] is not None and r[j + 1] is not None and r[j + 1] > r[j] for r in errs)
    ]
    text = (
        f"Collocation against the closed form over N = {fmt(conv['intervals'])} intervals: "
        f"least-squares log-log slope {fmt(conv['order'], 3)} [-] over all N (per state "
        f"{fmt(conv['order_per_state'], 3)} [-])."
    )
    if rising:
        text += (
            " The error is not monotone in N (it rises for some state at N = "
            f"{fmt(rising)}): the switch time falls between mesh points, so the slope "
            "summarizes the trend and is not a convergence order."
        )
    return text


def _unit_from_name(name: str, v: Any) -> str:
    """Show a value with the unit its key names (``_mm``, ``_s``, ``_deg``...)."""
    if name.startswith(("k1", "kp")) and isinstance(v, (int, float)):
        return qty(v, "1/s")  # a position gain: velocity per position
    for suffix, unit in (
        ("_mm_s", "mm/s"),
        ("_mm", "mm"),
        ("_deg", "deg"),
        ("_s", "s"),
        ("_rad_s", "rad/s"),
        ("_percent", "%"),
    ):
        if name.endswith(suffix):
            return qty(v, unit)
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return qty(v, "-")
    return fmt(v)


#: Columns of the properties table: key, header with unit.
_PROPERTY_COLUMNS = (
    ("states", "states [count]"),
    ("stride_overs", "stride-overs [count]"),
    ("crossings_into_linear", "curve crossings landing in |x1| < d [count]"),
    ("limit_cycles", "states in a limit cycle [count]"),
    ("not_settled", "states not settled (0p001mm) [count]"),
    ("states_chattering", "states that chatter [count]"),
    ("overshoots", "moves from rest that overshoot [count]"),
    ("max_overshoot_mm", "max overshoot [mm]"),
    ("time_to_linear_max_s", "max time to |x1| < d [s]"),
    ("max_abs_u", "max |u| [mm/s]"),
)


def properties(res: dict[str, Any]) -> list[Block]:
    """Stride-overs, limit cycles, chattering, |u| over the grid."""
    rows = [
        [_law(law), *[p[k] for k, _ in _PROPERTY_COLUMNS]] for law, p in res["properties"].items()
    ]
    blocks = [
        table(["law", *[h for _, h in _PROPERTY_COLUMNS]], rows),
        Block(
            "p",
            text="Over the gate's grid of initial states, on the samples. A curve crossing is a "
            "sample step across l1 or l2 (the PTO's switching curves, whatever the law); "
            "d is the PTO's linear zone, so its time is a distance reached for PD and TO too. "
            "Not settled: the record ends outside |x1| <= 0.001 mm (the definition 0p001mm).",
        ),
    ]
    base = [_law(law) for law in ("ptos", "cascade-p") if law in res["properties"]]
    if base:
        blocks.insert(
            0,
            Block(
                "p",
                text=f"The baselines ({', '.join(base)}) are measured as the paper's laws are, "
                "for information: the gates judge the paper's laws only. Stride-overs and "
                "crossings refer to the PTO's curves l1, l2 and its linear zone.",
            ),
        )
    return blocks


def claims(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Every claim: what is measured, paper value, value between samples and on the grid."""
    from ptoverify.studies.claims.types import tie_words

    rows = []
    for c in res["claims"]:
        differs = not _same(c["measured"], c["measured_grid"])
        rows.append(
            [
                f"Sec. {c['section']}",
                c["signal"],
                c["claim"],
                measured_quantity(c),
                _claim_qty(c["paper_value"], c["unit"]),
                _claim_qty(c["measured"], c["unit"]),
                _claim_qty(c["measured_grid"], c["unit"]) if differs else "same",
                c["verdict"],
                c["verdict_grid"] or "n/a",
                c["detail"],
            ]
        )
    readings = []
    for c in res["claims"]:
        for r in c["readings"]:
            differs = not _same(r["measured"], r["measured_grid"])
            readings.append(
                [
                    claim_title(c),
                    r["label"],
                    _claim_qty(r["measured"], c["unit"]),
                    _claim_qty(r["measured_grid"], c["unit"]) if differs else "same",
                    r["verdict"],
                    r["verdict_grid"] or "n/a",
                    "; ".join(tie_words(t) for t in r["ties"] or []) or "none",
                ]
            )
    blocks = [
        Block(
            "p",
            text="'measured' is read on the exact trajectory between samples (the input is "
            "constant over a sample and the flow is closed form); where the value read on the "
            f"{_ms(res['environment']['config']['plant']['sample_time'])} sample grid differs it "
            "is shown next to it, with the verdict the same rule gives on the grid. Times are "
            f"shown in ms. {TIE_NOTE}",
        ),
        table(
            [
                "paper section",
                "signal",
                "claim",
                "what is measured",
                "paper",
                "measured, between samples",
                "on the sample grid",
                "verdict",
                "verdict on the grid",
                "detail (primary reading)",
            ],
            rows,
        ),
        Block("p", text="Every reading of an ambiguous point is run and reported:"),
        table(
            [
                "claim",
                "reading",
                "measured",
                "on the sample grid",
                "verdict",
                "verdict on grid",
                "tied times (less than one sample apart)",
            ],
            readings,
        ),
    ]
    resp = res["responses"]
    if resp:
        keys = (
            ("settling_2pct_s", "2 % settling"),
            ("settling_0p01mm_s", "0.01 mm settling"),
            ("rise_time_s", "10-90 % rise"),
            ("overshoot_mm", "overshoot"),
        )
        rows = []
        for law, by in resp.items():
            m = by["step"]
            cells = []
            for k, _ in keys:
                ex, gr = m[k], m[f"{k}_grid"]
                val = _ms(ex) if k.endswith("_s") else qty(ex, "mm")
                if gr is not None and not _same(ex, gr):
                    val += f" (grid {_ms(gr) if k.endswith('_s') else qty(gr, 'mm')})"
                cells.append(val)
            rows.append([_law(law), *cells])
        blocks += [
            Block(
                "p",
                text="Step response metrics under the primary reading, between samples "
                "(sample-grid value in parentheses where it differs):",
            ),
            table(["law", *[t for _, t in keys]], rows),
        ]
    for key in sorted(figures):
        if key.startswith(("fig07", "fig08", "fig09", "fig10", "fig11", "fig12", "fig13", "fig14")):
            blocks += figure(figures, key)
    return blocks


#: ``ptoverify conform``'s settling definition (its settling / (N* T)), in words.
CONFORM_SETTLING_WORDS = f"|x1| <= {DEFINITIONS[CONFORM_SETTLING].band_mm:g} mm for good"


def sweep_definition_words(sw: Mapping[str, Any]) -> str:
    """Name the sweep's settling definition with what it bounds: ``box-0p01mm (|x1| <= ...)``.

    Parameters
    ----------
    sw : Mapping
        ``results["sweep"]`` (``settings``: ``band`` [mm], ``hold`` [s],
        ``velocity_band`` [mm/s] or None; ``velocity_band`` as used [mm/s]).

    Returns
    -------
    str
    """
    box, st = DEFINITIONS["box-0p01mm"], sw["settings"]
    name = (
        box.name
        if (st["band"], st["hold"], st["velocity_band"]) == (box.band_mm, box.hold_s, None)
        else "the sweep's own box"
    )
    vel = (
        f"|x2| <= a x {fmt(st['band'])} mm"
        if st["velocity_band"] is None
        else f"|x2| <= {qty(sw['velocity_band'], 'mm/s')}"
    )
    return f"{name} (|x1| <= {qty(st['band'], 'mm')} and {vel}, held {_ms(st['hold'])})"


def sweep(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Settling time over t_f* and over N* T, per law, with percentiles."""
    sw = res["sweep"]
    rows = []
    for law, v in sw["laws"].items():
        ptf = v["percentiles_ratio_tf"] or {}
        pnt = v["percentiles_ratio_nt"] or {}
        rows.append(
            [
                _law(law),
                qty(100 * v["fraction_settled"], "%"),
                *[ptf[k] for k in ("p50", "p95", "p99", "max")],
                v["worst_state_tf"],
                *[pnt[k] for k in ("p50", "p95", "p99", "max")],
                v["worst_state_nt"],
            ]
        )
    blocks = [
        Block(
            "p",
            text=f"Grid of {sw['grid'][0]} x {sw['grid'][1]} initial states over the envelope, "
            f"horizon {sw['steps']} samples; settling time under the definition "
            f"{sweep_definition_words(sw)}, read between samples, divided by the continuous "
            "minimum time t_f* and by the sampled limit N* T (zonotope N*). `ptoverify conform` "
            f"reports settling / (N* T) under {CONFORM_SETTLING} ({CONFORM_SETTLING_WORDS}), read "
            "on the samples, over its own smaller sweep of states: a narrower band and other "
            "states, so its medians differ from these.",
        ),
        table(
            [
                "law",
                "settled [% of states]",
                "p50 t/t_f* [-]",
                "p95 t/t_f* [-]",
                "p99 t/t_f* [-]",
                "max t/t_f* [-]",
                "worst state [mm, mm/s]",
                "p50 t/(N* T) [-]",
                "p95 t/(N* T) [-]",
                "p99 t/(N* T) [-]",
                "max t/(N* T) [-]",
                "worst state [mm, mm/s]",
            ],
            rows,
        ),
    ]
    for key in sorted(figures):
        if key.startswith("sweep"):
            blocks += figure(figures, key)
    return blocks
