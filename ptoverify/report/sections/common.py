"""Shared pieces of the report's sections: law names, units, times in ms, figure captions."""

from __future__ import annotations

import math
import re
from typing import Any

from ptoverify.report.render import (
    Block,
    image,
    qty,
    table,
)
from ptoverify.report.words import (
    LAW_WORDS,
    claim_quantity,
    claim_value_name,
    display_unit,
    law_name,
)

__all__ = [
    "LAW_WORDS",
    "CAPTIONS",
    "figure",
    "verdict",
    "measured_quantity",
    "settling_band_words",
]

_MATH = '<math xmlns="http://www.w3.org/1998/Math/MathML" display="block">{}</math>'


def _law(name: str) -> str:
    return law_name(name)


def _ms(seconds: float | None) -> str:
    """Show a time given in s in ms."""
    if seconds is None or not math.isfinite(seconds):
        return "never"
    return qty(1e3 * seconds, "ms")


#: Caption (a sentence, also the alt text) of each figure the report can show, by file stem.
CAPTIONS: dict[str, str] = {
    "fig02_trajectories": "Fig. 2: open-loop trajectories under u = +w_max and -w_max with the "
    "switching curves l1 and l2.",
    "fig03_saturation": "Fig. 3: sampled TO trajectories from the envelope's edge, with the "
    "velocity saturating at w_max.",
    "convergence": "Relative error of the collocation minimum time against the closed form, "
    "for each state, as the number of intervals N grows.",
    "collocation_switch": "The collocation input near the switch time, beside the closed-form "
    "bang-bang input.",
    "zone_geometry": "The switching zone: l1, l2, the corrected l1* and l2*, the printed curve "
    "(19), the linear zone, and sampled PTO trajectories coloured by region.",
    "fig04_zones_corrected": "Fig. 4 redrawn with the corrected construction: the switching zone "
    "between l1 and its widened curve, and the linear zone.",
    "fig04_zones_printed": "Fig. 4 as printed (eqs. 19-27): the zone the printed omega0 gives.",
    "fig05_l1_image_corrected": "Fig. 5, corrected: the image of l1 after one sample under "
    "-w_max lies inside the corrected zone.",
    "fig05_l1_image_printed": "Fig. 5 as printed: the image of l1 after one sample against the "
    "printed curve (19).",
    "fig06_trajectory_pto": "Fig. 6 with the corrected PTO: a fourth-quadrant trajectory enters "
    "the switching zone and slides to the linear zone.",
    "fig06_trajectory_pto-printed": "Fig. 6 with the PTO as printed: the same start; the printed "
    "zone is empty, so the law acts as TO outside the linear zone.",
    "fig07_step_position": "Fig. 7: position response of every law to the 5 mm step.",
    "fig08_step_error": "Fig. 8: position error of every law after the 5 mm step.",
    "fig09_ramp_position": "Fig. 9: position tracking of the ramp, with velocity feed-forward.",
    "fig09_ramp_position_noff": "Fig. 9: position tracking of the ramp, without feed-forward.",
    "fig10_ramp_velocity": "Fig. 10: velocity during the ramp, with feed-forward.",
    "fig10_ramp_velocity_noff": "Fig. 10: velocity during the ramp, without feed-forward.",
    "fig11_ramp_error": "Fig. 11: ramp tracking error, with feed-forward.",
    "fig11_ramp_error_noff": "Fig. 11: ramp tracking error, without feed-forward.",
    "fig12_sine_position": "Fig. 12: position tracking of the sine, with feed-forward.",
    "fig12_sine_position_noff": "Fig. 12: position tracking of the sine, without feed-forward.",
    "fig13_sine_velocity": "Fig. 13: velocity while tracking the sine, with feed-forward.",
    "fig13_sine_velocity_noff": "Fig. 13: velocity while tracking the sine, without feed-forward.",
    "fig14_sine_states": "Fig. 14: error and velocity-error phase portrait on the sine, with "
    "feed-forward.",
    "fig14_sine_states_noff": "Fig. 14: error and velocity-error phase portrait on the sine, "
    "without feed-forward.",
    "sweep_ratio_tf": "Settling time over the minimum time t_f*, per law, over the envelope of "
    "initial states (the colour scale says where it clips).",
    "sweep_ratio_nt": "Settling time over the sampled limit N* T, per law, over the envelope of "
    "initial states (the colour scale says where it clips).",
    "robust_limit_cycles": "States ending in a limit cycle, per law (rows) and delay (columns), "
    "over a_true / a_design and the w_max ratio.",
    "robust_settling_nt": "Worst settling / (N* T) over the states, per law and delay (never: "
    "some state never settles).",
    "proof_bound_pto": "Certified number of samples to reach the target ellipse from each cell "
    "of the envelope, corrected PTO (interval arithmetic; red: unproven), and beside it the "
    "certified suboptimality: that bound over N* per cell.",
    "proof_bound_pd": "Certified number of samples to reach the target ellipse from each cell "
    "of the envelope, PD (interval arithmetic; red: unproven), and beside it the certified "
    "suboptimality: that bound over N* per cell.",
    "penalty_moves": "Settling time of point-to-point moves from rest against the move size, "
    "per law at the configured gains, beside t_f* and N* T (left), and its ratio to N* T "
    "(right); a law that never settles from a size has no point there.",
    "penalty_moves_tuned": "The same penalty curves with each law at its best tuning under the "
    "shared overshoot bound: settling time against move size (left) and its ratio to N* T "
    "(right).",
    "design_chart": "The coarse design chart: at each sample time and bandwidth, the law with "
    "the least median settling / (N* T) and the runner-up's ratio over it; Z marks an unusable "
    "or degenerate PTO zone, D a PTO linear zone unstable with one sample of delay.",
    "tuning_pareto": "Settling against overshoot on the step: the Pareto fronts of PD and PTO "
    "over every candidate evaluated, the best tunings (stars), the paper's gains (squares) and "
    "the floor.",
}


#: Figures drawn at the single-panel size (:data:`ptoverify.report.plots.common.SIZE`),
#: by key prefix: two of them share a row of the page (``Block.css`` ``half``).
HALF_WIDTH = ("fig", "convergence", "collocation_switch", "tuning_pareto")


def figure(figures: dict[str, str], key: str) -> list[Block]:
    """Return the figure ``key`` with its sentence caption (none when it was not drawn).

    A single-panel figure (:data:`HALF_WIDTH`) is marked to share a row with its
    neighbour, so that a pair (printed and corrected, with and without
    feed-forward) sits side by side across the content width.

    Parameters
    ----------
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    key : str
        The figure's file stem; it must have a caption in :data:`CAPTIONS`.

    Returns
    -------
    list of Block
    """
    return image(figures, key, CAPTIONS[key], "half" if key.startswith(HALF_WIDTH) else "")


# ------------------------------------------------------------------ verdict
def verdict(res: Any) -> list[Block]:
    """Show the paper's standing in one screen: the drive engineer's and the reviewer's verdicts.

    Parameters
    ----------
    res : Results
        The results (:class:`ptoverify.report.results.Results`).

    Returns
    -------
    list of Block
    """
    from ptoverify.report.standing import (
        TIE_NOTE,
        adoption,
        bandwidth_hz,
        engineer_rows,
        reviewer_rows,
        versus_note,
    )
    from ptoverify.report.standing_claims import short_legend

    note = versus_note(res)
    return [
        Block("p", text=adoption(res)),
        table(
            ["question (drive engineer)", "answer", "evidence"],
            engineer_rows(res, short=True),
            css="verdict engineer",
        ),
        table(
            ["claim of the paper (reviewer)", "standing", "condition", "paper", "measured"],
            reviewer_rows(res, short=True),
            css="verdict reviewer",
        ),
        Block(
            "p",
            text="'holds': every reading tried reproduces the claim; 'fails': none does; "
            "'depends': some do, and the condition names the readings it holds with and "
            "those it fails with. Readings: the bandwidth's a as 2 pi f or as f in rad/s, the "
            "settling band, the PTO's zone as printed or corrected, the tracking, the tuning "
            f"(see the Section 6 claims). Short words: {short_legend(bandwidth_hz(res))}.",
        ),
        *([Block("p", text=note)] if note else []),
        Block("p", text=TIE_NOTE),
    ]


# ------------------------------------------------------------------ units
def _display_unit(unit: str) -> tuple[str, float]:
    """Return the unit a claim's number is shown in (:func:`ptoverify.report.words.display_unit`)."""
    return display_unit(unit)


def measured_quantity(c: dict[str, Any]) -> str:
    """Describe what a claim's 'measured' number is, in words with its unit.

    The name of the value that equals the headline number (units in the names:
    ``phase_delay_deg`` -> "phase delay [deg]"; times shown in ms).

    Parameters
    ----------
    c : dict
        A claim of ``results["claims"]``.

    Returns
    -------
    str
    """
    if c["measured"] is None:
        return "qualitative (no single number; see detail)"
    unit, _ = _display_unit(c["unit"])
    return f"{claim_value_name(c) or 'value'} [{unit or '-'}]"


def _claim_qty(v: float | None, unit: str) -> str:
    return claim_quantity(v, unit)


def _same(a: float | None, b: float | None) -> bool:
    if a is None or b is None:
        return a is b
    return abs(a - b) <= 1e-9 * max(abs(a), abs(b), 1e-300)


# ------------------------------------------------------------------ summary
_GATE_UNITS = {"1": "-", "": "-"}


def _downstream_ids(inherits: list[str]) -> list[str]:
    """Return the equation labels ('17', '20-27', '36, 35') that an erratum changes."""
    out = []
    for item in inherits:
        head, _, what = item.partition(":")
        if re.fullmatch(r"[\w\-, ]+", head.strip()) and not what.strip().startswith("unchanged"):
            out.append(head.strip())
    return out


def settling_band_words(name: str, fallback: str) -> str:
    """Return a named settling definition as its band and hold, in words.

    Parameters
    ----------
    name : str
        A name of :data:`ptoverify.sim.settling.DEFINITIONS`.
    fallback : str
        What to say for a name that is not there.

    Returns
    -------
    str
        ``abs(e) <= 0.01 mm, abs(e') <= a * 0.01 mm [mm/s], held 50 ms``.
    """
    from ptoverify.sim.settling import DEFINITIONS

    d = DEFINITIONS.get(name)
    if d is None:
        return fallback
    held = f", held {_ms(d.hold_s)}" if d.hold_s > 0 else ""
    return d.band_text() + held
