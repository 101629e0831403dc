"""The user's law in a child process: time, memory and lifetime limits.

Decisions:

* The child is a plain ``python -c`` process (:mod:`subprocess`, its own
  session), not a :mod:`multiprocessing` one: no resource tracker and no
  re-import of the caller's ``__main__``, and its stdout and stderr are an
  anonymous temporary file from its first instruction on, so nothing it (or a
  process it forks) does can hold ptoverify's own stdout or stderr open.
* Nothing is left running (:mod:`ptoverify.conform.reaper`): on Linux the child
  is a supervisor that runs no user code, a child subreaper that forks the
  worker running the law; every process the law starts, a ``setsid`` daemon
  included, stays its descendant, and it kills them all when the worker ends,
  when ptoverify asks (SIGTERM) and when ptoverify dies, by any signal
  (``prctl(PR_SET_PDEATHSIG)`` through ctypes, checked against the race
  between fork and prctl).  The worker dies with the supervisor (the same
  prctl); a watchdog thread polling the parent pid is the portable fallback.
  On every exit path ptoverify then kills what carries the run's token in its
  environment and the child's process group.
* Nothing is left on disk: the log is :func:`tempfile.TemporaryFile`
  (unlinked at once); named ``ptoverify-law-*.log`` files from older
  versions' dead runs are removed by the next run.
* Parent to child: pickles (the parent trusts itself).  Child to parent: JSON
  plus raw float64 bytes, never a pickle, so a hostile law that writes on the
  pipe cannot run code in the judging process; its length is bounded by the
  call it answers.
"""

from __future__ import annotations

import json
import os
import pickle
import secrets
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify.config import Config
from ptoverify.conform.reaper import TOKEN_VAR, kill_marked
from ptoverify.conform.userlaw import (
    DEFAULT_TIMEOUT_S,
    LawFault,
    check_spec,
    load_callable,
    wrap_callable,
)
from ptoverify.errors import InputError

__all__ = [
    "IsolatedLaw",
    "LawAborted",
    "CALL_BASE_S",
    "MEMORY_LIMIT_BYTES",
    "remove_stale_logs",
]

#: per-call budget of an isolated law: this many seconds plus _CALL_PER_STATE_S per state
CALL_BASE_S = 10.0
_CALL_PER_STATE_S = 1e-3
#: address-space limit of the law's process (RLIMIT_AS, where the OS has it) [bytes]
MEMORY_LIMIT_BYTES = 4 << 30
_LEN = struct.Struct("!Q")  #: frame length prefix
_JSON_LEN = struct.Struct("!I")  #: JSON part of a child's answer
_MAX_HEADER = 16 << 20  #: largest JSON part a child may send [bytes]
_POLL_S = 0.2  #: how often a waiting parent checks that the child still lives [s]
_STALE_S = 3600.0  #: named law logs older than this are stale [s]
_STOP_S = 5.0  #: longest wait for the supervisor to kill the law's processes and end [s]

#: the child's first instructions, before anything else is imported
_BOOT = """\
import os, sys
sys.path.insert(0, sys.argv[4])
from ptoverify.conform.reaper import supervise
watch = supervise(int(sys.argv[1]), int(sys.argv[2]))
from ptoverify.conform.isolation import child_main
child_main(watch, int(sys.argv[2]), int(sys.argv[3]))
"""


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


# ------------------------------------------------------------------ wire format
def _send_pickle(sock: socket.socket, obj) -> None:
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    sock.sendall(_LEN.pack(len(data)) + data)


def _send_answer(sock: socket.socket, head: dict, u: NDArray | None = None) -> None:
    text = json.dumps(head, default=float).encode()
    raw = b"" if u is None else np.ascontiguousarray(u, dtype="<f8").tobytes()
    body = _JSON_LEN.pack(len(text)) + text + raw
    sock.sendall(_LEN.pack(len(body)) + body)


def _read_exact(sock: socket.socket, n: int, deadline: float | None, alive) -> bytes:
    """Read n bytes; ``deadline`` (monotonic) None blocks; TimeoutError; EOFError."""
    buf = bytearray()
    while len(buf) < n:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError
            sock.settimeout(min(left, _POLL_S))
        try:
            chunk = sock.recv(min(n - len(buf), 1 << 20))
        except (socket.timeout, TimeoutError):
            if alive is not None and not alive():
                raise EOFError from None
            continue
        if not chunk:
            raise EOFError
        buf += chunk
    return bytes(buf)


# ------------------------------------------------------------------ the child
def _watchdog(ppid: int) -> None:
    """Portable fallback of PR_SET_PDEATHSIG: end when the parent is gone."""
    while True:
        time.sleep(0.5)
        if os.getppid() != ppid:
            os._exit(70)


def _limit_memory(memory_limit: int) -> None:
    if memory_limit <= 0:
        return
    try:
        import resource

        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        lim = memory_limit if hard == resource.RLIM_INFINITY else min(memory_limit, hard)
        resource.setrlimit(resource.RLIMIT_AS, (lim, hard))
    except (ImportError, ValueError, OSError):
        pass  # no RLIMIT_AS on this OS: the time limits still hold


def child_main(ppid: int, fd: int, memory_limit: int) -> None:
    """Body of the law's process: load, detect the mode, then answer calls.

    Parameters
    ----------
    ppid : int
        Process id of the judging process (the child ends when it is gone).
    fd : int
        File descriptor of the child's end of the socket pair.
    memory_limit : int
        Address-space limit [bytes]; 0 for none.
    """
    import threading

    threading.Thread(target=_watchdog, args=(ppid,), daemon=True).start()
    os.set_inheritable(fd, False)
    sock = socket.socket(fileno=fd)
    _limit_memory(memory_limit)

    def recv():
        (n,) = _LEN.unpack(_read_exact(sock, _LEN.size, None, None))
        return pickle.loads(_read_exact(sock, n, None, None))

    _, sys_path, spec, cfg = recv()
    sys.path[:] = sys_path
    try:
        user, failures = wrap_callable(load_callable(spec), cfg, in_child=True)
    except InputError as exc:
        _send_answer(sock, {"kind": "input", "message": str(exc)})
        return
    _send_answer(
        sock, {"kind": "ready", "mode": user.mode, "reason": user.reason, "failures": failures}
    )
    while True:
        msg = recv()
        if msg[0] == "stop":
            return
        try:
            u = user(msg[1], msg[2])
        except LawFault as fault:
            _send_answer(sock, {"kind": "fault", "state": fault.state, "message": fault.message})
        except InputError as exc:
            _send_answer(sock, {"kind": "input", "message": str(exc)})
        else:
            _send_answer(sock, {"kind": "ok", "n": int(u.size)}, u)


# ------------------------------------------------------------------ the parent
def remove_stale_logs(folder: str | Path | None = None, max_age_s: float = _STALE_S) -> int:
    """Remove named ``ptoverify-law-*.log`` files left by dead runs of older versions.

    Parameters
    ----------
    folder : str or Path, optional
        Where to look (default: :func:`tempfile.gettempdir`).
    max_age_s : float
        Files not modified for this long are stale [s].

    Returns
    -------
    int
        Number of files removed.
    """
    folder = Path(tempfile.gettempdir() if folder is None else folder)
    removed, now = 0, time.time()
    try:
        candidates = list(folder.glob("ptoverify-law-*.log"))
    except OSError:
        return 0
    for path in candidates:
        try:
            st = path.lstat()
            if st.st_uid == os.getuid() and now - st.st_mtime > max_age_s:
                path.unlink()
                removed += 1
        except OSError:
            continue  # another run removed it, or not ours to remove
    return removed


def _describe(code: int | None) -> str:
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
    """A user law loaded and called in a child process, with time, memory and lifetime limits.

    Same interface as :class:`~ptoverify.conform.userlaw.UserLaw` (``mode``,
    ``reason``, ``calls``, ``__call__(x1, x2)``, ``scalar``) once :meth:`ready`
    has returned (the child loads while the caller prepares its states).  The
    law's stdout and stderr go to an anonymous file, returned by :meth:`close`.
    A timeout (the whole ``timeout`` or the per-call budget of 10 s + 1 ms per
    state, the 1 ms scaled up by ``timeout`` / 120 s for a longer ``timeout``),
    any exit of the child (code 0 included), a signal or a lost pipe raises
    :class:`LawAborted`.  The child dies with the thread that created it
    (PR_SET_PDEATHSIG): create it in a thread that outlives the judgement.
    Use it as a context manager, or call :meth:`close` on every path.

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
        check_spec(spec)
        remove_stale_logs()
        self.cfg, self.timeout, self.calls = cfg, timeout, 0
        self.init_failures: list[dict] = []
        self.mode, self.reason = "unknown", "not loaded yet"
        self._deadline = time.monotonic() + timeout
        self._log = tempfile.TemporaryFile(prefix="ptoverify-law-")
        self._token = secrets.token_hex(16)
        self._sock, child = socket.socketpair()
        root = str(Path(__file__).resolve().parents[2])
        argv = [sys.executable, "-c", _BOOT, str(os.getpid()), str(child.fileno())]
        try:
            self._proc = subprocess.Popen(
                [*argv, str(memory_limit or 0), root],
                stdin=subprocess.DEVNULL,
                stdout=self._log,
                stderr=self._log,
                pass_fds=(child.fileno(),),
                start_new_session=True,
                env={**os.environ, TOKEN_VAR: self._token},
            )
        except OSError as exc:
            self._sock.close()
            self._log.close()
            raise LawAborted(f"cannot start the law's process: {exc}") from None
        finally:
            child.close()
        self._closed = False
        self._busy = True  # loading, or a call sent and its answer not read yet
        try:
            _send_pickle(self._sock, ("init", list(sys.path), spec, cfg))
        except OSError:
            pass  # the child is gone already: ready() says how

    def __enter__(self) -> IsolatedLaw:
        """Return self; :meth:`close` runs on leaving."""
        return self

    def __exit__(self, *exc) -> None:
        """Stop the child (any exit path)."""
        self.close()

    def ready(self) -> None:
        """Wait until the child has loaded the law and detected its mode.

        Raises
        ------
        InputError
            The law cannot be loaded or has a bad interface (exit 2).
        LawAborted
            The child hung, crashed or exited while loading.
        """
        head, _ = self._recv("loading the law and detecting its mode", self.timeout, 0)
        self._busy = False
        if head.get("kind") == "input":
            raise InputError(str(head.get("message")))
        if head.get("kind") != "ready":
            raise LawAborted("unreadable answer from the law's process (loading the law)")
        self.mode, self.reason = str(head["mode"]), str(head["reason"])
        self.init_failures = list(head["failures"])

    def _recv(self, what: str, budget: float, n_values: int) -> tuple[dict, NDArray | None]:
        """Receive one answer of at most ``n_values`` floats within the budget [s]."""
        left = self._deadline - time.monotonic()
        deadline = time.monotonic() + max(0.0, min(budget, left))
        try:
            (n,) = _LEN.unpack(_read_exact(self._sock, _LEN.size, deadline, self._alive))
            if n > _MAX_HEADER + 8 * n_values + _JSON_LEN.size:
                raise ValueError(f"a frame of {n} bytes")
            body = _read_exact(self._sock, n, deadline, self._alive)
            (k,) = _JSON_LEN.unpack(body[: _JSON_LEN.size])
            head = json.loads(body[_JSON_LEN.size : _JSON_LEN.size + k])
            raw = body[_JSON_LEN.size + k :]
            if not isinstance(head, dict) or len(raw) % 8:
                raise ValueError("malformed answer")
        except TimeoutError:
            self._kill()
            if left <= budget:
                raise LawAborted(
                    f"timeout: the law used up the --timeout of {self.timeout:g} s ({what})"
                ) from None
            raise LawAborted(
                f"timeout: the law did not answer within {budget:.3g} s ({what})"
            ) from None
        except (EOFError, OSError):
            raise LawAborted(f"{self._ended()} ({what})") from None
        except (ValueError, struct.error, UnicodeDecodeError) as exc:
            self._kill()
            raise LawAborted(f"unreadable answer from the law's process ({what}): {exc}") from None
        return head, np.frombuffer(raw, dtype="<f8").astype(float) if raw else None

    def _alive(self) -> bool:
        return self._proc.poll() is None

    def _ended(self) -> str:
        try:
            code = self._proc.wait(2.0)
        except subprocess.TimeoutExpired:
            code = None
        self._kill()
        return _describe(code)

    def __call__(self, x1: NDArray, x2: NDArray) -> NDArray[np.float64]:
        """Evaluate on 1-D arrays [mm], [mm/s] in the child; returns u [mm/s]."""
        x1 = np.array(x1, dtype=float).ravel()
        x2 = np.array(x2, dtype=float).ravel()
        what = (
            f"a call of {x1.size} states from ({x1[0]:.6g}, {x2[0]:.6g})" if x1.size else "a call"
        )
        self._busy = True
        try:
            _send_pickle(self._sock, ("call", x1, x2))
        except OSError:
            raise LawAborted(f"{self._ended()} (sending {what})") from None
        self.calls += 1 if self.mode == "vectorized" else x1.size
        per_state = _CALL_PER_STATE_S * max(1.0, self.timeout / DEFAULT_TIMEOUT_S)
        head, u = self._recv(what, CALL_BASE_S + per_state * x1.size, x1.size)
        self._busy = False
        kind = head.get("kind")
        if kind == "ok":
            if u is None and x1.size == 0:
                u = np.empty(0)
            if u is None or u.shape != x1.shape:
                shape = None if u is None else u.shape
                raise LawAborted(f"the law's process answered shape {shape} ({what})")
            return u
        if kind == "fault":
            state = head.get("state") or (float("nan"), float("nan"))
            raise LawFault((float(state[0]), float(state[1])), str(head.get("message")))
        if kind == "input":
            raise InputError(str(head.get("message")))
        raise LawAborted(f"unreadable answer from the law's process ({what})")

    def scalar(self, x1: float, x2: float) -> float:
        """Evaluate at one state (one round trip)."""
        return float(self(np.array([x1]), np.array([x2]))[0])

    def _kill(self) -> None:
        """Kill the child, every process the law started, and reap the child.

        Linux: SIGTERM to the supervisor, which kills its tree and ends
        (SIGKILL after :data:`_STOP_S`); then SIGKILL to whatever still carries
        the run's token.  Everywhere: SIGKILL to the child's process group.
        """
        if sys.platform.startswith("linux"):
            try:
                self._proc.send_signal(signal.SIGTERM)  # no signal once it is reaped
                self._proc.wait(_STOP_S)
            except (subprocess.TimeoutExpired, OSError):
                pass
        try:
            os.killpg(self._proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        kill_marked(self._token)
        try:
            self._proc.wait(5.0)
        except subprocess.TimeoutExpired:
            pass

    def close(self) -> str:
        """Stop the child and return what the law printed (stdout and stderr).

        A child that answered its last call is asked to stop and given 2 s; one
        still loading or inside a call (the wait for it was interrupted: Ctrl-C,
        SIGTERM) cannot read the request, so it is killed at once.
        """
        if self._closed:
            return ""
        self._closed = True
        try:
            if self._alive() and not self._busy:
                _send_pickle(self._sock, ("stop",))
                self._proc.wait(2.0)
        except (OSError, subprocess.TimeoutExpired):
            pass
        self._kill()
        self._sock.close()
        try:
            text = _read_log(self._log)
        finally:
            self._log.close()
        return text


def _read_log(fh, keep: int = 1 << 16) -> str:
    """Return the log's text, or its first and last ``keep`` bytes when longer."""
    try:
        size = os.fstat(fh.fileno()).st_size
        fh.seek(0)
        if size <= 2 * keep:
            data = fh.read()
        else:
            data = fh.read(keep) + b"\n[...]\n"
            fh.seek(size - keep)
            data += fh.read(keep)
    except OSError:
        return ""
    return data.decode("utf-8", errors="replace")
