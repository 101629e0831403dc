"""ptoverify: a verification suite for a proximate time-optimal (PTO) control law.

Plant (eq. 1): x1' = x2, x2' = -a x2 + a u, |u| <= w_max, sampled every T with ZOH.

Catalogue
---------
config      Plant, PDGains, PTOSettings, Config; TOML loading and validation; paper defaults
plant       flow (eq. 7), step (one-sample map, eq. 15), zoh_matrices
curves      switching_function, level_residual (eqs. 9, 11, 13, 14, 28, 33), Lambert-W roots
            root_22 (eq. 22), root_k (eqs. 26, 31), omega_c (eq. 32), bisection references
mintime     min_time: closed-form minimum time and switch time from any state;
            discrete_min_steps (N*, the discrete-time limit, by LPs), ZOHReach;
            discrete_min_steps_batch (N* for many states by zonotopes, see reach)
reach       ZonotopeTable, zonotope_steps: N-step null-controllable sets as 2-D zonotopes
ocp         TwoPhaseOCP, CollocationOCP (CasADi + IPOPT), convergence_study
groundtruth verified_mintime -> GroundTruth: closed form, both OCPs and N* from one state, each
            OCP answer checked a posteriori (exact-flow arcs, re-simulated collocation) or
            null; verify_two_phase, verify_collocation (used by mintime, report and check)
zones       PTOZone; printed_zone (eqs. 19-27 as printed, judged), corrected_zone (largest
            omega0 meeting the no-stride-over principle, verified on a grid), zone_summary
laws        Law, Region; to_law (eq. 12), pd_law, pto_law (eq. 35: pto, pto-printed); make_law
simulate    simulate (sampled closed loop on step/ramp/sine), simulate_batch
properties  closed-loop properties over a grid: stride-overs, limit cycles, chattering, overshoot
poles       PD and linear-zone (eq. 37) loops: poles, damping, margins (python-control), Lyapunov
metrics     settling_time (2 % and 0.01 mm bands), overshoot, oscillation_amplitude,
            sign_reversals, ramp_lag, sine_fit/phase_delay (whole periods), rise_time,
            time_to_linear_zone, input_switches, summarize
exact       metrics between samples on the exact ZOH flow: overshoot, settling (last exit),
            rise time, linear-zone entry, sine phase; exact_metrics / metrics_from_arrays give
            exact and sample-grid values side by side (ExactMetrics, Compared)
claims      Section 6 and conclusion claims, each measured under every reading
            (a = 2 pi f or f, feed-forward, PTO printed/corrected, band); evaluate_claims
sweep       run_sweep: settling time / t_f* and / N* T over a 200 x 200 grid of initial states
plots       Figs. 2-14 for TO, PD, PTO (both), sweep heat maps, zone geometry, collocation
            convergence, drawn from results passed in (the only module importing matplotlib)
checks      the gates of ``ptoverify check``: GATES (each a Verdict with a unit), GateContext
            (the run's options, e.g. the IPOPT cap), run_checks, summarize, ROBUST_GATES
report      collect (every result once, figure_inputs), write_report (atomic);
            report_sections builds the nine sections; render prints them (HTML, Markdown)
conform     conform: gate a third-party PTO law (callable or table) against the reference
agreement   conformance grid (--emit-grid), CSV tables, per-region agreement with the reference
userlaw     loading a user law (MODULE:FUNCTION or file.py:FUNCTION), vectorized/scalar detection
commands    the numeric side of commands that compose several steps: run_simulation
            (simulate), run_zone (zone)
cli         the ``ptoverify`` command line: parses, calls one function per command, formats
verdict     Verdict (PASS, FAIL, UNVERIFIED, NOT_RUN), at_most, tie_band
errors      InputError (exit 2), ConfigError, SolverError
"""

__version__ = "0.1.0"
