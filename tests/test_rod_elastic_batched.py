"""Finite-kappa tables built for many ``(alpha, kappa)`` at once (issue 22, stiff maps).

* tables built together (:func:`impactsym.rod.elastic.manifold.extend_tables`: one NumPy
  pass over the cells of all of them per interval) are, to the last bit, the tables built
  alone, whatever tables share the pass and however far each is built;
* the graded Taylor mesh (poles 4 to 8 apart: Taylor cells widening after each
  reflection, no slow cells) stays within its bounds of the pole sums evaluated in mpmath
  at 60 digits (a different evaluation of the exact pole data), and its contact times are
  those of the uniform Taylor table and of the pointwise search on the pole sums;
* the cells of an interval computed at once (float starts, low parts): bounds and values
  against the mpmath pole sums on the uniform Taylor table as well.
"""

from __future__ import annotations

import numpy as np
import pytest
from references.rod_pole_search import pointwise_pole_contact_times, table_within_its_bounds

from impactsym.rod.elastic.manifold import ManifoldTable, extend_tables, interval_mesh
from impactsym.rod.elastic.search import TABLE_TOLERANCE, elastic_contact_times
from impactsym.rod.elastic.taylor import TaylorTable

NAMES = ("Y", "V", "N", "Y_lo", "V_lo", "N_lo", "G_hi", "G_lo")


def test_tables_built_together_are_the_tables_built_alone():
    alphas, k = (0.1, 0.4, 2.0, 7.0), 3e3
    alone = [ManifoldTable(a, k, 5) for a in alphas]
    together = [ManifoldTable(a, k, 5, lazy=True) for a in alphas]
    # different depths, different companions in each pass
    extend_tables(together[:3], [1, 3, 2])
    extend_tables(together[1:], [5, 4, 5])
    extend_tables(together, [5, 5, 5, 5])
    for one, many in zip(alone, together, strict=True):
        assert many.built == 5
        for name in NAMES:
            assert np.array_equal(one._arrays[name], many._arrays[name]), name
        for name in ("err_y_a", "err_y_b", "err_n_a", "err_n_b"):
            assert np.array_equal(getattr(one, name), getattr(many, name)), name


def test_an_interrupted_pass_leaves_every_table_as_it_was(monkeypatch):
    from impactsym.rod.elastic import manifold

    whole = [ManifoldTable(a, 1e3, 4) for a in (0.5, 5.0)]
    tables = [ManifoldTable(a, 1e3, 4, lazy=True) for a in (0.5, 5.0)]
    extend_tables(tables, [1, 1])
    build = manifold._build_intervals

    def interrupted(batch, intervals):
        if max(intervals) == 2:
            raise KeyboardInterrupt
        build(batch, intervals)

    monkeypatch.setattr(manifold, "_build_intervals", interrupted)
    with pytest.raises(KeyboardInterrupt):
        extend_tables(tables, [4, 4])
    assert [t.built for t in tables] == [1, 1]
    monkeypatch.setattr(manifold, "_build_intervals", build)
    extend_tables(tables, [4, 4])
    for one, many in zip(whole, tables, strict=True):
        assert np.array_equal(one.err_n_b, many.err_n_b)
        assert np.array_equal(one.N_a, many.N_a)


@pytest.mark.parametrize(("a", "k"), [(0.1, 100.0), (0.08, 100.0), (0.06, 150.0)])
def test_the_graded_taylor_mesh_lies_within_its_bounds_of_the_mpmath_pole_sums(a, k):
    _, layer = interval_mesh(a, kappa=k)
    assert layer.all()  # no slow cells: the poles are too near (ratio 7.9, 5.8, 6.9)
    table = ManifoldTable(a, k, 4)
    rng = np.random.default_rng(7)
    t = np.concatenate([rng.uniform(0.0, 8.0, 10), 2.0 * np.arange(4) + rng.uniform(0, 0.8, 4)])
    bounds = table_within_its_bounds(table, a, k, 4, t, rng.uniform(0.0, 2.0, t.size))
    assert np.all(bounds <= TABLE_TOLERANCE)


def test_the_graded_taylor_mesh_finds_the_contact_times_of_the_uniform_one():
    a, k = 0.1, 100.0
    f = np.linspace(0.0, 2.0, 9)
    alpha, kappa = np.full(f.size, a), np.full(f.size, k)
    for which in ("N", "y"):
        got = elastic_contact_times(which, alpha, f, kappa=kappa, t_max=20.0)
        uniform = TaylorTable(a, k, 10).view(which)
        assert np.all(uniform.err_a + 2.0 * uniform.err_b <= TABLE_TOLERANCE)
        reference = pointwise_pole_contact_times(which, a, f[::4], kappa=k, t_max=20.0)
        np.testing.assert_array_equal(np.isinf(got[::4]), np.isinf(reference))
        finite = np.isfinite(reference)
        assert np.max(np.abs(got[::4][finite] - reference[finite]), initial=0.0) < 1e-11


@pytest.mark.parametrize(("a", "k"), [(1.3, 20.0), (0.1, 100.0)])
def test_the_uniform_taylor_table_lies_within_its_bounds_of_the_mpmath_pole_sums(a, k):
    rng = np.random.default_rng(9)
    t = rng.uniform(0.0, 6.0, 14)
    table_within_its_bounds(TaylorTable(a, k, 3), a, k, 3, t, rng.uniform(0, 2, t.size))


def test_the_batches_kept_do_not_keep_their_tables_alive():
    """The data of recent batches is kept between intervals, by weak references: a table
    no one holds is freed, and a new table at its address is not mistaken for it."""
    import gc
    import weakref

    tables = [ManifoldTable(a, 1e3, 2, lazy=True) for a in (0.5, 2.0)]
    extend_tables(tables, [2, 2])
    gone = weakref.ref(tables[0])
    del tables
    gc.collect()
    assert gone() is None
    fresh = [ManifoldTable(a, 1e4, 2, lazy=True) for a in (0.5, 2.0)]
    extend_tables(fresh, [2, 2])
    alone = [ManifoldTable(a, 1e4, 2) for a in (0.5, 2.0)]
    for one, many in zip(alone, fresh, strict=True):
        assert np.array_equal(one.N_a, many.N_a)


def test_a_pass_interrupted_in_its_bounds_leaves_the_unbounded_tables_as_they_were(monkeypatch):
    # the first table bounded, the second interrupted: the next pass finishes both as if
    # never interrupted
    from impactsym.rod.elastic import taylor

    whole = [ManifoldTable(a, 1e3, 4) for a in (0.5, 5.0)]
    tables = [ManifoldTable(a, 1e3, 4, lazy=True) for a in (0.5, 5.0)]
    extend_tables(tables, [1, 1])
    bound, calls = taylor.force_bounds, []

    def second_interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return bound(*args, **kwargs)

    monkeypatch.setattr(taylor, "force_bounds", second_interrupted)
    with pytest.raises(KeyboardInterrupt):
        extend_tables(tables, [3, 3])
    assert sorted(t.built for t in tables) == [1, 3]
    monkeypatch.setattr(taylor, "force_bounds", bound)
    extend_tables(tables, [4, 4])
    for one, many in zip(whole, tables, strict=True):
        for name in ("N_a", "N_b", "Y_a", "err_n_a", "err_n_b", "err_y_a", "err_y_b"):
            assert np.array_equal(getattr(one, name), getattr(many, name)), name
