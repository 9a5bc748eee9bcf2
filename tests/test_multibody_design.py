"""Penalty design (paper section 3), :mod:`impactsym.multibody.design`: the stick damping
``d*(k)``, damping for a wanted restitution and ``(k, d)`` for wanted targets, checked in
the reduced model and in the full nonlinear SciPy simulation."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import sympy as sp
from references.multibody_systems import FullSimulation, bar_system, reduced_oscillator

from impactsym.multibody.design import damping_for_restitution, penalty_for_targets, stick_damping
from impactsym.multibody.reduction import reduce_contact
from impactsym.multibody.simulation import falling_bar

x, v = sp.symbols("x v")
m, k, d = sp.symbols("m k d", positive=True)


def particle(M=1.0, force=0.0, kk=1.0, dd=0.0, speed=1.0):
    """A single particle pressed by ``force``: the section-2 oscillator itself."""
    return reduce_contact(
        sp.Matrix([[M]]), sp.Matrix([force]), x, [x], [v], {x: 0, v: speed}, kk, dd
    )


@pytest.mark.parametrize("condition", ["position", "force"])
def test_stick_damping_separates_release_from_sticking(condition):
    bar = falling_bar().reduce(1.0, 0.0, 0.2)
    k = np.array([1e4, 1e5, 1e6])
    d_star = stick_damping(bar, k, condition=condition)
    assert np.all(np.diff(d_star) > 0)
    assert not np.any(bar.with_penalty(k, 0.99 * d_star).sticks(condition))
    assert np.all(bar.with_penalty(k, 1.01 * d_star).sticks(condition))


def test_stick_damping_holds_in_the_full_simulation():
    sim, ex = FullSimulation(bar_system()), falling_bar()
    kk, speed = 1e5, 0.2
    omega = np.sqrt(kk / ex.reduce().m_eff)
    for condition in ("position", "force"):
        d_star = stick_damping(ex.reduce(1.0, 0.0, speed), kk, condition=condition)
        assert sim.contact_time(kk, 0.8 * d_star, speed, condition, 40 / omega) < np.inf
        assert sim.contact_time(kk, 1.25 * d_star, speed, condition, 40 / omega) == np.inf


def test_unloaded_particle_never_sticks_under_the_force_condition():
    assert stick_damping(particle(), 1.0, condition="force") == np.inf
    assert stick_damping(particle(M=4.0), 9.0, condition="position") == pytest.approx(
        12.0, rel=1e-12
    )


def test_penalty_for_targets_delivers_in_the_full_simulation():
    ex = falling_bar()
    reduced = ex.reduce(1.0, 0.0, 0.5)
    kk, dd = penalty_for_targets(reduced, restitution=0.5, contact_time=2e-3, condition="force")
    design = reduced.with_penalty(kk, dd)
    assert design.restitution("force") == pytest.approx(0.5, rel=1e-9)
    assert design.contact_time("force") == pytest.approx(2e-3, rel=1e-9)
    assert dd == pytest.approx(
        damping_for_restitution(reduced, kk, 0.5, condition="force"), rel=1e-9
    )
    sim = FullSimulation(bar_system())
    t_full, e_full = sim.contact(kk, dd, 0.5, "force", 40 / np.sqrt(kk / ex.reduce().m_eff))
    assert t_full == pytest.approx(2e-3, rel=0.02)
    assert e_full == pytest.approx(0.5, rel=0.02)


def test_design_bad_input_is_refused():
    symbolic = reduce_contact(sp.Matrix([[m]]), [0], x, [x], [v], {x: 0, v: 1}, k, d)
    with pytest.raises(TypeError, match="symbolic"):
        stick_damping(symbolic, 1.0, condition="force")
    with pytest.raises(TypeError, match="reduced must be a ReducedContact"):
        stick_damping({"m_eff": 1.0}, 1.0, condition="force")
    with pytest.raises(ValueError, match=r"restitution must be a number in \(0, 1\)"):
        damping_for_restitution(particle(), 1.0, 1.5, condition="force")
    own_damper = reduce_contact(sp.Matrix([[1.0]]), [-1.0 * v], x, [x], [v], {x: 0, v: 1}, 1, 0)
    with pytest.raises(ValueError, match="not reachable"):  # d~ >= 1 > 0.5 sqrt(k m) already
        damping_for_restitution(own_damper, 1.0, 0.9, condition="position")
    with pytest.raises(ValueError, match="^k must"):
        stick_damping(particle(), -1.0, condition="force")
    with pytest.raises(ValueError, match="^condition must"):
        stick_damping(particle(), 1.0, condition="gap")
    with pytest.raises(ValueError, match="^contact_time must"):
        penalty_for_targets(particle(), restitution=0.5, contact_time=0.0, condition="force")


def _attempt(call):
    """``(value, None)``, or ``(None, error)`` for a ``ValueError``."""
    try:
        return call(), None
    except ValueError as exc:
        return None, exc


@pytest.mark.parametrize("k", [1e-300, 1e300, 1e-30])
def test_penalty_design_errors_name_the_input(k):
    r = particle(force=0.1)
    for call in (
        lambda: stick_damping(r, k, condition="force"),
        lambda: damping_for_restitution(r, k, 0.5, condition="force"),
    ):
        value, error = _attempt(call)
        if error is not None:
            assert f"k = {k!r}" in str(error)
        else:
            assert np.isfinite(value)


@pytest.mark.parametrize("contact_time", [1e-300, 1e300, 1e30])
def test_penalty_for_targets_refuses_extreme_contact_times_by_name(contact_time):
    with pytest.raises(ValueError, match=re.escape(f"contact_time = {contact_time!r}")):
        penalty_for_targets(
            particle(force=0.1), restitution=0.5, contact_time=contact_time, condition="force"
        )


@pytest.mark.parametrize(
    "bad", [math.nan, -1.0, 0.0, 1.0, "__import__('os').system('touch PWNED')"]
)
def test_penalty_design_targets_are_validated(bad, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises((ValueError, TypeError), match="^restitution "):
        damping_for_restitution(particle(force=0.1), 1.0, bad, condition="force")
    assert not (tmp_path / "PWNED").exists(), "a string input was run as code"


def reduced_oscillator_releases(r, condition):
    """Whether ``m~ z'' + d~ z' + c~ z = F_n`` from ``z = 0, z' = v0`` reaches the end of
    contact (SciPy ``solve_ivp`` with events, independent of the section-2 closed forms)."""
    sol = reduced_oscillator(r, condition, 60.0 / r.omega0, atol=1e-15 * r.v0 / r.omega0)
    return sol.t_events[0].size > 0


@pytest.mark.parametrize("condition", ["position", "force"])
def test_stick_damping_separates_release_from_sticking_in_an_ode_integration(condition):
    bar = falling_bar().reduce(1.0, 0.0, 0.2)
    for kk in (1e4, 1e5, 1e6):
        d_star = float(stick_damping(bar, kk, condition=condition))
        assert reduced_oscillator_releases(bar.with_penalty(kk, 0.99 * d_star), condition)
        assert not reduced_oscillator_releases(bar.with_penalty(kk, 1.01 * d_star), condition)
