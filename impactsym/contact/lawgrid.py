r"""Contact-time and restitution maps of every contact law over (damping number, ``f``).

**What.** :func:`law_contact_map` evaluates one impact per point of a grid of a law's
damping number :math:`\delta` and pressing number ``f`` (:mod:`impactsym.contact.laws`):
the normalized contact time :math:`\tau_c = t_c/T` (``inf`` where the body sticks) and
the restitution, the analogue of the paper's contact-time maps for each law
(``docs/physics.md``, "Nonlinear contact laws", *Stick boundary and bounce sequence*).

**Why this numerics.** All points go through one call of
:func:`~impactsym.contact.lawnumbers.law_impact`, vectorized over the whole grid: the
closed forms of the linear contact for ``"linear"``, the exact order-8 integration (or a
closed form where one holds) for the others. Nothing here loops over grid points.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.lawnumbers import law_impact, law_inputs
from impactsym.records import ArrayRecord
from impactsym.validation import finish

ArrayLike = float | np.ndarray


@dataclass(frozen=True, eq=False)
class LawContactMap(ArrayRecord):
    r"""Contact time and restitution of one law over a (damping number, ``f``) grid.

    Attributes
    ----------
    law, condition
        The contact law and the contact condition.
    damping_number, f, exponent
        The broadcast inputs (``exponent``: the one in use, 1 for ``"linear"`` and 3/2
        for ``"viscoelastic"``).
    contact_time
        Normalized contact time :math:`t_c/T` (``inf`` where the body sticks); for
        ``"linear"`` :math:`\tau_c = \omega_0 t_c`.
    restitution
        Speed at the end of contact over the impact speed (``0.0`` where it sticks).
    """

    law: str
    condition: str
    damping_number: ArrayLike
    f: ArrayLike
    exponent: ArrayLike
    contact_time: ArrayLike
    restitution: ArrayLike

    @property
    def sticks(self) -> bool | np.ndarray:
        """Whether the body sticks (never releases)."""
        stuck = np.isinf(self.contact_time)
        return bool(stuck) if np.ndim(stuck) == 0 else stuck

    def plot(self, *, quantity: str = "contact_time", boundary: Any = None, ax: Any = None) -> Any:
        """Map of ``quantity`` (see :func:`impactsym.plotting.laws.plot_law_map`)."""
        from impactsym.plotting.laws import plot_law_map

        return plot_law_map(self, quantity=quantity, boundary=boundary, ax=ax)


def law_contact_map(
    law: str,
    damping_number: ArrayLike,
    f: ArrayLike,
    *,
    exponent: ArrayLike = 1.5,
    condition: str,
) -> LawContactMap:
    r"""Normalized contact time and restitution of ``law`` over broadcast arrays.

    Parameters
    ----------
    law : {"linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic"}
        The contact law.
    damping_number, f : float or array_like
        The law's damping number (``D``, ``s``, ``alpha``, ``beta``; ``>= 0``) and
        pressing number (:math:`F_0/(c v_0)` for ``"linear"``, :math:`F_0 T/(m v_0)`
        otherwise; ``>= 0``). Arrays broadcast (e.g. a meshgrid).
    exponent : float or array_like
        ``p >= 1`` of the laws that have one.
    condition : {"position", "force", "clipped"}
        How the contact ends (``"clipped"``: :func:`~impactsym.contact.nonlinear.impact`);
        clipped, the contact time runs to the end of the overlap and the restitution is
        the speed there.

    Returns
    -------
    LawContactMap

    Examples
    --------
    >>> m = law_contact_map("linear", [0.0, 0.5], 0.0, condition="force")
    >>> np.round(m.contact_time, 12).tolist()  # half a period without damping
    [3.14159265359, 2.418399152312]
    >>> law_contact_map("hunt-crossley", 0.3, 50.0, condition="position").sticks
    True
    """
    (delta, force), q, shape, scalar = law_inputs(
        law, condition=condition, exponent=exponent, damping_number=damping_number, f=f
    )
    tau_c, e = law_impact(law, delta, force, q, condition=condition)
    return LawContactMap(
        law=law,
        condition=condition,
        damping_number=finish(delta.reshape(shape), scalar),
        f=finish(force.reshape(shape), scalar),
        exponent=finish(q.reshape(shape), scalar),
        contact_time=finish(tau_c.reshape(shape), scalar),
        restitution=finish(e.reshape(shape), scalar),
    )
