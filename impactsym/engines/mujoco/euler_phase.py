r"""The touch-phase mean of MuJoCo's Euler contact at flat impedance, piece by piece exact.

At flat impedance the in-contact Euler step (:mod:`~impactsym.engines.mujoco.euler`) is
affine, and the first detecting state is a quadratic in the touch phase ``p``
(``X_0 = p + G p^2 / 2``, ``Y_0 = 1 + G p``, in units of ``speed * timestep`` and
``speed``). So every state of the contact is a quadratic in ``p``,

.. math::

    X_{n+1} = X_n + Y_{n+1}, \qquad
    Y_{n+1} = (1 - \beta) Y_n - \kappa X_n + (1 - d') G,

with its coefficients stepped exactly, and so is the force's sign function
``q_n = d' G + beta Y_n + kappa X_n`` (``F_n = q_n`` for the flat impedance). The contact
ends at the first state ``n >= 1`` with ``X_n <= 0`` or ``q_n <= 0``. The steps ``n``
at which that happens for *some* phase are few (two or three); the roots in ``(0, 1)``
of their quadratics split the phase interval into pieces on which the end step ``N`` is
constant, and on each piece the restitution ``-Y_N(p)`` is a quadratic and the contact
time ``(N + p) dt`` linear. The mean over the phase is then the sum of the pieces'
exact integrals, and the range over the phase comes from the pieces' one-sided end
values and the quadratics' vertices: no bisection, no quadrature, one pass over the
steps of the contact for all designs at once (`docs/physics.md#touch-phase`).

Where this does not apply the element is flagged (``ok = False``) and
:func:`~impactsym.engines.mujoco.discrete.phase_summary` takes it the general way: a
body that sticks at some phase (the coast after a force zero re-engages, checked at
three phases of every piece, or the contact does not end within ``_MAX_STEPS``), or more
than ``_MORE_SLOTS`` steps that end the contact for some phase (an element with more
than ``_SLOTS`` is done again alone with ``_MORE_SLOTS``: the work per element grows
with the slots of the worst one).

Internal: used by :mod:`~impactsym.engines.mujoco.discrete`. Dimensionless throughout.
"""

from __future__ import annotations

import numpy as np

from impactsym.engines.mujoco.euler import coast_flat
from impactsym.engines.mujoco.stepmap import spectral_radius

__all__ = ["FlatPhases", "flat_phases"]

_SLOTS = 6  # steps that end the contact at some phase, kept per element
_MORE_SLOTS = 24  # ... for the few elements that need more
_ARGS = ("kappa", "beta", "dp", "G", "bdt", "dkdt2")
_MAX_STEPS = 4096  # steps followed before an element is left to the general summary


class FlatPhases:
    """Phase statistics of :func:`flat_phases` (1-D arrays, one entry per element).

    ``restitution``, ``steps`` (mean of ``N + p``: the contact time in timesteps),
    ``restitution_min``/``_max`` and ``steps_min``/``_max`` over phases in ``(0, 1)``,
    ``stick_fraction`` (the phases that stay in contact for good count as restitution 0
    and make the mean and largest contact time infinite), ``ok`` (where ``False`` the
    other entries are meaningless) and ``sticks_at_some_phase`` (where ``True``, with
    ``ok`` False: a phase was found at which the coast after a force zero is caught
    again, so the body provably sticks at some phase; its share is not resolved here).
    """

    def __init__(self, e, s, e_lo, e_hi, s_lo, s_hi, stick_fraction, ok, caught):
        self.restitution, self.steps, self.ok = e, s, ok
        self.sticks_at_some_phase = caught
        self.stick_fraction = stick_fraction
        self.restitution_min, self.restitution_max = e_lo, e_hi
        self.steps_min, self.steps_max = s_lo, s_hi

    def put(self, i: np.ndarray, other: FlatPhases) -> None:
        """Replace the entries of elements ``i`` by those of ``other`` (in order)."""
        for name, value in vars(other).items():
            getattr(self, name)[i] = value


def flat_phases(*, kappa, beta, dp, G, bdt, dkdt2, slots: int = _SLOTS) -> FlatPhases:
    """Mean and range over the touch phase of the flat-impedance Euler contact.

    Parameters (1-D arrays of one length): ``kappa = d' d kbar dt^2``, ``beta = d' b
    dt``, ``dp = d'``, ``G = g dt / speed``, and ``bdt = b dt``, ``dkdt2 = d kbar dt^2``
    (the coast's force, :func:`~impactsym.engines.mujoco.euler.coast_flat`); ``slots``
    the steps ending the contact at some phase that an element may have.
    """
    size = kappa.size
    x = np.stack([np.zeros(size), np.ones(size), 0.5 * G])  # coefficients of p^0, p^1, p^2
    y = np.stack([np.ones(size), G, np.zeros(size)])
    c_step, c_force = (1.0 - dp) * G, dp * G
    slot_n = np.zeros((slots, size))
    slot_x, slot_q, slot_y = (np.zeros((3, slots, size)) for _ in range(3))
    count = np.zeros(size, int)
    done = np.zeros(size, bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_star = np.where(G > 0, c_step / kappa, 0.0)
    root = np.sqrt(((kappa + beta) ** 2 - 4.0 * kappa).astype(complex))
    lam1, lam2 = 0.5 * (2.0 - kappa - beta + root), 0.5 * (2.0 - kappa - beta - root)
    rest = np.zeros(size, bool)  # proven: no phase that is still in contact ever leaves
    # an unstable map (spectral radius >= 1) is left to the general summary
    live = np.flatnonzero(spectral_radius(kappa=kappa, beta=beta) < 1.0)
    x, y = x[:, live], y[:, live]
    par = [a[live] for a in (kappa, beta, c_step, c_force, x_star, lam1, lam2, G)]
    for n in range(1, _MAX_STEPS + 1):
        if live.size == 0:
            break
        k, b, cs, cf = par[:4]
        y = (1.0 - b) * y - k * x
        y[0] += cs
        x = x + y
        q = b * y + k * x
        q[0] += cf
        x_lo, x_hi = _bounds(x)
        q_lo, q_hi = _bounds(q)
        ends = (x_lo <= 0) | (q_lo <= 0)  # the contact ends at this step for some phase
        j = np.flatnonzero(ends)
        if j.size:
            el, slot = live[j], count[live[j]]
            keep = slot < slots
            el, slot, jj = el[keep], slot[keep], j[keep]
            slot_n[slot, el] = n
            slot_x[:, slot, el] = x[:, jj]
            slot_q[:, slot, el] = q[:, jj]
            slot_y[:, slot, el] = y[:, jj]
            count[live[j]] += 1
        # every phase has ended by now (sufficient: one condition holds at all phases)
        full = (x_hi <= 0) | (q_hi <= 0)
        done[live[full]] = True
        if n % 8 == 0:  # or the phases still in contact never leave it (they stick)
            never = ~full & _never_ends(x, y, *par[:2], *par[4:])
            rest[live[never]] = done[live[never]] = True
            full |= never
        full |= count[live] > slots
        if full.any():
            stay = ~full
            live = live[stay]
            x, y = x[:, stay], y[:, stay]
            par = [a[stay] for a in par]
    ok = done & (count <= slots)
    out = _pieces(slot_n, slot_x, slot_q, slot_y, count, ok, rest, G, bdt, dkdt2, slots)
    more = np.flatnonzero(count > slots)
    if more.size and slots < _MORE_SLOTS:  # the few that need more slots, alone
        args = zip(_ARGS, (kappa, beta, dp, G, bdt, dkdt2), strict=True)
        out.put(more, flat_phases(**{name: a[more] for name, a in args}, slots=_MORE_SLOTS))
    return out


def _never_ends(x, y, kappa, beta, x_star, lam1, lam2, G):
    r"""Whether from these states (quadratics in the phase) neither ``X`` nor ``q`` ever
    reaches 0 again in contact.

    The deviation from the static state decays in the two modes of the step matrix:
    ``H_m - H_* = c_1 \lambda_1^m + c_2 \lambda_2^m`` for a functional ``H`` (``X`` or
    ``q``), ``c_1 = (P - \lambda_2 L) / (\lambda_1 - \lambda_2)``,
    ``c_2 = (\lambda_1 L - P) / (\lambda_1 - \lambda_2)`` with ``L = H_0 - H_*`` and
    ``P = H_1 - H_*``. With ``|\lambda| < 1`` every later value is at least
    ``H_* - |c_1| - |c_2|``, and for real positive eigenvalues at least
    ``H_* + min(0, c_1) - |c_2|`` (the slow mode creeps to the static state from one
    side; taken at the current state, ``m = 0``). Bounds over the phase: coefficient-wise.
    """
    wx = x - np.stack([x_star, 0 * x_star, 0 * x_star])
    ax = (1.0 - kappa) * wx + (1.0 - beta) * y  # the deviation one step on
    ay = -kappa * wx + (1.0 - beta) * y
    real = (lam1.imag == 0) & (lam2.real > 0) & (lam1.real < 1) & (lam1 != lam2)
    stable = (np.abs(lam1) < 1) & (np.abs(lam2) < 1) & (lam1 != lam2)
    out = stable & (G > 0)
    for L, P, h_star in ((wx, ax, x_star), (kappa * wx + beta * y, kappa * ax + beta * ay, G)):
        with np.errstate(all="ignore"):
            c1 = (P - lam2 * L) / (lam1 - lam2)  # (3, size): coefficients in the phase
            c2 = (lam1 * L - P) / (lam1 - lam2)
        size2 = np.abs(c2).sum(axis=0)
        c1_lo, _ = _bounds(c1.real)
        lower_real = h_star + np.minimum(0.0, c1_lo) - size2
        lower_any = h_star - np.abs(c1).sum(axis=0) - size2
        out &= np.where(real, lower_real, lower_any) > 0
    return out


def _bounds(c):
    """Smallest and largest value over ``[0, 1]`` of the quadratics ``c[0] + c[1] p + c[2] p^2``."""
    f0, f1 = c[0], c[0] + c[1] + c[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        pv = -c[1] / (2.0 * c[2])
        fv = c[0] - 0.25 * c[1] * c[1] / c[2]
    inside = (pv > 0) & (pv < 1)
    lo, hi = np.minimum(f0, f1), np.maximum(f0, f1)
    return np.where(inside, np.minimum(lo, fv), lo), np.where(inside, np.maximum(hi, fv), hi)


def _roots(c):
    """Both roots of each quadratic in ``(0, 1)``, else 1 (stable: no cancellation)."""
    a0, a1, a2 = c
    with np.errstate(all="ignore"):
        disc = a1 * a1 - 4.0 * a0 * a2
        h = -0.5 * (a1 + np.copysign(np.sqrt(disc), a1))
        r = np.stack([h / a2, a0 / h])
    return np.where(np.isfinite(r) & (r > 0) & (r < 1) & (disc >= 0), r, 1.0)


def _value(c, p):
    return c[0] + p * (c[1] + p * c[2])


def _pieces(slot_n, slot_x, slot_q, slot_y, count, ok, rest, G, bdt, dkdt2, slots) -> FlatPhases:
    """The pieces of constant end step, their integrals and extremes (module docstring)."""
    size = count.size
    slots = int(min(count.max(initial=1), slots))  # the slots in use anywhere
    slot_n = slot_n[:slots]
    slot_x, slot_q, slot_y = (a[:, :slots] for a in (slot_x, slot_q, slot_y))
    used = np.arange(slots)[:, None] < np.minimum(count, slots)[None, :]  # (S, size)
    # the last slot of an element that does not rest ends every phase still in contact
    # (the steps stop there because one condition holds at all phases): it cuts nothing
    last = (np.arange(slots)[:, None] == count[None, :] - 1) & ~rest[None, :]
    cuts = [np.zeros((1, size)), np.ones((1, size))]
    cutting = used & ~last
    rows = slots if rest.any() else slots - 1  # the top slot cuts only where one rests
    for c in (slot_x, slot_q):
        r = _roots(c[:, :rows])  # (2, rows, size)
        cuts.append(np.where(cutting[None, :rows], r, 1.0).reshape(-1, size))
    edges = np.sort(np.concatenate(cuts), axis=0)  # (P + 1, size)
    edges = edges[: int((edges < 1.0).sum(axis=0).max()) + 1]  # no empty pieces at 1
    p0, p1 = edges[:-1], edges[1:]
    mid = 0.5 * (p0 + p1)
    # the first slot at which the contact ends for the phases of each piece (the top
    # slot, where nothing rests, is some element's last or unused: no values needed)
    first = np.zeros(mid.shape, int)
    found = np.zeros(mid.shape, bool)
    for s in range(slots):
        ends = last[s] if s == rows else last[s] | (_value(slot_x[:, s, None], mid) <= 0)
        if s < rows:
            ends = ends | (_value(slot_q[:, s, None], mid) <= 0)
        ends = ends & used[s] & ~found
        first[ends] = s
        found |= ends
    width = p1 - p0
    real = width > 0
    stuck = real & ~found & rest[None, :]  # still in contact for good: sticks
    ok = ok & np.all(found | stuck | ~real, axis=0)
    real &= ~stuck
    stick_fraction = np.where(stuck, width, 0.0).sum(axis=0)
    cols = np.arange(size)[None, :]
    N = slot_n[first, cols]
    a0, a1, a2 = (-slot_y[i][first, cols] for i in range(3))  # restitution -Y_N(p)
    e_int = a0 * width + a1 * (p1**2 - p0**2) / 2.0 + a2 * (p1**3 - p0**3) / 3.0
    s_int = N * width + (p1**2 - p0**2) / 2.0
    e_mean = np.where(real, e_int, 0.0).sum(axis=0)
    s_mean = np.where(stick_fraction > 0, np.inf, np.where(real, s_int, 0.0).sum(axis=0))
    e0, e1 = a0 + p0 * (a1 + p0 * a2), a0 + p1 * (a1 + p1 * a2)
    with np.errstate(divide="ignore", invalid="ignore"):
        pv = -a1 / (2.0 * a2)
        ev = a0 + pv * (a1 + pv * a2)
    inside = (pv > p0) & (pv < p1)
    lo = np.where(inside, np.minimum(np.minimum(e0, e1), ev), np.minimum(e0, e1))
    hi = np.where(inside, np.maximum(np.maximum(e0, e1), ev), np.maximum(e0, e1))
    e_min = np.where(real, lo, np.inf).min(axis=0)
    e_max = np.where(real, hi, -np.inf).max(axis=0)
    s_min = np.where(real, N + p0, np.inf).min(axis=0)
    s_max = np.where(stick_fraction > 0, np.inf, np.where(real, N + p1, -np.inf).max(axis=0))
    e_min = np.where(stick_fraction > 0, np.minimum(e_min, 0.0), e_min)
    e_max = np.where(stick_fraction > 0, np.maximum(e_max, 0.0), e_max)
    # the coast after a force zero must not re-engage (else: sticks, the general way)
    caught = np.zeros(size, bool)
    gravity = np.flatnonzero(ok & (G > 0))
    if gravity.size:
        g_cols = first[:, gravity], gravity[None, :]
        cx = [slot_x[i][g_cols] for i in range(3)]
        cy = [slot_y[i][g_cols] for i in range(3)]
        g0, g_width, g_real, Gg = p0[:, gravity], width[:, gravity], real[:, gravity], G[gravity]
        for frac in (1e-9, 0.5, 1.0 - 1e-9):
            p = g0 + frac * g_width
            X = cx[0] + p * (cx[1] + p * cx[2])
            Y = cy[0] + p * (cy[1] + p * cy[2])
            # a body that is out at the next state (X + Y + G <= 0) cannot stick: only
            # the others need coast_flat's integer check
            pi, ei = np.nonzero(g_real & (X > 0) & (X + Y + Gg > 0))
            if pi.size == 0:
                continue
            el = gravity[ei]
            sticks, _ = coast_flat(X[pi, ei], Y[pi, ei], G[el], bdt[el], dkdt2[el])
            ok[el[sticks]] = False
            caught[el[sticks]] = True
    return FlatPhases(e_mean, s_mean, e_min, e_max, s_min, s_max, stick_fraction, ok, caught)
