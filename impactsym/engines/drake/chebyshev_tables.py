r"""Chebyshev tables in two variables over a box, as the change tables of
:mod:`~impactsym.engines.drake.change_table` use them: the first variable the
restitution, the second the phase of the end state's change (or, on a plateau, the
step's share of the way across it), each mapped to ``[-1, 1]``.

* :func:`to_unit`, :func:`from_unit`: a box's points to ``[-1, 1]`` and back;
* :func:`fit`: the coefficients of values on a grid of Chebyshev points of the first
  kind (:func:`~impactsym.contact.lawtable.chebyshev_transform` either way), refused
  where the last two degrees in either variable exceed a share of the values: the table
  is not smooth enough to hold its designs;
* :func:`evaluate`, :func:`largest`: tables at points, and the largest of several;
* :func:`phase_where`: where, in the second variable, the largest of several tables
  meets a target at each first variable (the largest overlap of the states that can be
  deepest: each state's overlap is smooth, which one is deepest is not), by safeguarded
  Newton steps.

Flat arrays; coefficients ``(fields, first degrees, second degrees)``. Internal to
:mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawtable import chebyshev_transform
from impactsym.numeric.roots import bracketed_newton

__all__ = ["evaluate", "fit", "from_unit", "largest", "phase_where", "to_unit"]


def to_unit(x: np.ndarray | float, box: tuple[float, float]) -> np.ndarray | float:
    """The points ``x`` of the ``box`` mapped to ``[-1, 1]`` (the tables' variables).

    >>> to_unit(0.25, (0.0, 1.0))
    -0.5
    """
    return (2.0 * x - (box[0] + box[1])) / (box[1] - box[0])


def from_unit(y: np.ndarray | float, box: tuple[float, float]) -> np.ndarray | float:
    """The points ``y`` of ``[-1, 1]`` mapped into the ``box`` (:func:`to_unit`'s
    inverse)."""
    return 0.5 * (box[0] + box[1]) + 0.5 * (box[1] - box[0]) * y


def fit(values: np.ndarray, tail: float) -> np.ndarray | str:
    """Chebyshev coefficients ``(fields, n1, n2)`` of the values ``(fields, n1, n2)`` at
    the Chebyshev points of the first kind, or, where the last two degrees of a field in
    either variable sum above ``tail`` of its largest value, the variable of the larger
    such tail: ``"restitution"`` (the first) or ``"phase"`` (the second)."""
    m_e, m_p = (chebyshev_transform(count) for count in values.shape[1:])
    coef = np.einsum("ij,fjk,lk->fil", m_e, values, m_p)
    top = np.abs(values).max(axis=(1, 2))
    tail_e = (np.abs(coef[:, -2:, :]).sum(axis=(1, 2)) / top).max()
    tail_phase = (np.abs(coef[:, :, -2:]).sum(axis=(1, 2)) / top).max()
    if max(tail_e, tail_phase) <= tail:
        return coef
    return "phase" if tail_phase >= tail_e else "restitution"


def evaluate(coef: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The tables ``coef`` (``(fields, n1, n2)`` Chebyshev coefficients) at ``(x, y)``
    in ``[-1, 1]^2`` (beyond: extrapolated): ``(fields, points)``."""
    ve = chebyshev.chebvander(x, coef.shape[1] - 1)
    vp = chebyshev.chebvander(y, coef.shape[2] - 1)
    return np.einsum("ij,fjk,ik->fi", ve, coef, vp)


def largest(coef: np.ndarray, x: np.ndarray, y: float) -> np.ndarray:
    """The largest of the tables ``coef`` at the first variables ``x`` and the one
    second variable ``y``."""
    return evaluate(coef, x, np.full(x.size, y)).max(axis=0)


def phase_where(
    coef: np.ndarray, x: np.ndarray, target: np.ndarray, ends: tuple[float, float] = (-1.0, 1.0)
) -> np.ndarray:
    """The second variable ``y`` between ``ends`` (by default the table's ``[-1, 1]``;
    the ends of the phase interval lie beyond a table over a narrower window) where the
    largest of the tables ``coef`` (``(J, n1, n2)``) at the first variables ``x`` equals
    ``target`` (``nan`` where the ends do not bracket it): safeguarded Newton steps
    (:func:`~impactsym.numeric.roots.bracketed_newton`: the largest is not smooth where
    another table becomes the largest) from the secant's root between the ends, for the
    bracketed targets only."""
    vx = chebyshev.chebvander(x, coef.shape[1] - 1)
    c = _in_first(vx, coef)  # (targets, J, n2)
    (y_a, y_b), n = ends, x.size
    v_a, v_b = chebyshev.chebvander(np.array(ends, float), coef.shape[2] - 1)
    f_a = np.einsum("ifk,k->if", c, v_a).max(axis=1) - target
    f_b = np.einsum("ifk,k->if", c, v_b).max(axis=1) - target
    live = np.flatnonzero((f_a <= 0.0) & (f_b >= 0.0) & (f_b > f_a))
    c, t = c[live], target[live]  # (the bracketed ones only, from here)
    dc = _in_first(vx[live], chebyshev.chebder(coef, axis=2))

    def f(y, rows):  # (rows: the bracketed targets' indices, as floats)
        i = rows.astype(np.int64)
        vy = chebyshev.chebvander(y, coef.shape[2] - 1)
        values = np.einsum("ifk,ik->if", c[i], vy)
        top = np.argmax(values, axis=1)
        slope = np.einsum("ik,ik->i", dc[i, top], vy[:, :-1])
        return values[np.arange(i.size), top] - t[i], slope

    out = np.full(n, np.nan)
    start = y_a - (y_b - y_a) * f_a[live] / (f_b[live] - f_a[live])
    out[live] = bracketed_newton(f, None, y_a, y_b, [np.arange(live.size, dtype=float)],
                                 g_lo=f_a[live], g_hi=f_b[live], start=start)  # fmt: skip
    return out


def _in_first(vx, coef):
    """The tables ``coef`` (``(J, n1, n2)``) summed over the first variable's degrees
    with ``vx`` (``(n, n1)``): ``(n, J, n2)``, the coefficients in the second variable at
    each point. As one matrix product (bit for bit ``einsum("ij,fjk->ifk")``, twice as
    fast; not by BLAS, whose threads made it ten times slower on this shared machine)."""
    flat = np.ascontiguousarray(np.moveaxis(coef, 1, 0)).reshape(coef.shape[1], -1)
    return np.einsum("ij,jm->im", vx, flat).reshape(vx.shape[0], coef.shape[0], coef.shape[2])
