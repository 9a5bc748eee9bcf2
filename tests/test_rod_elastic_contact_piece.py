"""Tests of :mod:`impactsym.rod.elastic.contact_piece`: the contact force of one piece
solves :math:`\\alpha N'' + \\alpha\\kappa N' + \\kappa N = \\kappa f + 2\\alpha\\kappa G'`,
checked by the residual of that equation in mpmath (40 digits) at random points, an
independent check of the recurrences."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from impactsym.rod.elastic.contact_piece import confluent_series, forced_split
from impactsym.rod.sequence_elastic import _rates


def exp_poly(rates, Q, x, order):
    """The ``order``-th derivative of :math:`\\sum_r e^{rx} Q_r(x)` in mpmath."""
    return mp.diff(
        lambda s: sum(
            mp.exp(complex(r).real * s) * mp.polyval([mp.mpf(c.real) for c in q[::-1]], s)
            for r, q in zip(rates, Q, strict=True)
        ),
        x,
        order,
    )


def residual(alpha, kappa, f, rates_N, QN, rates_G, QG, x, constant):
    """Residual of the contact equation, relative to the size of its terms."""
    N = [exp_poly(rates_N, QN, x, k) for k in range(3)]
    N[0] += constant
    dG = exp_poly(rates_G, QG, x, 1)
    lhs = alpha * N[2] + alpha * kappa * N[1] + kappa * N[0]
    rhs = kappa * f + 2 * alpha * kappa * dG
    size = abs(alpha * N[2]) + abs(alpha * kappa * N[1]) + abs(kappa * N[0]) + abs(rhs)
    return float(abs(lhs - rhs) / max(size, 1))


@pytest.mark.parametrize(("alpha", "kappa"), [(1.0, 100.0), (0.45, 100.0), (0.5, 2e3)])
def test_split_particular_solution_solves_the_equation(alpha, kappa):
    """Stiff contact: the per-rate particular solution with M_r(0) = 0."""
    rates, d = _rates(alpha, kappa)
    assert d is None
    rng = np.random.default_rng(1)
    Qi = rng.normal(size=(2, 5)).astype(complex)
    M, dM0 = forced_split(Qi, rates, alpha=alpha, kappa=kappa)
    assert np.all(M[:, 0] == 0.0)
    assert dM0 == pytest.approx(float(M[:, 1].sum().real))
    with mp.workdps(40):
        for x in rng.uniform(0.0, 2.0 / abs(rates[1].real), 4):
            assert residual(alpha, kappa, 0.0, rates, M, rates, Qi, mp.mpf(x), 0) < 1e-13


@pytest.mark.parametrize(("alpha", "kappa"), [(0.4508, 10.0), (1.0, 4.0), (0.45, 100.0)])
def test_confluent_series_solves_the_equation_and_meets_the_start(alpha, kappa):
    """Confluent form (also forced on a stiff contact, the fallback): N = f + e^{sigma x}
    M(x) with N(0) = f + A0, N'(0) = dN, on a piece of the confluent length."""
    rates, d = _rates(alpha, kappa, True)
    sigma = rates[0]
    h = 2.0 / np.sqrt(0.25 * kappa * kappa + abs(d))
    rng = np.random.default_rng(2)
    Qi = rng.normal(size=(1, 4)).astype(complex)
    f, A0, dN = 0.7, -0.3, 2.5
    M = confluent_series(Qi, sigma, d, kappa=kappa, h=h, A0=A0, dN=dN, where="w", t=0.0)
    with mp.workdps(40):
        assert abs(exp_poly(rates, M, mp.mpf(0), 0) - A0) < 1e-15
        assert abs(exp_poly(rates, M, mp.mpf(0), 1) - dN) < 1e-13 * abs(kappa)
        for x in rng.uniform(0.0, h, 4):
            assert residual(alpha, kappa, f, rates, M, rates, Qi, mp.mpf(x), f) < 1e-13
