"""PyBullet's ``contactStiffness``/``contactDamping`` contact at the user's timestep.

* :mod:`~impactsym.engines.pybullet.stepping`: the exact one-contact map of Bullet's
  sequential-impulse solver (ERP/CFM from ``k``, ``c`` and the step, speculative
  contacts, slop, the non-negative impulse, sub-steps) per touch phase;
* :mod:`~impactsym.engines.pybullet.phases`: mean and range over touch phases;
* :mod:`~impactsym.engines.pybullet.prediction`: :func:`predict`;
* :mod:`~impactsym.engines.pybullet.design`: :func:`contact_for`, many targets of one
  contact started from a table of the phase means
  (:mod:`~impactsym.engines.pybullet.design_table`);
* :mod:`~impactsym.engines.pybullet.pair`: the pair rules (:func:`combine_pair`,
  :func:`split_pair`);
* :mod:`~impactsym.engines.pybullet.rigid`, :mod:`~impactsym.engines.pybullet.rigid_prediction`:
  the rigid contact (no ``contactStiffness``) with velocity ``restitution``,
  :func:`predict_rigid`;
* :mod:`~impactsym.engines.pybullet.body`, :mod:`~impactsym.engines.pybullet.body_prediction`,
  :mod:`~impactsym.engines.pybullet.body_design`: a free rigid body touching the plane with
  one point (a box's corner), its row's effective mass and lever turning with it step by
  step: :func:`predict_body`, :func:`body_contact_for`;
* :mod:`~impactsym.engines.pybullet.derivation`: the SymPy derivation of the map;
* :mod:`~impactsym.engines.pybullet.driver`: PyBullet itself, a sphere on a plane.

The physics is in `docs/physics.md#pybullet-at-its-timestep`. SI units throughout.
"""

from __future__ import annotations

from impactsym.engines.pybullet.body_design import body_contact_for
from impactsym.engines.pybullet.body_prediction import BodyContact, predict_body
from impactsym.engines.pybullet.design import contact_for
from impactsym.engines.pybullet.pair import combine_pair, split_pair
from impactsym.engines.pybullet.prediction import PyBulletContact, predict
from impactsym.engines.pybullet.rigid_prediction import RigidContact, predict_rigid

__all__ = [
    "BodyContact",
    "PyBulletContact",
    "RigidContact",
    "body_contact_for",
    "combine_pair",
    "contact_for",
    "predict",
    "predict_body",
    "predict_rigid",
    "split_pair",
]
