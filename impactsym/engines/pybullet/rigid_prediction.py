r"""What PyBullet delivers for a rigid contact with velocity ``restitution``: :func:`predict_rigid`.

No ``contactStiffness``: the row of :mod:`~impactsym.engines.pybullet.rigid` (error
reduction ``contactERP``, no mixing, the speculative row and the push-out bias), read with
its rigid rule, exactly per touch phase, or its phase mean and range
(:func:`~impactsym.engines.pybullet.phases.phase_summary` on the rigid pattern). The
map has no mass in it. With PyBullet's defaults (speculative contacts, slop ``s``) and
no gravity the closed form is (`docs/physics.md#pybullet-at-its-timestep`)

.. math::

    e(p) = \max\bigl(0,\ r - (1 - p) - s/(v h)\bigr) \text{ (else it sticks)}, \qquad
    \bar e = \tfrac12 \bigl(r - s/(v h)\bigr)^2

for a pair restitution ``r > s/(v h)`` with ``r v`` above the threshold (and the gap of
the step before touch inside Bullet's contact-breaking distance); without speculative
contacts (``contactProcessingThreshold=0``) ``e(p) = r + \mathrm{erp}\,(p - s/(v h))``
for ``p >= s/(v h)``: the push-out bias, ``erp/2`` on the phase mean.
SI units.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.pybullet.phases import phase_summary
from impactsym.engines.pybullet.prediction import check_settings
from impactsym.engines.pybullet.rigid import (
    DEFAULT_CONTACT_ERP,
    rigid_pattern,
    rigid_step_pattern,
)
from impactsym.engines.pybullet.stepping import DEFAULT_RESTITUTION_THRESHOLD, DEFAULT_SLOP
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = ["RigidContact", "predict_rigid"]


@dataclass(frozen=True, eq=False)
class RigidContact(ArrayRecord):
    """PyBullet's rigid contact with velocity restitution, as the engine delivers it (SI).

    Attributes
    ----------
    pair_restitution
        The pair's ``restitution`` the row uses (the product of both bodies' values).
    restitution
        Separation speed over approach speed where the body separates (``0`` where it
        sticks); the phase mean with ``phase=None``.
    contact_time
        Seconds from geometric touch to the separating state (``inf`` where it sticks
        at some phase).
    sticks, stick_fraction
        Whether it sticks (at ``phase``, or at some phase) and at which fraction of
        the phases.
    restitution_range, contact_time_range
        ``(min, max)`` over every touch phase (``(value, value)`` at a given phase).
    timestep, substeps, phase
        The engine's step, sub-steps per call, and the touch phase (``None``: the mean).
    """

    pair_restitution: float
    restitution: Any
    contact_time: Any
    sticks: Any
    stick_fraction: Any
    restitution_range: Any
    contact_time_range: Any
    timestep: float
    substeps: int
    phase: Any = None


def predict_rigid(
    *,
    restitution: float,
    speed: Any,
    gravity: Any = 0.0,
    timestep: float = 1 / 240,
    substeps: int = 1,
    phase: Any = None,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    contact_erp: float = DEFAULT_CONTACT_ERP,
) -> RigidContact:
    """PyBullet's bounce of a rigid body (no ``contactStiffness``) with velocity restitution.

    Parameters
    ----------
    restitution
        The pair's restitution ``r >= 0``: the product of both bodies'
        ``changeDynamics(restitution=...)`` (PyBullet's default 0 on each).
    speed, gravity
        Approach speed at touch (m/s, ``> 0``) and the gravity pressing the body on
        (m/s^2, ``>= 0``); arrays broadcast.
    timestep, substeps, slop, processing_threshold
        ``fixedTimeStep``, ``numSubSteps``, ``contactSlop`` and
        ``contactProcessingThreshold`` (as in :func:`~impactsym.engines.pybullet.predict`).
    restitution_threshold
        ``restitutionVelocityThreshold`` (default ``0.2f``): the row asks for ``r w*``
        only where the approach speed after the free step ``w*`` reaches it.
    contact_erp
        ``setPhysicsEngineParameter(contactERP=...)``, in ``(0, 1]`` (default ``0.08``).
    phase
        Touch phase in ``[0, 1)``; ``None``: the mean over phases and the range.

    Returns
    -------
    RigidContact
        Exact for PyBullet's rigid row read with the rigid rule of
        :mod:`~impactsym.engines.pybullet.rigid` (the proof runs PyBullet itself).

    >>> r = predict_rigid(restitution=0.5, speed=1.0)
    >>> round(r.restitution, 5), round(r.stick_fraction, 5)
    (0.1238, 0.5024)
    """
    arrays, scalar = [], True
    for name, value, strict in (("speed", speed, True), ("gravity", gravity, False)):
        a, s = real_array(name, value, lower=0.0, strict=strict)
        arrays.append(a)
        scalar = scalar and s
    v, g = arrays
    broadcast(speed=v, gravity=g)
    h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not h_scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    erp, erp_scalar = real_array("contact_erp", contact_erp, lower=0.0, strict=True)
    if not erp_scalar or erp > 1.0:
        raise ValueError(f"contact_erp must be one number in (0, 1], got {contact_erp!r}")
    settings = check_settings(slop, processing_threshold, substeps, restitution,
                              restitution_threshold)  # fmt: skip
    if phase is not None:
        p, p_scalar = real_array("phase", phase, lower=0.0)
        if np.any(p >= 1):
            raise ValueError(f"phase must lie in [0, 1), got {phase!r}")
        scalar = scalar and p_scalar
        at, _ = rigid_step_pattern(v, g, float(h), p, contact_erp=float(erp), **settings)
        e, t, sticks = at.restitution, at.contact_time, at.sticks
        frac = sticks.astype(float)
        ranges = (e, e), (t, t)
    else:
        zero = np.zeros(np.broadcast(v, g).shape)
        summary = phase_summary(zero, zero, zero + 1.0, v, g, float(h), **settings,
                                pattern=rigid_pattern(float(erp)))  # fmt: skip
        e, t, frac = summary.restitution, summary.contact_time, summary.stick_fraction
        sticks = frac > 0
        ranges = (
            (summary.restitution_min, summary.restitution_max),
            (summary.contact_time_min, summary.contact_time_max),
        )
    out = [e, t, sticks, frac]
    if scalar:
        out = [kind(a) for kind, a in zip((float, float, bool, float), out, strict=True)]
        ranges = tuple((float(a), float(b)) for a, b in ranges)
    r = settings["velocity_restitution"]
    return RigidContact(r, *out, *ranges, float(h), settings["substeps"], phase)
