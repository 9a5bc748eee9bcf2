"""Drake's discrete contact stepped with the live elements gathered at every step: the
reference of :func:`impactsym.engines.drake.stepping.step_contact` (which gathers them
only when half have finished). That function as it was, kept verbatim so the faster loop
can be held to the same numbers bit for bit. :func:`end_margin` as it was before its lean
loop (the update of ``hunt_crossley_velocity`` on masked arrays), verbatim."""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.drake.stepping import MAX_STEPS
from impactsym.engines.drake.update import (
    hunt_crossley_root,
    hunt_crossley_velocity,
    sap_velocity,
)
from impactsym.engines.mujoco.stepping import StepContact

_ZERO = 1e-12  # impulses below this times m v count as zero


def step_contact(
    k: Any, d: Any, tau: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, *, approximation: str
) -> StepContact:
    """The contact at touch phase ``phase`` under ``approximation`` (arrays broadcast, SI).

    ``k`` combined point stiffness, ``d`` Hunt–Crossley dissipation (s/m), ``tau``
    combined relaxation time (``sap`` only), ``m`` mass, ``g`` pressing acceleration,
    ``v`` approach speed at touch, ``h`` time step, ``phase`` in ``[0, 1)``.
    """
    arrays = np.broadcast_arrays(*(np.asarray(a, float) for a in (k, d, tau, m, g, v, h, phase)))
    shape = arrays[0].shape
    k, d, tau, m, g, v, h, phase = (a.ravel() for a in arrays)
    n = k.size
    t0 = phase * h
    x = v * t0 + 0.5 * g * t0 * t0
    u = v + g * t0
    e = np.zeros(n)
    t_c = np.full(n, np.inf)
    sticks = np.zeros(n, bool)
    by_position = np.zeros(n, bool)
    departure = np.zeros(n)
    steps = np.zeros(n, np.int64)
    x_max = np.zeros(n)
    peak = np.zeros(n)
    ended = np.zeros(n, bool)  # the end state is reached (coasting out, or done)
    live = np.arange(n)  # elements still stepped
    sap = approximation == "sap"
    for count in range(MAX_STEPS):
        if live.size == 0:
            break
        xl, ul = x[live], u[live]
        contact = xl >= 0.0
        args = (k[live], tau[live] if sap else d[live], m[live], g[live], h[live])
        new, impulse = (sap_velocity if sap else hunt_crossley_velocity)(xl, ul, *args)
        new = np.where(contact, new, ul + h[live] * g[live])
        # an impulse below 1e-12 m v is zero: at the rebound bound u -> -1/d it decays
        # geometrically and only rounding would decide when it is exactly zero
        impulse = np.where(contact & (impulse > _ZERO * m[live] * v[live]), impulse, 0.0)
        was_ended = ended[live]
        # the end state: the first without contact or without impulse
        end_now = ~was_ended & (~contact | (impulse <= 0.0))
        idx = live[end_now]
        e[idx] = -ul[end_now] / v[idx]
        t_c[idx] = t0[idx] + count * h[idx]
        by_position[idx] = ~contact[end_now]
        ended[idx] = True
        # before the end: record, and catch a body turning back inwards in the overlap
        going = ~was_ended & ~end_now
        gi = live[going]
        steps[gi] += 1
        x_max[gi] = np.maximum(x_max[gi], xl[going])
        peak[gi] = np.maximum(peak[gi], impulse[going] / h[gi])
        turned = going & (ul < 0.0) & (new > 0.0)
        # after the end: the impulse coming back inside the overlap means sticking
        back = was_ended & contact & (impulse > 0.0)
        stuck = live[turned | back]
        sticks[stuck] = True
        gone = live[ended[live] & ~contact]
        departure[gone] = -ul[~contact & ended[live]]
        keep = ~(turned | back) & ~(ended[live] & ~contact)
        live_new = live[keep]
        x[live_new] = xl[keep] + h[live_new] * new[keep]
        u[live_new] = new[keep]
        live = live_new
    sticks[live] = True
    e[sticks] = 0.0
    t_c[sticks] = np.inf
    departure[sticks] = 0.0
    by_position[sticks] = False
    fields = (e, t_c, sticks, by_position, departure, steps, x_max, peak / m)
    return StepContact(*(f.reshape(shape) for f in fields))


def end_margin(
    k: Any, d: Any, m: Any, g: Any, v: Any, h: Any, phase: Any, step: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How far the state ``step`` (0 the first detecting state) of a
    ``"tamsi"``/``"similar"``/``"lagged"`` contact is from ending, as a smooth function of
    the phase, for locating where the end state changes (flat arrays, SI).

    Returns ``(margin, ends, valid)``: ``margin`` (m/s) is the smaller of ``x/h`` and the
    update's impulse over ``m`` less the floor ``1e-12 v``, the impulse taken from the
    larger root of the quadratic without clipping (negative where the update is free, and
    through zero there: the larger root is ``u*`` at ``u* = max(-x/h, -1/d)``);
    ``ends`` is :func:`step_contact`'s end test at that state (no contact, or no impulse
    above the floor); ``valid`` is False where an earlier state already ended or turned
    back (then ``margin`` does not decide the end at ``step``).
    """
    k, d, m, g, v, h, phase = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (k, d, m, g, v, h, phase))
    )
    k, d, m, g, v, h, phase = (a.ravel() for a in (k, d, m, g, v, h, phase))
    step = np.broadcast_to(np.asarray(step, np.int64), k.shape).ravel()
    t0 = phase * h
    x, u = v * t0 + 0.5 * g * t0 * t0, v + g * t0
    valid = np.ones(k.size, bool)
    live = np.flatnonzero(step > 0)  # stepped; gathered when half have reached their step
    rows = [a[live] for a in (k, d, m, g, v, h, x, u, step)]
    count = 0
    while live.size:
        kl, dl, ml, gl, vl, hl, xl, ul, sl = rows
        new, impulse = hunt_crossley_velocity(xl, ul, kl, dl, ml, gl, hl)
        going = sl > count
        ended = (xl < 0.0) | (impulse <= _ZERO * ml * vl) | ((ul < 0.0) & (new > 0.0))
        valid[live[going & ended]] = False
        rows[6], rows[7] = np.where(going, xl + hl * new, xl), np.where(going, new, ul)
        count += 1
        reached = sl == count
        x[live[reached]], u[live[reached]] = rows[6][reached], rows[7][reached]
        rest = sl > count
        if 2 * np.count_nonzero(rest) <= live.size:
            live, rows = live[rest], [a[rest] for a in rows]
    ustar, root = hunt_crossley_root(x, u, k, d, m, g, h, clip=False)
    margin = np.minimum(x / h, ustar - root - _ZERO * v)
    _, impulse = hunt_crossley_velocity(x, u, k, d, m, g, h)
    ends = (x < 0.0) | (impulse <= _ZERO * m * v)
    return margin, ends, valid
