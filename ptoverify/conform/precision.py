"""Precision modes of ``conform``: what the implementation computes in (``--precision``).

``float64`` (the default) judges the law as a double-precision function of the
state.  ``float32`` judges it as firmware that computes in single precision:

The state as the implementation sees it
    The implementation rounds the state to float32 before anything else, so the
    reference is evaluated at ``x32 = fl32(x)`` (:func:`as_seen`), not at x.  A
    state 1e-9 mm inside the linear zone that rounds onto its edge is judged at
    the edge; that is what the firmware computed from.

Ties at float32 resolution (:func:`float32_ties`)
    Where u jumps (by up to 2 w_max) at a region boundary, a float32 evaluation
    of the boundary test may land on either side.  A state whose boundary test
    is within its float32 rounding error of zero is a tie: either side's value
    is accepted there, and the state is excluded from the agreement and counted,
    as the float64 curve ties are.  The band is the forward error bound of the
    test in the standard model fl(a op b) = (a op b)(1 + t), |t| <= u,
    u = 2^-24 (half of float32 epsilon), to first order in u:

    * the linear-zone edge |x1| = d: the state is already rounded, so only d's
      own rounding d32 = fl32(d) moves the edge: a tie where |x1| lies between
      d and d32 (inclusive; empty when d is a float32);
    * a level-omega curve (l1/l2 at omega = w_max, l1*/l2* at omega = omega0),
      residual r = a x1 + sgn(x2) omega h(s), s = |x2| / omega,
      h(s) = s - ln(1 + s): rounding a and the product a x1 gives at most
      2 u a |x1|; rounding omega and the quotient moves s by 2 u s, which moves
      omega h(s) by omega h'(s) 2 u s <= 2 u |x2| (h'(s) = s / (1 + s) <= 1: the
      boundary's slope in x2); log1p within one ulp and the subtraction in h,
      the product with omega (rounded) add at most u omega (2 ln(1 + s) + 3 h(s))
      <= 5 u |x2| (ln(1 + s) <= s, h(s) <= s); the final sum u |r|.  So
      |fl32(r) - r| <= u (2 a |x1| + 7 |x2| + |r|), and a state with
      |r| <= u (2 a |x1| + 7 |x2|) / (1 - u) is a tie (outside |x1| < d, where
      the curves decide).  In position, the band is that over the slope
      dr/dx1 = a of the boundary.

Everything else the float32 implementation computes (the linear zone's
-k1 x1 - k2 x2, omega_c inside the zone) is continuous in the state and is
judged to the agreement tolerance, like a float64 law.  The tie band of a
float64 law is :func:`ptoverify.verdict.tie_band` (1e-9 (w_max + a
position_range) around the curves); in float32 mode both bands are excluded.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.errors import InputError

__all__ = ["PRECISIONS", "UNIT_ROUNDOFF_32", "check_precision", "as_seen", "float32_ties"]

PRECISIONS = ("float64", "float32")  #: the precision modes of ``--precision``
UNIT_ROUNDOFF_32 = float(np.finfo(np.float32).eps) / 2.0  #: u = 2^-24 [-]


def check_precision(precision: str) -> str:
    """Return ``precision`` when it is a mode of :data:`PRECISIONS`.

    Parameters
    ----------
    precision : str
        ``float64`` or ``float32``.

    Returns
    -------
    str
        The mode.

    Raises
    ------
    InputError
        Any other value (one line).

    Examples
    --------
    >>> check_precision("float32")
    'float32'
    """
    if precision not in PRECISIONS:
        raise InputError(f"--precision must be one of {', '.join(PRECISIONS)}, got {precision!r}")
    return precision


def as_seen(x1: NDArray, x2: NDArray, precision: str) -> tuple[NDArray, NDArray]:
    """Return the state as an implementation in ``precision`` sees it (float64 arrays).

    Parameters
    ----------
    x1, x2 : ndarray
        States [mm], [mm/s].
    precision : str
        A mode of :data:`PRECISIONS`.

    Returns
    -------
    x1, x2 : ndarray
        Rounded to float32 (``float32``) or unchanged [mm], [mm/s].

    Examples
    --------
    >>> float(as_seen(np.array([0.1]), np.array([0.0]), "float32")[0][0])
    0.10000000149011612
    """
    if precision == "float32":
        return (
            np.asarray(x1, dtype=np.float32).astype(float),
            np.asarray(x2, dtype=np.float32).astype(float),
        )
    return x1, x2


def float32_ties(x1: NDArray, x2: NDArray, cfg: Config, omega0: float | None) -> NDArray[np.bool_]:
    """States (as seen in float32) within float32 resolution of a region boundary.

    Parameters
    ----------
    x1, x2 : ndarray
        States as the implementation sees them (:func:`as_seen`) [mm], [mm/s].
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], d [mm]).
    omega0 : float or None
        Level of l1*, l2* [mm/s] (None: no switching zone).

    Returns
    -------
    ndarray of bool
        Ties at the linear-zone edge and at the curves (module docstring).
    """
    from ptoverify.model.curves import level_residual

    a, w, d = cfg.plant.a, cfg.plant.w_max, cfg.pto.d
    u = UNIT_ROUNDOFF_32
    d32 = float(np.float32(d))
    ax = np.abs(x1)
    tie = (ax >= min(d, d32)) & (ax <= max(d, d32)) & (d != d32)
    band = u * (2.0 * a * ax + 7.0 * np.abs(x2)) / (1.0 - u)
    near = np.abs(level_residual(x1, x2, a, w)) <= band
    if omega0 is not None:
        near |= np.abs(level_residual(x1, x2, a, omega0)) <= band
    return tie | (near & (ax >= min(d, d32)))
