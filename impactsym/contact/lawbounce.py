r"""The bounce sequence until rest on a contact law (position, force and clipped conditions).

**What.** A body pressed towards the contact by a constant force hits it at speed
:math:`v_0`, leaves it, flies under the pressing force alone, hits again with its
departure speed, and so on until a contact no longer ends (``docs/physics.md``,
"Nonlinear contact laws", *Stick boundary and bounce sequence*). Used by
:func:`~impactsym.contact.bounce.bounce_sequence` with ``law=``.

**Which equations.** Everything is normalized on the first impact (:math:`T_0`,
:math:`L_0 = v_0 T_0` of :mod:`impactsym.contact.laws`). Under the position condition every
contact starts undeformed, so contact ``n`` at arrival speed :math:`u_n v_0` is a first
impact at that speed. The law's groups depend on the impact speed as powers,
:math:`T \propto v^{a_T}`, :math:`\delta \propto v^{a_\delta}`, :math:`f \propto v^{a_f}`
(:func:`speed_exponents`, derived from the law's normalization by
:math:`a_X = \partial \ln X / \partial \ln v_0`):

.. math::

    \delta_n = \delta\, u_n^{a_\delta}, \quad f_n = f\, u_n^{a_f}, \quad
    u_{n+1} = e(\delta_n, f_n)\, u_n, \quad
    \tau_{n+1}^\mathrm{start} = \tau_n^\mathrm{start} + u_n^{a_T}\, \tau_c(\delta_n, f_n)
        + \frac{2 u_{n+1}}{b},

with :math:`a_T = -(p-1)/(p+1)`, :math:`a_f = a_T - 1 = -2p/(p+1)` and :math:`a_\delta`
:math:`0` (linear, Tsuji), :math:`a_T` (hertz-linear), :math:`1` (Hunt–Crossley),
:math:`-a_T = 1/5` (viscoelastic); :math:`b` is the normalized pressing term of the first
impact (the body's acceleration in flight: :math:`b = f`, :math:`2Df` for ``"linear"``).
Since :math:`a_f < 0`, the pressing number grows as the arrival speed falls, so every
damped sequence with a pressing force ends sticking after finitely many contacts (the
linear recursion of :mod:`~impactsym.contact.bounce` is the case :math:`p = 1`).

**Why this numerics.** One exact impact per contact
(:func:`~impactsym.contact.lawnumbers.law_impact`), a loop over contacts only. The
conventions are those of the linear sequence: the departure speed is capped by the
arrival speed (energy), a release at zero speed counts as sticking, ``max_contacts``
bounds the loop, and a contact whose end the absolute time cannot resolve is refused
(:func:`~impactsym.contact.loop.check_resolution`).

**Force condition** (:func:`law_sequences`). A contact ends at a force zero with the
massless element still deflected, :math:`z_c > 0`. While the body flies
(:math:`z_b = z_c - u s + b s^2/2`) the element, free of load, keeps its force zero,
:math:`\varphi(z_e, z_e') = 0`, i.e. relaxes as :math:`z_e' = w_0(z_e)` (the analogue of
section 2's :math:`z_e' = -z_e/(2D)`); the next contact starts where the body meets it,
from :math:`(z_e, z_b')`, in the first impact's units throughout
(:func:`~impactsym.contact.lawcoast.recontact`; the integration of
:mod:`~impactsym.contact.lawkernel` from that state). Hunt–Crossley's force vanishes only
with the overlap under a pressing force, so its sequence is the position one.

**Clipped condition** (the engines' :math:`\max(0, F)` on the geometric overlap; any
law, the linear one included). The contact ends at zero overlap, and the clipped force is
a function of the overlap and its rate alone: nothing is left deflected and no state
carries over. So every contact starts undeformed at its arrival speed and is a first
impact there, clipped (:func:`~impactsym.contact.lawnumbers.law_impact` with
``condition="clipped"``): the position recursion above with the clipped single-contact
result. A contact whose force comes back inside the overlap and never lets go sticks.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from impactsym.contact.lawcoast import recontact
from impactsym.contact.lawkernel import integrate, law_functions
from impactsym.contact.lawnumbers import law_impact
from impactsym.contact.laws import contact_law, p, v0

#: A force-condition release this close to the fold (relative) does not leave the element.
TANGENT = 1e-13

#: The time-scale symbol of :attr:`impactsym.contact.laws.ContactLaw.damping_number`.
_T = sp.Symbol("T", positive=True)


@cache
def speed_exponents(law: str) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    r""":math:`(a_T, a_\delta, a_f)`: the powers of the impact speed in the law's time
    scale, damping number and pressing number (SymPy, in the exponent ``p``).

    >>> speed_exponents("hunt-crossley")
    (-(p - 1)/(p + 1), 1, -2*p/(p + 1))
    >>> speed_exponents("viscoelastic")
    (-1/5, 1/5, -6/5)
    """
    ContactLaw = contact_law(law)
    T = ContactLaw.time_scale
    out = []
    for expr in (T, ContactLaw.damping_number, ContactLaw.pressing_number):
        expr = sp.sympify(expr, strict=True).subs(_T, T)
        out.append(sp.factor(sp.simplify(v0 * sp.diff(sp.log(expr), v0))))
    return tuple(out)


@dataclass(frozen=True)
class LawSequence:
    """The contacts of one sequence (normalized on the first impact)."""

    start: np.ndarray
    duration: np.ndarray
    arrival: np.ndarray
    departure: np.ndarray
    n_contacts: int
    time_to_rest: float
    sticks: bool
    arrival_velocity: np.ndarray | None = None
    deflection: np.ndarray | None = None


@dataclass(frozen=True)
class LawSequences:
    """The sequences of many points: contacts, verdicts, and (``record``) the per-contact
    rows ``(point indices, start, duration, arrival velocity, departure speed,
    deflection)``, one tuple of arrays per contact number."""

    n_contacts: np.ndarray
    sticks: np.ndarray
    time_to_rest: np.ndarray
    rows: list | None = None

    def sequence(self, i: int) -> LawSequence:
        """The contacts of point ``i`` (needs ``record``)."""
        table = [[a[np.flatnonzero(r[0] == i)[0]] for a in r[1:]] for r in self.rows if i in r[0]]
        table = np.array(table, dtype=float).reshape(-1, 5)
        start, duration, arrival, departure, deflection = (table[:, j].copy() for j in range(5))
        return LawSequence(
            start=start,
            duration=duration,
            arrival=np.abs(arrival),
            departure=departure,
            n_contacts=int(self.n_contacts[i]),
            time_to_rest=float(self.time_to_rest[i]),
            sticks=bool(self.sticks[i]),
            arrival_velocity=arrival,
            deflection=deflection,
        )


def law_sequences(
    law: str,
    delta: np.ndarray,
    f: np.ndarray,
    q: np.ndarray,
    *,
    condition: str,
    max_contacts: int,
    record: bool = False,
    check=None,
) -> LawSequences:
    r"""The bounce sequences of many points at once (flat arrays of the first impact's
    damping number, pressing number and exponent in use), one contact after another for
    all points (points that rest drop out). ``check(start, duration, contact)`` is called
    for every contact number on the points still bouncing.

    Position and clipped conditions: the recursion of the module docstring on arrays,
    each contact a first impact under ``condition``. Force condition
    (not for ``"linear"``, whose section-2 sequence is :mod:`~impactsym.contact.loop`):
    everything in the first impact's units; contact ``n`` starts from the state
    :math:`(z_0, w_0)` where the body meets the relaxing element and ends at the force zero
    :math:`(z_c, -u)`; the element relaxes with zero force, :math:`z_e' = w_0(z_e)`, while
    the body flies, :math:`z_b = z_c - u s + b s^2/2`
    (:func:`~impactsym.contact.lawcoast.recontact`). A release with :math:`b \ge
    (1 - 10^{-13})\, w_0 w_0'(z_c)` is at the fold (the body does not separate from the
    element) and counts as sticking, as does a release at zero speed.
    """
    n = delta.size
    accel = 2.0 * delta * f if law == "linear" else f
    t, z0, w0 = np.zeros(n), np.zeros(n), np.ones(n)
    n_contacts = np.zeros(n, dtype=int)
    sticks = np.zeros(n, dtype=bool)
    time_to_rest = np.full(n, np.inf)
    rows: list | None = [] if record else None
    exponents, where = np.unique(q, return_inverse=True)  # a loop over distinct p only
    a_T, a_delta, a_f = (
        np.array([float(a.subs(p, x)) for x in exponents])[where] for a in speed_exponents(law)
    )
    fns = law_functions(law) if condition == "force" else None
    active = np.arange(n)
    for k in range(max_contacts):
        if active.size == 0:
            break
        n_contacts[active] = k + 1
        d, b, qq, u, ta = delta[active], accel[active], q[active], w0[active], t[active]
        if condition == "force":
            run = integrate(law, d, b, qq, condition="force", start=(z0[active], u))
            duration, speed, zc = run.tau_c.copy(), run.e.copy(), run.z_end
            with np.errstate(all="ignore"):
                margin = fns.release_slope(zc, 0.0 * d, d, qq)
            fold = (zc > 0) & ~(b < margin * (1.0 - TANGENT))
        else:
            with np.errstate(all="ignore"):
                d_n, f_n = d * u ** a_delta[active], f[active] * u ** a_f[active]
            tau, e = law_impact(law, d_n, f_n, qq, condition=condition)
            with np.errstate(over="ignore"):
                duration = tau * u ** a_T[active]
            speed, zc = np.minimum(e * u, u), np.zeros(active.size)
            fold = np.zeros(active.size, dtype=bool)
        if check is not None:
            check(ta, duration, k + 1)
        pressed = b > 0
        out = np.isfinite(duration) & ~(pressed & ((speed <= 0) | fold))
        duration[~out], speed[~out] = np.inf, 0.0
        sticks[active[~out]] = True
        time_to_rest[active[~out]] = ta[~out]
        if rows is not None:
            rows.append((active, ta, duration, u.copy(), speed, z0[active].copy()))
        back = out & pressed
        if condition == "force" and back.any():
            rc = recontact(fns, zc[back], -speed[back], d[back], b[back], qq[back])
            flight, z_next, w_next = rc.flight, rc.z, rc.w
        else:
            with np.errstate(all="ignore"):
                flight = 2.0 * speed[back] / b[back]
            z_next, w_next = np.zeros(flight.size), speed[back]
        with np.errstate(over="ignore", invalid="ignore"):
            t_next = ta[back] + duration[back] + flight
        ok = np.isfinite(t_next)
        idx = active[back][ok]
        t[idx], z0[idx], w0[idx] = t_next[ok], z_next[ok], w_next[ok]
        active = idx
    return LawSequences(n_contacts, sticks, time_to_rest, rows)


def law_sequence(
    law: str,
    delta: float,
    f: float,
    q: float,
    *,
    condition: str,
    max_contacts: int,
    check=None,
) -> LawSequence:
    """The bounce sequence of ``law`` with damping number ``delta``, pressing number ``f``
    and exponent in use ``q`` of the first impact, every contact starting undeformed:
    ``condition`` ``"position"`` or ``"clipped"`` (module docstring). ``check``, if
    given, is called as ``check(start, duration, contact)`` for every contact."""
    if condition not in ("position", "clipped"):
        raise ValueError(
            f"condition must be 'position' or 'clipped' here (the force condition's "
            f"contacts start from the relaxing element: law_sequences), got {condition!r}"
        )
    a_T, a_delta, a_f = (float(a.subs(p, q)) for a in speed_exponents(law))
    accel = 2.0 * delta * f if law == "linear" else f
    t, u = 0.0, 1.0
    rows: list[tuple[float, float, float, float]] = []
    sticks, time_to_rest = False, np.inf
    for k in range(max_contacts):
        with np.errstate(all="ignore"):
            d_n, f_n = delta * u**a_delta, f * u**a_f
        tau, e = law_impact(
            law, np.array([d_n]), np.array([f_n]), np.array([q]), condition=condition
        )
        with np.errstate(over="ignore"):
            duration = float(tau[0]) * u**a_T
        speed = min(float(e[0]) * u, u)
        if check is not None:
            check(np.array([t]), np.array([duration]), k + 1)
        if not np.isfinite(duration) or (f > 0 and speed <= 0):
            rows.append((t, np.inf, u, 0.0))
            sticks, time_to_rest = True, t
            break
        rows.append((t, duration, u, speed))
        if not accel > 0:
            break
        with np.errstate(over="ignore"):
            nxt = t + duration + 2.0 * speed / accel
        if not np.isfinite(nxt):
            break
        t, u = nxt, speed
    table = np.array(rows, dtype=float).reshape(-1, 4)
    return LawSequence(
        start=table[:, 0].copy(),
        duration=table[:, 1].copy(),
        arrival=table[:, 2].copy(),
        departure=table[:, 3].copy(),
        n_contacts=len(rows),
        time_to_rest=float(time_to_rest),
        sticks=sticks,
    )
