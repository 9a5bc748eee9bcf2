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
  Newton steps; :func:`phases_where`, that of several tables in one iteration.

Flat arrays; coefficients ``(fields, first degrees, second degrees)``. Internal to
:mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import chebyshev

from impactsym.contact.lawtable import chebyshev_transform
from impactsym.numeric.roots import bracketed_newton

__all__ = ["evaluate", "fit", "from_unit", "largest", "phase_where", "phases_where", "to_unit"]

#: Targets of several problems solved in one Newton iteration (:func:`phases_where`); a
#: problem of as many in one of its own (larger parts leave the cache: a call's 10^5
#: targets of 39 tables took 0.19 s of CPU in parts of 1024, 0.23 s in parts of 16384).
_PART = 1024


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
    bracketed targets only (:func:`phases_where` of one table)."""
    return phases_where([(coef, x, target, ends)])[0]


def phases_where(
    problems: list[tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, float]]],
) -> list[np.ndarray]:
    """:func:`phase_where` of several problems ``(coef, x, target, ends)`` at once: each
    problem's coefficients in the second variable at its points, then one Newton
    iteration for the bracketed targets of several problems of as many second degrees
    (:data:`_PART`), each's ``J`` tables padded to the most by repeating its last (their
    largest, and the first index of it, unchanged). The iterations of small problems
    cost NumPy's per call more than their arithmetic: by overlap, a call's 117 problems
    of under 300 targets each (neighbours' tables, starts' Jacobians) took 0.054 s of
    CPU one by one, 0.033 s so. Each problem's phases are its own's, the same sums of
    the same terms, but where a target was the last of its problem's iteration: NumPy's
    einsum sums the row of one point's Chebyshev Vandermonde matrix (contiguous) in
    another order than rows among others (strided), a rounding unit apart."""
    out = [np.full(x.size, np.nan) for _, x, _, _ in problems]
    for n2 in sorted({coef.shape[2] for coef, _, _, _ in problems}):
        same = [i for i, problem in enumerate(problems) if problem[0].shape[2] == n2]
        for i, y in zip(same, _solved([problems[i] for i in same]), strict=True):
            out[i] = y
    return out


def _solved(problems):
    """:func:`phases_where` of problems whose tables have as many second degrees: each
    problem's bracketed targets (:func:`_bracketed`), a problem of :data:`_PART` or more
    in a Newton iteration of its own (:func:`_newton`), the smaller gathered into parts
    of about that many."""
    out = [np.full(x.size, np.nan) for _, x, _, _ in problems]

    def solve(part):  # (part: the problems' indices and bracketed targets)
        for (i, (live, *_)), y in zip(part, _newton([b for _, b in part]), strict=True):
            out[i][live] = y

    part, count = [], 0
    for i, problem in enumerate(problems):
        bracketed = _bracketed(*problem)
        if bracketed[0].size >= _PART:
            solve([(i, bracketed)])
            continue
        part.append((i, bracketed))
        count += bracketed[0].size
        if count >= _PART:
            solve(part)
            part, count = [], 0
    if part:
        solve(part)
    return out


def _newton(parts):
    """The phases of the bracketed targets of several problems (:func:`_bracketed`'s
    ``(live, c, t, f_a, f_b, ends)``), one array each: one safeguarded Newton iteration
    from the secant's roots, the tables of each padded to the most ``J``, the slope of
    the largest that of its series (:func:`_slope`)."""
    width = max(part[1].shape[1] for part in parts)
    c = _joined([_padded(part[1], width) for part in parts])
    t, g_lo, g_hi = (_joined([part[k] for part in parts]) for k in (2, 3, 4))
    y_a, y_b = (_joined([np.full(part[0].size, part[5][k]) for part in parts]) for k in (0, 1))
    n2 = c.shape[2]

    def f(y, rows):  # (rows: the bracketed targets' indices, as floats)
        i = rows.astype(np.int64)
        values = np.einsum("ifk,ik->if", c[i], chebyshev.chebvander(y, n2 - 1))
        top = np.argmax(values, axis=1)
        return values[np.arange(i.size), top] - t[i], _slope(c[i, top], y)

    start = y_a - (y_b - y_a) * g_lo / (g_hi - g_lo)
    y = bracketed_newton(f, None, y_a, y_b, [np.arange(t.size, dtype=float)],
                         g_lo=g_lo, g_hi=g_hi, start=start)  # fmt: skip
    return np.split(y, np.cumsum([part[0].size for part in parts])[:-1])


def _bracketed(coef, x, target, ends):
    """The targets of one :func:`phase_where` problem that its ``ends`` bracket:
    ``(live, c, t, f_a, f_b, ends)``, their indices, the tables' coefficients in the
    second variable at their points (:func:`_in_first`), their targets, and the largest
    less the target at either end."""
    c = _in_first(chebyshev.chebvander(x, coef.shape[1] - 1), coef)  # (targets, J, n2)
    v_a, v_b = chebyshev.chebvander(np.array(ends, float), coef.shape[2] - 1)
    f_a = np.einsum("ifk,k->if", c, v_a).max(axis=1) - target
    f_b = np.einsum("ifk,k->if", c, v_b).max(axis=1) - target
    live = np.flatnonzero((f_a <= 0.0) & (f_b >= 0.0) & (f_b > f_a))
    return live, c[live], target[live], f_a[live], f_b[live], ends


def _slope(c, y):
    r"""The derivatives at ``y`` of the Chebyshev series ``c`` (``(n, n2)``) in it:
    :math:`\sum_k k c_k U_{k-1}(y)` (:math:`T_k' = k U_{k-1}`, the second kind by its
    recurrence :math:`U_k = 2 y U_{k-1} - U_{k-2}`), from the series at each point
    itself: its derivative's coefficients at every point (``chebder`` of the tables,
    summed over the first variable as the series are) cost a quarter of the phase
    solve's CPU."""
    u = np.empty((y.size, c.shape[1] - 1))
    u[:, :1] = 1.0  # (none where the series is constant)
    u[:, 1:2] = 2.0 * y[:, None]
    for k in range(2, u.shape[1]):
        u[:, k] = 2.0 * y * u[:, k - 1] - u[:, k - 2]
    return np.einsum("ik,ik->i", c[:, 1:] * np.arange(1.0, c.shape[1]), u)


def _joined(arrays):
    """The ``arrays`` one after another (one alone: itself, not a copy)."""
    return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)


def _padded(a, width):
    """``a`` (``(n, J, k)``) with its last table repeated to ``width`` tables."""
    return a if a.shape[1] == width else a[:, np.minimum(np.arange(width), a.shape[1] - 1)]


def _in_first(vx, coef):
    """The tables ``coef`` (``(J, n1, n2)``) summed over the first variable's degrees
    with ``vx`` (``(n, n1)``): ``(n, J, n2)``, the coefficients in the second variable at
    each point. As one matrix product (bit for bit ``einsum("ij,fjk->ifk")``, twice as
    fast; not by BLAS, whose threads made it ten times slower on this shared machine)."""
    flat = np.ascontiguousarray(np.moveaxis(coef, 1, 0)).reshape(coef.shape[1], -1)
    return np.einsum("ij,jm->im", vx, flat).reshape(vx.shape[0], coef.shape[0], coef.shape[2])
