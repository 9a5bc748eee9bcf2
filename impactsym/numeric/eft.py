r"""Error-free transformations: sums of float64 products with a rigorous error bound.

NumPy only, elementwise on arrays. In round-to-nearest binary64 without overflow,

* :func:`two_sum` (Knuth): :math:`s + e = a + b` exactly, :math:`s = \mathrm{fl}(a + b)`;
* :func:`two_prod` (Dekker, Veltkamp's split): :math:`p + e = a b` exactly,
  :math:`p = \mathrm{fl}(a b)`, as long as :math:`|e|` does not underflow (an absolute
  ``TINY`` per product covers that in :func:`sum_with_bound`);
* :func:`sum_with_bound` sums terms by cascaded two-sums (Ogita, Rump and Oishi,
  *Accurate sum and dot product*, SIAM J. Sci. Comput. 26 (2005), Sum2):
  :math:`|\hat s - \sum t_i| \le u |\hat s| + \gamma_{n-1}^2 \sum |t_i|`,
  :math:`u = 2^{-53}`, :math:`\gamma_n = n u/(1 - n u)`.

Used to bound the residuals of :mod:`impactsym.rod.elastic.taylor` at the level of the
stored coefficients themselves rather than of the rounding of their evaluation.
"""

from __future__ import annotations

import numpy as np

#: The unit roundoff of float64, ``u = 2^-53``.
UNIT_ROUNDOFF = 2.0**-53
_SPLIT = 2.0**27 + 1.0
#: Absolute slack per product for an underflowing error term (far below any bound used).
TINY = 1e-290


def two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(s, e)`` with ``s = fl(a + b)`` and ``s + e = a + b`` exactly."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = _SPLIT * a
    high = c - (c - a)
    return high, a - high


def two_prod(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(p, e)`` with ``p = fl(a b)`` and ``p + e = a b`` exactly (no under/overflow)."""
    # each factor split in its own shape (a scalar or a row once, not per element of
    # the broadcast), then broadcast by the arithmetic: the same values elementwise
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    p = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    return p, e


def gamma(n: int) -> float:
    """``gamma_n = n u / (1 - n u)``: the relative error bound of ``n`` float operations
    in sequence (Higham)."""
    return n * UNIT_ROUNDOFF / (1.0 - n * UNIT_ROUNDOFF)


def sum_with_bound(terms: list[np.ndarray], n_products: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(s, bound)``: the cascaded sum of ``terms`` (arrays of one shape) and a bound on
    ``|s - exact sum|``, plus ``TINY`` for each of ``n_products`` two-products whose
    terms are among them."""
    if not terms:
        raise ValueError("sum_with_bound needs at least one term, got none")
    terms = np.broadcast_arrays(*terms)
    s = terms[0].astype(float, copy=True)
    err = np.zeros_like(s)
    size = np.abs(terms[0])
    for t in terms[1:]:
        s, e = two_sum(s, t)
        err += e
        size = size + np.abs(t)
    n = len(terms)
    total = s + err
    bound = UNIT_ROUNDOFF * np.abs(total) + gamma(n) ** 2 * size * 4.0 + n_products * TINY
    return total, bound
