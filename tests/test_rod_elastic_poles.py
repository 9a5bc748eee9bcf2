"""The pole sums of a finite contact stiffness (:mod:`impactsym.rod.elastic.poles`, behind
``displacement``/``contact_force`` with ``kappa``): against the exact inverted series
terms at 60 digits, across critical contact damping, and towards rigid contact."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from impactsym.rod import (
    RodImpact,
    contact_force,
    displacement,
)

t = RodImpact.t
alpha, f = RodImpact.alpha, RodImpact.f
kappa = sp.Symbol("kappa", positive=True)


@pytest.fixture(scope="module")
def elastic() -> RodImpact:
    return RodImpact(kappa)


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
