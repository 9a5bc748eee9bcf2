r"""Exact inverse Laplace transform of a rational function from its partial fractions.

:func:`invert_rational` inverts each term :math:`F_k(s)` of a delay series (paper
section 1, eq. (2)): at a pole :math:`a` of order :math:`m` the Laurent coefficients come
from division-free truncated power series (:mod:`impactsym.symbolic.series`) in the
polynomial ring of the coefficients, so that no symbolic ``series`` or generic
``inverse_laplace_transform`` is ever called; the two roots of an irreducible quadratic
factor are inverted together into :math:`e^{\sigma t}(\cosh, \sinh)` form. Anything
that cannot be done exactly raises :class:`LaplaceInversionError`
(``docs/physics.md``, "Delay series and their exact inversion").
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import sympy as sp

from impactsym.symbolic.series import Quadratic, series_mul, series_pow, shifted_series, times
from impactsym.validation import as_sympy

__all__ = ["LaplaceInversionError", "invert_rational"]


class LaplaceInversionError(ValueError):
    """A term the engine cannot invert exactly, or a delay not provably non-negative."""


def check_symbols(**symbols: Any) -> None:
    """Internal: the transform and time variables must be SymPy symbols (never strings).

    Used by :func:`invert_rational` and :func:`impactsym.symbolic.transform.laplace_exp_poly`.
    """
    for name, value in symbols.items():
        if not isinstance(value, sp.Symbol):
            raise TypeError(f"{name} must be a SymPy Symbol, got {value!r}")


def _rational_parts(F: sp.Expr, s: sp.Symbol) -> tuple[Any, list, sp.Expr, list]:
    """Split ``F`` into ``numerator * constant / prod(factor**multiplicity)``.

    Returns the common coefficient domain, the numerator as ``(polynomial, power)``
    factors, the constant (free of ``s``) and the distinct irreducible denominator
    factors (as normalized by ``factor_list``) with multiplicities, all polynomials in
    ``s`` over that domain. A product of powers is taken apart without expanding it.
    """
    if not F.is_rational_function(s):
        raise LaplaceInversionError(
            f"transform is not a rational function of {s}: {F} (split delays "
            "exp(-T*s) off into the delay of the term)"
        )
    factors = _power_factors(F, s)
    if factors is None:
        factors = _power_factors(sp.cancel(sp.together(F)), s)
    if factors is None:  # pragma: no cover - cancel always yields polynomial factors
        raise LaplaceInversionError(f"cannot split {F} into polynomial factors in {s}")
    constant, parts = factors
    polys = [_poly(b, s) for b, _, _ in parts]
    domain = polys[0].domain if polys else sp.ZZ
    for p in polys[1:]:
        domain = domain.unify(p.domain)
    if not domain.is_Exact:
        raise LaplaceInversionError(
            f"transform {F} has floating-point coefficients; use exact numbers "
            "(sympy.Rational) so that poles and their orders are exact"
        )
    numerator: list[tuple[sp.Poly, int]] = []
    den_factors: list[list] = []
    for base, exponent, in_den in parts:
        poly = _poly(base, s, domain)
        if not in_den:
            numerator.append((poly, exponent))
            continue
        lead, irreducible = _factor_list(poly)
        constant = constant / lead**exponent
        for fac, mult in irreducible:
            if fac.degree() == 0:  # pragma: no cover - factor_list puts these in lead
                constant = constant / fac.as_expr() ** (mult * exponent)
                continue
            for entry in den_factors:
                if entry[0] == fac:
                    entry[1] += mult * exponent
                    break
            else:
                den_factors.append([fac, mult * exponent])
    return domain, numerator, constant, [(p, m) for p, m in den_factors]


@lru_cache(maxsize=4096)
def _poly(base: sp.Expr, s: sp.Symbol, domain: Any = None) -> sp.Poly:
    """``base`` as a polynomial in ``s`` (memoized: series terms share their bases)."""
    return sp.Poly(base, s) if domain is None else sp.Poly(base, s, domain=domain)


@lru_cache(maxsize=4096)
def _factor_list(poly: sp.Poly) -> tuple:
    return poly.factor_list()


def _power_factors(F: sp.Expr, s: sp.Symbol) -> tuple[sp.Expr, list] | None:
    """``F`` as ``constant * prod(base**(+-exponent))`` with bases polynomial in ``s``,
    or ``None`` if ``F`` is not already such a product."""
    numer, denom = sp.fraction(F)
    constant = sp.Integer(1)
    parts = []
    for part, in_den in ((numer, False), (denom, True)):
        for factor in sp.Mul.make_args(part):
            if not factor.has(s):
                constant = constant / factor if in_den else constant * factor
                continue
            base, exponent = factor.as_base_exp()
            if not (exponent.is_Integer and exponent > 0 and base.is_polynomial(s)):
                return None
            parts.append((base, int(exponent), in_den))
    return constant, parts


def _pole_terms(
    domain: Any,
    numerator: list,
    factors: list,
    index: int,
    t: sp.Symbol,
    constant: Any,
) -> sp.Expr:
    """Inverse transform of the principal parts at the roots of ``factors[index]``.

    With :math:`e = g (s - a)` for the root :math:`a = -h/g` of the factor,
    :math:`F = e^{-m} \\tilde N(e) / \\tilde R(e)` times :math:`g^E`, and the
    principal part gives :math:`e^{a t} \\sum_j g^{E + j - m} c_j\\,
    t^{m-1-j} / (m-1-j)!` with :math:`c_j` the Taylor coefficients of
    :math:`\\tilde N / \\tilde R`, computed division-free (a common denominator
    :math:`r_0^{j+1}` is kept aside).
    """
    K = domain
    zero, one = K.zero, K.one
    fac, m = factors[index]
    coeffs = fac.rep.to_list()
    degree = len(coeffs) - 1
    if degree == 1:
        c1, c0 = coeffs
        g, h = c1, -c0
        w = None
        z, u = zero, one
    elif degree == 2:
        c2, c1, c0 = coeffs
        D = c1 * c1 - 4 * c2 * c0
        g = Quadratic(2 * c2, zero, D)
        h = Quadratic(-c1, one, D)  # root a+ = (w - c1) / (2 c2)
        w = D
        z, u = Quadratic(zero, zero, D), Quadratic(one, zero, D)
    else:
        raise LaplaceInversionError(
            f"denominator factor {fac.as_expr()} is irreducible of degree {degree} over "
            f"{K}; only linear and quadratic factors are inverted exactly"
        )
    order = m
    # numerator and the other factors in the shifted variable e (times powers of g)
    num, exponent = [u], 0
    for base, power in numerator:
        shifted = shifted_series(base.rep.to_list(), h, g, order, z, u)
        num = series_mul(num, series_pow(shifted, power, order, z, u), order, z)
        exponent -= base.degree() * power
    rest = [u]
    for k, (other, mult) in enumerate(factors):
        exponent += other.degree() * mult
        if k == index:  # g**d * factor = c * e * phi(e): keep phi, fold c**(-m) into g
            shifted = [u] if w is None else [Quadratic(zero, 2 * one, D), u]
            exponent -= mult
        else:
            shifted = shifted_series(other.rep.to_list(), h, g, order, z, u)
        rest = series_mul(rest, series_pow(shifted, mult, order, z, u), order, z)
    rest = rest + [z] * (order - len(rest))
    num = num + [z] * (order - len(num))
    # C_j = c_j r0**(j+1) for the Taylor coefficients c_j of num / rest, by the
    # recurrence C_j = num_j r0**j - sum_i rest_i C_(j-i) r0**(i-1) (zeros skipped)
    r0 = rest[0]
    r0pow = [u]
    for _ in range(order):
        r0pow.append(times(r0pow[-1], r0, z, u))
    nonzero = [(i, r) for i, r in enumerate(rest) if i and r != z]
    scaled = []
    for j in range(order):
        acc = times(num[j], r0pow[j], z, u)
        for i, r in nonzero:
            if i > j:
                break
            acc = acc - times(r * scaled[j - i], r0pow[i - 1], z, u)
        scaled.append(acc)
    # denominators: r0 (linear) or its norm (quadratic), as a product of atoms
    atoms = []  # r0 (linear) or its norm (quadratic) is the product of these
    for k, (other, mult) in enumerate(factors):
        if k == index:
            if w is not None:  # phi(0) = 2 w, norm -4 D
                atoms.append((-4 * D, mult))
            continue
        atom = shifted_series(other.rep.to_list(), h, g, 1, z, u)[0]
        atoms.append((atom if w is None else atom.norm(), mult))
    rational = _Rationals(K, constant, atoms, exact_cancel=w is not None)
    if w is None:
        a = sp.together(K.to_sympy(h) / K.to_sympy(g))
        terms = []
        for j in range(order):
            k = m - 1 - j
            coeff = rational.expr(scaled[j], j + 1, math.factorial(k), g, exponent + j - m)
            terms.append(coeff * t**k)
        return sp.exp(a * t) * sp.Add(*terms)
    # quadratic: rationalize r0 and split X + Y w
    conj = r0.conjugate()
    c2e, c1e = K.to_sympy(coeffs[0]), K.to_sympy(coeffs[1])
    root = sp.sqrt(K.to_sympy(w))
    terms_c, terms_s = [], []
    conj_pow = u
    for j in range(order):
        conj_pow = conj_pow * conj
        value = scaled[j] * conj_pow
        k = m - 1 - j
        for part, out in ((value.a, terms_c), (value.b, terms_s)):
            # c2**(-m) = 2**m g**(-m): the power of g is in exponent, 2**m here
            coeff = rational.expr(
                2 ** (m + 1) * part, j + 1, math.factorial(k), g.a, exponent + j - m
            )
            out.append(coeff * t**k)
    sigma = sp.together(-c1e / (2 * c2e))
    arg = root * t / (2 * c2e)
    return sp.exp(sigma * t) * (
        sp.Add(*terms_c) * sp.cosh(arg) + sp.Add(*terms_s) * root * sp.sinh(arg)
    )


class _Rationals:
    """Build reduced coefficients ``constant * x * g**p / (atoms**n * integer)``.

    With ``exact_cancel`` over a polynomial ring, common factors are cancelled by
    trial division by the irreducible factors of the atoms instead of a
    multivariate gcd per coefficient (which dominates the cost for symbolic
    quadratic poles); otherwise the fraction-field arithmetic is used directly
    (fast when the denominators are monomials, as for linear poles here).
    """

    def __init__(self, K: Any, constant: Any, atoms: list, *, exact_cancel: bool) -> None:
        self.K, self.field = K, K.get_field()
        self.constant = constant
        self.atoms = atoms
        self.poly_ring = exact_cancel and bool(getattr(K, "is_PolynomialRing", False))
        if self.poly_ring:
            self.ground = K.dom
            self.cnum, self.cden = K.convert(constant.numer), K.convert(constant.denom)
            self.primes: dict[Any, int] = {}
            self.unit = self.ground.one
            for atom, mult in atoms:
                self._add(self.primes, K.convert(atom), mult)
            self.cden_primes: dict[Any, int] = {}
            self.cden_unit = self._add(self.cden_primes, self.cden, 1)

    def _add(self, primes: dict, value: Any, mult: int) -> Any:
        content, factors = value.factor_list()
        for p, e in factors:
            primes[p] = primes.get(p, 0) + e * mult
        if primes is getattr(self, "primes", None):
            self.unit = self.unit * content**mult
        return content

    def _factor(self, g: Any) -> tuple:
        if getattr(self, "_g", None) != g:
            self._g, self._g_factors = g, self.K.convert(g).factor_list()
        return self._g_factors

    def expr(self, x: Any, n: int, integer: int, g: Any = None, power: int = 0) -> sp.Expr:
        K, field = self.K, self.field
        if not self.poly_ring and getattr(K, "is_PolynomialRing", False):
            # one fraction: numerator and denominator built in the ring, cancelled once
            num = K.convert(self.constant.numer) * K.convert(x)
            den = K.convert(self.constant.denom) * integer
            for atom, mult in self.atoms:
                den = den * K.convert(atom) ** (mult * n)
            if g is not None and power > 0:
                num = num * K.convert(g) ** power
            elif g is not None and power < 0:
                den = den * K.convert(g) ** (-power)
            return field.to_sympy(field.convert(num) / field.convert(den))
        if not self.poly_ring:
            value = self.constant * field.convert(x) / integer
            for atom, mult in self.atoms:
                value = value / field.convert(atom) ** (mult * n)
            if g is not None:
                value = value * _field_pow(field.convert(g), power)
            return field.to_sympy(value)
        ground = self.ground
        num = self.cnum * K.convert(x)
        den = {p: e * n for p, e in self.primes.items()}
        for p, e in self.cden_primes.items():
            den[p] = den.get(p, 0) + e
        den_int = self.unit**n * self.cden_unit * integer
        if g is not None and power:
            content, factors = self._factor(g)
            if power > 0:
                num = num.mul_ground(content**power)
            else:
                den_int = den_int * content ** (-power)
            for p, e in factors:
                den[p] = den.get(p, 0) - e * power
        for p, e in list(den.items()):
            if e < 0:  # more of p above than below
                num, den[p] = num * p ** (-e), 0
                continue
            generator = p.is_generator
            while den[p] and num:
                if generator:  # divide by the largest power of a variable at once
                    i = p.ring.gens.index(p)
                    k = min(den[p], min(monom[i] for monom in num.itermonoms()))
                    if k == 0:
                        break
                    num, den[p] = num.exquo(p**k), den[p] - k
                    continue
                quotient, remainder = divmod(num, p)
                if remainder:
                    break
                num, den[p] = quotient, den[p] - 1
        if ground.is_Field:
            num, den_int = num.quo_ground(den_int), ground.one
        elif num:
            common = ground.gcd(num.content(), den_int)
            num, den_int = num.quo_ground(common), ground.quo(den_int, common)
        expr = K.to_sympy(num) / ground.to_sympy(den_int)
        for p, e in den.items():
            if e:
                expr = expr / K.to_sympy(p) ** e
        return expr


def _field_pow(x: Any, n: int) -> Any:
    return x**n if n >= 0 else 1 / x ** (-n)


def invert_rational(F: Any, s: sp.Symbol, t: sp.Symbol) -> sp.Expr:
    """Exact inverse Laplace transform of a rational function of ``s``.

    Every pole :math:`a` of order :math:`m` contributes

    .. math::

        e^{a t} \\sum_{i=1}^{m} A_{i} \\frac{t^{i-1}}{(i-1)!},
        \\qquad F(s) = \\frac{A_m}{(s-a)^m} + \\dots + \\frac{A_1}{s-a} + \\text{regular},

    a polynomial part :math:`\\sum_n q_n s^n` gives :math:`\\sum_n q_n \\delta^{(n)}(t)`,
    and the two roots :math:`\\sigma \\pm \\omega` of an irreducible quadratic factor
    are inverted together as :math:`e^{\\sigma t}(P(t)\\cosh \\omega t + Q(t)\\,
    \\omega \\sinh \\omega t)` (real for real and for complex roots).

    Parameters
    ----------
    F
        Rational function of ``s``; other symbols are coefficients.
    s, t
        Transform and time variables.

    Returns
    -------
    sympy.Expr
        :math:`f(t)` for :math:`t > 0`.

    Raises
    ------
    LaplaceInversionError
        If ``F`` is not rational in ``s``, has floating-point coefficients, or has
        an irreducible denominator factor of degree above two.

    Examples
    --------
    >>> s, t, a = sp.symbols("s t a", positive=True)
    >>> invert_rational(1 / (s * (s + a)), s, t)
    1/a - exp(-a*t)/a
    >>> invert_rational(1 / (s**2 + 1) ** 2, s, t)
    -t*cos(t)/2 + sin(t)/2
    """
    F = as_sympy("F", F)
    check_symbols(s=s, t=t)
    if F.is_zero:
        return sp.Integer(0)
    domain, numerator, constant, factors = _rational_parts(F, s)
    field = domain.get_field()
    try:  # fold the constant into the coefficients if it lies in their field
        inner, outer = field.from_sympy(constant), sp.Integer(1)
    except sp.polys.polyerrors.CoercionFailed:
        inner, outer = field.one, constant
    terms = []
    total = sum(p.degree() * m for p, m in factors)
    if sum(p.degree() * m for p, m in numerator) >= total:
        den = num = sp.Poly(1, s, domain=domain)
        for p, m in factors:
            den = den * p**m
        for p, m in numerator:
            num = num * p**m
        quotient = num.to_field().div(den.to_field())[0]
        for (n,), c in quotient.terms():
            terms.append(constant * c * (sp.DiracDelta(t, n) if n else sp.DiracDelta(t)))
    for index in range(len(factors)):
        terms.append(outer * _pole_terms(domain, numerator, factors, index, t, inner))
    return sp.Add(*terms)
