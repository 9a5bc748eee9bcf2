r"""Drake's discrete contact over the touch phase: its mean and its range.

The restitution and contact time of :func:`~impactsym.engines.drake.stepping.step_contact`
are smooth in the touch phase between the phases where the end state changes (or the
stick verdict does). As in :mod:`impactsym.engines.mujoco.discrete`, the summary samples
a grid of phases, locates each change of the end state between grid points to ``2^-42``
of a phase (multisection: 63 phases per call, 7 calls, up to ~500 brackets; 3 phases,
21 calls, for more: the work, not the calls, costs there), integrates each smooth piece by
5-point Gauss–Legendre (the
restitution is an algebraic, smooth function of the phase there: the error is far below
the engine's own solver tolerance) and bounds it by the piece ends (the one-sided limits
at the jumps), the nodes, and a zoom search (33 phases per call) where an interior node is extreme.
All designs and pieces are evaluated together on whole arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.drake.stepping import step_contact
from impactsym.engines.phase_pieces import integrate_pieces, reduce_at
from impactsym.records import ArrayRecord

__all__ = ["PhaseSummary", "phase_summary"]

_GRID = 8
_SPLIT = 64  # multisection: 6 bits of the jump phase per call (2^-42: 7 calls)
_BATCH = 32_000  # contacts per call above which the searches take fewer phases per call
_ZOOM = 33  # phases per zoom round of an interior extreme
_NODES = 5  # Gauss-Legendre nodes per piece


@dataclass(frozen=True, eq=False)
class PhaseSummary(ArrayRecord):
    """The contact over the touch phase (uniform in ``[0, 1)``), arrays, SI.

    Attributes
    ----------
    restitution, contact_time
        Means over the phase (``contact_time`` is ``inf`` where some phases stick).
    restitution_min, restitution_max, contact_time_min, contact_time_max
        Bounds over every phase.
    max_penetration
        Largest penetration over every phase (sampled at the grid and nodes).
    stick_fraction
        Fraction of the phases at which the body sticks.
    """

    restitution: np.ndarray
    contact_time: np.ndarray
    restitution_min: np.ndarray
    restitution_max: np.ndarray
    contact_time_min: np.ndarray
    contact_time_max: np.ndarray
    max_penetration: np.ndarray
    stick_fraction: np.ndarray


def phase_summary(
    k: Any, d: Any, tau: Any, m: Any, g: Any, v: Any, h: Any, *, approximation: str,
    bounds: bool = True, stuck_peaks: bool = True,
) -> PhaseSummary:  # fmt: skip
    """Mean over the touch phase and bounds over every phase (module docstring).

    Arguments as in :func:`~impactsym.engines.drake.stepping.step_contact`, without the
    phase; they broadcast. ``bounds=False`` skips the golden-section search of the
    restitution range (then bounded by the sampled phases only), for designs that need
    only the means; ``stuck_peaks=False`` lets the penetration of sticking phases stop
    at the stick verdict (:func:`~impactsym.engines.drake.stepping.step_contact`), for
    designs that do not read it.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, tau, m, g, v, h)))
    shape = arrays[0].shape
    flat = [a.ravel() for a in arrays]
    size = flat[0].size
    dt = flat[-1]

    def run(i, p):
        return step_contact(*(a[i] for a in flat), p, approximation=approximation,
                            stuck_peaks=stuck_peaks)  # fmt: skip

    def key(res, p, i):
        with np.errstate(invalid="ignore", over="ignore"):
            index = np.rint(res.contact_time / dt[i] - p)
        return np.where(res.sticks, -1, index)

    grid = np.linspace(0.0, 1.0, _GRID + 1)
    grid[-1] = 1.0 - 1e-15  # phases lie in [0, 1)
    lo = np.tile(grid[:-1], (size, 1))
    hi = np.tile(grid[1:], (size, 1))
    i_all = np.repeat(np.arange(size), _GRID)
    i_grid = np.repeat(np.arange(size), _GRID + 1)
    at = np.tile(grid, size)
    keys = key(run(i_grid, at), at, i_grid).reshape(size, _GRID + 1)
    key_lo, key_hi = keys[:, :-1], keys[:, 1:]
    jump = key_lo != key_hi
    ii, kk = np.nonzero(jump)
    a, c = lo[ii, kk].copy(), hi[ii, kk].copy()
    left = key_lo[ii, kk]
    # multisection: split - 1 phases per bracket and call, keep the first change; many
    # small calls cost Python overhead, few large ones cost work: 64 up to ~500 brackets,
    # 4 for more (measured: 1000 designs 0.5 s against 1.7 s with 64)
    split = _SPLIT if ii.size * _SPLIT <= _BATCH else 4
    frac = np.arange(1, split) / split
    for _ in range(int(np.ceil(42 / np.log2(split)))):
        if ii.size == 0:
            break
        pts = a[:, None] + (c - a)[:, None] * frac[None, :]
        rows = np.repeat(ii, frac.size)
        same = key(run(rows, pts.ravel()), pts.ravel(), rows) == np.repeat(left, frac.size)
        same = same.reshape(pts.shape)
        j = np.where(same.all(axis=1), frac.size, np.argmin(same, axis=1))
        grid_pts = np.concatenate([a[:, None], pts, c[:, None]], axis=1)
        a, c = grid_pts[np.arange(ii.size), j], grid_pts[np.arange(ii.size), j + 1]
    ends = np.where(jump, np.nan, hi)
    ends[ii, kk] = a
    p0 = np.concatenate([lo.ravel(), c])
    p1 = np.concatenate([ends.ravel(), hi[ii, kk]])
    own = np.concatenate([i_all, ii])
    pieces = integrate_pieces(run, p0, p1, own, size, nodes=_NODES)
    pts, res, e, t = pieces.pts, pieces.result, pieces.restitution, pieces.contact_time
    e_mean, t_mean, stick_frac = (
        pieces.restitution_mean, pieces.contact_time_mean, pieces.stick_fraction
    )  # fmt: skip
    e_lo, e_hi = e.min(axis=1), e.max(axis=1)
    if bounds:
        e_lo = np.fmin(e_lo, _interior_extreme(run, own, pts, e, -1.0))
        e_hi = np.fmax(e_hi, _interior_extreme(run, own, pts, e, 1.0))
    pen = res.max_penetration.reshape(pts.shape).max(axis=1)
    fields = (
        e_mean,
        t_mean,
        reduce_at(np.minimum, own, e_lo, size, np.inf),
        reduce_at(np.maximum, own, e_hi, size, -np.inf),
        reduce_at(np.minimum, own, t.min(axis=1), size, np.inf),
        reduce_at(np.maximum, own, t.max(axis=1), size, -np.inf),
        reduce_at(np.maximum, own, pen, size, 0.0),
        stick_frac,
    )
    return PhaseSummary(*(np.reshape(f, shape) for f in fields))


def _interior_extreme(run, own, pts, e, sign):
    """Largest (``sign = 1``) or smallest (``-1``) restitution inside each piece where an
    interior node holds the extreme sample; ``nan`` elsewhere. Zoom search: sample
    ``_ZOOM`` phases (9 for large batches) between the extreme's neighbours, keep the
    best and its neighbours, until the bracket is ``1e-9`` of a piece (the error of a
    smooth extreme is quadratic in that)."""
    j = np.argmax(sign * e, axis=1)
    inner = np.flatnonzero((j > 0) & (j < pts.shape[1] - 1))
    out = np.full(e.shape[0], np.nan)
    if inner.size == 0:
        return out
    a, c = pts[inner, j[inner] - 1], pts[inner, j[inner] + 1]
    points = _ZOOM if inner.size * _ZOOM <= _BATCH else 9
    owner = np.repeat(own[inner], points)
    best = sign * e[inner, j[inner]]
    frac = np.linspace(0.0, 1.0, points)
    rows = np.arange(inner.size)
    # the bracket shrinks (points - 1)/2-fold per round: to ~1e-9 of a piece
    for _ in range(int(np.ceil(9.0 / np.log10((points - 1) / 2.0)))):
        x = a[:, None] + (c - a)[:, None] * frac[None, :]
        f = (sign * run(owner, x.ravel()).restitution).reshape(x.shape)
        b = np.argmax(f, axis=1)
        best = np.fmax(best, f[rows, b])
        a = x[rows, np.maximum(b - 1, 0)]
        c = x[rows, np.minimum(b + 1, points - 1)]
    out[inner] = sign * best
    return out
