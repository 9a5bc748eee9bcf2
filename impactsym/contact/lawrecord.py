r"""The result of one impact on a contact law: :class:`NonlinearImpact`.

The record that :func:`~impactsym.contact.nonlinear.impact` returns, in physical units
with the normalized numbers it was computed from (``docs/physics.md``, "Nonlinear contact
laws").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.records import ArrayRecord

ArrayLike = float | np.ndarray


@dataclass(frozen=True, eq=False)
class NonlinearImpact(ArrayRecord):
    r"""One impact on a contact law, in physical units, with its normalized numbers.

    Attributes
    ----------
    law, condition
        The contact law and the contact condition used.
    damping_number, pressing_number
        The law's damping number (``D``, ``s``, ``alpha`` or ``beta``) and pressing
        number ``f`` (``docs/physics.md``, "Nonlinear contact laws").
    time_scale, length_scale
        :math:`T = (m/(k v_0^{p-1}))^{1/(p+1)}` and :math:`L = v_0 T`.
    contact_time
        From touch to the end of contact (``inf``: the body sticks).
    restitution
        Speed at the end of contact over ``v0`` (``0.0`` when sticking).
    max_penetration, peak_force
        Largest overlap and largest compressive contact force (without the pressing
        force); for a sticking body, over the whole motion towards rest.
    """

    law: str
    condition: str
    damping_number: ArrayLike
    pressing_number: ArrayLike
    time_scale: ArrayLike
    length_scale: ArrayLike
    contact_time: ArrayLike
    restitution: ArrayLike
    max_penetration: ArrayLike
    peak_force: ArrayLike

    @property
    def sticks(self) -> bool | np.ndarray:
        """Whether the body sticks (never releases)."""
        stuck = np.isinf(self.contact_time)
        return bool(stuck) if np.ndim(stuck) == 0 else stuck
