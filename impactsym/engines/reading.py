"""Reading a LAMMPS run state by state with the touch-phase definitions.

The drivers of :mod:`impactsym.engines.drivers` and
:mod:`impactsym.engines.lammps_granular_driver` step LAMMPS one timestep at a time and
hand every state (time, normal velocity, overlap, normal force) to a
:class:`StateReading`, which applies the definitions of
`docs/physics.md#touch-phase` in one place: the contact ends at the first state whose
overlap is gone (or, with ``limit_damping``, whose force is zero); a force that comes
back while the overlap lasts is a stick; the departure speed is read where the overlap
is gone. Needs no engine.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["StateReading"]


class StateReading:
    """The contact read from successive states; ``out`` holds the result.

    ``out`` starts from ``start`` (e.g. ``sticks``, ``steps``, ``mass``) and gains
    ``restitution``, ``contact_time``, ``released_by_position`` and ``departure_speed``.
    """

    def __init__(self, speed: float, limit_damping: bool, start: dict[str, Any]):
        self.v0, self.limit_damping = speed, limit_damping
        self.out = dict(start)
        self.touched = self.ended = False

    def see(self, t: float, vz: float, overlap: float, force: float) -> bool:
        """Take one state; ``True`` once the reading is complete (``out`` is final)."""
        out = self.out
        self.touched = self.touched or overlap > 0
        if not self.touched:
            return False
        if self.ended and overlap > 0 and force > 0:  # the force is back: it stays
            out.update(sticks=True, departure_speed=0.0, restitution=0.0)
            out["contact_time"] = math.inf
            return True
        if not self.ended and (overlap <= 0 or (self.limit_damping and force <= 0)):
            out.update(restitution=vz / self.v0, contact_time=t, released_by_position=overlap <= 0)
            self.ended = True
        if self.ended and overlap <= 0:
            out["departure_speed"] = vz
            return True
        if not self.ended:
            out["steps"] += 1
        return False

    def never_ended(self) -> dict[str, Any]:
        """The result when the steps ran out in contact: it sticks."""
        self.out.update(sticks=True, restitution=0.0, contact_time=math.inf, departure_speed=0.0)
        return self.out
