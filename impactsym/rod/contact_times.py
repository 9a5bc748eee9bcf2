"""Contact times of the rod impact: certified first sign changes of :math:`y(t)` and :math:`N(t)`.

No sampling: the first sign change is isolated with rigorous bounds on the second
derivative (:mod:`impactsym.numeric.isolation`) and refined with
:func:`impactsym.numeric.bracketed_newton`. On a grid, rigid pairs of equal ``alpha``
share the proofs that a reflection interval holds no sign change (:func:`_screen_interval`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from impactsym.numeric.isolation import first_sign_change
from impactsym.rod.elastic import T_LIMIT_ELASTIC, _elastic, _elastic_model
from impactsym.rod.elastic_table import _cell_table
from impactsym.rod.elastic_taylor import (
    MAX_CELLS,
    _cells_per_interval,
    _fastest_rate,
    _taylor_table,
)
from impactsym.rod.kernel import (
    T_LIMIT,
    _next_integrals,
    _next_laguerre,
    _rescale,
    _rigid_tables,
    check_alpha,
)
from impactsym.validation import broadcast, check_condition, finish, real_array

__all__ = ["ContactTimeMap", "contact_time", "contact_time_map"]

#: Largest contact-spring pole |s| (time scale 1/|s|) for finite-kappa contact times.
_FASTEST_POLE = 1e8
#: Initial nodes per unit of sqrt((m + 1) x) on reflection interval m (tuned by cell counts).
_INITIAL_DENSITY = {"N": 2.0, "y": 0.25}
#: Pairs per certified search (bounds the memory of its cells) and table entries per
#: chunk of distinct alpha (the rigid tables hold O(n_alpha * t_max) numbers).
_SEARCH_CHUNK, _TABLE_ENTRIES = 32768, 2**22
#: Strides in f of the searched pairs per alpha (:func:`_screen_interval`), used where
#: at least _SCREEN_MIN_PAIRS pairs per alpha are in contact (tuned on atlases).
_SCREEN_STRIDES, _SCREEN_MIN_PAIRS = (64, 1), 16
#: Largest proven error of the finite-kappa cell polynomials (units of ``y`` resp.
#: ``N``) for them to stand for the function; the measured error is about 1e-14.
_TABLE_TOLERANCE = 1e-12
#: Default search horizons (rigid, finite stiffness).
T_MAX_RIGID, T_MAX_ELASTIC = 100.0, 20.0


def _check_t_max(t_max, rigid):
    if t_max is None:
        return None
    value, scalar = real_array("t_max", t_max, lower=0.0, strict=True)
    if not scalar:
        raise TypeError(f"t_max must be a real number, got {t_max!r}")
    limit = T_LIMIT if rigid else T_LIMIT_ELASTIC
    if value > limit:
        kind = "rigid contact" if rigid else "finite kappa"
        raise ValueError(f"t_max must be <= {limit:g} for {kind}, got {float(value)!r}")
    return float(value)


class _RigidInterval:
    """``y`` or ``N`` on reflection interval ``m`` for many pairs, in ``x = 2 tau / alpha``.

    With the Laguerre functions :math:`E_j(x) = e^{-x/2} L_j(x)` and the coefficients
    :math:`a_j = c_{m-j}` of :mod:`impactsym.rod.kernel`, :math:`N = f + \\sum_j a_j
    E_j(x)` and :math:`y_{xx} = -\\frac{\\alpha}{4}(N - f)`. Bounds on the second
    derivative over a cell ``[a, b]`` use :math:`|E_j| \\le 1` on :math:`x \\ge 0`
    (Szegő, eq. (7.21.3)) and the Laguerre identities :math:`x E_j' = -x E_j/2 +
    j(E_j - E_{j-1})`, :math:`x E_j'' + E_j' + (j + 1/2 - x/4) E_j = 0`:

    .. math::

        |N'| \\le \\min\\Bigl(C_1, \\frac{C_0}{2} + \\frac{J_1}{a}\\Bigr), \\qquad
        |N''| \\le \\min\\Bigl(C_2, \\frac{|N'|_{\\max} + |1/2 - x/4|_{\\max}
        |N - f|_{\\max} + J_0}{a}\\Bigr),

    :math:`C_0 = \\sum |a_j|`, :math:`J_0 = \\sum j |a_j|`, :math:`J_1 = \\sum_k
    |k a_k - (k+1) a_{k+1}|` and :math:`C_1, C_2` the sums of the absolute
    coefficients of :math:`N', N''` in the :math:`E_k` basis (:math:`E_j' = -E_j/2 -
    \\sum_{k<j} E_k`); :math:`|N - f|_{\\max} \\le \\min(C_0, \\max(|N(a) - f|,
    |N(b) - f|) + |N'|_{\\max} h / 2)`, and :math:`|N'|_{\\max}` is tightened once with
    the slopes at the cell ends, :math:`\\max(|N'(a)|, |N'(b)|) + |N''|_{\\max} h / 2`.
    For ``y``: :math:`|y_{xx}| \\le \\frac{\\alpha}{4} |N - f|_{\\max}`.
    """

    def __init__(self, which, m, coef, alpha, f, y0, v0):
        self.which, self.m, self.coef = which, m, coef  # coef: (m + 1, n_pairs)
        # N' = -(N - f)/2 - sum_j tail_j E_j, tail_j = sum_(i>j) a_i
        self.tail = np.cumsum(coef[::-1], axis=0)[::-1] - coef
        self.alpha, self.f, self.y0, self.v0 = alpha, f, y0, v0
        j = np.arange(m + 1)[:, None]
        absc = np.abs(coef)
        self.C0 = absc.sum(axis=0)
        self.J0 = (j * absc).sum(axis=0)
        shifted = np.zeros_like(coef)
        shifted[:-1] = j[1:] * coef[1:]
        self.J1 = np.abs(j * coef - shifted).sum(axis=0)
        d1 = self._derivative(coef)
        self.C1 = np.abs(d1).sum(axis=0)
        self.C2 = np.abs(self._derivative(d1)).sum(axis=0)

    @staticmethod
    def _derivative(coef):
        """E-basis coefficients of the derivative: a'_k = -a_k/2 - sum_(j>k) a_j."""
        tail = np.cumsum(coef[::-1], axis=0)[::-1] - coef
        return -0.5 * coef - tail

    def __call__(self, x, own):
        """``(g, dg/dx, N - f)`` at ``x`` for pairs ``own``."""
        m, size = self.m, x.size
        scaled = size > 0 and x.max() > 1400.0
        if scaled:
            log_scale = -0.5 * x
            scale = np.exp(log_scale)
            E = np.ones(size)
        else:
            E = np.exp(-0.5 * x)
        E_prev, tmp, buf = np.zeros(size), np.empty(size), np.empty(size)
        S0, S1, total = np.zeros(size), np.zeros(size), np.zeros(size)
        is_y = self.which == "y"
        if is_y:
            I1 = -2.0 * np.expm1(-0.5 * x)
            I2 = 2.0 * x - 2.0 * I1
        for j in range(m + 1):
            if j > 0:
                E, E_prev, tmp = _next_laguerre(j, x, E, E_prev, tmp)
                if scaled:
                    _rescale(E, E_prev, scale, log_scale)
            Et = E * scale if scaled else E
            aj = self.coef[j][own]
            np.multiply(aj, Et, out=buf)
            S0 += buf
            if is_y:
                if j > 0:
                    I1, I2, buf = _next_integrals(E, E_prev, I1, I2, buf, scale if scaled else None)
                np.multiply(aj, I1, out=buf)
                S1 += buf
                np.multiply(aj, I2, out=buf)
                total += buf
            else:
                np.multiply(self.tail[j][own], Et, out=buf)
                S1 += buf
        if is_y:
            al = self.alpha[own]
            v0 = self.v0[own]
            g = self.y0[own] + v0 * (0.5 * al * x) - 0.25 * al * total
            dg = 0.5 * al * v0 - 0.25 * al * S1
            return g, dg, S0
        return self.f[own] + S0, -0.5 * S0 - S1, S0

    def bound(self, a, b, own, Sa, Sb, da=None, db=None):
        """Rigorous bound on ``|g''|`` (in ``x``) over the cells ``[a, b]``."""
        h = b - a
        C0, C1, C2 = self.C0[own], self.C1[own], self.C2[own]
        positive = a > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(positive, 1.0 / a, np.inf)
            J1 = self.J1[own]  # J1 = 0 (e.g. N = f, all a_j = 0) must not meet 1/a = inf
            M1 = np.minimum(C1, 0.5 * C0 + np.where(J1 > 0.0, J1 * inv, 0.0))  # |N'|
            end = np.maximum(np.abs(Sa), np.abs(Sb))
            sup = np.minimum(C0, end + 0.5 * h * M1)  # |N - f|
            if self.which == "y":
                return 0.25 * self.alpha[own] * sup
            weight = np.maximum(0.5, 0.25 * b - 0.5)  # |1/2 - x/4|
            M2 = np.where(positive, np.minimum(C2, (M1 + weight * sup + self.J0[own]) * inv), C2)
            # once more with |N'| from the slopes at the cell ends
            M1 = np.minimum(M1, np.maximum(np.abs(da), np.abs(db)) + 0.5 * h * M2)
            sup = np.minimum(sup, end + 0.5 * h * M1)
            local = (M1 + weight * sup + self.J0[own]) * inv
            return np.where(positive, np.minimum(M2, local), M2)


def _interval_tables(alpha, n_intervals):
    """:func:`impactsym.rod.kernel._rigid_tables` with ``B`` as ``c_d = Bs_d + f Bd_d``."""
    B, Y0, Y1, V0, V1 = _rigid_tables(alpha, n_intervals)
    return B[:, :-1] + B[:, 1:], B[:, :-1] - B[:, 1:], Y0, Y1, V0, V1


def _rigid_interval(which, m, tables, row, alpha, f):
    """:class:`_RigidInterval` on interval ``m`` for pairs ``(alpha, f)``, ``alpha`` at
    rows ``row`` of ``tables`` (:func:`_interval_tables`)."""
    Bs, Bd, Y0, Y1, V0, V1 = tables
    d = m - np.arange(m + 1)
    coef = (Bs[row][:, d] + f[:, None] * Bd[row][:, d]).T
    y0 = Y0[row, m] + f * Y1[row, m]
    v0 = V0[row, m] + f * V1[row, m]
    return _RigidInterval(which, m, coef, alpha, f, y0, v0)


def _search_interval(which, m, tables, row, alpha, f, t_max):
    """Certified first sign change of ``y`` or ``N`` on reflection interval ``m``.

    Returns ``(x, positive)`` per pair: the root in ``x = 2 tau / alpha`` (NaN if none)
    and whether ``g > 0`` was proved on the whole interval
    (:func:`impactsym.numeric.isolation.first_sign_change` with ``certify=True``).
    """
    x_root, positive = np.full(alpha.size, np.nan), np.zeros(alpha.size, dtype=bool)
    for start in range(0, alpha.size, _SEARCH_CHUNK):
        sl = slice(start, start + _SEARCH_CHUNK)
        al = alpha[sl]
        model = _rigid_interval(which, m, tables, row[sl], al, f[sl])
        x_end = 2.0 * np.minimum(2.0, t_max - 2.0 * m) / al
        # initial cells uniform in sqrt(x) (the Laguerre phase is ~ 2 sqrt(m x)); the
        # halving refines where the bounds ask for it. N: about one node per radian of
        # phase, near the cells the bound on |N''| ends up needing (fewer halving rounds
        # and cells); y (smoother, y'' = -alpha (N - f)/4) is decided on coarse cells
        n0 = 2 + np.ceil(_INITIAL_DENSITY[which] * np.sqrt((m + 1) * x_end)).astype(np.int64)
        owner = np.repeat(np.arange(al.size), n0 + 1)
        first = np.cumsum(n0 + 1) - (n0 + 1)
        k = np.arange(owner.size) - first[owner]
        nodes = x_end[owner] * (k / n0[owner]) ** 2
        x_root[sl], positive[sl] = first_sign_change(
            model, model.bound, nodes, owner, al.size, certify=True
        )
    return x_root, positive


def _screen_interval(search, row, strides):
    """First sign change on one reflection interval for pairs sorted by ``(alpha, f)``,
    searching only some of them.

    For a fixed ``alpha``, ``g = y`` or ``N`` is affine in ``f`` (:func:`_rigid_interval`):
    where ``g > 0`` is proved on the whole interval for ``f_1`` and ``f_2`` (``search``
    returns ``positive``), it holds for every ``f`` between them, whose search would find
    no sign change. So the pairs of each ``alpha`` are searched at the first stride, a
    run between two searched pairs is settled as a whole when both are proved positive,
    and the other runs are searched at the next stride, down to the last stride, 1.
    ``search(positions) -> (x, positive)``; returns ``x`` per pair (NaN: no sign change
    on this interval).
    """
    n = row.size
    x_root, positive = np.full(n, np.nan), np.zeros(n, dtype=bool)
    searched = np.zeros(n, dtype=bool)
    lo = np.flatnonzero(np.r_[True, row[1:] != row[:-1]])
    hi = np.r_[lo[1:], n] - 1
    for stride in strides:
        if lo.size == 0:
            break
        # nodes lo, lo + stride, ..., hi of every open run
        count = 1 + -(-(hi - lo) // stride)
        run = np.repeat(np.arange(lo.size), count)
        k = np.arange(run.size) - np.repeat(np.cumsum(count) - count, count)
        nodes = np.minimum(lo[run] + k * stride, hi[run])
        todo = np.unique(nodes[~searched[nodes]])
        if todo.size:
            x_root[todo], positive[todo] = search(todo)
            searched[todo] = True
        same = run[1:] == run[:-1]
        lo, hi = nodes[:-1][same], nodes[1:][same]
        still = ~(positive[lo] & positive[hi]) & (hi - lo > 1)
        lo, hi = lo[still], hi[still]
    if lo.size:
        raise ValueError(f"strides must end with 1, got {strides!r}")
    return x_root


def _rigid_contact_times(which, alpha, f, t_max):
    """First sign change of ``y`` or ``N`` in ``(0, t_max]`` for flat pairs; inf if none.

    Interval 0 holds none: there :math:`N = y' = f + (1 - f) e^{-t/\\alpha} > 0`. On
    every later interval the pairs still in contact are screened per ``alpha``
    (:func:`_screen_interval`) with the certified search :func:`_search_interval`.
    """
    n_int = int(np.ceil(t_max / 2.0))
    order = np.lexsort((f, alpha))
    a_sorted, f_sorted = alpha[order], f[order]
    new = np.r_[True, a_sorted[1:] != a_sorted[:-1]] if a_sorted.size else np.ones(0, bool)
    row_all = np.cumsum(new) - 1
    # chunks of whole alpha groups: the tables hold O(n_alpha * n_int) numbers
    per_chunk = max(1, _TABLE_ENTRIES // (n_int + 1))
    edges = np.r_[np.flatnonzero(new)[::per_chunk], a_sorted.size]
    out = np.full(a_sorted.size, np.inf)
    for lo, hi in itertools.pairwise(edges):
        al_all, f_all = a_sorted[lo:hi], f_sorted[lo:hi]
        rows = row_all[lo:hi] - row_all[lo]
        tables = _interval_tables(al_all[new[lo:hi]], n_int + 1)
        active = np.arange(hi - lo)  # sorted by (alpha, f)
        for m in range(1, n_int):
            if active.size == 0:
                break
            row, al, ff = rows[active], al_all[active], f_all[active]

            def search(pos, m=m, tables=tables, row=row, al=al, ff=ff):
                return _search_interval(which, m, tables, row[pos], al[pos], ff[pos], t_max)

            # screening pays where many pairs share an alpha; else search them all
            n_alpha = 1 + np.count_nonzero(row[1:] != row[:-1])
            crowded = active.size >= _SCREEN_MIN_PAIRS * n_alpha
            x_root = _screen_interval(search, row, _SCREEN_STRIDES if crowded else (1,))
            hit = np.isfinite(x_root)
            out[lo + active[hit]] = 2.0 * m + 0.5 * al[hit] * x_root[hit]
            active = active[~hit]
    result = np.empty(alpha.size)
    result[order] = out
    return result


def _elastic_contact_times(which, alpha, f, kappa, t_max, *, method="taylor"):
    r"""First sign change in ``(0, t_max]`` for flat pairs with finite ``kappa``.

    Pairs are grouped by ``(alpha, kappa)``; ``g`` starts at ``g(0) = 0`` with
    ``g'(0) > 0`` (``N' = kappa``, ``y' = 1``). Per group the time function is a
    certified piecewise polynomial :math:`g = A + f B` (built once, shared by every
    ``f``): the Taylor table of the delay equations,
    :class:`impactsym.rod.elastic_taylor.TaylorTable` (``method="taylor"``, float64,
    milliseconds), or for springs too stiff for it (more than
    ``elastic_taylor.MAX_CELLS`` cells per reflection interval) and with
    ``method="cells"`` the mpmath cell table of the pole data,
    :class:`impactsym.rod.elastic_table._CellTable`. On a cell where the table's proven
    error :math:`\epsilon_A + f \epsilon_B` is at most ``_TABLE_TOLERANCE`` the
    polynomial is the function searched (and :math:`|A''| + f |B''|` bounds its second
    derivative), elsewhere the pole sums of :mod:`impactsym.rod.elastic` (with their
    own 1e-12 rounding bound and mpmath fallback) and
    :meth:`impactsym.rod.elastic._ElasticModel.second_derivative_bound`. The cell
    edges (they include the reflection times ``2k``) are the initial nodes of
    :func:`impactsym.numeric.isolation.first_sign_change`. ``method="poles"`` searches
    the pole sums alone (the method before the tables, kept for the benchmark).
    """
    if method not in ("taylor", "cells", "poles"):
        raise ValueError(f"method must be 'taylor', 'cells' or 'poles', got {method!r}")
    name = "Y" if which == "y" else "N"
    result = np.full(alpha.size, np.inf)
    n_terms = int(t_max // 2) + 1
    keys = np.stack([alpha, kappa], axis=1)
    groups, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    for g_index, (ag, kg) in enumerate(groups):
        members = np.flatnonzero(inverse == g_index)
        members = members[np.argsort(f[members], kind="stable")]  # screened in order of f
        fm = f[members]
        ag, kg = float(ag), float(kg)
        fastest = _fastest_rate(ag, kg)
        if fastest > _FASTEST_POLE:
            raise ValueError(
                f"kappa = {kg!r} (alpha = {ag!r}) is too stiff for a certified "
                f"finite-kappa contact time: the contact spring's time scale "
                f"1/{fastest:.3g} is "
                f"below 1/{_FASTEST_POLE:g}; use kappa=inf (rigid contact), its limit"
            )

        def model(name=name, ag=ag, kg=kg):  # the pole data, built only where needed
            return _elastic_model(name, ag, kg, n_terms)

        if method != "poles":
            # interval by interval, so that later cells are repaired (mpmath) and
            # searched only for the f still in contact
            if method == "taylor" and _cells_per_interval(ag, kg) <= MAX_CELLS:
                table = _taylor_table(ag, kg, n_terms).view(which)
            else:
                table = _cell_table(name, ag, kg, n_terms)
            evaluate, bound = _table_search(table, model, name, ag, kg, fm)
            active = np.arange(members.size)
            for m in range(n_terms):
                start, end = 2.0 * m, min(2.0 * m + 2.0, t_max)
                if start >= t_max or active.size == 0:
                    break
                base = np.append(table.lo[(table.lo >= start) & (table.lo < end)], end)

                def search(pos, base=base, active=active, evaluate=evaluate, bound=bound):
                    pairs = active[pos]
                    return first_sign_change(
                        lambda t, own: evaluate(t, pairs[own]),
                        lambda ta, tb, own, *ends: bound(ta, tb, pairs[own], *ends),
                        np.tile(base, pos.size),
                        np.repeat(np.arange(pos.size), base.size),
                        pos.size,
                        max_cells=2**22,
                        certify=True,
                    )

                # g = A + f B is affine in f: proofs of g > 0 are shared between the
                # forces (not on interval 0, where g(0) = 0 leaves nothing to prove)
                crowded = m > 0 and active.size >= _SCREEN_MIN_PAIRS
                rows = np.zeros(active.size, dtype=np.int64)
                roots = _screen_interval(search, rows, _SCREEN_STRIDES if crowded else (1,))
                hit = np.isfinite(roots)
                result[members[active[hit]]] = roots[hit]
                active = active[~hit]
            continue
        evaluate, bound = _pole_search(model, name, ag, kg, fm)
        step = min(0.1, 0.25 * ag, 0.5 / np.sqrt(fastest))
        base = np.union1d(
            np.linspace(0.0, t_max, int(np.ceil(t_max / step)) + 1),
            np.arange(2.0, t_max, 2.0),
        )
        owner = np.repeat(np.arange(members.size), base.size)
        nodes = np.tile(base, members.size)
        roots = first_sign_change(evaluate, bound, nodes, owner, members.size, max_cells=2**22)
        hit = np.isfinite(roots)
        result[members[hit]] = roots[hit]
    return result


def _pole_search(model, name, ag, kg, fm):
    """``evaluate`` and ``bound`` for :func:`first_sign_change` from the pole sums
    (``model()`` returns the cached :class:`impactsym.rod.elastic._ElasticModel`)."""

    def evaluate(t, own):
        value = _elastic(name, t, ag, kg, fm[own])
        slope = _elastic(name, t, ag, kg, fm[own], True)
        return value, slope, value

    def bound(ta, tb, own, _a, _b, _da, _db):
        return model().second_derivative_bound(ta, tb, fm[own])

    return evaluate, bound


def _table_search(table, model, name, ag, kg, fm):
    """``evaluate`` and ``bound`` from the cell table, the pole sums on its cells whose
    error bound exceeds ``_TABLE_TOLERANCE`` for the ``f`` at hand."""
    pole_evaluate, pole_bound = _pole_search(model, name, ag, kg, fm)

    def usable(i, ff):
        ok = table.err_a[i] + ff * table.err_b[i] <= _TABLE_TOLERANCE
        if not ok.all():
            waiting = i[~ok][table.pending(i[~ok])]
            if waiting.size:  # repair in mpmath where first needed, then look again
                table.repair(waiting)
                ok = table.err_a[i] + ff * table.err_b[i] <= _TABLE_TOLERANCE
        return ok

    def evaluate(t, own):
        i, ff = table.cell(t), fm[own]
        ok = usable(i, ff)
        value, slope = np.empty(t.size), np.empty(t.size)
        value[ok], slope[ok] = table.evaluate(t[ok], ff[ok], i[ok])
        if not ok.all():
            value[~ok], slope[~ok], _ = pole_evaluate(t[~ok], own[~ok])
        value[t == 0.0] = 0.0  # exact: y(0) = N(0) = 0
        return value, slope, value

    def bound(ta, tb, own, *ends):
        i, ff = table.cell(0.5 * (ta + tb)), fm[own]
        ok = usable(i, ff)
        M = table.d2_a[i] + ff * table.d2_b[i]
        if not ok.all():
            M[~ok] = pole_bound(ta[~ok], tb[~ok], own[~ok], *(e[~ok] for e in ends))
        return M

    return evaluate, bound


def contact_time(
    alpha: ArrayLike,
    f: ArrayLike,
    *,
    condition: str = "force",
    kappa: ArrayLike = np.inf,
    t_max: float | None = None,
) -> float | np.ndarray:
    r"""First sign change of the contact force or the displacement after impact.

    The contact time :math:`t_c` is the first :math:`t > 0` where the
    persistent-contact solution changes sign to the non-contact side: :math:`N`
    (``condition="force"``, the paper's *Kraftbedingung*) or :math:`y`
    (``condition="position"``, *Ortsbedingung*) goes from positive to :math:`\le 0`.
    ``inf`` means: no sign change in :math:`(0, t_{max}]` (the striker sticks up to
    the horizon).

    **Certified, not sampled.** Rigid contact: interval 0 has none
    (:math:`N = y' = f + (1 - f) e^{-t/\alpha} > 0`); on every later reflection
    interval :math:`g = y` or :math:`N` is a Laguerre sum in :math:`x = 2\tau/\alpha`
    with rigorous bounds on :math:`|g''|` over any cell (:class:`_RigidInterval`);
    finite :math:`\kappa`: per :math:`(\alpha, \kappa)` a table of cells on which
    :math:`g = A(x) + f B(x)` is one real polynomial pair with a proven error bound
    (the Taylor recurrences of the delay equations in float64 with an a-posteriori
    energy bound, :mod:`impactsym.rod.elastic_taylor`; for very stiff springs the
    mpmath table :mod:`impactsym.rod.elastic_table`; built once and shared by every
    :math:`f`), and where that bound exceeds ``1e-12`` the pole sums :math:`e^{pu}`
    times polynomials, bounded term by term. Cells are proved zero-free (interpolation
    and Taylor lower bounds) or monotone, or halved
    (:func:`impactsym.numeric.isolation.first_sign_change`); the first sign-change
    cell, monotone, is refined with
    :func:`impactsym.numeric.bracketed_newton` to full precision. A sign change is
    needed: a tangential touch is not an end of contact, and a dip below zero
    shallower than ``1e-12`` (``impactsym.numeric.isolation.TOLERANCE``, in units of
    :math:`y` resp. :math:`N`) may be passed over; with a finite :math:`\kappa`, whose
    table may itself be off by up to ``1e-12``, shallower than ``2e-12``. Rigid pairs
    of equal :math:`\alpha` share proofs: :math:`g` is affine in :math:`f`, so
    :math:`g > 0` proved on an interval for two :math:`f` holds for every :math:`f`
    between them
    (:func:`_screen_interval`); an :math:`\alpha`-:math:`f` grid costs a few µs per
    pair, scattered pairs tens of µs.

    Parameters
    ----------
    alpha : float or array_like
        Mass ratio, > 0.
    f : float or array_like
        Pressing force, >= 0.
    condition : {"force", "position"}
        Contact condition.
    kappa : float or array_like, optional
        Contact stiffness, > 0; ``inf`` (default) is rigid.
    t_max : float, optional
        Search horizon; default 100 (50 round trips) for rigid and 20 (10 round
        trips) for finite :math:`\kappa`; at most 1e4 resp. 20 (where the time
        functions are verified).

    Returns
    -------
    float or numpy.ndarray
        Contact times, broadcast over ``alpha``, ``f``, ``kappa``; ``inf`` where no
        sign change occurs up to ``t_max``.

    Raises
    ------
    ValueError
        For bad parameter values, an unknown ``condition`` or ``t_max`` beyond the
        verified range.

    Examples
    --------
    Classical rigid striker, :math:`f = 0`: the force is
    :math:`e^{-t/\alpha} + 2 e^{-(t-2)/\alpha}(1 - (t-2)/\alpha)` on :math:`2 < t < 4`
    and vanishes at :math:`t = 2 + \alpha(1 + e^{-2/\alpha}/2)`:

    >>> import numpy as np
    >>> t_c = contact_time(0.5, 0.0)
    >>> bool(abs(t_c - (2 + 0.5 * (1 + np.exp(-4.0) / 2))) < 1e-12)
    True
    >>> contact_time(0.05, 2.0)  # a light striker pressed hard sticks
    inf
    """
    condition = check_condition(condition)
    a_arr, a_scalar = real_array("alpha", alpha, lower=0.0, strict=True)
    check_alpha(a_arr)
    f_arr, f_scalar = real_array("f", f, lower=0.0)
    k_arr, k_scalar = real_array("kappa", kappa, lower=0.0, strict=True, allow_inf=True)
    shape = broadcast(alpha=a_arr, f=f_arr, kappa=k_arr)
    a, ff, k = (np.broadcast_to(v, shape).ravel().copy() for v in (a_arr, f_arr, k_arr))
    rigid = np.isinf(k)
    which = "N" if condition == "force" else "y"
    result = np.full(a.size, np.inf)
    if rigid.any():
        horizon = _check_t_max(t_max, True)
        horizon = T_MAX_RIGID if horizon is None else horizon
        result[rigid] = _rigid_contact_times(which, a[rigid], ff[rigid], horizon)
    if not rigid.all():
        horizon = _check_t_max(t_max, False)
        horizon = T_MAX_ELASTIC if horizon is None else horizon
        result[~rigid] = _elastic_contact_times(which, a[~rigid], ff[~rigid], k[~rigid], horizon)
    return finish(result.reshape(shape), a_scalar and f_scalar and k_scalar)


@dataclass(frozen=True)
class ContactTimeMap:
    """Contact times of both conditions over an ``alpha``-``f`` grid.

    Attributes
    ----------
    alpha, f : numpy.ndarray
        The grid axes (1-D).
    force, position : numpy.ndarray
        Contact times, shape ``(len(f), len(alpha))``; ``inf`` where the striker sticks.
    kappa, t_max : float
        Contact stiffness and search horizon used.

    Examples
    --------
    >>> study = contact_time_map([0.1, 30.0], [0.0, 2.0])
    >>> study.force.shape, bool(np.isinf(study.force[1, 0]))  # alpha=0.1, f=2 sticks
    ((2, 2), True)
    >>> study.rows()[1][:2]
    (30.0, 0.0)
    """

    alpha: np.ndarray
    f: np.ndarray
    force: np.ndarray
    position: np.ndarray
    kappa: float
    t_max: float

    @property
    def ratio(self) -> np.ndarray:
        """``position / force`` where both release, NaN where either sticks."""
        both = np.isfinite(self.force) & np.isfinite(self.position)
        out = np.full(self.force.shape, np.nan)
        out[both] = self.position[both] / self.force[both]
        return out

    def interval(self, *, condition: str = "force") -> np.ndarray:
        """Reflection interval on which the first contact ends, :math:`\\lfloor t_c/2
        \\rfloor` (1: between the first and the second return of the reflected wave,
        :math:`2 \\le t_c < 4`); NaN where the striker sticks.

        >>> contact_time_map([0.5], [0.0]).interval().tolist()
        [[1.0]]
        """
        times = {"force": self.force, "position": self.position}[check_condition(condition)]
        with np.errstate(invalid="ignore"):
            return np.where(np.isfinite(times), np.floor(times / 2.0), np.nan)

    def rows(self) -> list[tuple[float, ...]]:
        """``(alpha, f, t_force, t_position, ratio)`` per grid point, for tables."""
        A, F = np.meshgrid(self.alpha, self.f)
        columns = (A, F, self.force, self.position, self.ratio)
        return list(zip(*(c.ravel().tolist() for c in columns), strict=True))

    def plot(self, *, axes: Any = None) -> Any:
        """Atlases of both contact times and their ratio (see
        :func:`impactsym.plotting.rod.plot_contact_time_atlases`)."""
        from impactsym.plotting.rod import plot_contact_time_atlases

        return plot_contact_time_atlases(self, axes=axes)


def contact_time_map(
    alpha: ArrayLike, f: ArrayLike, *, kappa: float = np.inf, t_max: float | None = None
) -> ContactTimeMap:
    """Contact times under the force and the position condition on an ``alpha``-``f`` grid.

    The paper's parameter study: :func:`contact_time` for both conditions at every
    pair of the 1-D axes ``alpha`` and ``f`` (rows: ``f``, columns: ``alpha``).

    Examples
    --------
    >>> study = contact_time_map([0.5, 50.0], [0.0])
    >>> study.force.shape
    (1, 2)
    >>> bool(abs(study.ratio[0, 1] - 1) < 0.05)  # heavy striker: the conditions agree
    True
    """
    a_axis, _ = real_array("alpha", alpha, lower=0.0, strict=True)
    f_axis, _ = real_array("f", f, lower=0.0)
    a_axis, f_axis = np.atleast_1d(a_axis), np.atleast_1d(f_axis)
    if a_axis.ndim != 1 or f_axis.ndim != 1:
        raise ValueError("alpha and f must be 1-D axes of the grid")
    A, F = np.meshgrid(a_axis, f_axis)
    horizon = _check_t_max(t_max, bool(np.isinf(kappa)))
    times = {
        c: contact_time(A, F, condition=c, kappa=kappa, t_max=horizon)
        for c in ("force", "position")
    }
    if horizon is None:
        horizon = T_MAX_RIGID if np.isinf(kappa) else T_MAX_ELASTIC
    return ContactTimeMap(a_axis, f_axis, times["force"], times["position"], float(kappa), horizon)
