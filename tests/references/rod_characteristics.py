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
