"""Delay series and their term-by-term inversion, :mod:`impactsym.symbolic.laplace`:
Heaviside shifts, the geometric expansion of a quotient of delay polynomials, and the
delays it refuses."""

from __future__ import annotations

import pytest
import sympy as sp
from conftest import CODE

from impactsym.symbolic.laplace import (
    LaplaceInversionError,
    check_delay,
    geometric_delay_series,
    invert_delay_series,
    invert_rational,
    laplace_exp_poly,
    time_function,
)

s, t = sp.symbols("s t")
x = sp.Symbol("x")


def test_former_names_stay_importable_from_laplace():
    from impactsym.symbolic import rational, transform

    assert invert_rational is rational.invert_rational
    assert laplace_exp_poly is transform.laplace_exp_poly
    assert LaplaceInversionError is rational.LaplaceInversionError


# ------------------------------------------------------------------ delay series


def test_invert_delay_series_shifts_by_heaviside():
    terms = invert_delay_series([(0, 1 / s), (2, -2 / (s + 1))], s, t)
    assert terms == [(0, 1), (2, -2 * sp.exp(-t))]
    x = time_function(terms, t)
    assert x.subs(t, 1) == 1
    assert x.subs(t, 2) == -1  # right-continuous: the term counts from its arrival
    assert sp.simplify(x.subs(t, 3) - (1 - 2 * sp.exp(-1))) == 0


def test_geometric_delay_series_merges_delays_of_one_class():
    # (1 - D^2) / (1 + q D^2) with q = -1/(s+1): coefficients of D^(2j)
    q = 1 / (s + 1)
    terms = geometric_delay_series([(0, 1), (2, -1)], 1, -q, 2, 4)
    assert [d for d, _ in terms] == [0, 2, 4, 6]
    for j, (_, c) in enumerate(terms[1:], start=1):
        assert sp.simplify(c - (q**j - q ** (j - 1))) == 0


def test_geometric_delay_series_keeps_incommensurate_delays_apart():
    xi = sp.Symbol("xi", positive=True)
    terms = geometric_delay_series([(xi, 1), (2 - xi, -1)], 1, -sp.Rational(1, 2), 2, 4)
    assert [d for d, _ in terms] == [xi, 2 - xi, xi + 2, 4 - xi]


# ------------------------------------------------------------------------ errors


@pytest.mark.parametrize("delay", [-1, sp.Symbol("T"), sp.oo, 2 - sp.Symbol("xi", positive=True)])
def test_rejects_delays_not_provably_non_negative(delay):
    with pytest.raises(LaplaceInversionError, match="delay"):
        invert_delay_series([(delay, 1 / s)], s, t)


def test_accepts_delay_non_negative_on_a_box():
    xi = sp.Symbol("xi", nonnegative=True)
    assert check_delay(2 - xi, {xi: (0, 1)}) == 2 - xi
    with pytest.raises(LaplaceInversionError):
        check_delay(1 - 2 * xi, {xi: (0, 1)})
    with pytest.raises(LaplaceInversionError):
        check_delay(1 - xi**2 - xi, {xi: (0, 1)})  # not multilinear: not decided


def test_geometric_delay_series_validates_arguments():
    with pytest.raises(ValueError, match="n_terms"):
        geometric_delay_series([(0, 1)], 1, 1, 2, -1)
    with pytest.raises(ValueError, match="period"):
        geometric_delay_series([(0, 1)], 1, 1, 0, 2)


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: check_delay(CODE), "delay"),
        (lambda: check_delay(2 - x, {x: (0, CODE)}), "bounds"),
        (lambda: geometric_delay_series([(0, CODE)], 1, -1 / (s + 1), 2, 3), "numerator"),
        (lambda: geometric_delay_series([(0, 1)], 1, CODE, 2, 3), "bp"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()
