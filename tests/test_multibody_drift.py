"""The drift of a reduced multibody contact during the contact, and its correction.

The coefficients are checked against closed forms of the falling bar; the corrected
MuJoCo prediction against MuJoCo itself on three scenes (a tilted capsule dropped on a
plane, a pendulum swung into a wall under gravity, a ball hitting a free capsule), run
at a fine timestep, where the frozen model is exact apart from the drift; the corrected
penalty contact against the full nonlinear simulation of section 3.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp

from impactsym.multibody import reduce_contact
from impactsym.multibody.drift import (
    DRIFT_LIMIT,
    ContactDrift,
    drift_free_contact_time,
    mass_drift,
)
from impactsym.multibody.examples import falling_bar

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)  # MuJoCo's


def _capsule(model, tilt, speed, gravity=0.0, half=0.2, radius=0.05, mass=1.0):
    inertia = float(model.body_inertia[1][1])  # about y (transverse, principal)
    x, z, th, vx, vz, om = sp.symbols("x z theta v_x v_z omega")
    gap = radius - z + half * sp.sin(th)
    at = {x: 0, z: half * math.sin(tilt) + radius, th: tilt, vx: 0, vz: -speed, om: 0}
    M, F = sp.diag(mass, mass, inertia), sp.Matrix([0, -mass * gravity, 0])
    return reduce_contact(M, F, gap, [x, z, th], [vx, vz, om], at, 1.0, 0.0)


def _wall_pendulum(angle, omega, length=0.5, radius=0.05, mass=2.0, gravity=9.81):
    ph, phd = sp.symbols("phi phidot")
    inertia = mass * length**2 + sp.Rational(2, 5) * mass * radius**2
    gap = -length * sp.sin(ph) + length * math.sin(angle)  # sphere beyond the wall
    torque = sp.Matrix([-mass * gravity * length * sp.sin(ph)])
    at = {ph: angle, phd: -omega}
    return reduce_contact(sp.Matrix([[inertia]]), torque, gap, [ph], [phd], at, 1.0, 0.0)


def _ball_on_capsule(model, tilt, offset, speed, h=0.2, radius=0.05, ball=0.05, m2=1.0):
    inertia = float(model.body_inertia[1][1])
    x1, z1, th, x2, z2 = sp.symbols("x1 z1 theta x2 z2")
    us = sp.symbols("u1:6")
    beta, reach = math.pi / 2 - tilt - offset, radius + ball
    gap = reach - sp.sqrt((x2 - x1 - h * sp.cos(th)) ** 2 + (z2 - z1 + h * sp.sin(th)) ** 2)
    at = {x1: 0, z1: 0, th: tilt}
    at |= {x2: h * math.cos(tilt) + reach * math.cos(beta)}
    at |= {z2: -h * math.sin(tilt) + reach * math.sin(beta)}
    at |= dict(zip(us, (0, 0, 0, -speed * math.cos(beta), -speed * math.sin(beta)), strict=True))
    M = sp.diag(1.0, 1.0, inertia, m2, m2)
    return reduce_contact(M, sp.zeros(5, 1), gap, [x1, z1, th, x2, z2], list(us), at, 1.0, 0.0)


# -- the coefficients ------------------------------------------------------------------
def test_bar_coefficients_are_the_closed_form_derivatives():
    bar = falling_bar(gravity=0.0)  # m = L = 1, I = 1/12, theta = 30 degrees, with drag
    r = bar.reduce(1e4, 10.0, 0.5)
    m, inertia, half, th = 1.0, 1.0 / 12.0, 0.5, math.pi / 6

    def inv_mass(theta):
        return 1.0 / m + (half * math.cos(theta)) ** 2 / inertia

    eps = 1e-6
    slope = (inv_mass(th + eps) - inv_mass(th - eps)) / (2 * eps)
    p_theta = half * math.cos(th) / inertia / inv_mass(th)  # impulse projection, theta part
    d = r.drift
    assert isinstance(d, ContactDrift)
    assert d.inv_mass[0] == pytest.approx(inv_mass(th), rel=1e-12)
    # the bar falls without rotating: the motion that leaves z alone turns it at -P v0
    assert d.inv_mass_rate == pytest.approx(slope * (-p_theta * 0.5), rel=1e-8)
    assert d.inv_mass_slope == pytest.approx(slope * p_theta, rel=1e-8)
    # curvature of the end's height: -(L/2) sin(theta) theta'^2, theta' = P_theta z'
    assert d.curvature[4] == pytest.approx(-half * math.sin(th) * p_theta**2, rel=1e-10)
    # the drag's press depends on z' (it is the reduction's delta_d) and, through the
    # drag's pull on the free motion, on t
    assert d.press[2] == pytest.approx(0.0, abs=1e-12)
    assert d.press[3] == pytest.approx(-r.delta_d / r.m_eff, rel=1e-10)


def test_free_acceleration_terms_are_the_bars_own():
    """Under gravity alone the contact force turns the bar at ``theta'' = -P_theta g``
    (the part of the body's free acceleration that the contact takes out), so that
    ``A_tt = A'(theta) theta''/2`` and the curvature gains ``t dv`` and ``t^2`` terms."""
    g, m, inertia, half, th = 9.81, 1.0, 1.0 / 12.0, 0.5, math.pi / 6
    r = falling_bar(drag=0.0, rotational_drag=0.0).reduce(1e4, 10.0, 0.5)
    a0 = 1.0 / m + (half * math.cos(th)) ** 2 / inertia
    p_theta = half * math.cos(th) / inertia / a0
    theta_acc = -p_theta * g  # G0 = g (w = (0, -1, L/2 cos)); M^-1 F has no rotation
    slope = -2 * half**2 * math.cos(th) * math.sin(th) / inertia  # dA/dtheta
    d = r.drift
    assert d.press[0] == pytest.approx(g, rel=1e-12)
    assert d.inv_mass[5] == pytest.approx(slope * theta_acc / 2, rel=1e-10)
    # kappa = -(L/2) sin(theta) theta'^2 with theta' = -P_theta v0 + P_theta z' + theta'' t
    assert d.curvature[6] == pytest.approx(-half * math.sin(th) * 2 * p_theta * theta_acc)
    assert d.curvature[1] == pytest.approx(0.0, abs=1e-12)  # theta'(0) = 0


def test_symbolic_reduction_carries_no_drift_and_says_so():
    m = sp.Symbol("m", positive=True)
    x, v = sp.symbols("x v")
    r = reduce_contact(sp.Matrix([[m]]), sp.Matrix([0]), x, [x], [v], {x: 0, v: 1}, 1.0, 0.0)
    assert r.drift is None
    with pytest.raises(ValueError, match="no drift coefficients"):
        mass_drift(r.subs({m: 2.0}), 0.01)


def test_mass_drift_grows_with_the_contact_time_and_the_limit_is_its_1_percent():
    r = falling_bar(gravity=0.0, drag=0.0, rotational_drag=0.0).reduce(1e4, 10.0, 0.5)
    times = np.array([1e-3, 2e-3, 4e-3])
    drift = mass_drift(r, times)
    assert drift == pytest.approx(drift[0] * times / times[0], rel=1e-12)
    from impactsym.engines.mujoco import from_reduced

    with pytest.warns(RuntimeWarning, match=r"below ([\d.]+) ms keeps") as info:
        from_reduced(r, contact_time=0.02)
    limit = float(str(info[0].message).split("below ")[1].split(" ms")[0]) * 1e-3
    assert mass_drift(r, limit) == pytest.approx(DRIFT_LIMIT, rel=5e-3)  # 3 digits
    exact = drift_free_contact_time(r.drift, 0.02, mass_drift(r, 0.02))
    assert mass_drift(r, exact) == pytest.approx(DRIFT_LIMIT, rel=1e-9)
    r_g = falling_bar().reduce(1e4, 10.0, 0.5)  # gravity: A_tt, no longer proportional
    exact = drift_free_contact_time(r_g.drift, 0.05, mass_drift(r_g, 0.05))
    assert mass_drift(r_g, exact) == pytest.approx(DRIFT_LIMIT, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        from_reduced(r, contact_time=0.5 * limit)  # below the limit: silent
        from_reduced(r)  # no contact time: silent, as before


# -- MuJoCo ---------------------------------------------------------------------------
def _check(p, e, t, frozen_off):
    assert p.mass_drift > DRIFT_LIMIT
    assert p.restitution == pytest.approx(e, rel=0.01)
    assert p.contact_time == pytest.approx(t, rel=0.01)
    off = max(abs(p.frozen.restitution / e - 1), abs(p.frozen.contact_time / t - 1))
    assert off > frozen_off  # the uncorrected prediction visibly misses
    fixed = max(abs(p.restitution / e - 1), abs(p.contact_time / t - 1))
    assert fixed < off / 4


@pytest.mark.parametrize(
    ("solimp", "speed", "gravity", "frozen_off"),
    [(FLAT, 1.0, 0.0, 0.025), (DEFAULT_SOLIMP, 0.5, 9.81, 0.05)],
    ids=["flat", "default-solimp-gravity"],
)
def test_tilted_capsule_in_mujoco(solimp, speed, gravity, frozen_off):
    from impactsym.engines.drivers import mujoco_capsule
    from impactsym.engines.mujoco.drift import predict_reduced

    solref, tilt = (0.03, 0.3), 0.8
    e, t, model = mujoco_capsule(
        solref=solref, solimp=solimp, speed=speed, gravity=gravity, tilt=tilt, timestep=2e-5
    )
    r = _capsule(model, tilt, speed, gravity)
    weight = float(model.body_invweight0[1][0])
    with pytest.warns(RuntimeWarning, match=r"1/m_eff changes by [\d.]+ %"):
        p = predict_reduced(r, solref=solref, solimp=solimp, inverse_weight=weight)
    _check(p, e, t, frozen_off)


def test_pendulum_into_a_wall_under_gravity_in_mujoco():
    from impactsym.engines.drivers import mujoco_wall_pendulum
    from impactsym.engines.mujoco.drift import predict_reduced

    solref, angle, omega = (0.03, 0.3), 0.9, 2.0
    e, t, model = mujoco_wall_pendulum(
        solref=solref, solimp=FLAT, omega=omega, angle=angle, timestep=2e-5
    )
    r = _wall_pendulum(angle, omega)
    assert r.load > 0  # gravity presses the sphere into the wall
    weight = float(model.body_invweight0[1][0])
    with pytest.warns(RuntimeWarning, match="drifts during the contact"):
        p = predict_reduced(r, solref=solref, solimp=FLAT, inverse_weight=weight)
    _check(p, e, t, 0.012)


def test_ball_on_a_free_capsule_in_mujoco():
    from impactsym.engines.drivers import mujoco_two_bodies
    from impactsym.engines.mujoco.drift import predict_reduced

    solref, tilt, offset, speed = (0.03, 0.3), 0.3, 0.6, 0.7
    e, t, model = mujoco_two_bodies(
        solref=solref,
        solimp=FLAT,
        speed=speed,
        tilt=tilt,
        offset=offset,
        ball_mass=1.0,
        timestep=2e-5,
    )
    r = _ball_on_capsule(model, tilt, offset, speed)
    weight = float(model.body_invweight0[1][0] + model.body_invweight0[2][0])
    with pytest.warns(RuntimeWarning, match="drifts during the contact"):
        p = predict_reduced(r, solref=solref, solimp=FLAT, inverse_weight=weight)
    _check(p, e, t, 0.015)


def test_without_drift_the_prediction_is_predict_and_silent():
    from impactsym.engines.mujoco import from_reduced, predict
    from impactsym.engines.mujoco.drift import predict_reduced

    x, v = sp.symbols("x v")
    r = reduce_contact(sp.Matrix([[2.0]]), sp.Matrix([19.62]), x, [x], [v], {x: 0, v: 1}, 1, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = predict_reduced(r, solref=(np.array([0.02, 0.05]), 0.3), solimp=FLAT)
    q = predict(solref=(np.array([0.02, 0.05]), 0.3), solimp=FLAT, **from_reduced(r))
    assert np.array_equal(p.restitution, q.restitution)
    assert np.array_equal(p.contact_time, q.contact_time)
    assert np.array_equal(p.mass_drift, [0.0, 0.0])


# -- hostile input ---------------------------------------------------------------------
def test_hostile_inputs_are_refused_by_name():
    from impactsym.engines.mujoco import from_reduced
    from impactsym.engines.mujoco.drift import predict_reduced

    r = falling_bar().reduce(1e4, 10.0, 0.5)
    for bad in (object(), None, "reduced"):
        with pytest.raises(TypeError, match="numeric ReducedContact"):
            mass_drift(bad, 0.01)
        with pytest.raises(TypeError, match="ReducedContact"):
            predict_reduced(bad, solref=(0.02, 0.3))
    for bad, kind in ((-1e-3, ValueError), (0.0, ValueError), (np.nan, ValueError)):
        with pytest.raises(kind, match="contact_time"):
            mass_drift(r, bad)
        with pytest.raises(kind, match="contact_time"):
            from_reduced(r, contact_time=bad)
    with pytest.raises(TypeError, match="contact_time"):
        mass_drift(r, "0.01")
    assert mass_drift(r, np.inf) == np.inf
    with pytest.raises(ValueError, match="inverse_weight"):
        predict_reduced(r, solref=(0.02, 0.3), inverse_weight=[1.0, 2.0])
    with pytest.raises(ValueError, match="inverse_weight"):
        predict_reduced(r, solref=(0.02, 0.3), inverse_weight=-1.0)
    with pytest.raises((TypeError, ValueError), match="solref"):
        predict_reduced(r, solref="0.02 0.3")


def test_mujoco_leaves_the_curvature_out_of_its_constraint_force():
    """The engine fact the MuJoCo correction rests on: ``a0 = J M^-1 F`` without ``J' q'``.

    The tilted capsule as a rigid body under MuJoCo's force law, integrated by SciPy,
    reproduces MuJoCo when ``a0`` leaves ``J' q'`` out; with it, the restitution is the
    frozen prediction's instead.
    """
    from scipy.integrate import solve_ivp

    from impactsym.engines.drivers import mujoco_capsule
    from impactsym.engines.mujoco import predict

    solref, tilt, half, radius, d = (0.05, 0.3), 0.5, 0.2, 0.05, 0.9
    e, t, model = mujoco_capsule(solref=solref, solimp=FLAT, speed=1.0, tilt=tilt)
    inertia = float(model.body_inertia[1][1])
    b = 2 / (d * solref[0])
    k = 1 / (d * solref[0] ** 2 * solref[1] ** 2)  # d kbar
    minv = np.array([1.0, 1.0, 1.0 / inertia])
    weight = float(model.body_invweight0[1][0])  # MuJoCo's A_diag
    R = (1 - d) / d * weight

    def run(jdot):
        def parts(s):
            J = np.array([0.0, 1.0, -half * np.cos(s[2])])  # d(gap)/d(x, z, theta)
            gap = s[1] - half * np.sin(s[2]) - radius
            curv = half * np.sin(s[2]) * s[5] ** 2  # J' q'
            return J, gap, J @ s[3:], curv

        def rhs(_, s):
            J, gap, rate, curv = parts(s)
            force = max(0.0, (-b * rate - k * gap - jdot * curv) / (J @ (minv * J) + R))
            return [*s[3:], *(minv * J * force)]

        def release(time, s):
            _, gap, rate, curv = parts(s)
            return -b * rate - k * gap - jdot * curv if time > 1e-6 else 1.0

        release.terminal, release.direction = True, -1
        s0 = [0.0, half * np.sin(tilt) + radius, tilt, 0.0, -1.0, 0.0]
        sol = solve_ivp(rhs, (0, 1), s0, events=release, rtol=1e-11, atol=1e-13, max_step=1e-4)
        return parts(sol.y_events[0][0])[2], sol.t_events[0][0]

    e_without, t_without = run(0.0)
    assert e_without == pytest.approx(e, rel=1e-3)
    assert t_without == pytest.approx(t, rel=1e-3)
    e_with, _ = run(1.0)
    r = _capsule(model, tilt, 1.0)
    frozen = predict(solref=solref, solimp=FLAT, mass=r.m_eff, speed=1.0, inverse_weight=weight)
    assert e_with == pytest.approx(frozen.restitution, rel=2e-3)
    assert e_with < e * 0.97


# -- the penalty contact of section 2 --------------------------------------------------
def test_penalty_contact_of_a_turning_bar_is_the_full_simulation():
    from impactsym.multibody.drift import corrected_contact
    from impactsym.multibody.simulation import simulate_contact

    bar = falling_bar(gravity=0.0, drag=0.0, rotational_drag=0.0)
    r = bar.reduce(1e4, 3.0, 1.0)
    sim = simulate_contact(bar, 1e4, 3.0, 1.0, condition=["force", "position"], steps=100)
    for i, condition in enumerate(("force", "position")):
        with pytest.warns(RuntimeWarning, match="drifts during the contact"):
            c = corrected_contact(r, condition=condition)
        e, t = float(sim.restitution[i]), float(sim.contact_time[i])
        assert abs(c.frozen_restitution / e - 1) > 0.01  # the frozen reduction misses
        assert c.restitution == pytest.approx(e, rel=1e-3)
        assert c.contact_time == pytest.approx(t, rel=1e-3)
        assert c.frozen_restitution == r.restitution(condition)


def test_penalty_contact_of_the_double_pendulum_within_1_percent():
    from impactsym.multibody.drift import corrected_contact
    from impactsym.multibody.examples import double_pendulum
    from impactsym.multibody.simulation import simulate_contact

    pendulum = double_pendulum()  # gravity, joint springs and dampers
    r = pendulum.reduce(np.array([1e4, 3e4]), np.array([3.0, 10.0]), 1.0)
    sim = simulate_contact(
        pendulum, np.array([1e4, 3e4]), np.array([3.0, 10.0]), 1.0, condition="position", steps=100
    )
    with pytest.warns(RuntimeWarning, match="drifts during the contact"):
        c = corrected_contact(r, condition="position")
    frozen = np.abs(c.frozen_restitution / sim.restitution - 1)
    fixed = np.abs(c.restitution / sim.restitution - 1)
    assert frozen[0] > 0.03
    assert np.all(fixed < 0.01)
    assert np.all(fixed < frozen / 3)
    assert np.all(np.abs(c.contact_time / sim.contact_time - 1) < 0.002)


def test_corrected_contact_refuses_bad_input():
    from impactsym.multibody.drift import corrected_contact

    r = falling_bar().reduce(1e4, 10.0, 0.5)
    with pytest.raises(TypeError):
        corrected_contact(r)  # the condition has no default
    with pytest.raises(ValueError, match="condition"):
        corrected_contact(r, condition="velocity")
    with pytest.raises(TypeError, match="numeric ReducedContact"):
        corrected_contact(object(), condition="force")


def test_drift_building_blocks_refuse_bad_input():
    from impactsym.multibody.drift import integrate_release

    d = falling_bar().reduce(1e4, 10.0, 0.5).drift
    with pytest.raises(ValueError, match="name"):
        d.value("mass", 0.0, 0.0, 0.5)
    with pytest.raises(TypeError, match="ContactDrift"):
        drift_free_contact_time({"speed": 1.0}, 0.01, 0.02)
    with pytest.raises(ValueError, match="contact_time"):
        drift_free_contact_time(d, -0.01, 0.02)
    with pytest.raises(ValueError, match="observed"):
        drift_free_contact_time(d, 0.01, np.nan)
    one = np.ones(1)

    def rhs(t, x, v):
        return -x

    for v0, t_end in ((0 * one, one), (one, np.inf * one), (one, -one)):
        with pytest.raises(ValueError, match="v0|t_end"):
            integrate_release(rhs, rhs, v0, t_end)
    v, t, _ = integrate_release(rhs, lambda t, x, v: x, one, np.pi * one)  # x'' = -x
    assert t == pytest.approx(np.pi, rel=1e-6)
    assert v == pytest.approx(-1.0, rel=1e-6)
