"""The one bridge from finished SymPy expressions to fast NumPy functions, and their source.

* :func:`lambdify` compiles with a fixed argument order, common-subexpression elimination
  and a docstring that lists the arguments and the formula; the result evaluates through
  :func:`broadcast_evaluate`.
* :func:`lambdified_source` is the NumPy-only Python source of what :func:`lambdify`
  compiled: the same statements (SymPy's generated code, its bare NumPy names written
  ``np.name``), so that an exported copy computes the same floats.

Modules made of such code and of the package's own source: :mod:`impactsym.numeric.pysource`.
"""

from __future__ import annotations

import ast
import builtins
import inspect
import textwrap
from collections.abc import Sequence

import numpy as np
import sympy as sp

from impactsym.numeric.roots import ArrayFunction


def broadcast_evaluate(compiled: ArrayFunction, *values: np.ndarray) -> np.ndarray:
    """``compiled(*values)`` as float64 of the broadcast shape of ``values``.

    The shape is that of the arguments also where the expression does not depend on
    all of them; floating-point warnings are silenced because a ``Piecewise`` evaluates
    every branch, also where it is not taken.

    >>> broadcast_evaluate(lambda x, y: 2 * x, np.ones(2), np.zeros((3, 1))).shape
    (3, 2)
    """
    with np.errstate(all="ignore"):
        out = compiled(*values)
    shape = np.broadcast_shapes(*(np.shape(v) for v in values))
    return np.broadcast_to(np.asarray(out, dtype=np.float64), shape)


def lambdify(
    args: Sequence[sp.Symbol], expr: sp.Expr, *, name: str, doc: str = ""
) -> ArrayFunction:
    """Compile ``expr`` into a broadcasting NumPy function of ``args`` (in that order).

    The result always has the broadcast shape of the arguments, also where the
    expression does not depend on all of them, and its docstring names the
    arguments and shows the expression. The compiled SymPy function is kept as its
    attribute ``compiled`` (see :func:`lambdified_source`).

    >>> x, y = sp.symbols("x y")
    >>> fn = lambdify([x, y], sp.exp(-x) * sp.cos(y), name="damped_cos")
    >>> float(fn(0.0, np.pi))
    -1.0
    >>> fn(np.zeros(3), 0.0).shape
    (3,)
    >>> print(fn.__doc__.splitlines()[0])
    damped_cos(x, y)
    """
    args = list(args)
    free = expr.free_symbols - set(args)
    if free:
        names = ", ".join(sorted(str(s) for s in free))
        raise ValueError(f"expression for {name!r} has symbols not among the arguments: {names}")
    compiled = sp.lambdify(args, expr, modules="numpy", cse=True, docstring_limit=0)

    def function(*values: np.ndarray) -> np.ndarray:
        if len(values) != len(args):
            raise TypeError(
                f"{name}() takes {len(args)} arguments ({signature}), got {len(values)}"
            )
        return broadcast_evaluate(compiled, *values)

    signature = ", ".join(str(a) for a in args)
    function.__name__ = name
    function.__qualname__ = name
    function.__doc__ = f"{name}({signature})\n\n{doc}\n\nComputes ``{sp.sstr(expr)}``.".replace(
        "\n\n\n", "\n\n"
    )
    function.expr = expr  # type: ignore[attr-defined]
    function.args = tuple(args)  # type: ignore[attr-defined]
    function.compiled = compiled  # type: ignore[attr-defined]
    return function


class _QualifyNumpy(ast.NodeTransformer):
    """Write the global names of SymPy's generated code as ``np.<name>``."""

    def __init__(self, namespace: dict, local: set[str]) -> None:
        self.namespace, self.local = namespace, local

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if node.id in self.local or not isinstance(node.ctx, ast.Load):
            return node
        value = self.namespace.get(node.id, getattr(builtins, node.id, None))
        attribute = node.id if getattr(np, node.id, None) is value else None
        if attribute is None:  # the same NumPy object under another name
            attribute = next((k for k, v in vars(np).items() if v is value), None)
        if attribute is None or value is None:
            raise ValueError(f"generated code uses {node.id!r}, which is not a NumPy name")
        return ast.copy_location(
            ast.Attribute(value=ast.Name("np", ast.Load()), attr=attribute, ctx=ast.Load()), node
        )


def lambdified_source(function: ArrayFunction, name: str, doc: str) -> str:
    """NumPy-only source of ``def name(...)``: the code :func:`lambdify` compiled.

    The statements are SymPy's own (the same operations in the same order, so the
    same floats); only its bare NumPy names become ``np.<name>``. The function
    returns what the compiled code returns; the caller broadcasts it
    (:func:`broadcast_evaluate`).

    >>> x = sp.Symbol("x")
    >>> print(lambdified_source(lambdify([x], sp.exp(x) + 1, name="e"), "e1", "e^x + 1."))
    def e1(x):
        \"\"\"e^x + 1.\"\"\"
        return np.exp(x) + 1
    """
    compiled = function.compiled  # type: ignore[attr-defined]
    (tree,) = ast.parse(textwrap.dedent(inspect.getsource(compiled))).body
    tree.name = name
    tree.body.insert(0, ast.Expr(ast.Constant(doc)))
    local = set(compiled.__code__.co_varnames)
    tree = _QualifyNumpy(compiled.__globals__, local).visit(tree)
    return ast.unparse(ast.fix_missing_locations(tree))
