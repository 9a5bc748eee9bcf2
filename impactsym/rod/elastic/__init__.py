"""Finite contact stiffness: the rod time functions :math:`y, N` for :math:`\\kappa < \\infty`.

One method per module (docs/physics.md#finite-contact-stiffness-three-methods):

* :mod:`~impactsym.rod.elastic.poles` -- pole sums of the inverted delay series, pointwise,
  float64 with an mpmath fallback: :func:`impactsym.rod.displacement` and
  :func:`impactsym.rod.contact_force`, and the reference of the tables;
* :mod:`~impactsym.rod.elastic.cells` -- a certified cell table re-expanded from the poles
  in mpmath (seconds; any stiffness);
* :mod:`~impactsym.rod.elastic.taylor` -- a certified Taylor table of the delay equations in
  float64 (milliseconds; springs up to ``MAX_CELLS`` cells per interval);
* :mod:`~impactsym.rod.elastic.manifold` -- the same equations and bound for stiff springs
  on a mesh that does not grow with the stiffness (fast layers, then the slow manifold);
* :mod:`~impactsym.rod.elastic.chain` -- all cells of a reflection interval at once, for
  the two float64 tables;
* :mod:`~impactsym.rod.elastic.search` -- the certified contact-time search on a table,
  falling back on the pole sums where the table's bound is too large.

Both tables follow :class:`CertifiedTable`, all the search asks of them.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np


class CertifiedTable(Protocol):
    """Internal: a time function :math:`g = A + f B + \\epsilon` on cells, as the
    finite-kappa contact-time search (:mod:`impactsym.rod.elastic.search`) uses it.

    Implemented by :class:`impactsym.rod.elastic.cells.CellTable` and
    :class:`impactsym.rod.elastic.taylor.TaylorView` (of a Taylor or a slow-manifold table).

    Attributes
    ----------
    lo : numpy.ndarray
        Left ends of the cells, increasing; they include the reflection times ``2k``.
    """

    lo: np.ndarray

    def cell(self, t: np.ndarray) -> np.ndarray:
        """Index of the cell holding each ``t`` (the right one at a node)."""
        ...

    def evaluate(
        self, t: np.ndarray, f: np.ndarray, index: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``A + f B`` and its time derivative at ``t`` on cells ``index``."""
        ...

    def certified(self, index: np.ndarray, f: np.ndarray, tolerance: float) -> np.ndarray:
        """Whether ``|epsilon|`` is proved at most ``tolerance`` on cells ``index`` for ``f``
        (where not, the search uses the pole sums)."""
        ...

    def second_derivative_bound(self, index: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Bound on ``|d^2/dt^2 (A + f B)|`` over cells ``index``."""
        ...
