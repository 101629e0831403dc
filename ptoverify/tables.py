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
            header = _header(path, fh.readline(MAX_HEADER), what)
            need = ", ".join(names)
            for name in names:
                if name not in header:
                    raise InputError(
                        f"{what} '{path}': no column '{name}' in header {','.join(header)} "
                        f"(need {need})"
                    )
            idx = [header.index(name) for name in names]
            rows, lines = _rows(fh, path, what)
    except OSError as exc:
        raise InputError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"cannot read {what} '{path}': not UTF-8 text ({exc.reason})") from None
    except csv.Error as exc:
        raise InputError(f"{what} '{path}': malformed CSV: {exc}") from None
    if not lines:
        raise InputError(f"{what} '{path}' has a header but no rows")
    width = max(idx) + 1
    for r, i in zip(rows, lines, strict=True):
        if len(r) < width:
            raise InputError(f"{what} '{path}' line {i}: missing field (need {need})")
    cols = []
    for name, j in zip(names, idx, strict=True):
        text = [r[j] for r in rows]
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


#: Longest header line read [characters].
MAX_HEADER = 1 << 16
#: Longest data line accepted [characters] (a row of a few numbers needs < 100).
MAX_LINE = 1 << 12


def _header(path, head: str, what: str) -> list[str]:
    """Parse and check a header: text, no byte-order mark, named columns, none twice."""
    if "\x00" in head:
        raise InputError(f"{what} '{path}' line 1: NUL bytes; not a CSV text file")
    if head.startswith("\ufeff"):
        raise InputError(
            f"{what} '{path}' starts with a UTF-8 byte-order mark (BOM, bytes EF BB BF) before "
            "the header; save it as UTF-8 without BOM"
        )
    if not head.strip():
        raise InputError(f"{what} '{path}' is empty")
    if len(head) >= MAX_HEADER and not head.endswith("\n"):
        raise InputError(f"{what} '{path}' line 1: header longer than {MAX_HEADER} characters")
    header = [h.strip() for h in next(csv.reader([head]))]
    seen: set[str] = set()
    for name in header:
        if name and name in seen:
            raise InputError(
                f"{what} '{path}': column '{name}' appears twice in header {','.join(header)}; "
                "which one is meant is ambiguous"
            )
        seen.add(name)
    return header


def _rows(fh, path, what: str) -> tuple[list[list[str]], list[int]]:
    """Read the data rows line by line, rejecting NUL bytes and overlong lines at once.

    One :func:`csv.reader` parses the checked, non-blank lines; a row that would
    span lines (a quoted line break) is malformed.
    """
    lines: list[int] = []

    def checked():
        line = 1
        while True:
            text = fh.readline(MAX_LINE)
            if not text:
                return
            line += 1
            if "\x00" in text:
                raise InputError(f"{what} '{path}' line {line}: NUL bytes; not a CSV text file")
            if len(text) >= MAX_LINE and not text.endswith("\n"):
                raise InputError(
                    f"{what} '{path}' line {line}: longer than {MAX_LINE} characters "
                    "(a row holds a few numbers)"
                )
            if text.strip():
                lines.append(line)
                yield text

    rows = []
    for row in csv.reader(checked()):
        if len(rows) + 1 != len(lines):
            raise InputError(f"{what} '{path}' line {lines[len(rows)]}: a quoted field spans lines")
        rows.append(row)
    return rows, lines


def _to_float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan
