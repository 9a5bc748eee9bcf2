r"""The slow cells of :mod:`impactsym.rod.elastic.manifold`: polynomials on the slow manifold.

On a wide cell of width :math:`h` (coefficients in :math:`\xi = (t - lo)/h`, degree
``DEGREE``) of a stiff spring, :math:`N = (1 + \kappa^{-1} d/dt)^{-1} (v + 2G) = S (v +
2G)` (finite on polynomials), and :math:`v` solves :math:`\alpha v' = f - N` from its
start: a linear solve, then one Gauss-Seidel sweep; :math:`N` in double-double by the
compensated back recurrence :math:`N_k = v_k + 2G_k - (k+1) N_{k+1}/(h\kappa)`. All
cells at once (NumPy operations over the cells, a product per cell: the same bits
whatever the number of cells). Internal, for the table of
:mod:`impactsym.rod.elastic.manifold`, whose a-posteriori bound accepts the cells; see
docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.eft import two_sum
from impactsym.rod.elastic.taylor import DEGREE


def slow_operator(alpha: float, width: float, *, kappa: float):
    """Internal: ``S`` (``N = S (v + 2G)`` on coefficients in ``xi``, degree ``DEGREE``) and the
    inverse of the matrix of ``alpha v' + N = f`` in ``v_1, ..., v_D`` (``v_0`` given)."""
    D = DEGREE
    eps = 1.0 / (width * kappa)
    # S[j, i] = prod_{l = j+1 .. i} (-eps l): running products along each row (above
    # the diagonal; ones on and below it multiply exactly), the same products in order
    order = np.arange(D + 1)
    factors = np.where(order[None, :] > order[:, None], -eps * order[None, :], 1.0)
    S = np.triu(np.cumprod(factors, axis=1))
    M = S[:D, 1:].copy()
    M[np.arange(D), np.arange(D)] += alpha * np.arange(1, D + 1) / width
    return S, np.linalg.inv(M)


def manifold_forces(V, V0_lo, G_hi, G_lo, widths, *, kappa):
    """Internal: ``N = S (v + 2G)`` of slow cells in double-double by the back recurrence
    ``N_k = v_k + 2 G_k - (k + 1) N_{k+1} / (h kappa)`` (``v`` from ``V`` and the low parts
    ``V0_lo`` of its constant coefficients, ``G = G_hi + G_lo``; ``[cell, order]``, one
    width per cell): ``(N_high, N_low)``, each step a compensated sum."""
    D = DEGREE
    # order first (contiguous per order: the loop runs over the orders)
    V, G_hi, G_lo = (np.ascontiguousarray(np.moveaxis(x, -1, 0)) for x in (V, G_hi, G_lo))
    n_high, n_low = np.zeros_like(V), np.zeros_like(V)
    nh, nl = np.zeros(V.shape[1:]), np.zeros(V.shape[1:])
    for k in range(D, -1, -1):
        t = ((k + 1) / widths * (nh + nl)) / kappa
        s1, e1 = two_sum(V[k], 2.0 * G_hi[k])
        s2, e2 = two_sum(s1, -t)
        low = (e1 + e2) + (2.0 * G_lo[k] + (V0_lo if k == 0 else 0.0))
        nh = s2 + low
        nl = low - (nh - s2)
        n_high[k], n_low[k] = nh, nl
    return np.moveaxis(n_high, 0, -1), np.moveaxis(n_low, 0, -1)


def _matvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``M_c x_c`` per cell ``c`` (a matrix product per cell: the same bits whatever the
    number of cells)."""
    return (M @ x[..., None])[..., 0]


def slow_cells(y0, v0, force, G_hi, G_lo, widths, operators, factors, *, kappa):
    """Internal: ``(Y, V)`` of slow cells (``[..., cell, order]``, one width per cell)
    from their starts ``y0, v0`` (float) and incoming waves ``G_hi + G_lo``: the linear
    solve, then one Gauss-Seidel sweep (``N_k`` from the new ``v_k`` and the solve's
    ``N_{k+1}``, in double-double, then ``v_{k+1} = h (f delta_{k0} - N_k)/(alpha
    (k+1))``), all cells at once; ``operators = (S, inverse)`` and ``factors = (c_v,
    c_y)`` per cell."""
    D = DEGREE
    S, inverse = operators
    c_v, c_y = factors
    twice_g = 2.0 * (G_hi + G_lo)
    rhs = -_matvec(S, twice_g)[..., :D]
    rhs[..., 0] += force - v0
    V = np.empty_like(G_hi)
    V[..., 0] = v0
    V[..., 1:] = _matvec(inverse, rhs)
    old = _matvec(S, V + twice_g)
    # the sweep order by order, on order-first copies (contiguous per order)
    gh, gl, old, V = (
        np.ascontiguousarray(np.moveaxis(x, -1, 0)) for x in (2.0 * G_hi, 2.0 * G_lo, old, V)
    )
    c_v = np.ascontiguousarray(c_v.T)
    fk = force
    for k in range(D):
        t = ((k + 1) / widths * old[k + 1]) / kappa
        s1, e1 = two_sum(V[k], gh[k])
        s2, e2 = two_sum(s1, -t)
        low = (e1 + e2) + gl[k]
        nh = s2 + low
        V[k + 1] = c_v[k] * ((fk - nh) - (low - (nh - s2)))
        fk = 0.0
    V = np.moveaxis(V, 0, -1)
    Y = np.empty((*V.shape[:-1], D + 2))
    Y[..., 0] = y0
    Y[..., 1:] = c_y * V
    return Y, V
