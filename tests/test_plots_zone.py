"""The zone-geometry figure draws what it says (headless)."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from numpy.testing import assert_allclose, assert_array_equal  # noqa: E402

from ptoverify.config import paper_config  # noqa: E402
from ptoverify.model.curves import level_residual  # noqa: E402
from ptoverify.model.laws import make_law  # noqa: E402
from ptoverify.model.zones import zone_for_law  # noqa: E402
from ptoverify.report.plots import plot_zone_geometry, zone_geometry_xlim  # noqa: E402
from ptoverify.sim.simulate import simulate_batch  # noqa: E402


def test_plot_zone_geometry(tmp_path):
    cfg = paper_config()
    zc, zp = zone_for_law(cfg, "corrected"), zone_for_law(cfg, "printed")
    xmax = zone_geometry_xlim(zc, cfg)
    batch = simulate_batch(make_law("pto", cfg), cfg.plant, [0.9 * xmax, -0.5 * xmax], [0, 0], 60)
    out = plot_zone_geometry(zc, zp, cfg, batch)
    a, w = cfg.plant.a, cfg.plant.w_max
    x, y = out["lines"]["l1"].get_data()
    assert_allclose(
        level_residual(x[1:], y[1:], a, w), 0.0, atol=1e-9, err_msg="plotted l1 lies on eq. (9)"
    )
    x, y = out["lines"]["l1*"].get_data()
    assert_allclose(
        level_residual(x[1:], y[1:], a, zc.omega0),
        0.0,
        atol=1e-9,
        err_msg="plotted l1* lies on eq. (13) at the given zone's omega0",
    )
    assert_array_equal(out["lines"]["trajectories"].get_xdata(), batch.x1[:, 0])
    assert out["zone"] is zc and out["printed"] is zp
    assert out["ax"].get_xlim() == (-xmax, xmax)
    assert out["ax"].get_xlabel().endswith("[mm]")
    out["figure"].savefig(tmp_path / "zone.png")
    assert (tmp_path / "zone.png").stat().st_size > 1000
    assert np.isfinite(out["printed"].omega0)
