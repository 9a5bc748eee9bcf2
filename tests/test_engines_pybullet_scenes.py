"""PyBullet's contact in a multibody scene: a free box touching the plane with a corner, 240 Hz.

The box (2 kg, principal inertia near the largest a box of its size can have) is tilted so
that one corner touches first. Its contact row reduces
(:func:`impactsym.multibody.reduce_contact`, the base's six velocities and mass matrix at
touch) to the scalar contact of :mod:`impactsym.engines.pybullet` with the effective mass
``m~ = 0.39 m``; the driver reads the corner's penetration and rate from PyBullet's pose
and base velocity. What is exact and what drifts:

* the first contact step (before the box turns) is the scalar map with ``m~`` to rounding;
* after it the corner's lever turns and its centripetal acceleration ``w^2 |r|`` lifts it:
  a drift of relative size about ``v t_c / (e |r|)``. At 240 Hz a contact lasts several
  4-ms steps and its restitution is small, so the drift is large except for **slow
  contacts without gravity** (0.05 m/s: 0.3-0.4 %), where predictions and designs hold
  within 0.5 %. Under gravity a bouncing corner needs some speed at 240 Hz and the
  measured drift is ~10 % (:func:`test_under_gravity_the_rotation_drift_is_large`);
* the body map (:func:`impactsym.engines.pybullet.predict_body`: the box stepped as PyBullet
  steps it, the row's effective mass, lever and load updated each step) is exact to
  rounding at every phase, under gravity too, gets the stick verdict right where the
  frozen one fails, and its design (:func:`impactsym.engines.pybullet.body_contact_for`)
  delivers under gravity within 0.5 %.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from impactsym.engines import pybullet as pyb
from impactsym.engines.pybullet.stepping import DEFAULT_SLOP
from impactsym.multibody import reduce_contact

pytest.importorskip("pybullet")

from impactsym.engines.drake.box_driver import lowest_corner
from impactsym.engines.pybullet.body import box_breaking_threshold, effective_mass, pivot_budget
from impactsym.engines.pybullet.box_driver import pybullet_box_steps

BOX = {"mass": 2.0, "inertia": (0.08, 0.12, 0.16), "half_extents": (0.3, 0.2, 0.15),
       "tilt": (0.3, 0.2, 0.1)}  # fmt: skip
PHASES = np.array([0.0, 0.3, 0.7, 0.95])
H = 1 / 240
SLOW = {"stiffness": 1e4, "damping": 0.0, "speed": 0.05}


def _reduced(gravity):
    """``(m~, g~)`` of the corner contact from the base's velocities and mass matrix."""
    _, lever, rotation = lowest_corner(BOX["half_extents"], BOX["tilt"])
    m = BOX["mass"]
    matrix = np.zeros((6, 6))  # velocities: the centre's (world), the angular (world)
    matrix[:3, :3] = m * np.eye(3)
    matrix[3:, 3:] = rotation @ np.diag(BOX["inertia"]) @ rotation.T
    normal = -np.concatenate([[0.0, 0.0, 1.0], np.cross(lever, [0.0, 0.0, 1.0])])
    q, u = sp.symbols("q0:6"), sp.symbols("u0:6")
    at = {**dict.fromkeys(q, 0.0), **dict.fromkeys(u, 0.0), u[2]: -1.0}
    force = np.array([0.0, 0.0, -m * gravity, 0.0, 0.0, 0.0])
    red = reduce_contact(matrix, force, normal, q, u, at, k=1.0, d=0.0)
    return float(red.m_eff), float(red.load / red.m_eff)


def _first_impulse(k, c, m, v, g, p):
    """The first positive impulse of the one-step map of
    :mod:`impactsym.engines.pybullet.stepping`, iterated from state -1 (free flight)."""
    t = (p - 1.0) * H
    x, w = v * t + 0.5 * g * t * t, v + g * t
    erp, cfm = H * k / (H * k + c), 1.0 / (H * k + c)
    first = np.zeros_like(x)
    for _ in range(3):  # the force starts at state 0 (speculative) or 1
        gap = DEFAULT_SLOP - x
        b = w + g * H - np.where(gap > 0, gap, erp * gap) / H
        impulse = np.maximum(0.0, b / (1.0 / m + cfm / H))
        first = np.where(first > 0, first, impulse)
        w = w + g * H - impulse / m
        x = x + H * w
    assert np.all(first > 0)
    return first


@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_the_first_contact_step_is_the_reduced_map(gravity):
    m_eff, g_eff = _reduced(gravity)
    law = {"stiffness": 1e4, "damping": 20.0, "speed": 0.5}
    run = pybullet_box_steps(**BOX, **law, gravity=gravity, phase=PHASES)
    k, c = law["stiffness"], law["damping"] + 0.1  # the plane's default damping adds
    want = _first_impulse(k, c, m_eff, law["speed"], g_eff, PHASES)
    np.testing.assert_allclose(run["first_impulse"], want, rtol=1e-9)
    bare = _first_impulse(k, c, BOX["mass"], law["speed"], gravity, PHASES)
    assert np.all(np.abs(run["first_impulse"] / bare - 1.0) > 0.1)  # m~ is not m


def test_a_slow_corner_without_gravity_is_predicted_per_phase():
    m_eff, _ = _reduced(0.0)
    run = pybullet_box_steps(**BOX, **SLOW, phase=PHASES)
    p = pyb.predict(**SLOW, mass=m_eff, phase=PHASES)
    np.testing.assert_array_equal(run["sticks"], p.sticks)
    np.testing.assert_allclose(run["restitution"], p.restitution, rtol=5e-3)
    np.testing.assert_allclose(run["contact_time"], p.contact_time, rtol=1e-12)  # whole steps
    bare = pyb.predict(**SLOW, mass=BOX["mass"], phase=PHASES)
    assert np.all(np.abs(run["restitution"] / bare.restitution - 1.0) > 0.2)


def test_a_design_for_the_reduced_mass_delivers_in_the_box():
    m_eff, _ = _reduced(0.0)
    target_e, target_t, speed = 0.45, 0.03, 0.05
    design = pyb.contact_for(restitution=target_e, contact_time=target_t, mass=m_eff,
                             speed=speed)  # fmt: skip
    phases = (np.arange(16) + 0.5) / 16
    run = pybullet_box_steps(**BOX, stiffness=design.stiffness, damping=design.damping,
                             speed=speed, phase=phases)  # fmt: skip
    assert run["restitution"].mean() == pytest.approx(target_e, rel=5e-3)
    assert run["contact_time"].mean() == pytest.approx(target_t, rel=5e-3)


def test_under_gravity_the_rotation_drift_is_large():
    # k = 1e4, no damping, 0.3 m/s at 240 Hz: a 9-10 step contact, e = 0.17-0.25 with m~.
    # The corner leaves 10-12 % faster than the frozen reduction says (measured
    # +9.9 % to +12.1 % over the phases); at a third of the speed without gravity the
    # drift is below a tenth of that
    m_eff, g_eff = _reduced(9.81)
    law = {"stiffness": 1e4, "damping": 0.0, "speed": 0.3}
    run = pybullet_box_steps(**BOX, **law, gravity=9.81, phase=PHASES)
    p = pyb.predict(**law, mass=m_eff, gravity=g_eff, phase=PHASES)
    drift = run["restitution"] / p.restitution - 1.0
    assert np.all((drift > 0.09) & (drift < 0.13))
    np.testing.assert_allclose(run["contact_time"], p.contact_time, rtol=1e-12)


def test_the_stick_verdict_for_the_corner():
    # under gravity a slow corner stays: still in contact after 30 steps (the bounce of
    # the case above lasts 10), where the box starts to pivot on it and to topple, which
    # the scalar contact does not describe; without gravity the same corner leaves
    m_eff, g_eff = _reduced(9.81)
    law = {"stiffness": 1e4, "damping": 0.0, "speed": 0.15}
    assert pyb.predict(**law, mass=m_eff, gravity=g_eff, phase=PHASES).sticks.all()
    run = pybullet_box_steps(**BOX, **law, gravity=9.81, phase=PHASES, budget=30)
    assert run["sticks"].all()
    assert not pyb.predict(**law, mass=m_eff, phase=PHASES).sticks.any()
    run = pybullet_box_steps(**BOX, **law, phase=PHASES, budget=30)
    assert not run["sticks"].any()


def _body():
    corner, _, rotation = lowest_corner(BOX["half_extents"], BOX["tilt"])
    return {"mass": BOX["mass"], "inertia": BOX["inertia"], "orientation": rotation,
            "point": corner}  # fmt: skip


def test_the_effective_mass_is_the_reduction():
    m_eff, _ = _reduced(0.0)
    assert effective_mass(**_body()) == pytest.approx(m_eff, rel=1e-12)
    p = pyb.predict_body(stiffness=1e4, damping=0.0, speed=0.3, phase=0.5, **_body())
    assert p.effective_mass == pytest.approx(m_eff, rel=1e-12)


@pytest.mark.parametrize(
    ("law", "gravity"),
    [
        ({"stiffness": 1e4, "damping": 0.0, "speed": 0.3}, 9.81),  # the drift case above
        ({"stiffness": 1e4, "damping": 20.0, "speed": 0.5}, 9.81),
        (SLOW, 0.0),
    ],
)
def test_the_body_map_is_exact_per_phase(law, gravity):
    run = pybullet_box_steps(**BOX, **law, gravity=gravity, phase=PHASES)
    p = pyb.predict_body(**law, **_body(), gravity=gravity, phase=PHASES)
    np.testing.assert_array_equal(run["sticks"], p.sticks)
    np.testing.assert_allclose(p.restitution, run["restitution"], rtol=1e-9)
    np.testing.assert_allclose(p.contact_time, run["contact_time"], rtol=1e-12)
    # the frozen scalar prediction beside it, for the same phases
    frozen = np.abs(p.frozen.restitution / run["restitution"] - 1.0)
    body = np.abs(p.restitution / run["restitution"] - 1.0)
    assert np.all(body <= frozen / 5)
    if law["speed"] == 0.3:
        assert np.all(body < 5e-3)
        assert np.all(frozen > 0.09)


def test_the_body_map_gets_the_stick_verdict_right_where_the_frozen_one_fails():
    # 0.25 m/s under gravity: the frozen reduction holds the corner on at every phase,
    # PyBullet bounces it off in 10 steps, as the body map says
    law = {"stiffness": 1e4, "damping": 0.0, "speed": 0.25}
    p = pyb.predict_body(**law, **_body(), gravity=9.81, phase=PHASES)
    assert p.frozen.sticks.all()
    assert not p.sticks.any()
    run = pybullet_box_steps(**BOX, **law, gravity=9.81, phase=PHASES)
    assert not run["sticks"].any()
    np.testing.assert_allclose(p.restitution, run["restitution"], rtol=1e-9)
    # 0.15 m/s: the box pivots on its corner past the body map's budget (two periods),
    # in PyBullet too (a second corner lands after 37 steps: beyond one point)
    law["speed"] = 0.15
    p = pyb.predict_body(**law, **_body(), gravity=9.81, phase=PHASES)
    budget = int(pivot_budget(1e4, 0.1, p.effective_mass, H))
    assert p.sticks.all()
    run = pybullet_box_steps(**BOX, **law, gravity=9.81, phase=PHASES, budget=budget)
    assert run["sticks"].all()


def test_a_body_design_under_gravity_delivers_in_the_box():
    # under gravity at 240 Hz the frozen scalar map sticks at some phase for slow
    # corners, so the design is for 2 m/s; the frozen prediction of the same design
    # misses the restitution by more than 15 %. At 2 m/s the gap before touch (up to
    # v h = 8.3 mm) can exceed Bullet's contact-breaking threshold for the box (7.8 mm):
    # no speculative row there, which breaking_threshold models
    target_e, target_t, speed = 0.3, 0.04, 2.0
    limit = box_breaking_threshold(BOX["half_extents"])
    design = pyb.body_contact_for(restitution=target_e, contact_time=target_t, speed=speed,
                                  gravity=9.81, breaking_threshold=limit, **_body())  # fmt: skip
    assert design.restitution == pytest.approx(target_e, rel=1e-3)
    assert design.contact_time == pytest.approx(target_t, rel=1e-3)
    assert abs(design.frozen.restitution / target_e - 1.0) > 0.15
    phases = (np.arange(16) + 0.5) / 16
    law = {"stiffness": design.stiffness, "damping": design.damping, "speed": speed}
    run = pybullet_box_steps(**BOX, **law, gravity=9.81, phase=phases)
    assert run["restitution"].mean() == pytest.approx(target_e, rel=5e-3)
    assert run["contact_time"].mean() == pytest.approx(target_t, rel=5e-3)
    # per phase the body map is exact with the threshold, and off at the first phase
    # (gap 8.1 mm: PyBullet has no point there) without it
    p = pyb.predict_body(**law, gravity=9.81, phase=phases, breaking_threshold=limit,
                         **_body())  # fmt: skip
    np.testing.assert_allclose(p.restitution, run["restitution"], rtol=1e-9)
    np.testing.assert_allclose(p.contact_time, run["contact_time"], rtol=1e-12)
    p = pyb.predict_body(**law, gravity=9.81, phase=phases, **_body())
    assert abs(p.restitution[0] / run["restitution"][0] - 1.0) > 0.01


@pytest.mark.parametrize(
    ("change", "word"),
    [
        ({"inertia": (0.1, 0.1, 0.3)}, "triangle"),
        ({"inertia": (0.1, 0.1)}, "inertia"),
        ({"orientation": np.diag([1.0, 1.0, -1.0])}, "orientation"),
        ({"orientation": np.eye(3) * 2.0}, "orientation"),
        ({"point": (0.1, 0.2)}, "point"),
        ({"mass": -1.0}, "mass"),
        ({"breaking_threshold": [0.1, 0.2]}, "breaking_threshold"),
    ],
)
def test_a_bad_body_is_refused_naming_it(change, word):
    body = {**_body(), **change}
    with pytest.raises(ValueError, match=word):
        pyb.predict_body(stiffness=1e4, damping=0.0, speed=0.3, phase=0.5, **body)
