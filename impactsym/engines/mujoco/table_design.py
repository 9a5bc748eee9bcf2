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

Where the phase summary is costly (a varying impedance: the general summary, about 60
model runs), the caller passes it, and the refined table holds the whole summary (its
bounds included). A target whose stencil on it is smooth -- the fourth differences of
every field on both five-point stencils around its interval below ``_SMOOTH`` -- is
then **read off**: its dampratio is the root of the table's cubic, its summary the
cubic of each field (:func:`_interpolated`), and no evaluation is spent on it; where
the stencil is not smooth, its interval is split in ``_SPLIT`` and tried again
(:func:`_split_intervals`), and only then evaluated as above. A smooth stretch
interpolates to ``3/128`` of its fourth difference; one kink of a field inside the
stencil (where an end step appears, where a bound changes piece) makes one of the two
fourth differences at least 2.6 times the error. The summary's own quadrature error
(about ``1e-9`` for a varying impedance: Gauss-Legendre across the kinks where a state
crosses the impedance's mid and width) ripples along the table at about twice its
spacing, which the fourth differences partly alias: measured errors reach 0.9 of them,
hence ``_SMOOTH = 1e-9``, and a design read off hits its target to about ``1e-9``, as
one evaluated does. The table then costs most of the work: with ``10^5`` targets about
``10^4`` summaries instead of ``10^5``.

This pays where a contact has at least ``_MIN_GROUP`` targets (a table costs
``_TABLE`` evaluations, a target of the scan about 40). `docs/physics.md#touch-phase`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from impactsym.numeric.poly import cubic_lagrange_weights
from impactsym.numeric.roots import bracketed_illinois

__all__ = ["table_crossings"]

_TABLE = 1024  # dampratios per table
_MIN_GROUP = 128  # targets per contact from which a table pays
_ACCEPT = 1e-9  # |phase mean - target| accepted from the interpolated crossing
_RTOL = 1e-11  # the Illinois refinement's relative width in the dampratio (e to ~1e-11)
_REFINE = 32  # the table between the brackets in use is refined up to this factor
_NEAR = 1.1  # the table's part below this multiple of its bottom is evaluated on demand
_SMOOTH = 1e-9  # largest fourth difference of a stretch of the table read off directly
_NEWTON = 8  # Newton steps for the root of the table's cubic
_SPLIT = 4  # intervals of the refined table not smooth enough are split in this many


def table_crossings(
    gap: Callable[[np.ndarray, np.ndarray], np.ndarray],
    contact: np.ndarray,
    target: np.ndarray,
    low: np.ndarray,
    top: float,
    summary: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Dampratios of the targets whose contact has a table, the elements left, a mask of
    those whose design was checked to ``_ACCEPT`` by an exact evaluation or read off a
    smooth table (:func:`_interpolated`), and the phase summaries ``(7, n)`` of the
    latter (``nan`` columns elsewhere).

    ``gap(dr, i, final=False)`` is target minus phase mean of elements ``i`` at
    dampratios ``dr`` (sticking counts as restitution 0; ``final=True`` marks the
    evaluations at which a design may be accepted, so the caller may keep more there);
    ``contact`` labels the elements that share one
    ``E(dampratio)`` (integers), ``target`` the restitutions, ``low`` the bottom of each
    element's scan (above the stability limit) and ``top`` the top of the scan.
    ``summary(dr, i)``, if given, is the exact phase summary of elements ``i`` at ``dr``
    with its bounds, ``(7, size)`` (the fields of
    :class:`~impactsym.engines.mujoco.discrete.PhaseSummary`; sticking at some phase: an
    infinite contact time): the table is then built from it, and the targets on a
    smooth stretch of the refined table are designed without another evaluation.
    """
    n = target.size
    dr = np.full(n, np.nan)
    checked = np.zeros(n, bool)
    known = np.full((7, n), np.nan)
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
        table = _Table(gap, summary, i0, target[i0])
        E = np.full(_TABLE, np.nan)
        E[m:] = table.mean(grid[m:])
        i = _crossing(E[m:], e) + m
        if np.any(i <= m):  # some target is crossed near the bottom, or not at all
            E[:m] = table.mean(grid[:m])
            i = _crossing(E, e)
        fine = _refine(table, x, E, i, members.size)
        if fine is not None:  # the crossing on the finer table, where it is the same one
            xf, Ef, Sf, a, r = fine
            jf = _crossing(Ef, e)
            same = (i >= a) & (jf >= (i - a) * r) & (jf < (i - a + 1) * r)
            jf = np.where(same, jf, -1)
            got = np.zeros(e.size, bool)
            if summary is not None:  # a smooth stretch of the table: read off it
                got, d_i, s_i = _interpolated(xf, Ef, Sf, jf, e)
                dr[members[got]], known[:, members[got]] = d_i, s_i
                # the rest: their intervals split, and read off where smooth then
                rest = np.flatnonzero(~got & (jf >= 0))
                more, d_i, s_i = _split_intervals(table, xf, Ef, Sf, jf[rest], e[rest])
                dr[members[rest[more]]], known[:, members[rest[more]]] = d_i, s_i
                got[rest[more]] = True
                checked[members[got]] = True
            part = same & ~got
            dr[members[part]], checked[members[part]] = _invert(
                gap, xf, Ef, jf[part], members[part], e[part]
            )
            members, e, i = members[~same], e[~same], i[~same]
        dr[members], checked[members] = _invert(gap, x, E, i, members, e)
    return dr, np.flatnonzero(np.isnan(dr)), checked, known


class _Table:
    """The phase mean of one element at dampratios (sticking at some phase counts as
    restitution 0), and with ``summary`` the whole summary."""

    def __init__(self, gap, summary, i0, e0):
        self.gap, self.summary, self.i0, self.e0 = gap, summary, i0, e0

    def mean(self, dr: np.ndarray) -> np.ndarray:
        return self.e0 - self.gap(dr, np.full(dr.size, self.i0))

    def both(self, dr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(E, S)``: the mean and the summary ``(7, size)`` (``nan`` without one)."""
        if self.summary is None:
            return self.mean(dr), np.full((7, dr.size), np.nan)
        S = self.summary(dr, np.full(dr.size, self.i0))
        return np.where(np.isinf(S[1]), 0.0, S[0]), S


def _crossing(E, e):
    """Largest index ``i`` with ``E[i] > e`` (``-1``: none; the suffix maximum of ``E``
    is non-increasing, so one ``searchsorted``)."""
    suffix = np.maximum.accumulate(E[::-1])[::-1]
    return np.searchsorted(-suffix, -e, side="left") - 1


def _refine(table, x, E, i, members):
    """The table between the lowest and the highest bracket in use, each of its intervals
    split in ``r`` (up to ``_REFINE``, ``members / 4`` evaluations at most): ``(x, E, S,
    a, r)`` with ``a`` the coarse index of its first point and ``S`` the summaries (the
    coarse points in it evaluated again where the table has a summary), or ``None``."""
    used = i[(i >= 0) & (i < x.size - 1)]
    if used.size == 0:
        return None
    a, b = int(used.min()), int(used.max()) + 1
    r = int(min(_REFINE, members // (4 * (b - a)) + 1))
    if r < 2:
        return None
    frac = np.arange(1, r) / r
    inner = x[a:b, None] + (x[a + 1 : b + 1] - x[a:b])[:, None] * frac[None, :]
    xf = np.concatenate([np.concatenate([x[a:b, None], inner], axis=1).ravel(), x[b : b + 1]])
    Ef, Sf = np.full(xf.size, np.nan), np.full((7, xf.size), np.nan)
    on_grid = np.arange(xf.size) % r == 0  # the coarse points a .. b
    Ef[on_grid] = E[a : b + 1]
    todo = ~on_grid if table.summary is None else np.ones(xf.size, bool)
    Ef[todo], Sf[:, todo] = table.both(np.exp(xf[todo]))
    return xf, Ef, Sf, a, r


def _interpolated(x, E, S, j, e):
    """The targets ``e`` read off the refined table ``(x, E, S)`` where it is smooth.

    ``j`` is each target's bracket on it (``-1``: none). A target qualifies where the six
    table points ``j - 2 .. j + 3`` exist, none sticks at any phase, ``E`` falls strictly
    on ``j - 1 .. j + 2`` and the fourth differences of every field on both five-point
    stencils are below ``_SMOOTH`` (absolute in the restitutions, relative in the
    contact times): the design is the root of the cubic through ``j - 1 .. j + 2``
    (Newton, kept inside the bracket) and its summary the cubic of each field there.
    The error of that cubic is ``3/128`` of a smooth fourth difference; a kink or a jump
    of a field inside the stencil (where an end step appears, or a bound changes piece)
    makes one of the two fourth differences of its own size, so the stretch is refused
    and the target evaluated. Returns ``(got, dampratio, summary)``, the last two for
    the targets ``got`` only.
    """
    ok = (j >= 2) & (j + 3 < x.size)
    k = np.flatnonzero(ok)
    st = j[k, None] + np.arange(-2, 4)[None, :]
    F = S[:, st]  # (7, targets, 6)
    times = np.abs(F[[1, 4, 5]]).min(axis=2)
    d4 = np.maximum(
        np.abs(F[..., 0] - 4 * F[..., 1] + 6 * F[..., 2] - 4 * F[..., 3] + F[..., 4]),
        np.abs(F[..., 1] - 4 * F[..., 2] + 6 * F[..., 3] - 4 * F[..., 4] + F[..., 5]),
    )
    with np.errstate(invalid="ignore"):
        smooth = np.all(d4[[0, 2, 3]] <= _SMOOTH, axis=0)
        smooth &= np.all(d4[[1, 4, 5]] <= _SMOOTH * times, axis=0)
    smooth &= np.all(np.isfinite(F[:6]), axis=(0, 2)) & np.all(F[6] == 0.0, axis=1)
    Es = E[st[:, 1:5]]
    smooth &= np.all(np.diff(Es, axis=1) < 0, axis=1)
    k, st, F, Es = k[smooth], st[smooth], F[:, smooth], Es[smooth]
    target = e[k]
    # the cubic through the nodes s = -1, 0, 1, 2 (s = 0, 1: the bracket), root in [0, 1]
    lo, hi = np.zeros(k.size), np.ones(k.size)
    s = (Es[:, 1] - target) / (Es[:, 1] - Es[:, 2])
    for _ in range(_NEWTON):
        w, dw = cubic_lagrange_weights(s)
        val = np.sum(w * Es, axis=1) - target
        slope = np.sum(dw * Es, axis=1)
        lo, hi = np.where(val > 0, s, lo), np.where(val > 0, hi, s)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = s - val / slope
        s = np.where((step >= lo) & (step <= hi), step, 0.5 * (lo + hi))
    w, _ = cubic_lagrange_weights(s)
    fields = np.sum(w[None] * F[:, :, 1:5], axis=2)
    hit = np.abs(fields[0] - target) <= 1e-12  # the root converged
    xs = x[st[:, 2]] + s * (x[st[:, 3]] - x[st[:, 2]])
    got = np.zeros(e.size, bool)
    got[k[hit]] = True
    return got, np.exp(xs[hit]), fields[:, hit]


def _split_intervals(table, x, E, S, j, e):
    """:func:`_interpolated` for targets the refined table could not serve, on their
    intervals ``j`` split in ``_SPLIT`` (the stencils around them evaluated: a kink of
    a field shrinks with the spacing faster than the reach of the stencil across it,
    and the table's quadrature noise, of the size of the summary's own error, with it).
    Returns ``(got, dampratio, summary)`` like :func:`_interpolated`."""
    q = _SPLIT
    if j.size == 0:
        return np.zeros(0, bool), np.zeros(0), np.zeros((7, 0))
    # sub-points k / q of a table spacing from each interval's start, k = -2 .. 2 q - 1
    # (the stencils of its q sub-intervals), keyed on the sub-lattice of the whole table
    keys = np.unique(q * j[:, None] + np.arange(-2, 2 * q)[None, :])
    keys = keys[(keys >= 0) & (keys <= q * (x.size - 1))]
    h = (x[-1] - x[0]) / (x.size - 1)
    xs = x[0] + keys * (h / q)
    on_table = keys % q == 0
    xs[on_table] = x[keys[on_table] // q]
    Es, Ss = np.full(keys.size, np.nan), np.full((7, keys.size), np.nan)
    Es[on_table], Ss[:, on_table] = E[keys[on_table] // q], S[:, keys[on_table] // q]
    Es[~on_table], Ss[:, ~on_table] = table.both(np.exp(xs[~on_table]))
    # dense over the keys (gaps nan: a stencil reaching one is refused)
    lo = keys[0]
    size = keys[-1] - lo + 1
    xd = x[0] + (lo + np.arange(size)) * (h / q)
    Ed, Sd = np.full(size, np.nan), np.full((7, size), np.nan)
    xd[keys - lo], Ed[keys - lo], Sd[:, keys - lo] = xs, Es, Ss
    # each target's sub-interval: the last sub-point of its interval above it
    first = q * j - lo
    above = np.stack([Ed[first + k] > e for k in range(1, q)], axis=1)
    sub = first + above.sum(axis=1)
    return _interpolated(xd, Ed, Sd, sub, e)


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
