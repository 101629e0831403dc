"""The zone-geometry figure draws what it says (headless)."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from numpy.testing import assert_allclose  # noqa: E402

from ptoverify.config import paper_config  # noqa: E402
from ptoverify.curves import level_residual  # noqa: E402
from ptoverify.plots import plot_zone_geometry  # noqa: E402


def test_plot_zone_geometry(tmp_path):
    cfg = paper_config()
    out = plot_zone_geometry(cfg)
    a, w = cfg.plant.a, cfg.plant.w_max
    x, y = out["lines"]["l1"].get_data()
    assert_allclose(
        level_residual(x[1:], y[1:], a, w), 0.0, atol=1e-9, err_msg="plotted l1 lies on eq. (9)"
    )
    x, y = out["lines"]["l1*"].get_data()
    assert_allclose(
        level_residual(x[1:], y[1:], a, out["zone"].omega0),
        0.0,
        atol=1e-9,
        err_msg="plotted l1* lies on eq. (13)",
    )
    assert out["ax"].get_xlabel().endswith("[mm]")
    out["figure"].savefig(tmp_path / "zone.png")
    assert (tmp_path / "zone.png").stat().st_size > 1000
    assert np.isfinite(out["printed"].omega0)
