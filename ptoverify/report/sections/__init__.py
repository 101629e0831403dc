"""The sections of the report, built from the JSON results as neutral blocks.

Each function takes the JSON results of :func:`ptoverify.report.collect.collect` (and
the figure paths) and returns a list of :class:`ptoverify.report.render.Block`.  No
number is typed in here: every figure shown is read from the results, with its
unit (``[-]`` marks a dimensionless number) and 4 significant digits (the full
values are in ``results.json``).  Nothing here computes: the derivation and
errata sections get the records the collect step made.
"""

from .charts import charts
from .common import CAPTIONS, LAW_WORDS, figure, measured_quantity, verdict
from .equations import (
    SYMBOL_UNITS,
    derivations,
    errata,
    inherited_errata,
    render_records,
    tilde_mathml,
    tilde_text,
)
from .front import c31_paper, headline, headline_findings, summary
from .guarantees import CONFIG_UNITS, environment, proofs, robustness, simulate_command, tuning
from .studies import claims, ground_truth, poles, properties, sweep, zone

__all__ = [
    "CAPTIONS",
    "CONFIG_UNITS",
    "LAW_WORDS",
    "SYMBOL_UNITS",
    "c31_paper",
    "charts",
    "claims",
    "derivations",
    "environment",
    "errata",
    "figure",
    "ground_truth",
    "headline",
    "headline_findings",
    "inherited_errata",
    "measured_quantity",
    "poles",
    "proofs",
    "properties",
    "render_records",
    "robustness",
    "simulate_command",
    "summary",
    "sweep",
    "tilde_mathml",
    "tilde_text",
    "tuning",
    "verdict",
    "zone",
]
