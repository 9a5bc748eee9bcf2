r"""PyBullet's phase-mean contact for the designs: the pattern's break points in closed form.

:func:`~impactsym.engines.pybullet.phases.phase_summary` finds where the branch pattern
of :func:`~impactsym.engines.pybullet.stepping.step_pattern` changes by bisection (42
runs of the map per change, on 32 grid intervals) for any map; for PyBullet's own
:func:`break_pieces` finds the same pieces from a few runs and :func:`root_summary`
integrates them in closed form (the summary the designs need many times over). Where the
pattern is constant the state of every (sub)step is an affine map of the free-flight
state ``-1``, itself quadratic in the phase ``p`` (``x = v t + g t^2/2``, ``w = v + g
t``, ``t = (p - 1) h``), so every quantity whose sign picks a branch (the gap ``d = s -
x`` of the speculative branch, the bias ``b`` of the clipped impulse, the processing
threshold ``x + threshold``, the restitution threshold) is a quadratic in ``p``, and
:func:`tracked_pattern` carries the first and second phase derivatives of the state
along the run: the first root ahead of a phase, over the (sub)steps up to the end state,
is the next point where the pattern can change. ``b`` is followed across a change of the
speculative branch it does not feel (where ``b <= 0`` at ``d = 0`` the impulse is zero
on both sides, so ``b`` changes formula but the pattern not): its root counts on the
side of ``d`` whose formula gives it.

The roots are checked, never trusted: the pattern ``1e-12`` of a phase before a root
must be that of the piece (the pattern ``1e-12`` after it starts the next piece, and
both are the one-sided limits a range needs), and a piece ends at one of 8 grid points
only where the grid's pattern is the piece's; everything else (a change the roots do
not see, such as a contact that starts sticking after its end state) is searched
as before, 15 phases a round (to ``2^-44`` of a grid interval in 11 runs of the map).
Pieces meet at the roots; adjacent pieces of one pattern are merged (the end speed is
one quadratic there) and integrated in closed form (:func:`root_summary`): the run
that read a piece's pattern carries the quadratic's three coefficients. The roots are
found to ~1e-14 of a phase, so the means agree with the bisection's to ~1e-13 and the
ranges to ~1e-12 (tested). The roots are solved only at the sub-steps where one can
lie within a phase (a bound from the quadratic's coefficients), the few next to a
change of branch; the piece search seeks them only up to twice what is left of its
interval (a root past its end changes no piece). A processing threshold or velocity
restitution adds roots whose changes the pattern may not show (then searched, slower
than the old search): the callers use this module with PyBullet's defaults for both.
All arrays, SI.

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
    close_state,
    end_final,
    pattern_code,
    run_live,
    run_pattern,
    start_state,
    step_budget,
    substep_impulse,
)
from impactsym.numeric.memory import keep_freed_pages
from impactsym.numeric.poly import quadratic_at, quadratic_roots_ahead

__all__ = ["CHUNK", "break_pieces", "root_summary", "tracked_pattern"]

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
_REACH = 1.0  # roots ahead further than this (in phase) lie past every phase range
_GAP = 1e-12  # the patterns either side of a root are read this far (in phase) from it
_END_STATE = ("w_end", "w1_end", "w2_end", "x_end", "x1_end")  # the tracked run's end state


def tracked_pattern(
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any,
    timestep: Any,
    phase: Any,
    *,
    substeps: int,
    slop: float,
    processing_threshold: float,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pattern of :func:`~impactsym.engines.pybullet.stepping.step_pattern` (the
    same numbers), the phase distance to the first root ahead (``inf``: none within a
    whole phase, so none before the end of the phase range; module docstring) and
    ``(3, n)``: the end state's speed ``w`` and its first and second derivatives in the
    phase (where the contact ended; while the pattern holds, ``w`` is that quadratic in
    the phase). Flat arrays, broadcast together."""
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep, phase))
    )
    settings = (substeps, slop, processing_threshold, velocity_restitution, restitution_threshold)
    pattern, first, end = _track(*(a.ravel().copy() for a in arrays), settings)
    return pattern, first, end[:3]


def _track(k, c, m, v, g, H, p, settings, *, give_up=False, horizon=np.inf):
    """:func:`tracked_pattern` of flat arrays (``settings``: ``substeps, slop,
    processing_threshold, velocity_restitution, restitution_threshold``), the end state
    ``(5, n)``: its speed ``w`` with two phase derivatives, then its penetration ``x``
    with the first (where the contact ended). ``give_up`` (no gravity): a run also stops
    where its end fails :func:`_final_at` there (``u = 0``), its pattern then not read
    further: for the start of a piece whose element :func:`_grid_pieces` gives up.
    ``horizon``: the root ahead is sought no further (fewer roots solved, :func:`_ahead`)."""
    substeps = settings[0]
    fixed, state = start_state(k, c, m, v, g, H, p, substeps)
    # the phase derivatives ride along: x = x0 + x1 dp + x2 dp^2 / 2, w likewise
    size = k.size
    state.update({
        "x1": state["w"] * H, "x2": g * H * H, "w1": g * H, "w2": np.zeros(size),
        "first": np.broadcast_to(np.asarray(horizon, float), size).copy(),
        "w1_end": np.zeros(size), "w2_end": np.zeros(size), "x1_end": np.zeros(size),
    })  # fmt: skip
    curved = bool(np.any(g))  # (without gravity every second derivative stays 0)
    if give_up:
        state["H"] = H

    def advance(a, n, limit):
        _advance(a, n, limit, curved, give_up, *settings)

    state = run_live(fixed, state, advance)
    sticks, n_end, n_first = state["sticks"], state["n_end"], state["n_first"]
    n_spec, n_pos, n_rest = state["n_spec"], state["n_pos"], state["n_rest"]
    pattern = pattern_code(sticks, n_end, n_first, n_spec, n_pos, n_rest)
    return pattern, state["first"], np.stack([state[key] for key in _END_STATE])


def _advance(a, n, limit, curved, give_up, substeps, slop, threshold, rest_coef, rest_threshold):
    """State ``n``: the map of :func:`~impactsym.engines.pybullet.stepping.step_pattern`
    (the same operations), the derivatives of ``x`` and ``w`` in the phase, and the first
    root of the branch quantities while the contact has not ended. Not ``curved`` (no
    gravity): the second derivatives are zeros, carried as the scalar ``0.0``."""
    h, erp, gain = a["h"], a["erp"], a["gain"]
    x, w = a["x"], a["w"]
    x1, w1 = a["x1"], a["w1"]
    x2, w2 = (a["x2"], a["w2"]) if curved else (0.0, 0.0)
    watching = ~a["ended"] & ~a["done"]
    first = a["first"]  # (lowered in place)
    settings = (slop, threshold, rest_coef, rest_threshold)
    for _ in range(substeps):
        w_star, d, spec, b_spec, b_pos, rest, within, dv = substep_impulse(a, x, w, *settings)
        s1, p1 = w1 + x1 / h, w1 + erp * x1 / h  # derivatives of b_spec, b_pos
        s2, p2 = (w2 + x2 / h, w2 + erp * x2 / h) if curved else (0.0, 0.0)
        if rest is not None:  # the restitution term's
            r0 = np.where(rest, rest_coef, 0.0)
            s1, s2, p1, p2 = s1 + r0 * w1, s2 + r0 * w2, p1 + r0 * w1, p2 + r0 * w2
        on = dv > 0
        quantities = (x, x1, x2, w_star, w1, w2, d, within, b_spec, s1, s2, b_pos, p1, p2)
        if watching.any():  # the roots ahead, for the contacts not yet ended
            _ahead(first, watching, quantities, threshold, rest_coef, rest_threshold)
        # the derivatives through the branch taken
        gb = np.where(on, gain, 0.0)
        w1 = w1 - gb * np.where(spec, s1, p1)
        x1 = x1 + h * w1
        if curved:
            w2 = w2 - gb * np.where(spec, s2, p2)
            x2 = x2 + h * w2
        w = w_star - dv
        x = x + h * w
    a["x"], a["w"], a["x1"], a["w1"], a["first"] = x, w, x1, w1, first
    if curved:
        a["x2"], a["w2"] = x2, w2
    close_state(a, n, limit, dv * a["m"] / h, extremes=False)  # (the pattern alone)
    stop = a["ended"] & (a["n_end"] == n)  # the end state: its speed's phase derivatives
    if stop.any():
        np.copyto(a["w1_end"], w1, where=stop)
        np.copyto(a["x1_end"], x1, where=stop)
        np.copyto(a["w2_end"], w2, where=stop)  # (0.0 where not curved)
        if not curved:  # without gravity what a run that ended final reports is final
            final = end_final(a, n, stop, substeps)
            if give_up:  # and one that fails _final_at is given up (_track)
                j = np.flatnonzero(stop & ~final)
                ends = np.stack([a[key][j] for key in _END_STATE])
                final[j] = ~_final_at(0.0, n, ends, a["budget"][j], a["H"][j])
            a["done"] |= final


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
    ``sampled_start`` and its two phase derivatives (:func:`tracked_pattern`): the
    quadratic the end speed follows over the piece. Arguments as in
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
    fails the finality test at one of its ends (:func:`_final_at`; a sticking piece
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
        return _track(*(a[i] for a in flat), p, settings, give_up=give_up, horizon=horizon)

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
        keep = drop(~_final_at(lo - s_lo, k_lo["end"], end_state, budget[own], flat[5][own]))
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
            keep = drop(bad | ~_final_at(end - s_lo, k_lo["end"], end_state, *room)
                        | ~_final_at(cut - b, key_b["end"], end_b, *room))  # fmt: skip
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


def _final_at(u, n_end, state, budget, H):
    """Per piece: whether at ``u`` from the phase where its pattern was read (end state
    ``n_end``, ``-1`` where it sticks; ``state`` that state and its phase derivatives, as
    :func:`_grid_pieces` keeps them) the contact ends separating within the step
    ``budget`` (:func:`_ends_final`)."""
    w0, w1, _, x0, x1 = state
    room = (budget - np.asarray(n_end, float) - 2.0) * H
    w, x = w0 + w1 * u, x0 + x1 * u
    slack = 1e-9 * (np.abs(w0) + np.abs(w1))
    ok = (w + slack < 0.0) & (x + 1e-9 * (np.abs(x0) + np.abs(x1)) < room * (-w - slack))
    return ok & (np.asarray(n_end) >= 0)


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
        ok &= _final_at(u, key["end"], state, budget[own], H[own])
    return np.bincount(own, ~ok, minlength=budget.size) == 0


def _ahead(first, watch, quantities, threshold, rest_coef, rest_threshold):
    """Lower ``first`` (in place) to the first root ahead of the branch quantities of one
    sub-step (module docstring) where ``watch``: ``b`` on the side of ``d`` whose formula
    it is, ``d`` where the impulse is on at ``d = 0`` (there ``b = w*``, plus the
    restitution term), the thresholds. Roots are solved only where one can lie before
    ``min(first, 1)``: ``|q0| <= (|q1| + |q2| D / 2) D`` at that ``D`` (a root further
    than a whole phase lies past the end of every phase range, and one past ``first``
    changes nothing), which leaves the few sub-steps next to a change of branch."""
    x, x1, x2, w_star, w1, w2, d, within, b_spec, s1, s2, b_pos, p1, p2 = quantities
    mx1, mx2 = -x1, -x2
    q = [
        (b_spec, s1, s2, (d, mx1, mx2, True)),
        (b_pos, p1, p2, (d, mx1, mx2, False)),
        (d, mx1, mx2, (w_star, w1, w2, True)),
    ]
    if np.isfinite(threshold):
        q.append((x + threshold, x1, x2, None))
    if rest_coef:
        q += [(w_star - rest_threshold, w1, w2, None), (w_star, w1, w2, None)]
    reach = np.minimum(first, _REACH) * (1.0 + 1e-9)  # (the slack covers rounding)
    half = 0.5 * reach
    # (without a processing threshold every contact is within it: no mask to apply)
    inside = watch if threshold == np.inf else watch & within
    for q0, q1, q2, valid in q:
        with np.errstate(invalid="ignore", over="ignore"):
            slope = np.abs(q1) if np.ndim(q2) == 0 and q2 == 0 else np.abs(q1) + np.abs(q2) * half
            near = np.abs(q0) <= slope * reach
        near &= watch if valid is None else inside
        j = np.flatnonzero(near)
        if j.size == 0:
            continue

        def pick(q, j=j):  # (a second derivative may be the scalar 0.0)
            return q if np.ndim(q) == 0 else q[j]

        best = first[j]
        for root in quadratic_roots_ahead(q0[j], q1[j], pick(q2)):
            if valid is not None:  # the root counts where the side quantity allows it
                v0, v1, v2, positive = valid
                side = quadratic_at(v0[j], v1[j], pick(v2), root)
                root = np.where(side > 0 if positive else side <= 0, root, np.inf)
            best = np.minimum(best, root)
        first[j] = best


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
    coefficients tracked along that run, :func:`tracked_pattern`), the restitution
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
