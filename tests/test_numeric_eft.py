"""Error-free transformations against exact rational arithmetic (``fractions.Fraction``)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from impactsym.numeric.eft import sum_with_bound, two_prod, two_sum

# magnitudes where neither the products nor their error terms under- or overflow
moderate = st.floats(min_value=-1e100, max_value=1e100, allow_nan=False).filter(
    lambda x: x == 0.0 or abs(x) > 1e-100
)


@given(moderate, moderate)
@example(1.0, 1e-17)
@example(1e16, -1e16 + 2.0)
def test_two_sum_is_exact(a, b):
    s, e = two_sum(np.array([a]), np.array([b]))
    assert s[0] == a + b
    assert Fraction(s[0]) + Fraction(e[0]) == Fraction(a) + Fraction(b)


@given(moderate, moderate)
@example(1.0 + 2.0**-52, 1.0 - 2.0**-52)
@example(134217729.0, 134217727.0)
def test_two_prod_is_exact(a, b):
    p, e = two_prod(np.array([a]), np.array([b]))
    assert p[0] == a * b
    assert Fraction(p[0]) + Fraction(e[0]) == Fraction(a) * Fraction(b)


@settings(max_examples=200)
@given(st.lists(moderate, min_size=1, max_size=12))
@example([1e16, 1.0, -1e16, 1e-16])  # total cancellation of the large terms
@example([0.1] * 10 + [-1.0])
def test_sum_with_bound_contains_the_exact_sum(values):
    terms = [np.array([v]) for v in values]
    total, bound = sum_with_bound(terms)
    exact = sum((Fraction(v) for v in values), Fraction(0))
    assert abs(Fraction(total[0]) - exact) <= Fraction(bound[0])


def test_sum_with_bound_is_tight_where_the_terms_cancel():
    # the plain float sum loses everything here; the cascaded sum is exact to u^2
    terms = [np.array([1e16]), np.array([3.0]), np.array([-1e16]), np.array([2.0**-30])]
    total, bound = sum_with_bound(terms)
    assert total[0] == 3.0 + 2.0**-30
    # u |s| + gamma_3^2 sum |t| = 3e-16 + 2e-31 * 2e16: far below the plain sum's error
    assert bound[0] < 2e-14
    assert total[0] != (1e16 + 3.0 - 1e16) + 2.0**-30


def test_sum_with_bound_refuses_no_terms():
    with pytest.raises(ValueError, match="at least one term"):
        sum_with_bound([])
