r"""What each engine's users paste for "restitution ``e``, contact time ``t_c``": the native
recipes that :mod:`impactsym.engines.side_by_side` measures next to impactsym's designs.

Every recipe starts from the textbook linear spring-damper, released when the position
returns to zero:

.. math::

    D = \frac{-\ln e}{\sqrt{\pi^2 + \ln^2 e}}, \qquad
    \omega_0 = \frac{\pi}{t_c \sqrt{1 - D^2}}, \qquad
    k = m \omega_0^2, \qquad c = 2 D m \omega_0,

which gives ``e`` and ``t_c`` only for that continuous contact (no force criterion, no
gravity, no timestep). The engines' recipes:

* MuJoCo (:func:`mujoco_textbook`): ``solref = (0.02, D)``, MuJoCo's default ``timeconst``
  with the textbook ``dampratio``, default ``solimp`` (the MuJoCo documentation's
  dampratio, and the usual answer in its issues);
* LAMMPS (:func:`lammps_coeff_restitution`): ``pair_coeff * * hooke kn e ...  damping
  coeff_restitution`` with ``kn = m omega0^2``: LAMMPS turns ``e`` into
  ``eta_n = 2 D sqrt(m_eff kn)`` (``fix wall/gran``: ``m_eff`` the sphere's mass) and
  users run at ``timestep = t_c / 50``;
* Drake (:func:`drake_hunt_crossley`): ``point_contact_stiffness = m (pi / t_c)^2`` (the
  elastic linear spring of that contact time) and ``hunt_crossley_dissipation`` from a
  published Hunt–Crossley formula of :mod:`impactsym.contact.lawformulas` (Hunt–Crossley
  1975 ``3 (1 - e) / (2 v0)`` or Lankarani–Nikravesh ``3 (1 - e^2) / (4 v0)``);
* PyBullet (:func:`pybullet_textbook`): ``changeDynamics(contactStiffness=k,
  contactDamping=c)`` with the continuous ``k``, ``c`` above;
* PyBullet (:func:`pybullet_restitution`): the rigid default contact with velocity
  restitution, ``changeDynamics(body, -1, restitution=e)`` and the plane's
  ``restitution = 1`` (Bullet combines a pair's restitutions as their product, so the
  pair's is ``e``); no contact time can be asked for.

These are the inputs only; what the engines deliver with them is predicted by the
engine models and measured by :mod:`impactsym.engines.side_by_side`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.contact import lawformulas
from impactsym.engines import mujoco
from impactsym.engines.lammps import textbook_damping_ratio
from impactsym.validation import real_array

__all__ = [
    "HUNT_CROSSLEY_FORMULAS",
    "drake_hunt_crossley",
    "lammps_coeff_restitution",
    "linear_textbook",
    "mujoco_textbook",
    "pybullet_restitution",
    "pybullet_textbook",
]

#: The Hunt–Crossley formulas a Drake user may paste: name -> ``lambda(e, v0)`` (s/m).
HUNT_CROSSLEY_FORMULAS = {
    "hunt-crossley-1975": lawformulas.hunt_crossley_1975,
    "lankarani-nikravesh": lawformulas.lankarani_nikravesh,
}


def _inputs(restitution: Any, contact_time: Any, mass: Any) -> tuple[np.ndarray, ...]:
    e = real_array("restitution", restitution, lower=0.0, strict=True)[0]
    if np.any(e >= 1.0):
        raise ValueError(f"restitution must be < 1, got {float(np.max(e))!r}")
    t_c = real_array("contact_time", contact_time, lower=0.0, strict=True)[0]
    m = real_array("mass", mass, lower=0.0, strict=True)[0]
    return e, t_c, m


def linear_textbook(*, restitution: Any, contact_time: Any, mass: Any) -> tuple[Any, Any]:
    """The textbook continuous spring-damper ``(k, c)`` (N/m, N s/m) for ``restitution``
    and ``contact_time`` (s) of a ``mass`` (kg): module docstring, position criterion.

    >>> k, c = linear_textbook(restitution=0.5, contact_time=0.02, mass=0.1)
    >>> round(float(k), 3), round(float(c), 5)
    (2587.514, 6.93147)
    """
    e, t_c, m = _inputs(restitution, contact_time, mass)
    D = np.asarray(textbook_damping_ratio(e), dtype=float)
    omega0 = np.pi / (t_c * np.sqrt(1.0 - D * D))
    return m * omega0**2, 2.0 * D * m * omega0


def mujoco_textbook(*, restitution: Any) -> tuple[float, Any]:
    """MuJoCo's textbook ``solref``: ``(DEFAULT_TIMECONST, D(e))`` (timeconst form).

    >>> mujoco_textbook(restitution=0.5)[0]
    0.02
    """
    e = _inputs(restitution, 1.0, 1.0)[0]
    return mujoco.DEFAULT_TIMECONST, np.asarray(textbook_damping_ratio(e), dtype=float)


def lammps_coeff_restitution(
    *, restitution: Any, contact_time: Any, mass: Any
) -> tuple[Any, Any, Any]:
    """``(kn, e, eta_n)``: the ``pair_coeff`` of ``hooke kn e`` with ``damping
    coeff_restitution`` (``kn = m omega0^2``, :func:`linear_textbook`) and the
    ``eta_n = 2 D sqrt(m kn)`` (N s/m) LAMMPS derives from ``e`` (``m`` the effective
    mass; ``pair granular`` source: ``sqrt(4 meff kn / (1 + (pi / ln e)^2))``).

    >>> kn, e, eta = lammps_coeff_restitution(restitution=0.5, contact_time=0.02, mass=0.1)
    >>> round(float(eta), 5)
    6.93147
    """
    e, t_c, m = _inputs(restitution, contact_time, mass)
    kn, _ = linear_textbook(restitution=e, contact_time=t_c, mass=m)
    D = np.asarray(textbook_damping_ratio(e), dtype=float)
    return kn, e, 2.0 * D * np.sqrt(m * kn)


def drake_hunt_crossley(
    *,
    restitution: Any,
    contact_time: Any,
    mass: Any,
    speed: Any,
    formula: str = "hunt-crossley-1975",
) -> tuple[Any, Any]:
    """``(point_contact_stiffness, hunt_crossley_dissipation)``: the elastic linear
    stiffness ``m (pi / t_c)^2`` (N/m) and the dissipation ``d`` (s/m) of a published
    formula (:data:`HUNT_CROSSLEY_FORMULAS`) at the approach ``speed``.

    >>> k, d = drake_hunt_crossley(restitution=0.5, contact_time=0.02, mass=0.1, speed=1.0)
    >>> round(float(k), 3), float(d)
    (2467.401, 0.75)
    """
    if formula not in HUNT_CROSSLEY_FORMULAS:
        raise ValueError(
            f"formula must be one of {sorted(HUNT_CROSSLEY_FORMULAS)}, got {formula!r}"
        )
    e, t_c, m = _inputs(restitution, contact_time, mass)
    v = real_array("speed", speed, lower=0.0, strict=True)[0]
    d = np.asarray(HUNT_CROSSLEY_FORMULAS[formula](e, speed=v), dtype=float)
    return m * (np.pi / t_c) ** 2, d


def pybullet_textbook(*, restitution: Any, contact_time: Any, mass: Any) -> tuple[Any, Any]:
    """``(contactStiffness, contactDamping)``: the continuous :func:`linear_textbook`
    values, pasted into ``changeDynamics`` of the body (the plane keeps its defaults).

    >>> k, c = pybullet_textbook(restitution=0.5, contact_time=0.02, mass=0.1)
    >>> round(float(c), 5)
    6.93147
    """
    return linear_textbook(restitution=restitution, contact_time=contact_time, mass=mass)


def pybullet_restitution(*, restitution: Any) -> tuple[Any, Any]:
    """``(body, plane)``: the velocity ``restitution`` of ``changeDynamics`` for the body
    (``e``) and the plane (``1``), rigid contact (no ``contactStiffness``).

    Bullet's pair rule is the product (``btManifoldResult::calculateCombinedRestitution``),
    so the contact's restitution is ``e``; what PyBullet delivers with it is
    :func:`impactsym.engines.pybullet.predict_rigid`.

    >>> pybullet_restitution(restitution=0.5)
    (array(0.5), array(1.))
    """
    e = _inputs(restitution, 1.0, 1.0)[0]
    return e, np.ones_like(e)
