r"""The largest value of an RK4 interior row over the steps of a closed-form jump.

Over a jump through the interior (:mod:`~impactsym.engines.mujoco.rk4`) a stage's
penetration or force term is the exponential polynomial ``g(n) = s* + m^n (q cosh n delta
+ w sinh n delta / sinh delta)`` of the step ``n``; the contact's largest penetration and
peak force over those steps are its maxima at the integers. For complex eigenvalues
(``delta = i theta``) ``g = s* + R m^t cos(theta t + u0)`` has its continuous local maxima
at ``theta t + u0 = atan(ln m / theta) mod 2 pi`` (growing or decaying: the first or the
last is the largest); for real ones it has at most one extremum, at the root of
``g'(t)`` in closed form. The integers next to those, and both ends, are the candidates.

SI: the row's units (metres or m/s^2).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["row_max"]

_TWO_PI = 2.0 * np.pi


def row_max(row: Any, last: np.ndarray) -> np.ndarray:
    """Largest value of ``row`` at the integers from 1 to ``last`` (``-inf`` where ``last < 1``).

    ``row`` holds ``s, q, w, lm, rate, osc`` and ``value(n)`` (module docstring); the
    candidates are ``1``, ``last`` and the integers either side of the first and the last
    continuous local maximum in ``[1, last]``.
    """
    lm, rate = row.lm, row.rate
    end = np.minimum(last, 1e15)
    with np.errstate(divide="ignore", invalid="ignore"):
        # continuous local maxima: oscillating, at theta t + u0 = atan(ln m / theta) mod 2 pi
        amp_s = row.w / np.sin(rate)
        u0 = -np.angle(row.q + 1j * amp_s)
        twist = np.arctan(lm / rate)
        first = 1 + np.mod(twist - (rate + u0), _TWO_PI) / rate
        final = end - np.mod(rate * end + u0 - twist, _TWO_PI) / rate
        sd = np.sinh(rate)
        sdc = np.where(rate == 0, 1.0, sd / np.where(rate == 0, 1.0, rate))
        t_d = -(row.q * sdc * lm + row.w) / (row.w * lm + rate * row.q * sd)
        tau = t_d * rate
        atc = np.where(tau == 0, 1.0, np.arctanh(tau) / np.where(tau == 0, 1.0, tau))
        t_e = atc * t_d
    first = np.where(row.osc, first, t_e)
    final = np.where(row.osc, final, t_e)
    best = np.full(lm.shape, -np.inf)
    for t in (
        np.ones_like(end),
        end,
        np.floor(first),
        np.ceil(first),
        np.floor(final),
        np.ceil(final),
    ):
        t = np.where(np.isfinite(t), np.clip(t, 1.0, end), 1.0)
        best = np.maximum(best, row.value(t))
    return np.where(last >= 1, best, -np.inf)
