r"""The rod impact continued past separation: contact, flight and re-contact, rigid contact.

Normalized variables of paper section 1 (:math:`\xi = x/L`, :math:`t` in :math:`L/c`).
d'Alembert's solution with the fixed end :math:`\xi = 1` and the rod at rest before the
impact is

.. math::

    w(\xi, t) = \phi(t - \xi) - \phi(t + \xi - 2), \qquad g = \phi', \quad g(s) = 0
    \ (s < 0),

so at the struck end :math:`u = w(0, t) = \phi(t) - \phi(t - 2)`,
:math:`u' = g(t) - g(t - 2)`, the contact force :math:`N = -w_\xi(0, t) = g(t) + g(t-2)`
and the stress at the fixed end (compression positive)
:math:`\sigma(1, t) = -w_\xi(1, t) = 2 g(t - 1)`. Everything follows from the outgoing
wave :math:`g`:

* **contact** (:math:`y = u`, :math:`\alpha y'' = f - N`): the neutral delay equation
  :math:`\alpha g'(t) + g(t) = f + \alpha g'(t-2) - g(t-2)`; :math:`y'` is continuous, so
  :math:`g` jumps with the incoming wave and at a (re-)contact it starts from
  :math:`g(t^+) = y'(t) + g(t-2)`;
* **flight** (free end, :math:`N = 0`): :math:`g(t) = -g(t-2)`, the striker moves as
  :math:`y'' = f/\alpha`;
* contact ends where :math:`N` falls to zero, continuously or by a jump below zero
  (a tensile front arriving); it resumes where the gap :math:`u - y` closes.

**Representation (exact, piecewise).** On each piece :math:`[s_0, s_0 + h]` of retarded
time, :math:`g(s) = p + e^{-x} Q(x)` with :math:`x = (s - s_0)/\alpha`, a constant
:math:`p` and a polynomial :math:`Q` (float64 coefficients, stored per piece). The family
is closed under the delay equation: with the incoming piece :math:`p_i + e^{-x} Q_i(x)`,

.. math::

    p = f - p_i, \qquad Q(x) = Q(0) + Q_i(x) - Q_i(0) - 2 \int_0^x Q_i, \qquad
    N = f + e^{-x} \bigl(Q(x) + Q_i(x)\bigr),

and in flight :math:`p = -p_i`, :math:`Q = -Q_i`. Pieces are cut where an incoming piece
ends, at events and at :math:`x = 2` (``_X_MAX``), so that no polynomial is evaluated
far from its origin, where its monomials would cancel: the piece-local origin replaces
high-precision arithmetic. The polynomials reach degree ~20 by :math:`t = 40` with
alternating coefficients up to ~:math:`10^3`, so float64 keeps 11-13 digits: in the
tested cases (:math:`\alpha` from 0.05 to 20, :math:`f \le 1`, to :math:`t = 40`) the
energy balance holds to :math:`10^{-10}` of :math:`\max(\alpha/2 + f|y|, 1)` and the
striker position accumulated through the flights meets the rod end computed from the
wave to :math:`10^{-11}` at every re-contact. The degree grows by about one per round
trip, and while the striker keeps returning the cancellation wins after some tens of
transits (the antiderivatives :math:`\sum_j Q^{(j)}` are summed from the top, which
keeps :math:`\alpha = 10, f = 5` balanced to :math:`10^{-12}` at :math:`t = 100`, where
summing derivative by derivative was off by 89; a heavy pressed striker,
:math:`\alpha = 40, f = 2`, is still lost near :math:`t = 258`). So
:func:`impact_sequence` checks the energy
balance in the middle of every piece and refuses, naming ``alpha, f, t_end`` and the
time reached, where the residual exceeds :math:`10^{-9}` of :math:`\alpha/2 + |f y|`
(``_BALANCE_RTOL``): exact or refused, never silently wrong. An exponential part whose bound
on its piece is below :math:`10^{-17}` is dropped (it is below rounding). The evaluated integrals of
:math:`g` and :math:`g^2` (rod end position, rod energy) use Gauss-Legendre rules on
pieces of degree >= 1 (exact for the polynomial part) rather than the closed form,
whose repeated derivatives cancel for :math:`g^2`; the event loop advances the
positions with the closed form.

**Events, certified.** Separation is the first zero with sign change of
:math:`f e^x + Q(x) + Q_i(x)` on a contact piece, re-contact the first zero of the gap
:math:`e^x \bigl[(u_0 - y_0) - \alpha(2p_i + v_0)x - \tfrac{\alpha f}{2}x^2 - 2\alpha
P_i(0)\bigr] + 2\alpha P_i(x)` on a flight piece (:math:`P_i = \sum_j Q_i^{(j)}`,
:math:`\int_0^x e^{-x}Q_i = P_i(0) - e^{-x} P_i(x)`); both are exponential polynomials
:math:`e^x A + B`. Most pieces hold no event, and
:func:`impactsym.numeric.exppoly.exp_poly_positive` proves that without a search (a
one-sided bound of the Taylor series at the piece's start); the others are isolated by
:func:`impactsym.numeric.exppoly.exp_poly_roots` (Taylor enclosures: every sub-interval
is proven root-free or monotone) and polished by
:func:`impactsym.numeric.roots.bracketed_newton_scalar`. The pieces' polynomials are
lists of plain floats in the loop (NumPy's cost per call dominates at these sizes).

**Energy** (unit :math:`m_{rod} v_0^2`): striker :math:`\alpha y'^2/2`, work of the
pressing force :math:`f y`, rod :math:`\int_0^1 (w_t^2 + w_\xi^2)/2 \, d\xi =
\int_{t-2}^{t} g^2 \, ds`; :math:`\alpha/2 + f y = \alpha y'^2/2 + E_{rod}` at all times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import polynomial as npoly

from impactsym.numeric.exppoly import _trim, exp_poly_positive, exp_poly_roots, taylor_shift
from impactsym.validation import real_array

__all__ = ["RodImpactSequence", "RodSequenceEnergy", "impact_sequence"]

_X_MAX = 2.0  # longest piece in x = tau / alpha for a non-constant exponential part
_X_LONG = 40.0  # longest piece with a constant exponential polynomial (e^-40 ~ 4e-18)
_NEGLIGIBLE = 1e-17
_MAX_COEFFICIENTS = 96  # the 48-node Gauss rule below is exact to degree 95
# Gauss-Legendre rules for the integrals of g and g^2 on a piece, by the degree d of its
# Q: exact for the polynomial part of g^2 (degree 2d) with nodes to spare for the
# exponential factor on x <= 2 (48 nodes: exact to degree 95)
_GAUSS_BY_DEGREE = [
    (8, np.polynomial.legendre.leggauss(24)),
    (16, np.polynomial.legendre.leggauss(32)),
    (_MAX_COEFFICIENTS, np.polynomial.legendre.leggauss(48)),
]
# Largest energy-balance residual, relative to alpha/2 + |f y|, at which the float64
# pieces are still trusted (at piece starts); beyond it impact_sequence refuses.
_BALANCE_RTOL = 1e-9


def _exp_antiderivative(Q: list) -> list:
    """``R = sum_j Q^(j)``, so that :math:`\\int_0^x e^{-x'} Q = R(0) - e^{-x} R(x)`.

    Summed from the top, ``R_k = Q_k + (k + 1) R_{k+1}`` (the coefficients of ``R``
    are ``R_k = sum_j (k + j)!/k! Q_{k+j}``): every step adds one rounding, where summing
    the derivatives one after another lets the large factorial terms cancel. This order
    is what keeps long chattering sequences exact: measured, ``(10, 5)`` and ``(3, 1)``
    balance to ``1e-11`` at ``t = 100``, where the derivative-by-derivative sum was
    refused at ``t`` ~ 57 and 61.
    """
    R = list(Q)
    for k in range(len(R) - 2, -1, -1):
        R[k] += (k + 1) * R[k + 1]
    return R


_REUSE_ANTIDERIVATIVES = True  # see impact_sequence (a test switches it off)


def _horner(c, x: float) -> float:
    out = 0.0
    for ck in reversed(c):
        out = out * x + ck
    return out


def _bound_exp_part(Q, X: float) -> float:
    """Upper bound of :math:`|e^{-x} Q(x)|` on :math:`[0, X]`
    (:math:`x^k e^{-x}` is largest at :math:`x = k`)."""
    total = 0.0
    for k, c in enumerate(Q):
        if c == 0.0:
            continue
        peak = min(k, X)
        total += abs(c) * (math.exp(k * math.log(peak) - peak) if peak > 0 else 1.0)
    return total


@dataclass
class _Pieces:
    """Growing store of the pieces of the outgoing wave ``g`` (retarded time)."""

    alpha: float
    start: list = field(default_factory=list)
    p: list = field(default_factory=list)
    q: list = field(default_factory=list)

    def append(self, s0: float, h: float, p: float, Q: list) -> None:
        """Add the piece ``p + e^{-x} Q(x)`` (``Q`` a list of floats, lowest order first)
        on ``[s0, s0 + h]``."""
        while Q and Q[-1] == 0.0:
            Q = Q[:-1]
        if len(Q) > _MAX_COEFFICIENTS:
            raise ValueError(
                f"polynomial degree {len(Q) - 1} exceeds {_MAX_COEFFICIENTS - 1} at s = {s0!r}"
            )
        small = _NEGLIGIBLE * max(1.0, abs(p))
        if Q and abs(Q[0]) < small and _bound_exp_part(Q, h / self.alpha) < small:
            Q = []  # (the bound is at least |Q[0]|: the first test only saves its cost)
        if h <= 0.0:
            return
        if self.q and not Q and not self.q[-1] and self.p[-1] == p:
            return  # the constant piece before goes on (a piece ends where the next starts)
        self.start.append(s0)
        self.p.append(p)
        self.q.append(Q)


@dataclass(frozen=True)
class _Tables:
    """Padded arrays of the pieces for vectorized evaluation."""

    alpha: float
    start: np.ndarray
    p: np.ndarray
    q: np.ndarray  # (pieces, degree + 1)
    G1: np.ndarray  # int_{s_first}^{start} g
    G2: np.ndarray  # int_{s_first}^{start} g^2
    degree: np.ndarray  # of each piece's Q (0 also for Q = 0)

    @classmethod
    def build(cls, pieces: _Pieces, s_end: float) -> _Tables:
        a = pieces.alpha
        n = len(pieces.start)
        deg = max((len(q) for q in pieces.q), default=1)
        q = np.zeros((n, max(deg, 1)))
        for i, Q in enumerate(pieces.q):
            q[i, : len(Q)] = Q
        start = np.array(pieces.start)
        p = np.array(pieces.p)
        h = np.diff(np.r_[start, s_end])
        degree = np.array([max(len(Q) - 1, 0) for Q in pieces.q])
        tab = cls(a, start, p, q, np.zeros(n), np.zeros(n), degree)
        i1, i2 = tab._partial(np.arange(n), h)
        tab.G1[1:] = np.cumsum(i1)[:-1]
        tab.G2[1:] = np.cumsum(i2)[:-1]
        return tab

    def _partial(self, i, tau):
        """Integrals of ``g`` and ``g^2`` over ``[start_i, start_i + tau]``.

        Closed form for pieces with a constant ``Q`` (the only ones longer than
        ``_X_MAX``); Gauss-Legendre otherwise, with 24 to 48 nodes by the degree of
        ``Q`` (``_GAUSS_BY_DEGREE``: exact for the polynomial part, and the exponential
        factor on ``x <= 2`` is resolved to rounding), which avoids the large
        derivatives of the closed form.
        """
        a = self.alpha
        i, tau = np.broadcast_arrays(np.asarray(i), np.asarray(tau, dtype=float))
        x = tau / a
        p, q0 = self.p[i], self.q[i, 0]
        e1 = -np.expm1(-x)
        e2 = -np.expm1(-2.0 * x)
        int1 = a * (p * x + q0 * e1)
        int2 = a * (p * p * x + 2.0 * p * q0 * e1 + 0.5 * q0 * q0 * e2)
        degree = self.degree[i]
        if np.any(degree > 0):
            int1 = np.array(int1, dtype=float).ravel()
            int2 = np.array(int2, dtype=float).ravel()
            flat_i, flat_x, flat_d = np.ravel(i), np.ravel(x), np.ravel(degree)
            low = 0
            for top, (z, weight) in _GAUSS_BY_DEGREE:  # nodes enough for the degree
                k = np.flatnonzero((flat_d > low) & (flat_d <= top))
                low = top
                if k.size == 0:
                    continue
                ii, xx = flat_i[k], flat_x[k]
                nodes = 0.5 * xx[:, None] * (1.0 + z[None, :])
                d = int(flat_d[k].max()) + 1
                vals = self.p[ii][:, None] + np.exp(-nodes) * _polyval_rows(
                    self.q[ii, :d][:, None, :], nodes
                )
                w = 0.5 * a * xx[:, None] * weight[None, :]
                int1[k] = (w * vals).sum(axis=1)
                int2[k] = (w * vals * vals).sum(axis=1)
            int1, int2 = int1.reshape(x.shape), int2.reshape(x.shape)
        return int1, int2

    def locate(self, s: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.start, s, side="right") - 1, 0, len(self.start) - 1)

    def g(self, s: np.ndarray) -> np.ndarray:
        """``g(s)`` (right limits at piece starts), zero before the impact."""
        i = self.locate(s)
        x = (s - self.start[i]) / self.alpha
        val = self.p[i] + np.exp(-x) * _polyval_rows(self.q[i], x)
        return np.where(s < 0.0, 0.0, val)

    def integral(self, s: np.ndarray, square: bool = False) -> np.ndarray:
        """:math:`\\int_{-2}^{s} g` (or of :math:`g^2`)."""
        return self.integrals(s)[1 if square else 0]

    def integrals(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:math:`\\int_{-2}^{s} g` and :math:`\\int_{-2}^{s} g^2` from one pass."""
        i = self.locate(s)
        i1, i2 = self._partial(i, s - self.start[i])
        return self.G1[i] + i1, self.G2[i] + i2


def _polyval_rows(C: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Row-wise Horner: ``sum_k C[..., k] x^k``."""
    out = np.zeros(np.broadcast_shapes(np.shape(x), C.shape[:-1]))
    for k in range(C.shape[-1] - 1, -1, -1):
        out = out * x + C[..., k]
    return out


@dataclass(frozen=True)
class RodSequenceEnergy:
    r"""Energy split of a continued rod impact, unit :math:`m_{rod} v_0^2`.

    Methods take normalized times (array or float): :meth:`striker` the kinetic energy
    :math:`\alpha y'^2/2`, :meth:`work` the work :math:`f y` done by the pressing force,
    :meth:`rod` the elastic plus kinetic energy of the rod :math:`\int_{t-2}^t g^2`,
    :meth:`balance` the residual :math:`\alpha y'^2/2 + E_{rod} - f y - \alpha/2`
    (zero up to rounding).

    Examples
    --------
    >>> energy = impact_sequence(1.0, 0.5, t_end=10.0).energy
    >>> bool(np.abs(energy.balance(np.linspace(0.0, 9.9, 100))).max() < 1e-12)
    True
    """

    sequence: RodImpactSequence

    def striker(self, t):
        return 0.5 * self.sequence.alpha * self.sequence.velocity(t) ** 2

    def work(self, t):
        return self.sequence.f * self.sequence.displacement(t)

    def rod(self, t):
        tab, tt = self.sequence._tables, self.sequence._times(t)
        return tab.integral(tt, square=True) - tab.integral(tt - 2.0, square=True)

    def balance(self, t):
        return self.striker(t) + self.rod(t) - self.work(t) - 0.5 * self.sequence.alpha

    def _rigid_balance_and_work(self, t):
        """:meth:`balance` and :meth:`work` of a rigid-contact sequence, the integrals of
        ``g`` and ``g^2`` taken in one pass at ``t`` and ``t - 2`` (the same numbers as
        the methods compute separately; not for subclasses, which add terms)."""
        seq = self.sequence
        tt = seq._times(t)
        now, before = seq._tables.integrals(tt), seq._tables.integrals(tt - 2.0)
        rod = now[1] - before[1]
        work = seq.f * seq._striker_position(tt, now[0] - before[0])
        striker = 0.5 * seq.alpha * seq.velocity(tt) ** 2
        if np.ndim(t) == 0:
            striker, rod, work = float(striker), float(rod), float(work)
        return striker + rod - work - 0.5 * seq.alpha, work


@dataclass(frozen=True)
class RodImpactSequence:
    r"""The rigid-contact rod impact followed through contacts and flights up to ``t_end``.

    Attributes
    ----------
    alpha, f, kappa, t_end
        The parameters (normalized, paper section 1).
    contacts
        ``(start, end)`` of every contact up to ``t_end`` (``end = t_end`` if the
        striker is still in contact then).
    separation_speeds
        Striker velocity :math:`y'` at each separation (negative: rebounding).
    restitution
        For ``f = 0``: the striker's rebound speed after its last contact over the
        impact speed, :math:`-y'`, when that flight provably never ends (``final``);
        ``nan`` otherwise (``f > 0``: the striker always returns; or the sequence is not
        over at ``t_end``).
    final
        Whether the striker has left for good (``f = 0``, receding and beyond any
        reach of the rod end, :math:`|u| \le \sqrt{2 E_{rod}}`).
    max_fixed_end_stress
        Largest compressive stress :math:`\sigma(1, t)` for :math:`t \le t_{end}`
        (unit :math:`E v_0 / c`).
    """

    alpha: float
    f: float
    kappa: float
    t_end: float
    contacts: list
    separation_speeds: list
    restitution: float
    final: bool
    max_fixed_end_stress: float
    _tables: _Tables = field(repr=False)
    _flights: tuple = field(repr=False)  # (t0, y0, v0) per flight

    def _times(self, t) -> np.ndarray:
        """``t`` as a float array, refused beyond ``t_end`` (nothing is known there).

        At ``t_end`` itself the pieces of ``g`` stop, while a piece of the delayed
        ``g(t - 2)`` may start exactly there (a wave front); the time functions take their
        left limits at ``t_end``, evaluated one ulp earlier, so that both delays are
        one-sided alike.
        """
        tt, _ = real_array("t", t)
        if np.any(tt > self.t_end):
            raise ValueError(f"t must be <= t_end = {self.t_end}, got {float(tt.max())!r}")
        return np.where(tt == self.t_end, np.nextafter(self.t_end, -np.inf), tt)

    @property
    def energy(self) -> RodSequenceEnergy:
        """Striker and rod energies as functions of time (:class:`RodSequenceEnergy`)."""
        return RodSequenceEnergy(self)

    def fixed_end_stress(self, t):
        r""":math:`\sigma(1, t) = 2 g(t - 1)`, compression positive (vectorized)."""
        tt = self._times(t)
        out = 2.0 * self._tables.g(tt - 1.0)
        return float(out) if np.ndim(t) == 0 else out

    def rod_end_displacement(self, t):
        """:math:`u(t) = w(0, t)`."""
        tt = self._times(t)
        out = self._tables.integral(tt) - self._tables.integral(tt - 2.0)
        return float(out) if np.ndim(t) == 0 else out

    def _flight_index(self, tt):
        starts = np.array([fl[0] for fl in self._flights] + [np.inf])
        k = np.searchsorted(starts, tt, side="right") - 1
        ends = np.array([c[0] for c in self.contacts[1:]] + [np.inf])
        in_flight = (k >= 0) & (tt < ends[np.clip(k, 0, None)] if ends.size else False)
        return k, in_flight

    def displacement(self, t):
        """Striker displacement :math:`y(t)`."""
        tt = self._times(t)
        y = self._striker_position(tt, np.asarray(self.rod_end_displacement(tt), dtype=float))
        return float(y) if np.ndim(t) == 0 else y

    def _striker_position(self, tt, u):
        """:math:`y` at the times ``tt`` (checked) given the rod end position ``u`` there."""
        y = u
        if self._flights:
            k, fl = self._flight_index(tt)
            data = np.array(self._flights)
            t0, y0, v0 = data[np.clip(k, 0, None)].T
            d = tt - t0
            y = np.where(fl, y0 + v0 * d + 0.5 * self.f / self.alpha * d * d, y)
        return y

    def velocity(self, t):
        """Striker velocity :math:`y'(t)`."""
        tt = self._times(t)
        v = self._tables.g(tt) - self._tables.g(tt - 2.0)
        if self._flights:
            k, fl = self._flight_index(tt)
            data = np.array(self._flights)
            t0, _, v0 = data[np.clip(k, 0, None)].T
            v = np.where(fl, v0 + self.f / self.alpha * (tt - t0), v)
        return float(v) if np.ndim(t) == 0 else v

    def contact_force(self, t):
        """:math:`N(t)`: :math:`g(t) + g(t-2)` in contact, zero in flight."""
        tt = self._times(t)
        n = self._tables.g(tt) + self._tables.g(tt - 2.0)
        if self._flights:
            n = np.where(self._flight_index(tt)[1], 0.0, n)
        return float(n) if np.ndim(t) == 0 else n

    def plot(self, *, ax=None):
        """Contact/flight sequence with the energy split (see
        :func:`impactsym.plotting.rod_sequence.plot_sequence`)."""
        from impactsym.plotting.rod_sequence import plot_sequence

        return plot_sequence(self, ax=ax)


def _g_max(tab: _Tables, s_end: float) -> float:
    """Largest value of ``g`` on ``[0, s_end]``: piece ends and zeros of ``Q' - Q``.

    Only pieces that can reach the largest value are searched for their zeros of
    ``Q' - Q``: ``floor``, the largest of ``g`` sampled at ``_G_SAMPLES`` points of
    every piece, is a value that ``g`` takes, and a piece whose upper bound is below it
    cannot hold the maximum. The bound is the smaller of ``p + max |e^{-x} Q|`` and,
    with ``L`` a bound of ``|g'|`` on the piece (in ``x``), the largest
    ``(g(a) + g(b) + L (b - a)) / 2`` over neighbouring samples ``a, b`` (plus a
    rounding margin). The result is the largest value at the candidates (ends and
    critical points) of the other pieces, as if every piece had been searched.
    """
    a = tab.alpha
    ends = np.r_[tab.start[1:], np.inf]
    live = np.flatnonzero((tab.start < s_end) & (ends > 0.0))
    s0 = tab.start[live]
    lo, hi = np.maximum(s0, 0.0), np.minimum(ends[live], s_end)
    xlo, xhi = (lo - s0) / a, (hi - s0) / a
    x = xlo[:, None] + (xhi - xlo)[:, None] * np.linspace(0.0, 1.0, _G_SAMPLES)
    q = tab.q[live]
    p = tab.p[live]
    sampled = p[:, None] + np.exp(-x) * _polyval_rows(q[:, None, :], x)
    floor = float(sampled.max())
    # upper bounds: |e^-x c(x)| <= sum_k |c_k| max x^k e^-x (largest at x = k) for
    # c = Q, and for c = Q' - Q a Lipschitz constant L of g in x; between two
    # samples a, b = a + d, g <= (g(a) + g(b) + L d) / 2 (plus rounding)
    k = np.arange(q.shape[1], dtype=float)
    peak = np.minimum(k, xhi[:, None])
    with np.errstate(divide="ignore"):
        m = np.exp(k * np.log(np.where(peak > 0, peak, 1.0)) - peak)
    m[:, 0] = 1.0
    size = (np.abs(q) * m).sum(axis=1)
    slope = np.abs(np.c_[q[:, 1:] * k[1:], np.zeros(len(q))] - q)
    lipschitz = (slope * m).sum(axis=1)
    step = (xhi - xlo) / (_G_SAMPLES - 1)
    pairs = 0.5 * (sampled[:, 1:] + sampled[:, :-1]).max(axis=1)
    rounding = 64.0 * q.shape[1] * np.finfo(float).eps * (size + np.abs(p))
    bound = np.minimum(p + size, pairs + 0.5 * lipschitz * step + rounding)
    constant = ~q.any(axis=1)
    best = max(0.0, float(p[constant].max())) if constant.any() else 0.0
    keep = np.flatnonzero(~constant & (bound >= floor))
    for i, s0_i, lo_i, hi_i, X, bound_i in zip(
        live[keep].tolist(),
        s0[keep],
        lo[keep],
        hi[keep],
        xhi[keep].tolist(),
        bound[keep],
        strict=True,
    ):
        if bound_i <= best:
            continue  # cannot beat the best value so far
        Q = _trim(tab.q[i])
        cand = [lo_i, hi_i]
        if Q.size > 1:
            crit = exp_poly_roots(
                np.zeros(0), npoly.polysub(npoly.polyder(Q), Q), (lo_i - s0_i) / a, X
            )
            cand += list(s0_i + a * crit)
        xc = (np.array(cand) - s0_i) / a
        vals = tab.p[i] + np.exp(-xc) * npoly.polyval(xc, Q)
        best = max(best, float(vals.max()))
    return best


_G_SAMPLES = 33


def _first_root(A: np.ndarray, B: list, X: float, *, rising_from_zero: bool = False):
    """First certified zero with sign change of :math:`e^x A + B` in :math:`(0, X]`, or
    ``None`` (:func:`impactsym.numeric.exppoly.exp_poly_roots`)."""
    root = exp_poly_roots(A, np.array(B), 0.0, X, first=True, rising_from_zero=rising_from_zero)
    return float(root[0]) if root.size else None


def impact_sequence(
    alpha: float,
    f: float,
    *,
    kappa: float = math.inf,
    t_end: float = 40.0,
    max_contacts: int = 2000,
) -> RodImpactSequence:
    r"""Follow the rigid-contact rod impact through separations and re-contacts.

    Solves the impact of paper section 1 exactly past the end of the first contact: in
    contact the outgoing wave obeys :math:`\alpha g' + g = f + \alpha g'(t-2) - g(t-2)`,
    in flight :math:`g(t) = -g(t-2)` and :math:`\alpha y'' = f`; events are certified
    roots of exponential polynomials (see the module notes).

    Parameters
    ----------
    alpha : float
        Mass ratio :math:`M / m_{rod} > 0`.
    f : float
        Pressing force :math:`F c / (EA v_0) \ge 0`.
    kappa : float, optional
        Contact stiffness :math:`k_c L / (EA)`; ``inf`` is rigid contact, a finite value
        is solved by :mod:`impactsym.rod.elastic_continuation` (a massless contact
        spring; returns an :class:`~impactsym.rod.elastic_continuation.ElasticRodImpactSequence`).
    t_end : float, optional
        End of the simulated time (unit :math:`L / c`).
    max_contacts : int, optional
        Limit on the number of contacts before ``t_end``. A very light striker pressed
        by ``f > 0`` chatters on the vibrating rod end with ever shorter flights
        (flight time :math:`\sim 2 \alpha |y'| / f`); past the limit a
        ``RuntimeError`` says so instead of running on.

    Returns
    -------
    RodImpactSequence

    Raises
    ------
    ValueError, TypeError
        For ``alpha <= 0``, ``f < 0``, ``t_end <= 0``, non-finite or non-scalar input;
        and when the float64 pieces stop being exact before ``t_end`` (energy balance
        residual above ``1e-9`` of :math:`\alpha/2 + |f y|` in the middle of a piece,
        or a piece degree above 95): the message names ``alpha, f, t_end`` and the
        time reached. Sequences that keep chattering are exact to about
        :math:`t = 80`-:math:`250` (e.g. ``(10, 5)``, ``(3, 1)`` and ``(0.3, 1)`` to
        beyond 100, ``(40, 2)`` to 258; a strongly pressed light striker reaches the
        degree limit near 190); ``f = 0`` sequences whose striker leaves run to any
        ``t_end``. A finite ``kappa`` is checked the same way (the message also names
        ``kappa``; chattering sequences typically hold to :math:`t = 30`-:math:`40`).
    RuntimeError
        When more than ``max_contacts`` contacts occur before ``t_end``.

    Examples
    --------
    A light striker (:math:`\alpha < 1.7`, :math:`f = 0`) leaves at
    :math:`t = 2 + \alpha(1 + e^{-2/\alpha}/2)`, after the first reflection returned:

    >>> seq = impact_sequence(0.5, 0.0)
    >>> start, end = seq.contacts[0]
    >>> bool(abs(end - (2 + 0.5 * (1 + np.exp(-4.0) / 2))) < 1e-13)
    True
    >>> bool(abs(seq.restitution - 2 * np.exp(-1 - np.exp(-4.0) / 2)) < 1e-13)
    True
    """
    a_arr, _ = real_array("alpha", alpha, lower=0.0, strict=True)
    f_arr, _ = real_array("f", f, lower=0.0)
    k_arr, _ = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    t_arr, _ = real_array("t_end", t_end, lower=0.0, strict=True)
    for name, arr in (("alpha", a_arr), ("f", f_arr), ("kappa", k_arr), ("t_end", t_arr)):
        if arr.ndim:
            raise TypeError(f"{name} must be a scalar, got an array of shape {arr.shape}")
    alpha, f, kappa, t_end = float(a_arr), float(f_arr), float(k_arr), float(t_arr)
    if t_end > 1e4:
        raise ValueError(f"t_end must be <= 1e4, got {t_end}")
    if isinstance(max_contacts, bool) or not isinstance(max_contacts, int) or max_contacts < 1:
        raise ValueError(f"max_contacts must be a positive integer, got {max_contacts!r}")
    if not math.isinf(kappa):
        from impactsym.rod.elastic_continuation import _elastic_sequence

        return _elastic_sequence(alpha, f, kappa, t_end, max_contacts)

    pieces = _Pieces(alpha)
    pieces.append(-2.0, 2.0, 0.0, [])  # rest before the impact
    starts = pieces.start
    contacts, speeds, flights = [], [], []
    t, v, y, u = 0.0, 1.0, 0.0, 0.0  # time, striker velocity and position, rod end
    in_contact, contact_start = True, 0.0
    j = 0  # incoming piece index
    final = False
    # The pieces' polynomials are lists of plain floats: at degree < ~20 Python's
    # arithmetic beats NumPy's cost per call on such small arrays.
    # A flight copies the incoming piece with its sign flipped, so the antiderivative
    # of the copy is the flipped one of the incoming piece, bit for bit: kept per piece
    # index for the flight that meets the copy two time units later.
    antiderivatives: dict[int, list] = {}
    try:
        while t < t_end:
            # incoming piece j: the one holding t - 2; piece boundaries are compared in
            # the time of arrival (start + 2) so that aligned pieces meet exactly
            while j + 1 < len(starts) and starts[j + 1] + 2.0 <= t:
                j += 1
            s_in = starts[j]
            delta = max(t - (s_in + 2.0), 0.0) / alpha
            p_in = pieces.p[j]
            Q_in = pieces.q[j]
            if Q_in and delta > 0.0:
                Q_in = (math.exp(-delta) * taylor_shift(np.array(Q_in), delta)).tolist()
            t_next = min((starts[j + 1] if j + 1 < len(starts) else t) + 2.0, t_end)
            h = t_next - t
            if final:  # free vibration: copy the reflected wave, no events
                pieces.append(t, h, -p_in, [-c for c in Q_in])
                t = t_next
                continue
            if in_contact:
                p_new = f - p_in
                q0 = Q_in[0] if Q_in else 0.0
                G0 = v + p_in + q0 - p_new
                if Q_in:  # G = G0 + Q_in - q0 - 2 int Q_in
                    n = len(Q_in)
                    G = [G0] + [Q_in[k] - 2.0 * Q_in[k - 1] / k for k in range(1, n)]
                    G.append(-2.0 * Q_in[n - 1] / n)
                    B = [G[k] + Q_in[k] for k in range(n)]
                    B.append(G[n])
                else:  # below rounding the exponential part is dropped, as in _Pieces.append
                    G = [G0 if abs(G0) >= _NEGLIGIBLE * max(1.0, abs(p_new)) else 0.0]
                    B = G
                cap = _X_MAX if len(B) > 1 else (_X_LONG if B[0] != 0.0 else math.inf)
                if h > alpha * cap:
                    h = alpha * cap
                    t_next = t + h
                X = h / alpha
                if f + B[0] < 0.0:  # a tensile front: N jumps below zero
                    contacts.append((contact_start, t))
                    speeds.append(v)
                    flights.append((t, y, v))
                    in_contact = False
                    continue
                # with B = 0, N = f >= 0 throughout: no sign change; most pieces are
                # proven positive by the cheap certificate, the others searched
                if not any(B) or exp_poly_positive([f], B, X):
                    root = None
                else:
                    root = _first_root(np.array([f]), B, X)
                ended = root is not None
                if ended:
                    X, h = root, alpha * root
                    t_next = t + h
                pieces.append(t, h, p_new, G)
                ex = math.exp(-X)
                Gd = G.copy()
                for k in range(len(Q_in)):
                    Gd[k] -= Q_in[k]
                v = p_new - p_in + ex * _horner(Gd, X)
                R = _exp_antiderivative(Gd)
                y += alpha * ((p_new - p_in) * X + R[0] - ex * _horner(R, X))
                u = y
                t = t_next
                if ended:
                    contacts.append((contact_start, t))
                    speeds.append(v)
                    flights.append((t, y, v))
                    in_contact = False
            else:
                if Q_in and h > alpha * _X_MAX:
                    h = alpha * _X_MAX
                    t_next = t + h
                X = h / alpha
                if Q_in and delta == 0.0 and _REUSE_ANTIDERIVATIVES and j in antiderivatives:
                    R = antiderivatives[j]
                else:
                    R = _exp_antiderivative(Q_in) if Q_in else [0.0]
                C = [u - y - 2 * alpha * R[0], -alpha * (2 * p_in + v), -0.5 * alpha * f]
                if Q_in:
                    A, Bgap = C, [2 * alpha * r for r in R]
                    slope = C[0] + C[1] + 2 * alpha * (R[1] if len(R) > 1 else 0.0)
                else:
                    A, Bgap = [], C
                    slope = C[1]
                opening = bool(flights) and flights[-1][0] == t
                if opening and slope < 0.0:
                    # at a separation gap' = -N >= 0 exactly; clear a rounding-level slope
                    C[1] -= slope
                lo_gap = C[0] + (2 * alpha * R[0] if Q_in else 0.0)
                if lo_gap < 0.0:  # u - y >= 0 in flight; clear a rounding-level overlap
                    C[0] -= lo_gap
                if exp_poly_positive(A, Bgap, X, rising_from_zero=opening):
                    root = None  # the gap stays open (the cheap certificate)
                else:
                    root = _first_root(np.array(A), Bgap, X, rising_from_zero=opening)
                ended = root is not None
                if ended:
                    X, h = root, alpha * root
                    t_next = t + h
                count = len(pieces.q)
                pieces.append(t, h, -p_in, [-c for c in Q_in])
                if len(pieces.q) > count and pieces.q[-1]:  # (trailing zeros add nothing)
                    antiderivatives[count] = [-r for r in R[: len(pieces.q[-1])]]
                ex = math.exp(-X)
                u += -2 * alpha * (p_in * X + (R[0] - ex * _horner(R, X) if Q_in else 0.0))
                y += v * h + 0.5 * f / alpha * h * h
                v += f / alpha * h
                t = t_next
                if ended:
                    if len(contacts) >= max_contacts:
                        raise RuntimeError(
                            f"impact_sequence({alpha!r}, {f!r}): more than max_contacts="
                            f"{max_contacts} contacts before t = {t:.6g} < t_end = {t_end} "
                            "(chatter); raise max_contacts or lower t_end"
                        )
                    y = u
                    in_contact, contact_start = True, t
                elif f == 0.0 and v < 0.0:
                    e_rod = 0.5 * alpha * (1.0 - v * v)  # energy balance
                    final = y < -math.sqrt(2.0 * max(e_rod, 0.0)) - 1e-12
    except ValueError as exc:  # e.g. a piece degree beyond what taylor_shift handles
        raise ValueError(
            f"impact_sequence(alpha={alpha!r}, f={f!r}, t_end={t_end!r}): the float64 pieces "
            f"fail at t = {t:.6g}: {exc}; lower t_end"
        ) from exc
    if in_contact:
        contacts.append((contact_start, t_end))
    tables = _Tables.build(pieces, t)
    restitution = -float(speeds[-1]) if (final and f == 0.0) else math.nan
    stress = 2.0 * _g_max(tables, t_end - 1.0) if t_end > 1.0 else 0.0
    seq = RodImpactSequence(
        alpha,
        f,
        kappa,
        t_end,
        [(float(a), float(b)) for a, b in contacts],
        [float(v) for v in speeds],
        restitution,
        final,
        stress,
        tables,
        tuple(flights),
    )
    _check_balance(seq)
    return seq


def _check_balance(seq: RodImpactSequence) -> None:
    """Refuse a sequence whose energy balance fails by more than ``_BALANCE_RTOL``
    (relative to :math:`\alpha/2 + |f y|`) in the middle of a piece: the float64 polynomial
    pieces grow about one degree per round trip and their coefficients cancel, so past
    some time (that depends on ``alpha, f``) the result is no longer exact."""
    ends = np.r_[seq._tables.start, seq.t_end]
    ts = 0.5 * (ends[:-1] + ends[1:])  # mid-piece: no event (jump) is evaluated
    ts = ts[(ts > 0.0) & (ts < seq.t_end)]
    energy = seq.energy
    if type(energy) is RodSequenceEnergy:  # rigid contact: both integrals in one pass
        residual, work = energy._rigid_balance_and_work(ts)
    else:  # a subclass (finite kappa) adds its own terms
        residual, work = energy.balance(ts), energy.work(ts)
    residual = np.abs(residual)
    scale = 0.5 * seq.alpha + np.abs(work)
    bad = np.flatnonzero(residual > _BALANCE_RTOL * scale)
    if bad.size:
        k = bad[0]
        good = float(ts[k - 1]) if k else 0.0
        raise ValueError(
            f"impact_sequence(alpha={seq.alpha!r}, f={seq.f!r}, t_end={seq.t_end!r}): the "
            f"float64 pieces are no longer exact at t = {ts[k]:.8g} (energy balance residual "
            f"{residual[k]:.2g} > {_BALANCE_RTOL:g} x (alpha/2 + |f y|)); they are trusted "
            f"up to t = {good:.8g}, lower t_end"
        )
