r"""Drake's discrete contact over the touch phase: its mean and its range.

The restitution and contact time of :func:`~impactsym.engines.drake.stepping.step_contact`
are smooth in the touch phase between the phases where the end state changes (or the
stick verdict does). As in :mod:`impactsym.engines.mujoco.discrete`, the summary samples
a grid of phases and locates each change of the end state between grid points to
``2^-45`` (``2^-42`` of a grid interval). Where neither side sticks (``"tamsi"``,
``"similar"``, ``"lagged"``) the change is where the earlier end state ``j`` starts or
stops ending, a zero of its end margin
(:func:`~impactsym.engines.drake.stepping.end_margin`, smooth in the phase): one margin
per bracket and call, at a quadratic-corrected regula falsi estimate stepped just past
it towards the bracket's farther end, so that consecutive phases straddle the root
(:func:`_roots`). Where rounding blurs the margin (1e-13 to 1e-11 of a phase, wider
with the damping number ``d v``) the end state flips back and forth, and the change
found may lie anywhere in that band, as the multisection's may: mean contact times then
agree with it to ~2e-11 of a step for ``d v`` below 2 and ~2e-10 up to 5.5 (contacts of
2-100 steps; 3e-10 on contacts of 300-500). About 10 margins per change (measured over
10^4 random contacts: 9.1 for ``d v`` up to 4, 11.5 for 4-5.5; the former falsi, two
phases per call, took 18 and 24) instead of 63 (large batches) or 441 contacts; the
full contact's end states at the bracket's ends confirm it. Where the contact may end on
the impulse floor (``d v`` above :data:`_FLOOR`) the end state can change several
times inside one grid interval, and the margin of one state does not see an earlier
change of another: on a contact of 2.7 steps at ``d v = 18.8`` it found the third of
three changes, the mean contact time 3.8e-3 steps off (found by review); there, and
where the search fails, multisection on the full contact's end state (63 phases per call, 7
calls, up to ~500 brackets; 3 phases, 21 calls, for more). The pieces are the quarters
of the phase (two grid intervals each) cut at the changes, each integrated by 7-point
Gauss–Legendre (the restitution is an algebraic, smooth function of the phase there; the
error of a typical contact behaves as ``~1e-2 (L/2.5)^(2N)`` for ``N`` nodes on a length
``L``; contacts of under 3 steps do worse: 5e-13 at most). Against 16 nodes per quarter,
over 12000 random contacts of 2.2-100 steps (log-uniform), ``d v`` up to 5, gravity 0
and 9.81 m/s^2, steps 1e-3 and 1e-4, the mean restitution moves by 0.8-1.4e-14 at the
99th percentile (the former 5 nodes per eighth, 45 runs per design instead of 35:
3-5e-14; 6 nodes per quarter: up to 2e-11 on the shortest contacts, too much for designs
held to 1e-12). *Two changes inside one grid interval* (the end state ends one state
early or late over a band of 0.02-0.1 of a phase, or steps twice) leave the grid's end
states alike, or the root search finds only the first: before this check, random
contacts of 2-10 steps were off in 5 of 4000 (``d v = 0``) to 5 % (``d v`` 8-10),
up to 4e-2 steps in the mean contact time and 2.5e-3 in the restitution. Each piece is
therefore checked: its node samples' end states, and the end state's margins and the
state before's, closed-form in the end state (its penetration and speed, which the
runs record) and smooth along the piece (:func:`hidden_changes`); a flagged element
is summed again on a grid four times finer, down to :data:`_FINEST` intervals (as
:mod:`impactsym.engines.mujoco.discrete` does). Against a midpoint mean over 2^14
phases with its own error bound (two reviews, ~40000 contacts, ``d v`` 0-10, both
gravities, steps 1e-3 and 1e-4) none is off after; about 2 % of the elements of 2-4
steps are summed again, 0.07 % of those of 10-60, none of 2*10^4 of 20-40. Left: a band
that does not stick inside a sticking piece is seen only where a node falls in it (1 of
6000 contacts of 2-4 steps that mostly stick: 2.4e-3 in e), and contacts ending on the
impulse floor at ``d v`` above 10 (4 of 1500, up to 1.2e-2 steps; the margins there are
rounding). The bounds are over the piece ends (the one-sided limits at the
jumps), the nodes and every grid phase (the odd ones lie inside the quarters), and a
search where an interior node is extreme (two zoom rounds, then two parabolic steps:
22 runs per piece instead of the 135 of a zoom to 1e-9 of a piece, the same bounds to
1e-15; 17 % of a summary under gravity). The piece ends are
the grid phases and the located brackets' ends, whose contacts were run already: only
the nodes are run again. Those runs take
:func:`~impactsym.engines.drake.stepping.contact_ends` (``"sap"``: ``step_contact``),
the same numbers bit for bit. The largest overlap is the deepest sample; that is the
last grid phase's on every contact that does not stick (measured: the body enters almost
a whole step deep before the first force).
All designs and pieces are evaluated together on whole arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from impactsym.engines.drake.extremes import BATCH, interior_extreme
from impactsym.engines.drake.stepping import (
    ContactEnds,
    contact_ends,
    end_margin,
    end_steps,
    step_contact,
)
from impactsym.engines.phase_pieces import (
    gauss_legendre,
    integrate_pieces,
    least_vertex,
    reduce_at,
)
from impactsym.records import ArrayRecord

__all__ = [
    "GRID_PHASES",
    "SUMMARY_FIELDS",
    "PhaseSummary",
    "hidden_changes",
    "phase_summary",
]

_GRID = 8


def hidden_changes(
    e: np.ndarray, x_end: np.ndarray, d: np.ndarray, g: np.ndarray, v: np.ndarray,
    h: np.ndarray, *, positions: np.ndarray | None = None,
) -> np.ndarray:  # fmt: skip
    """Pieces (columns of the samples' restitution ``e`` and end penetration ``x_end``,
    ``samples x pieces``, the samples in phase order at the relative ``positions`` shared
    by every piece, by default the summary's: the piece start, its :data:`_NODES` Gauss
    nodes, its end, on ``[-1, 1]``; parameters per piece) whose end state may change
    between samples.

    The end state ``B`` of a piece ends where its update is free, ``F3 = x/h + u*`` or
    ``F4 = u* + 1/d`` at most zero (``u* = u + h g``, ``u = -e v``), or its impulse is
    below the floor ``1e-12 m v``; the state before it did not, which for a state
    reached by a contact update means ``F1 = x > 0`` and ``F2 = 1 + d u > 0`` (the
    previous state's two margins are ``F1 (1/h + h k F2/m)`` and ``F2 (1/d + h k F1/m)``).
    All four are smooth in the phase along the piece, however its contacts end. A
    function of one sign at every sample whose quadratic through a least sample and the
    two next to it falls below :data:`_NEAR` of that sample (:func:`_toward_zero`), or
    ``F3`` and ``F4`` whose zeros between two samples interpolate in the order that
    leaves both positive (within :data:`_LAG` of the interval), flags the piece. The
    margins do not see changes of a contact that ends on the impulse floor (both
    positive; mostly ``d v`` above 5.5): the node samples' end states do. Pieces that
    stick, and ``"sap"`` (no end penetration), are skipped (a band that does not stick
    inside a sticking piece is seen only where a node falls in it). Column bounds come
    first (``F2`` and ``F4`` fall as ``e`` rises), the fits only on the pieces they
    leave.
    """
    if positions is None:
        positions = np.concatenate([[-1.0], gauss_legendre(_NODES)[0], [1.0]])
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_d = np.where(d > 0, 1.0 / d, np.inf)
        f3 = x_end / h + (h * g - v * e)
    e_lo, e_hi = e.min(axis=0), e.max(axis=0)

    def f2(i):
        return 1.0 - d[i] * v[i] * e[:, i]

    def f4(i):
        return h[i] * g[i] + inv_d[i] - v[i] * e[:, i]

    functions = (  # each with its least and largest sample per piece
        (lambda i: x_end[:, i], x_end.min(axis=0), x_end.max(axis=0)),
        (f2, 1.0 - d * v * e_hi, 1.0 - d * v * e_lo),
        (lambda i: f3[:, i], f3.min(axis=0), f3.max(axis=0)),
        (f4, h * g + inv_d - v * e_hi, h * g + inv_d - v * e_lo),
    )
    flag = np.zeros(e.shape[1], bool)
    for f, low, high in functions:
        reach = 1.0 + 4.0 * _NEAR  # a spread over 4 _NEAR times the least (_toward_zero)
        with np.errstate(invalid="ignore"):
            up = (low > 0) & (high > reach * low)
            down = (high < 0) & (low < reach * high)
        for i, sign in ((np.flatnonzero(up), 1.0), (np.flatnonzero(down), -1.0)):
            if i.size:
                flag[i] |= _toward_zero(sign * f(i), positions)
    # F3 rising through zero and F4 falling through it between two samples (or the
    # reverse): linearly, a gap between their zeros where both are positive
    lo3, hi3, lo4, hi4 = functions[2][1], functions[2][2], functions[3][1], functions[3][2]
    both = np.flatnonzero((lo3 <= 0) & (hi3 > 0) & (lo4 <= 0) & (hi4 > 0))
    if both.size:
        g3, g4 = f3[:, both], f4(both)
        a3, b3, a4, b4 = g3[:-1], g3[1:], g4[:-1], g4[1:]
        with np.errstate(divide="ignore", invalid="ignore"):
            z3, z4 = a3 / (a3 - b3), a4 / (a4 - b4)  # fractions of the sample interval
            up = (a3 <= 0) & (b3 > 0) & (a4 > 0) & (b4 <= 0) & (z3 < z4 + _LAG)
            down = (a4 <= 0) & (b4 > 0) & (a3 > 0) & (b3 <= 0) & (z4 < z3 + _LAG)
        flag[both] |= (up | down).any(axis=0)
    return flag & np.isfinite(functions[0][1])


def _toward_zero(a, positions):
    """Columns of ``a`` (positive samples at the pieces' relative ``positions``) whose
    quadratic through a least sample and the two next to it (the first or last three
    where the least is an end) has its vertex between them and below :data:`_NEAR` of
    the least sample. That quadratic falls below the least of its three samples by at
    most a quarter of their spread, so only columns whose spread exceeds ``4 _NEAR``
    times their least can be flagged."""
    low = least_vertex(a.T, positions)  # nan where outside
    with np.errstate(invalid="ignore"):
        return low < _NEAR * a.min(axis=0)


def _grid(intervals):
    """``intervals`` equal phase intervals of ``[0, 1)``, the last phase ``1 - 1e-15``."""
    grid = np.linspace(0.0, 1.0, intervals + 1)
    grid[-1] = 1.0 - 1e-15
    return grid


#: The phases every summary runs first: ``_GRID`` equal intervals of ``[0, 1)`` (the last
#: phase ``1 - 1e-15``).
GRID_PHASES = _grid(_GRID)
GRID_PHASES.flags.writeable = False
_SPLIT = 64  # multisection: 6 bits of the jump phase per call (2^-42: 7 calls)
_NODES = 7  # Gauss-Legendre nodes per piece (a quarter of the phase at most)
_WIDTH = 2.0**-45  # a change of the end state is located to this (1/8 of a phase / 64^7)
_FAN = 64  # phases per bracket and call of the root search at most
_FAN_ROWS = 512  # fans of _FAN_ROWS // brackets phases (from 2: 256 brackets or fewer left)
_ROOT_CALLS = 40  # calls of the root search at most (measured: up to 35), then the multisection
_FLOOR = 5.5  # damping numbers d v above which the multisection locates the changes
_FINEST = _GRID * 4**5  # grid intervals at most where pieces hide changes (1/8192 of a phase)
_NEAR = 0.5  # a margin whose fit between samples falls below this share of its least sample
_LAG = 0.25  # linear zeros of F3, F4 closer than this share of a sample interval: a gap


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

    def stacked(self) -> np.ndarray:
        """The fields stacked in their order: the form the designs pass summaries in."""
        return np.stack([getattr(self, f.name) for f in fields(self)])


#: The rows of :meth:`PhaseSummary.stacked`.
SUMMARY_FIELDS = len(fields(PhaseSummary))


def phase_summary(
    k: Any, d: Any, tau: Any, m: Any, g: Any, v: Any, h: Any, *, approximation: str,
    bounds: bool = True, stuck_peaks: bool = True,
) -> PhaseSummary:  # fmt: skip
    """Mean over the touch phase and bounds over every phase (module docstring).

    Arguments as in :func:`~impactsym.engines.drake.stepping.step_contact`, without the
    phase; they broadcast. ``bounds=False`` skips the golden-section search of the
    restitution range (then bounded by the sampled phases only), for designs that need
    only the means; ``stuck_peaks=False`` lets the penetration of sticking phases stop
    at the stick verdict (:func:`~impactsym.engines.drake.stepping.step_contact`), for
    designs that do not read it.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, tau, m, g, v, h)))
    flat = [a.ravel() for a in arrays]
    fields = _summary(flat, approximation, bounds, stuck_peaks, _GRID)
    return PhaseSummary(*(np.reshape(f, arrays[0].shape) for f in fields))


def _summary(flat, approximation, bounds, stuck_peaks, intervals):
    """:func:`phase_summary`'s fields (a ``(8, size)`` array) of the flat arrays, on a
    grid of ``intervals`` equal phase intervals. A grid interval can hold two changes
    of the end state (the grid sees neither, or the search finds one of them): a piece
    whose samples do not all share one end state shows it (the only sign where the
    contact ends on the impulse floor), or one whose end-state margins come near zero
    between its samples (:func:`hidden_changes`), and its element is done again on a
    grid four times finer, up to :data:`_FINEST` intervals (changes closer than that
    are integrated as one piece: off by at most their distance times the jump), as
    :mod:`impactsym.engines.mujoco.discrete` does."""
    size = flat[0].size
    dt = flat[-1]

    def run(i, p):
        if approximation == "sap":
            return step_contact(*(a[i] for a in flat), p, approximation=approximation,
                                stuck_peaks=stuck_peaks)  # fmt: skip
        k, d, _, m, g, v, h = (a[i] for a in flat)  # (no relaxation time)
        return contact_ends(k, d, m, g, v, h, p, stuck_peaks=stuck_peaks)

    def key(res, p, i):
        return end_steps(res.contact_time, res.sticks, dt[i], p)

    grid = GRID_PHASES if intervals == _GRID else _grid(intervals)
    lo = np.tile(grid[:-1], (size, 1))
    hi = np.tile(grid[1:], (size, 1))
    i_grid = np.repeat(np.arange(size), intervals + 1)
    at = np.tile(grid, size)
    at_grid = _fields(run(i_grid, at))
    keys = key(at_grid, at, i_grid).reshape(size, intervals + 1)
    key_lo, key_hi = keys[:, :-1], keys[:, 1:]
    jump = key_lo != key_hi
    ii, kk = np.nonzero(jump)
    a, c = lo[ii, kk].copy(), hi[ii, kk].copy()
    left = key_lo[ii, kk]
    todo = np.arange(ii.size)
    at_jump = ContactEnds(*(np.empty((ii.size, 2), f.dtype) for f in at_grid))  # at (a, c)
    if approximation != "sap":  # a root of the end margin where it decides the change
        found, a_r, c_r, at_found = _roots(flat, run, key, ii, a, c, left, key_hi[ii, kk])
        a[found], c[found] = a_r[found], c_r[found]
        if found.any():
            for f, g in zip(at_jump, at_found, strict=True):
                f[found] = g[found]
        todo = np.flatnonzero(~found)
    if todo.size:  # the others (sap, sticking, a margin that does not decide)
        a[todo], c[todo] = _multisection(run, key, ii[todo], a[todo], c[todo], left[todo])
        rows, p = np.repeat(ii[todo], 2), np.column_stack([a[todo], c[todo]]).ravel()
        for f, g in zip(at_jump, _fields(run(rows, p)), strict=True):
            f[todo] = g.reshape(-1, 2)
    # the pieces: quarters of the phase (two grid intervals each), cut at the changes;
    # the records at their ends come from the grid and the changes' brackets (run there)
    ends = np.where(jump, np.nan, hi)  # of each interval's first piece, and its record
    ends[ii, kk] = a
    f_ends = []
    for f, g in zip(at_grid, at_jump, strict=True):
        f_end = f.reshape(size, intervals + 1)[:, 1:].copy()
        f_end[ii, kk] = g[:, 0]
        f_ends.append(f_end)
    even = np.arange(0, intervals, 2)
    # an even interval's first piece runs on through the odd one where it has no change
    first_end = np.where(jump[:, even], ends[:, even], ends[:, even + 1])
    # a change's second piece ends at its interval's end where that is odd, else at the
    # odd interval's first end (its change where it has one; the index is clipped only
    # to keep the branch not taken in range)
    odd_jump = kk % 2 == 1
    jump_end = np.where(odd_jump, hi[ii, kk], ends[ii, np.minimum(kk + 1, intervals - 1)])
    p0 = np.concatenate([lo[:, even].ravel(), c])
    p1 = np.concatenate([first_end.ravel(), jump_end])
    own = np.concatenate([np.repeat(np.arange(size), even.size), ii])
    at_p0, at_p1 = [], []
    for f, f_end, g in zip(at_grid, f_ends, at_jump, strict=True):
        f = f.reshape(size, intervals + 1)
        end_first = np.where(jump[:, even], f_end[:, even], f_end[:, even + 1])
        end_jump = np.where(odd_jump, f[ii, kk + 1], f_end[ii, np.minimum(kk + 1, intervals - 1)])
        at_p0.append(np.concatenate([f[:, even].ravel(), g[:, 1]]))
        at_p1.append(np.concatenate([end_first.ravel(), end_jump]))

    def run_inner(i, p):
        """``run`` at the pieces' samples (start, nodes, end), run at the nodes only."""
        shape = (p0.size, _NODES + 2)
        inner = run(i.reshape(shape)[:, 1:-1].ravel(), p.reshape(shape)[:, 1:-1].ravel())
        out = []
        for f, f0, f1 in zip(_fields(inner), at_p0, at_p1, strict=True):
            full = np.empty(shape, f.dtype)
            full[:, 0], full[:, 1:-1], full[:, -1] = f0, f.reshape(-1, _NODES), f1
            out.append(full.ravel())
        return ContactEnds(*out)

    pieces = integrate_pieces(run_inner, p0, p1, own, size, nodes=_NODES)
    pts, res, e, t = pieces.pts, pieces.result, pieces.restitution, pieces.contact_time
    e_mean, t_mean, stick_frac = (
        pieces.restitution_mean, pieces.contact_time_mean, pieces.stick_fraction
    )  # fmt: skip
    e_lo, e_hi = e.min(axis=1), e.max(axis=1)
    if bounds:
        e_lo = np.fmin(e_lo, interior_extreme(run, own, pts, e, -1.0))
        e_hi = np.fmax(e_hi, interior_extreme(run, own, pts, e, 1.0))
    pen = res.max_penetration.reshape(pts.shape).max(axis=1)
    # the bounds over every sample: the pieces' and the grid's (the odd grid phases lie
    # inside the quarters)
    e_g, t_g, _, pen_g, _ = (f.reshape(size, intervals + 1) for f in at_grid)
    fields = (
        e_mean,
        t_mean,
        np.fmin(reduce_at(np.minimum, own, e_lo, size, np.inf), e_g.min(axis=1)),
        np.fmax(reduce_at(np.maximum, own, e_hi, size, -np.inf), e_g.max(axis=1)),
        np.fmin(reduce_at(np.minimum, own, t.min(axis=1), size, np.inf), t_g.min(axis=1)),
        np.fmax(reduce_at(np.maximum, own, t.max(axis=1), size, -np.inf), t_g.max(axis=1)),
        np.fmax(reduce_at(np.maximum, own, pen, size, 0.0), pen_g.max(axis=1)),
        stick_frac,
    )
    out = np.stack(fields)
    # a piece whose samples do not all share its end state holds changes the grid missed
    keys = key(res, pts.ravel(), np.repeat(own, pts.shape[1])).reshape(pts.shape)
    mixed = np.zeros(size, bool)
    mixed[own[(keys != keys[:, :1]).any(axis=1)]] = True
    x_end = np.ascontiguousarray(res.end_penetration.reshape(pts.shape).T)
    d_p, g_p, v_p, h_p = (flat[i][own] for i in (1, 4, 5, 6))
    mixed[own[hidden_changes(np.ascontiguousarray(e.T), x_end, d_p, g_p, v_p, h_p)]] = True
    redo = np.flatnonzero(mixed)
    if redo.size and intervals < _FINEST:
        sub = [a[redo] for a in flat]
        out[:, redo] = _summary(sub, approximation, bounds, stuck_peaks, 4 * intervals)
    return out


def _fields(res) -> ContactEnds:
    """The fields of a contact record that the summary reads (``step_contact``'s
    records, of ``"sap"``, carry no end penetration: ``nan``)."""
    if isinstance(res, ContactEnds):
        return res
    end = np.full(np.shape(res.restitution), np.nan)
    return ContactEnds(res.restitution, res.contact_time, res.sticks, res.max_penetration, end)


def _multisection(run, key, ii, a, c, left):
    """The first change of the end state in each bracket ``[a, c]`` of elements ``ii``
    (``key`` at ``a`` is ``left``), to ``2^-42`` of the bracket: ``split - 1`` phases per
    bracket and call, the first change kept. Many small calls cost Python overhead, few
    large ones cost work: 64 up to ~500 brackets, 4 for more (measured: 1000 designs
    0.5 s against 1.7 s with 64)."""
    split = _SPLIT if ii.size * _SPLIT <= BATCH else 4
    frac = np.arange(1, split) / split
    for _ in range(int(np.ceil(42 / np.log2(split)))):
        pts = a[:, None] + (c - a)[:, None] * frac[None, :]
        rows = np.repeat(ii, frac.size)
        same = key(run(rows, pts.ravel()), pts.ravel(), rows) == np.repeat(left, frac.size)
        same = same.reshape(pts.shape)
        j = np.where(same.all(axis=1), frac.size, np.argmin(same, axis=1))
        grid_pts = np.concatenate([a[:, None], pts, c[:, None]], axis=1)
        a, c = grid_pts[np.arange(ii.size), j], grid_pts[np.arange(ii.size), j + 1]
    return a, c


def _roots(flat, run, key, ii, a, c, left, right):
    """The change of the end state in each bracket ``[a, c]`` (elements ``ii``, end
    states ``left`` and ``right`` at its ends, ``-1`` sticking) located as the root of
    the end margin of the earlier end state ``j``
    (:func:`~impactsym.engines.drake.stepping.end_margin`: smooth in the phase, through
    zero where state ``j`` stops or starts ending), to the width :data:`_WIDTH` of the
    multisection.

    Each call evaluates one margin per bracket (a margin costs a full contact run, and
    large batches pay per phase): the estimate is the regula falsi on the bracket,
    corrected by a Newton step on the quadratic through the bracket's ends and the
    phase beyond the end moved last (where those three rise; superlinear), and the
    phase evaluated lies past it, towards the bracket's farther end, by a quarter of
    the width, doubled after each one that fell short. Consecutive phases then straddle
    the root and the bracket closes from both sides; the last two, a width apart, shut
    it (the two straddling phases of a certificate, one per call). Where the margin is
    rounding the end test flips back and forth over a band of the phase (module
    docstring): the doubling reaches past the band, and where the bracket has not
    halved in three calls while phases keep falling short, a bisection step. Few
    brackets left (``q = _FAN_ROWS // brackets`` from 2: 256 brackets or fewer) take a
    fan of ``q`` phases per call
    instead (up to :data:`_FAN`: a call costs ~0.8 ms whatever its few rows), at the
    same step doubled outwards past the estimate and before it (``q = 2``: the two
    straddling it by a quarter width). Of the phases of one call the first change is
    kept, as the multisection keeps it. Measured over 10^4 random contacts of 2-100
    steps (large batches: one phase per call): 9.1 margins per change for ``d v`` up
    to 4, 11.5 for 4-5.5 (the former falsi, two phases per call straddling its estimate,
    then trisection: 18.2 and 24.1); small batches take about half the
    calls (20 designs: 6-9 against 13-19; all phases of a call run together). Brackets
    of contacts with ``d v`` above :data:`_FLOOR` are left to the multisection (module
    docstring). The phases' side is
    :func:`~impactsym.engines.drake.stepping.step_contact`'s own end test at state ``j``.
    Returns ``(found, a, c, at_found)``; ``found`` is False where a state before ``j``
    ends, the contact's ``d v`` exceeds :data:`_FLOOR`, a bracket sticks at an end, a margin
    is not finite, or the bracket is not
    shut after :data:`_ROOT_CALLS` calls; and where the end states of
    :func:`step_contact` at the final ``a`` and ``c`` are not ``left`` and another
    (then the multisection decides); ``at_found`` holds the contact's record at
    ``(a, c)`` (``n x 2``) where found (the pieces' ends: not run again).
    """
    n = ii.size
    found = np.zeros(n, bool)
    a, c = a.copy(), c.copy()
    # the records at the final (a, c) where found
    at_found = ContactEnds(*(np.zeros((n, 2), t) for t in (float, float, bool, float, float)))
    j = np.minimum(left, right)
    live = np.flatnonzero((j >= 0) & (flat[1][ii] * flat[5][ii] <= _FLOOR))
    if live.size == 0:
        return found, a, c, at_found
    sign = np.where(left == j, 1.0, -1.0)  # f = sign * margin: f <= 0 at the left end

    def side(rows, p):
        """``f`` at phases ``p`` (``len(rows) x q``: ``q`` per bracket ``rows``),
        whether each is on the left side, and whether the margin decides there."""
        q = p.shape[1]
        r = np.repeat(rows, q)
        k, d, _, m, g, v, h = (x[ii[r]] for x in flat)  # (no relaxation time)
        margin, ends, valid = end_margin(k, d, m, g, v, h, p.ravel(), j[r])
        f = (sign[r] * margin).reshape(-1, q)
        is_left = (ends == (left[r] == j[r])).reshape(-1, q)
        ok = (valid & np.isfinite(margin)).reshape(-1, q).all(axis=1)
        return f, is_left, ok

    f, is_left, ok = side(live, np.column_stack([a[live], c[live]]))
    ok &= is_left[:, 0] & ~is_left[:, 1] & (f[:, 0] <= 0) & (f[:, 1] > 0)
    live = live[ok]
    fa, fc = np.zeros(n), np.zeros(n)
    fa[live], fc[live] = f[ok, 0], f[ok, 1]
    p, fp = np.full(n, np.nan), np.full(n, np.nan)  # the phase beyond the end moved last
    short = np.zeros(n)  # phases in a row that fell short of the root
    widths = np.tile(c - a, (3, 1))  # the bracket's width after the last three calls
    halve = np.zeros(n, bool)  # bisection next
    for _ in range(_ROOT_CALLS):
        if live.size == 0:
            break
        la, lc, lfa, lfc, lp, lfp = (y[live] for y in (a, c, fa, fc, p, fp))
        with np.errstate(all="ignore"):
            xs = la - lfa * (lc - la) / (lfc - lfa)  # regula falsi
            slope = (lfc - lfa) / (lc - la)
            s_a, s_c = (lfp - lfa) / (lp - la), (lfp - lfc) / (lp - lc)
            curv = (s_a - slope) / (lp - lc)  # f[a, c, p]
            est = xs - curv * (xs - la) * (xs - lc) / (slope + curv * (2.0 * xs - la - lc))
        est = np.where((s_a > 0) & (s_c > 0) & (est > la) & (est < lc), est, xs)
        far = np.where(lc - est > est - la, 1.0, -1.0)
        # q phases per bracket: few brackets left take a fan of them (calls cost more
        # than phases there), past the estimate towards the far end and before it
        q = int(np.clip(_FAN_ROWS // live.size, 1, _FAN))
        before = q // 2
        fan = np.concatenate([-(2.0 ** np.arange(before))[::-1], 2.0 ** np.arange(q - before)])
        step = 0.25 * _WIDTH * 2.0 ** np.minimum(short[live], 64.0)  # (64: past any bracket)
        x = est[:, None] + (far * step)[:, None] * fan
        x = np.sort(x, axis=1)
        inside = (x > la[:, None]) & (x < lc[:, None])
        mid = ~inside.any(axis=1) | halve[live]  # (also where est is nan): multisection
        x = np.where(inside, x, np.clip(x, la[:, None], lc[:, None]))
        split = la[:, None] + (lc - la)[:, None] * (np.arange(1, q + 1) / (q + 1))
        x[mid] = split[mid]
        f, is_left, ok = side(live, x)
        # the first change, as the multisection keeps it
        i = np.where(is_left.all(axis=1), q, np.argmin(is_left, axis=1))
        rows = np.arange(live.size)
        xf, ff = np.column_stack([la, x, lc]), np.column_stack([lfa, f, lfc])
        missed = ~mid & ((i == 0) | (i == q)) & ((q > 1) | ((far > 0) == (i == q)))
        short[live] = np.where(mid, short[live], np.where(missed, short[live] + q - before, 0))
        nxt = np.where(i < q, i + 2, np.maximum(i - 1, 0))  # the point beyond the moved end
        r = live[ok]
        a[r], fa[r] = xf[rows, i][ok], ff[rows, i][ok]
        c[r], fc[r] = xf[rows, i + 1][ok], ff[rows, i + 1][ok]
        p[r], fp[r] = xf[rows, nxt][ok], ff[rows, nxt][ok]
        width = c[live] - a[live]
        halve[live] = (width > 0.5 * widths[-1, live]) & (short[live] >= 2)
        widths[1:, live] = widths[:-1, live]
        widths[0, live] = width
        shut = ok & (width <= _WIDTH)
        found[live[shut]] = True
        live = live[ok & ~shut]
    done = np.flatnonzero(found)
    if done.size:  # the end states of the full contact at the final ends
        rows = np.repeat(ii[done], 2)
        p = np.column_stack([a[done], c[done]]).ravel()
        at_ends = _fields(run(rows, p))
        k_end = key(at_ends, p, rows).reshape(-1, 2)
        found[done] = (k_end[:, 0] == left[done]) & (k_end[:, 1] != left[done])
        for f, g in zip(at_found, at_ends, strict=True):
            f[done] = g.reshape(-1, 2)
    return found, a, c, at_found
