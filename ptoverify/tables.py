"""The one CSV reader: named numeric columns of a table with a header.

Used by ``ptoverify mintime --states`` (columns x1, x2) and ``ptoverify conform
--table`` (x1, x2, u).  Bad input raises :class:`~ptoverify.errors.InputError`
with the file line and column named.
"""

from __future__ import annotations

import csv
import io
import math
from operator import itemgetter
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
    cols: list[list[NDArray[np.float64]]] = [[] for _ in names]
    numbers: list[NDArray[np.int64]] = []
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
            width, where = max(idx) + 1, f"{what} '{path}'"
            number: list[int] = []  # the file line of each line read and not converted yet
            rows: list[list[str]] = []

            def convert() -> None:  # the rows read so far, into the columns
                if min(map(len, rows)) < width:
                    k = next(k for k, r in enumerate(rows) if len(r) < width)
                    raise InputError(f"{where} line {number[k]}: missing field (need {need})")
                for col, name, j in zip(cols, names, idx, strict=True):
                    col.append(_column(rows, j, number, where, name))
                numbers.append(np.array(number[: len(rows)], dtype=np.int64))
                del number[: len(rows)]
                rows.clear()

            reader = csv.reader(_lines(fh, number, path, what))
            for n_rows, row in enumerate(reader, 1):
                rows.append(row)
                if reader.line_num != n_rows:  # this row took more than one line
                    k = len(rows) - 1
                    raise InputError(f"{where} line {number[k]}: a quoted field spans lines")
                if len(rows) == BATCH:
                    convert()
            if rows:
                convert()
    except OSError as exc:
        raise InputError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise InputError(f"cannot read {what} '{path}': not UTF-8 text ({exc.reason})") from None
    except csv.Error as exc:
        raise InputError(f"{what} '{path}': malformed CSV: {exc}") from None
    if not numbers:
        raise InputError(f"{what} '{path}' has a header but no rows")
    return tuple(np.concatenate(c) for c in cols), np.concatenate(numbers)


def _column(rows: list[list[str]], j: int, number: list[int], where: str, name: str) -> NDArray:
    """Field ``j`` of every row as floats; InputError naming the first that is not finite."""
    text = list(map(itemgetter(j), rows))
    try:
        v = np.array(text, dtype=float)
    except ValueError:
        v = np.array([_to_float(t) for t in text])
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"{where} line {number[k]}: column {name} = {text[k].strip()!r} is not a finite number"
        )
    return v


#: Longest header line read [characters].
MAX_HEADER = 1 << 16
#: Longest data line accepted [characters] (a row of a few numbers needs < 100).
MAX_LINE = 1 << 12
#: Characters read at a time (a few MB of memory for the block and its lines).
CHUNK = 1 << 20
#: Rows converted to floats at a time (the text in memory is this many rows and a block).
BATCH = 1 << 16


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


def _lines(fh, number: list[int], path, what: str):
    """Yield the data lines, reading a block of :data:`CHUNK` characters at a time.

    Lines end as :func:`open` with ``newline=""`` reads them (at a line feed, a
    carriage return and line feed, or a carriage return).  NUL bytes and overlong
    lines are rejected in the block they are in (so a binary file is refused
    after one block, in bounded memory); blank lines are skipped.  The file line
    of each line yielded is appended to ``number`` (the header is line 1) before
    the block's lines are yielded.
    """
    carry, first = "", 2  # the block's last line while its end is not read; its number
    while True:
        block = fh.read(CHUNK)
        text = carry + block
        if not text:
            return
        lines = io.StringIO(text, newline="").readlines()
        carry = lines.pop() if block and not lines[-1].endswith("\n") else ""
        if "\x00" in text or max(map(len, lines), default=0) >= MAX_LINE or len(carry) >= MAX_LINE:
            _reject_line([*lines, carry], first, path, what)
        if any(map(str.isspace, lines)):  # blank lines: skipped, still counted
            number.extend(n for n, t in enumerate(lines, first) if not t.isspace())
            kept = [t for t in lines if not t.isspace()]
        else:
            number.extend(range(first, first + len(lines)))
            kept = lines
        first += len(lines)
        yield from kept


def _reject_line(lines: list[str], first: int, path, what: str) -> None:
    """Reject the first of ``lines`` (file line ``first`` on) with NUL bytes or too long.

    As a reader of at most :data:`MAX_LINE` characters at a time sees them: a
    line is too long when its end is not within its first MAX_LINE characters,
    and NUL bytes count where they are within those.
    """
    for n, t in enumerate(lines, first):
        if "\x00" in t[:MAX_LINE]:
            raise InputError(f"{what} '{path}' line {n}: NUL bytes; not a CSV text file")
        if len(t) > MAX_LINE or (len(t) == MAX_LINE and not t.endswith("\n")):
            raise InputError(
                f"{what} '{path}' line {n}: longer than {MAX_LINE} characters "
                "(a row holds a few numbers)"
            )


def _to_float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan
