"""Drive Drake itself: a sphere on a prismatic joint drops on a half space with point contact.

The tests compare these runs with :mod:`impactsym.engines.drake`. They need Drake
(``pip install impactsym[engines]``); it is imported inside the functions, so this module
imports without it. ``stiffness``, ``dissipation`` and ``relaxation_time`` are the
combined values of the pair: the sphere (radius 0.1 m) and the half space each carry
``2 k``, ``d`` and ``tau/2``, which Drake's rules combine exactly into ``k``, ``d`` and
``tau`` (a rigid half space, ``point_contact_stiffness = inf``, makes Drake's contact
point NaN). ``pair=((k_ball, d_ball), (k_plane, d_plane))`` sets the two geometries
instead, to check the combination rules. Friction is zero.

* :func:`drake_phases`: a discrete plant (``time_step > 0``) stepped one update at a
  time with ``EvalUniquePeriodicDiscreteUpdate`` (``use_sampled_output_ports=False``, so
  that the contact results are those of the update from the current state), read state
  by state with the definitions of :mod:`impactsym.engines.drake.stepping`.
* :func:`drake_continuous`: a continuous plant (``time_step = 0``) under a
  :class:`Simulator` with an error-controlled fifth-order Runge–Kutta integrator; the
  release is located from the free flight after it (exact).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

RADIUS = 0.1


def _plant(*, time_step, approximation, stiffness, dissipation, mass, gravity, relaxation_time,
           pair):  # fmt: skip
    from pydrake.geometry import (
        AddContactMaterial,
        HalfSpace,
        ProximityProperties,
        Sphere,
    )
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import (
        AddMultibodyPlant,
        CoulombFriction,
        MultibodyPlantConfig,
    )
    from pydrake.multibody.tree import PrismaticJoint, SpatialInertia, UnitInertia
    from pydrake.systems.framework import DiagramBuilder

    config = MultibodyPlantConfig(
        time_step=float(time_step),
        contact_model="point",
        use_sampled_output_ports=False,
    )
    if approximation is not None:
        config.discrete_contact_approximation = approximation
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(config, builder)
    inertia = SpatialInertia(float(mass), np.zeros(3), UnitInertia.SolidSphere(RADIUS))
    body = plant.AddRigidBody("ball", inertia)
    plant.AddJoint(PrismaticJoint("z", plant.world_frame(), body.body_frame(), [0, 0, 1]))
    if pair is None:
        pair = ((2.0 * stiffness, dissipation), (2.0 * stiffness, dissipation))
    tau = 0.1 if relaxation_time is None else 0.5 * float(relaxation_time)
    (k_ball, d_ball), (k_plane, d_plane) = pair
    geometries = (
        ("ball", Sphere(RADIUS), body, k_ball, d_ball, tau),
        ("plane", HalfSpace(), plant.world_body(), k_plane, d_plane, tau),
    )
    for name, shape, frame, k, d, tau in geometries:
        props = ProximityProperties()
        AddContactMaterial(
            dissipation=float(d),
            point_stiffness=float(k),
            friction=CoulombFriction(0.0, 0.0),
            properties=props,
        )
        props.AddProperty("material", "relaxation_time", float(tau))
        plant.RegisterCollisionGeometry(frame, RigidTransform(), shape, name, props)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -float(gravity)])
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    return diagram, plant, context


def drake_phases(
    *,
    stiffness,
    dissipation,
    mass,
    speed,
    gravity=0.0,
    time_step=1e-3,
    approximation="lagged",
    phases,
    relaxation_time=None,
    pair=None,
    max_steps=100_000,
) -> dict[str, np.ndarray]:
    """A sphere hits the half space at Drake's ``time_step``, read state by state per phase.

    Each run starts at the first detecting state, ``phase * time_step`` after geometric
    touch, with the free-flight penetration ``speed t + g t^2/2`` and approach speed
    ``speed + g t``. A state's force is the contact result of the update from it. The
    contact ends at the first state without contact or with zero normal force
    (below ``1e-12 mass speed / time_step`` counts as zero, as in
    :mod:`impactsym.engines.drake.stepping`; ``restitution``: its separation speed over
    ``speed``; ``contact_time``: touch to
    it); if the force comes back while the overlap lasts, or the contact never ends
    within ``max_steps`` updates, the body sticks. ``relaxation_time`` is the combined
    value (``None``: Drake's default 0.1 s on each geometry, 0.2 s).
    Returns a dict of arrays, one entry per phase: ``restitution``, ``contact_time``,
    ``sticks``, ``departure_speed``, ``steps``, ``max_penetration``, ``peak_force``.
    """
    diagram, plant, context = _plant(
        time_step=time_step,
        approximation=approximation,
        stiffness=stiffness,
        dissipation=dissipation,
        mass=mass,
        gravity=gravity,
        relaxation_time=relaxation_time,
        pair=pair,
    )
    pc = plant.GetMyMutableContextFromRoot(context)
    port = plant.get_contact_results_output_port()
    zero = 1e-12 * mass * speed / time_step  # as in the model: rounding

    def state() -> tuple[bool, float, float, float]:
        results = port.Eval(pc)
        touching = results.num_point_pair_contacts() > 0
        force = -results.point_pair_contact_info(0).contact_force()[2] if touching else 0.0
        rate = float(plant.GetVelocities(pc)[0])
        return touching, force, rate, RADIUS - float(plant.GetPositions(pc)[0])

    def advance() -> None:
        context.SetDiscreteState(diagram.EvalUniquePeriodicDiscreteUpdate(context))

    runs = []
    for phase in phases:
        t = float(phase) * time_step
        plant.SetPositions(pc, [RADIUS - (speed * t + 0.5 * gravity * t * t)])
        plant.SetVelocities(pc, [-(speed + gravity * t)])
        runs.append(read_run(state, advance, speed=speed, start=t, time_step=time_step,
                             zero=zero, max_steps=max_steps))  # fmt: skip
    return {key: np.array([run[key] for run in runs]) for key in runs[0]}


def read_run(
    state: Any,
    advance: Any,
    *,
    speed: float,
    start: float,
    time_step: float,
    zero: float,
    max_steps: int,
) -> dict[str, Any]:
    """One run read state by state with the definitions of :func:`drake_phases` (used
    by it and by the box-corner driver).

    ``state()`` gives the current state's ``(touching, force, rate, penetration)``: the
    compressive normal force of its update, the separation rate along the normal and the
    penetration; ``advance()`` carries the plant one update on; ``start`` is the first
    state's time after touch. A force at or below ``zero`` counts as zero. Returns
    ``restitution``, ``contact_time``, ``sticks``, ``departure_speed``, ``steps``,
    ``max_penetration`` and ``peak_force``.
    """
    out = {"sticks": False, "max_penetration": 0.0, "peak_force": 0.0, "steps": 0}
    ended, t = False, start
    for _ in range(max_steps):
        touching, force, rate, penetration = state()
        if force <= zero:
            force = 0.0
        if ended and touching and force > 0:
            out.update(sticks=True)
            break
        if not ended and (not touching or force <= 0):
            out.update(restitution=rate / speed, contact_time=t)
            ended = True
        if ended and not touching:
            out["departure_speed"] = rate
            break
        if not ended:
            out["max_penetration"] = max(out["max_penetration"], penetration)
            out["peak_force"] = max(out["peak_force"], force)
            out["steps"] += 1
        advance()
        t += time_step
    else:
        out["sticks"] = True
    if out["sticks"]:
        out.update(restitution=0.0, contact_time=math.inf, departure_speed=0.0)
    return out


def drake_continuous(
    *,
    stiffness,
    dissipation,
    mass,
    speed,
    gravity=0.0,
    pair=None,
    accuracy=1e-14,
    t_max=None,
) -> dict[str, Any]:
    """The sphere hits the half space on a continuous plant (``time_step = 0``).

    Runs a :class:`Simulator` (``runge_kutta5``, target accuracy ``accuracy``) from touch
    in chunks of a hundredth of ``sqrt(m/k)`` until the sphere is clear of the plane,
    then places the release from the free flight: ``v_out^2 = v^2 + 2 g (z - R)`` and the
    time back to ``z = R``. ``max_penetration`` is the largest over the integrator's
    steps (a monitor), refined by the cubic Hermite interpolant of the two steps
    around the turn. Sticks if not clear by ``t_max`` (default ``200 sqrt(m/k)``).
    Returns a dict: ``restitution``, ``contact_time``, ``sticks``, ``max_penetration``.
    """
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
    from pydrake.systems.framework import EventStatus

    diagram, plant, context = _plant(
        time_step=0.0,
        approximation=None,
        stiffness=stiffness,
        dissipation=dissipation,
        mass=mass,
        gravity=gravity,
        relaxation_time=None,
        pair=pair,
    )
    if pair is not None:
        stiffness = pair[0][0] * pair[1][0] / (pair[0][0] + pair[1][0])
    scale = math.sqrt(mass / stiffness)
    t_max = 200.0 * scale if t_max is None else t_max
    pc = plant.GetMyMutableContextFromRoot(context)
    plant.SetPositions(pc, [RADIUS])
    plant.SetVelocities(pc, [-float(speed)])
    simulator = Simulator(diagram, context)
    ResetIntegratorFromFlags(simulator, "runge_kutta5", 0.01 * scale)
    simulator.get_mutable_integrator().set_target_accuracy(accuracy)
    deepest = [0.0]
    last = []

    def monitor(root):
        z = float(plant.GetPositions(plant.GetMyContextFromRoot(root))[0])
        w = float(plant.GetVelocities(plant.GetMyContextFromRoot(root))[0])
        sample = (root.get_time(), RADIUS - z, -w)  # time, penetration, its rate
        deepest[0] = max(deepest[0], sample[1])
        if last and last[0][2] > 0 >= sample[2]:  # the turn: cubic Hermite between steps
            deepest[0] = max(deepest[0], _hermite_peak(last[0], sample))
        last[:] = [sample]
        return EventStatus.DidNothing()

    simulator.set_monitor(monitor)
    simulator.Initialize()
    t = 0.0
    while t < t_max:
        t += 0.01 * scale
        simulator.AdvanceTo(t)
        z = float(plant.GetPositions(pc)[0])
        w = float(plant.GetVelocities(pc)[0])
        if z > RADIUS and w > 0:
            v_out = math.sqrt(w * w + 2.0 * gravity * (z - RADIUS))
            back = (v_out - w) / gravity if gravity else (z - RADIUS) / w
            return {
                "restitution": v_out / speed,
                "contact_time": context.get_time() - back,
                "sticks": False,
                "max_penetration": deepest[0],
            }
    return {"restitution": 0.0, "contact_time": math.inf, "sticks": True,
            "max_penetration": deepest[0]}  # fmt: skip


def _hermite_peak(a, b) -> float:
    """Largest value of the cubic Hermite interpolant through ``(t, p, p')`` samples."""
    (t0, p0, q0), (t1, p1, q1) = a, b
    dt = t1 - t0
    # p(s) on s in [0, 1]: Hermite basis; p'(s) = A s^2 + B s + C
    c = (p0, q0 * dt, 3 * (p1 - p0) - (2 * q0 + q1) * dt, 2 * (p0 - p1) + (q0 + q1) * dt)
    roots = np.roots([3 * c[3], 2 * c[2], c[1]])
    best = max(p0, p1)
    for r in roots[np.isreal(roots)].real:
        if 0.0 <= r <= 1.0:
            best = max(best, c[0] + c[1] * r + c[2] * r * r + c[3] * r**3)
    return float(best)
