r"""Many discrete designs by contact time, read off tables of exact designs: one table
per end state, then one exact evaluation per design (:func:`table_designs`).

A target contact time of ``q`` steps fixes the end state :math:`B = \lfloor q - 1/2
\rfloor` before which, and the phase :math:`\varphi^* = q - 1/2 - B` at which, the end
state changes (:mod:`~impactsym.engines.drake.jump_means`). For one ``B`` (and one
``g / v``) the design, in the damping number :math:`s = d v` and the step
:math:`w = h \sqrt{k/m}`, is then a smooth function of :math:`(e, \varphi^*)`: the
change's equations have no plateau and no kink there. Across ``B`` it is not (a plateau
of the contact time lies between the designs at :math:`\varphi^* \to 1` and at the next
``B``'s :math:`\varphi^* \to 0`), so each ``B`` gets its own table.

* **The table** of a ``B``: the exact designs (``design``, the caller's own path) at
  :data:`NODES_E` by :data:`NODES_PHASE` Chebyshev points of the first kind, over the
  restitutions of that ``B``'s targets and the phases :data:`PHASES` (under gravity
  :data:`PHASES_PRESSED`: closer to the ends of the phase interval the design is not
  smooth there, 3e-4 off a smooth continuation at ``e = 0.56``, ``phi* = 0.001``).
  Measured (20 x 12 nodes, ``e`` 0.3-0.6, contacts of 22-35 steps, gravity 0 and 9.81):
  the interpolated ``(s, w)`` are within ``2e-14`` (median) and ``5e-13`` (largest) of
  exact designs at random targets, which is the exact designs' own spread: they meet
  their tolerances, not a point.
* **One exact evaluation** of the change's equations
  (:func:`~impactsym.engines.drake.jump_means.jump_means`, the full rule) at the table's
  design: it is done where the restitution is within :data:`TOLERANCE` of the target
  and the size within its relative tolerance, and the full contact confirms the change
  at the phase grid (:func:`~impactsym.engines.drake.jump_means.jump_holds`). The others
  are left to the caller (its tables and steps).

A ``B`` gets a table where at least :data:`MIN_TARGETS` targets share it: a table costs
``NODES_E * NODES_PHASE`` designs by the caller's path, a design read off it one
evaluation instead of about four and the steps'. All quantities SI, flat arrays.
Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawtable import chebyshev_points, chebyshev_transform
from impactsym.engines.drake.jump_means import jump_holds, jump_means

__all__ = [
    "MIN_TARGETS",
    "NODES_E",
    "NODES_PHASE",
    "PHASES",
    "PHASES_PRESSED",
    "TOLERANCE",
    "table_designs",
]

#: Chebyshev nodes of a table in the restitution and in the phase of the change.
NODES_E, NODES_PHASE = 20, 12
#: Targets sharing one end state ``B`` from which they are read off a table.
MIN_TARGETS = 1024
#: The phases of the change a table covers without gravity, and under it.
PHASES, PHASES_PRESSED = (0.0, 1.0), (0.05, 0.95)
#: A design read off a table is done within these of the restitution and (relative) of
#: the contact time: half the tolerances of the caller's check of its prediction
#: (``1e-12``, ``1e-10``), which the exact phase means meet where the change's
#: equations do (they agree to ``~2e-14`` and ``~1e-12`` steps).
TOLERANCE = (5e-13, 5e-11)


def table_designs(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, g: np.ndarray, q: np.ndarray, h: float,
    design: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(ok, k, d)`` of the targets ``(e, q)`` (restitution, contact time in steps) that
    share ``g / v``, read off the tables of their end states where those hold enough
    targets, each confirmed by one exact evaluation (module docstring); ``ok`` marks
    the targets designed here. ``design(e, q)`` gives the exact designs ``(s, w)`` of
    the tables' nodes (``nan`` where it has none) for the first target's ``m, v, g``.
    """
    n = e.size
    ok, k, d = np.zeros(n, bool), np.full(n, np.nan), np.full(n, np.nan)
    base = np.floor(q - 0.5)
    phase = q - 0.5 - base
    lo, hi = PHASES_PRESSED if g[0] > 0 else PHASES
    inside = (phase >= lo) & (phase < hi)
    bases, counts = np.unique(base[inside], return_counts=True)
    bases = bases[counts >= MIN_TARGETS]
    if bases.size == 0:
        return ok, k, d
    groups = [np.flatnonzero(inside & (base == b)) for b in bases]
    boxes = [_box(e[rows]) for rows in groups]
    x_e, x_p = chebyshev_points(NODES_E), chebyshev_points(NODES_PHASE)
    node_phase = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x_p
    node_e = np.concatenate(
        [np.repeat(0.5 * (a + b) + 0.5 * (b - a) * x_e, NODES_PHASE) for a, b in boxes]
    )
    node_q = np.concatenate([np.tile(b + 0.5 + node_phase, NODES_E) for b in bases])
    s_nodes, w_nodes = design(node_e, node_q)
    shape = (bases.size, NODES_E, NODES_PHASE)
    s_nodes, w_nodes = s_nodes.reshape(shape), w_nodes.reshape(shape)
    s, w = np.full(n, np.nan), np.full(n, np.nan)
    m_e, m_p = chebyshev_transform(NODES_E), chebyshev_transform(NODES_PHASE)
    for i, rows in enumerate(groups):
        values = np.stack([s_nodes[i], w_nodes[i]])
        if not np.isfinite(values).all():  # a node the caller's path leaves: no table
            continue
        coef = np.einsum("ij,fjk,lk->fil", m_e, values, m_p)
        a, b = boxes[i]
        x = (2.0 * e[rows] - (a + b)) / (b - a)
        y = (2.0 * phase[rows] - (lo + hi)) / (hi - lo)
        s[rows], w[rows] = _evaluate(coef, x, y)
    live = np.flatnonzero(np.isfinite(s) & np.isfinite(w))
    if live.size == 0:
        return ok, k, d
    k_t, d_t = m[live] * (w[live] / h) ** 2, s[live] / v[live]
    rows = (a[live] for a in (m, g, v))
    r = jump_means(k_t, d_t, *rows, h, q[live])
    hit = (np.abs(r.restitution - e[live]) <= TOLERANCE[0]) & (
        np.abs(r.size - q[live]) <= TOLERANCE[1] * q[live]
    )
    live, k_t, d_t = live[hit], k_t[hit], d_t[hit]
    held = jump_holds(k_t, d_t, *(a[live] for a in (m, g, v)), h, q[live])
    live = live[held]
    ok[live], k[live], d[live] = True, k_t[held], d_t[held]
    return ok, k, d


def _box(e):
    """The restitutions a table covers: those of its targets (a point widened a
    little)."""
    a, b = float(e.min()), float(e.max())
    pad = max(0.0, 1e-6 - 0.5 * (b - a))
    return a - pad, b + pad


def _evaluate(coef, x, y):
    """The tables ``coef`` (``(fields, NODES_E, NODES_PHASE)`` Chebyshev coefficients)
    at ``(x, y)`` in ``[-1, 1]^2``: ``fields`` arrays."""
    ve = chebyshev.chebvander(x, coef.shape[1] - 1)
    vp = chebyshev.chebvander(y, coef.shape[2] - 1)
    return np.einsum("ij,fjk,ik->fi", ve, coef, vp)
