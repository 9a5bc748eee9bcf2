r"""How the frozen reduction of a multibody contact drifts while the contact lasts.

:func:`~impactsym.multibody.reduction.reduce_contact` freezes the mass matrix, the normal
and the forces at the impact state. During a long contact of rotating bodies the
configuration moves on, and the inverse effective mass ``A = 1/m~ = w^T M^-1 w``, the
pressing acceleration ``G = r^T F`` and the curvature ``kappa`` of the normal motion
change with it. To first order the configuration follows the reduced motion itself,

.. math::

    u(t) = u_t + P\,\dot z(t), \qquad q(t) = q_0 + p_t\,t + p\,z(t), \qquad
    u_t = u_0 - P v_0,\ p_t = A_\mathrm{kin} u_t,\ p = A_\mathrm{kin} P,

(``P`` the impulse projection: what the contact impulse changes; ``u_t`` the rest of the
motion, which does not change ``z``), so every quantity ``X(q, u)`` of the normal
dynamics is, to first order in the configuration change,

.. math::

    X(t) \approx X_0 + X_t\,t + X_z\,z + X_v\,(\dot z - v_0) + X_{vv}\,(\dot z - v_0)^2 .

:func:`derive_drift` derives these coefficients (SymPy, at the impact state);
:class:`ContactDrift` carries them (``ReducedContact.drift``); :func:`mass_drift`
estimates the relative change of ``1/m~`` over a contact of given duration and
:func:`warn_mass_drift` warns above 1 %. The engines correct their predictions with the
same coefficients (:mod:`impactsym.engines.mujoco.drift`). Derivation and checks:
`docs/physics.md#multibody-drift`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from impactsym.records import ArrayRecord
from impactsym.validation import real_array

__all__ = ["DRIFT_LIMIT", "ContactDrift", "derive_drift", "mass_drift", "warn_mass_drift"]

#: relative change of ``1/m~`` over the contact above which the frozen reduction warns
DRIFT_LIMIT = 0.01


@dataclass(frozen=True, eq=False)
class ContactDrift(ArrayRecord):
    r"""First-order drift coefficients of a reduced contact, SI units.

    Each of ``inv_mass``, ``press`` and ``curvature`` is the tuple
    ``(X_0, X_t, X_z, X_v, X_vv)`` of the expansion
    ``X(t) = X_0 + X_t t + X_z z + X_v (z' - v0) + X_vv (z' - v0)^2`` along the reduced
    motion (module docstring).

    Attributes
    ----------
    speed
        Normal approach speed ``v0``, m/s.
    inv_mass
        ``A = 1/m~ = w^T M^-1 w``, 1/kg (``A_v = A_vv = 0``: it depends on ``q`` only).
    press
        ``G = r^T F`` with ``r = M^-1 w``: the acceleration the system's own forces give
        along the normal, m/s^2 (positive pressing in).
    curvature
        ``kappa = (d z'/d q) q' + d z'/d t``: the part of the normal acceleration from the
        curvature of the motion, m/s^2 (positive pressing in).
    """

    speed: float
    inv_mass: tuple[float, ...]
    press: tuple[float, ...]
    curvature: tuple[float, ...]

    @property
    def inv_mass_rate(self) -> float:
        """``dA/dt`` at impact from the motion that does not change ``z``, 1/(kg s)."""
        return self.inv_mass[1]

    @property
    def inv_mass_slope(self) -> float:
        """``dA/dz`` along the contact motion ``p``, 1/(kg m)."""
        return self.inv_mass[2]


def derive_drift(
    *,
    M: sp.Matrix,
    F: sp.Matrix,
    w: sp.Matrix,
    kappa: sp.Expr,
    kinematics: sp.Matrix,
    Q: sp.Matrix,
    U: sp.Matrix,
    state: dict,
    r: sp.Matrix,
    P_u: sp.Matrix,
    P_q: sp.Matrix,
    v0: Any,
) -> ContactDrift | None:
    r"""The :class:`ContactDrift` of a reduction at the impact state (SymPy, exact).

    Called by :func:`~impactsym.multibody.reduction.reduce_contact` with its own
    quantities: the mass matrix ``M(Q)``, forces ``F(Q, U)``, normal ``w(Q)`` in speed
    space, curvature ``kappa(Q, U)``, ``q' = kinematics * u``, the impact ``state``,
    ``r = M0^-1 w0`` and the projections ``P_u``, ``P_q``. The gradients follow from
    ``dA/dq_i = 2 r^T w_{,i} - r^T M_{,i} r`` and
    ``dG/dq_i = r_{,i}^T F_0 + r^T F_{,i}``, ``r_{,i} = M0^-1 (w_{,i} - M_{,i} r)``
    (no symbolic inverse). Returns ``None`` when symbols remain (a symbolic reduction).
    """

    def at0(expr: Any) -> Any:
        return expr.xreplace(state)

    numbers = [at0(x) for x in (*M, *F, *w, kappa, *kinematics, *U)]
    if not all(getattr(x, "is_number", False) for x in numbers) or not sp.sympify(v0).is_number:
        return None
    # differentiate after substituting the other variables: far smaller expressions
    on_q = {k: v for k, v in state.items() if k not in set(Q)}
    on_u = {k: v for k, v in state.items() if k not in set(U)}
    M_q, w_q = M.xreplace(on_q), w.xreplace(on_q)
    F_q, kappa_q = F.xreplace(on_q), kappa.xreplace(on_q)
    F_u, kappa_u = F.xreplace(on_u), kappa.xreplace(on_u)
    M0, F0, w0 = at0(M), at0(F), at0(w)
    u_t = at0(U) - P_u * v0
    p_t = at0(kinematics) * u_t
    grad_a, grad_g = [], []
    for qi in Q:
        w_i, M_i = at0(w_q.diff(qi)), at0(M_q.diff(qi))
        r_i = M0.LUsolve(w_i - M_i * r)
        grad_a.append(2 * (r.T * w_i)[0] - (r.T * M_i * r)[0])
        grad_g.append((r_i.T * F0)[0] + (r.T * at0(F_q.diff(qi)))[0])
    grad_a, grad_g = sp.Matrix(grad_a), sp.Matrix(grad_g)
    g_u = (r.T * at0(F_u.jacobian(U))).T
    g_uu = sp.zeros(len(U), len(U))
    for rk, fk in zip(r, F_u, strict=True):
        g_uu += rk * at0(sp.hessian(fk, U))
    k_q = at0(sp.Matrix([kappa_q]).jacobian(Q)).T
    k_u = at0(sp.Matrix([kappa_u]).jacobian(U)).T
    k_uu = at0(sp.hessian(kappa_u, U))

    def terms(value, grad_q, grad_u, hess_u) -> tuple[float, ...]:
        out = (
            value,
            (grad_q.T * p_t)[0],
            (grad_q.T * P_q)[0],
            (grad_u.T * P_u)[0],
            (P_u.T * hess_u * P_u)[0] / 2,
        )
        return tuple(float(sp.re(sp.N(x))) for x in out)

    zero = sp.zeros(len(U), 1)
    return ContactDrift(
        speed=float(v0),
        inv_mass=terms((w0.T * r)[0], grad_a, zero, sp.zeros(len(U), len(U))),
        press=terms((r.T * F0)[0], grad_g, g_u, g_uu),
        curvature=terms(at0(kappa), k_q, k_u, k_uu),
    )


def drift_of(reduced: Any) -> ContactDrift:
    """The :class:`ContactDrift` of a numeric ``ReducedContact``, or a ``TypeError``/``ValueError``.

    >>> drift_of(object())
    Traceback (most recent call last):
    ...
    TypeError: reduced must be a numeric ReducedContact from reduce_contact, got object
    """
    drift = getattr(reduced, "drift", None)
    if getattr(reduced, "is_symbolic", True) or not hasattr(reduced, "drift"):
        raise TypeError(
            "reduced must be a numeric ReducedContact from reduce_contact, got "
            f"{type(reduced).__name__}"
        )
    if not isinstance(drift, ContactDrift):
        raise ValueError(
            "the reduction carries no drift coefficients: reduce_contact derives them only "
            "when the impact state and all parameters are numbers (substitute them in the "
            "at= dict, not afterwards with .subs)"
        )
    return drift


def mass_drift(reduced: Any, contact_time: Any) -> float | np.ndarray:
    r"""Estimated largest relative change of ``1/m~`` over a contact of ``contact_time`` s.

    Along the reduced motion ``A(t) = A_0 + A_t t + A_z z(t)`` (module docstring), with
    the penetration taken as the half sine ``z = v0 t_c/pi sin(pi t/t_c)`` of an elastic
    contact of the same duration:

    .. math::

        \Delta = \max_{0 \le s \le 1} \frac{|A_t\, t_c\, s + A_z\, v_0 t_c \sin(\pi s)/\pi|}
        {A_0},

    which is proportional to ``t_c`` (so ``t_c * 0.01 / Delta`` keeps it at 1 %). The
    engines' corrected predictions evaluate ``A`` along their own predicted motion
    instead. ``contact_time`` may be an array (seconds, > 0; ``inf`` gives ``inf``).

    >>> from types import SimpleNamespace
    >>> d = ContactDrift(speed=1.0, inv_mass=(2.0, 0.4, 0.0, 0.0, 0.0), press=(0.0,) * 5,
    ...                  curvature=(0.0,) * 5)
    >>> round(float(mass_drift(SimpleNamespace(drift=d, is_symbolic=False), 0.05)), 12)
    0.01
    """
    drift = drift_of(reduced)
    t_c, scalar = real_array("contact_time", contact_time, lower=0.0, strict=True, allow_inf=True)
    a0, a_t, a_z = drift.inv_mass[:3]
    s = np.linspace(0.0, 1.0, 513)
    rate = np.max(np.abs(a_t * s + a_z * drift.speed * np.sin(np.pi * s) / np.pi)) / abs(a0)
    with np.errstate(invalid="ignore"):
        out = np.where(rate == 0, 0.0, rate * t_c)  # no drift at all: 0 even for inf
    return float(out) if scalar else out


def warn_mass_drift(drift: Any, contact_time: Any, *, what: str, stacklevel: int = 3) -> None:
    """Warn (``RuntimeWarning``) where the relative drift ``drift`` of ``1/m~`` over a
    contact of ``contact_time`` exceeds :data:`DRIFT_LIMIT`, naming the drift and the
    contact time that keeps it at the limit (the drift grows in proportion to it).

    ``what`` ends the message (e.g. how to correct the prediction).
    """
    drift, t_c = np.broadcast_arrays(np.abs(np.asarray(drift, float)), np.asarray(contact_time))
    over = np.isfinite(drift) & np.isfinite(t_c) & (drift > DRIFT_LIMIT)
    if not over.any():
        return
    i = int(np.argmax(np.where(over, drift, -1.0)))
    worst, t = float(drift.flat[i]), float(t_c.flat[i])
    warnings.warn(
        f"the effective mass drifts during the contact: 1/m_eff changes by {100 * worst:.2g} % "
        f"over the {t * 1e3:.4g} ms contact (the reduction freezes it at impact); a contact "
        f"time below {t * DRIFT_LIMIT / worst * 1e3:.3g} ms keeps the drift below "
        f"{100 * DRIFT_LIMIT:g} %; {what}",
        RuntimeWarning,
        stacklevel=stacklevel,
    )
