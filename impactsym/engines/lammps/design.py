r"""Designing a LAMMPS Hooke contact: ``kn``, ``eta_n`` for a wanted restitution.

:func:`hooke_for` inverts :func:`~impactsym.engines.lammps.hooke.predict` (continuous, or
at the user's timestep: the phase means of :mod:`~impactsym.engines.lammps.phases`);
:func:`coeff_restitution_achieved` and :func:`coeff_restitution_for` translate LAMMPS's
``damping coeff_restitution`` (the textbook relation) under ``limit_damping``
(`docs/physics.md#simulation-engines`). SI units.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from impactsym.engines.lammps.common import TINY, check_flag, release, unrepresentable
from impactsym.engines.lammps.hooke import HookeContact, predict
from impactsym.engines.lammps.phases import phase_statistics
from impactsym.engines.lammps.verlet import positive_limit, stability_limit
from impactsym.numeric.roots import bracketed_illinois
from impactsym.validation import broadcast, finish, real_array, renamed

__all__ = [
    "coeff_restitution_achieved",
    "coeff_restitution_for",
    "hooke_for",
    "textbook_damping_ratio",
]


def textbook_damping_ratio(restitution: Any) -> float | np.ndarray:
    r"""``D`` of the textbook relation ``e = exp(-pi D / sqrt(1 - D^2))`` (position condition).

    .. math:: D = -\ln e / \sqrt{\pi^2 + \ln^2 e}

    >>> round(textbook_damping_ratio(0.5), 6)
    0.215454
    """
    e, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e > 1):
        raise ValueError(f"restitution must be <= 1, got {float(e.max())!r}")
    log_e = np.log(e)
    return finish(-log_e / np.sqrt(np.pi**2 + log_e**2), scalar)


#: largest damping ratio searched for a force-condition restitution (e there ~ 1.5e-8;
#: the release loses its accuracy in double precision a little beyond)
_D_MAX = 4096.0


#: hooke_for refuses a design whose prediction misses a target by more than this
#: (relative; as solref_for: the release is accurate to ~1e-6 at the largest damping)
_DESIGN_RTOL = 1e-5


def _damping_ratio_for(e: np.ndarray, limit_damping: bool) -> np.ndarray:
    if not limit_damping:
        return np.asarray(textbook_damping_ratio(e))
    # force condition without load: e falls from 1 (D = 0) towards 0 as D grows
    zero = np.zeros_like(e)

    def residual(D, i):
        return e[i] - release(D, zero[i], True).restitution

    every = np.arange(e.size)
    hi = np.full(e.shape, 1.0)
    short = residual(hi, every) < 0
    while short.any():
        hi = np.where(short, 4.0 * hi, hi)
        if hi.max() > _D_MAX:
            i = np.flatnonzero(short)[0]
            e_min = float(release(np.array([_D_MAX]), np.zeros(1), True).restitution[0])
            raise ValueError(
                f"restitution = {float(e[i])!r} is too small: under limit_damping it needs "
                f"a damping ratio above {_D_MAX:g} (e = {e_min:.3g} there; "
                f"e ~ 1 / (4 D^2)), beyond what the release is resolved for"
            )
        short = residual(hi, every) < 0
    return bracketed_illinois(residual, np.full(e.shape, 1e-12), hi, rtol=1e-13)


def hooke_for(
    *,
    restitution: Any,
    mass: float,
    contact_time: Any = None,
    max_penetration: Any = None,
    speed: Any = None,
    limit_damping: bool = True,
    max_overlap: Any = None,
    timestep: float | None = None,
) -> HookeContact:
    r"""``kn`` and ``eta_n`` for a wanted restitution and contact time (or largest overlap).

    With ``limit_damping`` the damping ratio solves the force-condition restitution
    ``e_force(D) = e`` (paper section 2, ``f = 0``); without it the textbook
    ``D = -ln e / sqrt(pi^2 + ln^2 e)``. Then ``omega0 = tau_c(D) / t_c`` (or
    ``max_penetration(D) v / delta_max`` with the normalized contact time and largest
    penetration of the release), ``kn = m omega0^2`` and ``eta_n = 2 D m omega0``.
    No pressing load (particle-particle collisions).

    Parameters
    ----------
    restitution
        Wanted ``e`` in (0, 1).
    mass
        Effective mass, kg.
    contact_time
        Wanted duration of the contact force, seconds; or
    max_penetration
        Wanted largest overlap, metres (needs ``speed``).
    speed
        Approach speed, m/s (for ``max_penetration``, and for the returned prediction).
    limit_damping
        Whether the LAMMPS input uses ``limit_damping``.
    max_overlap
        Former name of ``max_penetration`` (give one of the two).
    timestep
        ``None``: the continuous design (exact as ``timestep -> 0``; at ``t_c / 50``
        LAMMPS misses it by up to 4 % in ``e`` and 3 % in ``t_c``,
        `docs/physics.md#lammps-at-its-timestep`). A number (seconds, with
        ``contact_time``): ``D`` and ``omega0`` solve "phase-mean restitution and
        contact time of LAMMPS's velocity-Verlet at this timestep hit the targets" by
        Newton's method from the continuous design (finite-difference Jacobian of
        :func:`~impactsym.engines.lammps.phases.phase_statistics`); the result carries
        the ranges over phases. A target the timestep cannot reach (the step map
        unstable or over-correcting near ``omega0 h ~ 1``) is refused, naming a timestep
        that reaches it.

    >>> c = hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)
    >>> round(c.restitution, 12), round(c.contact_time, 15), round(c.damping_ratio, 6)
    (0.5, 0.001, 0.255276)
    """
    max_penetration = renamed("max_penetration", max_penetration, "max_overlap", max_overlap, None)
    e, _ = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e.max())!r}")
    limit = check_flag("limit_damping", limit_damping)
    if (contact_time is None) == (max_penetration is None):
        raise ValueError("give exactly one of contact_time and max_penetration")
    if max_penetration is not None and speed is None:
        raise ValueError("max_penetration needs the approach speed (speed=...)")
    m_arr, m_scalar = real_array("mass", mass, lower=0.0, strict=True)
    if not m_scalar:
        raise ValueError(f"mass must be one number (the effective mass, kg), got {mass!r}")
    m = float(m_arr)
    v = 1.0 if speed is None else real_array("speed", speed, lower=0.0, strict=True)[0]
    scalar = all(np.ndim(a) == 0 for a in (restitution, contact_time, max_penetration, speed))
    target_name = "contact_time" if max_penetration is None else "max_penetration"
    target = real_array(
        target_name,
        contact_time if max_penetration is None else max_penetration,
        lower=0.0,
        strict=True,
    )[0]
    shape = broadcast(**{"restitution": e, target_name: target, "speed": v})
    e, target, v = (np.broadcast_to(a, shape) for a in (e, target, v))
    D = _damping_ratio_for(e.ravel(), limit).reshape(e.shape)
    rel = release(D, np.zeros_like(D), limit)
    with np.errstate(over="ignore", under="ignore"):
        if max_penetration is None:
            omega = rel.contact_time / target
        else:
            omega = rel.max_penetration * v / target
    if timestep is not None:
        if max_penetration is not None:
            raise ValueError("a timestep design needs contact_time (not max_penetration)")
        h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
        if not h_scalar:
            raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
        D, omega = _discrete_design(e, target, D, omega, float(h), limit)
    with np.errstate(over="ignore", under="ignore"):
        kn = m * omega**2
        eta = 2.0 * D * m * omega
    named = {"restitution": e, target_name: target, "mass": m}
    for what, value in (("the stiffness kn = m omega0^2", kn), ("the damping eta_n", eta)):
        # an underflow to a subnormal or zero has lost the design as surely as an overflow
        unrepresentable(what, np.where(np.abs(value) < TINY, np.inf, value), named)
    design = predict(
        kn=finish(kn, scalar),
        damping=finish(eta, scalar),
        mass=m,
        speed=finish(v, scalar),
        limit_damping=limit,
        timestep=None if timestep is None else float(timestep),
    )
    _check_design(design, e, target, target_name)
    return design


#: Newton iterations of the timestep design and its tolerance (relative, both targets)
_NEWTON_STEPS = 40
_NEWTON_RTOL = 1e-11


def _phase_means(D, tau, limit):
    """Phase-mean restitution and normalized contact time (``nan`` beyond the model)."""
    ok = (D > 0) & (tau > 0) & (tau < np.minimum(stability_limit(D), positive_limit(D)))
    e = np.full(D.shape, np.nan)
    T = np.full(D.shape, np.nan)
    if ok.any():
        st = phase_statistics(D[ok], np.zeros(int(ok.sum())), tau[ok], limit)
        e[ok], T[ok] = st["restitution"], st["contact_time"]
    return e, T


def _discrete_design(e, t_c, D, omega, h, limit):
    """``D``, ``omega0`` whose phase means at timestep ``h`` hit ``e`` and ``t_c``."""
    shape = e.shape
    e, t_c = e.ravel(), t_c.ravel()
    u = np.stack([np.log(D.ravel()), np.log(omega.ravel())])  # unknowns, in logs

    def residual(uu, idx):
        om = np.exp(uu[1])
        ek, Tk = _phase_means(np.exp(uu[0]), om * h, limit)
        return np.stack([ek / e[idx] - 1.0, Tk / (om * t_c[idx]) - 1.0])

    every = np.arange(e.size)
    r = residual(u, every)
    step = 1e-7
    for _ in range(_NEWTON_STEPS):
        todo = np.flatnonzero(
            np.isfinite(r).all(axis=0) & (np.max(np.abs(r), axis=0) > _NEWTON_RTOL)
        )
        if todo.size == 0:
            break
        ut, rt = u[:, todo], r[:, todo]
        J = np.empty((2, 2, todo.size))
        for j in range(2):
            du = ut.copy()
            du[j] += step
            J[:, j] = (residual(du, todo) - rt) / step
        det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
        delta = np.stack(
            [
                -(J[1, 1] * rt[0] - J[0, 1] * rt[1]) / det,
                -(-J[1, 0] * rt[0] + J[0, 0] * rt[1]) / det,
            ]
        )
        delta = np.where(np.isfinite(delta), delta, 0.0)
        scale = np.minimum(1.0, 0.5 / np.maximum(np.max(np.abs(delta), axis=0), 1e-300))
        u[:, todo] = ut + scale * delta
        r[:, todo] = residual(u[:, todo], todo)
    bad = ~(np.max(np.abs(r), axis=0) <= 1e-9)
    if bad.any():
        i = np.flatnonzero(bad)[0]
        tau0 = float(np.exp(u[1, i]) * h)
        finer = h
        for _ in range(20):
            finer /= 2.0
            try:
                _discrete_design(
                    e[i : i + 1],
                    t_c[i : i + 1],
                    D.ravel()[i : i + 1],
                    omega.ravel()[i : i + 1],
                    finer,
                    limit,
                )
                break
            except ValueError:
                continue
        raise ValueError(
            f"restitution = {float(e[i])!r} with contact_time = {float(t_c[i])!r} is not "
            f"reached at timestep = {h!r}: LAMMPS's velocity-Verlet (omega0 * timestep = "
            f"{tau0:.3g} near the design) cannot give that phase mean there (the step map "
            f"is unstable or over-corrects, or the design drifts out of the model); "
            f"timestep <= {finer:.3g} s reaches it"
        )
    return np.exp(u[0]).reshape(shape), np.exp(u[1]).reshape(shape)


def _check_design(design: HookeContact, e, target, target_name) -> None:
    """Refuse a design whose own prediction misses its targets (relative ``1e-5``).

    Under ``limit_damping`` at damping ratios above a few hundred the release's contact
    time is resolved only to ``1e-5 .. 1e-3`` in double precision (a cancellation in
    the force ``2 D z' + z``): such designs are refused rather than returned off target.
    """
    got = getattr(design, target_name)
    e_got = np.broadcast_to(design.restitution, e.shape)
    t_got = np.broadcast_to(got, e.shape)
    miss = np.abs(e_got - e) > _DESIGN_RTOL * e
    miss |= ~(np.abs(t_got / target - 1.0) <= _DESIGN_RTOL)
    if miss.any():
        i = np.flatnonzero(miss.ravel())[0]
        D = float(np.ravel(np.broadcast_to(design.damping_ratio, e.shape))[i])
        raise ValueError(
            f"restitution = {float(e.ravel()[i])!r} with {target_name} = "
            f"{float(target.ravel()[i])!r} (element {i}) is not reached within "
            f"{_DESIGN_RTOL:g}: the designed kn, eta_n (damping ratio {D:.6g}) give "
            f"restitution {float(e_got.ravel()[i]):.10g} and {target_name} "
            f"{float(t_got.ravel()[i]):.10g} in predict"
            + (
                "; at this damping the force-condition contact time is not resolved in "
                "double precision: a larger restitution or limit_damping=False reaches it"
                if D > 100
                else ""
            )
        )


def coeff_restitution_achieved(restitution: Any) -> float | np.ndarray:
    r"""What LAMMPS's ``damping coeff_restitution e`` really gives under ``limit_damping``.

    LAMMPS sets the textbook damping ``D = -ln e / sqrt(pi^2 + ln^2 e)`` (position
    condition) but ``limit_damping`` ends contact by the force condition, so the
    achieved restitution is ``e_force(D)`` (paper section 2, ``f = 0``), always larger.

    >>> round(coeff_restitution_achieved(0.5), 4)
    0.5503
    """
    D = textbook_damping_ratio(restitution)
    arr = np.asarray(D, dtype=float)
    out = release(arr, np.zeros_like(arr), True).restitution
    return finish(out, np.ndim(D) == 0)


def coeff_restitution_for(restitution: Any) -> float | np.ndarray:
    r"""The value to give ``damping coeff_restitution`` so that ``limit_damping`` yields ``e``.

    The force-condition damping ratio ``D`` for ``e`` is written in the textbook's
    terms, ``e_input = exp(-pi D / sqrt(1 - D^2))``. Needs ``D < 1`` (the textbook
    cannot express more damping), and the critically damped force condition rebounds
    with exactly ``e = exp(-2) = 0.1353...`` (``z = tau e^-tau``, the force
    ``(2 - tau) e^-tau`` vanishes at ``tau = 2``): every target ``e <= exp(-2)`` is out
    of reach of ``coeff_restitution`` under ``limit_damping`` (LAMMPS itself gives
    0.1374 for ``e_input = 1e-9``), and just above it ``e_input`` falls towards zero
    (``1.3e-16`` for 0.136); a target whose ``e_input`` underflows is refused too.
    Use ``damping velocity`` with :func:`hooke_for` for those.

    >>> round(coeff_restitution_for(0.5), 4), round(coeff_restitution_achieved(0.4363), 4)
    (0.4363, 0.5)
    """
    e, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e.max())!r}")
    D = _damping_ratio_for(e.ravel(), True).reshape(e.shape)
    with np.errstate(divide="ignore", invalid="ignore", under="ignore"):
        out = np.exp(-np.pi * D / np.sqrt(1.0 - D**2))
    bad = (D >= 1) | ~(out >= TINY)
    if np.any(bad):
        raise ValueError(
            f"restitution = {float(e[bad].flat[0])!r} is out of reach: under limit_damping "
            f"'damping coeff_restitution' cannot express targets e <= exp(-2) = "
            f"{math.exp(-2):.6g} (the critically damped force condition; just above it "
            f"the input underflows to 0); use 'damping velocity' with eta_n from "
            f"hooke_for(...)"
        )
    return finish(out, scalar)
