"""Every printed equation of the paper, transcribed once, as data.

Hold this file against the paper.  Each entry is the printed form as SymPy
source: a relation is written ``lhs - rhs`` (zero on the relation), a chain of
equalities ``A = B = C`` as the tuple ``(A, B, C)``, a system as a tuple of
residuals, an inequality with ``<=``/``>=``.  Tildes are spelled ``t``
(``tx1`` is x~1, ``tx20`` is x~20); a starred root is written without the star
(``y`` in eq. 23 is y*).  Region memberships in eqs. (12) and (35) are Boolean
symbols (``in_SP`` is "(x1, x2) in S_P").  Symbols the paper implies positive
(a, omega_m, omega_0, omega_c, T, d, t) are declared positive.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp
from sympy.parsing.sympy_parser import parse_expr

__all__ = ["SYMBOLS", "PRINTED", "parse", "printed", "printed_text"]

_POSITIVE = "a omega_m omega_0 omega_c T d t t_f"
_REAL = (
    "x1 x2 x10 x20 u u_star lambda1 lambda2 H H_star H_min J tx1 tx2 tx10 tx20 "
    "y b0 k z w k1 k2 V Vdot dx1 dx2"
)
_BOOL = "in_SP in_SN in_O in_l1 in_l2 in_tSP in_tSN in_l1s in_l2s in_SL"

SYMBOLS: dict[str, sp.Symbol] = {}
SYMBOLS.update({s.name: s for s in sp.symbols(_POSITIVE, positive=True)})
SYMBOLS.update({s.name: s for s in sp.symbols(_REAL, real=True)})
SYMBOLS.update({s.name: s for s in sp.symbols(_BOOL)})
_LOCALS = dict(
    SYMBOLS,
    log=sp.log,
    exp=sp.exp,
    sign=sp.sign,
    Piecewise=sp.Piecewise,
    LambertW=sp.LambertW,
    Eq=sp.Eq,
    sqrt=sp.sqrt,
)

PRINTED: dict[str, str | tuple[str, ...]] = {
    # Section 2
    "1": ("dx1 - x2", "dx2 - (-a*x2 + a*u)"),
    "2": "J - t_f",
    # Section 3
    "3": "H - (1 + lambda1*x2 + lambda2*(-a*x2 + a*u))",
    "4": "H_star - H_min",
    "5": (
        "1 + lambda1*x2 - a*lambda2*x2 + a*lambda2*u_star"
        " <= 1 + lambda1*x2 - a*lambda2*x2 + a*lambda2*u"
    ),
    "6": "u_star - (-sign(lambda2)*omega_m)",
    "7": (
        "x1 - (x10 + omega_m*t + (x20 - omega_m)*(1 - exp(-a*t))/a)",
        "x2 - (omega_m + (x20 - omega_m)*exp(-a*t))",
    ),
    "8": "a*(x1 - x10) + (x2 - x20) + omega_m*log((x2 - omega_m)/(x20 - omega_m))",
    "9": "a*x1 + x2 + omega_m*log(1 - x2/omega_m)",
    "10": "a*(x1 - x10) + (x2 - x20) - omega_m*log((x2 + omega_m)/(x20 + omega_m))",
    "11": "a*x1 + x2 - omega_m*log(1 + x2/omega_m)",
    "12": "u - Piecewise((omega_m, in_SP | in_l1), (0, in_O), (-omega_m, in_SN | in_l2))",
    # Section 4
    "13": "a*x1 + x2 + omega_0*log(1 - x2/omega_0)",
    "14": "a*x1 + x2 - omega_0*log(1 + x2/omega_0)",
    "15": (
        "tx1 - (x1 + omega_m*T + (x2 - omega_m)*(1 - exp(-a*T))/a)",
        "tx2 - (x2*exp(-a*T) + omega_m*(1 - exp(-a*T)))",
    ),
    "16": ("a*tx1 + tx2", "a*x1 + x2 - a*omega_m*T", "-omega_m*log(1 - x2/omega_m) - a*omega_m*T"),
    "17": "x2 - (tx2 - omega_m*(1 - exp(-a*T)))*exp(a*T)",
    "18": (
        "a*tx1 + tx2",
        "-omega_m*log(1 - (tx2 - omega_m*(1 - exp(-a*T)))/(omega_m*exp(-a*T))) - a*omega_m*T",
        "-omega_m*log(1 - (1 + (tx2 - omega_m)/(omega_m*exp(-a*T)))) - a*omega_m*T",
        "-omega_m*log(exp(a*T)*(omega_m - tx2)/omega_m) - a*omega_m*T",
        "-omega_m*(a*T + log(1 - tx2/omega_m)) - a*omega_m*T",
        "-omega_m*log(1 - tx2/omega_m) - 2*a*omega_m*T",
    ),
    "19": "a*tx1 + tx2 + omega_m*log(1 - tx2/omega_m) - (-2*a*omega_m*T)",
    "20": (
        "a*tx10 + tx20 + omega_m*log(1 - tx20/omega_m) - (-2*a*omega_m*T)",
        "log(1 - tx20/omega_m) - (-tx20/omega_m - (a*tx10/omega_m + 2*a*T))",
    ),
    "21": ("y - (-tx20/omega_m)", "b0 - (a*tx10/omega_m + 2*a*T)"),
    "22": "log(1 + y) - (y - b0)",
    "23": "tx20 - (-y*omega_m)",
    "24": (
        "a*tx10 + tx20 + omega_0*log(1 - tx20/omega_0)",
        "log(1 - tx20/omega_0) - (1 + a*tx10/tx20)*(-tx20/omega_0)",
    ),
    "25": ("k - (1 + a*tx10/tx20)", "z - (-tx20/omega_0)"),
    "26": "log(1 + z) - k*z",
    "27": "omega_0 - (-tx20/z)",
    "28": "a*x1 + x2 + omega_c*log(1 - x2/omega_c)",
    "29": ("log(1 - x2/omega_c)", "-(a*x1 + x2)/omega_c", "(1 + a*x1/x2)*(-x2/omega_c)"),
    "30": ("k - (1 + a*x1/x2)", "w - (-x2/omega_c)"),
    "31": "log(1 + w) - k*w",
    "32": "omega_c - (-x2/w)",
    "33": "a*x1 + x2 - omega_c*log(1 + x2/omega_c)",
    "34": "u - (-k1*x1 - k2*x2)",
    "35": (
        "u - Piecewise((omega_m, in_SP | in_l1), (-omega_c, in_tSN | in_l2s),"
        " (-k1*x1 - k2*x2, in_SL), (0, in_O), (omega_c, in_tSP | in_l1s),"
        " (-omega_m, in_SN | in_l2))"
    ),
    # Section 5
    "36": (
        "a*x1 + x2 + omega_m*log(1 - x2/omega_m) >= 0",
        "a*x1 + x2 + omega_0*log(1 - x2/omega_0) <= 0",
    ),
    "37": ("dx1 - x2", "dx2 - (-a*k1*x1 - a*(1 + k2)*x2)"),
    "38": "V - (a*k1*x1**2 + x2**2)",
    "39": ("Vdot", "2*a*k1*x1*x2 + 2*x2*(-a*k1*x1 - a*(1 + k2)*x2)", "-2*a*(1 + k2)*x2**2"),
}


@lru_cache(maxsize=None)
def parse(text: str) -> sp.Basic:
    """Parse SymPy source with the declared symbols.

    Parameters
    ----------
    text : str
        SymPy source in the symbols of :data:`SYMBOLS`.

    Returns
    -------
    sympy.Basic

    Examples
    --------
    >>> parse("a*x1 + x2").free_symbols == {SYMBOLS["a"], SYMBOLS["x1"], SYMBOLS["x2"]}
    True
    """
    return parse_expr(text, local_dict=_LOCALS)


def printed(id_: str) -> tuple[sp.Basic, ...]:
    """Return the parsed printed form of an equation, as a tuple.

    Parameters
    ----------
    id_ : str
        Equation number, "1" to "39".

    Returns
    -------
    tuple of sympy.Basic
    """
    entry = PRINTED[id_]
    return tuple(parse(e) for e in ((entry,) if isinstance(entry, str) else entry))


def printed_text(id_: str) -> str:
    """Return the printed form as one string ('; ' between the parts of a tuple).

    Parameters
    ----------
    id_ : str
        Equation number.

    Returns
    -------
    str
    """
    entry = PRINTED[id_]
    return entry if isinstance(entry, str) else "; ".join(entry)
