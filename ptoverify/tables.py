"""The one CSV reader: named numeric columns of a table with a header.

Used by ``ptoverify mintime --states`` (columns x1, x2) and ``ptoverify conform
--table`` (x1, x2, u).  Bad input raises :class:`~ptoverify.errors.InputError`
with the file line and column named.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ptoverify.errors import InputError

__all__ = ["read_columns"]


def read_columns(
    path: str | Path, names: tuple[str, ...], *, what: str = "table"
) -> tuple[tuple[NDArray[np.float64], ...], NDArray[np.int64]]:
    """Read the columns ``names`` of a CSV file whose first line is a header.

    Other columns are ignored; blank lines are skipped (they still count as
    lines in messages).  Every field read must be a finite number.

    Parameters
    ----------
    path : str or Path
        A regular file, UTF-8 text.
    names : tuple of str
        Columns to read, e.g. ("x1", "x2") [unit of each column].
    what : str
        What the file is, for messages (``states file``, ``table``).

    Returns
    -------
    columns : tuple of ndarray
        One array per name, one value per data row.
    lines : ndarray of int
        The file line of each data row (1 is the header).

    Raises
    ------
    InputError
        Not a regular file, unreadable, empty, a missing column, no rows, a
        missing field or a field that is not a finite number.

    Examples
    --------
    >>> import tempfile, os
    >>> fd, name = tempfile.mkstemp(suffix=".csv"); os.close(fd)
    >>> _ = Path(name).write_text(chr(10).join(["x2,x1", "2,1", "", "4,3", ""]))
    >>> (x1, x2), lines = read_columns(name, ("x1", "x2"))
    >>> x1.tolist(), x2.tolist(), lines.tolist()
    ([1.0, 3.0], [2.0, 4.0], [2, 4])
    >>> os.remove(name)
    """
    p = Path(path)
    if not p.is_file():
        why = "does not exist" if not p.exists() else "is not a regular file"
        raise InputError(f"{what} '{path}' {why}")
    try:
        with open(p, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except OSError as exc:
        raise InputError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"cannot read {what} '{path}': not UTF-8 text ({exc.reason})") from None
    except csv.Error as exc:
        raise InputError(f"{what} '{path}': malformed CSV: {exc}") from None
    if not rows or not any(f.strip() for f in rows[0]):
        raise InputError(f"{what} '{path}' is empty")
    header = [h.strip() for h in rows[0]]
    need = ", ".join(names)
    for name in names:
        if name not in header:
            raise InputError(
                f"{what} '{path}': no column '{name}' in header {','.join(header)} (need {need})"
            )
    idx = [header.index(name) for name in names]
    lines = [i for i, r in enumerate(rows[1:], start=2) if any(f.strip() for f in r)]
    if not lines:
        raise InputError(f"{what} '{path}' has a header but no rows")
    width = max(idx) + 1
    for i in lines:
        if len(rows[i - 1]) < width:
            raise InputError(f"{what} '{path}' line {i}: missing field (need {need})")
    cols = []
    for name, j in zip(names, idx, strict=True):
        text = [rows[i - 1][j] for i in lines]
        try:
            v = np.array(text, dtype=float)
        except ValueError:
            v = np.array([_to_float(t) for t in text])
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{what} '{path}' line {lines[k]}: column {name} = {text[k].strip()!r} "
                "is not a finite number"
            )
        cols.append(v)
    return tuple(cols), np.array(lines, dtype=np.int64)


def _to_float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan
