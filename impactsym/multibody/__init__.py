"""Penalty contacts in multibody systems (paper section 3).

* :mod:`~impactsym.multibody.equations` -- ``M(q) u' = F`` from matrices or a
  ``sympy.physics.mechanics`` model;
* :mod:`~impactsym.multibody.reduction` -- :func:`reduce_contact`: ``M q'' = F + n lambda``
  with ``lambda = -d z' - k z`` reduced to one scalar oscillator;
* :mod:`~impactsym.multibody.oscillator` -- :class:`ReducedContact`, that oscillator and its
  section-2 contact time, restitution and stick/release verdict;
* :mod:`~impactsym.multibody.design` -- penalty parameters ``k, d`` for a wanted behaviour;
* :mod:`~impactsym.multibody.examples` -- the example systems, a falling bar and a double
  pendulum;
* :mod:`~impactsym.multibody.simulation` -- a full NumPy simulation with event location,
  the judge of the reduction, and the sweeps comparing the two.
"""

from __future__ import annotations

from impactsym._lazy import lazy_names

_NAMES = {
    "reduce_contact": "impactsym.multibody.reduction",
    "ReducedContact": "impactsym.multibody.oscillator",
    "stick_damping": "impactsym.multibody.design",
    "damping_for_restitution": "impactsym.multibody.design",
    "penalty_for_targets": "impactsym.multibody.design",
}
__all__ = sorted(_NAMES)
__getattr__, __dir__ = lazy_names(__name__, _NAMES)
