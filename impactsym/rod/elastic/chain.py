"""All cells of a reflection interval at once, each starting where the one before ends.

Internal, for the float64 tables of :mod:`impactsym.rod.elastic.taylor` and
:mod:`impactsym.rod.elastic.manifold`: a cell's polynomials are affine in its start, so
the starts of all cells follow from the interval's start by a scan over the cells' maps
(:func:`affine_scan`, by doubling), the polynomials of all cells from those starts are
one NumPy operation per order, and what each start misses of the exact end of the cell
before is kept, exactly to ``u^2``, as low parts of every coefficient
(:func:`cell_chain`). Also the sums along the coefficients by pairwise two-sums
(:func:`tree_sum_with_bound`). See docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.eft import UNIT_ROUNDOFF as _U
from impactsym.numeric.eft import gamma, two_sum


def scan_stages(A: np.ndarray) -> tuple[list, np.ndarray]:
    """Internal: the maps of :func:`affine_scan` for ``A`` (``[..., n, k, k]``), computed
    once where many scans share them: per doubling step ``d`` the composed maps before
    it, and the composition of each prefix. Elementwise products and sums written out (no
    matrix product, whose rounding may depend on the shape): each entry is the same to the
    last bit whatever the leading axes hold."""
    A, stages, d = A.copy(), [], 1
    while d < A.shape[-3]:
        stages.append(A)
        A = A.copy()
        A[..., d:, :, :] = np.stack(
            [
                _apply(stages[-1][..., d:, :, :], stages[-1][..., :-d, :, j])
                for j in range(A.shape[-1])
            ],
            axis=-1,
        )
        d *= 2
    return stages, A


def stacked_stages(own: list, width: int) -> tuple[list, np.ndarray]:
    """Internal: :func:`scan_stages` of the chains of several tables (``own``: each
    table's, of its cells but the last) for their batch: stacked, padded to ``width``
    maps, for both right-hand sides (``[r J + j, position, 3, 3]``). A map at position
    ``i`` is composed of the maps up to ``i`` only, so each chain's are its own; a
    chain's stages past its own count leave its positions as its last one did."""
    depth = max(len(stages) for stages, _ in own)
    J = len(own)

    def stack(pick):
        out = np.broadcast_to(np.eye(3), (J, width, 3, 3)).copy()
        for j, stages in enumerate(own):
            x = pick(stages)
            out[j, : x.shape[0]] = x
        return np.concatenate([out, out])  # [rhs J + j, position, 3, 3]

    maps = [stack(lambda st, s=s: st[0][s] if s < len(st[0]) else st[1]) for s in range(depth)]
    return maps, stack(lambda st: st[1])


def affine_scan(stages: tuple, c: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """Internal: ``x_1, ..., x_n`` of ``x_(i+1) = A_i x_i + c_i`` (``c: [..., n, k]``, ``x0:
    [..., k]``, ``stages = scan_stages(A)``), by doubling (Hillis and Steele): ``log2 n``
    NumPy steps instead of ``n``, rounding at the level of a sequential loop, and the
    same bits whatever the leading axes hold."""
    maps, A = stages
    c, d = c.copy(), 1
    for before in maps:
        c[..., d:, :] = _apply(before[..., d:, :, :], c[..., :-d, :]) + c[..., d:, :]
        d *= 2
    return _apply(A, x0[..., None, :]) + c


def _apply(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A x`` over the last axes (``A: [..., k, k]``, ``x: [..., k]``): products, then the
    sum of each row of ``k`` (the same additions whatever the leading axes)."""
    return (A * x[..., None, :]).sum(axis=-1)


def _column_sums(C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(s, e)`` per row of ``C`` (``[..., order]``): the value of a polynomial in ``xi``
    at ``xi = 1`` as a high part and the sum of the two-sums' errors
    (:func:`tree_sum_with_bound`), ``s + e`` within ``u^2``-level of the exact sum."""
    return _tree_sum(C, size=False)[:2]


def _tree_sum(C: np.ndarray, size: bool = True) -> tuple:
    """Pairwise two-sums along the last axis: ``(s, e, size, levels)`` with ``s + e_exact
    = sum C`` exactly, ``e`` the float sum of the two-sums' errors (each level's errors
    summed along with the pairs), ``size = sum |C|`` (or ``None``)."""
    s, e, levels = C, np.zeros(C.shape[:-1]), 0
    size = np.abs(C).sum(axis=-1) if size else None
    while s.shape[-1] > 1:
        if s.shape[-1] % 2:  # an odd one out waits for the next level
            s = np.concatenate([s, np.zeros_like(s[..., :1])], axis=-1)
        s, err = two_sum(s[..., 0::2], s[..., 1::2])
        e = e + err.sum(axis=-1)
        levels += 1
    return s[..., 0], e, size, levels


def tree_sum_with_bound(C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Internal: ``(total, bound)``: the sum of ``C`` along its last axis by pairwise
    two-sums (``log2 n`` NumPy steps, not ``n``), and a bound on ``|total - exact|``.
    Every two-sum is exact, ``|err| <= u |s|`` of its pair, and the pairs of a level
    partition the terms, so the errors sum to at most ``levels u sum |C|`` in absolute
    value; adding them up in float (``<= n`` of them, any order) errs by at most
    ``gamma_n`` of that, and the last addition by ``u |total|``."""
    s, e, size, levels = _tree_sum(C)
    n = C.shape[-1]
    total = s + e
    bound = (_U * np.abs(total) + gamma(n) * levels * _U * size) * (1.0 + 1e-9)
    return total, bound


def cell_chain(coefficients, responses, stages, c, state, last=None):
    """Internal: the cells of one reflection interval, all at once, each starting where the
    one before ends, up to ``u^2``: ``((Y, V, N), (Y_lo, V_lo, N_lo), state)``.

    The cells are affine in their start ``x = (y, v, N)``: a cell from ``x`` ends at
    ``A_i x + c_i`` (``A: [rhs, cell, end, start]``, ``c: [rhs, cell, end]``, in float:
    only to find starts; ``stages = scan_stages(A[:, :-1])``, shared by every interval),
    and ``coefficients(starts)`` (``starts: [rhs, cell, 3]``) gives
    its polynomials ``(Y, V, N)`` (``[rhs, cell, order]``) from a float start, in the
    cells' own arithmetic, and their own low parts (an array like each, or ``None``);
    ``responses = (E_y, E_v, E_n)``, the polynomials of unit starts (``[start, order]``,
    one set, or ``[rhs, cell, start, order]``, one per cell). The first axis may hold
    several chains (right-hand sides, tables); ``last`` the index of each one's last cell
    (default: the last; the cells after it are padding, ignored).

    1. the float starts of every cell from ``state = (high, low)`` (``[rhs, 3]``, the
       start of the interval) by :func:`affine_scan`; the polynomials from them;
    2. what each cell misses of the exact end of the one before, ``l``, is the low part
       of its start: ``l_(i+1) = (end_i - start_(i+1)) + A_i l_i`` (the ends of the
       stored polynomials to ``u^2``, :func:`_column_sums`), and its polynomials' low
       parts are ``l`` times the unit responses (float: ``l`` is a few ulps, so their
       rounding is ``u^2``): the stored ``C + C_lo`` starts at the exact end before;
    3. ``state`` the exact end of the last cell.

    Unlike a cell-by-cell loop with double-double starts the polynomials are the
    recurrence of a start a few ulps off, completed by the low parts (the bound measures
    both, :func:`cell_bounds`); a NumPy operation on all cells of the interval replaces
    one per cell."""
    high, low = state
    starts = np.concatenate([high[:, None], affine_scan(stages, c[:, :-1], high + low)], 1)
    starts[:, 0] = high
    polys, own = coefficients(starts)
    sums = [
        _column_sums(C if C_lo is None else np.concatenate([C, C_lo], axis=-1))
        for C, C_lo in zip(polys, own, strict=True)
    ]
    s_end = np.stack([s for s, _ in sums], axis=-1)  # [rhs, cell, end]
    e_end = np.stack([e for _, e in sums], axis=-1)
    # what the next start misses of this end: exact difference of near values, then
    # the end's error term (a few ulps of the state: its rounding is u^2)
    missed = (s_end[:, :-1] - starts[:, 1:]) + e_end[:, :-1]
    lows = np.concatenate([low[:, None], affine_scan(stages, missed, low)], axis=1)
    added = tuple(
        (lows[..., 0, None] * E[..., 0, :] + lows[..., 1, None] * E[..., 1, :])
        + lows[..., 2, None] * E[..., 2, :]
        for E in responses
    )
    # the exact end of the last cell, as (high, low)
    if last is None:
        last = np.full(high.shape[0], s_end.shape[1] - 1)
    chain = np.arange(high.shape[0])
    rest = e_end[chain, last] + np.stack([P[chain, last].sum(axis=-1) for P in added], axis=-1)
    end_high, end_low = two_sum(s_end[chain, last], rest)
    # the low parts of the wide layer cells can be many ulps (their ends cancel): each
    # coefficient's high part takes them, exactly (two-sum), the low part keeps <= u/2 of it
    stored = [
        two_sum(C, P if C_lo is None else C_lo + P)
        for C, P, C_lo in zip(polys, added, own, strict=True)
    ]
    return tuple(hi for hi, _ in stored), tuple(lo for _, lo in stored), (end_high, end_low)
