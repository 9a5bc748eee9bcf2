"""The certified rigid contact-time search (:mod:`impactsym.rod.rigid_search`): the
second-derivative bound against an independent delay-equation solution, the screening of
pressing forces (affine in ``f``) and the chunking, which must not change any contact
time."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.polynomial import chebyshev as cheb
from references.rod_characteristics import Characteristics

from impactsym.rod import (
    contact_time,
)


@settings(max_examples=6, deadline=None)
@given(
    a=st.floats(math.log(0.05), math.log(10.0)).map(math.exp),
    f1=st.floats(0.0, 2.0),
    f2=st.floats(0.0, 2.0),
    lam=st.floats(0.0, 1.0),
)
def test_contact_functions_are_affine_in_f_as_the_atlas_screening_assumes(a, f1, f2, lam):
    """An atlas settles every ``f`` between two ``f`` whose ``g > 0`` is proved on a
    reflection interval (``rigid_search.screen_interval``): sound only because ``N``
    and ``y`` are affine in ``f`` at fixed ``alpha``, checked here on the independent
    delay-equation solution."""
    t = np.linspace(0.013, 19.99, 41)
    fm = (1.0 - lam) * f1 + lam * f2
    refs = [Characteristics(a, force, 10) for force in (f1, f2, fm)]
    for name in ("N", "y"):
        g1, g2, gm = (getattr(ref, name)(t) for ref in refs)
        np.testing.assert_allclose(gm, (1.0 - lam) * g1 + lam * g2, rtol=0, atol=1e-9)


SCREENED_ALPHAS = (0.07515749760695055, 0.5767450137140747, 0.6606700471450271, 3.0)


SCREENED_F = (*np.linspace(0.0, 2.0, 41).tolist(), 14 / 13, 68 / 39, 62 / 39, 1.0)


@functools.cache
def _pair_by_pair(condition):
    """Contact times of the screening test's grid, one pair per call (nothing shared),
    and the number of pair searches on reflection intervals that took."""
    A, F = np.meshgrid(SCREENED_ALPHAS, SCREENED_F)
    times, n_searched = [], 0
    for a, force in zip(A.ravel(), F.ravel(), strict=True):
        times.append(contact_time(a, force, condition=condition, t_max=30.0))
        # searched on reflection intervals 1, ..., its last (14 within t_max = 30)
        n_searched += 14 if math.isinf(times[-1]) else math.floor(times[-1] / 2.0)
    return np.array(times), n_searched


@pytest.mark.parametrize("strides", [(64, 1), (16, 4, 1)])
@pytest.mark.parametrize("condition", ["force", "position"])
def test_an_atlas_equals_the_search_pair_by_pair_with_far_fewer_searches(
    condition, strides, monkeypatch
):
    """Screening a grid (pairs of equal ``alpha`` settled together where ``g > 0`` is
    proved at both ends of a run of ``f``) gives the contact time of every pair, the
    narrow dips of the issue included, and searches a fraction of the pairs."""
    from impactsym.rod import rigid_search as module

    searched = []
    search = module.search_interval

    def counting(which, m, tables, row, *args, **kwargs):
        searched.append(row.size)
        return search(which, m, tables, row, *args, **kwargs)

    monkeypatch.setattr(module, "search_interval", counting)
    monkeypatch.setattr(module, "SCREEN_STRIDES", strides)
    monkeypatch.setattr(module, "SCREEN_MIN_PAIRS", 1)
    A, F = np.meshgrid(SCREENED_ALPHAS, SCREENED_F)
    grid = contact_time(A, F, condition=condition, t_max=30.0)
    n_grid = sum(searched)
    pairs, n_pairs = _pair_by_pair(condition)
    np.testing.assert_allclose(grid.ravel(), pairs, rtol=0, atol=1e-12)
    assert np.isinf(grid).any()
    assert np.isfinite(grid).any()
    # measured 0.30-0.72 of the pair-by-pair searches; 1 without the screening
    assert n_grid < 0.8 * n_pairs, (n_grid, n_pairs)


@settings(max_examples=20, deadline=None)
@given(
    a=st.floats(math.log(0.05), math.log(10.0)).map(math.exp),
    forces=st.lists(st.floats(0.0, 2.0), min_size=2, max_size=24),
    condition=st.sampled_from(["force", "position"]),
)
def test_screening_random_pressing_forces_equals_the_search_pair_by_pair(a, forces, condition):
    from impactsym.rod import rigid_search as module

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(module, "SCREEN_STRIDES", (4, 1))
        patch.setattr(module, "SCREEN_MIN_PAIRS", 1)
        grid = contact_time(a, np.array(forces), condition=condition, t_max=20.0)
    pairs = [contact_time(a, force, condition=condition, t_max=20.0) for force in forces]
    np.testing.assert_allclose(grid, pairs, rtol=0, atol=1e-12)


def test_chunks_of_tables_and_searches_do_not_change_the_contact_times(monkeypatch):
    """Distinct alphas are split into chunks (table memory) and searches into batches
    (cell memory); neither changes any contact time, nor do repeated pairs."""
    from impactsym.rod import rigid_search as module

    rng = np.random.default_rng(11)
    alpha = np.r_[np.exp(rng.uniform(np.log(0.05), np.log(10.0), 30)), 0.5, 0.5, 0.5]
    f = np.r_[rng.uniform(0.0, 2.0, 30), 1.3, 0.2, 1.3]
    want = {c: contact_time(alpha, f, condition=c, t_max=24.0) for c in ("force", "position")}
    monkeypatch.setattr(module, "_TABLE_ENTRIES", 40)  # 3 alphas per chunk at t_max = 24
    monkeypatch.setattr(module, "_SEARCH_CHUNK", 7)
    for condition, times in want.items():
        got = contact_time(alpha, f, condition=condition, t_max=24.0)
        np.testing.assert_allclose(got, times, rtol=0, atol=1e-12)
        assert got[-1] == got[-3]


def _reference_second_derivative(ref, which, k, tau):
    """``d^2 g / d tau^2`` on interval ``k`` from the collocation series (g = N or y)."""
    if which == "N":
        series = [ref.coef[k]] + ([ref.coef[k - 1]] if k else [])
    else:  # y = Phi_(k-1)(2) - Phi_(k-1)(tau) + Phi_k(tau)
        series = [ref.icoef[k]] + ([-ref.icoef[k - 1]] if k else [])
    return sum(cheb.chebval(tau - 1.0, cheb.chebder(c, 2)) for c in series)


@settings(max_examples=30, deadline=None)
@given(
    st.floats(0.1, 5.0),
    st.floats(0.0, 2.0),
    st.integers(1, 12),
    st.sampled_from(["N", "y"]),
    st.integers(0, 2**32 - 1),
)
@example(1.0, 1.0, 1, "y", 0)  # f = 1: N = f, all a_j = 0; the bound at x = 0 was 0 * inf
# f = 1, m = 1: N = 1 + 2 e^(-tau/alpha), |N_xx| = 1/2 at x = 0, exactly the bound; the
# collocation series' second derivative is 6e-6 high there (its own accuracy at an end)
@example(3.0, 1.0, 1, "N", 0)
def test_second_derivative_bound_holds_on_random_cells(a, force, m, which, seed):
    """The search is certified only if ``|g''| <= bound`` on every cell: checked on
    random cells (including ``x = 0`` and whole intervals) against ``g''`` of the
    independent delay-equation solution, 60 points per cell. A bound that is too small
    anywhere lets :func:`first_sign_change` pass over a dip, i.e. miss a root."""
    from impactsym.rod.rigid_search import interval_tables, rigid_interval

    ref = Characteristics(a, force, m + 1)
    model = rigid_interval(
        which,
        m,
        interval_tables(np.array([a]), m + 2),
        np.zeros(1, int),
        np.array([a]),
        np.array([force]),
    )
    rng = np.random.default_rng(seed)
    x_end = 4.0 / a
    n_cells = 40
    lo = np.where(rng.random(n_cells) < 0.2, 0.0, rng.uniform(0.0, x_end, n_cells))
    hi = lo + (x_end - lo) * np.exp(rng.uniform(np.log(1e-3), 0.0, n_cells))
    own = np.zeros(n_cells, int)
    ga, dga, auxa = model(lo, own)
    gb, dgb, auxb = model(hi, own)
    # the mapping x = 2 tau / alpha and the model's values agree with the reference
    for x, g in ((lo, ga), (hi, gb)):
        t = 2.0 * m + 0.5 * a * x
        want = ref.N(t) if which == "N" else ref.y(np.minimum(t, 2.0 * m + 2.0 - 1e-15))
        np.testing.assert_allclose(g, want, rtol=0, atol=1e-8)
    bound = model.bound(lo, hi, own, auxa, auxb, dga, dgb)
    s = np.linspace(0.0, 1.0, 60)
    x = lo[:, None] + s[None, :] * (hi - lo)[:, None]
    sampled = np.abs(_reference_second_derivative(ref, which, m, 0.5 * a * x)) * (0.5 * a) ** 2
    worst = sampled.max(axis=1)
    assert np.all(worst <= bound * (1.0 + 2e-5) + 1e-6 * (1.0 + worst)), (
        np.max(worst / bound),
        which,
    )
