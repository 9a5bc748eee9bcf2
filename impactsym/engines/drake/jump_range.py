r"""The restitution's range of the phase summary of a contact whose end state changes
once (:func:`~impactsym.engines.drake.jump_means.jump_summary`): the least and largest
restitution over its samples (the Gauss nodes of the two pieces, both sides of the
change, the phase grid) and, where the extreme sample lies between two others of its
piece (or at a piece's end with the samples or the one-sided slope at the change saying
the extreme lies just inside), the search of
:func:`~impactsym.engines.drake.extremes.interior_extreme` there: :data:`_STEPS` steps
of successive parabolic interpolation from the samples themselves, which lie 0.125 of a
phase apart at most. The figures and the reasons for each rule are in
:mod:`~impactsym.engines.drake.jump_means` ("The summary"). All quantities are SI.
Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.drake.extremes import interior_extreme
from impactsym.engines.drake.phases import GRID_PHASES
from impactsym.engines.drake.stepping import ContactEnds, contact_ends

__all__ = ["restitution_range"]

_STEPS = 6  # parabolic steps of an interior extreme's search from the samples (docstring)
_ROWS = 4096  # contacts whose samples are sorted together (:func:`_extremes`)
_APART = 1e-7  # phases closer than this are one place for the range's search (_extremes)


def restitution_range(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    ev: Any, r: ContactEnds, held: np.ndarray, sides: tuple[np.ndarray, np.ndarray],
    change: np.ndarray,
) -> list[np.ndarray]:  # fmt: skip
    """The least and largest restitution over every sample of the held contacts (the
    nodes, both sides at the change's estimate ``change``, the grid) and inside the
    pieces where a sample between two of the same piece is extreme, or one at an end of
    a piece (of the phase interval, or a side of the change) is and the samples next to
    it say the extreme lies just inside
    (:func:`~impactsym.engines.drake.extremes.interior_extreme`, from those samples: they
    lie 0.125 of a phase apart at most, :data:`_STEPS` parabolic steps reach the extreme
    there), or next to a side where its slope says so (:func:`_beside`). ``ev``: the
    evaluation of the change's equations (``jump_means``: the node phases, weights and
    restitution, ``phi*`` and the slopes at the change), ``r``: the grid's runs,
    ``sides``: the restitution and end penetration of states ``B + 1`` and ``B`` at the
    change. Returns ``[least, largest]``, searched only where ``held``."""
    n = ev.phi.size
    extreme, at, place, count, win_p, win_e = _extremes(ev, r, sides, change)

    def run(i, phases):
        return contact_ends(*(a[i] for a in (k, d, m, g, v)), h, phases)

    bounds = []
    for s, sign in enumerate((-1.0, 1.0)):
        inner = np.full(n, np.nan)
        # a node or grid sample: interior_extreme reads its neighbours, or at an end of
        # the interval the next two, and searches where the samples say the extreme lies
        # just inside (5e-7 short with three panels of 5 nodes before); at a side of the
        # change: that piece's last (or first) three samples, the extreme may lie just
        # inside it (4.8e-7 short before, under gravity)
        for side, window in ((1, None), (0, np.arange(-2, 1)), (2, np.arange(3))):
            i = np.flatnonzero(held & (at[s] == side))
            if window is None:
                pts, e = win_p[s, i], win_e[s, i]
            else:  # (where the piece has three; their places among the five)
                j = place[s, i]
                i, j = (a[(j + window[0] >= 0) & (j + window[-1] < count[i])] for a in (i, j))
                cols = (j - np.clip(j - 2, 0, count[i] - 5))[:, None] + window
                pts, e = (np.take_along_axis(a[s, i], cols, axis=1) for a in (win_p, win_e))
            if i.size:
                inner[i] = interior_extreme(run, i, pts, e, sign, rounds=0, steps=_STEPS)
            if i.size and window is not None:
                inner[i] = _beside(run, i, pts, e, sign, inner[i], ev.slopes[side // 2, i], side)
        bounds.append(sign * np.fmax(sign * extreme[s], sign * inner))
    return bounds


def _beside(run, i, pts, e, sign, found, slope, side):
    """``found`` (the searches' extremes of the contacts ``i`` whose extreme sample is a
    side of the change: the ``side`` before it, 0, last of the three ``pts``, or after
    it, 2, first), and where none was searched but the restitution's one-sided slope at
    the change (``slope``, from the evaluation of ``jump_means``) says it goes on towards
    the extreme inside the piece: one run at the vertex of the quadratic through the
    side's value, that slope and the piece's next sample (or their middle), and the
    search from those three. The quadratic through the three samples alone can put an extreme
    that lies within ``~1e-5`` of a phase of the side just outside: ``4e-12`` short
    (a design of the change tables under gravity, :func:`interior_extreme`'s test of
    an end; its slope at the side ``2e-7`` per phase)."""
    end, near, inward = (-1, -2, -1.0) if side == 0 else (0, 1, 1.0)
    j = np.flatnonzero(np.isnan(found) & (sign * inward * slope > 0.0))
    if j.size == 0:
        return found
    p0, f0, p1, f1, s0 = pts[j, end], e[j, end], pts[j, near], e[j, near], slope[j]
    with np.errstate(all="ignore"):
        at = p0 - 0.5 * s0 * (p1 - p0) ** 2 / (f1 - f0 - s0 * (p1 - p0))
    at = np.where((at - p0) * (at - p1) < 0.0, at, 0.5 * (p0 + p1))  # (strictly between)
    e_at = run(i[j], at).restitution
    three = [p1, at, p0] if side == 0 else [p0, at, p1]
    values = [f1, e_at, f0] if side == 0 else [f0, e_at, f1]
    searched = interior_extreme(run, i[j], np.column_stack(three), np.column_stack(values), sign,
                                rounds=0, steps=_STEPS)  # fmt: skip
    out = found.copy()
    out[j] = sign * np.fmax(sign * e_at, sign * searched)
    return out


def _extremes(ev, r, sides, change):
    """Per sign (least, largest) and contact, over the samples of
    :func:`restitution_range`: the extreme restitution, whether the sample nearest it
    among those apart (below) is the side of the change before it (0), after it (2) or
    another sample (1), that sample's place in phase order among them, their count, and
    the phases and restitutions of the five around it (from two before to two after it,
    within the samples). Samples within :data:`_APART` of the next in phase are not
    apart: of such a pair the one that is not a side of the change is left out (a Gauss
    node or grid phase on another, at ``phi*`` near ``k/8``; the empty piece's side at
    ``phi* = 0``): the search around the extreme needs its neighbours apart (two
    samples 1e-12 apart made it search one side only, up to 1e-5 short; review).
    Blocks of :data:`_ROWS` contacts (their temporaries stay in the cache: the samples
    of all at once cost up to 0.15 s of CPU per 10^5 contacts to sort and gather)."""
    n, width = ev.phi.size, ev.phases.shape[1] + GRID_PHASES.size + 2
    extreme, at, place = np.empty((2, n)), np.empty((2, n), np.int8), np.empty((2, n), np.intp)
    count = np.empty(n, np.intp)
    win_p, win_e = np.empty((2, n, 5)), np.empty((2, n, 5))
    for lo in range(0, n, _ROWS):
        b = slice(lo, min(lo + _ROWS, n))
        rows = width * np.arange(b.stop - lo)
        # (an empty first piece, at phi* = 0, has no samples: its places take the other's)
        after = sides[0][1, b]
        before = np.where(ev.phi[b] > 0.0, sides[0][0, b], after)
        nodes = np.where(ev.weights[b] > 0.0, ev.e[b], before[:, None])
        # the samples in phase order, the change's sides apart: the side before it first
        # and the side after it last among the samples at its phase (a stable sort)
        e = np.concatenate([before[:, None], nodes, r.restitution[b], after[:, None]], axis=1)
        grid = np.broadcast_to(GRID_PHASES, (rows.size, GRID_PHASES.size))
        p = np.concatenate([change[b, None], ev.phases[b], grid, change[b, None]], axis=1)
        order = np.argsort(p, axis=1, kind="stable")
        side = (order == 0) | (order == width - 1)
        order += rows[:, None]  # (flat indices)
        e, p = e.ravel(), p.ravel()
        e_sorted, p_sorted = e.take(order), p.take(order)
        kept = _apart(p_sorted, side, ev.phi[b] == 0.0)
        m = np.count_nonzero(kept, axis=1)
        count[b] = m
        kept_order, near = order, None
        if not kept.all():  # each sample's nearest kept one: itself, the next or the last
            rank = np.cumsum(kept, axis=1) - 1  # (the place of the last kept at or before)
            nxt = np.minimum(rank + ~kept, m[:, None] - 1)
            prev = np.maximum(rank, 0)
            kept_order = np.take_along_axis(order, np.argsort(~kept, axis=1, kind="stable"),
                                            axis=1)  # fmt: skip
            kept_p = p.take(kept_order)
            near = np.where(np.abs(np.take_along_axis(kept_p, nxt, axis=1) - p_sorted)
                            <= np.abs(np.take_along_axis(kept_p, prev, axis=1) - p_sorted),
                            nxt, prev).ravel()  # fmt: skip
        for s in range(2):
            j = np.argmin(e_sorted, axis=1) if s == 0 else np.argmax(e_sorted, axis=1)
            extreme[s, b] = e_sorted.ravel().take(j + rows)
            k = j if near is None else near.take(j + rows)
            col = kept_order.ravel().take(k + rows) - rows
            at[s, b] = np.where(col == 0, 0, np.where(col == width - 1, 2, 1))
            place[s, b] = k
            five = kept_order.ravel().take((np.clip(k - 2, 0, m - 5) + rows)[:, None]
                                           + np.arange(5))  # fmt: skip
            win_p[s, b], win_e[s, b] = p.take(five), e.take(five)
    return extreme, at, place, count, win_p, win_e


def _apart(p, side, empty):
    """Which of the samples (rows in phase order ``p``; ``side``: the change's sides) are
    kept apart: of two within :data:`_APART` in phase, the one that is not a side (the
    first where neither is; the sides themselves, at one phase, both); and not the side
    before the change where its piece is ``empty`` (at ``phi* = 0``: its place is the
    other's)."""
    close = p[:, 1:] - p[:, :-1] <= _APART
    left, right = side[:, :-1], side[:, 1:]
    drop = np.zeros(p.shape, bool)
    drop[:, :-1] = close & ~left
    drop[:, 1:] |= close & left & ~right
    if empty.any():  # (the first side in phase order is the one before the change)
        drop |= side & empty[:, None] & (np.cumsum(side, axis=1) == 1)
    return ~drop
