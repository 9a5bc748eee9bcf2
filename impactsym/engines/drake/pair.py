r"""Drake's rules that combine two geometries' point-contact properties into one contact.

``multibody/plant/contact_properties.cc`` (Drake 1.51): the stiffnesses act in series,
the Hunt–Crossley dissipations are weighted by the *other* geometry's stiffness, and the
relaxation times (``"sap"``) add:

.. math::

    k = \frac{k_A k_B}{k_A + k_B}, \qquad
    d = \frac{k_B d_A + k_A d_B}{k_A + k_B}, \qquad \tau = \tau_A + \tau_B .

A rigid geometry (``k = inf``) leaves the other's ``k`` and ``d``. (Drake rejects two
rigid geometries, and a rigid one in point contact puts the contact point at NaN in the
discrete solvers; give the ground a finite stiffness, e.g. twice the pair's ``k``.)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.validation import broadcast, finish, real_array

__all__ = ["combine"]


def combine(
    *,
    stiffness_a: Any,
    dissipation_a: Any,
    stiffness_b: Any,
    dissipation_b: Any,
) -> tuple[Any, Any]:
    """The pair's ``(point_contact_stiffness, hunt_crossley_dissipation)`` from two
    geometries' values, as Drake combines them (module docstring).

    Parameters
    ----------
    stiffness_a, stiffness_b : float or array_like
        Each geometry's ``point_contact_stiffness`` (N/m, ``> 0``; ``inf`` for rigid,
        at most one of the two).
    dissipation_a, dissipation_b : float or array_like
        Each geometry's ``hunt_crossley_dissipation`` (s/m, ``>= 0``).

    Examples
    --------
    >>> combine(stiffness_a=2e4, dissipation_a=0.5, stiffness_b=2e4, dissipation_b=1.5)
    (10000.0, 1.0)
    >>> combine(stiffness_a=1e4, dissipation_a=0.5, stiffness_b=np.inf, dissipation_b=9.0)
    (10000.0, 0.5)
    """
    values = {
        name: real_array(name, value, lower=0.0, strict=strict, allow_inf=allow_inf)
        for name, value, strict, allow_inf in (
            ("stiffness_a", stiffness_a, True, True),
            ("dissipation_a", dissipation_a, False, False),
            ("stiffness_b", stiffness_b, True, True),
            ("dissipation_b", dissipation_b, False, False),
        )
    }
    scalar = all(flag for _, flag in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    ka, da, kb, db = (np.broadcast_to(a, shape) for a, _ in values.values())
    rigid_a, rigid_b = np.isinf(ka), np.isinf(kb)
    if (rigid_a & rigid_b).any():
        raise ValueError("stiffness_a and stiffness_b are both inf: Drake needs one compliant "
                         "geometry in a point contact")  # fmt: skip
    with np.errstate(invalid="ignore"):
        k = np.where(rigid_a, kb, np.where(rigid_b, ka, ka * kb / (ka + kb)))
        d = np.where(rigid_a, db, np.where(rigid_b, da, kb / (ka + kb) * da + ka / (ka + kb) * db))
    return finish(k, scalar), finish(d, scalar)
