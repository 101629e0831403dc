"""The simulation layer: the sampled-data loop, exact between samples, and its metrics.

Catalogue
---------
reference  Reference (step/ramp/sine), SIGNALS, reference
simulate   simulate, Mismatch, simulate_batch (the one loop), simulate_parts
lockstep   run_together (searches side by side, batches merged), simulate_asks
flow       Signal, Trajectory and the monotone pieces of the exact ZOH flow
settling   SettlingDefinition, DEFINITIONS, settling_time, overshoot (named definitions)
events     rise time, linear-zone entry, sine phase between samples
exact      exact_metrics: every metric between samples and on the grid (Compared)
metrics    summarize, oscillation_amplitude, sign_reversals, ramp_lag, sine_fit, phase_delay
runs       run_simulation: the path of ``ptoverify simulate``
"""
