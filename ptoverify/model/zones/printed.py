"""The zone as printed, eqs. (19)-(27), and the printed numbers it leads to."""

from __future__ import annotations

import math

import numpy as np

from ptoverify.config import Config
from ptoverify.model.curves import level_curve_x1, level_residual, root_22, root_k
from ptoverify.model.plant import flow

from .corrected import _degenerate, smallest_d
from .margins import _tol, _worst_margin
from .types import _NAN, PTOZone


# ------------------------------------------------------------------ printed
def _printed_numbers(a: float, w: float, T: float, d: float) -> dict:  # noqa: N803
    """Eqs. (21)-(27) exactly as printed."""
    b0 = a * d / w + 2.0 * a * T  # eq. (21), x~10 = d
    y = float(root_22(b0))  # eq. (22)
    x20 = -y * w  # eq. (23)
    k = 1.0 + a * d / x20  # eq. (25)
    z = float(root_k(-a * d / x20))  # eq. (26), m = 1 - k
    omega0 = -x20 / z if z != 0 else _NAN  # eq. (27)
    return {"b0": b0, "y_star": y, "x20_tilde": x20, "k": k, "z_star": z, "omega0": omega0}


def _image_residuals(cfg: Config) -> dict:
    """Residual sigma of the one-sample image of l1 under +-w_max (checks eq. 16/19)."""
    a, w, T = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time
    x2 = -np.linspace(0.01, 1.0, 200) * w
    x1 = level_curve_x1(x2, a, w)
    fp1, fp2 = flow(x1, x2, w, T, a)
    fn = flow(x1, x2, -w, T, a)
    rp = a * fp1 + fp2 + w * np.log1p(-fp2 / w)  # eq. (9) itself, valid also for x2 > 0
    rn = level_residual(fn[0], fn[1], a, w)
    return {
        "image_plus_residual_max_abs": float(np.abs(rp).max()),
        "image_minus_residual_range": [float(rn.min()), float(rn.max())],
        "eq19_residual": -2.0 * a * w * T,
    }


def printed_zone(cfg: Config) -> PTOZone:
    """Switching zone from eqs. (19)-(27) exactly as printed, with a verdict.

    b0 = a d / w_max + 2 a T (eq. 21), y* from eq. (22), x~20 = -y* w_max
    (eq. 23), k = 1 + a d / x~20 (eq. 25), z* from eq. (26), omega0 = -x~20 / z*
    (eq. 27).  Valid only if 0 < omega0 < w_max and the principle (strict
    reading, module docstring) holds for the zone it defines.

    Parameters
    ----------
    cfg : Config
        Configuration (a [rad/s], w_max [mm/s], T [s], d [mm]).

    Returns
    -------
    PTOZone
        The printed construction and its reasons.

    Examples
    --------
    >>> from ptoverify.config import paper_config
    >>> z = printed_zone(paper_config())
    >>> z.valid, z.omega0 > 300.0
    (False, True)
    """
    a, w, T, d = cfg.plant.a, cfg.plant.w_max, cfg.plant.sample_time, cfg.pto.d
    num = _printed_numbers(a, w, T, d)
    om, x20 = num["omega0"], num["x20_tilde"]
    img = _image_residuals(cfg)
    reasons = [
        f"eq. (16) sign: with the +w_max flow of (15), a x1 + x2 grows by a w_max T "
        f"and the image of l1 is l1 itself (max |sigma| = "
        f"{img['image_plus_residual_max_abs']:.2e} mm/s), not the curve (19) at "
        f"sigma = -2 a w_max T = {img['eq19_residual']:.4g} mm/s; under -w_max the image "
        f"has sigma in [{img['image_minus_residual_range'][0]:.4g}, "
        f"{img['image_minus_residual_range'][1]:.4g}] mm/s, not a constant"
    ]
    if x20 < -w:
        reasons.append(
            f"x~20 = {x20:.6g} mm/s lies beyond -w_max = {-w:g} mm/s, outside the "
            "envelope |x2| <= w_max that a sampled state can reach"
        )
    usable = math.isfinite(om) and 0.0 < om < w
    if not usable:
        reasons.append(
            f"omega0 = {om:.6g} mm/s is not in (0, w_max = {w:g}): the interval "
            "[omega0, w_max] of eq. (28) is empty and l1* lies on the S_P side of "
            "l1, so the zone between l1 and l1* is empty; eq. (35) reduces to the "
            "time-optimal law outside the linear zone"
        )
    om_eff = om if usable else w  # no zone: u = -w_max up to l1
    margin = _worst_margin(cfg, om_eff, "strict")
    margin_l = _worst_margin(cfg, om_eff, "lenient")
    holds = margin >= -_tol(cfg)
    reasons.append(
        f"principle (strict) {'holds' if holds else 'fails'} for the zone it "
        f"defines: worst landing sigma = {margin:.6g} mm/s (lenient reading: "
        f"{margin_l:.6g} mm/s)"
    )
    degenerate = usable and _degenerate(cfg, om)
    valid = usable and holds and not degenerate
    details = {"usable": usable, "margin_lenient_mm_s": margin_l, **img}
    return PTOZone(
        construction="printed",
        omega0=om,
        x20_tilde=x20,
        b0=num["b0"],
        y_star=num["y_star"],
        k=num["k"],
        z_star=num["z_star"],
        valid=valid,
        degenerate=degenerate,
        reason="; ".join(reasons),
        reading="strict",
        margin=margin,
        d_min=smallest_d(cfg, "strict"),
        details=details,
    )
