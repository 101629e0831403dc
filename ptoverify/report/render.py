"""Rendering helpers of the report: neutral blocks, number formatting, HTML and Markdown.

A report is a list of sections ``(anchor, title, blocks)``; a :class:`Block` is a
paragraph, a table, a figure or a raw fragment (HTML with a plain-text twin
for Markdown).  :func:`render_html` and :func:`render_markdown` print them.
Every text that reaches the HTML goes through :func:`html.escape`; equations
arrive as raw fragments of SymPy's presentation MathML (``derivations.render_html``),
each in a ``div.eq`` that scrolls sideways inside its cell (:data:`CSS`), so a wide
equation is neither clipped nor pushes its table past the page.

Used by :mod:`ptoverify.report.collect` and :mod:`ptoverify.report.sections`, which
both import it and not each other.
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = [
    "Block",
    "Section",
    "fmt",
    "table",
    "paragraph",
    "qty",
    "image",
    "findings",
    "code",
    "link",
    "md_cell",
    "render_html",
    "render_markdown",
    "STATUS_WORDS",
]


@dataclass(frozen=True)
class Block:
    """A piece of a section: ``p`` text, ``table``, ``img``, or ``raw`` (html, md).

    Attributes
    ----------
    kind : {"p", "table", "img", "raw"}
        What the block is.
    text : str
        Paragraph text, figure caption, or the Markdown twin of a raw fragment.
    headers, rows : tuple of str
        Table header and (already formatted) cells.
    html : str
        Raw HTML fragment, or the figure's relative path.
    css : str
        CSS classes of a table or a figure in the HTML (:data:`CSS`): ``verdict``
        for the compact verdict tables; ``half`` for a single-panel figure, which
        shares a row with its neighbour (consecutive figures form a grid).
    """

    kind: str
    text: str = ""
    headers: tuple[str, ...] = ()
    rows: tuple[tuple[str, ...], ...] = ()
    html: str = ""
    css: str = ""


Section = tuple[str, str, list[Block]]


def fmt(v: Any, digits: int = 4) -> str:
    """Format a value for a table cell: n/a for None and non-finite, yes/no, g-format.

    Readable precision: 4 significant digits by default (the full values stay in
    ``results.json``).  Lists print as ``(a, b)`` and mappings as ``k = v; ...``:
    never a Python ``repr``.

    Parameters
    ----------
    v : any
        The value (None, bool, float, int, str, or a list/tuple/dict of those).
    digits : int
        Significant digits of floats.

    Returns
    -------
    str

    Examples
    --------
    >>> fmt(0.123456789), fmt(None), fmt(True), fmt([1.0, float("nan")], 3)
    ('0.1235', 'n/a', 'yes', '(1, n/a)')
    >>> fmt({"a": 1.0, "b": [2, 3]})
    'a = 1; b = (2, 3)'
    """
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if not math.isfinite(v):
            return "n/a"
        return f"{v:.{digits}g}"
    if isinstance(v, (list, tuple)):
        return "(" + ", ".join(fmt(x, digits) for x in v) + ")"
    if isinstance(v, Mapping):
        return "; ".join(f"{k} = {fmt(x, digits)}" for k, x in v.items())
    return str(v)


def qty(v: Any, unit: str, digits: int = 4) -> str:
    """Format a number with its unit: ``0.2409 mm``; ``[-]`` marks a dimensionless one.

    Parameters
    ----------
    v : any
        The value (as :func:`fmt`).
    unit : str
        Its unit (``mm``, ``mm/s``, ``%``, ``deg``...); ``""`` or ``"1"`` or ``"-"``
        for a dimensionless number.
    digits : int
        Significant digits.

    Returns
    -------
    str

    Examples
    --------
    >>> qty(0.240891, "mm"), qty(1.5, ""), qty(None, "s"), qty(12.0, "%")
    ('0.2409 mm', '1.5 [-]', 'n/a', '12 %')
    """
    text = fmt(v, digits)
    if text == "n/a":
        return text
    if unit in ("", "1", "-"):
        return f"{text} [-]"
    return f"{text} {unit}"


def table(headers: list[str], rows: list[list[Any]], css: str = "") -> Block:
    """Return a table block; every cell is formatted with :func:`fmt`.

    Parameters
    ----------
    headers : list of str
        Column titles.
    rows : list of list
        Cell values.
    css : str
        CSS classes of the HTML table (:attr:`Block.css`).

    Returns
    -------
    Block
    """
    return Block(
        "table",
        headers=tuple(headers),
        rows=tuple(tuple(fmt(c) for c in r) for r in rows),
        css=css,
    )


def paragraph(text: str) -> Block:
    """Return a paragraph block (plain text; escaped when rendered).

    Parameters
    ----------
    text : str
        The paragraph.

    Returns
    -------
    Block
        A ``p`` block.
    """
    return Block("p", text=text)


def code(text: str) -> Block:
    """Return a preformatted block (a command line to copy).

    Parameters
    ----------
    text : str
        The text, shown verbatim.

    Returns
    -------
    Block
        A raw block: ``<pre><code>`` in HTML, an indented code block in Markdown.
    """
    md = "\n".join("    " + line for line in text.splitlines())
    return Block("raw", text=md, html=f"<pre><code>{html.escape(text)}</code></pre>")


def findings(items: list[tuple[str, str, str]], figure: str = "", caption: str = "") -> Block:
    """Return the headline findings as a numbered list, with a figure beside them.

    Parameters
    ----------
    items : list of (str, str, str)
        ``(sentence, anchor, link text)``: each finding with the section holding
        its evidence.
    figure : str
        Relative path of the overview figure ("" for none).
    caption : str
        The figure's caption and alt text.

    Returns
    -------
    Block
        A raw block (HTML ``<ol class="findings">``; Markdown numbered list).

    Examples
    --------
    >>> b = findings([("3 of 5 pass.", "summary", "gates")])
    >>> 'id="finding-1"' in b.html and b.text.startswith("1. 3 of 5 pass.")
    True
    """
    lis = "".join(
        f'<li id="finding-{i}">{html.escape(s)} <a href="#{html.escape(a)}">'
        f"({html.escape(t)})</a></li>"
        for i, (s, a, t) in enumerate(items, 1)
    )
    md = "\n".join(f"{i}. {s} ([{t}](#{a}))" for i, (s, a, t) in enumerate(items, 1))
    fig = ""
    if figure:
        fig = (
            f'<figure class="overview"><img src="{html.escape(figure)}" '
            f'alt="{html.escape(caption)}"><figcaption>{html.escape(caption)}</figcaption></figure>'
        )
        md += f"\n\n![{caption}]({figure})"
    return Block(
        "raw", text=md, html=f'<div class="headline"><ol class="findings">{lis}</ol>{fig}</div>'
    )


def image(figures: dict[str, str], key: str, caption: str, css: str = "") -> list[Block]:
    """Return ``[figure block]`` when ``key`` is among the written figures, else ``[]``.

    Parameters
    ----------
    figures : dict
        Figure key -> relative path (``figures/x.png``).
    key : str
        The figure's key (file stem).
    caption : str
        Caption and alt text.
    css : str
        ``half`` for a single-panel figure that shares a row (:attr:`Block.css`).

    Returns
    -------
    list of Block
    """
    return [Block("img", text=caption, html=figures[key], css=css)] if key in figures else []


#: A Markdown link to an anchor of this page: ``](#anchor)``.
_SECTION_LINK = re.compile(r"\]\(#([A-Za-z0-9_-]+)\)")


def link(anchor: str, text: str) -> Block:
    """Return a paragraph linking to a section of the same page.

    Parameters
    ----------
    anchor : str
        The section's anchor.
    text : str
        The link text.

    Returns
    -------
    Block
        A raw block with the link.
    """
    return Block(
        "raw",
        text=f"[{text}](#{anchor})",  # the Markdown renderer points #anchor at the heading
        html=f'<p><a href="#{html.escape(anchor)}">{html.escape(text)}</a></p>',
    )


def _links(text: str) -> str:
    """Escape text and turn Markdown links ``[text](href)`` into HTML links."""
    out, pos = [], 0
    for m in re.finditer(r"\[([^\]]+)\]\(([^)\s]+)\)", text):
        out.append(html.escape(text[pos : m.start()]))
        out.append(f'<a href="{html.escape(m.group(2))}">{html.escape(m.group(1))}</a>')
        pos = m.end()
    out.append(html.escape(text[pos:]))
    return "".join(out)


def md_cell(text: str) -> str:
    """Escape a Markdown table cell (pipes, newlines).

    Parameters
    ----------
    text : str
        Cell content.

    Returns
    -------
    str
        The escaped cell.
    """
    return text.replace("|", "\\|").replace("\n", " ")


CSS = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:1em auto;padding:0 1em;
color:#222;line-height:1.4}h1{font-size:1.15em;margin:.2em 0}table{border-collapse:collapse;margin:1em 0;font-size:.9em}
th,td{border:1px solid #ccc;padding:.3em .5em;vertical-align:top;text-align:left}
th{background:#f0f0f0}.pass,.verified,.reproduced{background:#e6f4e6}
.fail,.erratum,.not-reproduced,.fails{background:#fbe3e3}.holds{background:#e6f4e6}
.unverified,.ambiguous,.unchecked,.inherits,.depends{background:#fff4d6}
img{max-width:100%;border:1px solid #ddd}figure{margin:1em 0}nav a{margin-right:1em}
math{font-size:1.05em}code{font-size:.85em}pre{background:#f6f6f6;padding:.5em;overflow-x:auto}
.headline{display:flex;gap:1.5em;align-items:flex-start;flex-wrap:wrap}
.headline ol{flex:1 1 28em;font-size:1.05em}.headline li{margin:.4em 0}
.headline figure{flex:1 1 24em;margin:0}.row{display:flex;gap:1em;flex-wrap:wrap}
.row figure{flex:1 1 22em}.erratum-block{border-left:4px solid #d88;padding:.2em 1em;margin:1em 0}
table.derivations,.erratum-block table.forms{table-layout:fixed;width:100%}
table.derivations th,table.derivations td,table.forms th,table.forms td{min-width:0;
overflow-wrap:anywhere}
.eq{overflow-x:auto;overflow-y:hidden;max-width:100%}.eq math{max-width:none}
table.derivations th:nth-child(1),table.derivations td:nth-child(1){width:3.5em}
table.derivations th:nth-child(2),table.derivations td:nth-child(2){width:9em}
table.derivations th:nth-child(5),table.derivations td:nth-child(5){width:22%}
table.forms th{width:7em}
td{overflow-wrap:break-word}table{max-width:100%}
table.verdict{width:100%;table-layout:fixed;font-size:.76em;line-height:1.2;margin:.3em 0}
table.verdict th,table.verdict td{padding:.1em .35em}
table.engineer th:nth-child(1){width:24%}table.engineer th:nth-child(2){width:32%}
table.reviewer th:nth-child(1){width:40%}table.reviewer th:nth-child(2){width:4.6em}
table.reviewer th:nth-child(4){width:5.6em}table.reviewer th:nth-child(5){width:15%}
#verdict h2{margin:.4em 0 .2em}#verdict p{margin:.3em 0}
.figs{display:grid;grid-template-columns:repeat(2,minmax(0,1fr));gap:.5em 1em;margin:1em 0}
.figs figure{margin:0;grid-column:1/-1}.figs figure.half{grid-column:auto}
.figs figure.half img{width:100%}"""

#: Cell texts that get a CSS class (colour) of their own.
STATUS_WORDS = frozenset(
    {
        "pass",
        "fail",
        "unverified",
        "verified",
        "erratum",
        "unchecked",
        "definition",
        "reproduced",
        "not reproduced",
        "ambiguous",
        "holds",
        "fails",
        "depends",
    }
)


def _html_block(b: Block) -> str:
    if b.kind == "p":
        return f"<p>{html.escape(b.text)}</p>"
    if b.kind == "raw":
        return b.html
    if b.kind == "img":
        cls = f' class="{html.escape(b.css)}"' if b.css else ""
        return (
            f'<figure{cls}><img src="{html.escape(b.html)}" alt="{html.escape(b.text)}">'
            f"<figcaption>{html.escape(b.text)}</figcaption></figure>"
        )
    head = "".join(f"<th>{html.escape(h)}</th>" for h in b.headers)
    body = []
    for row in b.rows:
        cells = []
        for c in row:
            cls = f' class="{c.replace(" ", "-")}"' if c in STATUS_WORDS else ""
            cells.append(f"<td{cls}>{html.escape(c)}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    cls = f' class="{html.escape(b.css)}"' if b.css else ""
    return f"<table{cls}><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _html_blocks(blocks: list[Block]) -> list[str]:
    """Render blocks; a run of two or more figures shares a grid (``div.figs``, :data:`CSS`)."""
    out: list[str] = []
    run: list[Block] = []
    for b in [*blocks, None]:
        if b is not None and b.kind == "img":
            run.append(b)
            continue
        if len(run) > 1:
            out.append('<div class="figs">' + "".join(_html_block(f) for f in run) + "</div>")
        else:
            out += [_html_block(f) for f in run]
        run = []
        if b is not None:
            out.append(_html_block(b))
    return out


def render_html(
    sections: list[Section], title: str, intro: str = "", *, lead: int = 0, downloads: str = ""
) -> str:
    """Render the sections as one offline HTML page (MathML, escaped text).

    Parameters
    ----------
    sections : list of (str, str, list of Block)
        Anchor, heading and blocks of each section, in order.
    title : str
        Page title.
    intro : str
        A paragraph under the title; ``[text](href)`` becomes a link.
    lead : int
        How many sections come before the table of contents (the report's verdict,
        so that its first screen is the verdict).
    downloads : str
        A paragraph under the table of contents (links as in ``intro``).

    Returns
    -------
    str
        The page.

    Examples
    --------
    >>> page = render_html([("s", "A & B", [Block("p", text="<x>")])], "t")
    >>> "&lt;x&gt;" in page and "A &amp; B" in page
    True
    """
    nav = "".join(f'<a href="#{a}">{html.escape(t)}</a>' for a, t, _ in sections)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{_links(intro)}</p>" if intro else "",
    ]
    for k, (anchor, heading, blocks) in enumerate(sections):
        if k == lead:
            parts.append(f"<nav>{nav}</nav>")
            parts.append(f'<p class="downloads">{_links(downloads)}</p>' if downloads else "")
        parts.append(f'<section id="{anchor}"><h2>{html.escape(heading)}</h2>')
        parts += _html_blocks(blocks)
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


#: Longest inline code span (a raw SymPy form) the Markdown shows in full [characters].
MD_CODE_MAX = 200
#: Tables longer than this [rows] are folded into a collapsible block in the Markdown.
MD_FOLD_ROWS = 20


def md_slug(heading: str) -> str:
    """Return the anchor a code-hosting site gives a Markdown heading.

    Parameters
    ----------
    heading : str
        The heading text.

    Returns
    -------
    str
        Lower case; letters, digits, hyphens and underscores kept; spaces become hyphens.

    Examples
    --------
    >>> md_slug("1. Summary: gates, errata, claims")
    '1-summary-gates-errata-claims'
    """
    s = "".join(c for c in heading.lower() if c.isalnum() or c in " -_")
    return s.replace(" ", "-")


def _md_code(text: str, anchor: str) -> str:
    """Shorten inline code spans longer than :data:`MD_CODE_MAX` (full form in the HTML)."""

    def cut(m: re.Match) -> str:
        body = m.group(1)
        if len(body) <= MD_CODE_MAX:
            return m.group(0)
        return f"`{body[:MD_CODE_MAX]}...` ([full form](index.html#{anchor}))"

    return re.sub(r"`([^`]+)`", cut, text)


def render_markdown(
    sections: list[Section], title: str, intro: str = "", *, lead: int = 0, downloads: str = ""
) -> str:
    """Render the sections as Markdown that reads on a code-hosting site.

    A table of contents links every section; equations are plain text, and an
    inline form longer than :data:`MD_CODE_MAX` characters is cut with a link to
    the HTML; a table of more than :data:`MD_FOLD_ROWS` rows is folded into a
    collapsible block.

    Parameters
    ----------
    sections : list of (str, str, list of Block)
        Anchor, heading and blocks of each section, in order.
    title : str
        Page title.
    intro : str
        A paragraph under the title (the paper's title, the downloads).
    lead : int
        How many sections come before the table of contents (as :func:`render_html`).
    downloads : str
        A paragraph under the table of contents.

    Returns
    -------
    str
        The Markdown text.

    Examples
    --------
    >>> md = render_markdown([("s", "1. A", [Block("p", text="x")])], "t")
    >>> "- [1. A](#1-a)" in md
    True
    """
    lines = [f"# {title}", ""]
    if intro:
        lines += [intro, ""]
    contents = ["Contents:", ""]
    contents += [f"- [{heading}](#{md_slug(heading)})" for _a, heading, _b in sections]
    contents += ["", downloads, ""] if downloads else [""]
    # a link to a section's anchor goes to its heading's slug (what a code host makes)
    slugs = {a: md_slug(heading) for a, heading, _b in sections}

    def to_heading(m: re.Match) -> str:
        return f"](#{slugs.get(m.group(1), m.group(1))})"

    for k, (anchor, heading, blocks) in enumerate(sections):
        if k == lead:
            lines += contents
        lines += [f"## {heading}", ""]
        for b in blocks:
            if b.kind in ("p", "raw"):
                lines += [_SECTION_LINK.sub(to_heading, _md_code(b.text, anchor)), ""]
            elif b.kind == "img":
                lines += [f"![{b.text}]({b.html})", "", f"*{b.text}*", ""]
            else:
                rows = ["| " + " | ".join(md_cell(h) for h in b.headers) + " |"]
                rows.append("|" + "---|" * len(b.headers))
                rows += [
                    "| " + " | ".join(_md_code(md_cell(c), anchor) for c in r) + " |"
                    for r in b.rows
                ]
                if len(b.rows) > MD_FOLD_ROWS:
                    summary = f"{len(b.rows)} rows: {', '.join(b.headers[:3])}, ..."
                    lines += ["<details>", f"<summary>{html.escape(summary)}</summary>", ""]
                    lines += rows + ["", "</details>", ""]
                else:
                    lines += rows + [""]
    return "\n".join(lines) + "\n"
