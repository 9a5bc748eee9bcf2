r"""PyBullet's rigid contact (no ``contactStiffness``) with velocity ``restitution``, per phase.

Without ``contactStiffness``/``contactDamping`` Bullet's contact row
(``btMultiBodyConstraintSolver::setupMultiBodyContactConstraint``) has no constraint-force
mixing (``globalCFM = 0``) and the error reduction ``contactERP`` (PyBullet's default
``0.08``, :data:`DEFAULT_CONTACT_ERP`); the solver's one-row answer is then
``lambda = m max(0, b)``, and the map does not depend on the mass. In approach
coordinates (penetration ``x``, approach speed ``w``, gravity ``g`` pressing on) one
(sub)step ``h``:

.. math::

    w^* = w + g h, \quad d = s - x, \quad
    b = \begin{cases} w^* - d/h & d > 0 \text{ (speculative)} \\
                      w^* - \mathrm{erp}\, d/h & d \le 0 \end{cases}
        + \begin{cases} r\,w^* & w^* \ge w_r \\ 0 & \text{else} \end{cases}

    w' = w^* - \max(0, b), \quad x' = x + h w',

with the pair's velocity restitution ``r`` (the product of both bodies'
``changeDynamics(restitution=...)``), its threshold ``w_r``
(``restitutionVelocityThreshold``, default ``0.2f``), the slop ``s`` (``contactSlop``) and
no impulse while the gap ``-x`` exceeds the contact processing threshold. Two terms make
the rebound differ from ``r``: the **speculative** row asks for ``d/h - r w*`` *before*
the body touches (it may turn round at a distance, or be slowed to a creep and land
later), and the **push-out bias** ``erp (x - s)/h`` of a row that starts in overlap
(``contactProcessingThreshold=0``, or a gap beyond the contact-breaking distance) adds
to the separation speed.

**Reading rule (rigid).** The touch phase is that of
:mod:`~impactsym.engines.pybullet.stepping` (geometric touch ``phase * timestep`` before
state 0, the first state free flight would carry into overlap; the force of a state is
what ``getContactPoints`` reports after the call that produced it). The contact begins at
the first state with a positive force and **ends at the first later state without force
at which the body separates** (``w < 0``). A state without force at which the body still
approaches (a speculative impulse only slowed it) belongs to the contact: the impulses
that follow are the same contact, so the restitution, that end state's separation speed
over ``speed``, is never negative (the compliant rule, "the first state without force",
would read the slowed approach as a negative restitution). ``contact_time`` runs from
geometric touch to that state (the body may never reach the surface: the touch is then
the time free flight would have touched). If the body never separates within
:data:`RIGID_BUDGET` calls after the contact begins (it lands and rests; a creep below
the threshold gets no restitution), or the force comes back while it overlaps after the
end, it **sticks**.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact
from impactsym.engines.pybullet.stepping import (
    DEFAULT_RESTITUTION_THRESHOLD,
    DEFAULT_SLOP,
    new_reading,
    pattern_code,
    read_state,
    reading_fields,
)

__all__ = ["DEFAULT_CONTACT_ERP", "RIGID_BUDGET", "rigid_pattern", "rigid_step_pattern"]

#: PyBullet's contact error reduction without contact stiffness (``contactERP`` of
#: ``setPhysicsEngineParameter``; measured: the first positional impulse is
#: ``0.08 (x - s)/h``)
DEFAULT_CONTACT_ERP = 0.08
#: calls after the contact begins within which a body must separate (else it sticks)
RIGID_BUDGET = 200


def rigid_step_pattern(
    speed: Any,
    gravity: Any,
    timestep: Any,
    phase: Any,
    *,
    velocity_restitution: float,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    contact_erp: float = DEFAULT_CONTACT_ERP,
    substeps: int = 1,
) -> tuple[StepContact, np.ndarray]:
    """The rigid contact at touch phase ``phase`` and its branch pattern (arrays, SI).

    Validated arrays in (broadcast together), the module's map iterated on whole arrays
    with its reading rule. Returns a
    :class:`~impactsym.engines.mujoco.stepping.StepContact` (``peak_accel`` is the
    largest reported force per unit mass) and an integer key of the branches taken
    (first and end state, steps with a speculative, a positional and a restitution
    term; ``-1`` where it sticks): where the key is constant in the phase the end state
    is an affine map of the free-flight state ``-1``, the restitution a quadratic in
    the phase.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (speed, gravity, timestep, phase)))
    shape = arrays[0].shape
    v, g, H, p = (a.ravel().copy() for a in arrays)
    h = H / substeps
    t = (p - 1.0) * H  # state -1: free flight
    x = v * t + 0.5 * g * t * t
    w = v + g * t
    size = v.size
    r, done = new_reading(size), np.zeros(size, bool)
    n_spec, n_pos, n_rest = (np.zeros(size) for _ in range(3))
    n = -1
    while not done.all():
        n += 1
        for _ in range(substeps):
            w_star = w + g * h
            d = slop - x
            b = np.where(d > 0, w_star - d / h, w_star - contact_erp * d / h)
            rest = (w_star >= restitution_threshold) & (w_star > 0)
            b = b + np.where(rest, velocity_restitution * w_star, 0.0)
            dv = np.where(-x <= processing_threshold, np.maximum(b, 0.0), 0.0)
            counting = ~r["ended"] & (dv > 0)
            n_spec += counting & (d > 0)
            n_pos += counting & (d <= 0)
            n_rest += counting & rest
            w = w_star - dv
            x = x + h * w
        back, gone = read_state(r, n, x, w, dv / h, ~done, separating=w < 0)
        started, n_first = r["started"], r["n_first"]
        over = ~done & ~gone & ~back & (n - np.where(started, n_first, 0.0) >= RIGID_BUDGET)
        r["sticks"] |= over
        done |= back | gone | over
    fields = reading_fields(r, v, p, H, 1.0)
    sticks, n_end, n_first = r["sticks"], r["n_end"], r["n_first"]
    pattern = pattern_code(sticks, n_end, n_first, n_spec, n_pos, n_rest)
    record = StepContact(**{name: val.reshape(shape) for name, val in fields.items()})
    return record, pattern.reshape(shape)


def rigid_pattern(contact_erp: float) -> Callable[..., tuple[StepContact, np.ndarray]]:
    """:func:`rigid_step_pattern` with the arguments of
    :func:`~impactsym.engines.pybullet.stepping.step_pattern` (stiffness, damping and mass
    ignored: the rigid map has none), for
    :func:`~impactsym.engines.pybullet.phases.phase_summary`'s ``pattern``."""

    def pattern(stiffness, damping, mass, speed, gravity, timestep, phase, **settings):
        return rigid_step_pattern(speed, gravity, timestep, phase, contact_erp=contact_erp,
                                  **settings)  # fmt: skip

    return pattern
