"""One pluraliser for every layer's sentences: a count with its noun in the right number.

The report (:mod:`ptoverify.report.words` re-exports it), the claims' details and
the gates' sentences all count with :func:`plural`: ``1 sign reversal``,
``2 samples``, never ``1 reversals``.
"""

from __future__ import annotations

from typing import Any

__all__ = ["plural"]


def plural(count: Any, noun: str, many: str | None = None) -> str:
    """Return a count with its noun in the right number: ``1 reversal``, ``2 samples``.

    Parameters
    ----------
    count : int or float
        The count; a float that is a whole number prints without a fraction.
    noun : str
        The singular noun (``sample``, ``sign reversal``).
    many : str, optional
        The plural when it is not ``noun + "s"``.

    Returns
    -------
    str

    Examples
    --------
    >>> plural(1, "sign reversal"), plural(3, "sample"), plural(1.0, "sample")
    ('1 sign reversal', '3 samples', '1 sample')
    >>> plural(0, "limit cycle"), plural(2.5, "sample")
    ('0 limit cycles', '2.5 samples')
    """
    if isinstance(count, float) and count.is_integer():
        count = int(count)
    text = f"{count:g}" if isinstance(count, float) else str(count)
    if count == 1:
        return f"{text} {noun}"
    return f"{text} {many or noun + 's'}"
