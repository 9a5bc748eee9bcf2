r"""Drake's discrete contact over the touch phase: its mean and its range.

The restitution and contact time of :func:`~impactsym.engines.drake.stepping.step_contact`
are smooth in the touch phase between the phases where the end state changes (or the
stick verdict does). As in :mod:`impactsym.engines.mujoco.discrete`, the summary samples
a grid of phases, locates each change of the end state between grid points by bisection
to ``2^-42`` of a phase, integrates each smooth piece by 5-point Gauss–Legendre (the
restitution is an algebraic, smooth function of the phase there: the error is far below
the engine's own solver tolerance) and bounds it by the piece ends (the one-sided limits
at the jumps), the nodes, and golden-section search where an interior node is extreme.
All designs and pieces are evaluated together on whole arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.engines.drake.stepping import step_contact
from impactsym.records import ArrayRecord

__all__ = ["PhaseSummary", "phase_summary"]

_GRID = 8
_BISECT = 42
_GOLDEN = 40
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(5)


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


def phase_summary(k, d, tau, m, g, v, h, *, approximation: str) -> PhaseSummary:
    """Mean over the touch phase and bounds over every phase (module docstring).

    Arguments as in :func:`~impactsym.engines.drake.stepping.step_contact`, without the
    phase; they broadcast.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, tau, m, g, v, h)))
    shape = arrays[0].shape
    flat = [a.ravel() for a in arrays]
    size = flat[0].size
    dt = flat[-1]

    def run(i, p):
        return step_contact(*(a[i] for a in flat), p, approximation=approximation)

    def key(res, p, i):
        with np.errstate(invalid="ignore", over="ignore"):
            index = np.rint(res.contact_time / dt[i] - p)
        return np.where(res.sticks, -1, index)

    grid = np.linspace(0.0, 1.0, _GRID + 1)
    grid[-1] = 1.0 - 1e-15  # phases lie in [0, 1)
    lo = np.tile(grid[:-1], (size, 1))
    hi = np.tile(grid[1:], (size, 1))
    i_all = np.repeat(np.arange(size), _GRID)
    key_lo = key(run(i_all, lo.ravel()), lo.ravel(), i_all).reshape(size, _GRID)
    key_hi = key(run(i_all, hi.ravel()), hi.ravel(), i_all).reshape(size, _GRID)
    jump = key_lo != key_hi
    ii, kk = np.nonzero(jump)
    a, c = lo[ii, kk].copy(), hi[ii, kk].copy()
    left = key_lo[ii, kk]
    for _ in range(_BISECT):
        if ii.size == 0:
            break
        mid = 0.5 * (a + c)
        same = key(run(ii, mid), mid, ii) == left
        a, c = np.where(same, mid, a), np.where(same, c, mid)
    ends = np.where(jump, np.nan, hi)
    ends[ii, kk] = a
    p0 = np.concatenate([lo.ravel(), c])
    p1 = np.concatenate([ends.ravel(), hi[ii, kk]])
    own = np.concatenate([i_all, ii])
    half, centre = 0.5 * (p1 - p0), 0.5 * (p1 + p0)
    pts = np.concatenate(
        [p0[:, None], centre[:, None] + half[:, None] * _NODES[None, :], p1[:, None]], axis=1
    )
    res = run(np.repeat(own, pts.shape[1]), pts.ravel())
    e = res.restitution.reshape(pts.shape)
    t = res.contact_time.reshape(pts.shape)
    stuck = res.sticks.reshape(pts.shape)
    w = half[:, None] * _WEIGHTS[None, :]
    e_mean = np.bincount(own, (w * e[:, 1:-1]).sum(axis=1), minlength=size)
    with np.errstate(invalid="ignore"):
        t_piece = np.where(stuck[:, 1:-1].any(axis=1), np.inf, (w * t[:, 1:-1]).sum(axis=1))
    t_mean = np.zeros(size)
    np.add.at(t_mean, own, t_piece)
    stick_frac = np.bincount(own, (w * stuck[:, 1:-1]).sum(axis=1), minlength=size)
    e_lo = np.fmin(e.min(axis=1), _interior_extreme(run, own, pts, e, -1.0))
    e_hi = np.fmax(e.max(axis=1), _interior_extreme(run, own, pts, e, 1.0))
    pen = res.max_penetration.reshape(pts.shape).max(axis=1)
    fields = (
        e_mean,
        t_mean,
        _reduce(np.minimum, own, e_lo, size, np.inf),
        _reduce(np.maximum, own, e_hi, size, -np.inf),
        _reduce(np.minimum, own, t.min(axis=1), size, np.inf),
        _reduce(np.maximum, own, t.max(axis=1), size, -np.inf),
        _reduce(np.maximum, own, pen, size, 0.0),
        stick_frac,
    )
    return PhaseSummary(*(np.reshape(f, shape) for f in fields))


def _interior_extreme(run, own, pts, e, sign):
    """Largest (``sign = 1``) or smallest (``-1``) restitution inside each piece where an
    interior node holds the extreme sample (golden section between its neighbours);
    ``nan`` elsewhere."""
    j = np.argmax(sign * e, axis=1)
    inner = np.flatnonzero((j > 0) & (j < pts.shape[1] - 1))
    out = np.full(e.shape[0], np.nan)
    if inner.size == 0:
        return out
    a, c = pts[inner, j[inner] - 1], pts[inner, j[inner] + 1]
    owner = own[inner]
    ratio = 0.5 * (np.sqrt(5.0) - 1.0)
    x1, x2 = c - ratio * (c - a), a + ratio * (c - a)
    f1, f2 = sign * run(owner, x1).restitution, sign * run(owner, x2).restitution
    best = np.fmax(sign * e[inner, j[inner]], np.fmax(f1, f2))
    for _ in range(_GOLDEN):
        right = f2 > f1
        a = np.where(right, x1, a)
        c = np.where(right, c, x2)
        x1, x2 = np.where(right, x2, c - ratio * (c - a)), np.where(right, a + ratio * (c - a), x1)
        f_new = sign * run(owner, np.where(right, x2, x1)).restitution
        f1, f2 = np.where(right, f2, f_new), np.where(right, f_new, f1)
        best = np.fmax(best, f_new)
    out[inner] = sign * best
    return out


def _reduce(op, owner, values, size, start):
    out = np.full(size, start)
    op.at(out, owner, values)
    return out
