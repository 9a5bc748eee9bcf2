"""Division-free truncated power series, :mod:`impactsym.symbolic.series`, against SymPy's
polynomial expansion and the square root of the discriminant."""

from __future__ import annotations

import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from impactsym.symbolic.series import Quadratic, series_mul, series_pow, shifted_series, times

e = sp.Symbol("e")
ZERO, ONE = sp.Integer(0), sp.Integer(1)
coefficients = st.lists(st.integers(-5, 5), min_size=1, max_size=5)


def truncated(expr, order):
    """Coefficients of ``e**0 .. e**(order-1)`` of a polynomial in ``e`` (SymPy)."""
    poly = sp.Poly(sp.expand(expr), e)
    return [poly.coeff_monomial(e**i) for i in range(order)]


def as_poly(coeffs):
    return sum(c * e**i for i, c in enumerate(coeffs))


def padded(coeffs, order):
    return [sp.expand(c) for c in coeffs] + [ZERO] * (order - len(coeffs))


@settings(max_examples=40, deadline=None)
@given(x=coefficients, y=coefficients, order=st.integers(1, 6))
def test_series_mul_is_the_truncated_product(x, y, order):
    x, y = [sp.Integer(c) for c in x], [sp.Integer(c) for c in y]
    out = series_mul(x, y, order, ZERO)
    assert padded(out, order)[:order] == truncated(as_poly(x) * as_poly(y), order)


@settings(max_examples=40, deadline=None)
@given(x=coefficients, n=st.integers(0, 6), order=st.integers(1, 6))
def test_series_pow_is_the_truncated_power(x, n, order):
    x = [sp.Integer(c) for c in x]
    out = series_pow(x, n, order, ZERO, ONE)
    assert padded(out, order)[:order] == truncated(as_poly(x) ** n, order)


def test_series_pow_of_a_symbolic_binomial():
    a, b = sp.symbols("a b")
    out = series_pow([a, b], 5, 3, ZERO, ONE)
    assert [sp.expand(c) for c in out] == truncated((a + b * e) ** 5, 3)


@pytest.mark.parametrize("c", [ZERO, ONE, -ONE, sp.Integer(3), sp.Symbol("c")])
def test_times_shortcuts_agree_with_the_product(c):
    v = sp.Symbol("v")
    assert times(v, c, ZERO, ONE) == v * c


def test_shifted_series_is_the_scaled_polynomial_about_a_root():
    # g**d p((e + h) / g) for p = 2 s^3 - s + 5, expanded in e
    g, h = sp.symbols("g h")
    coeffs = [2, 0, -1, 5]
    s = (e + h) / g
    expected = sp.expand(g**3 * (2 * s**3 - s + 5))
    for order in (1, 2, 4):
        out = shifted_series(coeffs, h, g, order, ZERO, ONE)
        assert padded(out, order)[:order] == truncated(expected, order)


def test_quadratic_arithmetic_is_that_of_the_square_root():
    D = sp.Integer(7)
    w = sp.sqrt(D)

    def value(q):
        return q.a + q.b * w

    x, y = Quadratic(sp.Integer(2), sp.Integer(-3), D), Quadratic(sp.Integer(5), ONE, D)
    for got, want in [
        (x + y, value(x) + value(y)),
        (x - y, value(x) - value(y)),
        (x * y, value(x) * value(y)),
        (-x, -value(x)),
        (x * 4, 4 * value(x)),
        (x.conjugate(), 2 - (-3) * w),
    ]:
        assert sp.expand(value(got) - want) == 0
    assert sp.expand(x.norm() - value(x) * value(x.conjugate())) == 0
