"""Switching zone of the PTO law, Section 4: as printed (eqs. 19-27) and corrected.

Geometry (fourth quadrant, x2 = -s < 0).  The level-omega curve through the
origin is a x1 = omega h(s / omega) (eqs. 9, 13, 28); omega h(s/omega) falls as
omega grows, so for omega0 < w_max the boundary l1* lies right of l1 and the
zone S~_P = {sigma_w >= 0, residual_omega0 <= 0, x2 < 0} is the band a state
coming from the right under u = -w_max meets first.  S~_N is its mirror image.

The principle (Section 4, rules 1 and 2; Section 7)
---------------------------------------------------
"A sampled state must enter the zone but not stride over it."  On the exact
one-sample map F_u of the ZOH plant (eq. 7 held for T) it reads, for the
fourth quadrant:

    for every state x with |x1| >= d and |x2| <= w_max that lies in S_N u l2
    on or outside l1* (where eq. 35 applies u = -w_max; l1* itself is included
    as the closure of that set, as rule 1 states it for points of l1*),
    the state F_{-w_max}(x) one sample later satisfies sigma(F) >= 0, i.e. it is
    on or right of l1 (in the zone, on l1, or still in S_N).

Mirror (rule 2): states with |x1| >= d in S_P u l1 outside l2*, after one
sample of +w_max, satisfy sigma <= 0.  The plant is odd, F_{-u}(-x) = -F_u(x),
and sigma(-x) = -sigma(x), so the mirror holds exactly when the rule above
does; it is checked once and the mirror is tested separately.

Decisions, and why:

* Sources are restricted to the envelope |x2| <= w_max: that set is invariant
  under |u| <= w_max, so no state beyond it is ever sampled.
* Sources inside the linear zone |x1| < d are exempt (eq. 35 applies the linear
  law there; the paper places the linear zone "left of the intersection").
* Landing: ``reading="strict"`` (the default, used by the ``pto`` law) demands
  sigma(F) >= 0 even when F lies inside the linear zone, as rule 1 literally
  does ("(x~1, x~2) should stay above the curve l1").  ``reading="lenient"``
  also accepts any landing with |F1| < d.  The lenient reading is reported
  too: at the paper's defaults l1 lies inside |x1| < d over the whole envelope,
  so the lenient principle already holds with no zone at all (omega0 = w_max),
  while the time-optimal law then lands in the linear zone at nearly -w_max on
  the wrong side of l1; that reading cannot be what the zone is for.
* A tolerance of :func:`ptoverify.verdict.tie_band` [mm/s] on sigma absorbs
  round-off for states that ride a curve exactly.

Exact per-velocity test.  At fixed x2, F1 = x1 + c(x2) and F2 do not depend
on x1 otherwise, so sigma(F(x1, x2)) is strictly increasing in x1; the worst
source at each velocity is the left end of each x1-interval of the source set
(for the lenient reading, of each interval cut at F1 = +-d).  This is how a
candidate omega0 is decided (dense in x2); a 2-D grid over the envelope and
over the band just outside l1* verifies the result without that argument.
The same argument shows the margin cannot fall as omega0 falls (l1* moves
right); the scan over (0, w_max] does not rely on it.
"""

from .corrected import corrected_zone, smallest_d
from .margins import principle_margin, principle_violations
from .printed import printed_zone
from .summary import clear_caches, zone_for_law, zone_summary
from .types import READINGS, PTOZone

__all__ = [
    "PTOZone",
    "READINGS",
    "clear_caches",
    "corrected_zone",
    "principle_margin",
    "principle_violations",
    "printed_zone",
    "smallest_d",
    "zone_for_law",
    "zone_summary",
]
