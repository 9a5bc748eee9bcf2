"""The exact inverse Laplace transform of one rational term, :mod:`impactsym.symbolic.rational`:
known pairs, closed forms, SymPy's generic inverse, round trips through a forward transform,
and what it refuses."""

from __future__ import annotations

import pytest
import sympy as sp
from conftest import CODE
from hypothesis import given, settings
from hypothesis import strategies as st

from impactsym.symbolic.rational import LaplaceInversionError, invert_rational
from impactsym.symbolic.transform import laplace_exp_poly

s, t = sp.symbols("s t")
a, f, k = sp.symbols("a f k", positive=True)
SAMPLE = {s: sp.Rational(7, 3), a: sp.Rational(3, 5), f: sp.Rational(2, 7), k: sp.Rational(11, 3)}


def same_at_sample(lhs: sp.Expr, rhs: sp.Expr, points=(SAMPLE,)) -> bool:
    """Exact-arithmetic comparison at sample points (30-digit evaluation of a
    difference that must vanish identically)."""
    return all(abs(sp.N((lhs - rhs).subs(p), 40)) < sp.Float("1e-30") for p in points)


# ------------------------------------------------------------------ known pairs


@pytest.mark.parametrize(
    ("F", "expected"),
    [
        (1 / (s * (s + a)), (1 - sp.exp(-a * t)) / a),
        (1 / (s + 1) ** 3, t**2 * sp.exp(-t) / 2),
        (1 / (s**2 + 1) ** 2, (sp.sin(t) - t * sp.cos(t)) / 2),
        (s / (a * s**2 + 2), sp.cos(sp.sqrt(2 / a) * t) / a),
        (1 / (s**2 - 2), sp.sinh(sp.sqrt(2) * t) / sp.sqrt(2)),
        ((s + 3) / ((s + 1) ** 2 * (s**2 + 2 * s + 5)), None),
        (1 / (s**2 * (a * s + 1)), t - a + a * sp.exp(-t / a)),
    ],
)
def test_known_transform_pairs(F, expected):
    g = invert_rational(F, s, t)
    if expected is None:  # by hand, z = s + 1: 1/(4z) + 1/(2z^2) - (z/4 + 1/2)/(z^2 + 4)
        expected = sp.exp(-t) * (sp.Rational(1, 4) + t / 2 - sp.cos(2 * t) / 4 - sp.sin(2 * t) / 4)
    assert sp.simplify((g - expected).rewrite(sp.exp)) == 0


def test_improper_rational_function_gives_dirac_deltas():
    g = invert_rational(s**3 / (s + 1), s, t)
    # s**3/(s+1) = s**2 - s + 1 - 1/(s+1)
    expected = sp.DiracDelta(t, 2) - sp.DiracDelta(t, 1) + sp.DiracDelta(t) - sp.exp(-t)
    assert sp.simplify(g - expected) == 0


def test_high_order_pole_matches_laguerre_closed_form():
    # L^-1 {(s-1)^n / (s+1)^(n+1)} = exp(-t) L_n(2t): an independent closed form
    for n in (3, 12):
        g = invert_rational((s - 1) ** n / (s + 1) ** (n + 1), s, t)
        assert sp.expand(g * sp.exp(t) - sp.laguerre(n, 2 * t)) == 0


def test_agrees_with_sympy_generic_inverse_on_a_small_term():
    F = 2 * (2 * s + f) * (2 * s - 1) / (s**2 * (2 * s + 1) ** 3)
    ours = invert_rational(F, s, t)
    theirs = sp.inverse_laplace_transform(F, s, t).subs(sp.Heaviside(t), 1)
    assert sp.simplify(ours - theirs) == 0


# -------------------------------------------------------------------- round trips


@pytest.mark.parametrize(
    "F",
    [
        (a * s + f) * (a * s - 1) ** 6 / (s**2 * (a * s + 1) ** 8),
        (a * s + f) / (s * (a * s**2 + a * k * s + k) ** 3),
        2 * a * k**2 * (a * s + f) * (a * s**2 - a * k * s + k) / (a * s**2 + a * k * s + k) ** 3,
        (s**2 + 1) / (s * (s + 2) ** 2 * (s**2 + s + 1) ** 2),
        1 / (s**3 + 1),
    ],
)
def test_round_trip_forward_transform_restores_the_term(F):
    g = invert_rational(F, s, t)
    back = laplace_exp_poly(g, t, s)
    other = {s: sp.Rational(19, 4), a: sp.Rational(5, 2), f: 3, k: sp.Rational(1, 9)}
    assert same_at_sample(back, F, (SAMPLE, other))


def test_round_trip_with_sympy_forward_transform():
    F = (a * s + f) * (a * s - 1) / (s**2 * (a * s + 1) ** 3)
    g = invert_rational(F, s, t)
    back = sp.laplace_transform(g, t, s, noconds=True)
    assert sp.simplify(back - F) == 0


@settings(max_examples=25, deadline=None)
@given(
    roots=st.lists(st.integers(-4, 3), min_size=1, max_size=3),
    mults=st.lists(st.integers(1, 3), min_size=3, max_size=3),
    quadratic=st.tuples(st.integers(-3, 3), st.integers(1, 4), st.integers(0, 2)),
    numerator=st.lists(st.integers(-3, 3), min_size=1, max_size=4),
)
def test_round_trip_property(roots, mults, quadratic, numerator):
    """Random rational functions with repeated real and complex poles."""
    b, c, m2 = quadratic
    den = sp.Integer(1)
    for r, m in zip(dict.fromkeys(roots), mults, strict=False):
        den *= (s - r) ** m
    den *= (s**2 + b * s + b**2 + c) ** m2  # discriminant -3 b^2 - 4 c < 0
    num = sum(coef * s**i for i, coef in enumerate(numerator))
    F = num / den
    g = invert_rational(F, s, t)
    point = {s: sp.Rational(37, 7)}
    assert same_at_sample(laplace_exp_poly(g, t, s), F, (point,))


# ------------------------------------------------------------------------ errors


def test_rejects_non_rational_transform():
    with pytest.raises(LaplaceInversionError, match="not a rational function"):
        invert_rational(sp.exp(-s) / s, s, t)


def test_rejects_float_coefficients():
    with pytest.raises(LaplaceInversionError, match="floating-point"):
        invert_rational(1 / (s + 0.5), s, t)


def test_rejects_irreducible_cubic_factor():
    with pytest.raises(LaplaceInversionError, match="degree 3"):
        invert_rational(1 / (s**3 - 2), s, t)


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: invert_rational(CODE, s, t), "F"),
        (lambda: invert_rational(1 / s, CODE, t), "s"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name):
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()
