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
* **gravity > 0, restitution only**: secant steps in ``log dr`` (each inside the bracket
  the evaluated signs verify: ``e`` falls with ``dr``; bisection where a step would
  leave it) from the root of the first-order load model
  ``e ~ e0(D) (1 - 2 (1 - d') gamma D)`` and its slope.
* **gravity > 0 with a contact time**: Broyden's method in ``(log tc, log dr)`` from the
  fixed point of the first-order model (``tau_c ~ tau0(D) + gamma (1 + (1 - d') e0)/e0``
  beside it), its first Jacobian the gravity-0 closed form's (``e`` depends on ``D``
  alone, ``log t_c = log tau_c(D) + log tc + log dr + const``); one kernel evaluation
  per iteration, steps bounded, halved back where the contact sticks.
* **many targets of one contact** (equal speed, gravity, ``rho`` and timeconst or
  contact time: a vector of targets): the starts come from a table of the one curve
  they share (256 kernel points, or 32 designs with their Jacobians), inverted by cubic
  Hermite interpolation (:func:`_tabulated`, :func:`_tabulated_both`); then one (two or
  three) kernel evaluations settle each design, where the brackets took 22 (restitution) and
  about 1000 (with a contact time).

A secant root is accepted where its residual is below ``1e-11`` (relative), or below
``1e-6`` with its last two steps ``|s_k| <= 1e-6``, ``|s_k s_(k-1)| <= 1e-13``
(:func:`_settled`); a Broyden root where its residual is below ``1e-9`` (its Jacobian
need not converge); both only inside the brackets the fallback searches (``dr`` in
``[1e-3, 100]``, ``tc`` in ``[1e-6, 1e3]``), and each takes one more (unevaluated)
step. The designs agree with the bracketed ones to about ``1e-10``. The others (targets
near a jump of the restitution or near sticking, out of reach, or slow to converge) go
to the bracketed methods, which find what is reachable and refuse the rest with its
cause, naming the element of the caller's array (`docs/physics.md#simulation-engines`). Internal:
:mod:`~impactsym.engines.mujoco.design` reads it. SI units throughout.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.contact.unpressed import force_exponent
from impactsym.engines.mujoco.flat_brackets import (
    DR_RANGE,
    TC_RANGE,
    bracketed_dampratio,
    flat_restitution,
    nested_both,
)
from impactsym.engines.mujoco.model import d_max, effective_impedance, impedance_at
from impactsym.numeric.poly import hermite_basis
from impactsym.numeric.roots import bracketed_newton

__all__ = ["design_flat_both", "design_flat_dampratio"]

_MAX_ITER = 16  # fast iterations before an element goes to the bracketed method
_RTOL = 1e-11  # accepted residual, relative (restitution and contact time)
_FD = 1e-5  # relative step of the central differences on the closed form
#: the bounds of Broyden's ``(log tc, log dr)``: the fallback's brackets widened by 1
_Y_LO = np.log([TC_RANGE[0], DR_RANGE[0]]) - 1.0
_Y_HI = np.log([TC_RANGE[1], DR_RANGE[1]]) + 1.0
_TABLE = 256  # points of a restitution table (:func:`_tabulated`)
_TABLE_BOTH = 32  # designs of a table of designs (:func:`_tabulated_both`)


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
    tau_p, tau_m = force_exponent(D * np.exp(_FD))[0], force_exponent(D * np.exp(-_FD))[0]
    return tau, h, np.log(tau_p / tau_m) / (2 * _FD), _dh(D, tau)


def _dh(D, tau):
    """``dh/dlog D = D (tau_c/2 - D)/(1 - D^2)`` (:func:`_unpressed`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        dh = (0.5 * tau - D) / ((1.0 - D) * (1.0 + D))
    return np.where(np.abs(1.0 - D) <= 1e-6, 2.0 / 3.0, dh) * D


def _h_dh(u, big, b1, b2):
    """``h(D) - log(1 - b1 D - b2 D^2)/2 - big`` and its derivative in ``u = log D``
    (``h' = (tau_c/2 - D)/(1 - D^2)``, :func:`_unpressed`)."""
    D = np.exp(u)
    tau, h = force_exponent(D)
    q = 1.0 - b1 * D - b2 * D * D
    return h - 0.5 * np.log(q) - big, _dh(D, tau) + 0.5 * (b1 * D + 2 * b2 * D * D) / q


def _free_damping_ratio(e_t, a):
    """``D`` with ``exp(-2 h(D)) = e_t`` (the unpressed force condition), Newton in
    ``log D`` inside the bracket of the dampratios ``[1e-3, 100]``; ``inside`` says where
    that bracket holds the target (elsewhere ``D`` is the nearer end). The bracket is
    first narrowed to ``+-0.01`` around the root of a table of ``h`` (checked by the
    signs at its ends), so that Newton needs few steps."""
    big = -0.5 * np.log(e_t)  # h wanted
    zero = np.zeros(e_t.shape)
    u_lo, u_hi = np.log(a * DR_RANGE[0]), np.log(a * DR_RANGE[1])
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
    elements that fail go to
    :func:`~impactsym.engines.mujoco.flat_brackets.bracketed_dampratio`, which refuses an
    unreachable target with its cause, naming the element by ``index`` (default: its
    position).
    """
    index = np.arange(e_t.size) if index is None else np.asarray(index)
    rho = np.broadcast_to(np.asarray(rho, float), e_t.shape)
    a, scale, soft = _scales(simp, rho)
    dr, good = np.full(e_t.size, np.nan), np.zeros(e_t.size, bool)
    free, loaded = np.flatnonzero(g == 0), np.flatnonzero(g != 0)
    if free.size:
        D, good[free] = _free_damping_ratio(e_t[free], a[free])
        dr[free] = D / a[free]
    if loaded.size:
        j = loaded

        def e_of(x, k):
            k = j[k]
            return flat_restitution(tc[k], np.exp(x), simp, rho[k], g[k], v0[k], extremes=False)

        x0, slope, use = _tabulated(e_t[j], a[j], (g[j] * tc[j] / v0[j], rho[j]), e_of)
        m = np.flatnonzero(~use)
        if m.size:  # the first-order gravity model: gamma = g tc D / (a K v0)
            k = j[m]
            D = _free_damping_ratio(e_t[k], a[k])[0]
            b2 = 2.0 * soft[k] * g[k] * tc[k] / (a[k] * scale[k] * v0[k])
            D1 = _first_order(e_t[k], D, np.zeros(k.size), b2)
            _, _, _, dh = _unpressed(D1)
            q = 1.0 - b2 * D1 * D1
            slope[m] = e_t[k] * (-2.0 * dh - 2.0 * b2 * D1 * D1 / q)  # the model's de/dx
            x0[m] = np.log(D1 / a[k])
        x, ok = _secant(e_t, v0, g, tc, simp, rho, j, x0, slope, use)
        dr[loaded] = np.exp(x)
        good[loaded] = ok
    rest = np.flatnonzero(~good)
    if rest.size:
        part = (q[rest] for q in (e_t, v0, g, tc))
        dr[rest] = bracketed_dampratio(*part, simp, rho[rest], index=index[rest])
    return dr


def _tabulated(e_t, a, key, e_of):
    """Starts ``x = log dr`` and slopes ``de/dx`` from a table, where many targets share
    one restitution curve: ``e`` depends on ``dr`` through ``D = a dr`` and
    ``gamma = g tc dr / (K v0)``, so elements with equal ``g tc / v0`` and ``rho`` (the
    ``key``) have one curve ``e(x)``. It is tabulated once per curve (``_TABLE`` points
    from 1 below to 0.05 above the gravity-0 designs of its extreme targets: gravity
    lowers the restitution) with one kernel call (three points per node) and inverted by
    cubic Hermite interpolation of ``x(e)``; the slopes at the nodes by central
    differences (error ~1e-10), so that the starts are good to about ``step^4 / 384``,
    ~1e-10, and the interpolated slopes to ~1e-5, which lets the first secant step
    settle (:func:`_secant`). Elsewhere, and where the table is not monotone, the starts
    are NaN (``use`` False). Skipped where there are fewer than four targets per table
    point.
    """
    m, none = _TABLE, np.full(e_t.size, np.nan)
    first, group, e_lo, e_hi = _groups(key, e_t, m)
    if first is None:
        return none, none, np.zeros(e_t.size, bool)
    # the gravity-0 designs of the extreme targets span the curve's (gravity lowers e)
    ends = _free_damping_ratio(np.concatenate([e_hi, e_lo]), np.tile(a[first], 2))[0]
    ends = np.log(ends / np.tile(a[first], 2))
    n_groups, lo, hi = first.size, ends[: first.size] - 1.0, ends[first.size :] + 0.05
    step = (hi - lo) / (m - 1)
    grid = lo[:, None] + step[:, None] * np.arange(m)
    near = grid.ravel() + _FD * np.array([[0.0], [1.0], [-1.0]])  # central differences
    e3 = e_of(near.ravel(), np.tile(np.repeat(first, m), 3)).restitution.reshape(3, -1)
    table = e3[0].reshape(n_groups, m)
    de = ((e3[1] - e3[2]) / (2 * _FD)).reshape(n_groups, m)
    # e falls along each row: search -e, rows stacked 4 apart
    flat = (4.0 * np.arange(n_groups)[:, None] - table).ravel()
    i = np.searchsorted(flat, 4.0 * group - e_t, side="right") - 1
    local = i - group * m
    use = (local >= 0) & (local < m - 1)
    i = np.where(use, i, 0)
    e0, e1 = table.ravel()[i], table.ravel()[i + 1]
    s0, s1 = de.ravel()[i], de.ravel()[i + 1]
    use &= (e1 < e0) & (s0 < 0) & (s1 < 0) & (flat[i + 1] > flat[i])
    h = np.where(use, e1 - e0, 1.0)
    t = np.where(use, (e_t - e0) / h, 0.0)
    h00, h10, h01, h11 = hermite_basis(t)
    xg, dx = grid.ravel()[i], step[group]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = h00 * xg + h10 * h / s0 + h01 * (xg + dx) + h11 * h / s1
        s = s0 + t * (s1 - s0)
    use &= np.isfinite(x) & np.isfinite(s)
    return np.where(use, x, np.nan), np.where(use, s, np.nan), use


def _groups(key, values, m):
    """The elements of equal ``key`` rows: the first of each group, each element's group
    and the range of ``values`` per group; ``None`` where fewer than four elements per
    table point of ``m`` would share a table."""
    _, first, group = np.unique(
        np.stack(key, axis=1), axis=0, return_index=True, return_inverse=True
    )
    if 4 * first.size * m > values.size:
        return None, None, None, None
    group = group.ravel()
    lo, hi = np.full(first.size, np.inf), np.full(first.size, -np.inf)
    np.minimum.at(lo, group, values)
    np.maximum.at(hi, group, values)
    return first, group, lo, hi


def _secant(e_t, v0, g, tc, simp, rho, idx, x, slope, tabled):
    """Secant steps in ``x = log dr`` for the elements ``idx`` (module notes); returns the
    roots and where they were accepted."""
    # the fallback's bracket widened by 1: bisection stays finite (a root out there is
    # not accepted: the fallback refuses it)
    lo, hi = np.full(x.size, np.log(DR_RANGE[0]) - 1), np.full(x.size, np.log(DR_RANGE[1]) + 1)
    x_prev, f_prev = np.full(x.size, np.nan), np.full(x.size, np.nan)
    # a start from a table has its slope to ~1e-5 (:func:`_tabulated`): as if after a
    # secant step of that size, so that its first step may settle (:func:`_settled`)
    root, last = np.full(x.size, np.nan), np.where(tabled, 1e-5, np.nan)
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
    ok = (root >= np.log(DR_RANGE[0])) & (root <= np.log(DR_RANGE[1]))
    return np.where(ok, root, x), ok


def _settled(residual, step, last):
    """Where a secant or Broyden step ``step`` after ``last`` lands within about
    ``1e-13`` of the root: their error shrinks like ``C |step| |last|`` (superlinear
    convergence), taken where both steps are small and the relative ``residual`` is
    below ``1e-6`` (no jump is being straddled)."""
    with np.errstate(invalid="ignore"):
        return (np.abs(residual) <= 1e-6) & (np.abs(step) <= 1e-6) & (np.abs(step * last) <= 1e-13)


def design_flat_both(e_t, v0, g, t_c, simp, rho) -> tuple[np.ndarray, np.ndarray]:
    """``(timeconst, dampratio)`` for restitution ``e_t`` and contact time ``t_c`` (flat).

    Without gravity the restitution depends on the dampratio alone and the contact time
    is proportional to the timeconst (both coefficients scale with ``1/timeconst``): the
    dampratio of the restitution at timeconst 1, then the timeconst scaled to ``t_c``.
    With gravity, Broyden's method from that design (module notes); the elements it does
    not settle go to the nested brackets
    (:func:`~impactsym.engines.mujoco.flat_brackets.nested_both`).
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
        key = (v0[j], g[j], t_c[j], rho[j])
        y, jac, use = _tabulated_both(e_t[j], key, a[j], scale[j], soft[j], simp)
        m = np.flatnonzero(~use)
        if m.size:
            k = j[m]
            y[m], jac[m] = _loaded_start(e_t[k], a[k], scale[k], soft[k], g[k], t_c[k], v0[k])
        y, ok = _broyden(e_t, v0, g, t_c, simp, rho, loaded, y, jac)
        tc[loaded], dr[loaded] = np.exp(y[:, 0]), np.exp(y[:, 1])
        rest = loaded[~ok]
        if rest.size:
            part = (q[rest] for q in (e_t, v0, g, t_c, rho))
            tc[rest], dr[rest] = nested_both(*part, simp, index=rest)
    return tc, dr


def _loaded_start(e_t, a, scale, soft, g, t_c, v0):
    """The start ``y = (log tc, log dr)`` of :func:`_broyden` and its first Jacobian.

    The first-order gravity model by fixed-point steps: ``gamma = g t_c / (tau v0)``,
    ``tau = tau0(D) + gamma (1 + (1 - d') e0) / e0``, ``e0 (1 - 2 (1 - d') gamma D) = e_t``
    (module notes); the Jacobian is the gravity-0 one, rows ``(e, log t_c)``.
    """
    zero = np.zeros(e_t.size)
    D0, _ = _free_damping_ratio(e_t, a)
    D, gamma = D0, zero
    for _ in range(3):
        tau, h, dtau, dh = _unpressed(D)
        e0 = np.exp(-2.0 * h)
        tau = tau + gamma * (1.0 + soft * e0) / e0
        gamma = g * t_c / (tau * v0)
        D = _first_order(e_t, D0, 2.0 * soft * gamma, zero)
    dr0 = D / a
    tc0 = scale * gamma * v0 / (g * dr0)  # omega_0 = g / (gamma v0) = K / (tc dr)
    jac = np.zeros((e_t.size, 2, 2))  # columns (log tc, log dr)
    jac[:, 0, 1] = -2.0 * e_t * dh
    jac[:, 1, 0] = 1.0
    jac[:, 1, 1] = 1.0 + dtau
    return np.stack([np.log(tc0), np.log(dr0)], axis=1), jac


def _tabulated_both(e_t, key, a, scale, soft, simp):
    """Starts ``y = (log tc, log dr)`` from a table, where many targets share one contact:
    elements with equal speed, gravity, contact time and ``rho`` (the ``key``) differ in
    the target alone, so their designs lie on one curve ``y(e)``. It is solved at
    ``_TABLE_BOTH`` targets spanning theirs (:func:`_broyden`, on few elements) and
    interpolated by cubic Hermite polynomials (slopes by differences), the Jacobian of
    the residual at the nodes (forward differences) linearly. Returns the starts, their
    Jacobians and where they hold (not where a table design failed, nor where there are
    fewer than four targets per table point).
    """
    m = _TABLE_BOTH
    first, group, lo, hi = _groups(key, e_t, m)
    if first is None:
        return np.zeros((e_t.size, 2)), np.zeros((e_t.size, 2, 2)), np.zeros(e_t.size, bool)
    n_groups = first.size
    step = np.maximum(hi - lo, 1e-300) / (m - 1)
    nodes = (lo[:, None] + step[:, None] * np.arange(m)).ravel()
    nodes = np.minimum(nodes, np.repeat(hi, m))
    rep = np.repeat(first, m)
    part = (q[rep] for q in (a, scale, soft))
    v0, g, t_c, rho = (q[rep] for q in key)
    y_n, jac = _loaded_start(nodes, *part, g, t_c, v0)
    y_n, ok = _broyden(nodes, v0, g, t_c, simp, rho, np.arange(rep.size), y_n, jac)
    # the Jacobian at the nodes by forward differences (3 kernel calls on few elements)
    y_n = np.where(ok[:, None], y_n, 0.0)
    r = [_residual(y_n + dy, nodes, v0, g, t_c, simp, rho) for dy in np.eye(3, 2, -1) * _FD]
    jac_n = np.stack([(r[1] - r[0]) / _FD, (r[2] - r[0]) / _FD], axis=2)
    jac_n = np.where(ok[:, None, None], jac_n, np.nan).reshape(n_groups, m, 2, 2)
    y_n = np.where(ok[:, None], y_n, np.nan).reshape(n_groups, m, 2)
    dy = np.empty_like(y_n)  # dy/de: central differences, one-sided at the ends
    dy[:, 1:-1] = (y_n[:, 2:] - y_n[:, :-2]) / (2 * step[:, None, None])
    dy[:, 0] = (y_n[:, 1] - y_n[:, 0]) / step[:, None]
    dy[:, -1] = (y_n[:, -1] - y_n[:, -2]) / step[:, None]
    i = np.clip(((e_t - lo[group]) / step[group]).astype(int), 0, m - 2)
    h = step[group]
    t = ((e_t - lo[group]) / h - i)[:, None]
    h00, h10, h01, h11 = hermite_basis(t)
    y0n, y1n = y_n[group, i], y_n[group, i + 1]
    d0, d1 = dy[group, i], dy[group, i + 1]
    y = h00 * y0n + h10 * h[:, None] * d0 + h01 * y1n + h11 * h[:, None] * d1
    jac = jac_n[group, i] + t[:, :, None] * (jac_n[group, i + 1] - jac_n[group, i])
    use = np.isfinite(y).all(axis=1) & np.isfinite(d0).all(axis=1) & np.isfinite(d1).all(axis=1)
    use &= np.isfinite(jac).all(axis=(1, 2))
    return np.where(use[:, None], y, 0.0), np.where(use[:, None, None], jac, 0.0), use


def _residual(y, e_t, v0, g, t_c, simp, rho):
    """``(e - e_t, log(t / t_c))`` at ``y = (log tc, log dr)`` (inf where it sticks)."""
    ph = flat_restitution(np.exp(y[:, 0]), np.exp(y[:, 1]), simp, rho, g, v0, extremes=False)
    with np.errstate(divide="ignore", over="ignore"):
        return np.stack([ph.restitution - e_t, np.log(ph.contact_time / t_c)], axis=1)


def _broyden(e_t, v0, g, t_c, simp, rho, idx, y, jac):
    """Broyden's method in ``y = (log tc, log dr)`` for the elements ``idx`` (module
    notes); returns the roots and where they were accepted."""
    m = idx.size
    y_prev, r_prev = np.full((m, 2), np.nan), np.full((m, 2), np.nan)
    root = np.full((m, 2), np.nan)
    active = np.arange(m)
    for _ in range(_MAX_ITER):
        if active.size == 0:
            break
        k, ya, ja = idx[active], y[active], jac[active]
        r = _residual(ya, e_t[k], v0[k], g[k], t_c[k], simp, rho[k])
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
        new = np.clip(np.where(stuck[:, None], back, ya + step), _Y_LO, _Y_HI)
        rel = np.maximum(np.abs(r[:, 0]) / e_t[k], np.abs(r[:, 1]))
        # the polishing step leaves about (Jacobian error) x |step|: a residual below
        # 1e-9 (Broyden's Jacobian, unlike the secant's slope, need not converge)
        done = ~stuck & (rel <= 1e-9)
        failed = ~np.isfinite(new).all(axis=1)
        root[active[done]] = new[done]
        keep = stuck[:, None]
        y_prev[active] = np.where(keep, y_prev[active], ya)
        r_prev[active] = np.where(keep, r_prev[active], r)
        jac[active], y[active] = ja, new
        active = active[~(done | failed)]
    tc, dr = np.exp(root[:, 0]), np.exp(root[:, 1])
    ok = (dr >= DR_RANGE[0]) & (dr <= DR_RANGE[1]) & (tc >= TC_RANGE[0]) & (tc <= TC_RANGE[1])
    return np.where(ok[:, None], root, y), ok
