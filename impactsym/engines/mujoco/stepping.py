r"""MuJoCo's contact as the engine steps it: the touch phase and the per-phase result.

A discrete engine sees the contact only at its states ``t_n``. Definitions (every
discrete model and every engine test uses them; `docs/physics.md#touch-phase`):

* ``speed`` is the normal approach speed at geometric touch (time 0). The body arrives
  in free flight; the **touch phase** ``phase`` in ``[0, 1)`` places geometric touch
  ``phase * timestep`` before the first engine state that detects the contact.
  For the Euler-type integrators that state carries the free-flight penetration
  ``speed t + g t^2 / 2`` and velocity ``speed + g t`` at ``t = phase * timestep``; for
  RK4 the state one step earlier carries free flight, and the step that carries the body
  in runs its own four stages (each with its own collision and force).
* The contact lasts over the engine states from the first detecting one on, at which the
  engine reports the contact with a positive normal force; it **ends** at the first
  state at which the contact is gone or its force is zero. ``restitution`` is the normal
  separation velocity of that state over ``speed``; ``contact_time`` is the time from
  geometric touch to that state.
* If the force comes back before the overlap is gone, the body does not leave: it
  **sticks** (``sticks=True``, ``contact_time=inf``, ``restitution=0``). Where gravity
  slows the body while it coasts through the remaining overlap, ``departure_speed`` is
  the speed with which it finally leaves.

All quantities are SI: seconds, metres, m/s, m/s^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.records import ArrayRecord

__all__ = ["StepContact"]


@dataclass(frozen=True, eq=False)
class StepContact(ArrayRecord):
    """The contact at a given touch phase, as the engine's states show it (arrays, SI).

    Attributes
    ----------
    restitution
        Separation speed of the end state over ``speed`` (0 where it sticks).
    contact_time
        Seconds from geometric touch to the end state (``inf`` where it sticks).
    sticks
        True where the contact never ends, or its force comes back inside the overlap.
    released_by_position
        True where the end state has no contact (the overlap is gone), False where its
        force is zero.
    departure_speed
        Normal speed (m/s) of the first state without contact (0 where it sticks); equal
        to ``restitution * speed`` where the contact ends by position.
    steps
        Engine states in contact before the end state (integers).
    max_penetration
        Largest penetration over the states in contact, metres.
    peak_accel
        Largest constraint acceleration over the states in contact, m/s^2 (times the
        effective mass: the peak force).
    """

    restitution: np.ndarray
    contact_time: np.ndarray
    sticks: np.ndarray
    released_by_position: np.ndarray
    departure_speed: np.ndarray
    steps: np.ndarray
    max_penetration: np.ndarray
    peak_accel: np.ndarray
