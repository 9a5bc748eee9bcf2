"""Rod contact times (issue 11) and the rod far out (issue 13), against independent references.

* contact times: the neutral delay equation of :mod:`rod_characteristics` (Chebyshev
  collocation interval by interval, nothing from the Laplace series), sampled densely
  and refined with ``scipy.optimize.brentq``;
* far out: the modal expansion of the rigid-contact displacement, written here from the
  poles of :math:`Y(s) = (\\alpha s + f)\\sinh s / (s^2(\\alpha s \\sinh s + \\cosh s))`,
  and for the force its second difference identity
  :math:`y(t+h) - 2y(t) + y(t-h) = \\alpha^{-1}\\int_{-h}^{h}(h - |s|)(f - N(t+s))\\,ds`.
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.polynomial import chebyshev as cheb
from references.rod_characteristics import Characteristics
from scipy.optimize import brentq

from impactsym.rod import contact_force, contact_time, displacement, numpy_source

# ------------------------------------------------------------------ references

#: Dips shallower than this may be passed over (impactsym.rod.contact_times docstring).
TOLERANCE = 1e-12


def reference_contact_time(alpha, f, condition, t_max=20.0, n_samples=4001):
    """First sign change of the collocation solution: dense samples, then brentq."""
    n_int = math.ceil(t_max / 2)
    ref = Characteristics(alpha, f, n_int + 1)

    def g(k, tau):
        phi = cheb.chebval(tau - 1.0, ref.coef[k])
        if condition == "force":
            return phi + (cheb.chebval(tau - 1.0, ref.coef[k - 1]) if k else 0.0)
        value = cheb.chebval(tau - 1.0, ref.icoef[k])
        if k:
            value = value + cheb.chebval(1.0, ref.icoef[k - 1])
            value = value - cheb.chebval(tau - 1.0, ref.icoef[k - 1])
        return value

    for k in range(n_int):
        tau = np.linspace(0.0, min(2.0, t_max - 2 * k), n_samples)
        values = g(k, tau)
        # below the library's documented tolerance a value is rounding noise, not a
        # crossing (a light striker's exp(-t/alpha) reaches 1e-16 before the reflection)
        below = np.flatnonzero(values[1:] < -TOLERANCE) + 1
        if below.size:
            i = below[0]
            j = np.flatnonzero(values[:i] > 0)[-1]
            return 2 * k + brentq(lambda x, k=k: g(k, x), tau[j], tau[i], xtol=1e-14)
    return math.inf


def modal_displacement(t, alpha, f, n_modes=400_000):
    """y(t) = f - sum_k 2 sin w (f cos wt - alpha w sin wt) / (w^2 ((alpha+1) sin w
    + alpha w cos w)) over the roots of alpha w tan w = 1; tail < 2/(alpha pi^3 K^2)."""
    k = np.arange(n_modes)
    w = k * np.pi + np.arctan(1.0 / (alpha * np.maximum(k * np.pi, np.sqrt(1.0 / alpha))))
    for _ in range(50):  # Newton on cos w - alpha w sin w
        F = np.cos(w) - alpha * w * np.sin(w)
        dF = -(1 + alpha) * np.sin(w) - alpha * w * np.cos(w)
        w = w - F / dF
    s, c = np.sin(w), np.cos(w)
    den = w**2 * ((alpha + 1) * s + alpha * w * c)
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.empty(t.size)
    for i, ti in enumerate(t):
        phase = w * ti
        out[i] = f - np.sum(2 * s * (f * np.cos(phase) - alpha * w * np.sin(phase)) / den)
    return out


# ------------------------------------------------------------------ contact times

ISSUE_POINTS = [  # from the issue: 50-digit check of the delay system
    (0.6606700471450271, 68 / 39, "position", 5.8531774710),
    (0.5767450137140747, 14 / 13, "force", 6.4072128479),
    (0.07515749760695055, 62 / 39, "position", 4.2107774796),
]


@pytest.mark.parametrize(("a", "force", "condition", "expected"), ISSUE_POINTS)
def test_first_roots_the_sampled_search_missed(a, force, condition, expected):
    tc = contact_time(a, force, condition=condition)
    assert abs(tc - expected) < 1e-9
    assert abs(tc - reference_contact_time(a, force, condition)) < 1e-9


def _compare(a, force, condition):
    tc = contact_time(a, force, condition=condition, t_max=20.0)
    ref = reference_contact_time(a, force, condition)
    if math.isinf(ref):
        assert math.isinf(tc), (a, force, condition, tc)
        return
    if tc < ref - 1e-7:  # a dip between the reference's samples: it must be real
        y = contact_force if condition == "force" else displacement
        assert y(tc - 1e-7, a, force) > 0 > y(tc + 1e-7, a, force)
        assert tc > ref - 2.0 / 4000 * 2  # within one reference sample step
        return
    assert abs(tc - ref) < 1e-7, (a, force, condition, tc, ref)


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(math.log(0.05), math.log(10.0)).map(math.exp),
    force=st.floats(0.0, 2.0),
    condition=st.sampled_from(["force", "position"]),
)
@example(a=math.exp(-2.875), force=0.0, condition="force")  # light striker: N ~ 1e-16 at t = 2
def test_contact_time_equals_the_first_root_of_the_delay_equation(a, force, condition):
    _compare(a, force, condition)


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(0.07, 0.9),
    force=st.floats(1.0, 2.0),
    condition=st.sampled_from(["force", "position"]),
)
def test_narrow_dips_are_found(a, force, condition):
    _compare(a, force, condition)


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


def test_the_whole_issue_grid_is_decided_and_never_later_than_dense_sampling():
    A, F = np.meshgrid(np.geomspace(0.05, 10, 100), np.linspace(0, 2, 100))
    for condition in ("force", "position"):
        tc = contact_time(A, F, condition=condition, t_max=20.0)
        assert tc.shape == A.shape
        assert not np.isnan(tc).any()
        # brute force on a few rows: a dense sample below zero before t_c is a miss
        fn = contact_force if condition == "force" else displacement
        t = np.linspace(1e-9, 20.0, 40001)
        for i in range(0, 100, 33):
            for j in range(0, 100, 9):
                values = fn(t, A[i, j], F[i, j])
                before = t < tc[i, j] - 1e-9
                assert np.all(values[before] > -1e-12), (A[i, j], F[i, j], condition)


def test_sticking_and_horizon_semantics():
    assert contact_time(0.05, 2.0) == math.inf
    # with f = 0 the light striker always releases, on the first reflection interval
    assert 2.0 < contact_time(0.05, 0.0) < 4.0
    tc = contact_time(0.5767450137140747, 14 / 13)
    assert contact_time(0.5767450137140747, 14 / 13, t_max=tc - 1e-6) == math.inf
    assert contact_time(0.5767450137140747, 14 / 13, t_max=tc + 1e-6) == tc


def test_contact_time_limits_are_refused_with_the_limit_named():
    with pytest.raises(ValueError, match="t_max must be <= 10000"):
        contact_time(1.0, 0.5, t_max=2e4)
    with pytest.raises(ValueError, match="t_max must be <= 20 for finite kappa"):
        contact_time(1.0, 0.5, kappa=10.0, t_max=100.0)
    with pytest.raises(TypeError):
        contact_time(1.0, 0.5, "force")  # condition is keyword-only


def test_finite_stiffness_contact_time_is_a_sign_change_and_fast():
    start = time.perf_counter()
    tc = contact_time(np.array([1.0, 1.0, 3.0]), 0.2, kappa=50.0)
    elapsed = time.perf_counter() - start
    for t, a in zip(tc, (1.0, 1.0, 3.0), strict=True):
        assert contact_force(t - 1e-7, a, 0.2, kappa=50.0) > 0
        assert contact_force(t + 1e-7, a, 0.2, kappa=50.0) < 0
    assert elapsed < 30.0
    assert abs(contact_time(3.0, 0.0, kappa=1e5) - contact_time(3.0, 0.0)) < 1e-4


# ------------------------------------------------------------------ far out


@settings(max_examples=8, deadline=None)
@given(
    t=st.floats(0.0, 1e4),
    a=st.floats(math.log(0.02), math.log(20.0)).map(math.exp),
    force=st.floats(0.0, 3.0),
)
def test_displacement_anywhere_up_to_1e4_equals_the_modal_expansion(t, a, force):
    assert abs(displacement(t, a, force) - modal_displacement(t, a, force)[0]) < 1e-9


@pytest.mark.parametrize(
    ("a", "force", "t"), [(math.exp(3.75), 3.0, 6778.150390625), (100.0, 1.0, 1e4)]
)
def test_heavy_striker_far_out_is_within_2e_9(a, force, t):
    """Heavy strikers accumulate more rounding over 5000 intervals (measured 1.04e-9 at
    alpha = 42.5, t = 6778 and 5.5e-10 at alpha = 100, t = 1e4)."""
    assert abs(displacement(t, a, force) - modal_displacement(t, a, force)[0]) < 2e-9


@pytest.mark.parametrize(
    ("a", "force"), [(2.0, 0.5), (0.5, 1.0), (0.05, 1.5), (10.0, 0.2), (0.01, 0.3)]
)
def test_displacement_far_out_equals_the_modal_expansion(a, force):
    t = np.array([501.3, 2001.7, 7777.7, 9999.9, 1e4])
    y = displacement(t, a, force)
    assert np.max(np.abs(y - modal_displacement(t, a, force))) < 1e-9
    # energy: |y - f| <= sqrt(alpha + f^2)
    assert np.all(np.abs(y - force) <= math.sqrt(a + force**2) + 1e-9)


@pytest.mark.parametrize(("a", "force"), [(2.0, 0.5), (0.3, 1.2)])
def test_contact_force_far_out_satisfies_newton_against_the_modal_displacement(a, force):
    t0, h = 9990.0 + 1.0, 0.5  # inside one reflection interval
    nodes, weights = np.polynomial.legendre.leggauss(40)
    s = h * (nodes + 1) / 2  # s in [0, h]
    N = contact_force(np.r_[t0 + s, t0 - s], a, force)
    kernel = np.r_[(h - s), (h - s)] * np.r_[weights, weights] * h / 2
    rhs = np.sum(kernel * (force - N)) / a
    y = modal_displacement(np.array([t0 - h, t0, t0 + h]), a, force)
    lhs = y[0] - 2 * y[1] + y[2]
    assert abs(lhs - rhs) < 5e-10  # four y values, each within ~1e-10; N within ~1e-9


def test_far_out_beyond_the_limit_is_refused_with_the_limit_named():
    with pytest.raises(ValueError, match=r"t must be <= 10000 .* got t = 1e\+300"):
        displacement(1e300, 2.0, 0.5)
    with pytest.raises(ValueError, match="t must be <= 20 for a finite kappa"):
        contact_force(100.0, 2.0, 0.5, kappa=10.0)
    namespace: dict = {}
    exec(numpy_source(), namespace)
    assert namespace["rod_displacement"](1e4, 2.0, 0.5) == displacement(1e4, 2.0, 0.5)
    with pytest.raises(ValueError, match="t must be <= 10000"):
        namespace["rod_displacement"](2e4, 2.0, 0.5)


# ------------------------------------------------------------------ atlases


def test_atlas_marks_reflection_intervals_and_stays_small_as_pdf(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from impactsym.plotting.rod import plot_contact_time_atlases
    from impactsym.rod import contact_time_map

    study = contact_time_map(np.geomspace(0.05, 10.0, 120), np.linspace(0.0, 2.0, 120))
    interval = study.interval(condition="position")
    finite = np.isfinite(study.position)
    assert np.array_equal(np.isnan(interval), ~finite)
    assert np.all(2 * interval[finite] <= study.position[finite])
    assert np.all(study.position[finite] < 2 * interval[finite] + 2)
    assert {1.0, 2.0, 3.0} <= set(np.unique(interval[finite]).tolist())
    axes = plot_contact_time_atlases(study)
    meshes = [c for ax in axes for c in ax.collections if type(c).__name__ == "QuadMesh"]
    assert meshes
    assert all(m.get_rasterized() for m in meshes)
    labels = {t.get_text() for t in axes[1].texts}
    assert {"1st", "2nd"} <= labels
    path = tmp_path / "atlas.pdf"
    axes[0].figure.savefig(path, dpi=150)
    plt.close(axes[0].figure)
    assert path.stat().st_size < 1_000_000


def test_extreme_kappa_gives_the_rigid_limit_or_a_clear_refusal():
    # the small root of alpha s^2 + alpha kappa s + kappa without cancellation
    assert abs(displacement(5.3, 1.0, 0.5, kappa=1e300) - displacement(5.3, 1.0, 0.5)) < 1e-12
    with pytest.raises(ValueError, match=r"kappa = 1e\+300 .* too stiff"):
        contact_time(1.0, 0.5, kappa=1e300)
