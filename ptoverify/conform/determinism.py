"""The determinism check of ``conform`` (``pure-function``): a law must have no memory.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions, "Determinism"): on ``N_DETERMINISM`` states the same batch twice,
shuffled and in chunks must give bit-identical u; a latch, a cache, a delay or
a call counter shows here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.agreement import RANDOM_SEED, failure, ties

__all__ = ["N_DETERMINISM", "determinism_states", "determinism", "differs"]

N_DETERMINISM = 2000  #: states of the determinism check
_CHUNKS = (1, 2, 3, 5, 8, 13, 21, 34)  #: chunk sizes of the determinism check, cycled


def determinism_states(cfg: Config, grid: tuple[NDArray, NDArray]) -> tuple[NDArray, NDArray]:
    """Return probe-like states: grid points on/near curves and edges, and random states.

    Parameters
    ----------
    cfg : Config
        Configuration.
    grid : (x1, x2)
        The conformance grid [mm], [mm/s].

    Returns
    -------
    x1, x2 : ndarray
        ``N_DETERMINISM`` states [mm], [mm/s] (seeded).
    """
    rng = np.random.default_rng(RANDOM_SEED + 1)
    g1, g2 = grid
    tie = ties(g1, g2, cfg)
    pick = np.concatenate(
        [
            rng.choice(np.flatnonzero(tie), min(200, int(tie.sum())), replace=False),
            rng.choice(g1.size, min(N_DETERMINISM // 2, g1.size), replace=False),
        ]
    )
    n = N_DETERMINISM - pick.size
    R, w = cfg.plant.position_range, cfg.plant.w_max
    x1 = np.concatenate([g1[pick], rng.uniform(-R, R, n)])
    x2 = np.concatenate([g2[pick], rng.uniform(-w, w, n)])
    return x1, x2


def determinism(user, x1: NDArray, x2: NDArray) -> tuple[NDArray, list[dict]]:
    """Call the law on the same states twice, shuffled and in chunks; all must agree.

    Parameters
    ----------
    user : UserLaw or IsolatedLaw
        The law.
    x1, x2 : ndarray
        States [mm], [mm/s].

    Returns
    -------
    u : ndarray
        u of the first pass [mm/s] (kept for the re-check after all other calls).
    failures : list of dict
        One ``pure-function`` failure at the first differing state, or none.
    """
    first = user(x1, x2)
    perm = np.random.default_rng(RANDOM_SEED + 2).permutation(x1.size)
    shuffled = np.empty_like(first)
    shuffled[perm] = user(x1[perm], x2[perm])
    chunked, i, k = np.empty_like(first), 0, 0
    while i < x1.size:
        j = min(x1.size, i + _CHUNKS[k % len(_CHUNKS)])
        chunked[i:j] = user(x1[i:j], x2[i:j])
        i, k = j, k + 1
    passes = (("a second call", user(x1, x2)), ("a shuffled call", shuffled))
    passes += (("calls in chunks of " + "/".join(map(str, _CHUNKS)), chunked),)
    for how, other in passes:
        fails = differs(first, other, x1, x2, how)
        if fails:
            return first, fails
    return first, []


def differs(first, other, x1, x2, how: str) -> list[dict]:
    """Return a ``pure-function`` failure at the first state where two calls differ.

    Parameters
    ----------
    first, other : ndarray
        u of two calls at the same states [mm/s].
    x1, x2 : ndarray
        The states [mm], [mm/s].
    how : str
        How the second call was made (for the detail).

    Returns
    -------
    list of dict
        One failure, or none when the calls agree bit for bit.
    """
    diff = first != other
    if not diff.any():
        return []
    i = int(np.argmax(diff))
    return [
        failure(
            "pure-function",
            (x1[i], x2[i]),
            f"has memory or is not deterministic: u = {float(first[i])!r} mm/s at the first "
            f"call, {float(other[i])!r} mm/s at {how} ({int(diff.sum())} of {x1.size} "
            "states differ)",
        )
    ]
