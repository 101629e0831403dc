"""The studies layer: what the suite measures about the laws (imports model and sim only).

Catalogue
---------
properties   closed-loop properties over a grid: stride-overs, limit cycles, chattering
sweep        run_sweep: settling time / t_f* and / N* T over a grid of initial states
groundtruth  verified_mintime -> GroundTruth: closed form, both OCPs and N* from one state
claims       Section 6 and conclusion claims, each measured under every reading
tune         tune PD (kp, kd) and PTO (d, k1, k2) under the same constraints
robust       robustness under model mismatch: maps, margins, worst-case search
cluster      --dask: the address checked up front, connecting to a scheduler time-boxed
checks       the gates of ``ptoverify check``
"""
