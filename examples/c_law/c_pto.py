"""The C99 PTO law of ``pto_law.c``, built with the system C compiler, as ``u = f(x1, x2, cfg)``.

Gate it like any Python law::

    ptoverify conform --law examples/c_law/c_pto.py:pto          # double precision
    ptoverify conform --law examples/c_law/c_pto.py:pto_single   # the -DPTO_SINGLE build

On first use, each variant is compiled (``cc -std=c99 -O2 -shared -fPIC``, warnings as
errors) into a fresh temporary folder, removed at exit, and loaded with ctypes.  Nothing is
written next to this file.  The zone level omega0 is computed once per configuration by
ptoverify (``ptoverify zone --json``, key ``corrected.omega0``) and handed to the C code with
the gains, as firmware gets it from its parameter set.

Code that cannot be called from Python (a different CPU, a PLC, a vendor tool) takes the
``--table`` route instead: ``ptoverify conform --emit-grid grid.csv``, evaluate the law at each
row on the target, write column ``u`` (and the state as the target actually saw it), then
``ptoverify conform --table grid_with_u.csv``.
"""

from __future__ import annotations

import atexit
import ctypes
import functools
import shutil
import subprocess
import tempfile
from pathlib import Path

SOURCE = Path(__file__).resolve().with_name("pto_law.c")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-shared", "-fPIC"]


class Params(ctypes.Structure):
    """``pto_params`` of pto_law.c: a [rad/s], w_max [mm/s], d [mm], k1 [1/s], k2 [-], omega0 [mm/s]."""

    _fields_ = [(n, ctypes.c_double) for n in ("a", "w_max", "d", "k1", "k2", "omega0")]


def compiler() -> str | None:
    """Return the system C compiler (``cc``, else ``gcc`` or ``clang``), or None."""
    for name in ("cc", "gcc", "clang"):
        path = shutil.which(name)
        if path:
            return path
    return None


def build(dest: Path, single: bool = False) -> Path:
    """Compile pto_law.c into a shared library in ``dest``; return its path.

    Parameters
    ----------
    dest : Path
        Existing folder for the library.
    single : bool
        Compute in float (``-DPTO_SINGLE``) instead of double.

    Returns
    -------
    Path
        The shared library.

    Raises
    ------
    RuntimeError
        No C compiler, or the compilation failed (its output in the message).
    """
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc, gcc or clang) on PATH")
    lib = Path(dest) / ("libpto_single.so" if single else "libpto.so")
    cmd = [cc, *FLAGS, *(["-DPTO_SINGLE"] if single else []), str(SOURCE), "-o", str(lib), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr}")
    return lib


@functools.lru_cache(maxsize=2)
def _function(single: bool):
    dest = Path(tempfile.mkdtemp(prefix="ptoverify-c-law-"))
    atexit.register(shutil.rmtree, dest, True)
    fn = ctypes.CDLL(str(build(dest, single))).pto_u
    fn.argtypes = [ctypes.c_double, ctypes.c_double, ctypes.POINTER(Params)]
    fn.restype = ctypes.c_double
    return fn


@functools.lru_cache(maxsize=8)
def params(cfg) -> Params:
    """Return the C parameter block for a Config (omega0: the corrected zone's level)."""
    from ptoverify.model.zones import corrected_zone

    omega0 = corrected_zone(cfg, verify=False).omega0
    p = cfg.plant
    return Params(p.a, p.w_max, cfg.pto.d, cfg.pto.k1, cfg.pto.k2, float(omega0 or 0.0))


def pto(x1: float, x2: float, cfg) -> float:
    """PTO input u [mm/s] at x1 [mm], x2 [mm/s], from the double-precision C build."""
    return _function(False)(float(x1), float(x2), ctypes.byref(params(cfg)))


def pto_single(x1: float, x2: float, cfg) -> float:
    """PTO input u [mm/s] at x1 [mm], x2 [mm/s], from the single-precision C build."""
    return _function(True)(float(x1), float(x2), ctypes.byref(params(cfg)))
