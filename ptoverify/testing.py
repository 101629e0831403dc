"""Public entry point of the pytest helper: ``from ptoverify.testing import assert_conforms``."""

from ptoverify.conform.testing import assert_conforms

__all__ = ["assert_conforms"]
