r"""MuJoCo's ``Euler`` (and ``implicitfast``) step applied to one contact: exact per phase.

One step of MuJoCo 4 (``mj_forward`` then ``mj_Euler``; `docs/physics.md#touch-phase`):
the contact exists iff the distance is ``< 0`` (penetration ``x > 0``: the collision
reports distance 0 too, but ``engine_collision_driver.c`` excludes a contact at distance
exactly 0 from the constraints); its constraint acceleration is computed from the state
at the start of the step, with the impedance ``d(x)`` there, ``R = (1 - d)/d A_diag``
and refsafe, and clipped at zero,

.. math::

    F_n = d'_n\,\max(0,\ g + b\,u_n + d_n \bar k\,x_n), \qquad
    u_{n+1} = u_n + \Delta t\,(g - F_n), \qquad x_{n+1} = x_n + \Delta t\,u_{n+1}

(``u = x'``; semi-implicit: the position uses the new velocity). ``implicitfast``
solves ``(M - dt D) a = f`` with ``D`` the velocity derivative of the *smooth* forces
only, zero without joint damping or actuators, so its step is the same map
(:func:`impactsym.engines.derivation.mujoco_euler_step` shows both).

In units of ``speed * timestep`` (``X = x / (v0 dt)``, ``Y = u / v0``, ``G = g dt / v0``)
the step is ``Y' = Y + G - F``, ``X' = X + Y'`` with
``F = d' (G + b dt Y + d kbar dt^2 X)``. At flat impedance it is affine with the matrix
of :mod:`~impactsym.engines.mujoco.stepmap`; the end step is found in closed form there
and the coast after a force zero (free flight while the overlap lasts) from two
quadratics in the step count. A varying impedance runs the exact recurrence, vectorized
over designs and phases (a loop over steps on whole arrays), with a closed-form proof of
rest once the body is beyond the impedance width.

Internal: :mod:`~impactsym.engines.mujoco.discrete` dispatches to it.
All quantities are SI: seconds, metres, m/s, m/s^2.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.mujoco.model import (
    Coefficients,
    d_max,
    effective_impedance,
    impedance_at,
    is_flat,
)
from impactsym.engines.mujoco.stepmap import Sequence, first_hit, sequence_max
from impactsym.engines.mujoco.stepping import StepContact

__all__ = [
    "coast_flat",
    "euler_constants",
    "euler_contact",
    "euler_end_value",
    "euler_first_state",
    "euler_force",
    "euler_state",
]

_MAX_STEPS = 2_000_000  # recurrence steps refused beyond this (a contact that never settles)
_PROOF_EVERY = 32  # recurrence steps between attempts to prove rest
#: ``(omega0 dt)^2`` above which a flat contact is stepped rather than solved in closed
#: form (under about 24 steps per half period the recurrence costs less)
_SHORT_KAPPA = (np.pi / 24.0) ** 2


def euler_contact(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
) -> StepContact:
    """The contact as MuJoCo's Euler step shows it, at touch phase ``phase`` (arrays, SI).

    Parameters
    ----------
    coeffs
        ``b`` and ``kbar`` of the ``solref``, refsafe applied
        (:func:`~impactsym.engines.mujoco.model.coefficients` with the timestep).
    solimp
        Checked five-tuple.
    rho, gravity, speed, timestep, phase
        Weight ratio ``A / A_diag``, pressing acceleration (m/s^2), approach speed at
        geometric touch (m/s), timestep (s) and touch phase in ``[0, 1)``; all broadcast.

    Returns
    -------
    StepContact
        Per element, with the definitions of :mod:`~impactsym.engines.mujoco.stepping`.
    """
    arrays = np.broadcast_arrays(
        *(
            np.asarray(a, float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep, phase)
        )
    )
    shape = arrays[0].shape
    b, kbar, rho, g, v0, dt, p = (a.ravel() for a in arrays)
    G = g * dt / v0
    # phase 0: the state at touch has zero distance, which MuJoCo does not count as
    # contact (con->exclude for dist >= margin): one free Euler step to the first state
    t0 = np.where(p > 0, p, 1.0)
    state = {
        "X": np.where(p > 0, p + 0.5 * G * p * p, 1.0 + G),
        "Y": np.where(p > 0, 1.0 + G * p, 1.0 + G),
        "G": G,
        "bdt": b * dt,
        "kdt2": kbar * dt * dt,
        "rho": rho,
        "L": v0 * dt,
    }
    size = b.size
    out = {
        "N": np.full(size, np.inf),
        "Y_end": np.zeros(size),
        "X_end": np.zeros(size),
        "by_pos": np.zeros(size, bool),
        "X_max": np.zeros(size),
        "F_max": np.zeros(size),
        "dep": np.zeros(size),
        "sticks": np.zeros(size, bool),
    }
    todo = np.arange(size)
    if is_flat(solimp) and size:
        todo = _flat(state, float(impedance_at(np.zeros(()), solimp)), out)
    if todo.size:
        _recurrence(state, solimp, out, todo)
    sticks = out["sticks"] | ~np.isfinite(out["N"])
    with np.errstate(invalid="ignore"):
        e = np.where(sticks, 0.0, -out["Y_end"])
        t_c = np.where(sticks, np.inf, (t0 + out["N"]) * dt)
        dep = np.where(sticks, 0.0, out["dep"] * v0)
    fields = (
        e,
        t_c,
        sticks,
        out["by_pos"] & ~sticks,
        dep,
        np.where(np.isfinite(out["N"]), out["N"], -1).astype(np.int64),
        out["X_max"] * v0 * dt,
        out["F_max"] * v0 / dt,
    )
    return StepContact(*(np.reshape(a, shape) for a in fields))


def euler_end_value(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
    step: Any,
) -> np.ndarray:
    """``min(X_m, F_m)`` at the state ``m = step`` after the first detecting one (phase > 0).

    The state ``m`` ends the contact iff this is ``<= 0`` (the body is gone or the force
    is zero; :func:`euler_contact`), and it is continuous in the phase while the states
    before ``m`` are in contact with a positive force, so a jump of the end step from or
    to ``m`` is a root of it in the phase: the phase summary locates such jumps by a
    bracketed secant on it rather than by sampling the end step. The state of
    :func:`euler_state` (arrays broadcast; dimensionless). Internal.
    """
    return np.minimum(*euler_state(coeffs, solimp, rho, gravity, speed, timestep, phase, step))


def euler_state(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
    step: Any,
) -> tuple[np.ndarray, np.ndarray]:
    """``(X_m, F_m)``: the penetration and the constraint's force per step (before its
    clip at zero) of the state ``m = step`` after the first detecting one (phase > 0),
    stepped in contact (``Y' = Y + G - max(F, 0)``, ``X' = X + Y'``) whatever the states
    before it: continuous in the phase while they push. Same arithmetic as
    :func:`euler_contact` (arrays broadcast; dimensionless: ``X`` in ``speed *
    timestep``, ``F`` per step in ``speed``). Internal.
    """
    arrays = np.broadcast_arrays(
        *(
            np.asarray(a, float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep, phase, step)
        )
    )
    shape = arrays[0].shape
    b, kbar, rho, g, v0, dt, p, m = (a.ravel() for a in arrays)
    consts = euler_constants(b, kbar, rho, g, v0, dt)
    x, y = euler_first_state(p, consts[0])
    x_out, f_out = np.full(x.size, np.nan), np.full(x.size, np.nan)
    live = np.arange(x.size)
    for k in range(int(m.max(initial=0.0)) + 1):
        F = euler_force(x, y, consts, solimp)
        at = m[live] == k
        if at.any():
            x_out[live[at]], f_out[live[at]] = x[at], F[at]
            more = ~at
            live, x, y, F = live[more], x[more], y[more], F[more]
            consts = tuple(c[more] for c in consts)
        y = y + consts[0] - np.maximum(F, 0.0)
        x = x + y
    return x_out.reshape(shape), f_out.reshape(shape)


def euler_constants(b: Any, kbar: Any, rho: Any, g: Any, v0: Any, dt: Any) -> tuple:
    """``(G, b dt, kbar dt^2, v0 dt, rho)``: the constants of the recurrence in contact
    (dimensionless; :func:`euler_force`). Internal."""
    return g * dt / v0, b * dt, kbar * dt * dt, v0 * dt, rho


def euler_first_state(p: Any, G: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(X, Y)`` of the first detecting state at phase ``p > 0``: free flight for ``p``
    steps (dimensionless). Internal."""
    return p + 0.5 * G * p * p, 1.0 + G * p


def euler_force(x: Any, y: Any, consts: tuple, solimp: tuple[float, ...]) -> np.ndarray:
    """The constraint's ``F`` per step at the state ``(x, y)``, before the clip at zero
    (``consts`` of :func:`euler_constants`). Internal."""
    G, bdt, kdt2, L, rho = consts
    d = impedance_at(x * L, solimp)
    return effective_impedance(d, rho) * (G + bdt * y + d * kdt2 * x)


def _take(state: dict, i: np.ndarray) -> dict:
    return {k: v[i] for k, v in state.items()}


def _flat(state: dict, d: float, out: dict) -> np.ndarray:
    """The closed form at flat impedance ``d``; returns the elements left to the recurrence."""
    dp = effective_impedance(d, state["rho"])
    kappa = dp * d * state["kdt2"]
    beta = dp * state["bdt"]
    G, X0, Y0 = state["G"], state["X"], state["Y"]
    with np.errstate(divide="ignore", invalid="ignore"):
        x_star = np.where(G > 0, (1.0 - dp) * G / kappa, 0.0)
    # short contacts (fewer than about 24 steps per half period) are cheaper stepped:
    # the sequences are built for the long ones only
    cand = np.flatnonzero((kappa < _SHORT_KAPPA) & np.isfinite(x_star))
    kappa, beta, x_star, G = kappa[cand], beta[cand], x_star[cand], G[cand]
    w1, w2 = X0[cand] - x_star, Y0[cand]
    zero = np.zeros_like(G)
    pos = Sequence(kappa, beta, 1.0, 0.0, w1, w2, x_star)
    keep = np.flatnonzero(pos.kind > 0)
    closed = cand[keep]
    kappa, beta, x_star, G, w1, w2 = (a[keep] for a in (kappa, beta, x_star, G, w1, w2))
    pos = pos.take(keep)
    force = Sequence(kappa, beta, kappa, beta, w1, w2, G)
    vel = Sequence(kappa, beta, 0.0, 1.0, w1, w2, zero[keep])
    n_pos = first_hit(pos, lambda n, i: pos.take(i).at(n) <= 0)
    n_force = first_hit(force, lambda n, i: force.take(i).at(n) <= 0)
    N = np.minimum(n_pos, n_force)
    by_pos = n_pos <= n_force
    ended = np.isfinite(N)
    at = np.where(ended, N, 0.0)
    Y_end, X_end = vel.at(at), pos.at(at)
    last = np.where(ended, N - 1.0, np.inf)
    out["N"][closed] = N
    out["Y_end"][closed] = Y_end
    out["X_end"][closed] = X_end
    out["by_pos"][closed] = by_pos & ended
    out["X_max"][closed] = sequence_max(pos, last)
    out["F_max"][closed] = sequence_max(force, last)
    out["dep"][closed] = np.where(by_pos, -Y_end, 0.0)
    coast = np.flatnonzero(ended & ~by_pos)
    if coast.size:
        c = closed[coast]
        sticks, dep = coast_flat(
            X_end[coast], Y_end[coast], G[coast], state["bdt"][c], d * state["kdt2"][c]
        )
        out["sticks"][c] = sticks
        out["dep"][c] = dep
    left = np.ones(state["G"].size, bool)
    left[closed] = False
    return np.flatnonzero(left)


def coast_flat(X, Y, G, bdt, dkdt2):
    """After a force zero at ``(X, Y)``: free flight ``Y_j = Y + j G``,
    ``X_j = X + j Y + G j (j + 1) / 2``; the body leaves at the first ``j`` with
    ``X_j < 0`` unless the force ``G + b dt Y_j + d kbar dt^2 X_j`` is positive at an
    earlier state in contact (it sticks). Both are quadratics in ``j``: their roots, then
    the integer check. Returns ``(sticks, departure Y)``."""

    def x_at(j):
        return X + j * Y + 0.5 * G * j * (j + 1.0)

    def f_at(j):
        return G + bdt * (Y + j * G) + dkdt2 * x_at(j)

    with np.errstate(divide="ignore", invalid="ignore"):
        # X_j = (G/2) j^2 + (Y + G/2) j + X: first j >= 1 with X_j < 0
        a, bb = 0.5 * G, Y + 0.5 * G
        disc = bb * bb - 4.0 * a * X
        root = np.where(
            G > 0, (-bb - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a), X / np.maximum(-Y, 0.0)
        )
        root = np.where((G > 0) & (bb < 0), 2.0 * X / (-bb + np.sqrt(np.maximum(disc, 0.0))), root)
        j_x = _first_integer(np.where(np.isfinite(root), root, 1e300), lambda j: x_at(j) <= 0)
        j_x = np.where((G > 0) & (disc < 0), np.inf, j_x)
        # F_j: convex in j, <= 0 at j = 0: positive past its larger root
        a2 = 0.5 * G * dkdt2
        b2 = bdt * G + dkdt2 * (Y + 0.5 * G)
        c2 = G + bdt * Y + dkdt2 * X
        disc2 = b2 * b2 - 4.0 * a2 * c2
        big = np.where(
            b2 > 0,
            -2.0 * c2 / (b2 + np.sqrt(np.maximum(disc2, 0.0))),
            (-b2 + np.sqrt(np.maximum(disc2, 0.0))) / (2.0 * a2),
        )
        j_f = _first_integer(np.where(np.isfinite(big), big, 1e300), lambda j: f_at(j) > 0)
        j_f = np.where(G > 0, j_f, np.inf)
    sticks = j_f < j_x
    dep = np.where(sticks | ~np.isfinite(j_x), 0.0, -(Y + np.where(np.isfinite(j_x), j_x, 0.0) * G))
    return sticks | ~np.isfinite(j_x), dep


def _first_integer(root, holds):
    """Smallest integer ``j >= 1`` at or next to ``ceil(root)`` where ``holds(j)``."""
    base = np.maximum(np.ceil(np.minimum(root, 1e15)), 1.0)
    out = np.full(base.shape, np.inf)
    for shift in (1.0, 0.0, -1.0):
        j = base + shift
        ok = (j >= 1) & (root < 1e15) & holds(j)
        out = np.where(ok, j, out)
    return out


def _recurrence(state: dict, solimp, out: dict, todo: np.ndarray) -> None:
    """The exact step-by-step recurrence on the elements ``todo`` (vectorized).

    The loop works on compacted arrays of the elements still running (gathered again
    only when some finish), so a step costs a few whole-array operations; the results
    are scattered as elements finish.
    """
    s = _take(state, todo)
    size = todo.size
    N = np.full(size, np.inf)
    Y_end, x_max, f_max = np.zeros(size), np.zeros(size), np.zeros(size)
    by_pos = np.zeros(size, bool)
    dep = np.zeros(size)
    sticks = np.zeros(size, bool)
    proof = _RestProof(s, solimp)
    # the running elements: their index into s, state, previous state and constants
    live = np.arange(size)
    x, y = s["X"].copy(), s["Y"].copy()
    x1, y1 = np.full(size, np.nan), np.full(size, np.nan)
    G, bdt, kdt2, rho, L = s["G"], s["bdt"], s["kdt2"], s["rho"], s["L"]
    heavy, weightless = G > 0, G == 0
    wide = impedance_at(np.asarray(solimp[2], float), solimp)  # d at and beyond the width
    tol_f, tol_y = 1e-9 * G, 1e-12 * (1 + G)
    coast = np.zeros(size, bool)
    xm, fm = np.zeros(size), np.zeros(size)
    for step in range(_MAX_STEPS):
        if live.size == 0:
            break
        d = _impedance(x * L, solimp, wide)
        dr = d * rho
        F = dr / (dr + 1.0 - d) * (G + bdt * y + d * kdt2 * x)  # effective_impedance
        gone = x <= 0
        stay = np.ones(live.size, bool)
        coasting = coast.any()
        # the end of the contact: gone or zero force (a state that does neither in
        # contact, or neither leaves nor meets the force back coasting, stays)
        ends = (gone | (F <= 0)) if step > 0 else np.zeros(live.size, bool)
        if coasting:
            end = ~coast & ends
            left = coast & gone
            back = coast & ~gone & (F > 0)
            stay &= ~left & ~back
            if left.any():
                dep[live[left]] = -y[left]
            if back.any():
                sticks[live[back]] = True
        else:
            end = ends
        if end.any():
            zero = end & ~gone
            # without gravity the coast cannot end in contact: it leaves (F only falls)
            free = zero & weightless
            i = live[end]
            N[i], Y_end[i], by_pos[i] = step, y[end], gone[end]
            dep[i] = np.where(gone[end] | free[end], -y[end], 0.0)
            coast |= zero
            stay &= ~(end & gone) & ~free
            coasting = True
        keep = (stay & ~coast) if coasting else stay
        np.maximum(xm, x, out=xm, where=keep)
        np.maximum(fm, F, out=fm, where=keep)
        accel = np.where(coast, 0.0, np.maximum(F, 0.0)) if coasting else np.maximum(F, 0.0)
        y_new = y + G - accel
        x_new = x + y_new
        # rest in floats: the state repeats (a fixed point or a 2-cycle) with the force
        # on, or leaves the float range (an unstable map): the contact never ends;
        # or rests within rounding: the force carries the weight (F = G) to 1e-9 and
        # the body moves less than 1e-12 of a free step (floats may cycle there).
        # Each needs x_new == x, x_new == x1, |y_new| <= tol_y or a non-finite x_new.
        maybe = (x_new == x) | (x_new == x1) | (np.abs(y_new) <= tol_y) | ~np.isfinite(x_new)
        if maybe.any():
            repeat = ((x_new == x) & (y_new == y)) | ((x_new == x1) & (y_new == y1))
            repeat |= heavy & (np.abs(F - G) <= tol_f) & (np.abs(y_new) <= tol_y)
            stuck = keep & (F > 0) & (repeat | ~np.isfinite(x_new))
            if stuck.any():
                sticks[live[stuck]] = True
                stay &= ~stuck
        x1, y1, x, y = x, y, x_new, y_new
        if step % _PROOF_EVERY == _PROOF_EVERY - 1:
            stuck = stay & ~coast
            stuck[stuck] = proof(x[stuck], y[stuck], live[stuck])
            if stuck.any():
                sticks[live[stuck]] = True
                stay &= ~stuck
        if not stay.all():
            # the elements that finish: their maxima out, the rest compacted
            done = ~stay
            x_max[live[done]], f_max[live[done]] = xm[done], fm[done]
            live, x, y, x1, y1, coast, xm, fm = (
                a[stay] for a in (live, x, y, x1, y1, coast, xm, fm)
            )
            G, bdt, kdt2, rho, L, heavy, weightless, tol_f, tol_y = (
                a[stay] for a in (G, bdt, kdt2, rho, L, heavy, weightless, tol_f, tol_y)
            )
    else:
        raise ValueError(
            f"the Euler recurrence did not settle within {_MAX_STEPS} steps (element "
            f"{int(todo[live[0]])}); use a flat solimp, whose contact is in closed form"
        )
    out["N"][todo] = np.where(sticks, np.inf, N)
    out["Y_end"][todo] = Y_end
    out["by_pos"][todo] = by_pos
    out["X_max"][todo] = x_max
    out["F_max"][todo] = f_max
    out["dep"][todo] = dep
    out["sticks"][todo] = sticks


def _impedance(depth: np.ndarray, solimp, wide: np.ndarray) -> np.ndarray:
    """:func:`impedance_at`, with the value ``wide`` it takes at and beyond the width
    (``depth / width`` clipped to exactly 1) set without evaluating the polynomials."""
    inner = ~(depth >= solimp[2])  # nan stays with impedance_at (nan), as there
    if inner.all():
        return impedance_at(depth, solimp)
    d = np.full(depth.shape, wide)
    if inner.any():
        d[inner] = impedance_at(depth[inner], solimp)
    return d


class _RestProof:
    """Proof that a body in contact beyond the impedance width never leaves.

    There ``d = d_max`` and the step is the flat affine map; if its closed form from the
    current state never ends the contact and never brings the penetration back below
    the width, the body sticks.
    """

    def __init__(self, s: dict, solimp):
        self.width = 0.0 if is_flat(solimp) else solimp[2]
        d = float(impedance_at(np.full((), np.inf), solimp)) if is_flat(solimp) else d_max(solimp)
        dp = effective_impedance(d, s["rho"])
        self.kappa = dp * d * s["kdt2"]
        self.beta = dp * s["bdt"]
        with np.errstate(divide="ignore", invalid="ignore"):
            self.x_star = (1.0 - dp) * s["G"] / self.kappa
        self.W = self.width / s["L"]
        self.G = s["G"]
        self.usable = (s["G"] > 0) & (self.x_star > self.W) & np.isfinite(self.x_star)

    def __call__(self, X, Y, i):
        ok = self.usable[i] & (self.W[i] < X)
        j = np.flatnonzero(ok)
        if j.size == 0:
            return ok
        k = i[j]
        w1 = X[j] - self.x_star[k]
        kap, bet = self.kappa[k], self.beta[k]
        wide = Sequence(kap, bet, 1.0, 0.0, w1, Y[j], self.x_star[k] - self.W[k])
        force = Sequence(kap, bet, kap, bet, w1, Y[j], self.G[k])
        n_w = first_hit(wide, lambda n, m: wide.take(m).at(n) <= 0)
        n_f = first_hit(force, lambda n, m: force.take(m).at(n) <= 0)
        ok[j] = (wide.kind > 0) & ~np.isfinite(n_w) & ~np.isfinite(n_f)
        return ok
