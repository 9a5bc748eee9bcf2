r"""Closed-form results of the nonlinear laws, evaluated on arrays (no pressing force).

The formulas are derived in :mod:`impactsym.contact.lawmaps`:

* Hunt–Crossley: :math:`e = (1 + W_0(-(1+s) e^{-(1+s)}))/s`, :math:`s = \lambda v_0`.
  Near :math:`s \to 0` the argument of :math:`W_0` approaches the branch point
  :math:`-1/e`, where :math:`W_0` loses half the digits (``1 + W`` from a rounded
  argument errs by :math:`\sim 10^{-16}/s`). So :func:`hunt_crossley_restitution` takes
  SciPy's :math:`W_0` as it is for :math:`s \ge 1` (good to 4e-16 there), and below as
  the start for the same exit equation in the form :math:`\rho(-s e) = -\rho(s)`,
  :math:`\rho(x) = \operatorname{sign}(x)\sqrt{2(x - \ln(1+x))}`, which is smooth,
  increasing and well conditioned (:math:`\rho(x) \approx x` near 0, evaluated by its
  series there); a few bracketed Newton steps give every digit, each element iterating
  until its own step is below 2 ulp. :func:`hunt_crossley_parameter` inverts it exactly
  (bracketed Newton steps on the same equation, whose sign tells on which side of the
  root a trial ``s`` lies).
* Tsuji: :math:`\zeta = \alpha/\sqrt{2(p+1)}` of the linear contact (:func:`tsuji_zeta`).
* The linear contact without pressing force, inverted (:func:`linear_damping_ratio`): the
  position condition restitutes :math:`e = \exp(-\pi D/\sqrt{1 - D^2})`, so
  :math:`D = -\ln e/\sqrt{\pi^2 + \ln^2 e}`; the force condition, whose force
  :math:`z + 2Dz' = e^{-D\tau}\sin(\omega\tau + \pi - 2\psi)/\omega`
  (:math:`\omega = \sqrt{1 - D^2}`, :math:`\psi = \arccos D`) first vanishes at
  :math:`\omega\tau = 2\psi`, restitutes :math:`e = e^{-D\tau} = \exp(-2 h(D))`,
  :math:`h(D) = D\arccos D/\sqrt{1 - D^2}` (:math:`D \operatorname{arcosh} D/\sqrt{D^2
  - 1}` above 1, 1 at 1), increasing from 0 to infinity: its root is bracketed and
  found by Illinois steps.
"""

from __future__ import annotations

import numpy as np
from scipy.special import lambertw

from impactsym.contact.unpressed import force_exponent, unpressed_release
from impactsym.validation import check_condition

#: Below this |x| the function rho is evaluated from its Taylor series.
_SERIES = 0.05
_TERMS = 24
#: Below this s, W0 is near its branch point and the restitution is polished by Newton
#: steps (above it W0 gives the restitution to 4e-16, checked against mpmath in the tests).
_POLISH = 1.0
#: An element's Newton iteration stops at a step below this fraction of its value (2 ulp).
_STEP = 4.5e-16


def rho(x: np.ndarray) -> np.ndarray:
    r""":math:`\rho(x) = \operatorname{sign}(x)\sqrt{2(x - \ln(1 + x))}` for :math:`x > -1`.

    >>> float(rho(np.array(1e-9)))  # ~ x - x^2/3
    9.999999996666667e-10
    """
    x = np.asarray(x, dtype=float)
    with np.errstate(all="ignore"):
        r = x - np.log1p(x)
    small = np.abs(x) < _SERIES
    if small.any():  # the series on the small entries only
        xs = x[small]
        # x - log1p(x) = x^2 (1/2 - x/3 + x^2/4 - ...)
        series = np.zeros_like(xs)
        for n in range(_TERMS + 1, 1, -1):
            series = series * (-xs) + 1.0 / n
        r = np.array(r, dtype=float)
        r[small] = xs * xs * series
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
    target = -rho(s).ravel()
    v = v.ravel()  # a fresh array: updated in place, element by element
    lo, hi = np.full(v.size, -1.0), np.zeros(v.size)
    idx = np.flatnonzero(~(s.ravel() >= _POLISH))  # the elements still iterating
    for _ in range(60 if idx.size else 0):
        vi = v[idx]
        rv = rho(vi)
        r = rv - target[idx]
        lo_i = np.where(r < 0, vi, lo[idx])
        hi_i = np.where(r < 0, hi[idx], vi)
        with np.errstate(all="ignore"):
            slope = (vi / (1.0 + vi)) / rv  # rho' = (1 - 1/(1+x)) / rho
            newton = vi - r / slope
        inside = np.isfinite(newton) & (newton > lo_i) & (newton < hi_i)
        new = np.where(inside, newton, 0.5 * (lo_i + hi_i))
        new = np.where(r == 0, vi, new)  # on the root already
        v[idx], lo[idx], hi[idx] = new, lo_i, hi_i
        idx = idx[~(np.abs(new - vi) <= _STEP * np.abs(vi))]
        if idx.size == 0:
            break
    v = v.reshape(s.shape)
    with np.errstate(all="ignore"):
        e = np.where(s > 0, -v / s, 1.0)
    return np.clip(e, 0.0, 1.0)


def hunt_crossley_parameter(e: np.ndarray) -> np.ndarray:
    r"""The ``s = lambda v0`` at which the Hunt–Crossley contact restitutes ``e`` (``0 <
    e <= 1``; ``s = 0`` at ``e = 1``): the root of :math:`\rho(-s e) + \rho(s)`, positive
    below it and negative above, bracketed in :math:`(0, 1/e)`: Newton steps
    (:math:`\rho'(x) = x / ((1 + x)\rho(x))`) from :math:`s = 3(1 - e)/(2e)`, a bisection
    wherever a step leaves the bracket.

    >>> [round(float(hunt_crossley_parameter(np.array(v))), 4) for v in (0.2, 0.95)]
    [4.9192, 0.0789]
    """
    e = np.asarray(e, dtype=float)
    flat = e.ravel()
    lo, hi = np.zeros(flat.size), 1.0 / flat
    with np.errstate(all="ignore"):
        s = np.minimum(1.5 * (1.0 - flat) / flat, 0.5 * hi)
    s = np.where(np.isfinite(s) & (s > 0), s, 0.5 * hi)
    idx = np.flatnonzero(flat < 1.0)  # the elements still iterating
    for _ in range(200):
        si, ei = s[idx], flat[idx]
        x = -si * ei
        rx, rs = rho(x), rho(si)
        g = rx + rs
        above = g < 0
        lo_i, hi_i = np.where(above, lo[idx], si), np.where(above, si, hi[idx])
        with np.errstate(all="ignore"):
            slope = -ei * (x / (1.0 + x)) / rx + (si / (1.0 + si)) / rs
            newton = si - g / slope
        inside = np.isfinite(newton) & (newton > lo_i) & (newton < hi_i)
        new = np.where(inside, newton, 0.5 * (lo_i + hi_i))
        new = np.where(g == 0, si, new)  # on the root already
        s[idx], lo[idx], hi[idx] = new, lo_i, hi_i
        done = (np.abs(new - si) <= _STEP * si) | (hi_i - lo_i <= 2e-16 * hi_i)
        idx = idx[~done]
        if idx.size == 0:
            break
    return np.where(e >= 1.0, 0.0, s.reshape(e.shape))


def tsuji_zeta(alpha: np.ndarray, exponent: np.ndarray) -> np.ndarray:
    r"""Damping ratio :math:`\zeta = \alpha/\sqrt{2(p+1)}` of the linear contact that
    ends with the same velocity as the Tsuji contact.

    >>> float(tsuji_zeta(np.sqrt(5.0), 1.5))
    1.0
    """
    return np.asarray(alpha, dtype=float) / np.sqrt(2.0 * (np.asarray(exponent) + 1.0))


def linear_damping_ratio(e: np.ndarray, *, condition: str) -> np.ndarray:
    r"""The damping ratio ``D`` at which the linear contact without pressing force
    restitutes ``e`` (``0 < e <= 1``; ``D = 0`` at ``e = 1``), under ``condition``.

    >>> from impactsym.contact.api import restitution
    >>> D = linear_damping_ratio(np.array([0.3, 0.05]), condition="force")
    >>> np.round(restitution(D, 0.0, condition="force"), 12).tolist()
    [0.3, 0.05]
    """
    check_condition(condition)
    e = np.asarray(e, dtype=float)
    if not np.all((e > 0) & (e <= 1)):
        bad = e[~((e > 0) & (e <= 1))].flat[0]
        raise ValueError(f"restitution must be in (0, 1], got {float(bad)!r}")
    L = -np.log(e)
    if condition == "position":
        return L / np.sqrt(np.pi**2 + L * L)
    L = 0.5 * L.ravel()  # h(D) = -ln(e)/2
    lo, hi = np.zeros(L.size), np.maximum(2.0, np.exp(L))  # e(2) < 0.05; e(1/sqrt(e)) < e
    g_lo, g_hi = -L, force_exponent(hi)[1] - L
    D = np.zeros(L.size)
    side = np.zeros(L.size, dtype=int)
    idx = np.flatnonzero(L > 0)  # the elements still iterating
    for _ in range(200):
        lo_i, hi_i, gl, gh = lo[idx], hi[idx], g_lo[idx], g_hi[idx]
        with np.errstate(all="ignore"):
            trial = (lo_i * gh - hi_i * gl) / (gh - gl)
        bad = ~np.isfinite(trial) | (trial <= lo_i) | (trial >= hi_i)
        trial = np.where(bad, 0.5 * (lo_i + hi_i), trial)
        g = force_exponent(trial)[1] - L[idx]
        above = g > 0
        hi_i, gh = np.where(above, trial, hi_i), np.where(above, g, gh)
        lo_i, gl = np.where(above, lo_i, trial), np.where(above, gl, g)
        s_i = side[idx]  # Illinois: halve the value kept on the same side twice
        gl = np.where(above & (s_i == 1), 0.5 * gl, gl)
        gh = np.where(~above & (s_i == -1), 0.5 * gh, gh)
        lo[idx], hi[idx], g_lo[idx], g_hi[idx], D[idx] = lo_i, hi_i, gl, gh, trial
        side[idx] = np.where(above, 1, -1)
        idx = idx[~((hi_i - lo_i <= 4e-16 * hi_i) | (g == 0))]
        if idx.size == 0:
            break
    return D.reshape(e.shape)


def linear_free_restitution(D: np.ndarray, *, condition: str) -> np.ndarray:
    r"""Restitution of the linear contact without pressing force at damping ratio ``D``:
    :math:`\exp(-\pi D/\sqrt{1 - D^2})` under the position condition (0 from ``D = 1``
    on: the body creeps back and sticks), :math:`\exp(-2 h(D))` under the force condition
    (:func:`linear_damping_ratio` inverts both), by
    :func:`impactsym.contact.unpressed.unpressed_release`.

    >>> float(linear_free_restitution(np.array(1.0), condition="force"))  # exp(-2)
    0.1353352832366127
    """
    return unpressed_release(D, condition=condition)[1]
