"""The one bridge from finished SymPy expressions to fast NumPy functions.

:func:`lambdify` compiles with a fixed argument order, common-subexpression elimination
and a docstring that lists the arguments and the formula.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from impactsym.numeric.roots import ArrayFunction


def lambdify(
    args: Sequence[sp.Symbol], expr: sp.Expr, *, name: str, doc: str = ""
) -> ArrayFunction:
    """Compile ``expr`` into a broadcasting NumPy function of ``args`` (in that order).

    The result always has the broadcast shape of the arguments, also where the
    expression does not depend on all of them, and its docstring names the
    arguments and shows the expression.

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
        with np.errstate(all="ignore"):  # Piecewise evaluates every branch
            out = compiled(*values)
        shape = np.broadcast_shapes(*(np.shape(v) for v in values))
        return np.broadcast_to(np.asarray(out, dtype=np.float64), shape)

    signature = ", ".join(str(a) for a in args)
    function.__name__ = name
    function.__qualname__ = name
    function.__doc__ = f"{name}({signature})\n\n{doc}\n\nComputes ``{sp.sstr(expr)}``.".replace(
        "\n\n\n", "\n\n"
    )
    function.expr = expr  # type: ignore[attr-defined]
    function.args = tuple(args)  # type: ignore[attr-defined]
    return function
