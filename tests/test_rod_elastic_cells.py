"""The mpmath cell table (:mod:`impactsym.rod.elastic.cells`) and finite-kappa contact times.

Against independent references:

* the delay ODE of :mod:`references.rod_elastic_delay` (d'Alembert + method of steps,
  SciPy DOP853 at ``rtol = 1e-13``, nothing from the Laplace series): contact times at
  a fixed random grid and near critical contact damping, the ``inf`` guarantee;
* the proven error bound of every cell against the pole sums evaluated with mpmath at
  90 digits (a different evaluation of the exact pole data, not the float assembly);
* the pointwise search on the pole sums alone (:mod:`references.rod_pole_search`) on an
  ``f`` sweep, where the Taylor table (the default) and the mpmath cell table
  (``method="cells"``) must agree with it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from references.rod_elastic_delay import ElasticDelay
from references.rod_pole_search import pointwise_pole_contact_times

from impactsym.rod import contact_force, contact_time, displacement
from impactsym.rod.elastic.cells import cell_table
from impactsym.rod.elastic.poles import pole_model
from impactsym.rod.elastic.search import elastic_contact_times

# contact times from the delay ODE agree to this (its event location and rtol)
REFERENCE = 1e-9


def _random_grid(n, seed):
    rng = np.random.default_rng(seed)
    alpha = np.exp(rng.uniform(math.log(0.1), math.log(5.0), n))
    f = rng.uniform(0.0, 2.0, n)
    kappa = np.exp(rng.uniform(math.log(0.5), math.log(60.0), n))
    return list(zip(alpha.tolist(), f.tolist(), kappa.tolist(), strict=True))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("a", "force", "k"),
    [
        *_random_grid(5, 11),
        (1.0, 0.3, 3.9),  # alpha kappa = 3.9, 4, 4.1: the contact poles (nearly) merge
        (0.5, 0.8, 8.0),
        (2.0, 0.1, 2.05),
        (0.8, 0.0, 0.7),  # f = 0, soft contact
        (3.0, 5.0, 10.0),  # f large: sticks
    ],
)
def test_contact_time_agrees_with_the_delay_ode(a, force, k):
    _agrees_with_the_delay_ode(a, force, k)


@pytest.mark.slow
@settings(max_examples=12, deadline=None, derandomize=True)
@given(a=st.floats(0.05, 20.0), force=st.floats(0.0, 2.0), k=st.floats(0.5, 60.0))
def test_contact_times_agree_with_the_delay_ode(a, force, k):
    _agrees_with_the_delay_ode(a, force, k)


def _agrees_with_the_delay_ode(a, force, k):
    ref = ElasticDelay(a, force, k, t_max=10.0)
    for condition in ("force", "position"):
        expected = ref.contact_time(condition)
        got = contact_time(a, force, condition=condition, kappa=k, t_max=10.0)
        if math.isinf(expected):
            assert math.isinf(got), (a, force, k, condition, got)
        else:
            assert abs(got - expected) < REFERENCE, (a, force, k, condition, got, expected)


@pytest.mark.parametrize(
    ("which", "a", "k"),
    [
        ("N", 1.3, 20.0),
        ("y", 1.3, 20.0),
        ("N", 1.0, 4.0),  # critical: a double root
        ("y", 1.0, 3.999),  # near critical: merged in mpmath
        ("N", 2.0, 1000.0),  # a fast pole
        ("y", 0.05, 1.0),  # underdamped contact
    ],
)
def test_cell_error_bound_holds_against_90_digit_pole_sums(which, a, k):
    table = cell_table(which, a, k, 11)
    reference = pole_model(which, a, k, 11, 90)
    rng = np.random.default_rng(3)
    # random points, and every cell's ends and centre in the first two intervals
    early = table.hi <= 4.0
    t = np.concatenate([rng.uniform(0.0, 21.99, 25), table.lo[early], table.c[early]])
    f = rng.uniform(0.0, 3.0, t.size)
    value, _ = table.evaluate(t, f)
    exact = np.array([reference.evaluate_mp(x, y) for x, y in zip(t, f, strict=True)])
    i = table.cell(t)
    bound = table.err_a[i] + f * table.err_b[i]
    assert np.all(np.abs(value - exact) <= bound)
    # and the bound is useful: most cells are at 1e-11 or better
    assert np.mean(table.err_a + table.err_b <= 1e-11) > 0.5


def test_no_sign_change_where_the_contact_time_is_inf():
    a, force, k = 0.05, 1.5, 10.0  # light striker pressed hard: sticks
    for condition, fn in (("force", contact_force), ("position", displacement)):
        assert contact_time(a, force, condition=condition, kappa=k) == math.inf
        t = np.linspace(1e-3, 20.0, 20001)
        assert np.min(fn(t, a, force, kappa=k)) > -1e-12


def test_horizon_cuts_exactly_at_the_contact_time():
    tc = contact_time(1.3, 0.5, kappa=20.0)
    assert contact_time(1.3, 0.5, kappa=20.0, t_max=tc - 1e-9) == math.inf
    assert contact_time(1.3, 0.5, kappa=20.0, t_max=tc + 1e-9) == tc


@pytest.mark.parametrize(
    ("a", "k"), [(1.3, 20.0), pytest.param(1.0, 4.1, marks=pytest.mark.slow), (0.3, 1000.0)]
)
def test_f_sweep_equals_the_pointwise_pole_search(a, k):
    f = np.linspace(0.0, 2.0, 12)
    alpha, kappa = np.full(f.size, a), np.full(f.size, k)
    for which in ("N", "y"):
        old = pointwise_pole_contact_times(which, a, f, kappa=k, t_max=10.0)
        for method in ("taylor", "cells"):
            new = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=10.0, method=method)
            assert np.array_equal(np.isinf(new), np.isinf(old)), method
            finite = np.isfinite(new)
            assert np.max(np.abs(new[finite] - old[finite]), initial=0.0) < 1e-11, method
