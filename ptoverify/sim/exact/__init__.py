"""Response metrics on the exact continuous trajectory, between the samples.

Within a sample the input u_k is held, so the plant follows eq. (7) exactly::

    x2(s) = u + (x2k - u) e^{-a s}
    x1(s) = x1k + u s + (x2k - u)(1 - e^{-a s}) / a,     0 <= s <= T_k

Every metric here is read on that continuous trajectory, never by
sub-sampling.  The error e(t) = r(t) - x1(t) has its extrema where
e'(s) = r'(t) - x2(s) = 0: in closed form for a step or ramp (x2(s) = r' has one
root, s* = ln((x2k - u)/(r' - u)) / a; for x1, s* = ln((u - x2k)/u) / a), and for a
sine by bracketed Newton on pieces where e' has at most one zero: e^{as} e'(s) is
monotone between the roots of cos(omega t + phi) = a (u - r'_lin)/(A omega R),
R = sqrt(a^2 + omega^2), phi = atan2(omega, a), which are closed form.  Between
its extrema e is monotone, so every band or level crossing is unique on its
piece and is found by ``brentq`` to round-off.

Definitions (the sample-grid value, returned side by side, is the same
definition restricted to the samples t_k):

* overshoot: max(0, max_t s (x1(t) - r_end)), s = sign(r_end - x1(t_0)) [mm];
* settling to a band: the last exit time of |e(t)| from the band, measured from
  t_0; 0 if never outside, NaN if the record ends outside [s] (bands: 2 % of the
  reference's size -- step height, ramp end value, sine amplitude -- and 0.01 mm);
* rise time: first time x1 reaches 90 % minus first time it reaches 10 % of the
  way from x1(t_0) to r_end [s] (step and ramp);
* linear zone: the first time the state is in {|x1 - r| <= d, |x2 - r'| <= v_max}
  (the PTO law's zone is |x1 - r| < d with v_max = inf; the grid uses the law's
  strict < d) [s];
* phase delay (sine): phase(r) - phase(x1) [deg] of the continuous least-squares
  fundamental over whole periods ending at the record's end and starting at or
  after one period: over whole periods sin, cos and 1 are orthogonal, so the fit
  is three integrals, computed per sample interval by 8-point Gauss-Legendre on
  panels with (a + omega) h <= 1.  The integrand is entire, its 16th derivative
  at most (a + omega)^16 times its scale, so the quadrature remainder is below
  2e-23 of the integral's scale: exact to round-off (no analytic antiderivative,
  whose differences would cancel for small omega h).

A metric's exact and grid values are flagged ``differs`` when they differ by
more than :data:`TIME_TOL_SAMPLES` sample periods (times), :data:`POSITION_TOL`
(overshoot) or :data:`PHASE_TOL_DEG` (phase).
"""

from ptoverify.sim.events import grid_rise_time, linear_zone_time, rise_time, sine_phase
from ptoverify.sim.flow import Signal, Trajectory, as_signal

from .batch import BatchSettling, settling_times_batch
from .response import (
    exact_metrics,
    metrics_from_arrays,
    settling_and_overshoot,
    settling_and_overshoot_many,
)
from .types import (
    METRIC_KEYS,
    PHASE_TOL_DEG,
    POSITION_TOL,
    STEP_FRACTION,
    TIGHT_BAND,
    TIME_TOL_SAMPLES,
    Compared,
    ExactMetrics,
    ResponseMetrics,
)

__all__ = [
    "Signal",
    "Trajectory",
    "as_signal",
    "grid_rise_time",
    "linear_zone_time",
    "rise_time",
    "sine_phase",
    "BatchSettling",
    "Compared",
    "ExactMetrics",
    "METRIC_KEYS",
    "PHASE_TOL_DEG",
    "POSITION_TOL",
    "ResponseMetrics",
    "STEP_FRACTION",
    "TIGHT_BAND",
    "TIME_TOL_SAMPLES",
    "exact_metrics",
    "metrics_from_arrays",
    "settling_and_overshoot",
    "settling_and_overshoot_many",
    "settling_times_batch",
]
