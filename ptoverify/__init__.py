"""ptoverify: a verification suite for a proximate time-optimal (PTO) control law.

Plant (eq. 1): x1' = x2, x2' = -a x2 + a u, |u| <= w_max, sampled every T with ZOH.

Catalogue (flat modules, one concept each, listed by layer; data flows downward)
---------
The package stays flat, as DESIGN.md asks (python-control's style): the layers
below are a reading order, not subpackages.  Where an equation lives: eqs. 1, 7,
15 plant; 8-14, 22, 26, 28-33 curves; 16-27 zones (and derivations/); 12, 34, 35
laws; 36-39 poles; minimum time mintime/reach/ocp.

Inputs and vocabulary
config      Plant, PDGains, PTOSettings, Robustness ([robustness] box), Config; TOML
            loading and validation (ranges named per key); paper defaults
verdict     Verdict (PASS, FAIL, UNVERIFIED, NOT_RUN), at_most, tie_band (defined once)
errors      InputError (exit 2), ConfigError, SolverError
counts      plural: a count with its noun in the right number (every layer's sentences)

Plant, curves and ground truth
plant       flow (eq. 7), step (one-sample map, eq. 15), zoh_matrices
curves      switching_function, level_residual (eqs. 9, 11, 13, 14, 28, 33), Lambert-W roots
            root_22 (eq. 22), root_k (eqs. 26, 31), omega_c (eq. 32), bisection references
mintime     min_time: closed-form minimum time and switch time from any state;
            discrete_min_steps (N*, the discrete-time limit, by LPs), ZOHReach;
            discrete_min_steps_batch (N* for many states by zonotopes, see reach);
            batch_table (mintime --states)
reach       ZonotopeTable, zonotope_steps: N-step null-controllable sets as 2-D zonotopes;
            zonotope_steps_each (a plant per state)
ocp         TwoPhaseOCP, CollocationOCP (CasADi + IPOPT), convergence_study
groundtruth verified_mintime -> GroundTruth: closed form, both OCPs and N* from one state, each
            OCP answer checked a posteriori (exact-flow arcs, re-simulated collocation) or
            null; verify_two_phase, verify_collocation (used by mintime, report and check)

Laws
zones       PTOZone; printed_zone (eqs. 19-27 as printed, judged), corrected_zone (largest
            omega0 meeting the no-stride-over principle, verified on a grid), zone_summary
laws        Law, Region; to_law (eq. 12), pd_law, pto_law (eq. 35: pto, pto-printed); make_law
poles       PD and linear-zone (eq. 37) loops: poles, damping, margins (python-control), Lyapunov

Closed loop and metrics
simulate    Reference (step/ramp/sine, custom), simulate (tracking: feedforward, none, error;
            results carry their reference), Mismatch, simulate_batch (true plant, delay,
            quantization, noise), simulate_parts (several laws and mismatches, one run)
lockstep    run_together: searches side by side, their batches merged (threads);
            simulate_asks: asks simulated in few simulate_parts runs (robust, tune)
exact       metrics between samples on the exact ZOH flow: overshoot, settling (last exit),
            rise time, linear-zone entry, sine phase; exact and sample-grid values side by side
metrics     summarize (exact metrics with their grid twins), oscillation_amplitude,
            sign_reversals, ramp_lag, sine_fit/phase_delay, input_switches
properties  closed-loop properties over a grid: stride-overs (crossing_masks,
            stride_over_counts), limit cycles, chattering, overshoot
sweep       run_sweep: settling time / t_f* and / N* T over a 200 x 200 grid of initial states

Verdicts and studies
claims      Section 6 and conclusion claims, each measured under every reading
            (a = 2 pi f or f, feed-forward, PTO printed/corrected, band); evaluate_claims
checks      the gates of ``ptoverify check``: GATES (each a Verdict with a unit), GateContext
            (the run's options, e.g. the IPOPT cap), run_checks, summarize, ROBUST_GATES
robust      robustness under model mismatch: maps over the box, margins in a_true / a_design,
            worst-case search (differential evolution), Dask runner, robust gates
tune        tune PD (kp, kd) and PTO (d, k1, k2) under the same constraints; Pareto fronts
conform     conform: gate a third-party PTO law (callable or table) against the reference
agreement   conformance grid (--emit-grid), CSV tables, per-region agreement with the reference
conform_evidence  the evidence behind a conform verdict (conform --report): |u - u_ref| maps,
            region boundaries, responses of the user law, settling / N* T
userlaw     loading a user law (MODULE:FUNCTION or file.py:FUNCTION), isolated in a child
            process, vectorized/scalar detection
testing     assert_conforms, for a team's own pytest suite

Output
commands    the numeric side of commands that compose several steps: run_simulation
            (simulate), run_regulation (simulate --x0), run_zone, run_robust_study,
            mintime_states
plots       Figs. 2-14 for TO, PD, PTO (both), sweep heat maps, zone geometry, collocation
            convergence, drawn from results passed in (report/plots/: the only package
            importing matplotlib; Figure + savefig, no pyplot, no backend switch)
report      collect (every result once, figure_inputs), write_report (atomic);
            report_sections builds the sections; render prints them (HTML, Markdown)
conform_report  conform --report DIR: the user's law as an atomic HTML/Markdown/JSON report
junit       JUnit XML from verdicts (check --junit, conform --junit)
outdir      atomic output folders with a manifest marker; SIGTERM handling
progress    the one progress bar on stderr
cli         the ``ptoverify`` command line: parses, calls one function per command, formats
"""

__version__ = "0.1.0"
