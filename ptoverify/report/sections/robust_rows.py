"""Rows of the robustness margins table for the baselines (PTOS, the cascade P loop).

Beside the mapped laws' margins (``robust.margins``), the table shows each
baseline at the configured gains (``robust.baseline_margins``, computed in the
robustness stage without maps or search) and at its fair tuning under the
configuration's reading of a (``tuning.versus``, reading ``2pi``: the
configuration as loaded); the linear-loop margins only (eigenvalues, without and
with a one-sample delay; the simulated no-limit-cycle margin is not run for
them, to keep the report's cost small).  Nothing here computes.
"""

from __future__ import annotations

from typing import Any

from ptoverify.report.render import fmt
from ptoverify.report.standing import ratio_interval

from .common import _law

__all__ = ["baseline_margin_rows"]

#: Units of the gains shown in a row label (names of ``ptoverify.studies.tune.BOUNDS``).
_GAIN_UNITS = {"alpha": "", "k": " 1/s", "kp": " 1/s"}


#: The no-limit-cycle cell of a baseline's row: the simulated margin is not run for them.
_NOT_SIMULATED = "not simulated (eigenvalue margins only)"


def _gains(g: Any) -> str:
    return ", ".join(f"{k} {fmt(v)}{_GAIN_UNITS.get(k, '')}" for k, v in g.items())


def _interval(iv: Any, note: str) -> str:
    return ratio_interval(iv) if iv else note


def baseline_margin_rows(res: Any) -> list[list[str]]:
    """Rows (law, linear loop, with one-sample delay, no limit cycle) for the baselines.

    Parameters
    ----------
    res : Results
        The results (``robust.baseline_margins``; ``tuning`` may be None when skipped).

    Returns
    -------
    list of list of str
        The configured-gain rows, then the fair-tuned rows (none when the tuning
        was skipped or a baseline's tuning was infeasible).
    """
    rows = []
    for law, m in res["robust"]["baseline_margins"].items():
        rows.append(
            [
                f"{_law(law)} (configured gains: {_gains(m['gains'])})",
                _interval(m["linear_loop_a_ratio_stable"], m["linear_loop_note"] or "n/a"),
                _interval(
                    m["linear_loop_a_ratio_stable_delay1"], m["linear_loop_note_delay1"] or "n/a"
                ),
                _interval(m["no_limit_cycle_a_ratio"], m["no_limit_cycle_note"] or "n/a")
                if "no_limit_cycle_a_ratio" in m
                else _NOT_SIMULATED,
            ]
        )
    tuning = res["tuning"]
    if not tuning:
        return rows
    mapped = set(res["robust"]["baseline_margins"])
    for rd in tuning["versus"]["readings"]:
        if rd["reading"] != "2pi":  # the configuration as loaded
            continue
        for t in rd["laws"]:
            if t["law"] not in mapped or t["infeasible"]:
                continue
            unstable = "unstable at the design point"
            rows.append(
                [
                    f"{_law(t['law'])} (fair-tuned: {_gains(t['gains'])})",
                    _interval(t["a_ratio_stable"], unstable),
                    _interval(t["a_ratio_stable_delay1"], unstable),
                    _NOT_SIMULATED,
                ]
            )
    return rows
