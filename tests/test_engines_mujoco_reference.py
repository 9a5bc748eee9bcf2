"""The plain-Python re-implementation of MuJoCo's step (references.mujoco_steps) against MuJoCo
itself (impactsym.engines.drivers.mujoco_steps / mujoco_phases), state by state at the
user's timestep: the reference that the discrete models of impactsym.engines.mujoco are
derived independently of is shown to be MuJoCo's own update."""

from __future__ import annotations

import itertools
import math
import os

import numpy as np
import pytest
from references import mujoco_steps as reference

if os.environ.get("CI") == "true":
    import mujoco  # (CI installs the [engines] extra: a missing engine fails)
else:
    mujoco = pytest.importorskip("mujoco")

from impactsym.engines.drivers import mujoco_phases, mujoco_steps

FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)
DEFAULT = (0.9, 0.95, 0.001, 0.5, 2.0)
INTEGRATORS = ("euler", "implicitfast", "rk4")
TIMESTEPS = (0.002, 0.001, 0.0005)
PHASES = (0.0, 0.05, 0.37, 0.81, 0.995)
# solrefs cycled over the matrix: textbook, lightly damped, the direct form, overdamped
SOLREFS = ((0.02, 0.3), (0.01, 0.12), (-4000.0, -15.0), (0.02, 0.8), (0.005, 0.5))
MATRIX = [
    (integrator, dt, solimp, gravity, SOLREFS[i % len(SOLREFS)])
    for i, (integrator, dt, solimp, gravity) in enumerate(
        itertools.product(INTEGRATORS, TIMESTEPS, (FLAT, DEFAULT), (0.0, 9.81))
    )
]
# beyond MuJoCo's impedance range: it clamps d_min, d_max and the midpoint first
MATRIX += [("euler", 0.002, (5e-5, 0.99995, 0.001, 5e-5, 2.0), 9.81, SOLREFS[0])]
FLOATS = ("restitution", "contact_time", "departure_speed", "max_penetration", "peak_force")
EXACT = ("sticks", "steps", "released_by_position")


def assert_same(ref: dict, engine: dict, where: str, rel: float = 1e-10) -> None:
    """Every key equal (counts, verdicts) or within ``rel``; a resting contact to 1e-7.

    While a body rests on the plane Newton accepts a warm start within its tolerance
    (1e-8 m/s^2), so there MuJoCo's acceleration is not the exact one of the reference;
    the stick verdict, the state counts and the departure are still exact.
    """
    for key in EXACT:
        assert ref[key] == engine[key], f"{key} at {where}: {ref[key]!r} != {engine[key]!r}"
    rel = 1e-7 if ref["sticks"] else rel
    for key in FLOATS:
        a, b = ref[key], engine[key]
        if math.isinf(a) or math.isinf(b):
            assert a == b, f"{key} at {where}: {a!r} != {b!r}"
        else:
            assert a == pytest.approx(b, rel=rel, abs=1e-300), f"{key} at {where}"


@pytest.mark.parametrize(("integrator", "dt", "solimp", "gravity", "solref"), MATRIX)
def test_reference_is_mujocos_step(integrator, dt, solimp, gravity, solref):
    # one model, several touch phases; every quantity the driver reads, to 1e-10
    speed = 1.0
    engine = mujoco_phases(
        solref=solref,
        solimp=solimp,
        speed=speed,
        gravity=gravity,
        timestep=dt,
        integrator=integrator,
        phases=PHASES,
        max_steps=1500,
    )
    for i, phase in enumerate(PHASES):
        ref = reference.mujoco_steps(
            solref=solref,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=dt,
            integrator=integrator,
            phase=phase,
            max_steps=1500,
        )
        assert_same(ref, {k: v[i].item() for k, v in engine.items()}, f"phase {phase}")


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize(
    ("solref", "solimp", "speed"),
    [
        ((0.02, 1.0), FLAT, 0.05),  # settles: the contact never ends
        ((0.02, 0.3), DEFAULT, 0.05),  # low, lightly damped bounce under gravity
        ((0.02, 0.6), DEFAULT, 0.1),
    ],
)
def test_reference_sticks_where_mujoco_sticks(integrator, solref, solimp, speed):
    # under gravity at low speed: the verdict and the state counts agree
    kwargs = {
        "solref": solref,
        "solimp": solimp,
        "speed": speed,
        "gravity": 9.81,
        "timestep": 0.002,
    }
    for phase in (0.2, 0.7):
        ref = reference.mujoco_steps(**kwargs, integrator=integrator, phase=phase, max_steps=600)
        eng = mujoco_steps(**kwargs, integrator=integrator, phase=phase, max_steps=600)
        assert_same(ref, eng, f"phase {phase}")


def test_some_low_speed_case_sticks():
    # the stick cases above are not vacuous
    verdicts = [
        mujoco_steps(
            solref=(0.02, 1.0), solimp=FLAT, speed=0.05, gravity=9.81, max_steps=600, phase=p
        )["sticks"]
        for p in (0.2, 0.7)
    ]
    assert all(verdicts)


@pytest.mark.parametrize("mass", [0.3, 2.5])
def test_mass_enters_only_the_force(mass):
    # diagApprox = body_invweight0 = 1/mass for a slide-jointed body (engine_setconst.c):
    # the motion does not depend on the mass, the force scales with it
    kwargs = {"solref": (0.02, 0.3), "solimp": DEFAULT, "speed": 1.0, "gravity": 9.81, "phase": 0.4}
    for integrator in INTEGRATORS:
        eng = mujoco_steps(**kwargs, integrator=integrator, mass=mass)
        ref = reference.mujoco_steps(**kwargs, integrator=integrator, mass=mass)
        assert_same(ref, eng, f"mass {mass}")
        unit = mujoco_steps(**kwargs, integrator=integrator)
        assert eng["restitution"] == pytest.approx(unit["restitution"], rel=1e-12)
        assert eng["peak_force"] == pytest.approx(mass * unit["peak_force"], rel=1e-12)


def test_contact_at_distance_zero_is_no_constraint():
    # mj_setContact excludes a contact with dist >= includemargin (0): the sphere exactly
    # on the plane is a contact (ncon = 1) but no constraint (nefc = 0), one ulp lower is
    xml = """<mujoco><worldbody><geom type="plane" size="1 1 0.1" condim="1"/>
    <body><joint type="slide" axis="0 0 1"/><geom type="sphere" size="0.1" condim="1"/>
    </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[0] = reference.RADIUS
    mujoco.mj_forward(model, data)
    assert (data.ncon, data.nefc) == (1, 0)
    data.qpos[0] = np.nextafter(reference.RADIUS, 0.0)
    mujoco.mj_forward(model, data)
    assert (data.ncon, data.nefc) == (1, 1)
    law = reference.contact_law((0.02, 1.0), FLAT, 0.002)
    assert reference.forward(reference.RADIUS, -1.0, law, 0.0, 1.0)[1] is False


def test_phases_run_is_the_single_run():
    # mujoco_phases reuses one model (mj_resetData between phases): bit-identical results
    kwargs = {
        "solref": (0.01, 0.2),
        "solimp": DEFAULT,
        "speed": 0.7,
        "gravity": 9.81,
        "timestep": 0.001,
    }
    for integrator in INTEGRATORS:
        many = mujoco_phases(**kwargs, integrator=integrator, phases=[0.9, 0.1, 0.5])
        for i, phase in enumerate([0.9, 0.1, 0.5]):
            one = mujoco_steps(**kwargs, integrator=integrator, phase=phase)
            assert {k: v[i].item() for k, v in many.items()} == one


def test_refsafe_and_the_rk4_entry_step_matter():
    # refsafe (getsolparam): timeconst 0.002 runs as 2 dt = 0.004, in MuJoCo and here
    kwargs = {"solimp": FLAT, "speed": 1.0, "gravity": 0.0, "phase": 0.5, "timestep": 0.002}
    short = mujoco_steps(solref=(0.002, 0.3), **kwargs)
    assert short == mujoco_steps(solref=(0.004, 0.3), **kwargs)
    assert_same(reference.mujoco_steps(solref=(0.002, 0.3), **kwargs), short, "refsafe")
    # RK4 started at the first detecting state (as Euler is) instead of one step before
    # misses the stages of the entry step: a different restitution
    rk4 = mujoco_steps(solref=(0.02, 0.3), **kwargs, integrator="rk4")
    inside = reference.mujoco_steps(
        solref=(0.02, 0.3), **{**kwargs, "phase": 1.5}, integrator="rk4"
    )  # phase 1.5: the start state is (1.5 - 1) dt after touch, already in contact
    assert abs(inside["restitution"] / rk4["restitution"] - 1) > 0.01
