"""How a team gates its own PTO implementation in its own pytest suite.

Copy this file next to your tests and point ``LAW`` at your function.  It runs in
ptoverify's own suite too (``examples`` is in its ``testpaths``).
"""

from pathlib import Path

import pytest

from ptoverify.conform.testing import assert_conforms

LAW = f"{Path(__file__).with_name('my_pto.py')}:pto"  # or "mypkg.control:pto"


@pytest.mark.slow
def test_my_law_conforms():
    """The example third-party law conforms (exit 0 of ``conform``, as a test)."""
    assert_conforms(LAW)


def sluggish(x1, x2, cfg):
    """Return the reference law 5 % short of w_max in the bang-bang region (vectorized).

    At module level: ``assert_conforms`` loads the law by name in its own process.
    """
    import numpy as np

    from ptoverify.conform.gate import reference_law

    u = np.asarray(reference_law(x1, x2, cfg))
    out = np.where(np.abs(u) == cfg.plant.w_max, 0.95 * u, u)
    return float(out) if out.ndim == 0 else out


@pytest.mark.slow
def test_a_slow_law_is_rejected():
    """The helper fails loudly: a law 5 % short of w_max in the bang-bang region."""
    with pytest.raises(AssertionError, match="agreement/BANG_P") as exc:
        assert_conforms(sluggish)
    assert "first failing state" in str(exc.value)
