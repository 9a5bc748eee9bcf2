r"""Many restitution designs of one contact: the phase mean tabulated once, then inverted.

A restitution-only discrete design (:mod:`~impactsym.engines.mujoco.discrete_design`)
fixes the timeconst, so at a given timestep, ``solimp`` and integrator the phase-mean
restitution of a target depends on the dampratio and on the contact (speed, gravity,
weight ratio) alone. Targets that share a contact share one function ``E(dampratio)``:
it is evaluated once on a geometric grid of ``_TABLE`` dampratios (the design's own scan,
finer; the part within ``_NEAR`` times its bottom, the stability limit, only for targets
not crossed above it: the maps there ring long and take the general summary), each
target's largest-dampratio crossing is read off the table (the suffix maximum of ``E``
makes it one ``searchsorted``), and again off the table between the lowest and the
highest bracket in use refined ``_REFINE`` times (where the targets are many: at most a
quarter of them in evaluations), which is kept where it brackets the crossing inside the
same coarse interval (a bump of ``E`` inside one coarse interval is then resolved: the
largest crossing is found, not one the coarse bracket happened to hold). The crossing is
estimated by inverse
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
_REFINE = 16  # the table between the brackets in use is refined up to this factor
_NEAR = 1.1  # the table's part below this multiple of its bottom is evaluated on demand


def table_crossings(
    gap: Callable[[np.ndarray, np.ndarray], np.ndarray],
    contact: np.ndarray,
    target: np.ndarray,
    low: np.ndarray,
    top: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dampratios of the targets whose contact has a table, the elements left, and a
    mask of those whose design was checked to ``_ACCEPT`` by an exact evaluation.

    ``gap(dr, i, final=False)`` is target minus phase mean of elements ``i`` at
    dampratios ``dr`` (sticking counts as restitution 0; ``final=True`` marks the
    evaluations at which a design may be accepted, so the caller may keep more there);
    ``contact`` labels the elements that share one
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
        e = target[members]
        x = np.log(grid)
        # the phase mean on the table, through the gap of one member (target known);
        # first above _NEAR times its bottom (the stability limit): the maps just above
        # the limit ring long and take the general summary, and they matter only to
        # targets not crossed above them (the largest crossing is sought)
        m = int(np.searchsorted(x, x[0] + np.log(_NEAR)))
        E = np.full(_TABLE, np.nan)
        E[m:] = target[i0] - gap(grid[m:], np.full(_TABLE - m, i0))
        i = _crossing(E[m:], e) + m
        if np.any(i <= m):  # some target is crossed near the bottom, or not at all
            E[:m] = target[i0] - gap(grid[:m], np.full(m, i0))
            i = _crossing(E, e)
        fine = _refine(gap, grid, x, E, i, i0, target[i0], members.size)
        if fine is not None:  # the crossing on the finer table, where it is the same one
            xf, Ef, a, r = fine
            jf = _crossing(Ef, e)
            same = (i >= a) & (jf >= (i - a) * r) & (jf < (i - a + 1) * r)
            dr[members], checked[members] = _invert(gap, xf, Ef, np.where(same, jf, -1), members, e)
            members, e, i = members[~same], e[~same], i[~same]
        dr[members], checked[members] = _invert(gap, x, E, i, members, e)
    return dr, np.flatnonzero(np.isnan(dr)), checked


def _crossing(E, e):
    """Largest index ``i`` with ``E[i] > e`` (``-1``: none; the suffix maximum of ``E``
    is non-increasing, so one ``searchsorted``)."""
    suffix = np.maximum.accumulate(E[::-1])[::-1]
    return np.searchsorted(-suffix, -e, side="left") - 1


def _refine(gap, grid, x, E, i, i0, e0, members):
    """The table between the lowest and the highest bracket in use, each of its intervals
    split in ``r`` (up to ``_REFINE``, ``members / 4`` evaluations at most): ``(x, E, a,
    r)`` with ``a`` the coarse index of its first point, or ``None`` (not worth it)."""
    used = i[(i >= 0) & (i < x.size - 1)]
    if used.size == 0:
        return None
    a, b = int(used.min()), int(used.max()) + 1
    r = int(min(_REFINE, members // (4 * (b - a)) + 1))
    if r < 2:
        return None
    frac = np.arange(1, r) / r
    inner = x[a:b, None] + (x[a + 1 : b + 1] - x[a:b])[:, None] * frac[None, :]
    E_in = e0 - gap(np.exp(inner.ravel()), np.full(inner.size, i0)).reshape(inner.shape)
    xf = np.concatenate([np.concatenate([x[a:b, None], inner], axis=1).ravel(), x[b : b + 1]])
    Ef = np.concatenate([np.concatenate([E[a:b, None], E_in], axis=1).ravel(), E[b : b + 1]])
    return xf, Ef, a, r


def _invert(gap, x, E, i, members, e):
    """The crossings of the targets ``e`` of one contact (``nan``: left to the scan) and
    the mask of those accepted at the interpolated guess; ``i`` is each target's
    bracket on the table ``(x = log dampratio, E)`` (:func:`_crossing`)."""
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
    f = gap(np.exp(guess), who, True)  # target minus mean: < 0 too bouncy, >= 0 enough
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
