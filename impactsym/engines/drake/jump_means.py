r"""The phase means of a discrete contact whose end state changes once, at a given phase:
the equations of the discrete designs, without searching for the change.

At a step ``h`` the contact of touch phase :math:`\varphi` ends at the state
:math:`N(\varphi)` and lasts :math:`(N(\varphi) + \varphi)\, h`
(:mod:`impactsym.engines.drake.stepping`). The contact from touch lasts about the same
whatever the phase, so :math:`N` falls by one where the phase crosses one point
:math:`\varphi_j`: :math:`N = B + 1` on :math:`[0, \varphi_j)`, :math:`B` on
:math:`[\varphi_j, 1)` (the usual case; ``docs/physics.md``, "Drake point contact").
Then the phase-mean contact time in steps is

.. math:: Q = \int_0^1 (N + \varphi)\, d\varphi = B + \tfrac12 + \varphi_j ,

so a target ``q`` fixes both :math:`B = \lfloor q - 1/2 \rfloor` and where the change
must lie, :math:`\varphi^* = q - 1/2 - B`. The design's two equations become smooth in
the parameters (no plateau where every phase lasts as long, no kink where a change
enters the phase interval):

* **the size**: state :math:`B` stops ending at :math:`\varphi^*`, i.e. its end margin
  :math:`\mu(\varphi^*)` (:func:`~impactsym.engines.drake.stepping.margin_at`, smooth
  in the phase and the parameters, falling through zero at :math:`\varphi_j`) is zero.
  :func:`jump_means` reports it as the size Newton's step in the phase gives,
  :math:`\hat Q = B + 1/2 + \hat\varphi_j`, :math:`\hat\varphi_j = \varphi^* -
  \mu/\mu'` (:math:`\mu'` by a difference over :data:`_DPHASE`), which is the size to
  second order in :math:`\varphi_j - \varphi^*` and exactly ``q`` at the root (where
  :math:`\hat\varphi_j` leaves ``[0, 1)`` the mean rests at ``B + 1/2`` or ``B + 3/2``,
  every phase ending alike; the estimate goes on smoothly, for the designs' steps);
* **the restitution**: :math:`E = \int_0^{\varphi^*} e_{B+1} + \int_{\varphi^*}^1 e_B`
  with :math:`e_j(\varphi) = -u_j(\varphi)/v`, the separation speed at state ``j``
  (:func:`~impactsym.engines.drake.stepping.end_state`: smooth while the states
  before it carry an impulse, and then the numbers of the full contact), plus the
  share of the change's offset, :math:`(e_{B+1} - e_B)(\varphi^*)\,(\bar\varphi_j -
  \varphi^*)` with :math:`\bar\varphi_j` the estimate clipped to ``[0, 1]``, which
  makes it the mean to second order too (and vanishes at the root; on a plateau's edge,
  :math:`\varphi^* = 0`, an estimate below 0 adds nothing: every phase ends at ``B``,
  the mean is ``e_B``'s integral, as the pieces have it. Unclipped it added
  ``1.6e-12`` to a design under gravity there, found by review).

The integrals are 8-point Gauss–Legendre rules on three panels, the longer of the two
pieces halved (no panel longer than half a phase: :math:`10^{-2} (L/2.5)^{2n}`, the
error model of :mod:`impactsym.engines.drake.phases`, gives about ``1e-13`` for
``n = 8``, ``L = 1/2``; measured against 16 nodes per panel: below ``1e-14`` over
designs of 20-40 steps). A run of the states costs ``B`` updates, as a full contact
does; an evaluation is 24 nodes and 3 states at :math:`\varphi^*`, against about 65
contacts and 19 margins of a phase mean that searches for its changes
(:func:`~impactsym.engines.drake.phases.phase_summary`; measured before its one-margin
root search and quarter pieces, about 50 and 10 since).

The designs by largest overlap read it where
:func:`~impactsym.engines.drake.phases.phase_summary` samples it deepest: at its last
grid phase, ``1 - 1e-15`` (:func:`last_overlap`; the body enters a whole step deep
before the first force, and over 12000 random contacts, steps ``1e-3`` and ``1e-4``,
gravity 0 to ``50`` m/s^2, no other sample was deeper).

The structure is an assumption until checked: :func:`jump_holds` runs the full contact
(:func:`~impactsym.engines.drake.stepping.contact_ends`) at the phase grid of
:func:`~impactsym.engines.drake.phases.phase_summary` and at the nodes next to
:math:`\varphi^*`, and confirms the end states ``B + 1`` before it and ``B`` after,
nothing sticking. All quantities are SI. Internal to :mod:`impactsym.engines.drake`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from impactsym.engines.drake.phases import GRID_PHASES
from impactsym.engines.drake.stepping import contact_ends, end_state, end_steps, margin_at
from impactsym.engines.phase_pieces import gauss_legendre

__all__ = ["JumpMeans", "jump_holds", "jump_means", "last_overlap"]

_NODES = 8  # Gauss-Legendre nodes per panel
_DPHASE = 2.0**-20  # the difference in the phase for the margin's slope
_CLEAR = 1e-9  # grid phases this close to the change are not checked (the nodes are)


class JumpMeans(NamedTuple):
    """:func:`jump_means`: the phase-mean restitution and contact time in steps, and the
    restitution without the change's offset (``fixed``: the two pieces' integrals)."""

    restitution: np.ndarray
    size: np.ndarray
    fixed: np.ndarray


def _gauss(nodes):
    """Gauss–Legendre nodes and weights on ``[0, 1]``."""
    x, w = gauss_legendre(nodes)
    return 0.5 * (x + 1.0), 0.5 * w


def _split(q):
    """``(B, phi*)`` of the sizes in steps ``q`` (module docstring)."""
    base = np.floor(q - 0.5)
    return base.astype(np.int64), q - 0.5 - base


def _panels(phi, base):
    """The three panels ``(a, b, step)`` (each ``n x 3``) of the two pieces, the longer
    piece halved."""
    n = phi.size
    long_left = phi > 0.5
    mid_left, mid_right = 0.5 * phi, 0.5 * (1.0 + phi)
    a = np.stack([np.zeros(n), np.where(long_left, mid_left, phi),
                  np.where(long_left, phi, mid_right)], axis=1)  # fmt: skip
    b = np.stack([np.where(long_left, mid_left, phi), np.where(long_left, phi, mid_right),
                  np.ones(n)], axis=1)  # fmt: skip
    step = np.stack([base + 1, np.where(long_left, base + 1, base), base], axis=1)
    return a, b, step


def jump_means(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    q: np.ndarray, *, nodes: int = _NODES,
) -> JumpMeans:  # fmt: skip
    """The phase means of the contacts ``(k, d, m, g, v)`` at step ``h`` if their end
    state changes once, from ``B + 1`` to ``B``, where the size in steps ``q`` puts it
    (module docstring): to second order in the change's offset, exact at the design.
    Flat arrays of one length. ``nodes``: Gauss nodes per panel (fewer: a cheaper rule
    whose error is smooth in the parameters, for differences of the means)."""
    n = k.size
    base, phi = _split(q)
    a, b, step = _panels(phi, base)
    x01, w01 = _gauss(nodes)
    phases_in = a[:, :, None] + (b - a)[:, :, None] * x01
    weights = ((b - a)[:, :, None] * w01).reshape(n, -1)
    toward = np.where(phi < 0.5, _DPHASE, -_DPHASE)  # the slope's difference, inwards
    phases = np.concatenate([phases_in.ravel(), phi, phi + toward, phi])
    steps = np.concatenate([np.repeat(step.ravel(), nodes), base, base, base + 1])
    rows = np.concatenate([np.repeat(np.arange(n), 3 * nodes), np.tile(np.arange(n), 3)])
    x, u, _, flat = end_state(*(a[rows] for a in (k, d, m, g, v)), h, phases, steps)
    e = -u / flat[4]
    inner = n * 3 * nodes
    restitution = np.einsum("ij,ij->i", weights, e[:inner].reshape(n, 3 * nodes))
    at = slice(inner, inner + 2 * n)
    margin, _ = margin_at(x[at], u[at], *(a[at] for a in flat))
    mu, mu_next = margin[:n], margin[n:]
    with np.errstate(all="ignore"):  # (a flat margin: no finite size, the step refuses it)
        offset = -mu * toward / (mu_next - mu)
    e_before, e_after = e[inner + 2 * n :], e[inner : inner + n]
    inside = np.clip(phi + offset, 0.0, 1.0) - phi  # (outside: every phase ends alike)
    return JumpMeans(restitution + (e_before - e_after) * inside, base + 0.5 + phi + offset,
                     restitution)  # fmt: skip


def last_overlap(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float
) -> np.ndarray:
    """The largest overlap of the contact at the last phase of the grid of
    :func:`~impactsym.engines.drake.phases.phase_summary` (``1 - 1e-15``), the very
    number it samples there (``nan`` where it sticks): the phase summary's largest
    overlap where it is the deepest of its samples (module docstring). Flat arrays."""
    r = contact_ends(k, d, m, g, v, h, GRID_PHASES[-1], stuck_peaks=False)
    return np.where(r.sticks, np.nan, r.max_penetration)


def jump_holds(
    k: np.ndarray, d: np.ndarray, m: np.ndarray, g: np.ndarray, v: np.ndarray, h: float,
    q: np.ndarray, *, deepest_last: bool = False,
) -> np.ndarray:  # fmt: skip
    """Where the contacts' end state is ``B + 1`` before the phase the size ``q`` puts the
    change at and ``B`` after it, nothing sticking, at the phase grid of
    :func:`~impactsym.engines.drake.phases.phase_summary` (those within ``1e-9`` of the
    change left out) and at the Gauss nodes next to it: :func:`jump_means` then holds the
    means (module docstring). ``deepest_last``: and no phase run overlaps deeper than the
    last grid phase (:func:`last_overlap`). Flat arrays of one length."""
    n = k.size
    base, phi = _split(q)
    a, b, _ = _panels(phi, base)
    x01, _ = _gauss(_NODES)
    # the nodes next to the change: the last of the panel ending at it, the first after
    last_before = np.where(phi > 0.5, a[:, 1] + (b[:, 1] - a[:, 1]) * x01[-1], b[:, 0] * x01[-1])
    first_after = np.where(phi > 0.5, a[:, 2] + (b[:, 2] - a[:, 2]) * x01[0],
                           a[:, 1] + (b[:, 1] - a[:, 1]) * x01[0])  # fmt: skip
    phases = np.concatenate([np.tile(GRID_PHASES, (n, 1)), last_before[:, None],
                             first_after[:, None]], axis=1)  # fmt: skip
    rows = np.repeat(np.arange(n), phases.shape[1])
    r = contact_ends(*(a[rows] for a in (k, d, m, g, v)), h, phases.ravel())
    ends = end_steps(r.contact_time, r.sticks, h, phases.ravel()).reshape(phases.shape)
    want = np.where(phases < phi[:, None], base[:, None] + 1, base[:, None])
    check = np.abs(phases - phi[:, None]) > _CLEAR
    check[:, -2] = phi > 0.0  # the nodes (none before an empty first piece)
    check[:, -1] = True
    good = (ends == want) | ~check
    held = good.all(axis=1) & ~r.sticks.reshape(phases.shape).any(axis=1)
    if deepest_last:
        depth = r.max_penetration.reshape(phases.shape)
        held &= depth.max(axis=1) <= depth[:, GRID_PHASES.size - 1]
    return held
