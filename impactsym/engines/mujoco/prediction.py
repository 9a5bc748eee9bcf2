r"""MuJoCo's first contact phase: restitution, contact time, penetration, peak force.

The contact obeys the loaded oscillator of :mod:`~impactsym.engines.mujoco.model`,

.. math::

    x'' + d'\,b\,x' + d'\,d\,\bar k\,x = (1 - d')\,g, \qquad
    f = m\,d'\,(g + b\,x' + d\,\bar k\,x),

and **contact ends** at whichever comes first: the force vanishes
(``g + b x' + d kbar x = 0``) or the penetration does (``x = 0``, the contact is no
longer detected); the engine's own state shows both (`docs/physics.md#simulation-engines`).

The continuous solution (closed form for a flat impedance, Runge-Kutta for a varying
one) is in :mod:`~impactsym.engines.mujoco.continuous`.

All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from impactsym.contact.release import release_margin
from impactsym.engines.mujoco.continuous import ContactPhase, flat_phase, varying_phase
from impactsym.engines.mujoco.discrete import check_integrator, phase_summary, step_contact
from impactsym.engines.mujoco.model import (
    DEFAULT_SOLIMP,
    MAX_IMPEDANCE,
    MIN_IMPEDANCE,
    TINY,
    Coefficients,
    check_mass,
    check_solimp,
    check_timestep,
    coefficients,
    effective_impedance,
    impedance_at,
    is_flat,
    oscillator,
    time_unit,
    weight_ratio,
)
from impactsym.engines.mujoco.rk4 import rk4_spectral_radius
from impactsym.engines.mujoco.stepmap import spectral_radius
from impactsym.numeric.roots import bracketed_illinois
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = ["Prediction", "predict", "stick_speed"]

_GAMMA_RANGE = (1e-9, 1e9)  # stick_speed searches gamma = g / (omega0 v0) here


@dataclass(frozen=True, eq=False)
class Prediction(ArrayRecord):
    """MuJoCo's first contact phase for a body arriving at ``speed`` (SI units).

    Attributes
    ----------
    restitution
        Normal separation speed over approach speed when contact ends (``0.0`` if it
        sticks).
    contact_time
        Seconds from first touch to the end of contact (``inf`` if it sticks).
    sticks
        True where the contact never ends.
    released_by_position
        True where the penetration vanishes while the force is still positive
        (under gravity, slow impacts); False where the force vanishes first.
    max_penetration
        Largest penetration, metres.
    peak_force
        Largest contact force, newtons (needs ``mass``).
    restitution_range, contact_time_range
        ``(min, max)`` over the touch phases with a ``timestep`` and ``phase=None``;
        ``(value, value)`` for a given phase and for the continuous prediction.
    departure_speed
        Speed (m/s) with which the body finally leaves (``0`` where it sticks; below
        ``restitution * speed`` where gravity slows it while it coasts out of the
        overlap after a force zero).
    timestep, integrator, phase
        The engine's timestep (``None``: the continuous prediction, the limit
        ``timestep -> 0``), integrator and touch phase (``None``: the phase mean).
    """

    restitution: float | np.ndarray
    contact_time: float | np.ndarray
    sticks: bool | np.ndarray
    released_by_position: bool | np.ndarray
    max_penetration: float | np.ndarray
    _peak_accel: Any
    mass: float | None
    restitution_range: Any = None
    contact_time_range: Any = None
    departure_speed: Any = None
    timestep: float | None = None
    integrator: str | None = None
    phase: Any = None

    def __repr__(self) -> str:
        body = ", ".join(f"{f.name}={getattr(self, f.name)!r}" for f in fields(self))
        label = "  # continuous: the limit timestep -> 0" if self.timestep is None else ""
        return f"Prediction({body}){label}"

    @property
    def peak_force(self) -> float | np.ndarray:
        """Largest contact force in newtons: ``mass`` times the peak constraint acceleration."""
        if self.mass is None:
            raise ValueError("peak_force needs the effective mass: call predict(..., mass=m)")
        return self.mass * self._peak_accel


def predict(
    *,
    solref: Any,
    solimp: Any = DEFAULT_SOLIMP,
    speed: Any,
    gravity: Any = 0.0,
    mass: float | None = None,
    timestep: float | None = None,
    inverse_weight: Any = None,
    integrator: str = "euler",
    phase: Any = None,
) -> Prediction:
    r"""Predict MuJoCo's restitution and contact time for a contact with ``solref``, ``solimp``.

    Solves the loaded oscillator (module docstring) to its first release: in closed form
    for a flat ``solimp`` (linear), by Runge-Kutta for a varying one (the impedance
    depends on the penetration). See `docs/physics.md#mujoco-prediction`.

    Parameters
    ----------
    solref
        ``(timeconst, dampratio)`` (both > 0, seconds and 1) or
        ``(-stiffness, -damping)`` (1/s^2 and 1/s, per unit mass as MuJoCo reads them).
        Entries may be arrays; they broadcast with ``speed`` and ``gravity``.
    solimp
        ``(d_min, d_max, width, midpoint, power)`` of the contact (one tuple).
    speed
        Normal approach speed at first touch, m/s (> 0).
    gravity
        Acceleration pressing along the normal, m/s^2 (>= 0).
    mass
        Effective mass of the contact, kg (``1 / (J M^-1 J^T)``); needed for
        ``peak_force`` and with ``inverse_weight``.
    timestep
        MuJoCo's timestep, seconds. ``None`` (default): the continuous prediction, the
        limit ``timestep -> 0`` (refsafe not applied). Given: the contact as the engine
        steps it, exact (refsafe applied; `docs/physics.md#touch-phase`), with a
        ``RuntimeWarning`` naming the stable timestep where the in-contact step map is
        unstable (spectral radius ``>= 1``).
    inverse_weight
        MuJoCo's ``efc_diagA`` for the contact (the two bodies' ``body_invweight0[:, 0]``
        summed), 1/kg. Default: ``1 / mass``, exact for one free or slide-jointed body.
    integrator
        ``"euler"``, ``"implicitfast"`` (the same map without joint damping) or ``"rk4"``
        (needs ``timestep``).
    phase
        Touch phase in ``[0, 1)`` (number or array, broadcasting; needs ``timestep``):
        results exact at that phase. ``None``: the mean over the phase, with
        ``restitution_range``/``contact_time_range`` over every phase; then ``sticks``
        is True where the body sticks at some phase (the mean contact time is ``inf``
        there), and ``released_by_position``, ``max_penetration``, ``peak_force`` and
        ``departure_speed`` are those at phase 0.5.

    Returns
    -------
    Prediction
        In seconds, metres and newtons. With a varying ``solimp`` a body is reported
        sticking as soon as its state provably never releases, not after a fixed horizon.

    Raises
    ------
    ValueError
        For bad input (named), and with a varying ``solimp`` when the integration would
        need more than 400 000 steps (a very overdamped ``solref`` whose static
        penetration lies within the impedance width), naming the ``solref``.

    Examples
    --------
    >>> p = predict(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001, 0.5, 2), speed=1.0)
    >>> round(p.restitution, 4), round(p.contact_time, 5)
    (0.2984, 0.02418)
    >>> predict(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001), speed=0.1, gravity=9.81).sticks
    True
    """
    if timestep is not None:
        timestep = check_timestep(timestep)
    simp, coeffs, rho, g, v0, scalar, m = _arguments(
        solref, solimp, speed, gravity, mass, timestep, inverse_weight
    )
    if timestep is not None:
        return _discrete(coeffs, simp, rho, g, v0, timestep, integrator, phase, scalar, m)
    if phase is not None:
        raise ValueError(f"phase = {phase!r} needs a timestep (the continuous limit has none)")
    check_integrator(integrator)
    if is_flat(simp):
        phase = flat_phase(coeffs, impedance_at(np.zeros(()), simp), rho, g, v0)
    else:
        phase = _varying_in_time_unit(coeffs, simp, rho, g, v0)
    _check_range(phase, solref, v0, g)
    sticks = np.isinf(phase.contact_time)
    values = (
        phase.restitution,
        phase.contact_time,
        sticks,
        phase.released_by_position,
        phase.max_penetration,
        phase.peak_accel,
    )
    if scalar:
        kinds = (float, float, bool, bool, float, float)
        values = tuple(kind(a) for kind, a in zip(kinds, values, strict=True))
    e, t = values[0], values[1]
    return Prediction(*values, m, (e, e), (t, t), e * v0 if not scalar else e * float(v0))


def design_prediction(
    *,
    solref: Any,
    solimp: tuple[float, ...],
    speed: Any,
    gravity: Any,
    mass: float | None,
    timestep: float,
    inverse_weight: Any,
    integrator: str,
    known: np.ndarray,
) -> Prediction:
    """:func:`predict` with ``phase=None`` at a ``timestep`` for a design whose phase
    means are partly known already (internal: ``solref_for``).

    ``known`` is ``(7, size)`` over the flattened broadcast elements: the fields of
    :class:`~impactsym.engines.mujoco.discrete.PhaseSummary` without phase 0, exact, as
    the design evaluated them at its ``(timeconst, dampratio)`` (``solref`` may be that
    pair in the stiffness form: equal to rounding; ``nan`` columns: not known).
    """
    simp, coeffs, rho, g, v0, scalar, m = _arguments(
        solref, solimp, speed, gravity, mass, timestep, inverse_weight
    )
    return _discrete(coeffs, simp, rho, g, v0, timestep, integrator, None, scalar, m, known)


def _arguments(solref, solimp, speed, gravity, mass, timestep, inverse_weight) -> tuple:
    """The checked and broadcast arguments of :func:`predict` (``timestep`` checked)."""
    simp = check_solimp(solimp)
    v0, s_scalar = real_array("speed", speed, lower=0.0, strict=True)
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    m = check_mass(mass)
    rho = weight_ratio(m, inverse_weight)
    coeffs = coefficients(solref, simp, timestep)
    scalar = s_scalar and g_scalar and coeffs.damping.ndim == 0
    rho = np.asarray(rho, float)
    shape = broadcast(solref=coeffs.damping, speed=v0, gravity=g, inverse_weight=rho)
    damp, stiff, rate, v0, g, rho = (
        np.broadcast_to(a, shape)
        for a in (coeffs.damping, coeffs.stiffness, coeffs.rate, v0, g, rho)
    )
    return simp, Coefficients(damp, stiff, rate), rho, g, v0, scalar, m


def _discrete(
    coeffs, simp, rho, g, v0, timestep, integrator, phase, scalar, m, known=None
) -> Prediction:
    """``predict`` at a timestep: exact at ``phase``, or the phase mean and range
    (``known``: as in :func:`design_prediction`)."""
    check_integrator(integrator)
    if integrator == "rk4":
        _warn_unstable_rk4(coeffs, simp, rho, timestep)
    else:
        _warn_unstable(coeffs, simp, rho, timestep)
    if phase is not None:
        p, p_scalar = real_array("phase", phase, lower=0.0)
        if np.any(p >= 1):
            raise ValueError(f"phase must lie in [0, 1), got {phase!r}")
        scalar = scalar and p_scalar
        at = step_contact(coeffs, simp, rho, g, v0, timestep, p, integrator=integrator)
        e, t = at.restitution, at.contact_time
        ranges = (e, e), (t, t)
    else:
        summary = phase_summary(
            coeffs, simp, rho, g, v0, timestep, integrator=integrator, known=known
        )
        at = step_contact(coeffs, simp, rho, g, v0, timestep, 0.5, integrator=integrator)
        e, t = summary.restitution, summary.contact_time
        ranges = (
            (summary.restitution_min, summary.restitution_max),
            (summary.contact_time_min, summary.contact_time_max),
        )
    sticks = np.isinf(t)
    values = [e, t, sticks, at.released_by_position, at.max_penetration, at.peak_accel]
    dep = at.departure_speed
    if scalar:
        kinds = (float, float, bool, bool, float, float)
        values = [kind(a) for kind, a in zip(kinds, values, strict=True)]
        ranges = tuple((float(a), float(b)) for a, b in ranges)
        dep = float(dep)
    return Prediction(*values, m, *ranges, dep, timestep, integrator, phase)


def _warn_unstable(coeffs: Coefficients, simp, rho, timestep: float) -> None:
    """Warn where the in-contact Euler map is unstable (spectral radius ``>= 1``).

    The map of :mod:`~impactsym.engines.mujoco.stepmap` is stable iff
    ``omega^2 dt^2 + 2 d' b dt < 4`` (Jury), i.e.
    ``dt < 4 / (d' b + sqrt(d'^2 b^2 + 4 omega^2))``; checked at both ends of the
    impedance (`docs/physics.md#touch-phase`).
    """
    if np.size(coeffs.damping) == 0:
        return
    worst, limit = 0.0, np.inf
    for k in (0, 1):
        d = float(np.clip(simp[k], MIN_IMPEDANCE, MAX_IMPEDANCE))
        if is_flat(simp):
            d = float(impedance_at(np.zeros(()), simp))
        dp = effective_impedance(d, rho)
        kappa = dp * d * coeffs.stiffness * timestep**2
        beta = dp * coeffs.damping * timestep
        worst = max(worst, float(np.max(spectral_radius(kappa=kappa, beta=beta))))
        db, w2 = dp * coeffs.damping, dp * d * coeffs.stiffness
        with np.errstate(all="ignore"):
            limit = min(limit, float(np.min(4.0 / (db + np.sqrt(db * db + 4.0 * w2)))))
    if worst >= 1.0:
        warnings.warn(
            f"timestep = {timestep:g} s makes MuJoCo's in-contact step unstable for this "
            f"contact (spectral radius {worst:.4g} >= 1): the engine's contact is not a "
            f"damped oscillation there; timestep < {limit:.3g} s would be stable",
            RuntimeWarning,
            stacklevel=3,
        )


def _warn_unstable_rk4(coeffs: Coefficients, simp, rho, timestep: float) -> None:
    """Warn where RK4's interior map is unstable (:func:`~.rk4.rk4_spectral_radius` >= 1).

    The stable timestep named is found by bisection on the timestep (the radius grows
    with it), with the same coefficients.
    """
    if np.size(coeffs.damping) == 0:
        return
    worst = float(np.max(rk4_spectral_radius(coeffs, simp, rho, timestep)))
    if worst < 1.0:
        return
    lo, hi = 0.0, timestep
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if float(np.max(rk4_spectral_radius(coeffs, simp, rho, mid))) < 1.0:
            lo = mid
        else:
            hi = mid
    warnings.warn(
        f"timestep = {timestep:g} s makes MuJoCo's RK4 step unstable for this contact "
        f"(spectral radius {worst:.4g} >= 1): the engine's contact is not a damped "
        f"oscillation there; timestep < {lo:.3g} s would be stable",
        RuntimeWarning,
        stacklevel=3,
    )


def _varying_in_time_unit(coeffs: Coefficients, simp, rho, g, v0) -> ContactPhase:
    """:func:`varying_phase` run in the time unit of :func:`~.model.time_unit` (scale-free)."""
    unit = time_unit(coeffs)
    with np.errstate(over="ignore", under="ignore"):
        v_u, g_u = v0 * unit, g * unit * unit
        # a gravity that underflows in these units is harmless where its load is negligible
        felt = (g > 0) & (g_u < TINY) & (g * unit / v0 > 1e-20)
    bad = ~np.isfinite(v_u) | (v_u < TINY) | ~np.isfinite(g_u) | felt
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        raise ValueError(
            f"speed = {float(v0.ravel()[i])!r} and gravity = {float(g.ravel()[i])!r} with "
            f"solref of natural time {float(unit.ravel()[i]):.3g} s (element {i}): the "
            f"contact's scales leave the float range; use a flat solimp, whose prediction "
            f"is scale-free"
        )
    phase = varying_phase(coeffs.in_time_unit(unit), simp, rho, g_u, v_u)
    with np.errstate(over="ignore", under="ignore"):
        return ContactPhase(
            phase.restitution,
            phase.contact_time * unit,
            phase.released_by_position,
            phase.max_penetration,
            phase.peak_accel / unit / unit,
        )


def _check_range(phase: ContactPhase, solref, speed, gravity) -> None:
    """Refuse a contact whose time, penetration or force is beyond the float range."""
    released = np.isfinite(phase.contact_time) | (phase.restitution == 0.0)
    finite = np.isfinite(phase.max_penetration) & np.isfinite(phase.peak_accel)
    bad = ~(released & finite)
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        raise ValueError(
            f"solref = {solref!r} with speed = {float(np.ravel(speed)[i])!r}, gravity = "
            f"{float(np.ravel(gravity)[i])!r} (element {i}): the contact time, largest "
            f"penetration or peak force is beyond the float range"
        )


def stick_speed(
    *,
    solref: Any,
    solimp: Any,
    gravity: float,
    mass: float | None = None,
    inverse_weight: Any = None,
    timestep: float | None = None,
) -> float | np.ndarray:
    r"""Approach speed (m/s) below which MuJoCo's body sticks under ``gravity`` (flat solimp).

    With ``gamma = g / (omega0 v0)`` the body sticks where
    :func:`impactsym.contact.release.release_margin` of
    ``(D, (1 - d') gamma, d' gamma)`` is positive; the boundary ``gamma*(D, d')`` is
    found by the Illinois method in ``log gamma`` (derivative-free: the margin switches
    between closed forms) and ``v* = g / (omega0 gamma*)``
    (`docs/physics.md#simulation-engines`).
    ``0.0`` without gravity, or where the body releases for every ``gamma`` up to
    ``1e9`` (e.g. no damping); ``inf`` where it sticks for every ``gamma`` down to
    ``1e-9`` (every speed).

    >>> round(stick_speed(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001), gravity=9.81), 5)
    0.11954
    """
    simp = check_solimp(solimp)
    if not is_flat(simp):
        raise ValueError(
            f"stick_speed needs a flat solimp (d_min == d_max), got {simp!r}; use predict "
            "over speeds for a varying impedance"
        )
    g_arr, g_scalar = real_array("gravity", gravity, lower=0.0)
    if not g_scalar:
        raise ValueError(f"gravity must be one number here, got {gravity!r}")
    g = float(g_arr)
    if timestep is not None:
        timestep = check_timestep(timestep)
    m = check_mass(mass)
    rho = np.asarray(weight_ratio(m, inverse_weight), float)
    coeffs = coefficients(solref, simp, timestep)
    scalar = coeffs.damping.ndim == 0
    shape = broadcast(solref=coeffs.damping, inverse_weight=rho)
    damp, stiff, rho = (
        np.array(np.broadcast_to(a, shape), dtype=float).ravel()
        for a in (coeffs.damping, coeffs.stiffness, rho)
    )
    if g == 0:
        return 0.0 if scalar else np.zeros(np.shape(damp))
    d = float(impedance_at(np.zeros(()), simp))
    dp = effective_impedance(d, rho)
    osc = oscillator(Coefficients(damp, stiff), d, rho, 0.0, 1.0)
    omega, D = osc.omega0, osc.damping_ratio
    return _stick_boundary(D, dp, omega, g, scalar)


def _stick_boundary(D, dp, omega, g, scalar):
    """``v* = g / (omega0 gamma*)`` with ``gamma*`` where the release margin changes sign."""

    def margin(gamma, i):
        return release_margin(D[i], (1.0 - dp[i]) * gamma, dp[i] * gamma)

    every = np.arange(D.size)
    lo, hi = np.full(D.size, _GAMMA_RANGE[0]), np.full(D.size, _GAMMA_RANGE[1])
    never = margin(hi, every) <= 0  # releases even at gamma = 1e9 (the slowest impacts)
    always = ~never & (margin(lo, every) > 0)  # sticks even at gamma = 1e-9 (the fastest)
    out = np.where(never, 0.0, np.inf)
    ok = np.flatnonzero(~never & ~always)
    if ok.size:
        gamma = bracketed_illinois(lambda x, i: margin(x, ok[i]), lo[ok], hi[ok], log=True)
        out[ok] = g / (omega[ok] * gamma)
    return float(out[0]) if scalar else out
