r"""``contactStiffness``/``contactDamping`` for a free rigid body touching a plane with a point.

:func:`body_contact_for` designs with the scalar :func:`~impactsym.engines.pybullet.design.
contact_for` for the effective mass at touch and corrects the targets it asks of it by
what the body map (:func:`~impactsym.engines.pybullet.body_prediction.predict_body`, phase
mean) misses, a fixed-point iteration ``e_ask += e_target - e_body`` (likewise the contact
time) on whole arrays. The body map departs from the frozen scalar one by a few to ten per
cent and that departure changes slowly with the design, so the iteration contracts by about
that factor per round; it stops at 1e-3 relative (the midpoint phase mean moves in steps
of about ``jump / PHASES`` as the design changes: a contact time that gains a step at one
phase moves it by ``h / PHASES``, 4e-4 of a 40 ms contact at 240 Hz), or after
:data:`ROUNDS` rounds at the best round. SI units.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.pybullet.body import effective_mass
from impactsym.engines.pybullet.body_prediction import BodyContact, check_body, predict_body
from impactsym.engines.pybullet.design import contact_for
from impactsym.engines.pybullet.stepping import DEFAULT_SLOP
from impactsym.validation import real_array

__all__ = ["ROUNDS", "body_contact_for"]

#: rounds of the target correction
ROUNDS = 10
_TOL = 1e-3


def body_contact_for(
    *,
    restitution: Any,
    speed: Any,
    mass: float,
    inertia: Any,
    orientation: Any,
    point: Any,
    contact_time: Any,
    gravity: Any = 0.0,
    timestep: float = 1 / 240,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    other_stiffness: Any = np.inf,
    other_damping: Any = 0.1,
    breaking_threshold: float = np.inf,
) -> BodyContact:
    """The design that gives a body's point contact ``restitution`` and ``contact_time``.

    Parameters
    ----------
    restitution, contact_time
        Target phase means (the point's separation over approach speed; seconds).
    speed, gravity
        Approach speed at touch without rotation (m/s) and gravity (m/s^2).
    mass, inertia, orientation, point
        The body, as in :func:`~impactsym.engines.pybullet.body_prediction.predict_body`.
    timestep, slop, processing_threshold, other_stiffness, other_damping
        As in :func:`~impactsym.engines.pybullet.design.contact_for`.
    breaking_threshold
        As in :func:`~impactsym.engines.pybullet.body_prediction.predict_body`.

    Returns
    -------
    BodyContact
        ``.stiffness``/``.damping`` for ``changeDynamics`` of the body and the body map's
        phase mean with them (``.frozen``: the scalar prediction of that design).

    Raises
    ------
    ValueError
        Where the scalar design of a corrected target does not exist (its reason and a
        timestep that reaches it).
    """
    m, moments, rotation, at = check_body(mass, inertia, orientation, point)
    e, _ = real_array("restitution", restitution, lower=0.0, strict=True)
    t, _ = real_array("contact_time", contact_time, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {restitution!r}")
    m_eff = effective_mass(m, moments, rotation, at)
    limits = []
    for name, value in (("processing_threshold", processing_threshold),
                        ("breaking_threshold", breaking_threshold)):  # fmt: skip
        a, a_scalar = real_array(name, value, allow_inf=True)
        if not a_scalar:
            raise ValueError(f"{name} must be one number (m), got {value!r}")
        limits.append(float(a))
    common = {"speed": speed, "gravity": gravity, "timestep": timestep, "slop": slop,
              "processing_threshold": min(limits),
              "other_stiffness": other_stiffness, "other_damping": other_damping}  # fmt: skip
    body = {"mass": m, "inertia": moments, "orientation": rotation, "point": at}
    ask_e, ask_t = e, t
    best, best_err = None, np.inf
    for _ in range(ROUNDS):
        design = contact_for(restitution=ask_e, contact_time=ask_t, mass=m_eff, **common)
        got = predict_body(stiffness=design.stiffness, damping=design.damping, **body,
                           **common)  # fmt: skip
        miss_e = e - np.asarray(got.restitution)
        miss_t = t - np.asarray(got.contact_time)
        err = float(np.max(np.maximum(np.abs(miss_e / e), np.abs(miss_t / t))))
        if best is None or err < best_err:
            best, best_err = got, err
        if not (np.isfinite(err) and err > _TOL):  # met, or a contact that sticks
            break
        ask_e, ask_t = ask_e + miss_e, ask_t + miss_t
    return best
