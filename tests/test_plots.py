"""Figures are drawn headless, return what they drew, and save non-trivial PNGs."""

import matplotlib
import matplotlib.pyplot as plt
import pytest

from ptoverify import plots
from ptoverify.config import paper_config
from ptoverify.sweep import SweepSettings, run_sweep


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_backend_is_headless():
    assert matplotlib.get_backend().lower() == "agg"


def test_plot_functions_return_what_they_drew():
    cfg = paper_config()
    d = plots.plot_fig2(cfg)
    assert {"l1, x2 <= 0 (kept)", "l2, x2 >= 0 (kept)", "u = +w_max (eq. 8)"} <= set(d)
    d = plots.plot_fig3(cfg)
    assert "saturation |x2| = w_max" in d and "TO closed loop (sampled)" in d
    d = plots.plot_zones(cfg, "corrected")
    assert "linear zone |x1| < d" in d and "switching zone" in d
    assert any(k.startswith("l1* (eq. 13)") for k in d)
    assert "no zone" in plots.plot_zones(cfg, "printed"), "printed omega0 > w_max: no zone drawn"
    assert any(k.startswith("sample in") for k in plots.plot_fig6(cfg, "pto"))
    d = plots.plot_fig5(cfg)
    assert "l~1 as printed (eq. 19)" in d and "image of l1 after T under -w_max" in d
    _, ax = plt.subplots()
    d = plots.plot_response(cfg, "step", "error", ax)
    assert {"TO", "PD", "PTO (corrected zone)", "PTO (as printed)"} <= set(d)
    assert d["PD"].axes is ax and "[mm]" in ax.get_ylabel() and "[s]" in ax.get_xlabel()
    d = plots.plot_state_trajectories(cfg, feedforward=False)
    assert "reference" in d


def test_sweep_heat_map(tmp_path):
    res = run_sweep(paper_config(), SweepSettings(n1=6, n2=6, laws=("to", "pd")))
    d = plots.plot_sweep(res, "pd", "nt")
    assert {"mesh", "unsettled", "colorbar"} <= set(d)
    files = plots.save_sweep(res, tmp_path)
    assert [f.name for f in files] == ["sweep_ratio_tf.png", "sweep_ratio_nt.png"]


@pytest.mark.slow
def test_save_all_writes_figures_2_to_14(tmp_path):
    files = plots.save_all(paper_config(), tmp_path)
    nums = {int(f.name[3:5]) for f in files}
    assert nums == set(range(2, 15)), f"figures written: {sorted(nums)}"
    for f in files:
        assert f.exists() and f.stat().st_size > 10_000, f"{f.name} is too small"
        assert f.stat().st_size < 400_000, f"{f.name} is too large for a report"
