"""The penalty against move size and the coarse design chart (results ``charts``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ptoverify.report.render import Block, fmt, qty, table
from ptoverify.report.words import setting_words

from .common import _law, _ms, figure, settling_band_words

#: How many move sizes the penalty table shows (evenly spread over the log-spaced sizes).
TABLE_SIZES = 6


def _worst(values: Any, sizes: Any) -> tuple[Any, Any]:
    """Return the largest finite value and its move size (None, None when none is finite)."""
    best = (None, None)
    for v, s in zip(values, sizes, strict=True):
        if v is not None and (best[0] is None or v > best[0]):
            best = (v, s)
    return best


def _penalty_blocks(p: Any, figures: dict[str, str], stem: str, csv: str) -> list[Block]:
    sizes = p["sizes_mm"]
    n = p["count"]
    pick = sorted({int(round(x)) for x in np.linspace(0, n - 1, min(TABLE_SIZES, n))})
    laws = list(p["laws"])
    rows = []
    for i in pick:
        row = [qty(sizes[i], "mm"), _ms(p["t_f_s"][i]), _ms(p["nt_s"][i])]
        for law in laws:
            c = p["laws"][law]
            t, r = c["settling_s"][i], c["ratio_nt"][i]
            row.append("never" if t is None else f"{_ms(t)} ({fmt(r)} N*T)")
        rows.append(row)
    worst = []
    for law in laws:
        v, s = _worst(p["laws"][law]["ratio_nt"], sizes)
        never = p["laws"][law]["never_settled"]
        if v is None:
            worst.append(f"{_law(law)} never settles")
            continue
        text = f"{_law(law)} {fmt(v)} N*T at {qty(s, 'mm')}"
        if never:
            text += f" (never settles from {never} of {n} sizes)"
        worst.append(text)
    return [
        Block(
            "p",
            text=f"Gains: {setting_words(p['setting'])}. The worst settling / (N* T) over the "
            "moves: " + "; ".join(worst) + f". The curves as CSV: [{csv}]({csv}).",
        ),
        table(
            ["move", "t_f*", "N* T", *[f"{_law(law)} settling" for law in laws]],
            rows,
        ),
        *figure(figures, stem),
    ]


def _cell_words(t_s: float, f_hz: float) -> str:
    return f"T = {_ms(t_s)}, {qty(f_hz, 'Hz')}"


def _design_blocks(d: Any, figures: dict[str, str]) -> list[Block]:
    sm = d["summary"]
    ts, fs = list(d["sample_times_s"]), list(d["bandwidths_hz"])
    lead = []
    for law, f in sm["fastest"].items():
        by = f", ahead by up to x{fmt(f['by_max'])}" if f["by_max"] else ""
        lead.append(f"{_law(law)} in {f['cells']} of {sm['cells']} cells{by}")

    def where(cells: Any) -> str:
        return "; ".join(_cell_words(t, f) for t, f in cells) if cells else "none"

    text = (
        "Which law is fastest where (least median settling / (N* T) over a "
        f"{d['grid']} x {d['grid']} grid of the envelope, each law at the configured gains, "
        "a = 2 pi f; 'ahead by x': the runner-up's median ratio over the fastest's): "
        f"{'; '.join(lead) if lead else 'no law settles anywhere'}. "
        f"The PTO's corrected zone is unusable in {sm['pto_zone_unusable']} cells "
        f"({where(sm['pto_zone_unusable_cells'])}) and degenerate (inside the linear zone) in "
        f"{sm['pto_zone_degenerate']} ({where(sm['pto_zone_degenerate_cells'])}); its linear "
        f"zone is unstable with one sample of computation delay in {sm['pto_delay_unstable']} "
        f"cells ({where(sm['pto_delay_unstable_cells'])})."
    )
    if sm["paper_cell"] is not None:
        pt = d["points"][sm["paper_cell"]]
        text += (
            f" At the configuration's own point ({_cell_words(pt['sample_time'], pt['bandwidth_hz'])})"
            f" the fastest is {_law(pt['fastest']) if pt['fastest'] else 'none'}."
        )
    text += " `ptoverify design` draws finer charts, and tunes each law at each point (--tuned)."
    grid = {(p["sample_time"], p["bandwidth_hz"]): p for p in d["points"]}
    rows = []
    for t in ts:
        row = [_ms(t)]
        for f in fs:
            p = grid[(t, f)]
            by = p["fastest_by"]
            cell = _law(p["fastest"]) if p["fastest"] else "none"
            if isinstance(by, (int, float)):
                cell += f" (next x{fmt(by)})"
            pto = next((r for r in p["laws"] if r["law"] == "pto"), None)
            rho = pto["radius_delay1"] if pto is not None else None
            notes = []
            if not p["pto_zone_usable"]:
                notes.append("PTO zone unusable")
            elif p["pto_zone_degenerate"]:
                notes.append("PTO zone degenerate")
            if isinstance(rho, (int, float)) and rho >= 1.0:
                notes.append("PTO delay-unstable")
            row.append(cell + ("; " + ", ".join(notes) if notes else ""))
        rows.append(row)
    return [
        Block("p", text=text),
        table(["T", *[qty(f, "Hz") for f in fs]], rows),
        *figure(figures, "design_chart"),
    ]


def charts(res: Any, figures: dict[str, str]) -> list[Block]:
    """Show the penalty against move size and the coarse design chart.

    Parameters
    ----------
    res : Results
        The results (``charts``: :mod:`ptoverify.report.charts`; ``tuning.penalty``
        when the tuning ran).
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of Block
    """
    c = res["charts"]
    if c is None:
        return [
            Block(
                "p",
                text="Not computed in this run (report --skip charts); `ptoverify penalty` and "
                "`ptoverify design` compute them.",
            )
        ]
    p = c["penalty"]
    blocks = [
        Block(
            "p",
            text="How much slower than the limit is each law, for a given move? Point-to-point "
            f"moves from rest, {p['count']} sizes log-spaced from "
            f"{qty(p['sizes_mm'][0], 'mm')} to {qty(p['sizes_mm'][-1], 'mm')}; settling "
            f"definition {p['settling_definition']} ({settling_band_words(p['settling_definition'], p['definition_description'])}), beside the "
            "continuous "
            "minimum time t_f* and the sampled limit N* T.",
        ),
        *_penalty_blocks(p, figures, "penalty_moves", "tables/penalty_moves.csv"),
    ]
    t = res["tuning"]
    if t is not None and "penalty" in t:
        blocks += _penalty_blocks(
            t["penalty"], figures, "penalty_moves_tuned", "tables/penalty_moves_tuned.csv"
        )
    return blocks + _design_blocks(c["design"], figures)
