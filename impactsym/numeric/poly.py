r"""Polynomial helpers written once (NumPy only): evaluation, calculus, shifts, trimming.

Coefficients are stored lowest order first, along the last axis of an array (or in a
plain list of floats, where the rod sequence's event loop keeps them: at degree < ~20
Python's arithmetic beats NumPy's cost per call). Used by
:mod:`impactsym.numeric.exppoly` and the rod impact sequence
(:mod:`impactsym.rod.sequence_rigid`, :mod:`impactsym.rod.sequence_elastic`), and for
its Hermite basis by the MuJoCo contact's integration and flat design; see
docs/physics.md#the-rod-impact-continued-past-separation.

Internal: none of these names is part of the public interface of the package.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

_MAX_SHIFT = 96  # coefficients that taylor_shift handles (binomials exact in float64)
_BINOM = np.array(
    [[math.comb(b, a) for b in range(_MAX_SHIFT)] for a in range(_MAX_SHIFT)], dtype=float
)
_EXPONENT = np.maximum(
    np.subtract.outer(np.arange(-_MAX_SHIFT, 0), np.arange(-_MAX_SHIFT, 0)) * -1, 0
)


_LIST_SHIFT_MAX = 16  # taylor_shift_list's synthetic division up to here (measured)


def horner(c, x):
    """:math:`\\sum_k c_k x^k` by Horner's scheme (``c`` a list or 1-D array; ``x`` a
    float or an array, broadcast).

    >>> horner([1.0, -2.0, 3.0], 2.0)
    9.0
    """
    out = 0.0 * x
    for ck in reversed(c):
        out = out * x + ck
    return out


def hermite_basis(t):
    """The cubic Hermite basis ``(h00, h10, h01, h11)`` at ``t`` in ``[0, 1]``: the cubic
    with values ``y0, y1`` and slopes ``m0, m1`` (per unit of ``t``) at the ends is
    ``h00 y0 + h10 m0 + h01 y1 + h11 m1``.

    >>> [float(b) for b in hermite_basis(0.5)]
    [0.5, 0.125, 0.5, -0.125]
    """
    return 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2


def cubic_lagrange_weights(s):
    """Lagrange weights of the nodes ``-1, 0, 1, 2`` at ``s`` (an array) and their
    derivatives, each ``(size, 4)``: the cubic through the values ``y`` there (columns)
    is ``sum(w * y, axis=1)``.

    >>> w, dw = cubic_lagrange_weights(np.array([0.5]))
    >>> w.tolist()
    [[-0.0625, 0.5625, 0.5625, -0.0625]]
    >>> (24 * dw).tolist()
    [[1.0, -27.0, 27.0, -1.0]]
    """
    a, b, c, d = s + 1.0, s, s - 1.0, s - 2.0
    w = np.stack([-b * c * d / 6.0, a * c * d / 2.0, -a * b * d / 2.0, a * b * c / 6.0], axis=1)
    dw = np.stack(
        [
            -(c * d + b * d + b * c) / 6.0,
            (c * d + a * d + a * c) / 2.0,
            -(b * d + a * d + a * b) / 2.0,
            (b * c + a * c + a * b) / 6.0,
        ],
        axis=1,
    )
    return w, dw


def cubic_lagrange(x: np.ndarray, y: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cubic Lagrange interpolation of ``y`` (rows over the increasing nodes ``x``, at
    least four) at ``at``, through the four nodes around each point (clamped at the
    ends): ``(values, first)``, ``first`` the index of each stencil's first node.

    >>> x = np.array([0.0, 1.0, 2.0, 4.0, 5.0])
    >>> values, first = cubic_lagrange(x, x[None] ** 3, np.array([1.5, 4.5]))
    >>> values.round(12).tolist(), first.tolist()
    ([[3.375, 91.125]], [0, 1])
    """
    j = np.clip(np.searchsorted(x, at) - 2, 0, x.size - 4)
    out = np.zeros((y.shape[0], at.size))
    for a in range(4):
        w = np.ones(at.size)
        for b in range(4):
            if b != a:
                w = w * (at - x[j + b]) / (x[j + a] - x[j + b])
        out += w * y[:, j + a]
    return out, j


def polyval_rows(C: np.ndarray, x) -> np.ndarray:
    """Row-wise Horner: ``sum_k C[..., k] x**k``, the leading axes of ``C`` broadcast
    against ``x`` (real or complex, in the type of ``C`` and ``x``).

    >>> polyval_rows(np.array([[1.0, 1.0], [0.0, 2.0]]), np.array([3.0, 3.0])).tolist()
    [4.0, 6.0]
    """
    out = np.zeros(np.broadcast_shapes(np.shape(x), C.shape[:-1]), dtype=np.result_type(C, x))
    for k in range(C.shape[-1] - 1, -1, -1):  # in place: no temporary arrays (the same sums)
        out *= x
        out += C[..., k]
    return out


def derivative(c: np.ndarray) -> np.ndarray:
    """Derivative along the last axis, zero padded to the same length.

    >>> derivative(np.array([1.0, 2.0, 3.0])).tolist()
    [2.0, 6.0, 0.0]
    """
    out = np.zeros_like(c)
    n = c.shape[-1]
    out[..., : n - 1] = c[..., 1:] * np.arange(1, n)
    return out


def antiderivative(c: np.ndarray) -> np.ndarray:
    """Antiderivative vanishing at 0 along the last axis (one coefficient longer).

    >>> antiderivative(np.array([1.0, 2.0, 3.0])).tolist()
    [0.0, 1.0, 1.0, 1.0]
    """
    out = np.zeros((*c.shape[:-1], c.shape[-1] + 1), dtype=c.dtype)
    out[..., 1:] = c / np.arange(1, c.shape[-1] + 1)
    return out


def exp_antiderivative(Q: list) -> list:
    r"""``R`` with :math:`\int_0^x e^{-\xi} Q(\xi)\,d\xi = R(0) - e^{-x} R(x)`: the sum
    :math:`R = \sum_j Q^{(j)}` of all derivatives (``Q`` a list of floats).

    Summed from the top, :math:`R_k = Q_k + (k + 1) R_{k+1}`: one rounding per
    coefficient, where summing the derivatives one after another lets large factorial
    terms cancel (docs/physics.md#the-rod-impact-continued-past-separation).

    >>> exp_antiderivative([0.0, 0.0, 1.0])  # x^2 + 2x + 2
    [2.0, 2.0, 1.0]
    """
    R = list(Q)
    for k in range(len(R) - 2, -1, -1):
        R[k] += (k + 1) * R[k + 1]
    return R


def exp_antiderivative_at(Q: list, x: float) -> tuple[float, float, float]:
    r""":math:`Q(x)`, :math:`R(0)` and :math:`R(x)` for ``R = exp_antiderivative(Q)``,
    in one pass from the top: the same operations as :func:`horner` and
    :func:`exp_antiderivative` (bit for bit), without the list of ``R`` (the rod
    sequence's contact pieces need only these three numbers).

    >>> exp_antiderivative_at([0.0, 0.0, 1.0], 1.0)  # R = x^2 + 2x + 2
    (1.0, 2.0, 5.0)
    """
    if not Q:
        return 0.0 * x, 0.0, 0.0 * x
    k = len(Q) - 1
    value = r = r_value = Q[k]  # (Horner's first step: 0 x + c = c)
    for c in reversed(Q[:k]):
        r = c + k * r  # R_k = Q_k + (k + 1) R_{k+1}
        value = value * x + c
        r_value = r_value * x + r
        k -= 1
    return value, r, r_value


def taylor_shift_list(c: list, u: float) -> list:
    r"""Coefficients of :math:`c(x + u)` for a list of floats, in plain Python
    (repeated synthetic division, :math:`n(n - 1)/2` multiply-adds): the event loop's
    form of :func:`taylor_shift`, whose matrix NumPy builds at a cost per call that
    dominates below about 17 coefficients (beyond, the matrix form is used). The same
    value up to rounding (each
    coefficient within a few ulps of :math:`\sum_j \binom{j}{i} |u|^{j-i} |c_j|`).

    >>> taylor_shift_list([0.0, 0.0, 1.0], 2.0)
    [4.0, 4.0, 1.0]
    """
    d = list(c)
    n = len(d)
    if n > _LIST_SHIFT_MAX:  # the matrix form is cheaper there
        return (shift_matrix(n, u) @ np.array(d)).tolist()
    for i in range(n - 1):
        for k in range(n - 2, i - 1, -1):
            d[k] += u * d[k + 1]
    return d


def pad(c: np.ndarray, n: int) -> np.ndarray:
    """``c`` zero padded to ``n`` coefficients along the last axis (``c`` itself if it
    has as many already).

    >>> pad(np.array([1.0]), 3).tolist()
    [1.0, 0.0, 0.0]
    """
    if c.shape[-1] >= n:
        return c
    out = np.zeros((*c.shape[:-1], n), dtype=c.dtype)
    out[..., : c.shape[-1]] = c
    return out


def trim(c) -> np.ndarray:
    """``c`` as a float array without trailing zero coefficients.

    >>> trim([1.0, 0.0, 2.0, 0.0, 0.0]).tolist()
    [1.0, 0.0, 2.0]
    """
    c = np.asarray(c, dtype=float)
    if c.size and c[-1] != 0.0:
        return c
    nz = np.flatnonzero(c)
    return c[: nz[-1] + 1] if nz.size else c[:0]


def shift_matrix(n: int, u: float) -> np.ndarray:
    """Matrix ``S`` with ``S @ c`` the coefficients of ``c(x + u)`` (``n <= 96``
    coefficients: the binomials are exact in float64 up to there).

    >>> shift_matrix(2, 3.0).tolist()
    [[1.0, 3.0], [0.0, 1.0]]
    """
    if n > _BINOM.shape[0]:
        raise ValueError(f"polynomial degree {n - 1} exceeds {_BINOM.shape[0] - 1}")
    if u == 0.0:
        return np.eye(n)
    powers = np.cumprod(np.full(n, float(u)))
    powers[1:] = powers[:-1]
    powers[0] = 1.0
    return _BINOM[:n, :n] * powers[_EXPONENT[:n, :n]]


def taylor_shift(c: np.ndarray, u: float) -> np.ndarray:
    """Coefficients (lowest order first) of :math:`c(x + u)`.

    >>> taylor_shift(np.array([0.0, 0.0, 1.0]), 2.0).tolist()
    [4.0, 4.0, 1.0]
    """
    c = np.asarray(c, dtype=float)
    return shift_matrix(c.size, u) @ c if c.size > 1 else c.copy()


def quadratic_roots_ahead(q0: Any, q1: Any, q2: Any) -> list[np.ndarray]:
    """Both roots ``D > 0`` of ``q0 + q1 D + q2 D^2 / 2`` (arrays; ``inf`` where there is
    none), by the stable quadratic formula (``q2 = 0``: the linear root).

    >>> [r.tolist() for r in quadratic_roots_ahead(np.array([-2.0]), np.array([1.0]), 2.0)]
    [[inf], [1.0]]
    """
    a = 0.5 * q2
    with np.errstate(all="ignore"):
        disc = q1 * q1 - 4.0 * a * q0
        qq = -0.5 * (q1 + np.copysign(np.sqrt(disc), q1))
        out = []
        for r in (qq / a, q0 / qq):
            out.append(np.where(np.isfinite(r) & (r > 0) & (disc >= 0), r, np.inf))
    return out


def quadratic_at(q0: Any, q1: Any, q2: Any, D: Any) -> np.ndarray:
    """``q0 + q1 D + q2 D^2 / 2`` (``nan`` where ``D`` is ``inf``).

    >>> quadratic_at(np.array([-2.0]), np.array([1.0]), 2.0, np.array([1.0, np.inf])).tolist()
    [0.0, nan]
    """
    with np.errstate(all="ignore"):
        return np.where(np.isfinite(D), q0 + q1 * D + 0.5 * q2 * D * D, np.nan)
