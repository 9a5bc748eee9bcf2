r"""MuJoCo's first contact phase in continuous time (the limit ``timestep -> 0``).

The contact obeys the loaded oscillator of :mod:`~impactsym.engines.mujoco.model`,

.. math::

    x'' + d'\,b\,x' + d'\,d\,\bar k\,x = (1 - d')\,g, \qquad
    f = m\,d'\,(g + b\,x' + d\,\bar k\,x),

and **contact ends** at whichever comes first: the force vanishes
(``g + b x' + d kbar x = 0``) or the penetration does (``x = 0``, the contact is no
longer detected); the engine's own state shows both (`docs/physics.md#simulation-engines`).

* Flat impedance (``solimp[0] == solimp[1]``): the equation is linear and
  :func:`impactsym.contact.release.linear_release` gives the first release in closed
  form (:func:`flat_phase`).
* Varying impedance (MuJoCo's default ``solimp = (0.9, 0.95, 0.001, 0.5, 2)``): inside
  the impedance width the equation is integrated with the classical Runge-Kutta method,
  vectorized over the contacts, a step that crosses the width or the midpoint (where
  ``d''`` jumps) redone to end on it, the release located on the cubic Hermite
  interpolant of the step (Illinois steps); beyond the width the equation is linear and
  :func:`~impactsym.engines.mujoco.beyond_width.passage` carries the state in closed form
  to the release, back to the width, or proves that it sticks (:func:`varying_phase`).

Internal: :func:`~impactsym.engines.mujoco.prediction.predict` and
:mod:`~impactsym.engines.mujoco.design` read it.
All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.release import linear_release
from impactsym.engines.mujoco.beyond_width import passage
from impactsym.engines.mujoco.model import (
    MAX_IMPEDANCE,
    MIN_IMPEDANCE,
    Coefficients,
    effective_impedance,
    impedance_at,
    oscillator,
)
from impactsym.numeric.poly import hermite_basis
from impactsym.records import ArrayRecord

__all__ = ["ContactPhase", "flat_phase", "varying_phase"]

_RK_STEP = 0.04  # Runge-Kutta step in units of 1 / omega_max
_MAX_RK_STEPS = 400_000  # more is refused (a sticking contact is detected well before)


@dataclass(frozen=True, eq=False)
class ContactPhase(ArrayRecord):
    """The first contact phase per unit mass, as arrays (SI). Internal: ``design`` reads it.

    Attributes
    ----------
    restitution, contact_time, released_by_position, max_penetration
        As in :class:`~impactsym.engines.mujoco.prediction.Prediction`.
    peak_accel
        Largest constraint acceleration ``d' (g + b x' + d kbar x)``, m/s^2.
    """

    restitution: np.ndarray
    contact_time: np.ndarray
    released_by_position: np.ndarray
    max_penetration: np.ndarray
    peak_accel: np.ndarray


def flat_phase(
    coeffs: Coefficients, d: Any, rho: Any, gravity: Any, speed: Any, *, extremes: bool = True
) -> ContactPhase:
    """The contact phase at constant impedance ``d``, in closed form. Internal (``design``)."""
    osc = oscillator(coeffs, d, rho, gravity, speed)
    rel = linear_release(osc.damping_ratio, osc.load, osc.offset, extremes=extremes)
    omega = osc.omega0
    with np.errstate(over="ignore", under="ignore"):  # out of range: refused by predict
        return ContactPhase(
            rel.restitution,
            rel.contact_time / omega,
            rel.released_by_position,
            rel.max_penetration * speed / omega,
            rel.peak_force * omega * speed,
        )


@dataclass(frozen=True)
class _Step:
    """One Runge-Kutta step: penetration, its rate and acceleration at both ends."""

    x0: np.ndarray
    v0: np.ndarray
    a0: np.ndarray
    x1: np.ndarray
    v1: np.ndarray
    a1: np.ndarray
    h: np.ndarray

    def at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cubic Hermite ``(x, v)`` at fraction ``s`` (``x`` from ``v``, ``v`` from ``a``)."""
        h00, h10, h01, h11 = hermite_basis(s)
        h = self.h
        x = h00 * self.x0 + h10 * h * self.v0 + h01 * self.x1 + h11 * h * self.v1
        v = h00 * self.v0 + h10 * h * self.a0 + h01 * self.v1 + h11 * h * self.a1
        return x, v

    def crossing(self, mask, threshold, g0, g1):
        """Fraction of the step where ``threshold(x, v, k)`` crosses zero (Illinois steps).

        Evaluated on the contacts ``k = flatnonzero(mask)`` only (``inf`` elsewhere);
        ``threshold`` receives their interpolated states and ``k``.
        """
        out = np.full(mask.shape, np.inf)
        k = np.flatnonzero(mask)
        if k.size == 0:
            return out
        sub = _Step(*(q[k] for q in (self.x0, self.v0, self.a0, self.x1, self.v1, self.a1, self.h)))
        g0, g1 = g0[k], g1[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = g0 / (g0 - g1)
            s = np.clip(np.where(np.isfinite(s), s, 1.0), 0.0, 1.0)
            lo, hi, glo, ghi = np.zeros_like(s), np.ones_like(s), g0, g1
            for _ in range(4):
                gs = threshold(*sub.at(s), k)
                left = np.sign(gs) * np.sign(glo) > 0  # gs * glo may overflow
                lo, glo = np.where(left, s, lo), np.where(left, gs, glo)
                hi, ghi = np.where(left, hi, s), np.where(left, ghi, gs)
                s = np.clip(lo + glo / (glo - ghi) * (hi - lo), 0.0, 1.0)
                s = np.where(np.isfinite(s), s, 0.5 * (lo + hi))
        out[k] = s
        return out


def varying_phase(coeffs: Coefficients, solimp, rho, gravity, speed) -> ContactPhase:
    """The contact phase of ``x'' = (1-d')g - d'(b x' + d k-bar x)`` to its first release.

    Internal (``design``, ``predict``). Inside the impedance width (``x < solimp[2]``)
    the classical Runge-Kutta method with the step ``0.02 / omega_max`` integrates it;
    a step that crosses the width is redone to end on it, and beyond the width, where
    the equation is linear, :func:`~impactsym.engines.mujoco.beyond_width.passage`
    carries the state in closed form to the release or back to the width. The horizon
    allows the flat contact at the softest impedance to pass its second extremum (after
    which it never releases, `docs/physics.md#mujoco-prediction`); beyond the width
    sticking is decided exactly.
    """
    shape = np.shape(coeffs.damping)
    damp, stiff, rho, g, v0 = (
        np.array(a, dtype=float).ravel()
        for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed)
    )
    if v0.size == 0:
        empty = np.zeros(shape)
        return ContactPhase(empty, empty.copy(), empty.astype(bool), empty.copy(), empty.copy())
    damp, stiff, rho, g = np.broadcast_arrays(damp, stiff, rho, g)
    run = _Contacts(damp, stiff, rho, g, v0, solimp)
    pending = np.arange(v0.size)  # in the varying region, to be integrated
    x, v = np.zeros(v0.size), v0.copy()
    while pending.size:
        entered, x, v = run.integrate(pending, x, v)
        pending, x, v = run.beyond(entered, x, v)
    out = (run.e, run.tc, run.by_pos, run.xmax, run.fmax)
    return ContactPhase(*(a.reshape(shape) for a in out))


class _Contacts:
    """The contacts of :func:`varying_phase` (flat arrays) and their results so far."""

    def __init__(self, damp, stiff, rho, g, v0, solimp):
        self.damp, self.stiff, self.rho, self.g, self.v0 = damp, stiff, rho, g, v0
        self.solimp = solimp
        self.width = float(solimp[2])
        # the midpoint, where d'' jumps (not for power 1: d is linear in x there)
        self.kink = float(solimp[2] * solimp[3])
        self.smooth_mid = solimp[4] == 1.0
        # the impedances MuJoCo clamps to [1e-4, 0.9999] (solimp[0] = 1e-300 is 1e-4 there)
        s_hi, s_lo = (float(np.clip(solimp[k], MIN_IMPEDANCE, MAX_IMPEDANCE)) for k in (1, 0))
        d_hi, d_lo = effective_impedance(s_hi, rho), effective_impedance(s_lo, rho)
        omega_hi = np.sqrt(d_hi * s_hi * stiff)
        omega_lo = np.sqrt(d_lo * s_lo * stiff)
        D_lo = d_lo * damp / (2.0 * omega_lo)
        self.h = _RK_STEP / np.maximum(omega_hi, d_hi * damp)
        mu = np.sqrt(np.abs(1.0 - D_lo**2))
        periods = np.where(D_lo < 1.0, 3.5 * np.pi / np.maximum(mu, 1e-3), 0.0)
        self.horizon = (
            np.maximum(80.0, np.minimum(periods, 4000.0)) * np.maximum(1.0, D_lo) / omega_lo
        )
        # beyond the width: the constant-impedance oscillator at d_max
        self.dp_max = effective_impedance(s_hi, rho)
        self.omega = omega_hi
        self.D = d_hi * damp / (2.0 * omega_hi)
        x_s = (1.0 - self.dp_max) * g / (omega_hi * omega_hi)
        # under gravity, where the static penetration lies within the impedance width, a
        # sticking body runs to the horizon: refuse a long one at once
        hopeless = (self.horizon / self.h > _MAX_RK_STEPS) & (g > 0) & ~(x_s > self.width)
        if hopeless.any():
            _too_long(Coefficients(damp, stiff), solimp, np.flatnonzero(hopeless)[0])
        n = v0.size
        self.t = np.zeros(n)
        self.steps = np.zeros(n, dtype=np.int64)
        self.e = np.zeros(n)
        self.tc = np.full(n, np.inf)
        self.by_pos = np.zeros(n, bool)
        self.xmax = np.zeros(n)
        dd0 = impedance_at(np.zeros(n), solimp)
        self.fmax = effective_impedance(dd0, rho) * (g + damp * v0)

    def integrate(self, idx, x, v):
        """Runge-Kutta steps inside the width for the contacts ``idx`` (states ``x``,
        ``v``) until each releases, passes its horizon or reaches the width; returns those
        at the width and their states there.

        A step that crosses the width or the impedance's midpoint (``d''`` jumps there)
        is redone to end on it, so that no step straddles a kink of the law; which side
        of the midpoint a contact is on is kept as a flag (its landing may round to
        either side).
        """
        width, solimp = self.width, self.solimp
        prm = tuple(a[idx] for a in (self.damp, self.stiff, self.rho, self.g))
        h, t, steps = self.h[idx], self.t[idx], self.steps[idx]
        v0, horizon = self.v0[idx], self.horizon[idx]
        upper = x >= self.kink

        def force(x, v, k):
            damp, stiff, _, g = (q[k] for q in prm)
            return g + damp * v + impedance_at(x, solimp) * stiff * x

        def position(x, v, k):
            return x

        def below(level):
            return lambda x, v, k: level - x

        a, _, f_prev = _accel(x, v, prm, solimp)
        entered, x_in, v_in = [], [], []
        while idx.size:
            if steps.max() >= _MAX_RK_STEPS:
                _too_long(Coefficients(self.damp, self.stiff), solimp, idx[np.argmax(steps)])
            xn, vn = _rk4(x, v, h, a, prm, solimp)
            an, dpn, fn = _accel(xn, vn, prm, solimp)
            steps += 1
            t_end = t + h
            hit_f, hit_p, hit_w = fn <= 0, xn <= 0, xn >= width
            hit_m = self._crosses_kink(upper, xn)
            hit = hit_f | hit_p | hit_w
            if hit.any() or hit_m.any():
                # a step that starts on the width (where a passage beyond it ended) and
                # ends beyond it again goes on in closed form from its end
                cross_w = hit_w & (x < width)
                seg = _Step(x, v, a, xn, vn, an, h)
                s_f = seg.crossing(hit_f, force, f_prev, fn)
                s_p = seg.crossing(hit_p, position, x, xn)
                s_w = seg.crossing(cross_w, below(width), width - x, width - xn)
                s_w = np.where(hit_w & ~cross_w, 1.0, s_w)
                s_m = seg.crossing(hit_m, below(self.kink), self.kink - x, self.kink - xn)
                s_r = np.minimum(s_f, s_p)
                rel = hit & (s_r <= np.minimum(s_w, s_m))
                if rel.any():
                    v_at = seg.at(np.where(rel, s_r, 0.0))[1][rel]
                    k = idx[rel]
                    self.e[k] = -v_at / v0[rel]
                    self.tc[k] = t[rel] + s_r[rel] * h[rel]
                    self.by_pos[k] = s_p[rel] < s_f[rel]
                on_w = ~rel & (s_w <= s_m)
                land = ~rel & ((cross_w & on_w) | (hit_m & ~on_w))
                if land.any():  # the step again, ending on the width or the midpoint
                    hs = np.minimum(s_w, s_m)[land] * h[land]
                    on = np.where(on_w[land], width, self.kink)
                    sub = tuple(p[land] for p in prm)
                    xl, vl = _rk4(x[land], v[land], hs, a[land], sub, solimp)
                    xn[land], vn[land], t_end[land] = xl, vl, t[land] + hs
                    an[land], dpn[land], fn[land] = _accel(xl, vl, sub, solimp)
                    upper[land] ^= on < width  # on the midpoint: now on its other side
                hit_w = hit_w & on_w
                hit = rel | hit_w
            live = ~hit
            k = idx[live]
            self.xmax[k] = np.maximum(self.xmax[k], xn[live])
            self.fmax[k] = np.maximum(self.fmax[k], dpn[live] * fn[live])
            if hit_w.any():
                k = hit_w
                entered.append(idx[k])
                x_in.append(xn[k])
                v_in.append(vn[k])
                self.xmax[idx[k]] = np.maximum(self.xmax[idx[k]], xn[k])
            t = t_end
            live &= t < horizon  # past it: never released, it sticks (e 0, tc inf)
            if not live.all():
                gone = ~live
                self.t[idx[gone]], self.steps[idx[gone]] = t[gone], steps[gone]
                idx, h, t, steps, v0, horizon, upper = (
                    q[live] for q in (idx, h, t, steps, v0, horizon, upper)
                )
                prm = tuple(q[live] for q in prm)
                x, v, a, f_prev = xn[live], vn[live], an[live], fn[live]
            else:
                x, v, a, f_prev = xn, vn, an, fn
        if not entered:
            return np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0)
        return np.concatenate(entered), np.concatenate(x_in), np.concatenate(v_in)

    def _crosses_kink(self, upper, xn):
        """Whether a step from the side ``upper`` of the midpoint ends on its other side."""
        if self.smooth_mid:
            return np.zeros(xn.shape, bool)
        return np.where(upper, xn < self.kink, xn > self.kink)

    def beyond(self, idx, x, v):
        """Closed-form passages beyond the width for the contacts ``idx`` at the states
        ``x``, ``v``; returns those back at the width and their states."""
        if idx.size == 0:
            return idx, x, v
        p = passage(
            omega=self.omega[idx],
            D=self.D[idx],
            gravity=self.g[idx],
            dp=self.dp_max[idx],
            x0=x,
            v0=v,
            width=np.minimum(self.width, x),
        )
        self.xmax[idx] = np.maximum(self.xmax[idx], p.max_penetration)
        self.fmax[idx] = np.maximum(self.fmax[idx], p.peak_accel)
        rel = p.released
        self.e[idx[rel]] = -p.velocity[rel] / self.v0[idx[rel]]
        self.tc[idx[rel]] = self.t[idx[rel]] + p.duration[rel]
        back = ~rel & np.isfinite(p.duration)
        self.t[idx[back]] += p.duration[back]
        return idx[back], p.position[back], p.velocity[back]


def _accel(x, v, prm, solimp):
    """Acceleration ``(1-d')g - d'(b v + d kbar x)``, ``d'`` and the force threshold
    ``g + b v + d kbar x`` at ``(x, v)``; ``prm = (b, kbar, rho, g)``."""
    damp, stiff, rho, g = prm
    dd = impedance_at(x, solimp)
    dp = effective_impedance(dd, rho)
    f = g + damp * v + dd * stiff * x
    return g - dp * f, dp, f


def _rk4(x, v, h, a0, prm, solimp):
    """One classical Runge-Kutta step of size ``h`` from ``(x, v)`` with ``x'' = a0`` there."""
    v2 = v + 0.5 * h * a0
    a2 = _accel(x + 0.5 * h * v, v2, prm, solimp)[0]
    v3 = v + 0.5 * h * a2
    a3 = _accel(x + 0.5 * h * v2, v3, prm, solimp)[0]
    v4 = v + h * a3
    a4 = _accel(x + h * v3, v4, prm, solimp)[0]
    return x + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4), v + h / 6.0 * (
        a0 + 2.0 * a2 + 2.0 * a3 + a4
    )


def _too_long(coeffs: Coefficients, solimp, i):
    one = Coefficients(coeffs.damping[i], coeffs.stiffness[i])
    timeconst, dampratio = one.solref(solimp)
    stiffness, damping = one.solref(solimp, form="stiffness")
    raise ValueError(
        f"predict: solref = ({timeconst:.6g}, {dampratio:.6g}) (or equivalently "
        f"({stiffness:.6g}, {damping:.6g}); element {i}) needs more "
        f"than {_MAX_RK_STEPS} integration steps with the varying solimp {solimp!r} "
        f"(very overdamped, and rest is not provable: the static penetration lies within "
        f"the impedance width); use a flat solimp (d_min == d_max), whose prediction is "
        f"in closed form, or less damping"
    )
