"""MuJoCo bridge: the closed form against ODE integration, and designs against MuJoCo itself."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import sympy as sp

from impactsym.engines.mujoco import from_reduced, impedance, predict, solref_for
from impactsym.multibody import reduce_contact

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("mujoco")

from impactsym.engines.runs import fine_timestep, mujoco_drop, mujoco_pendulum

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


def _textbook_dampratio(e):
    return -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)


def test_varying_integrator_agrees_with_closed_form_when_the_impedance_is_flat():
    # a varying solimp whose width is far below the penetration acts like d_max
    wide = (0.9, 0.9 + 1e-9, 1e-9, 0.5, 2.0)
    for g in (0.0, 9.81):
        a = predict(solref=(0.02, 0.4), solimp=wide, speed=np.array([0.2, 1.0]), gravity=g)
        b = predict(solref=(0.02, 0.4), solimp=FLAT, speed=np.array([0.2, 1.0]), gravity=g)
        np.testing.assert_allclose(a.restitution, b.restitution, rtol=1e-5)
        np.testing.assert_allclose(a.contact_time, b.contact_time, rtol=1e-4)


def test_impedance_is_mujocos_efc_imp():
    import mujoco

    xml = """<mujoco><worldbody><geom type="plane" size="1 1 .1" solimp="0.5 0.99 0.002 0.3 3"/>
    <body><joint type="slide" axis="0 0 1"/><geom type="sphere" size="0.1" mass="1"
    solimp="0.5 0.99 0.002 0.3 3"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    for depth in (1e-5, 3e-4, 7e-4, 1.5e-3, 3e-3):
        data.qpos[0] = 0.1 - depth
        mujoco.mj_forward(model, data)
        assert impedance(depth, (0.5, 0.99, 0.002, 0.3, 3)) == pytest.approx(
            data.efc_KBIP[0][2], rel=1e-12
        )


# -- designs in the engine -----------------------------------------------------------
@pytest.mark.parametrize("gravity", [0.0, 9.81])
@pytest.mark.parametrize(("solimp", "tol"), [(FLAT, 0.01), (DEFAULT, 0.02)])
def test_designed_restitution_is_what_mujoco_gives(gravity, solimp, tol):
    # under gravity, 0.1 at 1 m/s lies in the restitution gap (see the test below)
    targets = np.array([0.2 if gravity else 0.1, 0.3, 0.5, 0.7, 0.95])
    speed = 1.0
    design = solref_for(restitution=targets, speed=speed, gravity=gravity, solimp=solimp)
    rows = []
    for i, target in enumerate(targets):
        sr = (float(design.solref[0][i]), float(design.solref[1][i]))
        e, t = mujoco_drop(
            solref=sr,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=fine_timestep(sr, speed, gravity),
        )
        assert e == pytest.approx(target, rel=tol)
        assert t == pytest.approx(design.contact_time[i], rel=0.02)
        text = (0.02, _textbook_dampratio(target))
        e_text, _ = mujoco_drop(
            solref=text,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=fine_timestep(text, speed, gravity),
        )
        rows.append((target, e, e_text))
    # the textbook dampratio misses low targets by far more than the tolerance
    low = rows[0]
    assert abs(low[2] - low[0]) / low[0] > 5 * tol


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_negative_solref_and_contact_time_design_in_mujoco(gravity):
    targets = np.array([0.2, 0.6, 0.9])
    for form in ("timeconst", "stiffness"):
        design = solref_for(
            restitution=targets,
            speed=0.7,
            gravity=gravity,
            contact_time=0.01,
            solimp=FLAT,
            form=form,
        )
        for i, target in enumerate(targets):
            sr = (float(design.solref[0][i]), float(design.solref[1][i]))
            e, t = mujoco_drop(
                solref=sr,
                solimp=FLAT,
                speed=0.7,
                gravity=gravity,
                timestep=fine_timestep(sr, 0.7, gravity),
            )
            assert e == pytest.approx(target, rel=0.01)
            assert t == pytest.approx(0.01, rel=0.02)


def test_slow_impacts_under_gravity_lose_contact_while_still_pressed():
    # MuJoCo's own behaviour: at low speed the body leaves through x = 0 with f > 0
    sr = (0.02, 0.2)
    p = predict(solref=sr, solimp=FLAT, speed=0.05, gravity=9.81)
    assert p.released_by_position
    assert not p.sticks
    e, t = mujoco_drop(solref=sr, solimp=FLAT, speed=0.05, gravity=9.81, timestep=2e-6)
    assert e == pytest.approx(p.restitution, rel=0.01)
    assert t == pytest.approx(p.contact_time, rel=0.02)


def test_restitution_gap_under_gravity_is_refused_and_mujoco_shows_the_jump():
    with pytest.raises(ValueError, match=r"jumps from 0\.14\d+ to 0\.07\d+") as info:
        solref_for(restitution=0.1, speed=1.0, gravity=9.81, solimp=FLAT)
    jump = float(str(info.value).split("dampratio = ")[1].split()[0])
    e_below, _ = mujoco_drop(solref=(0.02, jump * 0.99), solimp=FLAT, speed=1.0, gravity=9.81)
    e_above, _ = mujoco_drop(solref=(0.02, jump * 1.01), solimp=FLAT, speed=1.0, gravity=9.81)
    assert e_below > 0.14
    assert e_above < 0.08


@pytest.mark.parametrize("solimp", [FLAT, DEFAULT])
def test_stick_or_bounce_is_predicted_as_mujoco_shows_it(solimp):
    speeds = np.array([0.03, 0.1, 0.3, 1.0])
    for dampratio in (0.2, 0.5, 1.0):
        p = predict(solref=(0.02, dampratio), solimp=solimp, speed=speeds, gravity=9.81)
        for v, sticks in zip(speeds, p.sticks, strict=True):
            _e, t = mujoco_drop(
                solref=(0.02, dampratio),
                solimp=solimp,
                speed=v,
                gravity=9.81,
                timestep=5e-5,
                t_max=0.3,
            )
            assert math.isinf(t) == bool(sticks), (dampratio, v)


def test_multibody_contact_with_the_reduced_effective_mass():
    L, r, m, angle, omega = 0.5, 0.05, 2.0, 0.6, 2.0
    th, thd = sp.symbols("theta thetadot")
    inertia = m * L**2 + sp.Rational(2, 5) * m * r**2
    height = L * math.sin(angle) + r
    reduced = reduce_contact(
        sp.Matrix([[inertia]]),
        sp.Matrix([m * 9.81 * L * sp.cos(th)]),
        L * sp.sin(th) + r - height,
        [th],
        [thd],
        {th: angle, thd: omega},
        1.0,
        0.0,
    )
    kw = from_reduced(reduced)
    # MuJoCo's own estimate A_diag of the inverse effective mass, from the model
    _, _, model = mujoco_pendulum(solref=(0.02, 0.3), solimp=FLAT, omega=omega, timestep=1e-4)
    weight = float(model.body_invweight0[1][0])
    assert 1.0 / kw["mass"] != pytest.approx(weight, rel=0.1)  # a genuine multibody case
    design = solref_for(restitution=0.4, solimp=FLAT, inverse_weight=weight, **kw)
    e, t, _ = mujoco_pendulum(solref=design.solref, solimp=FLAT, omega=omega, timestep=1e-5)
    assert e == pytest.approx(0.4, rel=0.01)
    assert t == pytest.approx(design.contact_time, rel=0.02)


# -- errors and warnings --------------------------------------------------------------
def test_unreachable_target_says_why_and_what_reaches_it():
    with pytest.raises(ValueError, match=r"cannot be reached.*higher speed"):
        solref_for(restitution=0.9, speed=0.01, gravity=9.81, solimp=FLAT, contact_time=0.5)


def test_coarse_timestep_warns_with_the_timestep_that_would_do():
    with pytest.warns(RuntimeWarning, match=r"omega0 \* dt = .*timestep <= 3e-05 s"):
        predict(solref=(0.02, 0.05), solimp=FLAT, speed=1.0, timestep=1e-3)
    with pytest.warns(RuntimeWarning, match=r"g \* dt / v0 = .*timestep <= 1.02e-05 s"):
        predict(solref=(0.02, 0.2), solimp=FLAT, speed=0.02, gravity=9.81, timestep=5e-5)
    # and the warned-about timestep really misses by more than 1 % in MuJoCo
    p = predict(solref=(0.02, 0.05), solimp=FLAT, speed=1.0)
    e, _ = mujoco_drop(solref=(0.02, 0.05), solimp=FLAT, speed=1.0, timestep=1e-3)
    assert abs(e / p.restitution - 1) > 0.01


def test_bad_inputs_are_refused_by_name():
    with pytest.raises(ValueError, match="speed"):
        predict(solref=(0.02, 1.0), speed=-1.0)
    with pytest.raises(ValueError, match="solref"):
        predict(solref=(0.02, -1.0), speed=1.0)
    with pytest.raises(TypeError, match="solimp"):
        predict(solref=(0.02, 1.0), solimp="0.9 0.95", speed=1.0)
    with pytest.raises(ValueError, match="restitution"):
        solref_for(restitution=1.2, speed=1.0)
    with pytest.raises(ValueError, match="peak_force needs"):
        _ = predict(solref=(0.02, 1.0), speed=1.0).peak_force


def test_peak_force_is_mass_times_engine_constraint_acceleration():
    import mujoco

    sr, v, m = (0.02, 0.5), 1.0, 2.0
    p = predict(solref=sr, solimp=FLAT, speed=v, mass=m)
    xml = f"""<mujoco><option timestep="1e-5" gravity="0 0 0" integrator="Euler"/>
    <worldbody><geom type="plane" size="1 1 .1" condim="1" solref="0.02 0.5"
    solimp="0.9 0.9 0.001 0.5 2"/><body><joint type="slide" axis="0 0 1"/>
    <geom type="sphere" size="0.1" mass="{m}" condim="1" solref="0.02 0.5"
    solimp="0.9 0.9 0.001 0.5 2"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[0], data.qvel[0] = 0.1, -v
    peak, depth = 0.0, 0.0
    for _ in range(3000):
        mujoco.mj_step(model, data)
        if data.nefc:
            peak = max(peak, float(data.efc_force[0]))
            depth = max(depth, -float(data.efc_pos[0]))
    assert p.peak_force == pytest.approx(peak, rel=0.01)
    assert p.max_penetration == pytest.approx(depth, rel=0.01)


def test_cli_design_is_what_mujoco_gives(capsys):
    from impactsym.cli import main

    argv = ["mujoco", "--restitution", "0.4", "--speed", "1", "--contact-time", "0.01"]
    assert main([*argv, "--solimp", "0.9", "0.9", "0.001", "0.5", "2"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    solref = tuple(float(x) for x in first.split('"')[1].split())
    e, t = mujoco_drop(solref=solref, solimp=FLAT, speed=1.0, timestep=1e-5)
    assert e == pytest.approx(0.4, rel=0.01)
    assert t == pytest.approx(0.01, rel=0.02)


def test_default_solimp_design_of_both_restitution_and_contact_time():
    targets = np.array([0.2, 0.6, 0.9])
    design = solref_for(restitution=targets, speed=0.7, gravity=9.81, contact_time=0.01)
    for i, target in enumerate(targets):
        sr = (float(design.solref[0][i]), float(design.solref[1][i]))
        e, t = mujoco_drop(
            solref=sr,
            solimp=DEFAULT,
            speed=0.7,
            gravity=9.81,
            timestep=fine_timestep(sr, 0.7, 9.81),
        )
        assert e == pytest.approx(target, rel=0.02)
        assert t == pytest.approx(0.01, rel=0.02)


def test_stick_speed_is_where_mujoco_starts_to_hold_the_body():
    from impactsym.engines.mujoco import stick_speed

    for dampratio in (0.3, 0.5, 0.8):
        sr = (0.02, dampratio)
        v_star = stick_speed(solref=sr, solimp=FLAT, gravity=9.81)
        below, _ = mujoco_drop(
            solref=sr, solimp=FLAT, speed=0.95 * v_star, gravity=9.81, timestep=2e-5, t_max=0.3
        )
        above, _ = mujoco_drop(
            solref=sr, solimp=FLAT, speed=1.05 * v_star, gravity=9.81, timestep=2e-5, t_max=0.3
        )
        assert below == 0.0, dampratio
        assert above > 0.0, dampratio


def test_derivation_makes_dampratio_lehrs_D_and_gives_load_and_offset():
    from impactsym.engines.derivation import MujocoContact

    mc = MujocoContact()
    flat = {**mc.solref_positive, mc.d: mc.d_max, mc.rho: 1}
    assert sp.simplify(mc.damping_ratio.subs(flat) - mc.dampratio) == 0
    assert sp.simplify(mc.omega0.subs(flat) - 1 / (mc.timeconst * mc.dampratio)) == 0
    assert sp.simplify(mc.normalized_load - (1 - mc.d_eff) * mc.gamma) == 0
    assert sp.simplify(mc.normalized_offset - mc.d_eff * mc.gamma) == 0


@pytest.mark.parametrize("case", ["slide", "pendulum"])
def test_derived_contact_force_is_mujocos_efc_force(case):
    import mujoco

    from impactsym.engines.derivation import MujocoContact

    mc = MujocoContact()
    solimp = (0.8, 0.95, 0.002, 0.4, 3.0)
    if case == "slide":
        xml = f"""<mujoco><option gravity="0 0 -9.81"/><worldbody>
        <geom type="plane" size="1 1 .1" condim="1" solref="0.02 0.4"
        solimp="{" ".join(map(str, solimp))}"/><body><joint type="slide" axis="0 0 1"/>
        <geom type="sphere" size="0.1" mass="2" condim="1" solref="0.02 0.4"
        solimp="{" ".join(map(str, solimp))}"/></body></worldbody></mujoco>"""
        model = mujoco.MjModel.from_xml_string(xml)
        data = mujoco.MjData(model)
        data.qpos[0], data.qvel[0] = 0.1 - 7e-4, -0.3
    else:
        _, _, model = mujoco_pendulum(solref=(0.02, 0.4), solimp=solimp, omega=1.0)
        data = mujoco.MjData(model)
        data.qpos[0], data.qvel[0] = 0.6 + 1.5e-3, 0.8
    mujoco.mj_forward(model, data)
    assert data.nefc == 1
    J = np.array(data.efc_J[: model.nv])
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)  # MuJoCo 4 signature
    A = float(J @ np.linalg.solve(M, J))
    K, B, imp, _ = data.efc_KBIP[0]
    gravity_normal = -float(J @ np.linalg.solve(M, data.qfrc_bias))  # a0 along the normal
    values = {
        mc.m: 1 / A,
        mc.g: -gravity_normal,
        mc.d: imp,
        mc.rho: A / float(data.efc_diagA[0]),
        mc.b: B,
        mc.kbar: K,
        mc.x: -float(data.efc_pos[0]),
        mc.x_dot: -float(data.efc_vel[0]),
    }
    assert float(mc.contact_force.subs(values)) == pytest.approx(data.efc_force[0], rel=1e-9)


# -- review fixes: range ends, an overdamped body that sticks, refsafe after design ----
def test_stick_speed_range_ends_are_answers_mujoco_confirms():
    from impactsym.engines.mujoco import stick_speed

    # undamped: it never sticks (it used to return the search end, 1.4e-10 m/s)
    assert stick_speed(solref=(-1e4, 0.0), solimp=FLAT, gravity=9.81) == 0.0
    e, t = mujoco_drop(
        solref=(-1e4, 0.0), solimp=FLAT, speed=0.01, gravity=9.81, timestep=2e-6, t_max=0.1
    )
    assert e > 0.5
    assert math.isfinite(t)
    # hugely overdamped: it sticks at every speed (it used to return 1.96e11 m/s)
    assert stick_speed(solref=(0.02, 1e3), solimp=FLAT, gravity=9.81) == math.inf
    e, t = mujoco_drop(
        solref=(0.02, 1e3), solimp=FLAT, speed=3.0, gravity=9.81, timestep=2e-5, t_max=0.3
    )
    assert e == 0.0
    assert math.isinf(t)
    # element-wise with an ordinary design in between
    both = stick_speed(solref=([-1e4, 0.02, 0.02], [0.0, 0.5, 1e3]), solimp=FLAT, gravity=9.81)
    assert both[0] == 0.0
    assert both[2] == math.inf
    assert 0.1 < both[1] < 0.2


def test_overdamped_default_solimp_sticks_and_returns():
    # it used to integrate ~3e6 Runge-Kutta steps (dampratio^2): now the rest is proven
    p = predict(solref=(0.02, 20.0), speed=0.01, gravity=9.81)  # ~0.1 s
    assert p.sticks
    assert p.restitution == 0.0
    assert math.isinf(p.contact_time)
    # MuJoCo holds it too
    _e, t = mujoco_drop(
        solref=(0.02, 20.0), solimp=DEFAULT, speed=0.01, gravity=9.81, timestep=1e-5, t_max=0.3
    )
    assert math.isinf(t)
    # it creeps into the static penetration of MuJoCo's equation, (1 - d) g = d^2 k x
    d = 0.95
    k = 1.0 / (d**2 * 0.02**2 * 20.0**2)
    assert p.max_penetration == pytest.approx((1 - d) * 9.81 / (d**2 * k), rel=1e-4)
    many = predict(solref=(0.02, [20.0, 200.0]), speed=[0.01, 1.0], gravity=9.81)
    assert many.sticks.all()


def test_work_is_capped_with_an_error_naming_solref(monkeypatch):
    import impactsym.engines.mujoco as mj

    # static penetration inside the impedance width: rest is not provable, and the
    # horizon needs > 400 000 steps: refused at once, naming the solref
    with pytest.raises(ValueError, match=r"solref = \(0\.002, 10\)"):
        predict(solref=(0.002, 10.0), speed=0.1, gravity=9.81)
    # the same contact in the stiffness form is named in both forms
    with pytest.raises(ValueError, match=r"\(-2500, -1000\)"):
        predict(solref=(-2500.0, -1000.0), speed=0.1, gravity=9.81)
    # the loop's own cap (a backstop) names it too
    monkeypatch.setattr(mj, "_MAX_RK_STEPS", 50)
    with pytest.raises(ValueError, match="solref = "):
        mj.predict(solref=(0.02, 2.0), speed=0.01, gravity=9.81)


def test_refsafe_is_checked_on_the_final_varying_design(monkeypatch):
    import impactsym.engines.mujoco as mj

    # the varying design moves the timeconst below 2 timestep (the flat start is above)
    with pytest.raises(ValueError, match=r"contact_time = 0\.0013932.*2 \* timestep"):
        solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932, timestep=0.001)
    # MuJoCo with the design's timeconst raised to 2 timestep: contact time off by > 2 %
    free = solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932)
    assert free.solref[0] < 0.002
    _e, t = mujoco_drop(solref=(0.002, free.solref[1]), solimp=DEFAULT, speed=1.0, timestep=1e-6)
    assert abs(t / 0.0013932 - 1) > 0.02
    # a design whose prediction misses the targets is refused (tolerance made impossible)
    monkeypatch.setattr(mj, "_DESIGN_TOL", 0.0)
    with pytest.raises(ValueError, match="is not reached"):
        solref_for(restitution=0.5, speed=1.0, contact_time=0.0013932)


def test_array_arguments_that_must_be_one_number_are_named():
    from impactsym.engines.mujoco import stick_speed

    with pytest.raises(ValueError, match="gravity"):
        stick_speed(solref=(0.02, 0.5), solimp=FLAT, gravity=[9.81, 1.0])
    with pytest.raises(ValueError, match="timestep"):
        predict(solref=(0.02, 0.5), speed=1.0, timestep=[1e-3])
    with pytest.raises(ValueError, match="timestep"):
        stick_speed(solref=(0.02, 0.5), solimp=FLAT, gravity=9.81, timestep=[1e-3])
