"""The nine sections of the report, built from the JSON results as neutral blocks.

Each function takes the JSON results of :func:`ptoverify.report.collect` (and
the figure paths) and returns a list of :class:`ptoverify.render.Block`.  No
number is typed in here: every figure shown is read from the results.  Nothing
here computes: the derivation section gets the records the collect step made.
"""

from __future__ import annotations

from typing import Any

from ptoverify.render import Block, fmt, image, link, table

__all__ = [
    "summary",
    "derivations",
    "ground_truth",
    "zone",
    "poles",
    "properties",
    "claims",
    "sweep",
    "environment",
]


def summary(res: dict[str, Any]) -> list[Block]:
    """Section 1: what holds, what does not, with links."""
    s = res["summary"]
    g = s["gates"]
    blocks = [
        Block(
            "p",
            text=(
                f"Gates: {g['pass']} of {g['total']} pass, {g['fail']} fail, {g['unverified']} "
                f"unverified ({'all pass' if g['ok'] else 'NOT all pass'}). Derivation verdicts: "
                + ", ".join(f"{k} {v}" for k, v in sorted(s["derivation_verdicts"].items()))
                + ". Claim verdicts: "
                + ", ".join(f"{k} {v}" for k, v in sorted(s["claim_verdicts"].items()))
                + "."
            ),
        )
    ]
    rows = [
        [c["name"], c["status"], c["measured"], c.get("comparison", "<="), c["limit"]]
        for c in res["checks"]
    ]
    blocks.append(table(["gate", "status", "measured", "must be", "limit"], rows))
    errata = [r for r in res["derivations"] if r["verdict"] == "erratum"]
    if errata:
        blocks.append(
            Block("p", text="Errata found in the paper (derived form disagrees with the print):")
        )
        blocks.append(table(["eq.", "what fails"], [[r["id"], r["note"][:300]] for r in errata]))
        blocks.append(link("derivations", "Details in the derivations section"))
    z = res["zone"]
    blocks.append(
        Block(
            "p",
            text=(
                f"Switching zone as printed: {'valid' if z['printed']['valid'] else 'invalid'} "
                f"(omega0 = {fmt(z['printed']['omega0'])} mm/s). Corrected: "
                f"{'valid' if z['corrected']['valid'] else 'invalid'} (omega0 = "
                f"{fmt(z['corrected']['omega0'])} mm/s, the largest level meeting the no-stride-over "
                f"principle; worst one-sample landing margin "
                f"{fmt(z['corrected'].get('margin_mm_s'), 3)} mm/s, i.e. it sits at the edge of the "
                f"feasible interval {fmt(z['corrected'].get('feasible_intervals'), 4)})."
            ),
        )
    )
    blocks.append(link("zone", "Zone geometry and reasons"))
    bad = [c for c in res["claims"] if c["verdict"] != "reproduced"]
    if bad:
        blocks.append(
            Block(
                "p",
                text="Section 6 claims that are not reproduced, or that hold "
                "under some readings only (ambiguous). 'measured' is the "
                "primary reading (feed-forward, a = 2 pi f, corrected "
                "PTO); the range spans every reading.",
            )
        )
        rows = []
        for c in bad:
            vals = [r["measured"] for r in c["readings"] if r["measured"] is not None]
            rng = (min(vals), max(vals)) if vals else None
            ok = sum(r["verdict"] == "reproduced" for r in c["readings"])
            rows.append(
                [
                    c["claim"],
                    c["verdict"],
                    c["paper_value"],
                    c["measured"],
                    rng,
                    f"{ok}/{len(c['readings'])}",
                ]
            )
        blocks.append(
            table(
                [
                    "claim",
                    "verdict",
                    "paper",
                    "measured",
                    "range over readings",
                    "readings reproducing",
                ],
                rows,
            )
        )
        blocks.append(link("claims", "All claims with every reading"))
    sw = res["sweep"]["laws"]
    if sw:
        blocks.append(
            Block(
                "p",
                text="Suboptimality over the sweep grid (settling time / "
                "continuous minimum time t_f*): "
                + "; ".join(
                    f"{law}: settles from {100 * v['fraction_settled']:.0f} % of states, median "
                    f"{fmt(v['median_ratio_tf'], 3)}, 95th percentile {fmt(v.get('p95_ratio_tf'), 3)}"
                    for law, v in sw.items()
                )
                + ".",
            )
        )
        blocks.append(link("sweep", "Suboptimality maps"))
    return blocks


def derivations(res: dict[str, Any], records: list) -> list[Block]:
    """Section 2: printed next to derived (MathML), verdicts, errata.

    ``records`` are the :class:`derivations.EquationRecord` objects the collect
    step derived (their JSON form is ``res["derivations"]``); they carry the
    SymPy expressions that render as MathML.
    """
    import derivations as dv

    recs = list(records)
    return [
        Block(
            "p",
            text="Each equation is re-derived with SymPy from eq. (1) and compared "
            "with its transcription, symbolically, then at 200 random "
            "admissible points. Where a record quotes plant numbers (the "
            "printed zone chain, the linear-zone spectral radius) they are "
            "evaluated at this report's configuration.",
        ),
        Block("raw", text=dv.render_markdown(recs), html=dv.render_html(recs)),
    ]


def ground_truth(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Section 3: closed form vs two-phase vs collocation, convergence, N*."""
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
            "N = 100, and the discrete-time limit N* (fewest ZOH samples that reach "
            "the origin exactly, by linear programs). No sampled controller settles "
            "exactly in fewer than N* samples.",
        ),
        table(
            [
                "x0 [mm, mm/s]",
                "t_f* closed [s]",
                "switch [s]",
                "two-phase [s]",
                "rel. err",
                "collocation [s]",
                "rel. err",
                "N*",
                "N* T [s]",
                "(N* T - t_f*) / T",
            ],
            rows,
        ),
        Block(
            "p",
            text=f"Collocation convergence over N = {conv['intervals']}: observed "
            f"order {fmt(conv['order'], 3)} (per state "
            f"{fmt(conv['order_per_state'], 3)}).",
        ),
        *image(figures, "fig02_trajectories", "Fig. 2: trajectories under +-w_max, l1 and l2"),
        *image(figures, "fig03_saturation", "Fig. 3: trajectories with velocity saturation"),
        *image(figures, "convergence", "Collocation t_f error against N"),
        *image(figures, "collocation_switch", "Collocation input near the switch"),
    ]


def zone(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Section 4: printed and corrected construction with reasons."""
    z = res["zone"]
    rows = []
    for key in ("printed", "corrected", "corrected_lenient"):
        if key in z:
            v = z[key]
            rows.append(
                [key, v["omega0"], v.get("x20_tilde"), v["valid"], v.get("degenerate"), v["reason"]]
            )
    blocks = [
        table(
            ["construction", "omega0 [mm/s]", "x20~ [mm/s]", "valid", "degenerate", "reason"], rows
        )
    ]
    for name, o in z.get("outcome", {}).items():
        blocks.append(
            Block(
                "p",
                text=f"Closed-loop outcome of {name}: "
                + ", ".join(f"{k} = {fmt(v)}" for k, v in o.items()),
            )
        )
    blocks += image(figures, "zone_geometry", "Zone geometry, sampled trajectories by region")
    for key in sorted(figures):
        if key.startswith(("fig04", "fig05", "fig06")):
            blocks += image(figures, key, key.replace("_", " "))
    return blocks


def poles(res: dict[str, Any]) -> list[Block]:
    """Section 5: continuous and sampled poles, margins, the Lyapunov caveat."""
    rows = []
    for name, lp in res["poles"]["loops"].items():
        rows.append(
            [
                name,
                lp["gains"],
                lp["continuous_poles"],
                lp["continuous_zeta"],
                lp["sampled_moduli"],
                lp["gain_margin"],
                lp["phase_margin_deg"],
                lp["pole_mismatch"],
                lp["stable_sampled"],
                lp["lyapunov_conditions"],
            ]
        )
    ce = res["poles"]["lyapunov_counterexample"]
    return [
        table(
            [
                "loop",
                "gains",
                "continuous poles",
                "damping",
                "sampled |z|",
                "gain margin",
                "phase margin [deg]",
                "|python-control - numpy|",
                "sampled stable",
                "Section 5 conditions",
            ],
            rows,
        ),
        Block(
            "p",
            text="Section 5's conditions k1 > 0, 1 + k2 > 0 are a continuous-time "
            "statement; with sampling they do not imply stability: "
            + ", ".join(
                f"{k} = {fmt(v)}" for k, v in ce.items() if not isinstance(v, (dict, list))
            ),
        ),
    ]


def properties(res: dict[str, Any]) -> list[Block]:
    """Section 6: stride-overs, limit cycles, chattering, |u| over the grid."""
    keys = [
        "states",
        "stride_overs",
        "crossings_into_linear",
        "limit_cycles",
        "not_settled",
        "chattering",
        "overshoots",
        "max_overshoot_mm",
        "time_to_linear_max_s",
        "max_abs_u",
    ]
    rows = [[law, *[p.get(k) for k in keys]] for law, p in res["properties"].items()]
    return [table(["law", *keys], rows)]


def claims(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Section 7: every claim, paper value, measured value, verdict, readings."""
    rows = [
        [
            c["section"],
            c["signal"],
            c["claim"],
            c["paper_value"],
            c["measured"],
            c["unit"],
            c["verdict"],
            c["detail"],
        ]
        for c in res["claims"]
    ]
    readings = [
        [c["id"], r["label"], r["measured"], r["verdict"]]
        for c in res["claims"]
        for r in c["readings"]
    ]
    blocks = [
        table(
            [
                "sec.",
                "signal",
                "claim",
                "paper",
                "measured",
                "unit",
                "verdict",
                "detail (primary reading)",
            ],
            rows,
        ),
        Block("p", text="Every reading of an ambiguous point is run and reported:"),
        table(["claim", "reading", "measured", "verdict"], readings),
    ]
    for key in sorted(figures):
        if key.startswith(("fig07", "fig08", "fig09", "fig10", "fig11", "fig12", "fig13", "fig14")):
            blocks += image(figures, key, key.replace("_", " "))
    return blocks


def sweep(res: dict[str, Any], figures: dict[str, str]) -> list[Block]:
    """Section 8: settling time over t_f* and over N* T, per law."""
    sw = res["sweep"]
    rows = [
        [
            law,
            f"{100 * v['fraction_settled']:.1f} %",
            v["median_ratio_tf"],
            v.get("p95_ratio_tf"),
            v["worst_ratio_tf"],
            v["worst_state_tf"],
            v["median_ratio_nt"],
            v["worst_ratio_nt"],
            v["worst_state_nt"],
        ]
        for law, v in sw["laws"].items()
    ]
    blocks = [
        Block(
            "p",
            text=f"Grid {sw['grid']} of initial states, horizon {sw['steps']} "
            "samples; settling to the tight band and staying there.",
        ),
        table(
            [
                "law",
                "settled",
                "median t/t_f*",
                "p95 t/t_f*",
                "worst t/t_f*",
                "worst state",
                "median t/(N* T)",
                "worst t/(N* T)",
                "worst state",
            ],
            rows,
        ),
    ]
    for key in sorted(figures):
        if key.startswith("sweep"):
            blocks += image(figures, key, key.replace("_", " "))
    return blocks


def environment(res: dict[str, Any]) -> list[Block]:
    """Section 9: versions, configuration, commit, date."""
    env = res["environment"]
    rows = [[k, v] for k, v in env.items() if k != "config"]
    rows.append(["generated", res.get("meta", {}).get("generated")])
    cfg_rows = [
        [f"{sec}.{k}" if isinstance(vals, dict) else sec, v]
        for sec, vals in env["config"].items()
        for k, v in (vals.items() if isinstance(vals, dict) else [("", vals)])
    ]
    return [table(["item", "value"], rows), table(["configuration key", "value"], cfg_rows)]
