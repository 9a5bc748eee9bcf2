r"""PyBullet's phase-mean contact for the designs: the pattern's break points in closed form.

:func:`~impactsym.engines.pybullet.phases.phase_summary` finds where the branch pattern
of :func:`~impactsym.engines.pybullet.stepping.step_pattern` changes by bisection (42
runs of the map per change, on 32 grid intervals) for any map; for PyBullet's own
:func:`break_pieces` finds the same pieces from a few runs and :func:`root_summary`
integrates them in closed form (the summary the designs need many times over). Where the
pattern is constant every quantity whose sign picks a branch is a quadratic in the
phase, and the tracked run of :mod:`~impactsym.engines.pybullet.tracking` carries the
phase derivatives of the state along it: the first root ahead of a phase, over the
(sub)steps up to the end state, is the next point where the pattern can change.

The roots are checked, never trusted: the pattern ``1e-12`` of a phase before a root
must be that of the piece (the pattern ``1e-12`` after it starts the next piece, and
both are the one-sided limits a range needs), and a piece ends at one of 8 grid points
only where the grid's pattern is the piece's; everything else (a change the roots do
not see: without gravity past the end state, where the proof below takes over; with
gravity the tracked run watches the coast after it, where a band of sticking phases
inside one grid interval once went unseen) is searched as before, 15 phases a round
(to ``2^-44`` of a grid interval in 11 runs of the map). Pieces meet at the roots;
adjacent pieces of one pattern are merged (the end speed is one quadratic there) and
integrated in closed form (:func:`root_summary`): the run that read a piece's pattern
carries the quadratic's three coefficients. The roots are found to ~1e-14 of a phase,
so the means agree with the bisection's to ~1e-13 and the ranges to ~1e-12 (tested).
The piece search seeks the roots only up to twice what is left of its interval (a root
past its end changes no piece). A processing threshold or velocity restitution adds
roots whose changes the pattern may not show (then searched, slower than the old
search): the callers use this module with PyBullet's defaults for both. All arrays, SI.

Without gravity (and with those defaults) the grid is not needed where a proof takes its
place, and the pieces are searched from one interval ``[0, 1)`` first: every branch
quantity is then linear in the phase, so its root is its only sign change, and the
tracked run watches them all up to the end state; the pattern can change unseen only
after the end, where a contact that hovers (zero force while approaching) comes back
into force inside the overlap and one that leaves it too slowly outlasts its step
budget: both count as sticking. An element keeps the pieces from one interval where at
both ends of every piece the end state separates (``w < 0``) and leaves the overlap
within its step budget (the test by which a tracked run stops,
:func:`~impactsym.engines.pybullet.stepping.end_final`; ``w`` and ``x`` are linear in
the phase over a piece, so it then holds at every phase of it) and the roots missed no
change; the others are searched on the grid, given up by the one-interval search at the
first piece end that fails the test or change it would have to search (a sticking
contact's tracked run stops at its first failing end instead of at its step budget).
Besides two runs of the map per piece boundary, a run at ``0`` and one at ``1`` instead
of the grid's nine (designs of 10-40 steps: 6 runs per evaluation instead of 13, 3.9 ->
1.8 s per 10^5 designs); the same pieces, the means to ~1e-14 (tested against the grid,
the bisection and the map at random phases inside the pieces).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import PhaseSummary
from impactsym.engines.phase_pieces import reduce_at
from impactsym.engines.pybullet.stepping import (
    DEFAULT_RESTITUTION_THRESHOLD,
    MAX_STEPS,
    run_pattern,
    step_budget,
)
from impactsym.engines.pybullet.tracking import final_at
from impactsym.engines.pybullet.tracking import track as tracked_run
from impactsym.numeric.memory import keep_freed_pages

__all__ = ["CHUNK", "break_pieces", "root_summary"]

#: elements per pass of :func:`root_summary` and of the phase summary: every element's
#: numbers are its own, but a pass over 10^5 elements at once runs out of the cache
#: (measured 7.9 s against 3.9 s in passes of 5000-20000)
CHUNK = 8192

_GRID = 8  # phase intervals: the check of the roots (a change the roots miss is searched)
_COARSE_PASS = 4  # CHUNK times this many elements per pass where each runs one interval
#: pieces split off one grid interval before the rest counts as one piece (met where the
#: pattern changes thousands of times over the phase: in the random contacts checked,
#: only contacts that stick at some phases, whose mean contact time is infinite anyway)
_ROUNDS = 12
_SECTIONS = 16  # the fallback search cuts an interval into this many parts per round
_SECTION_ROUNDS = 11  # rounds of it: 16^-11 = 2^-44 of an interval
_GAP = 1e-12  # the patterns either side of a root are read this far (in phase) from it


def break_pieces(
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any,
    timestep: Any,
    *,
    substeps: int,
    slop: float,
    processing_threshold: float,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> tuple[np.ndarray, ...]:
    """The pieces of constant pattern (module docstring): ``(start, end, sampled_start,
    sampled_end, owner, pattern, end_speed)``, adjacent pieces of one pattern merged,
    sorted by owner and start. A piece that meets another at a root starts (ends) there,
    and its pattern was read ``_GAP`` inside, at ``sampled_start`` (``sampled_end``):
    there the map gives the one-sided limits at the jump (elsewhere the sampled end is
    the end). ``end_speed`` (``(3, pieces)``) is the end state's speed at
    ``sampled_start`` and its two phase derivatives
    (:func:`~impactsym.engines.pybullet.tracking.tracked_pattern`): the quadratic the end
    speed follows over the piece. Arguments as in
    :func:`root_summary`, flattened (``owner`` indexes the flat arrays). Without gravity
    from one phase interval where the ends are final, else from ``_GRID`` (module
    docstring)."""
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep))
    )
    flat = [a.ravel() for a in arrays]
    settings = (substeps, slop, processing_threshold, velocity_restitution, restitution_threshold)
    # without gravity (and with PyBullet's defaults for the thresholds) one interval is
    # searched first; an element keeps those pieces where every phase provably ends
    # final, the others are searched on the grid (module docstring)
    coarse = _one_interval(flat[4], velocity_restitution, processing_threshold)
    found = []
    if coarse.any():
        i = np.flatnonzero(coarse)
        k, c, m, H = (a[i] for a in (flat[0], flat[1], flat[2], flat[5]))
        budget = np.minimum(step_budget(k, c, m, H), MAX_STEPS)
        pieces, unsure = _grid_pieces([a[i] for a in flat], settings, 1, budget=budget)
        sure = ~unsure & _ends_final(pieces, budget, H)
        kept = sure[pieces[5]]
        found.append([a[..., kept] for a in pieces[:5]] + [i[pieces[5][kept]], pieces[6][:, kept]])
        coarse[i[~sure]] = False
    if not coarse.all():
        j = np.flatnonzero(~coarse)
        pieces, _ = _grid_pieces([a[j] for a in flat], settings, _GRID)
        found.append([*pieces[:5], j[pieces[5]], pieces[6]])
    parts = found[0]  # (one search: its arrays as they are, not copied by a concatenate)
    if len(found) > 1:
        parts = [np.concatenate(part, axis=-1) for part in zip(*found, strict=True)]
    parts[6] = parts[6][:3]  # the end speed's quadratic (the penetration's rows checked)
    return _merge(*parts)


def _one_interval(gravity, velocity_restitution, processing_threshold):
    """Per element: whether :func:`break_pieces` searches its pieces from one phase
    interval first (no gravity, PyBullet's defaults for the thresholds)."""
    default = not velocity_restitution and bool(np.isinf(processing_threshold))
    return (gravity == 0.0) & default


def _grid_pieces(flat, settings, intervals, *, budget=None):
    """The pieces of :func:`break_pieces` (not merged; ``end`` with the end state's
    penetration and its phase derivative as rows 3-4) from ``intervals`` grid intervals,
    and per element whether a change was searched (one the roots missed, or left after
    ``_ROUNDS`` roots of one interval).

    With the step ``budget`` (one interval without gravity, for :func:`_ends_final`): an
    element is given up (counted as searched, its pieces incomplete) as soon as a piece
    fails the finality test at one of its ends (:func:`final_at`; a sticking piece
    does) or a change the roots missed would have to be searched, since its pieces then
    come from the grid anyway: its later rounds (each a run to its step budget where it
    sticks) and the search are not run. The others' pieces are the same numbers (every
    element's runs are its own)."""
    size = flat[0].size
    searched = np.zeros(size, bool)
    if budget is not None:
        assert intervals == 1  # (then a piece per element is open at a time)

        def drop(fails):  # the rows kept: their owners given up where fails
            searched[own[fails]] = True
            return ~fails

    def track(i, p, end, give_up=False):  # (the root ahead is wanted up to end, p < end)
        horizon = 2.0 * (end - p) + 1e-9  # (a root past it leaves p + root past end)
        return tracked_run(*(a[i] for a in flat), p, settings, give_up=give_up, horizon=horizon)

    def run(i, p):
        names = ("substeps", "slop", "processing_threshold", "velocity_restitution",
                 "restitution_threshold")  # fmt: skip
        return run_pattern(*(a[i] for a in flat), p, **dict(zip(names, settings, strict=True)))

    grid = np.linspace(0.0, 1.0, intervals + 1)
    grid[-1] = np.nextafter(1.0, 0.0)
    own = np.repeat(np.arange(size), intervals)
    lo, hi = np.tile(grid[:-1], size), np.tile(grid[1:], size)
    # the pattern, roots ahead and end state where each grid interval starts; at the last
    # grid point only the pattern (a plain run: the same numbers, without the tracking)
    k_lo, r_lo, end_state = track(own, lo, hi, give_up=budget is not None)
    s_lo = lo.copy()  # where the pattern of the piece starting at lo was read
    if budget is not None:  # the first piece's start (at 0: a stick there ends the search)
        keep = drop(~final_at(lo - s_lo, k_lo["end"], end_state, budget[own], flat[5][own]))
        if not keep.all():
            lo, hi, s_lo, k_lo, r_lo, own = (arr[keep] for arr in (lo, hi, s_lo, k_lo, r_lo, own))
            end_state = end_state[:, keep]
    last = own[intervals - 1 :: intervals]  # the elements whose last grid point is run
    k_hi = np.concatenate([k_lo.reshape(-1, intervals)[:, 1:],
                           run(last, np.full(last.size, grid[-1]))[:, None]],
                          axis=1).ravel()  # fmt: skip
    # (start, end, sampled start, sampled end, pattern, owner, end state at the sampled
    # start and its phase derivatives) of every piece
    pieces = []
    for _ in range(_ROUNDS):
        cut = lo + r_lo
        split = cut < hi
        flat_piece = ~split & (k_lo == k_hi)
        pieces.append((*(arr[flat_piece] for arr in (lo, hi, s_lo, hi, k_lo, own)),
                       end_state[:, flat_piece]))  # fmt: skip
        rest = ~flat_piece
        if budget is not None:  # a change unseen by the roots (would be searched): given up
            rest &= drop(~split & ~flat_piece)
        lo, hi, s_lo, k_lo, k_hi, own, cut, split = (
            arr[rest] for arr in (lo, hi, s_lo, k_lo, k_hi, own, cut, split)
        )  # fmt: skip
        end_state = end_state[:, rest]
        if own.size == 0:
            break
        a = np.where(split, np.maximum(cut - _GAP, lo), lo)
        b = np.where(split, np.minimum(cut + _GAP, hi), hi)
        # the pattern just before each root (a plain run), and the pattern, root ahead
        # and end state after it
        key_a = run(own, a)
        key_b, r_b, end_b = track(own, b, hi)
        # the pieces meet at the root; the patterns either side are read _GAP away
        end, r_b = np.where(split, cut, a), r_b + (b - np.where(split, cut, b))
        bad = ~split | (key_a != k_lo)
        if budget is not None:  # given up: a search, a piece's end or the next's start fails
            room = (budget[own], flat[5][own])
            keep = drop(bad | ~final_at(end - s_lo, k_lo["end"], end_state, *room)
                        | ~final_at(cut - b, key_b["end"], end_b, *room))  # fmt: skip
            if not keep.all():
                lo, s_lo, k_lo, own, end_state, a, b, cut, hi, k_hi = (
                    arr[..., keep] for arr in (lo, s_lo, k_lo, own, end_state, a, b, cut, hi, k_hi)
                )  # fmt: skip
                end, bad, key_b, r_b, end_b = (
                    arr[..., keep] for arr in (end, bad, key_b, r_b, end_b)
                )  # fmt: skip
        if bad.any():  # a change the roots do not see: the multisection search
            j = np.flatnonzero(bad)
            searched[own[j]] = True
            end[j], b[j] = _multisect(run, own[j], lo[j], hi[j], k_lo[j])
            key_b[j], r_b[j], end_b[:, j] = track(own[j], b[j], hi[j])
        pieces.append((lo, end, s_lo, np.where(bad, end, a), k_lo, own, end_state))
        lo, s_lo, k_lo, r_lo, end_state = np.where(bad, b, cut), b, key_b, r_b, end_b
    else:
        pieces.append((lo, hi, s_lo, hi, k_lo, own, end_state))  # left after _ROUNDS
        searched[own] = True
    return [np.concatenate(part, axis=-1) for part in zip(*pieces, strict=True)], searched


def _ends_final(pieces, budget, H):
    """Per element: whether at every phase of every piece (of :func:`_grid_pieces`,
    without gravity: the end state linear in the phase) the contact ends separating,
    ``w < 0``, and leaves the overlap within its step budget ``budget``,
    ``n_end + x / (-w H) + 2 < budget`` (the test of the tracked run's stop), both
    checked at the piece's ends with a margin: there no branch changes after the end
    state, so the roots ahead see every change of the pattern and the grid's check is
    not needed.

    The test at a piece's end is a backstop no contact has been seen to need: at a
    zero-force end after an impulse the end speed is ``w <= 0``, ``0`` only at rest at
    ``x = s > 0`` (the last impulse leaves ``x >= s``, and a zero impulse there needs
    ``w <= -erp (x - s) / h``), so the end speed cannot change sign with the body out of
    the overlap; and the phases that stick after the end (by the step budget, roughly
    ``x + (budget - n) H w >= 0``, a hover with ``w >= 0 < x`` included) are, ``x`` and
    ``w`` linear, a half-line of the piece: they hold at one of its ends, whose pattern
    was read there (the start, or the pattern just before the root or at the last grid
    point), so that check already refuses them. What the end test alone refuses is a
    piece end within the margin (2 steps, ``1e-9``) of the budget: a change of which
    elements take the grid, not of a result."""
    p0, p1, s0, _, key, own, state = pieces
    ok = np.ones(own.size, bool)
    for u in (p0 - s0, p1 - s0):
        ok &= final_at(u, key["end"], state, budget[own], H[own])
    return np.bincount(own, ~ok, minlength=budget.size) == 0


def root_summary(
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any,
    timestep: Any,
    *,
    substeps: int,
    slop: float,
    processing_threshold: float,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> PhaseSummary:
    """The phase summary (means, ranges, stick fraction) from the pieces of
    :func:`break_pieces`, each integrated in closed form.

    On a piece the end speed is the quadratic ``w(p) = w0 + w1 u + w2 u^2 / 2``,
    ``u = p - s`` about the phase ``s`` where the piece's pattern was read (its three
    coefficients tracked along that run,
    :func:`~impactsym.engines.pybullet.tracking.tracked_pattern`), the restitution
    ``-w / v`` and the contact time ``(p + n) h`` (``n`` the end state): the mean is the
    exact integral of each over ``[start, end]``, the range the values at the sampled ends
    (the one-sided limits at the jumps) and at the quadratic's vertex where it lies
    between them. Where the piece sticks: restitution 0, contact time ``inf``. The
    same numbers as Gauss-Legendre on runs of the map at the nodes (which re-ran the
    map three or five times per piece) to rounding. Validated arrays in, broadcast
    together; arrays out, in passes of :data:`CHUNK` elements (4 times as many without
    gravity, where each starts from one phase interval).
    """
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep))
    )
    shape = arrays[0].shape
    flat = [a.ravel() for a in arrays]
    size = flat[0].size
    settings = {
        "substeps": substeps, "slop": slop, "processing_threshold": processing_threshold,
        "velocity_restitution": velocity_restitution,
        "restitution_threshold": restitution_threshold,
    }  # fmt: skip
    # a pass of CHUNK elements runs _GRID intervals of each; without gravity (and with
    # PyBullet's defaults for the thresholds) break_pieces starts from one interval:
    # passes of _COARSE_PASS CHUNK elements then (measured 1.8 s against 2.0 s for 10^5
    # designs)
    coarse = bool(np.all(_one_interval(flat[4], velocity_restitution, processing_threshold)))
    chunk = _COARSE_PASS * CHUNK if coarse else CHUNK
    if size > chunk:  # in passes of chunk elements: the same numbers, element by element
        # passes of contacts of like length (sorted by the period^2 m / k, then the damping
        # time c / k), so that a pass's runs end together instead of stepping the short
        # contacts' arrays until the long ones end
        keep_freed_pages()  # (the passes reuse the pages their temporaries free)
        k, c, m = flat[:3]
        order = np.lexsort((c / k, m / k))
        parts = [root_summary(*(a[order[i : i + chunk]] for a in flat), **settings)
                 for i in range(0, size, chunk)]  # fmt: skip
        out = []
        for f in dataclasses.fields(PhaseSummary):
            field = np.empty(size)
            field[order] = np.concatenate([getattr(part, f.name) for part in parts])
            out.append(field.reshape(shape))
        return PhaseSummary(*out)
    p0, p1, s0, s1, own, key, (w0, w1, w2) = break_pieces(*flat, **settings)
    v, h = flat[3][own], flat[5][own]
    stuck = key["end"] < 0
    length = p1 - p0
    u0, u1, top = p0 - s0, p1 - s0, s1 - s0
    with np.errstate(all="ignore"):
        # the exact mean of the quadratic over [p0, p1], times the length
        w_int = length * (w0 + w1 * (0.5 * (u0 + u1)) + w2 * ((u0 * u0 + u0 * u1 + u1 * u1) / 6.0))
        u_vertex = -w1 / w2
        inside = (u_vertex > 0.0) & (u_vertex < top)
        e_vertex = -(w0 + u_vertex * (w1 + 0.5 * w2 * u_vertex)) / v
        e_first = -w0 / v
        e_last = -(w0 + top * (w1 + 0.5 * w2 * top)) / v
    e_lo, e_hi = np.minimum(e_first, e_last), np.maximum(e_first, e_last)
    e_lo = np.where(inside, np.minimum(e_lo, e_vertex), e_lo)
    e_hi = np.where(inside, np.maximum(e_hi, e_vertex), e_hi)
    n_end = key["end"].astype(float)
    e_piece = np.where(stuck, 0.0, -w_int / v)
    t_piece = np.where(stuck, np.inf, h * length * (0.5 * (p0 + p1) + n_end))
    e_lo, e_hi = np.where(stuck, 0.0, e_lo), np.where(stuck, 0.0, e_hi)
    t_lo = np.where(stuck, np.inf, h * (s0 + n_end))
    t_hi = np.where(stuck, np.inf, h * (s1 + n_end))
    fields = (
        np.bincount(own, e_piece, minlength=size),
        np.bincount(own, t_piece, minlength=size),
        reduce_at(np.minimum, own, e_lo, size, np.inf),
        reduce_at(np.maximum, own, e_hi, size, -np.inf),
        reduce_at(np.minimum, own, t_lo, size, np.inf),
        reduce_at(np.maximum, own, t_hi, size, -np.inf),
        np.bincount(own, np.where(stuck, length, 0.0), minlength=size),
    )
    return PhaseSummary(*(np.reshape(f, shape) for f in fields))


def _merge(p0, p1, s0, s1, key, own, speed):
    """The pieces sorted by owner and start, adjacent ones of one pattern joined (the
    pattern and the end speed's quadratic are those of the first)."""
    # by owner and grid interval (stable, integers): by owner and start where each
    # interval's pieces came in order of their start, as the rounds append them (checked)
    cell = np.clip(np.floor(p0 * _GRID), 0, _GRID - 1).astype(np.int64)
    order = np.argsort(own * _GRID + cell, kind="stable")
    mine, start = own[order], p0[order]
    if np.any((mine[1:] == mine[:-1]) & (start[1:] < start[:-1])):
        order = np.lexsort((p0, own))
        mine, start = own[order], p0[order]
    own, p0, p1 = mine, start, p1[order]
    rows = np.ascontiguousarray(key).view(np.int64).reshape(key.size, len(key.dtype.names))
    key = rows.take(order, axis=0).view(key.dtype).ravel()
    joins = np.zeros(p0.size, bool)
    joins[1:] = (own[1:] == own[:-1]) & (key[1:] == key[:-1]) & (p0[1:] == p1[:-1])
    starts = np.flatnonzero(~joins)
    lasts = np.append(starts[1:], p0.size) - 1
    first, last = order[starts], order[lasts]  # (s0, s1 and speed are needed there alone)
    return p0[starts], p1[lasts], s0[first], s1[last], own[starts], key[starts], speed[:, first]


def _multisect(run, own, lo, hi, k_lo):
    """The phases ``a < b`` at most ``2^-44`` of ``[lo, hi]`` apart with pattern ``k_lo``
    at ``a`` and another at ``b`` (as the bisection of
    :mod:`~impactsym.engines.pybullet.phases`, but ``_SECTIONS - 1`` points per round:
    11 runs of the map instead of 42 sequential ones; the first sampled change is kept)."""
    a, b = lo.copy(), hi.copy()
    inner = np.arange(1, _SECTIONS) / _SECTIONS
    rows = np.repeat(own, inner.size)
    for _ in range(_SECTION_ROUNDS):
        pts = a[:, None] + (b - a)[:, None] * inner[None, :]
        same = (run(rows, pts.ravel()) == np.repeat(k_lo, inner.size)).reshape(pts.shape)
        # the first point off the pattern (or b): the change lies before it
        first = np.where(same.all(axis=1), inner.size, np.argmin(same, axis=1))
        at, last = np.arange(own.size), inner.size - 1
        before = np.where(first > 0, pts[at, np.maximum(first - 1, 0)], a)
        b = np.where(first <= last, pts[at, np.minimum(first, last)], b)
        a = before
    return a, b
