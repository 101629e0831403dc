"""``conform --table``: regular files only, chunked parsing, envelope, coverage."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ptoverify.cli import main
from ptoverify.conform.agreement import read_table
from ptoverify.conform.gate import MIN_PER_REGION, conformance_grid, reference_law
from ptoverify.errors import InputError

ROOT = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def write(path, x1, x2, u):
    path.write_text(
        "x1,x2,u\n"
        + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(x1.tolist(), x2.tolist(), u.tolist()))
    )
    return path


def test_dev_zero_is_bad_input_at_once():
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero on this OS")
    p = subprocess.run(
        [sys.executable, "-m", "ptoverify", "conform", "--table", "/dev/zero"],
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
    )
    assert p.returncode == 2 and "not a regular file" in p.stderr and p.stdout == ""


def test_fifo_is_bad_input(tmp_path):
    fifo = tmp_path / "t.csv"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        read_table(fifo)


def test_one_row_table_is_insufficient_coverage(capsys, tmp_path):
    table = tmp_path / "one.csv"
    table.write_text("x1,x2,u\n0.0,0.0,0.0\n")
    code, out, _ = run(capsys, "conform", "--table", str(table), "--json")
    data = json.loads(out)
    assert code == 1 and data["conforms"] is False
    assert data["properties"]["coverage"]["status"] == "fail"
    assert data["failures"][0]["property"] == "coverage"
    assert "insufficient coverage" in data["failures"][0]["detail"]


def test_small_grid_is_insufficient_coverage(capsys, tmp_path, paper_cfg):
    """An 11 x 11 grid covers every region with 100 states but not the probe set or the cells."""
    x1, x2 = conformance_grid(paper_cfg, n=11, n_curve=11)
    u = reference_law(x1, x2, paper_cfg)
    table = write(tmp_path / "a.csv", x1, x2, u)
    code, out, _ = run(capsys, "conform", "--table", str(table), "--json")
    data = json.loads(out)
    assert data["agreement"]["pass"] and data["properties"]["agreement"]["status"] == "pass"
    regions = data["agreement"]["regions"]
    assert all(
        e["points"] - e["excluded"] >= MIN_PER_REGION for k, e in regions.items() if k != "ORIGIN"
    )
    assert code == 1 and data["properties"]["coverage"]["status"] == "fail"
    assert "insufficient coverage" in data["failures"][0]["detail"]
    assert "cells empty" in data["properties"]["coverage"]["detail"]


@pytest.mark.parametrize("value", ["1e308", "-5.1e4"])
def test_state_far_outside_envelope_is_bad_input(capsys, tmp_path, value):
    table = tmp_path / "far.csv"
    table.write_text(f"x1,x2,u\n1.0,2.0,-300\n{value},0.0,300\n")
    code, out, err = run(capsys, "conform", "--table", str(table))
    assert code == 2 and out == "" and "line 3" in err and "envelope" in err


def test_error_line_named_across_chunks(monkeypatch, tmp_path):
    import ptoverify.tables as tables

    rows = ["x1,x2,u"] + [f"{i * 0.01},0.0,0.0" for i in range(30)]
    rows[23] = "0.5,abc,0.0"  # line 24 of the file, in the fourth batch of 7 rows
    rows.insert(10, "")  # a blank line still counts as a line
    table = tmp_path / "t.csv"
    table.write_text("\n".join(rows) + "\n")
    monkeypatch.setattr(tables, "CHUNK", 64)  # blocks of 64 characters: 4-5 lines each
    monkeypatch.setattr(tables, "BATCH", 7)
    with pytest.raises(InputError, match=r"line 25: column x2 = 'abc'"):
        read_table(table)


def test_read_round_trips(tmp_path, paper_cfg):
    x1, x2 = conformance_grid(paper_cfg, n=11, n_curve=11)
    u = reference_law(x1, x2, paper_cfg)
    table = write(tmp_path / "t.csv", x1, x2, u)
    got = read_table(table, paper_cfg)
    for a, b in zip(got, (x1, x2, u)):
        assert np.array_equal(a, b), "round trip through repr is exact"


@pytest.mark.parametrize("chunk, batch", [(1, 1), (2, 5), (7, 1), (64, 5), (1 << 20, 1 << 16)])
@pytest.mark.parametrize("seed", range(4))
def test_blocks_read_as_one_file(monkeypatch, tmp_path, chunk, batch, seed):
    """Any block size and batch of rows reads as :mod:`csv` reads the whole file at once.

    Random tables with LF, CR LF and CR line ends, blank and white-space lines,
    extra columns and spaces around numbers; the reference is ``csv.reader`` over
    the file opened with ``newline=""`` (its blank rows dropped, file lines from
    its ``line_num``).  A block size of 1 and 2 splits every CR LF pair.
    """
    import csv

    import ptoverify.tables as tables

    rng = np.random.default_rng(seed)
    ends = ["\n", "\r\n", "\r"]
    text = "x2,x1,u,note" + ends[rng.integers(3)]
    for _ in range(200):
        end = ends[rng.integers(3)]
        kind = rng.integers(6)
        if kind == 0:
            text += end
        elif kind == 1:
            text += "  \t" + end
        else:
            a, b, c = (rng.normal(size=3) * 10.0 ** rng.integers(-3, 4, size=3)).tolist()
            text += f" {a!r},{b!r} ,{c!r},x{kind}{end}"
    if rng.integers(2):
        text = text.rstrip("\r\n")  # no end on the last line
    path = tmp_path / "t.csv"
    path.write_bytes(text.encode())
    monkeypatch.setattr(tables, "CHUNK", chunk)
    monkeypatch.setattr(tables, "BATCH", batch)
    (x1, x2, u), lines = tables.read_columns(path, ("x1", "x2", "u"))
    want, numbers = [], []
    with open(path, newline="") as fh:
        reader = csv.reader(fh)
        next(reader)
        start = reader.line_num + 1
        for row in reader:
            if any(f.strip() for f in row):
                want.append([float(f) for f in row[:3]])
                numbers.append(start)
            start = reader.line_num + 1
    want = np.array(want)
    assert np.array_equal(x1, want[:, 1]) and np.array_equal(x2, want[:, 0])
    assert np.array_equal(u, want[:, 2]) and lines.tolist() == numbers


LONG = " " * 4090 + "1"  #: a field of 4091 characters: with ",2,3" and LF, MAX_LINE


@pytest.mark.parametrize("chunk", [3, 1 << 20])
@pytest.mark.parametrize(
    "body, words",
    [
        ('1,2,3\n4,"5\n6",7\n', "line 3: a quoted field spans lines"),
        ("1,2,3\n\n4,5\n", "line 4: missing field"),
        ("1,2,3\n" + LONG + ",2,3\n", [1.0, 1.0]),  # MAX_LINE characters with its LF
        ("1,2,3\n" + LONG + "5,2,3\n", "line 3: longer than 4096"),
        ("1,2,3\n" + LONG + "5,2,3", "line 3: longer than 4096"),  # at the end of the file
        ("1,2,3\n" + LONG + ",2,3\r\n", "line 3: longer than 4096"),
        ("1,2,3\n1,\x002,3\n", "line 3: NUL bytes"),
        ('1,2,3\n4,5,6,"a\n7,8,9\n', "line 3: a quoted field spans lines"),
        ('1,2,3,5"\n4,5,6\n', [1.0, 4.0]),  # a quote inside an unquoted field is text (csv)
        ("1,2\n", "line 2: missing field"),
        ("1,2,3\n4,x,6\n", "line 3: column x2 = 'x' is not a finite number"),
        ("1,2,3\n" + "9" * 5000 + "\x00\n", "line 3: longer than 4096"),  # NUL past the limit
    ],
)
def test_line_checks_hold_across_blocks(monkeypatch, tmp_path, chunk, body, words):
    import ptoverify.tables as tables

    path = tmp_path / "t.csv"
    path.write_text("x1,x2,u\n" + body, newline="")
    monkeypatch.setattr(tables, "CHUNK", chunk)
    if isinstance(words, list):  # read: the x1 column
        (x1, _, _), lines = tables.read_columns(path, ("x1", "x2", "u"))
        assert lines.tolist() == [2, 3] and x1.tolist() == words
    else:
        with pytest.raises(InputError, match=words):
            tables.read_columns(path, ("x1", "x2", "u"))
