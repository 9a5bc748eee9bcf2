"""The polynomial helpers, :mod:`impactsym.numeric.poly`, against ``numpy.polynomial``,
exact :class:`fractions.Fraction` arithmetic and mpmath."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath as mp
import numpy as np
import pytest
from numpy.polynomial import polynomial as npoly

from impactsym.numeric.poly import (
    antiderivative,
    derivative,
    exp_antiderivative,
    exp_antiderivative_at,
    horner,
    pad,
    polyval_rows,
    shift_matrix,
    taylor_shift,
    taylor_shift_list,
    trim,
)

RNG = np.random.default_rng(21)


def exact_value(c, x) -> Fraction:
    return sum((Fraction(ck) * Fraction(x) ** k for k, ck in enumerate(c)), Fraction(0))


@pytest.mark.parametrize("n", [0, 1, 2, 7, 20])
def test_horner_is_the_exact_value_to_rounding(n):
    c = RNG.normal(size=n)
    for x in (0.0, 0.37, -1.3, 2.0):
        size = float(sum(abs(Fraction(ck)) * abs(Fraction(x)) ** k for k, ck in enumerate(c)))
        exact = float(exact_value(c, x))
        assert abs(horner(c.tolist(), x) - exact) <= 2 * (n + 1) * 2.3e-16 * size
        assert horner(c, x) == horner(c.tolist(), x)
    x = np.linspace(-1.0, 2.0, 11)
    assert np.allclose(horner(c, x), npoly.polyval(x, c) if n else 0.0 * x, rtol=1e-13, atol=1e-13)
    assert horner([], 1.5) == 0.0


def test_polyval_rows_matches_numpy_row_by_row():
    C = RNG.normal(size=(4, 6))
    x = RNG.uniform(-2.0, 2.0, 4)
    got = polyval_rows(C, x)
    want = [npoly.polyval(xi, ci) for xi, ci in zip(x, C, strict=True)]
    assert np.allclose(got, want, rtol=1e-14, atol=1e-14)
    # leading axes broadcast: every row at every x
    grid = polyval_rows(C[:, None, :], np.linspace(0.0, 1.0, 5))
    assert grid.shape == (4, 5)
    assert np.allclose(grid[2], npoly.polyval(np.linspace(0.0, 1.0, 5), C[2]), rtol=1e-14)
    # complex coefficients stay complex
    Z = C + 1j * RNG.normal(size=C.shape)
    assert np.allclose(polyval_rows(Z, x), [npoly.polyval(a, z) for a, z in zip(x, Z, strict=True)])


def test_derivative_and_antiderivative_are_exact_on_integers():
    c = np.array([3.0, -1.0, 4.0, 1.0, -5.0])
    d = derivative(c)
    assert d.shape == c.shape
    assert d.tolist() == [*npoly.polyder(c).tolist(), 0.0]
    stacked = derivative(np.array([c, 2 * c]))
    assert stacked[1].tolist() == (2 * d).tolist()
    i = antiderivative(c)
    exact = [Fraction(0)] + [Fraction(ck) / (k + 1) for k, ck in enumerate(c)]
    assert i.tolist() == [float(e) for e in exact]
    assert np.allclose(i, npoly.polyint(c), rtol=0, atol=0)
    assert derivative(antiderivative(c))[:-1].tolist() == c.tolist()


def test_exp_antiderivative_is_the_exact_sum_to_rounding():
    """R_k = sum_j (k + j)!/k! Q_{k+j} (the coefficients of sum_j Q^(j), in 50-digit
    mpmath) to a few roundings of the terms' size, and int_0^x e^-s Q = R(0) - e^-x R(x)
    (mpmath quadrature)."""
    rng = np.random.default_rng(11)
    for n in [0, 1, 2, 5, 9, 10, 11, 17, 30, 60]:
        Q = rng.normal(size=n) * 3.0 ** rng.uniform(-3, 3, n) * (-2.0) ** np.arange(n)
        R = exp_antiderivative(Q.tolist())
        assert len(R) == n
        with mp.workdps(50):
            for k in range(n):
                terms = [
                    mp.factorial(k + j) / mp.factorial(k) * mp.mpf(Q[k + j]) for j in range(n - k)
                ]
                size = float(sum(abs(t) for t in terms))
                assert abs(R[k] - float(mp.fsum(terms))) <= 4 * (n - k) * 2.3e-16 * size
        if n:
            x = 1.3
            exact = mp.quad(lambda s, Q=Q: mp.exp(-s) * mp.polyval(Q[::-1].tolist(), s), [0, x])
            closed = R[0] - math.exp(-x) * horner(R, x)
            assert closed == pytest.approx(float(exact), rel=1e-12, abs=1e-12 * np.abs(R).max())


def test_exp_antiderivative_at_is_horner_of_exp_antiderivative_bit_for_bit():
    """The one-pass values Q(x), R(0), R(x) equal horner(Q, x), R[0], horner(R, x) of
    the list exp_antiderivative(Q) exactly (what lets the rod's contact use them with
    bit-identical results), from the empty list to 40 coefficients, and Q(x), R(x)
    agree with exact rational sums."""
    rng = np.random.default_rng(5)
    assert exp_antiderivative_at([], 0.7) == (0.0, 0.0, 0.0)
    for n in [1, 2, 3, 8, 15, 40]:
        for _ in range(50):
            Q = (rng.normal(size=n) * 10.0 ** rng.uniform(-6, 6, n)).tolist()
            x = float(rng.choice([0.0, 2.0, rng.uniform(0.0, 2.0)]))
            R = exp_antiderivative(Q)
            assert exp_antiderivative_at(Q, x) == (horner(Q, x), R[0], horner(R, x))
        value, _, r_x = exp_antiderivative_at(Q, x)
        size = float(exact_value(np.abs(Q), abs(x)))
        assert abs(value - float(exact_value(Q, x))) <= 4 * n * 2.3e-16 * size
        r_size = float(exact_value(np.abs(R), abs(x)))
        assert abs(r_x - float(exact_value(R, x))) <= 4 * n * 2.3e-16 * r_size


def test_pad_and_trim():
    c = np.array([[1.0, 2.0]])
    assert pad(c, 4).tolist() == [[1.0, 2.0, 0.0, 0.0]]
    assert pad(c, 1) is c
    assert trim([1.0, 0.0, 2.0, 0.0]).tolist() == [1.0, 0.0, 2.0]
    assert trim([0.0, 0.0]).size == 0
    assert trim([]).size == 0
    kept = np.array([1.0, 2.0])
    assert trim(kept) is kept


def test_taylor_shift_is_exact_in_fractions():
    """c(x + u) with small integers and a dyadic u: every coefficient exact."""
    c = [3.0, -2.0, 0.0, 5.0, 1.0, -7.0]
    u = 0.75
    got = taylor_shift(np.array(c), u)
    exact = [
        sum(math.comb(k, i) * Fraction(c[k]) * Fraction(u) ** (k - i) for k in range(i, len(c)))
        for i in range(len(c))
    ]
    assert got.tolist() == [float(e) for e in exact]
    for x in (Fraction(1, 3), Fraction(-5, 4)):
        assert exact_value([float(e) for e in exact], x) == exact_value(c, x + Fraction(u))
    assert taylor_shift(np.array([2.0]), 9.0).tolist() == [2.0]
    assert np.array_equal(shift_matrix(4, 0.0), np.eye(4))


def test_taylor_shift_matches_numpy_composition_and_refuses_high_degree():
    c = RNG.normal(size=12)
    u = -0.6
    want = np.polynomial.Polynomial(c)(np.polynomial.Polynomial([u, 1.0])).coef  # c(x + u)
    assert np.allclose(taylor_shift(c, u), want, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="degree 96 exceeds 95"):
        shift_matrix(97, 0.5)


@pytest.mark.parametrize("n", [1, 2, 5, 11, 16, 17, 24])
def test_taylor_shift_list_is_the_exact_shift_to_rounding(n):
    """The event loop's list form (synthetic division up to 16 coefficients, the matrix
    beyond) against exact Fraction arithmetic: each coefficient within 8n ulps of the
    sum of the magnitudes of its terms, for shifts of either sign."""
    for u in (0.37, -1.3, 2.0 / 3.0):
        c = (RNG.normal(size=n) * RNG.uniform(0.0, 3.0, size=n)).tolist()
        got = taylor_shift_list(c, u)
        assert isinstance(got, list)
        assert len(got) == n
        for i in range(n):
            terms = [math.comb(k, i) * Fraction(c[k]) * Fraction(u) ** (k - i) for k in range(i, n)]
            size = float(sum(abs(t) for t in terms))
            assert abs(Fraction(got[i]) - sum(terms)) <= 8 * n * np.finfo(float).eps * size
    assert taylor_shift_list([], 0.5) == []
    assert taylor_shift_list([0.0, 0.0, 1.0], 2.0) == [4.0, 4.0, 1.0]
