"""The Taylor table of the delay equations (:mod:`impactsym.rod.elastic.taylor`).

Against independent references:

* the proven error bound of the table against the pole sums of the Laplace series
  evaluated with mpmath at 90 digits (another derivation: the Laplace-domain solution,
  not the time-domain equations the table integrates);
* the delay ODE of :mod:`references.rod_elastic_delay` (d'Alembert, method of steps,
  SciPy DOP853), for values (its contact times: ``test_rod_elastic_cells.py``);
* planted errors: a coefficient of the table spoiled after it was computed must show in
  its a-posteriori bound (the bound is a property of the stored polynomials, not a
  promise about how they were made).
"""

from __future__ import annotations

import numpy as np
import pytest
from references.rod_elastic_delay import ElasticDelay
from references.rod_pole_search import pointwise_pole_contact_times

from impactsym.rod.elastic.poles import pole_model
from impactsym.rod.elastic.search import TABLE_TOLERANCE, elastic_contact_times
from impactsym.rod.elastic.taylor import MAX_CELLS, TaylorTable, cells_per_interval

CASES = [
    (1.3, 20.0),
    (1.0, 4.0),  # critical contact damping: a double root
    (1.0, 3.999),  # nearly critical: the pole parts cancel
    (0.05, 1.0),  # light striker, underdamped contact
    (50.0, 2.0),  # heavy striker
    (0.01, 0.5),  # very light striker
    (2.0, 100.0),  # stiff contact (256 cells per interval)
    (1.0, 1e-4),  # very soft contact: the y bound exceeds 1e-12 late (pole sums there)
]


def _samples(table, rng, n=30):
    first = table.hi <= 2.0  # every cell end of the first interval, and random points
    return np.concatenate([rng.uniform(0.0, table.hi[-1], n), table.lo[first]])


@pytest.mark.parametrize(("a", "k"), CASES)
def test_error_bound_holds_against_90_digit_pole_sums(a, k):
    table = TaylorTable(a, k, 8)
    rng = np.random.default_rng(7)
    for which in ("N", "y"):
        reference = pole_model(which, a, kappa=k, n_terms=8, dps=90)
        view = table.view(which)
        t = _samples(table, rng)
        f = rng.uniform(0.0, 3.0, t.size)
        value, _ = view.evaluate(t, f)
        exact = np.array([reference.evaluate_mp(x, y) for x, y in zip(t, f, strict=True)])
        i = view.cell(t)
        bound = view.err_a[i] + f * view.err_b[i]
        excess = np.max(np.abs(value - exact) / bound)
        assert np.all(np.abs(value - exact) <= bound), (which, excess)
        # and the bound is useful: the table stands for the function on every cell
        if k >= 0.5:
            assert np.max(view.err_a + 3.0 * view.err_b) <= TABLE_TOLERANCE, which


@pytest.mark.parametrize(("a", "force", "k"), [(1.3, 0.4, 20.0), (0.2, 1.0, 20.0), (5.0, 0.0, 3.0)])
def test_values_agree_with_the_delay_ode(a, force, k):
    ref = ElasticDelay(a, force, k, t_max=12.0)
    table = TaylorTable(a, k, 6)
    t = np.linspace(0.0, 12.0, 121)
    for which, fn in (("N", ref.N), ("y", ref.y)):
        value, _ = table.view(which).evaluate(t, np.full(t.size, force))
        expected = np.array([fn(x) for x in t])
        assert np.max(np.abs(value - expected)) < 1e-9, which


@pytest.mark.parametrize(
    ("array", "cell", "order", "affected"),
    [
        ("N", 37, 2, "Ny"),
        ("N", 37, 0, "Ny"),  # a constant coefficient: a jump at the cell start
        ("V", 5, 0, "Ny"),
        ("Y", 60, 1, "y"),
        ("Y", 37, 0, "y"),
    ],
)
def test_a_planted_error_shows_in_the_bound(monkeypatch, array, cell, order, affected):
    """Spoil one stored coefficient (of ``N``, of the internal ``v``, of ``y``; constant
    coefficients too, which make jumps) by 1e-8 after the recurrence: the table is then
    wrong by up to ~1e-8 from that cell on (``y`` does not feed back into ``N``), and its
    bound must still contain the truth and rise to that size where it is affected."""
    a, k, force = 1.3, 20.0, 0.5
    original = TaylorTable._bound

    def spoiled(self, Y, V, N, *rest):
        {"N": N, "V": V, "Y": Y}[array][:, cell, order] += 1e-8
        return original(self, Y, V, N, *rest)

    monkeypatch.setattr(TaylorTable, "_bound", spoiled)
    table = TaylorTable(a, k, 3)
    rng = np.random.default_rng(5)
    for which in ("N", "y"):
        reference = pole_model(which, a, kappa=k, n_terms=3, dps=60)
        view = table.view(which)
        t = np.concatenate([rng.uniform(0.0, 6.0, 25), view.lo[cell : cell + 3] + 1e-3])
        f = np.full(t.size, force)
        value, _ = view.evaluate(t, f)
        exact = np.array([reference.evaluate_mp(x, force) for x in t])
        i = view.cell(t)
        bound = view.err_a[i] + force * view.err_b[i]
        assert np.all(np.abs(value - exact) <= bound), (which, array)
        after = view.lo >= view.hi[cell]
        if which in affected:
            assert np.min(view.err_a[after]) > 1e-11, (which, array)  # noticed, not ignored
        assert np.max(view.err_a[view.hi <= view.lo[cell]]) < 1e-12  # before: untouched


def test_cells_follow_the_fastest_rate_and_stiff_springs_go_to_the_cell_table():
    assert cells_per_interval(1.0, kappa=4.0) == 16  # |p| = 2: the floor of 16 cells
    assert cells_per_interval(1.3, kappa=20.0) == 64  # |p| = 18.9: 2/64 * 18.9 <= 1
    assert cells_per_interval(0.3, kappa=1000.0) > MAX_CELLS
    with pytest.raises(ValueError, match="Taylor cells"):
        TaylorTable(0.3, 1000.0, 2)
    # the stiff pair is still answered (mpmath cell table), the same as the pole search
    f = np.array([0.0, 0.7])
    got = elastic_contact_times("N", np.full(2, 0.3), f, kappa=np.full(2, 1000.0), t_max=6.0)
    old = pointwise_pole_contact_times("N", 0.3, f, kappa=1000.0, t_max=6.0)
    assert np.allclose(got, old, rtol=0, atol=1e-11)


@pytest.mark.parametrize(
    ("args", "error", "match"),
    [
        ((-1.0, 20.0, 3), ValueError, "alpha must be > 0"),
        ((1.0, float("nan"), 3), ValueError, "kappa"),
        ((1.0, float("inf"), 3), ValueError, "kappa"),
        (("1.0", 20.0, 3), TypeError, "alpha"),
        ((np.ones(2), 20.0, 3), TypeError, "alpha must be a real number"),
        ((1.0, 20.0, 0), ValueError, "n_intervals must be >= 1"),
        ((1.0, 20.0, 2.5), TypeError, "n_intervals must be an integer"),
    ],
)
def test_bad_table_input_is_refused_with_its_name(args, error, match):
    with pytest.raises(error, match=match):
        TaylorTable(*args)


def test_unknown_time_function_is_refused():
    with pytest.raises(ValueError, match="which must be 'y' or 'N'"):
        TaylorTable(1.0, 4.0, 1).view("v")


@pytest.mark.parametrize("kind", ["taylor", "manifold"])
def test_evaluation_rounds_within_the_horner_allowance_of_the_bounds(kind):
    """The tables' polynomials are summed with the powers of ``x`` by a running product,
    not by Horner's rule; the cells' bounds allow ``(DEGREE + 4) eps sum |c_k|`` of
    rounding for ``N`` (one order more for ``y``). Against the stored coefficients summed
    in mpmath at 50 digits (at the same ``x``), at random points and forces, the values
    keep within that allowance, and the slopes (used to order the search, not in its
    proofs) agree to 1e-12 of their coefficients' size."""
    import mpmath as mp

    from impactsym.rod.elastic.manifold import ManifoldTable
    from impactsym.rod.elastic.taylor import DEGREE

    table = TaylorTable(1.3, 20.0, 3) if kind == "taylor" else ManifoldTable(0.3, 1e3, 3)
    rng = np.random.default_rng(11)
    eps = np.finfo(float).eps
    for which, allowance in (("N", DEGREE + 4), ("y", DEGREE + 5)):
        view = table.view(which)
        t = rng.uniform(0.0, view.hi[-1], 300)
        f = rng.uniform(0.0, 2.0, t.size)
        value, slope = view.evaluate(t, f)
        i = view.cell(t)
        h = np.broadcast_to(view.h, view.lo.shape)[i]
        x = (t - view.lo[i]) / h
        with mp.workdps(50):
            for j in range(t.size):
                a, b = view.A[i[j]], view.B[i[j]]
                c = [mp.mpf(p) + mp.mpf(f[j]) * mp.mpf(q) for p, q in zip(a, b, strict=True)]
                exact = mp.polyval(c[::-1], mp.mpf(x[j]))
                d_exact = mp.polyval([k * ck for k, ck in enumerate(c)][:0:-1], mp.mpf(x[j]))
                size = np.abs(a).sum() + f[j] * np.abs(b).sum()
                assert abs(value[j] - exact) <= allowance * eps * size, (which, j)
                d_size = np.abs(np.arange(a.size) * (a + f[j] * b)).sum()
                assert abs(slope[j] * h[j] - d_exact) <= 1e-12 * d_size, (which, j)
