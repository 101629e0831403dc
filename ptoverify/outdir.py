"""Safe, atomic output folders for ``report --out`` and ``sweep --out``.

A run validates its target before any computation (:func:`check_target`:
writability is probed by really creating, then removing, a folder next to it),
computes, writes into a temporary folder ``.NAME.tmp-PID-XXXX`` created in the
nearest existing ancestor of the target (same filesystem, so the final rename
is atomic), and publishes it with one rename (:func:`publish`).

Decisions (fail closed, lose nothing):

- **Manifest.** Every output carries the marker file ``.ptoverify``: JSON with
  the list of files and folders ptoverify wrote (``files``), the configuration
  hash (``config_hash``, see :meth:`ptoverify.config.Config.digest`) and the
  name.  An existing target is replaced only when it is empty or when every
  entry in it is listed in its manifest.  A folder holding anything else (a
  notes file, a sub-folder the user added) is **refused** (exit 2, the foreign
  entries named): ptoverify never deletes, and never silently moves, what it
  did not write.  A marker from before manifests (plain text) lists implicitly
  the names ptoverify writes (``index.html``, ``report.md``, ``results.json``,
  ``sweep.json``, ``figures/*.png``, ``*.png``).
- **Default folders.** When the folder was not named by the user (``report``
  writes ``reports/<config name>`` by default), an output of a *different*
  configuration (another hash, or none recorded) is refused: pass ``--out``.
- **The current folder** (``--out .``) or any folder containing it is refused
  with a clear message: the output is replaced as a whole by a rename, which
  cannot move the folder the shell is in.
- **Concurrency.** Publishing holds an exclusive ``flock`` on the target's
  parent folder, so concurrent runs publish one after another and the last
  complete one wins; a run that cannot get the lock within ``lock_timeout``
  raises :class:`OutputBusy` (exit 1, one line naming the race).  Nothing is
  left behind by either.
- **Stale temporaries.** A temporary or backup folder (``.NAME.tmp-PID-*``,
  ``.NAME.old-PID-*``) that carries the marker and whose process is dead is
  removed by the next run that writes next to it.
- **SIGTERM** is turned into :class:`Terminated` by :func:`sigterm_raises`, so
  the ``finally`` blocks remove the temporary folder; the CLI prints one line
  and exits 143.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import os
import re
import shutil
import signal
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from ptoverify.errors import InputError, PtoverifyError
from ptoverify.outfiles import (
    ENVIRONMENT_ERRNOS,
    GuardedStream,
    check_writable,
    current_umask,
    guarded_std_streams,
    os_error,
    write_atomic,
)

__all__ = [
    "MARKER",
    "OutputBusy",
    "Terminated",
    "Interrupted",
    "check_target",
    "make_temp",
    "publish",
    "discard",
    "read_marker",
    "sigterm_raises",
    "remove_stale",
    "os_error",
    "write_atomic",
    "check_writable",
    "current_umask",
    "GuardedStream",
    "guarded_std_streams",
    "ENVIRONMENT_ERRNOS",
]

MARKER = ".ptoverify"

#: Entries a marker without a manifest (written before manifests existed) stands for.
_LEGACY = re.compile(
    r"^(index\.html|report\.md|results\.json|sweep\.json|figures|[^/]+\.png|figures/[^/]+\.png)$"
)


class OutputBusy(PtoverifyError, RuntimeError):
    """Another run kept the output folder locked too long (a race, exit 1)."""


class Terminated(BaseException):
    """The process received SIGTERM (raised by :func:`sigterm_raises`)."""


class Interrupted(KeyboardInterrupt):
    """The process received SIGINT, Ctrl-C (raised by :func:`sigterm_raises`).

    A KeyboardInterrupt (every handler of one catches it), but not Python's own:
    CPython remembers a ``KeyboardInterrupt`` (exactly that type) that ends code
    run from a string (``exec`` of source text, as ``dataclasses`` and
    ``collections.namedtuple`` do when a module is imported), even when a caller
    catches it, and a ``python -m`` run then ends by SIGINT instead of its exit
    code (130).
    """


@contextlib.contextmanager
def sigterm_raises() -> Iterator[None]:
    """Raise :class:`Terminated` on SIGTERM and :class:`Interrupted` on SIGINT in the block.

    Main thread only.  SIGINT is taken over only where Python's default handler
    has it (an ignored SIGINT, as in a background job, stays ignored).

    Examples
    --------
    >>> with sigterm_raises():
    ...     pass
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_term(signum, frame):
        raise Terminated()

    def on_int(signum, frame):
        raise Interrupted()

    previous = signal.signal(signal.SIGTERM, on_term)
    previous_int = signal.getsignal(signal.SIGINT)
    if previous_int is signal.default_int_handler:
        signal.signal(signal.SIGINT, on_int)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
        if previous_int is signal.default_int_handler:
            signal.signal(signal.SIGINT, previous_int)


def _existing_ancestor(path: Path) -> Path:
    path = path.absolute()
    for parent in path.parents:
        if parent.exists():
            return parent
    return Path("/")


def read_marker(folder: Path) -> dict | None:
    """Return the marker of ``folder`` as a dict, ``{}`` for a legacy marker, None if absent.

    Parameters
    ----------
    folder : Path
        An output folder.

    Returns
    -------
    dict or None
        The marker's content (manifest and config hash).
    """
    marker = Path(folder) / MARKER
    if not marker.is_file():
        return None
    try:
        data = json.loads(marker.read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return {}
    return data if isinstance(data, dict) else {}


def _entries(folder: Path) -> list[str]:
    """Relative posix paths of every entry below ``folder`` (folders and files, no symlink followed)."""
    out = []
    for root, dirs, files in os.walk(folder):
        rel = Path(root).relative_to(folder)
        for name in dirs + files:
            out.append((rel / name).as_posix())
    return out


def _foreign(folder: Path, marker: dict) -> list[str]:
    """Entries of an existing ptoverify output that its manifest does not list."""
    listed = marker.get("files")
    if isinstance(listed, list):
        known = set(map(str, listed)).__contains__
    else:
        known = _LEGACY.match
    foreign = []
    for entry in sorted(_entries(folder)):
        if entry == MARKER or known(entry):
            continue
        if any(entry.startswith(f + "/") for f in foreign):
            continue  # inside a foreign folder already named
        foreign.append(entry)
    return foreign


def _check_replaceable(target: Path, config_hash: str | None, default: bool) -> None:
    try:
        _replaceable(target, config_hash, default)
    except FileNotFoundError:
        pass  # replaced by a concurrent run while we looked: it is checked again under the lock


def _replaceable(target: Path, config_hash: str | None, default: bool) -> None:
    if not target.exists():
        return
    if not target.is_dir() or target.is_symlink():
        raise InputError(f"--out '{target}' exists and is not a directory")
    marker = read_marker(target)
    if marker is None:
        if any(target.iterdir()):
            raise InputError(
                f"--out '{target}' exists and is not a ptoverify output folder "
                f"(no {MARKER} marker); refusing to replace it"
            )
        return
    foreign = _foreign(target, marker)
    if foreign:
        shown = ", ".join(foreign[:5]) + (
            f" and {len(foreign) - 5} more" if len(foreign) > 5 else ""
        )
        raise InputError(
            f"--out '{target}' holds files ptoverify did not write ({shown}); refusing to "
            f"replace it: move them or choose another --out"
        )
    if default and config_hash is not None and marker.get("config_hash") != config_hash:
        raise InputError(
            f"the default output folder '{target}' holds the output of a different "
            f"configuration (config hash {str(marker.get('config_hash'))[:12]} recorded, "
            f"{config_hash[:12]} now); pass --out DIR to write elsewhere (or --out '{target}' "
            f"to replace it on purpose)"
        )


def check_target(out: str | Path, *, config_hash: str | None = None, default: bool = False) -> Path:
    """Validate an output folder before any computation; return it as a Path.

    Parameters
    ----------
    out : str or Path
        The folder.
    config_hash : str, optional
        Hash of the configuration that will be written.
    default : bool
        True when the folder is the default one (not named by the user): an
        output of another configuration there is then refused.

    Returns
    -------
    Path
        ``out`` as a Path.

    Raises
    ------
    InputError
        Empty path; the current folder or one containing it; an existing
        non-folder; a folder that is not empty and not a ptoverify output, or
        that holds entries its manifest does not list; a default folder of
        another configuration; an ancestor in which no folder can be created.

    Examples
    --------
    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> check_target(d + "/out").name
    'out'
    """
    if str(out).strip() == "":
        raise InputError("--out must not be empty")
    target = Path(out)
    resolved = target.resolve()
    cwd = Path.cwd().resolve()
    if resolved == cwd or resolved in cwd.parents:
        raise InputError(
            f"--out '{out}' is the current folder or contains it: an output folder is "
            f"replaced as a whole by a rename, which cannot move the folder you are in; "
            f"name a sub-folder (e.g. --out report)"
        )
    _check_replaceable(target, config_hash, default)
    anchor = _existing_ancestor(target)
    if not anchor.is_dir():
        raise InputError(f"cannot write '{target}': '{anchor}' is not a directory")
    try:  # a real probe: access() says yes to root on read-only or virtual filesystems
        os.rmdir(
            tempfile.mkdtemp(prefix=f".{target.name or 'out'}.probe-{os.getpid()}-", dir=anchor)
        )
    except OSError as exc:
        raise InputError(f"cannot write '{target}': '{anchor}': {exc.strerror or exc}") from None
    return target


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stale(target: Path) -> list[Path]:
    """Remove temporary/backup folders of ``target`` left by dead runs; return them.

    Only folders named ``.NAME.tmp-PID-*`` or ``.NAME.old-PID-*`` that carry
    the marker and whose PID is not a live process are removed.

    Parameters
    ----------
    target : Path
        The output folder whose leftovers are looked for.

    Returns
    -------
    list of Path
        The folders removed.
    """
    target = Path(target)
    removed = []
    pattern = re.compile(rf"^\.{re.escape(target.name or 'out')}\.(tmp|old)-(\d+)-")
    for where in {target.absolute().parent, _existing_ancestor(target)}:
        if not where.is_dir():
            continue
        for entry in where.iterdir():
            m = pattern.match(entry.name)
            if not m or not entry.is_dir() or entry.is_symlink():
                continue
            pid = int(m.group(2))
            if pid == os.getpid() or _pid_alive(pid):
                continue
            try:
                if read_marker(entry) is None and any(entry.iterdir()):
                    continue  # not ours: only marked (or empty) folders are removed
            except OSError:
                continue  # removed by a concurrent run meanwhile
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry)
    return removed


def make_temp(target: Path) -> Path:
    """Create the temporary folder for ``target`` (in its nearest existing ancestor).

    Stale temporaries of dead runs are removed first (:func:`remove_stale`).
    A folder that cannot be created or marked (ENOSPC) is removed and raises
    :func:`os_error` (exit 2).
    """
    remove_stale(target)
    anchor = _existing_ancestor(target)
    try:
        tmp = Path(
            tempfile.mkdtemp(prefix=f".{target.name or 'out'}.tmp-{os.getpid()}-", dir=anchor)
        )
    except OSError as exc:
        raise os_error(exc, target) from None
    try:
        (tmp / MARKER).write_text(json.dumps({"ptoverify": "staging", "pid": os.getpid()}) + "\n")
    except OSError as exc:  # a full disk: the folder fits, its marker does not
        discard(tmp)
        raise os_error(exc, target) from None
    return tmp


def discard(tmp: Path | None) -> None:
    """Remove a temporary folder (after a failed run)."""
    if tmp is not None:
        shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def _locked(folder: Path, timeout: float, target: Path) -> Iterator[None]:
    fd = os.open(folder, os.O_RDONLY)
    try:
        deadline = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError as exc:
                if exc.errno not in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    raise
                if time.monotonic() > deadline:
                    raise OutputBusy(
                        f"another ptoverify run kept publishing to '{target}' for more than "
                        f"{timeout:g} s (concurrent writes to one --out); nothing was written"
                    ) from None
                time.sleep(0.02)
        yield
    finally:
        os.close(fd)  # releases the lock


def publish(
    tmp: Path,
    target: Path,
    *,
    config_hash: str | None = None,
    name: str = "",
    default: bool = False,
    lock_timeout: float = 60.0,
) -> None:
    """Move the finished ``tmp`` to ``target`` atomically, replacing an older output.

    The manifest of ``tmp`` (every entry in it) is written into its marker
    first.  Concurrent publishers to one target are serialized by a lock on
    the target's parent: the last one to finish wins.

    Parameters
    ----------
    tmp : Path
        The finished temporary folder (from :func:`make_temp`); removed on failure.
    target : Path
        The output folder.
    config_hash : str, optional
        Hash of the configuration written (recorded in the marker).
    name : str
        Configuration name (recorded in the marker).
    default : bool
        Whether ``target`` is a default folder (see :func:`check_target`).
    lock_timeout : float
        Longest wait for a concurrent publisher [s].

    Raises
    ------
    InputError
        When the folder cannot be put in place (the previous output is kept),
        or an existing output may not be replaced.
    OutputBusy
        When another run held the folder longer than ``lock_timeout``.
    """
    from ptoverify import __version__

    try:
        files = sorted(e for e in _entries(tmp) if e != MARKER)
        marker = {
            "ptoverify": __version__,
            "note": "written by ptoverify; it replaces this folder only if every entry is listed in files",
            "name": name,
            "config_hash": config_hash,
            "files": files,
        }
        (tmp / MARKER).write_text(json.dumps(marker, indent=1) + "\n")
        tmp.chmod(0o777 & ~current_umask())  # mkdtemp made it 0700
        target.absolute().parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        discard(tmp)
        raise os_error(exc, target) from None
    backup = None
    try:
        with _locked(target.absolute().parent, lock_timeout, target):
            _check_replaceable(target, config_hash, default)
            try:
                if target.exists():
                    backup = Path(
                        tempfile.mkdtemp(
                            prefix=f".{target.name}.old-{os.getpid()}-",
                            dir=target.absolute().parent,
                        )
                    )
                    os.replace(target, backup)  # replaces the empty backup folder
                os.replace(tmp, target)
                tmp = None
            except OSError as exc:
                if backup is not None and not target.exists():
                    os.replace(backup, target)
                    backup = None
                raise os_error(exc, target) from None
    finally:
        discard(tmp)
        discard(backup)
