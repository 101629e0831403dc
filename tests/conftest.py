"""Shared fixtures: the paper plant and other plants."""

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from ptoverify.config import Config, PDGains, Plant, PTOSettings, paper_config  # noqa: E402


@pytest.fixture
def paper_cfg() -> Config:
    return paper_config()


def other_configs() -> list[Config]:
    """Two more plants: the 'a = 30 rad/s' reading, and a slower, finer-sampled axis."""
    return [
        Config(
            "slow-a",
            Plant(a=30.0, w_max=300.0, sample_time=0.002, position_range=50.0),
            PDGains(),
            PTOSettings(),
        ),
        Config(
            "fine-T",
            Plant(a=100.0, w_max=100.0, sample_time=0.001, position_range=20.0),
            PDGains(kp=100.0, kd=0.5),
            PTOSettings(d=0.2, k1=100.0, k2=1.0),
        ),
    ]


ALL_CONFIGS = [paper_config(), *other_configs()]


@pytest.fixture(params=ALL_CONFIGS, ids=lambda c: c.name)
def any_cfg(request) -> Config:
    return request.param
