"""Helpers for users' own test suites: gate a PTO implementation from pytest.

::

    from ptoverify.conform.testing import assert_conforms

    def test_my_law_conforms():
        assert_conforms("mypkg.control:pto")        # or the callable itself

:func:`assert_conforms` runs the same judgement as ``ptoverify conform --law``
(agreement with the reference region by region, odd symmetry, |u| <= w_max,
the closed-loop properties) with the same isolation: the law runs in a child
process with the same time and memory limits
(:class:`~ptoverify.conform.isolation.IsolatedLaw`), so a law that exits
(``os._exit(0)``), hangs, exhausts memory, calls ``pytest.skip()`` or writes
to the frozen configuration makes the calling test fail with a clear message,
never pass, skip or hang.  It raises ``AssertionError`` listing every failing
property with its measured figure, limit and first failing state.
``unverified`` fails, as everywhere.

A callable is sent to the child by name: it must be a module-level function
(``module:qualname`` importable from ``sys.path``, or the module's file); a
lambda or a closure cannot be, and is bad input.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ptoverify.config import Config, load_config
from ptoverify.conform.isolation import MEMORY_LIMIT_BYTES
from ptoverify.conform.userlaw import DEFAULT_TIMEOUT_S
from ptoverify.errors import InputError

__all__ = ["assert_conforms"]


def law_spec(law: Callable | str) -> str:
    """Return the ``MODULE:FUNCTION`` or ``file.py:FUNCTION`` spec that loads ``law``.

    Parameters
    ----------
    law : callable or str
        A module-level function (or a spec, returned as it is).

    Returns
    -------
    str
        A spec the isolated child can load.

    Raises
    ------
    InputError
        A lambda, a closure, a bound method or a callable without a module.
    """
    import importlib.util
    import sys

    if isinstance(law, str):
        return law
    name = getattr(law, "__qualname__", None)
    mod_name = getattr(law, "__module__", None)
    module = sys.modules.get(mod_name or "")
    if not callable(law) or not name or "<" in name or module is None:
        raise InputError(
            f"assert_conforms runs the law in a child process and loads it there by name: "
            f"{law!r} is not a module-level function (a lambda, closure or object cannot be "
            "loaded); define it at module level or pass 'module:function'"
        )
    found = None
    if mod_name != "__main__":
        try:
            found = importlib.util.find_spec(mod_name)
        except (ImportError, ValueError):
            found = None
    path = getattr(module, "__file__", None)
    if found is not None and found.origin == path:
        return f"{mod_name}:{name}"
    if path and str(path).endswith(".py"):
        return f"{path}:{name}"
    raise InputError(f"assert_conforms: cannot load {name!r} from module {mod_name!r} by name")


def assert_conforms(
    law: Callable | str,
    config: Config | str | Path | None = None,
    *,
    rtol: float | None = None,
    timeout: float = DEFAULT_TIMEOUT_S,
    memory_limit: int | None = MEMORY_LIMIT_BYTES,
    precision: str = "float64",
    perturbations: tuple = (),
):
    """Assert that a PTO implementation conforms to the reference law.

    Parameters
    ----------
    law : callable or str
        ``u = law(x1, x2, cfg)`` with x1 [mm], x2 [mm/s], u [mm/s], a
        module-level function; or a spec ``package.module:function`` /
        ``path/to/file.py:function`` as for ``ptoverify conform --law``.
    config : Config, str or Path, optional
        The configuration or a TOML file (default: the paper's values).
    rtol : float, optional
        Agreement tolerance relative to w_max (default: the conform default, 1e-6).
    timeout : float
        Budget for everything the law does [s] (as ``conform --timeout``).
    memory_limit : int or None
        Address-space limit of the law's process [bytes].
    precision : str
        ``float64`` or ``float32``, as ``conform --precision``.
    perturbations : tuple of Perturbation
        Closed loops to compare with the reference's, as ``conform --delay`` etc.
        (:mod:`ptoverify.conform.perturbation`).

    Returns
    -------
    ConformResult
        The full result, when it conforms.

    Raises
    ------
    AssertionError
        When any property fails or could not be evaluated, or the law's process
        hung, ended or ran out of memory; the message lists them.
    ptoverify.errors.InputError
        When the law cannot be loaded, cannot be sent to the child (a lambda)
        or has the wrong signature, or a limit or a perturbation is not valid
        (bad input, before the law runs).

    Examples
    --------
    >>> assert_conforms("ptoverify.conform.gate:reference_law").conforms   # doctest: +SKIP
    True
    """
    from ptoverify.conform import gate as conform
    from ptoverify.conform.junit import conform_verdicts, failure_message
    from ptoverify.errors import InputError
    from ptoverify.verdict import NOT_RUN

    # the limits of `conform --timeout/--tolerance` (an unbounded timeout could hang the run)
    if not (isinstance(timeout, (int, float)) and 0 < timeout <= 86400):
        raise InputError(f"assert_conforms: timeout must be in (0, 86400] s, got {timeout!r}")
    if rtol is not None and not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
        raise InputError(f"assert_conforms: rtol must be in (0, 1), got {rtol!r}")
    if memory_limit is not None and not (
        isinstance(memory_limit, int) and not isinstance(memory_limit, bool) and memory_limit > 0
    ):
        raise InputError(
            f"assert_conforms: memory_limit must be a positive number of bytes or None, "
            f"got {memory_limit!r}"
        )
    from ptoverify.conform.perturbation import Perturbation

    try:
        perturbations = tuple(perturbations)
    except TypeError:
        raise InputError(
            f"assert_conforms: perturbations must be a tuple of Perturbation, got {perturbations!r}"
        ) from None
    wrong = [p for p in perturbations if not isinstance(p, Perturbation)]
    if wrong:
        raise InputError(
            f"assert_conforms: perturbations must be Perturbation objects "
            f"(ptoverify.conform.perturbation.perturbation), got {wrong[0]!r}"
        )
    cfg = config if isinstance(config, Config) else load_config(config)
    spec = law_spec(law)
    target = spec if isinstance(law, str) else getattr(law, "__qualname__", spec)
    kwargs = {} if rtol is None else {"rtol": rtol}
    result = conform.conform_spec(
        spec,
        cfg,
        timeout=timeout,
        memory_limit=memory_limit,
        precision=precision,
        perturbations=perturbations,
        **kwargs,
    )
    verdicts, states = conform_verdicts(result)
    bad = [v for v in verdicts if not v.passed and not (result.conforms and v.status == NOT_RUN)]
    if result.conforms and not bad:
        return result
    lines = [
        f"{target} does not conform to the reference {cfg.conform.reference} law "
        f"(config {cfg.name}):"
    ]
    lines.append(f"  {conform.summary_line(result)}")
    for v in bad:
        lines.append(f"  {v.name}: {failure_message(v, states.get(v.name))} -- {v.detail}")
    for f in result.failures:
        if f.get("property") not in {v.name for v in bad}:
            lines.append(f"  {f.get('property')}: {f.get('detail')}")
    if result.law_output:
        lines.append("  what the law printed (stdout and stderr):")
        lines += [f"    {t}" for t in result.law_output[-2000:].splitlines()]
    raise AssertionError("\n".join(lines))
