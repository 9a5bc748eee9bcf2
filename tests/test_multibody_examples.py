"""The example systems of the multibody analysis, :mod:`impactsym.multibody.examples`,
against closed forms and the same systems written with ``sympy.physics.mechanics``
(:mod:`references.multibody_systems`)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from references.multibody_systems import bar_system, pendulum_kane

from impactsym.multibody import examples as examples_module
from impactsym.multibody.examples import double_pendulum, examples, falling_bar


@pytest.mark.parametrize("angle", [0.2, np.pi / 6, 1.0, 1.4])
@pytest.mark.parametrize("mass", [0.5, 3.0])
def test_bar_effective_mass_is_the_impulse_momentum_closed_form(angle, mass):
    bar = falling_bar(mass=mass, angle=angle)
    assert bar.reduce().m_eff == pytest.approx(mass / (1 + 3 * np.cos(angle) ** 2), rel=1e-12)


@pytest.mark.parametrize(
    ("model", "example"), [(bar_system, falling_bar), (pendulum_kane, double_pendulum)]
)
def test_examples_match_the_mechanics_models_at_the_impact_state(model, example):
    # mass matrix, forces and gap of the hand-written matrices equal those that
    # sympy.physics.mechanics derives for the same system, at the impact state
    mod, ex = model(), example()
    method = mod.model.eom_method if hasattr(mod.model, "eom_method") else mod.model
    kin = method.kindiffdict()
    speed = 0.7
    ours = dict(zip(ex.q, ex.q0, strict=True)) | {
        u: speed * c for u, c in zip(ex.qd, ex.direction, strict=True)
    }
    theirs = mod.at(speed)
    M_ours = np.array(ex.M.subs(ours), dtype=float)
    M_ref = np.array(method.mass_matrix.xreplace(kin).subs(theirs), dtype=float)
    F_ours = np.array(ex.F.subs(ours), dtype=float).ravel()
    F_ref = np.array(method.forcing.xreplace(kin).subs(theirs), dtype=float).ravel()
    np.testing.assert_allclose(M_ours, M_ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(F_ours, F_ref, rtol=1e-12, atol=1e-12)
    assert abs(float(ex.g.subs(ours))) < 1e-12
    assert abs(float(mod.g.subs(theirs))) < 1e-12


def test_impact_state_and_registry():
    bar = falling_bar()
    state = bar.at(2.0)
    assert state[sp.Symbol("v_y")] == -2.0
    assert state[sp.Symbol("theta")] == pytest.approx(np.pi / 6)
    assert [e.name for e in examples()] == ["bar", "pendulum"]
    from impactsym.multibody import simulation

    assert simulation.falling_bar is examples_module.falling_bar  # former home, still importable
