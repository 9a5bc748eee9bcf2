r"""Rigid contact: the step model of the rod impact sequence (:mod:`impactsym.rod.sequence`).

In contact (:math:`y = u`, :math:`\alpha y'' = f - N`) the outgoing wave obeys the
neutral delay equation :math:`\alpha g'(t) + g(t) = f + \alpha g'(t-2) - g(t-2)`, in flight
:math:`g(t) = -g(t-2)`. On each piece :math:`g(s) = p + e^{-x} Q(x)`, :math:`x = (s -
s_0)/\alpha`, with float64 coefficients; with the incoming piece :math:`p_i + e^{-x}
Q_i(x)`,

.. math::

    p = f - p_i, \qquad Q(x) = Q(0) + Q_i(x) - Q_i(0) - 2 \int_0^x Q_i, \qquad
    N = f + e^{-x} \bigl(Q(x) + Q_i(x)\bigr),

and in flight :math:`p = -p_i`, :math:`Q = -Q_i`. Separation and re-contact are
certified roots of exponential polynomials :math:`e^x A + B`
(:mod:`impactsym.numeric.exppoly`). Pieces are at most :math:`x = 2` long so that no
polynomial is evaluated far from its origin (the piece-local origin replaces
high-precision arithmetic). Derivation, event functions and accuracy:
docs/physics.md#the-rod-impact-continued-past-separation.
"""

from __future__ import annotations

import functools
import itertools
import math
import operator
from dataclasses import dataclass, field

import numpy as np

from impactsym.numeric.exppoly import (
    exp_poly_bernstein_positive,
    exp_poly_positive,
    exp_poly_roots,
)
from impactsym.numeric.poly import (
    exp_antiderivative,
    exp_antiderivative_at,
    horner,
    polyval_rows,
    taylor_shift_list,
    trim,
)
from impactsym.rod.sequence import RodImpactSequence, SequenceState

__all__ = ["RigidStep"]

_X_MAX = 2.0  # longest piece in x = tau / alpha for a non-constant exponential part
_X_LONG = 40.0  # longest piece with a constant exponential polynomial (e^-40 ~ 4e-18)
_NEGLIGIBLE = 1e-17  # exponential parts bounded below this on their piece are dropped
_MAX_COEFFICIENTS = 96  # the 48-node Gauss rule below is exact to degree 95
# Gauss-Legendre rules for the integrals of g and g^2 on a piece, by the degree d of its
# Q: exact for the polynomial part of g^2 (degree 2d), nodes to spare for e^-x on x <= 2
_GAUSS_BY_DEGREE = [
    (8, np.polynomial.legendre.leggauss(24)),
    (16, np.polynomial.legendre.leggauss(32)),
    (_MAX_COEFFICIENTS, np.polynomial.legendre.leggauss(48)),
]
# each rule's nodes as fractions of [0, 1]
_GAUSS_NODES = [(top, 0.5 * (1.0 + z), w) for top, (z, w) in _GAUSS_BY_DEGREE]
_twice = functools.partial(operator.mul, 2.0)
_G_SAMPLES = 17  # samples per piece that floor the search for the largest g (33 cost more
# in sampling than they save in searches)
_G_FRACTIONS = np.linspace(0.0, 1.0, _G_SAMPLES)
_G_FRACTION_POWERS = np.power.outer(_G_FRACTIONS, np.arange(float(_MAX_COEFFICIENTS)))


def _small_matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` in blocks of rows small enough (at most 2**18 multiply-adds) that
    OpenBLAS runs each on one thread: for these sizes its worker threads cost more CPU
    time than they save."""
    rows = max(1, 2**18 // max(1, a.shape[1] * b.shape[1]))
    if a.shape[0] <= rows:
        return a @ b
    return np.concatenate([a[i : i + rows] @ b for i in range(0, a.shape[0], rows)])


def _bound_exp_part(Q, X: float) -> float:
    """Upper bound of :math:`|e^{-x} Q(x)|` on :math:`[0, X]` (:math:`x^k e^{-x}` is
    largest at :math:`x = k`)."""
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
    """Padded arrays of the pieces for vectorized evaluation: ``start``, ``g``,
    ``integral`` and ``integrals`` (what :class:`impactsym.rod.sequence.RodImpactSequence`
    and its energy read)."""

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
        lengths = np.fromiter(map(len, pieces.q), dtype=np.intp, count=n)
        width = max(int(lengths.max(initial=1)), 1)
        # scattered from one flat array (a list of padded lists costs more to convert)
        flat = np.fromiter(itertools.chain.from_iterable(pieces.q), dtype=float)
        q = np.zeros((n, width))
        rows = np.repeat(np.arange(n), lengths)
        q[rows, np.arange(flat.size) - np.repeat(np.cumsum(lengths) - lengths, lengths)] = flat
        start = np.array(pieces.start)
        p = np.array(pieces.p)
        h = np.diff(start, append=s_end)
        degree = np.maximum(lengths - 1, 0)
        tab = cls(a, start, p, q, np.zeros(n), np.zeros(n), degree)
        i1, i2 = tab._partial(np.arange(n), h)
        tab.G1[1:] = np.cumsum(i1)[:-1]
        tab.G2[1:] = np.cumsum(i2)[:-1]
        return tab

    def _partial(self, i, tau):
        """Integrals of ``g`` and ``g^2`` over ``[start_i, start_i + tau]``: closed form
        for a constant ``Q`` (the only pieces longer than ``x = 2``), else Gauss-Legendre
        with 24 to 48 nodes by the degree of ``Q`` (the closed form's repeated
        derivatives would cancel for ``g^2``)."""
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
            for top, zeta, weight in _GAUSS_NODES:  # nodes enough for the degree
                k = np.flatnonzero((flat_d > low) & (flat_d <= top))
                low = top
                if k.size == 0:
                    continue
                ii, xx = flat_i[k], flat_x[k]
                d = int(flat_d[k].max()) + 1
                # Q at the nodes by Horner's rule: the power sum (Q_k x^k) zeta^k as one
                # matrix product lost 1.3 digits on high degrees with cancellation
                nodes = np.multiply.outer(xx, zeta)
                vals = polyval_rows(self.q[ii, :d][:, None, :], nodes)
                vals *= np.exp(-nodes)
                vals += self.p[ii][:, None]
                half = 0.5 * a * xx  # the rule's weights on [0, x], times alpha
                int1[k] = half * (vals @ weight)
                vals *= vals
                int2[k] = half * (vals @ weight)
            int1, int2 = int1.reshape(x.shape), int2.reshape(x.shape)
        return int1, int2

    def locate(self, s: np.ndarray) -> np.ndarray:
        i = np.searchsorted(self.start, s, side="right") - 1
        return np.minimum(np.maximum(i, 0), len(self.start) - 1)  # (np.clip costs more)

    def g(self, s: np.ndarray) -> np.ndarray:
        """``g(s)`` (right limits at piece starts), zero before the impact."""
        i = self.locate(s)
        x = (s - self.start[i]) / self.alpha
        val = self.p[i] + np.exp(-x) * polyval_rows(self.q[i], x)
        return np.where(s < 0.0, 0.0, val)

    def integral(self, s: np.ndarray, square: bool = False) -> np.ndarray:
        """:math:`\\int_{-2}^{s} g` (or of :math:`g^2`)."""
        return self.integrals(s)[1 if square else 0]

    def integrals(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:math:`\\int_{-2}^{s} g` and :math:`\\int_{-2}^{s} g^2` from one pass."""
        i = self.locate(s)
        i1, i2 = self._partial(i, s - self.start[i])
        return self.G1[i] + i1, self.G2[i] + i2


def _g_max(tab: _Tables, s_end: float) -> float:
    """Largest value of ``g`` on ``[0, s_end]``: piece ends and zeros of ``Q' - Q``,
    searched only on the pieces whose upper bound reaches the largest sampled value
    (docs/physics.md#the-rod-impact-continued-past-separation), the most promising
    first, and not on those the cheap certificates prove below the best value found
    so far (a search costs about ten certificates)."""
    a = tab.alpha
    ends = np.append(tab.start[1:], np.inf)
    live = np.flatnonzero((tab.start < s_end) & (ends > 0.0))
    s0 = tab.start[live]
    lo, hi = np.maximum(s0, 0.0), np.minimum(ends[live], s_end)
    xlo, xhi = (lo - s0) / a, (hi - s0) / a
    x = xlo[:, None] + (xhi - xlo)[:, None] * _G_FRACTIONS
    q = tab.q[live]
    p = tab.p[live]
    # Q at the samples: on pieces sampled from their start (all but the one holding
    # s = 0), Q(X s_j) = sum_k (Q_k X^k) s_j^k, one matrix product; x <= 40 keeps X^k
    # finite (pieces with an exponential part are at most x = 2 long)
    near = (xlo == 0.0) & (xhi <= _X_LONG)
    poly = np.empty_like(x)
    if near.any():
        width = q.shape[1]
        scaled = q[near] * np.power.outer(xhi[near], np.arange(width, dtype=float))
        poly[near] = _small_matmul(scaled, _G_FRACTION_POWERS[:, :width].T)
    if not near.all():
        poly[~near] = polyval_rows(q[~near][:, None, :], x[~near])
    sampled = p[:, None] + np.exp(-x) * poly
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
    slope = np.zeros_like(q)
    slope[:, :-1] = q[:, 1:] * k[1:]
    slope = np.abs(slope - q)
    lipschitz = (slope * m).sum(axis=1)
    step = (xhi - xlo) / (_G_SAMPLES - 1)
    pairs = 0.5 * (sampled[:, 1:] + sampled[:, :-1]).max(axis=1)
    rounding = 64.0 * q.shape[1] * np.finfo(float).eps * (size + np.abs(p))
    bound = np.minimum(p + size, pairs + 0.5 * lipschitz * step + rounding)
    constant = ~q.any(axis=1)
    best = max(0.0, float(p[constant].max())) if constant.any() else 0.0
    keep = np.flatnonzero(~constant & (bound >= floor))
    # the most promising pieces first: the best value found early skips the others
    keep = keep[np.argsort(-sampled[keep].max(axis=1), kind="stable")]
    # a piece equal to one searched before (a free vibration repeats every four time
    # units) is searched only beyond that one's end: best already holds the rest
    searched: dict[tuple, float] = {}
    for i, s0_i, lo_i, X, bound_i in zip(
        live[keep].tolist(),
        s0[keep],
        lo[keep],
        xhi[keep].tolist(),
        bound[keep],
        strict=True,
    ):
        if bound_i <= best:
            continue  # cannot beat the best value so far
        Q = trim(tab.q[i])
        xlo = (lo_i - s0_i) / a
        if lo_i == s0_i:
            key = (tab.p[i], Q.tobytes())
            done = searched.get(key, -1.0)
            if done >= X:
                continue  # searched on [0, done] already
            if done < 0.0 and _below_on_piece(best - tab.p[i], Q, X):
                continue  # proven below the best value so far (cheaper than the search)
            searched[key] = X
            xlo = max(done, 0.0)
        xc = [xlo, X]
        if Q.size > 1:
            crit = exp_poly_roots(
                np.zeros(0), np.append(Q[1:] * np.arange(1.0, Q.size), 0.0) - Q, xlo, X
            )
            xc += ((s0_i + a * crit - s0_i) / a).tolist()  # (as times, then back)
        xc = np.array(xc)
        vals = tab.p[i] + np.exp(-xc) * horner(Q, xc)
        best = max(best, float(vals.max()))
    return best


def _ends_negative(A: list, B: list, X: float) -> bool:
    """Whether :math:`e^X A(X) + B(X)` evaluates below zero: then no certificate of
    positivity on :math:`[0, X]` can succeed (each needs a margin far above the
    rounding of this evaluation): the certificates are skipped for the search that
    will find the root (the same result, for less; on the benchmark's sequences no
    piece proven positive ends negative)."""
    value = horner(B, X)
    if A:
        value += math.exp(X) * horner(A, X)
    return value < 0.0


def _gap_stays_open(C: list, Q_in: list, R: list, alpha: float, X: float) -> bool:
    r"""Whether the flight gap :math:`C(x) + 2 \alpha e^{-x} R(x)` (``C`` quadratic,
    :math:`R - R' = Q_{in}`) is proven positive on :math:`[0, X]` by the quickest
    bound, before the certificates of :mod:`impactsym.numeric.exppoly` (it decides
    about half of the flight pieces that stay open, the striker far from the rod end).

    With gap' :math:`= C' - 2 \alpha e^{-x} Q_{in}` and :math:`|e^{-x} Q_{in}(x)| \le
    \sum_k |q_k| X^k` on the piece, gap(x) :math:`\ge` gap(0) :math:`+ \min(0, C(X) -
    C(0)) - 2 \alpha X \sum_k |q_k| X^k` (:math:`C` is concave: its smallest increment is
    at an end). ``True`` when that bound exceeds :math:`10^{-10}` of the magnitudes that
    round in the gap's evaluation: the search on the same function could then find no
    sign change, so the sequence is the same, bit for bit.
    """
    c0, c1, c2 = C
    if c2 > 0.0:
        return False
    two_alpha = 2.0 * alpha
    lower = c0 + two_alpha * R[0] + min(0.0, (c1 + c2 * X) * X)  # gap(0) + min(...)
    if lower <= 0.0:
        return False  # (most closing gaps end here, before the sums)
    mag_q = 0.0
    for q in reversed(Q_in):
        mag_q = mag_q * X + abs(q)
    lower -= two_alpha * X * mag_q
    if lower <= 0.0:
        return False
    mag_r = 0.0
    for r in reversed(R):
        mag_r = mag_r * X + abs(r)
    scale = abs(c0) + (abs(c1) - c2 * X) * X + two_alpha * mag_r
    return lower > 1e-10 * scale


def _below_on_piece(margin: float, Q: np.ndarray, X: float) -> bool:
    """Whether :math:`e^{-x} Q(x)` is proven below ``margin`` on :math:`[0, X]`: the
    cheap certificates of :mod:`impactsym.numeric.exppoly` applied to
    :math:`e^x m - Q(x) > 0` (``False`` says nothing)."""
    if margin <= 0.0 or X <= 0.0:
        return False
    A, B = [margin], (-Q).tolist()
    return exp_poly_positive(A, B, X) or exp_poly_bernstein_positive(A, B, X)


def _first_root(A: list, B: list, X: float, *, rising_from_zero: bool = False):
    """First certified zero with sign change of :math:`e^x A + B` in :math:`(0, X]`, or
    ``None``."""
    root = exp_poly_roots(A, B, 0.0, X, first=True, rising_from_zero=rising_from_zero)
    return float(root[0]) if root.size else None


class RigidStep:
    """Rigid contact as a step model of :func:`impactsym.rod.sequence.follow`.

    Internal: built by :func:`impactsym.rod.impact_sequence` (arguments validated there).
    The pieces' polynomials are lists of plain floats (NumPy's cost per call dominates
    at these sizes).
    """

    kappa = math.inf
    result = RodImpactSequence
    errstate: dict = {}  # noqa: RUF012 (read only)

    def __init__(self, alpha: float, f: float, *, t_max: float) -> None:
        self.alpha, self.f = alpha, f
        self.where = f"impact_sequence(alpha={alpha!r}, f={f!r}, t_max={t_max!r})"
        self.pieces = _Pieces(alpha)
        self.pieces.append(-2.0, 2.0, 0.0, [])  # rest before the impact
        self.starts = self.pieces.start
        # A flight copies the incoming piece with its sign flipped, so the antiderivative
        # of the copy is the flipped one of the incoming piece, bit for bit: kept per
        # piece index for the flight that meets the copy two time units later.
        self._antiderivatives: dict[int, list] = {}

    def incoming(self, j: int, delta: float) -> tuple:
        """``(j, x-shift, p_i, Q_i)`` of incoming piece ``j`` moved ``delta`` past its
        start: :math:`e^{-\\delta} Q_i(x + \\delta)`."""
        delta = delta / self.alpha
        Q_in = self.pieces.q[j]
        if Q_in and delta > 0.0:
            decay = math.exp(-delta)
            Q_in = list(map(decay.__mul__, taylor_shift_list(Q_in, delta)))
        return j, delta, self.pieces.p[j], Q_in

    def free(self, state: SequenceState, incoming: tuple, t_next: float) -> None:
        _, _, p_in, Q_in = incoming
        self.pieces.append(state.t, t_next - state.t, -p_in, list(map(operator.neg, Q_in)))
        state.t = t_next

    def contact(self, state: SequenceState, incoming: tuple, t_next: float) -> bool:
        alpha, f = self.alpha, self.f
        _, _, p_in, Q_in = incoming
        t, v = state.t, state.v
        h = t_next - t
        p_new = f - p_in
        q0 = Q_in[0] if Q_in else 0.0
        G0 = v + p_in + q0 - p_new
        if Q_in:  # G = G0 + Q_in - q0 - 2 int Q_in
            n = len(Q_in)
            G = [G0]  # (maps: the comprehension's operations, faster)
            G += map(operator.sub, Q_in[1:], map(operator.truediv, map(_twice, Q_in), range(1, n)))
            G.append(-2.0 * Q_in[n - 1] / n)
            B = list(map(operator.add, G, Q_in))
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
            return True
        # with B = 0, N = f >= 0 throughout: no sign change; most pieces are proven
        # positive by the cheap certificate, the others searched
        if (
            not any(B)
            or exp_poly_positive([f], B, X)
            or (not _ends_negative([f], B, X) and exp_poly_bernstein_positive([f], B, X))
        ):
            root = None
        else:
            root = _first_root([f], B, X)
        if root is not None:
            X, h = root, alpha * root
            t_next = t + h
        self.pieces.append(t, h, p_new, G)
        ex = math.exp(-X)
        Gd = list(map(operator.sub, G, Q_in))  # G - Q_in (G is one longer, or Q_in empty)
        Gd.extend(G[len(Gd) :])
        gd_x, r_0, r_x = exp_antiderivative_at(Gd, X)
        state.v = p_new - p_in + ex * gd_x
        state.y += alpha * ((p_new - p_in) * X + r_0 - ex * r_x)
        state.u = state.y
        state.t = t_next
        return root is not None

    def flight(self, state: SequenceState, incoming: tuple, t_next: float, opening: bool) -> bool:
        alpha, f = self.alpha, self.f
        j, delta, p_in, Q_in = incoming
        t, v, y, u = state.t, state.v, state.y, state.u
        h = t_next - t
        if Q_in and h > alpha * _X_MAX:
            h = alpha * _X_MAX
            t_next = t + h
        X = h / alpha
        if Q_in and delta == 0.0 and j in self._antiderivatives:
            R = self._antiderivatives[j]
        else:
            R = exp_antiderivative(Q_in) if Q_in else [0.0]
        C = [u - y - 2 * alpha * R[0], -alpha * (2 * p_in + v), -0.5 * alpha * f]
        if Q_in:
            A, Bgap = C, list(map((2 * alpha).__mul__, R))
            slope = C[0] + C[1] + 2 * alpha * (R[1] if len(R) > 1 else 0.0)
        else:
            A, Bgap = [], C
            slope = C[1]
        if opening and slope < 0.0:
            # at a separation gap' = -N >= 0 exactly; clear a rounding-level slope
            C[1] -= slope
        lo_gap = C[0] + (2 * alpha * R[0] if Q_in else 0.0)
        if lo_gap < 0.0:  # u - y >= 0 in flight; clear a rounding-level overlap
            C[0] -= lo_gap
        # a gap that ends closed is searched at once: no certificate can succeed (most
        # of these pieces hold the re-contact, where the first certificate would fail)
        if _gap_stays_open(C, Q_in, R, alpha, X) or (
            not _ends_negative(A, Bgap, X)
            and (
                exp_poly_positive(A, Bgap, X, rising_from_zero=opening)
                or exp_poly_bernstein_positive(A, Bgap, X, rising_from_zero=opening)
            )
        ):
            root = None  # the gap stays open (the cheap certificates)
        else:
            root = _first_root(A, Bgap, X, rising_from_zero=opening)
        if root is not None:
            X, h = root, alpha * root
            t_next = t + h
        count = len(self.pieces.q)
        self.pieces.append(t, h, -p_in, list(map(operator.neg, Q_in)))
        if len(self.pieces.q) > count and self.pieces.q[-1]:  # (trailing zeros add nothing)
            self._antiderivatives[count] = list(map(operator.neg, R[: len(self.pieces.q[-1])]))
        ex = math.exp(-X)
        state.u = u - 2 * alpha * (p_in * X + (R[0] - ex * horner(R, X) if Q_in else 0.0))
        state.y = y + (v * h + 0.5 * f / alpha * h * h)
        state.v = v + f / alpha * h
        state.t = t_next
        if root is not None:
            state.y = state.u
        return root is not None

    def tables(self, t_reached: float) -> _Tables:
        return _Tables.build(self.pieces, t_reached)

    def g_max(self, tables: _Tables, s_end: float) -> float:
        return _g_max(tables, s_end)

    def check(self, tables: _Tables, stress: float, velocities: list) -> None:
        """Nothing beyond the energy balance."""

    def balance_note(self) -> str:
        return ""
