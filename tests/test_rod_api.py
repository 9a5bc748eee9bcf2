"""The rod's public time functions :func:`impactsym.rod.displacement` and
:func:`impactsym.rod.contact_force` (:mod:`impactsym.rod.api`, paper section 1): against the
method of characteristics, numerical inverse Laplace transforms, closed forms and Newton's
law; bad input refused by name."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
from conftest import CODE
from hypothesis import given, settings
from hypothesis import strategies as st
from references.rod_characteristics import Characteristics

from impactsym.rod import contact_force, contact_time, displacement


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


def test_time_functions_are_zero_before_impact_and_keep_shapes():
    assert displacement(-0.5, 1.0, 0.3) == 0.0
    assert contact_force(-0.5, 1.0, 0.3, kappa=10.0) == 0.0
    assert isinstance(contact_force(1.0, 1.0, 0.3), float)
    assert contact_force(np.zeros((2, 3)), np.ones(3), 0.2).shape == (2, 3)


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize("function", [displacement, contact_force])
@pytest.mark.parametrize(
    ("args", "pattern"),
    [
        ((math.nan, 1.0, 0.0), "^t must be finite"),
        ((1.0, 0.0, 0.0), "^alpha must be > 0"),
        ((1.0, 1.0, -1.0), "^f must be >= 0"),
        ((CODE, 1.0, 0.0), "^t must be a real number"),
        ((1.0, True, 0.0), "^alpha must be a real number"),
    ],
)
def test_rod_functions_name_the_bad_argument(function, args, pattern):
    with pytest.raises((ValueError, TypeError), match=pattern):
        function(*args)


def test_rod_functions_name_mismatched_shapes():
    with pytest.raises(ValueError, match=r"^t \(shape \(2,\)\) and alpha \(shape \(3,\)\)"):
        displacement(np.zeros(2), np.ones(3), 0.0)
    with pytest.raises(ValueError, match=r"^alpha \(shape \(2,\)\) and f \(shape \(3,\)\)"):
        contact_time(np.ones(2), np.zeros(3), condition="force")


@pytest.mark.parametrize("alpha", [1e-300, 1e-12, 2e6, 1e16, 1e300])
def test_rod_mass_ratios_outside_the_verified_range_are_refused(alpha):
    # a heavy striker's Laguerre sums cancel (alpha = 1e16 gave y(4) = 4.44 > t), a very
    # light one's recurrences overflow (NaN) or its certified search runs out of cells
    for call in (
        lambda: displacement(4.0, alpha, 0.0),
        lambda: contact_force(4.0, alpha, 0.0),
        lambda: contact_time(alpha, 0.0, condition="position"),
    ):
        with pytest.raises(ValueError, match=r"^alpha must lie in \[1e-10, 1e\+06\]"):
            call()


@pytest.mark.parametrize("alpha", [1e-10, 1e6])
def test_rod_mass_ratios_at_the_ends_of_the_range_are_exact(alpha):
    # before the first reflection alpha y'' + y' = f, y(0) = 0, y'(0) = 1 (closed form)
    t = np.array([0.5, 1.0, 1.9])
    exact = [float(0.3 * s + 0.7 * alpha * -mp.expm1(-mp.mpf(s) / alpha)) for s in t]
    assert np.max(np.abs(displacement(t, alpha, 0.3) - exact)) < 1e-12
