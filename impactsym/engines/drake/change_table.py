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
  tables of that end state and both neighbours. A table also holds the overlap (over
  ``v h``) at the last grid phase of each state that is deepest at some node, and one
  more on either side: each is smooth in the design, their largest, the largest overlap
  (:func:`~impactsym.engines.drake.jump_means.last_overlap`), is not (which state is
  deepest changes; one table of the largest was ``2e-5`` off). The target's phase is
  where their largest meets its overlap (:func:`_phase_of`). A target whose overlap lies
  between the tables of ``B`` (at phase 1) and ``B + 1`` (at phase 0) has its design on
  the plateau between, where every phase ends at ``N = B + 1``: where at least
  :data:`MIN_PLATEAU` do, the plateau gets a table of its own over the restitution and
  the step's share of the way from one edge to the other (the edges' designs off the
  two tables), each node's damping the secant root of that one state's mean
  (:func:`_plateau_table`). Without gravity only: under it no window reaches the ends
  of the phase interval.
* **One exact evaluation** per design read off:
  :func:`~impactsym.engines.drake.jump_means.jump_summary` at the table's design, with
  :data:`NODES` Gauss nodes per panel (the change's equations, the phase grid's full
  contacts, every node's end state, the margins between samples). The design is done
  where that summary holds, its restitution is within :data:`TOLERANCE` of the target
  and its size within its relative tolerance (by overlap: its largest overlap, and the
  change's estimate within :data:`SETTLED` of where the table put it); the summary is
  then the design's prediction. The others are left to the caller.

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

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawtable import chebyshev_points, chebyshev_transform
from impactsym.engines.drake.continuous import free_scales
from impactsym.engines.drake.jump_means import jump_means, jump_summary
from impactsym.engines.drake.phases import GRID_PHASES, SUMMARY_FIELDS
from impactsym.engines.drake.stepping import states_through
from impactsym.numeric.roots import bracketed_newton

__all__ = [
    "CROWD",
    "MIN_PLATEAU",
    "MIN_SERVED",
    "MIN_STEPS",
    "MIN_TARGETS",
    "NODES",
    "NODES_E",
    "NODES_PHASE",
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
#: Gauss nodes per panel of the one exact evaluation: against 16, the mean restitution
#: of 3000 random designs of 10-60 steps (gravity 0 and 9.81, where the change held) moved
#: by ``4e-16`` at most with 5 (``4e-13`` with 4; :mod:`~impactsym.engines.drake.jump_means`
#: takes 8, for contacts of any length).
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
#: Targets on one plateau between two tables from which it gets a table of its own.
MIN_PLATEAU = 128
_SECANT = 60  # secant steps at most for a plateau node's damping


def table_designs(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, g: np.ndarray, q: np.ndarray, h: float,
    design: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
    *, steps: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(ok, k, d, summaries)`` of the targets ``(e, q)`` (restitution, and contact time
    in steps or, given ``steps``, largest overlap over ``v h``) that share ``g / v``,
    read off the tables of their end states where those serve enough targets, each
    confirmed by one exact evaluation (module docstring); ``ok`` marks the targets
    designed here, ``summaries`` their phase summaries (``nan`` elsewhere).
    ``design(e, q)`` gives the exact designs ``(s, w)`` by contact time in steps of the
    tables' nodes (``nan`` where it has none) for the first target's ``m, v, g``. By
    largest overlap, ``steps`` are the designs' contact times in steps about (within a
    step or so): each target asks the tables of that end state and its two neighbours.
    """
    by_overlap = steps is not None
    n = e.size
    ok, k, d = np.zeros(n, bool), np.full(n, np.nan), np.full(n, np.nan)
    summaries = np.full((SUMMARY_FIELDS, n), np.nan)
    if by_overlap:  # each target asks its likely end state and its neighbours
        asks = np.floor(steps - 0.5)[None, :] + np.array([-1.0, 0.0, 1.0])[:, None]
    else:
        asks = np.floor(q - 0.5)[None, :]
    keys = _keys(e, asks)
    windows = PHASES_PRESSED if g[0] > 0 else PHASES
    keys, tables = _built(keys, e, windows, design, (m[0], v[0], g[0]), h, by_overlap)
    s, w, change = (np.full(n, np.nan) for _ in range(3))
    for (b, box, serves), ((lo, hi), coef, overlaps) in zip(keys, tables, strict=True):
        rows = np.flatnonzero(serves & np.isnan(s))
        x = _unit(e[rows], box)
        # the whole phase interval: beyond a narrower window the table is extrapolated
        # (the evaluation decides; where the one change holds there, it holds them)
        ends = (_unit(0.0, (lo, hi)), _unit(1.0, (lo, hi)))
        # by overlap: the phase where the table's largest overlap is the target's
        y = (_phase_of(overlaps, x, q[rows], ends) if by_overlap
             else _unit(q[rows] - 0.5 - b, (lo, hi)))  # fmt: skip
        y = np.where((y >= ends[0]) & (y < ends[1]), y, np.nan)
        s[rows], w[rows] = _evaluate(coef, x, y)
        change[rows] = b + 0.5 + _within(y, (lo, hi))  # in steps
    if by_overlap:  # the designs on a plateau between two tables
        _plateau_starts(e, q, keys, tables, (m[0], v[0], g[0]), h, s, w, change)
    live = np.flatnonzero(np.isfinite(s) & np.isfinite(w))
    k_t, d_t = m[live] * (w[live] / h) ** 2, s[live] / v[live]
    rows = (a[live] for a in (m, g, v, e, q, change))
    held, summary = _confirmed(k_t, d_t, *rows, h, by_overlap)
    live = live[held]
    ok[live], k[live], d[live] = True, k_t[held], d_t[held]
    summaries[:, live] = summary[:, held]
    return ok, k, d, summaries


def may_fill_a_table(e: np.ndarray, q: np.ndarray, *, by_overlap: bool) -> bool:
    """Whether the targets ``(e, q)`` of one ``g / v`` (``q`` the size in steps) may get
    tables: :data:`MIN_SERVED` of them, :data:`MIN_TARGETS` in one end state ``B =
    floor(q - 1/2)`` by contact time, ``by_overlap`` within :data:`CROWD` end states of
    the continuous law's contact time without gravity (the discrete one lies within a
    step or two; the likely end state asks its neighbours' tables too). Else no table,
    and by overlap no coarse table of the caller's for their likely end states (it cost
    30 % of a call of 512 targets over 50 steps, for nothing)."""
    if e.size < MIN_SERVED:
        return False
    steps = q
    if by_overlap:  # the contact time in steps of the continuous design of overlap q
        _, tau0, z0 = free_scales(e)
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
    if k.size == 0:
        return np.zeros(0, bool), np.empty((SUMMARY_FIELDS, 0))
    r, held = jump_summary(k, d, m, g, v, h, change, deepest_last=by_overlap, nodes=NODES)
    steps = r.contact_time / h
    # by overlap: the overlap, and the change where the table put it (on a plateau, at
    # phase 0: every phase ends at the state ``change - 1/2``)
    size = r.max_penetration / (v * h) if by_overlap else steps
    with np.errstate(invalid="ignore"):  # (nan where the structure does not hold)
        held &= (np.abs(r.restitution - e) <= TOLERANCE[0]) & (np.abs(size - q) <= TOLERANCE[1] * q)
        if by_overlap:
            held &= np.abs(steps - change) <= SETTLED
    return held, r.stacked()


def _plateau_starts(e, q, keys, tables, member, h, s, w, change):
    """The starts ``s, w, change`` (in place) of the targets by largest overlap ``q`` left
    without one whose overlap lies between two tables of neighbouring end states ``B``
    and ``B + 1`` over the whole phase interval: their designs lie on the plateau between
    (every phase ends at ``N = B + 1``), read off a table of its own
    (:func:`_plateau_table`) where at least :data:`MIN_PLATEAU` targets lie on it: at
    ``change = N + 1/2``, the phase 0 of ``N``'s change."""
    whole = {}  # end state: its tables over the whole phase interval
    for (b, box, _), table in zip(keys, tables, strict=True):
        if table[0] == (0.0, 1.0):
            whole.setdefault(b, []).append((box, table))
    for b, lower in whole.items():
        for (box_l, (_, coef_l, over_l)), (box_u, (_, coef_u, over_u)) in product(
            lower, whole.get(b + 1, [])
        ):
            box = (max(box_l[0], box_u[0]), min(box_l[1], box_u[1]))
            rows = np.flatnonzero(np.isnan(s) & (e >= box[0]) & (e <= box[1]))
            # deeper than the lower table at phase 1, shallower than the upper at phase 0
            top = _largest(over_l, _unit(e[rows], box_l), 1.0)
            bottom = _largest(over_u, _unit(e[rows], box_u), -1.0)
            rows = rows[(q[rows] > top) & (q[rows] < bottom)]
            if rows.size < MIN_PLATEAU:
                continue
            ends = ((coef_l, box_l, 1.0), (coef_u, box_u, -1.0))
            table = _plateau_table(int(b) + 1, box, ends, member, h)
            if table is None:
                continue
            x = _unit(e[rows], box)
            y = _phase_of(table[1], x, q[rows])
            s[rows], w[rows] = _evaluate(table[0], x, np.where(np.abs(y) <= 1.0, y, np.nan))
            change[rows] = b + 1.5  # every phase ends at b + 1


def _plateau_table(state, box, ends, member, h):
    """``(coef, overlaps)`` (as :func:`_tables`) of the plateau where every phase ends at
    ``state``, over the restitution ``box`` and its width ``t`` in ``(0, 1)``: at each
    restitution node the step ``w`` runs from the lower table's design at phase 1 to the
    upper's at phase 0 (``ends``: each table's coefficients, box and phase), and the
    damping is the root of the one state's mean restitution by the secant from the
    line between the two (:func:`_plateau_damping`); ``None`` where a node has none or a
    tail is above :data:`TAIL`."""
    e_nodes = _within(chebyshev_points(NODES_E), box)
    width = _within(chebyshev_points(NODES_PHASE), (0.0, 1.0))
    (s1, w1), (s0, w0) = (
        _evaluate(coef, _unit(e_nodes, where), np.full(NODES_E, y)) for coef, where, y in ends
    )
    w = w1[:, None] + width[None, :] * (w0 - w1)[:, None]
    s = s1[:, None] + width[None, :] * (s0 - s1)[:, None]
    s = _plateau_damping(np.repeat(e_nodes, NODES_PHASE), s.ravel(), w.ravel(), state,
                         member, h).reshape(w.shape)  # fmt: skip
    if not np.isfinite(s).all():
        return None
    coef = _coefficients(np.stack([s, w]))
    overlaps = _overlaps(s, w, state - 1, member, h)
    refused = isinstance(coef, str) or isinstance(overlaps, str)
    return None if refused else (coef, overlaps)


def _plateau_damping(e, s, w, state, member, h):
    """The damping numbers at which the mean restitution of the contacts ``(s, w)`` that
    all end at ``state`` (:func:`~impactsym.engines.drake.jump_means.jump_means`' one
    state's integral) is ``e``: secant steps from ``s`` (``nan`` where they do not meet
    it to ``1e-14``)."""
    m, v, g = member
    one = np.ones(e.size)

    def f(s):
        k, d = m * (w / h) ** 2, s / v
        return jump_means(k, d, m * one, g * one, v * one, h, (state + 0.5) * one,
                          nodes=NODES).fixed - e  # fmt: skip

    f_s = f(s)
    s_prev, f_prev = s * (1.0 + 1e-6), f(s * (1.0 + 1e-6))
    with np.errstate(all="ignore"):
        for _ in range(_SECANT):
            step = f_s * (s - s_prev) / (f_s - f_prev)
            s_prev, f_prev = s, f_s
            s = s - np.where(np.isfinite(step), step, 0.0)
            f_s = f(s)
            if np.all(np.abs(f_s) <= 1e-15):
                break
    return np.where(np.abs(f_s) <= 1e-14, s, np.nan)


def _largest(coef, x, y):
    """The largest of the overlap tables ``coef`` at the restitutions ``x`` (in
    ``[-1, 1]``) and the phase ``y`` (``-1`` or ``1``)."""
    return _evaluate(coef, x, np.full(x.size, y)).max(axis=0)


def _unit(e, box):
    """The points ``e`` of the ``box`` mapped to ``[-1, 1]`` (the tables' variables)."""
    return (2.0 * e - (box[0] + box[1])) / (box[1] - box[0])


def _within(y, box):
    """The points ``y`` of ``[-1, 1]`` mapped into the ``box`` (:func:`_unit`'s inverse)."""
    return 0.5 * (box[0] + box[1]) + 0.5 * (box[1] - box[0]) * y


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
    ``(s, w)`` and, ``by_overlap``, those ``(J, NODES_E, NODES_PHASE)`` of the overlaps
    over ``v h`` of the states that can be deepest (:func:`_overlaps`; else ``None``),
    from one call of ``design`` for every node; where refused, why: ``"nodes"`` (a node
    not designed), ``"phase"`` or ``"restitution"`` (the direction of a tail above
    :data:`TAIL`)."""
    x_e, node_phase = chebyshev_points(NODES_E), _within(chebyshev_points(NODES_PHASE), phases)
    node_e = np.concatenate([np.repeat(_within(x_e, box), NODES_PHASE) for _, box, _ in keys])
    node_q = np.concatenate([np.tile(b + 0.5 + node_phase, NODES_E) for b, _, _ in keys])
    shape = (len(keys), NODES_E, NODES_PHASE)
    s, w = (a.reshape(shape) for a in design(node_e, node_q))
    out = []
    for i, (base, _, _) in enumerate(keys):
        if not (np.isfinite(s[i]).all() and np.isfinite(w[i]).all()):
            out.append("nodes")
            continue
        coef = _coefficients(np.stack([s[i], w[i]]))
        if by_overlap and not isinstance(coef, str):
            overlaps = _overlaps(s[i], w[i], int(base), member, h)
            out.append(overlaps if isinstance(overlaps, str) else (coef, overlaps))
        else:
            out.append(coef if isinstance(coef, str) else (coef, None))
    return out


def _overlaps(s, w, base, member, h):
    """The Chebyshev coefficients (:func:`_coefficients`) of the overlaps (over ``v h``)
    of the states ``j0 ... j1`` at the last grid phase of the nodes' designs ``(s, w)``
    (``NODES_E x NODES_PHASE``), the states that are deepest at some node and one more
    on either side. Each is smooth in the design, their largest (the largest overlap,
    :func:`~impactsym.engines.drake.jump_means.last_overlap`, the numbers of the same
    update) is not: which state is deepest changes."""
    m, v, g = member
    k, d = m * (w.ravel() / h) ** 2, s.ravel() / v
    # the states before the end state B + 1, and it
    x = states_through(k, d, m, g, v, h, GRID_PHASES[-1], base + 2) / (v * h)
    deepest = np.argmax(x, axis=1)
    j0, j1 = max(int(deepest.min()) - 1, 0), min(int(deepest.max()) + 1, base)
    values = np.moveaxis(x[:, j0 : j1 + 1].reshape(NODES_E, NODES_PHASE, -1), 2, 0)
    return _coefficients(values)


def _coefficients(values):
    """Chebyshev coefficients ``(fields, NODES_E, NODES_PHASE)`` of the node values, or
    where the last two degrees of a field in either direction sum above :data:`TAIL` of
    its largest value, the direction of the larger such tail: ``"restitution"`` or
    ``"phase"``."""
    m_e, m_p = chebyshev_transform(NODES_E), chebyshev_transform(NODES_PHASE)
    coef = np.einsum("ij,fjk,lk->fil", m_e, values, m_p)
    top = np.abs(values).max(axis=(1, 2))
    tail_e = (np.abs(coef[:, -2:, :]).sum(axis=(1, 2)) / top).max()
    tail_phase = (np.abs(coef[:, :, -2:]).sum(axis=(1, 2)) / top).max()
    if max(tail_e, tail_phase) <= TAIL:
        return coef
    return "phase" if tail_phase >= tail_e else "restitution"


def _phase_of(coef, x, target, ends=(-1.0, 1.0)):
    """The phase ``y`` between ``ends`` (the table's variable; the default ``[-1, 1]`` is
    its window, the phase interval's ends lie beyond a narrower one) where the largest of
    the tables ``coef`` (``(J, NODES_E, NODES_PHASE)``) at the restitutions ``x`` equals
    ``target`` (``nan`` where the ends do not bracket it): safeguarded Newton steps
    (:func:`~impactsym.numeric.roots.bracketed_newton`: the largest is not smooth where
    the deepest state changes) from the secant's root between the ends."""
    vx = chebyshev.chebvander(x, coef.shape[1] - 1)
    c = np.einsum("ij,fjk->ifk", vx, coef)  # (targets, J, phase)
    dc = chebyshev.chebder(c, axis=2)

    def f(y, rows):  # (rows: the targets' indices, as floats)
        i = rows.astype(np.int64)
        vy = chebyshev.chebvander(y, coef.shape[2] - 1)
        values = np.einsum("ifk,ik->if", c[i], vy)
        top = np.argmax(values, axis=1)
        slope = np.einsum("ik,ik->i", dc[i, top], vy[:, :-1])
        return values[np.arange(i.size), top] - target[i], slope

    everyone = np.arange(x.size, dtype=float)
    (y_a, y_b), n = ends, x.size
    f_a, _ = f(np.full(n, y_a), everyone)
    f_b, _ = f(np.full(n, y_b), everyone)
    live = np.flatnonzero((f_a <= 0.0) & (f_b >= 0.0) & (f_b > f_a))
    out = np.full(n, np.nan)
    start = y_a - (y_b - y_a) * f_a[live] / (f_b[live] - f_a[live])
    out[live] = bracketed_newton(f, None, y_a, y_b, [everyone[live]], g_lo=f_a[live],
                                 g_hi=f_b[live], start=start)  # fmt: skip
    return out


def _boxes(e):
    """The restitution boxes of the tables of one end state: the range of its targets'
    ``e`` cut into equal boxes at most :data:`WIDTH` wide (a point widened a little)."""
    a, b = float(e.min()), float(e.max())
    pad = max(0.0, 1e-6 - 0.5 * (b - a))
    a, b = a - pad, b + pad
    edges = np.linspace(a, b, int(np.ceil((b - a) / WIDTH)) + 1)
    return list(pairwise(edges))


def _evaluate(coef, x, y):
    """The tables ``coef`` (``(fields, NODES_E, NODES_PHASE)`` Chebyshev coefficients)
    at ``(x, y)`` in ``[-1, 1]^2``: ``fields`` arrays."""
    ve = chebyshev.chebvander(x, coef.shape[1] - 1)
    vp = chebyshev.chebvander(y, coef.shape[2] - 1)
    return np.einsum("ij,fjk,ik->fi", ve, coef, vp)
