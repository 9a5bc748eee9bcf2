"""Formulas typed in from the paper (Waltersberger, Keppler and Wauer, PAMM 2004).

Written out here by hand, not taken from impactsym, so that the derivation can be
compared with the print.
"""

from __future__ import annotations

import sympy as sp

s = sp.Symbol("s")
alpha = sp.Symbol("alpha", positive=True)
f = sp.Symbol("f", nonnegative=True)


def eq2_term(n: int, s: sp.Expr = s, alpha: sp.Expr = alpha, f: sp.Expr = f) -> tuple[int, sp.Expr]:
    r"""Term ``n >= 1`` of the paper's eq. (2): ``(delay, coefficient)`` of
    ``Y(s) = sum_n coefficient_n exp(-delay_n s)`` for rigid contact.

    .. math::

        Y = \frac{\alpha s + f}{s^2(\alpha s + 1)}
            - 2\sum_{n \ge 2} \frac{(\alpha s + f)(\alpha s - 1)^{n-2}}
                                     {s^2 (\alpha s + 1)^n}\, e^{-2(n-1)s}

    >>> delay, coefficient = eq2_term(3)
    >>> delay, sp.factor(coefficient)
    (4, -2*(alpha*s - 1)*(alpha*s + f)/(s**2*(alpha*s + 1)**3))
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    if n == 1:
        return 0, (alpha * s + f) / (s**2 * (alpha * s + 1))
    return 2 * (n - 1), -2 * (alpha * s + f) * (alpha * s - 1) ** (n - 2) / (
        s**2 * (alpha * s + 1) ** n
    )


def eq2_sum(s: sp.Expr = s, alpha: sp.Expr = alpha, f: sp.Expr = f) -> sp.Expr:
    r"""The whole of eq. (2) summed as the geometric series it is
    (ratio :math:`q = e^{-2s}(\alpha s - 1)/(\alpha s + 1)`):

    .. math::

        Y = \frac{\alpha s + f}{s^2(\alpha s + 1)}
            \left(1 - \frac{2 e^{-2s}}{(\alpha s + 1)(1 - q)}\right)

    >>> partial = sum(c * sp.exp(-d * s) for d, c in map(eq2_term, range(1, 30)))
    >>> bool(abs(float((eq2_sum() - partial).subs({s: 1, alpha: 2, f: 1}))) < 1e-15)
    True
    """
    q = sp.exp(-2 * s) * (alpha * s - 1) / (alpha * s + 1)
    return (
        (alpha * s + f)
        / (s**2 * (alpha * s + 1))
        * (1 - 2 * sp.exp(-2 * s) / ((alpha * s + 1) * (1 - q)))
    )
