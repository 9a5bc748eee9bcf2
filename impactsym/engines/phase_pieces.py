"""Touch-phase statistics from smooth pieces: the integrals and extremes every engine shares.

An engine's restitution and contact time at its timestep are piecewise smooth in the
touch phase, with jumps where the end state changes (`docs/physics.md#touch-phase`).
Each engine's phase summary (MuJoCo, Drake, PyBullet) finds its own pieces; this module
does what follows for all of them: Gauss–Legendre on every piece (exact for polynomials
of degree ``2 nodes - 1``, so for the quadratics of a flat linear contact with two nodes
or more), the piece ends (one-sided limits at the jumps) and nodes as samples for the
range, the vertex of the quadratic through three samples, and per-element reductions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

__all__ = [
    "PieceSamples",
    "gauss_legendre",
    "integrate_pieces",
    "least_vertex",
    "reduce_at",
    "vertex",
    "vertex_point",
]


@cache
def gauss_legendre(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on ``[-1, 1]`` (cached: the pieces of every
    summary share them)."""
    return np.polynomial.legendre.leggauss(nodes)


@dataclass(frozen=True, eq=False)
class PieceSamples:
    """The samples of every piece and the per-element means (1-D per element, SI).

    ``pts`` (pieces x (nodes + 2): the piece start, the Gauss nodes, the piece end),
    ``result`` (the model's record at ``pts``, flattened), ``restitution``,
    ``contact_time``, ``sticks`` (reshaped like ``pts``), and the means over the phase
    ``restitution_mean``, ``contact_time_mean`` (``inf`` where a piece sticks) and
    ``stick_fraction``.
    """

    pts: np.ndarray
    result: Any
    restitution: np.ndarray
    contact_time: np.ndarray
    sticks: np.ndarray
    restitution_mean: np.ndarray
    contact_time_mean: np.ndarray
    stick_fraction: np.ndarray


def integrate_pieces(
    run: Callable[[np.ndarray, np.ndarray], Any],
    p0: np.ndarray,
    p1: np.ndarray,
    owner: np.ndarray,
    size: int,
    *,
    nodes: int,
) -> PieceSamples:
    """Means over the phase from the pieces ``[p0, p1]`` of elements ``owner``.

    ``run(i, p)`` is the contact of elements ``i`` at phases ``p`` (a record with
    ``restitution``, ``contact_time`` and ``sticks``); ``size`` is the number of elements.
    """
    x, weights = gauss_legendre(nodes)
    half, centre = 0.5 * (p1 - p0), 0.5 * (p1 + p0)
    inner = centre[:, None] + half[:, None] * x[None, :]
    pts = np.concatenate([p0[:, None], inner, p1[:, None]], axis=1)
    res = run(np.repeat(owner, pts.shape[1]), pts.ravel())
    e = res.restitution.reshape(pts.shape)
    t = res.contact_time.reshape(pts.shape)
    stuck = res.sticks.reshape(pts.shape)
    w = half[:, None] * weights[None, :]
    e_mean = np.bincount(owner, (w * e[:, 1:-1]).sum(axis=1), minlength=size)
    with np.errstate(invalid="ignore"):
        t_piece = np.where(stuck[:, 1:-1].any(axis=1), np.inf, (w * t[:, 1:-1]).sum(axis=1))
    t_mean = np.zeros(size)
    np.add.at(t_mean, owner, t_piece)
    stick_frac = np.bincount(owner, (w * stuck[:, 1:-1]).sum(axis=1), minlength=size)
    return PieceSamples(pts, res, e, t, stuck, e_mean, t_mean, stick_frac)


def reduce_at(op: np.ufunc, owner: np.ndarray, values: np.ndarray, size: int, start: float):
    """``op`` (``np.minimum``/``np.maximum``) of ``values`` per element ``owner``."""
    out = np.full(size, start)
    op.at(out, owner, values)
    return out


def vertex(p: np.ndarray, e: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Value at the vertex of the quadratic through three points, where inside the piece."""
    xv, yv = vertex_point(p, e)
    inside = np.isfinite(yv) & (xv > lo) & (xv < hi)
    return np.where(inside, yv, np.nan)


def vertex_point(p: np.ndarray, e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(phase, value)`` of the vertex of the quadratic through the three points of each
    row of ``(p, e)`` (``nan`` or ``inf`` where they lie on a line or coincide)."""
    (x0, x1, x2), (y0, y1, y2) = p.T, e.T
    with np.errstate(all="ignore"):
        d01, d12 = (y1 - y0) / (x1 - x0), (y2 - y1) / (x2 - x1)
        c2 = (d12 - d01) / (x2 - x0)
        c1 = d01 - c2 * (x0 + x1)
        xv = -c1 / (2.0 * c2)
        yv = y0 + d01 * (xv - x0) + c2 * (xv - x0) * (xv - x1)
    return xv, yv


def least_vertex(a: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Per row of the samples ``a`` at the positions ``s``: the value at the vertex of the
    quadratic through the row's least sample and the two next to it (the first or last
    three where the least is an end), ``nan`` where the vertex lies outside them: how far
    a smooth function may dip below its samples (the phase summaries' margin checks)."""
    j = np.clip(np.argmin(a, axis=1), 1, s.size - 2)[:, None] + np.arange(-1, 2)
    y = np.take_along_axis(a, j, axis=1)
    return vertex(s[j], y, s[j[:, 0]], s[j[:, 2]])
