"""The exact ZOH flow between samples, and its monotone pieces.

Within a sample the input u_k is held, so the plant follows eq. (7) exactly::

    x2(s) = u + (x2k - u) e^{-a s}
    x1(s) = x1k + u s + (x2k - u)(1 - e^{-a s}) / a,     0 <= s <= T_k

This module holds the reference signals (:class:`Signal`), the sampled
trajectory (:class:`Trajectory`) and the machinery that splits each sample
interval into pieces on which the error e = r - x1 (or e' = r' - x2) is
monotone, so that every band crossing is unique on its piece.  The metrics
built on it are in :mod:`ptoverify.sim.settling` (settling, overshoot) and
:mod:`ptoverify.sim.exact` (rise time, linear zone, phase).
"""

from .pieces import (
    Pieces,
    bracketed_newton,
    error_derivatives,
    interval_extrema,
    monotone_pieces,
    piece_crossing,
    piece_error_derivatives,
    piece_value,
    pieces_of_intervals,
    reference_parts,
    split_intervals,
)
from .signal import Signal, Trajectory, as_float_array, as_signal, zoh_flow

__all__ = [
    "Pieces",
    "Signal",
    "Trajectory",
    "as_float_array",
    "as_signal",
    "bracketed_newton",
    "error_derivatives",
    "interval_extrema",
    "monotone_pieces",
    "piece_crossing",
    "piece_error_derivatives",
    "piece_value",
    "pieces_of_intervals",
    "reference_parts",
    "split_intervals",
    "zoh_flow",
]
