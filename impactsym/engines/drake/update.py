r"""Drake's discrete update for one frictionless point contact, in closed form.

Drake 1.51's discrete :class:`MultibodyPlant` advances ``v`` implicitly with the contact
impulse of the *new* velocity and then ``q`` with the new velocity (symplectic Euler). For
one normal degree of freedom (penetration ``x``, approach rate ``u = x'``, mass ``m``,
pressing acceleration ``g``, step ``h``) and the free velocity ``u* = u_n + h g``:

* ``"tamsi"``, ``"similar"``, ``"lagged"``: the impulse is the Hunt–Crossley law at the
  predicted penetration ``x_n + h u`` (``SapHuntCrossleyConstraint``,
  ``CalcDiscreteHuntCrossleyImpulse``: ``n = h (f_e0 + h k u)_+ (1 + d u)_+`` with
  ``f_e0 = k x_n``; TAMSI's normal force is the same function and the two SAP
  approximations differ only in the friction term), so

  .. math:: m (u - u^*) + h k (x_n + h u)_+ (1 + d u)_+ = 0,

  whose left side increases with ``u``: one root. It is ``u = u*`` (no force) where
  ``u* <= max(-x_n/h, -1/d)``, else the larger root of a quadratic
  (:func:`hunt_crossley_velocity`, derived in :mod:`impactsym.engines.drake.derivation`).
* ``"sap"``: ``SapFrictionConeConstraint`` ignores the dissipation ``d``; with the
  relaxation time ``tau`` (the sum of the two geometries' ``relaxation_time``) the normal
  impulse is ``(x_n/(h + tau) + u)_+ / R`` with
  ``R = max(beta^2/(4 pi^2) / m, 1/(h k (h + tau)))`` (near-rigid threshold
  ``beta = 1``): a spring ``k`` and a dashpot ``k tau`` evaluated implicitly, with the
  stiffness capped where the contact is near rigid (:func:`sap_velocity`).

Then ``x_{n+1} = x_n + h u_{n+1}``. Drake reports a point contact at penetration
``x >= 0`` (also exactly 0) and never ahead of it (no speculative contact).
All quantities are SI. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "APPROXIMATIONS",
    "DEFAULT_RELAXATION_TIME",
    "hunt_crossley_root",
    "hunt_crossley_velocity",
    "sap_velocity",
]

#: Drake's discrete contact approximations (MultibodyPlantConfig.discrete_contact_approximation).
APPROXIMATIONS = ("tamsi", "similar", "lagged", "sap")
#: Combined relaxation time of two geometries without a ``relaxation_time`` property:
#: Drake's default 0.1 s each, summed (``GetCombinedDissipationTimeConstant``).
DEFAULT_RELAXATION_TIME = 0.2
#: SAP's near-rigid threshold beta (``MultibodyPlantConfig.sap_near_rigid_threshold``).
NEAR_RIGID_THRESHOLD = 1.0


def hunt_crossley_velocity(
    x: Any, u: Any, k: Any, d: Any, m: Any, g: Any, h: Any
) -> tuple[np.ndarray, np.ndarray]:
    """New approach rate and impulse of one ``tamsi``/``similar``/``lagged`` update.

    Arrays broadcast. The root of ``m (u' - u*) + h k (x + h u')(1 + d u') = 0`` in the
    stable form ``u' = 2 c / (b + sqrt(b^2 + 4 a c))`` with ``a = h^2 k d``,
    ``b = m + h^2 k + h k d x`` and ``c = m u* - h k x`` (no cancellation for ``d = 0``
    either). Returns ``(u', impulse)`` with ``impulse = m (u* - u') >= 0``.
    """
    ustar, root = hunt_crossley_root(x, u, k, d, m, g, h)
    with np.errstate(invalid="ignore", divide="ignore"):
        limit = np.where(d > 0, np.maximum(-x / h, -1.0 / d), -x / h)
    free = ustar <= limit
    new = np.where(free, ustar, root)
    return new, np.where(free, 0.0, m * (ustar - new))


def hunt_crossley_root(
    x: Any, u: Any, k: Any, d: Any, m: Any, g: Any, h: Any, *, clip: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """``(u*, root)``: the free velocity and the larger root of
    ``m (u' - u*) + h k (x + h u')(1 + d u') = 0`` in the stable form of
    :func:`hunt_crossley_velocity`, without its clipping of the impulse (``clip=False``:
    nor of the discriminant at 0, so ``nan`` where there is no real root)."""
    ustar = u + h * g
    a = h * h * k * d
    b = m + h * h * k + h * k * d * x
    c = m * ustar - h * k * x
    disc = b * b + 4.0 * a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = 2.0 * c / (b + np.sqrt(np.maximum(disc, 0.0) if clip else disc))
    return ustar, root


def sap_velocity(
    x: Any, u: Any, k: Any, tau: Any, m: Any, g: Any, h: Any
) -> tuple[np.ndarray, np.ndarray]:
    """New approach rate and impulse of one ``sap`` update (arrays broadcast).

    ``m (u' - u*) = -(x/(h + tau) + u')_+ / R``: linear, so
    ``u' = (m R u* - x/(h + tau)) / (m R + 1)`` where the impulse is positive.
    """
    ustar = u + h * g
    rn = np.maximum(NEAR_RIGID_THRESHOLD**2 / (4.0 * np.pi**2) / m, 1.0 / (h * k * (h + tau)))
    bias = x / (h + tau)
    free = bias + ustar <= 0.0
    new = np.where(free, ustar, (m * rn * ustar - bias) / (m * rn + 1.0))
    return new, np.where(free, 0.0, m * (ustar - new))
