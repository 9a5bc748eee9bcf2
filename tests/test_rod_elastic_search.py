"""The finite-kappa contact-time search (:mod:`impactsym.rod.elastic.search`), against
independent references.

* the delay ODE of :mod:`references.rod_elastic_delay` (d'Alembert + method of steps,
  SciPy DOP853 at ``rtol = 1e-13``, nothing from the Laplace series): contact times at
  a fixed random grid and near critical contact damping, the ``inf`` guarantee;
* the pointwise search on the pole sums alone (:mod:`references.rod_pole_search`) on an
  ``f`` sweep, where the Taylor table (the default) and the mpmath cell table
  (``method="cells"``) must agree with it;
* the screening of forces must give the contact times of the search pair by pair."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from references.rod_elastic_delay import ElasticDelay
from references.rod_pole_search import pointwise_pole_contact_times

from impactsym.rod import (
    contact_force,
    contact_time,
    displacement,
    impact_sequence,
)
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


def test_no_sign_change_where_the_contact_time_is_inf():
    a, force, k = 0.05, 1.5, 10.0  # light striker pressed hard: sticks
    for condition, fn in (("force", contact_force), ("position", displacement)):
        assert contact_time(a, force, condition=condition, kappa=k) == math.inf
        t = np.linspace(1e-3, 20.0, 20001)
        assert np.min(fn(t, a, force, kappa=k)) > -1e-12


def test_horizon_cuts_exactly_at_the_contact_time():
    tc = contact_time(1.3, 0.5, kappa=20.0, condition="force")
    assert contact_time(1.3, 0.5, kappa=20.0, t_max=tc - 1e-9, condition="force") == math.inf
    assert contact_time(1.3, 0.5, kappa=20.0, t_max=tc + 1e-9, condition="force") == tc


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


def test_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method"):
        elastic_contact_times(
            "N", np.ones(1), np.ones(1), kappa=np.ones(1), t_max=4.0, method="fast"
        )


@pytest.mark.parametrize(("a", "k"), [(1.3, 20.0), (0.2, 20.0), (3.0, 2.0), (1.0, 1e-4)])
def test_screened_f_sweep_equals_the_search_pair_by_pair(a, k):
    """g = A + f B: a proof of g > 0 on an interval for two forces holds for every force
    between them, so a sweep searches only some forces per interval; the contact times
    must be those of the search of every pair on its own (no screening for one pair)."""
    f = np.linspace(0.0, 2.0, 97)
    for which in ("N", "y"):
        swept = elastic_contact_times(
            which, np.full(f.size, a), f, kappa=np.full(f.size, k), t_max=20.0
        )
        alone = [
            elastic_contact_times(
                which, np.array([a]), np.array([x]), kappa=np.array([k]), t_max=20.0
            )[0]
            for x in f
        ]
        assert np.array_equal(swept, alone), which


def test_the_slow_manifold_table_reaches_an_even_horizon():
    """At ``t_max = 18`` the slow-manifold table stops at 18 (9 intervals, none beyond the
    horizon): a contact ending at 16.07, in its last interval, as the pointwise search on
    the pole sums finds it; and the table of the call is the one of 9 intervals."""
    from impactsym.rod.elastic.manifold import manifold_table

    a, k, f = 0.316, 1e3, np.array([1.5])
    manifold_table.cache_clear()
    got = elastic_contact_times("N", np.array([a]), f, kappa=np.array([k]), t_max=18.0)
    built = manifold_table(a, kappa=k, n_intervals=9)
    assert manifold_table.cache_info().hits == 1
    assert built.hi[-1] == 18.0
    expected = pointwise_pole_contact_times("N", a, f, kappa=k, t_max=18.0)
    assert 16.0 < got[0] < 18.0
    assert abs(got[0] - expected[0]) < 1e-11


def test_the_taylor_table_reaches_an_even_horizon():
    """As the slow-manifold table: at ``t_max = 18`` the Taylor table of (0.5, 30) stops
    at 18 (9 intervals), and contacts ending at 17.3, in its last interval, are where
    the pointwise search on the pole sums finds them."""
    from impactsym.rod.elastic.taylor import taylor_table

    a, k, f = 0.5, 30.0, np.array([1.7, 2.0])
    taylor_table.cache_clear()
    got = elastic_contact_times("N", np.full(2, a), f, kappa=np.full(2, k), t_max=18.0)
    built = taylor_table(a, kappa=k, n_intervals=9)
    assert taylor_table.cache_info().hits == 1
    assert built.hi[-1] == 18.0
    expected = pointwise_pole_contact_times("N", a, f, kappa=k, t_max=18.0)
    assert np.all((got > 17.0) & (got < 18.0))
    assert np.max(np.abs(got - expected)) < 1e-11


@pytest.mark.parametrize(
    ("a", "k"), [(0.005, 500.0), (0.01, 500.0), (0.02, 500.0), (0.005, 1e3), (0.01, 1e3)]
)
def test_a_force_decaying_to_zero_is_no_end_of_contact(a, k):
    """Until the reflection returns (t < 2) an unpressed striker on its spring sees the
    rod end as a unit dashpot: ``N'' + kappa N' + (kappa / alpha) N = 0``, ``N(0) = 0``,
    ``N'(0) = kappa``. Under-damped (``zeta = sqrt(kappa alpha) / 2 < 1``) the force
    crosses zero at ``pi / omega_d``; over-damped it decays to zero without crossing
    (to 1e-19 by t = 0.3), and a table that rounds it below zero must not end the
    contact there: it ends after the reflection (a light striker's contact time was
    reported as 0.31 here)."""
    zeta = math.sqrt(k * a) / 2.0
    t_c = contact_time(a, 0.0, condition="force", kappa=k)
    if zeta < 1.0:
        omega_d = math.sqrt(k / a) * math.sqrt(1.0 - zeta * zeta)
        assert t_c == pytest.approx(math.pi / omega_d, rel=1e-12)
    else:
        assert 2.0 < t_c < 2.1  # the reflected wave pulls the rod end away
        # the continued impact's own exact pieces (sequence_elastic) end it there too
        first = impact_sequence(a, 0.0, kappa=k, t_max=3.0).contacts[0]
        assert t_c == pytest.approx(first[1], rel=1e-10)
