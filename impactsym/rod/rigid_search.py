"""Certified first sign changes of the rigid rod's :math:`y(t)` and :math:`N(t)`.

On the reflection interval :math:`t = 2m + \\tau` the rigid time functions are Laguerre
sums in :math:`x = 2\\tau/\\alpha` (:mod:`impactsym.rod.kernel`) with rigorous bounds on
their second derivative over any cell (:class:`RigidInterval`); the first sign change is
isolated with those bounds (:func:`impactsym.numeric.isolation.first_sign_change`), no
sampling. Pairs of equal ``alpha`` share the proofs that an interval holds no sign change
(:func:`screen_interval`). Internal: used by :mod:`impactsym.rod.contact_times`; see
docs/physics.md#1-rod-impact-paper-1.
"""

from __future__ import annotations

import itertools

import numpy as np

from impactsym.numeric.isolation import first_sign_change
from impactsym.rod.kernel import next_integrals, next_laguerre, rescale, rigid_tables

#: Initial nodes per unit of sqrt((m + 1) x) on reflection interval m (tuned by cell counts).
_INITIAL_DENSITY = {"N": 2.0, "y": 0.25}
#: Pairs per certified search (bounds the memory of its cells) and table entries per
#: chunk of distinct alpha (the rigid tables hold O(n_alpha * t_max) numbers).
_SEARCH_CHUNK, _TABLE_ENTRIES = 32768, 2**22
#: Strides in f of the searched pairs per alpha (:func:`screen_interval`), used where
#: at least SCREEN_MIN_PAIRS pairs per alpha are in contact (tuned on atlases).
SCREEN_STRIDES, SCREEN_MIN_PAIRS = (64, 1), 16


class RigidInterval:
    """Internal: ``y`` or ``N`` on reflection interval ``m`` for many pairs, in
    ``x = 2 tau / alpha``.

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
                E, E_prev, tmp = next_laguerre(j, x, E, E_prev, tmp)
                if scaled:
                    rescale(E, E_prev, scale, log_scale)
            Et = E * scale if scaled else E
            aj = self.coef[j][own]
            np.multiply(aj, Et, out=buf)
            S0 += buf
            if is_y:
                if j > 0:
                    I1, I2, buf = next_integrals(E, E_prev, I1, I2, buf, scale if scaled else None)
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


def interval_tables(alpha, n_intervals):
    """Internal: :func:`impactsym.rod.kernel.rigid_tables` with ``B`` as ``c_d = Bs_d + f Bd_d``."""
    B, Y0, Y1, V0, V1 = rigid_tables(alpha, n_intervals)
    return B[:, :-1] + B[:, 1:], B[:, :-1] - B[:, 1:], Y0, Y1, V0, V1


def rigid_interval(which, m, tables, row, alpha, f):
    """Internal: :class:`RigidInterval` on interval ``m`` for pairs ``(alpha, f)``,
    ``alpha`` at rows ``row`` of ``tables`` (:func:`interval_tables`)."""
    Bs, Bd, Y0, Y1, V0, V1 = tables
    d = m - np.arange(m + 1)
    coef = (Bs[row][:, d] + f[:, None] * Bd[row][:, d]).T
    y0 = Y0[row, m] + f * Y1[row, m]
    v0 = V0[row, m] + f * V1[row, m]
    return RigidInterval(which, m, coef, alpha, f, y0, v0)


def search_interval(which, m, tables, row, alpha, f, *, t_max):
    """Internal: certified first sign change of ``y`` or ``N`` on reflection interval ``m``.

    Returns ``(x, positive)`` per pair: the root in ``x = 2 tau / alpha`` (NaN if none)
    and whether ``g > 0`` was proved on the whole interval
    (:func:`impactsym.numeric.isolation.first_sign_change` with ``certify=True``).
    """
    x_root, positive = np.full(alpha.size, np.nan), np.zeros(alpha.size, dtype=bool)
    for start in range(0, alpha.size, _SEARCH_CHUNK):
        sl = slice(start, start + _SEARCH_CHUNK)
        al = alpha[sl]
        model = rigid_interval(which, m, tables, row[sl], al, f[sl])
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


def screen_interval(search, row, strides):
    """Internal (also used by :mod:`impactsym.rod.elastic.search`): first sign change on
    one reflection interval for pairs sorted by ``(alpha, f)``, searching only some of
    them.

    For a fixed ``alpha``, ``g = y`` or ``N`` is affine in ``f`` (:func:`rigid_interval`):
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


def rigid_contact_times(which, alpha, f, *, t_max):
    """Internal: first sign change of ``y`` or ``N`` in ``(0, t_max]`` for flat pairs; inf if none.

    Interval 0 holds none: there :math:`N = y' = f + (1 - f) e^{-t/\\alpha} > 0`. On
    every later interval the pairs still in contact are screened per ``alpha``
    (:func:`screen_interval`) with the certified search :func:`search_interval`.
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
        tables = interval_tables(al_all[new[lo:hi]], n_int + 1)
        active = np.arange(hi - lo)  # sorted by (alpha, f)
        for m in range(1, n_int):
            if active.size == 0:
                break
            row, al, ff = rows[active], al_all[active], f_all[active]

            def search(pos, m=m, tables=tables, row=row, al=al, ff=ff):
                return search_interval(which, m, tables, row[pos], al[pos], ff[pos], t_max=t_max)

            # screening pays where many pairs share an alpha; else search them all
            n_alpha = 1 + np.count_nonzero(row[1:] != row[:-1])
            crowded = active.size >= SCREEN_MIN_PAIRS * n_alpha
            x_root = screen_interval(search, row, SCREEN_STRIDES if crowded else (1,))
            hit = np.isfinite(x_root)
            out[lo + active[hit]] = 2.0 * m + 0.5 * al[hit] * x_root[hit]
            active = active[~hit]
    result = np.empty(alpha.size)
    result[order] = out
    return result
