"""Nothing the law starts outlives the run: a subreaper between ptoverify and the law.

Standard library only, imported by the law's child before anything else.

Design (Linux; see :func:`supervise`):

* The process :class:`~ptoverify.conform.isolation.IsolatedLaw` starts is a
  *supervisor* that runs no user code.  It makes itself a child subreaper
  (``prctl(PR_SET_CHILD_SUBREAPER)``), asks for SIGTERM when ptoverify dies
  (``prctl(PR_SET_PDEATHSIG)``), and forks the *worker* that loads and calls
  the law; the worker asks for SIGKILL when the supervisor dies.
* Every process the law starts descends from the supervisor, and stays so:
  an orphan (a double fork, a ``setsid`` daemon whose parent exited) is
  reparented to the nearest subreaper, the supervisor, not to init.  The
  supervisor reaps them.
* The supervisor ends in one way only: it kills every descendant
  (:func:`kill_tree`), then ends as the worker ended (same exit code, or the
  same signal).  That happens when the worker ends (the run's normal end, a
  crash), on SIGTERM from ptoverify (a timeout, the run's end), and on its
  death signal when ptoverify dies, SIGKILL included: the handler runs in the
  supervisor, which only waits, so neither a busy nor a hostile law can delay
  or block it.
* Every process of the run also carries a random token in its environment
  (:data:`TOKEN_VAR`); :func:`kill_marked` kills what carries it.  ptoverify
  runs it after the supervisor is gone, for what left the supervisor's tree.

Limits (stated in the README): a process that leaves the tree (the law kills
its supervisor, whose descendants then go to init) *and* replaces its
environment (``exec`` with a new one) is out of reach; so is a process the
law's user may not signal (a set-user-id program); a fork bomb faster than
:func:`kill_tree` is bounded by its time limit.  Elsewhere than Linux there is
no subreaper and no death signal: the worker is the child itself, it polls its
parent's pid, and ptoverify kills the child's process group.
"""

from __future__ import annotations

import os
import signal
import sys
import time

__all__ = ["TOKEN_VAR", "supervise", "descendants", "kill_tree", "kill_marked"]

#: environment variable carrying the run's token, inherited by every process of the run
TOKEN_VAR = "PTOVERIFY_LAW_RUN"
_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36
_PROC = "/proc"
_ON = sys.platform.startswith("linux")
#: signals after which the supervisor cleans up and ends (SIGTERM: ptoverify's request and death)
_SIGNALS = (signal.SIGTERM, signal.SIGHUP, signal.SIGINT, signal.SIGQUIT, signal.SIGUSR1)
_KILL_S = 5.0  #: longest a cleanup keeps killing [s]


def _prctl(option: int, value: int) -> bool:
    try:
        import ctypes

        return ctypes.CDLL(None, use_errno=True).prctl(option, value, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _table() -> dict[int, tuple[int, str]]:
    """Map every process visible in /proc to its (ppid, state letter)."""
    out = {}
    try:
        names = os.listdir(_PROC)
    except OSError:
        return out
    for name in names:
        if not name.isdigit():
            continue
        try:
            with open(f"{_PROC}/{name}/stat", "rb") as fh:
                text = fh.read()
        except OSError:
            continue  # it ended meanwhile
        fields = text.rpartition(b")")[2].split()  # the command name may hold ') '
        if len(fields) >= 2:
            out[int(name)] = (int(fields[1]), fields[0].decode("ascii", "replace"))
    return out


def descendants(root: int) -> list[int]:
    """Return the live (not zombie) descendants of ``root``, by ppid chains in /proc.

    Parameters
    ----------
    root : int
        Process id [-].

    Returns
    -------
    list of int
        Process ids of its children, their children and so on, zombies left out;
        empty where /proc is not available.

    Examples
    --------
    >>> descendants(os.getpid()) == [] or all(p > 0 for p in descendants(os.getpid()))
    True
    """
    table = _table()
    kids: dict[int, list[int]] = {}
    for pid, (ppid, _) in table.items():
        kids.setdefault(ppid, []).append(pid)
    out, todo, seen = [], [root], {root}
    while todo:
        for pid in kids.get(todo.pop(), ()):
            if pid not in seen:
                seen.add(pid)
                todo.append(pid)
                if table[pid][1] not in ("Z", "X"):
                    out.append(pid)
    return out


def _marked(token: str) -> list[int]:
    """Live processes (other than this one) whose environment holds ``TOKEN_VAR=token``."""
    if not token:
        return []
    needle = f"{TOKEN_VAR}={token}\0".encode()
    me, out = os.getpid(), []
    for pid, (_, state) in _table().items():
        if pid == me or state in ("Z", "X"):
            continue
        try:
            with open(f"{_PROC}/{pid}/environ", "rb") as fh:
                env = fh.read()
        except OSError:
            continue  # ended, or not ours to read
        if needle in env:
            out.append(pid)
    return out


def _reap() -> None:
    """Reap every child of this process that has ended (no wait)."""
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except (ChildProcessError, OSError):
            return
        if pid == 0:
            return


def _kill_all(find, limit_s: float) -> int:
    """SIGKILL what ``find()`` returns until it returns nothing or ``limit_s`` [s] passed."""
    end, killed = time.monotonic() + limit_s, set()
    while True:
        pids = find()
        if not pids or time.monotonic() > end:
            return len(killed)
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
                killed.add(pid)
            except (ProcessLookupError, PermissionError):
                pass
        _reap()
        time.sleep(0.01)  # SIGKILL is delivered asynchronously
        _reap()


def kill_tree(token: str = "", limit_s: float = _KILL_S) -> int:
    """SIGKILL every descendant of this process (and every process marked with ``token``).

    Repeated until none is left (a process forked meanwhile is found in the
    next round: its killed parent's orphans come to this process when it is a
    subreaper) or ``limit_s`` has passed; ended children are reaped.

    Parameters
    ----------
    token : str
        The run's token (:data:`TOKEN_VAR`); empty: the tree only.
    limit_s : float
        Longest time spent killing [s].

    Returns
    -------
    int
        Number of processes signalled [-].
    """
    me = os.getpid()
    return _kill_all(lambda: sorted(set(descendants(me)) | set(_marked(token))), limit_s)


def kill_marked(token: str, limit_s: float = _KILL_S) -> int:
    """SIGKILL every live process whose environment holds ``TOKEN_VAR=token``.

    Parameters
    ----------
    token : str
        The run's token.
    limit_s : float
        Longest time spent killing [s].

    Returns
    -------
    int
        Number of processes signalled [-]; 0 where /proc is not available.
    """
    if not _ON or not token:
        return 0
    return _kill_all(lambda: _marked(token), limit_s)


def _end_as(status: int) -> None:
    """End this process as a child that ended with wait ``status`` did."""
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        try:
            import resource

            resource.setrlimit(
                resource.RLIMIT_CORE, (0, resource.getrlimit(resource.RLIMIT_CORE)[1])
            )
            signal.signal(sig, signal.SIG_DFL)
            signal.pthread_sigmask(signal.SIG_UNBLOCK, [sig])
            os.kill(os.getpid(), sig)
        except (OSError, ValueError):
            pass
        os._exit(128 + sig)
    os._exit(os.WEXITSTATUS(status) if os.WIFEXITED(status) else 70)


def supervise(ppid: int, fd: int) -> int:
    """Become the run's supervisor and fork the worker; returns in the worker only.

    Linux: see the module's docstring.  Elsewhere: returns at once, the caller
    is the worker.  Ends the process (code 70) when ``ppid`` is no longer its
    parent (ptoverify died before the death signal was armed).

    Parameters
    ----------
    ppid : int
        Process id of ptoverify (the parent of this process).
    fd : int
        The worker's end of the socket to ptoverify (the supervisor closes it).

    Returns
    -------
    int
        Process id of the worker's parent, to watch (the supervisor, or ``ppid``).
    """
    if not _ON:
        return ppid
    token = os.environ.get(TOKEN_VAR, "")

    def on_signal(signum: int, _frame) -> None:
        kill_tree(token)
        _end_as(signum)  # as if killed by it

    for sig in _SIGNALS:
        signal.signal(sig, on_signal)
    _prctl(_PR_SET_CHILD_SUBREAPER, 1)
    _prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != ppid:
        os._exit(70)
    me = os.getpid()
    worker = os.fork()
    if worker == 0:
        for sig in _SIGNALS:
            signal.signal(sig, signal.SIG_DFL)
        _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != me:
            os._exit(70)
        return me
    os.close(fd)  # the worker alone talks to ptoverify: its end shows EOF when the worker ends
    status = None
    while status is None:
        try:
            pid, st = os.waitpid(-1, 0)  # reaps adopted orphans too
        except ChildProcessError:
            status = 70 << 8
            break
        if pid == worker:
            status = st
    kill_tree(token)
    _end_as(status)
    return me  # not reached
