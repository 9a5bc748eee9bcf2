r"""Design MuJoCo's ``solref`` for a wanted restitution (and contact time); the multibody bridge.

:func:`solref_for` inverts :func:`~impactsym.engines.mujoco.prediction.predict`: for a
flat ``solimp`` by :mod:`~impactsym.engines.mujoco.flat_design` (closed form without
gravity; secant or Broyden steps from it under gravity, the bracketed Illinois method
where they do not settle); for a varying ``solimp`` Newton on the Runge-Kutta
prediction (smooth, expensive, no bracket in two unknowns), started from the flat
design at ``d_max`` or, for many targets of one contact, from a table of their designs
(:mod:`~impactsym.engines.mujoco.varying_design`). Every design is checked by
``predict`` itself (`docs/physics.md#simulation-engines`).

All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.mujoco.discrete import check_integrator
from impactsym.engines.mujoco.discrete_design import DiscreteTarget, design_discrete
from impactsym.engines.mujoco.flat_design import design_flat_both, design_flat_dampratio
from impactsym.engines.mujoco.model import (
    DEFAULT_SOLIMP,
    DEFAULT_TIMECONST,
    check_mass,
    check_solimp,
    check_timestep,
    coefficients,
    is_flat,
    weight_ratio,
)
from impactsym.engines.mujoco.prediction import Prediction, design_prediction, predict
from impactsym.engines.mujoco.varying_design import design_varying
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, real_array

__all__ = ["Design", "from_reduced", "solref_for"]

#: solref_for refuses a design whose prediction misses a target by more than this
#: (absolute in the restitution, relative in the contact time)
_DESIGN_TOL = 1e-5


@dataclass(frozen=True, eq=False)
class Design(ArrayRecord):
    """MuJoCo contact parameters for a wanted restitution (and contact time), SI units.

    Attributes
    ----------
    solref
        The pair to write in MJCF: ``(timeconst, dampratio)`` or
        ``(-stiffness, -damping)`` (``form="stiffness"``); floats or arrays.
    solimp
        The ``solimp`` the design assumes (write it too).
    restitution, contact_time
        Predicted by :func:`~impactsym.engines.mujoco.prediction.predict` for this design
        (contact time in seconds); with a ``timestep``, the means over touch phases.
    restitution_range, contact_time_range
        ``(min, max)`` over touch phases (with a ``timestep`` only).
    prediction
        The full :class:`~impactsym.engines.mujoco.prediction.Prediction`.
    timestep, integrator
        The timestep (seconds) and integrator designed for; ``None``: the continuous
        design (the limit ``timestep -> 0``).
    """

    solref: tuple[Any, Any]
    solimp: tuple[float, ...]
    prediction: Prediction
    timestep: float | None = None
    integrator: str | None = None

    @property
    def restitution_range(self) -> tuple[Any, Any]:
        """``(min, max)`` of the restitution over touch phases (needs a ``timestep``)."""
        return self._range("restitution_range")

    @property
    def contact_time_range(self) -> tuple[Any, Any]:
        """``(min, max)`` of the contact time over touch phases, seconds (needs a ``timestep``)."""
        return self._range("contact_time_range")

    def _range(self, name: str) -> tuple[Any, Any]:
        if self.timestep is None:
            raise ValueError(f"{name} needs a design at a timestep (solref_for(..., timestep=h))")
        return getattr(self.prediction, name)

    @property
    def restitution(self) -> float | np.ndarray:
        """Predicted restitution of the design."""
        return self.prediction.restitution

    @property
    def contact_time(self) -> float | np.ndarray:
        """Predicted contact time of the design, seconds."""
        return self.prediction.contact_time

    def mjcf(self) -> str:
        """The MJCF attributes, e.g. ``solref="0.02 0.29" solimp="0.9 0.95 0.001 0.5 2"``."""
        if np.ndim(self.solref[0]):
            raise ValueError("mjcf() needs a scalar design")
        ref = " ".join(f"{float(v):.10g}" for v in self.solref)
        imp = " ".join(f"{v:g}" for v in self.solimp)
        return f'solref="{ref}" solimp="{imp}"'


def solref_for(
    *,
    restitution: Any,
    speed: Any,
    gravity: Any = 0.0,
    contact_time: Any = None,
    solimp: Any = DEFAULT_SOLIMP,
    mass: float | None = None,
    timestep: float | None = None,
    inverse_weight: Any = None,
    form: str = "timeconst",
    integrator: str = "euler",
) -> Design:
    r"""``solref`` for which MuJoCo gives ``restitution`` (and ``contact_time``).

    Without ``contact_time`` the timeconst stays MuJoCo's default 0.02 s (or
    ``2 timestep`` if that is longer, as MuJoCo enforces) and the dampratio is designed;
    with it both are designed. ``timestep=None`` designs the continuous contact (the
    limit ``timestep -> 0``); with a ``timestep`` the **phase mean** of the
    restitution (and contact time) at that timestep and ``integrator`` hits the target
    (:mod:`~impactsym.engines.mujoco.discrete_design`), and the design carries the
    range over touch phases. The result is checked by
    :func:`~impactsym.engines.mujoco.prediction.predict`, whose model it inverts (flat
    impedance: :mod:`~impactsym.engines.mujoco.flat_design`; for a varying impedance
    :mod:`~impactsym.engines.mujoco.varying_design`;
    `docs/physics.md#simulation-engines`).

    Parameters
    ----------
    restitution
        Wanted coefficient of restitution, ``0 < e < 1`` (array allowed).
    speed, gravity, mass, timestep, inverse_weight, solimp
        As in :func:`~impactsym.engines.mujoco.prediction.predict` (m/s, m/s^2, kg, s, 1/kg).
    contact_time
        Wanted contact time, seconds (array allowed).
    form
        ``"timeconst"``: ``solref = (timeconst, dampratio)``; ``"stiffness"``:
        ``solref = (-stiffness, -damping)`` with the same contact dynamics.
    integrator
        ``"euler"``, ``"implicitfast"`` or ``"rk4"`` (MuJoCo's integrator; with a
        ``timestep`` only).

    Returns
    -------
    Design

    Raises
    ------
    ValueError
        When no ``solref`` reaches the target (e.g. the body sticks at that speed under
        gravity), saying what would reach it; with a ``timestep``, when the target
        cannot be reached there (refsafe floor ``timeconst >= 2 timestep``, the
        stability limit of the step map, sticking at some touch phase), saying why and
        which timestep reaches it; and when ``predict`` of the
        design misses a target by more than ``1e-5`` (absolute in the restitution,
        relative in the contact time).

    Examples
    --------
    >>> des = solref_for(restitution=0.5, speed=1.0, solimp=(0.9, 0.9, 0.001))
    >>> des.mjcf()
    'solref="0.02 0.2552756376" solimp="0.9 0.9 0.001 0.5 2"'
    >>> round(des.restitution, 10)
    0.5
    """
    if form not in ("timeconst", "stiffness"):
        raise ValueError(f"form must be 'timeconst' or 'stiffness', got {form!r}")
    simp = check_solimp(solimp)
    e_t, e_scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e_t >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e_t.max())!r}")
    v0, s_scalar = real_array("speed", speed, lower=0.0, strict=True)
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    scalar = e_scalar and s_scalar and g_scalar
    t_c = None
    if contact_time is not None:
        t_c, t_scalar = real_array("contact_time", contact_time, lower=0.0, strict=True)
        scalar = scalar and t_scalar
    if timestep is not None:
        timestep = check_timestep(timestep)
        integrator = check_integrator(integrator)
    m = check_mass(mass)
    rho = weight_ratio(m, inverse_weight)
    arrays = [e_t, v0, g, np.asarray(rho, float)] + ([t_c] if t_c is not None else [])
    names = ["restitution", "speed", "gravity", "inverse_weight", "contact_time"]
    shape = broadcast(**dict(zip(names, arrays, strict=False)))
    flat = [np.broadcast_to(a, shape).ravel() for a in arrays]
    e_f, v_f, g_f, rho_f = flat[:4]
    t_f = flat[4] if t_c is not None else None
    if timestep is not None:
        w_f = None
        if inverse_weight is not None:
            w_f = np.broadcast_to(np.asarray(inverse_weight, float), shape).ravel()
        start = None if t_f is None else _continuous(e_f, v_f, g_f, t_f, simp, rho_f)
        target = DiscreteTarget(
            e_f, v_f, g_f, t_f, simp, m, w_f, rho_f, timestep, integrator, start
        )
        tc_d = max(DEFAULT_TIMECONST, 2.0 * timestep)  # the restitution design's
        target.guess = lambda i: design_flat_dampratio(
            e_f[i], v_f[i], g_f[i], np.full(i.size, tc_d), _flat(simp), rho_f[i]
        )
        target.continuous = lambda i: _continuous(
            e_f[i], v_f[i], g_f[i], None if t_f is None else t_f[i], simp, rho_f[i]
        )
        tc, dr = design_discrete(target)
    else:
        tc, dr = _continuous(e_f, v_f, g_f, t_f, simp, rho_f)
    tc, dr = tc.reshape(shape), dr.reshape(shape)
    if form == "timeconst":
        solref = (tc, dr)
    else:
        solref = coefficients((tc, dr), simp, None).solref(simp, form="stiffness")
    if scalar:
        solref = (float(solref[0]), float(solref[1]))
    args = {
        "solref": solref,
        "solimp": simp,
        "speed": speed if t_c is None or scalar else np.broadcast_to(v0, shape),
        "gravity": gravity if scalar else np.broadcast_to(g, shape),
        "mass": m,
        "timestep": timestep,
        "inverse_weight": inverse_weight,
    }
    if timestep is None:  # the continuous check
        pred = predict(**args)
    else:  # the discrete phase mean, where the design has it at hand not evaluated again
        known = target.known_at(tc.ravel(), dr.ravel())
        pred = design_prediction(**args, integrator=integrator, known=known)
    _check_design(pred, e_f, t_f, shape)
    return Design(solref, simp, pred, timestep, None if timestep is None else integrator)


def _continuous(e_f, v_f, g_f, t_f, simp, rho_f):
    """The continuous design ``(timeconst, dampratio)``, flat arrays (module docstring)."""
    if is_flat(simp):
        return _flat_design(e_f, v_f, g_f, t_f, simp, rho_f)
    flat_imp = _flat(simp)  # the flat design at d_max starts the varying one

    def flat_start(e, v, g, t, rho):
        return _flat_design(e, v, g, t, flat_imp, rho)

    return design_varying(e_f, v_f, g_f, t_f, DEFAULT_TIMECONST, simp, rho_f, flat_start)


def _flat_design(e, v, g, t_c, simp, rho):
    """The flat-impedance design: the dampratio at the default timeconst, or both."""
    if t_c is None:
        tc = np.full(e.shape, DEFAULT_TIMECONST)
        return tc, design_flat_dampratio(e, v, g, tc, simp, rho)
    return design_flat_both(e, v, g, t_c, simp, rho)


def _flat(simp: tuple[float, ...]) -> tuple[float, ...]:
    """The flat ``solimp`` at ``d_max`` (itself if flat): the start of a varying design."""
    return simp if is_flat(simp) else (simp[1], simp[1], 0.0, simp[3], simp[4])


def _check_design(pred: Prediction, e_t, t_c, shape) -> None:
    """Refuse a design whose prediction (with refsafe) misses the targets.

    Tolerances: ``_DESIGN_TOL`` absolute in the restitution, relative in the contact
    time (the designs converge to about ``1e-6``).
    """
    e = np.broadcast_to(pred.restitution, shape).ravel()
    miss = np.abs(e - e_t) > _DESIGN_TOL
    if t_c is not None:
        t = np.broadcast_to(pred.contact_time, shape).ravel()
        with np.errstate(invalid="ignore"):
            miss |= ~(np.abs(t / t_c - 1.0) <= _DESIGN_TOL)
    if miss.any():
        i = np.flatnonzero(miss)[0]
        wanted = f"restitution = {float(e_t[i])!r}" + (
            "" if t_c is None else f", contact_time = {float(t_c[i])!r} s"
        )
        got = f"restitution {float(e[i]):.6g}" + (
            "" if t_c is None else f", contact time {float(t[i]):.6g} s"
        )
        raise ValueError(
            f"{wanted} (element {i}) is not reached within {_DESIGN_TOL:g}: the designed "
            f"solref gives {got} in predict"
        )


def from_reduced(reduced: Any, *, contact_time: Any = None) -> dict[str, float]:
    """Keyword arguments ``mass``, ``speed``, ``gravity`` for a reduced multibody contact.

    ``mass`` is the effective mass ``m~``, ``speed`` the approach speed ``v0`` and
    ``gravity = load / m~`` the pressing acceleration of a
    :class:`impactsym.multibody.ReducedContact`. Use as
    ``solref_for(restitution=0.5, **from_reduced(r), inverse_weight=w)``. MuJoCo's
    contact has no further stiffness or damping, so ``delta_c`` and ``delta_d`` of the
    reduction (the system's own linearized forces) are not part of the engine's contact
    model; they are small during a short impact and are ignored here.

    With ``contact_time`` (seconds, e.g. the intended one) it estimates how much ``1/m~``
    changes over such a contact as the configuration moves on
    (:func:`impactsym.multibody.drift.mass_drift`) and warns (``RuntimeWarning``) above
    1 %, naming the contact time that keeps it below;
    :func:`impactsym.engines.mujoco.drift.predict_reduced` corrects the prediction.

    >>> from types import SimpleNamespace
    >>> from_reduced(SimpleNamespace(m_eff=2.0, v0=1.5, load=9.81, is_symbolic=False))
    {'mass': 2.0, 'speed': 1.5, 'gravity': 4.905}
    """
    if getattr(reduced, "is_symbolic", True):
        raise TypeError("reduced must be a numeric ReducedContact (substitute symbols first)")
    m = float(reduced.m_eff)
    v = float(reduced.v0)
    load = float(reduced.load)
    if not (m > 0 and v > 0 and load >= 0 and math.isfinite(m + v + load)):
        raise ValueError(f"reduced needs m_eff > 0, v0 > 0, load >= 0, got {m}, {v}, {load}")
    if contact_time is not None:
        from impactsym.multibody.drift import (
            drift_free_contact_time,
            drift_of,
            mass_drift,
            warn_mass_drift,
        )

        drift = mass_drift(reduced, contact_time)
        warn_mass_drift(
            drift,
            contact_time,
            drift_free_contact_time(drift_of(reduced), contact_time, drift),
            what="impactsym.engines.mujoco.drift.predict_reduced corrects the prediction",
        )
    return {"mass": m, "speed": v, "gravity": load / m}
