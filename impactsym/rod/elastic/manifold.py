r"""Finite contact stiffness, method 4: a certified table on the slow manifold of a stiff spring.

The equations are those of :mod:`impactsym.rod.elastic.taylor`,

.. math::

    y' = v, \qquad \alpha v' = f - N, \qquad N' = \kappa (v - N + 2G), \qquad
    G = N(t - 2) - G(t - 2).

For a stiff spring the roots of :math:`\alpha s^2 + \alpha\kappa s + \kappa` are real and
far apart, :math:`p_f \approx -\kappa`, :math:`p_s \approx -1/\alpha`. After each
reflection time :math:`2m` a fast transient (:math:`e^{p_f u}` times a polynomial) dies out
within a layer of length :math:`64/|p_f|`; beyond it the solution lies on the slow manifold
:math:`N = (1 + \kappa^{-1} d/dt)^{-1} (v + 2G)`. So every reflection interval is cut into
the same cells: Taylor cells across the layer, 8 of width :math:`h` (:math:`h |p_f| \le
1`: the kink of the incoming wave), then cells that widen as the transient decays
(:math:`h |p_f|` up to 1.25, from :math:`|p_f| u = 16` up to 2.5, from 32 up to 5: the
part of the transient a cell's degree cannot follow shrinks like :math:`e^{-|p_f| u}`),
then cells whose widths at most double from cell to cell up to :math:`H` (:math:`H |p_s|
\le 1`, at most 1/4), all powers of two: the count no longer grows with :math:`\kappa`
(46 to 115 cells per interval, 31 to 52 of them in the layer, where a uniform mesh needs
thousands; a layer of cells of h and 2h only had 84 to 160, and the cost of a table is
about proportional to its cells).

On a layer cell the polynomials are the Taylor recurrences of the Taylor table. On a
slow cell :math:`v` is the polynomial of degree ``DEGREE`` whose :math:`N =
\sum_j (-\kappa^{-1} d/dt)^j (v + 2G)` (finite on polynomials) satisfies
:math:`\alpha v' = f - N` (a linear solve, then one Gauss-Seidel sweep), and :math:`N` is
kept in double-double from the compensated back recurrence :math:`N_k = v_k + 2G_k -
(k+1) N_{k+1}/(h\kappa)`: the residual :math:`N' - \kappa(v - N + 2G)` then does not carry
:math:`\kappa` times the rounding of :math:`N`. Where the manifold meets the layer, the
jump of :math:`N` is the transient left over. Accepted by the same a-posteriori bound as
the Taylor table (:func:`impactsym.rod.elastic.taylor.force_bounds` and
:func:`~impactsym.rod.elastic.taylor.displacement_bounds`: residuals and jumps
measured on the stored arrays, the energy of the error): how the coefficients were made
does not enter the proof. See docs/physics.md#finite-contact-stiffness-three-methods.

Where the poles are only 4 to 8 apart (too near for the slow cells' bound) the table
keeps Taylor cells to the interval's end, graded as the layer's (``h p_f`` up to 5 once
the transient has decayed, ``h p_s <= 5/4``): fewer cells than the uniform Taylor mesh
(88 instead of 256 at ``(0.1, 1e2)``), the same bound.

All cells of an interval are computed at once
(:func:`impactsym.rod.elastic.chain.cell_chain`: float starts from the cells' affine
maps, the recurrences and solves as NumPy operations over the cells, the few ulps each
start misses of the exact end before as low parts of every coefficient), and the tables
of a search's ``(alpha, kappa)`` groups together (:func:`extend_tables`: one pass over
the cells of all of them per interval).
"""

from __future__ import annotations

import math
import threading
import weakref
from contextlib import ExitStack
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from impactsym.rod.elastic import taylor
from impactsym.rod.elastic.chain import cell_chain, scan_stages, stacked_stages
from impactsym.rod.elastic.slow import manifold_forces, slow_cells, slow_operator
from impactsym.rod.elastic.taylor import (
    DEGREE,
    TaylorTable,
    TaylorView,
    check_table_arguments,
    fastest_rate,
    layer_maps,
    next_incoming,
    taylor_cells,
)

#: Largest ``h p_f`` on a layer (Taylor) cell.
_LAYER_REACH = 1.0
#: Largest ``h p_f`` on the layer's cells after its first 8.
_GRADED_REACH = 1.25
#: Least ``p_f`` times the layer's length (``e^{-64}`` of the transient is left).
_LAYER_DECAY = 64.0
#: Largest ``H p_s`` on a slow cell.
_SLOW_REACH = 1.0
#: Largest slow cell (the later reflections raise the polynomials' degree).
_WIDEST = 0.25
#: ``(p, Z)``: layer cells starting at ``p_f u >= p`` after a reflection time have
#: ``h p_f <= Z`` (after the first 8 cells of ``h p_f <= 1``). The truncation of a cell
#: grows like ``Z^25 / 25!`` times the transient left, ``~ e^{-p_f u}``: the bound rises
#: by at most 30 % over ``Z = 1.25`` throughout; from 12 and 24 on by up to 2.2 times,
#: from 8 and 16 on to 2e-11 at kappa = 1e4, and ``Z = 10`` from 40 makes it 1e-9 .. 3e-5.
_GRADING = [(0.0, 1.25), (16.0, 2.5), (32.0, 5.0)]
#: Least ratio ``p_f / p_s`` of the contact poles for the slow manifold.
_SEPARATION = 8.0
#: Least ratio ``p_f / p_s`` for Taylor cells graded as the layer's throughout (below
#: ``_SEPARATION``: the slow cells' bound is too large there); the widest cells then have
#: ``h p_s <= 5/4``.
_GRADED_SEPARATION = 4.0


def _power_of_two_below(x: float) -> float:
    return 2.0 ** math.floor(math.log2(x))


def interval_mesh(alpha: float, *, kappa: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Internal: widths (powers of two) of the cells of one reflection interval and which
    of them are layer (Taylor) cells, or ``None`` where the mesh does not apply (complex
    or near contact poles, ``p_f / p_s < 4``, or a layer longer than 1). From ``p_f / p_s
    = 4`` to ``8`` every cell is a Taylor cell, graded as the layer's throughout (the
    slow manifold needs the poles 8 apart).

    The layer (in units of ``h``, ``h p_f <= 1``): 8 cells of ``h``, then each cell the
    widest power of two that the position is a multiple of with ``width p_f`` at most the
    reach of ``_GRADING`` at its start, up to a multiple of ``8 h`` at least ``64 / p_f``
    long; from its end the slow cells are the widest power of two up to ``H`` that the
    position is a multiple of (a dyadic tiling: the widths at most double from cell to
    cell, up to ``H``)."""
    if not kappa * kappa - 4.0 * kappa / alpha > 0.0:
        return None
    fast = fastest_rate(alpha, kappa=kappa)
    slow = kappa / (alpha * fast)  # the roots' product is kappa / alpha
    if not (math.isfinite(fast) and fast >= _GRADED_SEPARATION * slow):
        return None
    graded_only = fast < _SEPARATION * slow  # Taylor cells throughout, graded
    h = _power_of_two_below(_LAYER_REACH / fast)
    wide = _power_of_two_below(min(_SLOW_REACH / slow, _WIDEST))
    if wide < 8.0 * h and not graded_only:
        return None
    # the layer, in units of h: 8 cells of h (the kink), then as wide as the transient
    # left allows, up to a multiple of 8 h at least 64 / p_f long
    step = h * fast  # in (1/2, 1]
    widths, position = [1] * 8, 8
    while position * step < _LAYER_DECAY or position % 8:
        reach = max(z for p, z in _GRADING if position * step >= p)
        width = 1
        while 2 * width * step <= reach and position % (2 * width) == 0:
            width *= 2
        widths.append(width)
        position += width
    n_layer = len(widths)
    if position * h > 1.0:
        return None
    if graded_only:  # the layer's widest cells on to the interval's end
        width = 1
        while 2 * width * step <= _GRADING[-1][1] and position % (2 * width) == 0:
            width *= 2
        widths += [width] * ((round(2.0 / h) - position) // width)
        return np.array(widths) * h, np.ones(len(widths), dtype=bool)
    widths = [w * h for w in widths]
    top = round(wide / h)
    width = 1
    while position < round(2.0 / h):
        width = min(2 * width, top)
        while position % width:
            width //= 2
        widths.append(width * h)
        position += width
    layer = np.zeros(len(widths), dtype=bool)
    layer[:n_layer] = True
    return np.array(widths), layer


def cells_per_interval_manifold(alpha: float, *, kappa: float) -> int | None:
    """Internal: the number of cells per reflection interval of the slow-manifold table, or
    ``None`` where it does not apply."""
    mesh = interval_mesh(alpha, kappa=kappa)
    return None if mesh is None else mesh[0].size


class ManifoldTable(TaylorTable):
    """``y`` and ``N`` for one ``(alpha, kappa)`` of a stiff spring on ``[0, 2 n_intervals]``:
    the attributes and :meth:`view` of :class:`impactsym.rod.elastic.taylor.TaylorTable`,
    on the cells of :func:`interval_mesh` (``h`` per cell).

    Built interval by interval: with ``lazy=True`` none at first, then as far as
    :meth:`extend` asks (the attributes and views hold the intervals built); the cells,
    coefficients and bounds of an interval do not depend on later ones (the bound
    accumulates forward), so they are the same, to the last bit, however far the table
    is built and in how many steps. The bound of ``y`` (a quarter of the bound's work,
    :func:`impactsym.rod.elastic.taylor.displacement_bounds`) is computed only when asked
    for (``which`` of :meth:`extend`, a view of ``y``): until then ``err_y_a, err_y_b``
    are ``inf`` on the cells built (nothing certified), after it the same bits as when
    bounded with ``N``."""

    def __init__(self, alpha: float, kappa: float, n_intervals: int, *, lazy: bool = False):
        self.alpha, self.kappa = check_table_arguments(alpha, kappa=kappa, n_intervals=n_intervals)
        mesh = interval_mesh(self.alpha, kappa=self.kappa)
        if mesh is None:
            raise ValueError(
                f"kappa = {kappa!r} (alpha = {alpha!r}): the contact poles are not far "
                f"enough apart for the slow-manifold table"
            )
        widths, layer = mesh
        n = widths.size
        starts = np.concatenate([[0.0], np.cumsum(widths)[:-1]])
        self.cells_per_interval = n
        self.n_intervals, self.built = n_intervals, 0
        self._widths, self._layer = widths, layer
        self._h = np.tile(widths, n_intervals)
        self._lo = (2.0 * np.arange(n_intervals)[:, None] + starts).ravel()
        D, total = DEGREE, n * n_intervals
        # coefficients [rhs, cell, order] and their low parts (every order)
        self._arrays = {
            **{name: np.zeros((2, total, D + 2)) for name in ("Y", "Y_lo")},
            **{name: np.zeros((2, total, D + 1)) for name in ("V", "V_lo", "N", "N_lo")},
            **{name: np.zeros((2, total, D + 1)) for name in ("G_hi", "G_lo")},
        }
        # err_y_a, err_y_b, err_n_a, err_n_b; y's inf until bounded (built_y intervals)
        self._errors = np.zeros((4, total))
        self._errors[:2] = np.inf
        # what the bound of y needs of N's (taylor.force_bounds), per cell
        self._coupling = np.zeros((3, 2, total))
        self._carry, self._carry_y, self.built_y = None, None, 0
        self._lock = threading.Lock()
        # (y, v, N) at the next interval's start, high and low parts, per right-hand side
        # (replaced, never changed in place)
        self._state = (np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]), np.zeros((2, 3)))
        self._maps = self._cell_maps()
        self._expose()
        if not lazy:
            self.extend(n_intervals)

    def extend(self, n_intervals: int, *, which: str | tuple = ("y", "N")) -> None:
        """Build and bound the intervals up to ``n_intervals`` (at most the table's): the
        bound of ``N`` always, that of ``y`` if ``"y"`` is in ``which``; one thread at a
        time (a cached table is shared), the intervals built never change."""
        bound_y = _bounds_y(which)
        with self._lock:
            end = min(n_intervals, self.n_intervals)
            self._extend(end)
            if bound_y:
                self._bound_y(end)

    def _extend(self, end: int) -> None:
        if end <= self.built:
            return
        begin = self.built
        saved = self._state
        try:
            for m in range(begin, end):
                self._build_interval(m)
            self._bound(begin, end)
        except BaseException:  # (e.g. KeyboardInterrupt) the next extend starts over
            if self.built == begin:  # (the bound did not finish: nothing was taken on)
                self._state = saved
            raise

    def _bound(self, begin: int, end: int) -> None:
        """Bound ``N`` on the intervals ``begin .. end - 1`` (built), carrying the running
        sums on (:func:`impactsym.rod.elastic.taylor.force_bounds`)."""
        n, a = self.cells_per_interval, self._arrays
        upto, cells = slice(0, end * n), slice(begin * n, end * n)
        arrays = tuple(a[name][:, upto] for name in ("V", "N"))
        lows = tuple(a[name][:, upto] for name in ("V_lo", "N_lo"))
        incoming = (a["G_hi"][:, upto], a["G_lo"][:, upto])
        bounds, self._coupling[:, :, cells], self._carry = taylor.force_bounds(
            self.alpha, self._h[upto], arrays, lows, incoming, n,
            kappa=self.kappa, start=begin, carry=self._carry,
        )  # fmt: skip
        self._errors[2:, cells] = bounds
        self.built = end
        self._expose()

    def _bound_y(self, end: int) -> None:
        """Bound ``y`` on the intervals ``built_y .. end - 1`` (``N`` bounded there), the
        running sums carried on (:func:`impactsym.rod.elastic.taylor.displacement_bounds`)."""
        begin = self.built_y
        if end <= begin:
            return
        n, a = self.cells_per_interval, self._arrays
        upto, cells = slice(0, end * n), slice(begin * n, end * n)
        arrays = tuple(a[name][:, upto] for name in ("Y", "V"))
        lows = tuple(a[name][:, upto] for name in ("Y_lo", "V_lo"))
        bounds, carry = taylor.displacement_bounds(
            self.alpha, self._h[upto], arrays, lows, self._coupling[:, :, cells], n,
            kappa=self.kappa, start=begin, carry=self._carry_y,
        )  # fmt: skip
        # taken on together (an interruption before leaves the table as it was)
        self._errors[:2, cells], self._carry_y, self.built_y = bounds, carry, end
        self._expose()

    def view(self, which: str, *, n_intervals: int | None = None) -> TaylorView:
        """:meth:`TaylorTable.view` over the first ``n_intervals`` reflection intervals
        (default: all of them), built first as far as that."""
        if which not in ("y", "N"):
            raise ValueError(f"which must be 'y' or 'N', got {which!r}")
        if n_intervals is None:
            self.extend(self.n_intervals, which=which)
            return super().view(which)
        self.extend(n_intervals, which=which)
        upto = slice(0, min(n_intervals, self.n_intervals) * self.cells_per_interval)
        prefix = SimpleNamespace(lo=self.lo[upto], hi=self.hi[upto], h=self.h[upto])
        arrays = (self.Y_a, self.Y_b, self.err_y_a, self.err_y_b)
        if which == "N":
            arrays = (self.N_a, self.N_b, self.err_n_a, self.err_n_b)
        return TaylorView(prefix, *(x[upto] for x in arrays))

    def _expose(self) -> None:
        """The attributes of :class:`TaylorTable` over the intervals built."""
        upto = slice(0, self.built * self.cells_per_interval)
        self.h, self.lo = self._h[upto], self._lo[upto]
        self.hi = self.lo + self.h
        self.N_a, self.N_b = self._arrays["N"][:, upto]
        self.Y_a, self.Y_b = self._arrays["Y"][:, upto]
        self.err_y_a, self.err_y_b, self.err_n_a, self.err_n_b = self._errors[:, upto]

    def _cell_maps(self) -> dict:
        """What the cells of an interval need, per cell (``[cell, ...]``): the Taylor
        factors of the layer cells, the slow operators and factors of the wide cells, and
        for :func:`impactsym.rod.elastic.chain.cell_chain` the map of a cell's start to
        its end, the end's response to the incoming wave and to a unit force, and the
        polynomials of unit starts."""
        alpha, kappa, D = self.alpha, self.kappa, DEGREE
        widths, layer = self._widths, self._layer
        n = widths.size
        A, W, b = np.zeros((n, 3, 3)), np.zeros((n, 3, D + 1)), np.zeros((n, 3))
        E_y, E_v, E_n = np.zeros((n, 3, D + 2)), np.zeros((n, 3, D + 1)), np.zeros((n, 3, D + 1))
        k = np.arange(D)
        fine = np.flatnonzero(layer)
        taylor_factors = tuple(
            np.array(c)
            for c in (
                widths[fine, None] / (alpha * (k + 1)),
                widths[fine, None] * kappa / (k + 1),
                widths[fine, None] / np.arange(1, D + 2),
            )
        )
        # every layer width at once
        sizes, which = np.unique(widths[fine], return_inverse=True)
        first = np.array([np.flatnonzero(widths[fine] == w)[0] for w in sizes])
        (ry, rv, rn), T, WG, bf = layer_maps(tuple(c[first] for c in taylor_factors))
        A[fine], W[fine], b[fine] = T[which], WG[which], bf[which]
        E_y[fine], E_v[fine], E_n[fine] = ry[which], rv[which], rn[which]
        wide = np.flatnonzero(~layer)
        S, inverse = np.zeros((wide.size, D + 1, D + 1)), np.zeros((wide.size, D, D))
        slow_factors = (
            widths[wide, None] / (alpha * (k + 1)),
            widths[wide, None] / np.arange(1, D + 2),
        )
        # every slow width at once: S and the inverse per width, then the exact linear
        # responses (float: only for starts and the low parts) to a unit v0, to every
        # unit G_k (as 2 G) and to a unit force, as the right-hand sides of the solve
        if wide.size:
            sizes, which = np.unique(widths[wide], return_inverse=True)
            ops = [slow_operator(alpha, w, kappa=kappa) for w in sizes]
            s_op, inv = np.array([o[0] for o in ops]), np.array([o[1] for o in ops])
            S[:], inverse[:] = s_op[which], inv[which]
            c_y = sizes[:, None] / np.arange(1, D + 2)
            lanes = np.zeros((sizes.size, D + 1, 1 + (D + 1) + 1))  # [width, order, lane]
            lanes[:, 0, 0] = -1.0
            lanes[:, :, 1 : D + 2] = -(s_op * 2.0)
            lanes[:, 0, -1] = 1.0
            V = np.zeros_like(lanes)
            V[:, 0, 0] = 1.0
            V[:, 1:] = inv @ lanes[:, :D]
            twice_g = np.zeros_like(V)
            twice_g[:, :, 1 : D + 2] = 2.0 * np.eye(D + 1)
            N = s_op @ (V + twice_g)
            Y = np.concatenate([np.zeros_like(V[:, :1]), c_y[:, :, None] * V], axis=1)
            ends = np.stack([Y.sum(axis=1), V.sum(axis=1), N.sum(axis=1)], axis=1)  # [w, end, lane]
            ends = ends[which]
            A[wide, :, 0] = [1.0, 0.0, 0.0]  # a unit y0 only moves y
            A[wide, :, 1] = ends[:, :, 0]
            W[wide], b[wide] = ends[:, :, 1 : D + 2], ends[:, :, -1]
            E_y[wide, 0, 0] = 1.0
            E_y[wide, 1], E_v[wide, 1], E_n[wide, 1] = (X[which, :, 0] for X in (Y, V, N))
        return {
            "fine": fine,
            "wide": wide,
            "taylor": taylor_factors,
            "slow": ((S, inverse), slow_factors),
            "chain": ((E_y, E_v, E_n), A, W, b),
            "stages": scan_stages(A[:-1]),  # of one interval's chain (taken apart: _batch)
        }

    def _build_interval(self, m: int) -> None:
        """The coefficients of reflection interval ``m`` (the ones before built)."""
        _build_intervals([self], [m])


def _bounds_y(which: str | tuple) -> bool:
    """Whether ``which`` (``"y"``, ``"N"`` or a tuple of them) asks for the bound of ``y``."""
    parts = (which,) if isinstance(which, str) else tuple(which)
    if not parts or any(part not in ("y", "N") for part in parts):
        raise ValueError(f"which must be 'y', 'N' or a tuple of them, got {which!r}")
    return "y" in parts


def extend_tables(tables: list, n_intervals: list, *, which: str | tuple = ("y", "N")) -> None:
    """Internal: :meth:`ManifoldTable.extend` of ``tables[j]`` to ``n_intervals[j]`` (and
    ``which``) for all of them together: interval by interval, the tables that need one
    more built at once (:func:`_build_intervals`: a NumPy operation on the cells of all of
    them, not one per table), then each bounded. Holds every table's lock meanwhile (taken
    in one order by every caller: no deadlock); a table's intervals are the same to the
    last bit as when built alone."""
    bound_y = _bounds_y(which)
    wanted: dict = {}
    for table, n in zip(tables, n_intervals, strict=True):
        wanted[table] = max(wanted.get(table, 0), min(n, table.n_intervals))
    order = sorted(wanted, key=id)
    with ExitStack() as stack:
        for table in order:
            stack.enter_context(table._lock)
        todo = [t for t in order if wanted[t] > t.built]
        made = {t: t.built for t in todo}
        saved = {t: t._state for t in todo}
        try:
            while batch := [t for t in todo if made[t] < wanted[t]]:
                _build_intervals(batch, [made[t] for t in batch])
                for table in batch:
                    made[table] += 1
            for table in todo:
                table._bound(table.built, wanted[table])
        except BaseException:  # (e.g. KeyboardInterrupt) the next extend starts over,
            for table in todo:  # for the tables whose bound did not finish
                if table.built < wanted[table]:
                    table._state = saved[table]
            raise
        if bound_y:
            for table in order:
                table._bound_y(wanted[table])


#: The data of the last few batches (:func:`_batch`): ``ids -> (weak references, data)``.
_BATCHES: dict = {}
_BATCHES_LOCK = threading.Lock()


def _batch(tables: tuple) -> SimpleNamespace:
    """:func:`_batch_data` of ``tables``, kept for the last 8 batches (a search extends
    the same tables interval after interval). Weak references: the cache neither keeps a
    table alive nor mistakes a new table for a dead one with the same ``id``."""
    key = tuple(id(t) for t in tables)
    with _BATCHES_LOCK:
        hit = _BATCHES.get(key)
    if hit is not None and all(r() is t for r, t in zip(hit[0], tables, strict=True)):
        return hit[1]
    data = _batch_data(tables)
    with _BATCHES_LOCK:
        _BATCHES[key] = (tuple(weakref.ref(t) for t in tables), data)
        while len(_BATCHES) > 8:
            del _BATCHES[next(iter(_BATCHES))]
    return data


def _batch_data(tables: tuple) -> SimpleNamespace:
    """What :func:`_build_intervals` needs of ``tables`` that does not change from one
    interval to the next, stacked: one chain per right-hand side and table (``r J + j``),
    padded to the longest (the padding's maps leave the state as it is)."""
    D, J = DEGREE, len(tables)
    ns = np.array([t.cells_per_interval for t in tables])
    width = int(ns.max())
    A = np.broadcast_to(np.eye(3), (J, width, 3, 3)).copy()
    W, b = np.zeros((J, width, 3, D + 1)), np.zeros((J, width, 3))
    E = tuple(np.zeros((J, width, 3, D + k)) for k in (2, 1, 1))
    for j, table in enumerate(tables):
        responses, A[j, : ns[j]], W[j, : ns[j]], b[j, : ns[j]] = table._maps["chain"]
        for X, x in zip(E, responses, strict=True):
            X[j, : ns[j]] = x

    def lanes(key):  # (table, cell) of the layer resp. slow cells
        j = np.concatenate([np.full(t._maps[key].size, i) for i, t in enumerate(tables)])
        return j, np.concatenate([t._maps[key] for t in tables])

    def stacked(key, i, k=None):
        return np.concatenate(
            [t._maps[key][i] if k is None else t._maps[key][i][k] for t in tables]
        )

    (fj, fc), (sj, sc) = lanes("fine"), lanes("wide")
    return SimpleNamespace(
        ns=ns,
        width=width,
        fine=(fj, fc),
        wide=(sj, sc),
        taylor=tuple(stacked("taylor", i) for i in range(3)),
        operators=tuple(stacked("slow", 0, i) for i in range(2)),
        factors=tuple(stacked("slow", 1, i) for i in range(2)),
        widths=np.concatenate([t._widths[t._maps["wide"]] for t in tables]),
        kappa=np.concatenate([np.full(t._maps["wide"].size, t.kappa) for t in tables]),
        W=W,
        b=b,
        responses=tuple(np.concatenate([X, X]) for X in E),
        stages=stacked_stages([t._maps["stages"] for t in tables], width - 1),
        last=np.tile(ns - 1, 2),
    )


def _build_intervals(tables: list, intervals: list) -> None:
    """The coefficients of reflection interval ``intervals[j]`` of ``tables[j]`` (the ones
    before built), all cells of all of them at once: one chain per table and right-hand
    side (:func:`impactsym.rod.elastic.chain.cell_chain`; shorter chains padded), the
    layer's Taylor recurrences and the slow cells' solves and sweeps one NumPy operation
    each. Every operation is elementwise or a product per cell, so a table's coefficients
    are the same to the last bit whichever tables are built with it."""
    D, J = DEGREE, len(tables)
    batch = _batch(tuple(tables))
    ns, width = batch.ns, batch.width
    force = np.array([0.0, 1.0])
    g_hi, g_lo = np.zeros((2, J, width, D + 1)), np.zeros((2, J, width, D + 1))
    for j, (table, m) in enumerate(zip(tables, intervals, strict=True)):
        n, a = ns[j], table._arrays
        cells = slice(m * n, (m + 1) * n)
        if m:  # G_m = N_(m-1) - G_(m-1), nearly exactly (measured in the bound)
            before = slice((m - 1) * n, m * n)
            a["G_hi"][:, cells], a["G_lo"][:, cells] = next_incoming(
                a["N"][:, before], a["N_lo"][:, before], a["G_hi"][:, before], a["G_lo"][:, before]
            )
        g_hi[:, j, :n], g_lo[:, j, :n] = a["G_hi"][:, cells], a["G_lo"][:, cells]
    G = g_hi + g_lo
    (fj, fc), (sj, sc) = batch.fine, batch.wide

    def coefficients(starts):
        starts = starts.reshape(2, J, width, 3)
        Y = np.zeros((2, J, width, D + 2))
        V, N, N_lo = (np.zeros((2, J, width, D + 1)) for _ in range(3))
        y0, v0, n0 = np.moveaxis(starts[:, fj, fc], -1, 0)
        Y[:, fj, fc], V[:, fj, fc], N[:, fj, fc] = taylor_cells(
            y0, v0, n0, force[:, None], G[:, fj, fc], batch.taylor
        )
        # the slow cells of both right-hand sides: [rhs, cell, order]
        y0, v0 = (starts[:, sj, sc, i] for i in (0, 1))
        gh, gl = g_hi[:, sj, sc], g_lo[:, sj, sc]
        Y[:, sj, sc], V[:, sj, sc] = slow_cells(
            y0, v0, force[:, None], gh, gl, batch.widths, batch.operators, batch.factors,
            kappa=batch.kappa,
        )  # fmt: skip
        # N on the slow manifold in double-double (its low parts: part of the cell)
        N[:, sj, sc], N_lo[:, sj, sc] = manifold_forces(
            V[:, sj, sc], np.zeros(y0.shape), gh, gl, batch.widths, kappa=batch.kappa
        )
        chains = [X.reshape(2 * J, width, -1) for X in (Y, V, N)]
        return chains, (None, None, N_lo.reshape(2 * J, width, -1))

    offsets = (G[..., None, :] * batch.W).sum(axis=-1) + force[:, None, None, None] * batch.b
    state = tuple(
        np.stack([t._state[i] for t in tables], axis=1).reshape(2 * J, 3) for i in range(2)
    )
    polys, lows, (high, low) = cell_chain(
        coefficients,
        batch.responses,
        batch.stages,
        offsets.reshape(2 * J, width, 3),
        state,
        last=batch.last,
    )
    high, low = high.reshape(2, J, 3), low.reshape(2, J, 3)
    polys, lows = ([x.reshape(2, J, width, -1) for x in group] for group in (polys, lows))
    for j, (table, m) in enumerate(zip(tables, intervals, strict=True)):
        n, a = ns[j], table._arrays
        cells = slice(m * n, (m + 1) * n)
        for names, arrays in ((("Y", "V", "N"), polys), (("Y_lo", "V_lo", "N_lo"), lows)):
            for name, x in zip(names, arrays, strict=True):
                a[name][:, cells] = x[:, j, :n]
        table._state = (high[:, j].copy(), low[:, j].copy())


@lru_cache(maxsize=64)
def manifold_table(alpha: float, *, kappa: float, n_intervals: int) -> ManifoldTable:
    """Internal: the cached :class:`ManifoldTable` of ``(alpha, kappa)`` over ``n_intervals``,
    built lazily: :meth:`ManifoldTable.extend` builds the intervals a search needs."""
    return ManifoldTable(alpha, kappa, n_intervals, lazy=True)
