r"""Drake's discrete point contact at the user's ``time_step``, exact per touch phase.

The touch phase is that of :mod:`impactsym.engines.mujoco.stepping` (``docs/physics.md``,
"Drake point contact"): geometric touch lies ``phase * time_step`` before the first state
that detects the contact, which carries the free-flight penetration
``x = v t + g t^2/2`` and approach rate ``v + g t`` at ``t = phase * time_step``. Drake
has no speculative contact, so the first force step follows one free step; it reports
the contact at penetration ``x >= 0``, so at ``phase = 0`` the state at touch is the
first detecting one.

From that state on the exact update of :mod:`impactsym.engines.drake.update` runs on
whole arrays (a loop over steps, vectorized over designs and phases). The contact ends at
the first state whose contact is gone (``x < 0``) or whose update carries no impulse; the
restitution is that state's separation speed over ``v`` (an impulse below ``1e-12 m v``
counts as zero: where the rebound approaches ``1/d`` the impulse decays geometrically
and only rounding would end it). If the impulse comes back while
the overlap lasts, or the body turns back inwards inside the overlap before the end (a
loaded contact settling: its energy only falls from there, so it never leaves), the body
sticks. The result is :class:`~impactsym.engines.mujoco.stepping.StepContact`.

A contact that provably never ends (settled deep in the well, creeping up to its rest, or
at rest to the last bit) is declared sticking as soon as it is decided, by the rules of
:mod:`~impactsym.engines.drake.settling` checked every :data:`_SETTLE_EVERY` updates,
instead of after :data:`MAX_STEPS` updates.

:func:`contact_ends` is the same loop for the phase means (the restitution, contact
time, stick verdict and largest overlap of ``"tamsi"``/``"similar"``/``"lagged"``), bit
for bit, about six times faster: the update's constants once per contact (0-d arrays
where a block holds them alike: one stream less to read), its 18 operations into
preallocated buffers (a new array of a block's size cost as much as the operation), the
end test on ``u* - u'`` (one multiplication less), the finished contacts gathered out
(by one index) when a quarter have finished (not masked field by field at every step),
the end state's speed and time computed once per block from its recorded count, the
largest impulse kept rather than force (the force only where the rules read it), blocks
of :data:`_BLOCK` contacts that stay in the cache (twice as fast as 4e5 at once).
:func:`end_margin` steps its states the same way, in the order of their ``step``, so
that those reaching it are cut off by a slice; :func:`states_through` records every
state of one run. :func:`ended_at` runs to a state the caller expects to end the contact
(the phase grid of the summary of :mod:`~impactsym.engines.drake.jump_means`) as
:func:`end_state` does, with the largest overlap and one update more, and gives
:func:`contact_ends`' numbers wherever it ends there and leaves: 6.0 ns per update
against 7.4 under gravity, 5.8 against 6.9 without (the grid of 2*10^4 designs of the
benchmark, 1e-3 s). Measured (CPU per contact and update, 10^5 contacts of 20-70 steps,
``h = 10^{-3}`` s, back to back, before the buffers, 0-d constants, the floor on
``u* - u'`` and the end state per block -> after): :func:`contact_ends` 10.9 -> 7.9 ns
(``g = 0``), 11.3 -> 9.4 (9.81); :func:`end_state` 7.1 -> 6.2-6.4 (with its set-up);
the update alone about 5 ns, its square root 0.9 of them.
All quantities are SI. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from impactsym.engines.drake.settling import IMPULSE_FLOOR, stuck_early
from impactsym.engines.drake.step_buffers import (
    buffer_views,
    constant_rows,
    may_turn,
    new_buffers,
    uniform,
    update_constants,
)
from impactsym.engines.drake.update import hunt_crossley_root, hunt_crossley_velocity, sap_velocity
from impactsym.engines.mujoco.stepping import StepContact

__all__ = [
    "MAX_STEPS",
    "ContactEnds",
    "contact_ends",
    "end_margin",
    "end_state",
    "end_steps",
    "ended_at",
    "margin_at",
    "states_through",
    "step_contact",
]

#: Updates stepped before a contact that has not ended is declared sticking.
MAX_STEPS = 2_000_000
_ZERO = IMPULSE_FLOOR  # impulses below this times m v count as zero
_SETTLE_EVERY = 64  # updates between two checks of the rules of settling (stuck_early)
_NIL = np.zeros(())  # 0 to compare with (a 0-d array: a call 0.2 us faster than 0.0)
_NIL.flags.writeable = False
_BLOCK = 32_768  # contacts stepped together (2x faster than 4e5 at once; 5-10 % than 16384)


def step_contact(
    k: Any,
    d: Any,
    tau: Any,
    m: Any,
    g: Any,
    v: Any,
    h: Any,
    phase: Any,
    *,
    approximation: str,
    stuck_peaks: bool = True,
) -> StepContact:
    """The contact at touch phase ``phase`` under ``approximation`` (arrays broadcast, SI).

    ``k`` combined point stiffness, ``d`` Hunt–Crossley dissipation (s/m), ``tau``
    combined relaxation time (``sap`` only), ``m`` mass, ``g`` pressing acceleration,
    ``v`` approach speed at touch, ``h`` time step, ``phase`` in ``[0, 1)``.
    ``stuck_peaks=False``: ``max_penetration`` and ``peak_accel`` of a sticking contact
    may stop at the verdict. Under gravity the ``max_penetration`` of a contact creeping
    up to its rest from below is the rest ``m g / k``, the limit of the creep (both:
    :mod:`~impactsym.engines.drake.settling`).
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, tau, m, g, v, h, phase)))
    shape = arrays[0].shape
    k, d, tau, m, g, v, h, phase = (a.ravel() for a in arrays)
    n = k.size
    t0, x, u = _touch(v, g, h, phase)
    e = np.zeros(n)
    t_c = np.full(n, np.inf)
    sticks = np.zeros(n, bool)
    by_position = np.zeros(n, bool)
    departure = np.zeros(n)
    steps = np.zeros(n, np.int64)
    x_max = np.zeros(n)
    peak = np.zeros(n)
    live = np.arange(n)  # elements still stepped, gathered into the arrays below
    sap = approximation == "sap"
    velocity = sap_velocity if sap else hunt_crossley_velocity
    kl, dl, ml, gl, hl, vl = k, tau if sap else d, m, g, h, v
    xl, ul = x, u
    loaded = bool(np.any(g > 0))  # a contact may come to rest: the rules (docstring)
    ended = np.zeros(n, bool)  # the end state is reached (coasting out, or done)
    active = np.ones(n, bool)  # among the gathered: not yet finished
    steps_l, x_max_l, peak_l = np.zeros(n, np.int64), np.zeros(n), np.zeros(n)
    for count in range(MAX_STEPS):
        if live.size == 0:
            break
        contact = xl >= 0.0
        new, impulse = velocity(xl, ul, kl, dl, ml, gl, hl)
        new = np.where(contact, new, ul + hl * gl)
        # an impulse below 1e-12 m v is zero: at the rebound bound u -> -1/d it decays
        # geometrically and only rounding would decide when it is exactly zero
        impulse = np.where(contact & (impulse > _ZERO * ml * vl), impulse, 0.0)
        was_ended = ended
        # the end state: the first without contact or without impulse
        end_now = active & ~was_ended & (~contact | (impulse <= 0.0))
        idx = live[end_now]
        e[idx] = -ul[end_now] / v[idx]
        t_c[idx] = t0[idx] + count * h[idx]
        by_position[idx] = ~contact[end_now]
        ended = was_ended | end_now
        # before the end: record, and catch a body turning back inwards in the overlap
        going = active & ~was_ended & ~end_now
        steps_l += going
        x_max_l = np.where(going, np.maximum(x_max_l, xl), x_max_l)
        peak_l = np.where(going, np.maximum(peak_l, impulse / hl), peak_l)
        turned = going & (ul < 0.0) & (new > 0.0)
        if loaded and count % _SETTLE_EVERY == _SETTLE_EVERY - 1:
            stuck, x_max_l = stuck_early(going, xl, ul, new, kl, dl, ml, gl, hl, vl, x_max_l,
                                         peak_l, stuck_peaks, hunt_crossley=not sap)  # fmt: skip
            turned |= stuck
        # after the end: the impulse coming back inside the overlap means sticking
        back = active & was_ended & contact & (impulse > 0.0)
        sticks[live[turned | back]] = True
        left = active & ended & ~contact
        departure[live[left]] = -ul[left]
        active = active & ~(turned | back) & ~left
        xl = np.where(active, xl + hl * new, xl)
        ul = np.where(active, new, ul)
        remaining = int(np.count_nonzero(active))
        if 2 * remaining <= live.size:  # drop the finished ones
            steps[live], x_max[live], peak[live] = steps_l, x_max_l, peak_l
            keep = active
            live = live[keep]
            kl, dl, ml, gl, hl, vl, xl, ul = (a[keep] for a in (kl, dl, ml, gl, hl, vl, xl, ul))
            ended, steps_l, x_max_l, peak_l = (a[keep] for a in (ended, steps_l, x_max_l, peak_l))
            active = np.ones(live.size, bool)
    steps[live], x_max[live], peak[live] = steps_l, x_max_l, peak_l
    live = live[active]
    sticks[live] = True
    e[sticks] = 0.0
    t_c[sticks] = np.inf
    departure[sticks] = 0.0
    by_position[sticks] = False
    fields = (e, t_c, sticks, by_position, departure, steps, x_max, peak / m)
    return StepContact(*(f.reshape(shape) for f in fields))


def end_steps(contact_time: Any, sticks: Any, h: Any, phase: Any) -> np.ndarray:
    """The end state of contacts that last ``contact_time`` from touch at ``phase``
    (``(phase + count) h``: the state ``count``, 0 the first detecting one), ``-1`` where
    they stick (arrays broadcast): what the phase summaries compare across phases."""
    with np.errstate(invalid="ignore", over="ignore"):
        index = np.rint(np.asarray(contact_time) / h - phase)
    return np.where(sticks, -1, index)


def _touch(v, g, h, phase):
    """``(t0, x, u)``: the time from touch to the first detecting state, and that state's
    free-flight penetration and approach rate (module docstring, the touch phase)."""
    t0 = phase * h
    return t0, v * t0 + 0.5 * g * t0 * t0, v + g * t0


def end_margin(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, step: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How far the state ``step`` (0 the first detecting state) of a
    ``"tamsi"``/``"similar"``/``"lagged"`` contact is from ending, as a smooth function of
    the phase, for locating where the end state changes (flat arrays, SI).

    Returns ``(margin, ends, valid)``: ``margin`` and ``ends`` of :func:`margin_at` at
    the state :func:`end_state` steps to, ``valid`` as there (False where an earlier
    state already ended or turned back: then ``margin`` does not decide the end at
    ``step``).
    """
    x, u, valid, (k, d, m, g, v, h) = end_state(k, d, m, g, v, h, phase, step)
    margin, ends = margin_at(x, u, k, d, m, g, v, h)
    return margin, ends, valid


def end_state(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, step: Any, *,
    ends: bool = False, checked: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:  # fmt: skip
    """The state ``step`` (0 the first detecting state) of a
    ``"tamsi"``/``"similar"``/``"lagged"`` contact at touch phase ``phase``, stepped by
    the update of :func:`~impactsym.engines.drake.update.hunt_crossley_velocity` whatever
    the states before it (no end test): smooth in the phase and the parameters while
    they all carry an impulse, and then the very numbers of :func:`contact_ends`.

    Returns ``(x, u, valid, flat)`` (flat arrays): the penetration and approach rate of
    that state, whether no state before it ended (no contact, or no impulse above the
    floor) or turned back, and the flat broadcast ``(k, d, m, g, v, h)``. ``ends``: and
    ``valid`` only where that state ends too (:func:`contact_ends`' end test there, that
    of :func:`margin_at`; one update more per state). ``checked=False``: ``valid`` not
    tracked (all True; ``ends`` ignored), the same states about a tenth faster.
    """
    k, d, m, g, v, h, phase = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (k, d, m, g, v, h, phase))
    )
    k, d, m, g, v, h, phase = (a.ravel() for a in (k, d, m, g, v, h, phase))
    step = np.broadcast_to(np.asarray(step, np.int64), k.shape).ravel()
    x, u, valid = np.empty(k.size), np.empty(k.size), np.ones(k.size, bool)
    end = np.empty(k.size, bool) if ends and checked else None
    buffers = new_buffers(min(k.size, _BLOCK))
    for lo in range(0, k.size, _BLOCK):  # blocks that stay in the cache while stepped
        block = slice(lo, min(lo + _BLOCK, k.size))
        _, x[block], u[block] = _touch(v[block], g[block], h[block], phase[block])
        rows = (a[block] for a in (k, d, m, g, v, h, x, u, step))
        _margin_states(*rows, valid[block] if checked else None, buffers=buffers,
                       ended=None if end is None else (end[block],))  # fmt: skip
    if end is not None:
        valid &= end
    return x, u, valid, (k, d, m, g, v, h)


def ended_at(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, step: Any
) -> tuple[ContactEnds, np.ndarray]:
    """:func:`contact_ends`' numbers where the contact ends at the state ``step`` (0 the
    first detecting state) and leaves the overlap by the next (flat arrays, SI), from
    :func:`end_state`'s run to that state and one update more instead of the end test
    at every update.

    Returns ``(ends, status)``: ``status`` 1 where no state before ``step`` ended or
    turned back, the state ``step`` ends (:func:`contact_ends`' test) and it or the next
    state is out of the overlap: there ``ends`` is :func:`contact_ends`' bit for bit (the
    same updates; its rules of settling never flag a contact that ends, and the one
    that ends outside the overlap coasts no further); 0 where the state ``step`` ends
    that way but inside the overlap (:func:`contact_ends` coasts on and decides); -1
    where the contact does not end at ``step`` (an earlier state ended or turned back:
    it ends there or sticks; or the state ``step`` carries an impulse in the overlap).
    Where ``status < 1`` the fields of ``ends`` are those states' numbers, not the
    contact's.
    """
    arrays = (*(np.asarray(a, float) for a in (k, d, m, g, v, h, phase)), np.asarray(step))
    k, d, m, g, v, h, phase, step = (a.ravel() for a in np.broadcast_arrays(*arrays))
    step = step.astype(np.int64)
    n = k.size
    x, u, valid, x_max = np.empty(n), np.empty(n), np.ones(n, bool), np.empty(n)
    ends, leaves = np.empty(n, bool), np.empty(n, bool)
    buffers = new_buffers(min(n, _BLOCK))
    for lo in range(0, n, _BLOCK):  # blocks that stay in the cache while stepped
        b = slice(lo, min(lo + _BLOCK, n))
        _, x[b], u[b] = _touch(v[b], g[b], h[b], phase[b])
        rows = (a[b] for a in (k, d, m, g, v, h, x, u, step, valid))
        _margin_states(*rows, buffers=buffers, ended=(ends[b], x_max[b], leaves[b]))
    status = np.where(valid & ends, np.where(leaves, 1, 0), -1).astype(np.int8)
    out = ContactEnds(-u / v, phase * h + step * h, np.zeros(n, bool), x_max, x)
    return out, status


def states_through(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, steps: int
) -> np.ndarray:
    """The penetrations of the states ``0`` to ``steps - 1`` (0 the first detecting state)
    of ``"tamsi"``/``"similar"``/``"lagged"`` contacts at touch phase ``phase`` (arrays
    broadcast, SI), ``(n, steps)``: :func:`end_state`'s ``x`` at each of those steps,
    bit for bit (the same update, whatever the states before), from one run instead of
    one per step."""
    k, d, m, g, v, h, phase = (
        a.ravel()
        for a in np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, m, g, v, h, phase)))
    )
    _, x, u = _touch(v, g, h, phase)
    out = np.empty((steps, k.size))
    with np.errstate(all="ignore"):
        consts, _ = update_constants(*(uniform(a) for a in (k, d, m, g, v, h)), k.size)
        work, spare, _, _ = new_buffers(k.size)
        for j in range(steps):
            if j:
                _, new = _update(x, u, consts, (*work, spare), contact=False)
                x -= np.multiply(consts[6], new, out=work[0])  # x + h u' = x - (-h) u'
                u, spare = new, u
            out[j] = x
    return np.ascontiguousarray(out.T)  # (rows: as end_state's reshaped)


def margin_at(
    x: Any, u: Any, k: Any, d: Any, m: Any, g: Any, v: Any, h: Any
) -> tuple[np.ndarray, np.ndarray]:
    """``(margin, ends)`` of the state ``(x, u)`` (arrays broadcast, SI): ``margin``
    (m/s) is the smaller of ``x/h`` and the update's impulse over ``m`` less the floor
    ``1e-12 v``, the impulse taken from the larger root of the quadratic without
    clipping (negative where the update is free, and through zero there: the larger
    root is ``u*`` at ``u* = max(-x/h, -1/d)``); ``ends`` is :func:`step_contact`'s end
    test at that state (no contact, or no impulse above the floor)."""
    ustar, root = hunt_crossley_root(x, u, k, d, m, g, h, clip=False)
    margin = np.minimum(x / h, ustar - root - _ZERO * v)
    _, impulse = hunt_crossley_velocity(x, u, k, d, m, g, h)
    ends = (x < 0.0) | (impulse <= _ZERO * m * v)
    return margin, ends


def contact_ends(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, *, stuck_peaks: bool = True
) -> ContactEnds:
    """What :func:`step_contact` gives a ``"tamsi"``/``"similar"``/``"lagged"`` contact's
    phase means, bit for bit: the restitution, contact time, stick verdict and largest
    penetration (arrays broadcast, SI; ``stuck_peaks`` as there).

    The same update in the same floating-point operations, leaner: the constants of
    :func:`~impactsym.engines.drake.update.hunt_crossley_root` computed once per contact,
    the contacts that end dropped from the arrays (gathered when a quarter have ended)
    instead of masked at every step, and the contacts that end without leaving the
    overlap (no impulse) stepped apart until they leave or the impulse comes back.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, m, g, v, h, phase)))
    k, d, m, g, v, h, phase = (a.ravel() for a in arrays)
    n = k.size
    out = ContactEnds(
        np.zeros(n), np.full(n, np.inf), np.zeros(n, bool), np.zeros(n), np.full(n, np.nan)
    )
    buffers = new_buffers(min(n, _BLOCK))
    for lo in range(0, n, _BLOCK):  # blocks that stay in the cache while stepped
        block = slice(lo, min(lo + _BLOCK, n))
        rows = (a[block] for a in (k, d, m, g, v, h, phase))
        part = ContactEnds(*(a[block] for a in out))  # views: written in place
        _block_ends(*rows, part, stuck_peaks=stuck_peaks, buffers=buffers)
    out.restitution[out.sticks] = 0.0
    out.contact_time[out.sticks] = np.inf
    out.end_penetration[out.sticks] = np.nan
    shape = arrays[0].shape
    return ContactEnds(*(a.reshape(shape) for a in out))


def _block_ends(k, d, m, g, v, h, phase, out, *, stuck_peaks, buffers):
    """:func:`contact_ends` of one block, into ``out`` (``buffers``:
    :func:`~impactsym.engines.drake.step_buffers.new_buffers`)."""
    with np.errstate(all="ignore"):  # the finished contacts step on until gathered
        t0, x, u = _touch(v, g, h, phase)
        consts = update_constants(*(uniform(a) for a in (k, d, m, g, v, h)), k.size)
        coast = _ends_loop(np.arange(k.size), x, u, consts, (k, d, m, g, h, v, t0), out,
                           buffers, stuck_peaks=stuck_peaks)  # fmt: skip
        if coast is not None:
            _coast(*coast, *consts, out, buffers)


def _margin_states(k, d, m, g, v, h, x, u, step, valid, *, buffers, ended=None):
    """:func:`end_state`'s states ``step`` into ``x``, ``u`` (views, in place), and its
    ``valid``: the update of
    :func:`~impactsym.engines.drake.update.hunt_crossley_velocity` (no contact test), the
    same operations, and its end test without clipping the impulse of a free update at
    0 (it is ``m (u* - u*) = 0`` there already, ``u*`` finite). The contacts are stepped
    in the order of their ``step``, so that those reaching it are the first ones: cut
    off at once (slices), not stepped on until gathered. ``buffers``:
    :func:`~impactsym.engines.drake.step_buffers.new_buffers`.
    ``ended``: ``(ends,)`` (:func:`end_state`) or ``(ends, x_max, leaves)``
    (:func:`ended_at`) views, filled with the state's end test (:func:`contact_ends`'),
    the largest penetration before it and whether it or the next state is out of the
    overlap: one update more per contact. ``valid`` ``None``: not tracked (nor the end
    tests: the same states, about a tenth less per update)."""
    more, checked = ended is not None, valid is not None
    peaks = more and len(ended) > 1
    live = np.flatnonzero(step > 0) if not more else np.arange(step.size)
    live = live[np.argsort(step[live])]  # (any order among equal steps: they are apart)
    with np.errstate(all="ignore"):
        rows = (uniform(a) for a in (k, d, m, g, v, h))
        consts, scaled = update_constants(
            *(a if a.ndim == 0 else a.take(live) for a in rows), live.size
        )
        work, spare, (one, two, _), (xl, ul) = buffer_views(buffers, live.size)
        x.take(live, out=xl, mode="clip")  # (into the buffers: no new pages)
        u.take(live, out=ul, mode="clip")
        bad = np.zeros(live.size, bool)  # a state so far ended or turned back
        deepest = np.zeros(live.size) if peaks else None  # the largest x so far, and 0
        turns = may_turn(consts, scaled)
        arrivals = np.bincount(step.take(live) + more)  # how many reach it at each count
        for count in range(1, arrivals.size):
            impulse, new = _update(xl, ul, consts, (*work, spare), contact=False)
            if checked:
                impulse -= new  # u* - new
                if scaled:
                    impulse *= consts[1]
            n = arrivals[count]
            if more and n:  # the state (count - 1), its end test (and the largest x before)
                i, floor = live[:n], consts[8] if consts[8].ndim == 0 else consts[8][:n]
                x[i], u[i], valid[i] = xl[:n], ul[:n], ~bad[:n]
                ended[0][i] = ~(impulse[:n] > floor) | (xl[:n] < 0.0)  # (nan: ends)
                if peaks:
                    ended[1][i] = deepest[:n]
            if peaks:
                np.maximum(deepest, xl, out=deepest)
            if checked:  # an end state: no impulse, no contact, or turned back
                bad |= np.less_equal(impulse, consts[8], out=one)
                bad |= np.less(xl, _NIL, out=one)
            if checked and turns:
                np.less(ul, _NIL, out=one)
                one &= np.greater(new, _NIL, out=two)
                bad |= one
            xl -= np.multiply(consts[6], new, out=impulse)  # x + h u' = x - (-h) u'
            ul, spare = new, ul
            if n:  # its state, and whether a state before it ended (or its next state)
                i = live[:n]
                if peaks:
                    ended[2][i] = (x[i] < 0.0) | (xl[:n] < 0.0)
                elif not more:
                    x[i], u[i] = xl[:n], ul[:n]
                    if checked:
                        valid[i] = ~bad[:n]
                live, xl, ul, spare, bad, one, two = (
                    a[n:] for a in (live, xl, ul, spare, bad, one, two)
                )
                deepest = deepest[n:] if peaks else None
                work = tuple(a[n:] for a in work)
                consts = constant_rows(consts, slice(n, None))


class ContactEnds(NamedTuple):
    """:func:`contact_ends`: the fields of :class:`StepContact` that phase means read,
    and ``end_penetration``, the penetration of the end state (``nan`` where it
    sticks), from which the phase summary sees changes of the end state between its
    samples (:mod:`impactsym.engines.drake.phases`)."""

    restitution: np.ndarray
    contact_time: np.ndarray
    sticks: np.ndarray
    max_penetration: np.ndarray
    end_penetration: np.ndarray


def _update(x, u, consts, work, *, contact=True):
    """``(u*, new)`` of :func:`~impactsym.engines.drake.update.hunt_crossley_velocity`,
    the same operations (into the buffers ``work`` of
    :func:`~impactsym.engines.drake.step_buffers.new_buffers`, the last for ``new``):
    ``new = u*`` where the update is free, and with ``contact`` where the contact
    ``x >= 0`` is gone too."""
    hg, m, hk, b0, hkd, a4, nh, nd, _, zero = consts
    ustar, b, disc, t, free, neg, c = work
    np.add(u, hg, out=ustar)
    np.multiply(m, ustar, out=c)
    c -= np.multiply(hk, x, out=b)
    np.multiply(hkd, x, out=b)
    b += b0
    np.multiply(b, b, out=disc)
    disc += np.multiply(a4, c, out=t)
    np.maximum(disc, zero, out=disc)
    np.sqrt(disc, out=disc)
    disc += b
    c *= 2.0
    c /= disc  # the root
    np.divide(x, nh, out=t)
    np.maximum(t, nd, out=t)
    np.less_equal(ustar, t, out=free)
    if contact:
        free |= np.less(x, _NIL, out=neg)
    np.copyto(c, ustar, where=free)
    return ustar, c


def _ends_loop(live, x, u, constants, raw, out, buffers, *, stuck_peaks):
    """Steps the contacts ``live`` to their end state (:func:`step_contact`'s loop) into
    ``out``; returns those that end without leaving the overlap, to coast. The largest
    impulse (or ``u* - u'``,
    :func:`~impactsym.engines.drake.step_buffers.impulse_bound`) is kept, and made the
    force for the rules only when they are checked (the largest of the forces: rounding
    keeps the order)."""
    k, d, m, g, h, v, t0 = raw
    consts, scaled = constants
    settle = bool(np.any(g > 0))  # the rules of settling
    turns = settle or may_turn(consts, scaled)
    x_max, peak = np.zeros(live.size), np.zeros(live.size) if settle else None
    going = np.ones(live.size, bool)  # not yet ended (the others are dropped in a while)
    ended_at = np.full(live.size, -1)  # the count of the end state (its u in restitution)
    work, spare, (ends, turned, one), _ = buffer_views(buffers, live.size)
    finished = 0  # of the gathered
    coasting = []
    count = 0
    for count in range(MAX_STEPS):
        if live.size == 0:
            break
        stay = None
        impulse, new = _update(x, u, consts, (*work, spare))
        impulse -= new  # u* - new
        if scaled:
            impulse *= consts[1]
        # going, and no impulse above the floor (or no contact): the end state
        np.greater(going, np.greater(impulse, consts[8], out=one), out=ends)
        if np.count_nonzero(ends):  # the end state: its count, velocity and penetration
            j = ends.nonzero()[0]
            i, xj = live.take(j), x.take(j)
            ended_at[i], out.restitution[i] = count, u.take(j)
            out.max_penetration[i] = x_max.take(j)
            out.end_penetration[i] = xj
            stay = j[xj >= 0.0]  # no impulse inside the overlap: it coasts on (below)
            np.greater(going, ends, out=going)  # (going and not ends)
            finished += j.size
        np.maximum(x_max, x, out=x_max)
        if settle:
            np.maximum(peak, impulse, out=peak)
        if turns:
            np.less(u, _NIL, out=turned)
            turned &= np.greater(new, _NIL, out=one)
            turned &= going
        if settle and count % _SETTLE_EVERY == _SETTLE_EVERY - 1:  # step_contact's checks
            rows = [a.take(live) for a in (k, d, m, g, h, v)]
            force = (peak if scaled else rows[2] * peak) / rows[4]
            stuck, x_max = stuck_early(going, x, u, new, *rows, x_max, force, stuck_peaks)
            turned |= stuck
        if turns and np.count_nonzero(turned):
            i = live[turned]
            out.sticks[i] = True
            out.max_penetration[i] = x_max[turned]
            going &= ~turned
            finished += int(np.count_nonzero(turned))
        x -= np.multiply(consts[6], new, out=impulse)  # x + h u' = x - (-h) u'
        if stay is not None and stay.size:  # from the state after the end state
            start = np.full(stay.size, count + 1)
            coasting.append((live.take(stay), x.take(stay), new.take(stay), start))
        u, spare = new, u
        if 4 * finished >= live.size:  # drop the finished ones
            keep = going.nonzero()[0]
            live, x, u, x_max = (a.take(keep) for a in (live, x, u, x_max))
            consts = constant_rows(consts, keep)
            peak = peak.take(keep) if settle else None
            going = np.ones(live.size, bool)
            finished = 0
            work, spare, (ends, turned, one), _ = buffer_views(buffers, live.size)
    i = live[going]
    out.sticks[i] = True
    out.max_penetration[i] = x_max[going]
    i = np.flatnonzero(ended_at >= 0)  # the separation speed, and the time
    out.restitution[i] = -out.restitution[i] / v[i]
    out.contact_time[i] = t0[i] + ended_at[i] * h[i]
    if not coasting:
        return None
    return tuple(np.concatenate(a) for a in zip(*coasting, strict=True))


def _coast(live, x, u, start, consts, scaled, out, buffers):
    """Steps the contacts ``live`` that ended without impulse inside the overlap (at the
    state before ``start``) until they leave it; where the impulse comes back first, or
    the count reaches :data:`MAX_STEPS`, they stick (:func:`step_contact`)."""
    consts = constant_rows(consts, live)
    work, spare, _, _ = buffer_views(buffers, live.size)
    for j in range(MAX_STEPS):
        if live.size == 0:
            break
        impulse, new = _update(x, u, consts, (*work, spare))
        impulse -= new  # u* - new
        if scaled:
            impulse *= consts[1]
        inside = x >= 0.0
        back = inside & (impulse > consts[8])
        over = start + j >= MAX_STEPS
        out.sticks[live[back | over]] = True
        x -= np.multiply(consts[6], new, out=impulse)  # x + h u' = x - (-h) u'
        u, spare = new, u
        inside &= ~back
        inside &= ~over
        if not inside.all():  # drop those that left or stick
            keep = inside.nonzero()[0]
            live, x, u, start = (a.take(keep) for a in (live, x, u, start))
            consts = constant_rows(consts, keep)
            work, spare, _, _ = buffer_views(buffers, live.size)
