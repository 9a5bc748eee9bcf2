r"""Maximum penetration and peak force of the linear spring-damper contact in closed form,
with or without pressing force.

**What.** For :math:`z'' + 2Dz' + z = b` (:math:`b = 2Df`, the static penetration),
:math:`z(0) = 0`, :math:`z'(0) = 1`, ending at the contact time :math:`\tau_c` (``inf``
where the body sticks) (`docs/physics.md, section 2
<../physics.html#2-spring-damper-contact-paper-2>`_): the maximum penetration
:math:`\sup z` and the peak force :math:`\sup \max(0, \varphi)`,
:math:`\varphi = z + 2Dz' = b - z''`, over :math:`[0, \tau_c]`.

``z'``, ``z''`` and ``z'''`` solve the homogeneous equation
:math:`y'' + 2Dy' + y = 0`, whose zeros are closed forms (:func:`first_zero`):

* the maximum penetration is ``z`` at the first zero :math:`\tau_m` of ``z'``
  (``z' = 0`` needs :math:`z'' \le 0`, so :math:`z(\tau_m) \ge b`; later maxima of the
  damped oscillation about ``b`` are smaller, and over-damped ``z'`` has one zero at
  most); it lies before any release. Without a zero ``z`` creeps up to ``b``: the
  supremum is ``b``;
* the peak force is the largest of :math:`\varphi(0) = 2D`, :math:`\varphi` at its first
  interior local maximum :math:`\tau_p` (the first upward zero of :math:`z'''`) when
  :math:`\tau_p < \tau_c`, and its limit ``b`` where the body sticks: the local maxima of
  :math:`\varphi - b`, a damped oscillation, decrease, so the first is the largest.

**Why this numerics.** It replaces the order-8 integration of
:mod:`impactsym.contact.lawkernel`, which the linear law needed for these two numbers
alone (about 2 us per element and step, tens of steps); the closed forms cost a few
NumPy passes. The zeros are taken without cancellation: under-damped as
:math:`\operatorname{atan2}` of the phase over :math:`\omega = \sqrt{(1 - D)(1 + D)}`,
over-damped as :math:`\operatorname{log1p}(x)/(2\sigma)`,
:math:`\sigma = \sqrt{D - 1}\sqrt{D + 1}`, both tending to the critical
:math:`-y_0/(y_1 + y_0)` at :math:`D = 1`; the values from the damped basis of
:func:`impactsym.contact.kernel.homogeneous`.
"""

from __future__ import annotations

import numpy as np

from impactsym.contact.kernel import homogeneous
from impactsym.validation import real_array


def first_zero(D: np.ndarray, y0: np.ndarray, y1: np.ndarray, *, upward: bool) -> np.ndarray:
    r"""First :math:`\tau > 0` where :math:`y'' + 2Dy' + y = 0`, :math:`y(0) = y_0`,
    :math:`y'(0) = y_1`, crosses zero upwards (``upward``) or downwards; ``inf`` where it
    never does (flat arrays, ``D >= 0``).

    Under-damped :math:`y = R e^{-D\tau}\sin(\omega\tau + \theta_0)`,
    :math:`\theta_0 = \operatorname{atan2}(\omega y_0, y_1 + D y_0)`: upward zeros at
    :math:`\omega\tau + \theta_0 = 2j\pi`, downward at :math:`(2j + 1)\pi`. Over-damped
    :math:`y = A e^{-\tau/\mu} + B e^{-\mu\tau}` (:math:`\mu = D + \sigma`) has one zero at
    most, :math:`\tau = \operatorname{log1p}(-2\sigma y_0/(y_1 + \mu y_0))/(2\sigma)`,
    crossing from the sign of :math:`y_0`; critical: :math:`\tau = -y_0/(y_1 + y_0)`.

    >>> float(first_zero(np.array([0.0]), np.array([1.0]), np.array([0.0]), upward=False)[0])
    1.5707963267948966
    """
    D = real_array("D", D, lower=0.0)[0]
    tau = np.full(D.shape, np.inf)
    under, over, critical = D < 1.0, D > 1.0, D == 1.0
    if under.any():
        d, a, v = D[under], y0[under], y1[under]
        w = np.sqrt((1.0 - d) * (1.0 + d))
        theta = np.arctan2(w * a, v + d * a)  # in (-pi, pi]
        if upward:
            phase = np.where(theta < 0.0, -theta, 2.0 * np.pi - theta)
        else:
            phase = np.where(theta < np.pi, np.pi - theta, 2.0 * np.pi)  # theta = pi: y0 = 0
        with np.errstate(divide="ignore"):
            tau[under] = phase / w
    if over.any():
        d, a, v = D[over], y0[over], y1[over]
        sigma = np.sqrt(d - 1.0) * np.sqrt(d + 1.0)
        mu = d + sigma
        with np.errstate(divide="ignore", invalid="ignore"):
            x = -2.0 * sigma * a / (v + mu * a)
            t = np.log1p(x) / (2.0 * sigma)
        crosses = (x > 0.0) & ((a < 0.0) if upward else (a > 0.0))
        tau[over] = np.where(crosses, t, np.inf)
    if critical.any():
        a, v = y0[critical], y1[critical]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -a / (v + a)
        crosses = (t > 0.0) & ((a < 0.0) if upward else (a > 0.0))
        tau[critical] = np.where(crosses, t, np.inf)
    return tau


def linear_extrema(
    D: np.ndarray, b: np.ndarray, tau_c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    r"""Maximum penetration and peak force (normalized) of the linear contact over
    :math:`[0, \tau_c]` (flat arrays; ``tau_c = inf`` where the body sticks).

    >>> z_max, peak = linear_extrema(np.array([0.0]), np.array([0.0]), np.array([np.pi]))
    >>> float(z_max[0]), float(peak[0])  # z = sin(tau)
    (1.0, 1.0)
    """
    D = real_array("D", D, lower=0.0)[0]
    b, tau_c = (np.asarray(a, dtype=float) for a in (b, tau_c))
    one = np.ones(D.shape)
    basis = homogeneous()
    # z' = u: u(0) = 1, u'(0) = b - 2D
    tau_m = first_zero(D, one, b - 2.0 * D, upward=False)
    z_max = b.copy()  # no zero of z': z creeps up to b
    found = np.isfinite(tau_m)
    if found.any():
        t, d = tau_m[found], D[found]
        h, _ = basis(t, d, -b[found], one[found])  # z = b + h, h(0) = -b, h'(0) = 1
        z_max[found] = b[found] + h
    # z''' = s: s(0) = -2D z''(0) - z'(0), s'(0) = -2D s(0) - z''(0), z''(0) = b - 2D
    accel = b - 2.0 * D
    s0 = -2.0 * D * accel - 1.0
    tau_p = first_zero(D, s0, -2.0 * D * s0 - accel, upward=True)
    peak = np.where(np.isinf(tau_c), np.maximum(2.0 * D, b), 2.0 * D)
    inside = tau_p < tau_c
    if inside.any():
        t, d = tau_p[inside], D[inside]
        h, h_dot = basis(t, d, -b[inside], one[inside])
        peak[inside] = np.maximum(peak[inside], b[inside] + h + 2.0 * d * h_dot)
    return z_max, peak
