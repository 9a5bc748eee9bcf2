"""Drive PyBullet itself: a free box, tilted so that one corner touches the plane first.

The multibody scene of the tests of :mod:`impactsym.engines.pybullet`. A box of ``mass``,
principal ``inertia`` (``changeDynamics(localInertiaDiagonal=...)``, along the box's
axes) and ``half_extents`` is a ``createMultiBody`` base (a floating base: six degrees of
freedom) oriented by ``tilt = (roll, pitch, yaw)`` (``getQuaternionFromEuler``, the
rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` of
:func:`impactsym.engines.drake.box_driver.lowest_corner`) so that one corner touches a
``GEOM_PLANE`` first; it translates without rotation until it touches. Its contact row
has the effective mass ``1/m~ = 1/m + (r x n)^T I_W^-1 (r x n)`` at the corner ``r``.
The sphere driver's definitions (:func:`~impactsym.engines.pybullet.driver.pybullet_steps`:
the touch phase, a state's force from ``getContactPoints``, the end of the contact, the
stick) are applied to the corner, whose penetration and approach rate are read from the
base's pose and velocity (``x = -z_c``, ``x' = -(v + w x r)_z``). PyBullet is imported
inside the function (``[engines]`` extra).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from impactsym.engines.drake.box_driver import lowest_corner
from impactsym.engines.pybullet.stepping import step_budget

__all__ = ["pybullet_box_steps"]


def pybullet_box_steps(
    *,
    stiffness: float,
    damping: float,
    mass: float,
    inertia: Any,
    half_extents: Any,
    tilt: Any,
    speed: float,
    phase: Any,
    gravity: float = 0.0,
    timestep: float = 1 / 240,
    budget: int | None = None,
) -> dict[str, np.ndarray]:
    """Run PyBullet at each touch phase in ``phase``; read the corner's contact (SI).

    ``stiffness``/``damping`` go to the box (``changeDynamics``); the plane keeps
    PyBullet's defaults (``contactDamping`` 0.1, added by the pair rule). The box's
    ``lateralFriction`` is 0 (the pair's is the product: frictionless; the corner slides
    as the box turns, and friction there would change the rotation the impulse makes).
    Geometric touch of the corner lies ``phase * timestep`` before the first state that
    free flight would carry into overlap; the run starts one step earlier in free flight.
    ``budget`` caps the calls after the contact begins (default: the sphere driver's
    budget for the whole ``mass``, longer than the corner's, whose mass is smaller).
    Returns a dict of arrays, one entry per
    phase: ``restitution`` (the corner's separation rate at the first state without
    force, over ``speed``), ``contact_time``, ``sticks``, ``steps``, ``max_penetration``,
    ``first_impulse`` (the normal force of the first contact state times ``timestep``:
    the impulse of the step before the box turns, N s).
    """
    import pybullet as pb

    corner, lever, _ = lowest_corner(half_extents, tilt)
    phases = np.atleast_1d(np.asarray(phase, float))
    if budget is None:
        budget = int(step_budget(stiffness, damping + 0.1, mass, timestep))
    runs = []
    for p in phases:
        cid = pb.connect(pb.DIRECT)
        try:
            pb.setPhysicsEngineParameter(fixedTimeStep=timestep, physicsClientId=cid)
            scene = (stiffness, damping, mass, inertia, half_extents, tilt, corner, lever)
            runs.append(_run(pb, cid, *scene, speed, float(p), gravity, timestep, budget))
        finally:
            pb.disconnect(cid)
    return {key: np.array([run[key] for run in runs]) for key in runs[0]}


def _corner(pb, cid, box, corner):
    """Penetration and approach rate of the corner (body-frame point ``corner``)."""
    position, orientation = pb.getBasePositionAndOrientation(box, physicsClientId=cid)
    linear, angular = pb.getBaseVelocity(box, physicsClientId=cid)
    rotation = np.reshape(pb.getMatrixFromQuaternion(orientation), (3, 3))
    lever = rotation @ corner
    rate = np.asarray(linear) + np.cross(angular, lever)
    return -(position[2] + lever[2]), -float(rate[2])


def _run(pb, cid, k, c, m, inertia, half, tilt, corner, lever, v, p, g, h, budget):
    pb.setGravity(0, 0, -g, physicsClientId=cid)
    plane = pb.createMultiBody(
        0, pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=cid), physicsClientId=cid
    )
    t = (p - 1.0) * h
    x, w = v * t + 0.5 * g * t * t, v + g * t
    shape = pb.createCollisionShape(
        pb.GEOM_BOX, halfExtents=[float(a) for a in half], physicsClientId=cid
    )
    box = pb.createMultiBody(
        m,
        shape,
        basePosition=[0.0, 0.0, -lever[2] - x],
        baseOrientation=pb.getQuaternionFromEuler([float(a) for a in tilt]),
        physicsClientId=cid,
    )
    pb.changeDynamics(
        box,
        -1,
        contactStiffness=k,
        contactDamping=c,
        localInertiaDiagonal=[float(i) for i in inertia],
        linearDamping=0.0,
        angularDamping=0.0,
        lateralFriction=0.0,
        physicsClientId=cid,
    )
    pb.resetBaseVelocity(box, [0, 0, -w], [0, 0, 0], physicsClientId=cid)
    started = ended = False
    first = end = 0
    rate_end = deepest = impulse = 0.0
    n = 0
    while not started or n - first <= budget:
        pb.stepSimulation(physicsClientId=cid)
        depth, rate = _corner(pb, cid, box, corner)
        force = sum(q[9] for q in pb.getContactPoints(box, plane, physicsClientId=cid))
        if not started:
            if force > 0:
                started, first, deepest, impulse = True, n, depth, force * h
            elif n > 2:
                raise RuntimeError("the corner never touched: the run started too high")
        elif not ended:
            if force > 0:
                deepest = max(deepest, depth)
            else:
                ended, end, rate_end = True, n, rate
        elif force > 0 and depth > 0:
            break  # the force came back inside the overlap: sticks
        if ended and depth <= 0:
            return {"restitution": -rate_end / v, "contact_time": (p + end) * h,
                    "sticks": False, "steps": end - first, "max_penetration": deepest,
                    "first_impulse": impulse}  # fmt: skip
        n += 1
    return {"restitution": 0.0, "contact_time": math.inf, "sticks": True,
            "steps": math.inf, "max_penetration": deepest, "first_impulse": impulse}  # fmt: skip
