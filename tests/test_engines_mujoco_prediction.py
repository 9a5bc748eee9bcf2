"""MuJoCo's first contact phase (impactsym.engines.mujoco.prediction): against SciPy's
event integration of the same law and against MuJoCo itself."""

from __future__ import annotations

import importlib
import math
import os
import warnings

import numpy as np
import pytest
from references.mujoco_law import mujoco_contact

from impactsym.engines.mujoco import predict, stick_speed

if os.environ.get("CI") == "true":
    import mujoco  # noqa: F401  (CI installs the [engines] extra: a missing engine fails)
else:
    pytest.importorskip("mujoco")

from impactsym.engines.drivers import mujoco_drop

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)


@pytest.mark.parametrize(
    ("solref", "speed", "gravity"),
    [
        ((0.02, 0.3), 1.0, 0.0),
        ((0.02, 1.0), 0.5, 0.0),
        ((0.02, 0.1), 1.0, 0.0),
        ((0.01, 0.5), 0.3, 9.81),
        ((0.02, 0.2), 0.05, 9.81),
    ],
)
def test_varying_impedance_matches_event_integration(solref, speed, gravity):
    # the Runge-Kutta loop and its Hermite crossing against SciPy's events
    e, t, by_position = mujoco_contact(solref, DEFAULT, speed, gravity)
    p = predict(solref=solref, solimp=DEFAULT, speed=speed, gravity=gravity)
    assert p.restitution == pytest.approx(e, rel=1e-6)
    assert p.contact_time == pytest.approx(t, rel=1e-7)
    assert p.released_by_position == by_position


def test_varying_integrator_agrees_with_closed_form_when_the_impedance_is_flat():
    # a varying solimp whose width is far below the penetration acts like d_max
    wide = (0.9, 0.9 + 1e-9, 1e-9, 0.5, 2.0)
    for g in (0.0, 9.81):
        a = predict(solref=(0.02, 0.4), solimp=wide, speed=np.array([0.2, 1.0]), gravity=g)
        b = predict(solref=(0.02, 0.4), solimp=FLAT, speed=np.array([0.2, 1.0]), gravity=g)
        np.testing.assert_allclose(a.restitution, b.restitution, rtol=1e-5)
        np.testing.assert_allclose(a.contact_time, b.contact_time, rtol=1e-4)


def test_slow_impacts_under_gravity_lose_contact_while_still_pressed():
    # MuJoCo's own behaviour: at low speed the body leaves through x = 0 with f > 0
    sr = (0.02, 0.2)
    p = predict(solref=sr, solimp=FLAT, speed=0.05, gravity=9.81)
    assert p.released_by_position
    assert not p.sticks
    e, t = mujoco_drop(solref=sr, solimp=FLAT, speed=0.05, gravity=9.81, timestep=2e-6)
    assert e == pytest.approx(p.restitution, rel=0.01)
    assert t == pytest.approx(p.contact_time, rel=0.02)


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


def test_a_timestep_gives_the_engines_own_contact_and_warns_where_unstable():
    # replaces the old one-parameter "too coarse" warning: with a timestep the
    # prediction is MuJoCo's discrete contact itself (here where the old warning fired)
    from impactsym.engines.drivers import mujoco_steps

    p = predict(solref=(0.02, 0.05), solimp=FLAT, speed=1.0, timestep=1e-3, phase=0.3)
    run = mujoco_steps(solref=(0.02, 0.05), solimp=FLAT, speed=1.0, timestep=1e-3, phase=0.3)
    assert p.restitution == pytest.approx(run["restitution"], rel=1e-9)
    assert p.contact_time == pytest.approx(run["contact_time"], rel=1e-9)
    assert p.restitution_range == (p.restitution, p.restitution)
    # an unstable in-contact map warns, naming a stable timestep
    with pytest.warns(RuntimeWarning, match=r"spectral radius .* timestep < 0\.000"):
        predict(solref=(0.02, 0.01), solimp=FLAT, speed=1.0, timestep=0.002, phase=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        predict(solref=(0.02, 0.01), solimp=FLAT, speed=1.0, timestep=0.0003, phase=0.5)


def test_bad_inputs_are_refused_by_name():
    with pytest.raises(ValueError, match="speed"):
        predict(solref=(0.02, 1.0), speed=-1.0)
    with pytest.raises(ValueError, match="solref"):
        predict(solref=(0.02, -1.0), speed=1.0)
    with pytest.raises(TypeError, match="solimp"):
        predict(solref=(0.02, 1.0), solimp="0.9 0.95", speed=1.0)
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


def test_stick_speed_is_where_mujoco_starts_to_hold_the_body():
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


def test_stick_speed_range_ends_are_answers_mujoco_confirms():
    # undamped: it never sticks (0.0, not the end of the search range)
    assert stick_speed(solref=(-1e4, 0.0), solimp=FLAT, gravity=9.81) == 0.0
    e, t = mujoco_drop(
        solref=(-1e4, 0.0), solimp=FLAT, speed=0.01, gravity=9.81, timestep=2e-6, t_max=0.1
    )
    assert e > 0.5
    assert math.isfinite(t)
    # hugely overdamped: it sticks at every speed (inf, not the end of the search range)
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
    # the rest is proven early instead of integrating ~3e6 Runge-Kutta steps
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
    prediction = importlib.import_module("impactsym.engines.mujoco.prediction")
    continuous = importlib.import_module("impactsym.engines.mujoco.continuous")

    # static penetration inside the impedance width: rest is not provable, and the
    # horizon needs > 400 000 steps: refused at once, naming the solref
    with pytest.raises(ValueError, match=r"solref = \(0\.002, 10\)"):
        predict(solref=(0.002, 10.0), speed=0.1, gravity=9.81)
    # the same contact in the stiffness form is named in both forms
    with pytest.raises(ValueError, match=r"\(-2500, -1000\)"):
        predict(solref=(-2500.0, -1000.0), speed=0.1, gravity=9.81)
    # the loop's own cap (a backstop) names it too
    monkeypatch.setattr(continuous, "_MAX_RK_STEPS", 50)
    with pytest.raises(ValueError, match="solref = "):
        prediction.predict(solref=(0.02, 2.0), speed=0.01, gravity=9.81)


def test_array_arguments_that_must_be_one_number_are_named():
    with pytest.raises(ValueError, match="gravity"):
        stick_speed(solref=(0.02, 0.5), solimp=FLAT, gravity=[9.81, 1.0])
    with pytest.raises(ValueError, match="timestep"):
        predict(solref=(0.02, 0.5), speed=1.0, timestep=[1e-3])
    with pytest.raises(ValueError, match="timestep"):
        stick_speed(solref=(0.02, 0.5), solimp=FLAT, gravity=9.81, timestep=[1e-3])


def test_the_package_keeps_its_public_names():
    import impactsym.engines.mujoco as mj

    assert mj.predict is predict
    assert set(mj.__all__) == {
        "DEFAULT_SOLIMP",
        "DEFAULT_TIMECONST",
        "Design",
        "Prediction",
        "TimestepAdvice",
        "from_reduced",
        "impedance",
        "predict",
        "solref_for",
        "stick_speed",
        "timestep_for",
    }
    assert all(hasattr(mj, name) for name in mj.__all__)
