"""Independent reference for the rigid rod impact sequence: the delay equation in mpmath.

The outgoing wave :math:`g` (``N = g(t) + g(t - 2)``, striker velocity
:math:`y' = g(t) - g(t - 2)` in contact) obeys
:math:`\\alpha g'(t) + g(t) = f + \\alpha g'(t-2) - g(t-2)` in contact and
:math:`g(t) = -g(t - 2)` in flight, where :math:`\\alpha y'' = f` and the rod end moves with
:math:`u' = -2 g(t - 2)`. Solved piece by piece by the method of steps in 40-digit
arithmetic, each piece :math:`p + e^{-x} Q(x)` (:math:`x = (s - s_0)/\\alpha`) with the
variation-of-constants solution written out for the incoming piece. Events are found by
sampling the contact force (contact) or the gap :math:`u - y` (flight) on a uniform grid
refined geometrically towards the piece start, then bisected to 1e-30: no float64, no
certificate, no root isolation, no antiderivative carried over between pieces, no piece
length cap. A tangency (a double root) between samples would be missed; the cases
tested have none.
"""

from __future__ import annotations

import mpmath as mp

_SAMPLES = 100
_GEOMETRIC = 30


def _shift(Q: list, d) -> list:
    """Coefficients of :math:`e^{-d} Q(x + d)`."""
    n = len(Q)
    out = [mp.fsum(mp.binomial(k, i) * Q[k] * d ** (k - i) for k in range(i, n)) for i in range(n)]
    e = mp.exp(-d)
    return [e * c for c in out]


def _val(Q: list, x):
    return mp.polyval(Q[::-1], x) if Q else mp.mpf(0)


def _exp_integral(Q: list, x):
    """:math:`\\int_0^x e^{-s} Q(s) ds = R(0) - e^{-x} R(x)`, :math:`R = \\sum_j Q^{(j)}`."""
    R, D = [mp.mpf(0)] * len(Q), list(Q)
    while D:
        R = [r + c for r, c in zip(R, D + [mp.mpf(0)] * (len(R) - len(D)), strict=True)]
        D = [k * D[k] for k in range(1, len(D))]
    return _val(R, 0) - mp.exp(-x) * _val(R, x)


def _first_sign_change(F, X):
    """First x in (0, X] with F(x) <= 0 after F > 0, by sampling and bisection."""
    xs = sorted(
        {X * mp.mpf(2) ** -k for k in range(_GEOMETRIC, 0, -1)}
        | {X * mp.mpf(k) / _SAMPLES for k in range(1, _SAMPLES + 1)}
    )
    lo = mp.mpf(0)
    for x in xs:
        if F(x) <= 0:
            hi = x
            for _ in range(200):
                if hi - lo < mp.mpf(10) ** -30:
                    break
                mid = (lo + hi) / 2
                lo, hi = (mid, hi) if F(mid) > 0 else (lo, mid)
            return hi
        lo = x
    return None


class SequenceMP:
    """``contacts`` and ``separation_velocities`` of one rigid-contact sequence to ``t_max``."""

    def __init__(self, alpha: float, f: float, t_max: float, dps: int = 40) -> None:
        with mp.workdps(dps):
            self._run(mp.mpf(alpha), mp.mpf(f), mp.mpf(t_max))

    def _run(self, a, f, T) -> None:
        pieces = [(mp.mpf(-2), mp.mpf(0), [])]  # (start, p, Q): at rest before the impact
        t, v, y, u = mp.mpf(0), mp.mpf(1), mp.mpf(0), mp.mpf(0)
        contact, start = True, mp.mpf(0)
        self.contacts, self.separation_velocities = [], []
        j = 0
        while t < T:
            while j + 1 < len(pieces) and pieces[j + 1][0] + 2 <= t:
                j += 1
            s_i, p_i, Q_i = pieces[j]
            Q_i = _shift(Q_i, (t - 2 - s_i) / a) if Q_i else []
            t_next = min((pieces[j + 1][0] if j + 1 < len(pieces) else t) + 2, T)
            X = (t_next - t) / a
            if contact:
                p = f - p_i
                q0 = Q_i[0] if Q_i else mp.mpf(0)
                integ = [mp.mpf(0)] + [c / (k + 1) for k, c in enumerate(Q_i)]
                Q = [v + p_i + q0 - p] + [mp.mpf(0)] * len(Q_i)
                for k, c in enumerate(Q_i):
                    Q[k] += c
                Q[0] -= q0
                for k, c in enumerate(integ):
                    Q[k] -= 2 * c

                def N(x, Q=Q, Q_i=Q_i):
                    return f + mp.exp(-x) * (_val(Q, x) + _val(Q_i, x))

                # a tensile front arriving makes N jump below zero: separation at once
                root = mp.mpf(0) if N(0) < 0 else _first_sign_change(N, X)
                x = X if root is None else root
                if x > 0:
                    pieces.append((t, p, Q))
                diff = [c - (Q_i[k] if k < len(Q_i) else 0) for k, c in enumerate(Q)]
                v = p - p_i + mp.exp(-x) * _val(diff, x)
                y += a * ((p - p_i) * x + _exp_integral(diff, x))
                u = y
                t = t_next if root is None else t + a * x
                if root is not None:
                    self.contacts.append((start, t))
                    self.separation_velocities.append(v)
                    contact = False
            else:
                t0, v0, y0, u0 = t, v, y, u

                def gap(x, Q_i=Q_i, p_i=p_i, t0=t0, v0=v0, y0=y0, u0=u0):
                    tau = a * x
                    uu = u0 - 2 * a * (p_i * x + _exp_integral(Q_i, x))
                    return uu - (y0 + v0 * tau + f / (2 * a) * tau**2)

                root = _first_sign_change(gap, X)
                x = X if root is None else root
                pieces.append((t, -p_i, [-c for c in Q_i]))
                tau = a * x
                u = u0 - 2 * a * (p_i * x + _exp_integral(Q_i, x))
                y = y0 + v0 * tau + f / (2 * a) * tau**2
                v = v0 + f / a * tau
                t = t_next if root is None else t + tau
                if root is not None:
                    y = u
                    contact, start = True, t
        if contact:
            self.contacts.append((start, T))
        self.contacts = [(float(s), float(e)) for s, e in self.contacts]
        self.separation_velocities = [float(w) for w in self.separation_velocities]
