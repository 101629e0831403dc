"""The one progress bar of the command line (``report``, ``sweep``).

Long computations take a callback ``progress(stage)`` (a named stage began)
or ``progress(stage, fraction)`` (share done, 0..1).  :func:`stderr_bar`
returns such a callback drawing one self-overwriting line on stderr, or None
when stderr is not a terminal or the user asked for quiet, so logs and
``--json`` output stay clean.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import TextIO

__all__ = ["Bar", "stderr_bar"]


class Bar:
    """A text progress bar ``[#####.....]  50% stage`` on one line.

    Parameters
    ----------
    stages : sequence of str, optional
        Known stage names, in order: a call without a fraction counts
        stage ``i`` of ``n`` as ``(i + 1) / n`` done.
    stream : file, optional
        Where to draw (default ``sys.stderr``).
    width : int
        Characters of the bar.

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> bar = Bar(["a", "b"], stream=buf, width=4)
    >>> bar("a"); bar("b")
    >>> buf.getvalue().count(chr(13)), "[####] 100% b" in buf.getvalue()
    (2, True)
    """

    def __init__(
        self, stages: Sequence[str] | None = None, stream: TextIO | None = None, width: int = 30
    ):
        self.stages = list(stages or [])
        self.stream = stream
        self.width = width

    def __call__(self, stage: str, fraction: float | None = None) -> None:
        """Draw the bar at ``fraction`` (or at the end of the known ``stage``)."""
        if fraction is None:
            n = len(self.stages)
            fraction = (self.stages.index(stage) + 1) / n if stage in self.stages else 0.0
        fraction = min(max(float(fraction), 0.0), 1.0)
        k = int(round(self.width * fraction))
        out = self.stream or sys.stderr
        out.write(f"\r[{'#' * k}{'.' * (self.width - k)}] {fraction:4.0%} {stage:<24}")
        if fraction >= 1.0:
            out.write("\n")
        out.flush()


def stderr_bar(
    quiet: bool = False, stages: Sequence[str] | None = None
) -> Callable[..., None] | None:
    """Return a :class:`Bar` on stderr when it is a terminal and not ``quiet``; else None.

    Parameters
    ----------
    quiet : bool
        No bar at all.
    stages : sequence of str, optional
        Known stage names (see :class:`Bar`).

    Returns
    -------
    Bar or None
        The callback, or None (callers skip progress then).
    """
    if quiet or not sys.stderr.isatty():
        return None
    return Bar(stages)
