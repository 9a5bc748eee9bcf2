r"""Finite contact stiffness, method 3: a certified Taylor table of the delay equations in float64.

The rod's free end carries an outgoing wave :math:`g(t)` and the incoming one
:math:`G(t) = g(t - 2)`; with the massless contact spring :math:`N = \kappa(y - u)` the
persistent-contact problem (eq. (1) in the time domain) is, for :math:`t \ge 0`,

.. math::

    y' = v, \qquad \alpha v' = f - N, \qquad N' = \kappa (v - N + 2G), \qquad
    G = N(t - 2) - G(t - 2), \qquad y(0) = 0,\ v(0) = 1,\ N(0) = 0.

Every reflection interval is cut into :math:`2^j \ge 16` equal cells with
:math:`h |p| \le 1` for the roots :math:`p` of :math:`\alpha s^2 + \alpha\kappa s + \kappa`;
on a cell :math:`y, v, N` are Taylor polynomials of degree ``DEGREE`` from the exact
recurrences of the equations, linear in :math:`f` (:math:`A + f B`), all cells of an
interval at once (:func:`impactsym.rod.elastic.chain.cell_chain`), each starting at the
exact end of the one before (to :math:`u^2`, with low parts of every coefficient). The
error bound is
a posteriori: the residuals and jumps of the stored polynomials, measured exactly to
rounding (:mod:`impactsym.numeric.eft`), drive the error, whose energy the lossless rod
and spring cannot grow. Float64 and milliseconds per table, where the mpmath table of
:mod:`impactsym.rod.elastic.cells` takes seconds; springs needing more than ``MAX_CELLS``
cells per interval are left to that table. The bound and its proof:
docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import math
import numbers
from functools import lru_cache

import numpy as np

from impactsym.numeric.eft import UNIT_ROUNDOFF as _U
from impactsym.numeric.eft import gamma, sum_with_bound, two_prod, two_sum
from impactsym.rod.elastic.chain import cell_chain, scan_stages, tree_sum_with_bound
from impactsym.validation import real_array

#: Polynomial degree of ``v`` and ``g`` on a cell (``y``: one more).
DEGREE = 24
#: Largest ``h |p|`` on a cell, ``p`` a root of ``alpha s^2 + alpha kappa s + kappa``.
_REACH = 1.0
#: Most cells per reflection interval (beyond: the contact spring is too stiff for
#: this table).
MAX_CELLS = 256
_EPS = float(np.finfo(np.float64).eps)
#: Largest sum of the absolute coefficients of a cell's ``N`` (its Horner rounding
#: bound is ``(DEGREE + 4) eps`` times it) before the cells are halved.
_COEFFICIENT_SUM = 100.0
#: Fewest cells per reflection interval (the later intervals' polynomials grow in degree).
_MIN_CELLS = 16


def fastest_rate(alpha: float, *, kappa: float) -> float:
    """Internal: largest modulus of the roots of :math:`\\alpha s^2 + \\alpha\\kappa s + \\kappa`:
    :math:`\\sqrt{\\kappa/\\alpha}` for a complex pair, else :math:`(\\kappa + \\sqrt{\\kappa^2 -
    4\\kappa/\\alpha})/2`."""
    disc = kappa * kappa - 4.0 * kappa / alpha
    return math.sqrt(kappa / alpha) if disc <= 0 else 0.5 * (kappa + math.sqrt(disc))


def cells_per_interval(alpha: float, *, kappa: float) -> int:
    """Internal: cells per reflection interval, the least power of two ``n >= _MIN_CELLS``
    with ``(2/n) fastest_rate(alpha, kappa=kappa) <= _REACH``."""
    fastest = fastest_rate(alpha, kappa=kappa)
    if not math.isfinite(fastest):
        raise ValueError(f"kappa = {kappa!r} (alpha = {alpha!r}) overflows float64")
    n = _MIN_CELLS
    while 2.0 / n * fastest > _REACH:
        n *= 2
    return n


def check_table_arguments(
    alpha: object, *, kappa: object, n_intervals: object
) -> tuple[float, float]:
    """Internal: ``(alpha, kappa)`` as floats, or raise naming the argument: both real
    scalars ``> 0`` (``kappa`` finite), ``n_intervals`` an integer ``>= 1``."""
    checked = {
        name: real_array(name, value, lower=0.0, strict=True)
        for name, value in (("alpha", alpha), ("kappa", kappa))
    }
    for name, (_, scalar) in checked.items():
        if not scalar:
            raise TypeError(f"{name} must be a real number, got an array")
    if isinstance(n_intervals, bool) or not isinstance(n_intervals, numbers.Integral):
        raise TypeError(f"n_intervals must be an integer, got {n_intervals!r}")
    if n_intervals < 1:
        raise ValueError(f"n_intervals must be >= 1, got {n_intervals!r}")
    alpha_f, kappa_f = (float(value) for value, _ in checked.values())
    return alpha_f, kappa_f


class TaylorTable:
    """``y`` and ``N`` for one ``(alpha, kappa)`` on ``[0, 2 n_intervals]``.

    Attributes per cell ``i`` (``lo[i] <= t <= hi[i]``, width ``h``):
    ``Y_a, Y_b`` (degree ``DEGREE + 1``) and ``N_a, N_b`` (degree ``DEGREE``) in
    ``xi = (t - lo)/h``, lowest order first; proven bounds ``err_y_a, err_y_b,
    err_n_a, err_n_b`` of ``|g - (A + f B)|`` on the cell (including a Horner
    evaluation's rounding). :meth:`view` gives the search interface of one of them.
    """

    def __init__(self, alpha: float, kappa: float, n_intervals: int) -> None:
        self.alpha, self.kappa = check_table_arguments(alpha, kappa=kappa, n_intervals=n_intervals)
        n = cells_per_interval(self.alpha, kappa=self.kappa)
        if n > MAX_CELLS:
            raise ValueError(
                f"kappa = {kappa!r} (alpha = {alpha!r}) needs {n} Taylor cells per "
                f"reflection interval (at most {MAX_CELLS})"
            )
        while True:
            self._build(n, n_intervals)
            # polynomials whose coefficients cancel (the later reflections raise their
            # degree) cost their Horner rounding: halve the cells while that shows
            size = max(np.abs(c).sum(axis=-1).max() for c in (self.N_a, self.N_b))
            if size <= _COEFFICIENT_SUM or 2 * n > MAX_CELLS:
                break
            n *= 2
        self.cells_per_interval = n

    def _build(self, n: int, n_intervals: int) -> None:
        """Coefficients on ``n`` cells per interval, then :meth:`_bound`: all cells of an
        interval at once (:func:`impactsym.rod.elastic.chain.cell_chain`)."""
        self.h = h = 2.0 / n
        total = n * n_intervals
        self.lo = np.arange(total) * h
        self.hi = self.lo + h
        D = DEGREE
        # coefficients [rhs (A, B), cell, order] and their low parts (every order): a
        # cell starts exactly where the one before ends, up to u^2. G = g(t - 2), the
        # alternating sum of the N before, is double-double. (The bound measures both
        # afterwards, in _bound.)
        Y, Y_lo = np.zeros((2, total, D + 2)), np.zeros((2, total, D + 2))
        V, N, V_lo, N_lo, G_hi, G_lo = (np.zeros((2, total, D + 1)) for _ in range(6))
        factors = tuple(
            np.array(c)
            for c in (
                [h / (self.alpha * (k + 1)) for k in range(D)],
                [h * self.kappa / (k + 1) for k in range(D)],
                [h / (k + 1) for k in range(D + 1)],
            )
        )
        maps = layer_maps(factors)
        stages = scan_stages(np.broadcast_to(maps[1], (2, n - 1, 3, 3)))
        force = np.array([0.0, 1.0])
        # (y, v, N) at the interval's start, high and low parts, per right-hand side
        state = (np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]), np.zeros((2, 3)))
        for m in range(n_intervals):
            cells = slice(m * n, (m + 1) * n)
            if m:  # G_m = N_(m-1) - G_(m-1), nearly exactly
                before = slice((m - 1) * n, m * n)
                G_hi[:, cells], G_lo[:, cells] = next_incoming(
                    N[:, before], N_lo[:, before], G_hi[:, before], G_lo[:, before]
                )
            G = G_hi[:, cells] + G_lo[:, cells]
            offsets = G @ maps[2].T + force[:, None, None] * maps[3]

            def coefficients(starts, G=G):
                polys = taylor_cells(*np.moveaxis(starts, -1, 0), force[:, None], G, factors)
                return polys, (None, None, None)

            (Y[:, cells], V[:, cells], N[:, cells]), lows, state = cell_chain(
                coefficients, maps[0], stages, offsets, state
            )
            Y_lo[:, cells], V_lo[:, cells], N_lo[:, cells] = lows
        self._bound(Y, V, N, (Y_lo, V_lo, N_lo), G_hi, G_lo, n)

    def _bound(self, Y, V, N, lows, G_hi, G_lo, n):
        """The error bounds of the stored arrays (:func:`cell_bounds`); sets the tables."""
        bounds, _ = cell_bounds(
            self.alpha, self.h, (Y, V, N), lows, (G_hi, G_lo), n, kappa=self.kappa
        )
        self.N_a, self.N_b = N
        self.Y_a, self.Y_b = Y
        self.err_y_a, self.err_y_b, self.err_n_a, self.err_n_b = bounds

    def view(self, which: str) -> TaylorView:
        """One time function, ``"y"`` or ``"N"``, as a
        :class:`impactsym.rod.elastic.CertifiedTable`."""
        if which not in ("y", "N"):
            raise ValueError(f"which must be 'y' or 'N', got {which!r}")
        if which == "y":
            return TaylorView(self, self.Y_a, self.Y_b, self.err_y_a, self.err_y_b)
        return TaylorView(self, self.N_a, self.N_b, self.err_n_a, self.err_n_b)


def cell_bounds(alpha, h, arrays, lows, incoming, n, *, kappa, start=0, carry=None):
    """Internal: proven bounds ``(err_y_a, err_y_b, err_n_a, err_n_b)`` per cell of stored
    polynomials of the delay equations, from their residuals, jumps and the energy bound
    (docs/physics.md#finite-contact-stiffness-three-methods), all measured on the arrays,
    and the ``carry`` that continues them on later intervals: :func:`force_bounds`, then
    :func:`displacement_bounds` on its ``coupling``.

    ``arrays = (Y, V, N)`` (``[rhs, cell, order]`` in ``xi = (t - lo)/h``), ``lows = (Y_lo,
    V_lo, N_lo)`` their low parts (``[rhs, cell, order]``: of every coefficient, as
    :func:`~impactsym.rod.elastic.chain.cell_chain` makes them), ``incoming = (G_hi,
    G_lo)``, ``n`` cells
    per reflection interval (the same cells in every interval), ``h`` the cell width (a
    power of two: then ``t - lo`` and the divisions by ``h`` are exact), one for all cells
    or one per cell. Includes a Horner evaluation's rounding of the high parts.

    A table built interval by interval is bounded the same way: with ``start`` (the first
    reflection interval to bound) and the ``carry`` of the call that bounded the ones
    before, the bounds of the cells from interval ``start`` on are those of one call on
    all of them, to the last bit (the sums run on, in the same order); the cells before
    are read for the jump into the first new cell and the incoming wave's defect.
    """
    Y, V, N = arrays
    Y_lo, V_lo, N_lo = lows
    force_carry, displacement_carry = (None, None) if carry is None else (carry[:2], carry[2:])
    (err_n_a, err_n_b), coupling, force_carry = force_bounds(
        alpha, h, (V, N), (V_lo, N_lo), incoming, n, kappa=kappa, start=start, carry=force_carry
    )
    (err_y_a, err_y_b), displacement_carry = displacement_bounds(
        alpha, h, (Y, V), (Y_lo, V_lo), coupling, n, kappa=kappa, start=start,
        carry=displacement_carry,
    )  # fmt: skip
    return (err_y_a, err_y_b, err_n_a, err_n_b), (*force_carry, *displacement_carry)


def force_bounds(alpha, h, arrays, lows, incoming, n, *, kappa, start=0, carry=None):
    """Internal: the part of :func:`cell_bounds` that ``N`` needs, ``(err_n_a, err_n_b)``,
    from ``arrays = (V, N)``, ``lows = (V_lo, N_lo)`` and ``incoming`` (as there): the
    residuals of ``alpha v' = f - N`` and ``N' = kappa (v - N + 2G)``, the jumps of ``v``
    and ``N`` and the energy bound ``q`` they drive; also the ``coupling`` of each cell
    that :func:`displacement_bounds` needs of them (``q`` before its margin, the
    residual's and the jump's terms of ``N`` in ``sigma``; ``[3, rhs, cell]``) and the
    ``carry`` (``[incoming wave defect, q]``) that continues them on later intervals.
    ``y`` does not enter: a search for ``N`` alone bounds nothing of ``y``."""
    V, N = arrays
    G_hi, G_lo = incoming
    V_lo, N_lo = lows
    D = DEGREE
    first = start * n  # the first cell bounded
    _check_carry("force_bounds", start, carry)
    n_low_all = N_lo
    dG_raw = _incoming_wave_defect(N, n_low_all, G_hi, G_lo, n, start, carry)
    dG = dG_raw * (1.0 + 1e-9)  # (0 on interval 0: G = 0 there)
    # the cell before the ones bounded (its end: the first jump), then those
    ends = [
        (C[:, first - 1 : first], C_lo[:, first - 1 : first]) if first else None
        for C, C_lo in ((V, V_lo), (N, N_lo))
    ]
    V, N, G_hi, G_lo = (x[:, first:] for x in (V, N, G_hi, G_lo))
    V_lo, N_lo = (x[:, first:] for x in (V_lo, N_lo))
    h, hc, kp1 = _widths_from(h, first)
    pad = np.zeros_like(V[..., :1])
    v_next = np.concatenate([V[..., 1:], pad], axis=-1)
    n_next = np.concatenate([N[..., 1:], pad], axis=-1)
    force = np.zeros_like(V)
    force[1, :, 0] = 1.0
    v_low, n_low = V_lo, N_lo
    n_low_next = np.concatenate([n_low[..., 1:], pad], axis=-1)
    # with low parts of every coefficient (a few ulps: float, their rounding bounded):
    # their derivatives, by kp1/h (exact: h a power of two) and by alpha/h
    lows_v = [(alpha / hc) * (kp1 * np.concatenate([V_lo[..., 1:], pad], axis=-1))]
    # r1 = alpha v' - f + N
    x1, x2 = two_prod(kp1, v_next)
    p, e = two_prod(alpha / hc, x1)
    rest = (alpha / hc) * x2
    r1, b1 = sum_with_bound([p, e, rest, -force, N, n_low, *lows_v], 2)
    b1 += _U * np.abs(rest)
    for z in lows_v:
        b1 += 3.0 * _U * np.abs(z)
    # r2 = N' - kappa (v - N + 2 G), G = G_hi + G_lo (+- dG)
    terms = [*two_prod(kp1 / hc, n_next)]
    for factor, x in ((-kappa, V), (kappa, N), (-2.0 * kappa, G_hi)):
        terms += two_prod(factor, x)
    # the low parts' terms (each at most u/2 of its high part's, or of G's) in float: a
    # product each and their sum, within 5 u of the sum of their sizes (u^2 of r2's terms)
    small = [-kappa * v_low, kappa * n_low, (-2.0 * kappa) * G_lo, (kp1 / hc) * n_low_next]
    small_sum = small[0]
    for z in small[1:]:
        small_sum = small_sum + z
    r2, b2 = sum_with_bound([*terms, small_sum], len(terms) // 2)
    b2 += 2.0 * kappa * dG + 5.0 * _U * sum(np.abs(z) for z in small)
    # integrals over a cell: h int_0^1 |sum r_k xi^k| <= h sum |r_k| / (k + 1)
    margin = 1.0 + 1e-9
    i1, i2 = (_cell_integral(np.abs(r) + b, h, kp1) for r, b in ((r1, b1), (r2, b2)))
    # jumps at the cell starts (from the end of the cell before, or the initial state)
    j_v, j_n = (
        _jumps(C, C_lo, initial, before)
        for C, C_lo, initial, before in zip(
            (V, N), (V_lo, N_lo), (np.array([1.0, 0.0]), np.zeros(2)), ends, strict=True
        )
    )
    sqa, sqk = math.sqrt(alpha), math.sqrt(kappa)
    q_sum = _running_sum(
        i1 / sqa + i2 / sqk + sqa * j_v + j_n / sqk, None if carry is None else carry[1]
    )
    e_n = sqk * (q_sum * margin)
    # the tables hold the high parts: |low| and a Horner evaluation's rounding
    horner_n = _EPS * (D + 4) * np.abs(N).sum(axis=-1) + _abs_low(N_lo)
    err_n_a, err_n_b = (e_n + horner_n) * margin
    coupling = np.stack([q_sum, i2 / kappa, j_n / kappa])
    return (err_n_a, err_n_b), coupling, (dG_raw[:, -n:], q_sum[:, -1:])


def displacement_bounds(alpha, h, arrays, lows, coupling, n, *, kappa, start=0, carry=None):
    """Internal: the part of :func:`cell_bounds` that ``y`` adds, ``(err_y_a, err_y_b)``,
    from ``arrays = (Y, V)``, ``lows = (Y_lo, V_lo)`` (as there) and the ``coupling`` of
    :func:`force_bounds` on the same cells (from interval ``start`` on): the residual of
    ``y' = v`` and the jumps of ``y``, then two bounds of ``e_y``, both valid, the lesser
    kept. With ``start`` and the ``carry`` (``[sigma, v]``: the running sums) of the call
    on the intervals before, the same bits as one call on all of them; it may come any
    time after :func:`force_bounds` (a table bounds ``y`` only when a search asks)."""
    Y, V = arrays
    Y_lo, V_lo = lows
    D = DEGREE
    first = start * n  # the first cell bounded
    _check_carry("displacement_bounds", start, carry)
    before = (Y[:, first - 1 : first], Y_lo[:, first - 1 : first]) if first else None
    Y, V, Y_lo, V_lo = (x[:, first:] for x in (Y, V, Y_lo, V_lo))
    h, hc, kp1 = _widths_from(h, first)
    v_low = V_lo
    # r0 = y' - v
    p, e = two_prod(kp1 / hc, Y[..., 1:])
    # with low parts of every coefficient: their derivatives, by kp1/h (exact)
    lows_y = [(kp1 / hc) * Y_lo[..., 1:]]
    r0, b0 = sum_with_bound([p, e, -V, -v_low, *lows_y], 1)
    for z in lows_y:
        b0 += _U * np.abs(z)
    margin = 1.0 + 1e-9
    i0 = _cell_integral(np.abs(r0) + b0, h, kp1)
    j_y = _jumps(Y, Y_lo, np.zeros(2), before)
    q_sum, i2_term, j_n_term = coupling
    sqa, sqk = math.sqrt(alpha), math.sqrt(kappa)
    old = (None, None) if carry is None else carry
    sigma_sum = _running_sum(i0 + i2_term + j_y + j_n_term, old[0])
    q, sigma = q_sum * margin, sigma_sum * margin
    # two bounds of e_y, both valid: through y = u + N/kappa (tight unless the
    # spring is very soft), and e_y = int e_v with |e_v| <= q / sqrt(alpha)
    v_sum = _running_sum(h * q / sqa + i0 + j_y, old[1])
    through_v = v_sum * margin
    e_y = np.minimum(q * (1.0 + 1.0 / sqk) + sigma, through_v)
    # the tables hold the high parts: |low| and a Horner evaluation's rounding
    horner_y = _EPS * (D + 5) * np.abs(Y).sum(axis=-1) + _abs_low(Y_lo)
    err_y_a, err_y_b = (e_y + horner_y) * margin
    return (err_y_a, err_y_b), (sigma_sum[:, -1:], v_sum[:, -1:])


def _check_carry(name: str, start: int, carry) -> None:
    if (start > 0) != (carry is not None):
        raise ValueError(f"{name}: a carry goes with start > 0, and only then")


def _widths_from(h, first: int):
    """``(h, hc, kp1)`` of the cells from ``first`` on: the width (one, or one per cell),
    as a column to broadcast over the orders, and ``k + 1`` per order."""
    if np.ndim(h):
        h = np.asarray(h)[first:]
    hc = h if np.ndim(h) == 0 else np.asarray(h)[:, None]
    return h, hc, np.arange(DEGREE + 1) + 1.0


def _running_sum(x: np.ndarray, before: np.ndarray | None) -> np.ndarray:
    """``cumsum`` along the cells, continuing the running sum ``before`` (``[rhs, 1]``) of
    the cells before: the same additions in the same order as one ``cumsum``."""
    if before is None:
        return np.cumsum(x, axis=-1)
    return np.cumsum(np.concatenate([before, x], axis=-1), axis=-1)[..., 1:]


def next_incoming(
    N: np.ndarray, N_lo: np.ndarray, G_hi: np.ndarray, G_lo: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Internal: the incoming wave of the next reflection interval, ``G_m = N_(m-1) -
    G_(m-1)`` on the cell coefficients, in double-double from ``N + N_lo`` and ``G_hi +
    G_lo`` of the interval before (``N_lo``: every coefficient's low part)."""
    s, e = two_sum(N, -G_hi)
    return two_sum(s, e - G_lo + N_lo)


def _abs_low(low: np.ndarray) -> np.ndarray:
    """Bound on the low parts' value on a cell (``|xi| <= 1``)."""
    return np.abs(low).sum(axis=-1)


def _cell_integral(r: np.ndarray, h, kp1: np.ndarray) -> np.ndarray:
    """``h sum r_k / (k + 1)`` per cell (``h``: one width or one per cell)."""
    if np.ndim(h) == 0:
        return r @ (h / kp1)
    return (r * (np.asarray(h)[:, None] / kp1)).sum(axis=-1)


def taylor_cells(y0, v0, n0, force, G, factors):
    r"""Internal: Taylor coefficients ``(Y, V, N)`` (lowest order first) on many cells at
    once by the recurrences :math:`(k+1) v_{k+1} = h (f\delta_{k0} - N_k)/\alpha`,
    :math:`(k+1) N_{k+1} = h\kappa (v_k - N_k + 2G_k)`, :math:`(k+1) y_{k+1} = h v_k`,
    shaped ``broadcast + (DEGREE + 2,)`` resp. ``(DEGREE + 1,)``, from starts ``y0, v0,
    n0`` and forces ``force`` (arrays that broadcast), incoming waves ``G`` (``[...,
    order]``) and ``factors = (c_v, c_n, c_y)``, the factors ``h/(alpha (k+1))``, ``h
    kappa/(k+1)`` (``DEGREE`` each) and ``h/(k+1)`` (one more), ``[..., order]``: one
    set, or one per cell."""
    c_v, c_n, c_y = factors
    D = DEGREE
    shape = np.broadcast_shapes(
        np.shape(y0), np.shape(v0), np.shape(n0), np.shape(force), np.shape(G)[:-1],
        *(np.shape(c)[:-1] for c in factors),
    )  # fmt: skip
    V, N = np.empty((*shape, D + 1)), np.empty((*shape, D + 1))
    V[..., 0], N[..., 0] = v0, n0
    vk, wk, fk = V[..., 0], N[..., 0], np.asarray(force, dtype=float)
    for k in range(D):
        vk, wk = c_v[..., k] * (fk - wk), c_n[..., k] * ((vk - wk) + 2.0 * G[..., k])
        V[..., k + 1], N[..., k + 1] = vk, wk
        fk = 0.0
    Y = np.empty((*shape, D + 2))
    Y[..., 0] = y0
    Y[..., 1:] = c_y * V
    return Y, V, N


def layer_maps(factors):
    """Internal: what :func:`impactsym.rod.elastic.chain.cell_chain` needs of Taylor cells
    with ``factors`` (one set, or sets along leading axes ``...``): the responses ``(E_y,
    E_v, E_n)`` to unit starts ``(y, v, N)`` (each ``[..., start, order]``), the map
    ``T`` of the start to the end (``[..., end, start]``), and the ends' response to the
    incoming wave (``[..., end, order of G]``) and to a unit force (``[..., end]``)."""
    D = DEGREE
    lanes = 3 + (D + 1) + 1  # unit starts, unit G_k, unit force
    starts = np.zeros((lanes, 3))
    starts[:3] = np.eye(3)
    G = np.zeros((lanes, D + 1))
    G[3 : 3 + D + 1] = np.eye(D + 1)
    force = np.zeros(lanes)
    force[-1] = 1.0
    sets = tuple(np.asarray(c)[..., None, :] for c in factors)  # a set per lane block
    Y, V, N = taylor_cells(*starts.T, force, G, sets)
    ends = np.stack([C.sum(axis=-1) for C in (Y, V, N)], axis=-1)  # [..., lane, end]
    responses = (Y[..., :3, :], V[..., :3, :], N[..., :3, :])
    T = np.swapaxes(ends[..., :3, :], -1, -2)
    return responses, T, np.swapaxes(ends[..., 3 : 3 + D + 1, :], -1, -2), ends[..., -1, :]


def _jumps(C: np.ndarray, C_lo: np.ndarray, initial: np.ndarray, before=None) -> np.ndarray:
    """Bounds on ``|start of cell i - end of cell i - 1|`` (cell 0: ``- initial``, or the
    end of the cell ``before = (C, C_lo)`` of the cells before) of the polynomials ``C``
    (``[rhs, cell, order]``) with low parts ``C_lo`` of every coefficient, from an exact-to-``u^2``
    cascaded sum of all the coefficients involved."""
    if before is not None:  # the same sums, from the cell before on; its own jump dropped
        C = np.concatenate([before[0], C], axis=1)
        C_lo = np.concatenate([before[1], C_lo], axis=1)
        return _jumps(C, C_lo, initial)[:, 1:]
    # low parts of every coefficient (each <= u/2 of its high part): the end of the low
    # parts in float, within gamma_n sum |low| (u^2 of the ends)
    n = C.shape[-1]
    low_end = C_lo[:, :-1].sum(axis=-1)
    terms = np.concatenate(
        [C[:, 1:, :1], C_lo[:, 1:, :1], -C[:, :-1], -low_end[..., None]], axis=-1
    )
    later, bound = tree_sum_with_bound(terms)
    bound += gamma(n) * np.abs(C_lo[:, :-1]).sum(axis=-1) * (1.0 + 1e-9)
    first, first_bound = sum_with_bound([C[:, :1, 0], C_lo[:, :1, 0], -initial[:, None]])
    return np.concatenate([np.abs(first) + first_bound, np.abs(later) + bound], axis=1)


def _incoming_wave_defect(N, n_low, G_hi, G_lo, n, start=0, carry=None):
    """Bounds on ``|G - (G_hi + G_lo)|`` per coefficient, ``G`` the exact alternating sum
    ``G_m = N_(m-1) - G_(m-1)`` of the stored ``N + n_low`` (``n_low``: the low parts of
    every coefficient; ``n`` cells per interval; ``G = 0`` on the first
    interval): the defect of each step, summed with a bound, accumulates. For the
    intervals from ``start`` on (``carry[0]``: the sum on interval ``start - 1``), before
    the margin."""
    dG = np.zeros_like(G_hi[:, start * n :])
    for m in range(max(start, 1), N.shape[1] // n):
        now, before = slice(m * n, (m + 1) * n), slice((m - 1) * n, m * n)
        terms = [N[:, before], n_low[:, before], -G_hi[:, before], -G_lo[:, before]]
        step, bound = sum_with_bound([*terms, -G_hi[:, now], -G_lo[:, now]])
        k = m - start
        previous = carry[0] if k == 0 else dG[:, (k - 1) * n : k * n]
        dG[:, k * n : (k + 1) * n] = previous + np.abs(step) + bound
    return dG


class TaylorView:
    """One time function of a :class:`TaylorTable` (:meth:`TaylorTable.view`), a
    :class:`impactsym.rod.elastic.CertifiedTable`: cells with error bounds ``err_a,
    err_b`` and second-derivative bounds ``d2_a, d2_b``."""

    def __init__(self, table, A, B, err_a, err_b):
        self.lo, self.hi, self.h = table.lo, table.hi, table.h
        self.A, self.B, self.err_a, self.err_b = A, B, err_a, err_b
        n = np.arange(A.shape[1])
        self._orders = n[1:].astype(float)
        # row by row (not a matrix product, whose rounding may depend on the number of
        # rows): a view of the first intervals has the bounds of the whole table's view
        if np.ndim(self.h) == 0:
            d2 = n * (n - 1.0) / self.h**2 * (1.0 + 1e-12)
            self.d2_a, self.d2_b = ((np.abs(C) * d2).sum(axis=-1) for C in (A, B))
        else:  # a width per cell (the slow-manifold table)
            scale = (1.0 + 1e-12) / self.h**2
            d2 = n * (n - 1.0)
            self.d2_a, self.d2_b = ((np.abs(C) * d2).sum(axis=-1) * scale for C in (A, B))

    def cell(self, t: np.ndarray) -> np.ndarray:
        """Index of the cell holding ``t`` (the right one at a node)."""
        return np.clip(np.searchsorted(self.lo, t, side="right") - 1, 0, self.lo.size - 1)

    def evaluate(self, t: np.ndarray, f: np.ndarray, index: np.ndarray | None = None):
        """``g`` and ``dg/dt`` of the polynomial at ``t`` for ``f``."""
        i = self.cell(t) if index is None else index
        h = self.h if np.ndim(self.h) == 0 else self.h[i]
        x = (t - self.lo[i]) / h
        # sum_k c_k x^k with the powers by a running product, all points and orders at
        # once (not order by order as Horner's rule would): the rounding, at most
        # (2 DEGREE + 2) u sum |c_k| with |x| <= 1, stays within the Horner allowance
        # of the cells' error bounds, (DEGREE + 4) eps = (2 DEGREE + 8) u
        C = self.A[i] + np.asarray(f, dtype=float)[..., None] * self.B[i]
        powers = np.empty_like(C)
        powers[:, 0] = 1.0
        powers[:, 1:] = x[:, None]
        np.cumprod(powers, axis=1, out=powers)
        value = np.einsum("ij,ij->i", C, powers)
        slope = np.einsum("ij,ij->i", C[:, 1:] * self._orders, powers[:, :-1])
        return value, slope / h

    def certified(self, index: np.ndarray, f: np.ndarray, tolerance: float) -> np.ndarray:
        """Whether the proven error of cells ``index`` is at most ``tolerance`` for ``f``."""
        return self.err_a[index] + f * self.err_b[index] <= tolerance

    def second_derivative_bound(self, index: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Bound on ``|d^2/dt^2 (A + f B)|`` over cells ``index``."""
        return self.d2_a[index] + f * self.d2_b[index]


@lru_cache(maxsize=64)
def taylor_table(alpha: float, *, kappa: float, n_intervals: int) -> TaylorTable:
    """Internal: the cached :class:`TaylorTable` of ``(alpha, kappa)`` over ``n_intervals``."""
    return TaylorTable(alpha, kappa, n_intervals)
