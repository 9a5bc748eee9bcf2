"""The rigid-contact kernel (:mod:`impactsym.rod.kernel`) far out: against the exact
inverted series terms at 60 digits and an independent modal expansion, up to its limit
``T_LIMIT`` and refused beyond."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from impactsym.rod import (
    RodImpact,
    contact_force,
    displacement,
    numpy_source,
)

t = RodImpact.t
alpha, f = RodImpact.alpha, RodImpact.f


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
