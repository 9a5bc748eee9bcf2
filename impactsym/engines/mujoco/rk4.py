r"""MuJoCo's RK4 integrator as an exact discrete model of one frictionless contact.

MuJoCo's ``mj_RungeKutta`` (``engine_forward.c``) runs the whole forward pass at each of
four stages: the stage state ``X_i = X_0 + h c_i F_{i-1}`` (``c = 1/2, 1/2, 1``) gets its
own collision (a contact where ``x > 0``; distance 0 is excluded) and its own
constraint force; the step advances ``X_0 + h (F_0 + 2 F_1 + 2 F_2 + F_3) / 6``. Along the
normal (penetration ``x``, rate ``v``, gravity ``g`` pressing) a stage accelerates with

.. math::

    a(x, v) = g - d'(x)\,\bigl(g + b\,v + d(x)\,\bar k\,x\bigr)_+ \quad (x > 0), \qquad
    a = g \quad (x \le 0),

the clipped force ``f = (a_ref - a_0) / (A + R)`` of ``engine_core_constraint.c`` with
``R = (1 - d)/d A_diag`` (:mod:`~impactsym.engines.mujoco.model`). The step that carries
the body in starts from free flight one step before the first detecting state and runs
its four stages (the later ones feel the contact), as the touch-phase definitions of
:mod:`~impactsym.engines.mujoco.stepping` say.

Where all four stages are in contact with a positive force and a constant impedance (flat
``solimp``, or beyond the impedance width ``x >= w``) the step is the affine map
``u -> P(hA) u`` of ``u = y - y*`` (``P`` the degree-4 Taylor polynomial of ``exp``,
:func:`impactsym.engines.derivation.mujoco_rk4_step`). Its ``n``-th power is closed form
in the eigenvalues ``mu = m exp(+-delta) = P(h lambda)``,
so every stage's penetration and force term is ``s* + m^n (q cosh n delta + w sinh n
delta / sinh delta)``: an exponential polynomial in ``n``. The step where a stage first
leaves the interior is found on it (per half-period window its one dip, or the monotone
pieces around the one extremum of the overdamped case; then integer bisection), not by
stepping; the boundary steps, a varying impedance inside the width and the coast after a
zero force (free flight inside the overlap until the contact is gone or the force comes
back) run the exact recurrence, vectorized over contacts.

SI throughout: seconds, metres, m/s, m/s^2 (`docs/physics.md`, *MuJoCo's RK4 step*).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.mujoco.coast import coast_steps
from impactsym.engines.mujoco.model import (
    Coefficients,
    effective_impedance,
    impedance_at,
    is_flat,
)
from impactsym.engines.mujoco.rk4_entry import entering_step
from impactsym.engines.mujoco.rk4_peak import row_max
from impactsym.engines.mujoco.rk4_record import RK4Contact, pattern_bits, stage_bits

__all__ = ["rk4_contact", "rk4_spectral_radius"]

#: the driver's (and a long run's) limit: a contact not over after this many states sticks
MAX_STEPS = 100_000
#: relative margin by which the closed form stops early (the exact step then decides)
_MARGIN = 1e-11
_WINDOWS = 64  # dips searched per jump before a safe partial jump
#: states stepped before the closed form takes over: a short contact steps more cheaply
#: than it evaluates the eight stage conditions' exponential polynomials
_SHORT = 24
_TWO_PI = 2.0 * np.pi


class _Law:
    """The stage law's parameters for a subset of contacts (flat 1-d arrays)."""

    def __init__(self, b, kbar, g, rho, solimp, flat):
        self.b, self.kbar, self.g, self.rho = b, kbar, g, rho
        self.solimp, self.flat = solimp, flat
        # the impedance of the interior: flat value, or d_max beyond the width
        self.d_in = float(impedance_at(np.asarray(solimp[2] if not flat else 0.0), solimp))
        self.width = 0.0 if flat else float(solimp[2])
        self.dp_in = effective_impedance(self.d_in, rho)
        self.k_hi = max(self.d_in, float(impedance_at(np.zeros(()), solimp))) * kbar

    def take(self, i: np.ndarray) -> _Law:
        out = object.__new__(_Law)
        out.b, out.kbar, out.g, out.rho = self.b[i], self.kbar[i], self.g[i], self.rho[i]
        out.solimp, out.flat, out.d_in, out.width = self.solimp, self.flat, self.d_in, self.width
        out.dp_in, out.k_hi = self.dp_in[i], self.k_hi[i]
        return out

    def stage(self, x, v):
        """Acceleration, force term ``g + b v + d k x``, ``d'`` and interior flag of a stage."""
        if self.flat:
            d, dp = self.d_in, self.dp_in
        else:
            d = impedance_at(np.abs(x), self.solimp)
            dp = effective_impedance(d, self.rho)
        drive = self.g + self.b * v + d * self.kbar * x
        acc = np.where((x > 0) & (drive > 0), self.g - dp * drive, self.g)
        interior = (x >= self.width) & (drive > 0)
        return acc, drive, dp, interior

    def step(self, x, v, h):
        """One RK4 step stage by stage; whether all four stages were interior, or free,
        and its :func:`stage_bits`."""
        a0, _, _, i0 = self.stage(x, v)
        x1, v1 = x + 0.5 * h * v, v + 0.5 * h * a0
        a1, _, _, i1 = self.stage(x1, v1)
        x2, v2 = x + 0.5 * h * v1, v + 0.5 * h * a1
        a2, _, _, i2 = self.stage(x2, v2)
        x3, v3 = x + h * v2, v + h * a2
        a3, _, _, i3 = self.stage(x3, v3)
        x_new = x + h * (v / 6.0 + v1 / 3.0 + v2 / 3.0 + v3 / 6.0)
        v_new = v + h * (a0 / 6.0 + a1 / 3.0 + a2 / 3.0 + a3 / 6.0)
        free = (a0 == self.g) & (a1 == self.g) & (a2 == self.g) & (a3 == self.g)
        inside = stage_bits(x, x1, x2, x3)
        return x_new, v_new, i0 & i1 & i2 & i3, free, inside


def _mat(a, b):
    """Product of 2x2 matrices stored as 4-tuples of arrays (row-major)."""
    return tuple(a[2 * r] * b[c] + a[2 * r + 1] * b[2 + c] for r in (0, 1) for c in (0, 1))


def _lin(*terms):
    """Sum of scaled 2x2 matrices: ``_lin((c, A), (d, B)) = c A + d B``."""
    return tuple(sum(c * m[k] for c, m in terms) for k in range(4))


class _Interior:
    """The closed-form interior map of a subset of contacts (constant impedance ``d_in``)."""

    def __init__(self, law: _Law, h: np.ndarray):
        d, dp = law.d_in, law.dp_in
        w2, c1 = dp * d * law.kbar, dp * law.b
        self.x_star = (1.0 - dp) * law.g / w2
        one = np.ones_like(w2)
        eye = (one, 0 * one, 0 * one, one)
        z = (0 * one, h * one, -h * w2, -h * c1)
        z2 = _mat(z, z)
        z3 = _mat(z2, z)
        z4 = _mat(z3, z)
        self.M = _lin((1, eye), (1, z), (0.5, z2), (1 / 6, z3), (1 / 24, z4))
        stages = (
            eye,
            _lin((1, eye), (0.5, z)),
            _lin((1, eye), (0.5, z), (0.25, z2)),
            _lin((1, eye), (1, z), (0.5, z2), (0.25, z3)),
        )
        root = np.sqrt((c1 * c1 - 4.0 * w2).astype(complex))
        lam = (-c1 + root) / 2.0, (-c1 - root) / 2.0
        mu = [
            1 + hl * (1 + hl / 2 * (1 + hl / 3 * (1 + hl / 4))) for hl in (h * lam[0], h * lam[1])
        ]
        self.lm = 0.5 * np.log(np.abs(mu[0] * mu[1]))
        delta = np.log(mu[0]) - self.lm
        self.osc = np.abs(delta.imag) > 0
        self.rate = np.where(self.osc, np.abs(delta.imag), np.abs(delta.real))
        self.cosh = np.where(self.osc, np.cos(self.rate), np.cosh(self.rate))
        # rows (coefficients on u) and offsets s*: stage penetration beyond the width and
        # stage force term, for the four stages; then the state's x and v
        fx, fv = d * law.kbar, law.b
        rows, offsets = [], []
        for k in stages:
            rows.append((k[0], k[1]))
            offsets.append(self.x_star - law.width)
        for k in stages:
            rows.append((fx * k[0] + fv * k[2], fx * k[1] + fv * k[3]))
            offsets.append(law.g + fx * self.x_star)
        self.rows = rows
        self.offsets = offsets
        self.force_row = rows[4]
        self.force_star = offsets[4]

    def coefficients(self, row, x, v):
        """``q``, ``w`` of a row at ``u_0 = (x - x*, v)``."""
        u0, u1 = x - self.x_star, v
        mu0 = self.M[0] * u0 + self.M[1] * u1
        mu1 = self.M[2] * u0 + self.M[3] * u1
        m = np.exp(self.lm)
        q = row[0] * u0 + row[1] * u1
        p = (row[0] * mu0 + row[1] * mu1) / m
        return q, p - q * self.cosh


def _modes(n, lm, rate, osc):
    """``m^n cosh(n delta)`` and ``m^n sinh(n delta)/sinh(delta)`` (real; delta = i rate if osc)."""
    n, lm, rate, osc = np.broadcast_arrays(n, lm, rate, osc)
    cos_part, sin_part = np.empty(n.shape), np.empty(n.shape)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        i = np.flatnonzero(osc)
        if i.size:
            e = np.exp(n.flat[i] * lm.flat[i])
            th = rate.flat[i] * n.flat[i]
            cos_part.flat[i] = e * np.cos(th)
            sin_part.flat[i] = e * np.sin(th) / np.sin(rate.flat[i])
        i = np.flatnonzero(~osc)
        if i.size:
            nn, ll, dd = n.flat[i], lm.flat[i], rate.flat[i]
            e = np.exp(nn * ll)
            big = dd * nn > 1.0
            ep, em = np.exp(nn * (ll + dd)), np.exp(nn * (ll - dd))
            cos_part.flat[i] = np.where(big, 0.5 * (ep + em), e * np.cosh(dd * nn))
            sh = np.where(big, 0.5 * (ep - em), e * np.sinh(dd * nn)) / np.sinh(dd)
            sin_part.flat[i] = np.where(dd == 0, e * nn, sh)
    return cos_part, sin_part


class _Row:
    """One exponential polynomial ``g(n) = s* + m^n (q cosh n delta + w S_n)`` per pair."""

    def __init__(self, s, q, w, lm, rate, osc):
        self.s, self.q, self.w, self.lm, self.rate, self.osc = s, q, w, lm, rate, osc

    def take(self, i):
        return _Row(*(a[i] for a in (self.s, self.q, self.w, self.lm, self.rate, self.osc)))

    def value(self, n):
        c, s = _modes(n, self.lm, self.rate, self.osc)
        return self.s + self.q * c + self.w * s

    def leaves(self, n):
        """Whether the stage may have left the interior at step ``n`` (conservative)."""
        c, s = _modes(n, self.lm, self.rate, self.osc)
        qc, ws = self.q * c, self.w * s
        g = self.s + qc + ws
        return ~(g > _MARGIN * (np.abs(self.s) + np.abs(qc) + np.abs(ws)))


def _bisect(row: _Row, lo, hi):
    """First integer in ``(lo, hi]`` where ``row`` leaves, for ``leaves(lo)`` false, ``hi`` true."""
    lo, hi = lo.copy(), hi.copy()
    while True:
        open_ = hi - lo > 1
        if not open_.any():
            return hi
        i = np.flatnonzero(open_)
        mid = np.floor(0.5 * (lo[i] + hi[i]))
        out = row.take(i).leaves(mid)
        hi[i] = np.where(out, mid, hi[i])
        lo[i] = np.where(out, lo[i], mid)


def _exit_oscillating(row: _Row):
    """First leaving step ``n >= 1`` and the verified bound, for complex eigenvalues."""
    theta, lm = row.rate, row.lm
    amp_c, amp_s = row.q, row.w / np.sin(theta)
    amp = np.hypot(amp_c, amp_s)
    u0 = np.angle(amp_c + 1j * amp_s) * -1.0  # g = s* + R m^t cos(theta t + u0)
    twist = np.arctan(lm / theta)
    n_exit = np.full(theta.shape, np.inf)
    bound = np.full(theta.shape, np.inf)
    # s* <= 0: the first fall through zero, on the decreasing side of the first bump
    low = row.s <= 0
    if low.any():
        i = np.flatnonzero(low)
        r = row.take(i)
        end = (0.5 * np.pi - u0[i]) / theta[i]
        peak = (twist[i] - u0[i]) / theta[i]
        lo = np.maximum(0.0, np.floor(peak))
        hi = np.maximum(np.ceil(end), lo + 1)
        ok = r.leaves(hi)
        found = _bisect(r, lo, np.where(ok, hi, lo + 1))
        n_exit[i] = np.where(ok, found, np.inf)
        bound[i] = np.where(ok, found - 1, hi)
    # s* > 0: one dip per window where cos < 0; the first window whose dip holds an integer
    i = np.flatnonzero(~low)
    start = np.where(u0[i] <= -0.5 * np.pi, -1.0, 0.0)
    for j in range(_WINDOWS):
        if i.size == 0:
            break
        r = row.take(i)
        th, u, k = theta[i], u0[i], start + j
        ts = (0.5 * np.pi + _TWO_PI * k - u) / th
        te = ts + np.pi / th
        tm = (np.pi + twist[i] + _TWO_PI * k - u) / th
        lo = np.maximum(1.0, np.ceil(ts))
        nf = np.floor(tm)
        out_f = (nf >= lo) & r.leaves(np.maximum(nf, lo))
        found = _bisect(r, lo - 1, np.where(out_f, nf, lo))
        nc = np.maximum(nf + 1, lo)
        out_c = ~out_f & (nc <= te) & r.leaves(nc)
        hit = out_f | out_c
        n_hit = np.where(out_f, found, nc)
        n_exit[i[hit]] = n_hit[hit]
        bound[i[hit]] = n_hit[hit] - 1
        # decaying, and the dips no longer reach zero: it never leaves
        depth = amp[i] * np.exp(lm[i] * np.maximum(te, 0.0))
        never = ~hit & (lm[i] <= 0) & (depth < row.s[i] * (1 - 1e-9))
        keep = ~hit & ~never
        # integers up to the next window's start are verified (cos > 0 between windows)
        bound[i[keep]] = np.ceil(te[keep] + np.pi / th[keep]) - 1
        i, start = i[keep], start[keep]
    return n_exit, bound


def _exit_real(row: _Row):
    """First leaving step ``n >= 1`` and the verified bound, for real eigenvalues."""
    d, lm = row.rate, row.lm
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        sd = np.sinh(d)
        sdc = np.where(d == 0, 1.0, sd / np.where(d == 0, 1.0, d))
        num = row.q * sdc * lm + row.w
        den = row.w * lm + d * row.q * sd
        t_d = -num / den
        tau = t_d * d
        valid = (den != 0) & (np.abs(tau) < 1)
        atc = np.where(tau == 0, 1.0, np.arctanh(tau) / np.where(tau == 0, 1.0, tau))
        t_e = np.where(valid, atc * t_d, -1.0)
    n_exit, bound = np.full(d.shape, np.inf), np.full(d.shape, np.inf)
    # piece A: [1, floor(t_e)], monotone from g(0) > 0
    a_end = np.floor(t_e)
    piece_a = a_end >= 1
    out_a = piece_a & row.leaves(np.maximum(a_end, 1.0))
    if out_a.any():
        k = np.flatnonzero(out_a)
        n_exit[k] = _bisect(row.take(k), np.zeros(k.size), a_end[k])
    # piece B: [lo, inf), monotone
    rest = ~out_a
    lo = np.where(piece_a, a_end + 1, 1.0)
    first = rest & row.leaves(lo)
    n_exit[first] = lo[first]
    rest &= ~first
    top = lm + d
    never = rest & (top < 0) & (row.s > _MARGIN * np.abs(row.s))
    with np.errstate(divide="ignore", invalid="ignore"):
        lead = np.where(d == 0, np.where(row.w != 0, row.w, row.q), row.q + row.w / sd)
    growing = (top >= 0) & (lead > 0)
    never |= rest & growing
    search = np.flatnonzero(rest & ~never)
    if search.size:
        r = row.take(search)
        base = lo[search]
        prev, span = base.copy(), np.ones(search.size)
        hit = np.zeros(search.size, bool)
        for _ in range(62):
            probe = base + span
            out = ~hit & r.leaves(probe)
            hit |= out
            if hit.all():
                break
            prev = np.where(hit, prev, probe)
            span = np.where(hit, span, 2 * span)
        hi = base + span
        found = _bisect(r, prev, np.where(hit, hi, prev + 1))
        n_exit[search] = np.where(hit, found, np.inf)
        bound[search] = np.where(hit, np.inf, prev)
    fin = np.isfinite(n_exit)
    bound[fin] = n_exit[fin] - 1
    return n_exit, bound


def _first_exit(interior: _Interior, x, v):
    """The jump from an interior state: ``(n, exact)``; ``n`` steps stay interior before.

    ``exact`` where step ``n`` is the first that may leave the interior (``n = inf``:
    never); elsewhere ``n`` is a verified partial jump (all steps ``<= n`` interior).
    """
    size = x.size
    rows = interior.rows
    s = np.concatenate([np.broadcast_to(o, (size,)) for o in interior.offsets])
    qw = [interior.coefficients(r, x, v) for r in rows]
    q, w = (np.concatenate([pair[j] for pair in qw]) for j in (0, 1))
    tile = len(rows)
    lm, rate, osc = (np.tile(a, tile) for a in (interior.lm, interior.rate, interior.osc))
    row = _Row(s, q, w, lm, rate, osc)
    n_exit, bound = np.full(s.shape, np.inf), np.full(s.shape, np.inf)
    for mask, solve in ((osc, _exit_oscillating), (~osc, _exit_real)):
        k = np.flatnonzero(mask)
        if k.size:
            n_exit[k], bound[k] = solve(row.take(k))
    n_exit = n_exit.reshape(tile, size).min(axis=0)
    bound = bound.reshape(tile, size).min(axis=0)
    exact = n_exit <= bound + 1
    return np.where(exact, n_exit, bound), exact


def rk4_spectral_radius(
    coeffs: Coefficients, solimp: tuple[float, ...], rho: Any, timestep: Any
) -> np.ndarray:
    r"""Spectral radius of RK4's interior step map (all stages pressed, ``d = d_max``).

    ``max |P(h lambda)|``, ``lambda^2 + d' b lambda + d' d kbar = 0``, ``P`` the degree-4
    Taylor polynomial of ``exp``, ``d`` flat or ``d_max``. Above 1 the map is unstable
    (undamped: ``omega0 h > 2 sqrt(2)``; overdamped: ``h |lambda| > 2.785``). Unvalidated.

    >>> from impactsym.engines.mujoco.model import coefficients
    >>> si = (0.9, 0.9, 0.001, 0.5, 2.0)
    >>> [round(float(rk4_spectral_radius(coefficients(s, si, 0.002), si, 1.0, 0.002)), 4)
    ...  for s in ((0.02, 0.05), (0.004, 0.05))]
    [0.6563, 391.6618]
    """
    b, kbar, rho, h = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (coeffs.damping, coeffs.stiffness, rho, timestep))
    )
    shape = b.shape
    law = _Law(b.ravel(), kbar.ravel(), np.zeros(b.size), rho.ravel(), solimp, is_flat(solimp))
    interior = _Interior(law, h.ravel())
    radius = np.exp(interior.lm + np.where(interior.osc, 0.0, interior.rate))
    return radius.reshape(shape)


def rk4_contact(
    coeffs: Coefficients,
    solimp: tuple[float, ...],
    rho: Any,
    gravity: Any,
    speed: Any,
    timestep: Any,
    phase: Any,
) -> RK4Contact:
    r"""One contact as MuJoCo's RK4 steps it, at a given touch phase (arrays broadcast, SI).

    Parameters
    ----------
    coeffs, solimp
        ``b``, ``kbar`` with refsafe (:func:`~impactsym.engines.mujoco.model.coefficients`
        at ``timestep``) and the checked ``solimp`` (five floats).
    rho
        Weight ratio ``A / A_diag`` (1 for one body on a slide joint).
    gravity, speed, timestep
        Gravity pressing along the normal (m/s^2), approach speed at touch (m/s, > 0), ``h``.
    phase
        Touch phase in ``[0, 1)``: touch lies ``phase * timestep`` before the first
        detecting state; the state one step earlier carries free flight.

    Returns
    -------
    RK4Contact
        Exact per phase: the engine's states under the definitions of
        :mod:`~impactsym.engines.mujoco.stepping`, and which stages were in contact
        (:mod:`~impactsym.engines.mujoco.rk4_record`). Where the entering step throws the body
        back out before the first state (only beyond the stability limit,
        :func:`rk4_spectral_radius`), the contact ends at that state (``steps = 0``).
        Where the body settles, ``max_penetration`` is the supremum over all states and
        ``steps`` is -1; where a force comes back inside the overlap it counts
        the states to the force zero. Settled means: the map returns to a state, or the
        speed is below 1e-9 of ``speed`` under at least half the static force (a varying
        impedance inside its width); else sticking is reported after 100 000 states, as
        the engine driver does.

    Notes
    -----
    Stage by stage where any stage is outside the constant-impedance interior (the
    entering step in the cancellation-free form of
    :func:`~impactsym.engines.mujoco.rk4_entry.entering_step`: at phase ``1e-300`` it is
    the limit ``phase -> 0+``, at phase 0 the first state sits at distance 0 and does not
    detect), by the closed-form power of the interior map elsewhere (module docstring;
    `docs/physics.md`, *MuJoCo's RK4 step*). Inputs are not validated here (the public
    ``predict`` does).

    >>> from impactsym.engines.mujoco.model import coefficients
    >>> si = (0.9, 0.9, 0.001, 0.5, 2.0)
    >>> r = rk4_contact(coefficients((0.02, 0.25), si, 0.002), si, 1.0, 0.0, 1.0, 0.002, 0.1)
    >>> round(float(r.restitution), 9), int(r.steps)
    (0.499005866, 7)
    """
    flat = is_flat(solimp)
    arrays = np.broadcast_arrays(
        *(
            np.asarray(a, dtype=float)
            for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed, timestep, phase)
        )
    )
    shape = arrays[0].shape
    b, kbar, rho, g, speed, h, phase = (np.ascontiguousarray(a).ravel() for a in arrays)
    size = b.size
    law_all = _Law(b, kbar, g, rho, solimp, flat)
    t0 = (phase - 1.0) * h
    x, v = speed * t0 + 0.5 * g * t0 * t0, speed + g * t0
    k = -np.ones(size)  # state index from the first detecting state
    x_prev, v_prev = np.full(size, np.nan), np.full(size, np.nan)
    touched, ended = np.zeros(size, bool), np.zeros(size, bool)
    floats = ("restitution", "departure_speed", "max_penetration", "peak_accel")
    res = {key: np.zeros(size) for key in floats}
    res.update(contact_time=np.full(size, np.inf), steps=np.zeros(size, dtype=np.int64))
    res.update(sticks=np.zeros(size, bool), released_by_position=np.zeros(size, bool))
    res.update(stage_pattern=np.zeros(size, dtype=np.int64))
    act = np.arange(size)
    while act.size:
        law = law_all.take(act)
        xa, va = x[act], v[act]
        # observe the state as the driver does
        _, drive, dp, _ = law.stage(xa, va)
        on = xa > 0
        ena = ended[act]
        back = on & ena & (drive > 0)
        counted = on & ~ena
        ic = act[counted]
        res["max_penetration"][ic] = np.maximum(res["max_penetration"][ic], xa[counted])
        peak = dp * np.maximum(drive, 0.0)
        res["peak_accel"][ic] = np.maximum(
            res["peak_accel"][ic], np.broadcast_to(peak, xa.shape)[counted]
        )
        # the first detecting state is the one after the entering step; where the entering
        # step threw the body back out (beyond the stability limit) the contact ends there
        tou = touched[act] | on | ((k[act] >= 0) & (va < 0))
        end_now = tou & ~ena & (~on | (drive <= 0))
        ia = act[end_now]
        res["restitution"][ia] = -va[end_now] / speed[ia]
        res["contact_time"][ia] = (phase[ia] + k[ia]) * h[ia]
        res["released_by_position"][ia] = ~on[end_now]
        ena = ena | end_now
        gone = tou & ~on & ~back
        res["departure_speed"][act[gone]] = -va[gone]
        res["steps"][act] += (tou & ~ena & ~back).astype(np.int64)
        touched[act], ended[act] = tou, ena
        over = (k[act] >= MAX_STEPS) & ~back & ~gone
        res["steps"][act[over]] = np.where(ended[act[over]], res["steps"][act[over]], -1)
        stays = act[back | over]
        res["sticks"][stays] = True
        res["restitution"][stays] = 0.0
        res["contact_time"][stays] = np.inf
        res["released_by_position"][stays] = False
        alive = ~(back | gone | over)
        act, xa, va, law = act[alive], xa[alive], va[alive], law.take(np.flatnonzero(alive))
        if not act.size:
            break
        # advance: one exact step, or the closed-form jump through the interior
        xn, vn, inner, free, inside = law.step(xa, va, h[act])
        if k[act[0]] < 0:  # the first pass, every contact's entering step: cancellation-free
            xn, vn, inside = entering_step(law.stage, law.g, speed[act], h[act], phase[act])
        res["stage_pattern"][act] ^= pattern_bits(inside, k[act] + 1, ended[act])
        pressed = touched[act] & ~ended[act]
        jump = inner & pressed & (k[act] >= _SHORT)
        # settled: the map returns to a state (fixed point, 2-cycle), or the speed died to
        # 1e-9 of `speed` under half the static force (varying impedance inside its width)
        _, drive_a, dp_a, _ = law.stage(xa, va)
        slow = (np.abs(va) <= 1e-9 * speed[act]) & (np.abs(vn) <= 1e-9 * speed[act])
        held = (law.g > 0) & (drive_a * dp_a >= 0.5 * law.g)
        cycle = pressed & (
            ((xn == xa) & (vn == va)) | ((xn == x_prev[act]) & (vn == v_prev[act])) | (slow & held)
        )
        x_prev[act], v_prev[act] = xa, va
        x[act], v[act] = xn, vn
        k[act] += 1
        if cycle.any():
            ic = act[cycle]
            res["sticks"][ic] = True
            res["steps"][ic] = -1
            act, xa, va, law = act[~cycle], xa[~cycle], va[~cycle], law.take(np.flatnonzero(~cycle))
            jump = jump[~cycle]
            free = free[~cycle]
        glide = free & ended[act] & (xa > 0)  # coasting inside the overlap: jump the parabola
        if glide.any():
            gl, ig = np.flatnonzero(glide), act[glide]
            n = coast_steps(xa[gl], va[gl], law.g[gl], law.b[gl], law.k_hi[gl], h[ig])
            t = np.where(np.isfinite(n), n, 1.0) * h[ig]
            x[ig] = xa[gl] + va[gl] * t + 0.5 * law.g[gl] * t * t
            v[ig] = va[gl] + law.g[gl] * t
            k[ig] += np.where(np.isfinite(n), n, 1.0) - 1
        if jump.any():
            jx = np.flatnonzero(jump)
            ij = act[jx]
            lj = law.take(jx)
            cf = _Interior(lj, h[ij])
            n, exact = _first_exit(cf, xa[jx], va[jx])
            stuck = exact & np.isinf(n)
            # states 1 .. n-1 of the jump are in contact with a positive force
            last = np.where(stuck, np.inf, n - 1)
            qx, wx = cf.coefficients(cf.rows[0], xa[jx], va[jx])
            qf, wf = cf.coefficients(cf.force_row, xa[jx], va[jx])
            pen = row_max(_Row(cf.x_star + 0 * qx, qx, wx, cf.lm, cf.rate, cf.osc), last)
            frc = row_max(_Row(cf.force_star + 0 * qf, qf, wf, cf.lm, cf.rate, cf.osc), last)
            res["max_penetration"][ij] = np.maximum(res["max_penetration"][ij], pen)
            res["peak_accel"][ij] = np.maximum(res["peak_accel"][ij], lj.dp_in * frc)
            res["steps"][ij] += np.where(stuck, 0, np.maximum(n - 1, 0)).astype(np.int64)
            res["sticks"][ij[stuck]] = True
            res["steps"][ij[stuck]] = -1
            go = ~stuck & (n >= 2)
            if go.any():
                gi = np.flatnonzero(go)
                ig = ij[gi]
                nn = n[gi]
                c, s = _modes(nn, cf.lm[gi], cf.rate[gi], cf.osc[gi])
                q_v, w_v = cf.coefficients((0.0, 1.0), xa[jx], va[jx])
                x[ig] = cf.x_star[gi] + c * qx[gi] + s * wx[gi]
                v[ig] = c * q_v[gi] + s * w_v[gi]
                k[ig] += nn - 1
            keep = np.ones(act.size, bool)
            keep[jx[stuck]] = False
            act = act[keep]
    if shape == ():
        return RK4Contact(**{key: val.reshape(()).item() for key, val in res.items()})
    return RK4Contact(**{key: val.reshape(shape) for key, val in res.items()})
