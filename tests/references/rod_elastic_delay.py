"""Independent reference for the rod impact with a finite contact stiffness: a delay ODE.

With d'Alembert's solution :math:`w(\\xi, t) = F(t - \\xi) - F(t + \\xi - 2)` (fixed at
:math:`\\xi = 1`, at rest for :math:`t < 0`) and :math:`\\varphi = F'`, the rod end moves
as :math:`w_0 = F(t) - F(t - 2)` and carries the force :math:`N = -w_\\xi(0, t) =
\\varphi(t) + \\varphi(t - 2)`; the contact spring gives :math:`N = \\kappa (y - w_0)` and
the striker :math:`\\alpha y'' = f - N`, :math:`y(0) = 0`, :math:`y'(0) = 1`. So on each
reflection interval :math:`[2j, 2j + 2]` the state :math:`(y, y', F)` obeys the ODE

.. math::

    F' = \\kappa (y - F + F(t - 2)) - \\varphi(t - 2), \\qquad
    \\alpha y'' = f - \\kappa (y - F + F(t - 2)),

with the delayed values from the interval before (method of steps). It is integrated
with SciPy's DOP853 at ``rtol = 1e-13`` and the first sign change of :math:`N` or
:math:`y` is located by its event detection. Nothing here uses the Laplace series, the
poles or the cell tables of the package.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp


class ElasticDelay:
    """``y``, ``N`` and the first sign change for one ``(alpha, f, kappa)``."""

    def __init__(self, alpha: float, f: float, kappa: float, t_max: float = 20.0) -> None:
        self.alpha, self.f, self.kappa, self.t_max = alpha, f, kappa, t_max
        self.pieces: list = []  # dense outputs of (y, v, F) per interval
        state = np.array([0.0, 1.0, 0.0])
        j = 0
        while 2.0 * j < t_max:
            lo, hi = 2.0 * j, min(2.0 * j + 2.0, t_max)
            sol = solve_ivp(
                self._rhs,
                (lo, hi),
                state,
                method="DOP853",
                rtol=1e-13,
                atol=1e-15,
                dense_output=True,
                max_step=min(0.05, 0.5 / kappa),
            )
            if not sol.success:  # pragma: no cover
                raise RuntimeError(sol.message)
            self.pieces.append(sol.sol)
            state = sol.y[:, -1]
            j += 1

    def _F(self, t: float) -> float:
        if t <= 0.0:
            return 0.0
        j = min(int(t // 2.0), len(self.pieces) - 1)
        return float(self.pieces[j](t)[2])

    def _phi(self, t: float) -> float:
        """``phi = F'`` from the state, recursively through the delays."""
        if t <= 0.0:
            return 0.0
        j = min(int(t // 2.0), len(self.pieces) - 1)
        y, _, F = self.pieces[j](t)
        return self.kappa * (y - F + self._F(t - 2.0)) - self._phi(t - 2.0)

    def _rhs(self, t, state):
        y, v, F = state
        N = self.kappa * (y - F + self._F(t - 2.0))
        return [v, (self.f - N) / self.alpha, N - self._phi(t - 2.0)]

    def N(self, t: float) -> float:
        j = min(int(t // 2.0), len(self.pieces) - 1)
        y, _, F = self.pieces[j](t)
        return float(self.kappa * (y - F + self._F(t - 2.0)))

    def y(self, t: float) -> float:
        j = min(int(t // 2.0), len(self.pieces) - 1)
        return float(self.pieces[j](t)[0])

    def contact_time(self, condition: str, n_samples: int = 4000) -> float:
        """First sign change (``+`` to ``<= 0``) of ``N`` or ``y`` in ``(0, t_max]``:
        dense samples (``n_samples`` per reflection interval, after the start-up
        ``0 < t <= 1e-3 / kappa``) refined by bisection on the dense output."""
        g = self.N if condition == "force" else self.y
        t = np.unique(
            np.concatenate(
                [
                    np.linspace(1e-6 / self.kappa, 2.0 * j + 2.0, n_samples)[
                        np.linspace(1e-6 / self.kappa, 2.0 * j + 2.0, n_samples) > 2.0 * j
                    ]
                    for j in range(len(self.pieces))
                ]
                + [np.linspace(1e-6 / self.kappa, 3.0 / self.kappa, 200)]
            )
        )
        t = t[t <= self.t_max]
        values = np.array([g(x) for x in t])
        below = np.flatnonzero(values <= 0.0)
        if below.size == 0:
            return float("inf")
        lo, hi = t[below[0] - 1], t[below[0]]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if g(mid) > 0.0:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)
