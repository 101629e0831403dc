"""The derivation and errata sections: printed against derived equations, units, tildes."""

from __future__ import annotations

import html
import math
import re
from collections.abc import Mapping
from typing import Any

from ptoverify.report.render import (
    Block,
    fmt,
    qty,
    table,
)

from .common import _MATH, _downstream_ids

# ------------------------------------------------------------------ errata
#: Units of the symbols of a counterexample (the paper's symbols; omega_m is w_max).
SYMBOL_UNITS = {
    "a": "rad/s",
    "T": "s",
    "omega_m": "mm/s",
    "omega_0": "mm/s",
    "x1": "mm",
    "x2": "mm/s",
    "tx1": "mm",
    "tx2": "mm/s",
    "x10": "mm",
    "x20": "mm/s",
    "d": "mm",
    "k1": "1/s",
    "k2": "-",
}


_LENGTH = {"x1", "tx1", "x10", "tx10", "d"}


_SPEED = {"x2", "tx2", "x20", "tx20", "omega_m", "omega_0", "omega_c"}


def _expr_unit(text: str) -> str:
    """Return the unit of an expression of the paper's symbols, by scaling the units (mm, s).

    Scales lengths by L and times by S (so speeds by L / S, a by 1 / S) and
    reads the exponents from the value's change at a generic point; "mm/s",
    "mm", "s", "rad/s", "-" or "" when the expression is not homogeneous.
    """
    try:
        import sympy as sp

        from derivations.printed import parse

        exprs = [parse(p) for p in text.split("; ")]
    except Exception:  # noqa: BLE001 - prose, not formulas
        return ""
    units = set()
    for e in exprs:
        if isinstance(e, sp.Equality) or not isinstance(e, sp.Expr):
            return ""
        syms = {s.name: s for s in e.free_symbols}
        base = {s: sp.Rational(3 + i, 7) for i, s in enumerate(sorted(syms.values(), key=str))}
        if "omega_m" in syms:
            base[syms["omega_m"]] = sp.Integer(50)

        def scaled(L: int, S: int, base=base, syms=syms) -> float:  # noqa: N803
            sub = {}
            for name, s in syms.items():
                f = L if name in _LENGTH else (sp.Rational(L, S) if name in _SPEED else 1)
                f = sp.Rational(1, S) if name == "a" else (S if name == "T" else f)
                sub[s] = base[s] * f
            return complex(e.xreplace(sub).evalf()).real  # numbers for symbols: xreplace

        try:
            v0, vl, vs = scaled(1, 1), scaled(2, 1), scaled(1, 2)
            p = math.log2(vl / v0)
            q = math.log2(vs / v0)
        except (ValueError, ZeroDivisionError, TypeError):
            return ""
        units.add((round(p, 6), round(q, 6)))
    if len(units) != 1:
        return ""
    return {(1, -1): "mm/s", (1, 0): "mm", (0, 1): "s", (0, -1): "rad/s", (0, 0): "-"}.get(
        units.pop(), ""
    )


def _eq_links(head: str, ids: set[str]) -> str:
    """HTML links for an equation label: each id or range end that has a record."""
    parts = []
    for tok in re.split(r"(, |-)", head):
        parts.append(
            f'<a href="#eq-{html.escape(tok)}">{html.escape(tok)}</a>'
            if tok in ids
            else html.escape(tok)
        )
    return "".join(parts)


#: What the extra fields of a counterexample are, in words.
EXTRA_WORDS = {
    "state_on_l1": "a state on l1 (x1, x2)",
    "image_under_plus_omega_m": "its state one sample later under u = +omega_m (x1, x2)",
    "image_under_minus_omega_m": "its state one sample later under u = -omega_m (x1, x2)",
}


def same_counterexample(errata: list[dict[str, Any]]) -> dict[str, str]:
    """Map each erratum whose counterexample repeats an earlier erratum's to that erratum's id.

    Parameters
    ----------
    errata : list of dict
        The erratum records (``id``, ``counterexample``) in the report's order.

    Returns
    -------
    dict
        Erratum id -> id of the first erratum with the same counterexample (point
        and values); an erratum with a counterexample of its own is not a key.

    Examples
    --------
    >>> ce = {"point": {"a": 1.0}, "printed": [2.0], "derived": [0.0]}
    >>> same_counterexample([{"id": "18", "counterexample": ce}, {"id": "19", "counterexample": ce}])
    {'19': '18'}
    """

    def canon(v: Any) -> Any:  # a hashable form of nested mappings and lists
        if isinstance(v, Mapping):
            return tuple(sorted((k, canon(v[k])) for k in v))
        if isinstance(v, (list, tuple)):
            return tuple(canon(x) for x in v)
        return v

    seen: dict[Any, str] = {}
    out: dict[str, str] = {}
    for r in errata:
        if not r["counterexample"]:
            continue
        key = canon(r["counterexample"])
        if key in seen:
            out[r["id"]] = seen[key]
        else:
            seen[key] = r["id"]
    return out


def _counterexample_rows(ce: dict[str, Any], unit: str) -> tuple[list[str], list[list[str]]]:
    """Table rows of a counterexample: its point (with units), printed and derived values."""
    cols = [("random admissible point", ce)]
    if "at_plant" in ce and ce["at_plant"]:
        cols.append(("at this report's plant", ce["at_plant"]))
    names: list[str] = []
    for _, c in cols:
        names += [k for k in c["point"] if k not in names]
    extra = [k for k in ce if k not in ("point", "printed", "derived", "at_plant")]
    rows = []
    for n in names:
        u = SYMBOL_UNITS.get(n, "")
        rows.append(
            [
                f"{n}",
                *[
                    qty(c["point"][n], u) if u else fmt(c["point"][n]) + " (unit as in the paper)"
                    for _, c in cols
                ],
            ]
        )
    for n in extra:
        u = "mm, mm/s" if isinstance(ce[n], (list, tuple)) and len(ce[n]) == 2 else ""
        rows.append(
            [
                EXTRA_WORDS.get(n, n.replace("_", " ")),
                f"{fmt(ce[n])} {u}".strip(),
                *["" for _ in cols[1:]],
            ]
        )
    for which in ("printed", "derived"):
        vals = [c[which] for _, c in cols]
        vals = [v[0] if isinstance(v, (list, tuple)) and len(v) == 1 else v for v in vals]
        rows.append(
            [
                f"{which} form, evaluated",
                *[
                    (qty(v, unit) if unit else fmt(v) + " (residual, unit as in the paper)")
                    for v in vals
                ],
            ]
        )
    return ["quantity", *[t for t, _ in cols]], rows


#: The paper's tilded symbols, named ``tx1``, ``tx20``, ... in the derivations.
_TILDE_MI = re.compile(r"<mi>tx</mi>")


_TILDE_TEXT = re.compile(r"\btx(\d+)")


def tilde_mathml(text: str) -> str:
    """Draw the derivations' ``tx`` symbols as x with a tilde (x~1 is the paper's tilde-x1).

    Parameters
    ----------
    text : str
        MathML from SymPy's presentation printer.

    Returns
    -------
    str

    Examples
    --------
    >>> tilde_mathml("<msub><mi>tx</mi><mi>1</mi></msub>")
    '<msub><mover accent="true"><mi>x</mi><mo>~</mo></mover><mi>1</mi></msub>'
    """
    return _TILDE_MI.sub('<mover accent="true"><mi>x</mi><mo>~</mo></mover>', text)


def tilde_text(text: str) -> str:
    """Write the derivations' ``tx1`` as ``x~1`` in plain text.

    Parameters
    ----------
    text : str
        A plain-text form.

    Returns
    -------
    str

    Examples
    --------
    >>> tilde_text("a*tx1 + tx20")
    'a*x~1 + x~20'
    """
    return _TILDE_TEXT.sub(r"x~\1", text)


#: Plain-text spellings of a form that read as mathematics: relations, powers, Greek.
_READABLE = (
    ("<=", "\u2264"),
    (">=", "\u2265"),
    ("**", "^"),
    ("omega_m", "\u03c9_m"),
    ("omega_0", "\u03c9_0"),
    ("omega_c", "\u03c9_c"),
    ("lambda", "\u03bb"),
)


def readable(text: str) -> str:
    """Write a form that has no MathML (words and formulas mixed) as readable plain text.

    Parameters
    ----------
    text : str
        A printed or derived form.

    Returns
    -------
    str
        The tilde drawn (:func:`tilde_text`), relations as signs, powers with a caret,
        Greek letters by their symbol.

    Examples
    --------
    >>> readable("x_l1(x2) <= x1, a**2 + omega_m")
    'x_l1(x2) ≤ x1, a^2 + ω_m'
    """
    text = tilde_text(text)
    for plain, shown in _READABLE:
        text = text.replace(plain, shown)
    return text


def render_records(records: list) -> dict[str, dict[str, Any]]:
    """Render what the derivation sections show of each record (SymPy work, done once).

    Parameters
    ----------
    records : list of derivations.EquationRecord
        The derivation records.

    Returns
    -------
    dict
        Record id -> ``{"mathml": ..., "unit": ...}``: the MathML of each form
        (:meth:`derivations.EquationRecord.to_mathml`) and, for an erratum, the
        unit of its expressions ("" otherwise).  The report's derivations stage
        computes it beside the records, in the same worker process.
    """
    return {
        r.id: {
            "mathml": {k: tilde_mathml(v) for k, v in r.to_mathml().items()},
            "unit": (_expr_unit(r.derived) or _expr_unit(r.printed))
            if r.verdict == "erratum"
            else "",
        }
        for r in records
    }


def errata(res: dict[str, Any], records: list, rendered: dict | None = None) -> list[Block]:
    """Each erratum: printed and derived forms (MathML), counterexample, downstream links.

    Parameters
    ----------
    res : dict
        Output of :func:`ptoverify.report.collect.collect` (JSON part).
    records : list of derivations.EquationRecord
        The records the collect step derived (MathML of each form).
    rendered : dict, optional
        :func:`render_records` of them, when already computed.

    Returns
    -------
    list of Block
    """
    recs = {r.id: r for r in records}
    rendered = rendered if rendered is not None else render_records(records)
    ids = set(recs)
    err = [r for r in res["derivations"] if r["verdict"] == "erratum"]
    if not err:
        return [Block("p", text="No printed equation disagrees with its derivation.")]
    blocks = [
        Block(
            "p",
            text=f"{len(err)} printed equations disagree with their derivation from eq. (1). "
            "For each: the form as printed and as derived, a state where they differ, and the "
            "equations downstream that change with it.",
        )
    ]
    repeats = same_counterexample(err)
    for r in err:
        done = rendered.get(r["id"], {})
        ml = done.get("mathml", {})
        unit = done.get("unit") or _expr_unit(r["derived"]) or _expr_unit(r["printed"])
        head, rows = _counterexample_rows(r["counterexample"] or {}, unit)
        tb = table(head, rows)
        if r["id"] in repeats:
            ce_words = (
                f"No counterexample of its own: the one computed for it is eq. "
                f"({repeats[r['id']]})'s (the same point and values), so it is not repeated here."
            )
        elif not r["counterexample"]:
            ce_words = "No counterexample was computed for it."
        else:
            ce_words = "Counterexample (each row in its own unit):"
        forms = []
        for key, label in (
            ("printed", "printed"),
            ("derived", "derived"),
            ("corrected", "corrected"),
        ):
            if r[key]:
                m = ml.get(key, "")
                zero = key == "corrected" and "=" not in r[key]  # a residual: the curve is = 0
                if m:
                    body = _MATH.format(m + ("<mo>=</mo><mn>0</mn>" if zero else ""))
                else:
                    body = html.escape(readable(r[key]) + (" = 0" if zero else ""))
                forms.append(f'<tr><th>{label}</th><td><div class="eq">{body}</div></td></tr>')
        down = [i.split(":", 1) for i in r["inherits"]]
        lis = "".join(
            f"<li>eq. {_eq_links(h.strip(), ids)}: {html.escape(tilde_text(t.strip()))}</li>"
            if t
            else f"<li>{html.escape(h)}</li>"
            for h, *rest in down
            for t in [rest[0] if rest else ""]
        )
        inner = (
            f'<div class="erratum-block" id="erratum-{html.escape(r["id"])}">'
            f'<h3>Eq. ({html.escape(r["id"])}) <a href="#eq-{html.escape(r["id"])}">'
            "(in the derivations table)</a></h3>"
            f"<p>{html.escape(tilde_text(r['note']))}</p>"
            f'<table class="forms">{"".join(forms)}</table>'
            f"<p>{html.escape(ce_words)}</p>"
        )
        md = (
            f"### Eq. ({r['id']})\n\n{tilde_text(r['note'])}\n\n"
            f"printed: `{tilde_text(r['printed'])}`\n\n"
            f"derived: `{tilde_text(r['derived'])}`\n\n"
            + (
                f"corrected: `{tilde_text(r['corrected'])}"
                f"{'' if '=' in r['corrected'] else ' = 0'}`\n\n"
                if r["corrected"]
                else ""
            )
            + ce_words
        )
        blocks.append(Block("raw", text=md, html=inner))
        if ce_words.startswith("Counterexample"):
            blocks.append(tb)
        blocks.append(
            Block(
                "raw",
                text="Changes downstream:\n\n"
                + "\n".join(f"- eq. {tilde_text(i)}" for i in r["inherits"]),
                html=f"<p>Changes downstream:</p><ul>{lis}</ul></div>",
            )
        )
    return blocks


# ------------------------------------------------------------------ derivations
def inherited_errata(records: list) -> dict[str, str]:
    """Map each equation downstream of an erratum to that erratum's id.

    An equation whose own algebra is verified but whose input is an erratum's
    result (the printed chain (20)-(27) after (16)) is not "verified" as a
    result: it leads to a wrong value (the printed omega0).

    Parameters
    ----------
    records : list of derivations.EquationRecord
        The records (``id``, ``verdict``, ``inherits``).

    Returns
    -------
    dict
        Record id -> id of the first erratum it inherits from.

    Examples
    --------
    >>> from types import SimpleNamespace as R
    >>> recs = [R(id="16", verdict="erratum", inherits=["17: unchanged", "20-22: changes"]),
    ...         R(id="21", verdict="verified", inherits=[])]
    >>> inherited_errata(recs)
    {'20': '16', '21': '16', '22': '16'}
    """
    out: dict[str, str] = {}
    for r in records:
        if r.verdict != "erratum":
            continue
        for head in _downstream_ids(list(r.inherits)):
            for part in head.split(","):
                lo, _, hi = part.strip().partition("-")
                if lo.isdigit() and (not hi or hi.isdigit()):
                    for n in range(int(lo), int(hi or lo) + 1):
                        out.setdefault(str(n), r.id)
    return out


def derivations(res: dict[str, Any], records: list, rendered: dict | None = None) -> list[Block]:
    """Show printed next to derived (MathML), verdicts; each row anchored as ``eq-<id>``.

    ``records`` are the :class:`derivations.EquationRecord` objects the collect
    step derived (their JSON form is ``res["derivations"]``); they carry the
    SymPy expressions that render as MathML.  ``rendered`` is
    :func:`render_records` of them when already computed.
    """
    from derivations.record import N_CROSS, N_POINTS

    rendered = rendered or {}
    rows_html, rows_md = [], []
    tainted = inherited_errata(records)
    for r in records:
        ml = (rendered[r.id] if r.id in rendered else render_records([r])[r.id])["mathml"]
        verdict, css = r.verdict, r.verdict
        if r.verdict == "verified" and r.id in tainted:
            verdict = f"verified algebra; inherits the erratum of eq. ({tainted[r.id]})"
            css = "inherits"

        def cell(key: str, text: str, ml=ml) -> str:
            m = ml.get(key, "")
            body = _MATH.format(m) if m else html.escape(readable(text))
            return f'<div class="eq">{body}</div>'

        note = html.escape(r.note)
        if r.verdict == "erratum":
            note += f' <a href="#erratum-{html.escape(r.id)}">(counterexample, consequences)</a>'
        rows_html.append(
            f'<tr id="eq-{html.escape(r.id)}" class="{html.escape(css)}">'
            f"<td>{html.escape(r.id)}</td><td>{html.escape(verdict)}</td>"
            f"<td>{cell('printed', r.printed)}</td><td>{cell('derived', r.derived)}</td>"
            f"<td>{note}</td></tr>"
        )
        rows_md.append(
            "| "
            + " | ".join(
                c.replace("|", "\\|").replace("\n", " ")
                for c in (
                    r.id,
                    verdict,
                    f"`{tilde_text(r.printed)}`",
                    f"`{tilde_text(r.derived)}`",
                    tilde_text(r.note),
                )
            )
            + " |"
        )
    html_table = (
        '<table class="derivations"><thead><tr><th>eq.</th><th>verdict</th><th>printed</th>'
        "<th>derived</th><th>note</th></tr></thead><tbody>"
        + "".join(rows_html)
        + "</tbody></table>"
    )
    md = "| eq. | verdict | printed | derived | note |\n|---|---|---|---|---|\n" + "\n".join(
        rows_md
    )
    return [
        Block(
            "p",
            text="Each equation is re-derived with SymPy from eq. (1) and compared "
            "with its transcription: proved symbolically where SymPy can (then "
            f"cross-checked at {N_CROSS} random admissible points), otherwise "
            f"compared at {N_POINTS} random admissible points. Where a record quotes plant numbers (the "
            "printed zone chain, the linear-zone spectral radius) they are "
            "evaluated at this report's configuration.",
        ),
        Block("raw", text=md, html=html_table),
    ]
