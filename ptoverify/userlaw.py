"""User laws for ``ptoverify conform``: loading, vectorized/scalar detection, faults.

Decisions (see also :mod:`ptoverify.conform`):

* ``MODULE:FUNCTION`` imports exactly the named module with
  :func:`importlib.import_module` (importable from ``sys.path`` as it stands;
  nothing is added); ``path/to/file.py:FUNCTION`` loads exactly that file with
  :func:`importlib.util.spec_from_file_location`.  No path is searched for.
  Loading runs the user's code.
* Interface errors are :class:`~ptoverify.errors.InputError` (exit 2); a law
  that raises or returns NaN/inf at a state raises :class:`LawFault`, a
  finding (exit 1) that names the state.
* Vectorized when an array call of 8 probe states returns an array of their
  shape equal to element-wise calls to 1e-12 w_max; otherwise a scalar loop.
* Pure function: two passes over the probe states must return the same u.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ptoverify.agreement import failure
from ptoverify.config import Config
from ptoverify.errors import InputError

__all__ = ["load_callable", "LawFault", "UserLaw", "wrap_callable"]

_VEC_RTOL = 1e-12  #: vectorized-vs-scalar agreement relative to w_max


# ------------------------------------------------------------------ loading
def load_callable(spec: str) -> Callable:
    """Import ``MODULE:FUNCTION`` or load ``path/file.py:FUNCTION`` (runs user code).

    Parameters
    ----------
    spec : str
        ``package.module:function`` (imported from ``sys.path`` as it stands) or
        ``path/to/file.py:function`` (exactly that file).

    Returns
    -------
    callable
        The named object.

    Raises
    ------
    InputError
        Malformed spec, import failure, missing attribute, not callable.
    """
    mod_name, sep, attr = spec.rpartition(":")
    if not sep or not mod_name or not attr:
        raise InputError(f"--law '{spec}': expected MODULE:FUNCTION or path/file.py:FUNCTION")
    try:
        if mod_name.endswith(".py"):
            path = Path(mod_name)
            if not path.is_file():
                raise InputError(f"--law '{spec}': no such file '{mod_name}'")
            name = f"_ptoverify_user_{path.stem}"
            mspec = importlib.util.spec_from_file_location(name, path)
            if mspec is None or mspec.loader is None:
                raise InputError(f"--law '{spec}': cannot load '{mod_name}'")
            module = importlib.util.module_from_spec(mspec)
            mspec.loader.exec_module(module)
        else:
            module = importlib.import_module(mod_name)
    except InputError:
        raise
    except BaseException as exc:  # noqa: BLE001 - user code may raise anything, even SystemExit
        raise InputError(
            f"--law '{spec}': importing '{mod_name}' failed: {type(exc).__name__}: {exc}"
        ) from None
    obj: Any = module
    for part in attr.split("."):
        if not hasattr(obj, part):
            raise InputError(f"--law '{spec}': '{mod_name}' has no attribute '{attr}'")
        obj = getattr(obj, part)
    if not callable(obj):
        raise InputError(f"--law '{spec}': '{attr}' is not callable ({type(obj).__name__})")
    return obj


# ------------------------------------------------------------------ wrapping
class LawFault(Exception):
    """The user law failed at a state (raised, or returned a non-finite u): a finding."""

    def __init__(self, state: tuple[float, float], message: str):
        super().__init__(message)
        self.state = state
        self.message = message


def _as_number(value: Any, state: tuple[float, float]) -> float:
    """Convert a scalar return value to float; wrong type is bad input (exit 2)."""
    if isinstance(value, bool) or np.ndim(value) != 0:
        raise InputError(
            f"the law returned {type(value).__name__} (shape {np.shape(value)}) at "
            f"state ({state[0]!r}, {state[1]!r}); expected one number u [mm/s]"
        )
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(
            f"the law returned {type(value).__name__} at state ({state[0]!r}, "
            f"{state[1]!r}); expected one number u [mm/s]"
        ) from None


@dataclass
class UserLaw:
    """A user law u = f(x1, x2, cfg) with its evaluation mode.

    Attributes
    ----------
    fn : callable
        The user's function.
    cfg : Config
        Configuration passed to it.
    mode : str
        ``vectorized`` or ``scalar``.
    reason : str
        Why that mode was chosen.
    calls : int
        Number of calls made so far.
    """

    fn: Callable
    cfg: Config
    mode: str = "scalar"
    reason: str = ""
    calls: int = 0

    def scalar(self, x1: float, x2: float) -> float:
        """Evaluate at one state; LawFault on exception or non-finite u."""
        self.calls += 1
        try:
            value = self.fn(x1, x2, self.cfg)
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - any user exception is a finding
            raise LawFault((x1, x2), f"the law raised {type(exc).__name__}: {exc}") from None
        u = _as_number(value, (x1, x2))
        if not math.isfinite(u):
            raise LawFault((x1, x2), f"the law returned u = {u!r}")
        return u

    def __call__(self, x1: NDArray, x2: NDArray) -> NDArray[np.float64]:
        """Evaluate on 1-D arrays [mm], [mm/s]; returns u [mm/s]."""
        x1 = np.asarray(x1, dtype=float).ravel()
        x2 = np.asarray(x2, dtype=float).ravel()
        if self.mode == "scalar":
            return np.array([self.scalar(float(a), float(b)) for a, b in zip(x1, x2)], dtype=float)
        self.calls += 1
        try:
            value = self.fn(x1, x2, self.cfg)
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - locate the failing state element-wise
            for a, b in zip(x1, x2):
                self.scalar(float(a), float(b))
            raise LawFault(
                (float(x1[0]), float(x2[0])),
                f"the law raised {type(exc).__name__} on arrays but no element raised alone: {exc}",
            ) from None
        try:
            u = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"the law returned {type(value).__name__} for arrays; expected a float array"
            ) from None
        if u.shape != x1.shape:
            raise InputError(f"the law returned shape {u.shape} for {x1.size} states")
        bad = np.flatnonzero(~np.isfinite(u))
        if bad.size:
            i = int(bad[0])
            raise LawFault((float(x1[i]), float(x2[i])), f"the law returned u = {u[i]!r}")
        return u


def _probe_states(cfg: Config) -> tuple[NDArray, NDArray]:
    """Eight states across the regions: rest, bang, linear, zone band, |x2| = w_max."""
    R, w, d = cfg.plant.position_range, cfg.plant.w_max, cfg.pto.d
    x1 = np.array([0.3 * R, -0.7 * R, 0.5 * d, -0.5 * d, 0.2 * R, -0.2 * R, 1.5 * d, -1.5 * d])
    x2 = np.array([0.0, 0.5 * w, -0.25 * w, 0.1 * w, -w, w, -0.9 * w, 0.9 * w])
    return x1, x2


def wrap_callable(fn: Callable, cfg: Config) -> tuple[UserLaw, list[dict]]:
    """Check the signature, detect vectorized or scalar, test purity on probe states.

    Parameters
    ----------
    fn : callable
        The user law ``u = f(x1, x2, cfg)``.
    cfg : Config
        Configuration.

    Returns
    -------
    law : UserLaw
        The wrapped law with its mode.
    failures : list of dict
        Findings (``evaluation`` or ``pure-function``) at the probe states.
    """
    try:
        inspect.signature(fn).bind(0.0, 0.0, cfg)
    except TypeError as exc:
        raise InputError(f"the law's signature does not accept (x1, x2, cfg): {exc}") from None
    except ValueError:
        pass  # no signature available (builtins): try it
    law = UserLaw(fn, cfg)
    p1, p2 = _probe_states(cfg)
    try:
        first = law(p1, p2)
        second = law(p1, p2)
    except LawFault as fault:
        return law, [failure("evaluation", fault.state, fault.message)]
    failures = []
    diff = np.abs(first - second)
    if np.any(diff > 0):
        i = int(np.argmax(diff > 0))
        failures.append(
            failure(
                "pure-function",
                (p1[i], p2[i]),
                f"two calls at the same state returned {first[i]!r} and "
                f"{second[i]!r} mm/s: the law has memory (e.g. a delay)",
            )
        )
    law.reason = ""
    try:
        vec = np.asarray(fn(p1, p2, cfg), dtype=float)
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - any failure on arrays means: scalar loop
        law.reason = f"array call raised {type(exc).__name__}: {' '.join(str(exc).split())}"
    else:
        if vec.shape != p1.shape:
            law.reason = f"array call returned shape {vec.shape} for {p1.size} states"
        else:
            close = np.abs(vec - first) <= _VEC_RTOL * cfg.plant.w_max
            if not np.all(close):
                i = int(np.argmin(close))
                law.reason = (
                    f"array call differs from element-wise calls at ({p1[i]:g}, "
                    f"{p2[i]:g}): {vec[i]!r} vs {first[i]!r}"
                )
    if law.reason:
        law.reason += "; wrapped in a scalar loop"
    else:
        law.mode = "vectorized"
        law.reason = f"array call of {p1.size} probe states equals element-wise calls"
    return law, failures
