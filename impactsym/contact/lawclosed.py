r"""Closed-form results of the nonlinear laws, evaluated on arrays (no pressing force).

The formulas are derived in :mod:`impactsym.contact.lawmaps`:

* Hunt–Crossley: :math:`e = (1 + W_0(-(1+s) e^{-(1+s)}))/s`, :math:`s = \lambda v_0`.
  Near :math:`s \to 0` the argument of :math:`W_0` approaches the branch point
  :math:`-1/e`, where :math:`W_0` loses half the digits (``1 + W`` from a rounded
  argument errs by :math:`\sim 10^{-16}/s`). So :func:`hunt_crossley_restitution` takes
  SciPy's :math:`W_0` as the start and solves the same exit equation in the form
  :math:`\rho(-s e) = -\rho(s)`, :math:`\rho(x) = \operatorname{sign}(x)\sqrt{2(x -
  \ln(1+x))}`, which is smooth, increasing and well conditioned (:math:`\rho(x) \approx
  x` near 0, evaluated by its series there); a few bracketed Newton steps give every digit.
  :func:`hunt_crossley_parameter` inverts it exactly (bisection on the same equation, whose
  sign tells on which side of the root a trial ``s`` lies).
* Tsuji: :math:`\zeta = \alpha/\sqrt{2(p+1)}` of the linear contact (:func:`tsuji_zeta`).
"""

from __future__ import annotations

import numpy as np
from scipy.special import lambertw

#: Below this |x| the function rho is evaluated from its Taylor series.
_SERIES = 0.05
_TERMS = 24


def rho(x: np.ndarray) -> np.ndarray:
    r""":math:`\rho(x) = \operatorname{sign}(x)\sqrt{2(x - \ln(1 + x))}` for :math:`x > -1`.

    >>> float(rho(np.array(1e-9)))  # ~ x - x^2/3
    9.999999996666667e-10
    """
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < _SERIES
    xs = np.where(small, x, 0.0)
    # x - log1p(x) = x^2 (1/2 - x/3 + x^2/4 - ...)
    series = np.zeros_like(xs)
    for n in range(_TERMS + 1, 1, -1):
        series = series * (-xs) + 1.0 / n
    with np.errstate(all="ignore"):
        direct = x - np.log1p(x)
    r = np.where(small, xs * xs * series, direct)
    return np.sign(x) * np.sqrt(2.0 * np.maximum(r, 0.0))


def hunt_crossley_restitution(s: np.ndarray) -> np.ndarray:
    r"""Restitution of the Hunt–Crossley contact without pressing force, ``s = lambda v0``.

    >>> [round(float(hunt_crossley_restitution(np.array(v))), 3) for v in (4.919, 0.0789)]
    [0.2, 0.95]
    """
    s = np.asarray(s, dtype=float)
    with np.errstate(all="ignore"):
        W = np.real(lambertw(-(1.0 + s) * np.exp(-(1.0 + s)), 0))
    v = np.clip(-(1.0 + W), -1.0, 0.0)  # v = -s e in (-1, 0)
    v = np.where(np.isfinite(v) & (v < 0), v, -s / (1.0 + s))  # rounded past the branch point
    target = -rho(s)
    lo, hi = np.full(s.shape, -1.0), np.zeros(s.shape)
    for _ in range(60):
        r = rho(v) - target
        lo, hi = np.where(r < 0, v, lo), np.where(r < 0, hi, v)
        with np.errstate(all="ignore"):
            slope = (v / (1.0 + v)) / rho(v)  # rho' = (1 - 1/(1+x)) / rho
            newton = v - r / slope
        inside = np.isfinite(newton) & (newton > lo) & (newton < hi)
        new = np.where(inside, newton, 0.5 * (lo + hi))
        if np.all(np.abs(new - v) <= 1e-16 * np.abs(v)):
            v = new
            break
        v = new
    with np.errstate(all="ignore"):
        e = np.where(s > 0, -v / s, 1.0)
    return np.clip(e, 0.0, 1.0)


def hunt_crossley_parameter(e: np.ndarray) -> np.ndarray:
    r"""The ``s = lambda v0`` at which the Hunt–Crossley contact restitutes ``e`` (``0 <
    e <= 1``; ``s = 0`` at ``e = 1``): the root of :math:`\rho(-s e) + \rho(s)`, positive
    below it and negative above, found by bisection on :math:`(0, 1/e)`.

    >>> [round(float(hunt_crossley_parameter(np.array(v))), 4) for v in (0.2, 0.95)]
    [4.9192, 0.0789]
    """
    e = np.asarray(e, dtype=float)
    lo, hi = np.zeros(e.shape), 1.0 / e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        above = rho(-mid * e) + rho(mid) < 0
        lo, hi = np.where(above, lo, mid), np.where(above, mid, hi)
        if np.all(hi - lo <= 2e-16 * hi):
            break
    return np.where(e >= 1.0, 0.0, 0.5 * (lo + hi))


def tsuji_zeta(alpha: np.ndarray, exponent: np.ndarray) -> np.ndarray:
    r"""Damping ratio :math:`\zeta = \alpha/\sqrt{2(p+1)}` of the linear contact that
    ends with the same velocity as the Tsuji contact.

    >>> float(tsuji_zeta(np.sqrt(5.0), 1.5))
    1.0
    """
    return np.asarray(alpha, dtype=float) / np.sqrt(2.0 * (np.asarray(exponent) + 1.0))
