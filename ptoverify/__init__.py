"""ptoverify: a verification suite for a proximate time-optimal (PTO) control law.

Plant (eq. 1): x1' = x2, x2' = -a x2 + a u, |u| <= w_max, sampled every T with ZOH.

Catalogue
---------
config      Plant, PDGains, PTOSettings, Config; TOML loading and validation; paper defaults
plant       flow (eq. 7), step (one-sample map, eq. 15), zoh_matrices
curves      switching_function, level_residual (eqs. 9, 11, 13, 14, 28, 33), Lambert-W roots
            root_22 (eq. 22), root_k (eqs. 26, 31), omega_c (eq. 32), bisection references
mintime     min_time: closed-form minimum time and switch time from any state;
            discrete_min_steps (N*, the discrete-time limit, by LPs), ZOHReach
ocp         TwoPhaseOCP, CollocationOCP (CasADi + IPOPT), convergence_study
zones       PTOZone; printed_zone (eqs. 19-27 as printed, judged), corrected_zone (largest
            omega0 meeting the no-stride-over principle, verified on a grid), zone_summary
laws        Law, Region; to_law (eq. 12), pd_law, pto_law (eq. 35: pto, pto-printed); make_law
simulate    simulate (sampled closed loop on step/ramp/sine), simulate_batch
properties  closed-loop properties over a grid: stride-overs, limit cycles, chattering, overshoot
poles       PD and linear-zone (eq. 37) loops: poles, damping, margins (python-control), Lyapunov
metrics     settling_time (2 % and 0.01 mm bands), overshoot, oscillation_amplitude,
            sign_reversals, ramp_lag, sine_fit/phase_delay (whole periods), rise_time,
            time_to_linear_zone, input_switches, summarize
claims      Section 6 and conclusion claims, each measured under every reading
            (a = 2 pi f or f, feed-forward, PTO printed/corrected, band); evaluate_claims
sweep       run_sweep: settling time / t_f* and / N* T over a 50 x 50 grid of initial states
plots       Figs. 2-14 for TO, PD, PTO (both), sweep heat maps, zone geometry, collocation
            convergence, drawn from results passed in (the only module importing matplotlib)
checks      the gates of ``ptoverify check``: CheckResult, GATES, run_checks
report      collect (every result once, figure_inputs), write_report (atomic);
            report_sections builds the nine sections; render prints them (HTML, Markdown)
conform     conform: gate a third-party PTO law (callable or table) against the reference
agreement   conformance grid (--emit-grid), CSV tables, per-region agreement with the reference
userlaw     loading a user law (MODULE:FUNCTION or file.py:FUNCTION), vectorized/scalar detection
cli         the ``ptoverify`` command line
errors      InputError (exit 2), ConfigError, SolverError
"""

__version__ = "0.1.0"
