r"""Exact numerics of a normalized contact law: one impact, integrated on whole arrays.

Solves :math:`z'' = b - \varphi(z, z')`, :math:`z(0) = 0`, :math:`z'(0) = 1` of
:mod:`impactsym.contact.laws` for arrays of (damping number, pressing term, exponent) at
once and returns the contact time, restitution, maximum penetration, peak force and
whether the body sticks (``docs/physics.md``, "Nonlinear contact laws").

Why this numerics
-----------------
* **Order 8, adaptive per element.** Every element carries its own step size through the
  Dormand–Prince 8(5,3) pair (:mod:`impactsym.contact.rk853`); one iteration advances all
  active elements by one step (a loop over steps on whole arrays, never over elements).
* **No series start is needed.** At touch :math:`z \approx \tau`, so the terms
  :math:`z^p`, :math:`z^{(p-1)/2}`, :math:`z^{1/2}` make the solution non-smooth at
  :math:`\tau = 0` (e.g. :math:`z - \tau \propto \tau^{9/4}` for Tsuji with p = 3/2). The
  error estimate sees this and shrinks the first steps (to about :math:`10^{-6}`);
  the error they commit is of the order of the tolerance, not of the step.
* **Graded approach to d = 0.** The same singularity sits at the exit :math:`z \to 0`.
  While the body moves out, a step may cover at most half the remaining time
  :math:`z/|z'|` to ``z = 0``, so steps shrink geometrically, no stage ever evaluates a
  negative overlap, and the exit is reached when :math:`z` is :math:`10^{-14}` of the
  maximum penetration, or earlier where the force left cannot change :math:`z'` by
  :math:`10^{-14}` of it: :math:`\varphi = R(z) + C(z) z'` with ``R`` and ``|C|``
  non-decreasing in ``z``, so over the remaining flight :math:`z/|z'|`,
  :math:`|\Delta z'| \le (b + R(z) + |C(z) z'|)\, z/|z'|` (Hunt–Crossley then exits
  near :math:`z = 10^{-6}`, a fifth fewer steps; the remaining flight is added). Under
  the force and clipped conditions this early exit is taken only where the reduced force
  at ``z = 0`` and the current rate is positive, so the force cannot vanish on the way:
  with little damping the force zero sits just above ``z = 0`` (``z = -\beta z'``
  viscoelastic), and leaving at ``z = 0`` instead put the contact time off by the
  remaining flight, up to 3e-7 of it at :math:`\beta = 10^{-6}`.
* **Coasts in closed form (clipped condition).** Where the reduced force falls through
  zero the clipped contact's force :math:`\max(0, \varphi)` vanishes and the body flies,
  :math:`z'' = b`: the coast is solved exactly (:func:`~impactsym.contact.lawcoast.coast`:
  it leaves at ``z = 0`` iff the free flight reaches it, else the force returns at the
  root of the convex reduced force), and the integration restarts from there.
* **Events by the step map.** A sign change of the reduced force (force and clipped
  conditions), of
  :math:`z'` (maximum penetration) or of :math:`d\varphi/d\tau` (a force maximum) inside
  an accepted step is located by Illinois iteration on the length of one order-8 step
  from the step's start, so the event is as accurate as the integration. The extrema
  (maximum penetration, force maxima, and the force minimum that only closes the bracket
  of a force zero) stop at a bracket of :data:`EXTREMUM_WIDTH` of the step: the value at
  an extremum is off by half its curvature times the square of the time error
  (:math:`10^{-18} h^2`), so iterating to the last bit would buy nothing.
* **Sticking is decided by energy, never by a time limit.** The energy
  :math:`E = z'^2/2 + V(z) - b z` never increases. With a pressing force the body can
  never reach ``z = 0`` once :math:`E < 0` (position condition), and never reach a zero of
  the force once :math:`E < E_\mathrm{c} = \min(0, \min_z [w_0(z)^2/2 + V(z) - bz])`,
  :math:`w_0(z)` the rate at which the force vanishes (force condition; the bracket is
  convex in ``z``, minimized by bisection of its slope); clipped: once
  :math:`E < E_\mathrm{esc}`, the least energy of a force zero from which the coast
  reaches ``z = 0`` (:func:`~impactsym.contact.lawcoast.escape_energy`). A trapped body
  is followed to its
  rest for the maximum penetration and peak force: until an upper bound of all later
  forces (at the largest overlap of its energy, and its largest speed) is below the
  largest force met, or it is within :math:`10^{-12}` of equilibrium. A heavily
  over-damped body creeps towards rest on a time scale far beyond the step size that the
  fast mode allows an explicit method (a stiff system); after :data:`FOLLOW` steps its
  creep is taken as settled, the maximum penetration as the larger of the one met and
  the static overlap, the peak force as the larger of the one met and ``b``.
  Without pressing force the caller states where sticking is known (linear and Tsuji
  maps); for ``"hertz-linear"`` the region :math:`0 < z < D^{2/(p-1)}`,
  :math:`-Dz \le z' \le 0` is invariant and never reaches ``z = 0`` (proof in the docs).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from impactsym.contact import rk853
from impactsym.contact.lawcoast import coast, escape_energy
from impactsym.contact.laws import contact_law, p, w, z
from impactsym.numeric.codegen import lambdify

#: Tolerances of the order-8 steps (relative, absolute); global error about 1e-12.
RTOL, ATOL = 1e-13, 1e-14
#: Exit reached when the overlap is this fraction of the maximum penetration, or the
#: force left on the way to ``z = 0`` changes ``z'`` by less than this fraction of it.
EXIT_FRACTION = 1e-14
#: A trapped body is at rest when within this (relative) distance of its equilibrium.
REST = 1e-12
#: Most steps any element may take before the call fails naming the inputs.
MAX_STEPS = 100_000
#: Steps a trapped (sticking) body is followed before its creep is taken as settled.
FOLLOW = 2_000
#: Relative bracket (of the step) where an event that truncates the step is located.
EVENT_WIDTH = 4e-16
#: Relative bracket where an extremum is located: its value is off by the square of it.
EXTREMUM_WIDTH = 1e-9

_B = sp.Symbol("b", positive=True)


@dataclass(frozen=True)
class LawFunctions:
    """The normalized law lambdified: arguments ``(z, w, delta, p)`` (``rate``, ``h_slope``
    also ``b``)."""

    phi: object
    reduced: object
    rate: object
    spring: object
    damper: object
    potential: object
    release: object
    release_slope: object
    reduced_z: object
    reduced_w: object
    relax_power: object


@cache
def law_functions(name: str) -> LawFunctions:
    """Lambdify the expressions of :func:`~impactsym.contact.laws.contact_law` once."""
    law = contact_law(name)
    args = [z, w, law.number, p]
    w0 = law.release_speed
    spring = law.reduced_force.subs(w, 0)  # R(z) = z^a of lawcoast

    def fn(expr: sp.Expr, label: str, extra: tuple = ()) -> object:
        compiled = lambdify([*args, *extra], expr, name=f"{name}_{label}").compiled

        def evaluate(*values: np.ndarray) -> np.ndarray:
            # the compiled SymPy function itself (the bridge's broadcasting costs more
            # than the formula on the small arrays of one step): broadcast here
            out = compiled(*values)
            return out if np.shape(out) == np.shape(values[0]) else out + 0.0 * values[0]

        return evaluate

    return LawFunctions(
        phi=fn(law.phi, "phi"),
        reduced=fn(law.reduced_force, "reduced"),
        rate=fn(law.force_rate, "rate", (_B,)),
        spring=fn(law.spring, "spring"),
        damper=fn(law.damper, "damper"),
        potential=fn(law.potential, "potential"),
        release=fn(w0, "release"),
        release_slope=fn(sp.powsimp(sp.expand(w0 * sp.diff(w0, z)), force=True), "slope"),
        reduced_z=fn(sp.diff(law.reduced_force, z), "reduced_z"),
        reduced_w=fn(sp.diff(law.reduced_force, w), "reduced_w"),
        relax_power=fn(sp.simplify(z * sp.diff(spring, z) / spring), "relax_power"),
    )


@dataclass(frozen=True)
class Normalized:
    """One impact per element, normalized: ``tau_c`` (``inf`` when sticking), ``e``,
    ``z_max``, ``peak`` (largest normalized compressive force), ``sticks``, and
    ``z_end``, the overlap where the contact ended (``0`` at ``z = 0``, ``nan`` where it
    sticks or the end was given)."""

    tau_c: np.ndarray
    e: np.ndarray
    z_max: np.ndarray
    peak: np.ndarray
    sticks: np.ndarray
    z_end: np.ndarray | None = None


class _System:
    """The right-hand side and the order-8 step of one law on a subset of elements."""

    def __init__(self, fns: LawFunctions, delta: np.ndarray, b: np.ndarray, q: np.ndarray):
        self.fns, self.delta, self.b, self.q = fns, delta, b, q

    def sub(self, index: np.ndarray) -> _System:
        return _System(self.fns, self.delta[index], self.b[index], self.q[index])

    def phi(self, y: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return np.array(self.fns.phi(np.maximum(y[0], 0.0), y[1], self.delta, self.q))

    def rhs(self, y: np.ndarray) -> np.ndarray:
        out = np.empty_like(y)
        out[0] = y[1]
        with np.errstate(all="ignore"):
            out[1] = self.b - self.fns.phi(np.maximum(y[0], 0.0), y[1], self.delta, self.q)
        return out

    def reduced(self, y: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            return self.fns.reduced(np.maximum(y[0], 0.0), y[1], self.delta, self.q)

    def rate(self, y: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            r = self.fns.rate(np.maximum(y[0], 0.0), y[1], self.delta, self.q, self.b)
        return np.where(np.isnan(r), np.inf, r)  # at z = 0 the rate may be +inf * ...

    def energy(self, y: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            V = self.fns.potential(np.maximum(y[0], 0.0), 0.0, self.delta, self.q)
        return 0.5 * y[1] ** 2 + V - self.b * y[0]

    def step(self, y: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One DOP853 step of length ``h`` (per element): new state and error norm."""
        n = y.shape[1]
        K = np.empty((rk853.N_STAGES + 1, 2 * n))  # row i: the stage's (z', w') flattened
        phi, delta, q, b = self.fns.phi, self.delta, self.q, self.b
        with np.errstate(all="ignore"):  # once per step, not per stage
            yi = y
            for i in range(rk853.N_STAGES + 1):
                if i == rk853.N_STAGES:
                    yi = y1 = y + h * (rk853.B @ K[: rk853.N_STAGES]).reshape(2, n)
                elif i > 0:
                    yi = y + h * (rk853.A[i, :i] @ K[:i]).reshape(2, n)
                K[i, :n] = yi[1]
                K[i, n:] = b - phi(np.maximum(yi[0], 0.0), yi[1], delta, q)
        scale = ATOL + RTOL * np.maximum(np.abs(y), np.abs(y1))
        e5 = ((rk853.E5 @ K).reshape(2, n) / scale) ** 2
        e3 = ((rk853.E3 @ K).reshape(2, n) / scale) ** 2
        n5, n3 = e5.sum(axis=0), e3.sum(axis=0)
        with np.errstate(all="ignore"):
            err = np.abs(h) * n5 / np.sqrt((n5 + 0.01 * n3) * 2.0)
        return y1, np.where((n5 == 0) & (n3 == 0), 0.0, err)

    def falling_rate(self, y: np.ndarray) -> np.ndarray:
        """``-rate``: positive while the force falls (the event of a force minimum)."""
        return -self.rate(y)

    def locate(
        self, y0: np.ndarray, h: np.ndarray, event, *, width: float = EVENT_WIDTH
    ) -> tuple[np.ndarray, np.ndarray]:
        """Where ``event(system, y)`` (positive at ``y0``, not positive at the end of the
        step of length ``h``) crosses zero: Illinois iteration on the step length, each
        element until its bracket is ``width`` of its step (or it lands on the root)."""
        lo, hi = np.zeros_like(h), h.copy()
        y_hi = self.step(y0, h)[0]
        g_lo, g_hi = (
            np.array(event(self, y0), dtype=float),
            np.array(event(self, y_hi), dtype=float),
        )
        best_y, best_h = y_hi, hi.copy()
        side = np.zeros(h.shape, dtype=int)
        idx = np.arange(h.size)  # the elements still iterating
        system = self
        for _ in range(60):
            lo_i, hi_i, gl, gh = lo[idx], hi[idx], g_lo[idx], g_hi[idx]
            with np.errstate(all="ignore"):
                theta = (lo_i * gh - hi_i * gl) / (gh - gl)
            bad = ~np.isfinite(theta) | (theta <= lo_i) | (theta >= hi_i)
            theta = np.where(bad, 0.5 * (lo_i + hi_i), theta)
            y_t = system.step(y0[:, idx], theta)[0]
            g_t = event(system, y_t)
            right = g_t <= 0  # the root is in [lo, theta]
            r_idx = idx[right]
            best_y[:, r_idx], best_h[r_idx] = y_t[:, right], theta[right]
            hi_i, gh = np.where(right, theta, hi_i), np.where(right, g_t, gh)
            lo_i, gl = np.where(right, lo_i, theta), np.where(right, gl, g_t)
            # Illinois: halve the value kept on the same side twice
            s_i = side[idx]
            gl = np.where(right & (s_i == 1), 0.5 * gl, gl)
            gh = np.where(~right & (s_i == -1), 0.5 * gh, gh)
            lo[idx], hi[idx], g_lo[idx], g_hi[idx] = lo_i, hi_i, gl, gh
            side[idx] = np.where(right, 1, -1)
            keep = ~(((hi_i - lo_i) <= width * h[idx]) | (g_t == 0))
            if not keep.any():
                break
            if not keep.all():
                idx = idx[keep]
                system = self.sub(idx)
        return best_h, best_y


def _rate_of_overlap(_system: _System, y: np.ndarray) -> np.ndarray:
    """The event of the maximum penetration: :math:`z' = 0`."""
    return y[1]


def equilibrium(fns: LawFunctions, delta, b, q) -> tuple[np.ndarray, np.ndarray]:
    """Static penetration :math:`z_s = b^{1/p}` and energy :math:`E(z_s, 0)`."""
    with np.errstate(all="ignore"):
        z_s = np.where(b > 0, b ** (1.0 / q), 0.0)
        E_eq = fns.potential(z_s, 0.0, delta, q) - b * z_s
    return z_s, E_eq


def force_trap_energy(fns: LawFunctions, delta, b, q, z_s) -> np.ndarray:
    r""":math:`E_\mathrm{c} = \min(0, \min_{0<z\le z_s} [w_0^2/2 + V - bz])`: below it the
    force can no longer vanish. The bracket is convex; bisection of its slope."""
    lo, hi = np.zeros_like(z_s), z_s.copy()
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        with np.errstate(all="ignore"):
            slope = fns.release_slope(mid, 0.0, delta, q) + fns.spring(mid, 0.0, delta, q) - b
        up = ~(slope < 0)
        hi, lo = np.where(up, mid, hi), np.where(up, lo, mid)
    zc = 0.5 * (lo + hi)
    with np.errstate(all="ignore"):
        w0 = fns.release(zc, 0.0, delta, q)
        value = 0.5 * w0**2 + fns.potential(zc, 0.0, delta, q) - b * zc
    value = np.where(np.isnan(value), np.inf, value)  # no damping: the force vanishes at z = 0 only
    return np.minimum(0.0, value)


def force_bound(fns: LawFunctions, delta, b, q, energy, E_eq) -> np.ndarray:
    r"""An upper bound of the force at energy ``E`` and all later times: with
    :math:`z \le z_E` (the largest root of :math:`V(z) - bz = E`, by Newton's iteration from
    above, which stays above the root on this convex function) and
    :math:`|z'| \le \sqrt{2 (E - E_\mathrm{eq})}`, :math:`\varphi \le \varphi(z_E, 0) +
    \varphi_w(z_E) \sqrt{2 (E - E_\mathrm{eq})}`."""
    with np.errstate(all="ignore"):
        zE = np.maximum(
            (2.0 * (q + 1.0) * b) ** (1.0 / q),
            (2.0 * (q + 1.0) * np.maximum(energy, 0.0)) ** (1.0 / (q + 1.0)),
        )
        for _ in range(60):
            excess = fns.potential(zE, 0.0, delta, q) - b * zE - energy
            slope = fns.spring(zE, 0.0, delta, q) - b
            step = np.where(slope > 0, excess / slope, 0.0)
            zE = zE - np.maximum(step, 0.0)
            if np.all(step <= 1e-15 * zE):
                break
        speed = np.sqrt(2.0 * np.maximum(energy - E_eq, 0.0))
        return fns.spring(zE, 0.0, delta, q) + fns.damper(zE, 0.0, delta, q) * speed


def integrate(
    name: str,
    delta: np.ndarray,
    b: np.ndarray,
    q: np.ndarray,
    *,
    condition: str,
    end_time: np.ndarray | None = None,
    start: tuple[np.ndarray, np.ndarray] | None = None,
    settle: bool = True,
) -> Normalized:
    r"""Integrate one impact per element of the flat arrays ``delta``, ``b``, ``q``.

    ``condition``: ``"position"``, ``"force"`` or ``"clipped"`` (the force
    :math:`\max(0, \varphi)` on the overlap ``z > 0``: where it would turn tensile the
    body coasts, :func:`~impactsym.contact.lawcoast.coast`, and the contact ends at
    ``z = 0``). ``end_time``: ``nan`` where the end is to be found, a finite time where it
    is known (the contact is followed up to it only for the maximum penetration and peak
    force), ``inf`` where the body is known to stick. ``start``: the state ``(z, z')`` at
    the start of the contact (default ``(0, 1)``, a first impact; a force-condition
    re-contact starts from a deflected element), with a compressive force there.
    ``settle=False`` stops a trapped body at the verdict (its maximum penetration and
    peak force are then those met so far): for callers that ask only whether it sticks.
    """
    n = delta.size
    fns = law_functions(name)
    system = _System(fns, delta, b, q)
    end = np.full(n, np.nan) if end_time is None else np.asarray(end_time, dtype=float)
    if start is None:
        y = np.stack((np.zeros(n), np.ones(n)))
    else:
        y = np.stack([np.broadcast_to(np.asarray(a, dtype=float), (n,)) for a in start])
    t = np.zeros(n)
    h = np.full(n, 1e-3)
    tau_c, e, z_end = np.full(n, np.nan), np.zeros(n), np.full(n, np.nan)
    z_max, found_max = y[0].copy(), np.zeros(n, dtype=bool)
    peak = np.maximum(np.array(system.phi(y)), 0.0)
    sticks = np.isinf(end)
    z_s, E_eq = equilibrium(fns, delta, b, q)
    E_trap = {
        "position": lambda: np.zeros(n),
        "force": lambda: force_trap_energy(fns, delta, b, q, z_s),
        "clipped": lambda: escape_energy(fns, delta, b, q),
    }[condition]()
    by_force = condition in ("force", "clipped")
    hertz_trap = name == "hertz-linear"
    active = np.ones(n, dtype=bool)
    followed = np.zeros(n, dtype=int)
    for _ in range(MAX_STEPS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        sub = system.sub(idx)
        y0, t0, hi = y[:, idx], t[idx], h[idx]
        known = np.isfinite(end[idx])
        hi = np.where(known, np.minimum(hi, end[idx] - t0), hi)
        leaving = (y0[1] < 0) & ~known
        hi = np.where(leaving, np.minimum(hi, 0.5 * y0[0] / np.maximum(-y0[1], 1e-300)), hi)
        y1, err = sub.step(y0, hi)
        ok = (err <= 1.0) & np.all(np.isfinite(y1), axis=0) & ((y1[0] >= 0) | known)
        with np.errstate(divide="ignore"):
            factor = np.clip(0.9 * err ** (-1.0 / 8.0), 0.2, 10.0)
        h[idx] = np.where(ok, hi * factor, hi * np.minimum(factor, 0.5))
        if not ok.any():
            continue
        acc = idx[ok]
        sub = system.sub(acc)
        y0, y1, hs, t0 = y0[:, ok], y1[:, ok], hi[ok], t0[ok]
        ended = np.zeros(acc.size, dtype=bool)
        coasts = np.zeros(acc.size, dtype=bool)
        # the end of the contact force inside this step: truncate the step there
        if by_force:
            g0, g1 = sub.reduced(y0), sub.reduced(y1)
            cross = (g0 > 0) & ~(g1 > 0) & ~np.isfinite(end[acc])
            # a dip through zero inside the step, positive at both ends: the force has a
            # minimum in the step (its rate turns from falling to rising); where the force
            # there is not positive, the step is cut at that minimum and the zero before
            # it is located below
            dip = (g0 > 0) & (g1 > 0) & ~np.isfinite(end[acc])
            dip &= (sub.rate(y0) < 0) & (sub.rate(y1) > 0)
            if dip.any():
                c = np.flatnonzero(dip)
                part = sub.sub(c)
                hm, ym = part.locate(y0[:, c], hs[c], _System.falling_rate, width=EXTREMUM_WIDTH)
                low = ~(part.reduced(ym) > 0)
                c, hm, ym = c[low], hm[low], ym[:, low]
                hs[c], y1[:, c] = hm, ym
                cross[c] = True
            if cross.any():
                c = np.flatnonzero(cross)
                hc, yc = sub.sub(c).locate(y0[:, c], hs[c], _System.reduced)
                hs[c], y1[:, c] = hc, yc
                if condition == "force":
                    ended[c] = True
                else:
                    coasts[c] = True
        # maximum penetration and force maxima inside the (truncated) step
        first = ~found_max[acc] & (y0[1] > 0) & ~(y1[1] > 0)
        if first.any():
            c = np.flatnonzero(first)
            _, ym = sub.sub(c).locate(y0[:, c], hs[c], _rate_of_overlap, width=EXTREMUM_WIDTH)
            z_max[acc[c]], found_max[acc[c]] = ym[0], True
            peak[acc[c]] = np.maximum(peak[acc[c]], sub.sub(c).phi(ym))
        top = ~(sub.rate(y0) <= 0) & (sub.rate(y1) <= 0)
        if top.any():
            c = np.flatnonzero(top)
            _, yp = sub.sub(c).locate(y0[:, c], hs[c], _System.rate, width=EXTREMUM_WIDTH)
            peak[acc[c]] = np.maximum(peak[acc[c]], sub.sub(c).phi(yp))
        peak[acc] = np.maximum(peak[acc], sub.phi(y1))
        z_max[acc] = np.where(found_max[acc], z_max[acc], np.maximum(z_max[acc], y1[0]))
        t1 = t0 + hs
        if coasts.any():  # clipped: coast through the overlap (closed form)
            c = np.flatnonzero(coasts)
            ac = acc[c]
            flight = coast(fns, y1[0, c], y1[1, c], delta[ac], b[ac], q[ac])
            t1[c] += flight.duration
            y1[:, c] = np.stack((flight.z, flight.w))
            ended[c[flight.leaves]] = True
        tau_c[acc[ended]] = t1[ended]
        e[acc[ended]] = -y1[1, ended]
        # a known end, or the exit at z = 0 (graded approach)
        at_end = np.isfinite(end[acc]) & (t1 >= end[acc])
        exit_ = ~ended & ~np.isfinite(end[acc]) & (y1[1] < 0)
        near = y1[0] <= EXIT_FRACTION * np.maximum(z_max[acc], 1e-300)
        # or the force left on the way to z = 0 changes z' by less than EXIT_FRACTION
        ask = np.flatnonzero(exit_ & ~near & (y1[0] <= 1e-3 * z_max[acc]))
        if ask.size:
            ac, zz, ww = acc[ask], y1[0, ask], -y1[1, ask]
            with np.errstate(all="ignore"):
                push = b[ac] + fns.spring(zz, 0.0, delta[ac], q[ac])
                push = push + np.abs(fns.damper(zz, 0.0, delta[ac], q[ac])) * ww
                near[ask] = push * zz <= EXIT_FRACTION * ww * ww
                if by_force:  # not where the force would vanish before z = 0
                    near[ask] &= fns.reduced(0.0 * zz, -ww, delta[ac], q[ac]) > 0
        exit_ &= near
        with np.errstate(divide="ignore"):
            tau_c[acc[exit_]] = t1[exit_] + y1[0, exit_] / -y1[1, exit_]
        e[acc[exit_]] = -y1[1, exit_]
        z_end[acc[ended]] = y1[0, ended]
        z_end[acc[exit_]] = 0.0
        tau_c[acc[at_end]] = end[acc[at_end]]
        done = ended | exit_ | at_end
        # trapped: the body can no longer leave (sticks)
        b_acc = b[acc]
        energy = sub.energy(y1)
        trapped = sticks[acc] | ((b_acc > 0) & (energy < E_trap[acc]))
        if hertz_trap and condition == "position":
            dn, zz, ww = delta[acc], y1[0], y1[1]
            with np.errstate(all="ignore"):
                inside = zz ** (q[acc] - 1.0) < dn * dn
            trapped |= (b_acc == 0) & inside & (ww <= 0) & (ww >= -dn * zz)
        trapped &= ~done
        sticks[acc] |= trapped
        rest = (b_acc == 0) & (y1[1] < 0) & found_max[acc]
        zs = z_s[acc]
        rest |= (b_acc > 0) & (np.abs(y1[0] - zs) <= REST * zs) & (np.abs(y1[1]) <= REST * zs)
        bounded = trapped & ~rest & (b_acc > 0) & found_max[acc]
        if bounded.any():
            c = np.flatnonzero(bounded)
            ac = acc[c]
            top_force = force_bound(fns, delta[ac], b_acc[c], q[ac], energy[c], E_eq[ac])
            rest[c] = top_force <= np.maximum(peak[acc[c]], b_acc[c])
        followed[acc] += trapped
        rest |= followed[acc] > FOLLOW  # a stiff creep towards rest: see the docs
        if not settle:
            rest[:] = True
        rest &= trapped
        done |= rest
        y[:, acc], t[acc] = y1, t1
        active[acc[done]] = False
    else:
        bad = np.flatnonzero(active)[0]
        raise ValueError(
            f"the {name} contact with damping number {delta[bad]!r}, pressing term "
            f"{b[bad]!r}, exponent {q[bad]!r} was not decided in {MAX_STEPS} steps"
        )
    pressed = sticks & (b > 0)
    z_max = np.where(pressed & ~found_max, np.maximum(z_max, z_s), z_max)
    peak = np.where(pressed, np.maximum(peak, b), peak)
    tau_c = np.where(sticks, np.inf, tau_c)
    e = np.where(sticks, 0.0, np.clip(e, 0.0, 1.0))
    z_end = np.where(sticks, np.nan, z_end)
    return Normalized(tau_c=tau_c, e=e, z_max=z_max, peak=peak, sticks=sticks, z_end=z_end)
