"""Helpers for users' own test suites: gate a PTO implementation from pytest.

::

    from ptoverify.conform.testing import assert_conforms

    def test_my_law_conforms():
        assert_conforms("mypkg.control:pto")        # or the callable itself

:func:`assert_conforms` runs the same judgement as ``ptoverify conform --law``
(agreement with the reference region by region, odd symmetry, |u| <= w_max,
the closed-loop properties) in the calling process, and raises
``AssertionError`` listing every failing property with its measured figure,
limit and first failing state.  ``unverified`` fails, as everywhere.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ptoverify.config import Config, load_config

__all__ = ["assert_conforms"]


def assert_conforms(
    law: Callable | str,
    config: Config | str | Path | None = None,
    *,
    rtol: float | None = None,
):
    """Assert that a PTO implementation conforms to the reference law.

    Parameters
    ----------
    law : callable or str
        ``u = law(x1, x2, cfg)`` with x1 [mm], x2 [mm/s], u [mm/s]; or a spec
        ``package.module:function`` / ``path/to/file.py:function`` as for
        ``ptoverify conform --law``.
    config : Config, str or Path, optional
        The configuration or a TOML file (default: the paper's values).
    rtol : float, optional
        Agreement tolerance relative to w_max (default: the conform default, 1e-6).

    Returns
    -------
    ConformResult
        The full result, when it conforms.

    Raises
    ------
    AssertionError
        When any property fails or could not be evaluated; the message lists them.
    ptoverify.errors.InputError
        When the law cannot be loaded or has the wrong signature (bad input).

    Examples
    --------
    >>> from ptoverify.conform.gate import reference_law
    >>> assert_conforms(reference_law).conforms   # doctest: +SKIP
    True
    """
    from ptoverify.conform import gate as conform
    from ptoverify.conform.junit import conform_verdicts, failure_message
    from ptoverify.verdict import NOT_RUN

    cfg = config if isinstance(config, Config) else load_config(config)
    if isinstance(law, str):
        target, fn = law, conform.load_callable(law)
    else:
        target, fn = getattr(law, "__qualname__", repr(law)), law
    kwargs = {} if rtol is None else {"rtol": rtol}
    result = conform.conform_callable(fn, cfg, target=target, **kwargs)
    verdicts, states = conform_verdicts(result)
    bad = [v for v in verdicts if not v.passed and not (result.conforms and v.status == NOT_RUN)]
    if result.conforms and not bad:
        return result
    lines = [f"{target} does not conform to the reference PTO law (config {cfg.name}):"]
    for v in bad:
        lines.append(f"  {v.name}: {failure_message(v, states.get(v.name))} -- {v.detail}")
    for f in result.failures:
        if f.get("property") not in {v.name for v in bad}:
            lines.append(f"  {f.get('property')}: {f.get('detail')}")
    raise AssertionError("\n".join(lines))
