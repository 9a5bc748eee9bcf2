r"""What PyBullet delivers for a free rigid body touching a plane with one point (a corner).

:func:`predict_body` runs the step map of :mod:`~impactsym.engines.pybullet.body`, in
which the contact row's effective mass, lever and the body's rotation move on from step to
step, at one touch phase or as the mean over touch phases, and sets beside it the frozen
scalar prediction (:func:`~impactsym.engines.pybullet.prediction.predict` with the
effective mass at touch, ``1/m~ = 1/m + (r x n)^T I_W^-1 (r x n)``, and the same gravity).
The frozen one misses what the turning does during a contact of several steps (about
``v t_c / (e |r|)`` relative: +10 % for a box corner at 0.3 m/s at 240 Hz); the body map
is exact to rounding against PyBullet. The phase mean is the midpoint rule over
:data:`PHASES` phases: the body map is not piecewise quadratic in the phase, so the exact
integration of :mod:`~impactsym.engines.pybullet.phases` does not apply; each jump of the
step pattern costs at most ``jump / (2 PHASES)`` on the mean. SI units.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.pybullet.body import body_contact, effective_mass
from impactsym.engines.pybullet.pair import combine_pair
from impactsym.engines.pybullet.prediction import (
    PyBulletContact,
    check_budget,
    check_settings,
    predict,
)
from impactsym.engines.pybullet.stepping import DEFAULT_SLOP
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = ["PHASES", "BodyContact", "check_body", "predict_body"]

#: touch phases of the midpoint rule of the phase mean, ``(i + 1/2) / PHASES``
PHASES = 256


@dataclass(frozen=True, eq=False)
class BodyContact(ArrayRecord):
    """PyBullet's point contact of a free rigid body, and the frozen scalar one (SI units).

    Attributes
    ----------
    stiffness, damping
        The body's ``contactStiffness`` (N/m) and ``contactDamping`` (N s/m).
    restitution, contact_time
        The contact point's separation speed over the approach speed, and seconds from
        touch to the end state, from the body map (phase mean with ``phase=None``; ``0``
        and ``inf`` where it sticks).
    sticks, stick_fraction
        Whether it sticks (at ``phase``, or at some phase), and at which fraction.
    restitution_range, contact_time_range
        ``(min, max)`` over the phases.
    effective_mass
        ``m~`` at touch, kg.
    frozen
        The scalar prediction with ``m~`` (:class:`PyBulletContact`).
    timestep, phase
        The engine's step and the touch phase (``None``: the mean).
    """

    stiffness: Any
    damping: Any
    restitution: Any
    contact_time: Any
    sticks: Any
    stick_fraction: Any
    restitution_range: Any
    contact_time_range: Any
    effective_mass: float
    frozen: PyBulletContact
    timestep: float
    phase: Any = None


def check_body(mass: Any, inertia: Any, orientation: Any, point: Any) -> tuple:
    """The validated body ``(m, moments, R_WB, point)``; ``ValueError``/``TypeError`` naming
    the argument (one positive mass, three positive moments satisfying the triangle
    inequality, a proper rotation matrix, a point off the normal through the centre is
    allowed but a finite one is required)."""
    m, m_scalar = real_array("mass", mass, lower=0.0, strict=True)
    if not m_scalar:
        raise ValueError(f"mass must be one number (kg), got {mass!r}")
    moments, _ = real_array("inertia", inertia, lower=0.0, strict=True)
    if moments.shape != (3,):
        raise ValueError(f"inertia must be the three principal moments (kg m^2), got {inertia!r}")
    a, b, c = np.sort(moments)
    if c > a + b:
        raise ValueError(f"inertia {inertia!r} violates the triangle inequality (no rigid body)")
    rotation, _ = real_array("orientation", orientation)
    if rotation.shape != (3, 3) or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-9):
        raise ValueError(f"orientation must be a 3 x 3 rotation matrix R_WB, got {orientation!r}")
    if np.linalg.det(rotation) < 0:
        raise ValueError(f"orientation must be a proper rotation (det +1), got {orientation!r}")
    at, _ = real_array("point", point)
    if at.shape != (3,):
        raise ValueError(f"point must be a body-frame point (x, y, z) in metres, got {point!r}")
    return float(m), moments, rotation, at


def predict_body(
    *,
    stiffness: Any,
    damping: Any,
    mass: float,
    inertia: Any,
    orientation: Any,
    point: Any,
    speed: Any,
    gravity: Any = 0.0,
    timestep: float = 1 / 240,
    phase: Any = None,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    other_stiffness: Any = np.inf,
    other_damping: Any = 0.1,
    breaking_threshold: float = np.inf,
) -> BodyContact:
    """PyBullet's bounce of a free rigid body touching a static plane with one ``point``.

    Parameters
    ----------
    stiffness, damping
        The body's ``changeDynamics(body, -1, contactStiffness=..., contactDamping=...)``,
        combined with ``other_stiffness``/``other_damping`` by the pair rules.
    mass, inertia
        The body's mass (kg) and principal moments about its centre of mass
        (``localInertiaDiagonal``, kg m^2).
    orientation, point
        ``R_WB`` at touch (3 x 3) and the touching point in the body frame, from the
        centre of mass (m); the plane's normal is the world ``+z``.
    speed, gravity
        The body's approach speed at touch, without rotation (m/s), and gravity (m/s^2).
    timestep, slop, processing_threshold
        As in :func:`~impactsym.engines.pybullet.prediction.predict`.
    breaking_threshold
        The collision detection's own gap limit (m): Bullet reports no point farther than
        the contact-breaking threshold of the body's shape
        (:func:`~impactsym.engines.pybullet.body.box_breaking_threshold` for a box); the
        row sees the smaller of the two thresholds. Default: no limit (slow bodies).
    phase
        Touch phase in ``[0, 1)``; ``None``: the mean over :data:`PHASES` phases.

    Returns
    -------
    BodyContact
        The body map's bounce (exact per phase against PyBullet, frictionless) and the
        frozen scalar prediction beside it.
    """
    m, moments, rotation, at = check_body(mass, inertia, orientation, point)
    names = ("stiffness", "damping", "speed", "gravity")
    arrays, scalar = [], True
    for name, value, strict in zip(names, (stiffness, damping, speed, gravity),
                                   (True, False, True, False), strict=True):  # fmt: skip
        a, s = real_array(name, value, lower=0.0, strict=strict)
        arrays.append(a)
        scalar = scalar and s
    h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not h_scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    h = float(h)
    settings = check_settings(slop, processing_threshold, 1)
    brk, brk_scalar = real_array("breaking_threshold", breaking_threshold, lower=0.0,
                                 allow_inf=True)  # fmt: skip
    if not brk_scalar:
        raise ValueError(f"breaking_threshold must be one number (m), got {breaking_threshold!r}")
    settings["processing_threshold"] = min(settings["processing_threshold"], float(brk))
    k_body, c_body, v, g = arrays
    k, c = (np.asarray(a, float) for a in combine_pair(
        stiffness=k_body, damping=c_body, other_stiffness=other_stiffness,
        other_damping=other_damping))  # fmt: skip
    shape = broadcast(stiffness=k, damping=c, speed=v, gravity=g)
    m_eff = effective_mass(m, moments, rotation, at)
    check_budget(k, c, m, h)
    frozen = predict(stiffness=k_body, damping=c_body, mass=m_eff, speed=v, gravity=g,
                     timestep=h, phase=phase, slop=settings["slop"],
                     processing_threshold=settings["processing_threshold"],
                     other_stiffness=other_stiffness, other_damping=other_damping)  # fmt: skip
    body = (m, moments, rotation, at)
    opts = {"slop": settings["slop"], "processing_threshold": settings["processing_threshold"]}
    if phase is not None:
        p, p_scalar = real_array("phase", phase, lower=0.0)
        if np.any(p >= 1):
            raise ValueError(f"phase must lie in [0, 1), got {phase!r}")
        scalar = scalar and p_scalar
        at_p = body_contact(k, c, *body, v, g, h, p, **opts)
        e, t, sticks = at_p.restitution, at_p.contact_time, at_p.sticks
        frac = sticks.astype(float)
        ranges = (e, e), (t, t)
    else:
        grid = (np.arange(PHASES) + 0.5) / PHASES
        k, c, v, g = (np.broadcast_to(a, shape)[..., None] for a in (k, c, v, g))
        run = body_contact(k, c, *body, v, g, h, grid, **opts)
        frac = run.sticks.mean(axis=-1)
        sticks = frac > 0
        e = np.where(sticks, 0.0, run.restitution.mean(axis=-1))
        t = np.where(sticks, np.inf, run.contact_time.mean(axis=-1))
        ranges = (
            (run.restitution.min(axis=-1), run.restitution.max(axis=-1)),
            (run.contact_time.min(axis=-1), run.contact_time.max(axis=-1)),
        )
    out = [np.broadcast_to(a, np.shape(e)) for a in (k_body, c_body)] + [e, t, sticks, frac]
    if scalar:
        kinds = (float, float, float, float, bool, float)
        out = [kind(a) for kind, a in zip(kinds, out, strict=True)]
        ranges = tuple((float(a), float(b)) for a, b in ranges)
    return BodyContact(*out, *ranges, m_eff, frozen, h, phase)
