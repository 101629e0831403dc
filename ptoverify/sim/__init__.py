"""The simulation layer: the sampled-data loop, exact between samples, and its metrics.

Catalogue
---------
simulate  Reference (step/ramp/sine), simulate, Mismatch, simulate_batch, simulate_segments
lockstep  run_together (searches side by side, batches merged), simulate_asks
exact     metrics between samples on the exact ZOH flow: overshoot, settling, rise time
metrics   summarize, oscillation_amplitude, sign_reversals, ramp_lag, sine_fit, phase_delay
"""
