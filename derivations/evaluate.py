"""One pass over both sides of a comparison: lambdify's code with repeats computed once.

:func:`derivations.record.judge` evaluates a printed and a derived form at the
same points.  The two lambdified functions (SymPy's mpmath printer) repeat large
subexpressions (the flow's ``exp((a*x1 + x2)/omega_m)``, a Lambert-W root) many
times, within a form and between the two.  :func:`shared_evaluator` joins the
two functions' code into one and computes each repeated subexpression once.

The values are bit for bit those of the two functions: the code is SymPy's own,
parsed with :mod:`ast`; a repeated node of the syntax tree is one Python
operation on the same operands (its evaluation order is the tree), and mpmath's
operations are pure at a fixed precision, so computing it once gives the same
number as computing it each time.  Only nodes evaluated unconditionally are
shared: nothing is taken out of a conditional expression, ``and``/``or``, a
comparison or a comprehension.  Where the joined code raises, the caller runs
the two original functions (:class:`SharedEvaluator` keeps them), so an
exception is the original's too.
"""

from __future__ import annotations

import ast
import linecache
from collections import Counter
from collections.abc import Callable
from typing import Any

__all__ = ["shared_evaluator", "SharedEvaluator"]

#: Nodes whose sub-nodes are evaluated only under a condition: never shared from.
_CONDITIONAL = (ast.IfExp, ast.BoolOp, ast.Compare, ast.Lambda, ast.comprehension)
#: Nodes worth naming: an operation or a call (a name or a constant costs nothing).
_SHARED = (ast.BinOp, ast.UnaryOp, ast.Call)
_PREFIX = "_shared_"


class SharedEvaluator:
    """Both sides of a comparison at one point, with repeated work done once.

    Attributes
    ----------
    printed, derived : callable
        The two lambdified functions, as SymPy made them.
    joined : callable or None
        ``joined(*args) -> (printed values, derived values)``, the same code with
        each repeated subexpression computed once; None when the code was not of
        the form this module rewrites (the two functions are then used).
    """

    def __init__(self, printed: Callable, derived: Callable, joined: Callable | None) -> None:
        self.printed, self.derived, self.joined = printed, derived, joined

    def __call__(self, *args: Any) -> tuple[Any, Any] | None:
        """Values of both sides, or None when the joined code raised (or is absent).

        Parameters
        ----------
        *args
            The point (mpmath numbers, in the functions' argument order).

        Returns
        -------
        tuple or None
            ``(printed values, derived values)`` as the two functions return them.
        """
        if self.joined is None:
            return None
        try:
            return self.joined(*args)
        except Exception:  # noqa: BLE001 - the caller reruns the originals, which decide
            return None


def _single_return(fn: Callable) -> tuple[ast.arguments, ast.expr] | None:
    """Return the arguments and returned expression of a one-statement lambdified function."""
    code = getattr(fn, "__code__", None)
    lines = linecache.getlines(code.co_filename) if code is not None else []
    try:
        tree = ast.parse("".join(lines))
    except SyntaxError:
        return None
    if len(tree.body) != 1 or not isinstance(tree.body[0], ast.FunctionDef):
        return None
    body = tree.body[0].body
    if len(body) != 1 or not isinstance(body[0], ast.Return) or body[0].value is None:
        return None
    return tree.body[0].args, body[0].value


class _Keys:
    """Structural key of each node (equal keys: equal subtrees), interned as ints."""

    def __init__(self) -> None:
        self.ids: dict[tuple, int] = {}
        self.of: dict[int, int] = {}  # id(node) -> key
        self.count: Counter[int] = Counter()

    def key(self, node: ast.AST, counted: bool) -> int:
        """Key of node (computed once); counts the shared-kind nodes evaluated unconditionally."""
        counted = counted and not isinstance(node, _CONDITIONAL)
        parts: list[Any] = [type(node).__name__]
        for name, value in ast.iter_fields(node):
            if isinstance(value, ast.AST):
                value = self.key(value, counted)
            elif isinstance(value, list):
                value = tuple(self.key(v, counted) if isinstance(v, ast.AST) else v for v in value)
            else:  # a constant: 2 == 2.0 == True, but they are different literals
                value = (type(value).__name__, value)
            parts.append((name, value))
        k = self.ids.setdefault(tuple(parts), len(self.ids))
        self.of[id(node)] = k
        if counted and isinstance(node, _SHARED):
            self.count[k] += 1
        return k


class _Hoist(ast.NodeTransformer):
    """Replace each repeated unconditional node by a name assigned before the return."""

    def __init__(self, keys: _Keys) -> None:
        self.keys = keys
        self.names: dict[int, str] = {}
        self.assignments: list[ast.stmt] = []

    def generic_visit(self, node: ast.AST) -> ast.AST:
        if isinstance(node, _CONDITIONAL):
            return node  # evaluated under a condition: left as it is
        key = self.keys.of[id(node)] if isinstance(node, _SHARED) else None
        if key is not None and key in self.names:
            return ast.Name(self.names[key], ast.Load())
        node = super().generic_visit(node)  # children first: they are assigned earlier
        if key is None or self.keys.count[key] < 2:
            return node
        name = f"{_PREFIX}{len(self.names)}"
        self.names[key] = name
        self.assignments.append(ast.Assign([ast.Name(name, ast.Store())], node))
        return ast.Name(name, ast.Load())


def _join(printed: Callable, derived: Callable) -> Callable | None:
    """Compile the joined function, or None when the code is not of the expected form."""
    parts = [_single_return(printed), _single_return(derived)]
    if parts[0] is None or parts[1] is None:
        return None
    (args_p, ret_p), (args_d, ret_d) = parts
    if ast.dump(args_p) != ast.dump(args_d) or printed.__globals__ != derived.__globals__:
        return None
    both = ast.Tuple([ret_p, ret_d], ast.Load())
    if any(isinstance(n, ast.Name) and n.id.startswith(_PREFIX) for n in ast.walk(both)):
        return None
    keys = _Keys()
    keys.key(both, True)
    if not any(c > 1 for c in keys.count.values()):
        return None  # nothing repeats: the two functions as they are
    hoist = _Hoist(keys)
    both = hoist.visit(both)
    fn = ast.FunctionDef(
        name="_joined", args=args_p, body=[*hoist.assignments, ast.Return(both)], decorator_list=[]
    )
    module = ast.fix_missing_locations(ast.Module([fn], []))
    namespace = dict(printed.__globals__)
    exec(compile(module, "<derivations.evaluate>", "exec"), namespace)  # noqa: S102
    return namespace["_joined"]


def shared_evaluator(printed: Callable, derived: Callable) -> SharedEvaluator:
    """Join two lambdified functions of the same arguments into one evaluation.

    Parameters
    ----------
    printed, derived : callable
        Functions made by ``sympy.lambdify`` with the same arguments and modules.

    Returns
    -------
    SharedEvaluator
        Called with a point, it returns both functions' values (bit for bit
        theirs), or None where the joined code raised: the caller then calls
        ``printed`` and ``derived`` themselves.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> p = sp.lambdify([x], [sp.exp(x) ** 2 + sp.exp(x)], "mpmath")
    >>> d = sp.lambdify([x], [sp.exp(x) * (sp.exp(x) + 1)], "mpmath")
    >>> ev = shared_evaluator(p, d)
    >>> ev(0.5) == (p(0.5), d(0.5))
    True
    """
    return SharedEvaluator(printed, derived, _join(printed, derived))
