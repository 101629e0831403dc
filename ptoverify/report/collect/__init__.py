"""The verification report: compute every result once, draw it, render it.

``collect(cfg)`` is the one step that computes.  It runs the report's
independent stages (:data:`STAGES`): the SymPy derivations with the derivation
gate, the closed loop (zones, properties, Section 6 claims, the numeric
gates), the robustness study, the tuning comparison, the suboptimality sweep,
the ground truth (with the environment), the paper's figures and the poles.  Each stage
draws its own figures (:mod:`ptoverify.report.plots`, which only draws) from its own
results, so nothing large travels between processes.  The stages share only
the configuration, so they can run in a pool of spawned Python processes
(``jobs`` > 1), longest first; with ``jobs=1``, the default, they run in this
process one after the other, and the results are the same either
way.  Work shared inside a stage (the corrected zone and its grid check, the
corrected PTO's closed-loop properties, the claims) is memoized per frozen
configuration in the numeric modules, and the properties section hands its
PTO properties to the gates, so each runs once.  The sections
(:mod:`ptoverify.report.sections`) render the JSON results; the neutral blocks
are printed by :mod:`ptoverify.report.render`.

Two stages are optional: the robustness study
(:func:`ptoverify.studies.robust.run_robust` at :data:`ROBUST_SETTINGS`, the command's
defaults) and the tuning comparison (:func:`tuning_results`: PD and PTO tuned
on the step under shared overshoot bounds, at the reduced search effort
:data:`TUNE_SETTINGS`).  ``skip`` (the command's ``--skip robust,tuning``)
leaves them out for a quick report; their sections then say so.  Each stage's
wall time is kept in ``res["_timings"]`` (not in ``results.json``, which stays
reproducible).

``write_report`` writes the folder atomically: everything, figures included,
goes to a temporary sibling folder that is renamed into place only when
complete, and is removed when the run fails.

Two runs give the same ``results.json`` except ``meta.generated``: wall-clock
timings are not part of the results.
"""

from .parts import figure_inputs, tuning_results, write_traces
from .pool import default_jobs
from .run import collect
from .settings import (
    CONVERGENCE_INTERVALS,
    GROUND_TRUTH_STATES,
    PAPER_TITLE,
    ROBUST_SETTINGS,
    SKIPPABLE,
    TRACE_DIR,
    TUNE_SETTINGS,
    Progress,
)
from .stages import POLE_GATES, PROOF_GATES, STAGES, SYMBOLIC_GATE
from .write import (
    build_sections,
    downloads_intro,
    render_pages,
    results_view,
    stderr_progress,
    write_report,
)

__all__ = [
    "CONVERGENCE_INTERVALS",
    "GROUND_TRUTH_STATES",
    "PAPER_TITLE",
    "POLE_GATES",
    "PROOF_GATES",
    "Progress",
    "ROBUST_SETTINGS",
    "SKIPPABLE",
    "STAGES",
    "SYMBOLIC_GATE",
    "TRACE_DIR",
    "TUNE_SETTINGS",
    "build_sections",
    "collect",
    "default_jobs",
    "downloads_intro",
    "render_pages",
    "figure_inputs",
    "results_view",
    "stderr_progress",
    "tuning_results",
    "write_report",
    "write_traces",
]
