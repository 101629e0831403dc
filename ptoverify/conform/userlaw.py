"""User laws for ``ptoverify conform``: loading, vectorized/scalar detection, faults.

Decisions (see also :mod:`ptoverify.conform.gate`):

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
* The law gets copies of the states (a law that writes into its input arrays
  cannot move the states it is judged at) and the configuration it must not
  change: a change (``object.__setattr__`` on the frozen dataclass) is a
  finding at the call that made it.
* What the law returns must be a real number: a Python ``int`` or ``float``,
  a NumPy integer or floating scalar, or (vectorized) an array of such a dtype.
  ``bool``, complex, strings, bytes and objects (even an object array of
  floats) are a non-number: bad input (exit 2), never cast.  Where the array
  call returns a non-real dtype, the law is called state by state and each
  answer is checked.
* Anything the law raises, ``BaseException`` included (``SystemExit``,
  ``pytest.skip``'s outcome), is a finding; only ``KeyboardInterrupt`` passes
  through in the caller's own process (the user pressed Ctrl-C).
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

from ptoverify.config import Config
from ptoverify.conform.findings import failure
from ptoverify.errors import InputError

__all__ = [
    "load_callable",
    "LawFault",
    "UserLaw",
    "wrap_callable",
    "check_output",
    "DEFAULT_TIMEOUT_S",
]

_VEC_RTOL = 1e-12  #: vectorized-vs-scalar agreement relative to w_max


# ------------------------------------------------------------------ loading
def check_spec(spec: str) -> None:
    """Check the form of ``MODULE:FUNCTION`` / ``file.py:FUNCTION`` without running code.

    Parameters
    ----------
    spec : str
        The ``--law`` argument.

    Raises
    ------
    InputError
        Malformed spec or a ``.py`` file that does not exist.
    """
    mod_name, sep, attr = spec.rpartition(":")
    if not sep or not mod_name or not attr:
        raise InputError(f"--law '{spec}': expected MODULE:FUNCTION or path/file.py:FUNCTION")
    if mod_name.endswith(".py") and not Path(mod_name).is_file():
        raise InputError(f"--law '{spec}': no such file '{mod_name}'")


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
            names = _defined_callables(obj)
            shown = ", ".join(names[:20]) + (" ..." if len(names) > 20 else "")
            raise InputError(
                f"--law '{spec}': '{mod_name}' has no attribute '{attr}'"
                + (
                    f" (callables defined there: {shown})"
                    if names
                    else " (it defines no callables)"
                )
            )
        obj = getattr(obj, part)
    if not callable(obj):
        raise InputError(f"--law '{spec}': '{attr}' is not callable ({type(obj).__name__})")
    return obj


def _defined_callables(obj: Any) -> list[str]:
    """Public callables defined in a module (not imported into it), or an object's."""
    own = getattr(obj, "__name__", None)
    try:
        items = vars(obj).items()
    except TypeError:
        return []
    return sorted(
        k
        for k, v in items
        if callable(v)
        and not k.startswith("_")
        and (not inspect.ismodule(obj) or getattr(v, "__module__", None) == own)
    )


# ------------------------------------------------------------------ wrapping
class LawFault(Exception):
    """The user law failed at a state (raised, or returned a non-finite u): a finding."""

    def __init__(self, state: tuple[float, float], message: str):
        super().__init__(message)
        self.state = state
        self.message = message


_REAL_KINDS = "iuf"  #: accepted NumPy dtype kinds: signed, unsigned integer, floating


def check_output(value: Any, state: tuple[float, float], n: int | None = None) -> NDArray:
    """Validate what a law returned: real numbers only, never a silent cast.

    Parameters
    ----------
    value : object
        The law's return value.
    state : (float, float)
        The (first) state of the call [mm], [mm/s], for the message.
    n : int, optional
        Number of states of an array call (None: one state, a scalar expected).

    Returns
    -------
    ndarray of float64
        u [mm/s]: 0-d for one state, shape (n,) for an array call.

    Raises
    ------
    InputError
        A non-number (bool, complex, string, bytes, object) or a wrong shape.
    """

    def where() -> str:  # formatted only for a message (two reprs per call add up)
        return f"at state ({state[0]!r}, {state[1]!r})"

    if n is None:
        real = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
            value, (bool, np.bool_)
        )
        if isinstance(value, np.ndarray) and value.ndim == 0:
            real = value.dtype.kind in _REAL_KINDS
        if not real:
            shape = f" (shape {np.shape(value)})" if np.ndim(value) else ""
            raise InputError(
                f"the law returned {type(value).__name__}{shape} {where()}; expected one real "
                "number u [mm/s] (int or float; bool, complex, str and objects are rejected)"
            )
        return np.asarray(value, dtype=float)
    try:  # a plain ndarray: a subclass's methods (user code) never run in the judge
        arr = np.asarray(value)
    except Exception:  # noqa: BLE001 - an __array__ or __len__ of the law's object raised
        arr = np.asarray(None, dtype=object)
    if arr.dtype.kind not in _REAL_KINDS:
        raise InputError(
            f"the law returned {type(value).__name__} of dtype {arr.dtype} for {n} states "
            f"from {where()}; expected real numbers (integer or floating dtype)"
        )
    if arr.shape != (n,):
        raise InputError(f"the law returned shape {arr.shape} for {n} states")
    return arr.astype(float)


def _changed(now: Any, before: Any, path: str = "cfg") -> str | None:
    """Path of the first field of a (nested) dataclass that differs, or None."""
    import dataclasses

    if dataclasses.is_dataclass(before) and not isinstance(before, type):
        for f in dataclasses.fields(before):
            hit = _changed(getattr(now, f.name, None), getattr(before, f.name), f"{path}.{f.name}")
            if hit:
                return hit
        return None
    same = now == before or (now != now and before != before)  # NaN stays NaN
    return None if same else f"{path}: {before!r} -> {now!r}"


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
    in_child : bool
        True in the isolated child: ``KeyboardInterrupt`` from the law is a finding too.
    """

    fn: Callable
    cfg: Config
    mode: str = "scalar"
    reason: str = ""
    calls: int = 0
    in_child: bool = False

    def __post_init__(self):
        import copy

        self._pristine = copy.deepcopy(self.cfg)

    def _fault(self, exc: BaseException, state: tuple[float, float], what: str) -> LawFault:
        if isinstance(exc, KeyboardInterrupt) and not self.in_child:
            raise exc
        return LawFault(state, f"the law raised {type(exc).__name__}{what}: {exc}")

    def _check_cfg(self, state: tuple[float, float]) -> None:
        """Raise LawFault when the law changed its configuration (a frozen dataclass)."""
        if self.cfg is not self._pristine and self.cfg != self._pristine:
            hit = _changed(self.cfg, self._pristine)
            raise LawFault(state, f"the law changed its configuration argument ({hit})")

    def _loop(self, x1: list[float], x2: list[float]) -> list[float]:
        """Call the law state by state (Python floats); u in order, LawFault at the first bad one.

        One loop with the law and its configuration held in locals: a scalar law is
        called some 10^5 times per conformance, so the wrapper's cost per call
        counts.  A Python ``float`` is what :func:`check_output` accepts as it is;
        anything else the law returns goes through it.
        """
        fn, cfg, isfinite = self.fn, self.cfg, math.isfinite
        out: list[float] = []
        append = out.append
        for a, b in zip(x1, x2):
            self.calls += 1
            try:
                value = fn(a, b, cfg)
            except BaseException as exc:  # noqa: BLE001 - anything the user code raises is a finding
                raise self._fault(exc, (a, b), "") from None
            if type(value) is not float:
                value = float(check_output(value, (a, b)))
            if not isfinite(value):
                raise LawFault((a, b), f"the law returned u = {value!r}")
            append(value)
        return out

    def scalar(self, x1: float, x2: float) -> float:
        """Evaluate at one state; LawFault on exception, non-finite u or a changed cfg."""
        u = self._loop([float(x1)], [float(x2)])[0]
        self._check_cfg((x1, x2))
        return u

    def __call__(self, x1: NDArray, x2: NDArray) -> NDArray[np.float64]:
        """Evaluate on 1-D arrays [mm], [mm/s]; returns u [mm/s] (the law gets copies)."""
        x1 = np.array(x1, dtype=float).ravel()
        x2 = np.array(x2, dtype=float).ravel()
        first = (float(x1[0]), float(x2[0])) if x1.size else (math.nan, math.nan)
        if self.mode == "scalar":
            u = np.array(self._loop(x1.tolist(), x2.tolist()), dtype=float)
            self._check_cfg(first)
            return u
        self.calls += 1
        try:
            value = self.fn(x1.copy(), x2.copy(), self.cfg)
        except BaseException as exc:  # noqa: BLE001 - locate the failing state element-wise
            self._fault(exc, first, "")
            for a, b in zip(x1, x2):
                self.scalar(float(a), float(b))
            raise LawFault(
                first,
                f"the law raised {type(exc).__name__} on arrays but no element raised alone: {exc}",
            ) from None
        self._check_cfg(first)
        u = check_output(value, first, x1.size)
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


def wrap_callable(
    fn: Callable, cfg: Config, *, in_child: bool = False
) -> tuple[UserLaw, list[dict]]:
    """Check the signature, detect vectorized or scalar, test purity on probe states.

    Parameters
    ----------
    fn : callable
        The user law ``u = f(x1, x2, cfg)``.
    cfg : Config
        Configuration.
    in_child : bool
        True in the isolated child: a ``KeyboardInterrupt`` the law raises is
        a finding from the first probe call on (mode detection included), not
        an interruption of the judging run.

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
    law = UserLaw(fn, cfg, in_child=in_child)
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
                f"has memory or is not deterministic: two calls at the same state returned "
                f"{float(first[i])!r} and {float(second[i])!r} mm/s",
            )
        )
    law.reason = ""
    try:
        vec = fn(p1.copy(), p2.copy(), cfg)
        law._check_cfg((float(p1[0]), float(p2[0])))
        vec = check_output(vec, (float(p1[0]), float(p2[0])), p1.size)
    except LawFault as fault:
        return law, [failure("evaluation", fault.state, fault.message)]
    except InputError as exc:
        law.reason = f"an array call returned no array of real numbers ({exc})"
    except BaseException as exc:  # noqa: BLE001 - any failure on arrays means: scalar loop
        law._fault(exc, (float(p1[0]), float(p2[0])), "")
        law.reason = f"takes one state per call (an array call raised {type(exc).__name__})"
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
        law.reason += "; called state by state"
    else:
        law.mode = "vectorized"
        law.reason = f"array call of {p1.size} probe states equals element-wise calls"
    return law, failures


# ------------------------------------------------------------------ isolation
DEFAULT_TIMEOUT_S = 120.0  #: whole conformance of an isolated law [s]
