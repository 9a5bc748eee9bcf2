"""The rod impact's time functions, contact times and generated NumPy module (paper
section 1), :mod:`impactsym.rod`; the derivation is tested in ``test_rod_derivation.py``."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from references.rod_characteristics import Characteristics
from scipy.optimize import brentq

from impactsym.rod import (
    RodImpact,
    contact_force,
    contact_time,
    displacement,
    numpy_source,
)

t = RodImpact.t
alpha, f = RodImpact.alpha, RodImpact.f
kappa = sp.Symbol("kappa", positive=True)


@pytest.fixture(scope="module")
def elastic() -> RodImpact:
    return RodImpact(kappa)


# --------------------------------------------------------------- time functions


@pytest.mark.parametrize("a", [0.05, 0.7, 50.0])
def test_classical_rigid_striker_before_the_first_reflection(a):
    tt = np.linspace(0.0, 1.999, 50)
    assert np.allclose(contact_force(tt, a, 0.0), np.exp(-tt / a), rtol=0, atol=1e-14)
    assert np.allclose(displacement(tt, a, 0.0), a * (1 - np.exp(-tt / a)), rtol=0, atol=1e-14)
    assert contact_force(0.0, a, 0.0) == 1.0  # the impact force of a rigid striker


def test_contact_force_jumps_by_two_when_a_reflection_returns():
    for k in (1, 2, 7, 30):
        left = contact_force(np.nextafter(2.0 * k, 0), 1.3, 0.4)
        right = contact_force(2.0 * k, 1.3, 0.4)
        assert abs(right - left - 2.0) < 1e-10


@pytest.mark.parametrize("a", [0.05, 1.0, 50.0])
@pytest.mark.parametrize("force", [0.0, 0.7, 5.0])
def test_agrees_with_the_method_of_characteristics_up_to_t_100(a, force):
    reference = Characteristics(a, force, 51)
    tt = np.sort(np.random.default_rng(3).uniform(0, 100, 150))
    assert np.max(np.abs(reference.N(tt) - contact_force(tt, a, force))) < 1e-9
    assert np.max(np.abs(reference.y(tt) - displacement(tt, a, force))) < 1e-9


def _dehoog(F, T):
    with mp.workdps(30):
        return float(mp.invertlaplace(F, T, method="dehoog", degree=100))


@pytest.mark.parametrize(
    ("a", "force", "k"), [(0.7, 0.4, math.inf), (2.0, 1.5, 3.0), (1.0, 0.0, 4.0)]
)
def test_agrees_with_numerical_inverse_laplace_up_to_t_5(a, force, k):
    """de Hoog (100 terms) on the closed forms; reliable only up to t = 5."""
    if math.isinf(k):
        den = lambda x: mp.cosh(x) + a * x * mp.sinh(x)  # noqa: E731
        N = lambda x: (a * x + force) * mp.cosh(x) / (x * den(x))  # noqa: E731
    else:
        den = lambda x: (a * x**2 + k) * mp.cosh(x) + a * k * x * mp.sinh(x)  # noqa: E731
        N = lambda x: k * (a * x + force) * mp.cosh(x) / (x * den(x))  # noqa: E731
    Y = (lambda x: N(x) * mp.tanh(x) / x) if math.isinf(k) else None
    for T in (0.9, 4.7):  # before and after the first reflection
        assert abs(_dehoog(N, T) - contact_force(T, a, force, kappa=k)) < 1e-10
    if Y is not None:
        assert abs(_dehoog(Y, 4.1) - displacement(4.1, a, force)) < 1e-10


@pytest.fixture(scope="module")
def exact_rigid_terms():
    """Reference: the exact inverted terms evaluated with mpmath (> 30 correct digits)."""
    rod = RodImpact()
    return {
        name: [
            (int(d), sp.lambdify((t, alpha, f), g, "mpmath")) for d, g in rod.time_terms(name, 51)
        ]
        for name in ("Y", "N")
    }


def _exact(terms, T, a, force):
    # the expanded terms cancel ~20 digits for small alpha: 60 working digits
    with mp.workdps(60):
        x, a, force = mp.mpf(T), mp.mpf(a), mp.mpf(force)
        return float(mp.fsum(g(x - d, a, force) for d, g in terms if d <= x))


@pytest.mark.parametrize("a", [0.05, 1.0, 50.0])
def test_far_out_agrees_with_30_digit_exact_terms(exact_rigid_terms, a):
    for T in (37.3, 71.9, 99.7):
        for name, fn in (("Y", displacement), ("N", contact_force)):
            assert abs(_exact(exact_rigid_terms[name], T, a, 5.0) - fn(T, a, 5.0)) < 1e-10


@pytest.fixture(scope="module")
def exact_elastic_terms(elastic):
    return {
        name: [
            (int(d), sp.lambdify((t, alpha, f, kappa), g, "mpmath"))
            for d, g in elastic.time_terms(name, 11)
        ]
        for name in ("N",)
    }


@pytest.mark.parametrize(
    ("a", "k"), [(0.05, 1.0), (1.0, 3.999), (50.0, 2.0), (0.05, 1000.0), (1.0, 100.0)]
)
def test_finite_stiffness_agrees_with_exact_terms_for_ten_round_trips(exact_elastic_terms, a, k):
    terms = exact_elastic_terms["N"]
    for T in (1.7, 9.4, 19.9):
        with mp.workdps(60):
            x = mp.mpf(T)
            args = (mp.mpf(a), mp.mpf("0.6"), mp.mpf(k))
            exact = float(mp.re(mp.fsum(g(x - d, *args) for d, g in terms if d <= x)))
        assert abs(exact - contact_force(T, a, 0.6, kappa=k)) < 1e-10


def test_critical_contact_damping_is_continuous_in_kappa():
    # alpha kappa = 4: the two poles merge; the neighbours are evaluated apart
    tt = np.array([0.5, 3.1, 8.7, 15.2, 19.5])
    at = contact_force(tt, 1.0, 0.3, kappa=4.0)
    for dk in (1e-7, -1e-7):
        assert np.max(np.abs(contact_force(tt, 1.0, 0.3, kappa=4.0 + dk) - at)) < 1e-5


def test_finite_stiffness_tends_to_rigid_contact():
    tt = np.linspace(0.0, 20.0, 201)
    away = np.abs(tt / 2 - np.round(tt / 2)) > 0.1  # away from the jumps of the rigid N
    errors_y, errors_N = [], []
    for k in (1e2, 1e3, 1e4):
        errors_y.append(
            np.max(np.abs(displacement(tt, 0.8, 0.5, kappa=k) - displacement(tt, 0.8, 0.5)))
        )
        diff = contact_force(tt, 0.8, 0.5, kappa=k) - contact_force(tt, 0.8, 0.5)
        errors_N.append(np.max(np.abs(diff[away])))
    for errors in (errors_y, errors_N):
        assert errors[2] < errors[1] < errors[0]
        assert errors[1] / errors[2] > 5  # first order in 1/kappa
    assert errors_y[2] < 1e-3


@settings(max_examples=30, deadline=None)
@given(
    a=st.floats(0.05, 50.0),
    force=st.floats(0.0, 5.0),
    T=st.floats(0.05, 60.0).filter(lambda x: abs(x / 2 - round(x / 2)) > 0.01),
)
def test_striker_obeys_newton(a, force, T):
    """alpha y'' = f - N, by central differences away from the reflections."""
    # truncation ~ h^2 y^(4) / 12 with y^(4) ~ (m / alpha)^2 after m returns
    h = 1e-3 * min(1.0, a / math.sqrt(1 + T / 2))
    y = displacement(np.array([T - h, T, T + h]), a, force)
    acceleration = (y[0] - 2 * y[1] + y[2]) / h**2
    assert abs(a * acceleration - (force - contact_force(T, a, force))) < 1e-4 * (1 + force)


# ----------------------------------------------------------------- contact time


@pytest.mark.parametrize("a", [0.05, 0.5, 1.0, 1.5])
def test_contact_time_of_the_classical_rigid_striker(a):
    # f = 0: N = e^{-t/a} + 2 e^{-(t-2)/a} (1 - (t-2)/a) on (2, 4)
    expected = 2 + a * (1 + math.exp(-2 / a) / 2)
    assert abs(contact_time(a, 0.0) - expected) < 1e-12


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
    assert contact_time(0.05, 2.0) == math.inf
    assert np.all(contact_force(_dense_times(100.0), 0.05, 2.0) > 0)


def test_release_in_a_fast_transient_after_many_reflections_is_found():
    # alpha = 0.05, f = 1: N dips below zero for ~2e-3 just after the 23rd reflection
    tc = contact_time(0.05, 1.0)
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
    tc = contact_time(1.0, 0.2, kappa=50.0)
    assert 2.0 < tc < 20.0
    assert abs(contact_force(tc, 1.0, 0.2, kappa=50.0)) < 1e-9
    # a stiff spring releases close to the rigid striker ...
    assert abs(contact_time(3.0, 0.0, kappa=1e5) - contact_time(3.0, 0.0)) < 1e-4
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
        assert 4.0 < contact_time(1.0, 0.2, kappa=k) < 4.0 + 1.0 / k
    assert contact_time(1.0, 0.2) > 4.4


def test_heavy_striker_conditions_almost_coincide_and_force_spreads_them():
    """The paper's observation: large alpha, small f: the two contact times nearly
    coincide; growing f makes them differ strongly (small alpha)."""
    heavy = contact_time(50.0, 0.0, condition="position") / contact_time(50.0, 0.0)
    assert abs(heavy - 1) < 0.05
    light = contact_time(0.1, 1.2, condition="position") / contact_time(0.1, 1.2)
    assert light < 0.5


def test_contact_time_broadcasts():
    tc = contact_time(np.array([[0.5], [2.0]]), np.array([0.0, 0.3, 0.6]))
    assert tc.shape == (2, 3)
    assert tc[0, 0] == contact_time(0.5, 0.0)


# --------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"alpha": 0.0}, "alpha"),
        ({"alpha": -1.0}, "alpha"),
        ({"f": -0.1}, "f"),
        ({"kappa": 0.0}, "kappa"),
        ({"alpha": math.nan}, "alpha"),
        ({"f": math.inf}, "f"),
        ({"t": math.nan}, "t"),
    ],
)
def test_time_functions_reject_bad_input(kwargs, name):
    args = {"t": 1.0, "alpha": 1.0, "f": 0.5, "kappa": math.inf} | kwargs
    for fn in (displacement, contact_force):
        with pytest.raises(ValueError, match=name):
            fn(**args)


def test_contact_time_rejects_bad_input():
    with pytest.raises(ValueError, match="condition"):
        contact_time(1.0, 0.5, condition="pressure")
    with pytest.raises(ValueError, match="alpha"):
        contact_time(-1.0, 0.5)
    with pytest.raises(ValueError, match="kappa"):
        contact_time(1.0, 0.5, kappa=-2.0)
    with pytest.raises(ValueError, match="t_max"):
        contact_time(1.0, 0.5, t_max=0.0)
    with pytest.raises(TypeError, match="alpha"):
        contact_time("heavy", 0.5)


def test_time_functions_are_zero_before_impact_and_keep_shapes():
    assert displacement(-0.5, 1.0, 0.3) == 0.0
    assert contact_force(-0.5, 1.0, 0.3, kappa=10.0) == 0.0
    assert isinstance(contact_force(1.0, 1.0, 0.3), float)
    assert contact_force(np.zeros((2, 3)), np.ones(3), 0.2).shape == (2, 3)


# ------------------------------------------------------------- generated module


def test_numpy_source_runs_with_numpy_only_and_matches():
    source = numpy_source()
    for word in ("sympy", "mpmath", "impactsym", "scipy"):
        assert f"import {word}" not in source
        assert f"from {word}" not in source
    namespace: dict = {}
    exec(compile(source, "<rod_numpy>", "exec"), namespace)
    tt = np.linspace(-1.0, 100.0, 997)
    for a, force in ((0.05, 0.0), (1.0, 2.0), (50.0, 5.0)):
        assert np.array_equal(
            namespace["rod_displacement"](tt, a, force), displacement(tt, a, force)
        )
        assert np.array_equal(
            namespace["rod_contact_force"](tt, a, force), contact_force(tt, a, force)
        )
    assert "alpha" in namespace["rod_displacement"].__doc__
    with pytest.raises(ValueError, match="alpha"):
        namespace["rod_contact_force"](1.0, 0.0, 0.0)
