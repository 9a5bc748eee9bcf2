r"""The affine 2x2 in-contact step map of MuJoCo's Euler step, in closed form.

At flat impedance one Euler step in contact maps the state ``(X - X*, Y)`` (penetration
from its static value and the step's displacement, in units of ``speed * timestep``)
linearly,

.. math::

    M = \begin{pmatrix} 1 - \kappa & 1 - \beta \\ -\kappa & 1 - \beta \end{pmatrix},
    \qquad \operatorname{tr} M = 2 - \kappa - \beta, \quad \det M = 1 - \beta,
    \quad \Delta = (\kappa + \beta)^2 - 4 \kappa,

with ``kappa = d' d kbar dt^2`` and ``beta = d' b dt`` (derivation:
:func:`impactsym.engines.derivation.mujoco_euler_step`). A linear functional of the n-th
state plus a constant, ``H(n) = l . M^n w + q``, is by Cayley-Hamilton
``P U_n + Q U_{n-1} + q`` with ``P = l . M w``, ``Q = -det(M) l . w`` and
``U_n = (lambda_1^n - lambda_2^n) / (lambda_1 - lambda_2)``; :class:`Sequence` writes it
in a form that stays accurate for complex, distinct real and (nearly) repeated
eigenvalues and continues it to real ``s``. :func:`first_hit` finds the first integer
``n >= 1`` with ``H(n) <= 0`` from that continuation: a bracketed root of the
exponential-polynomial on a monotone piece, then the integer check
(`docs/physics.md#touch-phase`). Elements whose map has a negative or vanishing
eigenvalue, or a real eigenvalue ``>= 1``, are marked for the exact recurrence.

Internal: :mod:`~impactsym.engines.mujoco.euler` uses it. Dimensionless throughout.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.roots import bracketed_illinois

__all__ = ["Sequence", "first_hit", "spectral_radius"]

_REAL_TINY = 1e-12  # |lambda_2| below this times lambda_1: its mode is gone after one step
_BIG_DELTA = 700.0  # log(lambda_1 / lambda_2) used for such a vanishing mode
_MAX_WINDOWS = 400  # oscillation windows searched for a growing (unstable) map


def spectral_radius(*, kappa: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Largest eigenvalue modulus of ``M`` (``>= 1``: the in-contact map is unstable)."""
    tr, det = 2.0 - kappa - beta, 1.0 - beta
    disc = (kappa + beta) ** 2 - 4.0 * kappa
    with np.errstate(invalid="ignore"):
        root = np.sqrt(np.abs(disc))
    return np.where(disc < 0, np.sqrt(np.abs(det)), 0.5 * (np.abs(tr) + root))


class Sequence:
    """``H(s) = l^T M^s w + q`` for arrays of maps, functionals and start vectors.

    ``kind`` is 1 (complex eigenvalues: ``H = K r^s cos(s theta - phi) + q``), 2 (real,
    ``0 < lambda_2 <= lambda_1 < 1``: ``H = lambda_1^(s-1) (alpha E(s) - gamma
    e^(-(s-1) delta)) + q`` with ``E(s) = expm1(-s delta) / expm1(-delta)``) or 0 (not in
    closed form here: the recurrence takes it).
    """

    def __init__(self, kappa, beta, l1, l2, w1, w2, q):
        kappa, beta, l1, l2, w1, w2, q = np.broadcast_arrays(
            *(np.asarray(a, float) for a in (kappa, beta, l1, l2, w1, w2, q))
        )
        self.q = q
        tr, det = 2.0 - kappa - beta, 1.0 - beta
        disc = (kappa + beta) ** 2 - 4.0 * kappa
        mw1 = (1.0 - kappa) * w1 + (1.0 - beta) * w2
        mw2 = -kappa * w1 + (1.0 - beta) * w2
        P = l1 * mw1 + l2 * mw2
        lw = l1 * w1 + l2 * w2
        Q = -det * lw
        self.lw, self.P = lw, P
        with np.errstate(all="ignore"):
            # complex pair r e^(+-i theta)
            r = np.sqrt(np.abs(det))
            theta = np.arctan2(np.sqrt(np.abs(disc)), tr)
            a = P + Q * np.cos(theta) / r
            b = -Q * np.sin(theta) / r
            self.K = np.hypot(a, b) / (r * np.sin(theta))
            self.phi = np.arctan2(a, b)
            self.log_r, self.theta = np.log(r), theta
            # real pair lambda_1 >= lambda_2
            root = np.sqrt(np.abs(disc))
            big = 0.5 * (tr + np.where(tr >= 0, root, -root))
            small = det / big
            lam1, lam2 = np.maximum(big, small), np.minimum(big, small)
            gone = np.abs(lam2) <= _REAL_TINY * np.abs(lam1)
            delta = np.where(gone, _BIG_DELTA, np.log(lam1 / np.where(gone, 1.0, lam2)))
            self.log_l1, self.delta = np.log(lam1), delta
            self.alpha, self.gamma = P + Q / lam1, np.where(gone, 0.0, Q / lam1)
        complex_ = (disc < 0) & (det > 0)
        real = (disc >= 0) & (lam1 < 1.0) & (lam1 > 0) & ((lam2 > 0) | gone)
        self.kind = np.where(complex_, 1, np.where(real, 2, 0))

    def take(self, i):
        """The sequences of the elements ``i`` (an index array)."""
        out = Sequence.__new__(Sequence)
        for name, value in vars(self).items():
            setattr(out, name, value[i])
        return out

    def at(self, s):
        """``H(s)`` (``s`` real, broadcast with the elements; exact at integers)."""
        s = np.asarray(s, float)
        with np.errstate(all="ignore"):
            cplx = self.K * np.exp(s * self.log_r) * np.cos(s * self.theta - self.phi)
            E = _expm1_ratio(s, self.delta)
            real = np.exp((s - 1.0) * self.log_l1) * (
                self.alpha * E - self.gamma * np.exp(-(s - 1.0) * self.delta)
            )
            real = np.where(s == 0, self.lw, np.where(s == 1, self.P, real))
        return np.where(self.kind == 1, cplx, real) + self.q

    def slope_sign(self, s):
        """A function with the sign of ``dH/ds`` (real kind only)."""
        with np.errstate(all="ignore"):
            em = np.exp(-s * self.delta)
            ratio = np.where(self.delta > 0, self.delta / -np.expm1(-self.delta), 1.0)
            ex = np.exp(-(s - 1.0) * self.delta)
            return self.log_l1 * (self.alpha * _expm1_ratio(s, self.delta) - self.gamma * ex) + (
                self.alpha * em * ratio + self.gamma * self.delta * ex
            )


def _expm1_ratio(s, delta):
    """``expm1(-s delta) / expm1(-delta)`` (``s`` where ``delta = 0``)."""
    with np.errstate(all="ignore"):
        out = np.expm1(-s * delta) / np.expm1(-delta)
    return np.where(delta > 0, out, s)


def first_hit(seq: Sequence, hit) -> np.ndarray:
    """First integer ``n >= 1`` with ``hit(n, index)`` (``H(n) <= 0``), ``inf`` if never.

    ``hit(n, i)`` is the exact criterion on the elements ``i`` (it decides at the
    integers, so that rounding of the continuation never changes an end step). Kind-0
    elements come back as ``nan`` (for the recurrence).
    """
    n = np.full(seq.kind.shape, np.nan)
    one = np.ones(seq.kind.shape)
    every = np.arange(n.size)
    at_one = hit(one, every)
    n[at_one] = 1.0
    for kind, search in ((1, _first_complex), (2, _first_real)):
        i = np.flatnonzero((seq.kind == kind) & ~at_one)
        if i.size:
            n[i] = search(seq.take(i), lambda m, j, i=i: hit(m, i[j]))
    return n


def _check_candidates(hit, lo_int, root, idx):
    """Smallest integer ``>= lo_int`` near the root ``root`` for which ``hit`` holds."""
    base = np.maximum(np.ceil(root), lo_int)
    out = np.full(base.shape, np.inf)
    for shift in (1.0, 0.0, -1.0):  # the last assignment (the smallest hit) wins
        m = base + shift
        ok = (m >= lo_int) & hit(m, idx)
        out = np.where(ok, m, out)
    return out


def _first_complex(seq: Sequence, hit) -> np.ndarray:
    """First hit on ``K r^s cos(s theta - phi) + q``: one oscillation window at a time."""
    size = seq.K.size
    out = np.full(size, np.inf)
    psi = np.arctan2(seq.theta, seq.log_r)  # H' ~ cos(s theta - phi + psi)
    two_pi = 2.0 * np.pi
    k = np.floor((seq.theta - 0.5 * np.pi + psi - seq.phi) / two_pi)
    active = np.arange(size)
    for _ in range(_MAX_WINDOWS):
        if active.size == 0:
            break
        sub = seq.take(active)
        th, ps = sub.theta, psi[active]
        s_max = (0.5 * np.pi + two_pi * k[active] - ps + sub.phi) / th
        s_min = s_max + np.pi / th
        s_next = s_max + two_pi / th
        lo = np.maximum(s_max, 1.0)
        h_min = sub.at(np.maximum(s_min, 1.0))
        dips = (h_min <= 0) & (s_next >= 1.0)
        found = np.full(active.size, np.inf)
        # (a window whose minimum lies before s = 1 rises from H(1) > 0: no hit in it)
        j = np.flatnonzero(dips & (s_min > lo))
        if j.size:
            part = sub.take(j)
            h_lo = part.at(lo[j])
            root = np.array(lo[j])
            jj = np.flatnonzero(h_lo > 0)
            if jj.size:
                pp = part.take(jj)
                root[jj] = bracketed_illinois(
                    lambda s, m, pp=pp: -pp.take(m).at(s),
                    lo[j][jj],
                    s_min[j][jj],
                    atol=1e-9,
                    f_lo=-h_lo[jj],
                    f_hi=-h_min[j][jj],
                )
            found[j] = _check_candidates(hit, np.ceil(lo[j]), root, active[j])
        out[active] = found
        # decaying oscillation without a dip: none later either
        hopeless = ~np.isfinite(found) & (h_min > 0) & (sub.log_r <= 0) & (s_min >= 1.0)
        k[active] += 1.0
        active = active[~np.isfinite(found) & ~hopeless]
    return out


def _first_real(seq: Sequence, hit) -> np.ndarray:
    """First hit on ``lambda_1^(s-1) (alpha E - gamma e^(-(s-1) delta)) + q``.

    ``H`` has at most one critical point; it can reach ``H <= 0`` only by decreasing
    from ``s = 1`` to a minimum ``s_c`` (after it, it rises towards ``q >= 0``), so the
    first hit is the first integer past the root in ``[1, s_c]``, if ``H(s_c) <= 0``.
    """
    size = seq.K.size
    out = np.full(size, np.inf)
    s1 = np.ones(size)
    falling = (seq.slope_sign(s1) < 0) & (seq.alpha < 0)  # decreasing, then a minimum
    i = np.flatnonzero(falling)
    if i.size == 0:
        return out
    sub = seq.take(i)
    hi = np.full(i.size, 2.0)
    for _ in range(80):  # the minimum: double until the slope turns
        up = sub.slope_sign(hi) > 0
        if up.all():
            break
        hi = np.where(up, hi, 2.0 * hi)
    ok = sub.slope_sign(hi) > 0
    j = np.flatnonzero(ok)
    if j.size == 0:
        return out
    part = sub.take(j)
    s_c = bracketed_illinois(
        lambda s, m: part.take(m).slope_sign(s), np.ones(j.size), hi[j], atol=1e-9
    )
    h_c = part.at(s_c)
    dip = np.flatnonzero(h_c <= 0)
    if dip.size == 0:
        return out
    pp = part.take(dip)
    root = bracketed_illinois(
        lambda s, m: -pp.take(m).at(s), np.ones(dip.size), s_c[dip], atol=1e-9
    )
    idx = i[j[dip]]
    out[idx] = _check_candidates(hit, np.ones(dip.size), root, idx)
    return out


def sequence_max(seq: Sequence, last: np.ndarray) -> np.ndarray:
    """``max H(n)`` over the integers ``0 <= n <= last`` (``last`` may be ``inf``).

    The maximum lies at ``0``, at ``last`` or at an integer next to a maximum of the
    continuation: the first one (and for a growing oscillation the last one before
    ``last``); the real kind has at most one critical point after ``s = 1``.
    """
    size = seq.K.size
    last = np.asarray(last, float)
    big = np.where(np.isfinite(last), last, 1e300)
    best = seq.at(np.zeros(size))
    best = np.maximum(
        best, np.where(np.isfinite(last), seq.at(np.where(np.isfinite(last), last, 0.0)), best)
    )
    best = np.where(np.isfinite(last), best, np.maximum(best, seq.q))
    cands = []
    with np.errstate(all="ignore"):
        psi = np.arctan2(seq.theta, seq.log_r)
        two_pi = 2.0 * np.pi
        k0 = np.ceil((psi - seq.phi - 0.5 * np.pi) / two_pi)
        s_first = (0.5 * np.pi + two_pi * k0 - psi + seq.phi) / seq.theta
        k1 = np.floor((big * seq.theta - 0.5 * np.pi + psi - seq.phi) / two_pi)
        s_last = (0.5 * np.pi + two_pi * k1 - psi + seq.phi) / seq.theta
    cplx = seq.kind == 1
    cands += [np.where(cplx, s_first, np.nan)]
    cands += [np.where(cplx & (seq.log_r > 0), s_last, np.nan)]
    real = np.flatnonzero((seq.kind == 2) & (seq.slope_sign(np.ones(size)) > 0))
    s_c = np.full(size, np.nan)
    if real.size:
        sub = seq.take(real)
        hi = np.full(real.size, 2.0)
        for _ in range(80):
            down = sub.slope_sign(hi) < 0
            if down.all():
                break
            hi = np.where(down, hi, 2.0 * hi)
        j = np.flatnonzero(sub.slope_sign(hi) < 0)
        if j.size:
            part = sub.take(j)
            s_c[real[j]] = bracketed_illinois(
                lambda s, m: -part.take(m).slope_sign(s), np.ones(j.size), hi[j], atol=1e-9
            )
    cands.append(s_c)
    cands.append(np.where(seq.kind == 2, 1.0, np.nan))
    for c in cands:
        for m in (np.floor(c), np.ceil(c)):
            ok = np.isfinite(m) & (m >= 0) & (m <= big)
            value = seq.at(np.where(ok, m, 0.0))
            best = np.where(ok, np.maximum(best, value), best)
    return best
