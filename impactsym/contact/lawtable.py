r"""Piecewise Chebyshev tables of functions of one variable, built adaptively.

Without pressing force, the normalized impact of a contact law is a function of one
number, its damping number (:mod:`impactsym.contact.laws`). :func:`build` tabulates such a
function once, from its exact values, as a piecewise Chebyshev interpolant, and
:class:`ChebyshevTable` evaluates it on whole arrays (``docs/nonlinear_contact.md``,
"Tables without pressing force").

Why this numerics
-----------------
* **Chebyshev interpolation.** On a piece :math:`[a, b]` the function is sampled at the
  ``n`` Chebyshev points of the first kind :math:`x_i = \cos(\pi (i + 1/2)/n)` (never at the
  ends, where the exact function may be singular, e.g. at zero damping) and written as
  :math:`\sum_j c_j T_j(x)`, :math:`c_j = (2/n) \sum_i f_i \cos(j\pi(i + 1/2)/n)`
  (:math:`c_0` halved). For a function analytic around the piece the coefficients fall
  geometrically and the interpolation error is of the order of the first omitted ones.
* **Adaptive pieces.** A piece is accepted when the last :data:`TAIL_TERMS` coefficients
  of every quantity are below ``tail`` times its largest value on the piece plus
  ``floor`` (the absolute accuracy of the exact values, e.g. of a restitution near 0);
  otherwise it is halved. So pieces shrink geometrically towards kinks and singularities
  (a sticking threshold, where the contact time diverges; zero damping, where the force
  condition's release scales with a fractional power of the damping), and converge on
  each side. A piece still unresolved at ``min_width`` is left out (not covered): the
  caller evaluates the exact function there. A quantity constant on all nodes (``inf``,
  the contact time of a sticking body; ``0``, its restitution) is taken as that constant
  where the exact values at both ends of the piece are that constant too (the nodes
  never sit at the ends), so a piece whose nodes and ends all stick is sticking
  throughout (the callers use it where sticking is monotone in the variable); a
  threshold inside it halves it. A piece where a value exceeds ``cap`` is left out
  without halving (near a divergence the exact values grow expensive).
* **One exact call per level.** All nodes of all pieces of one bisection level go to the
  exact function in one call (vectorized), so the building cost is a few calls.
* **Clenshaw on whole arrays.** Evaluation finds each element's piece by binary search
  and runs Clenshaw's recurrence over the degree on all elements at once (a loop of
  ``n`` array operations, never a loop over elements).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: Chebyshev points per piece (the degree plus one).
NODES = 12
#: Coefficients whose size decides that a piece has converged.
TAIL_TERMS = 3
#: Default tail relative to the largest value of the quantity on the piece.
TAIL = 1e-12
#: Default absolute floor of the tail (the exact values' own absolute accuracy).
FLOOR = 1e-14
#: Most pieces a table may have before the build stops splitting (the rest uncovered).
MAX_PIECES = 1000


def chebyshev_points(n: int) -> np.ndarray:
    r"""The ``n`` Chebyshev points of the first kind on ``[-1, 1]``, decreasing.

    >>> chebyshev_points(2).round(6).tolist()
    [0.707107, -0.707107]
    """
    return np.cos(np.pi * (np.arange(n) + 0.5) / n)


def chebyshev_transform(n: int) -> np.ndarray:
    r"""The matrix ``M`` with :math:`c = M f`: Chebyshev coefficients from the values at
    :func:`chebyshev_points`.

    >>> x = chebyshev_points(4)
    >>> (abs(chebyshev_transform(4) @ (2 * x**2 - 1)) > 1e-12).tolist()  # T_2 alone
    [False, False, True, False]
    """
    theta = np.pi * (np.arange(n) + 0.5) / n
    matrix = 2.0 / n * np.cos(np.outer(np.arange(n), theta))
    matrix[0] *= 0.5
    return matrix


@dataclass(frozen=True, eq=False)
class ChebyshevTable:
    r"""A piecewise Chebyshev interpolant of ``k`` quantities on ``[edges[0], edges[-1]]``.

    Attributes
    ----------
    edges : ndarray, shape (m + 1,)
        Increasing break points of the ``m`` pieces.
    coefficients : ndarray, shape (n, k, m)
        ``coefficients[j, q, i]``: the coefficient of :math:`T_j` of quantity ``q`` on
        piece ``i`` (``nan`` on pieces not covered).
    covered : ndarray of bool, shape (m,)
        Whether the piece converged.
    """

    edges: np.ndarray
    coefficients: np.ndarray
    covered: np.ndarray

    @property
    def pieces(self) -> int:
        """The number of pieces."""
        return self.covered.size

    def __call__(
        self, u: np.ndarray, rows: tuple[int, ...] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Values of the quantities ``rows`` (default all) at the flat array ``u``, shape
        ``(len(rows), u.size)``, and where the table covers ``u`` (``nan`` elsewhere).

        >>> t = build(lambda u: np.stack((np.exp(u),)), 0.0, 1.0, min_width=0.1)
        >>> values, inside = t(np.array([0.5, 2.0]))
        >>> bool(abs(values[0, 0] - np.exp(0.5)) < 1e-14), inside.tolist()
        (True, [True, False])
        """
        u = np.asarray(u, dtype=float)
        C = self.coefficients if rows is None else self.coefficients[:, list(rows)]
        piece = np.clip(np.searchsorted(self.edges, u, side="right") - 1, 0, self.pieces - 1)
        inside = (u >= self.edges[0]) & (u <= self.edges[-1]) & self.covered[piece]
        a, b = self.edges[piece], self.edges[piece + 1]
        x = np.where(inside, (2.0 * u - (a + b)) / (b - a), 0.0)
        # Clenshaw: b_j = c_j + 2x b_{j+1} - b_{j+2}, in place on three buffers
        x2 = 2.0 * x
        b1, b2, t = (np.zeros((C.shape[1], u.size)) for _ in range(3))
        with np.errstate(invalid="ignore"):  # inf (a constant piece) times 0 stays nan-free
            for j in range(C.shape[0] - 1, 0, -1):
                np.multiply(x2, b1, out=t)
                t -= b2
                t += np.take(C[j], piece, axis=1)
                b1, b2, t = t, b1, b2
            values = np.take(C[0], piece, axis=1) + x * b1 - b2
        return np.where(inside, values, np.nan), inside


def build(
    fn: Callable[[np.ndarray], np.ndarray],
    lo: float,
    hi: float,
    *,
    min_width: float,
    nodes: int = NODES,
    tail: float = TAIL,
    floor: float = FLOOR,
    cap: float = np.inf,
    start: int = 1,
) -> ChebyshevTable:
    r"""Tabulate ``fn`` on ``[lo, hi]`` by adaptive bisection (module docstring).

    Parameters
    ----------
    fn : callable
        ``fn(u)`` of a flat array returns the quantities, shape ``(k, u.size)``.
    lo, hi : float
        The interval.
    min_width : float
        Pieces are not halved below this width; an unresolved one is left uncovered.
    nodes, tail, floor
        Chebyshev points per piece; the size of the last coefficients, relative to the
        quantity's largest value on the piece plus an absolute ``floor``, at which a piece
        is accepted.
    cap : float
        A piece where a quantity exceeds ``cap`` in size on a node is left uncovered and
        not halved (near a divergence, e.g. of a contact time, the exact values cost too
        much and the interpolant would not converge).
    start : int
        Equal pieces to start from: for a function known to need several, the coarser
        levels are not evaluated.

    Returns
    -------
    ChebyshevTable

    Examples
    --------
    :math:`\sqrt{u}` is singular at 0: the pieces shrink towards it and the first is left
    out; elsewhere the table is exact to rounding:

    >>> t = build(lambda u: np.sqrt(u)[None], 0.0, 1.0, min_width=1e-6)
    >>> values, inside = t(np.array([1e-9, 0.3]))
    >>> inside.tolist(), bool(abs(values[0, 1] - np.sqrt(0.3)) < 1e-14)
    ([False, True], True)
    """
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"the table needs finite lo < hi, got lo = {lo!r}, hi = {hi!r}")
    if not min_width > 0:
        raise ValueError(f"min_width must be positive, got {min_width!r}")
    x = chebyshev_points(nodes)
    transform = chebyshev_transform(nodes)
    cuts = np.linspace(lo, hi, int(start) + 1)
    pending = np.stack((cuts[:-1], cuts[1:]), axis=1)
    done: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []  # (pieces, coeffs, covered)
    count = 0
    while pending.size:
        a, b = pending[:, :1], pending[:, 1:]
        u = (0.5 * (a + b) + 0.5 * (b - a) * x).ravel()
        values = np.asarray(fn(u), dtype=float)
        values = values.reshape(values.shape[0], len(pending), nodes)  # (k, P, n)
        constant = np.all(values == values[..., :1], axis=-1)
        # the nodes never sit at a piece's ends: a quantity constant on them is that
        # constant only where both ends give it too (a sticking threshold between an end
        # and the first node would otherwise be covered as sticking)
        check = np.flatnonzero(np.any(constant, axis=0))
        if check.size:
            ends = np.asarray(fn(pending[check].ravel()), dtype=float)
            ends = ends.reshape(values.shape[0], check.size, 2)
            constant[:, check] &= np.all(ends == values[:, check, :1], axis=-1)
        finite = np.all(np.isfinite(values), axis=-1)
        with np.errstate(invalid="ignore"):
            coeffs = np.einsum("kpi,ji->kpj", np.where(np.isfinite(values), values, 0.0),
                               transform)  # fmt: skip
        scale = np.max(np.abs(np.where(finite[..., None], values, 0.0)), axis=-1)
        small = np.max(np.abs(coeffs[..., -TAIL_TERMS:]), axis=-1) <= tail * scale + floor
        coeffs[constant] = 0.0
        coeffs[..., 0] = np.where(constant, values[..., 0], coeffs[..., 0])
        ok = np.all(constant | (finite & small), axis=0)
        large = np.any(finite & (scale > cap), axis=0)
        ok &= ~large
        count += int(ok.sum())
        done.append((pending[ok], coeffs[:, ok], np.ones(int(ok.sum()), dtype=bool)))
        rest = pending[~ok]
        width = rest[:, 1] - rest[:, 0]
        split = (0.5 * width >= min_width) & ~large[~ok]
        if count + 2 * int(split.sum()) > MAX_PIECES:
            split[:] = False
        stuck = rest[~split]
        done.append((stuck, np.full((values.shape[0], len(stuck), nodes), np.nan),
                     np.zeros(len(stuck), dtype=bool)))  # fmt: skip
        count += len(stuck)
        rest = rest[split]
        mid = 0.5 * (rest[:, 0] + rest[:, 1])
        pending = np.concatenate(
            (np.stack((rest[:, 0], mid), axis=1), np.stack((mid, rest[:, 1]), axis=1))
        )
    pieces = np.concatenate([d[0] for d in done])
    order = np.argsort(pieces[:, 0])
    coefficients = np.concatenate([d[1] for d in done], axis=1)[:, order]
    covered = np.concatenate([d[2] for d in done])[order]
    edges = np.append(pieces[order, 0], pieces[order[-1], 1])
    return ChebyshevTable(
        edges=edges, coefficients=np.ascontiguousarray(coefficients.transpose(2, 0, 1)),
        covered=covered,
    )  # fmt: skip
