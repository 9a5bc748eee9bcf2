"""The flat-impedance continuous design (impactsym.engines.mujoco.flat_design): the designed
solref gives the targets in an independent integration of MuJoCo's contact law (SciPy's
solve_ivp with events on the force and the penetration), on the closed-form path
(gravity 0), the secant and Broyden paths (gravity) and the bracketed fallback; refusals
name the element of the caller's array."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactsym.engines.mujoco import solref_for
from impactsym.engines.mujoco.flat_design import design_flat_dampratio

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


def _ivp(solref, speed, gravity, *, d=0.9, rho=1.0):
    """Restitution and contact time of MuJoCo's flat contact law, integrated by SciPy.

    ``x'' = (1 - d') g - d' (b x' + d kbar x)`` from ``x = 0``, ``x' = v0``, until the
    force ``g + b x' + d kbar x`` or the penetration ``x`` reaches zero (MuJoCo's
    documentation, *Computation*; ``b = 2 / (d tc)``, ``kbar = 1 / (d tc dr)^2``).
    """
    tc, dr = solref
    b, kbar = 2.0 / (d * tc), 1.0 / (d * tc * dr) ** 2
    dp = d * rho / (d * rho + 1.0 - d)
    omega = np.sqrt(dp * d * kbar)

    def rhs(_, y):
        return [y[1], (1.0 - dp) * gravity - dp * (b * y[1] + d * kbar * y[0])]

    def force(_, y):
        return gravity + b * y[1] + d * kbar * y[0]

    def position(_, y):
        return y[0]

    for ev in (force, position):
        ev.terminal, ev.direction = True, -1
    sol = solve_ivp(
        rhs,
        (0.0, 1e4 / omega),
        [0.0, speed],
        method="DOP853",
        events=(force, position),
        rtol=1e-12,
        atol=1e-16 * speed / omega,
    )
    assert sol.status == 1, "no release within the horizon"
    times = [t[0] for t in sol.t_events if len(t)]
    end = min(times)
    state = sol.sol(end) if sol.sol is not None else sol.y[:, -1]
    return -state[1] / speed, end


def _check(design, targets, speeds, gravity, contact_time=None, rho=None):
    tc, dr = (np.atleast_1d(np.asarray(a, float)) for a in design.solref)
    for i in range(tc.size):
        e, t = _ivp(
            (tc[i], dr[i]),
            speeds[i],
            gravity[i],
            rho=1.0 if rho is None else rho[i],
        )
        assert e == pytest.approx(targets[i], rel=1e-7), i
        if contact_time is not None:
            assert t == pytest.approx(contact_time[i], rel=1e-7), i


def test_gravity_free_closed_form_design_is_the_integrated_contact():
    targets = np.array([0.01, 0.1, 0.1353352832366127, 0.5, 0.9, 0.99])  # e^-2: D = 1
    speeds = np.ones(targets.size)
    zero = np.zeros(targets.size)
    _check(solref_for(restitution=targets, speed=1.0, solimp=FLAT), targets, speeds, zero)
    t_c = np.geomspace(1e-3, 0.1, targets.size)
    design = solref_for(restitution=targets, speed=1.0, contact_time=t_c, solimp=FLAT)
    _check(design, targets, speeds, zero, t_c)


def test_loaded_designs_are_the_integrated_contact_over_speeds_and_weights():
    targets = np.array([0.2, 0.5, 0.8, 0.3, 0.6, 0.95])
    speeds = np.array([1.0, 3e-1, 10.0, 1e3, 0.05, 0.2])
    gravity = np.array([9.81, 9.81, 100.0, 9.81, 1.0, 9.81])
    weight = np.array([0.5, 1.0, 2.0, 0.3, 1.0, 3.0])  # inverse_weight at mass 1: rho = 1/w
    design = solref_for(
        restitution=targets,
        speed=speeds,
        gravity=gravity,
        solimp=FLAT,
        mass=1.0,
        inverse_weight=weight,
    )
    _check(design, targets, speeds, gravity, rho=1.0 / weight)
    t_c = np.array([0.02, 0.005, 0.01, 1e-3, 0.03, 0.02])
    design = solref_for(
        restitution=targets,
        speed=speeds,
        gravity=gravity,
        contact_time=t_c,
        solimp=FLAT,
        mass=1.0,
        inverse_weight=weight,
    )
    _check(design, targets, speeds, gravity, t_c, rho=1.0 / weight)


def test_slow_impacts_and_tiny_targets_under_gravity_are_designed():
    # far from the gravity-0 start: the fast iterations leave the dampratio bracket
    # (they must stay finite) and the bracketed method designs these
    targets = np.array([0.5, 0.03, 0.3])
    speeds = np.array([1e-3, 1.0, 1.0])
    gravity = np.array([9.81, 9.81, 0.0])
    design = solref_for(restitution=targets, speed=speeds, gravity=gravity, solimp=FLAT)
    _check(design, targets, speeds, gravity)


def test_mixed_gravity_arrays_equal_their_elements():
    targets = np.array([0.3, 0.5, 0.7, 0.9])
    gravity = np.array([0.0, 9.81, 0.0, 3.0])
    for extra in ({}, {"contact_time": 0.015}):
        whole = solref_for(restitution=targets, speed=1.0, gravity=gravity, solimp=FLAT, **extra)
        for i in range(targets.size):
            one = solref_for(
                restitution=targets[i], speed=1.0, gravity=gravity[i], solimp=FLAT, **extra
            )
            for k in range(2):
                assert whole.solref[k][i] == pytest.approx(one.solref[k], rel=1e-10)
        _check(whole, targets, np.ones(4), gravity, np.full(4, 0.015) if extra else None)


def test_targets_beside_the_jump_and_near_sticking_are_designed():
    # at 1 m/s under gravity the restitution jumps from about 0.14 to 0.07 where the
    # release switches from the force to the penetration; both sides stay reachable
    # (the fast iterations hand what they cannot settle to the bracketed method)
    targets = np.array([0.148, 0.072, 0.05])
    design = solref_for(restitution=targets, speed=1.0, gravity=9.81, solimp=FLAT)
    _check(design, targets, np.ones(3), np.full(3, 9.81))
    # near sticking with a contact time (sticking from e = 0.082 on, test_engines_hostile)
    targets = np.array([0.085, 0.3])
    design = solref_for(
        restitution=targets, speed=1.0, gravity=9.81, contact_time=0.01, solimp=FLAT
    )
    _check(design, targets, np.ones(2), np.full(2, 9.81), np.full(2, 0.01))


def test_refusals_name_the_element_of_the_callers_array():
    with pytest.raises(ValueError, match=r"restitution = 0\.1 \(element 2\).*jumps from"):
        solref_for(restitution=[0.5, 0.5, 0.1], speed=1.0, gravity=[9.81, 0.0, 9.81], solimp=FLAT)
    with pytest.raises(ValueError, match=r"restitution = 0\.999 \(element 1\).*every dampratio"):
        solref_for(restitution=[0.5, 0.999, 0.3], speed=1.0, gravity=[9.81, 0, 0], solimp=FLAT)
    with pytest.raises(ValueError, match=r"= 0\.9 \(element 2\).*no \(timeconst, dampratio\)"):
        solref_for(
            restitution=[0.5, 0.4, 0.9],
            speed=[1.0, 1.0, 0.01],
            gravity=[9.81, 0.0, 9.81],
            contact_time=0.5,
            solimp=FLAT,
        )


def test_gravity_free_dampratio_is_the_closed_form_inverse():
    # e = exp(-2 h(D)) with h = D arccos(D) / sqrt(1 - D^2): at D = 1/2, h = pi / (3 sqrt 3)
    e_t = np.array([np.exp(-2.0 * np.pi / (3.0 * np.sqrt(3.0)))])
    one = np.ones(1)
    dr = design_flat_dampratio(e_t, one, 0.0 * one, np.full(1, 0.02), FLAT, one)
    assert dr[0] == pytest.approx(0.5, rel=1e-14)


@pytest.mark.parametrize("contact_time", [None, 0.02])
def test_many_targets_of_one_contact_start_from_a_table(contact_time):
    # enough targets of one contact for the tabulated starts (1024 per restitution table,
    # 128 per table of designs): the same designs as one at a time, and the targets in
    # SciPy's integration
    n = 2048 if contact_time is None else 256
    targets = np.linspace(0.2, 0.95, n)
    extra = {} if contact_time is None else {"contact_time": contact_time}
    design = solref_for(restitution=targets, speed=1.0, gravity=9.81, solimp=FLAT, **extra)
    pick = np.array([0, 1, n // 3, n // 2 + 1, n - 2, n - 1])
    for i in pick:
        one = solref_for(restitution=targets[i], speed=1.0, gravity=9.81, solimp=FLAT, **extra)
        for k in range(2):
            assert design.solref[k][i] == pytest.approx(one.solref[k], rel=1e-9)
    sub = type(design)(tuple(np.asarray(a)[pick] for a in design.solref), FLAT, None)
    t_c = None if contact_time is None else np.full(pick.size, contact_time)
    _check(sub, targets[pick], np.ones(pick.size), np.full(pick.size, 9.81), t_c)
