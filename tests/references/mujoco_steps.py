"""MuJoCo's step applied to one contact, re-implemented in plain Python from MuJoCo's C source.

The independent reference of ``impactsym.engines.drivers.mujoco_steps`` (the engine) and of
the discrete models of ``impactsym.engines.mujoco`` (their derivation): scalar floats and
``math`` only, no impactsym import. The scene is the driver's: a sphere of radius 0.1 on a
vertical slide joint over a plane, one frictionless contact (``condim="1"``), Newton
solver, no joint damping. Read from google-deepmind/mujoco (``src/engine``):

* collision (``engine_collision_primitive.c``, ``mjraw_PlaneSphere``; ``engine_collision_
  driver.c``, ``mj_setContact``): ``dist = z - r``; the contact is generated for
  ``z <= r`` but excluded where ``dist >= includemargin`` (0 here), so it is a constraint
  only for ``dist < 0`` strictly: a state at distance exactly 0 has no contact;
* parameters (``engine_core_constraint.c``, ``getsolparam``): ``solimp[0,1,3]`` clamped to
  ``[1e-4, 0.9999]``, ``width >= 0``, ``power >= 1``; *refsafe* ``timeconst >= 2 dt`` for the
  positive form;
* impedance (``getimpedance``): flat where ``d0 == d1`` or ``width <= 1e-15``
  (``(d0 + d1) / 2``); else ``x = |dist| / width``, ``d0`` at ``x <= 0``, ``d1`` at
  ``x >= 1``, the two power-law halves around ``midpoint`` in between;
* ``mj_makeImpedance``: ``K = 1 / (d1^2 tc^2 dr^2)``, ``B = 2 / (d1 tc)`` (positive form) or
  ``K = -solref[0] / d1^2``, ``B = -solref[1] / d1``; ``R = max(1e-15, (1 - imp) diagA / imp)``
  with ``diagA = body_invweight0 = 1 / mass`` (``engine_setconst.c``: a body that only
  translates, ``body_simple == 2``, gets ``1 / mass``; a general body the mean of the
  translational diagonal of ``J M^-1 J'``);
* ``mj_referenceConstraint``: ``aref = -B vel - K imp dist``;
* the solver's answer for one frictionless row (``mj_constraintUpdate_impl``): with
  ``A = J M^-1 J' = 1 / mass`` and ``a0 = qacc_smooth = -g``, the force is
  ``f = (aref - a0) / (A + R)`` where positive, else 0, and ``qacc = a0 + A f``;
* ``engine_forward.c``: ``mj_Euler`` (no damping: ``qvel += h qacc``, then
  ``qpos += h qvel`` with the new velocity), ``mj_implicit`` for ``implicitfast``
  (``qH = M - h qDeriv = M`` without damping: the same update), ``mj_RungeKutta`` (classic
  RK4 tableau; stage ``i`` sets ``q = q0 + h sum_j A_ij v_j``, ``v = v0 + h sum_j A_ij a_j``
  and runs the whole forward pass there, collision included; the final update uses
  ``qvel += h sum_j B_j a_j``, ``qpos += h sum_j B_j v_j``).

The start state and the reading of the states follow the driver (and
``impactsym/engines/mujoco/stepping.py``). Newton stops when its scaled gradient is below
``tolerance = 1e-8``: where a warm start is already that close (a contact resting at its
static penetration) MuJoCo's acceleration differs from the exact one here by up to about
``1e-8`` m/s^2; during an impact the warm start is far and one Newton step is exact.
"""

from __future__ import annotations

import math

MIN_IMPEDANCE, MAX_IMPEDANCE, MIN_VALUE = 1e-4, 0.9999, 1e-15
RADIUS = 0.1


def contact_law(solref, solimp, timestep):
    """``(K, B, solimp)`` as ``getsolparam`` and ``mj_makeImpedance`` set them."""
    d0, d1, width, mid, power = (float(v) for v in solimp)
    d0 = min(MAX_IMPEDANCE, max(MIN_IMPEDANCE, d0))
    d1 = min(MAX_IMPEDANCE, max(MIN_IMPEDANCE, d1))
    mid = min(MAX_IMPEDANCE, max(MIN_IMPEDANCE, mid))
    width, power = max(0.0, width), max(1.0, power)
    a, b = float(solref[0]), float(solref[1])
    if (a > 0) != (b > 0):
        raise ValueError(f"mixed solref {solref!r}: MuJoCo would replace it by its default")
    if a > 0:
        a = max(a, 2.0 * timestep)  # refsafe
    k = 1.0 / max(MIN_VALUE, d1 * d1 * a * a * b * b) if a > 0 else -a / max(MIN_VALUE, d1 * d1)
    damp = 2.0 / max(MIN_VALUE, d1 * a) if b > 0 else -b / max(MIN_VALUE, d1)
    return k, damp, (d0, d1, width, mid, power)


def _power(a, b):
    if b == 1:
        return a
    if b == 2:
        return a * a
    return math.pow(a, b)


def impedance(dist, simp):
    """``getimpedance`` at constraint position ``dist`` (margin 0)."""
    d0, d1, width, mid, power = simp
    if d0 == d1 or width <= MIN_VALUE:
        return 0.5 * (d0 + d1)
    x = abs(dist / width)
    if x >= 1 or x <= 0:
        return d1 if x >= 1 else d0
    if power == 1:
        y = x
    elif x <= mid:
        y = (1 / _power(mid, power - 1)) * _power(x, power)
    else:
        y = 1 - (1 / _power(1 - mid, power - 1)) * _power(1 - x, power)
    return d0 + y * (d1 - d0)


def forward(z, v, law, gravity, mass):
    """One forward pass at height ``z``, velocity ``v``: ``(qacc, in contact, efc_force, dist)``."""
    k, damp, simp = law
    inverse = 1.0 / mass  # J M^-1 J' and diagApprox (body_invweight0) alike
    a0 = -(mass * gravity) * inverse  # qacc_smooth
    dist = z - RADIUS
    if not dist < 0.0:  # no constraint at distance >= 0 (mj_setContact's exclude)
        return a0, False, 0.0, dist
    imp = impedance(dist, simp)
    r = max(MIN_VALUE, (1 - imp) * inverse / imp)
    aref = -damp * v - k * imp * dist
    force = (aref - a0) / (inverse + r)
    if not force > 0.0:
        return a0, True, 0.0, dist
    return a0 + inverse * force, True, force, dist


def advance(z, v, a, law, gravity, mass, h, integrator):
    """The integrator's update from a state whose forward pass gave ``a``."""
    if integrator in ("euler", "implicitfast"):
        v = v + a * h
        return z + h * v, v
    if integrator != "rk4":
        raise ValueError(f"unknown integrator {integrator!r}")
    zs, vs, accs = [z], [v], [a]
    for i in range(3):  # stages 2..4: A = diag(1/2, 1/2, 1) below the diagonal
        c = 1.0 if i == 2 else 0.5
        zi = z + h * (c * vs[i])
        vi = v + h * (c * accs[i])
        zs.append(zi)
        vs.append(vi)
        accs.append(forward(zi, vi, law, gravity, mass)[0])
    weights = (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0)
    dz = dv = 0.0
    for w, vi, ai in zip(weights, vs, accs, strict=True):
        dz += vi * w
        dv += ai * w
    return z + h * dz, v + dv * h


def mujoco_steps(
    *,
    solref,
    solimp,
    speed,
    gravity=0.0,
    timestep=0.002,
    integrator="euler",
    phase=0.5,
    mass=1.0,
    max_steps=100_000,
):
    """What ``impactsym.engines.drivers.mujoco_steps`` reads from MuJoCo, computed here.

    The same keyword arguments and the same dict: ``restitution``, ``contact_time``,
    ``sticks``, ``released_by_position``, ``departure_speed``, ``steps``,
    ``max_penetration``, ``peak_force``.
    """
    law = contact_law(solref, solimp, timestep)
    t = (phase - (1.0 if integrator == "rk4" else 0.0)) * timestep
    z = RADIUS - (speed * t + 0.5 * gravity * t * t)
    v = -(speed + gravity * t)
    out = {"sticks": False, "max_penetration": 0.0, "peak_force": 0.0, "steps": 0}
    touched = force_ended = False
    for _ in range(max_steps):
        a, contact, force, dist = forward(z, v, law, gravity, mass)  # force: efc_force
        if contact:
            if force_ended and force > 0:
                out.update(sticks=True, restitution=0.0, contact_time=math.inf, departure_speed=0.0)
                return out
            if not force_ended:
                out["max_penetration"] = max(out["max_penetration"], -dist)
                out["peak_force"] = max(out["peak_force"], force)
            touched = True
        if touched and (not contact or force <= 0) and "restitution" not in out:
            out.update(restitution=v / speed, contact_time=t, released_by_position=not contact)
            force_ended = True
        if touched and not contact:
            out["departure_speed"] = v
            return out
        if touched and not force_ended:
            out["steps"] += 1
        z, v = advance(z, v, a, law, gravity, mass, timestep, integrator)
        t += timestep
    out.update(sticks=True, restitution=0.0, contact_time=math.inf, departure_speed=0.0)
    out.setdefault("released_by_position", False)
    return out
