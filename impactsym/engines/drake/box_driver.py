"""Drive Drake itself: a free box, tilted so that one corner touches a half space first.

The multibody scene of the tests of :mod:`impactsym.engines.drake` (and a check for a
design in a rotating body). A box of ``mass``, central principal ``inertia`` (the box's
axes) and ``half_extents`` is a free body (six degrees of freedom) oriented by
``tilt = (roll, pitch, yaw)`` so that one corner, :func:`lowest_corner`, is the lowest
point; it translates without rotation until it touches. The scalar contact it reduces to
(:func:`impactsym.multibody.reduce_contact`) has the effective mass
``1/m~ = 1/m + (r x n)^T I_W^-1 (r x n)`` at the corner ``r`` (from the centre of mass,
world frame), normal ``n = e_z``, and the pressing acceleration ``g`` of the free flight.
As in :mod:`~impactsym.engines.drake.driver`, each geometry carries twice the pair's
stiffness and the pair's dissipation; friction is zero. The corner's penetration and
approach rate are read from the body's pose and spatial velocity (``x = -z_c``,
``x' = -(v + w x r)_z``), so the scalar quantities are the engine's own, including what
the rotation during contact does to them. Drake is imported inside the functions.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from impactsym.engines.drake.driver import read_run

__all__ = ["drake_box_continuous", "drake_box_phases", "lowest_corner"]


def lowest_corner(half_extents: Any, tilt: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The box's lowest corner at orientation ``tilt = (roll, pitch, yaw)`` (radians).

    Returns ``(corner, lever, rotation)``: the corner in the body frame, the same corner
    from the centre of mass in the world frame, and the rotation matrix ``R_WB`` (Drake's
    ``RollPitchYaw`` convention: ``R = Rz(yaw) Ry(pitch) Rx(roll)``). Raises
    ``ValueError`` when two corners are within 1e-9 of the lowest height (an edge or a
    face would touch, not a corner).
    """
    half = np.asarray(half_extents, float)
    roll, pitch, yaw = (float(a) for a in tilt)
    cr, sr, cp, sp, cy, sy = (f(a) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    rotation = np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip
    signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], float)
    corners = signs * half
    heights = corners @ rotation[2]
    order = np.argsort(heights)
    if heights[order[1]] - heights[order[0]] < 1e-9 * float(np.max(half)):
        raise ValueError(f"tilt={tuple(tilt)} puts an edge or a face on the plane, not a corner")
    corner = corners[order[0]]
    return corner, rotation @ corner, rotation


def _box_plant(*, time_step, approximation, stiffness, dissipation, mass, inertia, half_extents,
               gravity):  # fmt: skip
    from pydrake.geometry import AddContactMaterial, Box, HalfSpace, ProximityProperties
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import (
        AddMultibodyPlant,
        CoulombFriction,
        MultibodyPlantConfig,
    )
    from pydrake.multibody.tree import RotationalInertia, SpatialInertia
    from pydrake.systems.framework import DiagramBuilder

    config = MultibodyPlantConfig(
        time_step=float(time_step), contact_model="point", use_sampled_output_ports=False
    )
    if approximation is not None:
        config.discrete_contact_approximation = approximation
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(config, builder)
    spatial = SpatialInertia.MakeFromCentralInertia(
        float(mass), np.zeros(3), RotationalInertia(*(float(i) for i in inertia))
    )
    body = plant.AddRigidBody("box", spatial)
    size = 2.0 * np.asarray(half_extents, float)
    for name, shape, frame in (
        ("box", Box(*size), body),
        ("plane", HalfSpace(), plant.world_body()),
    ):
        props = ProximityProperties()
        AddContactMaterial(
            dissipation=float(dissipation),
            point_stiffness=2.0 * float(stiffness),
            friction=CoulombFriction(0.0, 0.0),
            properties=props,
        )
        plant.RegisterCollisionGeometry(frame, RigidTransform(), shape, name, props)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -float(gravity)])
    plant.Finalize()
    diagram = builder.Build()
    return diagram, plant, body, diagram.CreateDefaultContext()


def _place(plant, body, pc, rotation, lever, depth, rate):
    """Pose the box with its corner at penetration ``depth``, translating at ``-rate``."""
    from pydrake.math import RigidTransform, RotationMatrix
    from pydrake.multibody.math import SpatialVelocity

    position = np.array([0.0, 0.0, -lever[2] - depth])
    plant.SetFreeBodyPose(pc, body, RigidTransform(RotationMatrix(rotation), position))
    velocity = SpatialVelocity(np.zeros(3), np.array([0.0, 0.0, -rate]))
    plant.SetFreeBodySpatialVelocity(pc, body, velocity)


def _corner_state(plant, body, pc, corner):
    """Penetration and approach rate of the corner (body-frame point ``corner``)."""
    pose = plant.EvalBodyPoseInWorld(pc, body)
    twist = plant.EvalBodySpatialVelocityInWorld(pc, body)
    lever = pose.rotation().matrix() @ corner
    rate = twist.translational() + np.cross(twist.rotational(), lever)
    return -(pose.translation()[2] + lever[2]), -float(rate[2])


def drake_box_phases(
    *,
    stiffness: float,
    dissipation: float,
    mass: float,
    inertia: Any,
    half_extents: Any,
    tilt: Any,
    speed: float,
    gravity: float = 0.0,
    time_step: float = 1e-3,
    approximation: str = "lagged",
    phases: Any,
    max_steps: int = 100_000,
) -> dict[str, np.ndarray]:
    """The box's corner hits the half space at Drake's ``time_step``, read per phase.

    The definitions of :func:`impactsym.engines.drake.driver.drake_phases` applied to the
    corner: each run starts at the first detecting state, ``phase * time_step`` after the
    corner's geometric touch (penetration ``speed t + g t^2/2``, approach rate
    ``speed + g t``, no rotation yet); a state's force is the contact result of the update
    from it; the contact ends at the first state without contact or with zero normal
    force (``restitution``: the corner's separation rate there over ``speed``,
    ``contact_time``: touch to it); the force coming back inside the overlap, or no end
    within ``max_steps`` updates, is a stick (read by
    :func:`~impactsym.engines.drake.driver.read_run`). Returns a dict of arrays, one entry
    per phase: ``restitution``, ``contact_time``, ``sticks``, ``departure_speed``,
    ``steps``, ``max_penetration``, ``peak_force``.
    """
    corner, lever, rotation = lowest_corner(half_extents, tilt)
    diagram, plant, body, context = _box_plant(
        time_step=time_step,
        approximation=approximation,
        stiffness=stiffness,
        dissipation=dissipation,
        mass=mass,
        inertia=inertia,
        half_extents=half_extents,
        gravity=gravity,
    )
    pc = plant.GetMyMutableContextFromRoot(context)
    port = plant.get_contact_results_output_port()
    zero = 1e-12 * mass * speed / time_step

    def state() -> tuple[bool, float, float, float]:
        results = port.Eval(pc)
        touching = results.num_point_pair_contacts() > 0
        force = abs(results.point_pair_contact_info(0).contact_force()[2]) if touching else 0.0
        depth, rate = _corner_state(plant, body, pc, corner)
        return touching, force, -rate, depth

    def advance() -> None:
        context.SetDiscreteState(diagram.EvalUniquePeriodicDiscreteUpdate(context))

    runs = []
    for phase in np.atleast_1d(np.asarray(phases, float)):
        t = float(phase) * time_step
        _place(plant, body, pc, rotation, lever, speed * t + 0.5 * gravity * t * t,
               speed + gravity * t)  # fmt: skip
        runs.append(read_run(state, advance, speed=speed, start=t, time_step=time_step,
                             zero=zero, max_steps=max_steps))  # fmt: skip
    return {key: np.array([run[key] for run in runs]) for key in runs[0]}


def drake_box_continuous(
    *,
    stiffness: float,
    dissipation: float,
    mass: float,
    inertia: Any,
    half_extents: Any,
    tilt: Any,
    speed: float,
    gravity: float = 0.0,
    accuracy: float = 1e-12,
    t_max: float | None = None,
) -> dict[str, Any]:
    """The box's corner hits the half space on a continuous plant (``time_step = 0``).

    A :class:`Simulator` (``runge_kutta5``, target accuracy ``accuracy``) runs from touch
    in chunks of a hundredth of ``sqrt(m/k)`` until the corner is out of the plane; the
    release (penetration back to 0) is placed by the cubic Hermite interpolant of the
    corner's penetration and rate over the last chunk, and the separation rate by the
    interpolant's slope there (the free corner is not ballistic: the box turns). Sticks
    if not out by ``t_max`` (default ``200 sqrt(m/k)``). Returns a dict:
    ``restitution``, ``contact_time``, ``sticks``, ``max_penetration``.
    """
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator

    corner, lever, rotation = lowest_corner(half_extents, tilt)
    diagram, plant, body, context = _box_plant(
        time_step=0.0,
        approximation=None,
        stiffness=stiffness,
        dissipation=dissipation,
        mass=mass,
        inertia=inertia,
        half_extents=half_extents,
        gravity=gravity,
    )
    pc = plant.GetMyMutableContextFromRoot(context)
    _place(plant, body, pc, rotation, lever, 0.0, speed)
    chunk = 0.01 * math.sqrt(mass / stiffness)
    t_max = 200.0 * math.sqrt(mass / stiffness) if t_max is None else t_max
    simulator = Simulator(diagram, context)
    ResetIntegratorFromFlags(simulator, "runge_kutta5", chunk)
    simulator.get_mutable_integrator().set_target_accuracy(accuracy)
    simulator.Initialize()
    last = (0.0, 0.0, float(speed))
    deepest = 0.0
    while last[0] < t_max:
        t = last[0] + chunk
        simulator.AdvanceTo(t)
        depth, rate = _corner_state(plant, body, pc, corner)
        if depth < 0.0:
            when, slope = _hermite_root(last, (t, depth, rate))
            return {"restitution": -slope / speed, "contact_time": when, "sticks": False,
                    "max_penetration": deepest}  # fmt: skip
        if last[2] > 0.0 >= rate:
            deepest = max(deepest, _hermite_peak(last, (t, depth, rate)))
        deepest = max(deepest, depth)
        last = (t, depth, rate)
    return {"restitution": 0.0, "contact_time": math.inf, "sticks": True,
            "max_penetration": deepest}  # fmt: skip


def _hermite(a, b):
    """Coefficients (in s on [0, 1]) of the cubic Hermite through ``(t, p, p')``."""
    (t0, p0, q0), (t1, p1, q1) = a, b
    dt = t1 - t0
    return dt, (p0, q0 * dt, 3 * (p1 - p0) - (2 * q0 + q1) * dt, 2 * (p0 - p1) + (q0 + q1) * dt)


def _hermite_root(a, b) -> tuple[float, float]:
    """Where the Hermite interpolant crosses zero downwards, and its slope there."""
    dt, c = _hermite(a, b)
    roots = np.roots([c[3], c[2], c[1], c[0]])
    real = [r.real for r in roots if abs(r.imag) < 1e-12 and -1e-12 <= r.real <= 1 + 1e-12]
    s = min(real)
    slope = (c[1] + 2 * c[2] * s + 3 * c[3] * s * s) / dt
    return a[0] + s * dt, slope


def _hermite_peak(a, b) -> float:
    """Largest value of the Hermite interpolant between the two samples."""
    _, c = _hermite(a, b)
    best = max(a[1], b[1])
    for r in np.roots([3 * c[3], 2 * c[2], c[1]]):
        if abs(r.imag) < 1e-12 and 0.0 <= r.real <= 1.0:
            s = r.real
            best = max(best, c[0] + c[1] * s + c[2] * s * s + c[3] * s**3)
    return float(best)
