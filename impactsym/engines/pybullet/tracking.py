r"""PyBullet's map run with the phase derivatives of its state: the roots ahead.

Where the branch pattern of :func:`~impactsym.engines.pybullet.stepping.step_pattern`
is constant, the state of every (sub)step is an affine map of the free-flight state
``-1``, itself quadratic in the phase ``p`` (``x = v t + g t^2/2``, ``w = v + g t``,
``t = (p - 1) h``), so every quantity whose sign picks a branch (the gap ``d = s - x``
of the speculative branch, the bias ``b`` of the clipped impulse, the processing
threshold ``x + threshold``, the restitution threshold) is a quadratic in ``p``, and
:func:`tracked_pattern` carries the first and second phase derivatives of the state
along the run: the first root ahead of a phase, over the (sub)steps up to the end state,
is the next point where the pattern can change
(:mod:`~impactsym.engines.pybullet.phase_means` builds the pieces of constant pattern
from them). ``b`` is followed across a change of the speculative branch it does not feel
(where ``b <= 0`` at ``d = 0`` the impulse is zero on both sides, so ``b`` changes
formula but the pattern not): its root counts on the side of ``d`` whose formula gives
it. The roots are solved only at the sub-steps where one can lie within a phase (a bound
from the quadratic's coefficients), the few next to a change of branch. All arrays, SI.

With gravity the run watches the coast after the end state too. There the body, its
contact over, moves on inside the overlap, and gravity can bring the force back before
it leaves (``x <= 0`` at a state): it sticks, a change of the pattern after the end
state that no root up to it shows (a band of sticking phases inside one of the piece
search's 8 grid intervals went unseen: stick fraction 0 and a finite mean contact time
where the truth is ``inf``; 38 of ~38,000 random short contacts, up to 1.5e-2 in the
mean restitution). The coast's sub-steps follow the same branch rules, so their biases are
watched as before, and the coast's length is the other thing that can change: the
penetration ``x`` at each of its states, a quadratic too, whose root moves the state
where the body leaves. A root that lengthens the coast (``x <= 0`` here) counts always;
one that shortens it (``x > 0`` here) counts only where the run sticks (a coast that
leaves without a force leaves without one when shorter: the pattern counts the
(sub)steps up to the end alone). What stays unseen is a coast that outlasts the step
budget without a force (with gravity pulling it back not met; left to the grid's
check and search). Without gravity the
coast is not watched: a contact that ended separating never sticks
(:func:`~impactsym.engines.pybullet.stepping.end_final`), and
:mod:`~impactsym.engines.pybullet.phase_means` checks the rest.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.pybullet.stepping import (
    DEFAULT_RESTITUTION_THRESHOLD,
    close_state,
    end_final,
    pattern_code,
    run_live,
    start_state,
    substep_impulse,
)
from impactsym.numeric.poly import quadratic_at, quadratic_roots_ahead

__all__ = ["END_STATE", "final_at", "track", "tracked_pattern"]

_REACH = 1.0  # roots ahead further than this (in phase) lie past every phase range
#: the tracked run's end state (rows of :func:`track`'s third result): the speed ``w``
#: with two phase derivatives, the penetration ``x`` with one
END_STATE = ("w_end", "w1_end", "w2_end", "x_end", "x1_end")


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
    pattern, first, end = track(*(a.ravel().copy() for a in arrays), settings)
    return pattern, first, end[:3]


def track(
    k: np.ndarray,
    c: np.ndarray,
    m: np.ndarray,
    v: np.ndarray,
    g: np.ndarray,
    H: np.ndarray,
    p: np.ndarray,
    settings: tuple,
    *,
    give_up: bool = False,
    horizon: Any = np.inf,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`tracked_pattern` of flat arrays (``settings``: ``substeps, slop,
    processing_threshold, velocity_restitution, restitution_threshold``), the end state
    ``(5, n)``: its speed ``w`` with two phase derivatives, then its penetration ``x``
    with the first (where the contact ended). ``give_up`` (no gravity): a run also stops
    where its end fails :func:`final_at` there (``u = 0``), its pattern then not read
    further: for the start of a piece whose element the phase means' grid search gives
    up (:mod:`~impactsym.engines.pybullet.phase_means`).
    ``horizon``: the root ahead is sought no further (fewer roots solved, :func:`_ahead`).
    With gravity the coast after the end state is watched too (module docstring): the
    roots of ``x`` at its states that shorten it, kept apart (``first_out``), count
    where the run sticks."""
    substeps = settings[0]
    fixed, state = start_state(k, c, m, v, g, H, p, substeps)
    # the phase derivatives ride along: x = x0 + x1 dp + x2 dp^2 / 2, w likewise
    size = k.size
    state.update({
        "x1": state["w"] * H, "x2": g * H * H, "w1": g * H, "w2": np.zeros(size),
        "first": np.broadcast_to(np.asarray(horizon, float), size).copy(),
        "w1_end": np.zeros(size), "w2_end": np.zeros(size), "x1_end": np.zeros(size),
        "first_out": np.full(size, np.inf),
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
    first = np.where(sticks, np.minimum(state["first"], state["first_out"]), state["first"])
    return pattern, first, np.stack([state[key] for key in END_STATE])


def _advance(a, n, limit, curved, give_up, substeps, slop, threshold, rest_coef, rest_threshold):
    """State ``n``: the map of :func:`~impactsym.engines.pybullet.stepping.step_pattern`
    (the same operations), the derivatives of ``x`` and ``w`` in the phase, and the first
    root of the branch quantities while the contact has not ended (with gravity: while
    the run goes on, and the roots of ``x`` at the coast's states; module docstring).
    Not ``curved`` (no gravity): the second derivatives are zeros, carried as the
    scalar ``0.0``."""
    h, erp, gain = a["h"], a["erp"], a["gain"]
    x, w = a["x"], a["w"]
    x1, w1 = a["x1"], a["w1"]
    x2, w2 = (a["x2"], a["w2"]) if curved else (0.0, 0.0)
    watching = ~a["ended"] & ~a["done"]
    if curved:  # with gravity the coast after the end state too: the force can come back
        coasting = a["ended"] & ~a["done"] & (a["g"] != 0.0)
        watching |= coasting
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
    was_done = a["done"]
    close_state(a, n, limit, dv * a["m"] / h, extremes=False)  # (the pattern alone)
    if curved:  # the coast's length: where a state's penetration changes sign
        out = a["ended"] & ~was_done & (a["g"] != 0.0)
        if out.any():  # (a root that shortens the coast changes a run that sticks alone)
            reach = np.minimum(first, _REACH) * (1.0 + 1e-9)
            inside = x > 0.0
            _lower(a["first_out"], out & inside, x, x1, x2, reach)
            _lower(first, out & ~inside, x, x1, x2, reach)
    stop = a["ended"] & (a["n_end"] == n)  # the end state: its speed's phase derivatives
    if stop.any():
        np.copyto(a["w1_end"], w1, where=stop)
        np.copyto(a["x1_end"], x1, where=stop)
        np.copyto(a["w2_end"], w2, where=stop)  # (0.0 where not curved)
        if not curved:  # without gravity what a run that ended final reports is final
            final = end_final(a, n, stop, substeps)
            if give_up:  # and one that fails final_at is given up (:func:`track`)
                j = np.flatnonzero(stop & ~final)
                ends = np.stack([a[key][j] for key in END_STATE])
                final[j] = ~final_at(0.0, n, ends, a["budget"][j], a["H"][j])
            a["done"] |= final


def final_at(
    u: Any, n_end: Any, state: np.ndarray, budget: np.ndarray, H: np.ndarray
) -> np.ndarray:
    """Per piece: whether at ``u`` from the phase where its pattern was read (end state
    ``n_end``, ``-1`` where it sticks; ``state`` that state and its phase derivatives,
    the ``(5, n)`` of :func:`track`) the contact ends separating within the step
    ``budget``: the finality test of the phase means' one-interval path
    (:mod:`~impactsym.engines.pybullet.phase_means`)."""
    w0, w1, _, x0, x1 = state
    room = (budget - np.asarray(n_end, float) - 2.0) * H
    w, x = w0 + w1 * u, x0 + x1 * u
    slack = 1e-9 * (np.abs(w0) + np.abs(w1))
    ok = (w + slack < 0.0) & (x + 1e-9 * (np.abs(x0) + np.abs(x1)) < room * (-w - slack))
    return ok & (np.asarray(n_end) >= 0)


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
    # (without a processing threshold every contact is within it: no mask to apply)
    inside = watch if threshold == np.inf else watch & within
    for q0, q1, q2, valid in q:
        _lower(first, watch if valid is None else inside, q0, q1, q2, reach, valid)


def _lower(first, watch, q0, q1, q2, reach, valid=None):
    """Lower ``first`` (in place) to the first root ahead of the quadratic ``q0 + q1 u +
    q2 u^2 / 2`` where ``watch`` and a root can lie before ``reach`` (:func:`_ahead`);
    ``valid`` ``(v0, v1, v2, positive)``: a root counts only where that quadratic is
    positive (``positive``) or not."""
    with np.errstate(invalid="ignore", over="ignore"):
        slope = (
            np.abs(q1) if np.ndim(q2) == 0 and q2 == 0 else np.abs(q1) + np.abs(q2) * (0.5 * reach)
        )
        near = np.abs(q0) <= slope * reach
    near &= watch
    j = np.flatnonzero(near)
    if j.size == 0:
        return

    def pick(q):  # (a second derivative may be the scalar 0.0)
        return q if np.ndim(q) == 0 else q[j]

    best = first[j]
    for root in quadratic_roots_ahead(q0[j], q1[j], pick(q2)):
        if valid is not None:  # the root counts where the side quantity allows it
            v0, v1, v2, positive = valid
            side = quadratic_at(v0[j], v1[j], pick(v2), root)
            root = np.where(side > 0 if positive else side <= 0, root, np.inf)
        best = np.minimum(best, root)
    first[j] = best
