"""An elastic rod, fixed at its far end, struck by a point mass (paper section 1).

* :mod:`~impactsym.rod.derivation` -- SymPy: the Laplace-transformed boundary-value problem
  (eq. (1)), its closed-form solution, the reflection series in :math:`\\Delta = e^{-s}`
  (eq. (2)) and their exact term-by-term inversion (:class:`RodImpact`);
* :mod:`~impactsym.rod.kernel` -- NumPy only: the rigid-contact :math:`y(t)`, :math:`N(t)`;
* :mod:`~impactsym.rod.elastic` -- a finite contact stiffness, one method per module: pole
  sums (``poles``), the mpmath cell table (``cells``), the float64 Taylor table (``taylor``),
  and the contact-time search on them (``search``);
* :mod:`~impactsym.rod.api` -- :func:`displacement`, :func:`contact_force`,
  :func:`impact_sequence` (the impact continued past separation: flight, re-contact);
* :mod:`~impactsym.rod.rigid_search` -- the certified contact-time search, rigid contact;
* :mod:`~impactsym.rod.contact_times` -- :func:`contact_time`, :func:`contact_time_map`;
* :mod:`~impactsym.rod.codegen` -- the NumPy-only source that ``impactsym export`` writes;
* :mod:`~impactsym.rod.history` -- :func:`time_history`: sampled :math:`y(t)`, :math:`N(t)`
  with both contact times, for figures;
* :mod:`~impactsym.rod.sequence` -- its result objects (:class:`RodImpactSequence`,
  :class:`ElasticRodImpactSequence`: energy split, fixed-end stress) and its one event loop,
  over the step models :mod:`~impactsym.rod.sequence_rigid` (rigid contact) and
  :mod:`~impactsym.rod.sequence_elastic` (a finite contact stiffness).
"""

from __future__ import annotations

from impactsym._lazy import lazy_names

_NAMES = {
    "RodImpact": "impactsym.rod.derivation",
    "latex_formulas": "impactsym.rod.derivation",
    "displacement": "impactsym.rod.api",
    "contact_force": "impactsym.rod.api",
    "contact_time": "impactsym.rod.contact_times",
    "contact_time_map": "impactsym.rod.contact_times",
    "ContactTimeMap": "impactsym.rod.contact_times",
    "numpy_source": "impactsym.rod.codegen",
    "impact_sequence": "impactsym.rod.api",
    "RodImpactSequence": "impactsym.rod.sequence",
    "ElasticRodImpactSequence": "impactsym.rod.sequence",
    "time_history": "impactsym.rod.history",
    "TimeHistory": "impactsym.rod.history",
}
__all__ = sorted(_NAMES)
__getattr__, __dir__ = lazy_names(__name__, _NAMES)
