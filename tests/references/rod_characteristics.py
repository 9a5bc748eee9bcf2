"""Independent reference for the rigid rod impact: characteristics and a delay equation.

With d'Alembert's solution :math:`w(\\xi, t) = F(t - \\xi) - F(t + \\xi - 2)` (fixed at
:math:`\\xi = 1`, at rest for :math:`t < 0`) and :math:`\\varphi = F'`, the contact
:math:`y = w(0, t)` and the striker's law :math:`\\alpha y'' = f - N` give

.. math::

    N = \\varphi(t) + \\varphi(t-2), \\qquad y' = \\varphi(t) - \\varphi(t-2), \\qquad
    \\alpha\\varphi'(t) + \\varphi(t) = f + \\alpha\\varphi'(t-2) - \\varphi(t-2),

a neutral delay equation with :math:`\\varphi = 0` for :math:`t < 0` and
:math:`\\varphi(0^+) = 1` (:math:`y'(0) = 1`). Continuity of :math:`y'` makes
:math:`\\varphi` jump by 1 at every :math:`t = 2k`. On interval :math:`k`
(:math:`t = 2k + \\tau`) it is the linear ODE
:math:`\\alpha\\varphi_k' + \\varphi_k = f + R_k` with
:math:`R_k = \\alpha\\varphi_{k-1}' - \\varphi_{k-1} = R_{k-1} + f - 2\\varphi_{k-1}`,
solved here interval by interval by Chebyshev collocation (spectral accuracy, no
derivative of data is ever taken). :math:`y(2k + \\tau) = \\int_{t-2}^{t}\\varphi`.
Nothing here uses the Laplace series or Laguerre functions of the package.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev as cheb
from scipy.linalg import lu_factor, lu_solve


def _cheb(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev-Lobatto points on [-1, 1] (descending) and differentiation matrix."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.r_[2.0, np.ones(n - 1), 2.0] * (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :]
    D = np.outer(c, 1 / c) / (dx + np.eye(n + 1))
    D -= np.diag(D.sum(axis=1))
    return x, D


class Characteristics:
    """Rigid-contact :math:`N(t)` and :math:`y(t)` from the neutral delay equation."""

    def __init__(self, alpha: float, f: float, n_intervals: int, n: int = 200) -> None:
        x, D = _cheb(n)
        A = alpha * D + np.eye(n + 1)  # x = tau - 1; the last node is tau = 0
        A[n, :] = 0.0
        A[n, n] = 1.0
        lu = lu_factor(A)
        to_coef = np.linalg.inv(cheb.chebvander(x, n))  # values at the nodes -> series
        phis, R, start = [], np.zeros(n + 1), 1.0
        for _ in range(n_intervals):
            rhs = f + R
            rhs[n] = start
            phi = lu_solve(lu, rhs)
            phis.append(phi)
            R = R + f - 2.0 * phi
            start = phi[0] + 1.0  # the jump of phi at the next reflection
        self.coef = [to_coef @ p for p in phis]
        self.icoef = [cheb.chebint(c, lbnd=-1) for c in self.coef]

    def _phi(self, k: int, tau: float) -> float:
        return float(cheb.chebval(tau - 1.0, self.coef[k])) if k >= 0 else 0.0

    def _Phi(self, k: int, tau: float) -> float:
        return float(cheb.chebval(tau - 1.0, self.icoef[k])) if k >= 0 else 0.0

    def N(self, t: np.ndarray) -> np.ndarray:
        k = np.floor(np.asarray(t) / 2).astype(int)
        tau = np.asarray(t) - 2 * k
        return np.array(
            [self._phi(i, x) + self._phi(i - 1, x) for i, x in zip(k, tau, strict=True)]
        )

    def y(self, t: np.ndarray) -> np.ndarray:
        k = np.floor(np.asarray(t) / 2).astype(int)
        tau = np.asarray(t) - 2 * k
        return np.array(
            [
                self._Phi(i - 1, 2.0) - self._Phi(i - 1, x) + self._Phi(i, x)
                for i, x in zip(k, tau, strict=True)
            ]
        )


def _flight_step(u, y, v, gi0, gi1, h, accel):
    """One step of the flight: the free end :math:`u' = -2 g_i` (trapezoidal, exact for
    a linearly interpolated :math:`g_i`), the striker under the constant acceleration
    :math:`f/\\alpha`; returns ``(u, y, v)``."""
    return u - h * (gi0 + gi1), y + v * h + 0.5 * accel * h * h, v + accel * h


class _Grid:
    """What the grid references share: the wave ``g`` on the times ``t``."""

    t: np.ndarray
    g: np.ndarray

    def fixed_end_stress(self, t: np.ndarray) -> np.ndarray:
        """:math:`\\sigma(1, t) = 2 g(t - 1)`, linear interpolation on the grid."""
        s = np.asarray(t) - 1.0
        return np.where(s < 0, 0.0, 2 * np.interp(s, self.t, self.g))


class UnilateralGrid(_Grid):
    """Rigid rod impact with separation and re-contact on a uniform grid (reference).

    The same characteristics, written for the striker velocity instead of the wave:
    with the incoming wave :math:`g_i(t) = g(t - 2)` (stored on the grid, zero before
    the impact), in contact :math:`\\alpha v' = f - N`, :math:`N = v + 2 g_i`, and the
    outgoing wave is :math:`g = v + g_i`; in flight :math:`g = -g_i`, the free end moves
    with :math:`u' = -2 g_i` and the striker with :math:`v' = f/\\alpha`. Each step is the
    exact exponential integrator for a linearly interpolated :math:`g_i`; contact ends at
    the step where :math:`N < 0`, resumes at the step where :math:`u < y`, the event time
    interpolated linearly. First order in the step at the jumps of :math:`g_i`; no
    polynomial, no root isolation.
    """

    def __init__(self, alpha: float, f: float, t_end: float, steps_per_transit: int = 2000):
        h = 1.0 / steps_per_transit
        lag = 2 * steps_per_transit
        n = round(t_end / h)
        g = np.zeros(n + 1 + lag)  # g[k + lag] = g(k h)
        E = np.exp(-h / alpha)
        v, y, u = 1.0, 0.0, 0.0
        g[lag] = 1.0
        contact, start = True, 0.0
        self.contacts, self.separation_speeds = [], []
        self.t = h * np.arange(n + 1)
        self.v = np.empty(n + 1)
        self.v[0] = 1.0
        for k in range(n):
            gi0, gi1 = g[k], g[k + 1]
            if contact:
                c0, slope = f - 2 * gi0, -2 * (gi1 - gi0) / h
                v_new = v * E + c0 * (1 - E) + slope * (h - alpha * (1 - E))
                N0, N1 = v + 2 * gi0, v_new + 2 * gi1
                if N1 < 0.0:
                    te = k * h + h * N0 / (N0 - N1) if N0 > 0 else k * h
                    self.contacts.append((start, te))
                    self.separation_speeds.append(v + (v_new - v) * (te - k * h) / h)
                    contact = False
                    u += 0.5 * h * (v + v_new)
                    y, v = u, v_new
                    g[k + 1 + lag] = -gi1
                else:
                    u += 0.5 * h * (v + v_new)
                    y, v = u, v_new
                    g[k + 1 + lag] = v + gi1
            else:
                gap0 = u - y
                u, y, v = _flight_step(u, y, v, gi0, gi1, h, f / alpha)
                gap1 = u - y
                if gap1 < 0.0:
                    start = k * h + h * gap0 / (gap0 - gap1)
                    contact = True
                    y = u
                    g[k + 1 + lag] = v + gi1
                else:
                    g[k + 1 + lag] = -gi1
            self.v[k + 1] = v
        if contact:
            self.contacts.append((start, t_end))
        self.g = g[lag:]


class SpringGrid(_Grid):
    """Rod impact through a massless contact spring ``kappa``, with separation and
    re-contact, on a uniform grid (reference for :mod:`impactsym.rod.sequence_elastic`).

    The characteristics as in :class:`UnilateralGrid`, with the spring compression
    :math:`z = y - u` (contact while :math:`N = \\kappa z > 0`): in contact
    :math:`\\alpha v' = f - N`, :math:`N' = \\kappa (v - N + 2 g_i)`, :math:`u' = N - 2 g_i`
    and the outgoing wave is :math:`g = N - g_i`; in flight :math:`g = -g_i`,
    :math:`u' = -2 g_i`, :math:`v' = f/\\alpha`. A contact step is the exact solution of
    this linear system for a linearly interpolated :math:`g_i` (the matrix exponential of
    the system augmented by :math:`1, g_i, g_i'`, computed once by
    ``scipy.linalg.expm``); contact ends at the step where :math:`N < 0`, resumes where
    :math:`u < y`, the event time interpolated linearly and the step's end state kept.
    First order in the step at the events; no polynomial, no root isolation, no
    Laplace transform.
    """

    def __init__(
        self, alpha: float, f: float, kappa: float, t_end: float, steps_per_transit: int = 4000
    ):
        from scipy.linalg import expm

        h = 1.0 / steps_per_transit
        lag = 2 * steps_per_transit
        n = round(t_end / h)
        # state (v, N, u, 1, g_i, g_i'): constant coefficients
        A = np.zeros((6, 6))
        A[0, 1], A[0, 3] = -1.0 / alpha, f / alpha
        A[1, 0], A[1, 1], A[1, 4] = kappa, -kappa, 2.0 * kappa
        A[2, 1], A[2, 4] = 1.0, -2.0
        A[4, 5] = 1.0
        E = expm(A * h)
        g = np.zeros(n + 1 + lag)  # g[k + lag] = g(k h)
        v, N, y, u = 1.0, 0.0, 0.0, 0.0
        contact, start = True, 0.0
        self.contacts, self.separation_speeds = [], []
        self.t = h * np.arange(n + 1)
        for k in range(n):
            gi0, gi1 = g[k], g[k + 1]
            if contact:
                v1, N1, u1 = (E @ np.array([v, N, u, 1.0, gi0, (gi1 - gi0) / h]))[:3]
                if N1 < 0.0:
                    te = k * h + h * N / (N - N1) if N > 0 else k * h
                    self.contacts.append((start, te))
                    self.separation_speeds.append(v + (v1 - v) * (te - k * h) / h)
                    contact = False
                    v, N, u, y = v1, 0.0, u1, u1
                    g[k + 1 + lag] = -gi1
                else:
                    v, N, u = v1, N1, u1
                    y = u + N / kappa
                    g[k + 1 + lag] = N - gi1
            else:
                gap0 = u - y
                u, y, v = _flight_step(u, y, v, gi0, gi1, h, f / alpha)
                gap1 = u - y
                if gap1 < 0.0:
                    start = k * h + h * gap0 / (gap0 - gap1)
                    contact = True
                    y, N = u, 0.0
                g[k + 1 + lag] = -gi1
        if contact:
            self.contacts.append((start, t_end))
        self.g = g[lag:]
