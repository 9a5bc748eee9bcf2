r"""MuJoCo's contact of a reduced multibody system whose configuration moves on during contact.

:func:`~impactsym.engines.mujoco.design.from_reduced` hands MuJoCo's prediction the
reduction frozen at impact. In MuJoCo the normal motion of a multibody contact obeys
(penetration ``x``, ``A = J M^-1 J^T = 1/m~``, ``G = r^T F``, curvature ``kappa``;
`docs/physics.md#multibody-drift`)

.. math::

    \ddot x = -d'(\rho)\,(b\,\dot x + d\,\bar k\,x) + (1 - d'(\rho))\,G + \kappa, \qquad
    \rho = A / A_\mathrm{diag},

with the force vanishing where ``G + b x' + d kbar x = 0``: MuJoCo's unconstrained
acceleration ``a0 = J M^-1 F`` leaves out ``J' q'``, so the curvature acts in full and
does not enter the force. :func:`predict_reduced` lets ``A``, ``G`` and ``kappa`` move
with the configuration to first order along the reduced motion
(:class:`impactsym.multibody.drift.ContactDrift`), integrates this equation and the
frozen one with the same classical Runge-Kutta steps (vectorized over the designs) and
corrects the frozen prediction by the difference; it warns where ``1/m~`` drifts by more
than 1 % over the contact.

All quantities are SI: seconds, metres, m/s, m/s^2, kilograms.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from impactsym.engines.mujoco.design import from_reduced
from impactsym.engines.mujoco.model import (
    DEFAULT_SOLIMP,
    check_solimp,
    check_timestep,
    coefficients,
    effective_impedance,
    impedance_at,
)
from impactsym.engines.mujoco.prediction import Prediction, predict
from impactsym.multibody.drift import (
    correct_along_drift,
    drift_free_contact_time,
    drift_of,
    warn_mass_drift,
)
from impactsym.records import ArrayRecord
from impactsym.validation import real_array

__all__ = ["DriftPrediction", "predict_reduced"]


@dataclass(frozen=True, eq=False)
class DriftPrediction(ArrayRecord):
    """MuJoCo's first contact phase of a reduced multibody contact, drift corrected (SI).

    Attributes
    ----------
    restitution, contact_time
        Corrected to first order in the configuration change during contact (seconds).
    frozen
        The :class:`~impactsym.engines.mujoco.prediction.Prediction` of the reduction
        frozen at impact (``predict(**from_reduced(reduced), ...)``).
    mass_drift
        Largest relative change of ``1/m~`` along the predicted contact motion.
    drift_free_contact_time
        The contact time at which that change would be 1 %
        (:data:`impactsym.multibody.drift.DRIFT_LIMIT`), seconds
        (:func:`impactsym.multibody.drift.drift_free_contact_time`).
    """

    restitution: float | np.ndarray
    contact_time: float | np.ndarray
    frozen: Prediction
    mass_drift: float | np.ndarray
    drift_free_contact_time: float | np.ndarray


def _clear_roundoff(reduced: Any, drift: Any) -> Any:
    """``reduced`` with a load that is negative by round-off only (e.g. ``-2e-15`` N where
    every term of it vanishes exactly) set to zero, so that ``from_reduced`` accepts it."""
    v = drift.speed
    terms = (drift.press[0], drift.press[3] * v, drift.curvature[0], drift.curvature[4] * v * v)
    scale = 1e-12 * float(reduced.m_eff) * sum(abs(x) for x in terms)
    if -scale <= float(reduced.load) < 0:
        return replace(reduced, load=0.0)
    return reduced


def predict_reduced(
    reduced: Any,
    *,
    solref: Any,
    solimp: Any = DEFAULT_SOLIMP,
    inverse_weight: Any = None,
    timestep: float | None = None,
) -> DriftPrediction:
    r"""MuJoCo's restitution and contact time for a reduced multibody contact, drift corrected.

    The frozen prediction is
    ``predict(solref=solref, solimp=solimp, **from_reduced(reduced), inverse_weight=...)``.
    Along the reduced motion ``1/m~``, the system's pressing acceleration and the
    curvature of the normal motion change to first order in the configuration change
    (:class:`impactsym.multibody.drift.ContactDrift`); the normal equation of MuJoCo's
    contact with them (module docstring) and the frozen one are integrated with the same
    Runge-Kutta steps (400 over the frozen contact time), and the frozen prediction is
    corrected by their difference (exactly the frozen prediction where nothing drifts).

    Parameters
    ----------
    reduced
        A numeric :class:`impactsym.multibody.ReducedContact` (with its ``drift``).
    solref, solimp, timestep
        As in :func:`~impactsym.engines.mujoco.prediction.predict` (``solref`` entries
        may be arrays).
    inverse_weight
        MuJoCo's ``efc_diagA`` of the contact, 1/kg (default ``1/m~``). It stays fixed
        while ``A = 1/m~`` drifts, so the effective impedance ``d'`` drifts with it.

    Returns
    -------
    DriftPrediction

    Warns
    -----
    RuntimeWarning
        Where ``1/m~`` changes by more than 1 % along the predicted contact, with the
        contact time that keeps it below.

    Notes
    -----
    First order in the configuration change ``q - q0 = p_t t + p z + b_perp t^2 / 2``;
    the drift of the body's own forces into the normal enters through ``G``. A contact
    that sticks in the frozen prediction is left uncorrected (``inf``). See
    `docs/physics.md#multibody-drift`.
    """
    drift = drift_of(reduced)
    kw = from_reduced(_clear_roundoff(reduced, drift))
    simp = check_solimp(solimp)
    if timestep is not None:
        timestep = check_timestep(timestep)
    if inverse_weight is None:
        diag = drift.inv_mass[0]
    else:
        w, w_scalar = real_array("inverse_weight", inverse_weight, lower=0.0, strict=True)
        if not w_scalar:
            raise ValueError(f"inverse_weight must be one number (1/kg), got {inverse_weight!r}")
        diag = float(w)
    frozen = predict(solref=solref, solimp=simp, inverse_weight=diag, timestep=timestep, **kw)
    coeffs = coefficients(solref, simp, timestep)
    shape = np.shape(frozen.restitution)
    b, kbar, t_c0 = (
        np.broadcast_to(np.asarray(a, float), shape).ravel()
        for a in (coeffs.damping, coeffs.stiffness, frozen.contact_time)
    )
    v0, g_f = kw["speed"], kw["gravity"]
    a0 = drift.inv_mass[0]
    live = np.isfinite(t_c0)

    def frozen_rhs(t, x, v):
        d = impedance_at(x, simp)
        dp = effective_impedance(d, a0 / diag)
        return -dp * (b * v + d * kbar * x) + (1.0 - dp) * g_f

    def frozen_force(t, x, v):
        return g_f + b * v + impedance_at(x, simp) * kbar * x

    def drift_rhs(t, x, v):
        d = impedance_at(x, simp)
        dp = effective_impedance(d, drift.value("inv_mass", t, x, v) / diag)
        return (
            -dp * (b * v + d * kbar * x)
            + (1.0 - dp) * drift.value("press", t, x, v)
            + drift.value("curvature", t, x, v)
        )

    def drift_force(t, x, v):
        return drift.value("press", t, x, v) + b * v + impedance_at(x, simp) * kbar * x

    e, t_c = np.array(frozen.restitution, float).ravel(), t_c0.copy()  # copies
    mass = np.zeros(t_c0.shape)
    if live.any():
        sel = np.flatnonzero(live)
        b, kbar = b[sel], kbar[sel]
        ok, de, dt, rel = correct_along_drift(
            (frozen_rhs, frozen_force), (drift_rhs, drift_force), drift, v0, t_c0[sel]
        )
        e[sel] = np.where(ok, e[sel] + de, e[sel])
        t_c[sel] = np.where(ok, t_c0[sel] + dt, t_c0[sel])
        mass[sel] = rel  # along the corrected motion
    free = drift_free_contact_time(drift, t_c, mass)
    warn_mass_drift(
        mass,
        t_c,
        free,
        what="restitution and contact_time here are corrected to first order",
    )
    out = [a.reshape(shape) for a in (e, t_c, mass, free)]
    if not shape:
        out = [float(a) for a in out]
    return DriftPrediction(out[0], out[1], frozen, out[2], out[3])
