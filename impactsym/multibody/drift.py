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
estimates the relative change of ``1/m~`` over a contact of given duration,
:func:`drift_free_contact_time` the contact time that keeps it at 1 % and
:func:`warn_mass_drift` warns above. :func:`corrected_contact` corrects the section-2
penalty contact of the reduction to first order (:func:`integrate_release` integrates the
frozen and the drifting normal equation alike); MuJoCo's contact is corrected with the
same coefficients in :mod:`impactsym.engines.mujoco.drift`. Derivation and checks:
`docs/physics.md#multibody-drift`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from impactsym.records import ArrayRecord
from impactsym.validation import check_condition, real_array

__all__ = [
    "DRIFT_LIMIT",
    "ContactDrift",
    "CorrectedContact",
    "corrected_contact",
    "derive_drift",
    "drift_free_contact_time",
    "drift_of",
    "integrate_release",
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
        if name not in ("inv_mass", "press", "curvature"):
            raise ValueError(f"name must be 'inv_mass', 'press' or 'curvature', got {name!r}")
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

    Bound by :func:`~impactsym.multibody.reduction.reduce_contact` to its own quantities
    and called on first use of ``ReducedContact.drift``: the mass matrix ``M(Q)``, forces
    ``F(Q, U)``, normal ``w(Q)`` in speed space, curvature ``kappa(Q, U)``,
    ``q' = kinematics * u``, the impact ``state``, ``r = M0^-1 w0`` and the projections
    ``P_u``, ``P_q``. The speed terms are exact
    where ``X`` is quadratic in ``u``; the configuration terms are first order (no Hessian
    in ``q``, no mixed ``q``-``u`` terms). The gradients follow from
    ``dA/dq_i = 2 r^T w_{,i} - r^T M_{,i} r`` and
    ``dG/dq_i = r_{,i}^T F_0 + r^T F_{,i}``, ``r_{,i} = M0^-1 (w_{,i} - M_{,i} r)``
    (no symbolic inverse). Returns ``None`` when symbols remain (a symbolic reduction).
    """

    def at0(expr: Any) -> Any:
        return expr.xreplace(state)

    numbers = [at0(x) for x in (*M, *F, *w, kappa, *kinematics, *U)]
    v0_is_number = sp.sympify(v0, strict=True).is_number  # strict: never parse a string
    if not all(getattr(x, "is_number", False) for x in numbers) or not v0_is_number:
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


_STEPS = 400  # Runge-Kutta steps over the expected contact time
_HORIZON = 3.0  # integrate up to this many expected contact times before calling it a stick


def _release(x, v, force, t, x1, v1, force1, t1):
    """Linear interpolation of the first of ``force <= 0`` and ``x <= 0`` on a step."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s_f = np.where(force1 <= 0, force / (force - force1), np.inf)
        s_x = np.where(x1 <= 0, x / (x - x1), np.inf)
    s = np.clip(np.minimum(s_f, s_x), 0.0, 1.0)
    return v + s * (v1 - v), t + s * (t1 - t)


def integrate_release(
    rhs: Callable, force: Callable, v0: np.ndarray, t_end: np.ndarray, track: Callable | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Classical Runge-Kutta from ``x = 0, x' = v0`` to the first release (vectorized).

    ``rhs(t, x, v)`` is the acceleration, ``force(t, x, v)`` the release function: the
    contact ends at the first step where it or ``x`` is ``<= 0`` (located by linear
    interpolation on the step). ``t_end`` (an array like ``v0``) is the expected contact
    time: ``_STEPS`` steps span it, at most ``_HORIZON`` times it are integrated. Returns
    the normal speed at release (positive inward), the release time (``inf``: none) and
    the largest ``|track(t, x, v)|`` over the contact's steps. Used by the drift
    corrections, which take the difference of two such runs, so that the integration
    error cancels to first order.
    """
    for name, value in (("v0", v0), ("t_end", t_end)):
        arr = np.asarray(value, float)
        if not np.all(np.isfinite(arr) & (arr > 0)):
            raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    v0 = np.asarray(v0, float)
    h = np.asarray(t_end, float) / _STEPS
    x, v, t = np.zeros_like(v0), v0.copy(), np.zeros_like(v0)
    done = np.zeros(v0.shape, bool)
    v_rel, t_rel = np.zeros_like(v0), np.full(v0.shape, np.inf)
    f = force(t, x, v)
    peak = np.zeros_like(v0)
    for _ in range(int(_HORIZON * _STEPS)):
        k1x, k1v = v, rhs(t, x, v)
        k2x, k2v = v + h / 2 * k1v, rhs(t + h / 2, x + h / 2 * k1x, v + h / 2 * k1v)
        k3x, k3v = v + h / 2 * k2v, rhs(t + h / 2, x + h / 2 * k2x, v + h / 2 * k2v)
        k4x, k4v = v + h * k3v, rhs(t + h, x + h * k3x, v + h * k3v)
        x1 = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v1 = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        t1 = t + h
        f1 = force(t1, x1, v1)
        if track is not None:
            peak = np.where(done, peak, np.maximum(peak, np.abs(track(t1, x1, v1))))
        ends = ~done & ((f1 <= 0) | (x1 <= 0))
        if ends.any():
            vr, tr = _release(x, v, f, t, x1, v1, f1, t1)
            v_rel, t_rel = np.where(ends, vr, v_rel), np.where(ends, tr, t_rel)
            done |= ends
            if done.all():
                break
        x, v, t, f = x1, v1, t1, f1
    return v_rel, t_rel, peak


def correct_along_drift(
    frozen: tuple[Callable, Callable],
    drifted: tuple[Callable, Callable],
    drift: ContactDrift,
    v0: float,
    contact_time: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """First-order drift correction: the drifting run minus the frozen one, same steps.

    ``frozen`` and ``drifted`` are ``(rhs, release)`` pairs of :func:`integrate_release`,
    started at ``x = 0, x' = v0`` over the predicted ``contact_time`` (array). Returns
    ``ok`` (both runs released), the restitution change ``(v_f - v_d) / v0``, the contact
    time change ``t_d - t_f`` and the largest ``|1/m_eff - 1/m_eff(0)|`` along the drifting
    motion relative to ``1/m_eff(0)``. The integration error cancels to first order in the
    differences. Used by :func:`corrected_contact` and MuJoCo's
    :func:`impactsym.engines.mujoco.drift.predict_reduced`.
    """
    a0 = drift.inv_mass[0]
    start = np.full(np.shape(contact_time), v0)
    v_f, t_f, _ = integrate_release(*frozen, start, contact_time)
    v_d, t_d, peak = integrate_release(
        *drifted,
        start,
        contact_time,
        lambda t, x, v: drift.value("inv_mass", t, x, v) - a0,
    )
    ok = np.isfinite(t_f) & np.isfinite(t_d)
    return ok, (v_f - v_d) / v0, t_d - t_f, peak / abs(a0)


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
    if not isinstance(drift, ContactDrift):
        raise TypeError(f"drift must be a ContactDrift (ReducedContact.drift), got {drift!r}")
    t_c, _ = real_array("contact_time", contact_time, lower=0.0, strict=True, allow_inf=True)
    seen, _ = real_array("observed", observed, lower=0.0, allow_inf=True)
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


@dataclass(frozen=True, eq=False)
class CorrectedContact(ArrayRecord):
    """The section-2 contact of a reduced multibody contact, drift corrected (SI units).

    Attributes
    ----------
    restitution, contact_time
        Corrected to first order in the configuration change during contact (seconds).
    frozen_restitution, frozen_contact_time
        Those of the reduction frozen at impact (``ReducedContact.restitution`` and
        ``.contact_time``).
    mass_drift
        Largest relative change of ``1/m~`` along the corrected contact motion.
    drift_free_contact_time
        The contact time at which that change would be 1 % (:func:`drift_free_contact_time`).
    """

    restitution: float | np.ndarray
    contact_time: float | np.ndarray
    frozen_restitution: float | np.ndarray
    frozen_contact_time: float | np.ndarray
    mass_drift: float | np.ndarray
    drift_free_contact_time: float | np.ndarray


def corrected_contact(reduced: Any, *, condition: str) -> CorrectedContact:
    r"""The penalty contact of a reduced multibody contact with its drift, to first order.

    The frozen reduction is the section-2 oscillator
    ``m~ z'' + d~ z' + c~ z = F_n``. The penalty force ``-(d z' + k z)`` acts along the
    current normal, so the exact normal dynamics is ``z'' = G + kappa - A (d z' + k z)``;
    with ``A``, ``G`` and ``kappa`` drifting along the reduced motion (module docstring) it
    is the frozen oscillator plus

    .. math::

        \delta = -(A - A_0)(d\dot z + kz) + (G - G_0 - G_v\,\delta v + (\tilde c - k)\,z/\tilde m)
        + (\kappa - \kappa_0),

    (what the frozen reduction already holds of ``G`` taken out). Both are integrated with
    the same Runge-Kutta steps (:func:`integrate_release`) to the end of contact under
    ``condition`` (``"force"``: ``d~ z' + c~ z`` turns tensile; ``"position"``: ``z``
    returns to zero), and the section-2 result is corrected by their difference. Where
    the frozen contact sticks it is left as it is. Warns (``RuntimeWarning``) where
    ``1/m~`` drifts by more than 1 % over the contact.

    Parameters
    ----------
    reduced
        A numeric :class:`impactsym.multibody.ReducedContact` (``k``, ``d`` may be arrays).
    condition
        ``"force"`` or ``"position"`` (no default: the two differ).

    Returns
    -------
    CorrectedContact

    Notes
    -----
    Checked against the full nonlinear simulation
    :func:`impactsym.multibody.simulation.simulate_contact`; see
    `docs/physics.md#multibody-drift`.
    """
    check_condition(condition)
    drift = drift_of(reduced)
    e0 = np.asarray(reduced.restitution(condition), float)
    t0 = np.asarray(reduced.contact_time(condition), float)
    shape = e0.shape
    m, v0 = float(reduced.m_eff), float(reduced.v0)
    a0 = drift.inv_mass[0]
    d_eff, c_eff, k, d = (
        np.broadcast_to(np.asarray(x, float), shape).ravel()
        for x in (reduced.d_eff, reduced.c_eff, reduced.k, reduced.d)
    )
    load, stiff_extra = float(reduced.load), float(reduced.delta_c) / m
    e, t_c = e0.ravel().copy(), t0.ravel().copy()
    mass = np.zeros(t_c.shape)
    live = np.flatnonzero(np.isfinite(t_c))
    if live.size:
        dd, cc, kk, dp = d_eff[live], c_eff[live], k[live], d[live]
        g0, gv, k0 = drift.press[0], drift.press[3], drift.curvature[0]

        def frozen(t, x, v):
            return (load - dd * v - cc * x) / m

        def drifted(t, x, v):
            d_inv = drift.value("inv_mass", t, x, v) - a0
            d_press = drift.value("press", t, x, v) - (g0 + gv * (v - v0) - stiff_extra * x)
            d_curv = drift.value("curvature", t, x, v) - k0
            return frozen(t, x, v) - d_inv * (dp * v + kk * x) + d_press + d_curv

        if condition == "force":

            def release(t, x, v):
                return dd * v + cc * x

        else:

            def release(t, x, v):
                return x + 0.0 * v

        ok, de, dt, rel = correct_along_drift(
            (frozen, release), (drifted, release), drift, v0, t_c[live]
        )
        e[live] = np.where(ok, e[live] + de, e[live])
        t_c[live] = np.where(ok, t_c[live] + dt, t_c[live])
        mass[live] = rel
    free = drift_free_contact_time(drift, t_c, mass)
    warn_mass_drift(
        mass, t_c, free, what="restitution and contact_time here are corrected to first order"
    )
    out = [a.reshape(shape) for a in (e, t_c, e0, t0, mass, free)]
    if not shape:
        out = [float(a) for a in out]
    return CorrectedContact(*out)
