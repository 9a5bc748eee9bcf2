r"""Forward Laplace transform of exponential polynomials, by the known pairs.

:func:`laplace_exp_poly` transforms what :mod:`impactsym.symbolic.rational` returns (sums
of :math:`t^n e^{a t}` times trigonometric or hyperbolic functions, and Dirac deltas). It
shares no algorithm with the inversion, so a round trip checks it
(``docs/physics.md``, "Delay series and their exact inversion").
"""

from __future__ import annotations

import math
from typing import Any

import sympy as sp

from impactsym.symbolic.rational import LaplaceInversionError, check_symbols
from impactsym.validation import as_sympy

__all__ = ["laplace_exp_poly"]


def laplace_exp_poly(g: Any, t: sp.Symbol, s: sp.Symbol) -> sp.Expr:
    """Forward Laplace transform of an exponential polynomial, by the known pairs.

    .. math::

        \\mathcal{L}\\{t^n e^{a t}\\} = \\frac{n!}{(s-a)^{n+1}},
        \\qquad \\mathcal{L}\\{\\delta^{(n)}(t)\\} = s^n,

    after rewriting :math:`\\cos, \\sin, \\cosh, \\sinh` as exponentials. Used to check
    :func:`invert_rational` by a round trip; it shares no code with the inversion.

    Raises
    ------
    LaplaceInversionError
        For a term that is not of that form.

    Examples
    --------
    >>> t, s = sp.symbols("t s")
    >>> sp.cancel(laplace_exp_poly(t * sp.exp(-t), t, s))
    1/(s**2 + 2*s + 1)
    >>> sp.cancel(laplace_exp_poly(sp.sin(t), t, s))
    1/(s**2 + 1)
    """
    check_symbols(t=t, s=s)
    total = []
    for coeff, n, rate, delta in _exp_poly_terms(as_sympy("g", g), t):
        if delta is not None:
            total.append(coeff * s**delta)
        else:
            total.append(coeff * math.factorial(n) / (s - rate) ** (n + 1))
    return sp.Add(*total)


_Term = tuple[sp.Expr, int, sp.Expr, "int | None"]


def _exp_poly_terms(expr: sp.Expr, t: sp.Symbol) -> list[_Term]:
    """``expr`` as a list of ``(coefficient, n, rate, delta_order)``: the sum of
    ``coefficient * t**n * exp(rate*t)`` (or ``coefficient * DiracDelta(t, k)``)."""
    if not expr.has(t):
        return [(expr, 0, sp.Integer(0), None)]
    if expr == t:
        return [(sp.Integer(1), 1, sp.Integer(0), None)]
    if isinstance(expr, sp.Add):
        return [term for arg in expr.args for term in _exp_poly_terms(arg, t)]
    if isinstance(expr, sp.Mul):
        terms: list[_Term] = [(sp.Integer(1), 0, sp.Integer(0), None)]
        for arg in expr.args:
            terms = [_times_term(x, y, expr) for x in terms for y in _exp_poly_terms(arg, t)]
        return terms
    if isinstance(expr, sp.Pow) and expr.exp.is_Integer and expr.exp > 0:
        terms = [(sp.Integer(1), 0, sp.Integer(0), None)]
        for _ in range(int(expr.exp)):
            terms = [_times_term(x, y, expr) for x in terms for y in _exp_poly_terms(expr.base, t)]
        return terms
    if isinstance(expr, sp.exp):
        arg = sp.expand(expr.exp)
        slope = arg.coeff(t)
        rest = sp.expand(arg - slope * t)
        if rest.has(t) or slope.has(t):
            raise LaplaceInversionError(f"exponent not linear in {t}: {arg}")
        return [(sp.exp(rest), 0, slope, None)]
    if isinstance(expr, (sp.cos, sp.sin, sp.cosh, sp.sinh)):
        return _exp_poly_terms(expr.rewrite(sp.exp), t)
    if isinstance(expr, sp.DiracDelta) and expr.args[0] == t:
        order = int(expr.args[1]) if len(expr.args) > 1 else 0
        return [(sp.Integer(1), 0, sp.Integer(0), order)]
    raise LaplaceInversionError(f"cannot transform {expr}: not an exponential polynomial in {t}")


def _times_term(x: _Term, y: _Term, expr: sp.Expr) -> _Term:
    if x[3] is not None or y[3] is not None:
        if (x[3] is not None and (y[1] or y[2] != 0 or y[3] is not None)) or (
            y[3] is not None and (x[1] or x[2] != 0)
        ):
            raise LaplaceInversionError(f"cannot transform a product with a delta: {expr}")
        return (x[0] * y[0], 0, sp.Integer(0), x[3] if x[3] is not None else y[3])
    return (x[0] * y[0], x[1] + y[1], x[2] + y[2], None)
