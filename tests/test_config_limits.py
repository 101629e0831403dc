"""Bounded work for every configuration the loader accepts (issue 28, class 2).

The limits of :data:`ptoverify.config.LIMITS` are checked up front, naming the
key and the limit; a property-based test draws configurations across (and just
beyond) the accepted space and runs the fast commands ``zone`` and ``mintime``
on each: every run ends with exit 0, 1 or 2, never an internal error.
"""

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ptoverify.cli import main
from ptoverify.config import LIMITS, config_from_mapping
from ptoverify.errors import ConfigError


def mapping(a, w_max, T, position_range, d_frac):  # noqa: N803
    return {
        "name": "drawn",
        "plant": {"a": a, "w_max": w_max, "sample_time": T, "position_range": position_range},
        "pd": {"kp": 0.5 / T, "kd": 0.5},
        "pto": {"d": d_frac * position_range, "k1": 0.5 / T, "k2": 0.5},
    }


def accepted(m) -> bool:
    try:
        config_from_mapping(m)
    except ConfigError:
        return False
    return True


def test_limits_name_the_key_and_the_limit():
    n_max = LIMITS["samples_across_range"]
    with pytest.raises(ConfigError, match=r"plant\.position_range.*above 2000"):
        config_from_mapping(mapping(188.5, 0.05, 0.002, 50.0, 0.01))  # issue 28: w_max = 0.05
    with pytest.raises(ConfigError, match=r"plant\.sample_time.*a T = 1e-06.*\[0\.01, 20\]"):
        config_from_mapping(mapping(10.0, 300.0, 1e-7, 0.03, 0.5))  # issue 28: a = 10, T = 1e-7
    # just inside both limits: accepted
    T = 0.002  # noqa: N806
    assert accepted(mapping(0.01 / T, 300.0, T, 0.999 * n_max * 300.0 * T, 0.01))


def test_default_quantum_follows_a_tiny_range():
    """position_range 1e-6 mm: the default quantum is lowered, not rejected as if user-set."""
    m = mapping(188.5, 1e-3, 0.002, 1e-6, 0.5)
    cfg = config_from_mapping(m)
    assert cfg.robustness.position_quantum <= 0.1 * 1e-6
    m["robustness"] = {"position_quantum": 0.001}
    with pytest.raises(ConfigError, match="robustness.position_quantum"):
        config_from_mapping(m)


log_uniform = lambda lo, hi: st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)  # noqa: E731


@pytest.mark.slow
@settings(
    max_examples=6,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    a=log_uniform(1.0, 1e4),
    w_max=log_uniform(1.0, 1e4),
    T=log_uniform(1e-5, 0.05),
    n_range=log_uniform(2.0, 3000.0),  # samples to cross the range: up to 1.5 x the limit
    d_frac=st.floats(0.0, 1.0),
)
def test_fast_commands_end_with_a_verdict_on_drawn_configs(
    tmp_path_factory,
    capsys,
    a,
    w_max,
    T,
    n_range,
    d_frac,  # noqa: N803
):
    m = mapping(a, w_max, T, n_range * w_max * T, d_frac)
    path = tmp_path_factory.mktemp("cfg") / "c.toml"
    p, pd, pto = m["plant"], m["pd"], m["pto"]
    path.write_text(
        'name = "drawn"\n[plant]\n'
        + "".join(f"{k} = {v!r}\n" for k, v in p.items())
        + "[pd]\n"
        + "".join(f"{k} = {v!r}\n" for k, v in pd.items())
        + "[pto]\n"
        + "".join(f"{k} = {v!r}\n" for k, v in pto.items())
    )
    ok = accepted(m)
    for argv in (["zone", "--json"], ["mintime", repr(0.5 * p["position_range"]), "0", "--json"]):
        code = main([*argv, "--config", str(path)])
        out, err = capsys.readouterr()
        assert code in (0, 1, 2), (argv, code, err)
        assert "internal error" not in err and "Traceback" not in err, (argv, err)
        assert code in ((0, 1) if ok else (2,)), (argv, ok, code, err)
