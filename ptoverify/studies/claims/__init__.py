"""Claims registry of Section 6 and the conclusion, with computed verdicts.

Each claim holds the paper's wording (and number, where it gives one); the
paper's values live only here.  The measured value is computed by simulating
the sampled closed loop (:func:`~ptoverify.sim.simulate.simulate`) and applying
:mod:`ptoverify.sim.metrics`; nothing in the measured column is typed in.

Readings
--------
Where the paper is ambiguous, each claim is measured under every reading
that can touch it, and each reading gets its own verdict:

* ``a``: "velocity loop bandwidth is 30Hz" read as a = 2 pi 30 rad/s (the
  suite's default) or as a = 30 rad/s.  Only when the configuration gives the
  bandwidth in Hz; a configuration that gives ``a`` has one reading.
* ``tracking`` (ramp and sine claims only; the step's reference velocity is 0):
  how the laws, written for regulation to the origin, track a moving reference.
  ``feed-forward``: the law sees the error state (x1 - r, x2 - r') and r' is
  added to its input (``simulate(tracking="feedforward")``); ``none``: the law
  sees (x1 - r, x2), nothing is added (``simulate(tracking="none")``);
  ``error``: the law sees the error state (x1 - r, x2 - r') and nothing is
  added, i.e. a PD on the error e and its derivative, the textbook PD
  (``simulate(tracking="error")``).  One simulator serves all three.
* ``pto``: PTO with the corrected zone (``pto``) or as printed (``pto-printed``),
  for the claims that involve PTO.
* ``band``: the settling band of "adjustment time", 2 % or 5 % of the step
  (claims that compare settling times).

The primary reading is the first of each: a = 2 pi f, feed-forward, PTO
corrected, 2 % band.  A claim's overall verdict is the common verdict of its
readings, and ``ambiguous`` when they disagree.

Verdict rules (decided here, the paper gives none)
--------------------------------------------------
The paper's numbers live once, in the registry entry's ``paper_value``: the
verdicts and the rule texts read them from there.

* A numeric claim "about X" is ``reproduced`` when |measured - X| <= max(20 % of
  |X|, floor), with floor 1 deg for phase delays and 5 percentage points for
  percentages; otherwise ``not reproduced``.
* "Oscillates" (persistent, in steady state): over the last half of the record
  the signal's half peak-to-peak exceeds the tight band (0.01 mm for
  positions, a * 0.01 mm/s for velocities) and it reverses sign at least twice
  outside that band.  "Without oscillation": no sign reversal of the error
  outside +-0.01 mm over the whole record.
* "Basically no phase delay": |delay| <= 1 deg (the floor above).
* "Much more fluctuant": the RMS of x1 minus its fitted fundamental is at least
  twice that of each other law.
* "Lags by a large value": the mean ramp error exceeds d, the paper's linear
  zone (1 % of the position range, its own scale for "close to the target").
* "Faster", "more stable", "quicker": strict inequalities of the metric; for
  times (settling, rise) under the suite's one tie rule
  (:data:`ptoverify.verdict.TIME_TIE_RULE`, :func:`ptoverify.verdict.time_order`),
  the rule the report states and its verdict table uses: two times less than one
  sample period T apart tie.
* Time metrics (settling, rise time), overshoots and phase delays are measured
  between the samples, on the exact continuous trajectory
  (:mod:`ptoverify.sim.exact`), and every verdict is decided on those values.  Two
  exact times less than one sample apart (or closer than the sum of their
  accuracies, :attr:`Compared.accuracy <ptoverify.sim.exact.Compared.accuracy>`)
  are a tie: the strict inequality does not hold, and the reading lists the tie in
  ``ties`` and
  its detail.  The same rule is also applied to the sample-grid values (which
  tie when equal, at one sample); each reading carries ``measured_grid``,
  ``values_grid``, ``verdict_grid`` and ``verdict_differs_on_grid``, so a reader
  sees where reading the samples would have decided otherwise.  Oscillation
  amplitudes, sign reversals, ramp lag and the fit residual stay properties of
  the sampled sequence.
* A qualitative claim whose metric cannot be measured (a law never settles)
  is ``not reproduced`` under that reading, and the detail says why.

"At the same overshoot" (Sec. 6.1): under the paper-gain readings the laws are
compared as configured (the paper's gains), both overshoots reported beside the
time ratio.  With ``evaluate_claims(tuned=True)`` the claims of
:data:`TUNED_CLAIMS` get three more readings (``Reading.gains``), each under the
primary reading otherwise: the PD retuned (best 2 % settling of the step) to the
PTO's paper-gain overshoot, the PTO at the paper's gains; and both laws at their
best tuning (:func:`ptoverify.studies.tune.fair_tunings`) under a shared overshoot bound,
once the PTO's paper-gain overshoot and once the PD's.  Their common verdict is
``verdict_tuned``; ``verdict`` stays that of the paper's gains.
"""

from .catalogue import CLAIMS
from .evaluate import evaluate_claims
from .sentences import TUNED_CLAIMS
from .tuned import fair_comparison, response_metrics
from .types import (
    MUCH,
    PERCENT_FLOOR,
    PHASE_FLOOR_DEG,
    REL_TOL,
    VERDICTS,
    ClaimResult,
    Outcome,
    Reading,
    ReadingResult,
    numeric_verdict,
)

__all__ = [
    "CLAIMS",
    "ClaimResult",
    "MUCH",
    "Outcome",
    "PERCENT_FLOOR",
    "PHASE_FLOOR_DEG",
    "REL_TOL",
    "Reading",
    "ReadingResult",
    "TUNED_CLAIMS",
    "VERDICTS",
    "evaluate_claims",
    "fair_comparison",
    "numeric_verdict",
    "response_metrics",
]
