"""Finite contact stiffness, method 2: a certified cell table built in mpmath from the poles.

For one :math:`(\\alpha, \\kappa)` the time function :math:`g = y` or :math:`N` is, on
each cell :math:`[c - w, c + w]` of a mesh of :math:`[0, 2n]` whose nodes include the
reflection times :math:`2k`,

.. math::

    g(c + w x) = A(x) + f B(x) + \\epsilon(x), \\qquad |x| \\le 1, \\quad
    |\\epsilon| \\le \\epsilon_A + f \\epsilon_B,

real float64 polynomials :math:`A, B` with proven bounds, re-expanded from the exact pole
data of :mod:`impactsym.rod.elastic.poles` (each term :math:`\\sum_p e^{pu} P_p(u)`):
slow exponentials are summed over the terms and the contact poles merged near critical
damping (:math:`\\alpha\\kappa \\approx 4`) in mpmath, where float64 would cancel; cells
whose bound stays above ``1e-12`` are repaired in mpmath when the search first needs them.
Slower to build than :mod:`impactsym.rod.elastic.taylor` (mpmath), but with no limit on
the spring's stiffness: the table for springs too stiff for the Taylor table. The
construction and its bounds: docs/physics.md#finite-contact-stiffness-three-methods.
"""

from __future__ import annotations

import math
import threading
from functools import lru_cache

import numpy as np

from impactsym.numeric.precision import workdps
from impactsym.rod.elastic.poles import pole_model, series_coefficients

#: Largest degree of the cell polynomials in ``x``.
_MAX_DEGREE = 64
#: Largest ``|lambda| w`` on a cell.
_Z_MAX = 1.0
#: Largest cell half-width.
_W_MAX = 0.5
#: A group whose size on the rest of the interval is below this is dropped (bounded).
_DEAD = 1e-18
#: Cells whose float bound exceeds this get their worst terms in mpmath.
_TARGET = 1e-12
#: Families ``e^{lam u}`` with ``|lam|`` up to this are summed over the terms.
_ACROSS = 4.0
#: Contact poles nearer than this (``|delta|``) are merged in mpmath.
_MERGE = 1.0
_EPS = np.finfo(np.float64).eps
_FACT = np.array([math.factorial(i) for i in range(171)], dtype=float)
_BINOM = np.array([[math.comb(j, i) for j in range(200)] for i in range(200)], dtype=float)


def _mp_shift(coeffs: list, x0) -> list:
    """Coefficients (lowest first) of ``c(x0 + e)`` by repeated synthetic division."""
    d = list(coeffs)
    n = len(d)
    for i in range(n - 1):
        for j in range(n - 2, i - 1, -1):
            d[j] += x0 * d[j + 1]
    return d


def _required_dps(which: str, alpha: float, kappa: float, n_terms: int) -> int:
    """Digits for the mpmath stage: 40, plus what the merged poles cancel."""
    disc = alpha * alpha * kappa * kappa - 4.0 * alpha * kappa
    two_delta = math.sqrt(abs(disc)) / alpha
    if two_delta >= 2.0 * _MERGE or two_delta == 0.0:
        return 40
    n_max = max(n for _, _, n, _ in series_coefficients(which, n_terms))
    return 40 + math.ceil(2 * n_max * max(0.0, -math.log10(two_delta))) + 10


class CellTable:
    """Internal: the cell table of ``which`` (``"y"`` or ``"N"``) for one ``(alpha, kappa)``
    on ``n_terms`` reflection intervals, a :class:`impactsym.rod.elastic.CertifiedTable`.

    Cells ``[lo, hi]`` (centre ``c``, half-width ``w``) with coefficients
    ``A, B`` (shape ``(n_cells, DEGREE + 1)``, lowest order first, in
    ``x = (t - c)/w``), error bounds ``err_a, err_b`` (of the function, including the
    rounding of a Horner evaluation) and bounds ``d2_a, d2_b`` on the second
    derivatives in ``t`` of the polynomials."""

    def __init__(self, which: str, alpha: float, kappa: float, n_terms: int) -> None:
        import mpmath as mp

        dps = _required_dps(which, alpha, kappa, n_terms)
        model = pole_model(which, alpha, kappa=kappa, n_terms=n_terms, dps=dps)
        self.fastest = model.fastest
        self._model, self._dps = model, dps
        self._pending: dict = {}  # cell -> data for repair()
        # a cached table is shared between threads, and _repair changes it: the lock
        # makes a check and the repair it starts one step (see certified)
        self._lock = threading.RLock()
        cells = []
        with workdps(dps):
            pbar = -mp.mpf(kappa) / 2
            groups_by_term = [
                _term_groups(parts, pbar, n_terms - j) for j, parts in enumerate(model.parts)
            ]
        # polynomial degree of the terms (merged poles: the double root's) plus 19
        # orders for e^{lam w x}, |lam w| <= 1 (tail 1/20! ~ 4e-19)
        longest = max(len(p[1]) for parts in model.parts for p in parts)
        merged = any(lam == complex(pbar) for lam, _, _ in groups_by_term[-1][0])
        self.degree = degree = min(_MAX_DEGREE, (2 if merged else 1) * longest + 19)

        def skip(r):  # roots whose parts are in a family summed over the terms
            return _across_terms(complex(pbar) if (merged and r != 0) else complex(r))

        self._skip = skip

        families = {g[0] for t in groups_by_term for g in t[0] if _across_terms(g[0])}
        fast = [g[0] for t in groups_by_term for g in t[0] if not _across_terms(g[0])]
        # how long (in u) a fast part can matter: e^{Re lam u} below 1e-18 of ~1e3
        alive = max((48.0 / -lam.real for lam in fast), default=0.0)

        for m in range(n_terms):
            # young terms (a fast part still alive: it cancels their slow parts) keep
            # all their parts per term; the slow families of the older ones are summed
            young = {j for j in range(m + 1) if 2 * (m - j) < alive}
            groups = []
            for j in range(m + 1):
                groups += [
                    (j, *g)
                    for g in groups_by_term[j][m - j]
                    if j in young or not _across_terms(g[0])
                ]
            old = [(j, model.parts[j]) for j in range(m + 1) if j not in young]
            with workdps(dps):  # slow families of the older terms at once
                for lam in families if old else ():
                    lam_mp = mp.mpf(0) if lam == 0 else (pbar if lam == complex(pbar) else None)
                    if lam_mp is None:
                        lam_mp = next(p[0] for p in model.parts[-1] if complex(p[0]) == lam)
                    groups.append(_family_group(old, 2 * m + 1, lam_mp, pbar, merged))
            lo, hi, c, w, A, B, err, mag = _interval_cells(2 * m + 1, groups, degree, m + 1)
            offset = sum(cell[0].size for cell in cells)
            bad = (err.sum(axis=0) + _EPS * len(groups) * mag.sum(axis=0)).sum(axis=0)
            for i in np.flatnonzero(bad > 0.5 * _TARGET):  # repaired when first needed
                self._pending[offset + i] = (
                    m,
                    c[i],
                    w[i],
                    A[:, i],
                    B[:, i],
                    err[:, :, i],
                    mag[:, :, i],
                    len(groups),
                    frozenset(young),
                )
            cells.append((lo, hi, c, w, *self._finish(A, B, err, mag, len(groups))))
        self.lo, self.hi, self.c, self.w, self.A, self.B, self.err_a, self.err_b = (
            np.concatenate([cell[i] for cell in cells]) for i in range(8)
        )
        self.d2_a, self.d2_b = self._second_derivative_bounds(self.A, self.B, self.w)

    def _second_derivative_bounds(self, A, B, w):
        n = np.arange(self.degree + 1)
        d2 = n * (n - 1)
        return (np.abs(A) @ d2) / w**2 * (1 + 1e-12), (np.abs(B) @ d2) / w**2 * (1 + 1e-12)

    def _finish(self, A, B, err, mag, n_groups):
        """Sum of the rows (terms, families) with its bound: the sum over the groups
        and a Horner evaluation of ``A + f B`` (``|x| <= 1``)."""
        A, B = A.sum(axis=0), B.sum(axis=0)
        summation = _EPS * n_groups * mag.sum(axis=0)
        horner = _EPS * (2 * self.degree + 4)
        err_a = err[:, 0].sum(axis=0) + summation[0] + horner * np.abs(A).sum(axis=-1)
        err_b = err[:, 1].sum(axis=0) + summation[1] + horner * np.abs(B).sum(axis=-1)
        return A, B, err_a, err_b

    def certified(self, index: np.ndarray, f: np.ndarray, tolerance: float) -> np.ndarray:
        """Whether the proven error of cells ``index`` is at most ``tolerance`` for ``f``;
        cells above it are first repaired (:meth:`_repair`) if they can be."""
        # under the lock: a thread that finds a cell another thread is repairing (taken
        # from the pending cells, its polynomial not yet written back) waits for it, and
        # does not search that cell on the pole sums instead, nor read a cell while it is
        # written. It does not make results independent of the call history: a waiting
        # cell may pass the tolerance at a small f before any repair, and a repair that a
        # larger f started (in this thread or another) rewrites its rows, which moves
        # values at the small f by rounding (up to 9e-16 measured), always within the
        # certified bound
        with self._lock:
            ok = self.err_a[index] + f * self.err_b[index] <= tolerance
            if not ok.all():
                waiting = index[~ok][self._waiting(index[~ok])]
                if waiting.size:  # repair in mpmath where first needed, then look again
                    self._repair(waiting)
                    ok = self.err_a[index] + f * self.err_b[index] <= tolerance
        return ok

    def second_derivative_bound(self, index: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Bound on ``|d^2/dt^2 (A + f B)|`` over cells ``index``."""
        with self._lock:  # rows that _repair may be writing
            return self.d2_a[index] + f * self.d2_b[index]

    def _repair(self, cells: np.ndarray) -> None:
        """Recompute the worst terms of pending ``cells`` exactly about the cell centre
        (mpmath, all their poles at once so that they cancel there), until the rows'
        float bound is below ``_TARGET / 2`` or the rest is many small errors."""
        with self._lock:  # it changes a table that threads share (see certified)
            self._repair_locked(cells)

    def _repair_locked(self, cells: np.ndarray) -> None:

        for gi in np.unique(cells):
            job = self._pending.pop(int(gi), None)
            if job is None:
                continue
            m, c, w, A, B, err, mag, n_groups, young = job
            A, B, err, mag = A.copy(), B.copy(), err.copy(), mag.copy()
            for j in np.argsort(-err.sum(axis=1)):
                if err.sum() + _EPS * n_groups * mag.sum() <= 0.5 * _TARGET:
                    break
                if err[j].sum() <= 0.125 * _TARGET:
                    break  # many small float errors: mpmath would not pay
                if j == m + 1:
                    continue  # the families summed over the terms in mpmath already
                with workdps(self._dps):
                    qa, qb, ea, eb, ma, mb = _mp_cell(
                        self._model.parts[j],
                        c - 2 * j,
                        w,
                        self.degree,
                        (lambda r: False) if j in young else self._skip,
                    )
                A[j], B[j], err[j], mag[j] = qa, qb, (ea, eb), (ma, mb)
            a, b, ea, eb = self._finish(
                A[:, None], B[:, None], err[:, :, None], mag[:, :, None], n_groups
            )
            self.A[gi], self.B[gi], self.err_a[gi], self.err_b[gi] = a[0], b[0], ea[0], eb[0]
            da, db = self._second_derivative_bounds(a, b, self.w[gi : gi + 1])
            self.d2_a[gi], self.d2_b[gi] = da[0], db[0]

    def _waiting(self, cells: np.ndarray) -> np.ndarray:
        """Which of ``cells`` still wait for :meth:`_repair`."""
        return np.array([int(i) in self._pending for i in np.ravel(cells)], dtype=bool)

    def cell(self, t: np.ndarray) -> np.ndarray:
        """Index of the cell holding ``t`` (the right one at a node)."""
        return np.clip(np.searchsorted(self.lo, t, side="right") - 1, 0, self.lo.size - 1)

    def evaluate(self, t: np.ndarray, f: np.ndarray, index: np.ndarray | None = None):
        """``g`` and ``dg/dt`` of the polynomial representation at ``t`` for ``f``."""
        i = self.cell(t) if index is None else index
        w = self.w[i]
        x = (t - self.c[i]) / w
        with self._lock:  # copies of rows that _repair may be writing
            A, B = self.A[i], self.B[i]
        value = A[:, -1] + f * B[:, -1]
        slope = np.zeros_like(value)
        for n in range(self.degree - 1, -1, -1):
            slope = slope * x + value
            value = value * x + (A[:, n] + f * B[:, n])
        return value, slope / w


def _term_groups(parts, pbar, n_centres):
    """For one term: per centre ``u0 = 1, 3, ...`` (``n_centres`` of them) the groups
    ``(lam, weight, bases)``; the group is ``weight Re(e^{lam u} (SA + f SB)(u - ub))``
    up to ``tau_a + f tau_b`` for ``|u - ub| <= radius``, for each basis ``(ub, SA, SB,
    tau_a, tau_b, radius)`` in ``bases`` (about ``u0`` and about ``0``)."""
    import mpmath as mp

    zero = [p for p in parts if p[0] == 0]
    contact = [p for p in parts if p[0] != 0]
    if len(contact) == 2:
        delta = (contact[0][0] - contact[1][0]) / 2
    elif contact and isinstance(contact[0][0], mp.mpc):
        delta = contact[0][0].imag
    else:
        delta = mp.mpf(0)  # double root
    merge = abs(delta) < _MERGE
    singles = zero + ([] if merge else contact)

    def single(p0, p1, ub):
        sa, sb = _mp_shift(p0, ub), _mp_shift(p1, ub)
        fa = np.array([complex(v) for v in sa])
        fb = np.array([complex(v) for v in sb])
        # exact polynomials: the rounding to float64 is part of the cell's rounding bound
        return (float(ub), fa, fb, 0.0, 0.0, math.inf)

    origin = [single(p0, p1, mp.mpf(0)) for _, p0, p1, _ in singles]
    if merge and contact:
        origin.append(_merged_basis(contact, pbar, mp.mpf(0), 2))
    out = []
    for i in range(n_centres):
        halves = (mp.mpf(2 * i + 1) - mp.mpf(0.5), mp.mpf(2 * i + 1) + mp.mpf(0.5))
        groups = []
        for (r, p0, p1, pair), base0 in zip(singles, origin, strict=False):
            bases = [single(p0, p1, u0) for u0 in halves]
            groups.append((complex(r), 2.0 if pair else 1.0, [*bases, base0]))
        if merge and contact:
            bases = [_merged_basis(contact, pbar, u0, 1) for u0 in halves]
            groups.append((complex(pbar), 1.0, [*bases, origin[-1]]))
        out.append(groups)
    return out


def _across_terms(lam) -> bool:
    """Whether the family ``e^{lam u}`` is summed over the terms (slow enough that a
    polynomial about the half-interval centres holds it; see :func:`_family_group`)."""
    return abs(complex(lam)) <= _ACROSS


def _family_group(parts_by_term, centre, lam, pbar, merge):
    """All arrived terms' parts with exponent ``lam`` (``0``, a contact root, or
    ``pbar`` for the merged contact poles) as one group, summed in mpmath:
    :math:`\\sum_k e^{\\lambda (t - 2k)} S_k(t - 2k) = e^{\\lambda (t - C)} \\sum_k
    e^{\\lambda (C - 2k)} S_k(t - 2k)` about ``t = C -+ 1/2`` (``k = C/2`` in the
    group, so that ``u = t - C``). The terms of one family cancel each other (the
    ``f`` parts of ``y`` by a factor 40), which float64 would not resolve."""
    import mpmath as mp

    C = mp.mpf(centre)
    bases, weight = [], 1.0
    for ub in (-mp.mpf(0.5), mp.mpf(0.5)):
        sums, tails = [[], []], [mp.mpf(0), mp.mpf(0)]
        for k, parts in parts_by_term:
            scale = mp.exp(lam * (C - 2 * k))
            u0 = C + ub - 2 * k
            if lam == pbar and merge:
                contact = [p for p in parts if p[0] != 0]
                (ka, kb), (ta, tb) = _merged_basis(contact, pbar, u0, 1, exact=True)
                polys = (ka, kb)
                tails[0] += abs(scale) * ta
                tails[1] += abs(scale) * tb
            else:
                match = [p for p in parts if p[0] == lam]
                if not match:
                    continue
                _, p0, p1, pair = match[0]
                weight = 2.0 if pair else 1.0
                polys = (_mp_shift(p0, u0), _mp_shift(p1, u0))
            for which, poly in enumerate(polys):
                acc = sums[which]
                acc += [mp.mpf(0)] * (len(poly) - len(acc))
                for j, v in enumerate(poly):
                    acc[j] += scale * v
        fa, fb = (np.array([complex(v) for v in acc] or [0j]) for acc in sums)
        radius = 1.0 if (lam == pbar and merge) else math.inf
        reach = min(radius, 1.5) ** np.arange(max(fa.size, fb.size))
        ta = float(tails[0]) * (1 + 1e-6) + _EPS * float(np.abs(fa) @ reach[: fa.size])
        tb = float(tails[1]) * (1 + 1e-6) + _EPS * float(np.abs(fb) @ reach[: fb.size])
        if radius == math.inf:
            ta = tb = 0.0  # exact polynomial: its rounding is part of the cell's bound
        bases.append((float(ub), fa, fb, ta, tb, radius))
    return (centre / 2.0, complex(lam), weight, bases)


def _abs_sum(c: np.ndarray) -> float:
    return float(np.abs(c).sum())


def _merged_basis(contact, pbar, u0, radius, exact=False):
    """The contact poles about ``pbar`` as one real series ``K`` about ``u0``, valid
    for ``|u - u0| <= radius`` (docs/physics.md#finite-contact-stiffness-three-methods);
    with ``exact`` the mpmath coefficients and tails ``((ka, kb), (tail_a, tail_b))``."""
    import mpmath as mp

    members = []
    for r, p0, p1, pair in contact:
        sigma = r - pbar
        members.append((sigma, mp.exp(sigma * u0), _mp_shift(p0, u0), _mp_shift(p1, u0), pair))
    n = max(len(m[2]) for m in members)
    R = mp.mpf(radius)
    result = []
    for which in (2, 3):
        degree = n + 20
        while True:
            tail = mp.mpf(0)
            for member in members:
                sigma, scale, pair, poly = member[0], member[1], member[4], member[which]
                s = abs(sigma) * R
                for j, c in enumerate(poly):
                    tail += (
                        (2 if pair else 1)
                        * abs(scale)
                        * abs(c)
                        * R**j
                        * s ** (degree - j + 1)
                        / mp.factorial(degree - j + 1)
                        * mp.exp(s)
                    )
            if tail <= 1e-20 or degree > 190:
                break
            degree += 10
        coeffs = []
        for order in range(degree + 1):
            total = mp.mpf(0)
            for member in members:
                sigma, scale, pair, poly = member[0], member[1], member[4], member[which]
                term = mp.fsum(
                    sigma ** (order - j) / mp.factorial(order - j) * poly[j]
                    for j in range(min(order, len(poly) - 1) + 1)
                )
                term *= scale
                total += 2 * mp.re(term) if pair else mp.re(term)
            coeffs.append(total)
        if exact:
            result.append((coeffs, tail))
            continue
        fc = np.array([float(v) for v in coeffs])
        rounding = _EPS * float(np.abs(fc) @ (float(radius) ** np.arange(fc.size)))
        result.append((fc.astype(complex), float(tail) * (1 + 1e-6) + rounding))
    if exact:
        return (result[0][0], result[1][0]), (result[0][1], result[1][1])
    (fa, ta), (fb, tb) = result
    return (float(u0), fa, fb, ta, tb, float(radius))


def _interval_cells(centre: int, groups: list, DEGREE: int, n_terms: int):
    """Mesh and coefficients on the reflection interval ``[centre - 1, centre + 1]``.

    ``groups``: ``(k, lam, weight, bases)`` (:func:`_term_groups`), ``u = t - 2k``.
    """
    start = centre - 1.0
    # when each group dies: e^{Re lam (t - 2k)} size < _DEAD
    limits = []
    for k, lam, weight, bases in groups:
        # |S(u)| on the interval from the basis about u = 0: u <= centre + 1 - 2k
        ub, sa, sb = bases[-1][:3]
        reach = centre + 1.0 - 2 * k - ub
        powers = reach ** np.arange(max(sa.size, sb.size))
        with np.errstate(all="ignore"):
            size = weight * (np.abs(sa) @ powers[: sa.size] + np.abs(sb) @ powers[: sb.size])
        if lam.real < 0 and size > 0 and np.isfinite(size):
            t_dead = 2 * k + max(0.0, math.log(size / _DEAD)) / -lam.real
        else:
            t_dead = math.inf
        limits.append((t_dead, abs(lam)))
    edges = [start]
    t = start
    while t < centre + 1.0:
        rate = max((mag for t_dead, mag in limits if t_dead > t), default=0.0)
        h = 2.0 * min(_W_MAX, _Z_MAX / rate if rate > 0 else _W_MAX)
        # stop a cell where a fast group dies, so the next may be wider
        nxt = min(t + h, centre + 1.0)
        deaths = [t_dead for t_dead, _ in limits if t < t_dead < nxt]
        if deaths and min(deaths) - t > 0.25 * h:
            nxt = min(deaths)
        edges.append(nxt)
        t = nxt
    edges = np.array(edges)
    lo, hi = edges[:-1], edges[1:]
    c = 0.5 * (lo + hi)
    w = 0.5 * (hi - lo)
    n_cells = lo.size
    # one row per term, the last for the polynomial group (lam = 0)
    A = np.zeros((n_terms + 1, n_cells, DEGREE + 1))
    B = np.zeros((n_terms + 1, n_cells, DEGREE + 1))
    err = np.zeros((n_terms + 1, 2, n_cells))
    mag = np.zeros((n_terms + 1, 2, n_cells))  # |contribution| per row, for the summation
    for k, lam, weight, bases in groups:
        u_c = c - 2.0 * k
        decay = np.exp(lam.real * (u_c - w))  # |e^{lam u}| <= decay on the cell
        best = None
        for basis in bases:
            with np.errstate(all="ignore"):  # overflow: an infinite bound, never chosen
                part = _basis_part(lam, weight, basis, u_c, w, decay, DEGREE)
            if part is None:
                continue
            part[2][~np.isfinite(part[2])] = np.inf
            if best is None:
                best = part
                continue
            better = part[2].sum(axis=0) < best[2].sum(axis=0)
            best = (
                np.where(better[:, None], part[0], best[0]),
                np.where(better[:, None], part[1], best[1]),
                np.where(better, part[2], best[2]),
                np.where(better, part[3], best[3]),
            )
        qa, qb, e, m = best
        qa, qb = np.where(np.isfinite(qa), qa, 0.0), np.where(np.isfinite(qb), qb, 0.0)
        m = np.where(np.isfinite(m), m, np.inf)
        row = k if float(k).is_integer() else n_terms  # family groups: k = centre / 2
        A[row] += qa
        B[row] += qb
        err[row] += e
        mag[row] += m
    return lo, hi, c, w, A, B, err, mag


def _mp_cell(parts, u_c, w, degree, skip):
    """Term ``sum_p e^{p u} P_p(u)`` on the cell ``u = u_c + w x`` in mpmath (the
    per-pole parts cancel at the model's precision): float coefficients of ``A, B``,
    their error bounds (truncation, rounding to float) and magnitudes."""
    import mpmath as mp

    u_c, w = mp.mpf(float(u_c)), mp.mpf(float(w))
    acc = [[mp.mpf(0)] * (degree + 1) for _ in range(2)]
    tails = [mp.mpf(0), mp.mpf(0)]
    for r, p0, p1, pair in parts:
        if skip(r):
            continue  # in a family group
        weight = 2 if pair else 1
        ex = mp.exp(r * u_c)
        lw = r * w
        z = abs(lw)
        E = [mp.mpf(1)]
        for i in range(1, degree + 1):
            E.append(E[-1] * lw / i)
        for which, poly in ((0, p0), (1, p1)):
            S = _mp_shift(poly, u_c)
            Sw = [S[j] * w**j for j in range(len(S))]
            dead = weight * mp.exp(mp.re(r) * (u_c - w)) * mp.fsum(abs(c) for c in Sw)
            if dead < _DEAD:  # below any expansion's tail: bounded as a whole
                tails[which] += dead
                continue
            for order in range(degree + 1):
                q = mp.fsum(Sw[j] * E[order - j] for j in range(min(order, len(Sw) - 1) + 1))
                q *= ex
                acc[which][order] += weight * mp.re(q)
            # orders above the degree, of e^{lam w x} and of the products
            tails[which] += (
                weight
                * abs(ex)
                * mp.fsum(
                    abs(Sw[j]) * z ** (degree - j + 1) / mp.factorial(degree - j + 1) * mp.exp(z)
                    for j in range(len(Sw))
                )
            )
    out = []
    for which in (0, 1):
        coeffs = np.array([float(v) for v in acc[which]])
        out.append(coeffs)
    mags = [float(np.abs(c).sum()) for c in out]
    errs = [float(tails[i]) * (1 + 1e-6) + _EPS * mags[i] for i in (0, 1)]
    return out[0], out[1], errs[0], errs[1], mags[0], mags[1]


def _basis_part(lam, weight, basis, u_c, w, decay, DEGREE):
    """One group's coefficients on every cell from one basis: ``(A, B, err, mag)``
    (``err, mag`` of shape ``(2, n_cells)``; ``err`` inf where the basis is not valid)."""
    ub, sa, sb, tau_a, tau_b, radius = basis
    n_cells = u_c.size
    e_c = u_c - ub
    reach = np.abs(e_c) + w
    valid = reach <= radius
    if not valid.any():
        return None
    n = max(sa.size, sb.size)
    S = np.zeros((2, n), dtype=complex)
    S[0, : sa.size], S[1, : sb.size] = sa, sb
    absS = np.abs(S)
    size = absS @ (reach[None, :] ** np.arange(n)[:, None])  # (2, n_cells)
    err = weight * decay * np.array([[tau_a], [tau_b]]) * np.ones(n_cells)
    mag = np.zeros((2, n_cells))
    qa = np.zeros((n_cells, DEGREE + 1))
    qb = np.zeros((n_cells, DEGREE + 1))
    alive = valid & ((weight * decay * size.max(axis=0) >= _DEAD) | (lam == 0))
    err += weight * decay * size * (valid & ~alive)
    idx = np.flatnonzero(alive)
    if idx.size:
        ec, wc, uc = e_c[idx], w[idx], u_c[idx]
        # S(e_c + w x) in x: M[j', j] = binom(j, j') e_c^(j - j') w^j'
        jj = np.arange(n)
        expo = jj[None, :] - jj[:, None]  # j - j'
        powc = np.where(expo[None] >= 0, ec[:, None, None] ** np.maximum(expo, 0)[None], 0.0)
        M = _BINOM[:n, :n][None] * powc * (wc[:, None, None] ** jj[None, :, None])
        Sx = np.einsum("cij,aj->aci", M, S)  # (2, cells, n)
        z = abs(lam) * wc
        # E_i = E_(i-1) lam w / i: relative error <= 4 i eps, weighted sum <= 4 z e^z eps
        E = np.ones((idx.size, DEGREE + 1), dtype=complex)
        step = lam * wc
        for i in range(1, DEGREE + 1):
            E[:, i] = E[:, i - 1] * step / i
        rho = z ** (DEGREE + 1) / _FACT[DEGREE + 1] * np.exp(z)
        Q = np.zeros((2, idx.size, n + DEGREE), dtype=complex)
        for j in range(n):
            Q[:, :, j : j + DEGREE + 1] += Sx[:, :, j : j + 1] * E[None]
        scale = weight * np.exp(lam * uc)
        kept = Q[:, :, : DEGREE + 1] * scale[None, :, None]
        qa[idx], qb[idx] = kept[0].real, kept[1].real
        absSx = np.abs(Sx).sum(axis=2)  # sup of |S| on the cell
        dropped = np.abs(Q[:, :, DEGREE + 1 :]).sum(axis=2)
        # shift (2n + 3), sums of the product (n), E (4 z), scaling by e^{lam u} (4)
        steps = 2 * n + 4 if lam == 0 else 3 * n + 8 + 4 * z
        rounding = (
            _EPS * (steps + np.abs(lam * uc)) * (size[:, idx] * np.exp(z) + np.abs(Q).sum(axis=2))
        )
        err[:, idx] += np.abs(scale) * (rho * absSx + dropped + rounding)
        mag[:, idx] = np.abs(scale) * np.abs(Q[:, :, : DEGREE + 1]).sum(axis=2)
    err[:, ~valid] = np.inf
    return qa, qb, err, mag


@lru_cache(maxsize=64)
def cell_table(which: str, alpha: float, *, kappa: float, n_terms: int) -> CellTable:
    """Internal: the cached :class:`CellTable` of ``which`` for ``(alpha, kappa)`` on
    ``n_terms`` reflection intervals."""
    return CellTable(which, alpha, kappa, n_terms)
