"""Exceptions of ptoverify.

Every error that a user can cause (bad configuration, bad command line, bad
state) is an :class:`InputError`; the command line turns it into one line on
stderr beginning ``ptoverify: error:`` and exit code 2.  A reference that
could not be computed (a solver that did not converge) is a
:class:`SolverError`; a gate that meets one is ``unverified``, never ``pass``.
"""


class PtoverifyError(Exception):
    """Base class of all ptoverify errors."""


class InputError(PtoverifyError, ValueError):
    """Bad input: configuration, command line or state (exit code 2)."""


class ConfigError(InputError):
    """A configuration file or value that is rejected."""


class SolverError(PtoverifyError, RuntimeError):
    """A numerical reference could not be computed (solver failure)."""


class ClusterError(PtoverifyError, RuntimeError):
    """A compute cluster (a Dask scheduler) could not be reached (exit code 1, not bad input)."""


class InfeasibleError(SolverError):
    """A search found nothing that meets its constraints: a result (exit 1), not bad input."""
