"""Hostile laws and tables never pass; a closed stdout never turns a failure into success.

Issue 28, class 1: the law is handed copies of its states, what it returns must
be real numbers (never cast), an ambiguous table is bad input, and a broken
pipe keeps the run's own exit code.  Every case is judged by the real gate; the
reference for "should fail" is the property itself (the law is a known mutant
of the reference law), never a stored verdict.
"""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from ptoverify.cli import main
from ptoverify.conform.gate import UserLaw, conform_callable, reference_law, wrap_callable
from ptoverify.conform.userlaw import check_output
from ptoverify.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SMALL = (11, 11, 20)  #: closed-loop sweep for API tests


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------ inputs are copies
def rounding_in_place(x1, x2, cfg):
    """Reference law at a state it rounded in place (to 0.5 mm / 50 mm/s)."""
    if isinstance(x1, np.ndarray):
        np.round(x1 * 2, 0, out=x1)
        x1 /= 2
        np.round(x2 / 50, 0, out=x2)
        x2 *= 50
        return reference_law(x1, x2, cfg)
    return reference_law(round(x1 * 2) / 2, round(x2 / 50) * 50, cfg)


def test_law_gets_copies_of_the_states(paper_cfg):
    seen = []

    def law(x1, x2, cfg):
        seen.append(x1)
        x1[:] = 0.0
        return np.zeros_like(x2)

    user = UserLaw(law, paper_cfg, mode="vectorized")
    x1 = np.array([1.0, 2.0, 3.0])
    user(x1, np.array([0.0, 0.0, 0.0]))
    assert x1.tolist() == [1.0, 2.0, 3.0], "the caller's states are unchanged"
    assert seen[0] is not x1


@pytest.mark.slow
def test_law_that_rounds_its_inputs_in_place_does_not_conform(paper_cfg):
    """Judged at the states it was given, not at the states it rounded them to."""
    r = conform_callable(rounding_in_place, paper_cfg, sweep=SMALL, n_random=2000, n_band=2000)
    assert r.mode == "vectorized"
    assert not r.conforms and "agreement" in r.failed_properties(), r.failures[:2]


# ------------------------------------------------------------------ real numbers only
@pytest.mark.parametrize(
    "value",
    [1.5, 2, np.float32(1.5), np.float64(-3.0), np.int64(4), np.uint8(3), np.array(2.5)],
    ids=lambda v: type(v).__name__,
)
def test_real_numbers_are_accepted(value):
    assert float(check_output(value, (0.0, 0.0))) == float(value)


@pytest.mark.parametrize(
    "value",
    [
        np.complex128(1 + 5j),
        np.complex128(1 + 0j),
        1 + 0j,
        "1.0",
        b"1.0",
        True,
        np.bool_(False),
        None,
        object(),
        np.array(1.0, dtype=object),
    ],
    ids=[
        "complex",
        "complex-0j",
        "py-complex",
        "str",
        "bytes",
        "bool",
        "np-bool",
        "None",
        "object",
        "object-0d",
    ],  # fmt: skip
)
def test_non_numbers_are_rejected_never_cast(value):
    with pytest.raises(InputError, match="expected one real number"):
        check_output(value, (0.5, 1.0))


@pytest.mark.parametrize(
    "value",
    [
        np.array([1.0, 2.0], dtype=complex),
        np.array(["1.0", "2.0"]),
        np.array([1.0, 2.0], dtype=object),
        np.array([True, False]),
        ["1.0", "2.0"],
    ],
    ids=["complex", "str", "object", "bool", "str-list"],
)
def test_non_real_arrays_are_rejected(value):
    with pytest.raises(InputError, match="expected real numbers"):
        check_output(value, (0.5, 1.0), 2)


LAWS = {
    "complex": "return np.complex128(reference_law(x1, x2, cfg) + 5j)",
    "complex_zero_imag": "return np.complex128(reference_law(x1, x2, cfg))",
    "string": "return repr(reference_law(x1, x2, cfg))",
    "string_arrays_for_big_batches": (
        "u = reference_law(x1, x2, cfg)\n"
        "    return np.asarray(u).astype(str) if np.size(x1) > 8 else u"
    ),
    "bool": "return bool(reference_law(x1, x2, cfg) > 0)",
}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_cli_rejects_a_law_returning_non_numbers(capsys, tmp_path, name):
    """Through the isolated CLI: bad input (exit 2) naming the type, never exit 0."""
    path = tmp_path / "law.py"
    path.write_text(
        "import numpy as np\nfrom ptoverify.conform.gate import reference_law\n"
        f"def f(x1, x2, cfg):\n    {LAWS[name]}\n"
    )
    code, out, err = run(capsys, "conform", "--law", f"{path}:f", "--json", "--timeout", "60")
    assert code == 2 and out == "", (code, err)
    assert "real number" in err and err.count("\n") == 1, err


# ------------------------------------------------------------------ configuration
class _Liar(np.ndarray):
    """An array whose every ufunc and array function answers zeros (user code)."""

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        raise AssertionError("the judge ran a method of the law's array subclass")

    def __array_function__(self, func, types, args, kwargs):
        raise AssertionError("the judge ran a method of the law's array subclass")


class _RaisingArrayLike:
    def __array__(self, dtype=None, copy=None):
        raise RuntimeError("the law's object refuses to be an array")


def test_conform_law_r6_ndarray_subclass_lies(paper_cfg):
    """Audit run 6, conform-law/r6-ndarray-subclass-lies: an ndarray subclass returned by
    the law ran its ``__array_ufunc__`` inside the judge (``vec - first`` in mode
    detection), so the isolated child died with ptoverify's traceback. The output is now a
    plain float64 array holding the same values, and a vectorized law returning it is
    judged on those values."""

    def law(x1, x2, cfg):
        return np.asarray(reference_law(x1, x2, cfg), dtype=float).view(_Liar)

    out = check_output(np.array([1.0, -2.0]).view(_Liar), (0.0, 0.0), 2)
    assert type(out) is np.ndarray and out.dtype == np.float64
    assert out.tolist() == [1.0, -2.0]
    user, failures = wrap_callable(law, paper_cfg)
    assert failures == [] and user.mode == "vectorized"
    x1, x2 = np.array([0.3, -20.0]), np.array([5.0, 100.0])
    got = user(x1, x2)
    assert type(got) is np.ndarray
    np.testing.assert_array_equal(got, reference_law(x1, x2, paper_cfg))
    with pytest.raises(InputError, match="dtype object"):
        check_output(_RaisingArrayLike(), (0.5, 1.0), 2)


def test_law_writing_to_the_frozen_config_is_a_finding(paper_cfg):
    def law(x1, x2, cfg):
        object.__setattr__(cfg.plant, "w_max", 1e9)
        return reference_law(x1, x2, cfg)

    cfg = paper_cfg
    user, failures = wrap_callable(law, cfg)
    assert failures and failures[0]["property"] == "evaluation"
    assert "changed its configuration" in failures[0]["detail"]
    assert "cfg.plant.w_max" in failures[0]["detail"]


def test_configuration_sent_to_the_law_hashes_as_one_built_there(paper_cfg):
    """The law's process gets the configuration as a pickle (copy likewise): a hash the
    judging process remembered is not sent (a string's hash differs between processes);
    the copy computes its own, equal to that of an equal configuration, and is equal."""
    import copy
    import pickle
    import subprocess as sp

    from ptoverify.config import paper_config

    h = hash(paper_cfg)  # remembered from here on
    for other in (pickle.loads(pickle.dumps(paper_cfg)), copy.deepcopy(paper_cfg)):
        assert other == paper_cfg and hash(other) == h == hash(paper_config())
        assert {paper_cfg: 1}[other] == 1
    # in another process (its own string hashes): the unpickled copy hashes as one built there
    code = (
        "import pickle, sys\nfrom ptoverify.config import paper_config\n"
        "c = pickle.loads(sys.stdin.buffer.read())\n"
        "print(c == paper_config(), hash(c) == hash(paper_config()), {paper_config(): 1}[c])"
    )
    p = sp.run(
        [sys.executable, "-c", code],
        input=pickle.dumps(paper_cfg),
        capture_output=True,
        env=dict(os.environ, PYTHONPATH=str(ROOT), PYTHONHASHSEED="random"),
        timeout=60,
    )
    assert p.stdout.split() == [b"True", b"True", b"1"], p.stderr[-500:]


# ------------------------------------------------------------------ tables
@pytest.mark.parametrize(
    "text, words",
    [
        ("x1,x2,u,u\n1,2,3,4\n", "column 'u' appears twice"),
        ("x1,x1,x2,u\n1,2,3,4\n", "column 'x1' appears twice"),
        ("\ufeffx1,x2,u\n1,2,3\n", "byte-order mark"),
        ("x1,x2,u\n" + "\0" * 10_000, "NUL bytes"),
        ("\0" * 10_000, "NUL bytes"),
        ("x1,x2,u\n" + "1" * 100_000 + ",2,3\n", "longer than"),
    ],
    ids=["dup-u", "dup-x1", "bom", "nul-after-header", "nul", "long-line"],
)
def test_ambiguous_or_binary_tables_are_bad_input(capsys, tmp_path, text, words):
    path = tmp_path / "t.csv"
    path.write_text(text, encoding="utf-8")
    code, out, err = run(capsys, "conform", "--table", str(path))
    assert code == 2 and out == "" and words in err and err.count("\n") == 1, err


@pytest.mark.slow
def test_nul_table_is_rejected_early_in_bounded_memory(tmp_path):
    """A header and 200 MB of NUL bytes: rejected at line 2, without reading them all."""
    path = tmp_path / "nul.csv"
    with open(path, "wb") as fh:
        fh.write(b"x1,x2,u\n")
        fh.truncate(200 << 20)  # sparse: NUL bytes
    p = subprocess.run(
        [sys.executable, "-c", CHILD_MAXRSS, "conform", "--table", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
    )
    assert p.returncode == 2 and "line 2: NUL bytes" in p.stderr, p.stderr
    rss_mb = int(p.stdout.split()[-1]) / 1024
    assert rss_mb < 400, f"peak memory {rss_mb:.0f} MB for a 200 MB table that is rejected"


#: run the CLI, then print the peak resident size of this process image [KiB]: VmHWM,
#: not getrusage's ru_maxrss, which Linux carries over exec from the forking parent (a
#: pytest worker of ~500 MB)
CHILD_MAXRSS = textwrap.dedent(
    """
    import sys
    from ptoverify.cli import main
    code = main(sys.argv[1:])
    with open("/proc/self/status") as fh:
        hwm = next(line for line in fh if line.startswith("VmHWM:"))
    print(int(hwm.split()[1]))
    sys.exit(code)
    """
)


# ------------------------------------------------------------------ closed pipes
def shell(command: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run(
        ["bash", "-c", f"set -o pipefail; {command}"],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=ROOT,
    )


#: the PTO's linear zone with k1 T = 8: its closed loop limit-cycles (gate no-limit-cycle fails)
UNSTABLE = """\
name = "unstable-pto"
[plant]
bandwidth_hz = 30.0
w_max = 300.0
sample_time = 0.002
position_range = 50.0
[pto]
d = 0.5
k1 = 4000.0
k2 = 3.6
[pd]
kp = 356.0
kd = 1.15
"""


@pytest.fixture
def failing_config(tmp_path):
    path = tmp_path / "unstable.toml"
    path.write_text(UNSTABLE)
    return path


def test_failing_gate_piped_into_a_closed_pipe_still_fails(failing_config):
    """`check | true` under pipefail: the gate fails, so the pipeline fails (1), never 0.

    The gate is no-limit-cycle on a PTO whose linear zone is unstable (a closed-loop
    sweep, 0.8 s of CPU per run); any failing gate shows what is tested, the exit code
    through a closed pipe, and the pole gates load python-control (1.7 s per run)."""
    py = f"{sys.executable} -m ptoverify"
    cmd = f"{py} check --config {failing_config} --gate no-limit-cycle"
    alone = shell(cmd)
    assert alone.returncode == 1, alone.stderr  # the gate fails
    for tail in (" | true", " --json | true", " | head -c 1 >/dev/null"):
        p = shell(f"sleep 0 | {cmd}{tail}")
        assert p.returncode == 1, (tail, p.returncode, p.stderr)
        assert "Traceback" not in p.stderr and "Exception ignored" not in p.stderr


def test_passing_run_into_a_closed_pipe_stays_a_success():
    p = shell(f"{sys.executable} -m ptoverify mintime 5 0 --json | true")
    assert p.returncode == 0, p.stderr
    assert "Traceback" not in p.stderr and "Exception ignored" not in p.stderr


@pytest.mark.slow
def test_failing_conform_into_a_closed_pipe_still_fails(tmp_path):
    """`conform | true`: the law fails (exit 1), and the closed pipe keeps that exit code.

    The law raises at its first call, so the run fails at once (evaluation, every
    other property not run): what is tested is the exit code through the closed
    pipe, which any finding shows; a full judgement of a wrong law costs 3 s more."""
    path = tmp_path / "broken.py"
    path.write_text("def f(x1, x2, cfg):\n    raise RuntimeError('firmware fault: no encoder')\n")
    p = shell(f"{sys.executable} -m ptoverify conform --law {path}:f | true")
    assert p.returncode == 1, p.stderr


def test_wrong_function_name_lists_the_callables_defined(capsys, tmp_path):
    path = tmp_path / "mylaw.py"
    path.write_text(
        "import numpy as np\nfrom ptoverify.conform.gate import reference_law\n"
        "def pto(x1, x2, cfg):\n    return reference_law(x1, x2, cfg)\n"
        "def helper():\n    pass\n"
    )
    code, out, err = run(capsys, "conform", "--law", f"{path}:pto_law", "--timeout", "60")
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert "(callables defined there: helper, pto)" in err, err  # not np or reference_law
