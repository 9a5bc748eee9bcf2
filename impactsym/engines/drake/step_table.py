r"""Many discrete designs of one contact: a table of the phase means, then a few exact
steps per design: :func:`stepped_designs`.

At a step ``h`` the ``"tamsi"``/``"similar"``/``"lagged"`` update of
:mod:`impactsym.engines.drake.update`, in the units :math:`T = \sqrt{m/k}` and
:math:`L = v T`, depends on the damping number :math:`s = d v`, the step
:math:`w = h / T` and the pressing number :math:`b = g T / v = (g / v)\, h / w`
(``docs/physics.md``, "Drake point contact"). So the targets of one call that share
``g / v`` share two functions of ``(s, w)``: the phase-mean restitution ``E`` and the
size ``Q`` (the phase-mean contact time in steps, :math:`t_c / h`, or the largest
overlap over the phases in units of :math:`v h`), and a target ``(e, q)`` asks for
:math:`E(s, w) = e`, :math:`Q(s, w) = q`, then :math:`k = m (w / h)^2`, :math:`d = s / v`.

The targets that share an end state with many others are first read off that end
state's table of exact designs (in the restitution and the phase of the change, where
the designs are smooth; by largest overlap, the end state each asks comes from the
coarse table below), each confirmed by one exact evaluation that gives its phase summary
(:mod:`~impactsym.engines.drake.change_table`); the rest of this docstring is the path
of the others, and of the tables' own nodes.

These functions are continuous but only piecewise smooth: the mean has a kink wherever
an end step enters or leaves the phase interval (about every step of contact time), and
the contact time rests on plateaus where every phase lasts the same number of steps. So
the table does not give the designs themselves; it gives each a start and a Jacobian,
and exact evaluations finish it:

* **The tables** hold ``E`` and ``Q`` on equally spaced nodes, from one exact call of
  :func:`~impactsym.engines.drake.phases.phase_summary` (means only) each: a coarse one
  (:data:`COARSE` nodes) on a wide box, the continuous designs without gravity
  (Lambert W and the free contact time or overlap)
  :data:`~impactsym.engines.drake.means_table.WIDE` times either way (built again wider
  where many targets lie beyond its means), then a fine one (:data:`NODES_S` by
  :data:`NODES_W`) on the box of the starts the coarse one gives, widened by one coarse
  cell and :data:`~impactsym.engines.drake.means_table.MARGIN` of its width on each side
  (:mod:`~impactsym.engines.drake.means_table`).
* **The start**: on each column of the table (one ``w``) the restitution falls with the
  damping, so the contour ``E = e`` crosses it once (linear interpolation), and along the
  contour ``Q`` falls with ``w``; the first sign change of ``Q - q`` along it (linear
  interpolation again) is the start, the table's cell there gives the Jacobian.
* **The change's equations** first (:mod:`~impactsym.engines.drake.jump_means`): where
  the end state changes once over the phase, the restitution's mean is two pieces'
  integrals, smooth in ``(s, w)`` for a given phase of the change (no plateau, no
  search for it). By contact time the target itself fixes that phase. By largest
  overlap the change's estimate follows the design: moved along its slopes in ``(s, w)``
  before an evaluation, set to the evaluation's Newton estimate after it, a design done
  only once that estimate held still (:data:`_SETTLED` steps: the restitution is the
  mean to second order in its move); where the estimate leaves the phase interval
  every phase ends alike (the contact time rests on a plateau) and the mean is one end
  state's integral. The overlap is the phase summary's own sample at its last grid
  phase (:func:`~impactsym.engines.drake.jump_means.last_overlap`, one run: the deepest
  of its samples on every contact measured). Broyden's steps run from the Jacobian of
  forward differences (:data:`_DIFF` relative) of the rule :data:`_CHEAP` (one Gauss
  node on the shorter piece, three on the longer: 4 runs), good to about ``1e-6``
  (median; 3e-3 at the 99th percentile) where the table's cell, across the kinks, is
  good to about a percent. A design is done within ``1e-13`` of the restitution and
  ``1e-11`` relative of the size (a tenth of the tolerances below each, so that the
  exact phase means, which agree with the change's to ``~2e-14`` and ``~1e-12`` steps,
  meet those), and kept where the full contact confirms the change at the phase grid, and by largest
  overlap that no phase run overlaps deeper than the last
  (:func:`~impactsym.engines.drake.jump_means.jump_holds`). Measured on the
  benchmark's targets (20-40 steps; 10^4 each): 4.2-4.4 evaluations of about 27 state
  runs and three of 6 per design, against about six phase means of ~65 contact runs and
  ~19 margins with the table's Jacobian; 98-100 % of the targets kept. The others take the
  steps below from the table's start. The caller predicts every design and designs
  again, by its iteration, any that its prediction finds off the target.
* **A change table's refusals** (under gravity a second change next to the ends of the
  phase interval, about 2 % of the benchmark's targets by either size) start from the
  change table's own design (:class:`~impactsym.engines.drake.change_table.Starts`):
  where the start's end state changes twice, Broyden's steps on the equations of the
  two changes (:mod:`~impactsym.engines.drake.two_changes`; the Jacobian by differences
  of their cheap rule), at most :data:`STARTS_STEPS`, done within ``1e-13`` with the
  changes settled (the caller's prediction checks each): 0.40 s of CPU became 0.12 s
  for the benchmark's 2057 such targets by overlap, 0.46 s 0.05 s for its 1568 by
  contact time (g = 9.81). The others by overlap take the steps below from the change
  table's Jacobian, at most :data:`STARTS_STEPS` phase means; by contact time (next to
  a plateau's edge, where those steps stall) the path here.
* **The steps**: Broyden's method on the exact phase means
  (:func:`~impactsym.engines.drake.mean_steps.broyden_steps`, one
  :func:`~impactsym.engines.drake.phases.phase_summary` per step for all designs at
  once), at most :data:`STEPS` evaluations. Where a step leaves the contact time
  unchanged (it landed on a plateau) the Jacobian's row of the size is not updated: a
  zero slope would send the next step out of the box, the slope of the table's cell
  leads back to the plateau's edge. A design is done when its phase-mean
  restitution is within ``1e-12`` of the target and its size within ``1e-10`` relative
  (the tolerances of the caller's own iteration).
* **Next to a plateau's edge** (a design Broyden's steps leave) the designs are solved
  along the contour ``E = e``
  (:func:`~impactsym.engines.drake.mean_steps.contour_steps`): each step moves ``w`` and
  corrects ``s`` by Newton's step on ``E``; ``w`` first walks off the plateau, the step
  doubling, until ``Q - q`` changes sign, then Illinois steps narrow that bracket, at most
  :data:`EDGE_STEPS` phase means. A design that leaves the box, sticks, or is not done
  by then (e.g. where ``Q`` jumps: an interval of phases with another end step,
  narrower than the phase grid of :func:`~impactsym.engines.drake.phases.phase_summary`,
  reaching a grid phase) is left to the caller's iteration.

On the exact phase means the steps converge about a hundredfold each (the table's
Jacobian is good to about a percent: the kinks), so a design takes about five and a
half phase means instead of the twenty-odd of the nested iteration; a few targets in a
thousand, within a few
hundredths of a step of a plateau's edge (the contact time in steps near ``N + 1/2``),
take the contour search, and fewer still are left to the iteration. The tables cost
``16 * 16 + NODES_S * NODES_W`` phase means per group. The caller
(:func:`~impactsym.engines.drake.design.point_contact_for`) uses it for the groups of at
least :data:`MIN_CALL` targets (equal ``g / v``) of one call, a rule of the call alone:
smaller calls are designed by the iteration, as before. A group whose sizes in steps
span more than :data:`SPAN` is split into chunks of at least :data:`MIN_TARGETS` that
span at most that (where it holds enough targets), one table each: the tables' work
follows the targets, and a box over a wide span would be coarse. Under gravity the box's
corners may stick; :func:`~impactsym.engines.drake.stepping.step_contact` decides such a
settled contact within a few hundred updates (it stepped it to ``2e6`` before: 256
targets over 8-100 steps took 136 s of table, now 2 s).
"""

from __future__ import annotations

import numpy as np

from impactsym.engines.drake.change_table import NODES, may_fill_a_table, table_designs
from impactsym.engines.drake.continuous import free_scales, start_stiffness
from impactsym.engines.drake.jump_means import jump_holds, jump_means, last_overlap
from impactsym.engines.drake.mean_steps import broyden_steps, contour_steps
from impactsym.engines.drake.means_table import (
    means_table,
    reaching,
    table_at,
    wide_box,
    widened,
)
from impactsym.engines.drake.phases import SUMMARY_FIELDS, phase_summary
from impactsym.engines.drake.two_changes import two_change_rows, two_change_starts

__all__ = [
    "COARSE",
    "EDGE_STEPS",
    "MIN_CALL",
    "MIN_TARGETS",
    "NODES_S",
    "NODES_W",
    "NODE_RULE",
    "NODE_SPAN",
    "NODE_TABLE",
    "SPAN",
    "STARTS_STEPS",
    "STEPS",
    "stepped_designs",
]

#: Targets sharing ``g / v`` per call from which a table starts their designs: cheaper
#: than the iteration from a few on (0.09-0.16 s for 10-255 targets, 0.22-0.87 s), where
#: they are reached (else the iteration refuses at once: :func:`_undamped_reach`).
MIN_CALL = 8
#: Targets of one chunk at least, where a call's sizes span more than :data:`SPAN`.
MIN_TARGETS = 256
#: Largest ratio of the sizes in steps (longest over shortest) of one table's targets,
#: where a group holds enough targets to split.
SPAN = 2.0
#: Nodes of the coarse table (in the damping number and in the step) on the wide box.
COARSE = (16, 16)
#: Nodes of the fine table on the box of the starts the coarse one gives.
NODES_S, NODES_W = 32, 48
#: For the nodes of the change tables (:func:`_node_designs`): a coarser fine table and
#: the tables' own rule of Gauss nodes (contacts of ten steps or more), which
#: the change's equations converge from as well: 0.61 s of CPU became 0.41 s for the
#: 7840 nodes of the benchmark's 10^5 targets by overlap (g = 0), the designs within
#: their tolerances of the others (1.8e-11 in the stiffness, 1.6e-12 in the damping).
NODE_TABLE, NODE_RULE = (16, 24), NODES
NODE_TOL = (2e-14, 1e-11)
#: The span of the nodes' chunks: their designs start from the change's equations, which
#: converge from a coarser table as well (the benchmark's 7840 nodes of 24-73 steps in
#: one chunk: 0.34 s of CPU, in two 0.39-0.42 s; all designed either way).
NODE_SPAN = 4.0
#: Exact phase means per design at most (Broyden's steps).
STEPS = 16
#: Exact phase means at most from a change table's start (its evaluation did not keep it).
STARTS_STEPS = 6
#: Exact phase means at most along the contour for the designs next to a plateau's edge.
EDGE_STEPS = 80
_TOL = (1e-12, 1e-10)  # a design is done within these (as the iteration's)
# the designs by contact time on the equations of a change at a given phase: within these
# (a tenth and a tenth of those: the exact means agree with them to ~2e-14 and ~1e-12 steps)
_JUMP_TOL = (1e-13, 1e-11)
_SETTLED = 1e-6  # steps the change's estimate may move in a design's last evaluation
_DIFF, _CHEAP = 1e-6, {"nodes": 1}  # the differences of the change's Jacobian, their rule


def stepped_designs(
    e: np.ndarray, v: np.ndarray, m: np.ndarray, g: np.ndarray, target: np.ndarray,
    h: float, approx: str, size_name: str,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(ok, k, d, summaries)`` of the discrete designs (flat arrays; module docstring),
    ``ok`` marking the targets designed here, ``summaries`` the fields of their
    :class:`~impactsym.engines.drake.phases.PhaseSummary` (``(8, size)``) where the
    design came with it (read off a table of
    :mod:`~impactsym.engines.drake.change_table`), ``nan`` elsewhere.

    >>> e, t = np.linspace(0.35, 0.55, 256), np.linspace(0.022, 0.038, 256)
    >>> one = np.ones(256)
    >>> ok, k, d, _ = stepped_designs(e, one, 0.1 * one, 0 * one, t, 1e-3, "lagged",
    ...                               "contact_time")
    >>> bool(ok.mean() > 0.9)
    True
    """
    n = e.size
    ok, k, d = np.zeros(n, bool), np.full(n, np.nan), np.full(n, np.nan)
    summaries = np.full((SUMMARY_FIELDS, n), np.nan)
    ratio = g / v
    q = target / (h if size_name == "contact_time" else v * h)  # the size in steps
    _, inverse, counts = np.unique(ratio, return_inverse=True, return_counts=True)
    for label, count in enumerate(counts):
        if count < MIN_CALL:
            continue
        rows = np.flatnonzero(inverse == label)
        if count < MIN_TARGETS and not _undamped_reach(*(a[rows] for a in (e, v, m, g, target)),
                                                       h, approx, size_name):  # fmt: skip
            continue  # (the caller's iteration refuses them at once; a table took 0.1-2 s)
        by_overlap = size_name != "contact_time"
        scales = free_scales(e[rows]) if by_overlap else None  # (computed once: 0.05 s)
        if may_fill_a_table(e[rows], q[rows], by_overlap=by_overlap, scales=scales):
            # first off the tables of the end states (none: no coarse table either)
            group = [a[rows] for a in (e, v, m, g)]
            steps = _likely_steps(*group, q[rows], h, approx, scales) if by_overlap else None
            done, k_r, d_r, summaries[:, rows], starts = table_designs(
                *group, q[rows], h, _node_designs(v[rows[0]], m[rows[0]], g[rows[0]], h, approx),
                steps=steps,
            )  # fmt: skip
            # those the one evaluation did not keep (a second change next to the phase
            # ends): Broyden's steps from the table's start
            near = np.flatnonzero(~done & np.isfinite(starts.s))
            if near.size:
                done[near], k_r[near], d_r[near] = _from_starts(
                    *(a[rows[near]] for a in (e, v, m, g, q)), starts.s[near], starts.w[near],
                    starts.jac[near], h, approx, size_name,
                )  # fmt: skip
            ok[rows], k[rows], d[rows] = done, k_r, d_r
            rows = rows[~done]
            if rows.size == 0:  # (the others: cheaper here than by the caller's iteration,
                continue  # even a few: 0.06-0.26 s for 1-250 targets, against 0.1-1.2 s)
        done, k_r, d_r = _chunked(*(a[rows] for a in (e, v, m, g, target, q)), h, approx,
                                  size_name)  # fmt: skip
        ok[rows], k[rows], d[rows] = done, k_r, d_r
    return ok, k, d, summaries


def _undamped_reach(e, v, m, g, target, h, approx, size_name):
    """Whether every target's restitution lies below its undamped phase mean at the
    iteration's first stiffness (:func:`~impactsym.engines.drake.continuous.start_stiffness`):
    where one does not, the caller's iteration refuses the call at its first check (the
    same phase means), in milliseconds."""
    k = start_stiffness(e, v, m, target, size_name=size_name, damped=True)
    r = phase_summary(k, np.zeros(e.size), 0.0, m, g, v, h, approximation=approx, bounds=False,
                      stuck_peaks=size_name != "contact_time")  # fmt: skip
    return bool(np.all(r.restitution > e))


def _from_starts(e, v, m, g, q, s, w, jac, h, approx, size_name):
    """``(ok, k, d)`` of the targets ``(e, q)`` (``q`` the size in steps, or over ``v h``)
    by Broyden's steps from the starts ``(s, w)`` with the Jacobians ``jac``
    (:class:`~impactsym.engines.drake.change_table.Starts`), within a box of twice the
    starts' either way: first on the equations of two changes where the start's end
    state changes twice (:mod:`~impactsym.engines.drake.two_changes`; the Jacobian from
    :func:`_differences` of its cheap rule), done within :data:`_JUMP_TOL` and the
    changes settled (the caller's prediction checks them); then, by largest overlap, on
    the exact phase means for the others from ``jac``, at most :data:`STARTS_STEPS` means
    each (by contact time such steps stall next to a plateau's edge: the caller's path
    of the others takes them)."""
    timed = size_name == "contact_time"
    box = ((0.5 * np.nanmin(s), 2.0 * np.nanmax(s)), (0.5 * np.nanmin(w), 2.0 * np.nanmax(w)))
    s, w, jac = s.copy(), w.copy(), jac.copy()
    two, base, first, second = two_change_starts(m * (w / h) ** 2, s / v, m, g, v, h)
    mean_two, cheap = (two_change_rows(m, v, g, h, base, first, second, v * h, timed=timed,
                                       nodes=r) for r in (None, 1))  # fmt: skip
    s_two, w_two = np.where(two, s, np.nan), np.where(two, w, np.nan)
    jac_two = _differences(cheap, s_two, w_two, jac, None)
    s_two, w_two, done = broyden_steps(mean_two, s_two, w_two, jac_two, e, q, *box,
                                       tol=_JUMP_TOL, steps=STARTS_STEPS)  # fmt: skip
    s, w = np.where(done, s_two, s), np.where(done, w_two, w)
    if not timed:  # the exact phase means for the others
        rest = ~done
        mean_rows = _means_rows(m, v, g, h, approx, size_name, v * h)
        s_r, w_r = np.where(rest, s, np.nan), np.where(rest, w, np.nan)
        s_r, w_r, done_r = broyden_steps(mean_rows, s_r, w_r, jac, e, q, *box, tol=_TOL,
                                         steps=STARTS_STEPS)  # fmt: skip
        s, w, done = np.where(rest, s_r, s), np.where(rest, w_r, w), done | done_r
    return done, np.where(done, m * (w / h) ** 2, np.nan), np.where(done, s / v, np.nan)


def _chunked(e, v, m, g, target, q, h, approx, size_name, *, span=SPAN, **options):
    """``(ok, k, d)`` of targets sharing ``g / v`` by :func:`_group` (with its
    ``options``), in the chunks of :func:`_chunks` (``q``: the sizes in steps)."""
    ok, k, d = np.zeros(e.size, bool), np.full(e.size, np.nan), np.full(e.size, np.nan)
    for rows in _chunks(np.arange(e.size), q, span):
        done, k_r, d_r = _group(*(a[rows] for a in (e, v, m, g, target)), h, approx,
                                size_name, **options)  # fmt: skip
        ok[rows], k[rows], d[rows] = done, k_r, d_r
    return ok, k, d


def _node_designs(v, m, g, h, approx):
    """``design(e, q)``: the exact designs ``(s, w)`` by contact time of the targets
    ``(e, q)`` (``q`` in steps) for one mass, speed and gravity, by :func:`_group`
    (``nan`` where it leaves them), for the tables of
    :func:`~impactsym.engines.drake.change_table.table_designs`."""

    def design(e, q):
        one = np.ones(e.size)
        ok, k, d = _chunked(e, v * one, m * one, g * one, q * h, q, h, approx, "contact_time",
                            span=NODE_SPAN, fine=NODE_TABLE, rule=NODE_RULE,
                            tol=NODE_TOL)  # fmt: skip
        return np.where(ok, d * v, np.nan), np.where(ok, h * np.sqrt(k / m), np.nan)

    return design


def _chunks(rows, q, span):
    """``rows`` in chunks of at least :data:`MIN_TARGETS` targets whose sizes in steps
    ``q`` span at most a factor ``span`` where there are enough targets (each chunk
    one table: a table on a wide box is coarse and reaches long contacts)."""
    order = rows[np.argsort(q[rows], kind="stable")]
    sizes = q[order]
    out, start = [], 0
    while start < order.size:
        end = max(int(np.searchsorted(sizes, span * sizes[start], side="right")),
                  start + MIN_TARGETS)  # fmt: skip
        if order.size - end < MIN_TARGETS:
            end = order.size
        out.append(np.sort(order[start:end]))
        start = end
    return out


def _group(
    e, v, m, g, target, h, approx, size_name, *, fine=(NODES_S, NODES_W), rule=None, tol=_JUMP_TOL
):
    """:func:`stepped_designs` for targets sharing ``g / v``: a ``fine`` table of that
    many nodes, the change's equations with ``rule`` Gauss nodes (``None``:
    :func:`~impactsym.engines.drake.jump_means.jump_means`' own)."""
    n = e.size
    ok, k_out, d_out = np.zeros(n, bool), np.full(n, np.nan), np.full(n, np.nan)
    unit = np.full(n, h) if size_name == "contact_time" else v * h  # Q = size / unit
    q = target / unit
    mean_rows = _means_rows(m, v, g, h, approx, size_name, unit)
    box = wide_box(e, q, size_name, g[0] / v[0] * h)
    for nodes in (COARSE, fine):
        s_nodes, w_nodes, T, s, w, jac, E, Q = means_table(mean_rows, box, nodes, e, q)
        if nodes is COARSE and (wider := reaching(box, E, Q, e, q)) is not None:
            box = wider  # (once: the targets beyond the wide box's means)
            s_nodes, w_nodes, T, s, w, jac, E, Q = means_table(mean_rows, box, nodes, e, q)
        found = np.isfinite(s)
        if not found.any():
            return ok, k_out, d_out
        # the next box: the starts found, widened by a cell and a margin
        cell = (s_nodes[1] - s_nodes[0], w_nodes[1] - w_nodes[0])
        box = tuple(widened(x[found], c) for x, c in zip((s, w), cell, strict=True))
    # first on the equations of the end state's change: where the target puts it (by
    # contact time), or where the design's estimate follows it (by largest overlap)
    timed = size_name == "contact_time"
    full = {} if rule is None else {"nodes": rule}
    change = q.copy() if timed else table_at(s_nodes, w_nodes, T, s, w)
    slopes = np.full((n, 2), np.nan)  # of the change's estimate in (s, w)
    rules = [_change_rows(m, v, g, h, change, unit, timed, slopes, r, cheap=r is _CHEAP)
             for r in (full, _CHEAP)]  # fmt: skip
    known = np.isfinite(change)  # (a start whose table cell sticks somewhere: none)
    s_c, w_c = np.where(known, s, np.nan), np.where(known, w, np.nan)
    jac_j = _differences(rules[1], s_c, w_c, jac, slopes)
    s_j, w_j, done_j = broyden_steps(rules[0], s_c, w_c, jac_j, e, q, *box, tol=tol, steps=STEPS)
    rows = np.flatnonzero(done_j)  # (their change is known: it stays finite)
    k_j, d_j = m[rows] * (w_j[rows] / h) ** 2, s_j[rows] / v[rows]
    held = jump_holds(k_j, d_j, *(a[rows] for a in (m, g, v)), h, change[rows],
                      deepest_last=not timed)  # fmt: skip
    ok[rows[held]], k_out[rows[held]], d_out[rows[held]] = True, k_j[held], d_j[held]
    s, w = s.copy(), w.copy()
    s[rows[held]] = w[rows[held]] = np.nan  # done: the exact phase means leave them
    s, w, done = broyden_steps(mean_rows, s, w, jac, e, q, *box, tol=_TOL, steps=STEPS)
    rest = np.flatnonzero(~done & np.isfinite(s) & np.isfinite(w))
    if rest.size:  # next to a plateau's edge: a bracket in w along the contour
        s[rest], w[rest], done[rest] = contour_steps(
            mean_rows,
            rest,
            s[rest],
            w[rest],
            jac[rest],
            e[rest],
            q[rest],
            box[1],
            tol=_TOL,
            steps=EDGE_STEPS,
        )
    ok[done] = True  # (done holds none of the jump's: they were left out)
    k_out[done] = m[done] * (w[done] / h) ** 2
    d_out[done] = s[done] / v[done]
    return ok, k_out, d_out


def _likely_steps(e, v, m, g, q, h, approx, scales):
    """The contact times in steps of the designs by largest overlap ``q`` (over ``v h``)
    of the targets, about (a step or so): read off the coarse table at its starts
    (``nan`` where it has none); ``scales``: ``free_scales(e)``."""
    mean_rows = _means_rows(m, v, g, h, approx, "max_penetration", v * h)
    box = wide_box(e, q, "max_penetration", g[0] / v[0] * h, scales)
    s_nodes, w_nodes, T, s, w, *_ = means_table(mean_rows, box, COARSE, e, q)
    return table_at(s_nodes, w_nodes, T, s, w)


def _change_rows(m, v, g, h, change, unit, timed, slopes, rule, *, cheap=False):
    """``mean(s, w, rows)``: the phase means ``(E, Q)`` of the designs ``rows`` if their
    end state changes once, where the contact time in steps ``change`` puts it
    (:func:`~impactsym.engines.drake.jump_means.jump_means` with the keywords ``rule``).
    By contact time (``timed``) ``Q`` is that function's size. By largest overlap ``Q``
    is :func:`~impactsym.engines.drake.jump_means.last_overlap` over ``unit``; the
    ``cheap`` rule adds the change's estimate (for its ``slopes``), and the full rule moves
    ``change`` with the design along the ``slopes`` before, and to its estimate after
    (in place), and adds where that held still (within :data:`_SETTLED`)."""
    last = np.full((change.size, 2), np.nan)  # the design of each row's last evaluation

    def mean(s, w, rows):
        mr, gr, vr = m[rows], g[rows], v[rows]
        k, d = mr * (w / h) ** 2, s / vr
        if not timed and not cheap:  # the change moves with the design, to first order
            moved = np.einsum("ij,ij->i", slopes[rows], np.column_stack([s, w]) - last[rows])
            # (at most half a step: next to a plateau the margin is flat, the estimate's
            # slopes huge, and a state 10^5 steps on would be stepped; found by review)
            change[rows] += np.clip(np.where(np.isfinite(moved), moved, 0.0), -0.5, 0.5)
        r = jump_means(k, d, mr, gr, vr, h, change[rows], **rule)
        if timed:
            return r.restitution, r.size
        size = last_overlap(k, d, mr, gr, vr, h) / unit[rows]
        if cheap:
            return r.restitution, size, r.size
        last[rows] = np.column_stack([s, w])
        # where the change's estimate leaves the phase interval every phase ends alike
        # (the contact time rests on a plateau): the mean is one end state's integral
        base = np.floor(change[rows] - 0.5)
        later = r.size - base - 0.5 >= 1.0
        plateau = later | (r.size < base + 0.5)
        estimate = np.where(plateau, base + 0.5 + later, r.size)
        restitution = r.restitution
        if plateau.any():
            i = np.flatnonzero(plateau)
            restitution[i] = jump_means(k[i], d[i], mr[i], gr[i], vr[i], h, estimate[i]).fixed
        # the restitution is the mean to second order in how far the change moved
        # (~0.1 per step squared): held only where that is below ~1e-13
        settled = np.abs(estimate - change[rows]) <= _SETTLED
        change[rows] = np.where(np.isfinite(estimate), estimate, change[rows])
        return restitution, size, settled

    return mean


def _differences(mean, s, w, jac, slopes):
    """The Jacobian of ``mean`` at the starts ``(s, w)`` (``n x 2 x 2``; the table's
    ``jac`` where a start is not finite or a difference is not), and into ``slopes``
    those of a third output where ``mean`` returns one: forward differences over
    :data:`_DIFF` relative, for the change's equations with the rule :data:`_CHEAP` of
    one Gauss node on the shorter piece and three on the longer, whose error is smooth
    in the parameters (against central differences of the full rule: 1e-6 median, 3e-3
    at the 99th percentile, as good as two nodes in the steps it saves; the table's
    cell, across the kinks, is good to about a percent: Broyden's steps converge about a
    hundredfold each from it); for the two changes' equations, one node on each short
    piece and three on the long one (:func:`_from_starts`)."""
    out = jac.copy()
    live = np.flatnonzero(np.isfinite(s) & np.isfinite(w))
    if live.size == 0:
        return out
    ds, dw = _DIFF * s[live], _DIFF * w[live]
    sl, wl = s[live], w[live]
    values = mean(np.concatenate([sl, sl + ds, sl]), np.concatenate([wl, wl, wl + dw]),
                  np.tile(live, 3))  # fmt: skip
    n = live.size
    for f, F in enumerate(values[:2]):
        out[live, f, 0] = (F[n : 2 * n] - F[:n]) / ds
        out[live, f, 1] = (F[2 * n :] - F[:n]) / dw
    for F in values[2:]:
        slopes[live] = np.column_stack([(F[n : 2 * n] - F[:n]) / ds, (F[2 * n :] - F[:n]) / dw])
    bad = ~np.isfinite(out[live]).all(axis=(1, 2))
    out[live[bad]] = jac[live[bad]]
    return out


def _means_rows(m, v, g, h, approx, size_name, unit):
    """``mean(s, w, rows)``: the phase means ``(E, Q)`` of the designs ``rows`` (and
    the contact time in steps, ``steps=True``)."""

    def mean(s, w, rows, *, steps=False):
        mr = m[rows]
        r = phase_summary(mr * (w / h) ** 2, s / v[rows], 0.0, mr, g[rows], v[rows], h,
                          approximation=approx, bounds=False, stuck_peaks=False)  # fmt: skip
        size = getattr(r, size_name) / unit[rows]
        if size_name != "contact_time":  # (the contact time is inf where a phase sticks)
            # a sticking phase's peak is cut short here (a settled corner of the box would
            # else be stepped to 2e6 updates): such a node gives no start, such a design is
            # left to the caller's iteration
            size = np.where(r.stick_fraction > 0, np.nan, size)
        if steps:  # and the contact time in steps
            return r.restitution, size, r.contact_time / h
        return r.restitution, size

    return mean
