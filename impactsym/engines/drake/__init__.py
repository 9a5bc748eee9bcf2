"""Drake's point contact as an impact: predict and design ``point_contact_stiffness`` and
``hunt_crossley_dissipation``.

Drake's point contact pushes with ``f_n = k x (1 + d x')_+``.

* :mod:`~impactsym.engines.drake.prediction`: :func:`predict` (continuous plants:
  the Hunt–Crossley law of :mod:`impactsym.contact.nonlinear`, with gravity; discrete
  plants: the exact update per touch phase, or its phase mean and range);
* :mod:`~impactsym.engines.drake.design`: :func:`point_contact_for` (the inverse);
* :mod:`~impactsym.engines.drake.pair`: :func:`combine` (two geometries into one contact);
* :mod:`~impactsym.engines.drake.update` (the discrete update of ``tamsi``, ``similar``,
  ``lagged`` and ``sap`` in closed form), :mod:`~impactsym.engines.drake.derivation`
  (its SymPy derivation), :mod:`~impactsym.engines.drake.stepping` (the contact per
  touch phase), :mod:`~impactsym.engines.drake.phases` (mean and range over the phase);
* :mod:`~impactsym.engines.drake.driver`: runs Drake itself (needs ``pydrake``) to check
  all of the above.

The physics, and how Drake's source was read, is in `docs/physics.md#drake-point-contact`.
All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

from impactsym.engines.drake.design import PointContact, point_contact_for
from impactsym.engines.drake.pair import combine
from impactsym.engines.drake.prediction import DEFAULT_APPROXIMATION, Prediction, predict
from impactsym.engines.drake.update import APPROXIMATIONS, DEFAULT_RELAXATION_TIME

__all__ = [
    "APPROXIMATIONS",
    "DEFAULT_APPROXIMATION",
    "DEFAULT_RELAXATION_TIME",
    "PointContact",
    "Prediction",
    "combine",
    "point_contact_for",
    "predict",
]
