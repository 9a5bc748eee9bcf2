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
the Taylor table (:func:`impactsym.rod.elastic.taylor.cell_bounds`: residuals and jumps
measured on the stored arrays, the energy of the error): how the coefficients were made
does not enter the proof. See docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import math
import threading
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from impactsym.rod.elastic import taylor
from impactsym.rod.elastic.taylor import (
    DEGREE,
    TaylorTable,
    TaylorView,
    check_table_arguments,
    fastest_rate,
    next_incoming,
    taylor_cell,
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


def _power_of_two_below(x: float) -> float:
    return 2.0 ** math.floor(math.log2(x))


def interval_mesh(alpha: float, *, kappa: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Internal: widths (powers of two) of the cells of one reflection interval and which
    of them are layer (Taylor) cells, or ``None`` where the slow manifold does not apply
    (complex or near contact poles, ``p_f / p_s < 8``, or a layer longer than 1).

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
    if not (math.isfinite(fast) and fast >= _SEPARATION * slow):
        return None
    h = _power_of_two_below(_LAYER_REACH / fast)
    wide = _power_of_two_below(min(_SLOW_REACH / slow, _WIDEST))
    if wide < 8.0 * h:
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


def _slow_operator(alpha: float, kappa: float, width: float):
    """``S`` (``N = S (v + 2G)`` on coefficients in ``xi``, degree ``DEGREE``) and the
    inverse of the matrix of ``alpha v' + N = f`` in ``v_1 .. v_D`` (``v_0`` given)."""
    D = DEGREE
    eps = 1.0 / (width * kappa)
    # S[j, i] = prod_{l = j+1 .. i} (-eps l): running products along each row (above
    # the diagonal; ones on and below it multiply exactly), the same products in order
    order = np.arange(D + 1)
    factors = np.where(order[None, :] > order[:, None], -eps * order[None, :], 1.0)
    S = np.triu(np.cumprod(factors, axis=1))
    M = S[:D, 1:].copy()
    M[np.arange(D), np.arange(D)] += alpha * np.arange(1, D + 1) / width
    return S, np.linalg.inv(M)


def _manifold_forces(V, V0_lo, G_hi, G_lo, widths, kappa):
    """``N = S (v + 2G)`` of slow cells in double-double by the back recurrence
    ``N_k = v_k + 2 G_k - (k + 1) N_{k+1} / (h kappa)`` (``v`` from ``V`` and the low parts
    ``V0_lo`` of its constant coefficients, ``G = G_hi + G_lo``; ``[cell, order]``, one
    width per cell): ``(N_high, N_low)``, each step a compensated sum."""
    D = DEGREE
    n_high, n_low = np.zeros_like(V), np.zeros_like(V)
    nh, nl = np.zeros(V.shape[0]), np.zeros(V.shape[0])
    for k in range(D, -1, -1):
        t = ((k + 1) / widths * (nh + nl)) / kappa
        vk, gh = V[:, k], 2.0 * G_hi[:, k]
        s1 = vk + gh
        bb = s1 - vk
        e1 = (vk - (s1 - bb)) + (gh - bb)
        s2 = s1 - t
        bb = s2 - s1
        e2 = (s1 - (s2 - bb)) + (-t - bb)
        low = (e1 + e2) + (2.0 * G_lo[:, k] + (V0_lo if k == 0 else 0.0))
        nh = s2 + low
        nl = low - (nh - s2)
        n_high[:, k], n_low[:, k] = nh, nl
    return n_high, n_low


def _slow_velocity(y0, v0, force, G_hi, G_lo, width, kappa, operator, factors):
    """``(v, y)`` (lists, lowest order first) on one slow cell from its start ``y0`` and
    ``v0 = (high, low)`` and its incoming wave ``G_hi + G_lo``: the linear solve, then one
    Gauss-Seidel sweep (``N_k`` from the new ``v_k`` and the solve's ``N_{k+1}``, in
    double-double, then ``v_{k+1} = h (f delta_{k0} - N_k)/(alpha (k+1))``)."""
    v0, v0_lo = v0
    D = DEGREE
    S, inverse = operator
    c_v, c_y = factors
    twice_g = 2.0 * (G_hi + G_lo)
    rhs = -(S @ twice_g)[:D]
    rhs[0] += force - v0
    v = [v0, *(inverse @ rhs).tolist()]
    old = (S @ (np.array(v) + twice_g)).tolist()
    gh, gl = (2.0 * G_hi).tolist(), (2.0 * G_lo).tolist()
    fk, vl = force, v0_lo
    for k in range(D):
        vk = v[k]
        t = ((k + 1) / width * old[k + 1]) / kappa
        s1 = vk + gh[k]
        bb = s1 - vk
        e1 = (vk - (s1 - bb)) + (gh[k] - bb)
        s2 = s1 - t
        bb = s2 - s1
        e2 = (s1 - (s2 - bb)) + (-t - bb)
        low = (e1 + e2) + (gl[k] + vl)
        nh = s2 + low
        v[k + 1] = c_v[k] * ((fk - nh) - (low - (nh - s2)))
        fk = vl = 0.0
    y = [y0] + [cy * vk for cy, vk in zip(c_y, v, strict=True)]
    return v, y


def _split_total(values: list) -> tuple[float, float]:
    """The exact sum of ``values`` as ``(high, low)``, both correctly rounded."""
    high = math.fsum(values)
    return high, math.fsum([*values, -high])


class ManifoldTable(TaylorTable):
    """``y`` and ``N`` for one ``(alpha, kappa)`` of a stiff spring on ``[0, 2 n_intervals]``:
    the attributes and :meth:`view` of :class:`impactsym.rod.elastic.taylor.TaylorTable`,
    on the cells of :func:`interval_mesh` (``h`` per cell).

    Built interval by interval: with ``lazy=True`` none at first, then as far as
    :meth:`extend` asks (the attributes and views hold the intervals built); the cells,
    coefficients and bounds of an interval do not depend on later ones (the bound
    accumulates forward), so they are the same, to the last bit, however far the table
    is built and in how many steps."""

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
        self._arrays = {
            "Y": np.zeros((2, total, D + 2)),
            **{name: np.zeros((2, total, D + 1)) for name in ("V", "N", "N_lo", "G_hi", "G_lo")},
            "Y_lo": np.zeros((2, total)),
            "V_lo": np.zeros((2, total)),
        }
        self._errors = np.zeros((4, total))
        self._carry = None
        self._lock = threading.Lock()
        # (y, v, N) at the next cell start, as (high, low) pairs
        self._state = [[(0.0, 0.0), (1.0, 0.0), (0.0, 0.0)], [(0.0, 0.0)] * 3]
        self._factors = self._cell_factors()
        self._expose()
        if not lazy:
            self.extend(n_intervals)

    def extend(self, n_intervals: int) -> None:
        """Build and bound the intervals up to ``n_intervals`` (at most the table's); one
        thread at a time (a cached table is shared), the intervals built never change."""
        with self._lock:
            self._extend(min(n_intervals, self.n_intervals))

    def _extend(self, end: int) -> None:
        if end <= self.built:
            return
        begin = self.built
        for m in range(begin, end):
            self._build_interval(m)
        n, a = self.cells_per_interval, self._arrays
        upto = slice(0, end * n)
        arrays = tuple(a[name][:, upto] for name in ("Y", "V", "N"))
        lows = tuple(a[name][:, upto] for name in ("Y_lo", "V_lo", "N_lo"))
        incoming = (a["G_hi"][:, upto], a["G_lo"][:, upto])
        bounds, self._carry = taylor.cell_bounds(
            self.alpha, self._h[upto], arrays, lows, incoming, n,
            kappa=self.kappa, start=begin, carry=self._carry,
        )  # fmt: skip
        self._errors[:, begin * n : end * n] = bounds
        self.built = end
        self._expose()

    def view(self, which: str, *, n_intervals: int | None = None) -> TaylorView:
        """:meth:`TaylorTable.view` over the first ``n_intervals`` reflection intervals
        (default: all built), built first as far as that."""
        if n_intervals is None:
            return super().view(which)
        self.extend(n_intervals)
        upto = slice(0, min(n_intervals, self.n_intervals) * self.cells_per_interval)
        if which not in ("y", "N"):
            raise ValueError(f"which must be 'y' or 'N', got {which!r}")
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

    def _cell_factors(self):
        """The Taylor factors of the layer cells and the slow operators of the wide cells,
        per width."""
        alpha, kappa, D = self.alpha, self.kappa, DEGREE
        width_list = self._widths.tolist()
        taylor_factors = {
            h: (
                [h / (alpha * (k + 1)) for k in range(D)],
                [h * kappa / (k + 1) for k in range(D)],
                [h / (k + 1) for k in range(D + 1)],
            )
            for h in {w for w, fine in zip(width_list, self._layer, strict=True) if fine}
        }
        slow = {}
        for width in {w for w, fine in zip(width_list, self._layer, strict=True) if not fine}:
            slow[width] = (
                _slow_operator(alpha, kappa, width),
                (
                    [width / (alpha * (k + 1)) for k in range(D)],
                    [width / (k + 1) for k in range(D + 1)],
                ),
            )
        return taylor_factors, slow

    def _build_interval(self, m: int) -> None:
        """The coefficients of reflection interval ``m`` (the ones before built)."""
        kappa, D = self.kappa, DEGREE
        widths, layer = self._widths, self._layer
        width_list = widths.tolist()
        taylor_factors, slow = self._factors
        n = widths.size
        a = self._arrays
        Y, V, N, N_lo, Y_lo, V_lo = (a[k] for k in ("Y", "V", "N", "N_lo", "Y_lo", "V_lo"))
        G_hi, G_lo = a["G_hi"], a["G_lo"]
        state = self._state
        cells = slice(m * n, (m + 1) * n)
        if m:  # G_m = N_(m-1) - G_(m-1), nearly exactly (measured in the bound)
            before = slice((m - 1) * n, m * n)
            G_hi[:, cells], G_lo[:, cells] = next_incoming(
                N[:, before], N_lo[:, before], G_hi[:, before], G_lo[:, before]
            )
        for rhs, force in ((0, 0.0), (1, 1.0)):
            (y0, y0_lo), (v0, v0_lo), (n0, n0_lo) = state[rhs]
            rows_v, rows_y, rows_n, lows = [], [], [], []
            incoming = (G_hi[rhs, cells] + G_lo[rhs, cells]).tolist()
            for i in range(n):
                c = m * n + i
                lows.append((v0_lo, y0_lo, n0_lo))
                if layer[i]:
                    v, n_high, y = taylor_cell(
                        y0, v0, n0, force, incoming[i], taylor_factors[width_list[i]]
                    )
                    rows_n.append(n_high)
                    n0, n0_lo = _split_total([*n_high, n0_lo])
                else:  # N: all slow cells of the interval at once, below
                    operator, factors = slow[width_list[i]]
                    v, y = _slow_velocity(
                        y0, (v0, v0_lo), force, G_hi[rhs, c], G_lo[rhs, c], width_list[i],
                        kappa, operator, factors,
                    )  # fmt: skip
                    rows_n.append([0.0] * (D + 1))
                rows_v.append(v)
                rows_y.append(y)
                y0, y0_lo = _split_total([*y, y0_lo])
                v0, v0_lo = _split_total([*v, v0_lo])
            V[rhs, cells], Y[rhs, cells], N[rhs, cells] = rows_v, rows_y, rows_n
            V_lo[rhs, cells], Y_lo[rhs, cells], N_lo[rhs, cells, 0] = np.array(lows).T
            state[rhs] = [(y0, y0_lo), (v0, v0_lo), (n0, n0_lo)]
        # N on the slow cells of both right-hand sides at once (elementwise)
        at = m * n + np.flatnonzero(~layer)
        flat = [X[:, at].reshape(2 * at.size, D + 1) for X in (V, G_hi, G_lo)]
        high, low = _manifold_forces(
            flat[0], V_lo[:, at].ravel(), *flat[1:], np.tile(widths[~layer], 2), kappa
        )
        N[:, at], N_lo[:, at] = (x.reshape(2, at.size, D + 1) for x in (high, low))
        if not layer[-1]:
            for rhs in (0, 1):
                state[rhs][2] = _split_total([*N[rhs, at[-1]], *N_lo[rhs, at[-1]]])


@lru_cache(maxsize=64)
def manifold_table(alpha: float, *, kappa: float, n_intervals: int) -> ManifoldTable:
    """Internal: the cached :class:`ManifoldTable` of ``(alpha, kappa)`` over ``n_intervals``,
    built lazily: :meth:`ManifoldTable.extend` builds the intervals a search needs."""
    return ManifoldTable(alpha, kappa, n_intervals, lazy=True)
