"""JUnit XML for CI systems: ``check --junit FILE`` and ``conform ... --junit FILE``.

One ``testcase`` per gate or property (``classname`` the suite, ``name`` the
verdict's name).  ``pass`` is a passing test case; ``fail`` carries a
``failure`` element; ``unverified`` and ``not_run`` carry an ``error``
element (fail closed: a figure that could not be computed is never a pass,
and never ``skipped``, which CI systems count as green).  The one exception,
``skip_not_run``, is for properties that do not apply to a run whose verdict
passed without them (a ``conform --table`` has no closed loop to judge).  The message carries
the measured figure, the comparison, the limit, the unit and, when known, the
first failing state; the element's text is the full detail.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from typing import Any

from ptoverify.verdict import FAIL, NOT_RUN, PASS, Verdict

__all__ = ["junit_xml", "conform_verdicts", "failure_message"]


def _num(v: float | None) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.6g}"


def failure_message(v: Verdict, state: Sequence[float] | None = None) -> str:
    """One-line message of a non-passing verdict: measured, limit, unit, state.

    Parameters
    ----------
    v : Verdict
        The verdict.
    state : sequence of two floats, optional
        First failing state (x1 [mm], x2 [mm/s]).

    Returns
    -------
    str
        ``"<status>: measured M <cmp> limit L [unit] (first failing state (x1 mm, x2 mm/s))"``.

    Examples
    --------
    >>> failure_message(Verdict("x", "fail", 2.0, 1.0, "d", "<=", "mm"), (1.0, -2.5))
    'fail: measured 2 mm, required <= 1 mm; first failing state (x1, x2) = (1 mm, -2.5 mm/s)'
    """
    unit = f" {v.unit}" if v.unit and v.unit != "1" else ""
    msg = f"{v.status}: measured {_num(v.measured)}{unit}, required {v.comparison} {_num(v.limit)}{unit}"
    if state is not None:
        msg += f"; first failing state (x1, x2) = ({state[0]:.10g} mm, {state[1]:.10g} mm/s)"
    return msg


def junit_xml(
    verdicts: Iterable[Verdict],
    suite: str,
    states: dict[str, Sequence[float]] | None = None,
    properties: dict[str, Any] | None = None,
    skip_not_run: bool = False,
) -> str:
    """Return JUnit XML with one ``testcase`` per verdict.

    Parameters
    ----------
    verdicts : iterable of Verdict
        Gates or properties, in the order to report.
    suite : str
        Test-suite name (e.g. ``ptoverify.check``).
    states : dict, optional
        Verdict name -> first failing state (x1 [mm], x2 [mm/s]).
    properties : dict, optional
        Suite properties (configuration name, target...), written as
        ``<property name= value=>``.
    skip_not_run : bool
        Report ``not_run`` verdicts as ``skipped`` (with their reason) instead
        of ``error``.  Only for a run whose verdict already passed without
        them (``conform --table``: the closed-loop properties need a callable),
        so the XML agrees with the exit code.

    Returns
    -------
    str
        The XML document (UTF-8 declaration included).

    Examples
    --------
    >>> import xml.etree.ElementTree as ET
    >>> xml = junit_xml([Verdict("a", "pass", 0.0, 1.0, ""),
    ...                  Verdict("b", "unverified", None, 1.0, "no")], "s")
    >>> root = ET.fromstring(xml)
    >>> root.get("tests"), root.get("errors"), root.get("failures")
    ('2', '1', '0')
    """
    verdicts = list(verdicts)
    states = states or {}
    skipped = sum(v.status == NOT_RUN for v in verdicts) if skip_not_run else 0
    failures = sum(v.status == FAIL for v in verdicts)
    errors = sum(v.status not in (PASS, FAIL) for v in verdicts) - skipped
    attrs = {
        "name": suite,
        "tests": str(len(verdicts)),
        "failures": str(failures),
        "errors": str(errors),
        "skipped": str(skipped),
    }
    root = ET.Element("testsuites", attrs)
    ts = ET.SubElement(root, "testsuite", attrs)
    if properties:
        props = ET.SubElement(ts, "properties")
        for key, value in properties.items():
            ET.SubElement(props, "property", {"name": str(key), "value": str(value)})
    for v in verdicts:
        tc = ET.SubElement(ts, "testcase", {"classname": suite, "name": v.name})
        if v.status == PASS:
            continue
        if skip_not_run and v.status == NOT_RUN:
            ET.SubElement(tc, "skipped", {"message": f"not run: {v.detail}"})
            continue
        tag = "failure" if v.status == FAIL else "error"
        el = ET.SubElement(
            tc, tag, {"message": failure_message(v, states.get(v.name)), "type": v.status}
        )
        el.text = v.detail
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def conform_verdicts(result: Any) -> tuple[list[Verdict], dict[str, Sequence[float]]]:
    """Verdicts and first failing states of a ``conform`` result, for :func:`junit_xml`.

    One verdict per agreement region (``agreement/<region>``), then one per
    property, from the result's JSON object (``to_json``).

    Parameters
    ----------
    result : ConformResult
        The outcome of :func:`ptoverify.conform.gate.conform_callable` or ``conform_table``.

    Returns
    -------
    verdicts : list of Verdict
    states : dict
        Name -> first failing state (x1 [mm], x2 [mm/s]), where known.
    """
    data = result.to_json() if hasattr(result, "to_json") else dict(result)
    verdicts: list[Verdict] = []
    states: dict[str, Sequence[float]] = {}
    for f in data.get("failures", []):
        if f.get("state") is not None:
            states.setdefault(str(f.get("property")), f["state"])
    agreement = data.get("agreement", {})
    tol = agreement.get("tolerance_mm_s")
    for region, e in agreement.get("regions", {}).items():
        name = f"agreement/{region}"
        ok = e.get("pass")
        status = PASS if ok is True else (FAIL if ok is False else "unverified")
        detail = (
            f"max |u - u_ref| over {e.get('points')} points of region {region} "
            f"({e.get('excluded')} excluded as curve ties)"
        )
        verdicts.append(Verdict(name, status, e.get("max_abs_du"), tol, detail, "<=", "mm/s"))
        if e.get("state") is not None and status != PASS:
            states[name] = e["state"]
    if not agreement.get("regions"):
        ok = agreement.get("pass")
        status = PASS if ok is True else (FAIL if ok is False else "unverified")
        verdicts.append(
            Verdict(
                "agreement",
                status,
                agreement.get("max_abs_du"),
                tol,
                str(agreement.get("detail", "")),
                "<=",
                "mm/s",
            )
        )
    for name, p in data.get("properties", {}).items():
        measured, limit = p.get("measured"), p.get("limit")
        verdicts.append(
            Verdict(
                name,
                str(p.get("status", "unverified")),
                None if measured is None else float(measured),
                None if limit is None else float(limit),
                str(p.get("detail", "")),
                str(p.get("comparison", "<=")),
                str(p.get("unit", "")),
            )
        )
    if data.get("conforms") is False and all(v.passed for v in verdicts):
        # the result says no but no property carries it: never report a green suite
        verdicts.append(
            Verdict("conforms", FAIL, None, None, "the conformance result is negative", "<=", "")
        )
    return verdicts, states
