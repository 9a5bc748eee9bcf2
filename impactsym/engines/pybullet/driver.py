"""Drive PyBullet itself: a sphere dropped on a plane, read state by state.

The engine's truth for the tests of :mod:`impactsym.engines.pybullet` (and for anyone who
wants to check a design in the engine): one ``DIRECT`` client per run, a sphere
(``createMultiBody``: PyBullet's default reduced coordinates) on a ``GEOM_PLANE``, the
touch phase set by the initial height, the velocity read after every ``stepSimulation``
and the contact read with ``getContactPoints`` (positive normal force: in contact), with
the definitions of :mod:`~impactsym.engines.pybullet.stepping`. PyBullet is imported
inside the function, so this module imports without it (``[engines]`` extra).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact
from impactsym.engines.pybullet.rigid import RIGID_BUDGET
from impactsym.engines.pybullet.stepping import step_budget

__all__ = ["pybullet_steps"]


def pybullet_steps(
    *,
    stiffness: float | None,
    damping: float | None,
    mass: float,
    speed: float,
    phase: Any,
    gravity: float = 0.0,
    timestep: float = 1 / 240,
    substeps: int = 1,
    slop: float | None = None,
    processing_threshold: float | None = None,
    plane: tuple[float, float] | None = None,
    radius: float = 0.5,
    restitution: tuple[float, float] | None = None,
    restitution_threshold: float | None = None,
    solver: dict | None = None,
) -> StepContact:
    """Run PyBullet at each touch phase in ``phase`` and read the contact (arrays, SI).

    ``stiffness``/``damping`` go to the sphere (``changeDynamics``), ``plane=(k, c)`` to
    the plane (``None``: the plane keeps PyBullet's defaults, damping ``0.1``);
    ``slop``/``processing_threshold`` set ``contactSlop``/``contactProcessingThreshold``
    where given; ``restitution=(r_ball, r_plane)`` sets both bodies' velocity
    restitution (``changeDynamics(restitution=...)``, the pair uses the product) and
    ``restitution_threshold`` the ``restitutionVelocityThreshold``; ``solver`` holds
    further ``setPhysicsEngineParameter`` keywords (e.g. ``numSolverIterations``,
    ``useSplitImpulse``). The sphere has
    ``linearDamping = angularDamping = 0``; ``radius`` must keep the contact inside
    Bullet's contact-breaking distance (``0.02 sqrt(3) radius`` must exceed a step's
    travel). Geometric touch lies ``phase * timestep`` before the
    first state (after a call) that free flight would carry into overlap; the run starts
    one step earlier in free flight.

    ``stiffness=None`` (``damping`` is then ignored) leaves the sphere rigid (no
    ``contactStiffness``) and reads the run with the rigid rule of
    :mod:`~impactsym.engines.pybullet.rigid`: a state without force ends the contact
    only where the sphere separates, and it sticks if it has not separated within
    :data:`~impactsym.engines.pybullet.rigid.RIGID_BUDGET` calls.
    """
    import pybullet as pb

    phases = np.atleast_1d(np.asarray(phase, float))
    rigid = stiffness is None
    budget = RIGID_BUDGET if rigid else int(step_budget(stiffness, damping + 0.1, mass, timestep))
    out = {name: np.zeros(phases.size) for name in StepContact.__dataclass_fields__}
    for i, p in enumerate(phases):
        cid = pb.connect(pb.DIRECT)
        try:
            _settings(pb, cid, timestep, substeps, slop, restitution_threshold, solver)
            one = _run(
                pb,
                cid,
                stiffness,
                damping,
                mass,
                speed,
                float(p),
                gravity,
                timestep,
                processing_threshold,
                plane,
                radius,
                budget,
                restitution,
            )
        finally:
            pb.disconnect(cid)
        for name, value in one.items():
            out[name][i] = value
    shape = np.shape(phase)
    out["sticks"] = out["sticks"].astype(bool)
    out["released_by_position"] = out["released_by_position"].astype(bool)
    return StepContact(**{name: a.reshape(shape) for name, a in out.items()})


def _settings(pb, cid, h, substeps, slop, restitution_threshold, solver):
    params = {**(solver or {}), "fixedTimeStep": h, "physicsClientId": cid}
    if substeps > 1:
        params["numSubSteps"] = substeps
    if slop is not None:
        params["contactSlop"] = slop
    if restitution_threshold is not None:
        params["restitutionVelocityThreshold"] = restitution_threshold
    pb.setPhysicsEngineParameter(**params)


def _run(pb, cid, k, c, m, v, p, g, h, threshold, plane, radius, budget, restitution):
    pb.setGravity(0, 0, -g, physicsClientId=cid)
    plane_id = pb.createMultiBody(
        0, pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=cid), physicsClientId=cid
    )
    t = (p - 1.0) * h
    x, w = v * t + 0.5 * g * t * t, v + g * t
    shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=radius, physicsClientId=cid)
    ball = pb.createMultiBody(m, shape, basePosition=[0, 0, radius - x], physicsClientId=cid)
    law = {} if k is None else {"contactStiffness": k, "contactDamping": c}
    pb.changeDynamics(ball, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=cid, **law)
    if threshold is not None:
        pb.changeDynamics(ball, -1, contactProcessingThreshold=threshold, physicsClientId=cid)
    if plane is not None:
        pb.changeDynamics(
            plane_id, -1, contactStiffness=plane[0], contactDamping=plane[1], physicsClientId=cid
        )
    if restitution is not None:
        pb.changeDynamics(ball, -1, restitution=restitution[0], physicsClientId=cid)
        pb.changeDynamics(plane_id, -1, restitution=restitution[1], physicsClientId=cid)
    pb.resetBaseVelocity(ball, [0, 0, -w], [0, 0, 0], physicsClientId=cid)
    started = ended = False
    first = end = 0
    w_end = x_end = x_max = f_max = 0.0
    for n in range(budget + 1 if k is not None else budget + 10):
        if k is None and started and n - first > budget:
            break  # rigid: not separated and gone within the budget: sticks
        pb.stepSimulation(physicsClientId=cid)
        z = pb.getBasePositionAndOrientation(ball, physicsClientId=cid)[0][2]
        x, w = radius - z, -pb.getBaseVelocity(ball, physicsClientId=cid)[0][2]
        points = pb.getContactPoints(ball, plane_id, physicsClientId=cid)
        force = sum(q[9] for q in points)
        if not started:
            if force > 0:
                started, first = True, n
                x_max, f_max = x, force
            continue
        if not ended:
            if force > 0 or (k is None and w >= 0):  # rigid: ends where it separates
                x_max, f_max = max(x_max, x), max(f_max, force)
                continue
            ended, end, w_end, x_end = True, n, w, x
        elif force > 0 and x > 0:
            break  # the force came back inside the overlap: sticks
        if x <= 0:
            return {
                "restitution": -w_end / v,
                "contact_time": (p + end) * h,
                "sticks": False,
                "released_by_position": x_end <= 0,
                "departure_speed": -w,
                "steps": end - first,
                "max_penetration": x_max,
                "peak_accel": f_max / m,
            }
    return {
        "restitution": 0.0,
        "contact_time": math.inf,
        "sticks": True,
        "released_by_position": False,
        "departure_speed": 0.0,
        "steps": math.inf,
        "max_penetration": x_max,
        "peak_accel": f_max / m,
    }
