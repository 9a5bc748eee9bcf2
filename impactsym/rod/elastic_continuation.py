r"""The rod impact continued past separation with a finite contact stiffness :math:`\kappa`.

Same d'Alembert bookkeeping as :mod:`impactsym.rod.continuation` (outgoing wave
:math:`g = \phi'`, rod end :math:`u = \phi(t) - \phi(t-2)`, :math:`u' = g(t) - g(t-2)`, rod
end force :math:`g(t) + g(t-2)`, fixed-end stress :math:`2 g(t-1)`), with a massless linear
spring between striker and rod end. With the incoming wave :math:`G(t) = g(t-2)` and the
spring compression :math:`z = y - u`:

* **contact** (:math:`z > 0`): :math:`N = \kappa z = g + G`, so :math:`g = N - G`,
  :math:`u' = N - 2G` and

  .. math::

      \alpha y'' = f - N, \qquad N' = \kappa (y' - N + 2 G), \qquad
      \alpha N'' + \alpha\kappa N' + \kappa N = \kappa f + 2 \alpha\kappa G';

* **flight** (:math:`z \le 0`): :math:`N = 0`, :math:`g = -G`, :math:`\alpha y'' = f`.

Position and force conditions coincide (:math:`N = \kappa z`); :math:`N` and :math:`g`
are continuous (at :math:`t = 0`, :math:`N = g = 0`), so contact ends where :math:`z`
falls through zero and resumes where the gap :math:`u - y` closes.

**Representation (exact, piecewise).** The homogeneous rates are the roots
:math:`\sigma \pm \sqrt{d}` of :math:`P(s) = \alpha s^2 + \alpha\kappa s + \kappa`,
:math:`\sigma = -\kappa/2`, :math:`d = \kappa^2/4 - \kappa/\alpha` (a complex pair for
:math:`\alpha\kappa < 4`, a double root at :math:`\alpha\kappa = 4`, decided in exact
rational arithmetic of the two floats). The incoming wave carries the same rates, so the
forcing is resonant and every piece of :math:`g` stays in the family
:math:`g(s) = p + \sum_r e^{r x} Q_r(x)`, :math:`x = s - s_0`, in one of two forms:

* **confluent** (:math:`d \le \theta^2\sigma^2`, ``_CONFLUENT`` :math:`\theta = 0.9`: every
  soft, critical and lightly damped contact, :math:`\alpha\kappa \le 21`): the single rate
  :math:`\sigma` with :math:`N = f + e^{\sigma x} M(x)`, :math:`M'' - d M =
  2\kappa(\sigma Q_i + Q_i')`, solved by the exact Taylor recurrence
  :math:`m_{k+2} = (d m_k + F_k)/((k+1)(k+2))` from :math:`M(0) = N(0) - f`,
  :math:`M'(0) = N'(0) - \sigma M(0)`, :math:`N'(0) = \kappa(y' - N + 2G)`. It is uniform
  in :math:`d` (no division by :math:`r_1 - r_2`; :math:`d = 0` is exactly critical). On
  pieces of length :math:`h \le 2/\sqrt{\sigma^2 + |d|}` the series is cut where its
  remaining terms are provably below :math:`10^{-18}` of its size (``_TAIL``);
* **split per rate** (a stiff contact, :math:`d > \theta^2\sigma^2`): two real rates,
  a slow one :math:`\approx -1/\alpha` and a fast one :math:`\approx -\kappa`, with
  :math:`\alpha M_r'' + P'(r) M_r' = 2\alpha\kappa (r Q_{i,r} + Q_{i,r}')` (degree + 1),
  then :math:`c_1 e^{r_1 x} + c_2 e^{r_2 x}` fitted to :math:`N(0), N'(0)`. Pieces are at
  most :math:`2/\min|r|` long; the fast part decays below rounding within
  :math:`\sim 40/\kappa` and is dropped.

Splitting per rate where the rates are close on the scale of a piece would cancel: the
parts grow like :math:`|r_1 - r_2|^{-k}` after :math:`k` passages (with :math:`\alpha = 10,
\kappa = 0.5` they reach :math:`10^9` by :math:`t = 17`), which is why the confluent form
is used there. Pieces are also cut where an incoming piece arrives and at events; terms
whose bound on a piece is below :math:`10^{-17}` (whole rates) or :math:`10^{-18}`
(trailing coefficients) are dropped. The degree still grows with every reflection that
meets the contact, and chattering sequences lose float64 digits after some 30-40
transits, as for rigid contact: the solver bounds the terms of every piece (refusing
where their rounding could exceed :math:`10^{-8}`, ``_MAGNITUDE_LIMIT``) and checks the
energy balance in the middle of every piece to :math:`10^{-9}` (as
:func:`impactsym.rod.impact_sequence` does for rigid contact); a ``ValueError`` names
``alpha, f, kappa, t_end`` and the time reached. Never a silently inexact result.

**Events, certified.** Separation is the first sign change of
:math:`N(x) = N(0) + \sum_r [(e^{rx} - 1) M_r(x) + M_r(x) - M_r(0)]` (increment form: no
cancellation near the piece start), re-contact the first sign change of the gap
:math:`u - y = (u_0 - y_0) - (2p_i + y_0')x - \tfrac{f}{2\alpha}x^2 - 2\sum_r \int_0^x
e^{r\xi} Q_{i,r}`. Both are isolated by
:func:`impactsym.numeric.isolation.first_sign_change` with rigorous bounds
:math:`|F''| \le \sum_r e^{\mathrm{Re}(r) a} \sum_j |C_{rj}| b^j` on every cell
:math:`[a, b]` (the coefficients :math:`C_r` of :math:`(e^{rx} M)'' e^{-rx}`), then
polished by :func:`impactsym.numeric.roots.bracketed_newton`.

**Energy** (unit :math:`m_{rod} v_0^2`): striker :math:`\alpha y'^2/2`, spring
:math:`N^2/(2\kappa)`, rod :math:`\int_{t-2}^t g^2`, work :math:`f y`;
:math:`\alpha/2 + f y = \alpha y'^2/2 + N^2/(2\kappa) + E_{rod}`. Integrals of :math:`g`
and :math:`g^2` use 48-point Gauss-Legendre rules on sub-intervals graded geometrically
towards each piece start (the fast rate :math:`\approx -\kappa` of a stiff contact).

The largest fixed-end stress is found by branch and bound over the pieces with the same
:math:`|g''|` bounds (within :math:`10^{-13}`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from impactsym.numeric.exppoly import taylor_shift
from impactsym.numeric.isolation import first_sign_change
from impactsym.rod.continuation import RodImpactSequence, RodSequenceEnergy, _check_balance

__all__ = ["ElasticRodImpactSequence", "ElasticSequenceEnergy"]

_EPS = np.finfo(float).eps
_NEGLIGIBLE = 1e-17
_SPAN = 2.0  # longest piece with an exponential part, in units of 1 / min |r|
_GAUSS = np.polynomial.legendre.leggauss(48)  # exact to degree 95 on a sub-interval
# Largest bound of the per-rate parts (relative to max(1, |p|)) times their number of
# coefficients before their rounding, ~eps times it, could reach 1e-8: refused beyond.
_MAGNITUDE_LIMIT = 1e-8 / _EPS
_STRESS_TOL = 1e-13
# Confluent form where |sqrt(d)| <= _CONFLUENT |sigma|: on a piece (length <= 2/|sigma|)
# the split rates differ by at most 2 * 1.8 / length, too little for a per-rate split.
_CONFLUENT = 0.9
_TAIL = 1e-18  # truncation of the confluent series, relative to its size on the piece
_MAX_COEFFICIENTS = 95  # taylor_shift's limit


def _rates(alpha: float, kappa: float) -> tuple[np.ndarray, float | None]:
    r"""The rates of the representation and, for the confluent form, :math:`d`.

    With :math:`\sigma = -\kappa/2` and :math:`d = \kappa^2/4 - \kappa/\alpha` (exact
    rational arithmetic of the two floats) the roots of
    :math:`\alpha s^2 + \alpha\kappa s + \kappa` are :math:`\sigma \pm \sqrt{d}`. Where
    :math:`d \le \theta^2 \sigma^2` (``_CONFLUENT``; every complex pair) the single rate
    :math:`\sigma` is returned with ``d`` (the confluent form); else (a stiff contact) the
    two real roots and ``None``.
    """
    sigma = -0.5 * kappa
    ratio = 1 - 4 / (Fraction(alpha) * Fraction(kappa))  # d / sigma^2, exact
    if ratio <= Fraction(_CONFLUENT) ** 2:
        try:
            d = float(Fraction(sigma) ** 2 * ratio)
        except OverflowError:
            d = math.inf
        if not math.isfinite(d):
            raise ValueError(
                f"alpha={alpha!r}, kappa={kappa!r}: kappa^2 / 4 - kappa / alpha overflows float64"
            )
        return np.array([complex(sigma)]), d
    root = math.sqrt(float(ratio))  # in (theta, 1): no cancellation below
    big = sigma * (1.0 + root)
    small = -2.0 / (1.0 + root) / alpha  # the product of the roots is kappa / alpha
    return np.array([complex(small), complex(big)]), None


def _der(c: np.ndarray) -> np.ndarray:
    """Derivative of polynomials along the last axis (same length, zero padded)."""
    out = np.zeros_like(c)
    n = c.shape[-1]
    out[..., : n - 1] = c[..., 1:] * np.arange(1, n)
    return out


def _integ(c: np.ndarray) -> np.ndarray:
    """Antiderivative vanishing at 0 along the last axis (one coefficient longer)."""
    out = np.zeros((*c.shape[:-1], c.shape[-1] + 1), dtype=c.dtype)
    out[..., 1:] = c / np.arange(1, c.shape[-1] + 1)
    return out


def _pad(c: np.ndarray, n: int) -> np.ndarray:
    if c.shape[-1] >= n:
        return c
    out = np.zeros((*c.shape[:-1], n), dtype=c.dtype)
    out[..., : c.shape[-1]] = c
    return out


def _expm1(z: np.ndarray) -> np.ndarray:
    """:math:`e^z - 1` for complex ``z`` without cancellation at small ``|z|``."""
    a, b = z.real, z.imag
    return np.expm1(a) * np.cos(b) - 2.0 * np.sin(0.5 * b) ** 2 + 1j * np.exp(a) * np.sin(b)


def _polyval(Q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``Q[..., r, :]`` evaluated at ``x`` (Horner); result ``x.shape + (n_rates,)``
    when ``Q`` is 2-D, or broadcast row-wise when ``Q`` has the leading axes of ``x``."""
    out = np.zeros(np.broadcast_shapes((*x.shape, 1), Q.shape[:-1]), dtype=complex)
    xx = x[..., None]
    for k in range(Q.shape[-1] - 1, -1, -1):
        out = out * xx + Q[..., k]
    return out


def _grade(reach: np.ndarray) -> np.ndarray:
    """Number of geometric sub-intervals for ``|r| x = reach``: the first one, of width
    ``x 2^-K``, has ``|r| x 2^-K <= 2``."""
    with np.errstate(divide="ignore"):
        k = np.ceil(np.log2(np.maximum(np.asarray(reach, dtype=float) / 2.0, 1.0)))
    return k.astype(np.int64)


def _graded_rule(x: np.ndarray, K: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights ``(m, (K + 1) 48)`` of the 48-point Gauss-Legendre rule on
    ``[0, x 2^-K]`` and ``[x 2^-k-1, x 2^-k]``, ``k < K``, for each ``x``."""
    edges = x[:, None] * 2.0 ** np.arange(-K, 1)[None, :]
    lo = np.concatenate([np.zeros((x.size, 1)), edges[:, :-1]], axis=1)
    half = 0.5 * (edges - lo)
    nodes = (lo + half)[..., None] + half[..., None] * _GAUSS[0]
    return nodes.reshape(x.size, -1), (half[..., None] * _GAUSS[1]).reshape(x.size, -1)


def _integral(Q: np.ndarray, rates: np.ndarray, x: np.ndarray) -> np.ndarray:
    r""":math:`\sum_r \int_0^x e^{r\xi} Q_r(\xi) d\xi` at ``x >= 0`` (array) by the graded
    Gauss-Legendre rule (exact for the polynomial, the exponential resolved to rounding;
    the closed form :math:`\sum_j (-1)^j Q^{(j)} / r^{j+1}` would cancel for a slow rate
    and a high degree)."""
    x = np.asarray(x, dtype=float)
    if Q.shape[-1] == 0:
        return np.zeros_like(x)
    flat = x.ravel()
    present = np.any(Q != 0.0, axis=1)
    fast = float(np.max(np.abs(rates[present]), initial=0.0))
    nodes, w = _graded_rule(flat, int(_grade(float(flat.max(initial=0.0)) * fast)))
    return (w * _exp_values(Q, rates, nodes)).sum(axis=1).reshape(x.shape)


def _magnitude(Q: np.ndarray, rates: np.ndarray, h: float, per_term: bool = False) -> np.ndarray:
    r"""Per rate, an upper bound of :math:`|e^{rx} Q_r(x)|` on :math:`[0, h]` (or of each
    term :math:`|q_{rk} x^k e^{rx}|`)."""
    n = Q.shape[-1]
    k = np.arange(n, dtype=float)
    rho = -rates.real[:, None]  # > 0
    peak = np.minimum(k[None, :] / rho, h)  # x^k e^{-rho x} is largest at k / rho
    with np.errstate(divide="ignore"):
        m = np.exp(k * np.log(np.where(peak > 0, peak, 1.0)) - rho * peak)
    m[:, 0] = 1.0
    return np.abs(Q) * m if per_term else (np.abs(Q) * m).sum(axis=-1)


def _bound_second(C: np.ndarray, rates: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    r""":math:`\sum_r e^{\mathrm{Re}(r) a} \sum_j |C_{rj}| b^j` (``0 <= a < b``), with a
    relative margin for rounding."""
    absC = np.abs(C)  # (n_rates, n)
    powers = b[:, None] ** np.arange(C.shape[-1])[None, :]  # (cells, n)
    poly = powers @ absC.T  # (cells, n_rates)
    return (np.exp(np.outer(a, rates.real)) * poly).sum(axis=1) * (1.0 + 1e-10)


def _second(Q: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """Coefficients of ``(e^{rx} Q_r)'' e^{-rx} = r^2 Q + 2 r Q' + Q''``."""
    r = rates[:, None]
    dQ = _der(Q)
    return r * r * Q + 2.0 * r * dQ + _der(dQ)


@dataclass
class _Pieces:
    """Growing store of the pieces of ``g``: start, constant, per-rate polynomials."""

    rates: np.ndarray
    span: float  # longest piece with an exponential part; terms are judged over it
    start: list = field(default_factory=list)
    p: list = field(default_factory=list)
    q: list = field(default_factory=list)

    def append(self, s0: float, h: float, p: float, Q: np.ndarray) -> None:
        if h <= 0.0:
            return
        if Q.size:
            scale = max(1.0, abs(p))
            # judged over the longest piece, so that a short piece keeps the terms its
            # derivative needs
            terms = _magnitude(Q, self.rates, self.span, per_term=True)  # (n_rates, n)
            keep = terms.sum(axis=1) >= _NEGLIGIBLE * scale
            Q = np.where(keep[:, None], Q, 0.0)
            # trailing terms whose sum is below _TAIL on the piece are rounding
            tail = np.cumsum(np.where(keep[:, None], terms, 0.0).sum(axis=0)[::-1])[::-1]
            nz = np.flatnonzero(tail > _TAIL * scale)
            Q = Q[:, : nz[-1] + 1] if nz.size else Q[:, :0]
        if self.q and Q.shape[-1] == 0 and self.q[-1].shape[-1] == 0 and self.p[-1] == p:
            return  # the constant piece before goes on
        self.start.append(s0)
        self.p.append(p)
        self.q.append(Q)


def _shift(Q: np.ndarray, rates: np.ndarray, delta: float) -> np.ndarray:
    r""":math:`e^{r\delta} Q_r(x + \delta)` per rate."""
    if Q.shape[-1] == 0 or delta == 0.0:
        return Q
    out = np.empty_like(Q)
    for i, r in enumerate(rates):
        out[i] = np.exp(r * delta) * (
            taylor_shift(Q[i].real, delta) + 1j * taylor_shift(Q[i].imag, delta)
        )
    return out


@dataclass(frozen=True)
class _Tables:
    """Padded arrays of the pieces for vectorized evaluation (the interface of
    ``impactsym.rod.continuation._Tables``: ``g``, ``integral``; plus ``dg``)."""

    rates: np.ndarray
    start: np.ndarray
    p: np.ndarray
    q: np.ndarray  # (pieces, n_rates, degree + 1), complex
    G1: np.ndarray
    G2: np.ndarray
    active: np.ndarray  # (pieces, n_rates): rate present in the piece

    @classmethod
    def build(cls, pieces: _Pieces, s_end: float) -> _Tables:
        rates = pieces.rates
        n = len(pieces.start)
        deg = max((q.shape[-1] for q in pieces.q), default=1)
        q = np.zeros((n, rates.size, max(deg, 1)), dtype=complex)
        for i, Q in enumerate(pieces.q):
            q[i, :, : Q.shape[-1]] = Q
        start = np.array(pieces.start)
        h = np.diff(np.r_[start, s_end])
        active = np.any(q != 0.0, axis=2)
        tab = cls(rates, start, np.array(pieces.p), q, np.zeros(n), np.zeros(n), active)
        i1, i2 = tab._partial(np.arange(n), h)
        tab.G1[1:] = np.cumsum(i1)[:-1]
        tab.G2[1:] = np.cumsum(i2)[:-1]
        return tab

    def locate(self, s: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.start, s, side="right") - 1, 0, len(self.start) - 1)

    def _exp_part(self, i: np.ndarray, x: np.ndarray, derivative: bool = False) -> np.ndarray:
        """Exponential part of piece ``i`` (shape ``(m,)``) at ``x`` (shape ``(m, ...)``)."""
        Q = self.q[i]  # (m, n_rates, n)
        if derivative:
            Q = self.rates[:, None] * Q + _der(Q)
        lead = (i.size,) + (1,) * (x.ndim - 1)
        out = np.zeros((*x.shape, self.rates.size), dtype=complex)
        xx = x[..., None]
        for k in range(Q.shape[-1] - 1, -1, -1):
            out = out * xx + Q[:, :, k].reshape((*lead, self.rates.size))
        return (np.exp(xx * self.rates) * out).sum(axis=-1).real

    def _at(self, s, derivative: bool) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        flat = s.ravel()
        i = self.locate(flat)
        val = self._exp_part(i, flat - self.start[i], derivative)
        if not derivative:
            val = val + self.p[i]
        return np.where(flat < 0.0, 0.0, val).reshape(s.shape)

    def g(self, s: np.ndarray) -> np.ndarray:
        """``g(s)``, zero before the impact."""
        return self._at(s, False)

    def dg(self, s: np.ndarray) -> np.ndarray:
        """``g'(s)``, zero before the impact."""
        return self._at(s, True)

    def _partial(self, i, tau):
        """Integrals of ``g`` and ``g^2`` over ``[start_i, start_i + tau]``: Gauss-Legendre
        on ``[0, tau 2^-K]`` and the geometric sub-intervals ``[tau 2^-k-1, tau 2^-k]``,
        ``K`` from the fastest rate present in the piece (see :func:`_grade`)."""
        i, tau = np.broadcast_arrays(np.asarray(i), np.asarray(tau, dtype=float))
        i, tau = i.ravel(), tau.ravel()
        fast = np.max(np.where(self.active[i], np.abs(self.rates), 0.0), axis=1)
        grade = _grade(tau * fast)
        i1, i2 = np.empty(tau.size), np.empty(tau.size)
        for K in np.unique(grade):
            sel = np.flatnonzero(grade == K)
            nodes, w = _graded_rule(tau[sel], int(K))
            vals = self.p[i[sel]][:, None] + self._exp_part(i[sel], nodes)
            i1[sel], i2[sel] = (w * vals).sum(axis=1), (w * vals * vals).sum(axis=1)
        return i1, i2

    def integral(self, s: np.ndarray, square: bool = False) -> np.ndarray:
        """:math:`\\int_{-2}^{s} g` (or of :math:`g^2`)."""
        s = np.asarray(s, dtype=float)
        i = self.locate(s)
        i1, i2 = self._partial(i, s - self.start[i])
        out = (self.G2[i].ravel() + i2) if square else (self.G1[i].ravel() + i1)
        return out.reshape(s.shape)


@dataclass(frozen=True)
class ElasticSequenceEnergy(RodSequenceEnergy):
    r"""Energy split with a contact spring, unit :math:`m_{rod} v_0^2`.

    As :class:`~impactsym.rod.continuation.RodSequenceEnergy`, plus :meth:`spring`, the
    energy :math:`N^2/(2\kappa)` stored in the contact spring; :meth:`balance` is
    :math:`\alpha y'^2/2 + N^2/(2\kappa) + E_{rod} - f y - \alpha/2`.

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> energy = impact_sequence(1.0, 0.5, kappa=20.0, t_end=10.0).energy
    >>> bool(np.abs(energy.balance(np.linspace(0.0, 9.9, 100))).max() < 1e-12)
    True
    """

    def spring(self, t):
        return self.sequence.contact_force(t) ** 2 / (2.0 * self.sequence.kappa)

    def balance(self, t):
        return super().balance(t) + self.spring(t)


@dataclass(frozen=True)
class ElasticRodImpactSequence(RodImpactSequence):
    r"""The rod impact with a finite contact stiffness followed up to ``t_end``.

    The attributes of :class:`~impactsym.rod.continuation.RodImpactSequence` (normalized,
    paper section 1): ``contacts`` (spring compressed, :math:`z = y - u > 0`),
    ``separation_speeds``, ``restitution``, ``final``, ``max_fixed_end_stress``; in
    contact the striker is :math:`N/\kappa` ahead of the rod end, and :attr:`energy`
    includes the spring.

    Examples
    --------
    >>> from impactsym.rod import impact_sequence
    >>> seq = impact_sequence(0.5, 0.0, kappa=1e3)
    >>> len(seq.contacts), seq.final
    (1, True)
    >>> rigid = impact_sequence(0.5, 0.0)
    >>> bool(abs(seq.restitution - rigid.restitution) < 1e-2)
    True
    """

    @property
    def energy(self) -> ElasticSequenceEnergy:
        """Striker, spring and rod energies as functions of time."""
        return ElasticSequenceEnergy(self)

    def displacement(self, t):
        """Striker displacement :math:`y = u + N/\\kappa` (in contact) or of the flight."""
        out = np.asarray(super().displacement(t)) + np.asarray(self.contact_force(t)) / self.kappa
        return float(out) if np.ndim(t) == 0 else out

    def velocity(self, t):
        """Striker velocity :math:`y' = u' + N'/\\kappa` (in contact) or of the flight."""
        tt = self._times(t)
        dn = (self._tables.dg(tt) + self._tables.dg(tt - 2.0)) / self.kappa
        if self._flights:
            dn = np.where(self._flight_index(tt)[1], 0.0, dn)
        out = np.asarray(super().velocity(tt)) + dn
        return float(out) if np.ndim(t) == 0 else out


def _first_change(value, slope, second, X: float, what: str, where: str) -> float | None:
    """First sign change (``> 0`` to ``<= 0``) on ``(0, X]`` of a function given by
    ``value(x)``, ``slope(x)`` and a bound ``second(a, b)`` of its second derivative."""

    def evaluate(x, owner):
        return value(x), slope(x), np.zeros_like(x)

    def bound(a, b, owner, *ends):
        return second(a, b)

    nodes = np.linspace(0.0, X, 9)
    try:
        root = first_sign_change(evaluate, bound, nodes, np.zeros(9, dtype=np.int64), 1)
    except RuntimeError as exc:
        raise ValueError(f"{where}: the {what} cannot be certified in float64: {exc}") from exc
    return None if np.isnan(root[0]) else float(root[0])


def _elastic_sequence(
    alpha: float, f: float, kappa: float, t_end: float, max_contacts: int
) -> ElasticRodImpactSequence:
    """The finite-``kappa`` branch of :func:`impactsym.rod.impact_sequence` (arguments
    already validated there: scalars, ``alpha, kappa > 0`` finite, ``f >= 0``).

    Overflow in extreme parameters is not warned about but refused: every table must be
    finite and the energy balance must hold."""
    where = f"impact_sequence(alpha={alpha!r}, f={f!r}, kappa={kappa!r}, t_end={t_end!r})"
    with np.errstate(over="ignore", invalid="ignore"):
        seq = _solve(alpha, f, kappa, t_end, max_contacts, where)
        tab = seq._tables
        numbers = (tab.p, tab.q, tab.G1, tab.G2, np.array(seq.separation_speeds))
        if not (
            all(np.all(np.isfinite(a)) for a in numbers) and np.isfinite(seq.max_fixed_end_stress)
        ):
            raise ValueError(f"{where}: float64 overflows (the parameters are too extreme)")
        try:
            _check_balance(seq)
        except ValueError as exc:
            hint = (
                "; a very soft contact: the striker position u + N/kappa amplifies the "
                "rounding of N by 1/kappa"
                if kappa < 1e-3
                else ""
            )
            raise ValueError(f"{exc} (kappa={kappa!r}{hint})") from exc
    return seq


def _solve(alpha, f, kappa, t_end, max_contacts, where) -> ElasticRodImpactSequence:
    """The event loop of :func:`_elastic_sequence`."""
    rates, d = _rates(alpha, kappa)
    nr = rates.size
    if d is None:
        span = _SPAN / float(np.min(np.abs(rates)))
    else:  # |sqrt(d)| span <= 2 as well: the confluent series stays short and exact
        span = _SPAN / math.sqrt(0.25 * kappa * kappa + abs(d))
    pieces = _Pieces(rates, span)
    pieces.append(-2.0, 2.0, 0.0, np.zeros((nr, 0), dtype=complex))
    contacts, speeds, flights = [], [], []
    t, v, y, u, N = 0.0, 1.0, 0.0, 0.0, 0.0
    in_contact, contact_start, final = True, 0.0, False
    j = 0
    try:
        while t < t_end:
            while j + 1 < len(pieces.start) and pieces.start[j + 1] + 2.0 <= t:
                j += 1
            delta = max(t - (pieces.start[j] + 2.0), 0.0)
            p_in = pieces.p[j]
            Qi = _shift(pieces.q[j], rates, delta)
            t_next = min((pieces.start[j + 1] if j + 1 < len(pieces.start) else t) + 2.0, t_end)
            if t_next <= t:  # no later piece: the last one goes on
                t_next = t_end
            h = t_next - t
            exp_in = Qi.shape[-1] > 0
            if final:
                if exp_in and h > span:
                    h = span
                pieces.append(t, h, -p_in, -Qi)
                t += h
                continue
            if in_contact:
                A0 = N - f
                Gi0 = p_in + float(Qi[:, 0].sum().real) if exp_in else p_in
                dN = kappa * (v - N + 2.0 * Gi0)  # N'(0)
                h = min(h, span)
                if d is not None:
                    QN = _confluent(Qi, rates[0], d, kappa, h, A0, dN, where, t)
                else:
                    QN, dN0 = _forced(Qi, rates, alpha, kappa)
                    QN = _pad(QN, 2)
                    c1 = (dN - dN0 - rates[1] * A0) / (rates[0] - rates[1])
                    QN[0, 0] += c1
                    QN[1, 0] += A0 - c1
                    if rates[0].imag != 0.0:
                        QN[1] = np.conj(QN[0])  # a conjugate pair: the sum is real
                Qg = QN - _pad(Qi, QN.shape[-1])
                _check_magnitude(QN, rates, h, max(1.0, abs(f)), where, t)
                CN = _second(QN, rates)
                root = _first_change(
                    lambda x, QN=QN, N0=N: N0 + _increment(QN, rates, x),
                    lambda x, QN=QN: _slope(QN, rates, x),
                    lambda a, b, CN=CN: _bound_second(CN, rates, a, b),
                    h,
                    "end of contact",
                    where,
                )
                X = h if root is None else root
                pieces.append(t, X, f - p_in, Qg)
                NX = N + float(_increment(QN, rates, np.array([X]))[0])
                dNX = float(_slope(QN, rates, np.array([X]))[0])
                GX = p_in + (_exp_sum(Qi, rates, X) if exp_in else 0.0)
                # u' = N - 2G: u(X) - u(0) = f X + int(N - f) - 2 (p_in X + int(G - p_in))
                ints = _integral(QN, rates, np.array([X])) - 2.0 * _integral(
                    Qi, rates, np.array([X])
                )
                u += (f - 2.0 * p_in) * X + float(ints[0])
                v = dNX / kappa + NX - 2.0 * GX
                t += X
                if root is not None:
                    N = 0.0
                    y = u  # z = 0 at the separation
                    contacts.append((contact_start, t))
                    speeds.append(v)
                    flights.append((t, y, v))
                    in_contact = False
                else:
                    N = NX
                    y = u + N / kappa
            else:
                if exp_in and h > span:
                    h = span
                W = rates[:, None] * Qi + _der(Qi) if exp_in else Qi
                gap0 = u - y
                opening = bool(flights) and flights[-1][0] == t
                if opening:
                    gap0 = 0.0
                v0 = v
                if exp_in:
                    _check_magnitude(Qi, rates, h, max(1.0, abs(p_in)), where, t)

                def gap(x, v0=v0, gap0=gap0, Qi=Qi, p_in=p_in):
                    out = gap0 - (2.0 * p_in + v0) * x - 0.5 * f / alpha * x * x
                    return out - 2.0 * _integral(Qi, rates, x)  # zero for an empty Qi

                def gap_slope(x, v0=v0, Qi=Qi, p_in=p_in):
                    return -2.0 * (p_in + _exp_values(Qi, rates, x)) - v0 - f / alpha * x

                def gap_second(a, b, W=W):
                    return f / alpha + 2.0 * _bound_second(W, rates, a, b)

                if opening and gap_slope(np.array([0.0]))[0] <= 0.0:
                    raise ValueError(
                        f"{where}: tangential separation at t = {t:.10g} (the gap opens with "
                        "zero speed); it cannot be certified in float64"
                    )
                root = _first_change(gap, gap_slope, gap_second, h, "re-contact", where)
                X = h if root is None else root
                pieces.append(t, X, -p_in, -Qi)
                u += -2.0 * (p_in * X + float(_integral(Qi, rates, np.array([X]))[0]))
                y += v * X + 0.5 * f / alpha * X * X
                v += f / alpha * X
                t += X
                if root is not None:
                    if len(contacts) >= max_contacts:
                        raise RuntimeError(
                            f"{where}: more than max_contacts={max_contacts} contacts before "
                            f"t = {t:.6g} (chatter); raise max_contacts or lower t_end"
                        )
                    y = u
                    N = 0.0
                    in_contact, contact_start = True, t
                elif f == 0.0 and v < 0.0:
                    e_rod = 0.5 * alpha * (1.0 - v * v)
                    final = y < -math.sqrt(2.0 * max(e_rod, 0.0)) - 1e-12
    except ValueError as exc:
        if str(exc).startswith(where):
            raise
        raise ValueError(f"{where}: the float64 pieces fail at t = {t:.6g}: {exc}") from exc
    if in_contact:
        contacts.append((contact_start, t_end))
    tables = _Tables.build(pieces, t)
    restitution = -float(speeds[-1]) if (final and f == 0.0) else math.nan
    stress = 2.0 * _g_max(tables, t_end - 1.0) if t_end > 1.0 else 0.0
    return ElasticRodImpactSequence(
        alpha,
        f,
        kappa,
        t_end,
        [(float(a), float(b)) for a, b in contacts],
        [float(s) for s in speeds],
        restitution,
        final,
        stress,
        tables,
        tuple(flights),
    )


def _forced(Qi, rates, alpha, kappa):
    r"""Per-rate polynomials ``M_r`` (``M_r(0) = 0``) of the particular solution of
    :math:`\alpha N'' + \alpha\kappa N' + \kappa N = 2\alpha\kappa G'` (two distinct
    rates) and :math:`\sum_r M_r'(0)`."""
    nr = rates.size
    if Qi.shape[-1] == 0:
        return np.zeros((nr, 0), dtype=complex), 0.0
    W = 2.0 * kappa * (rates[:, None] * Qi + _der(Qi))
    m = np.zeros_like(W)
    c = (rates - rates[::-1])[:, None]  # P'(r) / alpha
    D = W.copy()
    for k in range(W.shape[-1]):  # m' + c m = W: m = sum_k (-1)^k W^(k) / c^(k+1)
        m += (-1.0) ** k * D / c ** (k + 1)
        D = _der(D)
    M = _integ(m)
    return M, float(M[:, 1].sum().real)


def _confluent(Qi, sigma, d, kappa, h, A0, dN, where, t):
    r"""Taylor coefficients of :math:`M` in :math:`N = f + e^{\sigma x} M(x)` (confluent
    form): :math:`M'' - d M = 2\kappa(\sigma Q_i + Q_i')`, :math:`M(0) = N(0) - f`,
    :math:`M'(0) = N'(0) - \sigma M(0)`.

    The recurrence :math:`m_{k+2} = (d m_k + F_k)/((k+1)(k+2))` is exact; past the
    forcing it is homogeneous, :math:`|m_{k+2}| h^{k+2} \le q |m_k| h^k` with
    :math:`q = |d| h^2/((k+1)(k+2))`, so the series is cut where its last two terms on
    :math:`[0, h]` are below ``_TAIL`` of its size (the rest is below twice that)."""
    sigma = sigma.real
    n = Qi.shape[-1]
    F = 2.0 * kappa * (sigma * Qi[0].real + _der(Qi[0].real)) if n else np.zeros(0)
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
                f"{_MAX_COEFFICIENTS} coefficients; lower t_end"
            )
        k += 1
    return np.array(m, dtype=complex)[None, :]


def _increment(Q, rates, x):
    r""":math:`\sum_r e^{rx} Q_r(x) - Q_r(0)`: where :math:`|rx| < 1` as
    :math:`(e^{rx} - 1) Q_r(x) + (Q_r(x) - Q_r(0))` (no cancellation at small ``x``), else
    directly (no cancellation of a large :math:`Q_r(x)` under a vanishing :math:`e^{rx}`)."""
    x = np.asarray(x, dtype=float)
    if Q.shape[-1] == 0:
        return np.zeros_like(x)
    rx = x[..., None] * rates
    vals = _polyval(Q, x)  # x.shape + (n_rates,)
    tail = x[..., None] * _polyval(Q[:, 1:], x) if Q.shape[-1] > 1 else 0.0
    near = _expm1(rx) * vals + tail
    far = np.exp(rx) * vals - Q[:, 0]
    return np.where(np.abs(rx) < 1.0, near, far).sum(axis=-1).real


def _exp_values(Q, rates, x):
    x = np.asarray(x, dtype=float)
    return (np.exp(x[..., None] * rates) * _polyval(Q, x)).sum(axis=-1).real


def _exp_sum(Q, rates, X: float) -> float:
    return float(_exp_values(Q, rates, np.array([X]))[0])


def _slope(Q, rates, x):
    return _exp_values(rates[:, None] * Q + _der(Q), rates, x)


def _check_magnitude(Q, rates, h, scale, where, t) -> None:
    """Refuse where the rounding of the terms of a piece could reach 1e-8."""
    mag = float(_magnitude(Q, rates, h).sum()) * max(Q.shape[-1], 1)
    if mag > _MAGNITUDE_LIMIT * scale:
        raise ValueError(
            f"{where}: the polynomial pieces cancel (their degree grows with every "
            f"reflection that meets the contact): terms of size {mag:.2g} at t = {t:.6g} "
            "would lose more than 1e-8 in float64; lower t_end"
        )


def _g_max(tab: _Tables, s_end: float) -> float:
    """Largest value of ``g`` on ``[0, s_end]`` within ``_STRESS_TOL``: branch and bound
    over cells with the bound of ``|g''|`` of each piece."""
    ends = np.r_[tab.start[1:], np.inf]
    lo = np.maximum(tab.start, 0.0)
    hi = np.minimum(ends, s_end)
    use = np.flatnonzero(hi > lo)
    if use.size == 0:
        return 0.0
    C = _second(tab.q[use].reshape(-1, tab.q.shape[-1]), np.tile(tab.rates, use.size))
    C = C.reshape(use.size, tab.rates.size, -1)
    absC = np.abs(C)
    a, b, own = lo[use] - tab.start[use], hi[use] - tab.start[use], np.arange(use.size)
    best = float(max(tab.g(lo[use]).max(), tab.g(np.nextafter(hi[use], -np.inf)).max()))
    for _ in range(200):
        if a.size == 0:
            return best
        s0 = tab.start[use[own]]
        ga, gb = tab.g(s0 + a), tab.g(np.minimum(s0 + b, np.nextafter(hi[use[own]], -np.inf)))
        best = max(best, float(ga.max()), float(gb.max()))
        powers = b[:, None] ** np.arange(absC.shape[-1])[None, :]
        poly = np.einsum("ck,crk->cr", powers, absC[own])
        M = (np.exp(a[:, None] * tab.rates.real[None, :]) * poly).sum(axis=1) * (1 + 1e-10)
        ub = np.maximum(ga, gb) + M * (b - a) ** 2 / 8.0
        open_ = ub > best + _STRESS_TOL * max(1.0, abs(best))
        a, b, own = a[open_], b[open_], own[open_]
        mid = 0.5 * (a + b)
        a, b, own = np.r_[a, mid], np.r_[mid, b], np.r_[own, own]
    raise RuntimeError("max_fixed_end_stress: branch and bound did not converge")
