r"""LaTeX for papers: the derived formulas as an author would typeset them.

A :class:`Typeset` is one display formula built from SymPy pieces: a left side, one or
more branches ``(expression, condition)`` set as a ``cases`` environment, and named
abbreviations (:math:`\omega_d = \sqrt{1 - D^2}`) defined once after the formula. It
keeps the expression it was derived from (``source``) and the region where it holds
(``domain``), so that a test can substitute the abbreviations back
(:meth:`Typeset.expression`) and compare with the source at random points of every branch.

* :class:`AuthorLatexPrinter` -- SymPy's printer with the conventions of a paper:
  :math:`\operatorname{atan2}(y, x)`, :math:`\operatorname{artanh}`, ``\cos(\omega_d\tau)``
  without ``\left(\right)`` around a product, exponents as ``e^{-t/\alpha}``, and a sum
  starting with its constant or a positive term (``1 - 4 D^2 (1 - f)``).
* :func:`tidy` -- an expression collected over given atoms (``e^{-t/\alpha}``,
  ``\cosh s``), each coefficient a polynomial in one variable with factored coefficients.
* :func:`minimal_condition` -- a conjunction of inequalities linear in one variable,
  reduced to the tightest bounds over a parameter interval (derived: the sign of every
  leading coefficient and of every difference of bounds is constant on the interval,
  because :func:`sympy.solveset` finds no zero there).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import sympy as sp
from sympy.printing.latex import LatexPrinter

__all__ = [
    "Abbreviation",
    "AuthorLatexPrinter",
    "Branch",
    "Typeset",
    "aligned",
    "latex",
    "minimal_condition",
    "positive_factor",
    "tidy",
]

#: functions printed as ``\name(arg)``, or ``\name x`` for a single symbol
_ELEMENTARY = {"sin", "cos", "tan", "sinh", "cosh", "tanh", "log"}


class AuthorLatexPrinter(LatexPrinter):
    """SymPy's LaTeX printer with the conventions of a paper (see the module docstring).

    >>> x, y = sp.symbols("x y")
    >>> print(latex(sp.pi + sp.atan2(y, x) + sp.cos(2 * x) * sp.exp(-x / y)))
    \\pi + \\operatorname{atan2}\\left(y, x\\right) + e^{- x / y} \\cos(2 x)
    """

    def _bracket(self, arg: sp.Basic) -> str:
        body = self._print(arg)
        if isinstance(arg, sp.Symbol):
            return " " + body
        if "\\frac" in body:
            return rf"\left({body}\right)"
        return f"({body})"

    def _print_Function(self, expr: sp.Basic, exp: str | None = None) -> str:
        name = expr.func.__name__
        if name in _ELEMENTARY and len(expr.args) == 1:
            head = "\\" + ("ln" if name == "log" else name)
            if exp is not None:
                head += f"^{{{exp}}}"
            return head + self._bracket(expr.args[0])
        return super()._print_Function(expr, exp)

    def _print_atan2(self, expr: sp.Basic, exp: str | None = None) -> str:
        y, x = expr.args
        head = r"\operatorname{atan2}" + (f"^{{{exp}}}" if exp else "")
        return rf"{head}\left({self._print(y)}, {self._print(x)}\right)"

    def _print_atan(self, expr: sp.Basic, exp: str | None = None) -> str:
        head = r"\arctan" + (f"^{{{exp}}}" if exp else "")
        return rf"{head}\left({self._print(expr.args[0])}\right)"

    def _print_atanh(self, expr: sp.Basic, exp: str | None = None) -> str:
        head = r"\operatorname{artanh}" + (f"^{{{exp}}}" if exp else "")
        return rf"{head}\left({self._print(expr.args[0])}\right)"

    def _print_Sum(self, expr: sp.Sum) -> str:
        """``\\sum_{n \\ge 2} \\frac{...}{...} \\Delta^{...}``: factors with a negative
        exponent below the line, powers of a symbol with a symbolic exponent after it."""
        ((n, low, high),) = expr.limits
        if high != sp.oo:
            return super()._print_Sum(expr)
        numerator, denominator, tail = [], [], []
        for factor in sp.Mul.make_args(expr.function):
            for part in sp.Mul.make_args(factor):
                base, power = part.as_base_exp()
                if power.could_extract_minus_sign():
                    denominator.append(sp.Pow(base, -power))
                elif isinstance(base, sp.Symbol) and not power.is_number:
                    tail.append(part)
                else:
                    numerator.append(part)
        body = self._print(sp.Mul(*numerator))
        if denominator:
            body = rf"\frac{{{body}}}{{{self._print(sp.Mul(*denominator))}}}"
        body += "".join(" " + self._print(part) for part in tail)
        return rf"\sum_{{{self._print(n)} \ge {self._print(low)}}} {body}"

    def _print_ExpBase(self, expr: sp.Basic, exp: str | None = None) -> str:
        power = LatexPrinter({"fold_short_frac": True}).doprint(expr.args[0])
        base = f"e^{{{power}}}"
        return base if exp is None else rf"\left({base}\right)^{{{exp}}}"

    def _print_Add(self, expr: sp.Add, order: str | None = None) -> str:
        terms = list(self._as_ordered_terms(expr, order=order))
        # a constant like pi leads (pi + atan2(...)); a sum does not start with a minus
        # sign when it has a positive term, preferring a constant (1 - 2 f, not -2 f + 1)
        irrational = [t for t in terms if t.is_number and not t.is_Rational]
        sums = [t for t in terms if t.has(sp.Sum) and t not in irrational]
        terms = irrational + [t for t in terms if t not in irrational and t not in sums] + sums
        if terms[0].could_extract_minus_sign():
            positive = [t for t in terms if not t.could_extract_minus_sign()]
            if positive:
                lead = next((t for t in positive if t.is_number), positive[0])
                terms.remove(lead)
                terms.insert(0, lead)
        out = self._print(terms[0])
        for term in terms[1:]:
            if term.could_extract_minus_sign():
                out += " - " + self._print(-term)
            else:
                out += " + " + self._print(term)
        return out


def latex(expr: Any) -> str:
    r"""``expr`` as LaTeX with :class:`AuthorLatexPrinter`.

    >>> D, f = sp.symbols("D f", positive=True)
    >>> print(latex(1 - 4 * D**2 * (1 - f)))
    1 - 4 D^{2} \left(1 - f\right)
    """
    return AuthorLatexPrinter().doprint(expr)


#: LaTeX characters above which a formula's abbreviations go to a line of their own
LONG = 220


class Abbreviation(NamedTuple):
    r"""A named sub-expression, defined once per formula: ``symbol = definition``.

    ``shown=False`` leaves the definition out of the LaTeX (it is given by a preceding
    formula, e.g. the ridge time :math:`\tau_r` in a boundary equation); it is still
    substituted by :meth:`Typeset.expression`.
    """

    symbol: sp.Symbol
    definition: sp.Expr
    shown: bool = True


class Branch(NamedTuple):
    """One case of a formula: the expression (in the abbreviations) and where it holds."""

    expr: sp.Expr
    condition: sp.Boolean = sp.true


@dataclass(frozen=True)
class Typeset:
    r"""One display formula: ``lhs``, an equals sign, its branches, then its abbreviations.

    Parameters
    ----------
    lhs
        LaTeX of the left side, e.g. ``r"\tau_r"``.
    branches
        The right side; several branches are set as ``cases`` with their conditions,
        one branch with a condition other than ``true`` gets the condition after it.
    abbreviations
        Defined after the formula (``\text{with } \omega_d = \sqrt{1 - D^2}``), substituted
        back last-to-first by :meth:`expression`.
    source
        The expression of the package the formula was typeset from (``None`` for an
        equation written by hand).
    domain
        Where the formula claims to hold (the damping regime), a SymPy boolean.
    otherwise
        Text for the part of ``domain`` no branch covers (e.g. why there is no value).
    factor
        A common factor set before the right side, ``\frac{1}{\omega_d}\left(...\right)``
        instead of a fraction over a fraction.

    Examples
    --------
    >>> D, tau = sp.symbols("D tau", positive=True)
    >>> w = sp.Symbol("omega_d", positive=True)
    >>> form = Typeset("x", (Branch(sp.cos(w * tau)),), (Abbreviation(w, sp.sqrt(1 - D**2)),))
    >>> print(form.latex())
    x = \cos(\omega_{d} \tau), \qquad \text{with } \omega_{d} = \sqrt{1 - D^{2}}
    >>> form.expression()
    cos(tau*sqrt(1 - D**2))
    """

    lhs: str
    branches: tuple[Branch, ...]
    abbreviations: tuple[Abbreviation, ...] = ()
    source: sp.Basic | None = None
    domain: sp.Boolean = sp.true
    otherwise: str = ""
    factor: sp.Expr = sp.S.One

    def rhs(self) -> str:
        """LaTeX of the right side (a ``cases`` environment for several branches)."""
        if len(self.branches) == 1 and not self.otherwise:
            (branch,) = self.branches
            body = latex(branch.expr)
            if self.factor != 1:
                wrapped = rf"\left({body}\right)" if isinstance(branch.expr, sp.Add) else body
                body = latex(self.factor) + " " + wrapped
            if branch.condition != sp.true:
                body += r", \qquad \text{for } " + latex(branch.condition)
            return body
        rows = [
            latex(b.expr)
            + ", & "
            + (r"\text{otherwise}" if b.condition == sp.true else latex(b.condition))
            for b in self.branches
        ]
        if self.otherwise:
            rows.append(rf"\text{{{self.otherwise}}}")
        return r"\begin{cases}" + r" \\ ".join(rows) + r"\end{cases}"

    def where(self) -> str:
        """LaTeX of the shown abbreviations, ``a = ..., \\quad b = ...`` (or empty)."""
        shown = [a for a in self.abbreviations if a.shown]
        return r", \quad ".join(f"{latex(a.symbol)} = {latex(a.definition)}" for a in shown)

    def latex(self, *, align: bool = False) -> str:
        """The whole formula; ``align=True`` puts ``&`` before the equals sign.

        A long formula (more than :data:`LONG` characters of LaTeX) gets its
        abbreviations on a second line.
        """
        where = self.where()
        body = f"{self.lhs} {'&' if align else ''}= {self.rhs()}"
        if not where:
            return body
        if align or len(body) + len(where) <= LONG:
            return body + r", \qquad \text{with } " + where
        return rf"\begin{{aligned}}&{body}, \\ &\qquad \text{{with }} {where}\end{{aligned}}"

    def expression(self) -> sp.Expr:
        """The right side with every abbreviation substituted, as a ``Piecewise`` when
        the formula has conditions (``nan`` where no branch holds)."""
        if len(self.branches) == 1 and self.branches[0].condition == sp.true:
            expr = self.branches[0].expr
        else:
            expr = sp.Piecewise(*((b.expr, b.condition) for b in self.branches), (sp.nan, True))
        expr = self.factor * expr
        for abbreviation in reversed(self.abbreviations):
            expr = expr.subs(abbreviation.symbol, abbreviation.definition)
        return expr


def aligned(rows: Sequence[Typeset | str]) -> str:
    r"""Several formulas in one ``aligned`` environment, aligned at their equals signs;
    a row given as LaTeX must carry its own ``&``.

    >>> x = sp.Symbol("x")
    >>> print(aligned([Typeset("y", (Branch(x),)), r"z &= 2"]))
    \begin{aligned}y &= x \\ z &= 2\end{aligned}
    """
    body = r" \\ ".join(row if isinstance(row, str) else row.latex(align=True) for row in rows)
    return r"\begin{aligned}" + body + r"\end{aligned}"


def positive_factor(expr: sp.Expr) -> sp.Expr:
    """A product with a negative coefficient and a factor ``(x - 1)`` as ``(1 - x)``.

    >>> f = sp.Symbol("f")
    >>> positive_factor(sp.factor(2 * f - 2 * f**2))
    2*f*(1 - f)
    """
    if not (isinstance(expr, sp.Mul) and expr.could_extract_minus_sign()):
        return expr
    factors = list(expr.args)
    for i, factor in enumerate(factors):
        if isinstance(factor, sp.Add):
            coefficient = sp.Mul(*factors[:i], *factors[i + 1 :])
            return sp.Mul(*sp.Mul.make_args(-coefficient), -factor, evaluate=False)
    return expr


def tidy(
    expr: sp.Expr, atoms: tuple[sp.Expr, ...] = (), variable: sp.Symbol | None = None
) -> sp.Expr:
    r"""``expr`` collected over ``atoms``, each coefficient as a polynomial in
    ``variable`` whose coefficients are factored; with one atom :math:`E`, terms
    :math:`c\,x^k - c\,x^k E` are written :math:`c\,x^k (1 - E)`.

    >>> t, a, f = sp.symbols("t alpha f", positive=True)
    >>> E = sp.exp(-t / a)
    >>> tidy(4*a*f - 2*a - 2*f*t + (-4*a*f + 2*a + t*(2 - 2*f))*E, (E,), t)
    2*alpha*(1 - exp(-t/alpha))*(2*f - 1) - 2*f*t + 2*t*(1 - f)*exp(-t/alpha)
    """
    parts = sp.collect(sp.expand(expr), list(atoms), evaluate=False) if atoms else {1: expr}
    terms: dict[sp.Expr, dict[int, sp.Expr]] = {}
    for atom, coefficient in parts.items():
        if variable is not None and coefficient.is_polynomial(variable):
            powers = {k: c for (k,), c in sp.Poly(coefficient, variable).terms()}
        else:
            powers = {0: coefficient}
        terms[atom] = powers
    out = sp.Integer(0)
    if len(atoms) == 1 and variable is not None:  # c x^k (1 - E)
        (atom,) = atoms
        plain, decaying = terms.setdefault(sp.S.One, {}), terms.setdefault(atom, {})
        for k in [k for k in plain if sp.expand(plain[k] + decaying.get(k, 0)) == 0]:
            out += positive_factor(sp.factor(plain.pop(k))) * variable**k * (1 - atom)
            decaying.pop(k)
    for atom, powers in terms.items():
        coefficient = sp.Add(
            *(
                positive_factor(sp.factor(c)) * (variable**k if variable is not None else 1)
                for k, c in powers.items()
            )
        )
        out += coefficient * atom
    return out


def _linear(relation: sp.core.relational.Relational, variable: sp.Symbol):
    """``(a, b, op)`` of ``a variable + b op 0``, ``op`` one of ``<, <=, >, >=``."""
    lhs = sp.expand(relation.lhs - relation.rhs)
    a, b = lhs.coeff(variable, 1), lhs.coeff(variable, 0)
    if sp.expand(a * variable + b - lhs) != 0:
        raise ValueError(f"{relation} is not linear in {variable}")
    return a, b, relation.rel_op


def _sign_on(expr: sp.Expr, parameter: sp.Symbol | None, interval: sp.Interval) -> int:
    """The constant sign of ``expr`` on ``interval``: no zero inside (solveset), so the
    sign at one interior point holds throughout. Raises where it changes or is unknown."""
    expr = sp.radsimp(sp.simplify(expr))
    if parameter is None or not expr.has(parameter):
        value = expr
    else:
        zeros = sp.solveset(expr, parameter, domain=interval)
        if zeros != sp.EmptySet:
            raise ValueError(f"{expr} may change sign on {interval}: zeros {zeros}")
        low, high = interval.inf, interval.sup
        inner = {(True, True): 0, (False, True): low + 1, (True, False): high - 1}.get(
            (low == -sp.oo, high == sp.oo), (low + high) / 2
        )
        value = expr.subs(parameter, inner)
    sign = sp.sign(sp.nsimplify(value) if value.is_number else value)
    if sign not in (1, -1):
        raise ValueError(f"sign of {expr} on {interval} is not definite")
    return int(sign)


def minimal_condition(
    inequalities: sp.Boolean,
    variable: sp.Symbol,
    *,
    parameter: sp.Symbol | None = None,
    interval: sp.Set = sp.S.Reals,
) -> sp.Boolean:
    r"""A conjunction of inequalities linear in ``variable`` as its tightest bounds.

    Every inequality :math:`a\,x + b \lessgtr 0` becomes a bound :math:`x \lessgtr -b/a`
    (the sign of ``a`` is constant on ``interval`` of ``parameter``); of several upper
    (lower) bounds only the smallest (largest) is kept when their difference has
    a constant sign on the interval; bounds that cannot be ordered are all kept.

    >>> D, f = sp.symbols("D f", positive=True)
    >>> minimal_condition(sp.And(1 - 2 * f > 0, 4 * f - 3 < 0), f)
    f < 1/2
    >>> cond = sp.And(4 * D**2 * (f - 1) + 1 < 0, 2 * D * f - D < 0)
    >>> minimal_condition(cond, f, parameter=D, interval=sp.Interval.open(1, sp.oo))
    f < 1/2
    """
    atoms = sp.And.make_args(inequalities)
    upper: list[tuple[sp.Expr, bool]] = []  # (bound, strict)
    lower: list[tuple[sp.Expr, bool]] = []
    for atom in atoms:
        if not isinstance(atom, sp.core.relational.Relational) or atom.rel_op not in (
            "<",
            "<=",
            ">",
            ">=",
        ):
            raise ValueError(f"{atom} is not an inequality")
        a, b, op = _linear(atom, variable)
        sign = _sign_on(a, parameter, interval)
        bound = sp.radsimp(sp.factor(-b / a))
        below = (op in ("<", "<=")) == (sign > 0)  # variable < bound
        (upper if below else lower).append((bound, op in ("<", ">")))

    def tightest(bounds: list[tuple[sp.Expr, bool]], keep_smaller: bool):
        kept: list[tuple[sp.Expr, bool]] = []
        for bound, strict in bounds:
            for i, (other, _) in enumerate(kept):
                try:
                    sign = _sign_on(bound - other, parameter, interval)
                except ValueError:
                    continue
                if (sign < 0) == keep_smaller:
                    kept[i] = (bound, strict)
                break
            else:
                kept.append((bound, strict))
        return kept

    relations = [
        sp.StrictLessThan(variable, u) if strict else sp.LessThan(variable, u)
        for u, strict in tightest(upper, keep_smaller=True)
    ] + [
        sp.StrictGreaterThan(variable, lo) if strict else sp.GreaterThan(variable, lo)
        for lo, strict in tightest(lower, keep_smaller=False)
    ]
    return sp.And(*relations)
