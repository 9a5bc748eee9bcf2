r"""The phase means of a discrete contact whose end state changes once, at a given phase:
the equations of the discrete designs, without searching for the change.

At a step ``h`` the contact of touch phase :math:`\varphi` ends at the state
:math:`N(\varphi)` and lasts :math:`(N(\varphi) + \varphi)\, h`
(:mod:`impactsym.engines.drake.stepping`). The contact from touch lasts about the same
whatever the phase, so :math:`N` falls by one where the phase crosses one point
:math:`\varphi_j`: :math:`N = B + 1` on :math:`[0, \varphi_j)`, :math:`B` on
:math:`[\varphi_j, 1)` (the usual case; ``docs/physics.md``, "Drake point contact").
Then the phase-mean contact time in steps is

.. math:: Q = \int_0^1 (N + \varphi)\, d\varphi = B + \tfrac12 + \varphi_j ,

so a target ``q`` fixes both :math:`B = \lfloor q - 1/2 \rfloor` and where the change
must lie, :math:`\varphi^* = q - 1/2 - B`. The design's two equations become smooth in
the parameters (no plateau where every phase lasts as long, no kink where a change
enters the phase interval):

* **the size**: state :math:`B` stops ending at :math:`\varphi^*`, i.e. its end margin
  :math:`\mu(\varphi^*)` (:func:`~impactsym.engines.drake.stepping.margin_at`, smooth
  in the phase and the parameters, falling through zero at :math:`\varphi_j`) is zero.
  :func:`jump_means` reports it as the size Newton's step in the phase gives,
  :math:`\hat Q = B + 1/2 + \hat\varphi_j`, :math:`\hat\varphi_j = \varphi^* -
  \mu/\mu'` (:math:`\mu'` by a difference over :data:`_DPHASE`), which is the size to
  second order in :math:`\varphi_j - \varphi^*` and exactly ``q`` at the root (where
  :math:`\hat\varphi_j` leaves ``[0, 1)`` the mean rests at ``B + 1/2`` or ``B + 3/2``,
  every phase ending alike; the estimate goes on smoothly, for the designs' steps);
* **the restitution**: :math:`E = \int_0^{\varphi^*} e_{B+1} + \int_{\varphi^*}^1 e_B`
  with :math:`e_j(\varphi) = -u_j(\varphi)/v`, the separation speed at state ``j``
  (:func:`~impactsym.engines.drake.stepping.end_state`: smooth while the states
  before it carry an impulse, and then the numbers of the full contact), plus the
  share of the change's offset, :math:`(e_{B+1} - e_B)(\varphi^*)\,(\bar\varphi_j -
  \varphi^*)` with :math:`\bar\varphi_j` the estimate clipped to ``[0, 1]``, which
  makes it the mean to second order too (and vanishes at the root; on a plateau's edge,
  :math:`\varphi^* = 0`, an estimate below 0 adds nothing: every phase ends at ``B``,
  the mean is ``e_B``'s integral, as the pieces have it. Unclipped it added
  ``1.6e-12`` to a design under gravity there, found by review).

The integrals are Gauss–Legendre rules of one panel a piece (:func:`_layout`):
``nodes`` on the shorter piece (half a phase at most), ``nodes + 2`` on the longer (up
to a whole phase); 10 by default (22 nodes), 5 in the change tables (12). For contacts
of 10 steps or more the pieces' restitution is analytic far around the phase interval:
``n`` nodes on a panel of length ``L`` err by about :math:`(L/15)^{2n}` (5 nodes on half
a phase ``1e-15``, 4 ``1e-12``, as measured), so the longer piece whole with 7 nodes
(``3e-17``) does better than in two halves of 5, with 6 worse (``3e-14`` at 11 steps).
Measured against 16 nodes on each of three panels (the longer piece halved, the rule
before), over 2.1*10^4 held designs and random contacts of 10-70 steps (``g = 0`` and
``9.81``, steps ``1e-3`` and ``1e-4``: ``benchmarks/bench_drake_jump_rule.py``) and
1.1*10^5 designs of the benchmark's targets (15-70 steps), the pieces' integrals of
the 12-node rule agree to ``1.9e-15`` (``7e-16`` above 15 steps), those of 5 nodes on
each of three panels (15 runs) to ``4.2e-15`` (``4.4e-16``), of 4 on each to ``2e-12``
(the reference's own spread against 20: ``3e-16``; above 15 steps both are rounding,
the rule's fewer and heavier weights). Shorter contacts have nearer singularities:
over 1.7*10^4 random ones of 2-17 steps the default's 10 and 12 nodes give ``3e-15``
(8 on each of three panels ``2e-15``, 8 and 10 ``2.5e-13``, at 2-4 steps). With one
node (the rule of :mod:`~impactsym.engines.drake.step_table`'s finite differences) it
is 4 nodes, ``1e-4`` off and smooth in the parameters. A run of the states costs ``B``
updates, as a full contact does; an evaluation is its nodes and 2 states ``B`` at
:math:`\varphi^*` (state ``B + 1`` there is one update on from ``B``:
:func:`_next_state`), against about 65 contacts and 19 margins of a phase mean that
searches for its changes
(:func:`~impactsym.engines.drake.phases.phase_summary`; measured before its one-margin
root search and quarter pieces, about 50 and 10 since).

The designs by largest overlap read it where
:func:`~impactsym.engines.drake.phases.phase_summary` samples it deepest: at its last
grid phase, ``1 - 1e-15`` (:func:`last_overlap`; the body enters a whole step deep
before the first force, and over 12000 random contacts, steps ``1e-3`` and ``1e-4``,
gravity 0 to ``50`` m/s^2, no other sample was deeper).

The structure is an assumption until checked: :func:`jump_holds` runs the full contact
at the phase grid of :func:`~impactsym.engines.drake.phases.phase_summary` and at the
nodes next to :math:`\varphi^*`, and confirms the end states ``B + 1`` before it and
``B`` after, nothing sticking. Those end states known, each phase is run to its state
and one update on (:func:`~impactsym.engines.drake.stepping.ended_at`: the loop of
:func:`~impactsym.engines.drake.stepping.end_state` and the largest overlap), which
gives :func:`~impactsym.engines.drake.stepping.contact_ends`' numbers bit for bit where
the contact ends there and leaves the overlap; a phase that ends there inside the
overlap (it coasts: it may stick) or, within ``1e-9`` of the change, not there is run
in full; one that does not end there fails the structure, as the full run would
(:func:`_runs_hold`; on the 10^5 designs of the change tables of the benchmark's four
lagged cases, old and new interleaved in one process: the grid 0.23-0.31 -> 0.20-0.27 s
of CPU, with the nodes' end test in their runs (:class:`_Evaluation`) the summaries
0.63-0.83 -> 0.57-0.77 s; every field and ``held`` bit for bit the same there and on
3.6*10^4 random contacts of 2-70 steps, about 1 % of whose runs coast).

*The summary.* :func:`jump_summary` gives the whole
:class:`~impactsym.engines.drake.phases.PhaseSummary` of the structure from one
evaluation (the node states are shared with :func:`jump_means`) and the grid's runs,
instead of :func:`~impactsym.engines.drake.phases.phase_summary`'s search (measured on
10^4 contacts of 20-40 steps at their own means, ``d v`` up to 1.5: 1143 updates per
contact against 1618 without gravity, 1311 against 1920 under it; 0.19 s of CPU
against 0.35, 0.22 against 0.38). Where the end state is ``B + 1`` on
:math:`[0, \varphi_j)` and ``B`` on :math:`[\varphi_j, 1)` the contact lasts
:math:`(B + 1 + \varphi)\, h` then :math:`(B + \varphi)\, h`: its range is
:math:`(B + \hat\varphi_j)\, h` to :math:`(B + 1 + \hat\varphi_j)\, h`, the
one-sided limits at the change (at :math:`\varphi^* = 0` an estimate below 0 means
every phase ends at ``B``: the change is taken at 0, as the mean takes it), and the
mean :math:`(B + 1/2 + \hat\varphi_j)\, h` is the size of :func:`jump_means`. The
restitution's range is over every sample (the nodes, the states ``B + 1`` and ``B``
at :math:`\hat\varphi_j`, one more run and an update: those at :math:`\varphi^*` lie
off the change by the design's tolerance, which moved a design's range by ``3e-11``
under gravity; the grid) and, where a sample between two others of its piece is
extreme, the search of :func:`~impactsym.engines.drake.extremes.interior_extreme` there:
six steps of successive parabolic interpolation from the samples
themselves, which lie at most 0.125 of a phase apart with the grid (figures of three
panels of 5 nodes; one panel a piece moved no bound by ``2e-15`` over 4*10^5 designs
of the benchmark but the one below; two zoom rounds first, as
:func:`~impactsym.engines.drake.phases.phase_summary` searches, took 20 runs per
extreme, and sorting all 26 samples of every contact at once cost more: 0.22-0.30 s
of CPU per 10^5 designs of the change tables then, 0.03-0.07 s now; the bounds agree
to ``7e-16`` over 4*10^4 of their designs, both gravities, and with a dense search of
the pieces, at 1025 phases each refined to ``1e-10`` of a phase, to ``9e-16``, where
1 step falls ``4e-11`` and 2 ``2e-11`` short; over 2*10^4 held random contacts of
2-60 steps at their own mean, ``d v`` up to 6, ``g = 9.81`` and ``30``, steps
``1e-3`` and ``1e-4``, to ``7e-15`` of the dense search, the rounding of the contact
next to a flat extreme, where 4 steps fell ``2e-12`` short); the largest overlap is
the grid's. It holds where the grid's end states hold (as in :func:`jump_holds`),
every node's state is its end state (no state before it ended or turned back, it
ends) and the body leaves the overlap at the next update (it cannot coast and stick),
no end margin dips towards zero between the samples of either piece
(:func:`~impactsym.engines.drake.phases.hidden_changes` at the pieces' nodes), and
:math:`\hat\varphi_j` lies in ``[0, 1)``. There it agrees with
:func:`~impactsym.engines.drake.phases.phase_summary` (over random designs of 2-60
steps, both gravities, steps ``1e-3`` and ``1e-4``: the mean restitution to ``1e-13``,
the contact times to ``3e-13`` relative, the largest overlap bit for bit, the
restitution's range to ``1e-15`` since both search next to their pieces' ends too; with
5 nodes on each of three panels and the change evaluated up to ``1e-6`` steps off the
true one, an extreme about ``2e-5`` of a phase before the change can come out ``4e-13``
short, found by review). An extreme within ``~1e-5`` of a phase of a side of the change
is searched where the restitution's one-sided slope there, from the states of the
change's equations, says it lies inside
(:mod:`~impactsym.engines.drake.jump_range`): the quadratic through the
three samples can put it just outside, ``4e-12`` short (one of 4*10^5 designs of the
benchmark under gravity with the 12-node rule; with the 15-node rule none of them,
luck: its samples put the vertex ``2e-6`` inside). Over those 4*10^5 designs and
1.3*10^5 others (10-70 steps, both gravities and steps), probes at 13 phases ``3e-6``
to ``0.03`` from the change on each side found no restitution beyond the range. Not
verified: at :math:`\varphi^* = 0` a true change within ``1e-9`` of a phase after 0
(the grid's phase 0 is not checked that close to the change, and no sample sees state
``B + 1`` before it): the means stay exact to ``1e-14``, the range can be off by about
the change's distance (``1e-12`` at ``1e-6``). All quantities are SI. Internal to
:mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from impactsym.engines.drake.jump_range import restitution_range
from impactsym.engines.drake.phases import GRID_PHASES, PhaseSummary, hidden_changes
from impactsym.engines.drake.stepping import (
    ContactEnds,
    contact_ends,
    end_state,
    end_steps,
    ended_at,
    margin_at,
)
from impactsym.engines.drake.update import hunt_crossley_velocity
from impactsym.engines.phase_pieces import gauss_legendre

__all__ = ["JumpMeans", "jump_holds", "jump_means", "jump_summary", "last_overlap"]

_NODES = 10  # Gauss-Legendre nodes of the shorter piece (the longer: 2 more)
_DPHASE = 2.0**-20  # the difference in the phase for the slopes at phi* (margin, sides)
_CLEAR = 1e-9  # grid phases this close to the change are not checked (the nodes are)
_ROWS = 4096  # contacts whose samples are tested together (:func:`_hidden`)


class JumpMeans(NamedTuple):
    """:func:`jump_means`: the phase-mean restitution and contact time in steps, and the
    restitution without the change's offset (``fixed``: the two pieces' integrals)."""

    restitution: np.ndarray
    size: np.ndarray
    fixed: np.ndarray


def _gauss(nodes):
    """Gauss–Legendre nodes and weights on ``[0, 1]``."""
    x, w = gauss_legendre(nodes)
    return 0.5 * (x + 1.0), 0.5 * w


def _split(q):
    """``(B, phi*)`` of the sizes in steps ``q`` (module docstring)."""
    base = np.floor(q - 0.5)
    return base.astype(np.int64), q - 0.5 - base


def _layout(phi, base, nodes):
    """The node phases, weights and end states (each ``n x (2 nodes + 2)``, in phase order)
    of the pieces ``[0, phi*]`` (state ``B + 1``) and ``[phi*, 1]`` (``B``): the shorter
    (half a phase at most) one Gauss panel of ``nodes``, the longer one of ``nodes + 2``
    (module docstring)."""
    (xs, ws), (xl, wl) = _gauss(nodes), _gauss(nodes + 2)
    long_left = (phi > 0.5)[:, None]
    x = np.where(long_left, np.concatenate([xl, xs]), np.concatenate([xs, xl]))
    w = np.where(long_left, np.concatenate([wl, ws]), np.concatenate([ws, wl]))
    first = np.arange(2 * nodes + 2) < np.where(long_left, nodes + 2, nodes)
    start = np.where(first, 0.0, phi[:, None])
    width = np.where(first, phi[:, None], 1.0 - phi[:, None])
    return start + width * x, width * w, np.where(first, base[:, None] + 1, base[:, None])


class _Evaluation(NamedTuple):
    """One evaluation of the change's equations (:func:`_evaluate`), per contact:
    ``base`` (``B``), ``phi`` (``phi*``), the node ``phases`` and their ``weights``
    (``n x (2 nodes + 2)``, in phase order: :func:`_layout`), the nodes' restitution
    ``e`` and end states ``x``, ``u``, ``valid``
    (:func:`~impactsym.engines.drake.stepping.end_state`, of the same shape; for the
    summary ``valid`` where the state ends too: one update more per node, instead of
    :func:`~impactsym.engines.drake.stepping.margin_at` on each, bit for bit the same
    verdicts: 0.024 s of CPU per 10^5 summaries, the update about half that), the
    parameters ``flat`` of those rows, the restitution
    ``before`` (state ``B + 1``) and ``after`` (``B``) at ``phi*`` and their
    ``slopes`` in the phase there (``2 x n``, differences over :data:`_DPHASE`), the
    change's ``offset`` (Newton's step from ``phi*``) and the node integral ``fixed``."""

    base: np.ndarray
    phi: np.ndarray
    phases: np.ndarray
    weights: np.ndarray
    e: np.ndarray
    x: np.ndarray
    u: np.ndarray
    valid: np.ndarray
    flat: tuple[np.ndarray, ...]
    before: np.ndarray
    after: np.ndarray
    slopes: np.ndarray
    offset: np.ndarray
    fixed: np.ndarray


def _evaluate(k, d, m, g, v, h, q, nodes, *, summary=False):
    """The node states and the states at ``phi*`` of one evaluation (module docstring):
    what :func:`jump_means` and :func:`jump_summary` read. ``summary``: ``valid`` where no
    state before the node's ended and it ends
    (:func:`~impactsym.engines.drake.stepping.end_state`'s ``ends``); else not tracked
    (:func:`jump_means` reads none: its states a tenth faster)."""
    n = k.size
    base, phi = _split(q)
    phases_in, weights, step = _layout(phi, base, nodes)
    width = phases_in.shape[1]
    # the slopes' difference: back into [0, phi*], where state B + 1 is smooth (its
    # update from B turns free at the change), but from phi* = 0 (no piece there) on
    toward = np.where(phi >= _DPHASE, -_DPHASE, _DPHASE)
    phases = np.concatenate([phases_in.ravel(), phi, phi + toward])
    steps = np.concatenate([step.ravel(), base, base])
    rows = np.concatenate([np.repeat(np.arange(n), width), np.tile(np.arange(n), 2)])
    x, u, valid, flat = end_state(*(a[rows] for a in (k, d, m, g, v)), h, phases, steps,
                                  ends=summary, checked=summary)  # fmt: skip
    e = -u / flat[4]
    inner = n * width
    fixed = np.einsum("ij,ij->i", weights, e[:inner].reshape(n, width))
    at = slice(inner, inner + 2 * n)
    margin, _ = margin_at(x[at], u[at], *(a[at] for a in flat))
    mu, mu_next = margin[:n], margin[n:]
    with np.errstate(all="ignore"):  # (a flat margin: no finite size, the step refuses it)
        offset = -mu * toward / (mu_next - mu)
    # state B + 1 at phi* and at the slope's phase: one update on from B
    _, u_next = _next_state(x[at], u[at], *(a[at] for a in flat))
    sides = np.stack([-u_next / flat[4][at], e[at]]).reshape(2, 2, n)  # (state, phase, n)
    slopes = (sides[:, 1] - sides[:, 0]) / toward
    slopes[0, toward > 0.0] = np.nan  # (state B + 1 past the change)
    node_rows = (a[:inner].reshape(n, width) for a in (e, x, u, valid))
    return _Evaluation(base, phi, phases_in, weights, *node_rows,
                       tuple(a[:inner].reshape(n, width) for a in flat), sides[0, 0], sides[1, 0],
                       slopes, offset, fixed)  # fmt: skip


def _next_state(x, u, k, d, m, g, v, h):
    """``(x, u)`` of the state after ``(x, u)`` (flat arrays): one update of
    :func:`~impactsym.engines.drake.update.hunt_crossley_velocity`, which is
    :func:`~impactsym.engines.drake.stepping.end_state`'s next state bit for bit (the same
    operations; its ``valid`` not kept), for one update instead of a run from touch."""
    new, _ = hunt_crossley_velocity(x, u, k, d, m, g, h)
    return x + h * new, new


def _means(ev):
    """:func:`jump_means` of an evaluation."""
    inside = np.clip(ev.phi + ev.offset, 0.0, 1.0) - ev.phi  # (outside: every phase ends alike)
    return JumpMeans(ev.fixed + (ev.before - ev.after) * inside, ev.base + 0.5 + ev.phi + ev.offset,
                     ev.fixed)  # fmt: skip


def jump_means(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    q: np.ndarray, *, nodes: int = _NODES,
) -> JumpMeans:  # fmt: skip
    """The phase means of the contacts ``(k, d, m, g, v)`` at step ``h`` if their end
    state changes once, from ``B + 1`` to ``B``, where the size in steps ``q`` puts it
    (module docstring): to second order in the change's offset, exact at the design.
    Flat arrays of one length. ``nodes``: Gauss nodes of the shorter piece, 2 more on
    the longer (fewer: a cheaper rule whose error is smooth in the parameters, for
    differences of the means)."""
    return _means(_evaluate(k, d, m, g, v, h, q, nodes))


def last_overlap(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float
) -> np.ndarray:
    """The largest overlap of the contact at the last phase of the grid of
    :func:`~impactsym.engines.drake.phases.phase_summary` (``1 - 1e-15``), the very
    number it samples there (``nan`` where it sticks): the phase summary's largest
    overlap where it is the deepest of its samples (module docstring). Flat arrays."""
    r = contact_ends(k, d, m, g, v, h, GRID_PHASES[-1], stuck_peaks=False)
    return np.where(r.sticks, np.nan, r.max_penetration)


def _runs_hold(k, d, m, g, v, h, base, phi, phases, check):
    """The full contacts at ``phases`` (``n x p``; :func:`contact_ends`' numbers, records
    ``n x p``) and where their end states are ``B + 1`` before ``phi*`` and ``B`` after
    wherever ``check``, none sticking. Each is run to that state and one update on
    (:func:`~impactsym.engines.drake.stepping.ended_at`, the same numbers where it ends
    there and leaves the overlap); the full contact only where it ends there inside the
    overlap (it coasts) or, unchecked, elsewhere; a checked one that does not end there
    does not hold."""
    want = np.where(phases < phi[:, None], base[:, None] + 1, base[:, None])
    rows = np.repeat(np.arange(k.size), phases.shape[1])
    r, status = ended_at(*(a[rows] for a in (k, d, m, g, v)), h, phases.ravel(), want.ravel())
    full = np.flatnonzero((status == 0) | (status < 0) & ~check.ravel())
    if full.size:
        ends = contact_ends(*(a[rows[full]] for a in (k, d, m, g, v)), h, phases.ravel()[full])
        for a, b in zip(r, ends, strict=True):
            a[full] = b
    r = ContactEnds(*(a.reshape(phases.shape) for a in r))
    ends = end_steps(r.contact_time, r.sticks, h, phases)
    fails = (status.reshape(phases.shape) < 0) & check
    held = ((ends == want) | ~check).all(axis=1) & ~r.sticks.any(axis=1) & ~fails.any(axis=1)
    return r, held


def _grid_checked(phi):
    """The grid phases not within :data:`_CLEAR` of the change ``phi`` (``n x 9``)."""
    return np.abs(GRID_PHASES - phi[:, None]) > _CLEAR


def jump_holds(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    q: np.ndarray, *, deepest_last: bool = False,
) -> np.ndarray:  # fmt: skip
    """Where the contacts' end state is ``B + 1`` before the phase the size ``q`` puts the
    change at and ``B`` after it, nothing sticking, at the phase grid of
    :func:`~impactsym.engines.drake.phases.phase_summary` (those within ``1e-9`` of the
    change left out) and at the Gauss nodes next to it: :func:`jump_means` then holds the
    means (module docstring). ``deepest_last``: and no phase run overlaps deeper than the
    last grid phase (:func:`last_overlap`). Flat arrays of one length."""
    n = k.size
    base, phi = _split(q)
    placed, _, _ = _layout(phi, base, _NODES)
    # the nodes next to the change: the first piece's last, the second's first
    cut = np.where(phi > 0.5, _NODES + 2, _NODES)
    next_to = np.take_along_axis(placed, np.column_stack([cut - 1, cut]), axis=1)
    phases = np.concatenate([np.tile(GRID_PHASES, (n, 1)), next_to], axis=1)
    # (the nodes: none before an empty first piece)
    check = np.column_stack([_grid_checked(phi), phi > 0.0, np.ones(n, bool)])
    r, held = _runs_hold(k, d, m, g, v, h, base, phi, phases, check)
    if deepest_last:
        held &= r.max_penetration.max(axis=1) <= r.max_penetration[:, GRID_PHASES.size - 1]
    return held


def jump_summary(
    k: np.ndarray,
    d: np.ndarray,
    m: np.ndarray,
    g: np.ndarray,
    v: np.ndarray,
    h: float,
    q: np.ndarray,
    *,
    deepest_last: bool = False,
    nodes: int = _NODES,
) -> tuple[PhaseSummary, np.ndarray]:
    """The whole phase summary of the contacts ``(k, d, m, g, v)`` at step ``h`` whose end
    state changes once where the size in steps ``q`` puts it, from one evaluation of the
    change's equations and the runs of the phase grid, and ``held``: where that
    structure is verified (flat arrays of one length; elsewhere the fields are ``nan``).

    The fields are those :func:`~impactsym.engines.drake.phases.phase_summary` gives the
    structure (module docstring, "The summary"): the restitution and size of
    :func:`jump_means`; the contact time's range ``(B + phi_j) h`` to ``(B + 1 + phi_j)
    h`` at the change's estimate ``phi_j``; the restitution's range over the nodes, both
    sides of the change at ``phi_j``, the grid and the interior extremes; the grid's
    largest overlap; no sticking. ``held``: the grid's end states as in
    :func:`jump_holds`, nothing sticking; every node's state ``B + 1`` or ``B`` the end
    state (no state before it ended or turned back, and it ends) and the body out of
    the overlap at the next update (no coasting that could stick); no end-state margin
    dipping towards zero between the samples of either piece
    (:func:`~impactsym.engines.drake.phases.hidden_changes`); ``phi_j`` in ``[0, 1)``;
    ``deepest_last``: and no grid phase overlapping deeper than the last
    (:func:`last_overlap`). ``nodes``: Gauss nodes of the shorter piece (as
    :func:`jump_means`)."""
    n = k.size
    ev = _evaluate(k, d, m, g, v, h, q, nodes, summary=True)
    means = _means(ev)
    # the change's estimate; at phi* = 0 one below it means every phase ends at B
    change = np.where((ev.phi == 0.0) & (ev.offset < 0.0), 0.0, ev.phi + ev.offset)
    # (a flat margin's infinite estimate, not held, as nan: its runs and samples quiet)
    change[~np.isfinite(change)] = np.nan
    grid = np.tile(GRID_PHASES, (n, 1))
    r, held = _runs_hold(k, d, m, g, v, h, ev.base, ev.phi, grid, _grid_checked(ev.phi))
    empty = ev.weights == 0.0  # (the nodes of an empty first piece, at phi* = 0)
    held &= (ev.valid & _leaves(ev) | empty).all(axis=1) & (change >= 0.0) & (change < 1.0)
    # the two sides at the change's estimate (those at phi* are off it by the design's
    # tolerance: 3e-11 in the range, under gravity)
    x, u, _, flat = end_state(k, d, m, g, v, h, change, ev.base, checked=False)
    x_before, u_before = _next_state(x, u, *flat)  # (state B + 1: one update on)
    sides = np.stack([-u_before / v, -u / v]), np.stack([x_before, x])
    held &= ~_hidden(ev, r, sides)
    depth = r.max_penetration.max(axis=1)
    if deepest_last:
        held &= depth <= r.max_penetration[:, -1]
    e_lo, e_hi = restitution_range(k, d, m, g, v, h, ev, r, held, sides, change)
    fields = (means.restitution, (ev.base + 0.5 + change) * h, e_lo, e_hi, (ev.base + change) * h,
              (ev.base + 1 + change) * h, depth, np.zeros(n))  # fmt: skip
    return PhaseSummary(*(np.where(held, f, np.nan) for f in fields)), held


def _leaves(ev):
    """Where the body is out of the overlap at the update after each node's state (a free
    update: where the state ends, which ``ev.valid`` says, it cannot coast and stick),
    ``n x nodes``."""
    x, u, h, g = ev.x, ev.u, ev.flat[5], ev.flat[3]
    return x + h * (u + h * g) < 0.0  # the next update's position


def _hidden(ev, r, sides):
    """Where an end-state margin may dip towards zero between the samples of a piece
    (:func:`~impactsym.engines.drake.phases.hidden_changes`): the piece ``[0, phi_j]``
    (the grid's first phase, its nodes, state ``B + 1`` at the change) and ``[phi_j,
    1)`` (state ``B`` there, its nodes, the grid's last phase), each one Gauss panel
    (:func:`_layout`). ``sides``: the
    restitution and end penetration of states ``B + 1`` and ``B`` at the change."""
    nodes = (ev.e.shape[1] - 2) // 2  # of the shorter piece
    positions = {
        c: np.concatenate([[-1.0], gauss_legendre(c)[0], [1.0]]) for c in (nodes, nodes + 2)
    }
    d, g, v, h = (ev.flat[i][:, 0] for i in (1, 3, 4, 5))
    flag = np.zeros(ev.phi.size, bool)
    long_left = ev.phi > 0.5
    for rows, cut in ((long_left, nodes + 2), (~long_left, nodes)):
        all_rows = np.flatnonzero(rows)
        for lo in range(0, all_rows.size, _ROWS):
            i = all_rows[lo : lo + _ROWS]
            flag[i] = _hidden_in(ev, r, sides, i, cut, positions, (d[i], g[i], v[i], h[i]))
    return flag


def _hidden_in(ev, r, sides, i, cut, positions, params):
    """:func:`_hidden` of the contacts ``i`` whose first piece has ``cut`` nodes (a block
    of :data:`_ROWS` at most: its temporaries stay in the cache)."""
    first = (
        (r.restitution[i, :1], ev.e[i, :cut], sides[0][0, i, None]),
        (r.end_penetration[i, :1], ev.x[i, :cut], sides[1][0, i, None]),
    )
    second = (
        (sides[0][1, i, None], ev.e[i, cut:], r.restitution[i, -1:]),
        (sides[1][1, i, None], ev.x[i, cut:], r.end_penetration[i, -1:]),
    )
    flag = np.zeros(i.size, bool)
    for (e, x), width, used in ((first, cut, ev.phi[i] > 0.0),
                                (second, ev.e.shape[1] - cut, True)):  # fmt: skip
        e, x = (np.ascontiguousarray(np.concatenate(a, axis=1).T) for a in (e, x))
        flag |= hidden_changes(e, x, *params, positions=positions[width]) & used
    return flag
