"""The model layer: plant, curves, zones, laws, minimum time, poles (imports no other layer).

Catalogue
---------
plant     flow (eq. 7), step (one-sample map, eq. 15), zoh_matrices
curves    switching_function, level_residual (eqs. 9, 11, 13, 14, 28, 33), Lambert-W roots
          root_22 (eq. 22), root_k (eqs. 26, 31), omega_c (eq. 32)
zones     PTOZone; printed_zone (eqs. 19-27 as printed), corrected_zone, zone_summary
laws      Law (one vector path; one state is an array of one), Region; to_law (eq. 12),
          pd_law, pto_law (eq. 35: pto, pto-printed); make_law, with_state_gains
baselines ptos_law (Workman's PTOS on this plant), cascade_law (saturated P); registered
          with make_law when this package is imported (below)
mintime   min_time (closed form), discrete_min_steps (N* by LPs), discrete_min_steps_batch
reach     ZonotopeTable, zonotope_steps: N-step null-controllable sets as 2-D zonotopes
ocp       TwoPhaseOCP, CollocationOCP (CasADi + IPOPT), convergence_study
poles     PD and linear-zone (eq. 37) loops: poles, damping, margins (python-control)
memo      memo, clear_memos: the one memo mechanism, keyed on configuration objects
intervals outward-rounded interval arithmetic on NumPy arrays; log1p, h(r) by bounded series
lawbox    LawSpec, enclose: the laws enclosed over boxes of states (``prove``)
zohmaps   step_maps, affine_image, linear_image: the j-step ZOH maps enclosed for a point
          or an interval of a (``prove``)
"""

# the baselines import laws and register their names with make_law; importing them here
# (not from laws, which would be a cycle) makes make_law("ptos") work wherever laws is used
from ptoverify.model import baselines as _baselines  # noqa: E402, F401
