"""The memo mechanism of the model layer: keyed on configuration objects only."""

import dataclasses

import numpy as np
import pytest

from ptoverify.config import paper_config
from ptoverify.model import zones
from ptoverify.model.memo import check_key, clear_memos, memo


def test_keys_are_configurations_and_plain_values():
    cfg = paper_config()
    check_key((cfg, cfg.plant, "strict", 200, 0.5, True, None, (1, ("a", cfg))))
    for bad in (np.zeros(3), b"bytes", [1.0], {"a": 1}, (1, [2])):
        with pytest.raises(TypeError, match="memo key"):
            check_key(bad)

    @dataclasses.dataclass
    class Mutable:
        x: float

    @dataclasses.dataclass(eq=False)
    class ById:
        x: float

    for bad in (Mutable(1.0), ById(1.0)):
        with pytest.raises(TypeError, match="memo key"):
            check_key(bad)


def test_memo_remembers_per_equal_key_and_clears():
    calls = []

    @memo(maxsize=4)
    def f(cfg, reading):
        calls.append((cfg, reading))
        return len(calls)

    a, b = paper_config(), paper_config()  # equal, not identical
    assert f(a, "strict") == f(b, "strict") == 1
    assert f(a, "lenient") == 2
    with pytest.raises(TypeError, match="memo key"):
        f(np.zeros(2), "strict")
    clear_memos()
    assert f(a, "strict") == 3


def test_zone_memo_is_shared_by_equal_configurations():
    """Laws that differ only in gains share one zone (the key is the plant and d)."""
    zones.clear_caches()
    cfg = paper_config()
    other = dataclasses.replace(cfg, pto=dataclasses.replace(cfg.pto, k1=100.0))
    z1 = zones.zone_for_law(cfg, "corrected")
    assert zones.zone_for_law(other, "corrected") is z1
