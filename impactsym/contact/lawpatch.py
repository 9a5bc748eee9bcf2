r"""Tables of functions of two variables: tensor Chebyshev patches on a binary tree.

With a pressing force the normalized impact of a contact law is a function of two
numbers, its damping number and its pressing number (:mod:`impactsym.contact.laws`).
:func:`build` tabulates such a function once, from its exact values, as Chebyshev
interpolants on rectangular patches, and :class:`PatchTable` evaluates it on whole
arrays; the tables of one variable are :mod:`impactsym.contact.lawtable`
(``docs/nonlinear_contact.md``, "Tables with a pressing force").

Why this numerics
-----------------
* **Tensor Chebyshev interpolation.** On a patch :math:`[a_0, a_1] \times [b_0, b_1]`
  the function is sampled at the :math:`n \times n` products of the Chebyshev points of
  the first kind (never on the edges, where the exact function may be singular) and
  written as :math:`\sum_{ij} c_{ij} T_i(x) T_j(y)`, the coefficients being the
  one-variable transform (:func:`~impactsym.contact.lawtable.chebyshev_transform`)
  applied along each axis. For a function analytic around the patch they fall
  geometrically along both axes.
* **Adaptive bisection, one axis at a time.** A patch is accepted when the last
  :data:`~impactsym.contact.lawtable.TAIL_TERMS` coefficients along each axis are below
  ``tail`` times the largest value plus ``floor``; otherwise it is halved along the axis
  whose tail is worse relative to its threshold (the other axis if that one is already at
  its narrowest). So patches shrink towards kinks only across them, a binary tree of
  halvings records where, and a patch still unresolved at ``min_width`` (or holding a
  value above ``cap``, or a non-finite one) is left out: the caller evaluates the exact
  function there. ``skip`` names patches nobody will ask for: they are never evaluated.
* **One exact call per level.** All nodes of all patches of one level go to the exact
  function in one call (vectorized).
* **Evaluation on whole arrays.** Each element finds its patch by descending the tree
  (one array operation per level), the Chebyshev polynomials of its two local
  coordinates come from their recurrence on all elements at once, and the elements are
  grouped by patch (one sort) so that each patch's coefficients multiply its elements in
  one matrix product: a loop over patches, never over elements, and no copy of the
  :math:`n^2` coefficients per element.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from impactsym.contact.lawtable import TAIL_TERMS, chebyshev_points, chebyshev_transform

#: Chebyshev points per axis of a patch.
NODES = 20
#: Most patches a table may have before the build stops halving (the rest left out).
MAX_PATCHES = 3000


@dataclass(frozen=True, eq=False)
class PatchTable:
    r"""A piecewise tensor Chebyshev interpolant of ``k`` quantities on a rectangle.

    Attributes
    ----------
    lo, hi : ndarray, shape (2,)
        Corners of the rectangle.
    axis, mid, child : ndarray
        The tree: node ``i`` is halved along ``axis[i]`` at ``mid[i]`` into the nodes
        ``child[i, 0]`` (below) and ``child[i, 1]``; a leaf has ``axis = -1`` and holds
        patch ``child[i, 0]``. Node 0 is the rectangle.
    boxes : ndarray, shape (m, 4)
        The patches ``(a0, a1, b0, b1)``.
    coefficients : ndarray, shape (m, k, n, n)
        ``coefficients[p, q, i, j]``: the coefficient of :math:`T_i(x) T_j(y)` of quantity
        ``q`` on patch ``p`` (``nan`` where not covered).
    covered : ndarray of bool, shape (m,)
        Whether the patch converged.
    """

    lo: np.ndarray
    hi: np.ndarray
    axis: np.ndarray
    mid: np.ndarray
    child: np.ndarray
    boxes: np.ndarray
    coefficients: np.ndarray
    covered: np.ndarray

    @property
    def patches(self) -> int:
        """The number of patches."""
        return self.covered.size

    def locate(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The patch of each point of the flat arrays ``(u, v)`` and whether it is covered."""
        node = np.zeros(u.size, dtype=np.intp)
        for _ in range(self.axis.size):
            axis = self.axis[node]
            split = np.flatnonzero(axis >= 0)
            if split.size == 0:
                break
            n = node[split]
            coordinate = np.where(axis[split] == 0, u[split], v[split])
            node[split] = self.child[n, (coordinate >= self.mid[n]).astype(np.intp)]
        patch = self.child[node, 0]
        inside = (u >= self.lo[0]) & (u <= self.hi[0]) & (v >= self.lo[1]) & (v <= self.hi[1])
        return patch, inside & self.covered[patch]

    def __call__(
        self, u: np.ndarray, v: np.ndarray, rows: tuple[int, ...] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Values of the quantities ``rows`` (default all) at the flat arrays ``(u, v)``,
        shape ``(len(rows), u.size)``, and where the table covers the point (``nan``
        elsewhere).

        >>> t = build(lambda u, v: np.stack((np.exp(u) * np.cos(v),)), (0.0, 0.0), (1.0, 1.0),
        ...           min_width=(0.1, 0.1))
        >>> values, inside = t(np.array([0.3, 2.0]), np.array([0.6, 0.5]))
        >>> bool(abs(values[0, 0] - np.exp(0.3) * np.cos(0.6)) < 1e-14), inside.tolist()
        (True, [True, False])
        """
        u, v = np.asarray(u, dtype=float).ravel(), np.asarray(v, dtype=float).ravel()
        C = self.coefficients if rows is None else self.coefficients[:, list(rows)]
        values = np.full((C.shape[1], u.size), np.nan)
        patch, inside = self.locate(u, v)
        idx = np.flatnonzero(inside)
        if idx.size == 0:
            return values, inside
        p = patch[idx]
        box = self.boxes[p]
        x = (2.0 * u[idx] - (box[:, 0] + box[:, 1])) / (box[:, 1] - box[:, 0])
        y = (2.0 * v[idx] - (box[:, 2] + box[:, 3])) / (box[:, 3] - box[:, 2])
        Tx, Ty = _chebyshev_values(x, C.shape[2]), _chebyshev_values(y, C.shape[3])
        order = np.argsort(p, kind="stable")
        starts = np.flatnonzero(np.diff(p[order], prepend=-1))
        ends = np.append(starts[1:], order.size)
        out = np.empty((C.shape[1], idx.size))
        for s, e in zip(starts, ends, strict=True):  # one matrix product per patch
            sel = order[s:e]
            out[:, sel] = np.einsum("qij,in,jn->qn", C[p[sel[0]]], Tx[:, sel], Ty[:, sel])
        values[:, idx] = out
        return values, inside


def _chebyshev_values(x: np.ndarray, n: int) -> np.ndarray:
    """:math:`T_j(x)` for ``j < n``, shape ``(n, x.size)`` (three-term recurrence)."""
    T = np.empty((n, x.size))
    T[0] = 1.0
    if n > 1:
        T[1] = x
    for j in range(2, n):
        T[j] = 2.0 * x * T[j - 1] - T[j - 2]
    return T


def build(
    fn: Callable[[np.ndarray, np.ndarray], np.ndarray],
    lo: tuple[float, float],
    hi: tuple[float, float],
    *,
    min_width: tuple[float, float],
    nodes: int = NODES,
    tail: float = 1e-12,
    floor: float = 1e-14,
    cap: float = np.inf,
    skip: Callable[[np.ndarray], np.ndarray] | None = None,
    roots: np.ndarray | None = None,
    max_patches: int = MAX_PATCHES,
) -> PatchTable:
    r"""Tabulate ``fn`` on the rectangle ``lo``-``hi`` by adaptive bisection (module
    docstring).

    Parameters
    ----------
    fn : callable
        ``fn(u, v)`` of flat arrays returns the quantities, shape ``(k, u.size)``.
    lo, hi : pair of float
        Corners of the rectangle.
    min_width : pair of float
        Patches are not halved below these widths; an unresolved one is left out.
    nodes, tail, floor, cap
        Chebyshev points per axis; the acceptance threshold of the last coefficients
        (relative to the quantity's largest value on the patch, plus ``floor``); values
        above ``cap`` leave the patch out without halving.
    skip : callable, optional
        ``skip(boxes)`` of patches ``(m, 4)`` returns which are needed by nobody: they are
        left out without evaluation.
    roots : ndarray, optional
        Break points in ``u`` inside ``(lo[0], hi[0])`` where the patches must break
        (e.g. the pieces of a table the function depends on): the rectangle is first
        halved there, as a tree of its own.
    max_patches : int
        Most patches: beyond, unresolved patches are left out instead of halved.

    Returns
    -------
    PatchTable

    Examples
    --------
    :math:`|u - v|` has a kink on the diagonal: the patches shrink towards it and a thin
    band is left out; elsewhere the table is exact to rounding:

    >>> t = build(lambda u, v: np.abs(u - v)[None] + 1.0, (0.0, 0.0), (1.0, 1.0),
    ...           min_width=(1e-3, 1e-3))
    >>> values, inside = t(np.array([0.2, 0.5]), np.array([0.7, 0.5 + 1e-5]))
    >>> inside.tolist(), bool(abs(values[0, 0] - 1.5) < 1e-13)
    ([True, False], True)
    """
    lo, hi, min_width = (np.asarray(a, dtype=float) for a in (lo, hi, min_width))
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)):
        raise ValueError(f"the table needs a finite rectangle lo < hi, got {lo!r}, {hi!r}")
    if not np.all(min_width > 0):
        raise ValueError(f"min_width must be positive, got {min_width!r}")
    x = chebyshev_points(nodes)
    M = chebyshev_transform(nodes)
    axis: list[int] = []
    mid: list[float] = []
    child: list[list[int]] = []
    boxes: list[np.ndarray] = []
    coefficients: list[np.ndarray] = []
    covered: list[bool] = []

    def new_node() -> int:
        axis.append(-1)
        mid.append(np.nan)
        child.append([-1, -1])
        return len(axis) - 1

    def split(node: int, box: np.ndarray, along: int, at: float) -> list[tuple[int, np.ndarray]]:
        below, above = box.copy(), box.copy()
        below[2 * along + 1] = above[2 * along] = at
        axis[node], mid[node] = along, at
        child[node] = [new_node(), new_node()]
        return [(child[node][0], below), (child[node][1], above)]

    def leaf(node: int, box: np.ndarray, coeffs: np.ndarray | None) -> None:
        child[node] = [len(boxes), -1]
        boxes.append(box)
        coefficients.append(coeffs)  # None: left out (filled with nan below)
        covered.append(coeffs is not None)

    pending = [(new_node(), np.array([lo[0], hi[0], lo[1], hi[1]]))]
    for at in np.sort(np.asarray([] if roots is None else roots, dtype=float)):
        if not lo[0] < at < hi[0]:
            continue
        i = next(j for j, (_, b) in enumerate(pending) if b[0] < at < b[1])
        node, box = pending.pop(i)
        pending[i:i] = split(node, box, 0, at)
    k = 1
    while pending:
        box = np.array([b for _, b in pending])
        keep = np.ones(len(pending), dtype=bool) if skip is None else ~np.asarray(skip(box))
        for i in np.flatnonzero(~keep):
            leaf(pending[i][0], box[i], None)
        use = np.flatnonzero(keep)
        if use.size == 0:
            break
        b = box[use]
        U = 0.5 * (b[:, 0] + b[:, 1])[:, None] + 0.5 * (b[:, 1] - b[:, 0])[:, None] * x
        V = 0.5 * (b[:, 2] + b[:, 3])[:, None] + 0.5 * (b[:, 3] - b[:, 2])[:, None] * x
        u = np.broadcast_to(U[:, :, None], (use.size, nodes, nodes)).ravel()
        v = np.broadcast_to(V[:, None, :], (use.size, nodes, nodes)).ravel()
        values = np.asarray(fn(u, v), dtype=float)
        k = values.shape[0]
        values = values.reshape(k, use.size, nodes, nodes)
        finite = np.all(np.isfinite(values), axis=(0, 2, 3))
        safe = np.where(np.isfinite(values), values, 0.0)
        coeffs = np.einsum("ai,kpij,bj->kpab", M, safe, M)
        scale = np.max(np.abs(safe), axis=(2, 3))  # (k, P)
        limit = tail * scale + floor
        tail_u = np.max(np.abs(coeffs[:, :, -TAIL_TERMS:, :]), axis=(2, 3)) / limit
        tail_v = np.max(np.abs(coeffs[:, :, :, -TAIL_TERMS:]), axis=(2, 3)) / limit
        worse_u, worse_v = tail_u.max(axis=0), tail_v.max(axis=0)
        large = np.any(scale > cap, axis=0)
        ok = finite & (worse_u <= 1.0) & (worse_v <= 1.0) & ~large
        next_pending = []
        for j, i in enumerate(use):
            node, bx = pending[i]
            if ok[j]:
                leaf(node, bx, coeffs[:, j])
                continue
            fits = [(bx[2 * a + 1] - bx[2 * a]) * 0.5 >= min_width[a] for a in (0, 1)]
            fails = [not finite[j] or worse_u[j] > 1.0, not finite[j] or worse_v[j] > 1.0]
            ranked = (0, 1) if (worse_u[j] >= worse_v[j] or not finite[j]) else (1, 0)
            along = next((a for a in ranked if fails[a] and fits[a]), None)
            if large[j] or along is None or len(boxes) + len(next_pending) >= max_patches:
                leaf(node, bx, None)
                continue
            next_pending += split(node, bx, along, 0.5 * (bx[2 * along] + bx[2 * along + 1]))
        pending = next_pending
    return PatchTable(
        lo=lo,
        hi=hi,
        axis=np.array(axis, dtype=np.intp),
        mid=np.array(mid),
        child=np.array(child, dtype=np.intp),
        boxes=np.array(boxes),
        coefficients=np.array(
            [np.full((k, nodes, nodes), np.nan) if c is None else c for c in coefficients]
        ),
        covered=np.array(covered, dtype=bool),
    )
