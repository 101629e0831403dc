"""Equation records and the judge that computes every verdict.

A record holds one paper equation: its printed transcription, the form re-derived
from eq. (1), the steps, and a verdict.  Verdicts of checked equations are never
written by hand: :func:`judge` compares the printed and the derived expression,
first symbolically, then numerically at random admissible points, and returns
``verified`` or ``erratum`` (with a counterexample), or ``unchecked`` when the
comparison could not be carried out.

Points.  A comparison proved symbolically is cross-checked at ``N_CROSS = 50``
random points (the proof decides; the points confirm that its log expansions
hold on the admissible set); one without a proof is decided by the numbers at
``N_POINTS = 200`` points.

Numeric tolerance.  The numeric comparison evaluates both expressions with
mpmath at ``DPS = 50`` significant digits at points whose coordinates are exact
binary floats.  Round-off is then below ~1e-48 relative to the largest term;
the tolerance ``RTOL = 1e-30`` (relative to ``1 + |printed| + |derived|``)
leaves 18 digits of margin for cancellation between terms, yet any genuine
discrepancy of the size a typo produces (a missing term, a wrong sign) is larger
than 1e-30 by many orders of magnitude at the sampled points.
"""

from __future__ import annotations

import html
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from sympy.printing.mathml import mathml

__all__ = [
    "EquationRecord",
    "Judgement",
    "judge",
    "VERDICTS",
    "DPS",
    "RTOL",
    "N_POINTS",
    "N_CROSS",
    "SEED",
    "definition",
    "as_tuple",
    "log_normal",
]

VERDICTS = ("verified", "erratum", "definition", "unchecked")
DPS = 50
RTOL = 1e-30
N_POINTS = 200
N_CROSS = 50
SEED = 20241121

Sampler = Callable[[np.random.Generator, int], dict[sp.Symbol, np.ndarray]]


@dataclass(frozen=True)
class EquationRecord:
    """One paper equation, printed against derived.

    Attributes
    ----------
    id : str
        The paper's equation number ("16") or an extra id ("22W", "mintime").
    printed : str
        The printed form, as a SymPy-parsable transcription (``lhs - rhs``).
    derived : str
        The form re-derived from eq. (1), in SymPy syntax.
    steps : list of str
        The derivation steps, in words and formulas.
    verdict : str
        One of ``verified``, ``erratum``, ``definition``, ``unchecked``.
    note : str
        Reason for the verdict.
    counterexample : dict or None
        For an erratum: the point (symbol -> value) and both values.
    corrected : str or None
        For an erratum: the corrected equation.
    inherits : list of str
        Later equations that inherit the error, with what changes in them.
    """

    id: str
    printed: str
    derived: str
    steps: list[str]
    verdict: str
    note: str
    counterexample: dict[str, Any] | None = None
    corrected: str | None = None
    inherits: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")

    def to_json(self) -> dict[str, Any]:
        """Return a JSON-able dict of the record.

        Returns
        -------
        dict
            Keys ``id``, ``verdict``, ``printed``, ``derived``, ``note``, ``steps``,
            ``counterexample``, ``corrected``, ``inherits``.
        """
        return {
            "id": self.id,
            "verdict": self.verdict,
            "printed": self.printed,
            "derived": self.derived,
            "note": self.note,
            "steps": list(self.steps),
            "counterexample": self.counterexample,
            "corrected": self.corrected,
            "inherits": list(self.inherits),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> EquationRecord:
        """Rebuild a record from :meth:`to_json` output.

        Parameters
        ----------
        data : dict
            The keys of :meth:`to_json`.

        Returns
        -------
        EquationRecord
        """
        return cls(**{f: data[f] for f in cls.__dataclass_fields__ if f in data})

    def to_mathml(self) -> dict[str, str]:
        """Return the printed and derived forms as presentation MathML.

        Returns
        -------
        dict
            Keys ``printed`` and ``derived`` (and ``corrected`` when present), each a
            MathML string (without the outer ``<math>`` element), or ``""`` when the
            text is not a SymPy expression.
        """
        out = {"printed": _to_mathml(self.printed), "derived": _to_mathml(self.derived)}
        if self.corrected:
            out["corrected"] = _to_mathml(self.corrected)
        return out


#: A relation between two formulas in a form's text: ``lhs = rhs``, ``x1 <= 0``.
_RELATION = re.compile(r"\s(<=|>=|=|<|>)\s")
#: How each relation is drawn.
_RELATION_MO = {"<=": "&#x2264;", ">=": "&#x2265;", "=": "=", "<": "&lt;", ">": "&gt;"}


def _formula_mathml(text: str) -> str | None:
    """MathML of a formula, relations between parts allowed (None if not a formula)."""
    from derivations.printed import parse

    sides = _RELATION.split(text.strip())
    if "," in text:  # a list or a chain with side conditions: not one formula
        return None
    out = []
    for k, side in enumerate(sides):
        if k % 2:
            out.append(f"<mo>{_RELATION_MO[side]}</mo>")
            continue
        try:
            out.append(mathml(parse(side), printer="presentation"))
        except Exception:  # noqa: BLE001 - prose, not a formula
            return None
    return "".join(out)


def _mixed_mathml(text: str) -> str | None:
    """MathML of a formula with words around it, the words as ``mtext`` (None: no formula).

    A prose lead ending in ``": "`` is text; after it, the longest run of leading
    words that is a formula with an operator is drawn as mathematics and the rest
    as text: ``a*tx1 + tx2 = 0 on the image of l1`` -> formula, then words.  A
    text with a comma (a list, side conditions) or with operators left in its words
    is not drawn: its plain form stays.
    """

    def stacked(*rows: str) -> str:  # words on a line of their own: a narrow cell holds them
        cells = "".join(f"<mtr><mtd>{r}</mtd></mtr>" for r in rows)
        return f'<mtable columnalign="left">{cells}</mtable>'

    lead, sep, rest = text.partition(": ")
    if sep and _formula_mathml(rest) is not None:
        return stacked(f"<mtext>{html.escape(lead)}:</mtext>", str(_formula_mathml(rest)))
    words = text.split(" ")
    for end in range(len(words), 0, -1):
        head = " ".join(words[:end])
        if not re.search(r"[-+*/=<>(]", head):
            break
        formula = _formula_mathml(head)
        tail = " ".join(words[end:])
        if formula is not None and not re.search(r"[=<>*/]", tail):  # the rest is words
            return stacked(formula, f"<mtext>{html.escape(tail)}</mtext>") if tail else formula
    return None


@lru_cache(maxsize=1024)
def _to_mathml(text: str) -> str:
    """MathML of a '; '-separated list of SymPy expressions ('' if unparsable).

    A piece that is a formula with relations or with words around it (``lhs = 0
    on the image of l1``) is drawn as the formula and the words as text
    (:func:`_mixed_mathml`).  Memoized: a definition's derived form is its
    printed one, rendered once.
    """
    from derivations.printed import parse

    parts = []
    for piece in text.split("; "):
        try:
            parts.append(mathml(parse(piece), printer="presentation"))
        except Exception:  # noqa: BLE001 - prose, not a formula: rendered as text
            mixed = _mixed_mathml(piece)
            if mixed is None:
                return ""
            parts.append(mixed)
    if len(parts) == 1:
        return "<mrow>" + parts[0] + "</mrow>"
    # one row per part: a chain of equations stacks instead of running off the page
    rows = "".join(f"<mtr><mtd>{p}</mtd></mtr>" for p in parts)
    return f'<mtable columnalign="left">{rows}</mtable>'


def as_tuple(expr: Any) -> tuple[sp.Expr, ...]:
    """Return expr as a tuple of SymPy expressions."""
    if isinstance(expr, (tuple, list)):
        return tuple(sp.sympify(e) for e in expr)
    if isinstance(expr, sp.MatrixBase):
        return tuple(expr)
    return (sp.sympify(expr),)


@dataclass(frozen=True)
class Judgement:
    """Outcome of :func:`judge`.

    Attributes
    ----------
    verdict : str
        ``verified``, ``erratum`` or ``unchecked``.
    symbolic : bool or None
        True: the difference simplified to 0; None: cannot prove (never a disproof).
    n_points : int
        Admissible points at which both sides evaluated to real numbers.
    max_rel_err : float
        Largest relative difference seen.
    counterexample : dict or None
        The worst point and both values, when the numeric check failed.
    reason : str
        One sentence on how the verdict came about.
    """

    verdict: str
    symbolic: bool | None
    n_points: int
    max_rel_err: float
    counterexample: dict[str, Any] | None
    reason: str


@lru_cache(maxsize=1024)
def _log_abs_split(z: sp.Expr) -> sp.Expr:
    """log|z| as a sum over the irreducible factors of z, each with its sign removed.

    ``z`` is put over one denominator and factored; a factor f^e contributes
    e log|f|, written ``e*log(f)`` with f's sign normalized (``-f`` when f could
    extract a minus sign), so log(omega_m - x2) and log(x2 - omega_m) meet as one
    term.  On the admissible set every log argument of the judged forms is > 0,
    where log z = log|z| and log|.| is a homomorphism of the nonzero reals.
    """
    z = sp.factor(sp.together(z))
    terms = []
    for f in sp.Mul.make_args(z):
        base, e = f.as_base_exp()
        if base.is_number:
            base = abs(base)
        elif base.could_extract_minus_sign():
            base = -base
        terms.append(e * sp.log(base))
    return sp.Add(*terms)


def log_normal(expr: sp.Expr) -> sp.Expr:
    """Expand expr with every log argument split into sign-normalized factors.

    Each log(z) becomes the sum of e*log(f) over the irreducible factors f^e of z,
    with f's sign removed, then everything is expanded (``expand_log(force=True)``
    for what is left).  Valid where every log argument is > 0 (there log z =
    log|z|, a homomorphism of the nonzero reals).  An identity holds on that set
    when the result of its difference is 0 after ``cancel``.

    Parameters
    ----------
    expr : sympy.Expr

    Returns
    -------
    sympy.Expr

    Examples
    --------
    >>> w, v = sp.symbols("omega_m x2", positive=True)
    >>> log_normal(sp.log(1 - v / w) - sp.log(w - v) + sp.log(w))
    0
    """
    return sp.expand(sp.expand_log(expr.replace(sp.log, _log_abs_split), force=True))


@lru_cache(maxsize=1024)
def _rewrite_zero(diff: sp.Expr) -> bool | None:
    """Try to prove diff == 0 by cheap rewrites; False when they show it nonzero.

    The rewrite is :func:`log_normal` (every log argument factored into
    sign-normalized factors, everything expanded), then ``cancel``; it is valid
    on the admissible set, where every log argument is > 0.  When it leaves a
    form that SymPy's assumptions show nonzero (``is_zero is False``, e.g.
    ``2*T*a*omega_m`` with positive symbols), diff is nonzero there: no proof of
    equality exists.

    Returns
    -------
    bool or None
        True: proved zero; False: proved nonzero; None: neither.
    """
    if diff == 0:
        return True
    try:
        e = log_normal(diff)
        if e == 0 or sp.cancel(e) == 0:
            return True
        return False if e.is_zero is False else None
    except Exception:  # noqa: BLE001 - any failure of the CAS means "cannot prove"
        return None


def _simplify_zero(diff: sp.Expr) -> bool | None:
    """Try to prove diff == 0 by ``simplify``, then ``simplify`` after ``expand_log``.

    Returns True when proved and None otherwise: a failure to simplify to 0 (or a
    ``False`` from ``equals``, which tests at points that may lie outside the
    admissible set or on another Lambert-W branch) is never taken as a disproof.
    """
    try:
        s = sp.simplify(diff)
        if s == 0:
            return True
        # expand_log(force=True) is valid on the admissible set, where log arguments are > 0
        s2 = sp.simplify(sp.expand_log(s, force=True))
        return True if s2 == 0 else None
    except Exception:  # noqa: BLE001 - any failure of the CAS means "cannot prove"
        return None


def _to_real(v: Any) -> float | None:
    """Real part of an mpmath value if it is real and finite, else None."""
    if isinstance(v, bool):
        return float(v)
    if isinstance(v, mpmath.mpc):
        if abs(v.imag) > mpmath.mpf(10) ** (-DPS + 10) * (1 + abs(v.real)):
            return None
        v = v.real
    try:
        f = mpmath.mpf(v)
    except (TypeError, ValueError):
        return None
    return f if mpmath.isfinite(f) else None


@lru_cache(maxsize=256)
def _compiled(syms: tuple[sp.Symbol, ...], exprs: tuple[sp.Expr, ...]) -> Callable:
    """Both sides as one mpmath function, ``lambdify(..., cse=True)``; reused when judged again.

    The printed and the derived form share large subexpressions (the flow's
    ``exp((a*x1 + x2)/omega_m)``, a Lambert-W root): lambdified together, SymPy's
    common-subexpression elimination computes each once.  ``LambertW`` is printed as
    ``mpmath.lambertw``.
    """
    return sp.lambdify(syms, list(exprs), modules="mpmath", cse=True, docstring_limit=0)


def judge(
    printed: Any,
    derived: Any,
    sampler: Sampler,
    n: int = N_POINTS,
    seed: int = SEED,
    symbolic: bool = True,
) -> Judgement:
    """Compare a printed and a derived form; compute the verdict.

    Both arguments are SymPy expressions (or equal-length tuples of them) in the
    free symbols that ``sampler`` draws.  Step 1 tries to prove ``printed - derived
    == 0`` by cheap rewrites (:func:`_rewrite_zero`).  Step 2 evaluates both at
    admissible random points (fixed ``seed``) in ``DPS``-digit arithmetic:
    ``N_CROSS`` points cross-check a proof, ``n`` points decide otherwise; both
    sides are one ``lambdify(..., cse=True)`` function, and a point where it raises
    (a side, or a subexpression they share, undefined there) or a side is not real
    and finite is skipped.  Step 3,
    only when step 1 neither proved nor disproved and the numbers do not disagree,
    tries ``simplify`` (:func:`_simplify_zero`) to upgrade the comparison to a
    proof.  A symbolic "cannot prove" is never a pass on its own.

    Parameters
    ----------
    printed, derived : sympy.Expr or tuple of sympy.Expr
        The two forms; compared componentwise.
    sampler : callable
        ``sampler(rng, n) -> {symbol: array of n floats}``, admissible points (it may
        return fewer than n when it filters out inadmissible draws).
    n : int
        Number of points when there is no proof (at least ``N_POINTS`` = 200 must
        evaluate for a verdict; with a proof, ``N_CROSS`` = 50).
    seed : int
        Seed of the point generator.
    symbolic : bool
        Whether to attempt the symbolic proof (False for indicator functions).

    Returns
    -------
    Judgement
        ``verified`` if every admissible point agrees within ``RTOL``; ``erratum``
        with the worst point if any disagrees; ``unchecked`` if fewer than 200 (50
        with a proof) points could be evaluated or a symbolic proof of equality
        contradicts the numbers.

    Examples
    --------
    >>> x = sp.Symbol("x", positive=True)
    >>> s = lambda rng, n: {x: rng.uniform(0.1, 2.0, n)}
    >>> judge(sp.log(x**2), 2 * sp.log(x), s).verdict
    'verified'
    >>> judge(sp.log(x**2), sp.log(x), s).verdict
    'erratum'
    """
    p_t, d_t = as_tuple(printed), as_tuple(derived)
    if len(p_t) != len(d_t):
        raise ValueError("printed and derived have different lengths")
    # step 1: the cheap rewrites (a proof, a proof of a difference, or neither)
    diffs = [sp.sympify(p - d) for p, d in zip(p_t, d_t)] if symbolic else []
    cheap = [_rewrite_zero(e) for e in diffs]
    proved = symbolic and all(c is True for c in cheap)
    need = N_CROSS if proved else N_POINTS
    # step 2: the numbers (a proof needs only a cross-check)
    pts = sampler(np.random.default_rng(seed), min(n, N_CROSS) if proved else n)
    syms = list(pts)
    free = set().union(*(e.free_symbols for e in p_t + d_t))
    missing = free - set(syms)
    if missing:
        raise ValueError(f"sampler does not draw {sorted(map(str, missing))}")
    both = _compiled(tuple(syms), p_t + d_t)
    m = len(p_t)
    worst, worst_err, n_ok = None, -1.0, 0
    n_drawn = min((len(v) for v in pts.values()), default=0)  # a sampler may filter points
    cols = [np.asarray(pts[s], dtype=float).tolist() for s in syms]  # Python floats
    with mpmath.workdps(DPS):
        for i in range(n_drawn):
            args = [mpmath.mpf(c[i]) for c in cols]
            try:
                values = [_to_real(v) for v in both(*args)]
            except (ValueError, ZeroDivisionError, TypeError):
                continue  # not admissible: a side (or a shared subexpression) is undefined
            vp, vd = values[:m], values[m:]
            if any(v is None for v in vp + vd):
                continue
            n_ok += 1
            err = max(
                0.0 if p == d else float(abs(p - d) / (1 + abs(p) + abs(d))) for p, d in zip(vp, vd)
            )
            if err > worst_err:
                worst_err = err
                worst = {
                    "point": {str(s): c[i] for s, c in zip(syms, cols)},
                    "printed": [float(v) for v in vp],
                    "derived": [float(v) for v in vd],
                }
    # step 3: simplify, only to upgrade agreeing numbers to a proof (where the numbers
    # disagree it could only fail, or contradict them through the log expansion of step 1)
    sym: bool | None = True if proved else None
    disagree = n_ok >= N_POINTS and worst_err > RTOL
    if symbolic and not proved and not disagree and all(c is not False for c in cheap):
        if all(c is True or _simplify_zero(e) is True for c, e in zip(cheap, diffs)):
            sym = True
    if n_ok < need:
        return Judgement(
            "unchecked",
            sym,
            n_ok,
            worst_err,
            None,
            f"only {n_ok} admissible points evaluated (need {need})",
        )
    ok = worst_err <= RTOL
    if ok:
        how = "proved symbolically and" if sym else "symbolic proof inconclusive;"
        return Judgement(
            "verified",
            sym,
            n_ok,
            worst_err,
            None,
            f"{how} agrees at {n_ok} random points (max rel. err {worst_err:.1e})",
        )
    if not sym:
        return Judgement(
            "erratum",
            sym,
            n_ok,
            worst_err,
            worst,
            f"differs at random points (max rel. diff {worst_err:.3g})",
        )
    return Judgement(
        "unchecked", sym, n_ok, worst_err, worst, "symbolic and numeric checks disagree"
    )


def definition(
    id_: str, printed: str, note: str, derived: str = "", steps: Sequence[str] = ()
) -> EquationRecord:
    """Record for an equation that defines a symbol, set or law (nothing to prove).

    Parameters
    ----------
    id_ : str
        Equation number.
    printed : str
        Transcription.
    note : str
        What it defines and how it is used.
    derived : str
        Consistent derived form, if any.
    steps : sequence of str
        Consistency checks carried out, if any.

    Returns
    -------
    EquationRecord
    """
    return EquationRecord(id_, printed, derived or printed, list(steps), "definition", note)
