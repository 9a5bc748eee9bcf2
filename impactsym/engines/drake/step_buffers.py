r"""The per-contact constants and preallocated buffers of the lean step loops of
:mod:`impactsym.engines.drake.stepping` (:func:`~impactsym.engines.drake.stepping.contact_ends`,
:func:`~impactsym.engines.drake.stepping.end_state` and the runs built on them): the
update's constants once per contact, 0-d where a block holds them alike (one stream
less to read), the impulse floor as a bound on ``u* - u'`` where that is exact (one
multiplication per update less), and buffers allocated once a call (a new array of a
block's size cost as much as the operation). The floating-point operations of the
update are :func:`~impactsym.engines.drake.update.hunt_crossley_velocity`'s; nothing
here changes a number. All quantities are SI. Internal to
:mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

import numpy as np

from impactsym.engines.drake.settling import IMPULSE_FLOOR

__all__ = [
    "buffer_views",
    "constant_rows",
    "impulse_bound",
    "may_turn",
    "new_buffers",
    "uniform",
    "update_constants",
]


def update_constants(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: np.ndarray, n: int
) -> tuple[tuple[np.ndarray, ...], bool]:
    """``(consts, scaled)``: the per-contact constants of the update of ``n`` contacts
    (that of the step loops), 0-d where their inputs are (``m``, ``g``, ``v``, ``h`` of
    a call, mostly: :func:`uniform`; the same operations, reading one stream less,
    twice as fast), the impulse floor of :func:`impulse_bound` among them and whether
    the impulses are ``m (u* - u')`` (``scaled``) or ``u* - u'``."""
    hk = h * k
    floor, scaled = impulse_bound(m, v)
    consts = (
        h * g,  # u* = u + h g
        m,
        hk,  # c = m u* - h k x
        m + h * h * k,  # b = m + h^2 k + (h k d) x
        hk * d,
        4.0 * (h * h * k * d),  # disc = b^2 + (4 a) c
        -h,  # limit = max(-x/h, -1/d), -x/h = x/(-h); x + h u' = x - (-h) u'
        _full(np.where(d > 0, -1.0 / d, -np.inf), n),
        floor,
        np.zeros(n),  # (for np.maximum, as an array: _full)
    )
    return consts, scaled


def may_turn(consts: tuple[np.ndarray, ...], scaled: bool) -> bool:
    """Whether a contact may turn back inwards (``u < 0 < u'``) at a state whose update
    carries an impulse above the floor: not where ``h g <= 0``, the floor ``>= 0`` and
    ``m > 0`` for all, as then ``u' < u* <= u`` there (rounding is monotone); the
    turning test decides nothing then."""
    hg, m, floor = consts[0], consts[1], consts[8]
    return not (np.all(hg <= 0.0) and np.all(floor >= 0.0) and np.all(m > 0.0))


def impulse_bound(m: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, bool]:
    """``(floor, scaled)``: the impulse floor ``1e-12 m v`` (``scaled``) or, where exact
    for every contact, the largest ``T`` whose product ``m T`` (rounded) is at most it:
    then ``u* - u' <= T`` exactly where the impulse ``m (u* - u')`` is at most the floor
    (for ``m > 0`` rounding is monotone in ``u* - u'``; ``nan`` is neither), and the
    largest impulse is ``m`` times the largest ``u* - u'``, the same number; one
    multiplication per step less."""
    floor = IMPULSE_FLOOR * m * v
    t = floor / m
    for _ in range(3):  # to the last float whose product stays at the floor (an ulp off)
        t = np.where(m * t > floor, np.nextafter(t, -np.inf), t)
        up = np.nextafter(t, np.inf)
        t = np.where(m * up <= floor, up, t)
    exact = (m > 0.0) & (m < np.inf) & (m * t <= floor) & (m * np.nextafter(t, np.inf) > floor)
    return (t, False) if np.all(exact) else (floor, True)


def _full(a, n):
    """``a`` as an array of ``n`` (np.maximum with a 0-d array is 3x slower)."""
    return a if a.ndim else np.full(n, a)


def uniform(a: np.ndarray) -> np.ndarray:
    """``a``, or its one value as a 0-d array where every element has the same bits."""
    if a.ndim == 0 or a.size == 0:
        return a
    bits = a.view(np.uint64)
    return a[:1].reshape(()) if (bits == bits[0]).all() else a


def constant_rows(
    consts: tuple[np.ndarray, ...], rows: np.ndarray | slice
) -> tuple[np.ndarray, ...]:
    """The constants of the contacts ``rows`` (an index array or a slice); the zeros
    their first ones."""
    take = isinstance(rows, np.ndarray)
    zero = consts[-1][: rows.size] if take else consts[-1][rows]
    rest = (a if a.ndim == 0 else a.take(rows) if take else a[rows] for a in consts[:-1])
    return (*rest, zero)


def new_buffers(n: int) -> tuple:
    """``(work, spare, masks, states)``: the buffers of the step loops' update (``u*``,
    three temporaries, two masks), one for the next velocity, three masks and two states, of
    ``n`` contacts, allocated once a call (a new array of a block's size each operation
    cost as much as the operation, its new pages too)."""
    work = (*(np.empty(n) for _ in range(4)), np.empty(n, bool), np.empty(n, bool))
    masks = tuple(np.empty(n, bool) for _ in range(3))
    return work, np.empty(n), masks, (np.empty(n), np.empty(n))


def buffer_views(buffers: tuple, n: int) -> tuple:
    """The buffers of :func:`new_buffers`, their first ``n`` elements."""
    work, spare, masks, states = buffers
    work, masks, states = (tuple(a[:n] for a in group) for group in (work, masks, states))
    return work, spare[:n], masks, states
