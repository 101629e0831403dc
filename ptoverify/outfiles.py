"""Writing single files and the standard streams so that a failure is an error, never success.

Part of the output layer, beside :mod:`ptoverify.outdir` (which re-exports
every name here): one path for OS errors on outputs (:func:`os_error`: the
file, the cause, the errno name; exit 2), atomic single files
(:func:`write_atomic`) and guarded standard streams (:class:`GuardedStream`:
a closed pipe never turns a failing run into exit 0).
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ptoverify.errors import InputError

__all__ = [
    "os_error",
    "write_atomic",
    "check_writable",
    "current_umask",
    "GuardedStream",
    "guarded_std_streams",
    "ENVIRONMENT_ERRNOS",
]


#: OS errors that are the environment's, not a bug: named with the file, exit 2
ENVIRONMENT_ERRNOS = frozenset(
    getattr(errno, n)
    for n in ("ENOSPC", "EDQUOT", "ENAMETOOLONG", "EACCES", "EPERM", "EROFS", "EFBIG", "EIO")
    if hasattr(errno, n)
)


def os_error(exc: OSError, what: str | Path | None = None) -> InputError:
    """Build the one message for an OS error on an output: file, cause, errno name.

    Parameters
    ----------
    exc : OSError
        The error.
    what : str or Path, optional
        The output it concerns (named in preference to the error's own file).

    Returns
    -------
    InputError
        ``cannot write 'FILE': No space left on device (ENOSPC)`` (exit 2).
    """
    name = what if what is not None else exc.filename
    code = errno.errorcode.get(exc.errno or 0, "")
    cause = (exc.strerror or str(exc)) + (f" ({code})" if code else "")
    where = f" '{name}'" if name is not None else ""
    return InputError(f"cannot write{where}: {cause}")


def current_umask() -> int:
    """Return the process's umask (from /proc where it is shown, without changing it)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _replaceable_mode(path: Path) -> None:
    """Raise unless ``path`` is absent or a regular file, link or folder (never a device)."""
    try:
        mode = path.lstat().st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise os_error(exc, path) from None
    if not (stat.S_ISREG(mode) or stat.S_ISLNK(mode) or stat.S_ISDIR(mode)):
        raise InputError(
            f"cannot write '{path}': it exists and is not a regular file "
            "(a device, FIFO or socket is never replaced); name a file"
        )


def check_writable(path: str | Path) -> None:
    """Check, before any computation, that :func:`write_atomic` can write ``path``.

    The same checks as the write itself, on an empty probe: the name is not a
    device, FIFO or socket, and a temporary file can really be created (then
    removed) in its folder (``os.access`` says yes to root on a read-only mount).

    Parameters
    ----------
    path : str or Path
        The file to be written later.

    Raises
    ------
    InputError
        As :func:`write_atomic` would raise it (nothing is left behind).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_writable(Path(d) / "out.xml")
    ...     sorted(os.listdir(d))
    []
    """
    path = Path(path)
    _replaceable_mode(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:200]}.", dir=path.parent or ".")
    except OSError as exc:
        raise os_error(exc, path) from None
    os.close(fd)
    Path(tmp).unlink(missing_ok=True)


def write_atomic(path: str | Path, text: str) -> None:
    """Write a text file atomically (temp file in the same folder, then rename).

    The file gets the mode a plain ``open`` would give it (0666 less the
    umask), not the 0600 of the temporary file.

    Parameters
    ----------
    path : str or Path
        The file.
    text : str
        Its content.

    Raises
    ------
    InputError
        The file cannot be written (:func:`os_error`; nothing is left behind), or
        the name is a device, FIFO or socket: the rename would replace it (as root,
        ``--csv /dev/full`` replaced the device node with a regular file).
    """
    path = Path(path)
    _replaceable_mode(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:200]}.", dir=path.parent or ".")
    except OSError as exc:
        raise os_error(exc, path) from None
    try:
        os.fchmod(fd, 0o666 & ~current_umask())
        with os.fdopen(fd, "w", newline="") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise os_error(exc, path) from None


class GuardedStream(io.TextIOBase):
    """A standard stream whose failure never changes the exit code to success.

    A closed pipe (EPIPE; ``ptoverify check | head``) is remembered and the
    rest of the output is discarded (the descriptor is pointed at /dev/null, so
    the interpreter's last flush is silent too); the run goes on to its own exit
    code.  Any other OS error (ENOSPC on ``> /dev/full``) on stdout raises
    :func:`os_error` (exit 2) once; on stderr it is ignored.

    Parameters
    ----------
    stream : TextIO
        The stream to guard.
    name : str
        ``stdout`` or ``stderr``.
    """

    def __init__(self, stream, name: str):
        super().__init__()
        self.stream, self.name = stream, name
        self.broken: str | None = None

    def _failed(self, exc: OSError) -> None:
        self.broken = type(exc).__name__
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self.stream.fileno())
            os.close(devnull)
        except (OSError, ValueError, AttributeError, io.UnsupportedOperation):
            pass  # not a real descriptor (a test's capture): nothing is flushed later
        if self.name == "stdout" and not isinstance(exc, BrokenPipeError):
            raise os_error(exc, "standard output") from None

    def write(self, text: str) -> int:  # noqa: D102
        if self.broken is None:
            try:
                self.stream.write(text)
            except OSError as exc:
                self._failed(exc)
        return len(text)

    def flush(self) -> None:  # noqa: D102
        if self.broken is None:
            try:
                self.stream.flush()
            except OSError as exc:
                self._failed(exc)

    def isatty(self) -> bool:  # noqa: D102
        return self.broken is None and self.stream.isatty()

    def fileno(self) -> int:  # noqa: D102
        return self.stream.fileno()

    @property
    def encoding(self):  # noqa: D102
        return getattr(self.stream, "encoding", "utf-8")


@contextlib.contextmanager
def guarded_std_streams() -> Iterator[tuple[GuardedStream, GuardedStream]]:
    """Guard ``sys.stdout`` and ``sys.stderr`` (:class:`GuardedStream`) inside the block.

    Flush ``sys.stdout`` inside the block to see a failed write there; what
    is still buffered at its end is flushed without raising.  A stream that was
    closed before the run started (``ptoverify ... >&-``: Python sets it to None)
    is treated as a closed pipe: its output is discarded and the run keeps its
    own exit code.
    """
    import sys

    old = sys.stdout, sys.stderr
    sinks = [open(os.devnull, "w") if s is None else None for s in old]  # noqa: SIM115
    out = GuardedStream(sinks[0] or old[0], "stdout")
    err = GuardedStream(sinks[1] or old[1], "stderr")
    sys.stdout, sys.stderr = out, err
    try:
        yield out, err
    finally:
        sys.stdout, sys.stderr = old
        for stream in (out, err):
            try:
                stream.flush()
            except InputError:
                pass  # reported inside the block when it mattered
        for sink in sinks:
            if sink is not None:
                sink.close()
