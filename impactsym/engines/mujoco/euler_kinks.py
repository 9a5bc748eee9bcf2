r"""The touch phases where a state of MuJoCo's Euler contact crosses a kink of the impedance.

A varying ``solimp`` gives the impedance ``d(x) = d_min + (d_max - d_min) y(x / width)``
(:func:`~impactsym.engines.mujoco.model.impedance_at`) with two power branches that meet
at ``x = mid * width`` and a constant ``d`` from ``x = width`` on. ``y`` is continuous
with its slope there, but its second derivative jumps (for ``power = 2``, from
``4`` to ``-4`` at ``mid = 0.5`` and from ``-4`` to ``0`` at the width; for
``power = 1`` the slope itself jumps at the width). The Euler states
``X_k(phi), Y_k(phi)`` (:mod:`~impactsym.engines.mujoco.euler`) are smooth in the touch
phase ``phi`` until the penetration of some state ``k`` crosses such a depth; there the
restitution has a kink of the same order, and Gauss-Legendre across it converges only
like ``h^3`` (5 nodes on a grid interval of ``1/8``: up to ``7.4e-5`` in the mean
restitution, measured against a dense midpoint mean). The phase summary
(:mod:`~impactsym.engines.mujoco.discrete`) therefore cuts its pieces at these phases.

A piece whose end step is ``N`` cuts where ``X_k = level * width / (v_0 dt)`` for a state
``k < N`` (the states that push; state ``N`` only ends the contact, a jump the summary
locates apart) and ``level`` in ``{mid, 1}``. Each piece samples the states at
``_SAMPLES + 1`` equally spaced phases (the recurrence of
:func:`~impactsym.engines.mujoco.euler.euler_contact`, the same arithmetic, stepped on
whole arrays of pieces); a change of side between two samples is narrowed to ``1e-10``
of a phase by :func:`~impactsym.engines.mujoco.phase_secant.secant_bracket` on the
continuous ``X_k(phi)``. A kink misplaced by ``delta`` costs about ``delta^3`` times
the jump of the second derivative, so that is ample. Two crossings of one state
between neighbouring samples (a state whose deepest point over the phase just reaches
the level) are missed.

The same samples show end-step changes hidden between the summary's node samples (a
band of another end step inside one piece: measured 0.0038 and 0.0175 of a phase wide,
with node samples up to 0.034 apart; 1.75e-2 steps off in the mean contact time). Along
a piece of end step ``N`` the margins ``min(X_k, F_k)`` of the states ``1 .. N-1`` stay
positive and that of state ``N`` at most zero (``F`` the constraint's force per step,
as in :func:`~impactsym.engines.mujoco.euler.euler_end_value`), and both are smooth in
the phase. A piece is flagged where the least pushing margin or the end margin's
negative, over the samples, comes near zero between them: the quadratic through the
least sample and its two neighbours dips below ``_NEAR`` of it, or the least sample is
an inner one and below ``_NEAR`` times the samples' spread. The summary sums a flagged
element again on a finer grid. Pieces that stick are not checked (a band that does not
stick inside a sticking piece is seen only where a node falls in it).

Internal. Dimensionless: phases in ``[0, 1]``, ``X`` in ``speed * timestep``.
"""

from __future__ import annotations

import numpy as np

from impactsym.engines.mujoco.euler import (
    euler_constants,
    euler_first_state,
    euler_force,
    euler_state,
)
from impactsym.engines.mujoco.model import Coefficients
from impactsym.engines.mujoco.phase_secant import secant_bracket
from impactsym.engines.phase_pieces import least_vertex

__all__ = ["kink_cuts", "split_pieces"]

_SAMPLES = 4  # sub-intervals per piece sampled for a change of side
_TOLERANCE = 1e-10  # bracket width (phase) at which a kink is placed at its middle
_NEAR = 0.5  # a margin whose fit between samples falls below this share of its least


def kink_cuts(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: np.ndarray,
    gravity: np.ndarray,
    speed: np.ndarray,
    timestep: np.ndarray,
    p0: np.ndarray,
    p1: np.ndarray,
    steps: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kink phases inside the pieces ``[p0, p1]``, and the pieces whose end step may
    change between samples (module docstring).

    All arguments are 1-D per piece (SI), ``solimp`` a checked varying one; ``steps`` is
    the piece's end step (the states ``k < steps`` count; ``< 1``: none, as for a piece
    that sticks). Returns ``(piece, phase, hidden)``: the piece of each cut and its
    phase, sorted by piece, then phase, strictly inside its piece; and per piece whether
    its margins come near zero between its samples.
    """
    consts = euler_constants(coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep)
    width, mid = solimp[2], solimp[3]
    levels = np.array([mid, 1.0])[None, :] * (width / (speed * timestep))[:, None]
    use = np.flatnonzero((steps >= 1) & (p1 > p0))
    q = p0[use, None] + (p1 - p0)[use, None] * np.linspace(0.0, 1.0, _SAMPLES + 1)[None, :]
    x, y = euler_first_state(q, consts[0][use, None])
    live, left, lev = use, steps[use], levels[use, None, :]
    consts = tuple(c[use, None] for c in consts)
    found = []  # (piece, sub-interval, state, level, below at the sub-interval's start)
    # the least margin min(X_k, F_k) of the states 1 .. N-1, and that of the end state N
    push = np.full(x.shape, np.inf)
    push_out, end_out = np.zeros((p0.size, x.shape[1])), np.zeros((p0.size, x.shape[1]))
    for k in range(int(left.max(initial=0)) + 1):
        pushes = left > k
        side = x[:, :, None] > lev  # (pieces, samples, levels)
        change = (side[:, 1:] != side[:, :-1]) & pushes[:, None, None]
        if change.any():
            r, s, j = np.nonzero(change)
            found.append(np.stack((live[r], s, np.full(r.size, k), j, ~side[r, s, j])))
        F = euler_force(x, y, consts, solimp)
        margin = np.minimum(x, F) if k > 0 else np.full(x.shape, np.inf)
        if not pushes.all():  # the end states: out with their margins
            done = ~pushes
            push_out[live[done]], end_out[live[done]] = push[done], margin[done]
            live, left, lev, x, y, F, push, margin = (
                a[pushes] for a in (live, left, lev, x, y, F, push, margin)
            )
            consts = tuple(c[pushes] for c in consts)
        if live.size == 0:
            break
        np.minimum(push, margin, out=push)
        y = y + consts[0] - np.maximum(F, 0.0)
        x = x + y
    hidden = np.zeros(p0.size, bool)
    hidden[use] = _toward_zero(push_out[use]) | _toward_zero(-end_out[use])
    if not found:
        return np.zeros(0, np.int64), np.zeros(0), hidden
    piece, sub, state, lev, rising = np.concatenate(found, axis=1)
    frac = (p1 - p0)[piece] / _SAMPLES
    a, c = p0[piece] + sub * frac, p0[piece] + (sub + 1) * frac
    c = np.where(sub == _SAMPLES - 1, p1[piece], c)
    target = levels[piece, lev]

    def value(i, p, m):
        j = piece[i]
        x, _ = euler_state(
            Coefficients(coeffs.damping[j], coeffs.stiffness[j]), solimp, rho[j], gravity[j],
            speed[j], timestep[j], p, m,
        )  # fmt: skip
        return x - target[i]

    width = np.full(a.size, _TOLERANCE)
    lo, hi, ok = secant_bracket(value, a.copy(), c.copy(), state, rising.astype(bool), width)
    cut = np.where(ok, 0.5 * (lo + hi), 0.5 * (a + c))
    inside = (cut > p0[piece]) & (cut < p1[piece])
    piece, cut = piece[inside], cut[inside]
    order = np.lexsort((cut, piece))
    return piece[order], cut[order], hidden


def _toward_zero(a):
    """Rows of ``a`` (positive samples at the piece's equally spaced phases) whose
    quadratic through a least sample and the two next to it (the first or last three
    where the least is an end) has its vertex between them and below ``_NEAR`` of the
    least sample, or whose least sample is an inner one and below ``_NEAR`` times their
    spread (a sharp dip the quadratic misses: a 4 -> 5 -> 4 band 0.0038 wide between
    samples 0.031 apart): a margin that may reach zero between the samples. A false
    flag costs only the element's sum on a finer grid (about 40 of 63,000 pieces of
    random short contacts are flagged)."""
    low = least_vertex(a, np.linspace(-1.0, 1.0, _SAMPLES + 1))  # nan where outside
    least = a.min(axis=1)
    inner = (a[:, 0] > least) & (a[:, -1] > least)
    with np.errstate(invalid="ignore"):
        return (low < _NEAR * least) | (inner & (least < _NEAR * (a.max(axis=1) - least)))


def split_pieces(
    p0: np.ndarray, p1: np.ndarray, piece: np.ndarray, cut: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pieces ``[p0, p1]`` cut at the phases ``cut`` of pieces ``piece`` (sorted by
    piece, then phase, inside their pieces, as :func:`kink_cuts` gives them).

    Returns ``(p0, p1, parent)``: the new pieces in order, each with its original one.
    """
    counts = np.bincount(piece, minlength=p0.size)
    parent = np.repeat(np.arange(p0.size), counts + 1)
    first = np.cumsum(counts + 1) - (counts + 1)  # each original piece's first new one
    rank = np.arange(piece.size) - (np.cumsum(counts) - counts)[piece]
    at = first[piece] + rank  # the new piece that a cut ends
    new0, new1 = np.empty(parent.size), np.empty(parent.size)
    new0[first], new1[first + counts] = p0, p1
    new1[at], new0[at + 1] = cut, cut
    return new0, new1, parent
