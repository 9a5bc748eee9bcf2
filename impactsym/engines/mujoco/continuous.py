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
* Varying impedance (MuJoCo's default ``solimp = (0.9, 0.95, 0.001, 0.5, 2)``): the
  equation is integrated with the classical Runge-Kutta method, vectorized over the
  contacts, the release located on the cubic Hermite interpolant of the step (Illinois
  steps), and a contact is declared sticking as soon as a closed-form bound proves that
  it never releases (:class:`RestProof`), instead of after a fixed horizon
  (:func:`varying_phase`).

Internal: :func:`~impactsym.engines.mujoco.prediction.predict` and
:mod:`~impactsym.engines.mujoco.design` read it.
All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.release import linear_release
from impactsym.engines.mujoco.model import (
    MAX_IMPEDANCE,
    MIN_IMPEDANCE,
    Coefficients,
    d_max,
    effective_impedance,
    impedance_at,
    oscillator,
)
from impactsym.records import ArrayRecord

__all__ = ["ContactPhase", "RestProof", "flat_phase", "varying_phase"]

_RK_STEP = 0.02  # Runge-Kutta step in units of 1 / omega_max
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
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        h = self.h
        x = h00 * self.x0 + h10 * h * self.v0 + h01 * self.x1 + h11 * h * self.v1
        v = h00 * self.v0 + h10 * h * self.a0 + h01 * self.v1 + h11 * h * self.a1
        return x, v

    def crossing(self, mask, threshold, g0, g1):
        """Fraction of the step where ``threshold(x, v)`` crosses zero (Illinois steps)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(mask, g0 / (g0 - g1), np.inf)
            s = np.clip(np.where(np.isfinite(s), s, 1.0), 0.0, 1.0)
            lo, hi, glo, ghi = np.zeros_like(s), np.ones_like(s), g0, g1
            for _ in range(4):
                gs = threshold(*self.at(s))
                left = np.sign(gs) * np.sign(glo) > 0  # gs * glo may overflow
                lo, glo = np.where(left, s, lo), np.where(left, gs, glo)
                hi, ghi = np.where(left, hi, s), np.where(left, ghi, gs)
                s = np.clip(lo + glo / (glo - ghi) * (hi - lo), 0.0, 1.0)
                s = np.where(np.isfinite(s), s, 0.5 * (lo + hi))
        return np.where(mask, s, np.inf)


def varying_phase(coeffs: Coefficients, solimp, rho, gravity, speed) -> ContactPhase:
    """Runge-Kutta integration of ``x'' = (1-d')g - d'(b x' + d k-bar x)`` to first release.

    Internal (``design``). The step is ``0.02 / omega_max``; the horizon allows the flat
    contact at the softest impedance to pass its second extremum (after which it never
    releases, `docs/physics.md#simulation-engines`); :class:`RestProof` ends a sticking
    contact early.
    """
    shape = np.shape(coeffs.damping)
    damp, stiff, rho, g, v0 = (
        np.array(a, dtype=float).ravel()
        for a in (coeffs.damping, coeffs.stiffness, rho, gravity, speed)
    )
    if v0.size == 0:
        empty = np.zeros(shape)
        return ContactPhase(empty, empty.copy(), empty.astype(bool), empty.copy(), empty.copy())
    # the impedances MuJoCo clamps to [1e-4, 0.9999] (solimp[0] = 1e-300 is 1e-4 there)
    s_hi, s_lo = (float(np.clip(solimp[k], MIN_IMPEDANCE, MAX_IMPEDANCE)) for k in (1, 0))
    d_hi, d_lo = effective_impedance(s_hi, rho), effective_impedance(s_lo, rho)
    omega_hi = np.sqrt(d_hi * s_hi * stiff)
    omega_lo = np.sqrt(d_lo * s_lo * stiff)
    D_lo = d_lo * damp / (2.0 * omega_lo)
    h = _RK_STEP / np.maximum(omega_hi, d_hi * damp)
    mu = np.sqrt(np.abs(1.0 - D_lo**2))
    periods = np.where(D_lo < 1.0, 3.5 * np.pi / np.maximum(mu, 1e-3), 0.0)
    horizon = np.maximum(80.0, np.minimum(periods, 4000.0)) * np.maximum(1.0, D_lo) / omega_lo
    n_steps = int(np.ceil(np.max(horizon / h)))

    def accel(x, v):
        dd = impedance_at(x, solimp)
        dp = effective_impedance(dd, rho)
        return (1.0 - dp) * g - dp * (damp * v + dd * stiff * x), dp, dd

    def force_dd(x, v, dd):
        return g + damp * v + dd * stiff * x

    def force(x, v):
        return force_dd(x, v, impedance_at(x, solimp))

    def position(x, v):
        return x

    x, v = np.zeros_like(v0), v0.copy()
    t = np.zeros_like(v0)
    done = np.zeros(v0.shape, bool)
    e = np.zeros_like(v0)
    tc = np.full_like(v0, np.inf)
    by_pos = np.zeros(v0.shape, bool)
    xmax = np.zeros_like(v0)
    _a0, dp0, dd0 = accel(x, v)
    fmax = dp0 * force_dd(x, v, dd0)
    f_prev = force_dd(x, v, dd0)
    at_rest = RestProof(Coefficients(damp, stiff), solimp, rho, g)
    # under gravity, where rest cannot be proven (static penetration inside the
    # impedance width), a sticking body runs to the horizon: refuse a long one at once
    hopeless = (horizon / h > _MAX_RK_STEPS) & (g > 0) & ~at_rest.usable
    if hopeless.any():
        _too_long(Coefficients(damp, stiff), solimp, np.flatnonzero(hopeless)[0])
    for step in range(n_steps):
        if step % 8 == 0:
            stuck = at_rest(x, v) & ~done
            if stuck.any():
                x_fut, f_fut = at_rest.future_max(x, v, stuck)
                xmax = np.where(stuck, np.maximum(xmax, x_fut), xmax)
                fmax = np.where(stuck, np.maximum(fmax, f_fut), fmax)
                done |= stuck  # e stays 0.0 and tc inf: it sticks
                if done.all():
                    break
        if step >= _MAX_RK_STEPS:
            _too_long(Coefficients(damp, stiff), solimp, np.flatnonzero(~done)[0])
        k1x, (k1v, _, _) = v, accel(x, v)
        k2x, (k2v, _, _) = v + 0.5 * h * k1v, accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, (k3v, _, _) = v + 0.5 * h * k2v, accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, (k4v, _, _) = v + h * k3v, accel(x + h * k3x, v + h * k3v)
        xn = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        vn = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        _, dpn, ddn = accel(xn, vn)
        fn = force_dd(xn, vn, ddn)
        hit_f = (fn <= 0) & ~done
        hit_p = (xn <= 0) & ~done
        hit = hit_f | hit_p
        if hit.any():
            seg = _Step(x, v, k1v, xn, vn, accel(xn, vn)[0], h)
            s_f = seg.crossing(hit_f, force, f_prev, fn)
            s_p = seg.crossing(hit_p, position, x, xn)
            s = np.minimum(s_f, s_p)
            _, v_at = seg.at(np.where(hit, s, 0.0))
            e = np.where(hit, -v_at / v0, e)
            tc = np.where(hit, t + s * h, tc)
            by_pos = np.where(hit, s_p < s_f, by_pos)
        live = ~done & ~hit
        xmax = np.where(live, np.maximum(xmax, xn), xmax)
        fmax = np.where(live, np.maximum(fmax, dpn * fn), fmax)
        done |= hit
        x, v, t, f_prev = xn, vn, t + h, fn
        if done.all():
            break
    e = np.where(done, e, 0.0)
    return ContactPhase(*(a.reshape(shape) for a in (e, tc, by_pos & done, xmax, fmax)))


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


class RestProof:
    """Proof that a contact of :func:`varying_phase` sticks from a state ``(x, v)`` on.

    Internal. Beyond the impedance width the equation is linear with ``d = d_max``; a
    state whose closed-form future (two exponentials) provably keeps ``x`` beyond the
    width and the force threshold positive never releases
    (`docs/physics.md#simulation-engines`).
    """

    def __init__(self, coeffs: Coefficients, solimp, rho, g):
        damp, stiff = coeffs.damping, coeffs.stiffness
        self.width = solimp[2]
        d = d_max(solimp)
        dp = effective_impedance(d, rho)
        self.dk = d * stiff
        self.b = damp
        with np.errstate(all="ignore"):
            self.x_s = (1.0 - dp) * g / (dp * self.dk)
            root = np.sqrt((0.25 * (dp * damp) ** 2 - dp * self.dk).astype(complex))
        self.l1 = -0.5 * dp * damp - root  # fast
        self.l2 = -0.5 * dp * damp + root  # slow
        self.F_s = g + self.dk * self.x_s
        self.dp = dp
        self.usable = (g > 0) & (self.x_s > self.width) & (np.abs(root) > 1e-6 * np.abs(self.l1))

    def _split(self, x, v, i=slice(None)):
        u = x - self.x_s[i]
        with np.errstate(all="ignore"):
            A = (v - self.l2[i] * u) / (self.l1[i] - self.l2[i])
        return A, u - A

    @staticmethod
    def _lower(p, q, real):
        """Lower bound over ``t >= 0`` of ``p e^(l1 t) + q e^(l2 t)`` (``Re l < 0``)."""
        return np.where(
            real,
            np.minimum(p.real, 0.0) + np.minimum(q.real, 0.0),
            -(np.abs(p) + np.abs(q)),
        )

    def __call__(self, x, v):
        if not self.usable.any():
            return np.zeros(x.shape, bool)
        A, B = self._split(x, v)
        real = np.abs(self.l1.imag) == 0
        with np.errstate(all="ignore"):
            u_low = self._lower(A, B, real)
            f_low = self._lower(
                (self.b * self.l1 + self.dk) * A, (self.b * self.l2 + self.dk) * B, real
            )
            ok = (self.x_s + u_low > self.width * (1 + 1e-9)) & (self.F_s + f_low > 1e-9 * self.F_s)
        return self.usable & ok & np.isfinite(u_low) & np.isfinite(f_low)

    def future_max(self, x, v, mask, n=4001):
        """Largest penetration and ``d' (g + b v + d k x)`` of the linear solution ahead."""
        i = np.flatnonzero(mask)
        A, B = self._split(x[i], v[i], i)
        l1, l2 = self.l1[i], self.l2[i]
        t_end = 12.0 / np.minimum(np.abs(l1.real), np.abs(l2.real))
        t = np.linspace(0.0, 1.0, n)[:, None] * t_end
        e1, e2 = np.exp(l1 * t), np.exp(l2 * t)
        u = (A * e1 + B * e2).real
        du = (A * l1 * e1 + B * l2 * e2).real
        force = self.dp[i] * (self.F_s[i] + self.b[i] * du + self.dk[i] * u)
        x_out, f_out = np.zeros(x.shape), np.zeros(x.shape)
        x_out[i] = self.x_s[i] + u.max(axis=0)
        f_out[i] = force.max(axis=0)
        return x_out, f_out
