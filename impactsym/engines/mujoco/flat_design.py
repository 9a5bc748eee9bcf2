r"""The flat-impedance continuous design of MuJoCo's ``solref`` (the limit ``timestep -> 0``).

For a flat ``solimp`` the contact is the loaded oscillator of
:mod:`~impactsym.engines.mujoco.model` with the constant impedance ``d``; with
``solref = (tc, dr)`` its coefficients are

.. math::

    D = \mathrm{dr}\,\sqrt{d'/d}, \qquad
    \omega_0 = \frac{\sqrt{d' d}}{d_\max\,\mathrm{tc}\,\mathrm{dr}}, \qquad
    \gamma = \frac{g}{\omega_0 v_0}

(``b = 2/(d_max tc)``, ``kbar = 1/(d_max tc dr)^2``). The design inverts
:func:`~impactsym.engines.mujoco.continuous.flat_phase` (one release kernel,
:func:`impactsym.contact.release.linear_release`, about 0.15 s per 10^5 contacts):

* **gravity 0**: the force vanishes first (the paper's force condition), so
  ``e = exp(-2 h(D))`` with the closed form ``h`` of
  :func:`impactsym.contact.unpressed.force_exponent`; ``D`` is found by a bracketed Newton
  iteration in ``log D`` on the closed form (no kernel evaluation) and mapped back by
  ``dr = D sqrt(d/d')``; a wanted contact time scales the timeconst
  (``t_c = tau_c(D)/omega_0`` is proportional to ``tc``).
* **gravity > 0, restitution only**: from the gravity-0 design, secant steps in
  ``log dr`` (the first slope the gravity-0 closed form's), each inside the bracket the
  evaluated signs verify (``e`` falls with ``dr``; bisection where a step would leave it);
  about four kernel evaluations where the nested brackets took twenty.
* **gravity > 0 with a contact time**: Broyden's method in ``(log tc, log dr)`` from the
  gravity-0 design, its first Jacobian the gravity-0 closed form's (``e`` depends on
  ``D`` alone, ``log t_c = log tau_c(D) + log tc + log dr + const``); one kernel
  evaluation per iteration, steps bounded, halved back where the contact sticks.

An element is accepted when its residual is below ``1e-11`` (relative in the restitution
and in the contact time) and its root lies in the bracket the fallback searches
(``dr`` in ``[1e-3, 100]``, ``tc`` in ``[1e-6, 1e3]``); it then takes one more
(unevaluated) step, which leaves an error far below the tolerance. The others (targets
near a jump of the restitution or near sticking, out of reach, or slow to converge) go
to the bracketed methods, which find what is reachable and refuse the rest with its
cause, naming the element (`docs/physics.md#simulation-engines`). Internal:
:mod:`~impactsym.engines.mujoco.design` reads it. SI units throughout.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.contact.unpressed import force_exponent
from impactsym.engines.mujoco.continuous import ContactPhase, flat_phase
from impactsym.engines.mujoco.model import coefficients, d_max, effective_impedance, impedance_at
from impactsym.numeric.roots import bracketed_illinois, bracketed_newton

__all__ = ["design_flat_both", "design_flat_dampratio", "flat_restitution", "unreachable"]

_DR_RANGE = (1e-3, 1e2)  # the dampratios the bracketed design searches
_TC_RANGE = (1e-6, 1e3)  # the timeconsts its inner bracket searches
_MAX_ITER = 16  # fast iterations before an element goes to the bracketed method
_RTOL = 1e-11  # accepted residual, relative (restitution and contact time)
_FD = 1e-5  # relative step of the central differences on the closed form


def unreachable(
    what: str, mask: np.ndarray, targets: np.ndarray, hint: str, index: Any = None
) -> None:
    """Raise ``ValueError`` for the first element of ``mask``, naming it (``index``: the
    caller's numbers of the elements, default their positions) and its target."""
    if mask.any():
        first = np.flatnonzero(mask)[0]
        number = first if index is None else int(np.asarray(index)[first])
        raise ValueError(
            f"restitution = {float(targets.flat[first])!r} (element {number}) cannot be "
            f"reached: {what}; {hint}"
        )


def flat_restitution(tc, dr, simp, rho, g, v0, *, extremes: bool = True) -> ContactPhase:
    """The contact phase at ``solref = (tc, dr)`` for a flat ``simp`` (closed form)."""
    d = float(impedance_at(np.zeros(()), simp))
    return flat_phase(coefficients((tc, dr), simp, None), d, rho, g, v0, extremes=extremes)


def _scales(simp, rho):
    """``a = D/dr = sqrt(d'/d)``, ``K = omega_0 tc dr = sqrt(d' d)/d_max`` and ``1 - d'``
    per element."""
    d = float(impedance_at(np.zeros(()), simp))
    dp = effective_impedance(d, np.asarray(rho, float))
    return np.sqrt(dp / d), np.sqrt(dp * d) / d_max(simp), 1.0 - dp


def _unpressed(D):
    """``tau_c``, ``h`` and their derivatives in ``log D``: ``h' = (tau_c/2 - D)/(1 - D^2)``
    on both sides of ``D = 1`` (``D psi / w``, ``D phi / sigma`` differentiated, with
    ``psi/w = phi/sigma = tau_c/2``), ``2/3`` within ``1e-6`` of it where the quotient
    cancels; ``tau_c'`` by a central difference of the closed form (only the first
    Jacobian of :func:`_broyden` needs it)."""
    tau, h = force_exponent(D)
    near = np.abs(1.0 - D) <= 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):
        dh = np.where(near, 2.0 / 3.0, (0.5 * tau - D) / ((1.0 - D) * (1.0 + D))) * D
    tau_p, tau_m = force_exponent(D * np.exp(_FD))[0], force_exponent(D * np.exp(-_FD))[0]
    return tau, h, np.log(tau_p / tau_m) / (2 * _FD), dh


def _h_dh(u, big, b1, b2):
    """``h(D) - log(1 - b1 D - b2 D^2)/2 - big`` and its derivative in ``u = log D``
    (``h' = (tau_c/2 - D)/(1 - D^2)``, :func:`_unpressed`)."""
    D = np.exp(u)
    tau, h = force_exponent(D)
    near = np.abs(1.0 - D) <= 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):
        dh = np.where(near, 2.0 / 3.0, (0.5 * tau - D) / ((1.0 - D) * (1.0 + D))) * D
    q = 1.0 - b1 * D - b2 * D * D
    return h - 0.5 * np.log(q) - big, dh + 0.5 * (b1 * D + 2 * b2 * D * D) / q


def _free_damping_ratio(e_t, a):
    """``D`` with ``exp(-2 h(D)) = e_t`` (the unpressed force condition), Newton in
    ``log D`` inside the bracket of the dampratios ``[1e-3, 100]``; ``inside`` says where
    that bracket holds the target (elsewhere ``D`` is the nearer end). The bracket is
    first narrowed to ``+-0.01`` around the root of a table of ``h`` (checked by the
    signs at its ends), so that Newton needs few steps."""
    big = -0.5 * np.log(e_t)  # h wanted
    zero = np.zeros(e_t.shape)
    u_lo, u_hi = np.log(a * _DR_RANGE[0]), np.log(a * _DR_RANGE[1])
    h_lo = _h_dh(u_lo, big, zero, zero)[0]
    h_hi = _h_dh(u_hi, big, zero, zero)[0]
    inside = (h_lo < 0) & (h_hi >= 0)
    u = np.where(h_lo >= 0, u_lo, u_hi)
    k = np.flatnonzero(inside)
    if k.size:
        grid = np.linspace(-25.0, 25.0, 501)
        guess = np.interp(big[k], force_exponent(np.exp(grid))[1], grid)
        lo, hi = np.maximum(guess - 0.01, u_lo[k]), np.minimum(guess + 0.01, u_hi[k])
        par = [big[k], zero[k], zero[k]]
        g_lo, g_hi = _h_dh(lo, *par)[0], _h_dh(hi, *par)[0]
        wide = ~((g_lo < 0) & (g_hi >= 0))
        lo, g_lo = np.where(wide, u_lo[k], lo), np.where(wide, h_lo[k], g_lo)
        hi, g_hi = np.where(wide, u_hi[k], hi), np.where(wide, h_hi[k], g_hi)
        u[k] = bracketed_newton(_h_dh, None, lo, hi, par, rtol=1e-14, g_lo=g_lo, g_hi=g_hi)
    return np.exp(u), inside


def _first_order(e_t, D0, b1, b2):
    """``D`` of the first-order gravity model ``e = e0(D) (1 - b1 D - b2 D^2)`` near the
    gravity-0 ``D0`` (module notes); ``D0`` where the model's correction is not small."""
    big = -0.5 * np.log(e_t)
    u0 = np.log(D0)
    small = b1 * D0 + b2 * D0 * D0 < 0.25
    D = D0.copy()
    if small.any():
        k = np.flatnonzero(small)
        par = [big[k], b1[k], b2[k]]
        lo = u0[k] - 1.0
        g_lo = _h_dh(lo, *par)[0]
        g_hi = _h_dh(u0[k], *par)[0]
        sign = (g_lo < 0) & (g_hi > 0)
        k, lo, g_lo, g_hi = k[sign], lo[sign], g_lo[sign], g_hi[sign]
        par = [big[k], b1[k], b2[k]]
        D[k] = np.exp(
            bracketed_newton(_h_dh, None, lo, u0[k], par, rtol=1e-12, g_lo=g_lo, g_hi=g_hi)
        )
    return D


def design_flat_dampratio(e_t, v0, g, tc, simp, rho, *, index: Any = None) -> np.ndarray:
    """Dampratio with timeconst ``tc`` giving restitution ``e_t`` (flat impedance).

    Gravity 0 by the closed form, gravity > 0 by secant steps from it (module notes);
    elements that fail go to :func:`_bracketed_dampratio`, which refuses an unreachable
    target with its cause, naming the element by ``index`` (default: its position).
    """
    index = np.arange(e_t.size) if index is None else np.asarray(index)
    rho = np.broadcast_to(np.asarray(rho, float), e_t.shape)
    a, scale, soft = _scales(simp, rho)
    D, inside = _free_damping_ratio(e_t, a)
    dr = D / a
    free = g == 0
    good = free & inside
    loaded = np.flatnonzero(~free)
    if loaded.size:
        j = loaded
        # the first-order gravity model: gamma = g tc D / (a K v0), so b2 = 2 (1 - d') gamma / D
        b2 = 2.0 * soft[j] * g[j] * tc[j] / (a[j] * scale[j] * v0[j])
        D1 = _first_order(e_t[j], D[j], np.zeros(j.size), b2)
        _, _, _, dh = _unpressed(D1)
        q = 1.0 - b2 * D1 * D1
        slope = e_t[j] * (-2.0 * dh - 2.0 * b2 * D1 * D1 / q)  # the model's de/dlog dr
        x, ok = _secant(e_t, v0, g, tc, simp, rho, j, np.log(D1 / a[j]), slope)
        dr[loaded] = np.exp(x)
        good[loaded] = ok
    rest = np.flatnonzero(~good)
    if rest.size:
        part = (q[rest] for q in (e_t, v0, g, tc))
        dr[rest] = _bracketed_dampratio(*part, simp, rho[rest], index=index[rest])
    return dr


def _secant(e_t, v0, g, tc, simp, rho, idx, x, slope):
    """Secant steps in ``x = log dr`` for the elements ``idx`` (module notes); returns the
    roots and where they were accepted."""
    lo, hi = np.full(x.size, -np.inf), np.full(x.size, np.inf)
    x_prev, f_prev = np.full(x.size, np.nan), np.full(x.size, np.nan)
    root, last = np.full(x.size, np.nan), np.full(x.size, np.nan)
    active = np.arange(x.size)
    for _ in range(_MAX_ITER):
        if active.size == 0:
            break
        k = idx[active]
        xa = x[active]
        e = flat_restitution(tc[k], np.exp(xa), simp, rho[k], g[k], v0[k], extremes=False)
        f = e.restitution - e_t[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (f - f_prev[active]) / (xa - x_prev[active])
        s = np.where(np.isfinite(s) & (s < 0), s, slope[active])
        slope[active] = s
        la = np.where(f > 0, xa, lo[active])
        ha = np.where(f < 0, xa, hi[active])
        step = np.clip(-f / s, -1.0, 1.0)
        new = xa + step
        inside = (new > la) & (new < ha)
        done = (np.abs(f) <= _RTOL * e_t[k]) | (inside & _settled(f / e_t[k], step, last[active]))
        # (then the last, tiny, step polishes the root)
        new = np.where(done | inside, new, 0.5 * (la + ha))
        root[active[done]] = new[done]
        last[active] = np.where(inside, step, np.nan)  # a bisection starts afresh
        lo[active], hi[active] = la, ha
        x_prev[active], f_prev[active], x[active] = xa, f, new
        active = active[~done]
    ok = (root >= np.log(_DR_RANGE[0])) & (root <= np.log(_DR_RANGE[1]))
    return np.where(ok, root, x), ok


def _settled(residual, step, last):
    """Where a secant or Broyden step ``step`` after ``last`` lands within about
    ``1e-13`` of the root: their error shrinks like ``C |step| |last|`` (superlinear
    convergence), taken where both steps are small and the relative ``residual`` is
    below ``1e-6`` (no jump is being straddled)."""
    with np.errstate(invalid="ignore"):
        return (np.abs(residual) <= 1e-6) & (np.abs(step) <= 1e-6) & (np.abs(step * last) <= 1e-13)


def _bracketed_dampratio(e_t, v0, g, tc, simp, rho, *, index):
    """The bracketed design of the dampratio (Illinois in ``log dr`` on ``[1e-3, 100]``);
    refusals name the elements by ``index``."""
    n = e_t.size
    # the last dampratio tried and its restitution, per element: the gap check below
    # reads the restitution at the root the solver last evaluated instead of redoing it
    last_dr, last_e = np.full(n, np.nan), np.full(n, np.nan)

    def e_of(dr, idx):
        e = flat_restitution(tc[idx], dr, simp, rho[idx], g[idx], v0[idx], extremes=False)
        last_dr[idx], last_e[idx] = dr, e.restitution
        return e.restitution

    def e_at(dr):
        known = last_dr == dr
        if known.all():
            return last_e.copy()
        out = last_e.copy()
        out[~known] = e_of(dr[~known], np.flatnonzero(~known))
        return out

    # e falls with the dampratio, continuously or by a jump where the release switches
    # from the force to the penetration (then refused below); one bracket suffices
    idx = np.arange(n)
    # the ends as the solver (in log dampratio) sees them, so their restitutions serve it
    lo, hi = (np.exp(np.log(np.full(n, q))) for q in _DR_RANGE)
    e_lo = e_of(lo, idx)
    unreachable(
        "the body sticks or rebounds too slowly for every dampratio in [1e-3, 100]",
        e_lo <= e_t,
        e_t,
        "a higher speed, less gravity or a shorter timeconst (contact_time=...) reaches it",
        index,
    )
    e_hi = e_of(hi, idx)
    hi = np.where(e_hi <= e_t, hi, np.nan)
    unreachable(
        "even dampratio = 100 rebounds faster",
        np.isnan(hi),
        e_t,
        "a lower speed or more gravity reaches it",
        index,
    )
    dr = bracketed_illinois(
        lambda x, i: e_t[i] - e_of(x, i),
        lo,
        hi,
        log=True,
        rtol=1e-10,
        f_lo=e_t - e_lo,
        f_hi=e_t - e_hi,
    )

    def stuck(x):
        return np.isinf(flat_restitution(tc, x, simp, rho, g, v0, extremes=False).contact_time)

    e_dr = lambda x: e_at(x) if x is dr else e_of(x, idx)  # noqa: E731
    _check_gap(e_dr, e_t, dr, "dampratio", stuck, index)
    return dr


def _check_gap(e_of, e_t, at, name, stuck, index):
    """Refuse a target the solver could not reach: the body starts to stick there, or the
    restitution jumps where the release switches from force to position.

    ``stuck(x)`` says where the design at ``x`` sticks (for a wanted contact time: where
    no timeconst gives it without sticking); ``index`` numbers the elements.
    """
    achieved = e_of(at)
    miss = np.abs(achieved - e_t) > 1e-6 * np.maximum(e_t, 1e-3)
    if not miss.any():
        return
    i = np.flatnonzero(miss)[0]
    below, above = e_of(at * (1 - 1e-7))[i], e_of(at * (1 + 1e-7))[i]
    start = f"restitution = {float(e_t[i])!r} (element {int(index[i])}) cannot be reached: "
    hint = "a higher speed, less gravity or another contact_time"
    if any(stuck(at * (1 + step))[i] for step in (1e-7, 1e-5, 1e-3)):
        raise ValueError(
            f"{start}the body starts to stick at {name} = {float(at[i]):.6g}, where the "
            f"restitution is still {max(below, above):.4g}; with more damping it sticks, "
            f"so smaller targets are out of reach here; {hint} reaches them"
        )
    raise ValueError(
        f"{start}at {name} = {float(at[i]):.6g} the restitution jumps from {below:.4g} to "
        f"{above:.4g} (the force no longer vanishes before the penetration does), so "
        f"targets in between are out of reach here; {hint} moves the jump"
    )


def design_flat_both(e_t, v0, g, t_c, simp, rho) -> tuple[np.ndarray, np.ndarray]:
    """``(timeconst, dampratio)`` for restitution ``e_t`` and contact time ``t_c`` (flat).

    Without gravity the restitution depends on the dampratio alone and the contact time
    is proportional to the timeconst (both coefficients scale with ``1/timeconst``): the
    dampratio of the restitution at timeconst 1, then the timeconst scaled to ``t_c``.
    With gravity, Broyden's method from that design (module notes); the elements it does
    not settle go to the nested brackets (:func:`_nested_both`).
    """
    rho = np.broadcast_to(np.asarray(rho, float), e_t.shape)
    a, scale, soft = _scales(simp, rho)
    free = np.flatnonzero(g == 0)
    loaded = np.flatnonzero(g != 0)
    tc, dr = np.empty(e_t.size), np.empty(e_t.size)
    if free.size:
        one = np.ones(free.size)
        part = (q[free] for q in (e_t, v0, g))
        dr[free] = design_flat_dampratio(*part, one, simp, rho[free], index=free)
        tau = force_exponent(a[free] * dr[free])[0]
        tc[free] = t_c[free] * scale[free] / (tau * dr[free])  # t_c = tau tc dr / K
    if loaded.size:
        j = loaded
        e_l = e_t[j]
        D0, _ = _free_damping_ratio(e_l, a[j])
        # the first-order gravity model by fixed-point steps: gamma = g t_c / (tau v0),
        # tau = tau0(D) + gamma (1 + (1 - d') e0) / e0, e0 (1 - 2 (1 - d') gamma D) = e_t
        D, gamma = D0, np.zeros(j.size)
        for _ in range(3):
            tau, h, dtau, dh = _unpressed(D)
            e0 = np.exp(-2.0 * h)
            tau = tau + gamma * (1.0 + soft[j] * e0) / e0
            gamma = g[j] * t_c[j] / (tau * v0[j])
            D = _first_order(e_l, D0, 2.0 * soft[j] * gamma, np.zeros(j.size))
        dr0 = D / a[j]
        tc0 = scale[j] * gamma * v0[j] / (g[j] * dr0)  # omega_0 = g / (gamma v0) = K / (tc dr)
        jac = np.zeros((loaded.size, 2, 2))  # rows (e, log t_c), columns (log tc, log dr)
        jac[:, 0, 1] = -2.0 * e_l * dh
        jac[:, 1, 0] = 1.0
        jac[:, 1, 1] = 1.0 + dtau
        y = np.stack([np.log(tc0), np.log(dr0)], axis=1)
        y, ok = _broyden(e_t, v0, g, t_c, simp, rho, loaded, y, jac)
        tc[loaded], dr[loaded] = np.exp(y[:, 0]), np.exp(y[:, 1])
        rest = loaded[~ok]
        if rest.size:
            part = (q[rest] for q in (e_t, v0, g, t_c, rho))
            tc[rest], dr[rest] = _nested_both(*part, simp, index=rest)
    return tc, dr


def _broyden(e_t, v0, g, t_c, simp, rho, idx, y, jac):
    """Broyden's method in ``y = (log tc, log dr)`` for the elements ``idx`` (module
    notes); returns the roots and where they were accepted."""
    m = idx.size
    y_prev, r_prev = np.full((m, 2), np.nan), np.full((m, 2), np.nan)
    root, last = np.full((m, 2), np.nan), np.full(m, np.nan)
    active = np.arange(m)
    for _ in range(_MAX_ITER):
        if active.size == 0:
            break
        k, ya, ja = idx[active], y[active], jac[active]
        ph = flat_restitution(
            np.exp(ya[:, 0]), np.exp(ya[:, 1]), simp, rho[k], g[k], v0[k], extremes=False
        )
        with np.errstate(divide="ignore", over="ignore"):
            r = np.stack([ph.restitution - e_t[k], np.log(ph.contact_time / t_c[k])], axis=1)
        stuck = ~np.isfinite(r).all(axis=1)
        dy, dr = ya - y_prev[active], r - r_prev[active]
        norm = (dy * dy).sum(axis=1)
        upd = ~stuck & np.isfinite(dy).all(axis=1) & (norm > 0)
        if upd.any():  # the rank-one secant update J += (dr - J dy) dy^T / |dy|^2
            miss = dr[upd] - np.einsum("nij,nj->ni", ja[upd], dy[upd])
            ja[upd] += miss[:, :, None] * dy[upd][:, None, :] / norm[upd][:, None, None]
        det = ja[:, 0, 0] * ja[:, 1, 1] - ja[:, 0, 1] * ja[:, 1, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = -np.stack(
                [
                    (ja[:, 1, 1] * r[:, 0] - ja[:, 0, 1] * r[:, 1]) / det,
                    (ja[:, 0, 0] * r[:, 1] - ja[:, 1, 0] * r[:, 0]) / det,
                ],
                axis=1,
            )
            step /= np.maximum(1.0, np.abs(step).max(axis=1) / 0.5)[:, None]
        back = y_prev[active] + 0.5 * (ya - y_prev[active])  # halfway back from sticking
        new = np.where(stuck[:, None], back, ya + step)
        rel = np.maximum(np.abs(r[:, 0]) / e_t[k], np.abs(r[:, 1]))
        size = np.abs(step).max(axis=1)
        done = ~stuck & ((rel <= _RTOL) | _settled(rel, size, last[active]))
        failed = ~np.isfinite(new).all(axis=1)
        root[active[done]] = new[done]
        last[active] = np.where(stuck, np.nan, size)
        keep = stuck[:, None]
        y_prev[active] = np.where(keep, y_prev[active], ya)
        r_prev[active] = np.where(keep, r_prev[active], r)
        jac[active], y[active] = ja, new
        active = active[~(done | failed)]
    tc, dr = np.exp(root[:, 0]), np.exp(root[:, 1])
    ok = (dr >= _DR_RANGE[0]) & (dr <= _DR_RANGE[1]) & (tc >= _TC_RANGE[0]) & (tc <= _TC_RANGE[1])
    return np.where(ok[:, None], root, y), ok


def _nested_both(e_t, v0, g, t_c, rho, simp, *, index):
    """``(timeconst, dampratio)`` for ``e_t`` and ``t_c`` under gravity (flat), bracketed.

    Nested brackets: for a dampratio the contact time grows with the timeconst (inner
    Illinois solve); the restitution at that timeconst falls with the dampratio (outer
    solve, bracketed on a grid because no timeconst may exist at some dampratios).
    Refusals name the elements by ``index``.
    """

    def inner(dr, idx):
        # timeconst that gives the contact time t_c at this dampratio
        lo = np.full(idx.size, _TC_RANGE[0])
        hi = np.full(idx.size, _TC_RANGE[1])

        def t_of(tc, j):
            k = idx[j]
            t = flat_restitution(tc, dr[j], simp, rho[k], g[k], v0[k], extremes=False)
            t = t.contact_time
            return np.arctan(np.log(np.where(np.isfinite(t), t, 1e300) / t_c[idx[j]]))

        j_all = np.arange(idx.size)
        ok = (t_of(lo, j_all) < 0) & (t_of(hi, j_all) > 0)
        tc = np.full(idx.size, np.nan)
        if ok.any():
            sel = np.flatnonzero(ok)
            tc[sel] = bracketed_illinois(
                lambda x, j: t_of(x, sel[j]), lo[sel], hi[sel], log=True, rtol=1e-11
            )
            miss = np.abs(t_of(tc[sel], sel)) > 1e-8  # a jump (stick), not a root
            tc[sel[miss]] = np.nan
        return tc

    def residual(dr, idx):
        tc = inner(dr, idx)
        out = np.full(idx.size, -1.0)  # no timeconst gives t_c: treat as too much damping
        good = np.isfinite(tc)
        if good.any():
            j = idx[good]
            e = flat_restitution(tc[good], dr[good], simp, rho[j], g[j], v0[j], extremes=False)
            out[good] = e.restitution - e_t[j]
        return out

    n = e_t.size
    idx = np.arange(n)
    grid = np.geomspace(*_DR_RANGE, 21)
    vals = np.stack([residual(np.full(n, q), idx) for q in grid])
    below = vals <= 0
    has = below.any(axis=0)
    first = np.argmax(below, axis=0)
    unreachable(
        "no (timeconst, dampratio) gives both this restitution and this contact time",
        ~has | (first == 0),
        e_t,
        "a longer contact_time or a higher speed reaches it",
        index,
    )
    dr = bracketed_illinois(
        lambda x, i: -residual(x, i), grid[first - 1], grid[first], log=True, rtol=1e-12
    )
    _check_gap(
        lambda x: residual(x, idx) + e_t,
        e_t,
        dr,
        "dampratio",
        lambda x: ~np.isfinite(inner(x, idx)),
        index,
    )
    return inner(dr, idx), dr
