"""Delay series and their exact, term-by-term inverse Laplace transform.

A *delay series* is an explicit list of ``(delay, transform)`` pairs: the quantity is

.. math::

    X(s) = \\sum_k F_k(s)\\, e^{-T_k s},
    \\qquad
    x(t) = \\sum_k f_k(t - T_k)\\, \\mathrm{H}(t - T_k),

where every :math:`F_k` is a rational function of :math:`s` (symbolic coefficients
allowed) and :math:`f_k = \\mathcal{L}^{-1}\\{F_k\\}`. The engine splits nothing out of
a SymPy ``Add``: the caller hands it the terms, and it

* checks that every delay :math:`T_k` is provably non-negative,
* inverts every :math:`F_k` exactly from its partial fractions: at a pole :math:`a` of
  order :math:`m` the Laurent coefficients come from a division-free truncated power
  series in the polynomial ring of the coefficients, so that no symbolic ``series``
  or generic ``inverse_laplace_transform`` is ever called, and a pair of complex
  (or irrational) conjugate poles of an irreducible quadratic factor is inverted
  together into :math:`e^{\\sigma t}(\\cosh, \\sinh)` form,
* raises :class:`LaplaceInversionError` for anything it cannot do exactly.

:func:`laplace_exp_poly` is the forward transform of the results (sums of
:math:`t^n e^{a t}` times trigonometric or hyperbolic functions, and Dirac deltas), used
for round-trip checks.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import lru_cache
from itertools import product
from typing import Any

import sympy as sp

from impactsym.validation import as_sympy, reject_strings

DelayTerm = tuple[sp.Expr, sp.Expr]
"""``(delay, delay-free transform)``: one term :math:`F(s)e^{-Ts}` of a delay series."""

__all__ = [
    "DelayTerm",
    "LaplaceInversionError",
    "check_delay",
    "geometric_delay_series",
    "invert_delay_series",
    "invert_rational",
    "laplace_exp_poly",
    "time_function",
]


class LaplaceInversionError(ValueError):
    """A term the engine cannot invert exactly, or a delay not provably non-negative."""


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
    impactsym.symbolic.laplace.LaplaceInversionError: delay 2 - xi is not provably non-negative
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


# ------------------------------------------------------------- rational inversion


class _Quadratic:
    """Element ``a + b w`` of ``K[w] / (w**2 - D)`` for a ring ``K``: exact arithmetic
    with the square root of a discriminant, without any division."""

    __slots__ = ("D", "a", "b")

    def __init__(self, a: Any, b: Any, D: Any) -> None:
        self.a, self.b, self.D = a, b, D

    def _lift(self, other: Any) -> _Quadratic:
        if isinstance(other, _Quadratic):
            return other
        return _Quadratic(other, self.D * 0, self.D)

    def __add__(self, other: Any) -> _Quadratic:
        o = self._lift(other)
        return _Quadratic(self.a + o.a, self.b + o.b, self.D)

    __radd__ = __add__

    def __sub__(self, other: Any) -> _Quadratic:
        o = self._lift(other)
        return _Quadratic(self.a - o.a, self.b - o.b, self.D)

    def __neg__(self) -> _Quadratic:
        return _Quadratic(-self.a, -self.b, self.D)

    def __mul__(self, other: Any) -> _Quadratic:
        o = self._lift(other)
        return _Quadratic(self.a * o.a + self.b * o.b * self.D, self.a * o.b + self.b * o.a, self.D)

    __rmul__ = __mul__

    def conjugate(self) -> _Quadratic:
        return _Quadratic(self.a, -self.b, self.D)

    def norm(self) -> Any:
        return self.a * self.a - self.b * self.b * self.D


def _series_mul(x: list, y: list, order: int, zero: Any) -> list:
    """Product of two truncated power series (coefficient lists) modulo ``e**order``."""
    out = [zero] * min(order, len(x) + len(y) - 1)
    for i, xi in enumerate(x[:order]):
        for j, yj in enumerate(y[: order - i]):
            out[i + j] = out[i + j] + xi * yj
    return out


def _series_pow(x: list, n: int, order: int, zero: Any, one: Any) -> list:
    """``x**n`` modulo ``e**order`` (binomial formula for two-term series)."""
    if len(x) == 2:
        a, b = x
        if n == 0:
            return [one]
        apow = [one]
        for _ in range(n):
            apow.append(_times(apow[-1], a, zero, one))
        out, bpow = [], one
        for i in range(min(n, order - 1) + 1):
            out.append(_times(bpow * math.comb(n, i), apow[n - i], zero, one))
            bpow = _times(bpow, b, zero, one)
        return out
    result = [one]
    base = x[:order]
    while n:
        if n & 1:
            result = _series_mul(result, base, order, zero)
        n >>= 1
        if n:
            base = _series_mul(base, base, order, zero)
    return result


def _times(v: Any, c: Any, zero: Any, one: Any) -> Any:
    """``v * c`` with shortcuts for ``c`` in ``{0, 1, -1}`` (common shifts)."""
    if c == zero:
        return zero
    if c == one:
        return v
    if c == -one:
        return -v
    return v * c


def _shifted(coeffs: list, h: Any, g: Any, order: int, zero: Any, one: Any) -> list:
    """Coefficients in ``e`` of ``g**d * p((e + h) / g)`` modulo ``e**order`` (Horner),
    where ``coeffs`` lists ``p`` from the leading coefficient down, ``d = deg p``."""
    d = len(coeffs) - 1
    gpow = [one]
    for _ in range(d):
        gpow.append(_times(gpow[-1], g, zero, one))
    out = [one * coeffs[0]]
    for i, c in enumerate(coeffs[1:], start=1):
        nxt = [zero] * min(order, len(out) + 1)
        for k, v in enumerate(out):
            if k < order:
                nxt[k] = nxt[k] + _times(v, h, zero, one)
            if k + 1 < order:
                nxt[k + 1] = nxt[k + 1] + v
        if c != 0:
            nxt[0] = nxt[0] + _times(one * c, gpow[i], zero, one)
        out = nxt
    return out


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
        g = _Quadratic(2 * c2, zero, D)
        h = _Quadratic(-c1, one, D)  # root a+ = (w - c1) / (2 c2)
        w = D
        z, u = _Quadratic(zero, zero, D), _Quadratic(one, zero, D)
    else:
        raise LaplaceInversionError(
            f"denominator factor {fac.as_expr()} is irreducible of degree {degree} over "
            f"{K}; only linear and quadratic factors are inverted exactly"
        )
    order = m
    # numerator and the other factors in the shifted variable e (times powers of g)
    num, exponent = [u], 0
    for base, power in numerator:
        shifted = _shifted(base.rep.to_list(), h, g, order, z, u)
        num = _series_mul(num, _series_pow(shifted, power, order, z, u), order, z)
        exponent -= base.degree() * power
    rest = [u]
    for k, (other, mult) in enumerate(factors):
        exponent += other.degree() * mult
        if k == index:  # g**d * factor = c * e * phi(e): keep phi, fold c**(-m) into g
            shifted = [u] if w is None else [_Quadratic(zero, 2 * one, D), u]
            exponent -= mult
        else:
            shifted = _shifted(other.rep.to_list(), h, g, order, z, u)
        rest = _series_mul(rest, _series_pow(shifted, mult, order, z, u), order, z)
    rest = rest + [z] * (order - len(rest))
    num = num + [z] * (order - len(num))
    # C_j = c_j r0**(j+1) for the Taylor coefficients c_j of num / rest, by the
    # recurrence C_j = num_j r0**j - sum_i rest_i C_(j-i) r0**(i-1) (zeros skipped)
    r0 = rest[0]
    r0pow = [u]
    for _ in range(order):
        r0pow.append(_times(r0pow[-1], r0, z, u))
    nonzero = [(i, r) for i, r in enumerate(rest) if i and r != z]
    scaled = []
    for j in range(order):
        acc = _times(num[j], r0pow[j], z, u)
        for i, r in nonzero:
            if i > j:
                break
            acc = acc - _times(r * scaled[j - i], r0pow[i - 1], z, u)
        scaled.append(acc)
    # denominators: r0 (linear) or its norm (quadratic), as a product of atoms
    atoms = []  # r0 (linear) or its norm (quadratic) is the product of these
    for k, (other, mult) in enumerate(factors):
        if k == index:
            if w is not None:  # phi(0) = 2 w, norm -4 D
                atoms.append((-4 * D, mult))
            continue
        atom = _shifted(other.rep.to_list(), h, g, 1, z, u)[0]
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
    _check_symbols(s=s, t=t)
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


# --------------------------------------------------------------- forward transform


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
    _check_symbols(t=t, s=s)
    total = []
    for coeff, n, rate, delta in _exp_poly_terms(as_sympy("g", g), t):
        if delta is not None:
            total.append(coeff * s**delta)
        else:
            total.append(coeff * math.factorial(n) / (s - rate) ** (n + 1))
    return sp.Add(*total)


def _check_symbols(**symbols: Any) -> None:
    """The transform and time variables must be SymPy symbols (never strings)."""
    for name, value in symbols.items():
        if not isinstance(value, sp.Symbol):
            raise TypeError(f"{name} must be a SymPy Symbol, got {value!r}")


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
