r"""Many PyBullet designs of one contact: exact Newton started from a table of the phase means.

Targets that share the contact (speed, mass, gravity; one timestep and one set of engine
settings per call) share one map

.. math::

    F(u, z) = \bigl(\bar e,\ \ln \bar t_c\bigr), \qquad u = \ln k, \quad z = \ln \zeta,
    \quad \zeta = c / (2 \sqrt{k m}),

from the pair's stiffness and damping ratio to the phase-mean restitution and the log of
the phase-mean contact time. :func:`table_designs` tabulates ``F`` once on a grid, in two
passes: a coarse grid over the box around the continuous textbook designs (grown by half
its width towards targets whose nearest table point lies on its edge; under gravity the
designs lie far below the textbook damping), inverted for every target, then a finer grid
over the box those coarse designs span (padded by two coarse cells). Each target is
inverted on the fine table by Newton's method on the tensor-product cubic through the 4 x
4 table points around it (local: a cell whose stencil holds a sticking point gives no
start), started from the table point nearest in ``F``.

The table never decides a design. From its start each design takes quasi-Newton steps on
the **exact** phase means (one evaluation per step, against three for the
finite-difference Newton step of the textbook path), the Jacobian being the table's at the start,
updated by Broyden's rank-one rule after each step. A design is accepted only where an
exact evaluation meets both targets to ``rtol`` (the same test as the textbook path), so a
design from the table hits its targets exactly as well as one from the textbook start. The
phase means kink along curves about one step of contact time apart: where the phase at
which the contact ends one step earlier passes the touch phase 0 (there the first step's
speculative impulse switches on, so the restitution per phase kinks), the second
derivative of the mean restitution jumps and the first of the mean contact time. In the
cells a kink crosses the table's start and Jacobian are off (``1e-4`` in ``ln t`` and a
few per cent), the steps converge linearly, and Broyden's update corrects the Jacobian
step by step; elsewhere a start is good to ``1e-7`` and one step meets the targets.
Targets without a start, and those not accepted after ``_STEPS`` evaluations, come back as
``nan``: the caller designs them from the textbook start as before.

Cost: tables of ``_COARSE^2`` (one per growth of the coarse box) and
``min(max(n / 8, _COARSE^2), _FINE)`` evaluations for ``n`` targets, then 2-3 evaluations
per design where the finite-difference Newton from the textbook start spends about 14;
whatever else ``evaluate`` returns at the accepting evaluation (the caller's phase
summary) comes back with the designs, so that no design is evaluated again. The
interpolant and its inverse run in passes of ``_PASS`` columns (cache-sized; each column
its own numbers), and a coarse table that grows is inverted only at its edge targets,
until the growth is known (:func:`_coarse_designs`).
Measured on 10^5 random targets (restitution 0.2-0.5, 10-40 steps of 1/240 s): 3.05
evaluations per design, the table's 0.13 included; a finer table does not pay (the
interpolation error in the cells a kink crosses only halves with the spacing), nor
one-sided stencils in those cells (3.03).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree

from impactsym.numeric.memory import keep_freed_pages
from impactsym.numeric.poly import cubic_lagrange_weights

__all__ = ["table_designs"]

_COARSE = 24  # points per side of the coarse table
_FINE = 16384  # at most this many points in the fine table
_PAD_U = (1.0, 0.25)  # the coarse box: textbook ln k minus / plus these
_PAD_Z = (1.5, 0.5)  # and textbook ln zeta minus / plus these
_GROW = 4  # coarse tables at most: the box grows by half its width towards targets beyond it
_SPLINE_NEWTON = 12  # Newton steps on the table's cubic
_SETTLED = 1e-9  # a Newton step on the cubic this small (relative) ends its iteration
_STEPS = 8  # exact evaluations per design before it is left to the caller
_MAX_STEP = 0.5  # largest step in u or z
#: columns per pass of the interpolant and its inverse: a pass's temporaries (~1 kB a
#: column) stay in the cache, where 10^5 columns at once spent most of their time on
#: fresh memory; every column's numbers are its own, so the passes change none
#: (measured, inversions per 10^5 designs: 0.25 s in passes of 1024, 0.20 of 2048,
#: 0.17 of 4096 and 8192)
_PASS = 8192


def table_designs(
    evaluate: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]],
    target: np.ndarray,
    start: np.ndarray,
    *,
    rtol: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The designs ``(u, z)`` of one contact (``(2, n)``; ``nan`` columns: no design found
    from the table, left to the caller) and what ``evaluate`` gave besides at each
    design's accepting evaluation (``(extra, n)``; ``nan`` columns likewise).

    ``evaluate(u, z)`` is the exact ``(restitution, ln contact_time)`` phase means at the
    points ``(u, z)`` (flat arrays; ``inf`` contact time where a phase sticks), followed
    by any further arrays of the same points (``extra`` of them: the caller's prediction,
    so that the accepted evaluation need not be repeated), ``target`` the ``(2, n)``
    targets ``(e, ln t)``, ``start`` the ``(2, n)`` textbook designs (which place the
    coarse table). A design is accepted where ``|e_mean - e| < rtol e`` and ``|ln t_mean
    - ln t| < rtol`` at an exact evaluation.

    A map with a known inverse (``e = exp(-zeta)``, ``ln t = -u/2 + z/10``); the second
    design lies beyond the first coarse box, which grows towards it:

    >>> def f(u, z):
    ...     return np.exp(-np.exp(z)), -0.5 * u + 0.1 * z
    >>> target = np.array([[0.4, 0.3], [-3.0, -2.5]])
    >>> x, _ = table_designs(f, target, np.array([[5.5, 5.0], [-0.5, -0.2]]), rtol=1e-12)
    >>> [round(float(zeta), 9) for zeta in np.exp(x[1])]  # zeta = -ln e
    [0.916290732, 1.203972804]
    """
    keep_freed_pages()  # (the passes below reuse the pages their temporaries free)
    n = target.shape[1]
    lo = np.array([start[0].min() - _PAD_U[0], start[1].min() - _PAD_Z[0]])
    hi = np.array([start[0].max() + _PAD_U[1], start[1].max() + _PAD_Z[1]])
    out = np.full((2, n), np.nan)
    for attempt in range(_GROW):  # the coarse table, its box grown where targets lie beyond it
        coarse = _Table(evaluate, lo, hi, (_COARSE, _COARSE))
        first, low, high = _coarse_designs(coarse, target, last=attempt == _GROW - 1)
        if not (low.any() or high.any()):
            break
        width = hi - lo
        lo, hi = lo - np.where(low, width / 2, 0.0), hi + np.where(high, width / 2, 0.0)
    found = np.all(np.isfinite(first), axis=0)
    if not found.any():
        return out, np.full((0, n), np.nan)
    step = (hi - lo) / (_COARSE - 1)
    lo = np.maximum(lo, first[:, found].min(axis=1) - 2 * step)
    hi = np.minimum(hi, first[:, found].max(axis=1) + 2 * step)
    points = int(min(max(n // 8, _COARSE**2), _FINE))
    side = np.sqrt(points * (hi - lo) / (hi - lo)[::-1])  # equal spacing in u and z
    shape = tuple(int(s) for s in np.clip(np.ceil(side), 6, None))
    fine = _Table(evaluate, lo, hi, shape)
    guess = fine.invert(target, fine.nearest(target))
    has = np.flatnonzero(np.all(np.isfinite(guess), axis=0))
    designs, extra = _refine(evaluate, fine, guess[:, has], target[:, has], rtol)
    out[:, has] = designs
    more = np.full((extra.shape[0], n), np.nan)
    more[:, has] = extra
    return out, more


class _Table:
    """``F`` on a regular grid over the box ``[lo, hi]`` (``shape`` points), its local
    bicubic interpolant and the interpolant's inverse."""

    def __init__(self, evaluate, lo, hi, shape):
        self.lo, self.hi, self.shape = lo, hi, np.array(shape)
        self.step = (hi - lo) / (self.shape - 1)
        uu, zz = np.meshgrid(*(np.linspace(a, b, s) for a, b, s in zip(lo, hi, shape, strict=True)),
                             indexing="ij")  # fmt: skip
        E, L, *_ = evaluate(uu.ravel(), zz.ravel())
        self.values = np.stack([E, L]).reshape(2, *shape)
        self.points = np.stack([uu.ravel(), zz.ravel()])
        self.offsets = np.add.outer(np.arange(4) * shape[1], np.arange(4))  # a stencil's
        finite = np.all(np.isfinite(self.values), axis=0)
        windows = np.lib.stride_tricks.sliding_window_view(finite, (4, 4))
        self.finite_stencil = np.all(windows, axis=(2, 3))  # per stencil's first point

    def flat_index(self, base: np.ndarray, *, stencils: bool = False) -> np.ndarray:
        """The flat index of the grid points ``base`` (``(2, n)``) in the table, or with
        ``stencils`` in :attr:`finite_stencil`."""
        return base[0] * (self.shape[1] - (3 if stencils else 0)) + base[1]

    def at(self, x: np.ndarray, *, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The interpolant ``(2, n)`` and its Jacobian ``(2, 2, n)`` at ``x`` (``(2, n)``):
        the tensor-product cubic through the 4 x 4 points around each cell (Lagrange
        nodes ``-1, 0, 1, 2`` in grid units, shifted inwards at the edges); ``nan``
        outside the grid or where the stencil holds a non-finite value. Without
        ``jacobian`` the Jacobian is ``None`` (not computed). In passes of
        :data:`_PASS` columns."""
        n = x.shape[1]
        if n <= _PASS:
            return self._at(x, jacobian)
        val, jac = np.empty((2, n)), np.empty((2, 2, n)) if jacobian else None
        for i in range(0, n, _PASS):
            part, slope = self._at(x[:, i : i + _PASS], jacobian)
            val[:, i : i + _PASS] = part
            if jacobian:
                jac[..., i : i + _PASS] = slope
        return val, jac

    def _at(self, x, jacobian):
        """:meth:`at` of one pass."""
        s = (x - self.lo[:, None]) / self.step[:, None]
        top = self.shape[:, None] - 1
        with np.errstate(invalid="ignore"):
            inside = np.all((s >= 0) & (s <= top), axis=0)
        base = np.clip(np.floor(np.where(inside, s, 0.0)) - 1, 0, top - 3).astype(int)
        frac = s - base - 1  # in [-1, 2]: the cell's stencil, shifted at the edges
        wu, du = cubic_lagrange_weights(frac[0])
        wz, dz = cubic_lagrange_weights(frac[1])
        # the 4 x 4 stencils, (2, 4, 4, n): the weights contracted in z, then in u
        index = (self.offsets[:, :, None] + self.flat_index(base)).ravel()
        block = self.values.reshape(2, -1).take(index, axis=1).reshape(2, 4, 4, -1)
        wz, dz = wz.T, dz.T
        wu, du = wu.T, du.T
        # a stencil holding a sticking point (contact time inf) gives inf * 0 and inf - inf:
        # such stencils are masked as bad just below
        with np.errstate(invalid="ignore"):
            along = _sum4(block[:, :, j] * wz[j] for j in range(4))  # (2, 4, n)
            val = _sum4(along[:, i] * wu[i] for i in range(4))
            if jacobian:
                slope = _sum4(block[:, :, j] * dz[j] for j in range(4))
                jac = np.stack([
                    _sum4(along[:, i] * du[i] for i in range(4)) / self.step[0],
                    _sum4(slope[:, i] * wu[i] for i in range(4)) / self.step[1],
                ], axis=1)  # fmt: skip
        bad = ~inside | ~self.finite_stencil.ravel()[self.flat_index(base, stencils=True)]
        return np.where(bad, np.nan, val), np.where(bad, np.nan, jac) if jacobian else None

    def nearest(self, target: np.ndarray) -> np.ndarray:
        """The flat index of the table point nearest to each target ``(2, n)`` in ``F``
        (scaled by the table's spread; ``0`` where the table holds no finite point)."""
        flat = self.values.reshape(2, -1)
        ok = np.all(np.isfinite(flat), axis=0)
        if not ok.any():
            return np.zeros(target.shape[1], int)
        scale = np.ptp(flat[:, ok], axis=1)
        scale = np.where(scale > 0, scale, 1.0)[:, None]
        tree = cKDTree((flat[:, ok] / scale).T)
        _, nearest = tree.query((target / scale).T)
        return np.flatnonzero(ok)[nearest]

    def invert(self, target: np.ndarray, nearest: np.ndarray) -> np.ndarray:
        """``x`` with interpolant ``== target`` (Newton from the table points
        ``nearest``, flat indices, as :meth:`nearest` gives them; ``nan`` columns where
        it does not converge to ``1e-12`` in ``F`` inside the grid). In passes of
        :data:`_PASS` columns, each iterated to its end."""
        x = np.full(target.shape, np.nan)
        if self.finite_stencil.any():  # (else every interpolant, so every column, is nan)
            for i in range(0, target.shape[1], _PASS):
                part = slice(i, i + _PASS)
                x[:, part] = self._invert(self.points[:, nearest[part]], target[:, part])
        return x

    def _invert(self, x, target):
        """:meth:`invert` of one pass from the start ``x`` (updated in place)."""
        live = np.arange(x.shape[1])  # columns still moving (a column that no longer moves,
        for _ in range(_SPLINE_NEWTON):  # or went nan outside the grid, stays so)
            val, jac = self._at(x[:, live], True)
            was = x[:, live]
            now = np.clip(was + _newton_step(jac, target[:, live] - val), self.lo[:, None],
                          self.hi[:, None])  # fmt: skip
            x[:, live] = now
            with np.errstate(invalid="ignore"):
                still = np.abs(now - was) > _SETTLED * np.maximum(1.0, np.abs(was))
            live = live[np.any(still, axis=0)]
            if live.size == 0:
                break
        val, _ = self._at(x, False)
        with np.errstate(invalid="ignore"):
            good = np.all(np.abs(val - target) <= 1e-12 * np.maximum(1.0, np.abs(target)), axis=0)
        return np.where(good, x, np.nan)


def _coarse_designs(table, target, *, last):
    """The designs of ``target`` on the coarse ``table`` (``(2, n)``, ``nan`` columns
    where the inverse has none) and whether its box grows low and high (per axis: a
    target without a design whose nearest table point lies on that edge). Where it grows
    (and the table is not the ``last`` one) the designs are not needed and come back as
    ``None``: the targets whose nearest point lies on an edge are inverted first, in
    passes, until every growth they can still show is shown, and the others only where
    the box stays (the same numbers: every column is inverted on its own)."""
    n = target.shape[1]
    nearest = table.nearest(target)
    grid = np.stack(np.unravel_index(nearest, table.shape))
    on_low, on_high = grid == 0, grid == table.shape[:, None] - 1
    x = np.full((2, n), np.nan)
    done = np.zeros(n, bool)
    low, high = np.zeros(2, bool), np.zeros(2, bool)
    todo = np.flatnonzero(np.any(on_low | on_high, axis=0))
    while todo.size:
        cols, todo = todo[:_PASS], todo[_PASS:]
        x[:, cols] = table.invert(target[:, cols], nearest[cols])
        done[cols] = True
        lost = cols[~np.all(np.isfinite(x[:, cols]), axis=0)]
        low |= np.any(on_low[:, lost], axis=1)
        high |= np.any(on_high[:, lost], axis=1)
        # the rest on an edge only where they can still show a growth not yet shown
        todo = todo[np.any(on_low[:, todo] & ~low[:, None] | on_high[:, todo] & ~high[:, None],
                           axis=0)]  # fmt: skip
    if (low.any() or high.any()) and not last:
        return None, low, high
    rest = np.flatnonzero(~done)
    x[:, rest] = table.invert(target[:, rest], nearest[rest])
    return x, low, high


def _refine(evaluate, table, x, target, rtol):
    """Quasi-Newton on the exact ``F`` from the table's start ``x`` (module docstring):
    the accepted designs and the further outputs of ``evaluate`` there, ``nan`` columns
    for the rest."""
    out, more = np.full(x.shape, np.nan), None
    _, jac = table.at(x)
    live = np.arange(x.shape[1])
    last_x = last_r = None
    for _ in range(_STEPS):
        if live.size == 0:
            break
        E, L, *extra = evaluate(x[0], x[1])
        if more is None:
            more = np.full((len(extra), x.shape[1]), np.nan)
        r = np.stack([E, L]) - target[:, live]
        with np.errstate(invalid="ignore"):
            ok = (np.abs(r[0]) < rtol * target[0, live]) & (np.abs(r[1]) < rtol)
        if last_x is not None:  # Broyden: J += (dr - J dx) dx^T / |dx|^2
            dx, dr = x - last_x, r - last_r
            miss = dr - np.einsum("ijn,jn->in", jac, dx)
            with np.errstate(divide="ignore", invalid="ignore"):
                upd = miss[:, None, :] * dx[None, :, :] / np.sum(dx * dx, axis=0)
            jac = np.where(np.isfinite(upd), jac + upd, jac)
        out[:, live[ok]] = x[:, ok]
        for row, values in zip(more, extra, strict=True):
            row[live[ok]] = values[ok]
        step = _newton_step(jac, -r)
        keep = ~ok & np.all(np.isfinite(step), axis=0)
        last_x, last_r = x[:, keep], r[:, keep]
        live, x, jac = live[keep], x[:, keep] + step[:, keep], jac[:, :, keep]
    return out, np.full((0, out.shape[1]), np.nan) if more is None else more


def _sum4(terms):
    """The sum of four new arrays, added in order into the first (the numbers of
    ``sum``, without its leading ``0 +`` pass and the temporaries)."""
    terms = iter(terms)
    out = next(terms)
    for term in terms:
        out += term
    return out


def _newton_step(jac, rhs):
    """``jac^-1 rhs`` per column, each component clipped to ``_MAX_STEP`` (``nan`` where
    singular or non-finite)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        det = jac[0, 0] * jac[1, 1] - jac[0, 1] * jac[1, 0]
        d0 = (jac[1, 1] * rhs[0] - jac[0, 1] * rhs[1]) / det
        d1 = (-jac[1, 0] * rhs[0] + jac[0, 0] * rhs[1]) / det
    return np.clip(np.stack([d0, d1]), -_MAX_STEP, _MAX_STEP)
