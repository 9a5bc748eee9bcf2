r"""What PyBullet delivers for ``changeDynamics(contactStiffness=k, contactDamping=c)``.

:func:`predict` runs the exact one-contact map of
:mod:`~impactsym.engines.pybullet.stepping` at the user's ``timestep`` (one touch phase)
or its phase mean and range (:mod:`~impactsym.engines.pybullet.phases`). The settings
that change the answer are keyword options, each with the PyBullet call that sets it:

* ``timestep``: ``setPhysicsEngineParameter(fixedTimeStep=...)`` (default ``1/240``);
* ``substeps``: ``setPhysicsEngineParameter(numSubSteps=...)``: each ``stepSimulation``
  runs that many sub-steps of ``timestep / substeps``; the user reads the states and
  ``getContactPoints`` (the last sub-step's impulse) once per call;
* ``slop``: ``setPhysicsEngineParameter(contactSlop=...)`` (default ``1e-5`` m);
* ``processing_threshold``: ``changeDynamics(body, -1, contactProcessingThreshold=...)``
  (default: every contact point the collision detection keeps, i.e. speculative contacts:
  the impulse starts in the step that would carry the body across the surface; ``0``:
  only overlapping points);
* ``other_stiffness``, ``other_damping``: the other body's values (pair rules,
  :mod:`~impactsym.engines.pybullet.pair`; default a static body left at PyBullet's
  defaults, which adds ``0.1`` N s/m).

Settings that do not change it: ``numSolverIterations`` (one contact row is solved in
the first iteration), warm starting, ``useSplitImpulse`` (the reduced-coordinate
bodies of ``createMultiBody``/``loadURDF`` never split; bodies created with
``useMaximalCoordinates=True`` are not modelled). Keep ``linearDamping=0`` on the body
(PyBullet's default ``0.04`` adds a drag the model leaves out). Velocity restitution
(``velocity_restitution``, ``restitution_threshold``) is modelled as the row adds it to a
contact with stiffness and damping. SI units.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import PhaseSummary
from impactsym.engines.pybullet.pair import combine_pair
from impactsym.engines.pybullet.phases import phase_summary
from impactsym.engines.pybullet.stepping import (
    DEFAULT_RESTITUTION_THRESHOLD,
    DEFAULT_SLOP,
    MAX_STEPS,
    step_budget,
    step_contact,
)
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, check_count, real_array

__all__ = ["PyBulletContact", "check_budget", "check_settings", "predict", "summary_contact"]


@dataclass(frozen=True, eq=False)
class PyBulletContact(ArrayRecord):
    """A PyBullet contact design and what the engine delivers with it (SI units).

    Attributes
    ----------
    stiffness, damping
        The body's ``contactStiffness`` (N/m) and ``contactDamping`` (N s/m).
    pair_stiffness, pair_damping
        The values the solver uses for the pair (series stiffness, summed damping).
    restitution
        Separation speed over approach speed at the end of contact (``0`` where it
        sticks); the phase mean with ``phase=None``.
    contact_time
        Seconds from geometric touch to the end state (``inf`` where it sticks at some
        phase).
    sticks
        True where the body sticks (at ``phase``, or at some phase with ``phase=None``).
    stick_fraction
        Fraction of the touch phases at which it sticks (0 or 1 at a given phase).
    restitution_range, contact_time_range
        ``(min, max)`` over every touch phase (``(value, value)`` at a given phase).
    timestep, substeps, phase
        The engine's step, sub-steps per call, and the touch phase (``None``: the mean).
    """

    stiffness: Any
    damping: Any
    pair_stiffness: Any
    pair_damping: Any
    restitution: Any
    contact_time: Any
    sticks: Any
    stick_fraction: Any
    restitution_range: Any
    contact_time_range: Any
    timestep: float
    substeps: int
    phase: Any = None


def check_budget(k: Any, c: Any, m: Any, h: float) -> None:
    """Refuse a ``timestep`` so fine that the exact map would take minutes (``ValueError``)."""
    budget = np.max(step_budget(k, c, m, h), initial=0.0)  # (an empty call: nothing to refuse)
    if budget > MAX_STEPS:
        raise ValueError(
            f"timestep = {h!r} s is too fine for the exact step-by-step map: the contact "
            f"needs a budget of {budget:.3g} steps (limit {MAX_STEPS}); use a timestep of at "
            f"least {h * budget / MAX_STEPS:.3g} s (the continuous contact is the limit)"
        )


def check_settings(
    slop: Any,
    processing_threshold: Any,
    substeps: Any,
    velocity_restitution: Any = 0.0,
    restitution_threshold: Any = DEFAULT_RESTITUTION_THRESHOLD,
) -> dict:
    """The validated engine settings as keywords of the step map (one number each)."""
    r, r_scalar = real_array("velocity_restitution", velocity_restitution, lower=0.0)
    rt, rt_scalar = real_array("restitution_threshold", restitution_threshold, lower=0.0)
    if not (r_scalar and rt_scalar):
        raise ValueError(
            f"velocity_restitution and restitution_threshold must be single numbers, "
            f"got {velocity_restitution!r} and {restitution_threshold!r}"
        )
    s, s_scalar = real_array("slop", slop, lower=0.0)
    t, t_scalar = real_array("processing_threshold", processing_threshold, allow_inf=True)
    if not (s_scalar and t_scalar):
        raise ValueError(
            f"slop and processing_threshold must be single numbers (engine settings), "
            f"got {slop!r} and {processing_threshold!r}"
        )
    n = check_count("substeps", substeps, lower=1, upper=10_000)
    return {
        "substeps": n,
        "slop": float(s),
        "processing_threshold": float(t),
        "velocity_restitution": float(r),
        "restitution_threshold": float(rt),
    }


def predict(
    *,
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any = 0.0,
    timestep: float = 1 / 240,
    substeps: int = 1,
    phase: Any = None,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    other_stiffness: Any = np.inf,
    other_damping: Any = 0.1,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> PyBulletContact:
    """PyBullet's bounce of a body (``mass``, kg) arriving at ``speed`` on a static body.

    Parameters
    ----------
    stiffness, damping
        ``changeDynamics(body, -1, contactStiffness=..., contactDamping=...)``; combined
        with ``other_stiffness``/``other_damping`` by the pair rules.
    mass
        The contact's effective mass (the body's mass for a sphere on a plane).
    speed, gravity
        Approach speed at touch (m/s) and the gravity pressing the body on (m/s^2).
    timestep, substeps, slop, processing_threshold
        Engine settings (module docstring: the PyBullet call behind each).
    velocity_restitution, restitution_threshold
        The pair's ``restitution`` (the product of both bodies' ``changeDynamics(...,
        restitution=...)``, default 0) and ``setPhysicsEngineParameter(
        restitutionVelocityThreshold=...)`` (default ``0.2f``): where the approach speed
        after the unconstrained step is at least the threshold, the row also asks for a
        separation speed ``velocity_restitution * w*``.
    phase
        Touch phase in ``[0, 1)`` (`docs/physics.md#touch-phase`); ``None``: the mean
        over phases, with the range over every phase.

    Returns
    -------
    PyBulletContact
        Exact for PyBullet's one-contact map (the proof runs PyBullet itself).

    >>> r = predict(stiffness=1e4, damping=40.0, mass=1.0, speed=1.0)
    >>> round(r.restitution, 4), [round(x, 4) for x in r.restitution_range]
    (0.3284, [0.3224, 0.3344])
    """
    names = ("stiffness", "damping", "mass", "speed", "gravity")
    values = (stiffness, damping, mass, speed, gravity)
    lowers = (0.0, 0.0, 0.0, 0.0, 0.0)
    stricts = (True, False, True, True, False)
    arrays, scalar = [], True
    for name, value, low, strict in zip(names, values, lowers, stricts, strict=True):
        a, s = real_array(name, value, lower=low, strict=strict)
        arrays.append(a)
        scalar = scalar and s
    h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not h_scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    settings = check_settings(
        slop, processing_threshold, substeps, velocity_restitution, restitution_threshold
    )
    k_body, c_body, m, v, g = arrays
    k, c = combine_pair(
        stiffness=k_body,
        damping=c_body,
        other_stiffness=other_stiffness,
        other_damping=other_damping,
    )
    k, c = np.asarray(k, float), np.asarray(c, float)
    broadcast(stiffness=k, damping=c, mass=m, speed=v, gravity=g)
    check_budget(k, c, m, float(h))
    if phase is None:
        summary = phase_summary(k, c, m, v, g, float(h), **settings)
        return summary_contact(
            summary, k_body, c_body, k, c, scalar=scalar, timestep=float(h),
            substeps=settings["substeps"],
        )  # fmt: skip
    p, p_scalar = real_array("phase", phase, lower=0.0)
    if np.any(p >= 1):
        raise ValueError(f"phase must lie in [0, 1), got {phase!r}")
    scalar = scalar and p_scalar
    at = step_contact(k, c, m, v, g, float(h), p, **settings)
    e, t, sticks = at.restitution, at.contact_time, at.sticks
    ranges = (e, e), (t, t)
    frac = sticks.astype(float)
    return _record(
        k_body, c_body, k, c, e, t, sticks, frac, ranges, scalar, h, settings["substeps"], phase
    )


def summary_contact(
    summary: PhaseSummary,
    stiffness: Any,
    damping: Any,
    pair_stiffness: Any,
    pair_damping: Any,
    *,
    scalar: bool,
    timestep: float,
    substeps: int,
) -> PyBulletContact:
    """The :class:`PyBulletContact` over the touch phase (``phase=None``) of the body's
    ``stiffness``, ``damping`` and the pair's values, from their ``summary``
    (:func:`~impactsym.engines.pybullet.phases.phase_summary`); ``scalar``: floats out.
    Shared by :func:`predict` and the designs, whose last exact evaluation is this
    summary."""
    ranges = (
        (summary.restitution_min, summary.restitution_max),
        (summary.contact_time_min, summary.contact_time_max),
    )
    frac = summary.stick_fraction
    return _record(
        stiffness, damping, pair_stiffness, pair_damping, summary.restitution,
        summary.contact_time, frac > 0, frac, ranges, scalar, timestep, substeps, None,
    )  # fmt: skip


def _record(k_body, c_body, k, c, e, t, sticks, frac, ranges, scalar, h, substeps, phase):
    """The :class:`PyBulletContact` of these fields (floats where ``scalar``)."""
    out = [np.broadcast_to(a, np.shape(e)) for a in (k_body, c_body, k, c)]
    out += [e, t, sticks, frac]
    if scalar:
        kinds = (float, float, float, float, float, float, bool, float)
        out = [kind(a) for kind, a in zip(kinds, out, strict=True)]
        ranges = tuple((float(a), float(b)) for a, b in ranges)
    return PyBulletContact(*out, *ranges, float(h), substeps, phase)
