r"""PyBullet's contact as the engine steps it: the exact one-contact map, per touch phase.

One frictionless normal contact of a body of mass ``m`` (effective mass of the contact row)
with a static body, combined ``contactStiffness`` ``k`` and ``contactDamping`` ``c``
(:mod:`~impactsym.engines.pybullet.pair`). In approach coordinates (penetration ``x``,
approach speed ``w``, gravity ``g`` pressing the body on) one (sub)step ``h`` of
``btMultiBodyDynamicsWorld`` is (:mod:`~impactsym.engines.pybullet.derivation`):

.. math::

    w^* = w + g h, \quad d = s - x, \quad
    b = \begin{cases} w^* - d/h & d > 0 \text{ (speculative)} \\
                      w^* - \mathrm{erp}\, d / h & d \le 0 \end{cases}

    \lambda = \max\bigl(0,\ b / (1/m + \mathrm{cfm}/h)\bigr), \quad
    w' = w^* - \lambda / m, \quad x' = x + h w',

with ``erp = h k / (h k + c)``, ``cfm = 1 / (h k + c)``, slop ``s`` (``contactSlop``),
and ``lambda = 0`` while the gap ``-x`` exceeds the contact processing threshold. The
sequential-impulse solver reaches this ``lambda`` exactly in its first iteration (one
row), whatever the iteration count or warm start.

The touch phase (`docs/physics.md#touch-phase`, as for MuJoCo in
:mod:`impactsym.engines.mujoco.stepping`): geometric touch lies ``phase * timestep``
before state 0, the first state that free flight would carry into overlap; state ``-1``
carries free flight. The force *of a state* is what ``getContactPoints`` reports after
the ``stepSimulation`` call that produced it (the impulse of its last sub-step over the
sub-step). The contact begins at the first state with a positive force (state 0 under
speculative contacts, state 1 without) and **ends** at the first later state whose force
is zero: ``restitution`` is that state's separation speed over ``speed``,
``contact_time`` the time from touch to it. If the force comes back while the body still
overlaps (``x > 0``), or the contact outlasts the step budget, the body **sticks**.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from impactsym.engines.mujoco.stepping import StepContact

__all__ = [
    "DEFAULT_RESTITUTION_THRESHOLD",
    "DEFAULT_SLOP",
    "MAX_STEPS",
    "PATTERN",
    "close_state",
    "end_final",
    "new_reading",
    "pattern_code",
    "read_state",
    "reading_fields",
    "run_live",
    "run_pattern",
    "start_state",
    "step_budget",
    "step_contact",
    "step_pattern",
    "substep_impulse",
]

#: PyBullet's default ``contactSlop`` (``m_linearSlop`` set by PhysicsServerCommandProcessor)
DEFAULT_SLOP = 1e-5
#: the step budget is capped here (a contact still on then counts as sticking); the
#: public functions refuse a timestep whose contact would need more
MAX_STEPS = 50_000
#: ``m_restitutionVelocityThreshold = 0.2f`` (a float literal stored in a double)
DEFAULT_RESTITUTION_THRESHOLD = float(np.float32(0.2))


#: the arrays :func:`read_state` keeps per element (flags first)
READING = ("started", "ended", "sticks", "n_first", "n_end", "w_end", "x_end", "x_max",
           "f_max", "depart")  # fmt: skip


def new_reading(size: int) -> dict[str, np.ndarray]:
    """The bookkeeping of :func:`read_state` for ``size`` elements before any state."""
    return {key: np.zeros(size, bool if i < 3 else float) for i, key in enumerate(READING)}


def read_state(
    r: dict[str, np.ndarray],
    n: int,
    x: np.ndarray,
    w: np.ndarray,
    push: np.ndarray,
    live: np.ndarray,
    *,
    separating: np.ndarray | None = None,
    extremes: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Read state ``n`` into ``r`` (updated in place) by the definitions of the module
    docstring: the contact begins at the first positive ``push`` (the state's force, or
    its acceleration), ends at the first later zero one (``separating``: only where this
    mask also holds), is back while it overlaps (``x > 0``: a stick) and is gone where
    ``x <= 0`` after its end. ``live``: the elements not yet done. Returns the masks
    ``(back, gone)``; the caller marks them done. One place for the PyBullet maps
    (compliant, rigid and the rotating body). Without ``extremes`` the peak penetration
    and force are not kept (runs that want the pattern alone)."""
    on = push > 0
    started, ended = r["started"], r["ended"]  # (the arrays of r, updated in place)
    begin = live & ~started & on
    started |= begin
    np.copyto(r["n_first"], n, where=begin)
    contact = live & started & ~ended
    if extremes:
        np.maximum(r["x_max"], x, out=r["x_max"], where=contact)
        np.maximum(r["f_max"], push, out=r["f_max"], where=contact)
    stop = contact & ~on
    if separating is not None:
        stop &= separating
    ended |= stop
    if stop.any():
        np.copyto(r["n_end"], n, where=stop)
        np.copyto(r["w_end"], w, where=stop)
        np.copyto(r["x_end"], x, where=stop)
    after = live & ended & ~stop
    back = after & on & (x > 0)  # force back inside the overlap
    r["sticks"] |= back
    gone = (after & ~back | stop) & (x <= 0)
    if gone.any():
        np.copyto(r["depart"], -w, where=gone)
    return back, gone


def reading_fields(
    r: dict[str, np.ndarray], speed: np.ndarray, phase: np.ndarray, step: Any, scale: Any
) -> dict[str, np.ndarray]:
    """The :class:`StepContact` fields of a finished reading ``r``: ``step`` the time
    between states, ``scale`` what turns the peak ``push`` into an acceleration (the
    mass, or 1)."""
    sticks, n_end = r["sticks"], r["n_end"]
    return {
        "restitution": np.where(sticks, 0.0, -r["w_end"] / speed),
        "contact_time": np.where(sticks, np.inf, (phase + n_end) * step),
        "sticks": sticks,
        "released_by_position": ~sticks & (r["x_end"] <= 0),
        "departure_speed": np.where(sticks, 0.0, r["depart"]),
        "steps": np.where(sticks, np.inf, n_end - r["n_first"]),
        "max_penetration": r["x_max"],
        "peak_accel": r["f_max"] / scale,
    }


def step_budget(stiffness: Any, damping: Any, mass: Any, timestep: Any) -> np.ndarray:
    """Calls after which a contact still on counts as sticking (ten undamped periods plus
    ten damping times ``c / k``, at least 200 calls)."""
    k, c, m, h = (np.asarray(a, float) for a in (stiffness, damping, mass, timestep))
    span = 20.0 * np.pi * np.sqrt(m / k) + 10.0 * c / k
    return np.maximum(np.ceil(span / h), 200.0)


def step_contact(
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
) -> StepContact:
    """The contact at touch phase ``phase`` as PyBullet's states show it (arrays, SI).

    Validated arrays in (broadcast together; ``damping`` is the pair's combined value),
    a :class:`~impactsym.engines.mujoco.stepping.StepContact` out. The map of the module
    docstring is iterated on whole arrays, ``substeps`` sub-steps of ``timestep /
    substeps`` per state, until every element has ended and left the overlap (or stuck).
    """
    return step_pattern(
        stiffness,
        damping,
        mass,
        speed,
        gravity,
        timestep,
        phase,
        substeps=substeps,
        slop=slop,
        processing_threshold=processing_threshold,
        velocity_restitution=velocity_restitution,
        restitution_threshold=restitution_threshold,
    )[0]


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

    The pattern is a record (:data:`PATTERN`) of the counts of the branches the
    sub-steps took (first and end state, sub-steps with a speculative, a positional and a
    restitution impulse; all ``-1`` where the body sticks): where
    it is constant in the phase, the end state is a fixed affine map of the free-flight
    state ``-1``, quadratic in the phase, so the restitution is a quadratic there and
    the contact time linear (:mod:`~impactsym.engines.pybullet.phases` integrates it).
    """
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep, phase))
    )
    shape = arrays[0].shape
    settings = (slop, processing_threshold, velocity_restitution, restitution_threshold)
    state, pattern, (m, v, H, p) = _run_map(arrays, substeps, settings, pattern_only=False)
    fields = reading_fields(state, v, p, H, m)
    record = StepContact(**{key: val.reshape(shape) for key, val in fields.items()})
    return record, pattern.reshape(shape)


def run_pattern(
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
) -> np.ndarray:
    """The pattern of :func:`step_pattern` alone (the same records, flat), for less
    work: no peak penetration or force is kept, and without gravity (in the whole call)
    a run stops where its contact ends final (:func:`end_final`)."""
    arrays = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (stiffness, damping, mass, speed, gravity, timestep, phase))
    )
    settings = (slop, processing_threshold, velocity_restitution, restitution_threshold)
    return _run_map(arrays, substeps, settings, pattern_only=True)[1]


def _run_map(arrays, substeps, settings, *, pattern_only):
    """Run the map on the broadcast ``(k, c, m, v, g, H, p)`` (``settings``: ``slop,
    processing_threshold, velocity_restitution, restitution_threshold``): the finished
    state, the flat pattern and the flat ``(m, v, H, p)``. ``pattern_only``: as
    :func:`run_pattern` (no extremes; without gravity stopped at a final end)."""
    k, c, m, v, g, H, p = (a.ravel().copy() for a in arrays)
    fixed, state = start_state(k, c, m, v, g, H, p, substeps)
    final = pattern_only and not np.any(g)
    state = run_live(
        fixed, state,
        lambda a, n, limit: _advance(a, n, limit, substeps, *settings, pattern=pattern_only,
                                     final=final),
    )  # fmt: skip
    counts = ("sticks", "n_end", "n_first", "n_spec", "n_pos", "n_rest")
    return state, pattern_code(*(state[key] for key in counts)), (m, v, H, p)


def end_final(a: dict, n: int, stop: np.ndarray, substeps: int) -> np.ndarray:
    """Of the live elements ``a`` without gravity whose contact ended at state ``n``
    (``stop``): those whose run can stop there, its pattern final. A contact that ended
    separating (``w < 0``) never sticks: each later bias is the last one (``<= 0``) plus
    ``erp w < 0`` (or the speculative one, below ``w``); unless the way out (``x / (H
    |w|)`` calls) could outlast the step budget, which counts as sticking."""
    j = np.flatnonzero(stop)  # (few: the test on those alone)
    x, w = a["x"][j], a["w"][j]
    with np.errstate(divide="ignore", invalid="ignore"):
        calls = x / (-w * a["h"][j] * substeps)
        final = np.zeros(stop.size, bool)
        final[j] = (w < 0) & (n + calls + 2.0 < a["budget"][j])
    return final


def start_state(
    k: np.ndarray,
    c: np.ndarray,
    m: np.ndarray,
    v: np.ndarray,
    g: np.ndarray,
    H: np.ndarray,
    p: np.ndarray,
    substeps: int,
) -> tuple[dict, dict]:
    """The fixed arrays of the step map (``m, g, h, erp, gain, budget``: ERP and the
    impulse gain ``lambda / m = gain * b`` from ``k, c`` and the sub-step ``h``) and the
    state of every element at state ``-1`` (free flight ``(p - 1) H`` after touch), with
    the reading's fields and the branch counts zeroed. Flat arrays."""
    h = H / substeps
    erp = h * k / (h * k + c)
    cfm = 1.0 / (h * (h * k + c))
    gain = 1.0 / (1.0 + m * cfm)  # lambda / m = gain * b
    t = (p - 1.0) * H  # state -1: free flight
    size = k.size
    budget = np.minimum(step_budget(k, c, m, H), MAX_STEPS)
    fixed = {"m": m, "g": g, "h": h, "erp": erp, "gain": gain, "budget": budget}
    state = {
        "x": v * t + 0.5 * g * t * t, "w": v + g * t, "done": np.zeros(size, bool),
        **new_reading(size), **{key: np.zeros(size) for key in ("n_spec", "n_pos", "n_rest")},
    }  # fmt: skip
    return fixed, state


def run_live(fixed: dict, state: dict, advance: Callable[[dict, int, int], None]) -> dict:
    """Step every element of ``state`` until it is done and return ``state``.

    ``advance(a, n, limit)`` makes state ``n`` of the live elements (the dict ``a`` of
    their arrays, ``fixed`` and ``state`` gathered, updated in place) and marks the done
    ones; ``limit`` is the smallest step budget, from which each element is checked
    against its own (so no verdict depends on the other elements of the call). The loop
    steps a gathered copy of the live elements and drops the finished ones when they are
    half of it: elementwise the same numbers as stepping everything.
    """
    size = fixed["budget"].size
    limit = int(fixed["budget"].min()) if size else 0
    live = np.arange(size)
    a = {key: val.copy() for key, val in {**fixed, **state}.items()}  # live: every element
    n = -1
    while live.size:
        n += 1
        advance(a, n, limit)
        finished = int(np.count_nonzero(a["done"]))
        if 2 * finished >= live.size:
            for key in state:
                state[key][live] = a[key]
            keep = ~a["done"]
            live = live[keep]
            a = {key: val[keep] for key, val in a.items()}
    return state


def close_state(a: dict, n: int, limit: int, force: np.ndarray, *, extremes: bool = True) -> None:
    """State ``n`` of the live elements ``a`` (after their sub-steps): read it
    (:func:`read_state`, ``force`` the last sub-step's; ``extremes`` as there) and mark
    the elements done that departed, stick by a force back inside the overlap, or
    outlast their own step budget (a stick; checked from ``limit``, the smallest budget,
    on)."""
    back, gone = read_state(a, n, a["x"], a["w"], force, ~a["done"], extremes=extremes)
    done = a["done"] | back | gone
    if n >= limit:
        over = ~done & (n >= a["budget"])
        a["sticks"] |= over
        done |= over
    a["done"] = done


#: the record of a branch pattern: every count, compared field by field (exact at any size)
PATTERN = np.dtype([(name, np.int64) for name in ("end", "first", "spec", "pos", "rest")])


def pattern_code(
    sticks: np.ndarray,
    n_end: np.ndarray,
    n_first: np.ndarray,
    n_spec: np.ndarray,
    n_pos: np.ndarray,
    n_rest: np.ndarray,
) -> np.ndarray:
    """One record of :data:`PATTERN` per element that is equal exactly where the branch
    counts are (``==`` compares records field by field): every field ``-1`` where the
    body sticks, else the counts. Exact however long the contact (an earlier float
    packing of the counts overflowed past 1024 sub-steps of one kind, and the phase
    summaries then integrated across end-step jumps)."""
    counts = np.broadcast_arrays(n_end, n_first, n_spec, n_pos, n_rest)
    code = np.empty(counts[0].shape, PATTERN)
    stuck = np.asarray(sticks, bool)
    for name, count in zip(PATTERN.names, counts, strict=True):
        code[name] = np.where(stuck, -1, count)
    return code


def substep_impulse(
    a: dict,
    x: np.ndarray,
    w: np.ndarray,
    slop: float,
    processing_threshold: float,
    velocity_restitution: float,
    restitution_threshold: float,
) -> tuple[np.ndarray, ...]:
    """The impulse of one sub-step from the state ``x, w`` (module docstring's map), with
    its branches counted in the live elements ``a`` (``n_spec``, ``n_pos``, ``n_rest``,
    where the contact has not ended). Returns ``w_star, d, spec, b_spec, b_pos, rest,
    within, dv``: the bias on both sides of the speculative branch ``spec = d > 0``
    (``b_spec``, ``b_pos``, the restitution term included), the mask ``rest`` of the
    velocity-restitution term (``None`` without it), the mask ``within`` of the contact
    processing threshold (``True`` where it is ``+inf``: none; ``-inf`` processes
    nothing) and the velocity change ``dv = lambda / m``; the caller makes
    ``w' = w_star - dv``, ``x' = x + h w'``. Shared by :func:`step_pattern` and the
    phase-derivative tracker of :mod:`~impactsym.engines.pybullet.tracking`."""
    g, h, erp, gain, ended = a["g"], a["h"], a["erp"], a["gain"], a["ended"]
    w_star = w + g * h
    d = slop - x
    spec = d > 0
    b_spec, b_pos = w_star - d / h, w_star - erp * d / h
    rest = None
    if velocity_restitution:  # restitutionCurve: a wanted separation speed
        rest = (np.abs(w_star) >= restitution_threshold) & (w_star > 0)
        add = np.where(rest, velocity_restitution * w_star, 0.0)
        b_spec, b_pos = b_spec + add, b_pos + add
        a["n_rest"] += ~ended & rest
    dv = np.maximum(gain * np.where(spec, b_spec, b_pos), 0.0)
    if processing_threshold == np.inf:  # (every contact within it: no mask to apply)
        within = True
    else:
        within = -x <= processing_threshold
        dv = np.where(within, dv, 0.0)
    counting = ~ended & (dv > 0)
    a["n_spec"] += counting & spec
    a["n_pos"] += counting & ~spec
    return w_star, d, spec, b_spec, b_pos, rest, within, dv


def _advance(
    a,
    n,
    limit,
    substeps,
    slop,
    processing_threshold,
    velocity_restitution,
    restitution_threshold,
    *,
    pattern=False,
    final=False,
):
    """State ``n`` of the live elements (the dict ``a`` of their arrays, updated in
    place): the sub-steps of one ``stepSimulation`` call and the bookkeeping of the
    module docstring; ``a["done"]`` marks the elements departed or stuck. ``pattern``:
    the extremes not kept; ``final`` (no gravity): also done where :func:`end_final`."""
    settings = (slop, processing_threshold, velocity_restitution, restitution_threshold)
    x, w, h = a["x"], a["w"], a["h"]
    for _ in range(substeps):
        w_star, *_, dv = substep_impulse(a, x, w, *settings)
        w = w_star - dv
        x = x + h * w
    a["x"], a["w"] = x, w
    close_state(a, n, limit, dv * a["m"] / h, extremes=not pattern)
    if final:
        stop = a["ended"] & (a["n_end"] == n)
        if stop.any():
            a["done"] |= end_final(a, n, stop, substeps)
