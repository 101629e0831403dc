"""The result of ``ptoverify conform`` and its text form.

Part of ``ptoverify conform`` (:mod:`ptoverify.conform.gate` has the command's
decisions): :class:`ConformResult` (the ``--json`` object), the verdicts both
routes share (|u| <= w_max at the judged states, the agreement) and
:func:`format_result`, the summary a terminal shows.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ptoverify.config import Config
from ptoverify.conform.agreement import failure
from ptoverify.verdict import FAIL, PASS, UNVERIFIED, Verdict

__all__ = [
    "ConformResult",
    "format_result",
    "summary_line",
    "input_bound",
    "agreement_verdict",
    "clip_output",
]


def input_bound(x1, x2, u, cfg: Config, where: str) -> tuple[Verdict, list[dict]]:
    """Judge |u| <= w_max at the given states (``input-bound-grid``).

    Parameters
    ----------
    x1, x2, u : ndarray
        States [mm], [mm/s] and the law's u there [mm/s].
    cfg : Config
        Configuration.
    where : str
        Where the states come from (for the detail).

    Returns
    -------
    verdict : Verdict
        Largest |u| against w_max [mm/s].
    failures : list of dict
        The first state with |u| > w_max, or none.
    """
    w = cfg.plant.w_max
    over = np.abs(u) > w
    v = Verdict(
        "input-bound-grid",
        FAIL if over.any() else PASS,
        float(np.abs(u).max()) if u.size else 0.0,
        w,
        f"max |u| {where}; limit w_max",
        "<=",
        "mm/s",
    )
    fails = []
    if over.any():
        i = int(np.argmax(over))
        fails.append(
            failure(
                "input-bound-grid",
                (x1[i], x2[i]),
                f"|u| = {abs(u[i]):.10g} mm/s > w_max = {w:g} mm/s {where}",
            )
        )
    return v, fails


def agreement_verdict(agree: dict) -> Verdict:
    """Return the ``agreement`` verdict of an agreement summary (largest |u - u_ref| [mm/s]).

    Parameters
    ----------
    agree : dict
        :func:`ptoverify.conform.agreement.agreement`'s summary (with ``sources``).

    Returns
    -------
    Verdict
    """
    return Verdict(
        "agreement",
        PASS if agree["pass"] else FAIL,
        agree["max_abs_du"],
        agree["tolerance_mm_s"],
        f"max |u - u_ref| over {agree['points']} states ({agree['excluded']} curve ties "
        f"excluded): {', '.join(f'{k} {v}' for k, v in agree.get('sources', {}).items())}",
        "<=",
        "mm/s",
    )


@dataclass
class ConformResult:
    """Outcome of ``ptoverify conform`` (the JSON object, see :meth:`to_json`).

    Attributes
    ----------
    conforms : bool
        True when every property is ``pass`` and nothing failed.
    mode : str
        ``vectorized``, ``scalar`` or ``table``.
    target : str
        The ``--law`` spec or ``--table`` path.
    mode_reason : str
        Why the mode was chosen.
    agreement : dict
        Agreement with the reference (:func:`ptoverify.conform.agreement.agreement`),
        with ``sources`` (states per source) and ``gap`` (largest unprobed disc).
    properties : dict of str to Verdict
        Every property, in evaluation order.
    failures : list of dict
        Each with ``property``, ``state`` [x1, x2] (the first that shows it, or
        None for ``isolation``), ``detail``.
    timings_s : dict
        Wall time per phase [s].
    config : str
        Name of the configuration judged against.
    unverified : list of str
        Properties that could not be evaluated (``unverified``).
    law_output : str
        What an isolated law printed (stdout and stderr), first and last 2000 characters.
    precision : str
        What the implementation was judged as computing in (``float64``, ``float32``).
    perturbed : tuple of PerturbedRun
        The closed loops under perturbation (:mod:`ptoverify.conform.perturbed`).
    perturbations : tuple of Perturbation
        The perturbations asked for (empty: the nominal loop only).
    reference : str
        The reference law judged against (``pto``, ``ptos``, ``cascade-p``).
    """

    conforms: bool
    mode: str
    target: str
    mode_reason: str
    agreement: dict
    properties: dict
    failures: list[dict]
    timings_s: dict = field(default_factory=dict)
    config: str = ""
    law_output: str = ""
    precision: str = "float64"
    perturbed: tuple = ()
    perturbations: tuple = ()
    reference: str = "pto"

    @property
    def reference_fails(self) -> list[str]:
        """Where the reference itself fails under perturbation: ``property under perturbation``."""
        return [
            f"{name} under {r.perturbation.text()}"
            for r in self.perturbed
            for name in r.reference_fails
        ]

    @property
    def unverified(self) -> list[str]:
        """Names of the properties whose status is ``unverified``."""
        return [k for k, v in self.properties.items() if v.status == UNVERIFIED]

    def to_json(self) -> dict:
        """Return the JSON object printed by ``--json``."""
        return {
            "conforms": self.conforms,
            "mode": self.mode,
            "target": self.target,
            "mode_reason": self.mode_reason,
            "config": self.config,
            "reference": self.reference,
            "agreement": self.agreement,
            "properties": {k: v.to_json() for k, v in self.properties.items()},
            "failures": self.failures,
            "unverified": self.unverified,
            "timings_s": self.timings_s,
            "precision": self.precision,
            "perturbation": {
                "perturbations": [p.to_json() for p in self.perturbations],
                "runs": [r.to_json() for r in self.perturbed],
                "reference_fails": self.reference_fails,
            },
        }

    def failed_properties(self) -> list[str]:
        """Names of the failing properties, in order, without repeats."""
        return list(dict.fromkeys(f["property"] for f in self.failures))


def clip_output(text: str, n: int = 2000) -> str:
    """Keep the first and last n characters of what the law printed.

    Parameters
    ----------
    text : str
        What the law printed.
    n : int
        Characters kept at each end.

    Returns
    -------
    str
    """
    if len(text) <= 2 * n:
        return text
    return f"{text[:n]}\n[... {len(text) - 2 * n} characters left out ...]\n{text[-n:]}"


def summary_line(result: ConformResult) -> str:
    """Return the verdict in one line: precision, perturbations, where the reference fails.

    Parameters
    ----------
    result : ConformResult
        The result.

    Returns
    -------
    str
    """
    r = result
    why = f": {r.mode_reason}" if r.mode_reason else ""
    line = f"{'CONFORMS' if r.conforms else 'DOES NOT CONFORM'}: {r.target} (mode {r.mode}{why})"
    if r.precision != "float64":
        line += f"; precision {r.precision}"
    if r.perturbations:
        line += "; under " + "; ".join(p.text() for p in r.perturbations)
        fails = r.reference_fails
        if fails:
            line += (
                f"; WARNING: the reference itself fails {len(fails)} propert"
                f"{'y' if len(fails) == 1 else 'ies'} there ({', '.join(fails)}): conforming "
                "means no worse than a reference that fails"
            )
    return line


def format_result(result: ConformResult) -> str:
    """Human-readable report: verdict, agreement per region, properties, failures.

    Parameters
    ----------
    result : ConformResult
        The result.

    Returns
    -------
    str
        Lines: :func:`summary_line`, the agreement, each property, each failure.
    """
    r = result
    lines = [summary_line(r)]
    a = r.agreement
    if "regions" in a:
        src = ", ".join(f"{k} {v}" for k, v in a.get("sources", {}).items())
        lines.append(
            f"agreement with reference {r.reference}: {a['points']} states ({src}), {a['excluded']} "
            + (
                f"excluded (within {a['tie_band_mm_s']:.3g} mm/s of l1/l2/l1*/l2*"
                + (", or float32 ties" if a.get("precision") == "float32" else "")
                + "), "
                if r.reference == "pto"
                else "excluded (a continuous reference has no curve ties), "
            )
            + f"tolerance {a['tolerance_mm_s']:.3g} mm/s ({a['rtol']:g} w_max), "
            f"max |du| = {a['max_abs_du']:.3g} mm/s"
        )
        for name, e in a["regions"].items():
            s = e["state"]
            where = "" if s is None else f" at ({s[0]:.10g}, {s[1]:.10g})"
            lines.append(
                f"  {'ok  ' if e['pass'] else 'FAIL'} {name:<10} {e['points']:>8} "
                f"states ({e['excluded']} excluded) max |du| = "
                f"{e['max_abs_du']:.3g} mm/s{where}"
            )
        if "gap" in a:
            g = a["gap"]
            lines.append(
                f"  largest unprobed disc: centre ({g['center'][0]:.4g}, {g['center'][1]:.4g}), "
                f"half-widths {g['half_width_mm']:.3g} mm x {g['half_width_mm_s']:.3g} mm/s"
            )
    elif a.get("detail"):
        lines.append(f"agreement: {a['detail']}")
    for name, v in r.properties.items():
        lines.append(f"  {v.status.upper():<10} {name:<28} {v.detail}")
    for run in r.perturbed:
        cells = ", ".join(
            f"{c.name} {c.user:g}/{c.reference:g} (limit {c.limit:g} {c.unit})"
            + (" REFERENCE FAILS" if c.reference_fails else "")
            for c in run.comparisons
        )
        status = "ok  " if run.passed else "FAIL"
        lines.append(f"  {status} under {run.perturbation.text()}: yours/reference {cells}")
    for f in r.failures:
        at = "" if f["state"] is None else f" at state ({f['state'][0]:.10g}, {f['state'][1]:.10g})"
        lines.append(f"FAILED {f['property']}{at}: {f['detail']}")
    lines.append(f"time {r.timings_s.get('total', 0.0):.2f} s")
    return "\n".join(lines)
