r"""The spring-damper contact without pressing force (paper section 2, :math:`f = 0`) in
closed form: contact time and restitution of both conditions, on arrays.

**What.** For :math:`z'' + 2Dz' + z = 0`, :math:`z(0) = 0`, :math:`z'(0) = 1`
(`docs/physics.md, section 2 <../physics.html#2-spring-damper-contact-paper-2>`_), with
:math:`\omega = \sqrt{1 - D^2}` and :math:`\psi = \arccos D`:

* position condition (:math:`g = z = e^{-D\tau}\sin(\omega\tau)/\omega`):
  :math:`\tau_c = \pi/\omega`, :math:`e = \exp(-\pi D/\omega)` for :math:`D < 1`; from
  :math:`D = 1` on the body creeps back without crossing: :math:`\tau_c = \infty`,
  :math:`e = 0`;
* force condition (:math:`g = z + 2Dz' = -z'' = e^{-D\tau}\sin(2\psi - \omega\tau)/\omega`):
  :math:`\tau_c = 2\psi/\omega`, and :math:`z'(\tau_c) = -e^{-D\tau_c}`, so
  :math:`e = \exp(-2h)` with :math:`h = D\tau_c/2 = D\psi/\omega`. Over-damped the same
  expressions continue analytically: :math:`\tau_c = 2\operatorname{arcosh}(D)/\sigma`,
  :math:`\sigma = \sqrt{D^2 - 1}` (the inflection of :math:`z`,
  :math:`\lambda_1^2 e^{\lambda_1\tau} = \lambda_2^2 e^{\lambda_2\tau}`), and both sides
  meet at :math:`D = 1` in :math:`\tau_c = 2`, :math:`e = e^{-2}`.

**Why this numerics.** These replace the ridge-bracketed root of
:mod:`impactsym.contact.kernel` wherever :math:`f = 0` (10-20 times cheaper, and exact
to a few ulp: checked against 40-digit references). Near :math:`D = 1` nothing cancels:
:math:`1 - D` and :math:`D - 1` are exact in floating point for :math:`1/2 \le D \le 2`,
so :math:`\omega`, :math:`\sigma` and the ``arccos``/``arcosh`` of the exactly given
:math:`D` keep full relative accuracy, and so do their ratios, which tend to 1. Far
over-damped, :math:`\sigma = \sqrt{D - 1}\sqrt{D + 1}` does not overflow; there
:math:`e \approx 1/(4D^2)` underflows to 0 (:math:`D \gtrsim 10^{154}`) and
:math:`\tau_c \approx 2\ln(2D)/D`.
"""

from __future__ import annotations

import numpy as np

from impactsym.validation import check_condition, real_array


def unpressed_release(D: np.ndarray, *, condition: str) -> tuple[np.ndarray, np.ndarray]:
    r"""Contact time :math:`\tau_c` and restitution :math:`e` of the unpressed
    spring-damper contact at damping ratio ``D`` (any shape, ``D >= 0``; ``inf``
    allowed: :math:`\tau_c = 0`, :math:`e = 0` under the force condition; a negative,
    NaN or non-numeric ``D`` raises, naming it).

    .. math::
        \text{position: } \tau_c = \frac{\pi}{\sqrt{1 - D^2}},\ e = e^{-D\tau_c}
        \ (D < 1);\qquad
        \text{force: } \tau_c = \frac{2\arccos D}{\sqrt{1 - D^2}}
        = \frac{2\operatorname{arcosh} D}{\sqrt{D^2 - 1}},\ e = e^{-D\tau_c}.

    Examples
    --------
    Critical damping releases at :math:`\tau_c = 2` with :math:`e = e^{-2}` under the
    force condition and never under the position condition:

    >>> tau, e = unpressed_release(np.array([0.0, 1.0]), condition="force")
    >>> tau.tolist(), e.tolist()
    ([3.141592653589793, 2.0], [1.0, 0.1353352832366127])
    >>> unpressed_release(np.array(1.0), condition="position")
    (array(inf), array(0.))
    """
    check_condition(condition)
    D = real_array("D", D, lower=0.0, allow_inf=True)[0]
    if condition == "position":
        with np.errstate(all="ignore"):  # the branch is kept only where it is valid
            w = np.sqrt((1.0 - D) * (1.0 + D))
            under = D < 1.0
            return np.where(under, np.pi / w, np.inf), np.where(under, np.exp(-np.pi * D / w), 0.0)
    tau_c, h = _force_exponent(D)
    return tau_c, np.asarray(np.exp(-2.0 * h))


def force_exponent(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Force-condition contact time :math:`\tau_c` of the unpressed contact and the
    exponent :math:`h = D\tau_c/2` of its restitution :math:`e = e^{-2h}`:

    .. math::  h = \frac{D\arccos D}{\sqrt{1 - D^2}}\ (D < 1),\quad 1\ (D = 1),\quad
               \frac{D\operatorname{arcosh} D}{\sqrt{D^2 - 1}}\ (D > 1),

    increasing from 0 to infinity (``D = inf``: :math:`\tau_c = 0`, :math:`h = \infty`).

    >>> [float(v) for v in force_exponent(np.array(1.0))]
    [2.0, 1.0]
    """
    return _force_exponent(real_array("D", D, lower=0.0, allow_inf=True)[0])


def _force_exponent(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`force_exponent` of a checked float array."""
    shape = D.shape
    D = D.reshape(-1)
    under = D < 1.0
    if under.all():  # the common case: no masks
        tau_c, h = _force_under(D)
    else:
        tau_c, h = np.full(D.shape, 2.0), np.ones(D.shape)  # D = 1
        if under.any():
            tau_c[under], h[under] = _force_under(D[under])
        over = D > 1.0
        if over.any():
            tau_c[over], h[over] = _force_over(D[over])
    return tau_c.reshape(shape), h.reshape(shape)


def _force_under(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`force_exponent` for ``D < 1``: :math:`1 - D` is exact for ``D >= 1/2``."""
    w = np.sqrt((1.0 - D) * (1.0 + D))
    psi = np.arccos(D)
    return 2.0 * psi / w, D * psi / w


def _force_over(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r""":func:`force_exponent` for ``D > 1`` (``inf`` included): :math:`D - 1` is exact
    for ``D <= 2``; :math:`\sigma` does not overflow."""
    with np.errstate(over="ignore"):
        sigma = np.sqrt((D - 1.0) * (D + 1.0))
    huge = ~np.isfinite(sigma)
    if huge.any():
        sigma[huge] = np.sqrt(D[huge] - 1.0) * np.sqrt(D[huge] + 1.0)
    phi = np.arccosh(D)
    with np.errstate(invalid="ignore", over="ignore"):
        tau_c, h = 2.0 * phi / sigma, D * phi / sigma
    infinite = np.isinf(D)
    if infinite.any():  # tau_c ~ 2 ln(2D)/D -> 0, e ~ 1/(4D^2) -> 0
        tau_c[infinite], h[infinite] = 0.0, np.inf
    return tau_c, h
