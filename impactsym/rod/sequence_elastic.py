r"""A contact spring of stiffness :math:`\kappa`, the step model of the rod impact sequence.

A massless linear spring between striker and rod end (:func:`impactsym.rod.sequence.follow`
runs the loop). With the incoming wave :math:`G(t) = g(t-2)` and the compression
:math:`z = y - u`: in contact (:math:`z > 0`) :math:`N = \kappa z = g + G` and

.. math::

    \alpha y'' = f - N, \qquad N' = \kappa (y' - N + 2 G), \qquad
    \alpha N'' + \alpha\kappa N' + \kappa N = \kappa f + 2 \alpha\kappa G';

in flight :math:`N = 0`, :math:`g = -G`, :math:`\alpha y'' = f`. Every piece of :math:`g`
is :math:`p + \sum_r e^{r x} Q_r(x)` with the roots :math:`r` of
:math:`\alpha s^2 + \alpha\kappa s + \kappa`: one confluent rate :math:`\sigma = -\kappa/2`
with an exact Taylor recurrence where the roots are close (soft, critical, lightly damped
contacts), two real rates split per rate for a stiff contact. Events are first sign
changes certified by :func:`impactsym.numeric.isolation.first_sign_change` with rigorous
bounds of the second derivative. Derivation, the choice of form and accuracy:
docs/physics.md#the-rod-impact-continued-past-separation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from impactsym.numeric.isolation import first_sign_change
from impactsym.numeric.poly import derivative, pad, polyval_rows, taylor_shift
from impactsym.rod.elastic.contact_piece import confluent_series, forced_split
from impactsym.rod.sequence import ElasticRodImpactSequence, SequenceState, follow

__all__ = ["MAX_SPRING_PIECES", "ElasticStep", "follow_spring"]

_EPS = np.finfo(float).eps
_NEGLIGIBLE = 1e-17
_SPAN = 2.0  # longest piece with an exponential part, in units of 1 / min |r|
_GAUSS = np.polynomial.legendre.leggauss(48)  # exact to degree 95 on a sub-interval
# Largest bound of the per-rate parts (relative to max(1, |p|)) times their number of
# coefficients before their rounding, ~eps times it, could reach 1e-8: refused beyond.
_MAGNITUDE_LIMIT = 1e-8 / _EPS
# Contact pieces are halved while their terms exceed _MAGNITUDE_TARGET (rounding 1e-13),
# down to _SHORTEST of the span (a confluent piece) or to the confluent span (a split one,
# which then gives way to the confluent form where that needs at most MAX_SPRING_PIECES pieces).
_MAGNITUDE_TARGET = 1e-13 / _EPS
_SHORTEST = 2.0**-12
#: Most pieces of ``g`` a sequence with a contact spring may hold (up to 8 ms each): the
#: budget of :func:`follow_spring`, and the bound under which the confluent form is used.
MAX_SPRING_PIECES = 20_000
_STRESS_TOL = 1e-13
# Confluent form where |sqrt(d)| <= _CONFLUENT |sigma|: on a piece (length <= 2/|sigma|)
# the split rates differ by at most 2 * 1.8 / length, too little for a per-rate split.
_CONFLUENT = 0.9
_TAIL = 1e-18  # truncation of the confluent series, relative to its size on the piece


def _rates(alpha: float, kappa: float, confluent: bool = False) -> tuple[np.ndarray, float | None]:
    r"""The rates of the representation and, for the confluent form, :math:`d`.

    With :math:`\sigma = -\kappa/2` and :math:`d = \kappa^2/4 - \kappa/\alpha` (exact
    rational arithmetic of the two floats) the roots of
    :math:`\alpha s^2 + \alpha\kappa s + \kappa` are :math:`\sigma \pm \sqrt{d}`. Where
    :math:`d \le \theta^2 \sigma^2` (``_CONFLUENT``; every complex pair) the single rate
    :math:`\sigma` is returned with ``d`` (the confluent form); else (a stiff contact) the
    two real roots and ``None``; ``confluent`` asks for the confluent form whatever
    :math:`d` (the fallback of :func:`follow_spring`).
    """
    sigma = -0.5 * kappa
    ratio = 1 - 4 / (Fraction(alpha) * Fraction(kappa))  # d / sigma^2, exact
    if confluent or ratio <= Fraction(_CONFLUENT) ** 2:
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


def _expm1(z: np.ndarray) -> np.ndarray:
    """:math:`e^z - 1` for complex ``z`` without cancellation at small ``|z|``."""
    a, b = z.real, z.imag
    return np.expm1(a) * np.cos(b) - 2.0 * np.sin(0.5 * b) ** 2 + 1j * np.exp(a) * np.sin(b)


def _polyval(Q: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``Q[..., r, :]`` evaluated at ``x``; result ``x.shape + (n_rates,)`` when ``Q`` is
    2-D, or broadcast row-wise when ``Q`` has the leading axes of ``x``."""
    if Q.ndim == 2 and not np.iscomplexobj(x) and not np.any(Q.imag):
        # real rates (every form the solver builds): one matrix product of the powers
        powers = np.asarray(x, dtype=float)[..., None] ** np.arange(Q.shape[-1])
        return powers @ np.ascontiguousarray(Q.real.T)
    return polyval_rows(Q.astype(complex, copy=False), x[..., None])


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
    dQ = derivative(Q)
    return r * r * Q + 2.0 * r * dQ + derivative(dQ)


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
    """Padded arrays of the pieces for vectorized evaluation: ``start``, ``g``,
    ``integral`` (what :class:`impactsym.rod.sequence.RodImpactSequence` reads) and ``dg``
    (:class:`impactsym.rod.sequence.ElasticRodImpactSequence`)."""

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

    def _exp_part(self, i: np.ndarray, x: np.ndarray, prime: bool = False) -> np.ndarray:
        """Exponential part of piece ``i`` (shape ``(m,)``) at ``x`` (shape ``(m, ...)``),
        or its derivative."""
        Q = self.q[i]  # (m, n_rates, n)
        if prime:
            Q = self.rates[:, None] * Q + derivative(Q)
        lead = (i.size,) + (1,) * (x.ndim - 1)
        out = polyval_rows(Q.reshape((*lead, *Q.shape[1:])), x[..., None])
        return (np.exp(x[..., None] * self.rates) * out).sum(axis=-1).real

    def _at(self, s, prime: bool) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        flat = s.ravel()
        i = self.locate(flat)
        val = self._exp_part(i, flat - self.start[i], prime)
        if not prime:
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


class ElasticStep:
    """A contact spring as a step model of :func:`impactsym.rod.sequence.follow`.

    Internal: built by :func:`impactsym.rod.impact_sequence` (arguments validated there:
    scalars, ``alpha, kappa > 0`` finite, ``f >= 0``). Overflow in extreme parameters is
    not warned about but refused: every table must be finite and the energy balance hold.
    """

    result = ElasticRodImpactSequence
    errstate: dict = {"over": "ignore", "invalid": "ignore"}  # noqa: RUF012 (read only)

    confluent = False  # the confluent form whatever d (the fallback of follow_spring)

    def __init__(self, alpha: float, f: float, *, kappa: float, t_max: float) -> None:
        self.alpha, self.f, self.kappa = alpha, f, kappa
        self.where = f"impact_sequence(alpha={alpha!r}, f={f!r}, kappa={kappa!r}, t_max={t_max!r})"
        self.rates, self.d = _rates(alpha, kappa, self.confluent)
        # |sqrt(d)| span <= 2 as well: the confluent series stays short and exact
        self.confluent_span = _SPAN / math.sqrt(0.25 * kappa * kappa + abs(kappa / alpha))
        if self.d is None:
            self.span = _SPAN / float(np.min(np.abs(self.rates)))
        else:
            self.span = _SPAN / math.sqrt(0.25 * kappa * kappa + abs(self.d))
        self.fallback = False  # a split piece that cancels raises _SplitCancelsError
        n = t_max / self.confluent_span
        self.hint = (  # for the refusal of a split too long for the confluent fallback
            f" (per-rate parts of a stiff contact; the confluent form needs ~{n:.2g} pieces)"
            if self.d is None and n > MAX_SPRING_PIECES
            else ""
        )
        self.pieces = _Pieces(self.rates, self.span)
        self.pieces.append(-2.0, 2.0, 0.0, np.zeros((self.rates.size, 0), dtype=complex))
        self.starts = self.pieces.start
        self.N = 0.0  # contact force at state.t

    def incoming(self, j: int, delta: float) -> tuple:
        """``(p_i, Q_i)`` of incoming piece ``j`` moved ``delta`` past its start."""
        return self.pieces.p[j], _shift(self.pieces.q[j], self.rates, delta)

    def free(self, state: SequenceState, incoming: tuple, t_next: float) -> None:
        p_in, Qi = incoming
        h = t_next - state.t
        if Qi.shape[-1] > 0 and h > self.span:
            h = self.span
        self.pieces.append(state.t, h, -p_in, -Qi)
        state.t += h

    def contact(self, state: SequenceState, incoming: tuple, t_next: float) -> bool:
        alpha, f, kappa, rates, d = self.alpha, self.f, self.kappa, self.rates, self.d
        where = self.where
        p_in, Qi = incoming
        t, v, N = state.t, state.v, self.N
        exp_in = Qi.shape[-1] > 0
        A0 = N - f
        Gi0 = p_in + float(Qi[:, 0].sum().real) if exp_in else p_in
        dN = kappa * (v - N + 2.0 * Gi0)  # N'(0)
        h = min(t_next - t, self.span)
        scale = max(1.0, abs(f))
        if d is None:
            QN, dN0 = forced_split(Qi, rates, alpha=alpha, kappa=kappa)
            QN = pad(QN, 2)
            c1 = (dN - dN0 - rates[1] * A0) / (rates[0] - rates[1])
            QN[0, 0] += c1
            QN[1, 0] += A0 - c1
        while True:  # shorter pieces where the terms of this one would cancel
            if d is not None:
                QN = confluent_series(
                    Qi, rates[0], d, kappa=kappa, h=h, A0=A0, dN=dN, where=where, t=t
                )
                if _terms(QN, rates, h) <= _MAGNITUDE_TARGET * scale or h <= _SHORTEST * self.span:
                    break
            elif not self.fallback or _terms(QN, rates, h) <= _MAGNITUDE_TARGET * scale:
                break
            elif h <= self.confluent_span:
                raise _SplitCancelsError(t)
            h *= 0.5
        Qg = QN - pad(Qi, QN.shape[-1])
        _check_magnitude(QN, rates, h, scale, where, t, self.hint)
        CN = _second(QN, rates)
        root = _first_change(
            lambda x: N + _increment(QN, rates, x),
            lambda x: _slope(QN, rates, x),
            lambda a, b: _bound_second(CN, rates, a, b),
            h,
            "end of contact",
            where,
        )
        X = h if root is None else root
        self.pieces.append(t, X, f - p_in, Qg)
        NX = N + float(_increment(QN, rates, np.array([X]))[0])
        dNX = float(_slope(QN, rates, np.array([X]))[0])
        GX = p_in + (_exp_sum(Qi, rates, X) if exp_in else 0.0)
        # u' = N - 2G: u(X) - u(0) = f X + int(N - f) - 2 (p_in X + int(G - p_in))
        ints = _integral(QN, rates, np.array([X])) - 2.0 * _integral(Qi, rates, np.array([X]))
        state.u += (f - 2.0 * p_in) * X + float(ints[0])
        state.v = dNX / kappa + NX - 2.0 * GX
        state.t += X
        if root is not None:
            self.N = 0.0
            state.y = state.u  # z = 0 at the separation
            return True
        self.N = NX
        state.y = state.u + NX / kappa
        return False

    def flight(self, state: SequenceState, incoming: tuple, t_next: float, opening: bool) -> bool:
        alpha, f, rates, where = self.alpha, self.f, self.rates, self.where
        p_in, Qi = incoming
        t, v0 = state.t, state.v
        exp_in = Qi.shape[-1] > 0
        h = t_next - t
        if exp_in and h > self.span:
            h = self.span
        W = rates[:, None] * Qi + derivative(Qi) if exp_in else Qi
        gap0 = 0.0 if opening else state.u - state.y
        if exp_in:
            _check_magnitude(Qi, rates, h, max(1.0, abs(p_in)), where, t, self.hint)

        def gap(x):
            out = gap0 - (2.0 * p_in + v0) * x - 0.5 * f / alpha * x * x
            return out - 2.0 * _integral(Qi, rates, x)  # zero for an empty Qi

        def gap_slope(x):
            return -2.0 * (p_in + _exp_values(Qi, rates, x)) - v0 - f / alpha * x

        def gap_second(a, b):
            return f / alpha + 2.0 * _bound_second(W, rates, a, b)

        if opening and gap_slope(np.array([0.0]))[0] <= 0.0:
            raise ValueError(
                f"{where}: tangential separation at t = {t:.10g} (the gap opens with "
                "zero speed); it cannot be certified in float64"
            )
        root = _first_change(gap, gap_slope, gap_second, h, "re-contact", where)
        X = h if root is None else root
        self.pieces.append(t, X, -p_in, -Qi)
        state.u += -2.0 * (p_in * X + float(_integral(Qi, rates, np.array([X]))[0]))
        state.y += v0 * X + 0.5 * f / alpha * X * X
        state.v += f / alpha * X
        state.t += X
        if root is not None:
            state.y = state.u
            self.N = 0.0
        return root is not None

    def tables(self, t_reached: float) -> _Tables:
        return _Tables.build(self.pieces, t_reached)

    def g_max(self, tables: _Tables, s_end: float) -> float:
        return _g_max(tables, s_end)

    def check(self, tables: _Tables, stress: float, velocities: list) -> None:
        """Refuse a sequence whose tables overflowed."""
        numbers = (tables.p, tables.q, tables.G1, tables.G2, np.array(velocities))
        if not (all(np.all(np.isfinite(a)) for a in numbers) and np.isfinite(stress)):
            raise ValueError(f"{self.where}: float64 overflows (the parameters are too extreme)")

    def balance_note(self) -> str:
        if self.kappa < 1e-3:
            return (
                " (a very soft contact: the striker position u + N/kappa amplifies the "
                "rounding of N by 1/kappa)"
            )
        return ""


class _SplitCancelsError(ArithmeticError):
    """The per-rate parts of a stiff contact cancel."""


class _ConfluentStep(ElasticStep):
    confluent = True


def follow_spring(
    alpha: float, f: float, *, kappa: float, t_max: float, max_contacts: int
) -> ElasticRodImpactSequence:
    """:func:`impactsym.rod.sequence.follow` of :class:`ElasticStep`; a stiff contact whose
    per-rate split cancels (terms rounding above 1e-13 on pieces as short as the confluent
    ones) is run again in the confluent form if that needs at most ``MAX_SPRING_PIECES`` pieces
    (docs/physics.md#the-rod-impact-continued-past-separation). Internal: called by
    :func:`impactsym.rod.impact_sequence` (arguments validated there)."""
    split = _rates(alpha, kappa)[1] is None
    model = ElasticStep(alpha, f, kappa=kappa, t_max=t_max)
    model.fallback = split and t_max / model.confluent_span <= MAX_SPRING_PIECES
    try:
        return follow(model, t_max=t_max, max_contacts=max_contacts, max_pieces=MAX_SPRING_PIECES)
    except _SplitCancelsError:
        model = _ConfluentStep(alpha, f, kappa=kappa, t_max=t_max)
        return follow(model, t_max=t_max, max_contacts=max_contacts, max_pieces=MAX_SPRING_PIECES)


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
    return _exp_values(rates[:, None] * Q + derivative(Q), rates, x)


def _terms(Q, rates, h) -> float:
    """Bound of the terms of a piece on ``[0, h]`` times their number."""
    return float(_magnitude(Q, rates, h).sum()) * max(Q.shape[-1], 1)


def _check_magnitude(Q, rates, h, scale, where, t, hint="") -> None:
    """Refuse where the rounding of the terms of a piece could reach 1e-8."""
    mag = _terms(Q, rates, h)
    if mag > _MAGNITUDE_LIMIT * scale:
        raise ValueError(
            f"{where}: the terms of the pieces cancel{hint}: terms of size {mag:.2g} at "
            f"t = {t:.6g} would lose more than 1e-8 in float64; lower t_max below {t:.6g}"
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
