import math

import pytest

from ptoverify.config import config_from_mapping, load_config, paper_config
from ptoverify.errors import ConfigError

GOOD = """name = "paper"
[plant]
bandwidth_hz = 30.0
w_max = 300.0
sample_time = 0.002
position_range = 50.0
[pd]
kp = 356.0
kd = 1.15
[pto]
d = 0.5
k1 = 323.0
k2 = 3.6
"""


def test_paper_defaults_match_design():
    cfg = paper_config()
    assert cfg.plant.a == pytest.approx(2 * math.pi * 30.0, rel=1e-15)
    assert (cfg.plant.w_max, cfg.plant.sample_time, cfg.plant.position_range) == (300, 0.002, 50)
    assert (cfg.pd.kp, cfg.pd.kd, cfg.pto.d, cfg.pto.k1, cfg.pto.k2) == (356, 1.15, 0.5, 323, 3.6)


def test_load_good_file_equals_defaults(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(GOOD)
    assert load_config(f) == paper_config()


def test_a_instead_of_hz(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(GOOD.replace("bandwidth_hz = 30.0", "a = 30.0"))
    assert load_config(f).plant.a == 30.0


@pytest.mark.parametrize(
    "old,new,key",
    [
        ("w_max = 300.0", "w_max = 0.0", "plant.w_max"),
        ("w_max = 300.0", "w_max = -1.0", "plant.w_max"),
        ("sample_time = 0.002", "sample_time = 0", "plant.sample_time"),
        ("bandwidth_hz = 30.0", "bandwidth_hz = -30.0", "plant.bandwidth_hz"),
        ("bandwidth_hz = 30.0", "a = 0.0", "plant.a"),
        ("bandwidth_hz = 30.0", "bandwidth_hz = 30.0\na = 3.0", "exactly one"),
        ("bandwidth_hz = 30.0", "", "exactly one"),
        ("d = 0.5", "d = -0.5", "pto.d"),
        ("d = 0.5", "d = 51.0", "pto.d"),
        ("kp = 356.0", "kp = nan", "pd.kp"),
        ("kp = 356.0", "kp = inf", "pd.kp"),
        ("kp = 356.0", 'kp = "356"', "pd.kp"),
        ("kp = 356.0", "kp = true", "pd.kp"),
        ("kd = 1.15", "kd = 1.15\nki = 2.0", "pd.ki"),
        ("[pto]", "[pto2]", "pto2"),
        ("k2 = 3.6", "", "pto.k2"),
        ('name = "paper"', 'name = "../x"', "name"),
    ],
)
def test_rejections_name_the_key(tmp_path, old, new, key):
    f = tmp_path / "c.toml"
    f.write_text(GOOD.replace(old, new))
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        load_config(f)


def test_missing_section():
    with pytest.raises(ConfigError, match=r"\[pd\]"):
        config_from_mapping(
            {
                "name": "x",
                "plant": {"a": 1.0, "w_max": 1.0, "sample_time": 1.0, "position_range": 1.0},
                "pto": {},
            }
        )


def test_missing_file_and_not_toml(tmp_path):
    with pytest.raises(ConfigError, match="does not exist"):
        load_config(tmp_path / "nope.toml")
    f = tmp_path / "bad.toml"
    f.write_text("this is [not toml")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_config(f)


def test_roundtrip_mapping():
    cfg = paper_config()
    assert config_from_mapping(cfg.to_mapping()) == cfg


@pytest.mark.parametrize(
    "old,new,key",
    [
        ("k1 = 323.0", "k1 = 1e300", "pto.k1"),
        ("k2 = 3.6", "k2 = 1e300", "pto.k2"),
        ("kp = 356.0", "kp = 1e300", "pd.kp"),
        ("kd = 1.15", "kd = 1e300", "pd.kd"),
        ("kp = 356.0", "kp = -1.0", "pd.kp"),
        ("k2 = 3.6", "k2 = -0.1", "pto.k2"),
        ("k1 = 323.0", "k1 = 5000001.0", "pto.k1"),  # k1 T just above 1e4
        ("kd = 1.15", "kd = 10001.0", "pd.kd"),
    ],
)
def test_gains_out_of_range_name_the_key(tmp_path, old, new, key):
    f = tmp_path / "c.toml"
    f.write_text(GOOD.replace(old, new))
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        load_config(f)


def test_gain_range_reaches_the_sampled_instability():
    """The ranges reject nonsense, not unstable gains: at the top of the kp range the
    ZOH-sampled PD loop (computed here independently with scipy's expm) is unstable."""
    import numpy as np
    from scipy.linalg import expm

    from ptoverify.config import LIMITS

    cfg = paper_config()
    a, T = cfg.plant.a, cfg.plant.sample_time
    A = np.array([[0.0, 1.0], [0.0, -a]])
    B = np.array([[0.0], [a]])
    M = expm(np.block([[A, B], [np.zeros((1, 3))]]) * T)
    Ad, Bd = M[:2, :2], M[:2, 2:]

    def radius(kp, kd):
        return max(abs(np.linalg.eigvals(Ad - Bd @ np.array([[kp, kd]]))))

    assert radius(cfg.pd.kp, cfg.pd.kd) < 1, "the paper's PD is stable"
    kp_max = LIMITS["gain_T"] / T
    for kd in (0.0, 1.0, LIMITS["gain"]):
        assert radius(kp_max, kd) > 1, f"kp at its bound with kd = {kd} should be unstable"
    config_from_mapping(
        {**cfg.to_mapping(), "pd": {"kp": kp_max, "kd": LIMITS["gain"]}}
    )  # accepted: the gates, not the loader, judge it


def test_cli_rejects_huge_gain(tmp_path, capsys):
    from ptoverify.cli import main

    f = tmp_path / "c.toml"
    f.write_text(GOOD.replace("k1 = 323.0", "k1 = 1e300"))
    assert main(["check", "--config", str(f), "--gate", "odd-symmetry"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pto.k1" in err[0]


@pytest.mark.parametrize(
    "old,new,key",
    [
        ("w_max = 300.0", "w_max = 1" + "0" * 400, "plant.w_max"),
        ("position_range = 50.0", "position_range = -1" + "0" * 400, "plant.position_range"),
        (
            "k2 = 3.6",
            "k2 = 3.6\n[robustness]\nposition_quantum = 1" + "0" * 400,
            "position_quantum",
        ),
        ("kp = 356.0", "kp = 1" + "0" * 5000, "not valid TOML"),
        ("k2 = 3.6", "k2 = 3.6\n[conform]\nsettling_margin = 1" + "0" * 400, "settling_margin"),
    ],
)
def test_integers_beyond_the_float_range_are_bad_input(tmp_path, old, new, key):
    """Huge TOML integers are bad input naming the key (audit run 6, config/r6-int-*).

    Cases config/r6-int-400-digits, -int-400-digits-range, -quantum-int-huge,
    -conform-margin-400-digits and -int-5000-digits.

    TOML integers are unbounded: 10**400 overflowed ``float()`` and a 5000-digit one
    tripped Python's integer-string limit, both internal errors.
    """
    f = tmp_path / "c.toml"
    f.write_text(GOOD.replace(old, new))
    assert new in f.read_text()
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        load_config(f)


@pytest.mark.parametrize(
    "table",
    ["[ptos]\nk = 1e-300", "[ptos]\nalpha = 5e-324", "[ptos]\nalpha = 1e-200\nk = 1e-60"],
)
def test_ptos_whose_linear_edge_is_not_finite_is_bad_input(tmp_path, table):
    """A [ptos] with alpha k^2 / 2 underflowing names both keys (audit run 7).

    ``k = 1e-300`` (0 < k accepted) made ``ptos_design`` divide by zero: an internal
    error of ``simulate --law ptos``, ``design`` and ``conform --reference ptos``.
    """
    f = tmp_path / "c.toml"
    f.write_text(GOOD + table + "\n")
    text = f.read_text()
    alpha = float(text.split("alpha = ")[1].split()[0]) if "alpha" in text else 0.9
    k = float(text.split("k = ")[1].split()[0]) if "\nk = " in text else 60 * math.pi
    assert alpha * k * k / 2 == 0.0 or not math.isfinite(60 * math.pi * 300 / (alpha * k * k / 2))
    with pytest.raises(ConfigError, match=r"ptos\.alpha.*ptos\.k"):
        load_config(f)


def test_ptos_with_a_tiny_but_finite_edge_term_is_accepted(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(GOOD + "[ptos]\nalpha = 1e-300\n")  # y_l = 2 w / (alpha a): about 3e300 mm
    assert load_config(f).ptos.alpha == 1e-300


def test_digest_changes_with_every_value():
    cfg = paper_config()
    base = cfg.digest()
    m = cfg.to_mapping()
    m["pto"]["k1"] = 324.0
    assert config_from_mapping(m).digest() != base
    assert config_from_mapping(cfg.to_mapping()).digest() == base
