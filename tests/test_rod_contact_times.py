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

import math
import time

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.polynomial import chebyshev as cheb
from references.rod_characteristics import Characteristics
from scipy.optimize import brentq

from impactsym.rod import contact_force, contact_time, displacement

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
    assert contact_time(0.05, 2.0, condition="force") == math.inf
    # with f = 0 the light striker always releases, on the first reflection interval
    assert 2.0 < contact_time(0.05, 0.0, condition="force") < 4.0
    tc = contact_time(0.5767450137140747, 14 / 13, condition="force")
    assert contact_time(0.5767450137140747, 14 / 13, t_max=tc - 1e-6, condition="force") == math.inf
    assert contact_time(0.5767450137140747, 14 / 13, t_max=tc + 1e-6, condition="force") == tc


def test_contact_time_limits_are_refused_with_the_limit_named():
    with pytest.raises(ValueError, match="t_max must be <= 10000"):
        contact_time(1.0, 0.5, t_max=2e4, condition="force")
    with pytest.raises(ValueError, match="t_max must be <= 20 for finite kappa"):
        contact_time(1.0, 0.5, kappa=10.0, t_max=100.0, condition="force")
    with pytest.raises(TypeError):
        contact_time(1.0, 0.5, "force")  # condition is keyword-only


def test_finite_stiffness_contact_time_is_a_sign_change_and_fast():
    start = time.perf_counter()
    tc = contact_time(np.array([1.0, 1.0, 3.0]), 0.2, kappa=50.0, condition="force")
    elapsed = time.perf_counter() - start
    for t, a in zip(tc, (1.0, 1.0, 3.0), strict=True):
        assert contact_force(t - 1e-7, a, 0.2, kappa=50.0) > 0
        assert contact_force(t + 1e-7, a, 0.2, kappa=50.0) < 0
    assert elapsed < 30.0
    assert (
        abs(
            contact_time(3.0, 0.0, kappa=1e5, condition="force")
            - contact_time(3.0, 0.0, condition="force")
        )
        < 1e-4
    )


# ------------------------------------------------------------------ far out


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
        contact_time(1.0, 0.5, kappa=1e300, condition="force")


@pytest.mark.parametrize("a", [0.05, 0.5, 1.0, 1.5])
def test_contact_time_of_the_classical_rigid_striker(a):
    # f = 0: N = e^{-t/a} + 2 e^{-(t-2)/a} (1 - (t-2)/a) on (2, 4)
    expected = 2 + a * (1 + math.exp(-2 / a) / 2)
    assert abs(contact_time(a, 0.0, condition="force") - expected) < 1e-12


def test_position_contact_time_of_the_classical_rigid_striker():
    a = 0.5  # y = a(1 - e^{-t/a}) - 2a + (2a + 2u) e^{-u/a}, u = t - 2, on (2, 4)

    def y(T: float) -> float:
        u = T - 2
        return a * (1 - math.exp(-T / a)) - 2 * a + (2 * a + 2 * u) * math.exp(-u / a)

    expected = brentq(y, 2.0, 4.0, xtol=1e-15)
    assert abs(contact_time(a, 0.0, condition="position") - expected) < 1e-12


def _dense_times(t_end: float) -> np.ndarray:
    """Uniform samples plus very fine ones right after every reflection, where the
    force oscillates on the time scale alpha / (number of reflections)."""
    after = (2.0 * np.arange(int(t_end // 2) + 1))[:, None] + np.linspace(0, 0.2, 4001)
    tt = np.r_[np.linspace(1e-9, t_end, 100_001), after.ravel()]
    return np.sort(tt[(tt > 0) & (tt <= t_end)])


def test_sticking_gives_infinity_and_is_real():
    assert contact_time(0.05, 2.0, condition="force") == math.inf
    assert np.all(contact_force(_dense_times(100.0), 0.05, 2.0) > 0)


def test_release_in_a_fast_transient_after_many_reflections_is_found():
    # alpha = 0.05, f = 1: N dips below zero for ~2e-3 just after the 23rd reflection
    tc = contact_time(0.05, 1.0, condition="force")
    assert 46.0 < tc < 46.006
    assert abs(contact_force(tc, 0.05, 1.0)) < 1e-9
    tt = _dense_times(tc)
    assert np.all(contact_force(tt[tt < tc - 1e-9], 0.05, 1.0) > 0)


def test_contact_time_is_a_zero_of_the_right_quantity():
    a = np.array([0.3, 2.0, 20.0])
    force = np.array([0.3, 0.8, 1.6])
    for condition, fn in (("force", contact_force), ("position", displacement)):
        tc = contact_time(a, force, condition=condition)
        assert tc.shape == (3,)
        assert np.all(np.isfinite(tc))
        assert np.all(np.abs(fn(tc, a, force)) < 1e-9)
        for ti, ai, fi in zip(tc, a, force, strict=True):  # first crossing: positive before
            assert np.all(fn(np.linspace(1e-9, ti - 1e-6, 2000), ai, fi) > 0)


def test_contact_time_with_finite_stiffness():
    tc = contact_time(1.0, 0.2, kappa=50.0, condition="force")
    assert 2.0 < tc < 20.0
    assert abs(contact_force(tc, 1.0, 0.2, kappa=50.0)) < 1e-9
    # a stiff spring releases close to the rigid striker ...
    assert (
        abs(
            contact_time(3.0, 0.0, kappa=1e5, condition="force")
            - contact_time(3.0, 0.0, condition="force")
        )
        < 1e-4
    )
    assert (
        abs(
            contact_time(1.0, 0.2, condition="position", kappa=1e5)
            - contact_time(1.0, 0.2, condition="position")
        )
        < 1e-4
    )
    # ... but not always under the force condition: when a reflection returns, the
    # spring force first dips (by about 0.15, for a time ~ 1/kappa) before it rises
    # by 2; if N is small just before, the spring releases there (non-uniform limit)
    for k in (1e3, 1e5):
        assert 4.0 < contact_time(1.0, 0.2, kappa=k, condition="force") < 4.0 + 1.0 / k
    assert contact_time(1.0, 0.2, condition="force") > 4.4


def test_heavy_striker_conditions_almost_coincide_and_force_spreads_them():
    """The paper's observation: large alpha, small f: the two contact times nearly
    coincide; growing f makes them differ strongly (small alpha)."""
    heavy = contact_time(50.0, 0.0, condition="position") / contact_time(
        50.0, 0.0, condition="force"
    )
    assert abs(heavy - 1) < 0.05
    light = contact_time(0.1, 1.2, condition="position") / contact_time(0.1, 1.2, condition="force")
    assert light < 0.5


def test_contact_time_broadcasts():
    tc = contact_time(np.array([[0.5], [2.0]]), np.array([0.0, 0.3, 0.6]), condition="force")
    assert tc.shape == (2, 3)
    assert tc[0, 0] == contact_time(0.5, 0.0, condition="force")


def test_contact_time_rejects_bad_input():
    with pytest.raises(ValueError, match="condition"):
        contact_time(1.0, 0.5, condition="pressure")
    with pytest.raises(ValueError, match="alpha"):
        contact_time(-1.0, 0.5, condition="force")
    with pytest.raises(ValueError, match="kappa"):
        contact_time(1.0, 0.5, kappa=-2.0, condition="force")
    with pytest.raises(ValueError, match="t_max"):
        contact_time(1.0, 0.5, t_max=0.0, condition="force")
    with pytest.raises(TypeError, match="alpha"):
        contact_time("heavy", 0.5, condition="force")


def test_contact_time_maps_compare_by_value_and_hash():
    """== raised on the arrays (truth value ambiguous), hash on them (unhashable): now
    maps compare by value, inf equal to inf, and equal maps hash alike."""
    from impactsym.rod import contact_time_map

    a, b = contact_time_map([0.1, 0.5], [0.0, 2.0]), contact_time_map([0.1, 0.5], [0.0, 2.0])
    assert np.isinf(a.force).any()
    assert a == b
    assert hash(a) == hash(b)
    assert len({a, b}) == 1
    assert a != contact_time_map([0.1, 0.6], [0.0, 2.0])
    assert a != contact_time_map([0.1, 0.5], [0.0])  # other shape: unequal, no error
    assert a != "a map"
