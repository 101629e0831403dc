"""Every figure of the report, drawn from results passed in (the only matplotlib user).

Plots draw; they do not compute.  Every plot function takes results computed by
the caller (``SimResult``, ``BatchResult``, ``PTOZone``, ``SweepResult``,
``ConvergenceStudy``, or plain arrays) and an optional ``ax`` (a new figure when
None), and returns what it drew: a dict from legend label (or role) to artist.
As python-control's ``time_response_plot`` takes a ``TimeResponseData``,
nothing here simulates, builds a law or constructs a zone.  Figures are made
as :class:`matplotlib.figure.Figure` directly, outside pyplot, with constrained
layout, and written by ``Figure.savefig``: importing this package neither
selects nor switches a backend, and nothing is shown.

Catalogue
---------
common       new_figure, new_axes, save_figure, save_drawing, write_png; DPI, SIZE,
             STYLE (per law), REGION_STYLE (per PTO region)
phase        plot_fig2 (eqs. 8-11), plot_fig3 (eq. 12), plot_zones (Fig. 4, eqs. 13-14),
             plot_fig5 (eq. 19), plot_fig6, plot_zone_geometry, zone_geometry_xlim
paper        plot_response (Figs. 7-13), plot_state_trajectories (Fig. 14), FigureInputs,
             save_all (Figs. 2-14 and the zone geometry as PNGs)
studies      plot_sweep, save_sweep; plot_robust_map, save_robust; save_tuning;
             plot_convergence, plot_switch_profiles, save_ground_truth
pareto       plot_pareto (the tuning's fronts, with an inset of the PTO's minus the PD's)
charts       plot_penalty, plot_design, save_charts, save_penalty (move-size penalty,
             coarse design chart)
conformance  plot_du_map, plot_conform_response, save_conform_figures (conform --report)
"""

from ptoverify.report.plots.charts import (
    plot_design,
    plot_penalty,
    save_charts,
    save_penalty,
)
from ptoverify.report.plots.common import (
    DPI,
    REGION_STYLE,
    RENDER_RC,
    SIZE,
    STYLE,
    new_axes,
    new_figure,
    save_drawing,
    save_figure,
    write_png,
)
from ptoverify.report.plots.conformance import (
    plot_conform_response,
    plot_du_map,
    save_conform_figures,
)
from ptoverify.report.plots.paper import (
    FigureInputs,
    plot_response,
    plot_state_trajectories,
    save_all,
)
from ptoverify.report.plots.pareto import plot_pareto
from ptoverify.report.plots.phase import (
    plot_fig2,
    plot_fig3,
    plot_fig5,
    plot_fig6,
    plot_zone_geometry,
    plot_zones,
    zone_geometry_xlim,
)
from ptoverify.report.plots.studies import (
    ROBUST_MAPS,
    plot_convergence,
    plot_robust_map,
    plot_sweep,
    plot_switch_profiles,
    save_ground_truth,
    save_proof_map,
    save_robust,
    save_sweep,
    save_tuning,
)

__all__ = [
    "DPI",
    "SIZE",
    "RENDER_RC",
    "STYLE",
    "REGION_STYLE",
    "new_figure",
    "new_axes",
    "save_figure",
    "save_drawing",
    "write_png",
    "FigureInputs",
    "plot_fig2",
    "plot_fig3",
    "plot_zones",
    "plot_fig5",
    "plot_fig6",
    "plot_response",
    "plot_state_trajectories",
    "zone_geometry_xlim",
    "plot_zone_geometry",
    "save_all",
    "plot_sweep",
    "save_sweep",
    "ROBUST_MAPS",
    "plot_robust_map",
    "save_robust",
    "plot_pareto",
    "save_tuning",
    "plot_convergence",
    "plot_switch_profiles",
    "save_ground_truth",
    "plot_du_map",
    "plot_conform_response",
    "save_conform_figures",
    "save_proof_map",
    "plot_penalty",
    "plot_design",
    "save_charts",
    "save_penalty",
]
