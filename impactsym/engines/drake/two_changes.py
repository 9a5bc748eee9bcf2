r"""The phase-mean restitution of a discrete contact whose end state changes twice over
the phase interval, at given estimates of the two changes: the equations of the designs
whose contact lasts close to a whole number of steps.

At a step ``h`` the contact of touch phase :math:`\varphi` ends at the state
:math:`N(\varphi)` (:mod:`impactsym.engines.drake.stepping`). Where the contact from
touch lasts close to a whole number of steps, and a little longer from phase 0 than
from phase 1, the end state changes next to both ends of the phase interval:
:math:`N = B + 2` on :math:`[0, a)`, :math:`B + 1` on :math:`[a, b)`, :math:`B` on
:math:`[b, 1)` (under gravity about 2 % of the benchmark's designs, by largest overlap
and by contact time alike, with :math:`a` within 0.02 of 0 and :math:`b` within 0.02 of
1; the one-change equations of :mod:`~impactsym.engines.drake.jump_means` do not hold
them). The mean contact time in steps is then :math:`\int_0^1 (N + \varphi)\,
d\varphi = B + 1/2 + a + b`: smooth in the design while both changes lie inside (no
plateau).
The mean restitution is then the three pieces' integrals,

.. math:: E = \int_0^a e_{B+2} + \int_a^b e_{B+1} + \int_b^1 e_B ,

with :math:`e_j(\varphi) = -u_j(\varphi)/v` the separation speed at state ``j``
(:func:`~impactsym.engines.drake.stepping.end_state`: smooth in the phase and the
parameters while the states before it carry an impulse, and then the numbers of the
full contact). Each change is a zero of an end margin
(:func:`~impactsym.engines.drake.stepping.margin_at`, smooth): at :math:`a` state
``B + 1`` starts ending, at :math:`b` state ``B``. :func:`two_change_means` evaluates
the pieces at estimates :math:`\hat a, \hat b`, takes Newton's step of each margin
(its slope by a difference over :data:`_DPHASE`, as
:mod:`~impactsym.engines.drake.jump_means` does) and adds each change's share of its
offset, :math:`(e_{B+2} - e_{B+1})(\hat a)\,(\bar a - \hat a) + (e_{B+1} -
e_B)(\hat b)\,(\bar b - \hat b)` (:math:`\bar a, \bar b` the new estimates clipped to
the phase interval), which makes :math:`E` the mean to second order in the offsets:
a caller that moves the estimates to Newton's after each evaluation has the exact mean
once they hold still. Over the 2055 such designs of the benchmark's targets the means at
settled estimates agree with the exact phase means of
:func:`~impactsym.engines.drake.phases.phase_summary` to ``3.4e-14`` (median
``1.9e-14``, that summary's own quadrature; against SciPy's ``quad`` over the pieces
between changes bisected on the full contact: ``1e-15``, in the tests); over the 3100
contacts with two changes among 1.6*10^5 random ones of 10-70 steps (``g`` 9.81 and
30, steps ``1e-3`` and ``1e-4``, damping numbers up to 2) to ``4.3e-14``, and their
mean contact times to ``6e-12`` steps.

The integrals are one Gauss–Legendre panel a piece, :data:`NODES` nodes, two more on
the longest (the rule of :mod:`~impactsym.engines.drake.jump_means`' change tables:
``(L/15)^{2n}`` for ``n`` nodes on a length ``L`` on contacts of 10 steps or more, and
the short pieces here are a few hundredths of a phase). An evaluation runs
``3 NODES + 2`` node states and four at the changes. All quantities are SI. Internal
to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from impactsym.engines.drake.jump_means import last_overlap
from impactsym.engines.drake.phases import GRID_PHASES
from impactsym.engines.drake.stepping import contact_ends, end_state, end_steps, margin_at
from impactsym.engines.drake.update import hunt_crossley_velocity
from impactsym.engines.phase_pieces import gauss_legendre

__all__ = [
    "LOCATE",
    "NODES",
    "SETTLED",
    "TwoChanges",
    "change_estimate",
    "two_change_means",
    "two_change_rows",
    "two_change_starts",
]

#: Gauss–Legendre nodes of each piece but the longest (which has two more).
NODES = 5
#: Newton's steps that locate the changes at a start (:func:`two_change_starts`).
LOCATE = 2
#: Phases a change's estimate may move in a design's last evaluation (the restitution
#: is the mean to second order in that move: about ``0.1`` per phase squared).
SETTLED = 1e-6
_DPHASE = 2.0**-20  # the difference in the phase for a margin's slope


class TwoChanges(NamedTuple):
    """:func:`two_change_means`: the mean restitution (to second order in the changes'
    offsets) and Newton's estimates of the two changes (phases, not clipped)."""

    restitution: np.ndarray
    first: np.ndarray
    second: np.ndarray


def _pieces(a, b, nodes):
    """The node phases, weights and states above ``B`` (each ``n x (3 nodes + 2)``, in
    phase order) of the pieces ``[0, a]`` (state ``B + 2``), ``[a, b]`` (``B + 1``) and
    ``[b, 1]`` (``B``): one Gauss–Legendre panel each, ``nodes + 2`` nodes on the
    longest, ``nodes`` on the others."""
    starts = np.stack([np.zeros_like(a), a, b], axis=1)
    widths = np.stack([a, b - a, 1.0 - b], axis=1)
    rules = [gauss_legendre(c) for c in (nodes, nodes + 2)]
    # the three layouts (which piece is the longest): unit nodes, weights, pieces
    layouts = [
        [np.concatenate(parts) for parts in zip(*(
            (0.5 * (rules[p == longest][0] + 1.0), 0.5 * rules[p == longest][1],
             np.full(nodes + 2 * (p == longest), p)) for p in range(3)
        ), strict=True)]
        for longest in range(3)
    ]  # fmt: skip
    unit, weight, piece = (
        np.stack(a)[np.argmax(widths, axis=1)] for a in zip(*layouts, strict=True)
    )
    start, width = (np.take_along_axis(a, piece, axis=1) for a in (starts, widths))
    return start + width * unit, width * weight, 2 - piece


def _side(k, d, m, g, v, h, phase, state):
    """The restitution of ``state`` and of the state after it at ``phase``, and Newton's
    estimate of where ``state``'s end margin is zero (from ``phase`` and the phase
    :data:`_DPHASE` towards the inside of the interval)."""
    toward = np.where(phase >= _DPHASE, -_DPHASE, _DPHASE)
    both = np.concatenate([phase, phase + toward])
    steps = np.concatenate([state, state])
    x, u, _, flat = end_state(
        *(np.tile(a, 2) for a in (k, d, m, g, v)), h, both, steps, checked=False
    )
    margin, _ = margin_at(x, u, *flat)
    n = phase.size
    mu, mu_next = margin[:n], margin[n:]
    with np.errstate(all="ignore"):  # (a flat margin: no estimate, nan)
        estimate = phase - mu * toward / (mu_next - mu)
    new, _ = hunt_crossley_velocity(x[:n], u[:n], *(a[:n] for a in flat[:4]), h)
    return -u[:n] / v, -new / v, estimate


def _at_changes(k, d, m, g, v, h, base, a, b):
    """:func:`_side` of state ``B + 1`` at the phases ``a`` and of state ``B`` at ``b``
    (where each starts ending) in one run: each of its outputs as ``(at a, at b)``."""
    n = a.size
    out = _side(*(np.tile(x, 2) for x in (k, d, m, g, v)), h, np.concatenate([a, b]),
                np.concatenate([base + 1, base]))  # fmt: skip
    return [(o[:n], o[n:]) for o in out]


def change_estimate(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    phase: np.ndarray, state: np.ndarray,
) -> np.ndarray:  # fmt: skip
    """Newton's estimate, from ``phase``, of where the end margin of ``state`` (0 the
    first detecting state) is zero: where that state starts or stops ending. Flat
    arrays of one length (``state`` integers)."""
    return _side(k, d, m, g, v, h, phase, state)[2]


def two_change_means(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    base: np.ndarray, first: np.ndarray, second: np.ndarray, *, nodes: int = NODES,
) -> TwoChanges:  # fmt: skip
    """The phase-mean restitution of the contacts ``(k, d, m, g, v)`` at step ``h`` if
    their end state is ``base + 2`` before the phase ``first``, ``base + 1`` up to
    ``second`` and ``base`` after (module docstring), from those estimates (clipped to
    ``0 <= first <= second <= 1``), and Newton's new estimates of both changes. Flat
    arrays of one length (``base`` integers)."""
    a = np.clip(first, 0.0, 1.0)
    b = np.clip(second, a, 1.0)
    n = k.size
    phases, weights, above = _pieces(a, b, nodes)
    width = phases.shape[1]
    rows = np.repeat(np.arange(n), width)
    steps = (base[:, None] + above).ravel()
    _, u, _, flat = end_state(
        *(q[rows] for q in (k, d, m, g, v)), h, phases.ravel(), steps, checked=False
    )
    e = (-u / flat[4]).reshape(n, width)
    # (an empty piece's nodes weigh nothing: their states may not be finite)
    mean = np.einsum("ij,ij->i", weights, np.where(weights > 0.0, e, 0.0))
    # the changes: state B + 1 starts ending at a, state B at b
    (e_a, e_b), (e_a_next, e_b_next), (new_a, new_b) = _at_changes(k, d, m, g, v, h, base, a, b)
    moved_a = np.clip(new_a, 0.0, 1.0) - a
    moved_b = np.clip(new_b, 0.0, 1.0) - b
    mean = mean + (e_a_next - e_a) * moved_a + (e_b_next - e_b) * moved_b
    return TwoChanges(mean, new_a, new_b)


def two_change_starts(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    *, newton: int = LOCATE,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """``(two, base, first, second)``: where the contacts end two states later at phase 0
    than at the last grid phase of :func:`~impactsym.engines.drake.phases.phase_summary`
    (neither sticking), the state ``B`` there, and estimates of the two changes:
    ``newton`` of Newton's steps on the end margins of states ``B + 1`` from phase 0 and
    ``B`` from the last grid phase (``nan`` elsewhere). Flat arrays of one length."""
    n = k.size
    rows = np.tile(np.arange(n), 2)
    phases = np.repeat([GRID_PHASES[0], GRID_PHASES[-1]], n)
    r = contact_ends(*(a[rows] for a in (k, d, m, g, v)), h, phases, stuck_peaks=False)
    ends = end_steps(r.contact_time, r.sticks, h, phases).reshape(2, n)
    two = (ends[1] >= 0) & (ends[0] == ends[1] + 2)
    base = np.where(two, ends[1], 0).astype(np.int64)
    first = np.where(two, GRID_PHASES[0], np.nan)
    second = np.where(two, GRID_PHASES[-1], np.nan)
    i = np.flatnonzero(two)
    for _ in range(newton):
        *_, estimates = _at_changes(*(a[i] for a in (k, d, m, g, v)), h, base[i], first[i],
                                    second[i])  # fmt: skip
        first[i], second[i] = (np.clip(x, 0.0, 1.0) for x in estimates)
    return two, base, first, second


def two_change_rows(
    m: np.ndarray, v: np.ndarray, g: np.ndarray, h: float, base: np.ndarray,
    first: np.ndarray, second: np.ndarray, unit: np.ndarray, *, timed: bool = False,
    nodes: int | None = None,
) -> Callable[..., tuple[np.ndarray, ...]]:  # fmt: skip
    r"""``mean(s, w, rows)`` for :func:`~impactsym.engines.drake.mean_steps.broyden_steps`
    on the designs by largest overlap: ``(E, Q, settled)`` of the designs ``(s, w)``
    (:mod:`~impactsym.engines.drake.step_table`'s damping number and step) of the rows
    ``rows`` (of ``m``, ``v``, ``g``, ``base``, the estimates ``first``, ``second`` and
    the size's ``unit``): :func:`two_change_means` at the estimates, which then move to
    Newton's (in place); ``Q`` the overlap of
    :func:`~impactsym.engines.drake.jump_means.last_overlap` over ``unit``, or
    (``timed``) the mean contact time in steps, :math:`\int_0^1 (N + \varphi)\,
    d\varphi = B + 1/2 + a + b` at Newton's estimates (clipped to the phase interval:
    linear in them, so to second order too); ``settled``
    where neither estimate moved more than :data:`SETTLED` (then ``E`` is the mean to
    second order in that move). With ``nodes`` (a cheaper rule, for differences) the
    estimates stay, and ``mean`` gives ``(E, Q)``."""

    def mean(s, w, rows):
        mr, gr, vr = m[rows], g[rows], v[rows]
        k, d = mr * (w / h) ** 2, s / vr
        a, b = first[rows], second[rows]
        if nodes is None:  # the estimates moved to the design first (Newton's step)
            *_, (a_new, b_new) = _at_changes(k, d, mr, gr, vr, h, base[rows], a, b)
            a, b = np.where(np.isfinite(a_new), a_new, a), np.where(np.isfinite(b_new), b_new, b)
        r = two_change_means(k, d, mr, gr, vr, h, base[rows], a, b,
                             nodes=NODES if nodes is None else nodes)  # fmt: skip
        if timed:
            a_new = np.clip(r.first, 0.0, 1.0)
            size = base[rows] + 0.5 + a_new + np.clip(r.second, a_new, 1.0)
        else:
            size = last_overlap(k, d, mr, gr, vr, h) / unit[rows]
        if nodes is not None:
            return r.restitution, size
        new = np.stack([r.first, r.second])
        old = np.stack([a, b])
        settled = (np.abs(new - old) <= SETTLED).all(axis=0)
        moved = np.isfinite(new)
        first[rows], second[rows] = np.where(moved, new, old)
        return r.restitution, size, settled

    return mean
