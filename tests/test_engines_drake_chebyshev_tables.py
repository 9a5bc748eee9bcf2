"""The two-variable Chebyshev tables of the Drake change tables, against what did not
make them: the functions they were fitted to, and SciPy's brentq on the largest of two
tables for the phase where it meets a target."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import chebyshev
from scipy.optimize import brentq

from impactsym.contact.lawtable import chebyshev_points
from impactsym.engines.drake import chebyshev_tables as tables

RNG = np.random.default_rng(39)


def _grid(f, n1=16, n2=10):
    x, y = np.meshgrid(chebyshev_points(n1), chebyshev_points(n2), indexing="ij")
    return np.stack([f(x, y)]) if not isinstance(f, tuple) else np.stack([g(x, y) for g in f])


def test_a_smooth_table_holds_its_function_and_the_box_maps_back():
    f = (lambda x, y: 1.0 + 0.3 * x + 0.2 * x**2 * y - 0.1 * y**3, lambda x, y: 1.0 + 0.2 * x * y)
    coef = tables.fit(_grid(f), 1e-9)
    assert not isinstance(coef, str)
    x, y = RNG.uniform(-1, 1, 500), RNG.uniform(-1, 1, 500)
    values = tables.evaluate(coef, x, y)
    np.testing.assert_allclose(values[0], f[0](x, y), rtol=0, atol=1e-14)
    np.testing.assert_allclose(values[1], f[1](x, y), rtol=0, atol=1e-14)
    e = RNG.uniform(0.3, 0.6, 50)
    np.testing.assert_allclose(
        tables.from_unit(tables.to_unit(e, (0.3, 0.6)), (0.3, 0.6)), e, rtol=1e-15
    )


@pytest.mark.parametrize(("f", "why"), [(lambda x, y: np.abs(y), "phase"),
                                        (lambda x, y: np.abs(x - 0.1), "restitution")])  # fmt: skip
def test_a_table_across_a_kink_is_refused_in_its_direction(f, why):
    assert tables.fit(_grid(f), 1e-9) == why


def test_the_phase_where_the_largest_of_two_tables_meets_a_target_is_brentqs():
    """Two smooth tables whose largest changes over the phase (a kink inside), the
    phase where it meets each target found as brentq finds it on the evaluated largest."""
    f = (lambda x, y: 1.0 + 0.5 * y + 0.1 * x, lambda x, y: 1.2 - 0.3 * (y - 0.2) ** 2 + 0.05 * x)
    coef = tables.fit(_grid(f), 1e-9)
    x = RNG.uniform(-1, 1, 200)
    target = RNG.uniform(0.9, 1.6, 200)
    y = tables.phase_where(coef, x, target)
    for i in range(x.size):

        def g(t, i=i):
            return tables.largest(coef, x[i : i + 1], t)[0] - target[i]

        if g(-1.0) <= 0.0 <= g(1.0):
            assert y[i] == pytest.approx(brentq(g, -1.0, 1.0, xtol=1e-15), abs=1e-13)
        else:
            assert np.isnan(y[i])
    assert np.isfinite(y).sum() > 50
    assert np.isnan(y).sum() > 20


@pytest.mark.parametrize("part", [tables._PART, 64])
def test_several_problems_solved_together_are_each_solved_alone(part, monkeypatch):
    """``phases_where`` solves several tables' targets in one Newton iteration (tables of
    different ``J``, padded; of different second degrees, apart; other ends; an empty
    problem): each problem's phases are those of ``phase_where`` on it alone (to a few
    rounding units: NumPy's einsum sums a row alone, which its Vandermonde matrix stores
    contiguously, in another order than rows among others). Rows or problems out of
    line would be off by the spread of the phases, 0.1 or more. (With parts of 64: the
    larger problems each alone, the smaller gathered.)"""
    monkeypatch.setattr(tables, "_PART", part)
    rng = np.random.default_rng(40)
    problems = []
    for j, n2, n, ends, level in [(3, 8, 300, (-1.0, 1.0), 1.0), (1, 8, 40, (-1.05, 1.05), 1.0),
                                  (2, 6, 120, (-1.0, 1.0), 1.0), (4, 8, 0, (-1.0, 1.0), 1.0),
                                  (2, 8, 500, (-1.1, 1.1), -2.0), (3, 6, 7, (-1.0, 1.0), 1.0),
                                  (1, 8, 200, (-1.0, 1.0), 3.0)]:  # fmt: skip
        # (the largest below 0 somewhere: a table padded by zeros would be the largest)
        f = tuple(
            lambda x, y, i=i, a=level: (
                a + 0.5 * y + 0.1 * (i + 1) * x - 0.2 * i * (y - 0.1 * i) ** 2
            )
            for i in range(j)
        )
        coef = tables.fit(_grid(f, 16, n2), 1e-9)
        x, target = RNG.uniform(-1, 1, n), level + rng.uniform(-0.6, 0.6, n)
        problems.append((coef, x, target, ends))
    together = tables.phases_where(problems)
    assert [y.size for y in together] == [p[1].size for p in problems]
    found = 0
    for problem, y in zip(problems, together, strict=True):
        alone = tables.phase_where(*problem)
        np.testing.assert_array_equal(np.isnan(y), np.isnan(alone))
        np.testing.assert_allclose(y, alone, rtol=0, atol=1e-14)
        found += np.count_nonzero(np.isfinite(y))
    assert found > 500


@pytest.mark.parametrize("n2", [1, 2, 3, 8])
def test_the_slope_of_a_series_at_each_point_is_numpys_derivative(n2):
    """The Newton steps' slope, from each point's series by the second kind, against
    NumPy's ``chebder`` and ``chebval`` of the same series (a slope off would leave the
    root found, by bisection, but slowly)."""
    c, y = RNG.normal(size=(300, n2)), RNG.uniform(-1.1, 1.1, 300)
    expected = [chebyshev.chebval(y[i], chebyshev.chebder(c[i])) for i in range(y.size)]
    np.testing.assert_allclose(tables._slope(c, y), expected, rtol=1e-13, atol=1e-13)
