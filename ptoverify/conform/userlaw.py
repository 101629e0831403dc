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
from ptoverify.conform.agreement import failure
from ptoverify.errors import InputError

__all__ = [
    "load_callable",
    "LawFault",
    "LawAborted",
    "UserLaw",
    "IsolatedLaw",
    "wrap_callable",
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
                f"has memory or is not deterministic: two calls at the same state returned "
                f"{float(first[i])!r} and {float(second[i])!r} mm/s",
            )
        )
    law.reason = ""
    try:
        vec = np.asarray(fn(p1, p2, cfg), dtype=float)
    except (Exception, SystemExit) as exc:  # noqa: BLE001 - any failure on arrays means: scalar loop
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
#: per-call budget of an isolated law: this many seconds plus _CALL_PER_STATE_S per state
CALL_BASE_S = 10.0
_CALL_PER_STATE_S = 1e-3
#: address-space limit of the law's process (RLIMIT_AS, where the OS has it) [bytes]
MEMORY_LIMIT_BYTES = 4 << 30
DEFAULT_TIMEOUT_S = 120.0  #: whole conformance of an isolated law [s]


class LawAborted(Exception):
    """The isolated law's process hung, ended or lost its pipe: nothing more can be evaluated.

    A finding (exit 1): every property not evaluated yet is ``unverified``.

    Parameters
    ----------
    message : str
        What happened to the law's process.
    """

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


def _child_main(conn, spec: str, cfg: Config, out_path: str, memory_limit: int | None) -> None:
    """Body of the law's process: load, detect the mode, then answer batches."""
    import os
    import sys

    fd = os.open(out_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    os.close(fd)
    if memory_limit:
        try:
            import resource

            _, hard = resource.getrlimit(resource.RLIMIT_AS)
            lim = memory_limit if hard == resource.RLIM_INFINITY else min(memory_limit, hard)
            resource.setrlimit(resource.RLIMIT_AS, (lim, hard))
        except (ImportError, ValueError, OSError):
            pass  # no RLIMIT_AS on this OS: the time limits still hold
    try:
        user, failures = wrap_callable(load_callable(spec), cfg)
    except InputError as exc:
        conn.send(("input", str(exc)))
        return
    conn.send(("ready", user.mode, user.reason, failures))
    while True:
        msg = conn.recv()
        if msg[0] == "stop":
            return
        try:
            conn.send(("ok", user(msg[1], msg[2])))
        except LawFault as fault:
            conn.send(("fault", fault.state, fault.message))
        except InputError as exc:
            conn.send(("input", str(exc)))


def _ended(proc) -> str:
    """Describe how the law's process ended."""
    import signal

    proc.join(2.0)
    code = proc.exitcode
    if code is None:
        return "the pipe to the law's process was lost (the process is still running)"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"the law's process was killed by {name}"
    return f"the law's process exited with code {code}"


class IsolatedLaw:
    """A user law loaded and called in a child process (spawned), with time and memory limits.

    Same interface as :class:`UserLaw` (``mode``, ``reason``, ``calls``,
    ``__call__(x1, x2)``, ``scalar``) once :meth:`ready` has returned (the
    child loads while the caller prepares its states): calls are sent as arrays, the child
    loops over states in scalar mode.  The law's stdout and stderr go to a
    file, returned by :meth:`close`.  A timeout (the whole ``timeout`` or the
    per-call budget of 10 s + 1 ms per state, the 1 ms scaled up by
    ``timeout`` / 120 s for a longer ``timeout``), any exit of the child
    (code 0 included), a signal or a lost pipe raises :class:`LawAborted`.

    Parameters
    ----------
    spec : str
        ``MODULE:FUNCTION`` or ``path/file.py:FUNCTION``.
    cfg : Config
        Configuration passed to the law.
    timeout : float
        Budget for everything the law does, loading included [s].
    memory_limit : int or None
        Address-space limit of the child [bytes] (RLIMIT_AS where available).
    """

    def __init__(
        self,
        spec: str,
        cfg: Config,
        *,
        timeout: float = DEFAULT_TIMEOUT_S,
        memory_limit: int | None = MEMORY_LIMIT_BYTES,
    ):
        import multiprocessing
        import os
        import tempfile
        import time

        self.cfg, self.timeout, self.calls = cfg, timeout, 0
        check_spec(spec)
        self._deadline = time.monotonic() + timeout
        fd, self._out = tempfile.mkstemp(prefix="ptoverify-law-", suffix=".log")
        os.close(fd)
        ctx = multiprocessing.get_context("spawn")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(
            target=_child_main, args=(child, spec, cfg, self._out, memory_limit), daemon=True
        )
        self._proc.start()
        child.close()
        self.init_failures: list[dict] = []
        self.mode, self.reason = "unknown", "not loaded yet"

    def ready(self) -> None:
        """Wait until the child has loaded the law and detected its mode.

        Raises
        ------
        InputError
            The law cannot be loaded or has a bad interface (exit 2).
        LawAborted
            The child hung, crashed or exited while loading.
        """
        msg = self._recv("loading the law and detecting its mode", self.timeout)
        if msg[0] == "input":
            self.close()
            raise InputError(msg[1])
        _, self.mode, self.reason, self.init_failures = msg

    def _recv(self, what: str, budget: float):
        import time

        left = self._deadline - time.monotonic()
        wait = max(0.0, min(budget, left))
        try:
            ready = self._conn.poll(wait)
        except (OSError, EOFError):
            ready = True
        if not ready:
            self._kill()
            if left <= budget:
                raise LawAborted(
                    f"timeout: the law used up the --timeout of {self.timeout:g} s ({what})"
                )
            raise LawAborted(f"timeout: the law did not answer within {budget:.3g} s ({what})")
        try:
            return self._conn.recv()
        except (EOFError, OSError):
            raise LawAborted(f"{_ended(self._proc)} ({what})") from None
        except Exception as exc:  # noqa: BLE001 - garbage on the pipe from user code
            self._kill()
            raise LawAborted(f"unreadable answer from the law's process ({what}): {exc}") from None

    def __call__(self, x1: NDArray, x2: NDArray) -> NDArray[np.float64]:
        """Evaluate on 1-D arrays [mm], [mm/s] in the child; returns u [mm/s]."""
        x1 = np.ascontiguousarray(x1, dtype=float).ravel()
        x2 = np.ascontiguousarray(x2, dtype=float).ravel()
        what = (
            f"a call of {x1.size} states from ({x1[0]:.6g}, {x2[0]:.6g})" if x1.size else "a call"
        )
        try:
            self._conn.send(("call", x1, x2))
        except (OSError, EOFError, ValueError):
            raise LawAborted(f"{_ended(self._proc)} (sending {what})") from None
        self.calls += 1 if self.mode == "vectorized" else x1.size
        per_state = _CALL_PER_STATE_S * max(1.0, self.timeout / DEFAULT_TIMEOUT_S)
        msg = self._recv(what, CALL_BASE_S + per_state * x1.size)
        if msg[0] == "ok":
            u = np.asarray(msg[1], dtype=float)
            if u.shape != x1.shape:
                raise LawAborted(f"the law's process answered shape {u.shape} ({what})")
            return u
        if msg[0] == "fault":
            raise LawFault(tuple(msg[1]), msg[2])
        raise InputError(msg[1])

    def scalar(self, x1: float, x2: float) -> float:
        """Evaluate at one state (one round trip)."""
        return float(self(np.array([x1]), np.array([x2]))[0])

    def _kill(self) -> None:
        if self._proc.is_alive():
            self._proc.kill()
        self._proc.join(5.0)

    def close(self) -> str:
        """Stop the child and return what the law printed (stdout and stderr)."""
        import os

        try:
            if self._proc.is_alive():
                self._conn.send(("stop",))
                self._proc.join(2.0)
        except (OSError, EOFError, ValueError):
            pass
        self._kill()
        self._conn.close()
        try:
            with open(self._out, errors="replace") as fh:
                text = fh.read()
            os.unlink(self._out)
        except OSError:
            text = ""
        return text
