r"""The touch phase averaged out: mean and range over phases of LAMMPS's discrete contact.

For a fixed state index ``j`` the state ``j`` is ``M^j y_0(p)`` with ``y_0`` quadratic in
the phase ``p`` (:mod:`~impactsym.engines.lammps.verlet`: ``x_0 = p tau + L (p tau)^2 /
2``, ``w_0 = 1 + L (p - 1/2) tau``), so its end threshold ``phi_j(p)`` and its velocity
are quadratics in ``p`` with closed-form coefficients. The end state ``n(p)`` is the first
``j`` with ``phi_j(p) <= 0``. It is found (:func:`~impactsym.engines.lammps.verlet.verlet_phase`)
at ``p = 0`` (the limit from above) and just below ``p = 1``; the window ``j`` from one
below the smaller to one above the larger holds every end state, and the roots in
``(0, 1)`` of the window's quadratics split the phases into pieces of one end state (the
first ``j`` of the window with ``phi_j <= 0`` at the piece's middle). On each piece the
restitution is a known quadratic and the contact time ``(p + n) tau`` linear in ``p``:
their integrals and extremes are exact. The states before the window are assumed not to
end the contact at any phase (they are a step or more from the end at both ``p = 0`` and
``p -> 1``); a piece whose middle ends outside the window is solved at its middle.
Whether the body, after a force end inside the overlap, sticks (its force comes back) is
decided at each piece's middle: a sticking piece counts with restitution 0 and contact
time ``inf``.
"""

from __future__ import annotations

import numpy as np

from impactsym.engines.lammps.verlet import StepMap, coast, verlet_phase

__all__ = ["phase_statistics"]

#: width of the window of end states (beyond one below and one above the two ends)
_WINDOW = 4


def _quadratic_roots(a0, a1, a2):
    """Both real roots of ``a0 + a1 p + a2 p^2`` (``nan`` where absent), cancellation-free."""
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = a1 * a1 - 4.0 * a2 * a0
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        q = -0.5 * (a1 + np.copysign(sq, a1))
        r1 = np.where(a2 != 0, q / a2, -a0 / a1)
        r2 = np.where(a2 != 0, a0 / q, np.nan)
    return r1, r2


def phase_statistics(D, load, tau, limit_damping: bool) -> dict:
    """Mean and (min, max) over ``phase`` in ``[0, 1)`` of restitution and contact time.

    Normalized 1-D arrays in, a dict of arrays out: ``restitution``, ``contact_time``
    (means; ``inf`` if the body sticks at some phase), ``restitution_min/max``,
    ``contact_time_min/max``, ``sticks_somewhere``.
    """
    D, L, tau = (np.asarray(a, dtype=float).ravel() for a in np.broadcast_arrays(D, load, tau))
    size = D.size
    ends = [
        verlet_phase(D, L, tau, p, limit_damping, extremes=False)["steps"]
        for p in (0.0, np.nextafter(1.0, 0.0))
    ]
    known = np.where(np.isfinite(ends[0]), ends[0], ends[1])
    lower = np.where(np.isfinite(ends[1]), np.minimum(ends[1], known), known)
    start = np.maximum(np.where(np.isfinite(lower), lower, 1.0) - 1.0, 1.0)
    J = start[:, None] + np.arange(_WINDOW)  # (size, W)
    m = StepMap(np.repeat(D, _WINDOW), np.repeat(tau, _WINDOW))
    ix = np.arange(size * _WINDOW)
    cw = (2.0 * D if limit_damping else np.zeros_like(D))[:, None]
    Lc, Tc = L[:, None], tau[:, None]
    zero = np.zeros_like(J)
    vecs = [  # y_0(p) = u + p v + p^2 w
        (-Lc + zero, 1.0 - 0.5 * Lc * Tc + zero),
        (Tc + zero, Lc * Tc + zero),
        (0.5 * Lc * Tc * Tc + zero, zero),
    ]
    powered = [
        tuple(c.reshape(J.shape) for c in m.apply(J.ravel(), vx.ravel(), vw.ravel(), ix))
        for vx, vw in vecs
    ]
    A = [Lc + powered[0][0] + cw * powered[0][1]]
    A += [px + cw * pw for px, pw in powered[1:]]  # phi_j = A0 + A1 p + A2 p^2
    Bv = [powered[0][1] + 0.5 * Lc * Tc, powered[1][1], powered[2][1]]  # v_j
    Bx = [Lc + powered[0][0], powered[1][0], powered[2][0]]  # x_j
    r1, r2 = _quadratic_roots(*A)
    cuts = np.concatenate([r1, r2], axis=1)
    cuts = np.where((cuts > 0) & (cuts < 1), cuts, 1.0)
    points = np.sort(np.concatenate([np.zeros((size, 1)), cuts, np.ones((size, 1))], axis=1), 1)
    a, b = points[:, :-1], points[:, 1:]
    mid = 0.5 * (a + b)
    live = b > a
    # end state of each piece: first j of the window with phi_j(mid) <= 0
    phi_mid = A[0][:, None, :] + mid[:, :, None] * (
        A[1][:, None, :] + mid[:, :, None] * A[2][:, None, :]
    )
    ended = phi_mid <= 0
    first = np.argmax(ended, axis=2)
    inside = np.any(ended, axis=2)
    pick = np.take_along_axis
    coef = [pick(c[:, None, :].repeat(a.shape[1], 1), first[:, :, None], 2)[:, :, 0] for c in Bv]
    xco = [pick(c[:, None, :].repeat(a.shape[1], 1), first[:, :, None], 2)[:, :, 0] for c in Bx]
    n = pick(J[:, None, :].repeat(a.shape[1], 1), first[:, :, None], 2)[:, :, 0]
    stuck = ~inside
    out_of_window = live & ~inside
    if out_of_window.any():  # solve at the middle (never or beyond the window)
        rows, cols = np.nonzero(out_of_window)
        r = verlet_phase(
            D[rows], L[rows], tau[rows], mid[rows, cols], limit_damping, extremes=False
        )
        stuck[rows, cols] = ~np.isfinite(r["steps"])
        n[rows, cols] = np.where(np.isfinite(r["steps"]), r["steps"], 0.0)
        v_mid = -r["restitution"]
        for c in (coef, xco):
            c[1][rows, cols] = 0.0
            c[2][rows, cols] = 0.0
        coef[0][rows, cols] = v_mid
        xco[0][rows, cols] = 1.0  # a position end is not coasted
    # a force end inside the overlap: the coast decides (at the middle)
    x_end = xco[0] + mid * (xco[1] + mid * xco[2])
    v_end = coef[0] + mid * (coef[1] + mid * coef[2])
    coasting = live & ~stuck & (x_end > 0) & limit_damping
    if coasting.any():
        rows, cols = np.nonzero(coasting)
        w_end = v_end[rows, cols] - 0.5 * tau[rows] * L[rows]
        sticks, _, _ = coast(x_end[rows, cols], w_end, D[rows], L[rows], tau[rows])
        stuck[rows, cols] = sticks
    width = np.where(live, b - a, 0.0)
    c0, c1, c2 = (np.where(stuck, 0.0, -c) for c in coef)  # restitution = -v
    integral = c0 * width + c1 * (b * b - a * a) / 2.0 + c2 * (b**3 - a**3) / 3.0
    with np.errstate(invalid="ignore", divide="ignore"):
        vertex = np.where(c2 != 0, -c1 / (2.0 * c2), a)
    vertex = np.clip(vertex, a, b)
    values = [c0 + p * (c1 + p * c2) for p in (a, b, vertex)]
    e_min = np.min([np.min(np.where(live, v, np.inf), axis=1) for v in values], axis=0)
    e_max = np.max([np.max(np.where(live, v, -np.inf), axis=1) for v in values], axis=0)
    ta = np.where(stuck, np.inf, (a + n) * tau[:, None])
    tb = np.where(stuck, np.inf, (b + n) * tau[:, None])
    with np.errstate(invalid="ignore"):
        t_mean = np.sum(np.where(live, 0.5 * (ta + tb) * width, 0.0), axis=1)
    t_min = np.min(np.where(live, ta, np.inf), axis=1)
    t_max = np.max(np.where(live, tb, -np.inf), axis=1)
    return {
        "restitution": np.sum(np.where(live, integral, 0.0), axis=1),
        "contact_time": t_mean,
        "restitution_min": e_min,
        "restitution_max": e_max,
        "contact_time_min": t_min,
        "contact_time_max": t_max,
        "sticks_somewhere": np.any(live & stuck, axis=1),
    }
