"""PyBullet's one-contact step map stepping every element to the end: the reference of
:func:`impactsym.engines.pybullet.stepping.step_pattern` (which steps only the live
elements). This is that function as it was before the live-element loop, kept verbatim
so the faster loop can be held to the same numbers bit for bit."""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact
from impactsym.engines.pybullet.stepping import (
    DEFAULT_RESTITUTION_THRESHOLD,
    DEFAULT_SLOP,
    MAX_STEPS,
    step_budget,
)


def step_pattern(
    stiffness: Any,
    damping: Any,
    mass: Any,
    speed: Any,
    gravity: Any,
    timestep: Any,
    phase: Any,
    *,
    substeps: int = 1,
    slop: float = DEFAULT_SLOP,
    processing_threshold: float = np.inf,
    velocity_restitution: float = 0.0,
    restitution_threshold: float = DEFAULT_RESTITUTION_THRESHOLD,
) -> tuple[StepContact, np.ndarray]:
    """:func:`step_contact` and the *pattern* of each element (same shape).

    The pattern is a record of the counts of the branches the sub-steps took (first and end
    state, sub-steps with a speculative and with a positional impulse, sticking): where
    it is constant in the phase, the end state is a fixed affine map of the free-flight
    state ``-1``, quadratic in the phase, so the restitution is a quadratic there and
    the contact time linear (:mod:`~impactsym.engines.pybullet.phases` integrates it).
    """
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep, phase))
    )
    shape = arrays[0].shape
    k, c, m, v, g, H, p = (a.ravel().copy() for a in arrays)
    h = H / substeps
    erp = h * k / (h * k + c)
    cfm = 1.0 / (h * (h * k + c))
    gain = 1.0 / (1.0 + m * cfm)  # lambda / m = gain * b
    t = (p - 1.0) * H  # state -1: free flight
    x = v * t + 0.5 * g * t * t
    w = v + g * t
    size = k.size
    budget = step_budget(k, c, m, H)
    started = np.zeros(size, bool)
    ended = np.zeros(size, bool)
    done = np.zeros(size, bool)
    sticks = np.zeros(size, bool)
    n_end = np.zeros(size)
    n_first = np.zeros(size)
    w_end = np.zeros(size)
    x_end = np.zeros(size)
    depart = np.zeros(size)
    x_max = np.zeros(size)
    f_max = np.zeros(size)
    n_spec = np.zeros(size)
    n_pos = np.zeros(size)
    n_rest = np.zeros(size)
    n = -1
    budget = np.minimum(budget, MAX_STEPS)
    while not done.all():
        n += 1
        for _ in range(substeps):
            w_star = w + g * h
            d = slop - x
            b = np.where(d > 0, w_star - d / h, w_star - erp * d / h)
            if velocity_restitution:  # restitutionCurve: a wanted separation speed
                rest = (np.abs(w_star) >= restitution_threshold) & (w_star > 0)
                b = b + np.where(rest, velocity_restitution * w_star, 0.0)
                n_rest += ~ended & rest
            dv = np.where(-x <= processing_threshold, np.maximum(gain * b, 0.0), 0.0)
            counting = ~ended & (dv > 0)
            n_spec += counting & (d > 0)
            n_pos += counting & (d <= 0)
            w = w_star - dv
            x = x + h * w
        force = dv * m / h
        live = ~done
        on = force > 0
        begin = live & ~started & on
        started |= begin
        n_first = np.where(begin, n, n_first)
        contact = live & started & ~ended
        x_max = np.where(contact, np.maximum(x_max, x), x_max)
        f_max = np.where(contact, np.maximum(f_max, force), f_max)
        stop = contact & ~on
        ended |= stop
        n_end = np.where(stop, n, n_end)
        w_end = np.where(stop, w, w_end)
        x_end = np.where(stop, x, x_end)
        after = live & ended & ~stop
        back = after & on & (x > 0)  # force back inside the overlap
        sticks |= back
        gone = (after & ~back & (x <= 0)) | (stop & (x <= 0))
        depart = np.where(gone, -w, depart)
        done |= back | gone
        over = ~done & (n >= budget)  # each element's own budget
        sticks |= over
        done |= over
    restitution = np.where(sticks, 0.0, -w_end / v)
    contact_time = np.where(sticks, np.inf, (p + n_end) * H)
    fields = {
        "restitution": restitution,
        "contact_time": contact_time,
        "sticks": sticks,
        "released_by_position": ~sticks & (x_end <= 0),
        "departure_speed": np.where(sticks, 0.0, depart),
        "steps": np.where(sticks, np.inf, n_end - n_first),
        "max_penetration": x_max,
        "peak_accel": f_max / m,
    }
    # the pattern: every branch count, all -1 where the body sticks
    counts = {"end": n_end, "first": n_first, "spec": n_spec, "pos": n_pos, "rest": n_rest}
    pattern = np.empty(sticks.shape, [(name, np.int64) for name in counts])
    for name, count in counts.items():
        pattern[name] = np.where(sticks, -1, count)
    record = StepContact(**{key: val.reshape(shape) for key, val in fields.items()})
    return record, pattern.reshape(shape)
