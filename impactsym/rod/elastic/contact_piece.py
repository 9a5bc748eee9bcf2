r"""One contact piece of the rod impact sequence with a contact spring: the contact force
:math:`N` solving :math:`\alpha N'' + \alpha\kappa N' + \kappa N = \kappa f + 2\alpha\kappa G'`
for an incoming wave :math:`G = \sum_r e^{rx} Q_r(x)` over the rates of
:math:`\alpha s^2 + \alpha\kappa s + \kappa` (the resonant per-rate particular solution of a
stiff contact, or the exact Taylor recurrence of the confluent form). Internal: used by
:mod:`impactsym.rod.sequence_elastic`; derivation and accuracy:
docs/physics.md#the-rod-impact-continued-past-separation.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.poly import antiderivative, derivative

__all__ = ["confluent_series", "forced_split"]

_TAIL = 1e-18  # truncation of the confluent series, relative to its size on the piece
_MAX_COEFFICIENTS = 95  # taylor_shift's limit


def forced_split(Qi, rates, *, alpha, kappa):
    r"""Per-rate polynomials ``M_r`` (``M_r(0) = 0``) of the particular solution of
    :math:`\alpha N'' + \alpha\kappa N' + \kappa N = 2\alpha\kappa G'` (two distinct
    rates) and :math:`\sum_r M_r'(0)`."""
    nr = rates.size
    if Qi.shape[-1] == 0:
        return np.zeros((nr, 0), dtype=complex), 0.0
    W = 2.0 * kappa * (rates[:, None] * Qi + derivative(Qi))
    m = np.zeros_like(W)
    c = (rates - rates[::-1])[:, None]  # P'(r) / alpha
    D = W.copy()
    for k in range(W.shape[-1]):  # m' + c m = W: m = sum_k (-1)^k W^(k) / c^(k+1)
        m += (-1.0) ** k * D / c ** (k + 1)
        D = derivative(D)
    M = antiderivative(m)
    return M, float(M[:, 1].sum().real)


def confluent_series(Qi, sigma, d, *, kappa, h, A0, dN, where, t):
    r"""Taylor coefficients of :math:`M` in :math:`N = f + e^{\sigma x} M(x)` (confluent
    form): :math:`M'' - d M = 2\kappa(\sigma Q_i + Q_i')`, :math:`M(0) = N(0) - f`,
    :math:`M'(0) = N'(0) - \sigma M(0)`.

    The recurrence :math:`m_{k+2} = (d m_k + F_k)/((k+1)(k+2))` is exact; past the
    forcing it is homogeneous, :math:`|m_{k+2}| h^{k+2} \le q |m_k| h^k` with
    :math:`q = |d| h^2/((k+1)(k+2))`, so the series is cut where its last two terms on
    :math:`[0, h]` are below ``_TAIL`` of its size (the rest is below twice that)."""
    sigma = sigma.real
    n = Qi.shape[-1]
    F = 2.0 * kappa * (sigma * Qi[0].real + derivative(Qi[0].real)) if n else np.zeros(0)
    m = [A0, dN - sigma * A0]
    size = abs(m[0]) + abs(m[1]) * h
    k = 0
    while True:
        K = k + 2
        term = (d * m[k] + (F[k] if k < n else 0.0)) / ((k + 1) * (k + 2))
        m.append(term)
        size += abs(term) * h**K
        last = abs(m[K]) * h**K + abs(m[K - 1]) * h ** (K - 1)
        q = abs(d) * h * h / ((K + 1) * (K + 2))
        if n + 1 <= K and q <= 0.5 and last <= _TAIL * max(size, 1.0):
            break
        if K + 1 >= _MAX_COEFFICIENTS:
            raise ValueError(
                f"{where}: the confluent series at t = {t:.6g} needs more than "
                f"{_MAX_COEFFICIENTS} coefficients; lower t_max"
            )
        k += 1
    return np.array(m, dtype=complex)[None, :]
