r"""Certified real roots of exponential polynomials :math:`F(x) = e^x A(x) + B(x)` (NumPy only).

Separation and re-contact of the continued rod impact are roots of such functions on a
bounded piece :math:`[lo, hi]` (:mod:`impactsym.rod.sequence_rigid`). Sampling can miss a
pair of close roots; this module cannot, up to floating-point rounding. On a
sub-interval :math:`I = [u, u + r]`, with the Taylor coefficients :math:`T_k` of
:math:`F` at :math:`u` and the bounds :math:`\rho_0, \rho_1` of the omitted orders,

.. math::

    |F(x) - T_0| \le \sum_{k \ge 1} |T_k| r^k + \rho_0, \qquad
    |F'(x) - T_1| \le \sum_{k \ge 2} k |T_k| r^{k-1} + \rho_1 \qquad (x \in I),

taken one-sided (only the terms of the sign opposite to :math:`T_0`, resp. :math:`T_1`).
Every sub-interval is proven root-free, proven monotone with one simple root (then
polished by :func:`impactsym.numeric.roots.bracketed_newton_scalar`), or halved; an
interval below ``min_width`` or in rounding noise counts as a root only if its end values
differ in sign, so a tangential touch is no root. :func:`exp_poly_positive` is the first
test on :math:`[0, hi]` alone, without a search, for event loops that test many pieces.
Tail bound, rounding margin and the subdivision rules: See
`docs/physics.md#exp-poly-roots`.
"""

from __future__ import annotations

import functools
import math
import operator
from collections.abc import Sequence
from itertools import accumulate, islice, repeat

import numpy as np

from impactsym.numeric.poly import shift_matrix, trim
from impactsym.numeric.roots import bracketed_newton_scalar

__all__ = ["exp_poly_bernstein_positive", "exp_poly_positive", "exp_poly_roots"]

_EPS = float(np.finfo(float).eps)


_FACT = np.array([math.factorial(k) for k in range(171)], dtype=float)
_INVFACT = 1.0 / _FACT
_INVFACT_LIST = _INVFACT.tolist()
_INVFACT_FROM_1 = _INVFACT_LIST[1:]
_INVFACT_PADDED = [0.0, 0.0, *_INVFACT_LIST]
_ORDER_LIST = [float(k) for k in range(171)]
_ORDER_FROM_1, _ORDER_FROM_2 = _ORDER_LIST[1:], _ORDER_LIST[2:]


def _value_slope(A: list, B: list, x: float) -> tuple[float, float]:
    """``F(x)`` and ``F'(x)`` at one float, Horner in plain Python (``A``, ``B`` lists)."""
    b = db = 0.0
    for c in reversed(B):
        db = db * x + b
        b = b * x + c
    if not A:  # a plain polynomial: no exponential (which could overflow)
        return b, db
    if len(A) == 3:  # the rod's flight gap: the loop below written out (the same sums;
        a2 = A[2]  # its first steps give da = 0, a = A_2 exactly: A is trimmed)
        a = a2 * x + A[1]
        da = a2 * x + a
        a = a * x + A[0]
    else:
        a = da = 0.0
        for c in reversed(A):
            da = da * x + a
            a = a * x + c
    ex = math.exp(x)
    return ex * a + b, ex * (a + da) + db


# _EXPAND[i, k] = 1 / (k - i)! (zero for k < i): e^z z^i = sum_k _EXPAND[i, k] z^k
_LAG = np.subtract.outer(np.arange(171), np.arange(96)).T  # k - i
_EXPAND = np.where(_LAG >= 0, _INVFACT[np.maximum(_LAG, 0)], 0.0)


_LIST_SHIFT_PAIR_MAX = 11  # both shifts by synthetic division up to here (measured)


def _shifted(c: list, u: float) -> tuple[list, list]:
    r"""``c(x + u)`` and the magnitude of its summands (for rounding bounds):
    :math:`\sum_j \binom{j}{i} |u|^{j-i} |c_j|`, the shift of ``|c|`` by ``|u|``."""
    if u == 0.0 or len(c) < 2:  # no shift: the identity (or a constant)
        return c, list(map(abs, c))
    if len(c) > _LIST_SHIFT_PAIR_MAX:  # one matrix for both: cheaper from here on
        S = shift_matrix(len(c), u)
        Smag = np.abs(S) if u < 0.0 else S
        v = np.array(c)
        return (S @ v).tolist(), (Smag @ np.abs(v)).tolist()
    # both by synthetic division in one loop (taylor_shift_list's steps, in its order)
    d, mag, au = list(c), list(map(abs, c)), abs(u)
    n = len(c)
    for i in range(n - 1):
        for k in range(n - 2, i - 1, -1):
            d[k] += u * d[k + 1]
            mag[k] += au * mag[k + 1]
    return d, mag


def _coefficients(A: list, B: list, u: float, M: int) -> tuple[list, list, list]:
    """Taylor coefficients ``T`` of ``F`` at ``u`` (orders 0..M), the magnitudes of
    their summands (for rounding) and :math:`e^u |A(x + u)|` coefficientwise (for the
    omitted orders): what does not depend on the interval's length (lists of floats,
    plain Python: at these sizes NumPy's cost per call dominates)."""
    Bu, Bmag = _shifted(B, u)
    if A:  # e^z Au(z) = sum_k z^k sum_i Au[i] / (k - i)!
        Au, Amag = _shifted(A, u)
        eu = math.exp(u)
        if eu != 1.0:
            Au = [eu * a for a in Au]
            Amag = [eu * a for a in Amag]
        if len(Au) == 1:
            a, am = Au[0], Amag[0]
            T = [a * c for c in _INVFACT_LIST[: M + 1]]
            Tmag = [am * c for c in _INVFACT_LIST[: M + 1]]
        else:  # (one matrix product beats Python's loops from two coefficients on)
            T, Tmag = (np.array([Au, Amag]) @ _EXPAND[: len(Au), : M + 1]).tolist()
        absA = list(map(abs, Au))
    else:
        T, Tmag, absA = [0.0] * (M + 1), [0.0] * (M + 1), []
    n = len(Bu)  # (< M + 1)
    T[:n] = map(operator.add, T, Bu)
    Tmag[:n] = map(operator.add, Tmag, Bmag)
    return T, Tmag, absA


def _dot(a, b) -> float:
    """``sum(a[k] * b[k])`` over plain floats (the shorter length)."""
    return sum(map(operator.mul, a, b))


def exp_poly_positive(
    A: Sequence[float], B: Sequence[float], hi: float, *, rising_from_zero: bool = False
) -> bool:
    """Whether :math:`F(x) = e^x A(x) + B(x)` is proven positive on :math:`[0, hi]`: a
    cheap certificate, no root search.

    With the Taylor coefficients :math:`T_k = B_k + \\sum_i A_i / (k - i)!` of
    :math:`F` at 0 and :math:`0 \\le x \\le hi`,

    .. math::

        F(x) \\ge T_0 + \\sum_{1 \\le k < K} \\min(T_k, 0)\\, hi^k - \\rho_K, \\qquad
        \\rho_K = e^{hi} \\sum_i |A_i| \\frac{hi^K}{(K - i)!},

    the one-sided bound of :func:`exp_poly_roots` on one interval, in plain Python floats
    (cheap enough for every piece of an event loop). ``True`` when the bound is positive
    beyond the rounding margin; ``False`` says nothing (search with
    :func:`exp_poly_roots`). How ``K`` is chosen and the ``rising_from_zero`` form: See
    `docs/physics.md#exp-poly-roots`.

    Parameters
    ----------
    A, B
        Coefficients, lowest order first (lists of floats, either may be empty).
    hi
        Right end of the interval (``hi >= 0``).
    rising_from_zero
        :math:`F(0) = 0` and :math:`F'(0) \\ge 0` are known (a gap that opens):
        positivity on :math:`(0, hi]` is proven with :math:`T_0, T_1` left out.

    Examples
    --------
    :math:`e^x + 1 - 2x` is positive on :math:`[0, 1]` (its minimum is :math:`3 - 2
    \\ln 2`); :math:`e^x - 3` is not:

    >>> exp_poly_positive([1.0], [1.0, -2.0], 1.0), exp_poly_positive([1.0], [-3.0], 1.0)
    (True, False)

    :math:`e^x - 1 - x` rises from a double zero at 0:

    >>> exp_poly_positive([1.0], [-1.0, -1.0], 2.0, rising_from_zero=True)
    True
    """
    if not 0.0 <= hi < math.inf:  # the bound assumes 0 <= x <= hi; NaN fails here too
        raise ValueError(f"exp_poly_positive: hi must be finite and >= 0, got {hi!r}")
    n, m = len(B), len(A)
    lead = 2 if rising_from_zero else 0  # the first coefficient in the bound
    if not lead and m <= 1 and n and (m == 0 or A[0] >= 0.0):  # the rod's contact
        return _constant_times_exp_positive(A[0] if m else 0.0, B, hi)
    if m == 3 and n:  # the rod's flight gap: A quadratic
        return _quadratic_times_exp_positive(A, B, hi, lead)
    nonnegative = all(a >= 0.0 for a in A)
    last = max(n, lead + 1) if nonnegative else max(n, m, lead + 1) + 20
    e_hi = 1.0 if nonnegative else math.exp(hi)
    guard = 64.0 * (max(m, n) + 16) * _EPS * 4.0
    lower = mag = 0.0
    power = 1.0  # hi ** k
    for k in range(max(last, 1)):
        T = B[k] if k < n else 0.0
        Tmag = abs(T)
        for i in range(min(k + 1, m)):
            term = A[i] * _INVFACT_LIST[k - i]
            T += term
            Tmag += abs(term)
        if k == lead:
            if T <= 0.0:
                return False
            lower += T * power
        elif k > lead and T < 0.0:
            lower += T * power
        mag += Tmag * power
        power *= hi
        if k + 1 >= max(n, m, lead + 1) and not nonnegative:  # every (k + 1 - i)! defined
            # omitted orders k + 1, ...: term i contributes at most
            # |A_i| e^hi hi^(k+1) / (k + 1 - i)!
            tail = e_hi * power * sum(abs(a) * _INVFACT_LIST[k + 1 - i] for i, a in enumerate(A))
            if lower - tail > guard * mag:
                return True
            if lower <= guard * mag or tail < 1e-3 * guard * mag:
                return False  # more orders only lower the bound
    return lower > guard * mag


_BERNSTEIN_EXTRA = 8  # most orders of e^x A kept beyond those of B (A with a negative part)


@functools.cache
def _bernstein_ratios(n: int) -> np.ndarray:
    r"""Rows ``i``: :math:`\binom{i}{k} / \binom{n}{k}`, ``k <= i``, zero beyond (monomial
    to Bernstein coefficients of degree ``n`` on ``[0, 1]``)."""
    return np.array(
        [[math.comb(i, k) / math.comb(n, k) for k in range(n + 1)] for i in range(n + 1)]
    )


def exp_poly_bernstein_positive(
    A: list, B: list, X: float, *, rising_from_zero: bool = False
) -> bool:
    r"""Whether :math:`F(x) = e^x A(x) + B(x)` is proven positive on :math:`[0, X]`: the
    second, finer certificate, for callers to try where :func:`exp_poly_positive` fails
    and before a search (the rigid rod's event loop).

    With the Taylor coefficients :math:`T_k = B_k + \sum_i A_i / (k - i)!` of :math:`F`
    kept to order :math:`K`, :math:`F \ge P_K - \rho` on :math:`[0, X]` with
    :math:`\rho = e^X \sum_i |A_i| X^{K+1} / (K + 1 - i)!` (:math:`\rho = 0` where every
    :math:`A_i \ge 0`: the omitted orders are then nonnegative), and :math:`P_K` is at
    least its smallest Bernstein coefficient on :math:`[0, X]` (a convex combination),
    far tighter than the one-sided Taylor bound when the signs of the :math:`T_k`
    alternate. ``rising_from_zero`` (:math:`F(0) = 0`, :math:`F'(0) \ge 0` known, as for
    :func:`exp_poly_roots`): :math:`(F - T_0)/x` is bounded
    instead (positive on :math:`[0, X]`: :math:`F > 0` on :math:`(0, X]`). ``True``
    when the bound exceeds the rounding margin of this module
    (:math:`256 (K + 16)\,\epsilon` times the sum of the magnitudes). A proven
    :math:`F > 0` is a search that finds no root: the sequence is the same, bit for bit
    (checked on the 1000 sequences of benchmarks/bench_rod_sequence.py), where 98% of
    the searches that found no root are now skipped.
    """
    if not 0.0 < X <= 40.0:
        return False
    m, nb = len(A), len(B)
    negative = any(a < 0.0 for a in A)
    lead = 1 if rising_from_zero else 0
    first = max(nb, m, lead + 1) - 1  # the lowest top: every coefficient of B and A kept
    coef, mag, tail = [], 0.0, 0.0
    power = 1.0  # X ** (k - lead)
    e_X = math.exp(X) if negative else 1.0
    a0 = A[0] if m == 1 else 0.0  # (one coefficient, the rod's contact: written out)
    if m == 3:
        a0, a1, a2 = A
        inv = _INVFACT_PADDED  # inv[k + 2] = 1 / k!, zero for k < 0
    for top in range(lead, first + 1 + (_BERNSTEIN_EXTRA if negative else 0)):
        t = B[top] if top < nb else 0.0
        size = abs(t)
        if m == 1:
            term = a0 * _INVFACT_LIST[top]
            t += term
            size += abs(term)
        elif m == 3:  # (the rod's flight gap: the loop below written out, the same sums)
            term = a0 * inv[top + 2]
            t += term
            size += abs(term)
            term = a1 * inv[top + 1]
            t += term
            size += abs(term)
            term = a2 * inv[top]
            t += term
            size += abs(term)
        else:
            for i in range(min(top + 1, m)):
                term = A[i] * _INVFACT_LIST[top - i]
                t += term
                size += abs(term)
        coef.append(t * power)
        mag += size * power
        power *= X
        if negative and top >= first:  # orders top + 1, ...: power is X ** (top + 1 - lead)
            if m == 3:
                tail = abs(a0) * inv[top + 3] + abs(a1) * inv[top + 2] + abs(a2) * inv[top + 1]
            else:
                tail = sum(abs(a) * _INVFACT_LIST[top + 1 - i] for i, a in enumerate(A))
            tail *= e_X * power
            if tail <= 256.0 * _EPS * mag:  # below rounding: more orders add nothing
                break
    n = len(coef) - 1
    floor = tail + 256.0 * (top + 16) * _EPS * (mag + tail)
    # every Bernstein coefficient above the floor (one matrix product: cheaper than
    # stopping at the first one below, as most proofs succeed)
    return bool((_bernstein_ratios(n) @ np.array(coef) > floor).all())


def _constant_times_exp_positive(a: float, B: Sequence[float], hi: float) -> bool:
    """:func:`exp_poly_positive` for ``A = [a]``, ``a >= 0``, ``B`` not empty: the same
    bound (:math:`T_k = B_k + a / k!`, orders from ``len(B)`` on dropped), fewer steps."""
    guard = 64.0 * (len(B) + 16) * _EPS * 4.0
    lower = B[0] + a
    if lower <= 0.0:
        return False
    mag = abs(B[0]) + a
    power = 1.0
    for b, c in zip(islice(B, 1, None), _INVFACT_FROM_1, strict=False):
        power *= hi
        term = a * c
        T = b + term
        if T < 0.0:
            lower += T * power
        mag += (abs(b) + term) * power
    return lower > guard * mag


def _quadratic_times_exp_positive(
    A: Sequence[float], B: Sequence[float], hi: float, lead: int
) -> bool:
    """:func:`exp_poly_positive` for ``len(A) == 3``, ``B`` not empty (``lead``: 2 if
    rising from zero, else 0): the same bound and the same growth of ``K``, the sums
    over ``A`` written out."""
    a0, a1, a2 = A
    n = len(B)
    if a0 >= 0.0 and a1 >= 0.0 and a2 >= 0.0:
        last, e_hi = max(n, lead + 1), 1.0  # the omitted orders are nonnegative
    else:
        last, e_hi = max(n, 3) + 20, math.exp(hi)
    inv = _INVFACT_PADDED  # inv[k + 2] = 1 / k!, zero for k < 0
    first_tail = max(n, 3)
    guard = 64.0 * (max(3, n) + 16) * _EPS * 4.0
    lower = mag = 0.0
    power = 1.0  # hi ** k
    for k in range(last):
        t0, t1, t2 = a0 * inv[k + 2], a1 * inv[k + 1], a2 * inv[k]
        b = B[k] if k < n else 0.0
        T = b + t0 + t1 + t2
        if k == lead:
            if T <= 0.0:
                return False
            lower += T * power
        elif k > lead and T < 0.0:
            lower += T * power
        mag += (abs(b) + abs(t0) + abs(t1) + abs(t2)) * power
        power *= hi
        if k + 1 >= first_tail and e_hi != 1.0:
            K = k + 1  # omitted orders K, ...: term i at most |A_i| e^hi hi^K / (K - i)!
            tail = e_hi * power * (abs(a0) * inv[K + 2] + abs(a1) * inv[K + 1] + abs(a2) * inv[K])
            if lower - tail > guard * mag:
                return True
            if lower <= guard * mag or tail < 1e-3 * guard * mag:
                return False  # more orders only lower the bound
    return lower > guard * mag


#: Cells :func:`exp_poly_roots` may examine before it gives up (a guard far above what
#: the rod's pieces need, `docs/physics.md#exp-poly-roots`).
_MAX_CELLS = 100_000


def exp_poly_roots(
    A: np.ndarray | Sequence[float],
    B: np.ndarray | Sequence[float],
    lo: float,
    hi: float,
    *,
    first: bool = False,
    min_width: float = 1e-13,
    rising_from_zero: bool = False,
) -> np.ndarray:
    """Zeros with a sign change of :math:`F(x) = e^x A(x) + B(x)` in :math:`(lo, hi]`.

    Parameters
    ----------
    A, B
        Polynomial coefficients, lowest order first (empty for a zero polynomial):
        arrays or lists of floats.
    lo, hi
        The interval; ``lo`` itself is excluded (it may be a known zero).
    first
        Return only the smallest root (an array of length 0 or 1).
    min_width
        Width below which an interval that is neither proven root-free nor monotone is
        decided by the signs at its ends (relative to ``max(1, |x|)``).
    rising_from_zero
        The caller knows that :math:`F(lo) = 0` and :math:`F'(lo) \\ge 0` exactly (a
        gap that opens): intervals at ``lo`` are then proven root-free without bisecting
        down to ``min_width`` (`docs/physics.md#exp-poly-roots`).

    Returns
    -------
    numpy.ndarray
        The roots in increasing order, each polished to full precision.

    Examples
    --------
    :math:`e^x - 3 = 0` at :math:`\\ln 3`, and the two zeros of :math:`x^2 - x + 0.2`:

    >>> r = exp_poly_roots(np.array([1.0]), np.array([-3.0]), 0.0, 2.0)
    >>> bool(abs(r[0] - np.log(3.0)) < 1e-15)
    True
    >>> exp_poly_roots(np.array([]), np.array([0.2, -1.0, 1.0]), 0.0, 1.0).round(10).tolist()
    [0.2763932023, 0.7236067977]

    A tangential touch is no sign change, on a subdivision point or not:

    >>> exp_poly_roots(np.array([]), np.array([0.25, -1.0, 1.0]), 0.0, 1.0).size
    0
    """
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"exp_poly_roots: lo and hi must be finite, got [{lo!r}, {hi!r}]")
    Al, Bl = _trimmed_list(A), _trimmed_list(B)
    if hi <= lo or not (Al or Bl):
        return np.empty(0)
    if Al and max(abs(lo), abs(hi)) > 600.0:
        raise ValueError(f"exp_poly_roots: e^x overflows on [{lo!r}, {hi!r}]; rescale x")
    M = max(len(Al), len(Bl)) + 12
    brackets: list[tuple] = []  # (lo, hi, F(lo), F(hi)), the values None if not evaluated
    # Leaves come left to right. A sign change is judged between consecutive points of
    # known nonzero sign (leaf ends, or the proven sign of a root-free leaf), so that
    # an exact zero on a subdivision point counts only if F changes sign across it.
    known = [lo, 0.0, None, None]  # last such point, its sign (0: none yet), an exact zero
    # since, F there if evaluated

    def visit(x: float, sign: float, value: float | None = None) -> None:
        if sign == 0.0:
            if known[2] is None and x > lo:
                known[2] = x
            return
        if known[1] != 0.0 and sign != known[1] and known[0] < x:
            z = known[2]
            brackets.append((known[0], x, known[3], value) if z is None else (z, z, 0.0, 0.0))
        known[:] = [x, sign, None, value]

    b0 = Bl[0] if Bl else 0.0
    at_zero = 1.0 * Al[0] + b0 if Al else b0  # F(0), as _value_slope computes it
    stack = [(lo, hi)]
    at = math.nan  # the last expansion point (T, Tmag, absA: its coefficients)
    guard = 64.0 * (M + 4) * _EPS * 4.0  # rounding margin per unit of summed magnitude
    budget = _MAX_CELLS
    while stack and not (first and brackets):
        budget -= 1
        if budget < 0:  # e.g. an interval far longer than the scale of F (a hang else)
            raise RuntimeError(
                f"exp_poly_roots: more than {_MAX_CELLS} cells on [{lo!r}, {hi!r}]; "
                "the interval is too long for the variation of F, shorten or rescale it"
            )
        u, v = stack.pop()
        r = v - u
        # r**k by repeated products (k roundings at most, far below the margin; an
        # overflow gives inf, as the bounds expect)
        powers = list(accumulate(repeat(r, M), operator.mul, initial=1.0))
        if u != at:  # a left half keeps its left end: the same coefficients
            at = u
            T, Tmag, absA = _coefficients(Al, Bl, u, M)
        # rho0: the omitted orders of e^z A (term i from order M + 1 on) plus rounding
        tail0 = 0.0
        if absA:
            scale = math.exp(r) * powers[M]
            for i, a in enumerate(absA):
                tail0 += a * scale * r * _INVFACT_LIST[M - i + 1]
        noise = guard * _dot(Tmag, powers)
        rho0 = tail0 + noise
        T0 = T[0]
        # one-sided: only terms of the sign opposite to T_0 can bring F to zero (T_0
        # itself never passes the filter)
        if T0 > 0.0:
            s0 = 1.0
            against = -sum([t * p for t, p in zip(T, powers, strict=True) if t < 0.0])
        else:
            s0 = -1.0
            against = sum([t * p for t, p in zip(T, powers, strict=True) if t > 0.0])
        if T0 != 0.0 and abs(T0) > against + rho0:  # no zero in [u, v]: F has T_0's sign
            visit(u, s0)
            visit(v, s0)
            continue
        if rising_from_zero and u == lo and r > 0.0:
            rest = -sum([t * p for t, p in zip(T[3:], powers[1:], strict=False) if t < 0.0])
            if T[2] > rest + rho0 / (r * r):
                visit(v, 1.0)
                continue  # F = T1 z + z^2 (T2 + ...) > 0 on (lo, v]
        T1 = T[1]
        mono = False
        if T1 != 0.0:
            # the same bound rho1 for F' (orders k >= 2 as k T_k r^(k-1))
            terms = zip(_ORDER_FROM_2, islice(T, 2, None), islice(powers, 1, None), strict=False)
            if T1 > 0.0:
                slope_against = -sum([k * t * p for k, t, p in terms if t < 0.0])
            else:
                slope_against = sum([k * t * p for k, t, p in terms if t > 0.0])
            tail1 = 0.0
            if absA:
                for i, a in enumerate(absA):
                    K = M - i + 1  # first omitted power of e^z in term i
                    tail1 += a * scale * (i * _INVFACT_LIST[K] + _INVFACT_LIST[K - 1])
            slope_noise = _dot(map(operator.mul, _ORDER_FROM_1, islice(Tmag, 1, None)), powers)
            mono = abs(T1) > slope_against + (tail1 + guard * slope_noise)
        if (
            mono
            or r <= min_width * max(1.0, abs(u))
            # F is rounding noise all over [u, v]
            or abs(T0) + sum(map(operator.mul, map(abs, T[1:]), powers[1:])) <= 2.0 * noise
        ):
            # (at 0 Horner's scheme gives F = A_0 + B_0, bit for bit: no evaluation)
            Fu = _value_slope(Al, Bl, u)[0] if u != 0.0 else at_zero
            Fv = _value_slope(Al, Bl, v)[0]
            visit(u, _sign(Fu), Fu)
            if Fv == 0.0 and v == hi:
                brackets.append((u, v, Fu, Fv))  # a zero at hi: the sign beyond not examined
            visit(v, _sign(Fv), Fv)
            continue
        mid = u + 0.5 * r
        stack += [(mid, v), (u, mid)]  # left half first
    if not brackets:
        return np.empty(0)
    value_slope = functools.partial(_value_slope, Al, Bl)
    roots = [
        bracketed_newton_scalar(value_slope, a, b, g_lo=ga, g_hi=gb) for a, b, ga, gb in brackets
    ]
    return np.array(roots) if len(roots) == 1 else np.sort(np.array(roots))


_FLOAT_ONLY = frozenset([float])


def _trimmed_list(c) -> list:
    """``c`` as a list of floats without trailing zeros (a list of floats is stripped
    in plain Python: the event loop's pieces are lists)."""
    if type(c) is list and _FLOAT_ONLY.issuperset(map(type, c)):
        n = len(c)
        while n and c[n - 1] == 0.0:
            n -= 1
        return c[:n]
    return trim(c).tolist()


def _sign(x: float) -> float:
    """``numpy.sign`` of one float (NaN stays NaN)."""
    return 1.0 if x > 0.0 else -1.0 if x < 0.0 else x
