"""The catalogue of Section 6 claims: text, paper value, measurement."""

from __future__ import annotations

from .measure import (
    _Claim,
    _conclusion,
    _quicker,
    _ramp_pd_lag,
    _ramp_pto_smooth,
    _ramp_to_osc,
    _sine_delay,
    _sine_fluctuant,
    _sine_ratio,
    _sine_to,
    _step_pd_31,
    _step_pto_between,
    _step_to_osc,
)

"""Absolute floor of the numeric rule by unit: (value, words)."""


"""Reading.tracking (as reported) -> simulate's tracking mode."""


_OSC = "oscillates: last-half amplitude > 0.01 mm (a 0.01 mm/s) and >= 2 sign reversals"


CLAIMS: tuple[_Claim, ...] = (
    _Claim(
        "step-to-oscillation",
        "6.1",
        "step",
        'TO: "there exist persistent oscillations in the steady-state phase"',
        None,
        "mm",
        _OSC,
        ("a",),
        _step_to_osc,
    ),
    _Claim(
        "step-pd-31-percent",
        "6.1",
        "step",
        'PD: "with the same overshoot, it takes 31% more adjustment time than the PTO"',
        31.0,
        "%",
        "laws as configured",
        ("a", "pto", "band"),
        _step_pd_31,
    ),
    _Claim(
        "step-pto-steadier-quicker",
        "6.1",
        "step",
        'PTO: "a more stable steady-state phase compared with the TO controller and a '
        'quicker dynamic process compared with the PD controller"',
        None,
        "",
        "steady amplitude PTO < TO and settling time PTO < PD",
        ("a", "pto", "band"),
        _step_pto_between,
    ),
    _Claim(
        "ramp-to-oscillation",
        "6.2",
        "ramp",
        'TO: "there also exist series position and velocity oscillations"',
        None,
        "mm",
        _OSC + ", both position and velocity error",
        ("a", "ff"),
        _ramp_to_osc,
    ),
    _Claim(
        "ramp-pd-lag",
        "6.2",
        "ramp",
        'PD: "delays a large value about the command signal"',
        None,
        "mm",
        "mean ramp error (second half of the ramp) > d",
        ("a", "ff"),
        _ramp_pd_lag,
    ),
    _Claim(
        "ramp-pto-smooth",
        "6.2",
        "ramp",
        'PTO: "the command signal is tracked smoothly in a short time, and the state error '
        'trajectory reaches zero without any oscillation"',
        None,
        "reversals",
        "no error sign reversal outside 0.01 mm, and settles to 0.01 mm",
        ("a", "ff", "pto"),
        _ramp_pto_smooth,
    ),
    _Claim(
        "sine-to-no-delay-oscillates",
        "6.3",
        "sine",
        'TO: "there is basically no phase delay but oscillations exist"',
        None,
        "deg",
        "|delay| <= 1 deg and RMS of x1 minus fundamental > 0.01 mm",
        ("a", "ff"),
        _sine_to,
    ),
    _Claim(
        "sine-pto-delay",
        "6.3",
        "sine",
        'PTO: "the phase delay is about 4.5 deg"',
        4.5,
        "deg",
        "",
        ("a", "ff", "pto"),
        _sine_delay("pto"),
    ),
    _Claim(
        "sine-pd-delay",
        "6.3",
        "sine",
        'PD: "the phase delay with the PD controller (about 8.1 deg)"',
        8.1,
        "deg",
        "",
        ("a", "ff"),
        _sine_delay("pd"),
    ),
    _Claim(
        "sine-pto-vs-pd",
        "6.3",
        "sine",
        'PTO: its phase delay "is only 55.5% of the phase delay with the PD controller"',
        55.5,
        "%",
        "",
        ("a", "ff", "pto"),
        _sine_ratio,
    ),
    _Claim(
        "sine-to-fluctuant",
        "6.3",
        "sine",
        'Fig. 14: "the system with the TO controller is much fluctuant than that with the '
        'PD and PTO controllers"',
        None,
        "mm",
        "RMS of x1 minus fundamental: TO >= 2 x max(PD, PTO)",
        ("a", "ff", "pto"),
        _sine_fluctuant,
    ),
    _Claim(
        "conclusion-vs-to-and-pd",
        "7",
        "step",
        '"Compared with the TO, our PTO avoids oscillations and overshoots. And compared '
        'with the PD, our PTO has a shorter adjustment time"',
        None,
        "",
        "PTO does not oscillate, TO does; overshoot PTO <= 0.01 mm < TO; settling PTO < PD",
        ("a", "pto", "band"),
        _conclusion,
    ),
    _Claim(
        "conclusion-quicker-response",
        "7",
        "step",
        '"compared with the PD, our PTO has ... a quicker dynamic response"',
        None,
        "s",
        "10-90 % rise time PTO < PD",
        ("a", "pto"),
        _quicker,
    ),
)
