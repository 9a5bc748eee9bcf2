"""The largest or smallest restitution of a discrete Drake contact over the touch phases
inside a piece of its phase summary, from samples that show it lies there
(:func:`interior_extreme`): zoom rounds over the neighbours of the extreme sample, then
successive parabolic interpolation (the restitution is smooth inside a piece), or, for
samples dense enough that it is a quadratic between them, parabolic steps from the
samples alone. Used by :func:`~impactsym.engines.drake.phases.phase_summary` and
:func:`~impactsym.engines.drake.jump_means.jump_summary` for the restitution's range.
Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from impactsym.engines.phase_pieces import vertex_point

__all__ = ["BATCH", "ZOOM", "interior_extreme"]

#: Contacts per call above which the searches take fewer phases per call.
BATCH = 32_000
#: Phases per zoom round of an interior extreme (9 above :data:`BATCH`).
ZOOM = 33


def interior_extreme(
    run: Callable[[np.ndarray, np.ndarray], Any], own: np.ndarray, pts: np.ndarray,
    e: np.ndarray, sign: float, *, rounds: int = 2, steps: int = 2,
) -> np.ndarray:  # fmt: skip
    """Largest (``sign = 1``) or smallest (``-1``) restitution inside each piece where an
    interior node holds the extreme sample, or an end does and the quadratic through it
    and its next two samples peaks between it and the next; ``nan`` elsewhere. Two zoom
    rounds (sample ``ZOOM`` phases, 9 for large batches, between the extreme's neighbours; keep the
    best and its neighbours: the bracket 16 times narrower at least), then two steps of
    successive parabolic interpolation: the restitution is smooth there, so the vertex
    of the quadratic through the best sample and its neighbours is off the extreme by
    the cube of the bracket, and its value by twice that order (the former 15 zoom
    rounds, to 1e-9 of a piece, gave the same bounds to 1e-15 in 2*10^4 random contacts,
    at 135 runs per piece instead of 22). The result is a sampled value: never beyond
    the extreme. ``pts``, ``e``: each piece's samples in phase order (rows) and their
    restitution; ``own``: the element of each piece; ``run(i, p)``: the contacts (a
    record with ``restitution``) of elements ``i`` at phases ``p``. ``rounds``,
    ``steps``: the zoom rounds and parabolic steps; ``rounds=0``: ``steps`` steps from
    the samples themselves (the best and its neighbours, or the end's three), keeping
    the best and its neighbours among all samples so far
    (:func:`_bracketed_steps`): for samples dense enough that the restitution is a
    quadratic between them (:func:`~impactsym.engines.drake.jump_means.jump_summary`'s
    nodes, 0.14 of a phase apart at most: 3 steps gave its zoomed bounds to ``1e-15``
    over 4*10^4 designs of the change tables, random contacts of 2-60 steps need 5;
    it takes 6)."""
    f, last = sign * e, pts.shape[1] - 1
    j = np.argmax(f, axis=1)
    # the ends whose quadratic peaks inside (sampled at the end: up to 5e-7 short; the
    # quadratics of those rows only)
    start, end = j == 0, j == last
    for ends, three, (lo, hi), at in ((start, slice(0, 3), (0, 1), 0),
                                      (end, slice(-3, None), (-2, -1), -1)):  # fmt: skip
        i = np.flatnonzero(ends)
        x_v, f_v = vertex_point(pts[i, three], f[i, three])
        with np.errstate(invalid="ignore"):
            ends[i] = (x_v > pts[i, lo]) & (x_v < pts[i, hi]) & (f_v > f[i, at])
    inner = np.flatnonzero((j > 0) & (j < last) | start | end)
    out = np.full(e.shape[0], np.nan)
    if inner.size == 0:
        return out
    best = sign * e[inner, j[inner]]
    if rounds == 0:  # from the best sample and its neighbours (or the end's three)
        three = np.clip(j[inner], 1, last - 1)[:, None] + np.arange(-1, 2)
        p3, f3 = (np.take_along_axis(a[inner], three, axis=1) for a in (pts, f))
        out[inner] = sign * np.fmax(best, _bracketed_steps(run, own[inner], p3, f3, sign, steps))
        return out
    lo = np.clip(np.where(start, 0, np.where(end, last - 1, j - 1)), 0, last)[inner]
    a, c = pts[inner, lo], pts[inner, np.where((start | end)[inner], lo + 1, lo + 2)]
    points = ZOOM if inner.size * ZOOM <= BATCH else 9
    owner = np.repeat(own[inner], points)
    frac = np.linspace(0.0, 1.0, points)
    rows = np.arange(inner.size)
    for _ in range(rounds):  # zoom: the bracket shrinks (points - 1)/2-fold per round
        x = a[:, None] + (c - a)[:, None] * frac[None, :]
        f = (sign * run(owner, x.ravel()).restitution).reshape(x.shape)
        b = np.clip(np.argmax(f, axis=1), 1, points - 2)
        best = np.fmax(best, f[rows, b])
        three = b[:, None] + np.arange(-1, 2)
        a, c = x[rows, b - 1], x[rows, b + 1]
    p3, f3 = np.take_along_axis(x, three, axis=1), np.take_along_axis(f, three, axis=1)
    for _ in range(steps):  # successive parabolic interpolation
        at, _ = vertex_point(p3, f3)
        inside = (at > p3[:, 0]) & (at < p3[:, 2])  # (False where nan)
        at = np.where(inside, at, p3[:, 1])
        f_at = sign * run(own[inner], at).restitution
        best = np.fmax(best, f_at)
        # the three best of the four samples, in phase order
        p4, f4 = np.column_stack([p3, at]), np.column_stack([f3, f_at])
        keep = np.sort(np.argsort(-f4, axis=1, kind="stable")[:, :3], axis=1)
        p3, f3 = np.take_along_axis(p4, keep, axis=1), np.take_along_axis(f4, keep, axis=1)
        order = np.argsort(p3, axis=1)
        p3, f3 = np.take_along_axis(p3, order, axis=1), np.take_along_axis(f3, order, axis=1)
    out[inner] = sign * best
    return out


def _bracketed_steps(run, own, p3, f3, sign, steps):
    """The best (signed) restitution of ``steps`` runs of successive parabolic
    interpolation from the three samples ``(p3, f3)`` of each row (in phase order,
    ``f3`` signed), each at the vertex of the quadratic through the best sample so far
    and its two neighbours among the row's samples (a bracket where the best lies
    between them; the three at that end where it is an end); a vertex outside the three
    (or none: on a line) is replaced by the middle of the longer of their intervals."""
    best = np.full(p3.shape[0], -np.inf)
    rows = np.arange(p3.shape[0])
    for _ in range(steps):
        at, _ = vertex_point(p3, f3)
        inside = (at > p3[:, 0]) & (at < p3[:, 2])  # (False where nan)
        wide = (p3[:, 2] - p3[:, 1] >= p3[:, 1] - p3[:, 0]).astype(np.intp)
        at = np.where(inside, at, 0.5 * (p3[rows, wide] + p3[rows, wide + 1]))
        f_at = sign * run(own, at).restitution
        best = np.fmax(best, f_at)
        p4, f4 = np.column_stack([p3, at]), np.column_stack([f3, f_at])
        order = np.argsort(p4, axis=1, kind="stable")
        p4, f4 = np.take_along_axis(p4, order, axis=1), np.take_along_axis(f4, order, axis=1)
        keep = np.clip(np.argmax(f4, axis=1), 1, 2)[:, None] + np.arange(-1, 2)
        p3, f3 = np.take_along_axis(p4, keep, axis=1), np.take_along_axis(f4, keep, axis=1)
    return best
