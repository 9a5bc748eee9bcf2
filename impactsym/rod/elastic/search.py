"""Certified first sign changes of the rod's :math:`y(t)`, :math:`N(t)` for a finite kappa.

Per :math:`(\\alpha, \\kappa)` one certified table :math:`g = A + f B + \\epsilon`
(:class:`impactsym.rod.elastic.CertifiedTable`), built once and shared by every
:math:`f`: the float64 slow-manifold table (:mod:`impactsym.rod.elastic.manifold`) for
stiff springs where its bound certifies every cell, else the float64 Taylor table
(:mod:`impactsym.rod.elastic.taylor`) where the spring allows, else the mpmath cell table
(:mod:`impactsym.rod.elastic.cells`). Where a cell's
proven error exceeds ``TABLE_TOLERANCE`` the pole sums (:mod:`impactsym.rod.elastic.poles`)
stand in, with their own bounds. On the slow-manifold tables the first cells of each
reflection interval whose polynomials (of ``N``) their Bernstein coefficients prove
positive are not searched (:func:`_positive_prefix`: where ``N`` nearly touches zero at a reflection
time, its second derivative ``~ kappa^2``, the search's halving needs a dozen rounds to
prove what the coefficients show at once). Internal: used by
:mod:`impactsym.rod.contact_times`; see
docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from impactsym.numeric.eft import UNIT_ROUNDOFF as _U
from impactsym.numeric.isolation import first_sign_change
from impactsym.numeric.roots import bracketed_newton
from impactsym.rod.elastic import CertifiedTable
from impactsym.rod.elastic.cells import cell_table
from impactsym.rod.elastic.manifold import (
    cells_per_interval_manifold,
    extend_tables,
    manifold_table,
)
from impactsym.rod.elastic.poles import check_which, pole_model, time_function
from impactsym.rod.elastic.taylor import MAX_CELLS, cells_per_interval, fastest_rate, taylor_table
from impactsym.rod.rigid_search import SCREEN_MIN_PAIRS, SCREEN_STRIDES, screen_interval

#: Largest contact-spring pole |s| (time scale 1/|s|) for finite-kappa contact times.
_FASTEST_POLE = 1e8
#: Largest proven error of a table's cell polynomials (units of ``y`` resp. ``N``) for
#: them to stand for the function.
TABLE_TOLERANCE = 1e-12
#: Depth below zero at which a sign change is proven (twice the tables' error bound): the
#: contact ends at the zero just before ``g`` reaches ``-DEPTH``.
DEPTH = 2.0 * TABLE_TOLERANCE


def elastic_contact_times(which, alpha, f, *, kappa, t_max, method="taylor"):
    r"""Internal: first sign change of ``y`` or ``N`` (``which``) in ``(0, t_max]`` for flat
    pairs ``alpha, f, kappa`` with finite ``kappa``; ``inf`` if none.

    Pairs are grouped by ``(alpha, kappa)``; ``g`` starts at ``g(0) = 0`` with
    ``g'(0) > 0`` (``N' = kappa``, ``y' = 1``). Per group one
    :class:`impactsym.rod.elastic.CertifiedTable`: with ``method="taylor"`` (the default)
    the slow-manifold table of :mod:`impactsym.rod.elastic.manifold` where it applies,
    needs fewer cells than the Taylor mesh (and at most ``MAX_CELLS``) and its bound
    certifies every cell at the group's largest ``f``; else the Taylor table of
    :mod:`impactsym.rod.elastic.taylor` where the spring needs at most its ``MAX_CELLS``
    cells per reflection interval; else (and always with ``method="cells"``) the cell
    table of :mod:`impactsym.rod.elastic.cells`. On a cell
    whose proven error is at most ``TABLE_TOLERANCE`` the polynomial is the function
    searched, with its second-derivative bound; elsewhere the pole sums
    (:func:`pole_search`). The cell edges (they include the reflection times ``2k``) are
    the initial nodes of :func:`impactsym.numeric.isolation.first_sign_change`.
    """
    check_which(which)
    if method not in ("taylor", "cells"):
        raise ValueError(f"method must be 'taylor' or 'cells', got {method!r}")
    result = np.full(alpha.size, np.inf)
    # the float64 tables stop at the first reflection time >= t_max: their cells and
    # bounds on [0, 2 n] do not depend on later intervals (the bound accumulates forward)
    n_searched = max(1, math.ceil(t_max / 2.0))
    keys = np.stack([alpha, kappa], axis=1)
    groups, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    stiff = []  # (through, alpha, kappa, forces, members) of the slow-manifold groups
    for g_index, (ag, kg) in enumerate(groups):
        members = np.flatnonzero(inverse == g_index)
        members = members[np.argsort(f[members], kind="stable")]  # screened in order of f
        ag, kg = float(ag), float(kg)
        check_stiffness(ag, kappa=kg)
        n_manifold = cells_per_interval_manifold(ag, kappa=kg)
        fewer = n_manifold is not None and n_manifold < cells_per_interval(ag, kappa=kg)
        if method == "taylor" and fewer and n_manifold <= MAX_CELLS:
            through = _certified_manifold(ag, kg, which, n_searched, f[members])
            stiff.append((through, ag, kg, f[members], members))
        else:
            result[members] = _other_table(which, ag, kg, f[members], t_max, method)
    if stiff:
        # the slow-manifold groups searched together, interval by interval: each step
        # extends every table the search needs next at once (extend_tables)
        steps = _joint_search_steps(stiff, which, t_max)
        try:
            needs = next(steps)
            while True:
                extend_tables(
                    [stiff[g][0].table for g in needs], [needs[g] for g in needs], which=which
                )
                needs = steps.send(None)
        except StopIteration as stop:
            times = stop.value
        for (_, ag, kg, fm, members), found in zip(stiff, times, strict=True):
            if found is None:  # the slow-manifold table not certified: another one
                found = _other_table(which, ag, kg, fm, t_max, "taylor")
            result[members] = found
    return result


def _joint_search_steps(groups, which, t_max, *, prefix=True):
    """Contact times of the forces (sorted) of several groups ``(through, alpha, kappa,
    forces, members)``, each on its own table ``through(m)`` (a
    :class:`impactsym.rod.elastic.CertifiedTable` over at least the first ``m``
    reflection intervals, or ``None``: not certified), interval by interval, so that later
    cells are built, repaired and searched only for the ``f`` still in contact: one search
    per interval over the pairs of all groups, so that the work that does not depend on
    the pairs' number is done once. ``prefix``: the ``N`` search starts after the cells of
    an interval's start that :func:`_positive_prefix` proves positive. A generator: it
    yields ``{group: m}`` (the intervals each still searching group needs next, before it
    asks ``through(m)``: the caller can build the tables of many groups at once) and
    returns a list of contact times per group, ``None`` for a group whose table
    ``through(m)`` refused."""
    n_terms = int(t_max // 2) + 1
    sizes = [g[3].size for g in groups]
    offset = np.concatenate([[0], np.cumsum(sizes)])
    owner = np.repeat(np.arange(len(groups)), sizes)  # the group of each pair
    fm = np.concatenate([g[3] for g in groups])
    local = np.arange(fm.size) - offset[owner]
    result = np.full(fm.size, np.inf)
    refused = np.zeros(len(groups), dtype=bool)
    active = np.arange(fm.size)
    tables, searches = [None] * len(groups), [None] * len(groups)
    for m in range(n_terms):
        start, end = 2.0 * m, min(2.0 * m + 2.0, t_max)
        if start >= t_max or active.size == 0:
            break
        present = np.unique(owner[active])
        # this interval and the next (its end is the next one's first cell's start)
        yield {int(g): m + 2 for g in present}
        for g in present:
            through, ag, kg, forces, _ = groups[g]
            current = through(m + 2)
            if current is None:
                refused[g] = True
            elif current is not tables[g]:
                tables[g] = current
                searches[g] = _table_search(current, which, ag, kg, forces, n_terms)
        active = active[~refused[owner[active]]]
        if active.size == 0:
            continue
        present = np.unique(owner[active])
        cells = {g: np.flatnonzero((tables[g].lo >= start) & (tables[g].lo < end)) for g in present}
        bases = {g: np.append(tables[g].lo[cells[g]], end) for g in present}
        # the cells of the interval's start proved positive on their polynomials (their
        # Bernstein coefficients): the search starts after them, per pair (N only: y'' is
        # moderate at a reflection time, its search halves nothing there)
        skip = np.zeros(fm.size, dtype=np.int64)
        if prefix and m > 0 and which == "N":
            for g in present:
                mine = active[owner[active] == g]
                skip[mine] = _positive_prefix(tables[g], cells[g], fm[mine])

        def split(pairs, present=present):  # the positions of pairs per group
            return [(g, np.flatnonzero(owner[pairs] == g)) for g in present]

        def evaluate(t, pairs):
            value, slope = np.empty(t.size), np.empty(t.size)
            for g, at in split(pairs):
                if at.size:
                    value[at], slope[at], _ = searches[g][0](t[at], local[pairs[at]])
            return value, slope, value

        def bound(ta, tb, pairs, *ends):
            out = np.empty(ta.size)
            for g, at in split(pairs):
                if at.size:
                    cut = (e[at] for e in ends)
                    out[at] = searches[g][1](ta[at], tb[at], local[pairs[at]], *cut)
            return out

        def search(pos, bases=bases, active=active, evaluate=evaluate, bound=bound, skip=skip):
            pairs = active[pos]
            nodes = [bases[g][k:] for g, k in zip(owner[pairs], skip[pairs], strict=True)]
            return first_sign_change(
                lambda t, own: _deeper(evaluate(t, pairs[own])),
                lambda ta, tb, own, *ends: bound(ta, tb, pairs[own], *ends),
                np.concatenate(nodes),
                np.repeat(np.arange(pos.size), [x.size for x in nodes]),
                pos.size,
                max_cells=2**22,
                certify=True,
            )

        # g = A + f B is affine in f: proofs of g > 0 are shared between the forces of
        # a group (not on interval 0, where g(0) = 0 leaves nothing to prove)
        counts = np.bincount(owner[active])
        crowded = m > 0 and counts.max() >= SCREEN_MIN_PAIRS
        roots = screen_interval(search, owner[active], SCREEN_STRIDES if crowded else (1,))
        hit = np.isfinite(roots)
        result[active[hit]] = _zero_before(evaluate, roots[hit], active[hit], start)
        active = active[~hit]
    return [None if refused[g] else result[offset[g] : offset[g + 1]] for g in range(len(groups))]


#: Cells at the start of a reflection interval tried by :func:`_positive_prefix`.
_PREFIX_CELLS = 8


@lru_cache(maxsize=4)
def _bernstein_weights(degree: int) -> np.ndarray:
    """``W[j, k] = C(j, k) / C(degree, k)`` (``k <= j``, else 0), correctly rounded: the
    Bernstein coefficients of ``sum c_k xi^k`` on ``[0, 1]`` are ``W c``, each in [0, 1]."""
    weights = np.array(
        [
            [math.comb(j, k) / math.comb(degree, k) if k <= j else 0.0 for k in range(degree + 1)]
            for j in range(degree + 1)
        ]
    )
    weights.flags.writeable = False  # cached: shared by every later call
    return weights


def _positive_prefix(table, cells, forces):
    """Per force, how many of the first cells ``cells`` (a reflection interval's, in order)
    of ``table`` are proved positive before the first one that is not, so that the search
    may start after them.

    A cell counts if it and the next cell are certified (``TABLE_TOLERANCE`` each) and the
    exact polynomial ``p = A + f B`` exceeds ``4 u (|A_0| + |f B_0|)`` of the next cell on
    it: ``p`` is at least the least of its Bernstein coefficients ``W c`` on ``[0, 1]``,
    which float computes within ``32 u sum_k (|A_k| + |f B_k|)`` (``c_k`` within ``2 u``
    of its terms, ``W`` within ``u``, the sum of 25 or 26 products within ``gamma_26``). So
    ``g > -TABLE_TOLERANCE`` there, and the next cell starts above ``-DEPTH`` (the two
    polynomials within ``DEPTH`` of each other at the node), also as the search evaluates
    it (rounding ``2 u (|A_0| + |f B_0|)``): a sign change at ``-DEPTH`` cannot lie in
    the cells skipped, nor at their end."""
    index = cells[: _PREFIX_CELLS + 1]
    f = forces[:, None]
    A, B = table.A[index], table.B[index]  # [cell, order]
    size = np.abs(A).sum(axis=-1) + np.abs(f) * np.abs(B).sum(axis=-1)  # [force, cell]
    least = ((A + f[..., None] * B) @ _bernstein_weights(A.shape[-1] - 1).T).min(axis=-1)
    lower = least - 32.0 * _U * size
    head = np.abs(A[:, 0]) + np.abs(f) * np.abs(B[:, 0])
    ok = table.certified(index, f, TABLE_TOLERANCE)
    proved = ok[:, :-1] & ok[:, 1:] & (lower[:, :-1] > 4.0 * _U * head[:, 1:])
    # the first cell not proved (the prefix's length)
    return np.argmin(np.concatenate([proved, np.zeros((forces.size, 1), bool)], axis=1), axis=1)


def _other_table(which, ag, kg, fm, t_max, method):
    """Contact times of ``fm`` on the Taylor table (``method="taylor"``, where the spring
    needs at most ``MAX_CELLS`` cells per interval) or else the cell table."""
    n_terms = int(t_max // 2) + 1
    if method == "taylor" and cells_per_interval(ag, kappa=kg) <= MAX_CELLS:
        n_searched = max(1, math.ceil(t_max / 2.0))
        table = taylor_table(ag, kappa=kg, n_intervals=n_searched).view(which)
    else:
        table = cell_table(which, ag, kappa=kg, n_terms=n_terms)
    # one group, on a table built whole (nothing to extend between the steps); the
    # cells of an interval's start are searched as they are (prefix=False)
    group = (lambda _, table=table: table, ag, kg, fm, None)
    steps = _joint_search_steps([group], which, t_max, prefix=False)
    while True:
        try:
            next(steps)
        except StopIteration as stop:
            return stop.value[0]


def _certified_manifold(alpha, kappa, which, n_terms, forces):
    """The slow-manifold table of ``which`` as the search asks for it: ``through(m)``, its
    view over at least the first ``m`` reflection intervals (built as far as that, no
    further: the contacts that end early never pay for the later ones), or ``None`` once
    a cell built misses ``TABLE_TOLERANCE`` at the largest of ``forces`` (so at every one
    of them). Near its separation limit, at very stiff springs with light strikers, many
    cells miss it, and the pole sums standing in for them would cost far more than the
    Taylor or the cell table, which then serve instead."""
    table = manifold_table(alpha, kappa=kappa, n_intervals=n_terms)
    worst = float(np.max(np.abs(forces)))
    views = {0: None}  # intervals -> view, cells certified for these forces

    def through(m):
        m = min(m, n_terms)
        known = max(views)
        if m > known:
            view = table.view(which, n_intervals=m)  # exactly these: the same check always
            cells = np.arange(0 if views[known] is None else views[known].lo.size, view.lo.size)
            if not bool(view.certified(cells, np.full(cells.size, worst), TABLE_TOLERANCE).all()):
                return None
            views[m] = view
        return views[max(views)]

    through.table = table  # for the caller that extends many tables together
    return through


def check_stiffness(alpha: float, *, kappa: float) -> None:
    """Internal: refuse a contact spring whose fastest pole exceeds ``1e8`` (time scale
    below ``1e-8``), naming ``kappa``: too stiff for a certified search, and ``kappa=inf``
    is its limit."""
    fastest = fastest_rate(alpha, kappa=kappa)
    if fastest > _FASTEST_POLE:
        raise ValueError(
            f"kappa = {kappa!r} (alpha = {alpha!r}) is too stiff for a certified "
            f"finite-kappa contact time: the contact spring's time scale "
            f"1/{fastest:.3g} is "
            f"below 1/{_FASTEST_POLE:g}; use kappa=inf (rigid contact), its limit"
        )


def _deeper(values: tuple) -> tuple:
    """``(g + DEPTH, g', aux)``: the search looks for ``g <= -DEPTH``, a sign change the
    tables' error bound (``TABLE_TOLERANCE``) proves; a touch of zero within it (a
    decaying force of ``1e-19`` that a table rounds below zero) is no end of contact."""
    g, dg, aux = values
    return g + DEPTH, dg, aux


def _zero_before(evaluate, reached, pairs, start):
    """The zero of ``g`` just before each point ``reached`` where ``g = -DEPTH``: a left end
    with ``g > 0`` at ``4^k 1e-10`` before it (``k`` up, the interval's ``start`` at
    most, where ``g > 0`` or ``g(0) = 0``), then the safeguarded Newton iteration on
    ``g`` (a crossing: ``DEPTH / |g'|`` before ``reached``)."""
    left, g_left = reached.copy(), np.full(reached.size, np.nan)
    open_ = np.ones(reached.size, bool)
    for k in range(20):
        if not open_.any():
            break
        i = np.flatnonzero(open_)
        trial = np.maximum(reached[i] - 1e-10 * 4.0**k * (1.0 + reached[i]), start)
        left[i], g_left[i] = trial, evaluate(trial, pairs[i])[0]
        open_[i] = ~((g_left[i] > 0) | (trial <= start))
    if open_.any():
        i = np.flatnonzero(open_)
        left[i] = start
        g_left[i] = evaluate(left[i], pairs[i])[0]

    def g_and_slope(t, own):
        value, slope, _ = evaluate(t, pairs[own])
        return value, slope

    g_hi = evaluate(reached, pairs)[0]
    ok = (g_left >= 0) & (g_hi <= 0) & (left < reached)
    out = reached.copy()
    if ok.any():
        k = np.flatnonzero(ok)
        out[k] = bracketed_newton(
            lambda t, j: g_and_slope(t, k[j.astype(np.int64)]),
            None,
            left[k],
            reached[k],
            (np.arange(k.size, dtype=float),),
            g_lo=g_left[k],
            g_hi=g_hi[k],
        )
    return out


def pole_search(which, alpha, f, *, kappa, n_terms):
    """Internal: ``evaluate`` and ``bound`` of
    :func:`impactsym.numeric.isolation.first_sign_change` from the pole sums of ``which``
    for one ``(alpha, kappa)`` and the forces ``f`` (``own`` indexes them): values and
    slopes from :func:`impactsym.rod.elastic.poles.time_function`, the bound from
    :meth:`impactsym.rod.elastic.poles.PoleModel.second_derivative_bound` (the model of
    ``n_terms`` terms built only when first asked)."""

    def evaluate(t, own):
        value = time_function(which, t, alpha, f[own], kappa=kappa, n_terms=n_terms)
        slope = time_function(
            which, t, alpha, f[own], kappa=kappa, derivative=True, n_terms=n_terms
        )
        return value, slope, value

    def bound(ta, tb, own, _a, _b, _da, _db):
        model = pole_model(which, alpha, kappa=kappa, n_terms=n_terms)
        return model.second_derivative_bound(ta, tb, f[own])

    return evaluate, bound


def _table_search(table: CertifiedTable, which, ag, kg, fm, n_terms):
    """``evaluate`` and ``bound`` from ``table``, the pole sums on its cells whose error
    bound exceeds ``TABLE_TOLERANCE`` for the ``f`` at hand."""
    pole_evaluate, pole_bound = pole_search(which, ag, fm, kappa=kg, n_terms=n_terms)

    def evaluate(t, own):
        i, ff = table.cell(t), fm[own]
        ok = table.certified(i, ff, TABLE_TOLERANCE)
        value, slope = np.empty(t.size), np.empty(t.size)
        value[ok], slope[ok] = table.evaluate(t[ok], ff[ok], i[ok])
        if not ok.all():
            value[~ok], slope[~ok], _ = pole_evaluate(t[~ok], own[~ok])
        value[t == 0.0] = 0.0  # exact: y(0) = N(0) = 0
        return value, slope, value

    def bound(ta, tb, own, *ends):
        i, ff = table.cell(0.5 * (ta + tb)), fm[own]
        ok = table.certified(i, ff, TABLE_TOLERANCE)
        M = table.second_derivative_bound(i, ff)
        if not ok.all():
            M[~ok] = pole_bound(ta[~ok], tb[~ok], own[~ok], *(e[~ok] for e in ends))
        return M

    return evaluate, bound
