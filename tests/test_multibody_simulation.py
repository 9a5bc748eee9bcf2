"""The full penalty simulation of ``impactsym reproduce``, :mod:`impactsym.multibody.simulation`,
against SciPy's ``solve_ivp`` with event location on independently built models."""

from __future__ import annotations

import numpy as np
import pytest
from references.multibody_systems import FullSimulation, bar_system, pendulum_kane

from impactsym.multibody.simulation import double_pendulum, falling_bar, simulate_contact


@pytest.mark.parametrize(
    ("model", "example"), [(bar_system, falling_bar), (pendulum_kane, double_pendulum)]
)
def test_numpy_simulation_of_reproduce_matches_scipy(model, example):
    sim, ex = FullSimulation(model()), example()
    m_eff = ex.reduce().m_eff
    omega = np.array([300.0, 1000.0, 300.0])
    k, d, speed = m_eff * omega**2, 2 * np.array([0.1, 0.05, 0.2]) * m_eff * omega, 0.4
    for condition in ("position", "force"):
        ours = simulate_contact(ex, k, d, speed, condition=condition)
        for i in range(k.size):
            t_ref = sim.contact_time(k[i], d[i], speed, condition, 40 / omega[i])
            assert ours.contact_time[i] == pytest.approx(t_ref, rel=1e-7)
