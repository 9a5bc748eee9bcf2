r"""PyBullet's contact of a free rigid body touching a static plane with one point: the map.

The scalar map of :mod:`~impactsym.engines.pybullet.stepping` with the contact row's
effective mass frozen at touch is exact for the first contact step only: a body touching
with a point off its centre of mass (a box's corner) turns during the contact, so the
row's lever ``r``, its inverse effective mass ``A = 1/m + (r x n)^T I_W^-1 (r x n)`` and
the corner's own motion (its centripetal acceleration ``n . (w x (w x r))`` and the
gyroscopic torque ``-w x I_W w``) change from step to step. At several 4-ms steps per
contact that is a drift of 10 % in the restitution (`docs/physics.md`, the box corner in
PyBullet). This module steps the body itself, as ``btMultiBodyDynamicsWorld`` steps a
floating base (``createMultiBody``) with one contact row along the plane's normal
``n = +z`` (frictionless), per step ``h``:

.. math::

    v^* = v - g h\,n, \quad \omega^* = \omega - h\, I_W^{-1} (\omega \times I_W \omega),
    \quad w^* = -n \cdot (v^* + \omega^* \times r),

    \lambda = \max\bigl(0,\ b(w^*, x) / (A + \mathrm{cfm}/h)\bigr), \quad
    v' = v^* + \lambda n / m, \quad \omega' = \omega^* + \lambda I_W^{-1} (r \times n),

    z' = z + h\, v'_z, \quad R' = \exp(h [\omega']) R,

with ``b``, ``erp``, ``cfm``, the slop and the processing threshold of the scalar map and
``r = R p``, ``I_W = R I R^T``, the penetration ``x = -(z + r_z)`` taken at the start of the
step (where the collision detection finds the point). The orientation update is the exact
rotation by ``h w'`` (Bullet's exponential-map quaternion update). This is the scalar map
with a per-step ``A`` and a per-step load: everything but the contact impulse enters through
``w*`` and the rotation of ``r``. Against PyBullet it agrees to rounding at every phase
(``tests/test_engines_pybullet_scenes.py``). The states are read as the scalar map's (the
touch phase, the force of a state, the end of contact, sticking): the corner's penetration
and its approach rate ``-n . (v + w x r)`` after the step. All arrays, SI.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact
from impactsym.engines.pybullet.stepping import (
    DEFAULT_SLOP,
    MAX_STEPS,
    new_reading,
    read_state,
    reading_fields,
)

__all__ = [
    "BREAKING_FACTOR",
    "body_contact",
    "box_breaking_threshold",
    "effective_mass",
    "pivot_budget",
    "rotation_by",
]

_UP = np.array([0.0, 0.0, 1.0])
#: Bullet's ``gContactBreakingThreshold``: a manifold keeps points within this factor times
#: the shape's angular-motion disc (its bounding radius about the centre of mass)
BREAKING_FACTOR = 0.02


def box_breaking_threshold(half_extents: Any) -> float:
    """The gap (m) within which Bullet's box-plane collision reports a (speculative) point:
    ``0.02 |half_extents|`` (``btBoxShape``'s bounding radius; the plane's is unbounded,
    and the manifold takes the smaller). A point farther away gets no row, whatever
    ``contactProcessingThreshold`` says: at 240 Hz this matters from about 1.9 m/s for the
    0.39 m box of the tests (a gap of up to ``v h`` at the step before touch)."""
    return BREAKING_FACTOR * float(np.linalg.norm(np.asarray(half_extents, float)))


def effective_mass(mass: float, inertia: Any, orientation: Any, point: Any) -> float:
    """The contact row's effective mass at touch, ``1/m~ = 1/m + (r x n)^T I_W^-1 (r x n)``.

    ``inertia`` the principal moments (body frame, ``localInertiaDiagonal``),
    ``orientation`` the rotation matrix ``R_WB``, ``point`` the contact point in the body
    frame (from the centre of mass), ``n = +z``. kg.
    """
    rotation = np.asarray(orientation, float)
    lever = np.cross(rotation @ np.asarray(point, float), _UP)
    inverse = rotation @ np.diag(1.0 / np.asarray(inertia, float)) @ rotation.T
    return 1.0 / (1.0 / mass + float(lever @ inverse @ lever))


def pivot_budget(stiffness: Any, damping: Any, mass: float, timestep: float) -> np.ndarray:
    """Calls after which a body's point contact still on counts as sticking: two undamped
    periods of the touch's effective mass ``mass`` plus ten damping times ``c / k``, at
    least 30 calls. A bounce of the scalar contact lasts about half a period plus the
    damping times; a body still on its point after that rests or pivots on it, and a box
    pivoting on a corner topples onto another corner (in the 2 kg box of the tests after
    37 steps at 240 Hz), which a one-point contact does not describe."""
    k, c = np.asarray(stiffness, float), np.asarray(damping, float)
    span = 4.0 * np.pi * np.sqrt(mass / k) + 10.0 * c / k
    return np.maximum(np.ceil(span / timestep), 30.0)


def rotation_by(angle: np.ndarray) -> np.ndarray:
    """Rotation matrices ``exp([a])`` for rotation vectors ``angle`` (shape ``(..., 3)``),
    Rodrigues' formula (the identity where ``|a| = 0``)."""
    theta = np.linalg.norm(angle, axis=-1)
    safe = np.where(theta > 0, theta, 1.0)
    kx, ky, kz = np.moveaxis(angle / safe[..., None], -1, 0)
    zero = np.zeros_like(kx)
    cross = np.stack(
        [
            np.stack([zero, -kz, ky], -1),
            np.stack([kz, zero, -kx], -1),
            np.stack([-ky, kx, zero], -1),
        ],
        -2,
    )
    s, c = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    return np.eye(3) + s * cross + (1.0 - c) * (cross @ cross)


def body_contact(
    stiffness: Any,
    damping: Any,
    mass: float,
    inertia: Any,
    orientation: Any,
    point: Any,
    speed: Any,
    gravity: Any,
    timestep: float,
    phase: Any,
    *,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    budget: Any = None,
) -> StepContact:
    """The body's point contact at touch phase ``phase``, as PyBullet's states show it.

    Validated input: ``stiffness``, ``damping`` (the pair's combined values), ``speed``,
    ``gravity`` and ``phase`` broadcast together; one body (``mass``, principal
    ``inertia``, ``orientation`` ``R_WB`` at touch, contact ``point`` in the body frame)
    arriving without rotation at ``speed`` along ``-n``. Returns a
    :class:`~impactsym.engines.mujoco.stepping.StepContact` of that shape
    (``peak_accel`` is the peak force over the touch's effective mass). The map of the
    module docstring is iterated on whole arrays until every element has ended and left
    the overlap, or stuck: the force back inside the overlap, or the contact still on
    ``budget`` calls after it began (default :func:`pivot_budget`: the body rests or
    pivots on the point, and a box that pivots long enough topples onto other points,
    which a one-point contact does not describe).
    """
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, speed, gravity, phase))
    )
    shape = arrays[0].shape
    k, c, v, g, p = (a.ravel() for a in arrays)
    h = float(timestep)
    body = np.asarray(point, float)
    start = np.asarray(orientation, float)
    moments = np.asarray(inertia, float)
    erp = h * k / (h * k + c)
    cfm = 1.0 / (h * (h * k + c))
    t = (p - 1.0) * h  # state -1: free flight, no rotation yet
    size = k.size
    rotation = np.broadcast_to(start, (size, 3, 3)).copy()
    height = -(start @ body)[2] - (v * t + 0.5 * g * t * t)  # the centre of mass
    velocity = np.zeros((size, 3))
    velocity[:, 2] = -(v + g * t)
    omega = np.zeros((size, 3))
    m_touch = effective_mass(mass, moments, start, body)
    if budget is None:
        budget = pivot_budget(k, c, m_touch, h)
    else:
        budget = np.broadcast_to(np.asarray(budget, float), shape).ravel()
    budget = np.minimum(budget, MAX_STEPS)
    r, done = new_reading(size), np.zeros(size, bool)
    n = -1
    while not done.all():
        n += 1
        lever = rotation @ body
        x = -(height + lever[:, 2])
        world = rotation @ (moments[:, None] * np.swapaxes(rotation, 1, 2))  # I_W
        inverse = rotation @ (np.swapaxes(rotation, 1, 2) / moments[:, None])  # I_W^-1
        velocity[:, 2] -= g * h
        spin = np.cross(omega, np.einsum("nij,nj->ni", world, omega))
        omega = omega - h * np.einsum("nij,nj->ni", inverse, spin)
        w_star = -(velocity[:, 2] + np.cross(omega, lever)[:, 2])
        arm = np.cross(lever, _UP)
        turn = np.einsum("nij,nj->ni", inverse, arm)
        a = 1.0 / mass + np.einsum("ni,ni->n", arm, turn)
        d = slop - x
        b = np.where(d > 0, w_star - d / h, w_star - erp * d / h)
        impulse = np.where(-x <= processing_threshold, np.maximum(b / (a + cfm), 0.0), 0.0)
        velocity[:, 2] += impulse / mass
        omega = omega + impulse[:, None] * turn
        height = height + h * velocity[:, 2]
        rotation = rotation_by(h * omega) @ rotation
        lever = rotation @ body
        x = -(height + lever[:, 2])
        w = -(velocity[:, 2] + np.cross(omega, lever)[:, 2])
        back, gone = read_state(r, n, x, w, impulse / h, ~done)
        started, n_first = r["started"], r["n_first"]
        done |= back | gone
        over = ~done & started & (n - n_first >= budget)
        r["sticks"] |= over
        done |= over
        if n > 2 and not started.all():
            raise RuntimeError("the body never touched: the touch phase lies outside [0, 1)")
    fields = reading_fields(r, v, p, h, m_touch)
    return StepContact(**{key: val.reshape(shape) for key, val in fields.items()})
