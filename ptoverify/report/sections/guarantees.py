"""The sections on proofs, robustness, tuning and the environment of the run."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ptoverify.report.render import (
    Block,
    code,
    fmt,
    qty,
    table,
)
from ptoverify.report.standing import ratio_interval
from ptoverify.report.words import plural

from .common import _law, _ms, figure, settling_band_words
from .robust_rows import baseline_margin_rows

# ------------------------------------------------------------------ proofs
_PROOF_WORDS = {
    "input-bound": "|u| <= w_max",
    "no-stride-over-strict": "no stride-over (strict: never beyond the w_max curve)",
    "no-stride-over-relaxed": "no stride-over (relaxed: the linear strip allowed)",
    "reach": "reaches the target ellipse within the certified bound",
}


def proofs(res: Any, figures: dict[str, str]) -> list[Block]:
    """Show what is proved for every initial state of the envelope, and what is not.

    Parameters
    ----------
    res : Results
        The results (``proofs``: per law the ``prove --json`` object).
    figures : dict
        Figure key -> relative path.

    Returns
    -------
    list of Block
    """
    pr = res["proofs"]
    blocks = [
        Block(
            "p",
            text="Proved over the continuum of initial states (|x1| <= "
            f"{qty(res['environment']['config']['plant']['position_range'], 'mm')}, "
            f"|x2| <= w_max = {qty(res['environment']['config']['plant']['w_max'], 'mm/s')}) with outward-rounded interval arithmetic and python-flint arb "
            "certificates (`ptoverify prove`): each property is proved, refuted with a "
            "certified counterexample, or unproven with the region where the proof fails. "
            "Coverage is the fraction of the envelope's area proved.",
        )
    ]
    rows = []
    for law, p in pr.items():
        for name, prop in p["properties"].items():
            region = prop["unproven_region"]
            where = (
                f"{region['cells']} cells in x1 {fmt(region['bounding_box'][0])} to "
                f"{fmt(region['bounding_box'][1])} mm, x2 {fmt(region['bounding_box'][2])} to "
                f"{fmt(region['bounding_box'][3])} mm/s"
                if region
                else "none"
            )
            rows.append(
                [
                    _law(law),
                    _PROOF_WORDS.get(name, name),
                    prop["status"],
                    qty(100 * prop["coverage"], "%"),
                    where,
                ]
            )
    blocks.append(table(["law", "property", "status", "coverage", "unproven where"], rows))
    rows = [
        [
            _law(law),
            plural(p["bound_samples"], "sample") if p["bound_samples"] is not None else "n/a",
            plural(p["simulated_worst_samples"], "sample")
            if p["simulated_worst_samples"] is not None
            else "n/a",
            f"{p['simulation_over_bound']} of {p['simulated_states']}",
            qty(p["suboptimality"]["certified_max_ratio_nt"], "-")
            + f" outside |x1| < {qty(p['suboptimality']['excluded_radius'], 'mm')}",
            str(p["cells"]),
        ]
        for law, p in pr.items()
    ]
    blocks.append(
        table(
            [
                "law",
                "certified worst samples to the ellipse",
                "simulated worst (same ellipse)",
                "simulated states over their cell's bound",
                "certified samples / N* over the envelope",
                "cells [count]",
            ],
            rows,
        )
    )
    for law in pr:
        blocks += figure(figures, f"proof_bound_{law}")
    return blocks


# ------------------------------------------------------------------ robustness
_PROP_WORDS = {
    "stride_overs": ("stride-overs", "count"),
    "limit_cycle_mm": ("limit-cycle amplitude", "mm"),
    "overshoot_mm": ("overshoot", "mm"),
    "settling_ratio_nt": ("settling / (N* T)", "-"),
}


def _amount(v: Any, unit: str) -> str:
    """Return a worst-case value with its unit; a stride-over count in words (``0 stride-overs``)."""
    if unit == "count" and isinstance(v, (int, float)) and float(v).is_integer():
        return plural(int(v), "stride-over")
    return qty(v, unit)


def simulate_command(law: str, worst: dict[str, Any]) -> str:
    """Return the ``ptoverify simulate`` command line that reproduces a worst case.

    Parameters
    ----------
    law : str
        Law name.
    worst : dict
        ``state`` [mm, mm/s] and ``params`` of a ``robust`` worst case.

    Returns
    -------
    str
        The command (full float precision, so it reproduces exactly).

    Examples
    --------
    >>> simulate_command("pd", {"state": [1.0, -2.5], "params": {"a_ratio": 0.8}})
    'ptoverify simulate --law pd --x0 1.0 -2.5 --a-ratio 0.8'
    """
    flags = (
        ("a_ratio", "--a-ratio"),
        ("w_max_ratio", "--w-max-ratio"),
        ("delay_samples", "--delay"),
        ("position_quantum", "--quantum"),
        ("velocity_noise", "--velocity-noise"),
        ("seed", "--seed"),
    )
    x1, x2 = worst["state"]
    parts = ["ptoverify simulate", f"--law {law}", f"--x0 {float(x1)!r} {float(x2)!r}"]
    p = worst["params"] or {}
    parts += [f"{flag} {p[k]!r}" for k, flag in flags if k in p and p[k] is not None]
    return " ".join(parts)


def robustness(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show maps over the uncertainty box, margins, worst cases with reproducing commands.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of Block
    """
    rob = res["robust"]
    if not rob:
        return [
            Block(
                "p",
                text="Not computed in this run (report --skip robust); "
                "`ptoverify robust` runs the study.",
            )
        ]
    box, st = rob["box"], rob["settings"]
    maps = rob["maps"]
    blocks = [
        Block(
            "p",
            text="Every law is built from the nominal configuration; only the simulated plant "
            "and the measurement change: true a / design a in "
            f"{fmt(box['a_ratio'])} [-], drive saturation / w_max in {fmt(box['w_max_ratio'])} "
            f"[-], computation delay {fmt(box['delay_samples'])} samples, encoder quantum "
            f"{qty(box['position_quantum'], 'mm')}, velocity noise {qty(box['velocity_noise'], 'mm/s')}. "
            f"Laws: {', '.join(_law(k) for k in maps['laws'])}. "
            f"Maps: {len(maps['a_ratio'])} x {len(maps['w_max_ratio'])} perturbations per delay, "
            f"{maps['states']} initial states each (settings: "
            f"{st['n1']} x {st['n2']} grid + {st['rest']} at rest, worst-case search "
            f"{st['search_iterations']} generations of {st['search_population']}; "
            "as `ptoverify robust` with this configuration).",
        )
    ]
    rows = []
    for law, m in rob["margins"].items():
        rows.append(
            [
                _law(law),
                ratio_interval(m["linear_loop_a_ratio_stable"])
                if m["linear_loop_a_ratio_stable"]
                else m["linear_loop_note"] or "n/a",
                ratio_interval(m["linear_loop_a_ratio_stable_delay1"])
                if m["linear_loop_a_ratio_stable_delay1"]
                else m["linear_loop_note_delay1"] or "n/a",
                ratio_interval(m["no_limit_cycle_a_ratio"])
                if m["no_limit_cycle_a_ratio"]
                else m["no_limit_cycle_note"] or "n/a",
            ]
        )
    rows += baseline_margin_rows(res)
    best = rob["most_robust"]
    blocks += [
        Block(
            "p",
            text="Margins: the interval of a_true / a_design around 1 on which each "
            "property holds (endpoints to 1e-6 relative, searched over [0.1, 10]; an end "
            "that reaches the search's bound is named as such, never as a margin).",
        ),
        table(
            [
                "law",
                "linear loop stable",
                "linear loop stable, one-sample delay",
                "no limit cycle from any grid state",
            ],
            rows,
        ),
    ]
    if best["law"]:
        blocks.append(Block("p", text=_tolerance_sentence(rob["margins"])))
    blocks += figure(figures, "robust_limit_cycles") + figure(figures, "robust_settling_nt")
    wrows, cmds = [], []
    for law, by in rob["worst"].items():
        for prop, w in by.items():
            words, unit = _PROP_WORDS.get(prop, (prop, "-"))
            p = w["params"] or {}
            wrows.append(
                [
                    _law(law),
                    words,
                    "unbounded (never settles)"
                    if w["grid_unbounded"]
                    else _amount(w["grid"], unit),
                    "unbounded (never settles)" if w["unbounded"] else _amount(w["searched"], unit),
                    f"({fmt(w['state'][0])} mm, {fmt(w['state'][1])} mm/s)"
                    if w["state"]
                    else "n/a",
                    f"a ratio {fmt(p['a_ratio'])} [-], w_max ratio {fmt(p['w_max_ratio'])} "
                    "[-], "
                    + (
                        f"a delay of {plural(p['delay_samples'], 'sample')}"
                        if p["delay_samples"]
                        else "no delay"
                    ),
                ]
            )
            bad = (
                w["searched"] is not None
                and w["searched"] > 0
                and prop in ("stride_overs", "limit_cycle_mm")
            )
            if bad and w["state"]:
                cmds.append(
                    f"# {_law(law)}: {words} {qty(w['searched'], unit)}\n"
                    + simulate_command(law, w)
                )
    blocks += [
        Block(
            "p",
            text="Worst cases: the grid's worst cell, then a seeded search over (initial "
            "state x perturbation) started from it; the searched value is never below the grid's. "
            f"Settling is read on the samples under {rob['settling']} "
            f"({settling_band_words(rob['settling'], rob['settling'])}), over N* T of the "
            "true plant." + _nominal_vs_sweep(res),
        ),
        table(["law", "property", "grid worst", "searched worst", "state", "perturbation"], wrows),
    ]
    if cmds:
        blocks += [
            Block(
                "p",
                text="Counterexamples (stride-over or limit cycle), reproducible "
                "with the paper's configuration (add --config as for this report):",
            ),
            code("\n".join(cmds)),
        ]
    return blocks + _drive_sweeps(rob["drive"])


def _tolerance_sentence(margins: Any) -> str:
    """Say the largest a_true / a_design each linear loop tolerates, without and with delay."""
    parts = []
    for law, m in margins.items():
        iv, iv1 = m["linear_loop_a_ratio_stable"], m["linear_loop_a_ratio_stable_delay1"]
        if not iv:
            continue
        hi = "beyond the searched 10 x" if iv[1] is None else f"{fmt(iv[1])} x"
        hi1 = (
            "unstable at the design point"
            if not iv1
            else ("beyond the searched 10 x" if iv1[1] is None else f"{fmt(iv1[1])} x")
        )
        parts.append(f"{_law(law)} up to {hi} (one-sample delay: {hi1})")
    return (
        "A true bandwidth above the design value is what destabilizes a sampled linear loop; "
        "the largest a_true / a_design each tolerates: " + "; ".join(parts) + "."
    )


def _drive_sweeps(drive: Any) -> list[Block]:
    """Show the encoder-quantum and velocity-noise sweeps, a row per law and condition."""
    rows = []
    for p in drive["points"]:
        worst = p["worst_settling_s"]
        rows.append(
            [
                _law(p["law"]),
                qty(p["position_quantum_mm"], "mm"),
                qty(p["velocity_noise_mm_s"], "mm/s"),
                qty(p["residual_mm"], "mm"),
                f"{p['not_settled']} of {drive['states']}",
                "none settles"
                if worst is None
                else (_ms(worst) if worst > 0 else "only states that start settled"),
            ]
        )
    return [
        Block(
            "p",
            text="Encoder quantum and velocity noise, each alone (the noise at the "
            f"configuration's quantum {qty(drive['base_quantum_mm'], 'mm')}), on the nominal "
            f"plant: {drive['states']} initial states each, {_ms(drive['horizon_s'])} simulated, "
            f"noise seed {drive['seed']}. Residual: the largest |x1| over the last quarter of "
            f"the run (the standstill error or jitter). Settling under {drive['settling']} "
            "(|x1| <= 0.01 mm and |x2| <= a x 0.01 mm, both held 50 ms), read on the samples: "
            "velocity noise moves x2 too, so a small residual in x1 can still never settle.",
        ),
        table(
            [
                "law",
                "encoder quantum",
                "velocity noise (std)",
                "residual",
                "never settle",
                "longest settling",
            ],
            rows,
        ),
    ]


# ------------------------------------------------------------------ tuning
_GAIN_UNITS = {"kp": "1/s", "kd": "-", "d": "mm", "k1": "1/s", "k2": "-"}


def _gains(g: dict[str, float]) -> str:
    return "; ".join(f"{k} = {qty(v, _GAIN_UNITS.get(k, '-'))}" for k, v in g.items())


def tuning(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Show PD and PTO at their best tuning under shared overshoot bounds.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part); ``tuning`` is
        :func:`ptoverify.studies.claims.fair_comparison`.
    figures : dict
        Figure key -> relative path (``figures/x.png``).

    Returns
    -------
    list of Block
    """
    from ptoverify.studies.tune.measure import WORST_GRID

    t = res["tuning"]
    if not t:
        return [
            Block(
                "p",
                text="Not computed in this run (report --skip tuning); "
                "`ptoverify tune --law pd|pto` runs the search.",
            )
        ]
    fl, bud = t["floor"], t["budget"]
    bounds = "; ".join(
        f"{t['bound_meaning'][k]}: {qty(v, 'mm')}" for k, v in t["bounds_mm"].items()
    )
    blocks = [
        Block(
            "p",
            text="Is the paper's verdict an artefact of its gains? Each law minimizes its 2 % "
            "settling time of the step (between samples) under each shared overshoot bound ("
            f"{bounds}), with a stable sampled linear loop and, for the PTO, no stride-over and "
            "no limit cycle over the gate's grid (omega0 from the corrected construction for its "
            f"d). Differential evolution, seed {bud['seed']}, {bud['maxiter']} "
            f"generations, population factor {bud['popsize']} ({t['evaluations']} "
            "candidates; `ptoverify tune` searches longer). The floor of any 2 % settling time: "
            f"the least 2 % band entry {_ms(fl['band_entry_s'])}; the exact arrival needs "
            f"t_f* = {_ms(fl['tf_s'])} (continuous) and N* T = {_ms(fl['nt_s'])} (sampled).",
        )
    ]
    rows = []
    for law, m in t["paper"].items():
        rows.append(
            [
                "paper's gains",
                _law(law),
                "as configured",
                _ms(m["settling_2pct_s"]),
                qty(m["overshoot_mm"], "mm"),
                _ms(m["rise_time_s"]),
                _ms(m["settling_0p01mm_s"]),
                qty(m["worst_ratio_nt"], "-"),
            ]
        )
    for name, by in t["best"].items():
        for law, b in by.items():
            rows.append(
                [
                    f"best, overshoot <= {qty(t['bounds_mm'][name], 'mm')}",
                    _law(law),
                    _gains(b["gains"]),
                    _ms(b["settling_2pct_s"]),
                    qty(b["overshoot_mm"], "mm"),
                    _ms(b["rise_time_s"]),
                    _ms(b["settling_0p01mm_s"]),
                    qty(b["worst_ratio_nt"], "-"),
                ]
            )
    blocks += [
        table(
            [
                "tuning",
                "law",
                "gains",
                "2 % settling",
                "overshoot",
                "10-90 % rise",
                "0.01 mm settling",
                f"worst settling / (N* T), {WORST_GRID[0]} x {WORST_GRID[1]} grid [-]",
            ],
            rows,
        ),
        Block(
            "p",
            text="The last column: the tuner's check of the whole envelope, settling under "
            f"box-0p01mm read on the samples over a coarse {WORST_GRID[0]} x {WORST_GRID[1]} "
            "grid of initial states; the suboptimality maps' worst ratio (section 9) reads the "
            "same definition between samples over a much finer grid, which reaches smaller "
            "moves and so finds a larger worst ratio.",
        ),
        *figure(figures, "tuning_pareto"),
        Block("p", text="The paper's PD-vs-PTO claims judged at the best tuning of both laws:"),
        table(
            ["claim", "verdict at best tuning", "measured"],
            [[c["claim"], c["verdict"], c["sentence"]] for c in t["claims"]],
        ),
    ]
    return blocks


# ------------------------------------------------------------------ environment
#: Units of the configuration keys.
CONFIG_UNITS = {
    "plant.bandwidth_hz": "Hz",
    "plant.a": "rad/s",
    "plant.position_range": "mm",
    "plant.sample_time": "s",
    "plant.w_max": "mm/s",
    "pd.kp": "1/s",
    "pd.kd": "-",
    "pto.d": "mm",
    "pto.k1": "1/s",
    "pto.k2": "-",
    "robustness.a_ratio": "-",
    "robustness.w_max_ratio": "-",
    "robustness.delay_samples": "samples",
    "robustness.position_quantum": "mm",
    "robustness.velocity_noise": "mm/s",
    "robustness.seed": "-",
    "robustness.settling_ratio_limit": "-",
}


def environment(res: dict[str, Any]) -> list[Block]:
    """Versions, configuration (with units), commit, date."""
    env = res["environment"]
    rows = [[k, v] for k, v in env.items() if k != "config"]
    rows.append(["generated", res["meta"]["generated"]])
    cfg_rows = []
    for sec, vals in env["config"].items():
        for k, v in vals.items() if isinstance(vals, Mapping) else [("", vals)]:
            key = f"{sec}.{k}" if k else sec
            unit = CONFIG_UNITS.get(key)
            if isinstance(v, (int, float, list, tuple)) and not isinstance(v, bool):
                cell = qty(v, unit) if unit is not None else f"{fmt(v)} (unit not recorded)"
            else:
                cell = fmt(v)
            cfg_rows.append([key, cell])
    return [table(["item", "value"], rows), table(["configuration key", "value"], cfg_rows)]


def _nominal_vs_sweep(res: Any) -> str:
    """Say why the nominal cell's worst settling / (N* T) differs from the sweep's worst.

    Both are read under the same definition; the robustness grid holds fewer
    initial states than the suboptimality sweep, whose finer grid reaches smaller
    moves (N* of a few samples, where one sample more weighs much).

    Parameters
    ----------
    res : Results
        The results (``robust.maps``, ``sweep``; either may be None).

    Returns
    -------
    str
        A sentence (with a leading space), or "" when either study is missing.
    """
    rob, sw = res["robust"], res["sweep"]
    if not rob or not sw:
        return ""
    maps = rob["maps"]
    pairs = []
    for law, cells in maps["laws"].items():
        cell = next(
            (
                c
                for c in cells
                if c["a_ratio"] == 1 and c["w_max_ratio"] == 1 and c["delay_samples"] == 0
            ),
            None,
        )
        if cell is None or law not in sw["laws"] or cell["settling_ratio_nt"]["max"] is None:
            continue
        worst, states = sw["laws"][law]["worst_ratio_nt"], sw["laws"][law]["worst_states_nt"]
        if worst is None or not states:
            continue
        here, there = cell["settling_ratio_nt"], states[0]
        pairs.append(
            f"{_law(law)} {fmt(here['max'])} from {_state(here['state'])} here, "
            f"{fmt(worst)} from {_state(there[:2])} there"
        )
    if not pairs:
        return ""
    st = sw["settings"]
    return (
        f" On the nominal plant (no delay) the worst settling / (N* T) over these "
        f"{maps['states']} states differs from the suboptimality maps' worst over "
        f"{st['n1']} x {st['n2']} states ({'; '.join(pairs)}): each is the worst of its "
        "own grid, and the worst states are small moves, where N* is a few samples and one "
        "sample more weighs much."
    )


def _state(x: Any) -> str:
    """Return an initial state ``(x1 mm, x2 mm/s)`` in words."""
    return f"({qty(x[0], 'mm')}, {qty(x[1], 'mm/s')})"
