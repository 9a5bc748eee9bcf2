"""Independent reference for the rod impact sequence with a contact spring: a Taylor
method of steps on the delay ODE of d'Alembert's solution, in 30-digit decimal arithmetic.

With :math:`w(\\xi, t) = F(t - \\xi) - F(t + \\xi - 2)` (fixed at :math:`\\xi = 1`, at
rest for :math:`t < 0`) and :math:`\\varphi = F'`, the rod end moves as
:math:`u = F(t) - F(t - 2)` and carries the force :math:`\\varphi(t) + \\varphi(t - 2)`.
In contact (:math:`z = y - u > 0`) the spring gives :math:`N = \\kappa z` and

.. math::

    y' = v, \\qquad \\alpha v' = f - N, \\qquad F' = N - \\varphi(t - 2);

in flight :math:`N = 0`, :math:`F' = -\\varphi(t - 2)`, :math:`\\alpha v' = f`. On every
step the delayed :math:`F(t - 2)` is a stored Taylor polynomial (steps are cut where a
stored step arrives two time units later, so each delayed step is one polynomial), and the
linear recurrence of the Taylor coefficients is exact; steps are at most ``0.7/kappa``
long with 26 coefficients (remainder below ``1e-26``), in 30-digit arithmetic. Events
(sign changes of :math:`N` in contact, of :math:`z` in flight) are screened on 64 points
of each step and refined by bisection to 30 digits (Python's :mod:`decimal`, exactly
rounded and fast enough for thousands of steps). The energy
:math:`\\alpha v^2/2 + N^2/(2\\kappa) + \\int_{t-2}^t \\varphi^2 - f y - \\alpha/2` is
integrated exactly from the coefficients. Nothing here uses the exponential-polynomial
pieces, the rates or the certification of the package.
"""

from __future__ import annotations

from decimal import Decimal, localcontext

import numpy as np

_DPS = 30
_ZERO = Decimal(0)
_DEGREE = 26


def _shift(c: list, delta) -> list:
    """Coefficients of ``p(x + delta)`` from those of ``p`` (Horner, exact order)."""
    if delta == 0:
        return list(c)
    out = list(c)
    n = len(out)
    for i in range(n - 1):
        for k in range(n - 2, i - 1, -1):
            out[k] += delta * out[k + 1]
    return out


def _value(c: list, x):
    out = _ZERO
    for ck in reversed(c):
        out = out * x + ck
    return out


def _derivative(c: list) -> list:
    return [c[k] * k for k in range(1, len(c))] + [_ZERO]


class SpringSteps:
    """The sequence for one ``(alpha, f, kappa)`` up to ``t_max``: ``contacts`` (start,
    end) as Decimal, ``separation_velocities``, ``balance`` (energy residual at ``t_max``)
    and :meth:`stress` (fixed-end stress :math:`2\\varphi(t - 1)`)."""

    def __init__(self, alpha: float, f: float, kappa: float, t_max: float) -> None:
        with localcontext(prec=_DPS):
            self._run(Decimal(alpha), Decimal(f), Decimal(kappa), Decimal(t_max))

    def _delayed(self, t):
        """Taylor coefficients of ``F`` about ``t - 2`` (zero before the impact)."""
        s = t - 2
        if s < 0:
            return [_ZERO] * _DEGREE
        # compared in the time of arrival (start + 2), as the breaks are
        while self._j + 1 < len(self.steps) and self.steps[self._j + 1][0] + 2 <= t:
            self._j += 1
        a, _, c, _ = self.steps[self._j]
        return _shift(c, s - a)

    def _next_break(self, t):
        """The next arrival (step start + 2) after ``t``."""
        k = self._j
        while k < len(self.steps) and self.steps[k][0] + 2 <= t:
            k += 1
        return self.steps[k][0] + 2 if k < len(self.steps) else Decimal("Infinity")

    def _run(self, alpha, f, kappa, t_max) -> None:
        D = _DEGREE
        # |r| <= max(kappa, sqrt(kappa / alpha)) for the roots of alpha s^2 + alpha kappa s + kappa
        hmax = min(Decimal("0.7") / max(kappa, (kappa / alpha).sqrt()), Decimal("0.05"))
        self.steps = []  # (start, end, F coefficients, contact)
        self._j = 0
        self.contacts, self.separation_velocities = [], []
        t, y, v, F, contact, start = _ZERO, _ZERO, Decimal(1), _ZERO, True, _ZERO
        while t < t_max:
            Fd = self._delayed(t)
            Pd = _derivative(Fd)
            b = min(t + hmax, t_max, self._next_break(t))
            h = b - t
            Y, V, Fc = [y] + [_ZERO] * (D - 1), [v] + [_ZERO] * (D - 1), [F] + [_ZERO] * (D - 1)
            if contact:
                Nc = [_ZERO] * D
                for k in range(D - 1):
                    Nc[k] = kappa * (Y[k] - Fc[k] + Fd[k])
                    Y[k + 1] = V[k] / (k + 1)
                    V[k + 1] = ((f if k == 0 else _ZERO) - Nc[k]) / (alpha * (k + 1))
                    Fc[k + 1] = (Nc[k] - Pd[k]) / (k + 1)
                Nc[D - 1] = kappa * (Y[D - 1] - Fc[D - 1] + Fd[D - 1])
                event = Nc  # contact ends where N falls to zero
            else:
                Y[1], Y[2] = v, f / (2 * alpha)
                V[1] = f / alpha
                for k in range(D - 1):
                    Fc[k + 1] = -Pd[k] / (k + 1)
                event = [Y[k] - Fc[k] + Fd[k] for k in range(D)]  # z: flight ends at z = 0
                event = [-c for c in event]  # sign change + to <= 0 of -z
            x_end = self._first_change(event, h)
            X = h if x_end is None else x_end
            self.steps.append((t, t + X, Fc, contact))
            y, v, F = _value(Y, X), _value(V, X), _value(Fc, X)
            t = t + X
            if x_end is not None:
                if contact:
                    self.contacts.append((start, t))
                    self.separation_velocities.append(v)
                else:
                    start = t
                contact = not contact
        if contact:
            self.contacts.append((start, t_max))
        self.t_max = t_max
        self.alpha, self.f, self.kappa = alpha, f, kappa
        self._final = (y, v, contact)
        self.balance = self._balance()

    @staticmethod
    def _first_change(c: list, h):
        """First ``x`` in ``(0, h]`` where the polynomial ``c`` goes from ``> 0`` to
        ``<= 0`` (screened in float64 on 64 points, confirmed in decimal, refined by
        bisection), or ``None``."""
        xs = np.linspace(0.0, float(h), 65)[1:]
        screen = np.polynomial.polynomial.polyval(xs, np.array([float(ck) for ck in c]))
        below = np.flatnonzero(screen <= 1e-25 * np.abs(screen).max(initial=1.0))
        lo = _ZERO
        for i in range(64) if below.size else ():
            x = h * (i + 1) / 64
            if _value(c, x) <= 0:
                a, b = lo, x
                for _ in range(100):
                    mid = (a + b) / 2
                    if _value(c, mid) > 0:
                        a = mid
                    else:
                        b = mid
                return b
            lo = x
        return None

    def _phi(self, s):
        """``phi(s) = F'(s)`` (right limit at a step start)."""
        if s < 0:
            return _ZERO
        lo, hi = 0, len(self.steps) - 1
        while lo < hi:  # last step with start <= s
            mid = (lo + hi + 1) // 2
            if self.steps[mid][0] <= s:
                lo = mid
            else:
                hi = mid - 1
        a, _, c, _ = self.steps[lo]
        return _value(_derivative(c), s - a)

    def stress(self, t: float) -> float:
        """Fixed-end stress :math:`2\\varphi(t - 1)`."""
        with localcontext(prec=_DPS):
            return float(2 * self._phi(Decimal(t) - 1))

    def _balance(self):
        """Energy residual at ``t_max`` (exact integrals of the stored coefficients)."""
        y, v, contact = self._final
        t = self.t_max
        rod = _ZERO
        for a, b, c, _ in self.steps:
            lo, hi = max(a, t - 2), min(b, t)
            if hi <= lo:
                continue
            p = _derivative(c)
            sq = [_ZERO] * (2 * len(p))
            for i, pi in enumerate(p):
                for j, pj in enumerate(p):
                    sq[i + j] += pi * pj
            integral = [_ZERO] + [sq[k] / (k + 1) for k in range(len(sq))]
            rod += _value(integral, hi - a) - _value(integral, lo - a)
        N = _ZERO
        if contact:
            N = self._phi(t - Decimal("1e-25")) + self._phi(t - 2 - Decimal("1e-25"))
        return float(
            self.alpha * v * v / 2 + N * N / (2 * self.kappa) + rod - self.f * y - self.alpha / 2
        )
