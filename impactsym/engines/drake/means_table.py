r"""A table of the phase means of discrete designs over a box of the damping number
:math:`s = d v` and the step :math:`w = h \sqrt{k/m}`, and the starts it gives targets
``(e, q)``: the per-call tables of :mod:`~impactsym.engines.drake.step_table` (its
module docstring has the method).

* :func:`wide_box`: the first box, from the continuous designs without gravity;
* :func:`means_table`: the means on equally spaced nodes of a box, and the targets'
  starts (:func:`table_starts`: on each column the contour ``E = e``, along it the
  first sign change of ``Q - q``, linear in between; the table's cell for the Jacobian);
* :func:`reaching`: a wider box where many targets lie beyond a table's means;
* :func:`widened`: the box of the starts found, for the next table;
* :func:`table_at`: a table interpolated bilinearly.

Flat arrays. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.engines.drake.continuous import free_scales

__all__ = [
    "BEYOND",
    "MARGIN",
    "WIDE",
    "Box",
    "means_table",
    "reaching",
    "table_at",
    "table_starts",
    "wide_box",
    "widened",
]

#: A box of designs: ``((s_lo, s_hi), (w_lo, w_hi))``.
Box = tuple[tuple[float, float], tuple[float, float]]
#: The wide box: the continuous designs without gravity, this factor either way.
WIDE = 1.6
#: The box widened by this fraction of its width on each side.
MARGIN = 0.25
#: The share of a group's targets beyond its coarse table's means above which that table
#: is built again on a wider box (:func:`reaching`).
BEYOND = 0.05


def wide_box(
    e: np.ndarray, q: np.ndarray, size_name: str, pressing: float,
    scales: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> Box:  # fmt: skip
    """The box ``((s_lo, s_hi), (w_lo, w_hi))`` of the first table: the continuous designs
    without gravity of the targets ``(e, q)``, :data:`WIDE` times either way, and under
    gravity (``pressing = g h / v``) wider toward less damping and more stiffness by the
    largest pressing number ``g T / v``, ``T = h / w`` (the designs lie there: at
    ``e = 0.45``, 22 steps, ``g = 9.81``, ``s = 1.03`` against ``1.73`` without gravity,
    where no box had a start). ``scales``: :func:`~impactsym.engines.drake.continuous.free_scales`
    of ``e`` where the caller has them."""
    s0, tau0, z0 = free_scales(e) if scales is None else scales
    w0 = (tau0 if size_name == "contact_time" else z0) / q
    s_lo, s_hi, w_lo, w_hi = s0.min() / WIDE, s0.max() * WIDE, w0.min() / WIDE, w0.max() * WIDE
    wider = 1.0 + pressing / w_lo
    return (s_lo / wider, s_hi), (w_lo, w_hi * wider)


def means_table(
    mean_rows: Callable[..., tuple[np.ndarray, ...]], box: Box, nodes: tuple[int, int],
    e: np.ndarray, q: np.ndarray,
) -> tuple[np.ndarray, ...]:  # fmt: skip
    """A table of the phase means on ``nodes`` equally spaced nodes of ``box``, and the
    starts it gives the targets ``(e, q)``: ``(s_nodes, w_nodes, T, s, w, jac, E, Q)``
    with ``T`` the table's contact times in steps and ``E``, ``Q`` its means (``nan``
    starts where it does not hold the target; :func:`table_starts`). The means of one
    member's mass, speed and gravity: they depend on ``(s, w, g / v)`` alone."""
    s_nodes, w_nodes = (np.linspace(*side, count) for side, count in zip(box, nodes, strict=True))
    S, W = np.meshgrid(s_nodes, w_nodes, indexing="ij")
    E, Q, T = (
        a.reshape(S.shape)
        for a in mean_rows(S.ravel(), W.ravel(), np.zeros(S.size, int), steps=True)
    )
    s, w, jac = table_starts(s_nodes, w_nodes, E, Q, e, q)
    return s_nodes, w_nodes, T, s, w, jac, E, Q


def reaching(box: Box, E: np.ndarray, Q: np.ndarray, e: np.ndarray, q: np.ndarray) -> Box | None:
    """The box ``((s_lo, s_hi), (w_lo, w_hi))`` widened where more than :data:`BEYOND` of
    the targets ``(e, q)`` lie beyond the range of its table's means ``E``, ``Q`` (the
    restitution falls with the damping, the size with the step): the damping down to a
    quarter (under gravity the discrete designs of the larger restitutions damp far less
    than the continuous ones: at ``e = 0.79``, 30 steps, ``v = 3`` m/s, ``s = 0.15``
    against ``0.40``) or up to twice, the step down or up by half as much again; ``None``
    where it holds them."""
    (s_lo, s_hi), (w_lo, w_hi) = box
    limit = BEYOND * e.size
    moves = (
        (np.count_nonzero(e > np.nanmax(E)), (0.25 * s_lo, s_hi), (w_lo, w_hi)),
        (np.count_nonzero(e < np.nanmin(E)), (s_lo, 2.0 * s_hi), (w_lo, w_hi)),
        (np.count_nonzero(q > np.nanmax(Q)), (s_lo, s_hi), (w_lo / 1.5, w_hi)),
        (np.count_nonzero(q < np.nanmin(Q)), (s_lo, s_hi), (w_lo, 1.5 * w_hi)),
    )
    wider = [(a, b) for count, a, b in moves if count > limit]
    if not wider:
        return None
    return ((min(a[0] for a, _ in wider), max(a[1] for a, _ in wider)),
            (min(b[0] for _, b in wider), max(b[1] for _, b in wider)))  # fmt: skip


def widened(x: np.ndarray, cell: float) -> tuple[float, float]:
    """``[lo, hi]`` around ``x``, one ``cell`` and :data:`MARGIN` of the width wider on
    each side (and positive)."""
    lo, hi = x.min(), x.max()
    pad = cell + MARGIN * (hi - lo)
    return (max(lo - pad, 0.5 * lo), hi + pad)


def table_at(
    s_nodes: np.ndarray, w_nodes: np.ndarray, F: np.ndarray, s: np.ndarray, w: np.ndarray
) -> np.ndarray:
    """The table ``F`` interpolated bilinearly at ``(s, w)`` (``nan`` where a start is
    not finite or a corner of its cell is not)."""
    i = np.clip(np.searchsorted(s_nodes, s) - 1, 0, s_nodes.size - 2)
    j = np.clip(np.searchsorted(w_nodes, w) - 1, 0, w_nodes.size - 2)
    with np.errstate(invalid="ignore"):
        a = (s - s_nodes[i]) / (s_nodes[1] - s_nodes[0])
        b = (w - w_nodes[j]) / (w_nodes[1] - w_nodes[0])
        return ((1 - a) * (1 - b) * F[i, j] + a * (1 - b) * F[i + 1, j]
                + (1 - a) * b * F[i, j + 1] + a * b * F[i + 1, j + 1])  # fmt: skip


def table_starts(
    s_nodes: np.ndarray, w_nodes: np.ndarray, E: np.ndarray, Q: np.ndarray, e: np.ndarray,
    q: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Starts ``(s, w)`` and Jacobians ``(n, 2, 2)`` of ``(E, Q)`` from the table
    (``nan`` starts where it does not hold the target)."""
    n, nw = e.size, w_nodes.size
    # column by column (one w), for the targets whose start is not yet found: the
    # contour E = e crosses it once (the restitution falls with the damping), and along
    # the contour Q falls with w: the start lies before the first column where Q is
    # below the target
    j = np.zeros(n, np.int64)  # (0: none found)
    ends = np.full((4, n), np.nan)  # s and Q on the contour, the columns before and at j
    live, before = np.arange(n), np.full((2, n), np.nan)
    for col_j in range(nw):
        col = np.where(np.isfinite(E[:, col_j]), E[:, col_j], -np.inf)
        e_l = e[live]
        # the first crossing: on the running minimum, col[i - 1] > e >= col[i]
        i = np.searchsorted(-np.minimum.accumulate(col), -e_l)
        inside = (i > 0) & (i < col.size)
        i = np.clip(i, 1, col.size - 1)
        with np.errstate(all="ignore"):  # (outside the crossing: masked just below)
            t = (col[i - 1] - e_l) / (col[i - 1] - col[i])
            s_c = np.where(inside, s_nodes[i - 1] + t * (s_nodes[i] - s_nodes[i - 1]), np.nan)
            q_c = np.where(inside, Q[i - 1, col_j] + t * (Q[i, col_j] - Q[i - 1, col_j]), np.nan)
        hit = q_c <= q[live]
        rows = live[hit]
        j[rows] = col_j
        ends[:, rows] = before[0, hit], before[1, hit], s_c[hit], q_c[hit]
        live, before = live[~hit], np.stack([s_c[~hit], q_c[~hit]])
        if live.size == 0:
            break
    s_a, q_a, s_b, q_b = ends
    found = (j > 0) & np.isfinite(q_a) & np.isfinite(q_b)
    j = np.clip(j, 1, nw - 1)
    with np.errstate(all="ignore"):
        t = (q_a - q) / (q_a - q_b)
    t = np.where(np.isfinite(t), t, 0.5)
    w = w_nodes[j - 1] + t * (w_nodes[j] - w_nodes[j - 1])
    s = s_a + t * (s_b - s_a)
    # the Jacobian from the table's cell at the start
    i = np.clip(np.searchsorted(s_nodes, s) - 1, 0, s_nodes.size - 2)
    jw = j - 1
    ds, dw = s_nodes[1] - s_nodes[0], w_nodes[1] - w_nodes[0]
    jac = np.empty((n, 2, 2))
    with np.errstate(invalid="ignore"):  # a sticking node: inf, the start is not there
        for f, F in enumerate((E, Q)):
            jac[:, f, 0] = 0.5 * (F[i + 1, jw] - F[i, jw] + F[i + 1, jw + 1] - F[i, jw + 1]) / ds
            jac[:, f, 1] = 0.5 * (F[i, jw + 1] - F[i, jw] + F[i + 1, jw + 1] - F[i + 1, jw]) / dw
    s, w = np.where(found, s, np.nan), np.where(found, w, np.nan)
    return s, w, jac
