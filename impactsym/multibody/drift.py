r"""How the frozen reduction of a multibody contact drifts while the contact lasts.

:func:`~impactsym.multibody.reduction.reduce_contact` freezes the mass matrix, the normal
and the forces at the impact state. During a long contact of rotating bodies the
configuration moves on, and the inverse effective mass ``A = 1/m~ = w^T M^-1 w``, the
pressing acceleration ``G = r^T F`` and the curvature ``kappa`` of the normal motion
change with it. To first order the motion follows the reduced motion itself,

.. math::

    u(t) = u_0 + P\,(\dot z - v_0) + a_\perp t, \qquad
    q(t) = q_0 + p_t\,t + p\,z(t) + \tfrac12 b_\perp t^2,

with ``P`` the impulse projection (what the contact impulse changes), ``u_t = u0 - P v0``
the motion that does not change ``z``, ``a_perp = M^-1 F_0 - P G_0`` what the other forces
add to it, ``p_t = A_kin u_t``, ``p = A_kin P``, ``b_perp = A_kin a_perp``. Every quantity
``X(q, u)`` of the normal dynamics then is, to first order in the configuration change and
exactly in the speeds where it is quadratic in them (``dv = z' - v0``),

.. math::

    X \approx X_0 + X_t\,t + X_z\,z + X_v\,dv + X_{vv}\,dv^2 + X_{tt}\,t^2 + X_{tv}\,t\,dv .

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

__all__ = [
    "DRIFT_LIMIT",
    "ContactDrift",
    "derive_drift",
    "drift_free_contact_time",
    "drift_of",
    "mass_drift",
    "warn_mass_drift",
]

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

    def value(self, name: str, t: Any, z: Any, rate: Any) -> Any:
        """The expansion of ``name`` (``"inv_mass"``, ``"press"``, ``"curvature"``) at time
        ``t``, penetration ``z`` and normal speed ``rate`` (NumPy arrays broadcast).

        >>> d = ContactDrift(speed=1.0, inv_mass=(2.0, 0.5, 0, 0, 0, 0, 0),
        ...                  press=(0.0,) * 7, curvature=(0.0,) * 7)
        >>> d.value("inv_mass", 0.1, 0.0, 1.0)
        2.05
        """
        c = getattr(self, name)
        dv = rate - self.speed
        return (
            c[0] + c[1] * t + c[2] * z + c[3] * dv + c[4] * dv * dv + c[5] * t * t + c[6] * t * dv
        )

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
    ``r = M0^-1 w0`` and the projections ``P_u``, ``P_q``. The speed terms are exact
    where ``X`` is quadratic in ``u``; the configuration terms are first order (no Hessian
    in ``q``, no mixed ``q``-``u`` terms). The gradients follow from
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
    a_perp = M0.LUsolve(F0) - P_u * (r.T * F0)[0]  # what the other forces add to u_t
    b_perp = at0(kinematics) * a_perp
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
            (grad_q.T * p_t)[0] + (grad_u.T * a_perp)[0],
            (grad_q.T * P_q)[0],
            (grad_u.T * P_u)[0],
            (P_u.T * hess_u * P_u)[0] / 2,
            (grad_q.T * b_perp)[0] / 2 + (a_perp.T * hess_u * a_perp)[0] / 2,
            (P_u.T * hess_u * a_perp)[0],
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


def _half_sine_drift(drift: ContactDrift, t_c: np.ndarray) -> np.ndarray:
    """:func:`mass_drift`'s estimate for contact times ``t_c`` (an array, seconds)."""
    a0 = drift.inv_mass[0]
    if not any(drift.inv_mass[i] for i in (1, 2, 5)):
        return np.zeros(np.shape(t_c))  # nothing drifts, however long the contact
    s = np.linspace(0.0, 1.0, 257).reshape((-1,) + (1,) * t_c.ndim)
    with np.errstate(invalid="ignore", over="ignore"):  # 0 * inf: an infinite contact
        tau = s * t_c
        z = drift.speed * t_c / np.pi * np.sin(np.pi * s)
        path = drift.value("inv_mass", tau, z, drift.speed) - a0  # dv = 0: A has no u-terms
        out = np.max(np.abs(path), axis=0) / abs(a0)
    return np.where(np.isnan(out), np.inf, out)  # an infinite contact


def mass_drift(reduced: Any, contact_time: Any) -> float | np.ndarray:
    r"""Estimated largest relative change of ``1/m~`` over a contact of ``contact_time`` s.

    Along the reduced motion ``A = A_0 + A_t t + A_z z(t) + A_tt t^2`` (module docstring),
    with the penetration taken as the half sine ``z = v0 t_c/pi sin(pi t/t_c)`` of an
    elastic contact of the same duration:

    .. math::

        \Delta = \max_{0 \le s \le 1} \frac{|A_t\, t_c\, s + A_z\, v_0 t_c \sin(\pi s)/\pi
        + A_{tt}\, t_c^2 s^2|}{A_0},

    proportional to ``t_c`` where ``A_tt`` is negligible. The engines' corrected
    predictions evaluate ``A`` along their own predicted motion instead.
    ``contact_time`` may be an array (seconds, > 0; ``inf`` gives ``inf`` unless nothing
    drifts).

    >>> from types import SimpleNamespace
    >>> d = ContactDrift(speed=1.0, inv_mass=(2.0, 0.4, 0, 0, 0, 0, 0), press=(0.0,) * 7,
    ...                  curvature=(0.0,) * 7)
    >>> round(float(mass_drift(SimpleNamespace(drift=d, is_symbolic=False), 0.05)), 12)
    0.01
    """
    drift = drift_of(reduced)
    t_c, scalar = real_array("contact_time", contact_time, lower=0.0, strict=True, allow_inf=True)
    out = _half_sine_drift(drift, t_c)
    return float(out) if scalar else out


def drift_free_contact_time(drift: ContactDrift, contact_time: Any, observed: Any) -> np.ndarray:
    """The contact time below which ``1/m~`` drifts by less than :data:`DRIFT_LIMIT`.

    ``observed`` is the drift found over ``contact_time`` (e.g. along an engine's predicted
    motion); shorter contacts follow :func:`mass_drift`'s estimate scaled to it: the first
    crossing of the limit on 200 contact times from ``1e-6 contact_time`` up, refined by 40
    bisections (vectorized); ``inf`` where the full contact stays below the limit (or
    never ends).
    """
    t_c = np.asarray(contact_time, float)
    seen = np.asarray(observed, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = seen / _half_sine_drift(drift, t_c)
    scale = np.where(np.isfinite(scale), scale, 1.0)

    def over(tau):
        return _half_sine_drift(drift, tau) * scale > DRIFT_LIMIT

    grid = np.geomspace(1e-6, 1.0, 200).reshape((-1,) + (1,) * t_c.ndim) * t_c
    grid = np.where(np.isfinite(grid), grid, np.nan)  # no limit for an infinite contact
    above = over(grid)
    first = np.argmax(above, axis=0)[None]
    hi = np.take_along_axis(grid, first, axis=0)[0]
    lo = np.take_along_axis(grid, np.maximum(first - 1, 0), axis=0)[0]
    for _ in range(40):
        mid = np.sqrt(lo * hi)
        up = over(mid)
        lo, hi = np.where(up, lo, mid), np.where(up, mid, hi)
    found = np.isfinite(t_c) & above.any(axis=0) & (seen > DRIFT_LIMIT)
    return np.where(found, lo, np.inf)


def warn_mass_drift(
    drift: Any, contact_time: Any, limit: Any, *, what: str, stacklevel: int = 3
) -> None:
    """Warn (``RuntimeWarning``) where the relative drift ``drift`` of ``1/m~`` over a
    contact of ``contact_time`` exceeds :data:`DRIFT_LIMIT`, naming the drift and the
    contact time ``limit`` that keeps it below (:func:`drift_free_contact_time`).

    ``what`` ends the message (e.g. how to correct the prediction).
    """
    drift, t_c, limit = np.broadcast_arrays(
        np.abs(np.asarray(drift, float)), np.asarray(contact_time), np.asarray(limit)
    )
    over = np.isfinite(drift) & np.isfinite(t_c) & (drift > DRIFT_LIMIT)
    if not over.any():
        return
    i = int(np.argmax(np.where(over, drift, -1.0)))
    worst, t, free = float(drift.flat[i]), float(t_c.flat[i]), float(limit.flat[i])
    warnings.warn(
        f"the effective mass drifts during the contact: 1/m_eff changes by {100 * worst:.2g} % "
        f"over the {t * 1e3:.4g} ms contact (the reduction freezes it at impact); a contact "
        f"time below {free * 1e3:.3g} ms keeps the drift below "
        f"{100 * DRIFT_LIMIT:g} %; {what}",
        RuntimeWarning,
        stacklevel=stacklevel,
    )
