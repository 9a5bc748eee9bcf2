"""The full penalty simulation of ``impactsym reproduce``, :mod:`impactsym.multibody.simulation`,
against SciPy's ``solve_ivp`` with event location on independently built models."""

from __future__ import annotations

import numpy as np
import pytest
from references.multibody_systems import FullSimulation, bar_system, pendulum_kane

from impactsym.multibody.simulation import (
    agreement_sweep,
    double_pendulum,
    falling_bar,
    simulate_contact,
)


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
            t_ref, e_ref = sim.contact(k[i], d[i], speed, condition, 40 / omega[i])
            assert ours.contact_time[i] == pytest.approx(t_ref, rel=1e-7)
            assert ours.restitution[i] == pytest.approx(e_ref, rel=1e-6, abs=1e-9)
        assert np.array_equal(ours.sticks, ~np.isfinite(ours.contact_time))


def test_sticking_beyond_the_horizon_matches_scipy():
    # heavily damped and pressed: no release within t_max / omega in either simulation
    sim, ex = FullSimulation(bar_system()), falling_bar()
    m_eff = ex.reduce().m_eff
    omega = 300.0
    k, d = m_eff * omega**2, 2 * 5.0 * m_eff * omega
    ours = simulate_contact(ex, k, d, 0.01, condition="position", t_max=10.0)
    assert sim.contact(k, d, 0.01, "position", 10.0 / omega) == (np.inf, 0.0)
    assert (float(ours.contact_time), float(ours.restitution)) == (np.inf, 0.0)
    assert bool(ours.sticks)


def test_former_horizon_name_tau_max_is_accepted():
    ex = falling_bar()
    m_eff = ex.reduce().m_eff
    k, d = m_eff * 300.0**2, 2 * 0.1 * m_eff * 300.0
    new = simulate_contact(ex, k, d, 0.4, t_max=25.0, steps=20, condition="force")
    old = simulate_contact(ex, k, d, 0.4, tau_max=25.0, steps=20, condition="force")
    assert (new.contact_time, new.restitution) == (old.contact_time, old.restitution)
    with pytest.raises(TypeError, match="tau_max"):
        simulate_contact(ex, k, d, 0.4, t_max=25.0, tau_max=30.0, condition="force")
    grid = {"omegas": (1000.0,), "dampings": (0.1,), "forces": (0.5,), "steps": 20}
    sweep = agreement_sweep(double_pendulum(), tau_max=25.0, **grid)
    assert sweep.t_max == sweep.tau_max == 25.0
    assert agreement_sweep(double_pendulum(), t_max=25.0, **grid).summary() == sweep.summary()
