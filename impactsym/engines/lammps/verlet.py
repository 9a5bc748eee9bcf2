r"""LAMMPS's velocity-Verlet step applied to one Hooke contact: the exact discrete model.

``fix nve/sphere`` advances ``v += (dt/2) f/m; x += dt v`` (``initial_integrate``), then
computes the forces at the new positions with the **half-step velocity** (``pair_style
granular`` / ``fix wall/gran``: ``F = kn delta - eta_n v_n``, clipped at zero under
``limit_damping``; ``fix gravity`` adds ``m g``), then ``v += (dt/2) f/m``
(``final_integrate``). With the overlap ``x``, ``w_n = v_{n-1/2}`` the overlap rate the
force at state ``n`` sees and ``a_n = g - F_n / m``, one step is

.. math::

    w_{n+1} = w_n + h\,a_n, \qquad x_{n+1} = x_n + h\,w_{n+1}, \qquad
    v_n = w_n + \tfrac{h}{2} a_n \ (\text{the state's reported velocity}).

In contact (unclipped force) and in the section-2 normalization (``tau = omega0 h``,
lengths ``v0/omega0``, speeds ``v0``, load ``L = g/(omega0 v0)``) it is affine,
``y_{n+1} = M y_n`` for ``y = (x - L, w)``,

.. math::

    M = \begin{pmatrix} 1 - \tau^2 & \tau (1 - 2 D \tau) \\ -\tau & 1 - 2 D \tau
    \end{pmatrix}, \quad \det M = 1 - 2 D\tau, \quad \operatorname{tr} M = 2 - \tau^2
    - 2 D \tau,

stable for ``tau < 2 / (D + sqrt(1 + D^2))`` (the Jury conditions ``det < 1``,
``1 - tr + det = tau^2 > 0`` and ``1 + tr + det = 4 - tau^2 - 4 D tau > 0``).
Cayley-Hamilton gives the ``n``-th state
in closed form, ``M^n = s_n M - det(M) s_{n-1} I`` with ``s_n = (l1^n - l2^n)/(l1 - l2)``
(``r^{n-1} sin(n theta)/sin theta`` for complex eigenvalues ``r e^{+-i theta}``), which
extends to real ``n``: the end of the contact is the first integer ``n`` at which the
threshold ``x_n`` (or the force ``x_n + 2 D w_n`` under ``limit_damping``) is ``<= 0``,
found as the first root of that exponential polynomial in ``n`` bracketed between its
critical points (closed form), polished by :func:`~impactsym.numeric.roots.bracketed_illinois`
and checked at the integers around it: no loop over the steps of a contact.

**Touch phase** (`docs/physics.md#lammps-at-its-timestep`): geometric touch lies
``phase * h`` before state 0, the first state with overlap; before it the body is in free
flight (exact under velocity-Verlet). State 0 carries the free-flight overlap
``x_0 = v0 p h + g (p h)^2 / 2`` and the half-step velocity ``w_0 = v0 + g (p - 1/2) h``
(the free-flight velocity half a step before), which its force uses. A step map with a
non-positive eigenvalue (``tau >= 1/(2 D)`` or ``tr M <= 0``: the damping over-corrects
every step) is refused.
"""

from __future__ import annotations

import numpy as np

from impactsym.numeric.roots import bracketed_illinois

__all__ = [
    "StepMap",
    "at_step",
    "coast",
    "positive_limit",
    "stability_limit",
    "step_map",
    "verlet_phase",
]

#: lobes of the damped oscillation searched for an integer inside a negative region
_MAX_LOBES = 10_000


def stability_limit(D: np.ndarray) -> np.ndarray:
    """Largest stable ``tau = omega0 h``: ``2 / (D + sqrt(1 + D^2))`` (``|eigenvalues| < 1``)."""
    D = np.asarray(D, dtype=float)
    return 2.0 / (D + np.sqrt(1.0 + D * D))


def positive_limit(D: np.ndarray) -> np.ndarray:
    """Largest ``tau`` whose step map has no non-positive eigenvalue (modelled here).

    Real eigenvalues need ``det = 1 - 2 D tau > 0`` and ``tr = 2 - tau^2 - 2 D tau > 0``
    where the discriminant ``tr^2 - 4 det = tau^2 ((tau + 2 D)^2 - 4)`` is ``>= 0``
    (``tau >= 2 - 2 D``); complex ones are always modelled.
    """
    D = np.asarray(D, dtype=float)
    det_zero = np.where(D > 0, 0.5 / np.where(D > 0, D, 1.0), np.inf)
    trace_zero = np.sqrt(D * D + 2.0) - D
    return np.maximum(np.maximum(2.0 - 2.0 * D, 0.0), np.minimum(det_zero, trace_zero))


class StepMap:
    """The in-contact step map of designs ``D`` at ``tau`` and its ``n``-th power."""

    def __init__(self, D: np.ndarray, tau: np.ndarray) -> None:
        self.D, self.tau = D, tau
        self.m11, self.m12 = 1.0 - tau * tau, tau * (1.0 - 2.0 * D * tau)
        self.m21, self.m22 = -tau, 1.0 - 2.0 * D * tau
        self.det = 1.0 - 2.0 * D * tau
        self.trace = self.m11 + self.m22
        disc = tau * tau * ((tau + 2.0 * D) ** 2 - 4.0)  # trace^2 - 4 det, factored
        self.complex = disc < 0
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.sqrt(np.where(self.complex, self.det, 1.0))
            cos_t = np.clip(self.trace / (2.0 * r), -1.0, 1.0)
            self.r, self.theta = r, np.arccos(cos_t)
            sq = np.sqrt(np.where(self.complex, 0.0, disc))
            l1 = 0.5 * (self.trace + sq)
            self.l1 = np.where(self.complex, 1.0, l1)
            self.l2 = np.where(self.complex, 1.0, self.det / self.l1)
            self.log_q = np.log(self.l2) - np.log(self.l1)

    def s(self, t: np.ndarray, idx) -> np.ndarray:
        """``s(t)`` (``s_0 = 0``, ``s_1 = 1``) at real ``t`` for the designs ``idx``."""
        return self.s_pair(t, idx)[0]

    def s_pair(self, t: np.ndarray, idx) -> tuple[np.ndarray, np.ndarray]:
        """``s(t)`` and ``s(t - 1)``, each branch evaluated only where it applies."""
        t = np.asarray(t, dtype=float)
        idx = np.broadcast_to(np.arange(self.D.size)[idx], t.shape)
        c = self.complex[idx]
        s1, s0 = np.empty(t.shape), np.empty(t.shape)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
            if c.any():
                tc, ic = t[c], idx[c]
                r, th = self.r[ic], self.theta[ic]
                sin_th = np.sin(th)
                ok = th > 0
                power = r ** (tc - 1.0)
                sn, cs = np.sin(tc * th), np.cos(tc * th)
                safe = np.where(ok, sin_th, 1.0)
                s1[c] = power * np.where(ok, sn / safe, tc)
                s0[c] = power / r * np.where(ok, (sn * np.cos(th) - cs * sin_th) / safe, tc - 1.0)
            real = ~c
            if real.any():
                tr, ir = t[real], idx[real]
                lq, l1 = self.log_q[ir], self.l1[ir]
                distinct = lq < 0
                den = np.expm1(np.where(distinct, lq, -1.0))
                power = l1 ** (tr - 1.0)
                s1[real] = power * np.where(distinct, np.expm1(tr * lq) / den, tr)
                s0[real] = (
                    power / l1 * np.where(distinct, np.expm1((tr - 1.0) * lq) / den, tr - 1.0)
                )
        return s1, s0

    def apply(self, t, y0x, y0w, idx):
        """``M^t y0`` (both components) for the designs ``idx``."""
        zx = self.m11[idx] * y0x + self.m12[idx] * y0w
        zw = self.m21[idx] * y0x + self.m22[idx] * y0w
        s1, s0 = self.s_pair(np.broadcast_to(t, np.shape(zx)), idx)
        det = self.det[idx]
        return s1 * zx - det * s0 * y0x, s1 * zw - det * s0 * y0w


def step_map(D, tau) -> StepMap:
    """The :class:`StepMap` of arrays ``D``, ``tau`` (refusing what is not modelled)."""
    D, tau = np.asarray(D, dtype=float), np.asarray(tau, dtype=float)
    unstable = tau >= stability_limit(D)
    if unstable.any():
        i = np.flatnonzero(unstable.ravel())[0]
        raise ValueError(
            f"the timestep is unstable for this contact: omega0 * timestep = "
            f"{float(tau.ravel()[i]):.6g} >= {float(stability_limit(D).ravel()[i]):.6g} = "
            f"2 / (D + sqrt(1 + D^2)) at damping ratio D = {float(D.ravel()[i]):.6g}"
        )
    m = StepMap(D, tau)
    flip = ~m.complex & ((m.det <= 0) | (m.trace <= 0))
    if flip.any():
        i = np.flatnonzero(flip.ravel())[0]
        raise ValueError(
            f"the timestep is too coarse for this contact: omega0 * timestep = "
            f"{float(tau.ravel()[i]):.6g} at damping ratio D = {float(D.ravel()[i]):.6g} "
            f"gives the Verlet step a non-positive eigenvalue (the damping overshoots every "
            f"step); omega0 * timestep < {float(positive_limit(D).ravel()[i]):.6g} is modelled"
        )
    return m


def _first_end(m: StepMap, cx, cw, L, y0x, y0w):
    """First integer ``n >= 0`` with ``phi_n = L + c . M^n y0 <= 0`` (``inf``: never)."""
    size = L.size

    def phi(t, idx):
        yx, yw = m.apply(t, y0x[idx], y0w[idx], idx)
        return L[idx] + cx * yx + cw[idx] * yw

    end = np.full(size, np.inf)
    # state 0 from its own values (the closed form at n = 0 rounds); phase 0 is the limit
    # from above: x_0 = 0 is in contact
    at0 = L + cx * y0x + cw * y0w < 0
    end[at0] = 0.0
    # critical points of the continuous extension
    zx = m.m11 * y0x + m.m12 * y0w
    zw = m.m21 * y0x + m.m22 * y0w
    cy, cz = cx * y0x + cw * y0w, cx * zx + cw * zw
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        # complex: L + rho r^t cos(theta t - psi), minima at theta t - psi = u0 + k pi, k odd
        r, th = m.r, m.theta
        alpha = cy
        beta = (cz / r - cy * np.cos(th)) / np.sin(th)
        psi = np.arctan2(beta, alpha)
        u0 = np.arctan(np.log(r) / th)
        k1 = np.floor(-(psi + u0) / np.pi) + 1.0
        k1 = np.where(np.mod(k1, 2.0) == 0, k1 + 1.0, k1)
        # real: L + A l1^t + B l2^t, one critical point
        l1, l2 = m.l1, m.l2
        A = (cz - l2 * cy) / (l1 - l2)
        B = (l1 * cy - cz) / (l1 - l2)
        mu1, mu2 = np.log(l1), np.log(l2)
        t_real = np.log(-B * mu2 / (A * mu1)) / (mu1 - mu2)
    active = ~at0
    lobe = np.zeros(size)
    for _ in range(_MAX_LOBES):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        c = m.complex[idx]
        k = k1[idx] + 2.0 * lobe[idx]
        hi = np.where(c, (psi[idx] + u0[idx] + k * np.pi) / th[idx], t_real[idx])
        lo = np.where(c, np.maximum((psi[idx] + u0[idx] + (k - 1) * np.pi) / th[idx], 0.0), 0.0)
        ok = np.isfinite(hi) & (hi > 0)
        f_hi = np.where(ok, phi(np.where(ok, hi, 1.0), idx), 1.0)
        reach = ok & (f_hi <= 0)
        active[idx[~reach]] = False  # the minimum stays positive: never (later ones higher)
        idx, lo, hi, f_hi, c = idx[reach], lo[reach], hi[reach], f_hi[reach], c[reach]
        if idx.size == 0:
            break
        # without load the first root is closed form: the zero of the cosine before the
        # minimum, or (real) A l1^t + B l2^t = 0; else bracketed. The integer check below
        # needs the root only to well within one step.
        free = L[idx] == 0
        with np.errstate(invalid="ignore", divide="ignore"):
            k = k1[idx] + 2.0 * lobe[idx]
            closed = np.where(
                c,
                (psi[idx] + 0.5 * np.pi + (k - 1.0) * np.pi) / th[idx],
                np.log(-B[idx] / A[idx]) / (mu1[idx] - mu2[idx]),
            )
        free &= np.isfinite(closed)
        root = np.where(free, np.clip(np.where(free, closed, 0.0), lo, hi), 0.0)
        solve = ~free
        if solve.any():
            js = idx[solve]
            root[solve] = bracketed_illinois(
                lambda t, j, js=js: -phi(t, js[j]),
                lo[solve],
                hi[solve],
                rtol=0.0,
                atol=1e-6,
                f_hi=-f_hi[solve],
            )
        n = np.maximum(np.floor(root), 1.0)
        f_n = phi(n, idx)
        n = np.where(f_n <= 0, n, n + 1.0)
        hit = phi(n, idx) <= 0
        end[idx[hit]] = n[hit]
        active[idx[hit]] = False
        # no integer inside this negative region: a real map has no other; complex: next lobe
        active[idx[~hit & ~c]] = False
        lobe[idx[~hit & c]] += 1.0
    return end


def coast(x, w, D, L, tau):
    """After a force end inside the overlap: free flight (``a = L``) from ``(x_N, w_N)``.

    Returns ``(sticks, steps_to_leave, departure_speed)``: the body leaves at the first
    state ``N + j`` whose overlap is gone unless the unclipped force ``x + 2 D w``
    turns positive at an earlier state (it re-engages: the body sticks).
    """
    b = w + 0.5 * tau * L
    with np.errstate(invalid="ignore", divide="ignore"):
        # x(j) = (tau^2 L / 2) j^2 + tau b j + x ; smaller root, cancellation-free
        disc_x = b * b - 2.0 * L * x
        sq = np.sqrt(np.maximum(disc_x, 0.0))
        j1 = 2.0 * x / (tau * (-b + sq))
        j1 = np.where(np.isfinite(j1), j1, np.inf)
        n_x = np.maximum(np.ceil(j1), 1.0)

        def xj(j):
            return x + tau * (j * w + 0.5 * tau * L * j * (j + 1.0))

        def fj(j):
            return xj(j) + 2.0 * D * (w + j * tau * L)

        n_x = np.where(xj(n_x - 1.0) <= 0, np.maximum(n_x - 1.0, 1.0), n_x)
        leaves = (disc_x >= 0) & (xj(n_x) <= 0)
        # F(j) = (tau^2 L/2) j^2 + Bq j + F0 with F0 <= 0: first integer above the larger root
        F0 = x + 2.0 * D * w
        Bq = tau * b + 2.0 * D * tau * L
        sqF = np.sqrt(np.maximum(Bq * Bq - 2.0 * tau * tau * L * F0, 0.0))
        jF = np.where(Bq <= 0, (-Bq + sqF) / (tau * tau * L), -2.0 * F0 / (Bq + sqF))
        jF = np.where(L > 0, jF, np.inf)
        n_f = np.maximum(np.floor(np.where(np.isfinite(jF), jF, 0.0)) + 1.0, 1.0)
        n_f = np.where((n_f > 1) & (fj(n_f - 1.0) > 0), n_f - 1.0, n_f)
        n_f = np.where(fj(n_f) > 0, n_f, n_f + 1.0)
        n_f = np.where(L > 0, n_f, np.inf)
    sticks = ~leaves | (n_f < n_x)
    w_out = w + n_x * tau * L
    departure = np.where(sticks, 0.0, -(w_out + 0.5 * tau * L))
    return sticks, np.where(sticks, np.inf, n_x), departure


def verlet_phase(D, load, tau, phase, limit_damping: bool, *, extremes: bool = True) -> dict:
    """The contact at touch phase ``phase`` (normalized; broadcast 1-D arrays).

    Returns arrays: ``restitution``, ``contact_time`` (``omega0`` units, from geometric
    touch), ``sticks``, ``released_by_position``, ``departure_speed`` (``v0`` units),
    ``steps`` (states in contact before the end state), ``max_penetration`` and
    ``peak_force`` (normalized ``x`` and ``x + 2 D w`` over the states in contact; left
    ``nan`` with ``extremes=False``, for loops that need only the end).
    """
    D, L, tau, p = (np.asarray(a, dtype=float) for a in np.broadcast_arrays(D, load, tau, phase))
    shape = D.shape
    D, L, tau, p = (a.ravel() for a in (D, L, tau, p))
    m = step_map(D, tau)
    every = np.arange(D.size)
    x0 = p * tau + 0.5 * L * (p * tau) ** 2
    w0 = 1.0 + L * (p - 0.5) * tau
    y0x, y0w = x0 - L, w0
    cw = 2.0 * D if limit_damping else np.zeros_like(D)
    end = _first_end(m, 1.0, cw, L, y0x, y0w)
    finite = np.isfinite(end)
    n = np.where(finite, end, 0.0)
    yx, yw = m.apply(n, y0x, y0w, every)
    x_n, w_n = L + yx, yw
    v_n = w_n + 0.5 * tau * L  # the end state's force is zero: a = g
    by_position = finite & (x_n <= 0)
    restitution = np.where(finite, -v_n, 0.0)
    departure = np.where(finite, -v_n, 0.0)
    sticks = ~finite
    inside = finite & ~by_position
    if inside.any():
        st, _, dep = coast(x_n[inside], w_n[inside], D[inside], L[inside], tau[inside])
        departure[inside] = dep
        sticks[inside] = st
    restitution = np.where(sticks, 0.0, restitution)
    contact_time = np.where(sticks, np.inf, (p + n) * tau)
    if extremes:
        x_max, f_max = _extremes(m, D, L, y0x, y0w, end)
    else:
        x_max = f_max = np.full(D.shape, np.nan)
    out = {
        "restitution": restitution,
        "contact_time": contact_time,
        "sticks": sticks,
        "released_by_position": by_position & ~sticks,
        "departure_speed": departure,
        "steps": np.where(finite, n, np.inf),
        "max_penetration": x_max,
        "peak_force": f_max,
    }
    return {k: v.reshape(shape) for k, v in out.items()}


def _extremes(m: StepMap, D, L, y0x, y0w, end):
    """Largest overlap and force over the states ``0 .. end - 1`` (integers near the
    first maximum of the continuous extension, the first state and the last)."""
    every = np.arange(D.size)
    last = np.where(np.isfinite(end), np.maximum(end - 1.0, 0.0), np.inf)
    out = []
    for cw in (np.zeros_like(D), 2.0 * D):
        zx = m.m11 * y0x + m.m12 * y0w
        zw = m.m21 * y0x + m.m22 * y0w
        cy, cz = y0x + cw * y0w, zx + cw * zw
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            r, th = m.r, m.theta
            beta = (cz / r - cy * np.cos(th)) / np.sin(th)
            psi = np.arctan2(beta, cy)
            u0 = np.arctan(np.log(r) / th)
            k0 = np.ceil(-(psi + u0) / np.pi)
            k0 = np.where(np.mod(k0, 2.0) == 1, k0 + 1.0, k0)  # maxima: k even
            t_c = (psi + u0 + k0 * np.pi) / th
            l1, l2 = m.l1, m.l2
            A = (cz - l2 * cy) / (l1 - l2)
            B = (l1 * cy - cz) / (l1 - l2)
            t_r = np.log(-B * np.log(l2) / (A * np.log(l1))) / (np.log(l1) - np.log(l2))
        t_c = np.where(m.complex, t_c, t_r)
        t_c = np.where(np.isfinite(t_c) & (t_c > 0), t_c, 0.0)
        best = np.full(D.size, -np.inf)
        for cand in (np.zeros_like(D), np.floor(t_c), np.ceil(t_c), last):
            c = np.clip(np.where(np.isfinite(cand), cand, 0.0), 0.0, last)
            yx, yw = m.apply(c, y0x, y0w, every)
            best = np.maximum(best, L + yx + cw * yw)
        out.append(best)
    return out


def at_step(D, load, tau, phase, n):
    """Overlap ``x_n``, half-step rate ``w_n`` and the reported velocity ``v_n`` (with the
    force clipped away, ``a = L``) of state ``n`` at touch phase ``phase`` (normalized)."""
    D, L, tau, p, n = (
        np.asarray(a, dtype=float) for a in np.broadcast_arrays(D, load, tau, phase, n)
    )
    m = StepMap(D.ravel(), tau.ravel())
    p = p.ravel()
    x0 = p * tau.ravel() + 0.5 * L.ravel() * (p * tau.ravel()) ** 2
    w0 = 1.0 + L.ravel() * (p - 0.5) * tau.ravel()
    yx, yw = m.apply(n.ravel(), x0 - L.ravel(), w0, np.arange(p.size))
    x, w = L.ravel() + yx, yw
    v = w + 0.5 * tau.ravel() * L.ravel()
    return x.reshape(D.shape), w.reshape(D.shape), v.reshape(D.shape)
