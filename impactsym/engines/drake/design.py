r"""The point contact Drake needs for a target impact: :func:`point_contact_for`.

The inverse of :func:`~impactsym.engines.drake.prediction.predict` (``docs/physics.md``,
"Drake point contact"). Two numbers fix the contact: the restitution and one size, the
contact time or the maximum penetration, which scale as :math:`\sqrt{m/k}` at a fixed
damping number. So the stiffness is the fixed point of
:math:`k \leftarrow k\,(q(k)/q^*)^2` (``q`` the size), exact in one step where the
damping number does not depend on ``k`` (no gravity, continuous) and a fast contraction
where gravity or the step couple them, and at each ``k`` the damping is the root of the
restitution:

* continuous: :func:`impactsym.contact.lawdesign.damping_for` (Hunt–Crossley, exponent 1,
  pressing force ``m g``; the exact Lambert-W inverse without gravity);
* discrete: the phase mean of the exact discrete map falls as the damping grows; a
  bracketed Illinois root of it. For ``"tamsi"``/``"similar"``/``"lagged"`` the bracket
  ends at ``d = 1/(e v)``: the rebound speed ``e v`` cannot exceed ``1/d``, where the
  factor ``(1 + d x')`` of the law vanishes. For ``"sap"`` the damping is the
  relaxation time (``hunt_crossley_dissipation`` is ignored there and returned as 0).

At a step the phase-mean contact time rests at ``(N + 1/2) h`` over stretches of ``k``
where every phase lasts ``N`` steps; there the stiffness step doubles until the size
crosses the target, then a bracketed Illinois step finishes it.

All designs are solved together on whole arrays. A call with at least
:data:`~impactsym.engines.drake.pressed_table.MIN_TARGETS` continuous targets under
gravity (``g > 0``) reads their designs off one Chebyshev table of the normalized impact
in the damping and pressing numbers instead
(:mod:`~impactsym.engines.drake.pressed_table`: the same numbers to about ``1e-14``,
without an exact evaluation per design). A call with at least
:data:`~impactsym.engines.drake.step_table.MIN_CALL` discrete ``"tamsi"``,
``"similar"`` or ``"lagged"`` targets sharing ``g / v`` (below
:data:`~impactsym.engines.drake.step_table.MIN_TARGETS`, only where the undamped
contact reaches each) reads those that share an end state with many others off that
end state's table of exact designs (:mod:`~impactsym.engines.drake.change_table`: boxes
of ``MIN_TARGETS`` that serve ``MIN_SERVED`` together), one exact evaluation each,
which also gives their phase summary, starts the others from a table of the phase
means and finishes them on the equations of the end state's change
(:mod:`~impactsym.engines.drake.jump_means`) or by Broyden steps on the exact phase
means (:mod:`~impactsym.engines.drake.step_table`). The targets those leave, and every
smaller call, take the iteration above (at a step from the continuous damped design).
Every discrete design is predicted: a table's design that misses its
target is designed again by the iteration, and one that still misses is refused (a
safety net: no target is known to reach it). Its stopping rules act on its whole batch:
where it refuses the targets a table left, they are iterated in halves, down to the
target refused alone, which the refusal names with its reason (the call is not
iterated again as a whole: that cost as much as designing it without a table, after
the table, and could name another target).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.lawclosed import hunt_crossley_parameter
from impactsym.contact.lawdesign import damping_for
from impactsym.contact.nonlinear import normalized_impact
from impactsym.engines.drake.continuous import start_stiffness
from impactsym.engines.drake.phases import phase_summary
from impactsym.engines.drake.prediction import (
    Prediction,
    check_approximation,
    check_time_step,
    predict,
    read_prediction,
    summary_prediction,
)
from impactsym.engines.drake.pressed_table import MIN_TARGETS, pressed_designs
from impactsym.engines.drake.step_table import MIN_CALL as STEPPED_MIN
from impactsym.engines.drake.step_table import stepped_designs
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, finish, real_array

__all__ = ["PointContact", "point_contact_for"]

_OUTER = 80  # fixed-point steps in the stiffness
_INNER = 100  # Illinois steps in the damping
_TOL = 1e-10


@dataclass(frozen=True, eq=False)
class PointContact(ArrayRecord):
    """Drake point-contact parameters for a target impact, and what they deliver (SI).

    Attributes
    ----------
    point_contact_stiffness, hunt_crossley_dissipation
        Combined ``k`` (N/m) and ``d`` (s/m) of the pair (``d = 0`` for ``"sap"``,
        which ignores it); e.g. give both geometries ``2 k`` and ``d``, which
        :func:`~impactsym.engines.drake.pair.combine` turns back into ``k`` and ``d``.
    relaxation_time
        Combined relaxation time (s) for ``"sap"``; ``None`` otherwise.
    restitution, contact_time, max_penetration, sticks
        What :func:`~impactsym.engines.drake.prediction.predict` gives at the design
        (phase means at a discrete step).
    prediction
        That :class:`~impactsym.engines.drake.prediction.Prediction`, with the ranges.
    """

    point_contact_stiffness: Any
    hunt_crossley_dissipation: Any
    relaxation_time: Any
    restitution: Any
    contact_time: Any
    max_penetration: Any
    sticks: Any
    prediction: Prediction


def point_contact_for(
    *,
    restitution: Any,
    speed: Any,
    mass: Any,
    gravity: Any = 0.0,
    contact_time: Any = None,
    max_penetration: Any = None,
    time_step: float = 0.0,
    approximation: str | None = None,
) -> PointContact:
    r"""``point_contact_stiffness`` and ``hunt_crossley_dissipation`` for a target impact.

    Parameters
    ----------
    restitution : float or array_like
        Target coefficient of restitution, ``0 < e < 1`` (the phase mean at a step).
    speed, mass, gravity : float or array_like
        Approach speed (m/s), mass (kg), pressing acceleration (m/s^2, ``>= 0``).
    contact_time, max_penetration : float or array_like
        Exactly one: the target contact time (s) or largest penetration (m).
    time_step, approximation
        As in :func:`~impactsym.engines.drake.prediction.predict`.

    Returns
    -------
    PointContact

    Raises
    ------
    ValueError
        For bad input, or a target out of reach, saying why (the rebound bound
        ``e v < 1/d``, the restitution of the undamped step, a contact too short for the
        step, sticking under gravity, a design whose prediction misses the target).

    Examples
    --------
    >>> c = point_contact_for(restitution=0.5, speed=1.0, mass=0.1, contact_time=1e-3)
    >>> round(c.hunt_crossley_dissipation, 4), round(c.point_contact_stiffness)
    (1.4328, 1079336)
    """
    h = check_time_step(time_step)
    approx = check_approximation(approximation, h)
    if (contact_time is None) == (max_penetration is None):
        raise ValueError(
            "give exactly one of contact_time and max_penetration (the size of the contact "
            f"that fixes the stiffness), got contact_time={contact_time!r}, "
            f"max_penetration={max_penetration!r}"
        )
    size_name = "contact_time" if contact_time is not None else "max_penetration"
    size_in = contact_time if contact_time is not None else max_penetration
    values = {
        name: real_array(name, value, lower=0.0, strict=strict)
        for name, value, strict in (
            ("restitution", restitution, True),
            ("speed", speed, True),
            ("mass", mass, True),
            ("gravity", gravity, False),
            (size_name, size_in, True),
        )
    }
    e_arr = values["restitution"][0]
    if (e_arr >= 1.0).any():
        raise ValueError(
            "restitution must be < 1 (e = 1 needs no dissipation and any stiffness), got "
            f"{float(e_arr[e_arr >= 1.0].flat[0])!r}"
        )
    scalar = all(flag for _, flag in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    e, v, m, g, target = (np.broadcast_to(a, shape).ravel() for a, _ in values.values())

    if h > 0 and size_name == "contact_time" and np.any(target < 2.0 * h):
        bad = np.flatnonzero(target < 2.0 * h)[0]
        raise ValueError(
            f"contact_time {float(target[bad])!r} is out of reach at time_step {h!r}: a contact "
            f"lasts at least two steps; use time_step <= {target[bad] / 20.0:.3g}"
        )
    read, values_read, summaries = np.zeros(e.size, bool), None, None
    if approx is None and np.count_nonzero(g > 0) >= MIN_TARGETS:
        # many continuous targets under gravity: their designs read off one table
        pressed = np.flatnonzero(g > 0)
        ok, k_read, d_read, *values_read = pressed_designs(
            *(a[pressed] for a in (e, v, m, g, target)), size_name
        )
        read[pressed[ok]] = True
        k_read, d_read = k_read[ok], d_read[ok]
        values_read = [a[ok] for a in values_read]
    elif approx not in (None, "sap") and e.size >= STEPPED_MIN:
        # many discrete targets: started from a table of the phase means, a few exact steps
        ok, k_read, d_read, summaries = stepped_designs(e, v, m, g, target, h, approx, size_name)
        read, k_read, d_read = ok, k_read[ok], d_read[ok]
    if not read.any():
        k, damp = _iterate(e, v, m, g, target, h, approx, size_name)
    else:  # the table's designs, and the exact iteration for the others
        k, damp = np.empty(e.size), np.empty(e.size)
        k[read], damp[read] = k_read, d_read
        rest = np.flatnonzero(~read)
        if rest.size:
            rows = (a[rest] for a in (e, v, m, g, target))
            k[rest], damp[rest] = _iterate_apart(*rows, h, approx, size_name)

    def out(a):
        return finish(np.asarray(a, dtype=float).reshape(shape), scalar)

    sap = approx == "sap"
    if values_read is not None and read.any():  # the table's values, the exact elsewhere
        p = read_prediction(shape, read, values_read, k, damp, m, v, g)
    else:  # the full prediction (with the ranges) once, with the summaries tables gave
        p = (_predict(*(a.item() if scalar else a.reshape(shape) for a in (k, damp, m, v, g)),
                      h, approx) if summaries is None else
             summary_prediction(summaries, k, damp, m, v, g, h, approx, shape, scalar))  # fmt: skip
        missed = _missed(p, e, target, size_name) if h > 0 else np.zeros(e.size, bool)
        if (again := missed & read).any():  # a table's design stands where it holds
            rows = (a[again] for a in (e, v, m, g, target))
            k[again], damp[again] = _iterate_apart(*rows, h, approx, size_name)
            p = _predict(*(a.reshape(shape) for a in (k, damp, m, v, g)), h, approx)
            missed = _missed(p, e, target, size_name)
        if missed.any():  # a safety net: the design the iteration found misses the target
            bad = np.flatnonzero(missed)[0]
            raise ValueError(
                f"restitution {float(e[bad])!r} is out of reach with {approx!r} at time_step "
                f"{h!r} and {size_name} {float(target[bad])!r}: the design found misses it "
                f"(its prediction: e {float(np.ravel(p.restitution)[bad]):.9g}, "
                f"{size_name} {float(np.ravel(getattr(p, size_name))[bad]):.9g}); use a smaller "
                "time_step"
            )
    return PointContact(
        point_contact_stiffness=out(k),
        hunt_crossley_dissipation=out(np.zeros_like(k) if sap else damp),
        relaxation_time=out(damp) if sap else None,
        restitution=p.restitution,
        contact_time=p.contact_time,
        max_penetration=p.max_penetration,
        sticks=p.sticks,
        prediction=p,
    )


def _missed(p, e, target, size_name) -> np.ndarray:
    """Where ``p`` misses a target (flat) by more than ``1e-12`` in ``e`` or ``1e-10``
    relative in the size, the designs' tolerances (5 % more: rounding in another batch)."""
    got_e, got = np.ravel(p.restitution), np.ravel(getattr(p, size_name))
    with np.errstate(invalid="ignore"):
        return ~((np.abs(got_e - e) <= 1.05e-12) & (np.abs(got / target - 1.0) <= 1.05e-10))


def _iterate_apart(e, v, m, g, target, h, approx, size_name):
    """:func:`_iterate` on the targets a table left; where it refuses them together, on
    each half apart, down to the first target refused alone, whose reason is raised (the
    iteration's stopping rules act on its whole batch: a target may hold up a batch that
    designs every other)."""
    try:
        return _iterate(e, v, m, g, target, h, approx, size_name)
    except ValueError:
        if e.size == 1:
            raise
    half = e.size // 2
    k, damp = np.empty(e.size), np.empty(e.size)
    for part in (slice(0, half), slice(half, None)):
        rows = (a[part] for a in (e, v, m, g, target))
        k[part], damp[part] = _iterate_apart(*rows, h, approx, size_name)
    return k, damp


def _iterate(e, v, m, g, target, h, approx, size_name):
    """The stiffness and damping of each target (flat arrays) by the exact iteration: the
    fixed point in the stiffness, a damping root at each (module docstring); raises
    where a target is out of reach."""
    # the undamped law's scale, at a step the damped law's (an undamped start may lie
    # where the step restitutes less than the target: a reachable target was refused)
    k = k_start = start_stiffness(e, v, m, target, size_name=size_name, damped=approx is not None)
    damp = np.zeros_like(k)
    if approx is None and np.all(g > 0):
        # the first damping bracket around the root without gravity (d v = s(e), Lambert
        # W): under gravity the root lies near it (at a step a cold bracket is as fast)
        damp = hunt_crossley_parameter(e) / v
    log_prev = q_prev = None
    # the bracket in ln k once the size has been seen on both sides of the target: along
    # the restitution's contour the size falls with k, continuous, with flat stretches
    # (at a step the phase-mean contact time rests at (N + 1/2) h while every phase
    # lasts N steps), where a secant stalls; inside a bracket Illinois steps take over
    below = np.full_like(k, -np.inf)  # ln k whose size is above the target
    above = np.full_like(k, np.inf)  # ln k whose size is below it
    f_below, f_above = np.ones_like(k), -np.ones_like(k)
    side = np.zeros(k.size, int)
    f_last = np.full_like(k, np.inf)
    stride = np.ones_like(k)  # doubles while a design walks along a plateau of the size
    best, stalled = np.inf, 0
    q = np.full_like(k, np.nan)
    moved = np.full_like(k, np.inf)  # |change of ln k| since the last damping root
    todo = np.arange(k.size)  # the designs whose stiffness moved: only these are evaluated
    for _ in range(_OUTER):
        rows = (e[todo], k[todo], m[todo], v[todo], g[todo])
        if approx is None:
            damp[todo], q[todo] = _continuous_damping(*rows, damp[todo], size_name, moved[todo])
        else:  # the size comes with the damping's root (the same evaluations)
            damp[todo], q[todo] = _discrete_damping(*rows, h, approx, damp[todo], size_name,
                                                    moved[todo])  # fmt: skip
        if np.any(~np.isfinite(q)):
            bad = np.flatnonzero(~np.isfinite(q))[0]
            raise ValueError(
                f"restitution {float(e[bad])!r} at speed {float(v[bad])!r}, gravity "
                f"{float(g[bad])!r}: the body sticks at the design (the pressing force holds "
                "it); ask for a larger restitution, a smaller gravity or a larger speed"
            )
        ratio = q / target
        converged = np.abs(ratio - 1.0) <= _TOL
        if np.all(converged):
            break
        log_k, log_q = np.log(k), np.log(q)
        f = log_q - np.log(target)
        up, down = f > 0, f < 0
        below[up], f_below[up] = log_k[up], f[up]
        above[down], f_above[down] = log_k[down], f[down]
        f_above[up & (side == 1)] *= 0.5  # Illinois: the same end moved twice
        f_below[down & (side == -1)] *= 0.5
        side = np.where(up, 1, np.where(down, -1, side))
        # secant in (log k, log q): the slope is -1/2 where the damping number is fixed
        slope = np.full_like(k, -0.5)
        bracketed = np.isfinite(below) & np.isfinite(above)
        if log_prev is not None:
            with np.errstate(all="ignore"):
                secant = (log_q - q_prev) / (log_k - log_prev)
            slope = np.where(np.isfinite(secant), np.clip(secant, -2.0, -0.1), slope)
            # on a plateau (the size unmoved by a move of k) the step doubles until the
            # size crosses the target: next to the plateau's edge the miss, and with it
            # the secant's step, is tiny (a target 1.6e-4 steps from the edge walked
            # 80 steps of 1e-5 in ln k and was refused)
            flat = (log_q == q_prev) & (log_k != log_prev) & ~bracketed
            stride = np.where(flat, 2.0 * stride, 1.0)
        log_prev, q_prev = log_k, log_q
        trial = log_k - stride * f / slope
        low, high = np.minimum(below, above), np.maximum(below, above)
        with np.errstate(all="ignore"):  # (unbracketed: inf - inf, not used below)
            false_pos = (below * f_above - above * f_below) / (f_above - f_below)
            middle = 0.5 * (below + above)
        inside = (false_pos > low) & (false_pos < high)
        false_pos = np.where(inside, false_pos, middle)
        # the secant while it stays inside and at least halves the miss, else Illinois
        fast = (trial > low) & (trial < high) & (np.abs(f) <= 0.5 * f_last)
        trial = np.where(bracketed & ~fast & ~converged, false_pos, trial)
        f_last = np.abs(f)
        # a converged design keeps its stiffness (and its evaluation): compaction
        k = np.where(converged, k, np.exp(trial))
        moved = np.abs(np.log(k) - log_k)
        todo = np.flatnonzero(~converged)
        width = np.abs(above - below)
        shut = bracketed & ~converged & (width <= 1e-14 * np.maximum(1.0, np.abs(below)))
        if np.any(shut):  # the size jumps across the target: no k between
            break
        miss = float(np.max(np.abs(ratio - 1.0)))
        progress = np.all(bracketed | converged)  # Illinois always shrinks the bracket
        # a design still walking along a plateau of the size (unbracketed, its miss
        # unchanged, its stiffness moving) makes progress too, however slowly: stopping it
        # refused targets that a larger batch (one that kept the loop going) designed
        walking = np.any(~bracketed & ~converged & (moved > 1e-12))
        stalled = 0 if progress or walking or miss <= 0.5 * best else stalled + 1
        best = min(best, miss)
        if stalled >= 6 or np.any(k > 1e6 * k_start) or np.any(k < 1e-6 * k_start):
            break  # no progress: out of reach
    if not np.all(np.abs(ratio - 1.0) <= _TOL):
        bad = int(np.argmax(np.abs(ratio - 1.0)))
        if np.isfinite(below[bad]) and np.isfinite(above[bad]):
            raise ValueError(
                f"{size_name} {float(target[bad])!r} is out of reach at time_step {h!r} with "
                f"restitution {float(e[bad])!r}: along the restitution's contour the "
                f"{size_name} jumps across it between k = {np.exp(below[bad]):.9g} and "
                f"{np.exp(above[bad]):.9g} N/m; use a smaller time_step"
            )
        raise ValueError(
            f"{size_name} {float(target[bad])!r} is out of reach at time_step {h!r} with "
            f"restitution {float(e[bad])!r}: the stiffness iteration does not settle "
            f"({size_name} {float(q[bad])!r} at k = {k[bad]:.6g}; near the rebound bound "
            "v_out < 1/d the contact time stops following the stiffness); use a smaller "
            "time_step or a larger restitution"
        )
    return k, damp


def _predict(k, damp, m, v, g, h, approx) -> Prediction:
    if approx == "sap":
        return predict(stiffness=k, dissipation=0.0, mass=m, speed=v, gravity=g, time_step=h,
                       approximation=approx, relaxation_time=damp)  # fmt: skip
    return predict(stiffness=k, dissipation=damp, mass=m, speed=v, gravity=g, time_step=h,
                   approximation=approx)  # fmt: skip


def _size(k, damp, m, v, g, size_name) -> np.ndarray:
    """The contact time or deepest overlap of the continuous contact (flat arrays)."""
    p = predict(stiffness=k, dissipation=damp, mass=m, speed=v, gravity=g)
    return np.asarray(getattr(p, size_name), float).ravel()


def _continuous_damping(e, k, m, v, g, start, size_name, moved):
    """The Hunt–Crossley ``d`` whose restitution is ``e`` at stiffness ``k`` (flat arrays),
    and the size there: warm-started Illinois on the exact restitution (the size from the
    same integrations), else :func:`~impactsym.contact.lawdesign.damping_for`."""
    scale = np.sqrt(m / k) * (1.0 if size_name == "contact_time" else v)  # T, or v T

    def e_of(p, rows):
        b = g[rows] * np.sqrt(m[rows] / k[rows]) / v[rows]  # the pressing number
        s = p * v[rows]
        tau, e_p, z_max, _ = normalized_impact("hunt-crossley", s, b, np.ones(rows.size),
                                               condition="position")  # fmt: skip
        return e_p, (tau if size_name == "contact_time" else z_max) * scale[rows]

    if np.all(start > 0) and np.all(g == 0):
        # without gravity s = d v does not depend on k: the last root holds
        return start, _size(k, start, m, v, g, size_name)
    root, q = np.full(e.size, np.nan), np.full(e.size, np.nan)
    cold = np.ones(e.size, bool)
    if np.all(start > 0) and np.all(g > 0):
        _warm_rows(e, start, (1.0 - 1e-12) / (e * v), e_of, moved, root, q, cold, cap=0.3)
    if cold.any():
        i = np.flatnonzero(cold)
        root[i] = np.asarray(damping_for("hunt-crossley", restitution=e[i], stiffness=k[i],
                             mass=m[i], speed=v[i], force=m[i] * g[i], exponent=1.0,
                             condition="position"), float).ravel()  # fmt: skip
        q[i] = _size(k[i], root[i], m[i], v[i], g[i], size_name)
    return root, q


def _warm_rows(e, start, upper, e_of, moved, root, q, cold, cap=2e-2):
    """Warm starts in place: where the root lies in a bracket around the last one, as
    narrow as the stiffness moved (the damping moves less; at most ``cap``), else 2 %,
    else 30 % wide, ``root`` and ``q`` get it and ``cold`` is cleared (measured: a cap of
    30 % saves the continuous solve under gravity a quarter of its integrations, 2 % is
    best at a step)."""
    upper = np.broadcast_to(upper, e.shape)
    tried = np.zeros(e.size)
    for width in (np.clip(2.0 * moved, 1e-9, cap), np.full(e.size, 2e-2), np.full(e.size, 0.3)):
        i = np.flatnonzero(cold & (width > tried))  # a bracket not yet tried
        if i.size == 0:
            continue
        tried[i] = width[i]

        def e_of_i(p, r, i=i):
            return e_of(p, i[r])

        root[i], q[i], ok = _warm(e[i], start[i], upper[i], e_of_i, width[i])
        cold[i[ok]] = False


def _warm(e, start, upper, e_of, width=2e-2):
    """The root in a narrow bracket around the last one (relative ``width``), its size,
    and where the root was in the bracket (elsewhere the two are ``nan``)."""
    rows = np.arange(e.size)
    lo, hi = start * (1.0 - width), np.minimum(start * (1.0 + width), upper)
    (e_lo, q_lo), (e_hi, q_hi) = e_of(lo, rows), e_of(hi, rows)
    ok = (e_lo > e) & (e_hi <= e)
    root, q = np.full(e.size, np.nan), np.full(e.size, np.nan)
    if ok.any():
        i = np.flatnonzero(ok)

        def e_of_i(p, r):
            return e_of(p, i[r])

        root[i], q[i] = _illinois(e[i], lo[i], hi[i], e_lo[i], e_hi[i], q_lo[i], q_hi[i], e_of_i)
    return root, q, ok


def _mean_of(k, m, v, g, h, approx, size_name):
    """``e_of(p, rows)``: the phase-mean restitution and size of designs ``rows`` at the
    damping ``p`` (``d``, or ``tau`` for ``"sap"``), without the range search."""
    sap = approx == "sap"

    def e_of(p, rows):
        d = np.zeros(rows.size) if sap else p
        tau = p if sap else 0.0
        r = phase_summary(k[rows], d, tau, m[rows], g[rows], v[rows], h, approximation=approx,
                          bounds=False, stuck_peaks=size_name != "contact_time")  # fmt: skip
        return r.restitution, getattr(r, size_name)

    return e_of


def _discrete_damping(e, k, m, v, g, h, approx, start, size_name, moved):
    """The damping (``d``, or ``tau`` for ``"sap"``) whose phase-mean restitution is ``e``
    at stiffness ``k`` (flat arrays): Illinois inside a bracket, warm-started where the
    last root is near, and the phase-mean size (``size_name``) there, from the same
    evaluations."""
    sap = approx == "sap"
    e_of = _mean_of(k, m, v, g, h, approx, size_name)

    root, q = np.full(e.size, np.nan), np.full(e.size, np.nan)
    cold = np.ones(e.size, bool)
    if np.all(start > 0):  # warm start: a narrow bracket around the last root
        _warm_rows(e, start, np.inf if sap else (1.0 - 1e-12) / (e * v), e_of, moved, root, q,
                   cold)  # fmt: skip
    if cold.any():
        i = np.flatnonzero(cold)
        args = (a[i] for a in (e, k, m, v, g))
        root[i], q[i] = _discrete_cold(*args, h, approx, start[i], size_name)
    return root, q


def _discrete_cold(e, k, m, v, g, h, approx, start, size_name):
    """:func:`_discrete_damping` from the widest bracket (``0`` to the rebound bound, or
    a growing relaxation time for ``"sap"``), refusing what it cannot reach."""
    sap = approx == "sap"
    e_of = _mean_of(k, m, v, g, h, approx, size_name)

    rows = np.arange(e.size)
    e0, q0 = e_of(np.zeros(e.size), rows)
    high = e0 <= e
    if high.any():
        bad = np.flatnonzero(high)[0]
        if e0[bad] == 0.0 and g[bad] > 0:  # every phase sticks: the load, not the step
            raise ValueError(
                f"restitution {float(e[bad])!r} is out of reach at speed {float(v[bad])!r}, "
                f"gravity {float(g[bad])!r}: even without dissipation the body sticks at "
                f"the stiffness this {size_name} needs (k = {float(k[bad]):.6g} N/m; the "
                "pressing force holds it at every touch phase); ask for a larger speed, a "
                "shorter contact or a smaller gravity"
            )
        if g[bad] > 0:  # the load's impulse takes its share of the rebound
            raise ValueError(
                f"restitution {float(e[bad])!r} is out of reach with {approx!r} at time_step "
                f"{h!r}: without dissipation the contact restitutes {e0[bad]:.6g} under "
                f"gravity {float(g[bad])!r} (the step and the load's impulse both take "
                "from the rebound); ask for a smaller restitution, a larger speed or a "
                "shorter contact, or use a smaller time_step"
            )
        raise ValueError(
            f"restitution {float(e[bad])!r} is out of reach with {approx!r} at time_step {h!r}: "
            f"without dissipation the step itself restitutes {e0[bad]:.6g}; ask for a "
            "smaller restitution or use a smaller time_step"
        )
    if sap:
        hi = np.where(start > 0, 2.0 * start, 10.0 * h)
        e_hi, q_hi = e_of(hi, rows)
        for _ in range(60):
            grow = e_hi > e
            if not grow.any():
                break
            hi[grow] *= 4.0
            e_hi[grow], q_hi[grow] = e_of(hi[grow], rows[grow])
        else:
            bad = np.flatnonzero(e_hi > e)[0]
            raise ValueError(
                f"restitution {float(e[bad])!r} is out of reach with 'sap': it stays at "
                f"{e_hi[bad]:.6g} up to relaxation_time {hi[bad]:.3g} s"
            )
    else:
        # the rebound e v must stay below 1/d: the bracket ends just short of 1/(e v)
        hi = (1.0 - 1e-12) / (e * v)
        e_hi, q_hi = e_of(hi, rows)
        bad = np.flatnonzero(e_hi > e)
        if bad.size:
            i = bad[0]
            raise ValueError(
                f"restitution {float(e[i])!r} is out of reach with {approx!r} at time_step {h!r}: "
                f"the rebound speed e v must stay below 1/d, and at d = 1/(e v) = {hi[i]:.6g} "
                f"s/m the step still restitutes {e_hi[i]:.6g}; use a smaller time_step"
            )
    return _illinois(e, np.zeros(e.size), hi, e0, e_hi, q0, q_hi, e_of)


def _illinois(e, lo, hi, e_lo, e_hi, q_lo, q_hi, e_of):
    """The root of ``e_of(p)[0] = e`` inside ``[lo, hi]`` (falling), Illinois steps, and
    ``e_of(p)[1]`` (the size) there."""
    lo, hi, q_lo, q_hi = lo.copy(), hi.copy(), np.array(q_lo, float), np.array(q_hi, float)
    g_lo, g_hi = e_lo - e, e_hi - e
    side = np.zeros(e.size, int)
    active = np.ones(e.size, bool)
    for _ in range(_INNER):
        r = np.flatnonzero(active)
        if r.size == 0:
            break
        with np.errstate(all="ignore"):
            trial = (lo[r] * g_hi[r] - hi[r] * g_lo[r]) / (g_hi[r] - g_lo[r])
        bad = ~np.isfinite(trial) | (trial <= lo[r]) | (trial >= hi[r])
        trial = np.where(bad, 0.5 * (lo[r] + hi[r]), trial)
        e_t, q_t = e_of(trial, r)
        g_t = e_t - e[r]
        up = g_t > 0
        ru, rd = r[up], r[~up]
        lo[ru], g_lo[ru], q_lo[ru] = trial[up], g_t[up], q_t[up]
        hi[rd], g_hi[rd], q_hi[rd] = trial[~up], g_t[~up], q_t[~up]
        g_hi[ru] = np.where(side[ru] == 1, 0.5 * g_hi[ru], g_hi[ru])
        g_lo[rd] = np.where(side[rd] == -1, 0.5 * g_lo[rd], g_lo[rd])
        side[ru], side[rd] = 1, -1
        done = (np.abs(g_t) <= 1e-12) | (hi[r] - lo[r] <= 1e-13 * hi[r])
        active[r[done]] = False
    nearer = np.abs(g_lo) <= np.abs(g_hi)
    return np.where(nearer, lo, hi), np.where(nearer, q_lo, q_hi)
