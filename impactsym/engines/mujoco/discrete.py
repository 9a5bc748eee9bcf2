r"""MuJoCo's contact at the user's timestep: dispatch per integrator, and the phase statistics.

:func:`step_contact` gives the contact at a touch phase as the engine's states show it
(:class:`~impactsym.engines.mujoco.stepping.StepContact`) for ``integrator`` ``"euler"``
or ``"implicitfast"`` (the same map without joint damping:
:func:`~impactsym.engines.mujoco.euler.euler_contact`). :func:`phase_summary` averages
over the touch phase, uniform in ``[0, 1)``, and bounds the result over all phases.

The restitution and contact time are piecewise smooth in the phase, with jumps where the
end step changes (`docs/physics.md#touch-phase`). The summary evaluates the contact on a
grid of phases, locates every change of the end step (or of the stick verdict) between
grid points by an 8-ary search in the phase to ``2^-42``, and integrates each smooth piece by
Gauss-Legendre (exact for the flat impedance, whose restitution is a quadratic in the
phase on each piece; a varying-impedance Euler contact's pieces are cut where a state
that pushes crosses a kink of the impedance, :mod:`~impactsym.engines.mujoco.euler_kinks`,
without which the mean restitution was up to ``7.4e-5`` off, against a dense midpoint
mean); the range takes the piece ends (the one-sided limits at the jumps),
the nodes and the vertex of the quadratic through each piece. An interval whose samples
show two end steps (two jumps in it) is redone on a finer grid, and so is one whose
states' margins come near zero between the samples (varying-impedance Euler: a band of
another end step narrower than the samples' spacing). For a varying-impedance
Euler contact a jump between two end steps is first narrowed by a bracketed secant on the
continuous end value (:func:`~impactsym.engines.mujoco.euler.euler_end_value`), and the
search samples only its lattice points near that bracket: the same cells, far fewer runs.

Flat-impedance Euler contacts skip all that: their pieces and integrals are in closed
form (:mod:`~impactsym.engines.mujoco.euler_phase`), the general way taking only the
elements it leaves (an unstable map, a coast that re-engages). :func:`phase_mean` is the
summary without phase 0 itself, what a design iterating on the mean needs.

All quantities are SI: seconds, metres, m/s, m/s^2.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.mujoco.euler import euler_contact, euler_end_value
from impactsym.engines.mujoco.euler_kinks import kink_cuts, split_pieces
from impactsym.engines.mujoco.euler_phase import flat_phases
from impactsym.engines.mujoco.model import (
    Coefficients,
    effective_impedance,
    impedance_at,
    is_flat,
)
from impactsym.engines.mujoco.phase_secant import secant_bracket
from impactsym.engines.mujoco.rk4 import rk4_contact
from impactsym.engines.mujoco.rk4_entry import rk4_entry_phases
from impactsym.engines.mujoco.rk4_record import PATTERN_BITS
from impactsym.engines.mujoco.stepping import StepContact
from impactsym.engines.phase_pieces import integrate_pieces, reduce_at, vertex
from impactsym.records import ArrayRecord

__all__ = [
    "INTEGRATORS",
    "PhaseSummary",
    "bounds_without_search",
    "phase_mean",
    "phase_summary",
    "step_contact",
]


#: the discrete contact model of each MuJoCo integrator (same signature)
INTEGRATORS = {"euler": euler_contact, "implicitfast": euler_contact, "rk4": rk4_contact}
#: phases where an integrator's entering step changes structure (besides end-step jumps)
ENTRY_PHASES = {"rk4": rk4_entry_phases}

_GRID = 8  # phase intervals searched for jumps of the end step
_FINEST = _GRID * 4**5  # grid intervals at most where pieces hide jumps (1/8192 of a phase)
# RK4 at most 512: its stage patterns put slivers next to end-step changes (3e-5 of a
# phase, 3.5e-7 in e) that a finer grid never separates, at 2x the cost per level
_FINEST_RK4 = _GRID * 4**3
_WAYS, _ROUNDS = 8, 14  # search per jump: 8 sub-intervals a round (8^-14 = 2^-42 < 1e-12)
_MARGIN = 64.0  # lattice cells on each side of the secant bracket sampled all the same
_GOLDEN = 40  # golden-section steps for an extreme inside a piece
_NODES = 5  # Gauss-Legendre nodes per piece


def bounds_without_search(integrator: str, solimp: tuple[float, ...]) -> bool:
    """Whether :func:`phase_mean`'s bounds are exact with ``bounds=False`` too: the
    pieces are quadratics in the phase (Euler and ``implicitfast`` at flat impedance),
    so the extremes come from their ends and vertices without a search. Internal."""
    return integrator not in ENTRY_PHASES and is_flat(solimp)


def check_integrator(integrator: object) -> str:
    """``integrator`` as a key of :data:`INTEGRATORS`, or raise naming it. Internal."""
    if not isinstance(integrator, str) or integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {sorted(INTEGRATORS)}, got {integrator!r}")
    return integrator


def step_contact(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
    *,
    integrator: str,
) -> StepContact:
    """The contact at touch phase ``phase`` under MuJoCo's ``integrator`` (arrays, SI).

    Arguments as in :func:`~impactsym.engines.mujoco.euler.euler_contact` (``coeffs``
    with refsafe applied).
    """
    model = INTEGRATORS[check_integrator(integrator)]
    return model(coeffs, solimp, rho, gravity, speed, timestep, phase)


@dataclass(frozen=True, eq=False)
class PhaseSummary(ArrayRecord):
    """The contact over the touch phase (uniform in ``[0, 1)``), arrays, SI.

    Attributes
    ----------
    restitution, contact_time
        Means over the phase (``contact_time`` is ``inf`` where some phases stick).
    restitution_min, restitution_max, contact_time_min, contact_time_max
        Bounds that hold at every phase.
    stick_fraction
        Fraction of the phases at which the body sticks.
    """

    restitution: np.ndarray
    contact_time: np.ndarray
    restitution_min: np.ndarray
    restitution_max: np.ndarray
    contact_time_min: np.ndarray
    contact_time_max: np.ndarray
    stick_fraction: np.ndarray


def phase_summary(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    *,
    integrator: str,
    known: np.ndarray | None = None,
) -> PhaseSummary:
    """Mean over the touch phase and bounds over every phase (module docstring).

    Arguments as in :func:`step_contact`, without ``phase``; ``known`` (or ``None``) is
    :func:`phase_mean`'s result already at hand, ``(7, size)`` over the flattened
    broadcast elements with ``nan`` columns where it is not (it must be exact there,
    bounds included).
    """
    model = INTEGRATORS[integrator]
    b, k, rho, g, v, dt = np.broadcast_arrays(
        *(
            np.asarray(a, float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep)
        )
    )
    if known is None:
        inner = phase_mean(Coefficients(b, k), solimp, rho, g, v, dt, integrator=integrator)
    else:
        out = np.array(known, float).reshape(7, -1)
        todo = np.flatnonzero(np.isnan(out[0]))
        if todo.size:
            part = phase_mean(
                Coefficients(*(a.ravel()[todo] for a in (b, k))),
                solimp, *(a.ravel()[todo] for a in (rho, g, v, dt)), integrator=integrator,
            )  # fmt: skip
            names = (f.name for f in dataclasses.fields(PhaseSummary))
            out[:, todo] = np.stack([getattr(part, name) for name in names])
        inner = PhaseSummary(*(f.reshape(b.shape) for f in out))
    zero = model(Coefficients(b, k), solimp, rho, g, v, dt, np.zeros(b.shape))  # phase 0
    return PhaseSummary(
        inner.restitution,
        inner.contact_time,
        np.minimum(inner.restitution_min, zero.restitution),
        np.maximum(inner.restitution_max, zero.restitution),
        np.minimum(inner.contact_time_min, zero.contact_time),
        np.maximum(inner.contact_time_max, zero.contact_time),
        inner.stick_fraction,
    )


def phase_mean(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    *,
    integrator: str,
    bounds: bool = True,
    resolve_sticking: bool = True,
) -> PhaseSummary:
    """:func:`phase_summary` with the bounds over the phases in ``(0, 1)`` only.

    Phase 0 itself (one model run) is left out: what a design iterating on the mean
    needs. Flat-impedance Euler contacts take the closed form of
    :mod:`~impactsym.engines.mujoco.euler_phase`; the rest the general way, where
    ``bounds=False`` skips the search for extremes inside pieces (the ranges are then
    only those of the samples: for a design that needs the mean alone), and
    ``resolve_sticking=False`` leaves out elements the closed form proves to stick at
    some phase, or the general way finds sticking at a phase of its grid (a design
    rejects them whatever their share): their contact time is ``inf`` and the other
    fields ``nan``.
    """
    model = INTEGRATORS[check_integrator(integrator)]
    arrays = np.broadcast_arrays(
        *(
            np.asarray(a, float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep)
        )
    )
    shape = arrays[0].shape
    b, k, rho, g, v, dt = (a.ravel() for a in arrays)
    size = b.size
    out = np.full((7, size), np.nan)  # the fields of PhaseSummary, phase 0 left out
    todo = np.arange(size)
    if integrator in ("euler", "implicitfast") and is_flat(solimp) and size:
        d = float(impedance_at(np.zeros(()), solimp))
        dp = effective_impedance(d, rho)
        kdt2, bdt = d * k * dt * dt, b * dt
        fast = flat_phases(kappa=dp * kdt2, beta=dp * bdt, dp=dp, G=g * dt / v, bdt=bdt, dkdt2=kdt2)
        fields = (
            fast.restitution, fast.steps * dt, fast.restitution_min, fast.restitution_max,
            fast.steps_min * dt, fast.steps_max * dt, fast.stick_fraction,
        )  # fmt: skip
        out[:, fast.ok] = np.stack(fields)[:, fast.ok]
        done = fast.ok
        if not resolve_sticking:
            out[1, fast.sticks_at_some_phase] = np.inf
            done = done | fast.sticks_at_some_phase
        todo = np.flatnonzero(~done)
    if todo.size:
        out[:, todo] = _split_and_integrate(
            model, integrator, solimp, b[todo], k[todo], rho[todo], g[todo], v[todo], dt[todo],
            bounds=bounds, skip_stuck=not resolve_sticking,
        )  # fmt: skip
    return PhaseSummary(*(np.reshape(f, shape) for f in out))


def _split_and_integrate(
    model,
    integrator,
    solimp,
    b,
    k,
    rho,
    g,
    v,
    dt,
    intervals: int = _GRID,
    bounds: bool = True,
    skip_stuck: bool = False,
) -> np.ndarray:
    """The phase statistics the general way (module docstring): ``(7, size)``, phase 0 out.

    A grid interval can hold two jumps of the end step (the search finds one); a piece
    whose samples do not all share one end step shows it, and its element is done again
    on a grid four times finer, up to :data:`_FINEST` intervals (jumps closer than that
    are integrated as one piece: at 512 intervals, two jumps 1/2000 of a phase apart
    were 1.5e-4 steps off, found by review); RK4 down to :data:`_FINEST_RK4`. Euler at a
    varying impedance first cuts the pieces at the impedance's kinks (``kink_cuts``, more node
    samples), and its states' margins flag a piece whose end step may change between
    samples all the same (a band narrower than the samples' spacing). ``skip_stuck``:
    an element that sticks at a grid phase is left there (contact time ``inf``, the rest
    ``nan``; a design rejects it whatever its share, and its other phases, the long
    runs of a body coming to rest, cost the most).
    """
    size = b.size

    def run(i, p):
        """The contact of elements ``i`` at phases ``p`` (same shape)."""
        c = Coefficients(b[i], k[i])
        return model(c, solimp, rho[i], g[i], v[i], dt[i], p)

    # the phase grid, with the phases where the model's entering step changes its
    # structure (RK4's stages 2 and 3 reaching the contact) as extra piece ends
    grid = np.linspace(0.0, 1.0, intervals + 1)
    grid[0] = 1e-300  # the limit phase -> 0+ (phase 0 itself is checked on its own)
    breaks = np.zeros((size, 0))
    if integrator in ENTRY_PHASES:
        breaks = ENTRY_PHASES[integrator](g, v, dt).reshape(size, -1)
        breaks = np.where(np.isnan(breaks), 1.0, breaks)  # none: an empty piece at 1
    edges = np.sort(np.concatenate([np.tile(grid, (size, 1)), breaks], axis=1), axis=1)
    lo, hi = edges[:, :-1].copy(), edges[:, 1:]
    # a piece that starts at such a phase starts just after it (the stage is in contact
    # only for x > 0: the phase itself belongs to the piece before)
    after = (breaks[:, None, :] == lo[:, :, None]).any(axis=2) & (lo < 1.0)
    lo = np.where(after, lo + 1e-12, lo)
    n_pieces = lo.shape[1]
    i_all = np.repeat(np.arange(size), n_pieces)
    at_edges = None
    if not after.any():  # the pieces share their ends: one run per edge
        i_e = np.repeat(np.arange(size), n_pieces + 1)
        at_edges = run(i_e, edges.ravel())
        at = _end_step(at_edges, edges.ravel(), dt[i_e]).reshape(size, -1)
        key_lo, key_hi = at[:, :-1], at[:, 1:]
    else:
        at_lo, at_hi = run(i_all, lo.ravel()), run(i_all, hi.ravel())
        key_lo = _end_step(at_lo, lo.ravel(), dt[i_all]).reshape(size, n_pieces)
        key_hi = _end_step(at_hi, hi.ravel(), dt[i_all]).reshape(size, n_pieces)
    stuck = ((key_lo < 0) | (key_hi < 0)).any(axis=1) if skip_stuck else None
    if stuck is not None and stuck.any():
        out = np.full((7, size), np.nan)
        out[1, stuck] = np.inf
        keep = np.flatnonzero(~stuck)
        if keep.size:
            out[:, keep] = _split_and_integrate(
                model, integrator, solimp, b[keep], k[keep], rho[keep], g[keep], v[keep],
                dt[keep], intervals, bounds, skip_stuck,
            )  # fmt: skip
        return out
    # the jump inside each interval whose ends differ
    jump = key_lo != key_hi
    ii, kk = np.nonzero(jump)
    a, c = lo[ii, kk].copy(), hi[ii, kk].copy()
    left_key = key_lo[ii, kk]
    lo_j, hi_j = a.copy(), c.copy()
    # Euler: a jump between two end steps is a root of the continuous end value of the
    # earlier one (euler_end_value). A bracketed secant narrows it to the width of
    # the search's last cell; the search then needs that value only at its lattice
    # points inside the bracket (the others lie on a known side), and its cells are the
    # same as when every point is sampled. Checked against the end step at the cell's
    # start; the rest (stick verdicts, RK4, failed checks) sample the end step.
    secant = np.zeros(ii.size, bool)
    a_s, c_s = np.full(ii.size, np.nan), np.full(ii.size, np.nan)
    value, m_end, rising = None, None, None
    # (a varying impedance only: there the model runs the same recurrence, so the end
    # step changes exactly where the value changes sign; at flat impedance it comes
    # from the closed form, whose rounding differs)
    if integrator in ("euler", "implicitfast") and not is_flat(solimp) and ii.size:
        right_key = key_hi[ii, kk]
        m_end = np.minimum(left_key, right_key)
        rising = left_key < right_key

        def value(j, p):
            i = ii[j]
            c_j = Coefficients(b[i], k[i])
            return euler_end_value(c_j, solimp, rho[i], g[i], v[i], dt[i], p, m_end[j])

        sec = np.flatnonzero((left_key >= 0) & (right_key >= 0))
        if sec.size:
            width = (c[sec] - a[sec]) * float(_WAYS) ** -_ROUNDS
            a_s[sec], c_s[sec], secant[sec] = secant_bracket(
                lambda j, p, m: value(sec[j], p), a[sec], c[sec], m_end[sec],
                rising[sec], width,
            )  # fmt: skip
            # the value is exact to rounding only: near its root its sign (and the end
            # step with it) may flip back and forth, so a margin around the bracket
            # is sampled as well
            a_s[sec] -= _MARGIN * width
            c_s[sec] += _MARGIN * width
    a, c = _lattice_search(run, dt, ii, a, c, left_key, secant, a_s, c_s, value, rising)
    if secant.any():
        check = np.flatnonzero(secant)
        res = run(ii[check], a[check])
        bad = check[_end_step(res, a[check], dt[ii[check]]) != left_key[check]]
        if bad.size:
            none = np.zeros(bad.size, bool)
            a[bad], c[bad] = _lattice_search(
                run, dt, ii[bad], lo_j[bad], hi_j[bad], left_key[bad], none, None, None,
                None, None,
            )  # fmt: skip
    # pieces: [lo, a], [c, hi] for jumping intervals, [lo, hi] otherwise
    starts = [lo.ravel()]
    ends = [np.where(jump, np.nan, hi).ravel()]
    owner = [np.repeat(np.arange(size), n_pieces)]
    ends[0][np.ravel_multi_index((ii, kk), jump.shape)] = a
    starts.append(c)
    ends.append(hi[ii, kk])
    owner.append(ii)
    p0, p1, own = np.concatenate(starts), np.concatenate(ends), np.concatenate(owner)
    # Euler at a varying impedance: the pieces are cut where a state that pushes crosses
    # a kink of the impedance (euler_kinks), so that Gauss-Legendre sees smooth pieces
    parent, hidden_own = np.arange(p0.size), np.zeros(0, np.int64)
    if integrator in ("euler", "implicitfast") and not is_flat(solimp):
        steps = np.where(jump, key_lo, np.maximum(key_lo, key_hi)).ravel()
        steps = np.concatenate([steps, key_hi[ii, kk]])
        c_own = Coefficients(b[own], k[own])
        *cuts, hidden = kink_cuts(c_own, solimp, rho[own], g[own], v[own], dt[own], p0, p1, steps)
        p0, p1, parent = split_pieces(p0, p1, *cuts)
        hidden_own = own[hidden]
        own = own[parent]
    run_pieces = run
    if at_edges is not None:  # the piece ends on the grid were run already: reused
        edge = np.arange(size)[:, None] * (n_pieces + 1) + np.arange(n_pieces)[None, :]
        end = (edge + 1).ravel()
        end[jump.ravel()] = -1  # the jump's left side ends at a: not run yet
        start = np.concatenate([edge.ravel(), np.full(ii.size, -1)])  # c: not run yet
        end = np.concatenate([end, ii * (n_pieces + 1) + kk + 1])
        new = np.diff(parent, prepend=-1, append=parent.size) != 0  # cuts: not run yet
        start = np.where(new[:-1], start[parent], -1)
        end = np.where(new[1:], end[parent], -1)
        run_pieces = _reuse_ends(run, at_edges, start, end, _NODES + 2)
    pieces = integrate_pieces(run_pieces, p0, p1, own, size, nodes=_NODES)
    pts, res, e, t = pieces.pts, pieces.result, pieces.restitution, pieces.contact_time
    key = _end_step(res, pts.ravel(), dt[np.repeat(own, pts.shape[1])]).reshape(pts.shape)
    mixed = np.zeros(size, bool)
    mixed[own[(key != key[:, 3:4]).any(axis=1)]] = True
    mixed[hidden_own] = True
    e_mean, t_mean = pieces.restitution_mean, pieces.contact_time_mean
    stick_frac = pieces.stick_fraction
    # the range: piece ends, nodes, and the vertex of the quadratic through each piece
    top = vertex(pts[:, [0, 3, -1]], e[:, [0, 3, -1]], p0, p1)
    e_lo = np.fmin(e.min(axis=1), top)
    e_hi = np.fmax(e.max(axis=1), top)
    if bounds and not bounds_without_search(integrator, solimp):  # no quadratics
        e_lo = np.fmin(e_lo, _interior_extreme(run, own, pts, e, -1.0))
        e_hi = np.fmax(e_hi, _interior_extreme(run, own, pts, e, 1.0))
    e_min = reduce_at(np.minimum, own, e_lo, size, np.inf)
    e_max = reduce_at(np.maximum, own, e_hi, size, -np.inf)
    t_min = reduce_at(np.minimum, own, t.min(axis=1), size, np.inf)
    t_max = reduce_at(np.maximum, own, t.max(axis=1), size, -np.inf)
    out = np.stack([e_mean, t_mean, e_min, e_max, t_min, t_max, stick_frac])
    redo = np.flatnonzero(mixed)
    if redo.size and intervals < (_FINEST_RK4 if integrator == "rk4" else _FINEST):
        out[:, redo] = _split_and_integrate(
            model, integrator, solimp, b[redo], k[redo], rho[redo], g[redo], v[redo],
            dt[redo], 4 * intervals, bounds, skip_stuck,
        )  # fmt: skip
    return out


def _reuse_ends(run, known, start, end, width):
    """``run`` for the samples of the pieces (``width`` a piece: its start, the nodes, its
    end), taking a piece's start and end from ``known`` (a record of the model at the
    grid edges) where ``start``, ``end`` index it (``-1``: run them)."""

    def run_pieces(i, p):
        need = np.ones((start.size, width), bool)
        need[:, 0], need[:, -1] = start < 0, end < 0
        src = np.full((start.size, width), -1)
        src[:, 0], src[:, -1] = start, end
        need, src = need.ravel(), src.ravel()
        res = run(i[need], p[need])
        fields = []
        for f in dataclasses.fields(res):
            got, old = getattr(res, f.name), getattr(known, f.name)
            out = np.empty(p.size, np.result_type(got, old))
            out[need], out[~need] = got, old[src[~need]]
            fields.append(out)
        return type(res)(*fields)

    return run_pieces


def _lattice_search(run, dt, ii, a, c, left_key, narrowed, a_s, c_s, value, rising):
    """The 8-ary search for the jump in ``[a, c]`` of elements ``ii`` (module docstring).

    7 phases per round, the first whose end step differs from ``left_key`` bounds the
    jump (14 rounds: ``8^-14 = 2^-42`` of a grid interval). Where ``narrowed``, the jump
    lies in ``(a_s, c_s)``: a phase at or below ``a_s`` is on its left, at or above
    ``c_s`` on its right, and one inside is placed by the sign of ``value(j, p)``
    (``<= 0`` on the left where ``rising``) instead of the model's end step.
    """
    a, c = a.copy(), c.copy()
    frac = np.arange(1, _WAYS) / _WAYS
    sample = np.flatnonzero(~narrowed)
    for _ in range(_ROUNDS):
        if ii.size == 0:
            break
        m = a[:, None] + (c - a)[:, None] * frac[None, :]
        differs = np.zeros(m.shape, bool)
        if sample.size:
            i_t, m_t = ii[sample], m[sample]
            res = run(np.repeat(i_t, _WAYS - 1), m_t.ravel())
            key = _end_step(res, m_t.ravel(), np.repeat(dt[i_t], _WAYS - 1)).reshape(m_t.shape)
            differs[sample] = key != left_key[sample, None]
        if narrowed.any():
            differs |= narrowed[:, None] & (m >= c_s[:, None])
            r, q = np.nonzero(narrowed[:, None] & (m > a_s[:, None]) & (m < c_s[:, None]))
            if r.size:
                h = value(r, m[r, q])
                differs[r, q] = (h <= 0) != rising[r]
        j = np.where(differs.any(axis=1), np.argmax(differs, axis=1), _WAYS - 1)
        pts = np.concatenate([a[:, None], m, c[:, None]], axis=1)
        rows = np.arange(ii.size)
        a, c = pts[rows, j], pts[rows, j + 1]
    return a, c


def _interior_extreme(run, own, pts, e, sign):
    """Largest (``sign = 1``) or smallest (``-1``) restitution inside each piece.

    Where a piece's extreme sample is one of its interior nodes, golden-section search
    between the neighbouring nodes (``_GOLDEN`` steps: ``0.618^40`` of a piece, ``~1e-9``
    of a phase) finds it; it need not be the quadratic's vertex (a varying impedance has
    kinks where a state crosses the impedance width, RK4's pieces are not quadratics).
    ``nan`` where the extreme sample is a piece end.
    """
    j = np.argmax(sign * e, axis=1)
    inner = np.flatnonzero((j > 0) & (j < pts.shape[1] - 1))
    out = np.full(e.shape[0], np.nan)
    if inner.size == 0:
        return out
    a, c = pts[inner, j[inner] - 1], pts[inner, j[inner] + 1]
    owner = own[inner]
    ratio = 0.5 * (np.sqrt(5.0) - 1.0)
    x1, x2 = c - ratio * (c - a), a + ratio * (c - a)
    f1, f2 = sign * run(owner, x1).restitution, sign * run(owner, x2).restitution
    best = sign * e[inner, j[inner]]
    for _ in range(_GOLDEN):
        right = f2 > f1  # the extreme lies in [x1, c]
        a, c = np.where(right, x1, a), np.where(right, c, x2)
        x1, x2, f1, f2 = (
            np.where(right, x2, c - ratio * (c - a)),
            np.where(right, a + ratio * (c - a), x1),
            np.where(right, f2, np.nan),
            np.where(right, np.nan, f1),
        )
        new = np.where(right, x2, x1)
        f_new = sign * run(owner, new).restitution
        f1, f2 = np.where(right, f1, f_new), np.where(right, f_new, f2)
        best = np.fmax(best, np.fmax(f1, f2))
    out[inner] = sign * best
    return out


def _end_step(res: StepContact, phase: np.ndarray, dt: np.ndarray) -> np.ndarray:
    """The end state's index counted from touch, ``contact_time / dt - phase`` (-1: sticks).

    The key of a smooth piece: unlike ``steps`` it does not depend on which state first
    detects the contact. An RK4 record also jumps (or has a kink) where a stage gains or
    loses the force with the end step unchanged
    (:mod:`~impactsym.engines.mujoco.rk4_record`): its key is ``index * 2^28`` plus its
    stage pattern (below ``2^28``).
    """
    with np.errstate(invalid="ignore", over="ignore"):
        index = np.rint(res.contact_time / dt - phase)
    pattern = getattr(res, "stage_pattern", None)
    if pattern is not None:
        index = index * 2.0**PATTERN_BITS + pattern
    return np.where(res.sticks, -1, index)
