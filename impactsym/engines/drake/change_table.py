r"""Many discrete designs read off tables of exact designs, one per end state (and one
per plateau between two), each confirmed by one exact evaluation that also gives its
phase summary (:func:`table_designs`).

A target contact time of ``q`` steps fixes the end state :math:`B = \lfloor q - 1/2
\rfloor` before which, and the phase :math:`\varphi^* = q - 1/2 - B` at which, the end
state changes (:mod:`~impactsym.engines.drake.jump_means`). For one ``B`` (and one
``g / v``) the design, in the damping number :math:`s = d v` and the step
:math:`w = h \sqrt{k/m}`, is then a smooth function of :math:`(e, \varphi^*)` where
that one change is the structure: the change's equations have no plateau and no kink
there. Across ``B`` it is not (a plateau of the contact time lies between the designs at
:math:`\varphi^* \to 1` and at the next ``B``'s :math:`\varphi^* \to 0`), so each ``B``
gets its own tables.

* **A table**: the exact designs (``design``, the caller's own path) at :data:`NODES_E`
  by :data:`NODES_PHASE` Chebyshev points of the first kind, over a box of the
  restitutions of that ``B``'s targets within :data:`RESTITUTIONS` (at most
  :data:`WIDTH` wide; wider ranges get several) and a window of the phases, the first
  of :data:`PHASES` (under gravity :data:`PHASES_PRESSED`). A table whose last degrees
  exceed :data:`TAIL` is refused: for a tail in the phase (near the ends of the phase
  interval a second change can appear, on another branch) it is built again over the
  next window; otherwise (a node not designed, a tail in the restitution: below about
  0.25 the one-change structure breaks) as the two halves of its box (:func:`_built`).
  Measured (20 x 12 nodes, ``e`` 0.3-0.6, contacts of 22-35 steps, gravity 0 and 9.81):
  the interpolated ``(s, w)`` lie within ``2e-14`` (median) and ``5e-13`` (largest) of
  exact designs at random targets, which is the exact designs' own spread: they meet
  tolerances, not a point. With 16 x 10 nodes one evaluation confirms 99.3 % of the
  benchmark's targets by contact time without gravity, with 14 x 8 almost none. A
  target whose change lies beyond a narrower window is read off the table extrapolated
  to the ends of the phase interval (from ``0.02-0.98``, 0.02/0.96 of the window beyond
  each end; from ``0.05-0.95`` further): where the one change still holds there its
  evaluation keeps it (61 % of the benchmark's 3994 such
  targets by contact time under gravity; before, all took the caller's path, at about
  ten times the cost each), elsewhere it is the caller's.
* **By largest overlap** the target does not name its end state: the caller's coarse
  table of phase means tells each its contact time to a step or so, and it asks the
  tables of that end state and both neighbours. A table also holds the overlap (over ``v
  h``) at the last grid phase of each state that is deepest at some node, and one more
  on either side: each is smooth in the design, their largest, the largest overlap
  (:func:`~impactsym.engines.drake.jump_means.last_overlap`), is not (which state is
  deepest changes; one table of the largest was ``2e-5`` off). The target's phase is
  where their largest meets its overlap
  (:func:`~impactsym.engines.drake.chebyshev_tables.phase_where`). A target whose
  overlap lies between the tables of ``B`` (at phase 1) and ``B + 1`` (at phase 0) has
  its design on the plateau between, where every phase ends at ``N = B + 1``: where at
  least :data:`MIN_PLATEAU` do, the plateau gets a table of its own over the restitution
  and the step's share of the way from one edge to the other (the edges' designs off the
  two tables), each node's damping the secant root of that one state's mean
  (:func:`_plateau_tables`, :data:`PLATEAU_NODES` nodes across: its designs are smooth
  there, 6 held the tail of all 41 plateau tables of the benchmark by overlap as 10 did,
  4 none). Without gravity only: under it no window reaches the ends of the phase
  interval. A target asks its likely end state's table first, the neighbours' where that
  has none (half the phase solves of asking them in the order of the tables), the tables
  asked in one turn read together
  (:func:`~impactsym.engines.drake.chebyshev_tables.phases_where`).
* **One exact evaluation** per design read off:
  :func:`~impactsym.engines.drake.jump_means.jump_summary` at the table's design, with
  :data:`NODES` Gauss nodes on the shorter piece and two more on the longer (the
  change's equations, the phase grid's full contacts, every node's end state, the
  margins between samples). The design is done where that summary holds, its restitution
  is within :data:`TOLERANCE` of the target and its size within its relative tolerance
  (by overlap: its largest overlap, and the change's estimate within :data:`SETTLED` of
  where the table put it); the summary is then the design's prediction. The others are
  left to the caller, with the table's design and, by overlap, the Jacobian of the
  targets in it (:class:`Starts`, by forward differences of the table: where a second
  change next to the ends of the phase interval fails the evaluation, the design is
  still close).

A box gets a table where it serves at least :data:`MIN_TARGETS` targets of contacts of
:data:`MIN_STEPS` steps or more, and a call's boxes serve :data:`MIN_SERVED` together: a
table costs ``NODES_E * NODES_PHASE`` designs by the caller's path (about 15 ms of CPU
among many, 0.08-0.23 s alone), a design read off it one evaluation instead of about
four and a phase summary (about 15 us against 150-250 us). All quantities SI, flat
arrays. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise, product
from typing import NamedTuple

import numpy as np

from impactsym.contact.lawtable import chebyshev_points
from impactsym.engines.drake.chebyshev_tables import (
    evaluate,
    fit,
    from_unit,
    largest,
    phase_where,
    phases_where,
    to_unit,
)
from impactsym.engines.drake.continuous import free_scales
from impactsym.engines.drake.jump_means import jump_means, jump_summary
from impactsym.engines.drake.phases import GRID_PHASES, SUMMARY_FIELDS, PhaseSummary
from impactsym.engines.drake.stepping import states_through

__all__ = [
    "CROWD",
    "MIN_PLATEAU",
    "MIN_SERVED",
    "MIN_STEPS",
    "MIN_TARGETS",
    "NODES",
    "NODES_E",
    "NODES_PHASE",
    "NODES_PHASE_OVERLAP",
    "PHASES",
    "PHASES_PRESSED",
    "RESTITUTIONS",
    "SETTLED",
    "TAIL",
    "TOLERANCE",
    "WIDTH",
    "may_fill_a_table",
    "table_designs",
]

#: Chebyshev nodes of a table in the restitution and in the phase of the change.
NODES_E, NODES_PHASE = 16, 10
#: In the phase by largest overlap: there the change need lie only within
#: :data:`SETTLED` of the table's (by contact time it is the size, to ``5e-11``
#: relative): 16 x 8 nodes confirmed as many of the benchmark's targets as 16 x 10 (99.7 %
#: and 97.9 %, g = 0 and 9.81; by contact time 79 % and 71 %), 16 x 7 half.
NODES_PHASE_OVERLAP = 8
#: Widest restitution box of one table (wider ranges: several tables side by side).
WIDTH = 0.3
#: Targets one table serves at least, and all a call's tables together: built together,
#: a table pays for itself from about 100 targets (~15 ms of CPU); one alone costs
#: 0.08-0.23 s (the caller's path's fixed cost for its nodes: calls of 300 targets of one
#: end state took 0.09-0.32 s with a table, 0.09-0.13 s without; reviews). With 1024 per table a
#: call of 3 x 10^4 targets of ``e`` 0.25-0.75 over 21 end states got none (two boxes of
#: ~700 each) and took 2.3-2.8 s of CPU, 1.2-1.9 s now.
MIN_TARGETS, MIN_SERVED = 256, 1024
#: Steps of the continuous contact time in which targets by overlap may fill a table.
CROWD = 7
#: The restitutions tables serve: below, the one-change structure breaks (at ``B = 15``
#: it held at 69 of 160 nodes of ``e`` 0.1-0.3); above, the caller's path leaves nodes
#: undesigned; tables there were refused, their nodes designed for nothing (a call of
#: 10^5 targets by overlap, ``e`` 0.1-0.9, took twice the CPU).
RESTITUTIONS = (0.25, 0.75)
#: End states ``B`` below this get no table (short contacts: fewer Gauss nodes do worse).
MIN_STEPS = 10
#: Gauss nodes of the shorter piece in the one exact evaluation, 7 on the longer (12 runs;
#: :mod:`~impactsym.engines.drake.jump_means`): against 16 on each of three panels, the
#: pieces' integrals of 2.1*10^4 designs of 10-70 steps (gravity 0 and 9.81, where the
#: change held) moved by ``1.9e-15`` at most, ``7e-16`` above 15 steps (5 on each of three
#: panels, 15 runs: ``4.2e-15`` and ``4.4e-16``; 4: ``2e-12``); the default is 10.
NODES = 5
#: The phases of the change a table covers, tried in turn where a table's tail is above
#: :data:`TAIL`: without gravity, and under it (closer to the ends of the phase interval
#: a second change appears at the larger restitutions: 3e-4 off a smooth continuation
#: at ``e = 0.56``, ``phi* = 0.001``; tables over ``0.01-0.99`` had tails of ``1e-6``).
PHASES = ((0.0, 1.0), (0.02, 0.98))
PHASES_PRESSED = ((0.02, 0.98), (0.05, 0.95))
#: A table holds where its last two degrees either way sum below this share of its
#: largest value (``1e-12`` measured on smooth tables, ``1e-6`` across a second change).
TAIL = 1e-9
#: A design read off a table is done within these of the restitution and (relative) of
#: the contact time: half the tolerances of the caller's check of its prediction
#: (``1e-12``, ``1e-10``), which the exact phase means meet where the change's
#: equations do (they agree to ``~2e-14`` and ``~1e-12`` steps).
TOLERANCE = (5e-13, 5e-11)
#: By largest overlap, the change's estimate may be this far (steps) from where the table
#: put it: the restitution is the mean to second order in that offset (``~0.1`` per
#: step squared, :mod:`~impactsym.engines.drake.jump_means`), here below ``1e-13``.
SETTLED = 1e-6
#: Targets on one plateau between two tables from which it gets a table of its own: a
#: table costs about 5 ms of CPU, a target left to the caller's path about 0.2 ms (with
#: 128, 1451 of the benchmark's 10^5 targets by overlap, g = 0, were left: 0.29 s).
MIN_PLATEAU = 32
#: Chebyshev nodes of a plateau's table across it (its step's share of the way).
PLATEAU_NODES = 6
_SECANT = 60  # secant steps at most for a plateau node's damping
#: Designs evaluated together: their arrays stay below 4 MiB, which NumPy asks the
#: kernel to back with huge pages; with the default ``defrag=madvise`` each such fault
#: can stall on compaction (10^5 designs at once: 1.4 s of CPU in a call, 1.05 s in parts).
_EVALUATED = 32_768
_TABLE_DIFF = 1e-6  # the differences of a start's Jacobian off its table (relative)


class Starts(NamedTuple):
    """The table's starts of the targets its one evaluation did not keep
    (:func:`table_designs`): the designs read off it, ``s = d v`` and ``w = h
    sqrt(k/m)``, and by largest overlap ``jac``, the Jacobian ``n x 2 x 2`` of the
    target's restitution and size ``(e, q)`` in ``(s, w)``, from the table's differences
    (``nan`` where none: by contact time, no table, a plateau's, or a difference leaving
    the table)."""

    s: np.ndarray
    w: np.ndarray
    jac: np.ndarray


def table_designs(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, g: np.ndarray, q: np.ndarray, h: float,
    design: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    *, steps: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Starts]:  # fmt: skip
    """``(ok, k, d, summaries, starts)`` of the targets ``(e, q)`` (restitution, and
    contact time in steps or, given ``steps``, largest overlap over ``v h``) that share
    ``g / v``, read off the tables of their end states where those serve enough targets,
    each confirmed by one exact evaluation (module docstring); ``ok`` marks the targets
    designed here, ``summaries`` their phase summaries (``nan`` elsewhere), ``starts``
    the table's designs of those its evaluation did not keep, with the Jacobian of the
    targets in them (:class:`Starts`: where the one-change structure fails next to the
    ends of the phase interval, the design is still close to the table's).
    ``design(e, q)`` gives the exact designs ``(s, w)`` by contact time in steps of the
    tables' nodes (``nan`` where it has none) for the first target's ``m, v, g``. By
    largest overlap, ``steps`` are the designs' contact times in steps about (within a
    step or so): each target asks the table of that end state, then those of its two
    neighbours.
    """
    by_overlap = steps is not None
    n = e.size
    ok, k, d = np.zeros(n, bool), np.full(n, np.nan), np.full(n, np.nan)
    summaries = np.full((SUMMARY_FIELDS, n), np.nan)
    likely = np.floor((q if steps is None else steps) - 0.5)
    offsets = ((0.0,), (-1.0, 1.0)) if by_overlap else ((0.0,),)  # asked in turn
    asks = likely[None, :] + np.array([o for group in offsets for o in group])[:, None]
    keys = _keys(e, asks)
    windows = PHASES_PRESSED if g[0] > 0 else PHASES
    keys, tables = _built(keys, e, windows, design, (m[0], v[0], g[0]), h, by_overlap)
    s, w, change = (np.full(n, np.nan) for _ in range(3))
    source = np.full(n, -1)  # the table each start was read off (-1: a plateau's, or none)
    served = [np.flatnonzero(serves) for _, _, serves in keys]
    for group in offsets:  # the likely end state's table first: fewer phases to solve
        _read_in_turn(group, likely, keys, tables, served, e, q, by_overlap, (s, w, change, source))
    if by_overlap:  # the designs on a plateau between two tables
        _plateau_starts(e, q, likely, keys, tables, (m[0], v[0], g[0]), h, s, w, change)
    live = np.flatnonzero(np.isfinite(s) & np.isfinite(w))
    k_t, d_t = m[live] * (w[live] / h) ** 2, s[live] / v[live]
    rows = (a[live] for a in (m, g, v, e, q, change))
    held, summary = _confirmed(k_t, d_t, *rows, h, by_overlap)
    ok[live[held]], k[live[held]], d[live[held]] = True, k_t[held], d_t[held]
    summaries[:, live[held]] = summary[:, held]
    starts = Starts(np.full(n, np.nan), np.full(n, np.nan), np.full((n, 2, 2), np.nan))
    refused = live[~held & (source[live] >= 0)]  # (the others: a plateau's start, no table's)
    starts.s[refused], starts.w[refused] = s[refused], w[refused]
    if by_overlap:  # (by contact time the caller's differences give it)
        starts.jac[refused] = _target_slopes(keys, tables, source[refused], e[refused],
                                             q[refused], s[refused], w[refused])  # fmt: skip
    return ok, k, d, summaries, starts


def _read_in_turn(group, likely, keys, tables, served, e, q, by_overlap, out):
    """The starts ``out = (s, w, change, source)`` (in place) of the targets still
    without one whose likely end state plus one of the offsets ``group`` is a table's,
    read off those tables (``served``: the targets each serves) in turn: each target
    asks them in the order of the tables until one gives its start, as it would one
    table at a time; the tables asked in one turn read in one phase solve
    (:func:`_read`)."""
    s, w, change, source = out
    pending = []  # (each table's targets that ask it, in order)
    for b, rows in zip((key[0] for key in keys), served, strict=True):
        rows = rows[np.isnan(s[rows])]
        pending.append(rows[np.any([likely[rows] + o == b for o in group], axis=0)])
    while True:  # (each turn: every target's first table not yet asked)
        turn, later, claimed = [], [], np.zeros(e.size, bool)
        for i, rows in enumerate(pending):
            taken = claimed[rows]  # (by a table before it)
            turn += [(i, rows[~taken])] if not taken.all() else []
            later.append(rows[taken])
            claimed[rows] = True
        if not turn:
            return
        reads = [(*keys[i][:2], tables[i], e[rows], q[rows]) for i, rows in turn]
        for (i, rows), read in zip(turn, _read(reads, by_overlap), strict=True):
            s[rows], w[rows], change[rows] = read
            source[rows[np.isfinite(read[0])]] = i
        pending = [rows[np.isnan(s[rows])] for rows in later]


def _read(reads, by_overlap):
    """``(s, w, change)`` of each read ``(b, box, table, e, q)``: the designs of the
    targets ``(e, q)`` read off the table of end state ``b`` over the restitution
    ``box`` (``nan`` where the table has none), and the change in steps where it puts
    them. By overlap the phases of every read in one call
    (:func:`~impactsym.engines.drake.chebyshev_tables.phases_where`: the small reads'
    targets in one Newton iteration, whose NumPy calls cost more than their arithmetic
    on a few hundred)."""
    x = [to_unit(e, box) for _, box, _, e, _ in reads]
    # the whole phase interval: beyond a narrower window the table is extrapolated
    # (the evaluation decides; where the one change holds there, it holds them)
    ends = [(to_unit(0.0, window), to_unit(1.0, window)) for _, _, (window, _, _), _, _ in reads]
    if by_overlap:  # the phase where the table's largest overlap is the target's
        ys = phases_where([(table[2], x_i, q, ends_i) for (_, _, table, _, q), x_i, ends_i
                           in zip(reads, x, ends, strict=True)])  # fmt: skip
    else:
        ys = [to_unit(q - 0.5 - b, table[0]) for b, _, table, _, q in reads]
    out = []
    for (b, _, (window, coef, _), _, _), x_i, (lo, hi), y in zip(reads, x, ends, ys, strict=True):
        y = np.where((y >= lo) & (y < hi), y, np.nan)
        out.append((*evaluate(coef, x_i, y), b + 0.5 + from_unit(y, window)))  # (change: steps)
    return out


def _target_slopes(keys, tables, index, e, q, s, w):
    """The Jacobians ``n x 2 x 2`` of the targets by largest overlap ``(e, q)`` in the
    designs ``(s, w)`` read off the tables ``index``: the inverse of each table's forward
    differences of ``(s, w)`` in ``(e, q)`` (:data:`_TABLE_DIFF`, relative to the table's
    box and the size), every table's two reads in one phase solve (:func:`_read`)."""
    tabled = [(i, np.flatnonzero(index == i)) for i in np.unique(index)]
    de, dq, reads = np.empty(e.size), _TABLE_DIFF * q, []
    for i, rows in tabled:
        (b, box, _), table = keys[i], tables[i]
        de[rows] = _TABLE_DIFF * (box[1] - box[0])
        reads += [(b, box, table, e[rows] + de[rows], q[rows]),
                  (b, box, table, e[rows], q[rows] + dq[rows])]  # fmt: skip
    s_e, w_e, s_q, w_q = (np.empty(e.size) for _ in range(4))
    read = _read(reads, True)
    for k, (_, rows) in enumerate(tabled):
        (s_e[rows], w_e[rows], _), (s_q[rows], w_q[rows], _) = read[2 * k : 2 * k + 2]
    ds_de, ds_dq = (s_e - s) / de, (s_q - s) / dq
    dw_de, dw_dq = (w_e - w) / de, (w_q - w) / dq
    with np.errstate(all="ignore"):  # (the 2 x 2 inverse; nan where a read failed)
        inverse = np.array([[dw_dq, -ds_dq], [-dw_de, ds_de]]) / (ds_de * dw_dq - ds_dq * dw_de)
    return np.moveaxis(inverse, 2, 0)


def may_fill_a_table(
    e: np.ndarray, q: np.ndarray, *, by_overlap: bool,
    scales: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> bool:  # fmt: skip
    """Whether the targets ``(e, q)`` of one ``g / v`` (``q`` the size in steps) may get
    tables: :data:`MIN_SERVED` of them, :data:`MIN_TARGETS` in one end state ``B =
    floor(q - 1/2)`` by contact time, ``by_overlap`` within :data:`CROWD` end states of
    the continuous law's contact time without gravity (the discrete one lies within a
    step or two; the likely end state asks its neighbours' tables too). Else no table,
    and by overlap no coarse table of the caller's for their likely end states (it cost
    30 % of a call of 512 targets over 50 steps, for nothing). ``scales``:
    :func:`~impactsym.engines.drake.continuous.free_scales` of ``e`` where the caller
    has them."""
    if e.size < MIN_SERVED:
        return False
    steps = q
    if by_overlap:  # the contact time in steps of the continuous design of overlap q
        _, tau0, z0 = free_scales(e) if scales is None else scales
        steps = tau0 / z0 * q
    states, counts = np.unique(np.floor(steps - 0.5), return_counts=True)
    before = np.concatenate([[0], np.cumsum(counts)])
    upto = np.searchsorted(states, states + (CROWD if by_overlap else 1))
    return bool((before[upto] - before[:-1]).max() >= MIN_TARGETS)


def _keys(e, asks):
    """``(end state, restitution box, targets served)`` of each table: the end states
    asked, each's targets' restitutions within :data:`RESTITUTIONS` in boxes
    (:func:`_boxes`), where a box serves at least :data:`MIN_TARGETS`, and none unless
    those serve :data:`MIN_SERVED` together."""
    keys, served = [], np.zeros(e.size, bool)
    inside = (e >= RESTITUTIONS[0]) & (e <= RESTITUTIONS[1])
    for b in np.unique(asks[np.isfinite(asks) & (asks >= MIN_STEPS)]):
        asking = (asks == b).any(axis=0) & inside
        if not asking.any():
            continue
        for box in _boxes(e[asking]):
            serves = asking & (e >= box[0]) & (e <= box[1])
            if np.count_nonzero(serves) >= MIN_TARGETS:
                keys.append((b, box, serves))
                served |= serves
    return keys if np.count_nonzero(served) >= MIN_SERVED else []


def _confirmed(k, d, m, g, v, e, q, change, h, by_overlap):
    """``(held, summary)``: where the designs ``(k, d)`` meet their targets ``(e, q)`` by
    one exact evaluation of the change's equations at ``change`` (steps; module
    docstring) that the full contact confirms, and their phase summaries
    (:func:`~impactsym.engines.drake.jump_means.jump_summary`, ``(8, size)``)."""
    held, summary = np.zeros(k.size, bool), np.empty((SUMMARY_FIELDS, k.size))
    for lo in range(0, k.size, _EVALUATED):  # (in parts: _EVALUATED)
        part = slice(lo, lo + _EVALUATED)
        r, held[part] = jump_summary(*(a[part] for a in (k, d, m, g, v)), h, change[part],
                                     deepest_last=by_overlap, nodes=NODES)  # fmt: skip
        summary[:, part] = r.stacked()
    r = PhaseSummary(*summary)
    steps = r.contact_time / h
    # by overlap: the overlap, and the change where the table put it (on a plateau, at
    # phase 0: every phase ends at the state ``change - 1/2``)
    size = r.max_penetration / (v * h) if by_overlap else steps
    with np.errstate(invalid="ignore"):  # (nan where the structure does not hold)
        held &= (np.abs(r.restitution - e) <= TOLERANCE[0]) & (np.abs(size - q) <= TOLERANCE[1] * q)
        if by_overlap:
            held &= np.abs(steps - change) <= SETTLED
    return held, summary


def _plateau_starts(e, q, likely, keys, tables, member, h, s, w, change):
    """The starts ``s, w, change`` (in place) of the targets by largest overlap ``q`` left
    without one (their ``likely`` end states within two of the plateau's) whose overlap
    lies between two tables of neighbouring end states ``B`` and ``B + 1`` over the whole
    phase interval: their designs lie on the plateau between
    (every phase ends at ``N = B + 1``), read off a table of its own
    (:func:`_plateau_tables`) where at least :data:`MIN_PLATEAU` targets lie on it: at
    ``change = N + 1/2``, the phase 0 of ``N``'s change."""
    whole = {}  # end state: its tables over the whole phase interval
    for (b, box, _), table in zip(keys, tables, strict=True):
        if table[0] == (0.0, 1.0):
            whole.setdefault(b, []).append((box, table))
    plateaus = []  # (state, box, ends, rows)
    for b, lower in whole.items():
        for (box_l, (_, coef_l, over_l)), (box_u, (_, coef_u, over_u)) in product(
            lower, whole.get(b + 1, [])
        ):
            box = (max(box_l[0], box_u[0]), min(box_l[1], box_u[1]))
            near = np.abs(likely - b - 0.5) <= 2.0  # (the others: another plateau's)
            rows = np.flatnonzero(np.isnan(s) & near & (e >= box[0]) & (e <= box[1]))
            # deeper than the lower table at phase 1, shallower than the upper at phase 0
            top = largest(over_l, to_unit(e[rows], box_l), 1.0)
            bottom = largest(over_u, to_unit(e[rows], box_u), -1.0)
            rows = rows[(q[rows] > top) & (q[rows] < bottom)]
            if rows.size >= MIN_PLATEAU:
                ends = ((coef_l, box_l, 1.0), (coef_u, box_u, -1.0))
                plateaus.append((int(b) + 1, box, ends, rows))
    built = _plateau_tables([p[:3] for p in plateaus], member, h)
    for (state, box, _, rows), table in zip(plateaus, built, strict=True):
        rows = rows[np.isnan(s[rows])]  # (one plateau's each)
        if table is None or rows.size == 0:
            continue
        x = to_unit(e[rows], box)
        y = phase_where(table[1], x, q[rows])
        s[rows], w[rows] = evaluate(table[0], x, np.where(np.abs(y) <= 1.0, y, np.nan))
        change[rows] = state + 0.5  # every phase ends at the state


def _plateau_tables(plateaus, member, h):
    """``(coef, overlaps)`` (as :func:`_tables`) of each plateau ``(state, box, ends)``
    where every phase ends at ``state``, over the restitution ``box`` and its width
    ``t`` in ``(0, 1)``: at each restitution node the step ``w`` runs from the lower
    table's design at phase 1 to the upper's at phase 0 (``ends``: each table's
    coefficients, box and phase), and the damping is the root of the one state's mean
    restitution by the secant from the line between the two (:func:`_plateau_damping`,
    for every plateau's nodes at once: one by one, NumPy's cost per call on a few hundred
    nodes was most of it); ``None`` where a node has none or a tail is above
    :data:`TAIL`."""
    width = from_unit(chebyshev_points(PLATEAU_NODES), (0.0, 1.0))
    shape = (NODES_E, PLATEAU_NODES)
    nodes = []  # (e, s, w, state) of each plateau's nodes
    for state, box, ends in plateaus:
        e_nodes = from_unit(chebyshev_points(NODES_E), box)
        (s1, w1), (s0, w0) = (
            evaluate(coef, to_unit(e_nodes, where), np.full(NODES_E, y)) for coef, where, y in ends
        )
        w = w1[:, None] + width[None, :] * (w0 - w1)[:, None]
        s = s1[:, None] + width[None, :] * (s0 - s1)[:, None]
        nodes.append((np.repeat(e_nodes, PLATEAU_NODES), s.ravel(), w.ravel(),
                      np.full(s.size, state)))  # fmt: skip
    if not nodes:
        return []
    e, s, w, state = (np.concatenate(a) for a in zip(*nodes, strict=True))
    s = _plateau_damping(e, s, w, state, member, h).reshape(-1, *shape)
    w = w.reshape(-1, *shape)
    out = [fit(np.stack([s[i], w[i]]), TAIL) if np.isfinite(s[i]).all() else None
           for i in range(len(plateaus))]  # fmt: skip
    todo = [i for i, c in enumerate(out) if c is not None and not isinstance(c, str)]
    found = _overlaps([(s[i], w[i], plateaus[i][0] - 1) for i in todo], member, h)
    for i, overlaps in zip(todo, found, strict=True):
        out[i] = None if isinstance(overlaps, str) else (out[i], overlaps)
    return [c if isinstance(c, tuple) else None for c in out]


def _plateau_damping(e, s, w, state, member, h):
    """The damping numbers at which the mean restitution of the contacts ``(s, w)`` that
    all end at ``state`` (per contact; :func:`~impactsym.engines.drake.jump_means.jump_means`'
    one state's integral) is ``e``: secant steps from ``s``, each contact's until it is
    met to ``1e-15``, or to ``1e-14`` and no longer closer (rounding: a node may hover
    at ``2e-15``), at most :data:`_SECANT` (``nan`` where not met to ``1e-14``)."""
    m, v, g = member

    def f(s, i):
        k, d = m * (w[i] / h) ** 2, s / v
        one = np.ones(i.size)
        return jump_means(k, d, m * one, g * one, v * one, h, state[i] + 0.5,
                          nodes=NODES).fixed - e[i]  # fmt: skip

    s = s.copy()
    everyone = np.arange(e.size)
    f_s = f(s, everyone)
    s_prev, f_prev = s * (1.0 + 1e-6), f(s * (1.0 + 1e-6), everyone)
    live = np.flatnonzero(np.abs(f_s) > 1e-15)
    with np.errstate(all="ignore"):
        for _ in range(_SECANT):
            if live.size == 0:
                break
            step = f_s[live] * (s[live] - s_prev[live]) / (f_s[live] - f_prev[live])
            s_prev[live], f_prev[live] = s[live], f_s[live]
            s[live] -= np.where(np.isfinite(step), step, 0.0)
            f_s[live] = f(s[live], live)
            off = np.abs(f_s[live])
            live = live[(off > 1e-15) & ((off < np.abs(f_prev[live])) | (off > 1e-14))]
    return np.where(np.abs(f_s) <= 1e-14, s, np.nan)


def _built(keys, e, windows, design, member, h, by_overlap):
    """The tables of the ``keys`` (:func:`_keys`): ``(keys, tables)``, each table
    ``((lo, hi), coef, overlaps)`` (:func:`_tables`) over the first phase ``window``
    whose tail in the phase holds (none left: given up; halving it again cost a call of
    tables that all fail, under ``g = 30``, a third more). A table refused otherwise (a
    node not designed, a tail in the restitution: the caller's path or the one-change
    structure can fail at one end of a box only) is built again as the two halves of
    its box that still serve :data:`MIN_TARGETS`. Three rounds at most."""
    pending, done = [(key, 0) for key in keys], []
    for _ in range(3):
        retry = []
        for index in sorted({i for _, i in pending}):
            batch = [key for key, i in pending if i == index]
            built = _tables(batch, windows[index], design, member, h, by_overlap)
            for key, table in zip(batch, built, strict=True):
                if not isinstance(table, str):
                    done.append((key, (windows[index], *table)))
                elif table == "phase":  # (no narrower window left: given up)
                    retry.extend([(key, index + 1)] if index + 1 < len(windows) else [])
                else:
                    retry.extend((half, index) for half in _halves(key, e))
        pending = retry
    return [key for key, _ in done], [table for _, table in done]


def _halves(key, e):
    """The key's box cut in two halves, those that serve at least :data:`MIN_TARGETS` of
    the targets' restitutions ``e``."""
    b, (lo, hi), serves = key
    halves = [(b, (x, y), serves & (e >= x) & (e <= y))
              for x, y in ((lo, 0.5 * (lo + hi)), (0.5 * (lo + hi), hi))]  # fmt: skip
    return [half for half in halves if np.count_nonzero(half[2]) >= MIN_TARGETS]


def _tables(keys, phases, design, member, h, by_overlap):
    """Each table (``keys``: end state, restitution box, targets) over the ``phases``:
    ``(coef, overlaps)``, the Chebyshev coefficients ``(2, NODES_E, NODES_PHASE)`` of
    ``(s, w)`` (by overlap :data:`NODES_PHASE_OVERLAP` in the phase) and, ``by_overlap``,
    those ``(J, NODES_E, NODES_PHASE_OVERLAP)`` of the overlaps
    over ``v h`` of the states that can be deepest (:func:`_overlaps`; else ``None``),
    from one call of ``design`` for every node; where refused, why: ``"nodes"`` (a node
    not designed), ``"phase"`` or ``"restitution"`` (the direction of a tail above
    :data:`TAIL`)."""
    count = NODES_PHASE_OVERLAP if by_overlap else NODES_PHASE
    x_e, node_phase = chebyshev_points(NODES_E), from_unit(chebyshev_points(count), phases)
    node_e = np.concatenate([np.repeat(from_unit(x_e, box), count) for _, box, _ in keys])
    node_q = np.concatenate([np.tile(b + 0.5 + node_phase, NODES_E) for b, _, _ in keys])
    shape = (len(keys), NODES_E, count)
    s, w = (a.reshape(shape) for a in design(node_e, node_q))
    out = []
    for i in range(len(keys)):
        finite = np.isfinite(s[i]).all() and np.isfinite(w[i]).all()
        out.append(fit(np.stack([s[i], w[i]]), TAIL) if finite else "nodes")
    if not by_overlap:
        return [c if isinstance(c, str) else (c, None) for c in out]
    todo = [i for i, c in enumerate(out) if not isinstance(c, str)]
    found = _overlaps([(s[i], w[i], int(keys[i][0])) for i in todo], member, h)
    for i, overlaps in zip(todo, found, strict=True):
        out[i] = overlaps if isinstance(overlaps, str) else (out[i], overlaps)
    return out


def _overlaps(tables, member, h):
    """For each table's node designs ``(s, w, base)`` (``s``, ``w``: ``NODES_E x
    count``) the Chebyshev coefficients
    (:func:`~impactsym.engines.drake.chebyshev_tables.fit`) of the overlaps (over ``v
    h``) of the states ``j0 ... j1`` at the last grid phase, the states that are deepest
    at some node and one more on either side. Each is smooth in the design, their
    largest (the largest overlap,
    :func:`~impactsym.engines.drake.jump_means.last_overlap`, the numbers of the same
    update) is not: which state is deepest changes. Every table's nodes in one run
    (:func:`~impactsym.engines.drake.stepping.states_through`, to the last table's end
    state; one run per table cost NumPy's per-call price at each step of 100-odd
    nodes)."""
    if not tables:
        return []
    m, v, g = member
    s, w = (np.concatenate([t[i].ravel() for t in tables]) for i in (0, 1))
    k, d = m * (w / h) ** 2, s / v
    # the states before the end state B + 1, and it
    x = states_through(k, d, m, g, v, h, GRID_PHASES[-1], max(t[2] for t in tables) + 2)
    x /= v * h
    out, start = [], 0
    for s_t, _, base in tables:
        rows = x[start : start + s_t.size, : base + 2]
        start += s_t.size
        deepest = np.argmax(rows, axis=1)
        j0, j1 = max(int(deepest.min()) - 1, 0), min(int(deepest.max()) + 1, base)
        out.append(fit(np.moveaxis(rows[:, j0 : j1 + 1].reshape(*s_t.shape, -1), 2, 0), TAIL))
    return out


def _boxes(e):
    """The restitution boxes of the tables of one end state: the range of its targets'
    ``e`` cut into equal boxes at most :data:`WIDTH` wide (a point widened a little)."""
    a, b = float(e.min()), float(e.max())
    pad = max(0.0, 1e-6 - 0.5 * (b - a))
    a, b = a - pad, b + pad
    edges = np.linspace(a, b, int(np.ceil((b - a) / WIDTH)) + 1)
    return list(pairwise(edges))
