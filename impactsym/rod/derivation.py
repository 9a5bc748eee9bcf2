"""Impact of a mass on an elastic rod (paper section 1): derivation and time functions.

A striker (mass ratio :math:`\\alpha`, pressing force :math:`f`) hits the free end of
an elastic rod fixed at its other end, through a contact spring of stiffness
:math:`\\kappa` (rigid contact: :math:`\\kappa \\to \\infty`). In the Laplace domain
(normalization of the physics page of the docs, ``docs/physics.md``), the paper's eq. (1) is

.. math::

    s^2 W - W'' = 0, \\quad W(1, s) = 0, \\quad
    \\alpha s^2 Y + \\kappa Y - \\frac{f}{s} - \\kappa W(0, s) - \\alpha = 0, \\quad
    W'(0, s) + \\frac{f}{s} - \\alpha s^2 Y + \\alpha = 0.

:class:`RodImpact` builds and solves it with SymPy, expands the closed forms in
:math:`\\Delta = e^{-s}` into delay series (the paper's eq. (2) for
:math:`\\kappa \\to \\infty`) and inverts them term by term with
:mod:`impactsym.symbolic.laplace`. The float time functions
:func:`~impactsym.rod.displacement`, :func:`~impactsym.rod.contact_force` and
:func:`~impactsym.rod.contact_time` live in :mod:`impactsym.rod.api` and
:mod:`impactsym.rod.contact_times`; :mod:`impactsym.rod` exports them.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp

from impactsym.symbolic.laplace import (
    DelayTerm,
    LaplaceInversionError,
    geometric_delay_series,
    invert_delay_series,
)
from impactsym.symbolic.typeset import Abbreviation, Branch, Typeset, aligned, tidy
from impactsym.validation import as_sympy

__all__ = ["RodImpact", "latex_formulas", "typeset_formulas"]

s = sp.Symbol("s")
t = sp.Symbol("t", real=True)
xi = sp.Symbol("xi", nonnegative=True)
alpha = sp.Symbol("alpha", positive=True)
f = sp.Symbol("f", nonnegative=True)
kappa = sp.Symbol("kappa", positive=True)

_W = sp.Function("W")
_Y = sp.Function("Y")
QUANTITIES = ("W", "Y", "N")


def _as_kappa(value: Any) -> sp.Expr:
    """The contact stiffness as SymPy: ``oo``, a positive exact number, or a symbol."""
    if isinstance(value, (bool, np.bool_)) or value is None:
        raise TypeError(
            f"kappa must be a positive number, sympy.oo or a SymPy symbol, got {value!r}"
        )
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if math.isnan(value):
            raise ValueError("kappa must be a positive number or inf, got nan")
        if math.isinf(value):
            if value < 0:
                raise ValueError(f"kappa must be > 0, got {value!r}")
            return sp.oo
        value = sp.Rational(repr(value))  # the decimal the float prints as
    value = as_sympy("kappa", value)
    if value is sp.oo:
        return value
    if isinstance(value, sp.Float):
        value = sp.Rational(str(value))
    if value.is_number:
        if not (value.is_real and value.is_positive and value.is_finite):
            raise ValueError(f"kappa must be > 0 (a real number or oo), got {value}")
        return value
    if value.is_positive is False:
        raise ValueError(f"kappa must be positive, got {value}")
    return value


class RodImpact:
    """The rod impact problem, eq. (1), solved in closed form and as delay series.

    Parameters
    ----------
    kappa
        Normalized contact stiffness :math:`\\kappa = k_c L / (EA)`: ``sympy.oo``
        (rigid contact, the default), a positive number (floats are read as the
        decimal they print as) or a SymPy symbol.

    Attributes
    ----------
    equations : dict of str to sympy.Eq
        Eq. (1): ``"rod"``, ``"fixed end"``, ``"mass"`` and ``"end"``; for rigid
        contact ``"mass"`` is replaced by ``"contact"``: :math:`Y = W(0, s)`.
    W, Y, N : sympy.Expr
        Closed-form transforms :math:`W(\\xi, s)`, :math:`Y(s)` and the contact force
        :math:`N(s) = -\\partial_\\xi W(0, s)`.

    Notes
    -----
    The general solution of :math:`W'' = s^2 W` is taken as
    :math:`A \\sinh s(1-\\xi) + B \\cosh s(1-\\xi)`; the boundary conditions give
    :math:`A`, :math:`B = 0` and :math:`Y` by a linear solve. For rigid contact

    .. math::

        Y = \\frac{(\\alpha s + f)\\sinh s}{s^2(\\cosh s + \\alpha s \\sinh s)}, \\qquad
        N = \\frac{(\\alpha s + f)\\cosh s}{s(\\cosh s + \\alpha s \\sinh s)}.

    Series (:meth:`series`), inverted terms (:meth:`time_terms`) are computed once
    per instance and extended on demand; the result never depends on call order.

    Examples
    --------
    >>> rod = RodImpact()
    >>> rod.series("Y", 2)[1]
    (2, -2*(alpha*s + f)/(s**2*(alpha*s + 1)**2))
    >>> rod.time_terms("N", 1)[0]
    (0, f + (1 - f)*exp(-t/alpha))
    """

    s, t, xi, alpha, f = s, t, xi, alpha, f

    def __init__(self, kappa: Any = sp.oo) -> None:
        self.kappa = _as_kappa(kappa)
        self._series: dict[str, list[DelayTerm]] = {}
        self._time_terms: dict[str, list[DelayTerm]] = {}

    def __repr__(self) -> str:
        return f"RodImpact(kappa={self.kappa})"

    @property
    def rigid(self) -> bool:
        """Whether the contact is rigid (:math:`\\kappa = \\infty`)."""
        return self.kappa is sp.oo

    # ------------------------------------------------------------ equations (1)

    @cached_property
    def equations(self) -> dict[str, sp.Eq]:
        """The transformed boundary-value problem, eq. (1).

        >>> RodImpact(10).equations["mass"]
        Eq(alpha*s**2*Y(s) - alpha - f/s - 10*W(0, s) + 10*Y(s), 0)
        """
        W, Y = _W(xi, s), _Y(s)
        eqs = {
            "rod": sp.Eq(s**2 * W - sp.Derivative(W, (xi, 2)), 0),
            "fixed end": sp.Eq(_W(1, s), 0),
        }
        if self.rigid:
            eqs["contact"] = sp.Eq(Y, _W(0, s))
        else:
            k = self.kappa
            eqs["mass"] = sp.Eq(alpha * s**2 * Y + k * Y - f / s - k * _W(0, s) - alpha, 0)
        eqs["end"] = sp.Eq(
            sp.Subs(sp.Derivative(W, xi), xi, 0) + f / s - alpha * s**2 * Y + alpha, 0
        )
        return eqs

    def residuals(self, W: sp.Expr, Y: sp.Expr) -> dict[str, sp.Expr]:
        """Left minus right side of every equation of (1) for a candidate ``W``, ``Y``.

        ``W`` is an expression in ``xi`` and ``s``, ``Y`` in ``s``; all residuals of
        the solution simplify to zero.

        >>> rod = RodImpact()
        >>> {k: sp.simplify(v) for k, v in rod.residuals(rod.W, rod.Y).items()}
        {'rod': 0, 'fixed end': 0, 'contact': 0, 'end': 0}
        """

        W, Y = as_sympy("W", W), as_sympy("Y", Y)

        def insert(expr: sp.Expr) -> sp.Expr:
            expr = expr.replace(_W, lambda x, _s: W.subs(xi, x)).subs(_Y(s), Y)
            return expr.doit()

        return {name: insert(eq.lhs - eq.rhs) for name, eq in self.equations.items()}

    @cached_property
    def _solution(self) -> dict[str, sp.Expr]:
        A, B, Yv = sp.symbols("A B Y_s")
        ansatz = A * sp.sinh(s * (1 - xi)) + B * sp.cosh(s * (1 - xi))
        residuals = self.residuals(ansatz, Yv)
        if sp.simplify(residuals.pop("rod")) != 0:  # pragma: no cover - W'' = s^2 W
            raise RuntimeError("the ansatz does not solve the rod equation")
        # the boundary conditions are linear in A, B, Y with coefficients rational in
        # s, sinh s, cosh s: solve over that field (sinh s, cosh s as symbols)
        S, C = sp.symbols("S C")
        hyper = {sp.sinh(s): S, sp.cosh(s): C}
        equations = [sp.expand(r).xreplace(hyper) for r in residuals.values()]
        solution = sp.solve(equations, [A, B, Yv], dict=True)
        if len(solution) != 1:  # pragma: no cover - the system is linear and regular
            raise RuntimeError(f"eq. (1) has no unique solution: {solution}")
        back = {S: sp.sinh(s), C: sp.cosh(s)}
        sol = {k: sp.factor(v).xreplace(back) for k, v in solution[0].items()}
        W = sol[A] * sp.sinh(s * (1 - xi)) + sol[B] * sp.cosh(s * (1 - xi))
        N = sp.factor(-sp.diff(W, xi).subs(xi, 0))
        return {"W": W, "Y": sol[Yv], "N": N}

    @property
    def W(self) -> sp.Expr:
        """Rod displacement :math:`W(\\xi, s)`."""
        return self._solution["W"]

    @property
    def Y(self) -> sp.Expr:
        """Striker displacement :math:`Y(s)`."""
        return self._solution["Y"]

    @property
    def N(self) -> sp.Expr:
        """Contact force :math:`N(s) = -\\partial W / \\partial \\xi\\,(0, s)`."""
        return self._solution["N"]

    def closed_form(self, name: str) -> sp.Expr:
        """The closed form of ``"W"``, ``"Y"`` or ``"N"``.

        >>> RodImpact().closed_form("N")
        (alpha*s + f)*cosh(s)/(s*(alpha*s*sinh(s) + cosh(s)))
        """
        return self._solution[_check_name(name)]

    # ------------------------------------------------------------- delay series

    @cached_property
    def _quotient(self) -> dict[str, tuple[list[DelayTerm], sp.Expr, sp.Expr]]:
        """Each closed form as (numerator delay terms, b0, b2) of ``num / (b0 + b2 Δ²)``.

        Numerator and denominator are multiplied by :math:`2e^{-s}`, which turns
        :math:`\\cosh cs` into :math:`e^{-(1-c)s} + e^{-(1+c)s}` and
        :math:`\\sinh cs` into :math:`e^{-(1-c)s} - e^{-(1+c)s}`.
        """
        out = {}
        for name, expr in self._solution.items():
            numer, denom = sp.fraction(sp.together(expr))
            den_terms = _hyperbolic_delay_terms(denom)
            delays = dict(den_terms)
            if set(delays) != {0, 2}:  # pragma: no cover - structure of eq. (1)
                raise RuntimeError(f"unexpected denominator {denom}")
            out[name] = (_hyperbolic_delay_terms(numer), delays[0], delays[2])
        return out

    def series(self, name: str, n_terms: int) -> list[DelayTerm]:
        """The first ``n_terms`` terms of the delay series of ``W``, ``Y`` or ``N``.

        .. math::

            X(s) = \\sum_{k} X_k(s)\\, e^{-T_k s}, \\qquad
            \\frac{1}{b_0 + b_2 \\Delta^2}
            = \\frac{1}{b_0} \\sum_{j \\ge 0} \\Bigl(-\\frac{b_2}{b_0}\\Bigr)^j \\Delta^{2j},

        absolutely convergent for :math:`\\operatorname{Re} s > 0`, where
        :math:`|b_2 / b_0| < 1` (the reflection factor is all-pass). For rigid
        contact :math:`-b_2/b_0 = (\\alpha s - 1)/(\\alpha s + 1)` and ``Y`` is eq. (2),

        .. math::

            Y = \\frac{\\alpha s + f}{s^2(\\alpha s + 1)}
              - \\sum_{n \\ge 2} \\frac{2(\\alpha s + f)(\\alpha s - 1)^{n-2}}
                {s^2 (\\alpha s + 1)^n} \\Delta^{2(n-1)},
            \\qquad
            N = \\frac{\\alpha s + f}{s(\\alpha s + 1)}
              + \\sum_{n \\ge 2} \\frac{2\\alpha(\\alpha s + f)(\\alpha s - 1)^{n-2}}
                {(\\alpha s + 1)^n} \\Delta^{2(n-1)};

        for finite :math:`\\kappa` the factors are quadratic,
        :math:`P = \\alpha s^2 + \\alpha\\kappa s + \\kappa` and
        :math:`Q = \\alpha s^2 - \\alpha\\kappa s + \\kappa`.

        Parameters
        ----------
        name
            ``"Y"``, ``"N"`` or ``"W"`` (for ``W`` the delays are :math:`\\xi + 2j`
            and :math:`2 - \\xi + 2j`, the incident and the reflected wave).
        n_terms
            Number of ``(delay, coefficient)`` pairs.

        Returns
        -------
        list of (delay, coefficient)
            The coefficient is a SymPy expression in ``s``, ``alpha``, ``f`` (and
            ``kappa``); the quantity is the sum of ``coefficient * exp(-delay * s)``.

        Examples
        --------
        >>> RodImpact().series("N", 2)
        [(0, (alpha*s + f)/(s*(alpha*s + 1))), (2, 2*alpha*(alpha*s + f)/(alpha*s + 1)**2)]
        """
        name = _check_name(name)
        n_terms = _check_n_terms(n_terms)
        cached = self._series.get(name, [])
        if len(cached) < n_terms:
            numerator, b0, b2 = self._quotient[name]
            cached = geometric_delay_series(numerator, b0, b2, 2, n_terms)
            self._series[name] = cached
        return list(cached[:n_terms])

    def time_terms(self, name: str, n_terms: int) -> list[DelayTerm]:
        """The first ``n_terms`` series terms inverted exactly, as ``(delay, g)`` pairs.

        .. math::

            x(t) = \\sum_{k:\\, T_k \\le t} g_k(t - T_k),
            \\qquad g_k = \\mathcal{L}^{-1}\\{X_k\\},

        with ``g`` a SymPy expression in ``t`` (and ``alpha``, ``f``, ``kappa``; for
        ``W`` also ``xi``). Inverted by :func:`impactsym.symbolic.laplace.invert_delay_series`.

        Examples
        --------
        >>> RodImpact().time_terms("Y", 1)
        [(0, -alpha*f + alpha + f*t + (alpha*f - alpha)*exp(-t/alpha))]
        """
        name = _check_name(name)
        n_terms = _check_n_terms(n_terms)
        cached = self._time_terms.get(name, [])
        if len(cached) < n_terms:
            new = self.series(name, n_terms)[len(cached) :]
            cached = cached + invert_delay_series(new, s, t, bounds={xi: (0, 1)})
            self._time_terms[name] = cached
        return list(cached[:n_terms])

    def time_function(self, name: str, n_terms: int) -> sp.Expr:
        """The sum of the first ``n_terms`` inverted terms with their Heaviside steps.

        >>> rod = RodImpact()
        >>> rod.time_function("N", 2).subs({rod.f: 0, rod.t: 1})
        exp(-1/alpha)
        """
        from impactsym.symbolic.laplace import time_function

        return time_function(self.time_terms(name, n_terms), t)

    # --------------------------------------------------------------------- LaTeX

    def latex(self, name: str, *, condition: str | None = None) -> str:
        r"""LaTeX of an equation of (1) (``rod``, ``fixed end``, ``mass``, ``end``, or
        ``contact`` for the rigid limit) or of a closed form (``W``, ``Y``, ``N``).

        ``condition`` is accepted for the common interface of the derivation objects;
        no rod formula depends on it, so it must be ``None``.

        >>> RodImpact().latex("Y").startswith(r"\frac{\left(\alpha s + f\right) \sinh")
        True
        """
        if condition is not None:
            raise ValueError(f"no rod formula depends on the contact condition, got {condition!r}")
        names = (*self.equations, *QUANTITIES)
        if not isinstance(name, str) or name not in names:
            raise ValueError(f"name must be one of {names}, got {name!r}")
        expr = self.equations[name] if name in self.equations else self._solution[name]
        return sp.latex(expr)


def _check_name(name: object) -> str:
    if not isinstance(name, str):
        raise TypeError(f"name must be one of {QUANTITIES}, got {name!r}")
    if name not in QUANTITIES:
        raise ValueError(f"name must be one of {QUANTITIES}, got {name!r}")
    return name


#: Most series terms a LaTeX document shows: the exact inversion of term ``n`` has a
#: pole of order ``n`` and the document takes about a second per 8 terms at 20, growing
#: quadratically (``latex_formulas(200)`` would run for minutes).
MAX_LATEX_TERMS = 20


def _check_n_terms(n_terms: object, budget: int | None = None) -> int:
    if isinstance(n_terms, (bool, np.bool_)) or not isinstance(n_terms, (int, np.integer)):
        raise TypeError(f"n_terms must be an int, got {n_terms!r}")
    n_terms = int(n_terms)
    if n_terms < 0:
        raise ValueError(f"n_terms must be >= 0, got {n_terms}")
    if budget is not None and n_terms > budget:
        raise ValueError(
            f"n_terms = {n_terms} exceeds the budget of {budget} terms for formula "
            "documents (the symbolic work grows quadratically with the number of terms)"
        )
    return n_terms


def _hyperbolic_delay_terms(expr: sp.Expr) -> list[DelayTerm]:
    """``2 exp(-s) * expr`` as delay terms, for ``expr`` linear in ``cosh(c s)``,
    ``sinh(c s)`` with rational coefficients and ``0 <= c <= 1``."""
    expr = sp.expand(expr)
    terms: dict[sp.Expr, sp.Expr] = {}
    hyper = [h for h in expr.atoms(sp.cosh, sp.sinh) if h.has(s)]
    rest = expr
    for h in hyper:
        coeff = expr.coeff(h)
        rest = rest - coeff * h
        c = sp.expand(h.args[0] / s)
        if c.has(s):
            raise LaplaceInversionError(f"argument of {h} is not proportional to {s}")
        sign = 1 if isinstance(h, sp.cosh) else -1
        for delay, weight in ((1 - c, 1), (1 + c, sign)):
            delay = sp.expand(delay)
            terms[delay] = terms.get(delay, 0) + weight * coeff
    if sp.expand(rest) != 0:
        raise LaplaceInversionError(f"{expr} is not linear in cosh and sinh of {s}")
    return [(d, sp.factor(c)) for d, c in terms.items() if c != 0]


# ----------------------------------------------------------------------- LaTeX


#: the delay factor of eq. (2), an abbreviation of the typeset series
DELTA = sp.Symbol("Delta", positive=True)
_n = sp.Symbol("n", integer=True, positive=True)


def _typeset_closed_form(model: RodImpact, name: str) -> Typeset:
    """W, Y or N as one fraction, every factor collected over sinh s and cosh s."""
    numerator, denominator = sp.fraction(model.closed_form(name))
    hyperbolic = (sp.sinh(s), sp.cosh(s))

    def collected(product: sp.Expr) -> sp.Expr:
        return sp.Mul(
            *(
                tidy(factor, hyperbolic) if factor.has(*hyperbolic) else factor
                for factor in sp.Mul.make_args(product)
            )
        )

    lhs = {"W": r"W(\xi, s)", "Y": "Y(s)", "N": "N(s)"}[name]
    return Typeset(
        lhs, (Branch(collected(numerator) / collected(denominator)),), (), model.closed_form(name)
    )


def _typeset_series(model: RodImpact, name: str, n_terms: int) -> Typeset:
    r"""Eq. (2) (``Y``) and the contact force series (``N``) in the paper's closed form
    :math:`X_1 + \sum_{n \ge 2} X_n \Delta^{2(n-1)}`; ``source`` is the sum of the first
    ``n_terms`` derived terms with :math:`\Delta = e^{-s}`."""
    a = alpha * s
    if name == "Y":
        first = (a + f) / (s**2 * (a + 1))
        sign, term = -1, 2 * ((a + f) * (a - 1) ** (_n - 2)) / (s**2 * (a + 1) ** _n)
    else:
        first = (a + f) / (s * (a + 1))
        sign, term = 1, 2 * alpha * ((a + f) * (a - 1) ** (_n - 2)) / (a + 1) ** _n
    delay = DELTA ** sp.Mul(2, _n - 1, evaluate=False)
    series = first + sign * sp.Sum(sp.Mul(term, delay, evaluate=False), (_n, 2, sp.oo))
    source = sp.Add(*(c * sp.exp(-d * s) for d, c in model.series(name, n_terms)))
    return Typeset(f"{name}(s)", (Branch(series),), (Abbreviation(DELTA, sp.exp(-s)),), source)


def _typeset_time_terms(model: RodImpact, name: str, n_terms: int) -> list[Typeset | str]:
    """The inverted terms g_k(t), collected over exp(-t/alpha) with factored coefficients
    of the powers of t, after the line that sums them."""
    symbol = {"Y": "y", "N": "N"}[name]
    decay = sp.exp(-t / alpha)
    rows: list[Typeset | str] = [rf"{symbol}(t) &= \sum_{{k \ge 0}} {symbol}_k(t - 2k)\, H(t - 2k)"]
    for k, (_, g) in enumerate(model.time_terms(name, n_terms)):
        rows.append(Typeset(f"{symbol}_{{{k}}}(t)", (Branch(tidy(g, (decay,), t)),), (), g))
    return rows


def typeset_formulas(n_terms: int = 3) -> list[tuple[str, str, Any]]:
    r"""Formulas of the rod analysis as ``(label, sentence, form)``, typeset for a paper.

    ``form`` is a :class:`~impactsym.symbolic.typeset.Typeset` (with the expression it
    came from), a list of them set as ``aligned`` rows, or LaTeX written by hand (eq. (1)).
    The closed forms are collected over :math:`\sinh s, \cosh s`; the series are the
    paper's closed form of eq. (2) with :math:`\Delta = e^{-s}`; the inverted terms
    (the first ``n_terms``, at most :data:`MAX_LATEX_TERMS`) are collected over
    :math:`e^{-t/\alpha}`.

    >>> [label for label, _, _ in typeset_formulas(1)][-2:]
    ['rod-Y-time-terms', 'rod-N-time-terms']
    """
    n_terms = _check_n_terms(n_terms, budget=MAX_LATEX_TERMS)
    rigid, elastic = RodImpact(), RodImpact(kappa)
    out: list[tuple[str, str, Any]] = [
        (
            "rod-bvp",
            r"The transformed boundary-value problem of the paper's eq. (1): rod, fixed end, "
            r"striker on the contact spring $\kappa$ and the force balance at the struck end "
            r"(primes are derivatives in $\xi$).",
            r"\begin{gathered}s^{2} W(\xi, s) - W''(\xi, s) = 0, \qquad W(1, s) = 0, \\ "
            r"\alpha s^{2} Y(s) + \kappa Y(s) - \frac{f}{s} - \kappa W(0, s) - \alpha = 0, \\ "
            r"W'(0, s) + \frac{f}{s} - \alpha s^{2} Y(s) + \alpha = 0\end{gathered}",
        ),
        (
            "rod-bvp-rigid",
            r"For rigid contact ($\kappa \to \infty$) the mass equation of eq. (1) becomes "
            "the contact condition.",
            r"Y(s) = W(0, s)",
        ),
    ]
    for model, tag, words in (
        (rigid, "rigid", "rigid contact"),
        (
            elastic,
            "kappa",
            "contact "
            r"stiffness $\kappa$",
        ),
    ):
        for name in QUANTITIES:
            what = {
                "W": r"rod displacement $W(\xi, s)$",
                "Y": "striker displacement $Y(s)$",
                "N": r"contact force $N(s) = -W'(0, s)$",
            }[name]
            out.append(
                (
                    f"rod-{name}-{tag}",
                    f"Closed form of the {what}, {words}.",
                    _typeset_closed_form(model, name),
                )
            )
    out.append(
        (
            "rod-eq2",
            r"The striker displacement as a series of wave reflections (the paper's eq. (2)), "
            r"rigid contact: $\Delta = e^{-s}$ is the delay of one round trip.",
            _typeset_series(rigid, "Y", n_terms),
        )
    )
    out.append(
        (
            "rod-N-series",
            "The contact force as a series of wave reflections, rigid contact; from the "
            "force balance at the struck end.",
            _typeset_series(rigid, "N", n_terms),
        )
    )
    for name, words in (("Y", "striker displacement"), ("N", "contact force")):
        out.append(
            (
                f"rod-{name}-time-terms",
                f"The {words} in time, rigid contact: the first inverted terms of its series, "
                "each switched on by the Heaviside step $H$ when its reflection arrives.",
                _typeset_time_terms(rigid, name, n_terms),
            )
        )
    return out


def latex_formulas(n_terms: int = 3) -> list[tuple[str, str, str]]:
    """Formulas of the rod analysis as ``(label, caption, latex_math_body)``.

    Every body compiles inside ``\\[ ... \\]`` with amsmath: the typeset forms of
    :func:`typeset_formulas` (eq. (1), the closed forms of :math:`W`, :math:`Y`,
    :math:`N` for rigid and finite :math:`\\kappa`, eq. (2) and the contact force
    series, and the first ``n_terms`` inverted terms, at most :data:`MAX_LATEX_TERMS`).

    Examples
    --------
    >>> labels = [label for label, _, _ in latex_formulas(2)]
    >>> labels[:2]
    ['rod-bvp', 'rod-bvp-rigid']
    """
    out = []
    for label, caption, form in typeset_formulas(n_terms):
        if isinstance(form, list):
            form = aligned(form)
        out.append((label, caption, form if isinstance(form, str) else form.latex()))
    return out
