"""Atomic output folders for ``report --out`` and ``sweep --out``.

A run writes into a temporary folder created inside the nearest existing
ancestor of the target (same filesystem, so the final rename is atomic), and
creates nothing else until it publishes.  Publishing replaces an existing
target only when it is a ptoverify output (it carries the marker file
``.ptoverify``) or an empty folder; any other existing folder is refused, so
``--out $HOME`` can never delete a user's files.  If the final rename fails,
the previous output is put back.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from ptoverify.errors import InputError

__all__ = ["MARKER", "check_target", "make_temp", "publish", "discard"]

MARKER = ".ptoverify"


def _existing_ancestor(path: Path) -> Path:
    path = path.absolute()
    for parent in path.parents:
        if parent.exists():
            return parent
    return Path("/")


def check_target(out: str | Path) -> Path:
    """Validate an output folder before any computation; return it as a Path.

    Raises
    ------
    InputError
        Empty path, an existing non-folder, a folder that is neither empty nor
        a ptoverify output, or an ancestor that is not a writable folder.
    """
    if str(out).strip() == "":
        raise InputError("--out must not be empty")
    target = Path(out)
    if target.exists():
        if not target.is_dir():
            raise InputError(f"--out '{target}' exists and is not a directory")
        if any(target.iterdir()) and not (target / MARKER).exists():
            raise InputError(
                f"--out '{target}' exists and is not a ptoverify output folder "
                f"(no {MARKER} marker); refusing to replace it"
            )
    anchor = _existing_ancestor(target)
    if not anchor.is_dir():
        raise InputError(f"cannot write '{target}': '{anchor}' is not a directory")
    if not os.access(anchor, os.W_OK | os.X_OK):
        raise InputError(f"cannot write '{target}': '{anchor}' is not writable")
    return target


def make_temp(target: Path) -> Path:
    """Create the temporary folder for ``target`` (in its nearest existing ancestor)."""
    anchor = _existing_ancestor(target)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name or 'out'}.tmp-", dir=anchor))
    except OSError as exc:
        raise InputError(f"cannot write '{target}': {exc.strerror or exc}") from None
    (tmp / MARKER).write_text("written by ptoverify; this folder may be replaced by it\n")
    return tmp


def discard(tmp: Path | None) -> None:
    """Remove a temporary folder (after a failed run)."""
    if tmp is not None:
        shutil.rmtree(tmp, ignore_errors=True)


def publish(tmp: Path, target: Path) -> None:
    """Move the finished ``tmp`` to ``target`` atomically, replacing an older output.

    Raises
    ------
    InputError
        When the folder cannot be put in place (the previous output is restored).
    """
    check_target(target)
    backup = None
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists():
            backup = target.parent / f".{target.name}.old-{os.getpid()}"
            os.replace(target, backup)
        os.replace(tmp, target)
        umask = os.umask(0)
        os.umask(umask)
        target.chmod(0o777 & ~umask)  # mkdtemp made it 0700
    except OSError as exc:
        if backup is not None and not target.exists():
            os.replace(backup, target)
            backup = None
        discard(tmp)
        raise InputError(f"cannot write '{target}': {exc.strerror or exc}") from None
    if backup is not None:
        shutil.rmtree(backup, ignore_errors=True)
