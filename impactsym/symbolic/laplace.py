r"""Delay series and their exact, term-by-term inverse Laplace transform (paper section 1).

A *delay series* is an explicit list of ``(delay, transform)`` pairs: the quantity is

.. math::

    X(s) = \sum_k F_k(s)\, e^{-T_k s},
    \qquad
    x(t) = \sum_k f_k(t - T_k)\, \mathrm{H}(t - T_k),

where every :math:`F_k` is a rational function of :math:`s` (symbolic coefficients
allowed) and :math:`f_k = \mathcal{L}^{-1}\{F_k\}`. The caller hands over the terms
(nothing is split out of a SymPy ``Add``); this module checks that every delay is provably
non-negative (:func:`check_delay`), expands quotients of delay polynomials
(:func:`geometric_delay_series`) and inverts term by term (:func:`invert_delay_series`)
with :func:`~impactsym.symbolic.rational.invert_rational`. The forward transform
:func:`~impactsym.symbolic.transform.laplace_exp_poly` checks results by a round trip.
Method and checks: ``docs/physics.md``, "Delay series and their exact inversion".

``LaplaceInversionError``, ``invert_rational`` and ``laplace_exp_poly`` are importable from
here as well.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from itertools import product
from typing import Any

import sympy as sp

from impactsym.symbolic.rational import LaplaceInversionError as LaplaceInversionError
from impactsym.symbolic.rational import invert_rational
from impactsym.symbolic.transform import laplace_exp_poly as laplace_exp_poly
from impactsym.validation import as_sympy, reject_strings

DelayTerm = tuple[sp.Expr, sp.Expr]
"""``(delay, delay-free transform)``: one term :math:`F(s)e^{-Ts}` of a delay series."""

# LaplaceInversionError, invert_rational and laplace_exp_poly are re-exported and
# documented in impactsym.symbolic.rational and impactsym.symbolic.transform.
__all__ = [
    "DelayTerm",
    "check_delay",
    "geometric_delay_series",
    "invert_delay_series",
    "time_function",
]


# --------------------------------------------------------------------------- delays


def check_delay(delay: Any, bounds: Mapping[sp.Symbol, tuple[Any, Any]] | None = None) -> sp.Expr:
    """Return ``delay`` as a SymPy expression if it is provably non-negative, else raise.

    A delay is accepted if SymPy's assumptions prove :math:`T \\ge 0`, or if ``bounds``
    box some of its symbols (``{xi: (0, 1)}``) and :math:`T` is multilinear in them
    with a non-negative value at every vertex of the box (a multilinear function
    takes its minimum over a box at a vertex).

    Parameters
    ----------
    delay
        The delay :math:`T` of a term :math:`F(s) e^{-Ts}`.
    bounds
        Optional closed intervals for symbols of ``delay``.

    Raises
    ------
    LaplaceInversionError
        If the delay is infinite, undefined, or not provably non-negative.

    Examples
    --------
    >>> xi = sp.Symbol("xi", nonnegative=True)
    >>> check_delay(xi + 2)
    xi + 2
    >>> check_delay(2 - xi, {xi: (0, 1)})
    2 - xi
    >>> check_delay(2 - xi)
    Traceback (most recent call last):
        ...
    impactsym.symbolic.rational.LaplaceInversionError: delay 2 - xi is not provably non-negative
    """
    delay = as_sympy("delay", delay)
    reject_strings("bounds", bounds)
    if delay.has(sp.oo, -sp.oo, sp.zoo, sp.nan) or delay.is_finite is False:
        raise LaplaceInversionError(f"delay {delay} is not finite")
    if delay.is_nonnegative:
        return delay
    if bounds:
        boxed = [x for x in bounds if x in delay.free_symbols]
        if boxed and delay.is_polynomial(*boxed):
            poly = sp.Poly(delay, *boxed)
            if all(d <= 1 for d in poly.degree_list()):
                corners = product(*(bounds[x] for x in boxed))
                if all(
                    delay.subs(dict(zip(boxed, c, strict=True))).is_nonnegative for c in corners
                ):
                    return delay
    raise LaplaceInversionError(f"delay {delay} is not provably non-negative")


# ------------------------------------------------------------------- delay series


def geometric_delay_series(
    numerator: Sequence[DelayTerm],
    b0: sp.Expr,
    bp: sp.Expr,
    period: sp.Expr,
    n_terms: int,
) -> list[DelayTerm]:
    """Expand a quotient of delay polynomials into an explicit delay series.

    .. math::

        \\frac{\\sum_i a_i(s) e^{-d_i s}}{b_0(s) + b_p(s) e^{-p s}}
        = \\sum_i \\sum_{j \\ge 0} \\frac{a_i}{b_0} q^j e^{-(d_i + j p) s},
        \\qquad q = -\\frac{b_p}{b_0},

    which converges absolutely wherever :math:`|q e^{-p s}| < 1`. Terms with the same
    delay are merged: numerator delays that differ by an integer multiple of
    :math:`p` form a class, and in each class the coefficient of delay index
    :math:`n \\ge \\max o_i` is :math:`q^{\\,n - \\max o_i}` times one factored bracket,
    computed once (so that the :math:`n`-th coefficient costs no simplification).

    Parameters
    ----------
    numerator
        ``(delay, coefficient)`` pairs :math:`(d_i, a_i)`.
    b0, bp
        Coefficients of the denominator :math:`b_0 + b_p e^{-ps}`; :math:`b_0 \\ne 0`.
    period
        The denominator delay :math:`p > 0`.
    n_terms
        Number of ``(delay, coefficient)`` pairs returned, in order of the power
        :math:`j` of the geometric series and then of the numerator classes.

    Examples
    --------
    >>> s = sp.Symbol("s")
    >>> geometric_delay_series([(0, 1)], 1, -1 / (s + 1), 2, 3)
    [(0, 1), (2, 1/(s + 1)), (4, (s + 1)**(-2))]
    """
    if n_terms < 0:
        raise ValueError(f"n_terms must be >= 0, got {n_terms}")
    period = as_sympy("period", period)
    if not period.is_positive:
        raise ValueError(f"period must be provably positive, got {period}")
    b0, bp = as_sympy("b0", b0), as_sympy("bp", bp)
    q = sp.factor(-bp / b0)
    # group numerator delays into classes that differ by integer multiples of period
    classes: list[tuple[sp.Expr, list[tuple[int, sp.Expr]]]] = []
    for delay, coeff in numerator:
        delay, coeff = as_sympy("numerator delay", delay), as_sympy("numerator coefficient", coeff)
        for base, members in classes:
            shift = sp.simplify((delay - base) / period)
            if shift.is_integer:
                members.append((int(shift), coeff))
                break
        else:
            classes.append((delay, [(0, coeff)]))
    normalized = []
    for base, members in classes:
        low = min(o for o, _ in members)
        members = [(o - low, c) for o, c in members]
        high = max(o for o, _ in members)
        bracket = sp.factor(sum(c * q ** (high - o) for o, c in members) / b0)
        normalized.append((base + low * period, members, high, bracket))
    out: list[DelayTerm] = []
    n = 0
    while len(out) < n_terms:
        for base, members, high, bracket in normalized:
            if len(out) == n_terms:
                break
            if n >= high:
                coeff = bracket * q ** (n - high)
            else:
                coeff = sp.factor(sum(c * q ** (n - o) for o, c in members if o <= n) / b0)
            out.append((base + n * period, coeff))
        n += 1
    return out


def invert_delay_series(
    terms: Sequence[DelayTerm],
    s: sp.Symbol,
    t: sp.Symbol,
    *,
    bounds: Mapping[sp.Symbol, tuple[Any, Any]] | None = None,
) -> list[DelayTerm]:
    """Invert a delay series term by term.

    .. math::

        \\sum_k F_k(s) e^{-T_k s} \\;\\longrightarrow\\;
        \\sum_k f_k(t - T_k)\\, \\mathrm{H}(t - T_k),
        \\qquad f_k = \\mathcal{L}^{-1}\\{F_k\\}.

    Parameters
    ----------
    terms
        ``(delay, transform)`` pairs; every delay must be provably non-negative
        (see :func:`check_delay`), every transform rational in ``s``.
    s, t
        Transform and time variables.
    bounds
        Intervals for symbols in the delays, passed to :func:`check_delay`.

    Returns
    -------
    list of (delay, g)
        ``g`` is :math:`f_k(t)`, the unshifted inverse; the quantity is the sum of
        ``g(t - delay)`` over the terms whose delay has arrived (:func:`time_function`).

    Examples
    --------
    >>> s, t = sp.symbols("s t")
    >>> invert_delay_series([(0, 1 / s), (2, -2 / (s + 1))], s, t)
    [(0, 1), (2, -2*exp(-t))]
    """
    out = []
    for delay, transform in terms:
        delay = check_delay(delay, bounds)
        out.append((delay, invert_rational(transform, s, t)))
    return out


def time_function(terms: Sequence[DelayTerm], t: sp.Symbol) -> sp.Expr:
    """Sum ``g(t - delay) * Heaviside(t - delay)`` over inverted terms.

    The Heaviside step is taken right-continuous, :math:`\\mathrm{H}(0) = 1`: a term
    counts from the instant its delay has arrived.

    Examples
    --------
    >>> t = sp.Symbol("t")
    >>> time_function([(0, sp.Integer(1)), (2, -2 * sp.exp(-t))], t)
    -2*exp(2 - t)*Heaviside(t - 2, 1) + Heaviside(t, 1)
    """
    return sp.Add(*(g.subs(t, t - d) * sp.Heaviside(t - d, 1) for d, g in terms))
