"""SymPy re-derivation of the paper, equation by equation.

Each paper equation (1)-(39) is a claim: it is re-derived from the plant, eq. (1),
and the minimum principle, and compared with its printed transcription, first
symbolically and then numerically at random admissible points.  The verdict of
every checked record is computed by :func:`derivations.record.judge`.

Catalogue
---------
all_records      -- every record, ordered by equation number (cached per plant)
PlantNumbers     -- the plant at which records quote numeric examples
render_markdown  -- Markdown table: id, verdict, printed, derived, note
render_html      -- HTML fragment: MathML printed vs derived, verdict, note
record           -- EquationRecord, judge (the verdict machinery)
printed          -- the printed transcriptions, as data, in one file
common           -- the flow of eq. (1) by dsolve, PlantNumbers, shared helpers
section3         -- eqs. (3)-(12); minimum time and switch time (``mintime``)
section4         -- eqs. (13)-(35): assembles the four parts below; ``intersection``
section4_image   -- eqs. (13)-(19): l1*, l2*, the one-sample image of l1; 15inv, 19c
section4_boundary -- eqs. (20)-(27): the intersection, y*, z*, omega0; 22c
section4_input   -- eqs. (28)-(35): the suboptimal input omega_c, the compound law
section4_lambert -- Lambert-W closed forms of (22), (26), (31): 22W, 26W, 31W
section5         -- eqs. (36)-(39); the stability claim (``39L``)

Examples
--------
>>> from derivations import PlantNumbers, all_records
>>> plant = PlantNumbers(a=100.0, w_max=200.0, T=0.001, d=0.2, k1=150.0, k2=1.0)
>>> ids = [r.id for r in all_records(plant)]
>>> all(str(i) in ids for i in range(1, 40))
True
"""

from __future__ import annotations

import html
import re
from functools import lru_cache

from derivations.common import PlantNumbers
from derivations.record import EquationRecord, definition

__all__ = ["all_records", "render_markdown", "render_html", "EquationRecord", "PlantNumbers"]


def _order(rec: EquationRecord) -> tuple[float, str]:
    if rec.id == "mintime":
        return (12.5, "")
    m = re.match(r"(\d+)(.*)", rec.id)
    return (float(m.group(1)), m.group(2)) if m else (1e9, rec.id)


@lru_cache(maxsize=8)
def _records(numbers: PlantNumbers) -> tuple[EquationRecord, ...]:
    from derivations import section3, section4, section5
    from derivations.printed import printed_text

    recs = [
        definition(
            "1",
            printed_text("1"),
            "The plant: x1' = x2, x2' = -a x2 + a u, "
            "|u| <= omega_m; every other equation is derived from it.",
        ),
        definition("2", printed_text("2"), "The cost: minimum final time."),
    ]
    recs += list(section3.records())
    recs += list(section4.records(numbers)) + list(section5.records(numbers))
    return tuple(sorted(recs, key=_order))


def all_records(numbers: PlantNumbers) -> list[EquationRecord]:
    """Every equation record, ordered by equation number.

    Ids "1" to "39" are all present; extras ("mintime", "15inv", "19c", "22c",
    "22W", "26W", "31W", "36Z", "39L") follow the equation they extend.  The
    first call derives everything (about 2 s of one core); the symbolic part is
    cached, so a call for another plant only redoes the numeric examples.

    Parameters
    ----------
    numbers : PlantNumbers
        Plant at which records 16, 27, 36Z and 39L quote numeric examples
        (a [rad/s], w_max [mm/s], T [s], d [mm], k1 [1/s], k2 [-]).  The
        derivations themselves are symbolic and do not depend on it.

    Returns
    -------
    list of EquationRecord
    """
    if not isinstance(numbers, PlantNumbers):
        raise TypeError(f"numbers must be a PlantNumbers, got {type(numbers).__name__}")
    return list(_records(numbers))


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render_markdown(records: list[EquationRecord]) -> str:
    """Markdown table of the records: id, verdict, printed, derived, note.

    Errata get a line below the table with the counterexample and correction.

    Parameters
    ----------
    records : list of EquationRecord
        Records to render, in order.

    Returns
    -------
    str
    """
    lines = ["| id | verdict | printed | derived | note |", "|---|---|---|---|---|"]
    for r in records:
        lines.append(
            "| "
            + " | ".join(
                _md_cell(c) for c in (r.id, r.verdict, f"`{r.printed}`", f"`{r.derived}`", r.note)
            )
            + " |"
        )
    errata = [r for r in records if r.verdict == "erratum"]
    if errata:
        lines += ["", "Errata:", ""]
        for r in errata:
            lines.append(
                f"- ({r.id}) corrected: `{r.corrected}`; counterexample: "
                f"{r.counterexample}; inherits: {'; '.join(r.inherits)}"
            )
    return "\n".join(lines) + "\n"


def _math(ml: str, fallback: str) -> str:
    if not ml:
        return f"<code>{html.escape(fallback)}</code>"
    return f'<math xmlns="http://www.w3.org/1998/Math/MathML" display="block">{ml}</math>'


def render_html(records: list[EquationRecord]) -> str:
    """HTML fragment: a table of MathML printed vs derived, verdict and note.

    All text is escaped with :func:`html.escape`; formulas are SymPy's
    presentation MathML.

    Parameters
    ----------
    records : list of EquationRecord
        Records to render, in order.

    Returns
    -------
    str
    """
    rows = [
        '<table class="derivations">',
        "<thead><tr><th>id</th><th>verdict</th><th>printed</th><th>derived</th>"
        "<th>note</th></tr></thead>",
        "<tbody>",
    ]
    for r in records:
        ml = r.to_mathml()
        note = html.escape(r.note)
        if r.verdict == "erratum":
            note += (
                "<br/><b>corrected:</b> "
                + _math(ml.get("corrected", ""), r.corrected or "")
                + "<br/><b>counterexample:</b> "
                + html.escape(str(r.counterexample))
                + "<br/><b>inherits:</b><ul>"
                + "".join(f"<li>{html.escape(i)}</li>" for i in r.inherits)
                + "</ul>"
            )
        rows.append(
            f'<tr class="{html.escape(r.verdict)}"><td>{html.escape(r.id)}</td>'
            f"<td>{html.escape(r.verdict)}</td>"
            f"<td>{_math(ml['printed'], r.printed)}</td>"
            f"<td>{_math(ml['derived'], r.derived)}</td><td>{note}</td></tr>"
        )
    rows += ["</tbody>", "</table>"]
    return "\n".join(rows) + "\n"
