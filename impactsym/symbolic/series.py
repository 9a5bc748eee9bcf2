"""Division-free truncated power series over a coefficient ring (paper section 1 inversion).

Internal: used by :mod:`impactsym.symbolic.rational` to compute Laurent coefficients at a
pole without dividing in the polynomial ring of the symbolic coefficients
(``docs/physics.md``, "Delay series and their exact inversion"). Series are coefficient
lists, lowest order first; :class:`Quadratic` adjoins the square root of a discriminant so
that the two roots of an irreducible quadratic factor are handled as one.
"""

from __future__ import annotations

import math
from typing import Any


class Quadratic:
    """Element ``a + b w`` of ``K[w] / (w**2 - D)`` for a ring ``K``: exact arithmetic
    with the square root of a discriminant, without any division.

    Internal: used by :mod:`impactsym.symbolic.rational`.
    """

    __slots__ = ("D", "a", "b")

    def __init__(self, a: Any, b: Any, D: Any) -> None:
        self.a, self.b, self.D = a, b, D

    def _lift(self, other: Any) -> Quadratic:
        if isinstance(other, Quadratic):
            return other
        return Quadratic(other, self.D * 0, self.D)

    def __add__(self, other: Any) -> Quadratic:
        o = self._lift(other)
        return Quadratic(self.a + o.a, self.b + o.b, self.D)

    __radd__ = __add__

    def __sub__(self, other: Any) -> Quadratic:
        o = self._lift(other)
        return Quadratic(self.a - o.a, self.b - o.b, self.D)

    def __neg__(self) -> Quadratic:
        return Quadratic(-self.a, -self.b, self.D)

    def __mul__(self, other: Any) -> Quadratic:
        o = self._lift(other)
        return Quadratic(self.a * o.a + self.b * o.b * self.D, self.a * o.b + self.b * o.a, self.D)

    __rmul__ = __mul__

    def conjugate(self) -> Quadratic:
        return Quadratic(self.a, -self.b, self.D)

    def norm(self) -> Any:
        return self.a * self.a - self.b * self.b * self.D


def series_mul(x: list, y: list, order: int, zero: Any) -> list:
    """Product of two truncated power series (coefficient lists) modulo ``e**order``."""
    out = [zero] * min(order, len(x) + len(y) - 1)
    for i, xi in enumerate(x[:order]):
        for j, yj in enumerate(y[: order - i]):
            out[i + j] = out[i + j] + xi * yj
    return out


def series_pow(x: list, n: int, order: int, zero: Any, one: Any) -> list:
    """``x**n`` modulo ``e**order`` (binomial formula for two-term series)."""
    if len(x) == 2:
        a, b = x
        if n == 0:
            return [one]
        apow = [one]
        for _ in range(n):
            apow.append(times(apow[-1], a, zero, one))
        out, bpow = [], one
        for i in range(min(n, order - 1) + 1):
            out.append(times(bpow * math.comb(n, i), apow[n - i], zero, one))
            bpow = times(bpow, b, zero, one)
        return out
    result = [one]
    base = x[:order]
    while n:
        if n & 1:
            result = series_mul(result, base, order, zero)
        n >>= 1
        if n:
            base = series_mul(base, base, order, zero)
    return result


def times(v: Any, c: Any, zero: Any, one: Any) -> Any:
    """``v * c`` with shortcuts for ``c`` in ``{0, 1, -1}`` (common shifts)."""
    if c == zero:
        return zero
    if c == one:
        return v
    if c == -one:
        return -v
    return v * c


def shifted_series(coeffs: list, h: Any, g: Any, order: int, zero: Any, one: Any) -> list:
    """Coefficients in ``e`` of ``g**d * p((e + h) / g)`` modulo ``e**order`` (Horner),
    where ``coeffs`` lists ``p`` from the leading coefficient down, ``d = deg p``."""
    d = len(coeffs) - 1
    gpow = [one]
    for _ in range(d):
        gpow.append(times(gpow[-1], g, zero, one))
    out = [one * coeffs[0]]
    for i, c in enumerate(coeffs[1:], start=1):
        nxt = [zero] * min(order, len(out) + 1)
        for k, v in enumerate(out):
            if k < order:
                nxt[k] = nxt[k] + times(v, h, zero, one)
            if k + 1 < order:
                nxt[k + 1] = nxt[k + 1] + v
        if c != 0:
            nxt[0] = nxt[0] + times(one * c, gpow[i], zero, one)
        out = nxt
    return out
