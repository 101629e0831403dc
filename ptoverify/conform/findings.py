"""The failure entry every property of ``conform`` reports (no numerics imported).

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions).  Here on its own so that the law's isolated process
(:mod:`ptoverify.conform.isolation`, :mod:`ptoverify.conform.userlaw`) loads
only what wrapping and calling a law needs: the reference law, the curves and
SciPy load there only when the user's law imports them.
"""

from __future__ import annotations

__all__ = ["failure"]


def failure(prop: str, state, detail: str, **extra) -> dict:
    """Return a failure entry: property, state [x1, x2], detail (and extra keys).

    Parameters
    ----------
    prop : str
        The property (or ``evaluation``, ``isolation``).
    state : sequence of 2 floats
        The first state that shows it, x1 [mm], x2 [mm/s].
    detail : str
        What failed.
    **extra
        More keys (``sample``, ``at``).

    Returns
    -------
    dict

    Examples
    --------
    >>> failure("agreement", (1, -2.5), "too far")
    {'property': 'agreement', 'state': [1.0, -2.5], 'detail': 'too far'}
    """
    return {
        "property": prop,
        "state": [float(state[0]), float(state[1])],
        "detail": detail,
        **extra,
    }
