"""Cases added in audit run 7 (names hold ``/r7-``): surfaces added or changed since run 6.

Imported by ``run_audit.py`` (``build_cases``); not a test module.  Covered:
``conform --reference ptos|cascade-p`` and ``[conform] reference`` (bad names, tables, the
baselines' gains at their extremes), ``prove --law ptos|cascade-p``, ``design`` options
(axes, sizes, Dask addresses and listeners), ``[robustness]`` boxes around
``MAX_BOX_WORK``, ``conform`` under delay / quantum / noise / a-ratio / float32, odd
states of ``simulate`` and ``mintime``, ``report --skip``, strict ``--json`` (no NaN or
Infinity) on every command that has it, SIGINT/SIGTERM mid-run of report, robust,
design, conform, penalty and prove, and every writer into a read-only mount and under
an existing file.  ``prove`` work limits at extreme a T or zero gains (R9/R10) are not
here: they are being fixed on branch ``h-prove``.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
from collections.abc import Callable
from pathlib import Path

from run_audit import PAPER, PTO, PY, REPO, Case, cfg  # noqa: F401 - the harness's own names

EX_PTO = str(REPO / "examples" / "my_pto.py") + ":pto"
EX_BASE = str(REPO / "examples" / "my_baselines.py")
A_PAPER = 2.0 * math.pi * 30.0  # the paper's a [1/s] (bandwidth_hz = 30)

LISTENER = r"""
import os, socket, sys, time
mode, path = sys.argv[1], sys.argv[2]
s = socket.socket(); s.bind(("127.0.0.1", 0)); s.listen(8)
open(path, "w").write(str(s.getsockname()[1]))
held = []
end = time.monotonic() + 60
s.settimeout(1.0)
while time.monotonic() < end:
    try:
        c, _ = s.accept()
    except OSError:
        continue
    if mode == "garbage":
        c.sendall(b"\xff" * 64 + os.urandom(4096))
    held.append(c)
"""


def strict_json(work: Path, out: str, _err: str) -> str | None:
    """Reject NaN / Infinity in a --json object (Python's json.loads accepts them)."""
    if not out.strip():
        return None

    def bad(const: str) -> None:
        raise ValueError(f"non-standard JSON constant {const}")

    try:
        json.loads(out, parse_constant=bad)
    except ValueError as exc:
        return f"--json not strict JSON: {exc}"
    return None


def empty_stdout(_work: Path, out: str, _err: str) -> str | None:
    """A run stopped by a signal prints no partial JSON."""
    return f"stdout after a signal: {out.strip()[:80]!r}" if out.strip() else None


def _ro_mount(rel: str = "ro") -> Callable[[Path], None]:
    def setup(work: Path) -> None:
        (work / rel).mkdir()
        subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=64k,ro", "tmpfs", str(work / rel)], check=True
        )

    return setup


def _unmount(rel: str = "ro") -> Callable[[Path, str, str], str | None]:
    def check(work: Path, _out: str, _err: str) -> str | None:
        left = os.listdir(work / rel)
        subprocess.run(["umount", str(work / rel)], capture_output=True)
        return f"written into the read-only mount: {left}" if left else None

    return check


def _file_unchanged(rel: str, text: str) -> Callable[[Path, str, str], str | None]:
    def check(work: Path, _out: str, _err: str) -> str | None:
        p = work / rel
        if not p.is_file() or p.read_text() != text:
            return f"{rel} changed or removed by a failed run"
        return None

    return check


def _listener(mode: str) -> Callable[[Path], None]:
    def setup(work: Path) -> None:
        port = work / "port"
        subprocess.Popen(
            [PY, "-c", LISTENER, mode, str(port)],
            start_new_session=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        for _ in range(100):
            if port.exists() and port.read_text():
                return
            __import__("time").sleep(0.1)

    return setup


def _cascade_table(kp: float | None, name: str = "t.csv") -> Callable[[Path], None]:
    """The probe set with u = sat(-kp x1) (the cascade P loop; kp = a / 4 when None)."""

    def setup(work: Path) -> None:
        cfgarg = ["--config", "c.toml"] if (work / "c.toml").exists() else []
        subprocess.run(
            [PTO, "conform", "--emit-grid", "g.csv", *cfgarg],
            cwd=work,
            check=True,
            capture_output=True,
        )
        gain = A_PAPER / 4.0 if kp is None else kp
        lines = (work / "g.csv").read_text().splitlines()
        out = [lines[0].strip() + ",u"]
        for ln in lines[1:]:
            x1, x2 = (float(v) for v in ln.split(","))
            out.append(f"{x1!r},{x2!r},{max(-300.0, min(300.0, -gain * x1))!r}")
        (work / name).write_text("\n".join(out) + "\n")
        (work / "g.csv").unlink()

    return setup


def _both(*checks: Callable[[Path, str, str], str | None] | None):
    def check(work: Path, out: str, err: str) -> str | None:
        found = [c(work, out, err) for c in checks if c is not None]
        found = [f for f in found if f]
        return "; ".join(found) if found else None

    return check


def run7_cases(root: bool) -> list[Case]:  # noqa: C901 - a flat list of cases
    """Cases added in run 7 (names hold ``/r7-``)."""
    cases: list[Case] = []
    add = cases.append
    not_root = None if root else "needs root (a read-only tmpfs mount)"

    # -- conform --reference and [conform] reference -------------------------------------
    for name, value in {"unknown": "xyz", "empty": "", "upper-case": "PTOS", "pd": "pd"}.items():
        add(
            Case(
                f"conform-ref/r7-flag-{name}",
                [PTO, "conform", "--emit-grid", "g.csv", "--reference", value],
                (2,),
                20,
                absent=("g.csv",),
            )
        )
    for name, value in {
        "unknown": '"xyz"',
        "int": "3",
        "list": '["pto"]',
        "table": "{ x = 1 }",
        "empty": '""',
    }.items():
        add(
            Case(
                f"conform-ref/r7-config-{name}",
                [PTO, "conform", "--emit-grid", "g.csv", "--config", "c.toml"],
                (2,),
                20,
                files={"c.toml": PAPER + f"[conform]\nreference = {value}\n"},
                absent=("g.csv",),
            )
        )
    # the baselines' own copies through the command line, against the right and wrong reference
    for fn, ref, expect in (
        ("ptos", "ptos", (0,)),
        ("cascade_p", "cascade-p", (0,)),
        ("ptos_no_half", "ptos", (1,)),
        ("cascade_p_hz", "cascade-p", (1,)),
        ("ptos", "cascade-p", (1,)),
        ("cascade_p", "pto", (1,)),
    ):
        add(
            Case(
                f"conform-ref/r7-law-{fn}-vs-{ref}",
                [PTO, "conform", "--law", f"{EX_BASE}:{fn}", "--reference", ref, "--json"],
                expect,
                120,
                one_line=False,
                check=strict_json,
            )
        )
    # [conform] reference chooses, --reference overrides it
    add(
        Case(
            "conform-ref/r7-config-ptos-with-pto-law",
            [PTO, "conform", "--law", EX_PTO, "--config", "c.toml", "--json"],
            (1,),
            120,
            files={"c.toml": PAPER + '[conform]\nreference = "ptos"\n'},
            check=strict_json,
        )
    )
    add(
        Case(
            "conform-ref/r7-flag-overrides-config",
            [PTO, "conform", "--law", EX_PTO, "--reference", "pto", "--config", "c.toml", "--json"],
            (0,),
            120,
            files={"c.toml": PAPER + '[conform]\nreference = "ptos"\n'},
            check=strict_json,
        )
    )
    # the baselines' gains at the extremes the loader accepts (a result, never an internal error)
    gains = {
        "ptos-k-max": ("[ptos]\nk = 5000000.0\n", "ptos", (0, 1)),  # k T = 1e4
        "ptos-alpha-tiny": ("[ptos]\nalpha = 1e-300\n", "ptos", (0, 1)),  # y_l about 3e300 mm
        "ptos-k-underflow": ("[ptos]\nk = 1e-300\n", "ptos", (2,)),  # alpha k^2 / 2 = 0
        "ptos-alpha-denormal": ("[ptos]\nalpha = 5e-324\n", "ptos", (2,)),
        "cascade-kp-0": ("[cascade]\nkp = 0\n", "cascade-p", (0, 1)),  # u = 0
        "cascade-kp-tiny": ("[cascade]\nkp = 1e-300\n", "cascade-p", (0, 1)),
        "cascade-kp-max": ("[cascade]\nkp = 5000000.0\n", "cascade-p", (0, 1)),
    }
    for name, (table, ref, expect) in gains.items():
        fn = "ptos" if ref == "ptos" else "cascade_p"
        add(
            Case(
                f"conform-ref/r7-gains-{name}",
                [PTO, "conform", "--law", f"{EX_BASE}:{fn}", "--reference", ref]
                + ["--config", "c.toml", "--json"],
                expect,
                120,
                files={"c.toml": PAPER + table},
                one_line=expect == (2,),
                check=strict_json,
            )
        )
        add(
            Case(
                f"conform-ref/r7-emit-{name}",
                [PTO, "conform", "--emit-grid", "g.csv", "--reference", ref, "--config", "c.toml"],
                (0,) if expect != (2,) else (2,),
                30,
                files={"c.toml": PAPER + table},
                absent=("g.csv",),
            )
        )
    # --emit-grid with options that judge nothing: bad input, never ignored (D17)
    for name, extra in {
        "junit": ["--junit", "j.xml"],
        "tolerance": ["--tolerance", "1e-3"],
        "robust": ["--robust"],
        "a-ratio": ["--a-ratio", "0.5"],
    }.items():
        add(
            Case(
                f"conform-ref/r7-emit-grid-with-{name}",
                [PTO, "conform", "--emit-grid", "g.csv", *extra],
                (2,),
                20,
                absent=("g.csv", "j.xml"),
                check=lambda _w, _o, err: (
                    None
                    if "--emit-grid" in err
                    else f"the message does not name --emit-grid: {err.strip()[:120]!r}"
                ),
            )
        )
    # options a mode does not use: bad input, never ignored (D18)
    for name, argv in {
        "mintime-states-intervals": ["mintime", "--states", "s.csv", "--intervals", "50"],
        "prove-check-law": ["prove", "--check", "c.npz", "--law", "pd"],
        "prove-check-out": ["prove", "--check", "c.npz", "--out", "pr"],
    }.items():
        add(
            Case(
                f"cli/r7-ignored-{name}",
                [PTO, *argv],
                (2,),
                20,
                files={"s.csv": "x1,x2\n1,0\n", "c.npz": b""},
                absent=("pr",),
                check=lambda _w, _o, err, f=argv[-2]: (
                    None if f in err else f"the message does not name {f}: {err.strip()[:120]!r}"
                ),
            )
        )
    # tables against a baseline
    add(
        Case(
            "conform-ref/r7-table-cascade",
            [PTO, "conform", "--table", "t.csv", "--reference", "cascade-p", "--json"],
            (0,),
            60,
            setup=_cascade_table(None),
            check=strict_json,
        )
    )
    add(
        Case(
            "conform-ref/r7-table-cascade-vs-pto",
            [PTO, "conform", "--table", "t.csv", "--json"],
            (1,),
            60,
            setup=_cascade_table(None),
            check=strict_json,
        )
    )
    add(
        Case(
            "conform-ref/r7-table-cascade-kp-0",
            [PTO, "conform", "--table", "t.csv", "--reference", "cascade-p"]
            + ["--config", "c.toml", "--json", "--junit", "j.xml"],
            (0, 1),
            60,
            files={"c.toml": PAPER + "[cascade]\nkp = 0\n"},
            setup=_cascade_table(0.0),
            check=strict_json,
        )
    )
    add(
        Case(
            "conform-ref/r7-table-delay",
            [PTO, "conform", "--table", "t.csv", "--reference", "cascade-p", "--delay", "1"],
            (2,),
            60,
            setup=_cascade_table(None),
        )
    )

    # -- prove --law ptos | cascade-p --------------------------------------------------------
    for name, argv in {
        "ptos": ["--law", "ptos"],
        "ptos-json": ["--law", "ptos", "--json"],
        "ptos-with-cascade-out": ["--law", "cascade-p", "--law", "ptos", "--out", "pr"],
        "ptos-a-interval": ["--law", "ptos", "--a-interval", "0.9,1.1", "--json"],
        "law-unknown": ["--law", "cascade", "--json"],
    }.items():
        add(Case(f"prove/r7-{name}", [PTO, "prove", *argv], (2,), 20, absent=("pr",)))
    for name, (argv, files) in {
        "cascade-twice": (["--law", "cascade-p", "--law", "cascade-p"], {}),
        "cascade-kp-0": (
            ["--law", "cascade-p", "--config", "c.toml"],
            {"c.toml": PAPER + "[cascade]\nkp = 0\n"},
        ),
        "cascade-a-interval": (["--law", "cascade-p", "--a-interval", "0.8,1.25"], {}),
    }.items():
        add(
            Case(
                f"prove/r7-{name}",
                [PTO, "prove", *argv, "--json"],
                (0, 1),
                150,
                files=files,
                check=strict_json,
            )
        )

    # -- design options ------------------------------------------------------------------------
    one = ["--sample-times", "0.002", "--bandwidths", "30", "--grid", "2"]
    for name, argv in {
        "sample-time-negative": ["--sample-times", "-0.002", "--bandwidths", "30"],
        "sample-time-zero": ["--sample-times", "0", "--bandwidths", "30"],
        "bandwidth-zero": ["--sample-times", "0.002", "--bandwidths", "0"],
        "bandwidth-nan": ["--sample-times", "0.002", "--bandwidths", "nan"],
        "sample-times-empty": ["--sample-times", "--bandwidths", "30"],
        "grid-1": [*one[:4], "--grid", "1"],
        "grid-101": [*one[:4], "--grid", "101"],
        "jobs-0": [*one, "--jobs", "0"],
        "law-unknown": [*one, "--laws", "ptos2"],
        "dask-empty": [*one, "--dask", ""],
        "dask-port-70000": [*one, "--dask", "tcp://127.0.0.1:70000"],
        "dask-inproc": [*one, "--dask", "inproc://x"],
        "dask-http": [*one, "--dask", "http://127.0.0.1:8786"],
        "dask-no-port": [*one, "--dask", "tcp://127.0.0.1"],
        "dask-port-0": [*one, "--dask", "tcp://127.0.0.1:0"],
        "tuned-negative": [*one, "--tuned", "-1"],
        "out-empty": [*one, "--out", ""],
    }.items():
        add(Case(f"design/r7-{name}", [PTO, "design", *argv, "--json"], (2,), 20, absent=("de",)))
    add(
        Case(
            "design/r7-dask-closed-port",
            [PTO, "design", *one, "--dask", "tcp://127.0.0.1:1", "--json"],
            (1,),
            15,
        )
    )
    for mode in ("silent", "garbage"):
        add(
            Case(
                f"design/r7-dask-{mode}-listener",
                f'"$PTO" design {" ".join(one)} --dask tcp://127.0.0.1:$(cat port) --json',
                (1,),
                15,
                setup=_listener(mode),
            )
        )
    add(
        Case(
            "design/r7-laws-twice-every-law",
            [PTO, "design", *one, "--laws", "pd", "pd", "to", "pto", "pto-printed", "ptos"]
            + ["cascade-p", "--json"],
            (0, 1),
            150,
            check=strict_json,
        )
    )
    add(
        Case(
            "design/r7-out-existing-file",
            [PTO, "design", *one, "--out", "de"],
            (2,),
            30,
            files={"de": "mine\n"},
            check=_file_unchanged("de", "mine\n"),
        )
    )

    # -- [robustness] around MAX_BOX_WORK (400,000 cell-samples) -----------------------------
    over = (
        "[robustness]\ndelay_samples = [0, 10]\na_ratio = [0.2, 1.25]\nw_max_ratio = [0.1, 1.0]\n"
    )
    under = (
        "[robustness]\ndelay_samples = [0, 10]\na_ratio = [0.3, 1.25]\nw_max_ratio = [0.1, 1.0]\n"
    )
    small = ["--grid", "3", "--generations", "0", "--population", "5", "--quiet"]
    add(
        Case(
            "robust/r7-box-just-over-limit",  # 165 cells x 2463 samples = 406,395
            [PTO, "robust", *small, "--config", "c.toml", "--json"],
            (2,),
            15,
            files={"c.toml": PAPER + over},
        )
    )
    add(
        Case(
            "robust/r7-box-just-under-limit-pd",  # 165 cells x 2198 samples = 362,670
            [PTO, "robust", *small, "--law", "pd", "--config", "c.toml", "--json"],
            (0, 1),
            500,
            files={"c.toml": PAPER + under},
            check=strict_json,
        )
    )
    add(
        Case(
            "robust/r7-box-over-limit-check-robust",
            [PTO, "check", "--robust", "--config", "c.toml", "--json"],
            (1,),
            150,
            files={"c.toml": PAPER + over},
            check=strict_json,
        )
    )
    add(
        Case(
            "robust/r7-box-over-limit-report",
            [PTO, "report", "--jobs", "1", "--quiet", "--config", "c.toml", "--out", "rep"],
            (2,),
            20,
            files={"c.toml": PAPER + over},
            absent=("rep",),
        )
    )
    add(
        Case(
            "robust/r7-box-over-limit-conform-robust",
            [PTO, "conform", "--law", EX_PTO, "--robust", "--config", "c.toml", "--json"],
            (0, 1),
            200,
            files={"c.toml": PAPER + over},
            check=strict_json,
        )
    )
    add(
        Case(
            "robust/r7-baselines-widest-noise",
            [PTO, "robust", *small, "--law", "ptos", "--law", "cascade-p", "--config", "c.toml"]
            + ["--json"],
            (0, 1),
            200,
            files={
                "c.toml": PAPER
                + "[robustness]\nposition_quantum = 5.0\nvelocity_noise = 300.0\nseed = 4294967295\n"
            },
            check=strict_json,
        )
    )

    # -- conform under delay / quantum / noise / a-ratio / float32 --------------------------
    for name, (argv, expect) in {
        "delay-10": (["--delay", "10"], (0, 1)),
        "delay-11": (["--delay", "11"], (2,)),
        "quantum-max": (["--quantum", "5"], (0, 1)),
        "quantum-over": (["--quantum", "5.0001"], (2,)),
        "noise-without-seed": (["--velocity-noise", "1"], (2,)),
        "noise-max-seed-max": (["--velocity-noise", "300", "--seed", "4294967295"], (0, 1)),
        "seed-2-32": (["--velocity-noise", "1", "--seed", "4294967296"], (2,)),
        "a-ratio-0.1": (["--a-ratio", "0.1"], (0, 1)),
        "a-ratio-10": (["--a-ratio", "10"], (0, 1)),
        "every-perturbation": (
            ["--delay", "3", "--quantum", "0.5", "--velocity-noise", "10", "--seed", "7"]
            + ["--a-ratio", "0.5"],
            (0, 1),
        ),
        "float32-delay": (["--precision", "float32", "--delay", "1"], (0, 1)),
        "robust-and-delay": (["--robust", "--delay", "1"], (2,)),
        "baseline-delay": (["--reference", "ptos", "--delay", "2"], (1,)),
    }.items():
        add(
            Case(
                f"conform-perturbed/r7-{name}",
                [PTO, "conform", "--law", EX_PTO, *argv, "--json"],
                expect,
                150,
                one_line=expect == (2,),
                check=strict_json,
            )
        )

    # -- simulate / mintime with odd states ---------------------------------------------------
    for name, (argv, expect) in {
        "x0-negative-zero": (["--x0", "-0.0", "-0.0"], (0,)),
        "x0-subnormal": (["--x0", "5e-324", "-5e-324"], (0,)),
        "x0-speed-over-w_max": (["--x0", "0", "100000"], (0,)),
        "x0-beyond-1000x": (["--x0", "50001", "0"], (2,)),
        "x0-hex": (["--x0", "0x10", "0"], (2,)),
        "ptos-every-perturbation-max": (
            ["--law", "ptos", "--x0", "10", "0", "--delay", "10", "--quantum", "5"]
            + ["--velocity-noise", "300", "--seed", "4294967295", "--a-ratio", "0.1"]
            + ["--w-max-ratio", "0.05"],
            (0,),
        ),
        "cascade-from-corner": (
            ["--law", "cascade-p", "--x0", "-50", "-300", "--a-ratio", "10"],
            (0,),
        ),
        "ramp-to-zero": (["--signal", "ramp", "--ramp-to", "0"], (2,)),
    }.items():
        add(
            Case(
                f"simulate/r7-{name}",
                [PTO, "simulate", *argv, "--json"],
                expect,
                30,
                check=strict_json,
            )
        )
    for name, (argv, expect) in {
        "subnormal": (["5e-324", "0"], (0,)),
        "speed-over-w_max": (["0", "301"], (0,)),
        "intervals-1": (["1", "0", "--intervals", "1"], (0,)),
        "negative-zero": (["--json", "--", "-0.0", "-0.0"], (0,)),
    }.items():
        argv = argv if "--json" in argv else [*argv, "--json"]
        add(Case(f"mintime/r7-{name}", [PTO, "mintime", *argv], expect, 60, check=strict_json))

    # -- report --skip ---------------------------------------------------------------------
    for name, skip in {
        "upper-case": "ROBUST",
        "semicolon": "robust;tuning",
        "prove": "prove",
    }.items():
        add(
            Case(
                f"report/r7-skip-{name}",
                [PTO, "report", "--skip", skip, "--out", "rep"],
                (2,),
                20,
                absent=("rep",),
            )
        )
    add(
        Case(
            "report/r7-skip-spaces-json",
            [PTO, "report", "--skip", " robust, tuning ,charts", "--jobs", "1", "--quiet"]
            + ["--out", "rep", "--json"],
            (0,),
            500,
            check=strict_json,
        )
    )

    # -- strict --json on every command that has it ------------------------------------------
    for name, argv, bound in (
        ("check", ["check"], 120),
        ("derive", ["derive"], 120),
        ("sweep", ["sweep", "--grid", "4"], 60),
        ("zone", ["zone"], 60),
        ("tune-ptos", ["tune", "--law", "ptos", "--maxiter", "2"], 120),
        ("tune-cascade", ["tune", "--law", "cascade-p", "--maxiter", "2"], 120),
        ("penalty-baselines", ["penalty", "--count", "2", "--laws", "ptos", "cascade-p"], 60),
        ("simulate-ptos", ["simulate", "--law", "ptos"], 30),
        ("mintime", ["mintime", "5", "0"], 60),
        ("prove-cascade", ["prove", "--law", "cascade-p"], 150),
    ):
        add(Case(f"json/r7-{name}", [PTO, *argv, "--json"], (0, 1), bound, check=strict_json))

    # -- signals mid-run: nothing half-written, no partial JSON -----------------------------
    sig = {
        "design-sigint-out": (
            [PTO, "design", "--laws", "pd", "ptos", "--grid", "30", "--out", "de"],
            4.0,
            signal.SIGINT,
            ("de",),
        ),
        "robust-sigterm-json": (
            # all four laws: --law ptos alone ended in 4.7 s, before the signal (run 7)
            [PTO, "robust", "--quiet", "--json"],
            3.0,
            signal.SIGTERM,
            (),
        ),
        "robust-sigint-json": (
            # all four laws at 3 s: --law cascade-p had ended (its JSON printed) at 5.0 s, and
            # the SIGINT then came in the interpreter's exit: -2 (run 7)
            [PTO, "robust", "--quiet", "--json"],
            3.0,
            signal.SIGINT,
            (),
        ),
        "report-sigterm-late": (
            [PTO, "report", "--skip", "robust,tuning", "--jobs", "2", "--out", "rep", "--quiet"],
            45.0,
            signal.SIGTERM,
            ("rep",),
        ),
        "report-sigint-json": (
            [PTO, "report", "--skip", "charts", "--jobs", "1", "--out", "rep", "--quiet", "--json"],
            10.0,
            signal.SIGINT,
            ("rep",),
        ),
        "conform-report-sigint": (
            [PTO, "conform", "--law", EX_PTO, "--report", "rep", "--json"],
            5.0,
            signal.SIGINT,
            ("rep",),
        ),
        "penalty-sigterm-out": (
            # --tuned: the untuned moves ended in 1.8 s, before the signal (run 7)
            [PTO, "penalty", "--tuned", "--out", "pe"],
            3.0,
            signal.SIGTERM,
            ("pe",),
        ),
        "prove-cascade-sigint-out": (
            [PTO, "prove", "--law", "cascade-p", "--out", "pr"],
            3.0,
            signal.SIGINT,
            ("pr",),
        ),
    }
    # --dask local: a LocalCluster of 2 worker processes torn down by the signal
    dask_local = {
        "design-dask-local-sigint": (["design", "--laws", "pd", "--grid", "20"], signal.SIGINT),
        "design-dask-local-sigterm": (["design", "--laws", "pd", "--grid", "20"], signal.SIGTERM),
        # all four laws: --law pd alone ended in 13.8 s, before the signal (run 7)
        "robust-dask-local-sigint": (["robust", "--quiet", "--json"], signal.SIGINT),
        "prove-dask-local-sigterm": (
            ["prove", "--law", "cascade-p", "--a-interval", "0.5,2", "--json"],
            signal.SIGTERM,
        ),
    }
    for name, (argv, s) in dask_local.items():
        out = ["--out", "dl"] if argv[0] in ("design", "prove") else []
        sig[name] = ([PTO, *argv, "--dask", "local", *out], 15.0, s, ("dl",))
    for name, (cmd, after, s, absent) in sig.items():
        add(
            Case(
                f"signal/r7-{name}",
                cmd,
                (130,) if s == signal.SIGINT else (143,),
                after + 40,
                signal_after=(after, s),
                absent=absent,
                one_line=False,
                check=empty_stdout,
            )
        )

    # -- every writer: a read-only mount, and under an existing file -------------------------
    writers = {
        "mintime-out": ["mintime", "--states", "s.csv", "--out", "{d}/o.csv"],
        "simulate-csv": ["simulate", "--csv", "{d}/s.csv"],
        "check-junit": ["check", "--junit", "{d}/j.xml"],
        "emit-grid": ["conform", "--emit-grid", "{d}/g.csv"],
        "conform-report": ["conform", "--law", EX_PTO, "--report", "{d}/rep"],
        "conform-junit": ["conform", "--law", EX_PTO, "--junit", "{d}/j.xml"],
        "sweep-out": ["sweep", "--grid", "4", "--out", "{d}/sw"],
        "design-out": ["design", *one, "--out", "{d}/de"],
        "penalty-out": ["penalty", "--count", "2", "--laws", "pd", "--out", "{d}/pe"],
        "prove-out": ["prove", "--law", "cascade-p", "--out", "{d}/pr"],
        "report-out": ["report", "--skip", "robust,tuning,charts", "--out", "{d}/rep"],
    }
    for name, argv in writers.items():
        add(
            Case(
                f"out/r7-read-only-mount-{name}",
                [PTO, *[a.format(d="ro") for a in argv]],
                (2,),
                150,
                files={"s.csv": "x1,x2\n1,0\n2,0\n"},
                setup=_ro_mount() if root else None,
                check=_unmount() if root else None,
                skip=not_root,
            )
        )
        add(
            Case(
                f"out/r7-under-a-file-{name}",
                [PTO, *[a.format(d="afile") for a in argv]],
                (2,),
                150,
                files={"s.csv": "x1,x2\n1,0\n2,0\n", "afile": "mine\n"},
                check=_file_unchanged("afile", "mine\n"),
            )
        )
    return cases
