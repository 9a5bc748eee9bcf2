r"""Many restitution designs of one contact: the phase mean tabulated once, then inverted.

A restitution-only discrete design (:mod:`~impactsym.engines.mujoco.discrete_design`)
fixes the timeconst, so at a given timestep, ``solimp`` and integrator the phase-mean
restitution of a target depends on the dampratio and on the contact (speed, gravity,
weight ratio) alone. Targets that share a contact share one function ``E(dampratio)``:
it is evaluated once on a geometric grid of ``_TABLE`` dampratios (the design's own scan,
finer), each target's largest-dampratio crossing is read off the table (the suffix
maximum of ``E`` makes it one ``searchsorted``), the crossing is estimated by inverse
cubic interpolation in ``log dampratio`` through the four table points around it, and
one exact evaluation there accepts it when it hits the target to ``_ACCEPT``. The others
are refined by the Illinois method inside their table bracket, where the sign change is
known, to ``_RTOL`` in the dampratio (the phase mean then hits the target to about
``1e-11``; all designs here hit it to ``1e-9`` or better). A target the table does not
bracket (unreachable, or still too bouncy at the top of the scan) is left to the
caller's scan, which refuses it with the reason.

This pays where a contact has at least ``_MIN_GROUP`` targets (a table costs
``_TABLE`` evaluations, a target of the scan about 40). `docs/physics.md#touch-phase`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.numeric.roots import bracketed_illinois

__all__ = ["table_crossings"]

_TABLE = 1024  # dampratios per table
_MIN_GROUP = 128  # targets per contact from which a table pays
_ACCEPT = 1e-9  # |phase mean - target| accepted from the interpolated crossing
_RTOL = 1e-11  # the Illinois refinement's relative width in the dampratio (e to ~1e-11)


def table_crossings(
    gap: Callable[[np.ndarray, np.ndarray], np.ndarray],
    contact: np.ndarray,
    target: np.ndarray,
    low: np.ndarray,
    top: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dampratios of the targets whose contact has a table, the elements left, and a
    mask of those whose design was checked to ``_ACCEPT`` by an exact evaluation.

    ``gap(dr, i)`` is target minus phase mean of elements ``i`` at dampratios ``dr``
    (sticking counts as restitution 0); ``contact`` labels the elements that share one
    ``E(dampratio)`` (integers), ``target`` the restitutions, ``low`` the bottom of each
    element's scan (above the stability limit) and ``top`` the top of the scan.
    """
    n = target.size
    dr = np.full(n, np.nan)
    checked = np.zeros(n, bool)
    labels, first, counts = np.unique(contact, return_index=True, return_counts=True)
    for label, i0, count in zip(labels, first, counts, strict=True):
        if count < _MIN_GROUP:
            continue
        members = np.flatnonzero(contact == label)
        grid = np.exp(np.linspace(np.log(low[i0]), np.log(top), _TABLE))
        # the phase mean on the table, through the gap of one member (target known)
        E = target[i0] - gap(grid, np.full(_TABLE, i0))
        dr[members], checked[members] = _invert(gap, grid, E, members, target[members])
    return dr, np.flatnonzero(np.isnan(dr)), checked


def _invert(gap, grid, E, members, e):
    """The crossings of the targets ``e`` of one contact (``nan``: left to the scan) and
    the mask of those accepted at the interpolated guess."""
    x = np.log(grid)
    # largest index with E > e: the suffix maximum is non-increasing
    suffix = np.maximum.accumulate(E[::-1])[::-1]
    i = np.searchsorted(-suffix, -e, side="left") - 1
    inside = (i >= 0) & (i < x.size - 1)
    out = np.full(e.size, np.nan)
    checked = np.zeros(e.size, bool)
    k = np.flatnonzero(inside)
    if k.size == 0:
        return out, checked
    i, ek, who = i[k], e[k], members[k]
    # inverse cubic through i-1 .. i+2 where E falls strictly there, else inverse linear
    j = np.clip(i - 1, 0, x.size - 4)
    xs = np.stack([x[j + m] for m in range(4)])
    es = np.stack([E[j + m] for m in range(4)])
    falling = np.all(np.diff(es, axis=0) < 0, axis=0)
    cubic = np.zeros(k.size)
    for a in range(4):
        term = xs[a].copy()
        for b in range(4):
            if b != a:
                term = term * (ek - es[b]) / (es[a] - es[b])
        cubic = cubic + term
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = x[i] + (x[i + 1] - x[i]) * (E[i] - ek) / (E[i] - E[i + 1])
    guess = np.where(falling, cubic, linear)
    guess = np.clip(np.where(np.isfinite(guess), guess, x[i]), x[i], x[i + 1])
    f = gap(np.exp(guess), who)  # target minus mean: < 0 too bouncy, >= 0 enough
    done = np.abs(f) <= _ACCEPT
    out[k[done]] = np.exp(guess[done])
    checked[k[done]] = True
    rest = np.flatnonzero(~done)
    if rest.size:
        lo = np.where(f[rest] < 0, guess[rest], x[i[rest]])
        hi = np.where(f[rest] < 0, x[i[rest] + 1], guess[rest])
        f_lo = np.where(f[rest] < 0, f[rest], e[k[rest]] - E[i[rest]])
        f_hi = np.where(f[rest] < 0, e[k[rest]] - E[i[rest] + 1], f[rest])
        idx = who[rest]
        out[k[rest]] = bracketed_illinois(
            lambda d, m: gap(d, idx[m]),
            np.exp(lo),
            np.exp(hi),
            log=True,
            rtol=_RTOL,
            f_lo=f_lo,
            f_hi=f_hi,
        )
    return out, checked
