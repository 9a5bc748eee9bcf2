"""The slow-manifold table of stiff springs (:mod:`impactsym.rod.elastic.manifold`).

* its values lie within their proven bounds of the pole sums evaluated in mpmath at 60
  digits (:meth:`impactsym.rod.elastic.poles.PoleModel.evaluate_mp`: the inverted
  Laplace series, nothing of the delay equations), across the fast layers after the
  reflection times and on the wide cells, and those bounds certify the table;
* so do its values on the graded layer's wider cells (after ``p_f u = 16`` and 32);
* a coefficient spoiled after the build shows in the bound;
* the search takes this table only where its bound certifies every cell at the largest
  force (near its separation limit it does not, and the Taylor table serves);
* contact times of ``f`` sweeps at ``kappa = 1e2, 1e3, 1e4`` equal the pointwise search
  on the pole sums alone (:mod:`references.rod_pole_search`), at ``f = 0`` and on both
  sides of the forces where the first sign change jumps (a tangency)."""

from __future__ import annotations

import numpy as np
import pytest
from references.rod_pole_search import pointwise_pole_contact_times, table_within_its_bounds

from impactsym.rod.elastic import taylor
from impactsym.rod.elastic.manifold import ManifoldTable, interval_mesh
from impactsym.rod.elastic.poles import pole_model
from impactsym.rod.elastic.search import TABLE_TOLERANCE, elastic_contact_times

T_MAX = 8.0


@pytest.mark.parametrize(("a", "k"), [(0.1, 1e3), (1.0, 1e3), (8.0, 1e4), (0.3, 1e4)])
def test_values_lie_within_their_bounds_of_the_mpmath_pole_sums(a, k):
    table = ManifoldTable(a, k, 4)
    rng = np.random.default_rng(3)
    # random times, and times in the fast layers just after the reflections
    t = np.concatenate(
        [rng.uniform(0.0, T_MAX, 12), 2.0 * np.arange(4) + rng.uniform(0.0, 30.0 / k, 4)]
    )
    f = rng.uniform(0.0, 2.0, t.size)
    bounds = table_within_its_bounds(table, a, k, 4, t, f)
    assert np.all(bounds <= TABLE_TOLERANCE)  # the table stands for the function


def test_the_cell_count_does_not_grow_with_the_stiffness():
    counts = [interval_mesh(1.0, kappa=k)[0].size for k in (1e3, 1e4, 1e5, 1e6)]
    assert max(counts) < 160, counts  # a uniform Taylor mesh: 2048 .. 2e6 cells
    assert interval_mesh(1.0, kappa=4.0) is None  # complex contact poles: no manifold
    assert interval_mesh(1.0, kappa=30.0) is None  # layer too long: the Taylor table
    # roots 11.3 and 88.7, too near for slow cells: Taylor cells graded throughout
    widths, layer = interval_mesh(0.1, kappa=100.0)
    assert layer.all()
    assert widths.size < 256
    assert widths.sum() == 2.0
    assert interval_mesh(0.05, kappa=100.0) is None  # roots 27.6 and 72.4: too near


@pytest.mark.parametrize(("a", "k"), [(0.3, 1e3), (3.0, 1e4)])
def test_the_graded_layer_lies_within_its_bounds_of_the_mpmath_pole_sums(a, k):
    """The layer's later cells are wider (``h p_f`` up to 2.5 from ``p_f u = 16``, up to 5
    from 32): values there, after every reflection, within their bounds of the pole sums
    at 60 digits, and those bounds certify the table."""
    table = ManifoldTable(a, k, 4)
    fast = taylor.fastest_rate(a, kappa=k)
    rng = np.random.default_rng(11)
    t = (2.0 * np.arange(4)[:, None] + rng.uniform(16.0, 64.0, (4, 3)) / fast).ravel()
    f = rng.uniform(0.0, 2.0, t.size)
    for which in ("N", "y"):  # the widest layer cells are among them
        view = table.view(which)
        assert np.max(view.h[view.cell(t)] * fast) > 2.5, which
    bounds = table_within_its_bounds(table, a, k, 4, t, f)
    assert np.all(bounds <= TABLE_TOLERANCE)


@pytest.mark.parametrize("k", [1e3, 1e4, 1e5])
def test_the_layer_widens_as_its_transient_decays(k):
    """8 cells of ``h p_f <= 1`` after every reflection (the kink of the incoming wave),
    then never narrower, ``h p_f`` at most 1.25 before ``p_f u = 16``, 2.5 before 32 and
    5 after, at least 64 / p_f long: half the layer cells of a mesh of ``h`` and ``2 h``."""
    widths, layer = interval_mesh(1.0, kappa=k)
    fast = taylor.fastest_rate(1.0, kappa=k)
    reach = widths[layer] * fast
    start = np.concatenate([[0.0], np.cumsum(widths[layer])[:-1]]) * fast
    assert np.all(reach[:8] <= 1.0)
    assert np.all(np.diff(reach) >= 0.0)
    assert np.all(reach[start < 16.0] <= 1.25)
    assert np.all(reach[start < 32.0] <= 2.5)
    assert np.max(reach) <= 5.0
    assert (start[-1] + reach[-1]) >= 64.0
    assert layer.sum() <= 44, layer.sum()
    assert widths.size <= 80, widths.size


@pytest.mark.parametrize(("array", "offset"), [("N", 0), ("N", 1), ("V", 2), ("Y", 1)])
def test_a_planted_error_on_a_slow_cell_shows_in_the_bound(monkeypatch, array, offset):
    """Spoil one stored coefficient of the first wide cell after the layer (offset 0: its
    constant coefficient, a jump) by 1e-8 once the cells are built, before they are
    bounded: the bound must still contain the truth, and the cells after it (where it
    matters) must no longer pass as certified. The table is bounded for ``N`` first, and
    for ``y`` only when its view asks (as a search for ``N`` leaves it)."""
    a, k, force = 1.0, 1e3, 0.5
    _, layer = interval_mesh(a, kappa=k)
    cell = int(np.flatnonzero(~layer)[0]) + 1
    original = ManifoldTable._bound  # the bound of N; y's comes later, on the same arrays

    def spoiled(self, begin, end):
        self._arrays[array][:, cell, offset] += 1e-8
        original(self, begin, end)

    monkeypatch.setattr(ManifoldTable, "_bound", spoiled)
    table = ManifoldTable(a, k, 2, lazy=True)
    table.extend(2, which="N")
    assert np.all(np.isinf(table.err_y_a))  # y not bounded yet: nothing certified
    rng = np.random.default_rng(5)
    for which in ("N", "y"):
        reference = pole_model(which, a, kappa=k, n_terms=2, dps=60)
        view = table.view(which)
        t = np.concatenate([rng.uniform(0.0, 4.0, 12), view.lo[cell : cell + 3] + 1e-3])
        f = np.full(t.size, force)
        value, _ = view.evaluate(t, f)
        exact = np.array([reference.evaluate_mp(x, force) for x in t])
        bound = view.err_a[view.cell(t)] + force * view.err_b[view.cell(t)]
        assert np.all(np.abs(value - exact) <= bound), (which, array)
        if which == "y" or array != "Y":  # y does not feed back into N
            after = view.err_a[view.lo >= view.hi[cell]]
            assert np.min(after) > TABLE_TOLERANCE, (which, array)  # no longer certified


def _tangency(which, a, k, lo, hi):
    """A force in ``[lo, hi]`` where the contact time jumps (by more than 0.5), to 1e-7,
    and the two sides' forces."""
    search = elastic_contact_times

    def time_at(x):
        return search(which, np.array([a]), np.array([x]), kappa=np.array([k]), t_max=T_MAX)[0]

    t_lo = time_at(lo)
    while hi - lo > 1e-7:
        mid = 0.5 * (lo + hi)
        if abs(time_at(mid) - t_lo) < 0.5:
            lo = mid
        else:
            hi = mid
    return [lo, hi]


@pytest.mark.parametrize("k", [1e2, 1e3, 1e4])
@pytest.mark.parametrize(("which", "jump"), [("N", (0.1, 0.3)), ("y", (1.4, 1.8))])
def test_f_sweep_equals_the_pointwise_pole_search(k, which, jump):
    a = 0.3
    f = np.array([0.0, 0.5, 1.2, 2.0, *_tangency(which, a, k, *jump)])
    got = elastic_contact_times(which, np.full(f.size, a), f, kappa=np.full(f.size, k), t_max=T_MAX)
    expected = pointwise_pole_contact_times(which, a, f, kappa=k, t_max=T_MAX)
    assert np.array_equal(np.isinf(got), np.isinf(expected)), (got, expected)
    finite = np.isfinite(got)
    assert np.max(np.abs(got[finite] - expected[finite]), initial=0.0) < 1e-11
    assert abs(got[-1] - got[-2]) > 0.5  # the two sides of the jump, both right


def test_the_search_takes_the_table_only_where_its_bound_certifies_every_cell():
    """alpha = 0.10125, kappa = 100 is just past the table's separation limit: its bound
    misses 1e-12 on a fifth of the N cells at f = 2, whose pole sums would cost tens of
    seconds; the Taylor table serves instead, with the cell table's contact time."""
    from impactsym.rod.elastic import search

    forces = np.array([0.0, 2.0])
    assert search._certified_manifold(0.3, 100.0, "N", 11, forces)(11) is not None
    assert search._certified_manifold(0.10125, 100.0, "N", 11, forces)(11) is None
    f = np.array([0.0, 1.0, 2.0])
    alpha, kappa = np.full(3, 0.10125), np.full(3, 100.0)
    got = elastic_contact_times("N", alpha, f, kappa=kappa, t_max=20.0)
    ref = elastic_contact_times("N", alpha, f, kappa=kappa, t_max=20.0, method="cells")
    np.testing.assert_array_equal(np.isinf(got), np.isinf(ref))
    np.testing.assert_allclose(got[np.isfinite(got)], ref[np.isfinite(ref)], rtol=0, atol=1e-10)


@pytest.mark.parametrize(
    ("args", "error", "match"),
    [
        ((-1.0, 1e3, 3), ValueError, "alpha must be > 0"),
        ((1.0, -5.0, 3), ValueError, "kappa must be > 0"),
        ((float("nan"), 1e3, 3), ValueError, "alpha"),
        (("1.0", 1e3, 3), TypeError, "alpha"),
        ((1.0, 1e3, 0), ValueError, "n_intervals must be >= 1"),
        ((1.0, 1e3, 2.5), TypeError, "n_intervals must be an integer"),
    ],
)
def test_bad_table_input_is_refused_with_its_name(args, error, match):
    """As the Taylor table (the same check): before the mesh is even asked for."""
    with pytest.raises(error, match=match):
        ManifoldTable(*args)


@pytest.mark.parametrize(("a", "k"), [(0.1, 1e3), (1.0, 1e4), (10.0, 100.0), (0.3, 3e3)])
@pytest.mark.parametrize("steps", [[1, 2, 3, 10], [4, 10], list(range(1, 11))])
def test_a_table_built_interval_by_interval_is_the_table_built_at_once(a, k, steps):
    """The search builds the table as far as its contacts last (``lazy=True``, then
    :meth:`ManifoldTable.extend`): the coefficients and the bounds of every interval
    built, in whatever steps, are those of the table built at once, to the last bit (the
    bound's running sums carried over, not started again)."""
    whole = ManifoldTable(a, k, 10)
    table = ManifoldTable(a, k, 10, lazy=True)
    assert table.built == 0
    assert table.lo.size == 0
    names = ("lo", "hi", "h", "N_a", "N_b", "Y_a", "Y_b")
    names += ("err_n_a", "err_n_b", "err_y_a", "err_y_b")
    for step in steps:
        table.extend(step)
        cells = step * table.cells_per_interval
        for name in names:
            assert np.array_equal(getattr(table, name), getattr(whole, name)[:cells]), name
        for which in ("N", "y"):  # a view over fewer intervals: those cells alone
            part, full = table.view(which, n_intervals=step - 1 or 1), whole.view(which)
            i = np.arange(part.lo.size)
            assert np.array_equal(part.err_a, full.err_a[i])
            assert np.array_equal(part.d2_b, full.d2_b[i])


@pytest.mark.parametrize(("a", "k"), [(0.1, 100.0), (1.0, 1e4), (3.0, 1e3)])
def test_the_bound_of_y_asked_for_late_is_the_bound_computed_with_n(a, k):
    """A search for ``N`` bounds only ``N`` (``which="N"``): ``err_y`` stays ``inf`` (not
    certified) until ``y`` is asked for, in whatever steps, and is then the bound of the
    table bounded for both at once, to the last bit (the running sums of ``y`` carried on
    from where its bound stopped, not from where ``N``'s did)."""
    whole = ManifoldTable(a, k, 8)
    table = ManifoldTable(a, k, 8, lazy=True)
    n = table.cells_per_interval
    table.extend(3, which="N")
    assert np.all(np.isinf(table.err_y_a))
    assert np.all(np.isinf(table.err_y_b))
    assert np.array_equal(table.err_n_b, whole.err_n_b[: 3 * n])
    table.extend(2, which="y")  # y on the first two intervals only
    assert np.array_equal(table.err_y_a[: 2 * n], whole.err_y_a[: 2 * n])
    assert np.all(np.isinf(table.err_y_b[2 * n :]))
    table.extend(6, which="N")
    view = table.view("y", n_intervals=5)  # y on intervals 3 .. 5 (N built to 6)
    assert np.array_equal(view.err_b, whole.err_y_b[: 5 * n])
    assert np.all(np.isinf(table.err_y_a[5 * n :]))
    table.extend(8)
    for name in ("N_a", "Y_b", "err_n_a", "err_n_b", "err_y_a", "err_y_b"):
        assert np.array_equal(getattr(table, name), getattr(whole, name)), name


@pytest.mark.parametrize("which", ["x", (), ("N", "v"), "yN"])
def test_extend_refuses_an_unknown_function(which):
    table = ManifoldTable(1.0, 1e3, 2, lazy=True)
    with pytest.raises(ValueError, match="which"):
        table.extend(1, which=which)


def test_an_interrupted_extension_leaves_the_table_as_it_was(monkeypatch):
    """A build interrupted inside an interval (Ctrl-C, MemoryError) leaves the table as
    before it: the next extension builds the same coefficients and bounds as a table
    never interrupted (the state carried between intervals is restored)."""
    whole = ManifoldTable(1.0, 1e3, 6)
    table = ManifoldTable(1.0, 1e3, 6, lazy=True)
    table.extend(2)
    build = ManifoldTable._build_interval

    def interrupted(self, m):
        if m == 3:
            raise KeyboardInterrupt
        build(self, m)

    monkeypatch.setattr(ManifoldTable, "_build_interval", interrupted)
    with pytest.raises(KeyboardInterrupt):
        table.extend(5)
    assert table.built == 2
    monkeypatch.setattr(ManifoldTable, "_build_interval", build)
    table.extend(6)
    _assert_same_table(table, whole)


def test_a_view_of_a_lazy_table_without_a_count_is_the_whole_table():
    table = ManifoldTable(1.0, 1e3, 4, lazy=True)
    table.extend(1)
    view, full = table.view("N"), ManifoldTable(1.0, 1e3, 4).view("N")
    assert np.array_equal(view.lo, full.lo)
    assert np.array_equal(view.err_a, full.err_a)


def test_the_search_builds_only_the_intervals_its_contacts_need():
    """Heavy strikers pressed lightly leave the rod by t = 12: the search builds the
    table of (10, 1e3) through the interval after the last contact's end, not to t = 20,
    and finds what the pointwise search on the pole sums alone finds."""
    from impactsym.rod.elastic.manifold import manifold_table

    a, k = 10.0, 1e3
    f = np.array([0.0, 0.3, 0.6])
    manifold_table.cache_clear()
    got = elastic_contact_times("N", np.full(f.size, a), f, kappa=np.full(f.size, k), t_max=20.0)
    table = manifold_table(a, kappa=k, n_intervals=10)
    assert np.all(got < 12.0)
    assert table.built == int(np.max(got) // 2) + 2 < 10
    expected = pointwise_pole_contact_times("N", a, f, kappa=k, t_max=20.0)
    assert np.max(np.abs(got - expected)) < 1e-11


def test_threads_sharing_the_cached_tables_find_what_one_thread_finds():
    """The cached tables are built lazily and shared: eight threads searching different
    forces at once extend the same tables to different depths, and find, bit for bit,
    what one thread finds alone (every interval is the same however it was built)."""
    from concurrent.futures import ThreadPoolExecutor

    from impactsym.rod.elastic.manifold import manifold_table

    alpha = np.repeat([0.3, 1.0, 10.0], 8)
    f = np.tile(np.linspace(0.0, 2.0, 8), 3)
    kappa = np.full(alpha.size, 1e3)
    manifold_table.cache_clear()
    alone = {w: elastic_contact_times(w, alpha, f, kappa=kappa, t_max=20.0) for w in "Ny"}
    manifold_table.cache_clear()
    jobs = [(w, np.arange(i, alpha.size, 4)) for w in "Ny" for i in range(4)]
    with ThreadPoolExecutor(8) as pool:
        found = list(
            pool.map(
                lambda job: elastic_contact_times(
                    job[0], alpha[job[1]], f[job[1]], kappa=kappa[job[1]], t_max=20.0
                ),
                jobs,
            )
        )
    for (which, points), times in zip(jobs, found, strict=True):
        assert np.array_equal(times, alone[which][points]), which


def test_an_extension_interrupted_in_its_bound_leaves_the_table_as_it_was(monkeypatch):
    """Interrupted while bounding (after the intervals were built), the table starts the
    next extension over from its state before (the build alone was guarded: the bound's
    interruption left the carried state advanced, found by review)."""
    from impactsym.rod.elastic import taylor

    whole = ManifoldTable(1.0, 1e3, 4)
    table = ManifoldTable(1.0, 1e3, 4, lazy=True)
    table.extend(2)
    bound = taylor.force_bounds

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(taylor, "force_bounds", interrupted)
    with pytest.raises(KeyboardInterrupt):
        table.extend(3)
    assert table.built == 2
    monkeypatch.setattr(taylor, "force_bounds", bound)
    table.extend(4)
    _assert_same_table(table, whole)


def _assert_same_table(table, whole):
    """``table`` holds the coefficients and bounds of ``whole`` to the last bit."""
    for name in ("N_a", "N_b", "Y_a", "Y_b", "err_n_a", "err_n_b", "err_y_a", "err_y_b"):
        assert np.array_equal(getattr(table, name), getattr(whole, name)), name
