r"""MuJoCo's soft contact as an impact oscillator: predict and design ``solref``/``solimp``.

MuJoCo computes the force of a frictionless contact (``condim="1"``) so that the
constrained acceleration ``a1`` along the normal satisfies (MuJoCo documentation,
*Computation*, soft constraints)

.. math::

    a_1 + d\,(b\,v + k\,r) = (1 - d)\,a_0, \qquad f \ge 0,

with ``r`` the signed distance (negative in penetration), ``v = r'``, ``a0`` the
unconstrained acceleration, ``d = d(r)`` the impedance of ``solimp`` and ``b``, ``k``
from ``solref``. Read back from the engine (``efc_KBIP``, ``efc_R``, MuJoCo 4.0):

* ``solref = (timeconst, dampratio) > 0``: ``b = 2 / (d_max timeconst)``,
  ``k = d(r) / (d_max^2 timeconst^2 dampratio^2)``; ``timeconst`` is raised to
  ``2 timestep`` when it is shorter (MuJoCo's *refsafe*).
* ``solref = (-stiffness, -damping)``: ``b = damping / d_max``,
  ``k = d(r) stiffness / d_max^2``.
* The force is ``f = (aref - a0) / (A + R)`` clipped at zero, with ``A`` the inverse
  effective mass and ``R = (1 - d)/d * A_diag``; ``A_diag`` (``efc_diagA``) is MuJoCo's
  estimate of ``A`` from the bodies' ``body_invweight0``. It equals ``A`` for a single
  free or slide-jointed body; in general the effective impedance is
  ``d' = d rho / (d rho + 1 - d)``, ``rho = A / A_diag``.

With penetration ``x = -r`` and gravity ``g`` pressing along the normal (``a0 = -g``)
this is, per unit effective mass ``m``,

.. math::

    x'' + d'\,b\,x' + d'\,d\,\bar k\,x = (1 - d')\,g, \qquad
    f = m\,d'\,(g + b\,x' + d\,\bar k\,x), \qquad \bar k = k / d,

so only the fraction ``1 - d'`` of gravity presses during contact, and the force
threshold is offset by ``d' g``: the contact force vanishes when the body is in free
fall (``x'' = g``), not when the spring-damper force vanishes. **Contact ends** (the
engine's own state shows it, MuJoCo 4.0, checked in ``tests/test_engines_mujoco.py``)
at whichever comes first: the force reaches zero (``g + b x' + d k x = 0``) or the
penetration vanishes (``x = 0``, the contact is no longer detected). Without gravity the
force always vanishes first (the paper's force condition); under gravity a slow body
loses the contact while still pressed, which is neither of the paper's conditions.

For flat impedance (``solimp[0] == solimp[1]``) this is
:func:`impactsym.contact.release.linear_release` with ``D = d' b / (2 omega0)``,
``omega0^2 = d' d k-bar``, load ``(1 - d') gamma`` and offset ``d' gamma``,
``gamma = g / (omega0 v0)``. For a varying impedance (MuJoCo's default
``solimp = (0.9, 0.95, 0.001, 0.5, 2)``) the same equation is integrated numerically
(classical Runge-Kutta, NumPy, vectorized over the designs).

All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.release import linear_release, release_margin
from impactsym.numeric.roots import bracketed_illinois
from impactsym.validation import real_array

__all__ = [
    "DEFAULT_SOLIMP",
    "DEFAULT_TIMECONST",
    "Design",
    "Prediction",
    "from_reduced",
    "impedance",
    "predict",
    "solref_for",
    "stick_speed",
]

#: MuJoCo's default ``solimp``: ``(d_min, d_max, width, midpoint, power)``.
DEFAULT_SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
#: MuJoCo's default ``timeconst`` (seconds).
DEFAULT_TIMECONST = 0.02
_MIN_IMP, _MAX_IMP = 1e-4, 0.9999  # MuJoCo clamps the impedance to this range
#: largest ``omega dt`` for which MuJoCo's Euler step keeps e within about 1 %
_OMEGA_DT = 0.03
#: largest ``g dt / v0`` for the same accuracy under gravity
_GRAVITY_DT = 0.005
_RK_STEP = 0.02  # Runge-Kutta step in units of 1 / omega_max
_MAX_RK_STEPS = 400_000  # more is refused (a sticking contact is detected well before)
#: solref_for refuses a design whose prediction misses a target by more than this
#: (absolute in the restitution, relative in the contact time)
_DESIGN_TOL = 1e-5
_GAMMA_RANGE = (1e-9, 1e9)  # stick_speed searches gamma = g / (omega0 v0) here


def _check_solimp(solimp: object) -> tuple[float, ...]:
    if isinstance(solimp, (str, bytes)) or np.ndim(solimp) != 1 or len(solimp) not in (3, 5):
        raise TypeError(f"solimp must be 3 or 5 real numbers, got {solimp!r}")
    values = [float(real_array("solimp", v)[0]) for v in solimp]
    if len(values) == 3:
        values += [0.5, 2.0]
    dmin, dmax, width, mid, power = values
    if not (0 < dmin < 1 and 0 < dmax < 1):
        raise ValueError(f"solimp d_min, d_max must lie in (0, 1), got {solimp!r}")
    if width < 0 or not (0 < mid < 1) or power < 1:
        raise ValueError(f"solimp needs width >= 0, 0 < midpoint < 1, power >= 1, got {solimp!r}")
    return tuple(values)


def _is_flat(solimp: tuple[float, ...]) -> bool:
    return solimp[0] == solimp[1] or solimp[2] <= 1e-15


def impedance(depth: Any, solimp: Any = DEFAULT_SOLIMP) -> float | np.ndarray:
    r"""MuJoCo's impedance ``d(r)`` at penetration ``depth`` (metres, ``>= 0``).

    .. math::

        d = d_\min + y(x)\,(d_\max - d_\min), \quad x = \min(1, \mathrm{depth}/w),\quad
        y = \begin{cases} x^p / m^{p-1} & x \le m \\
                           1 - (1 - x)^p / (1 - m)^{p-1} & x > m \end{cases}

    with ``solimp = (d_min, d_max, w, m, p)``; flat (``(d_min + d_max)/2``) when
    ``d_min = d_max`` or ``w = 0``; clamped to ``[1e-4, 0.9999]`` as in MuJoCo.

    >>> impedance([0.0, 0.0003, 0.0007, 0.002])
    array([0.9  , 0.909, 0.941, 0.95 ])
    """
    dmin, dmax, width, mid, power = _check_solimp(solimp)
    x_arr, scalar = real_array("depth", depth)
    out = _impedance(np.abs(x_arr), (dmin, dmax, width, mid, power))
    return float(out) if scalar else out


def _impedance(depth: np.ndarray, solimp: tuple[float, ...]) -> np.ndarray:
    dmin, dmax, width, mid, power = solimp
    if _is_flat(solimp):
        return np.full(np.shape(depth), np.clip(0.5 * (dmin + dmax), _MIN_IMP, _MAX_IMP))
    x = np.clip(depth / width, 0.0, 1.0)
    low = x**power / mid ** (power - 1)
    high = 1.0 - (1.0 - x) ** power / (1.0 - mid) ** (power - 1)
    y = np.where(x <= mid, low, high)
    return np.clip(dmin + y * (dmax - dmin), _MIN_IMP, _MAX_IMP)


def _coefficients(solref, solimp, timestep) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``b`` (1/s) and ``k-bar = k / d`` (1/s^2) of MuJoCo, and the form (True: positive)."""
    if isinstance(solref, (str, bytes)) or len(solref) != 2:
        raise TypeError(f"solref must be a pair (timeconst, dampratio), got {solref!r}")
    a, _ = real_array("solref[0]", solref[0])
    b, _ = real_array("solref[1]", solref[1])
    a, b = np.broadcast_arrays(a, b)
    positive = a > 0
    if np.any(positive & (b <= 0)) or np.any(~positive & (b > 0)) or np.any(a == 0):
        raise ValueError(
            f"solref must be (timeconst > 0, dampratio > 0) or "
            f"(-stiffness < 0, -damping <= 0), got {solref!r}"
        )
    dmax = np.clip(solimp[1], _MIN_IMP, _MAX_IMP)
    tc = a if timestep is None else np.maximum(a, 2.0 * timestep)  # MuJoCo's refsafe
    with np.errstate(divide="ignore"):
        damp = np.where(positive, 2.0 / (dmax * tc), -b / dmax)
        stiff = np.where(positive, 1.0 / (dmax**2 * tc**2 * b**2), -a / dmax**2)
    return damp, stiff, positive


def _effective(d: np.ndarray, rho: np.ndarray) -> np.ndarray:
    return d * rho / (d * rho + 1.0 - d)


@dataclass(frozen=True)
class Prediction:
    """MuJoCo's first contact phase for a body arriving at ``speed`` (SI units).

    Attributes
    ----------
    restitution
        Normal separation speed over approach speed when contact ends (``0.0`` if it
        sticks).
    contact_time
        Seconds from first touch to the end of contact (``inf`` if it sticks).
    sticks
        True where the contact never ends.
    released_by_position
        True where the penetration vanishes while the force is still positive
        (under gravity, slow impacts); False where the force vanishes first.
    max_penetration
        Largest penetration, metres.
    peak_force
        Largest contact force, newtons (needs ``mass``).
    """

    restitution: float | np.ndarray
    contact_time: float | np.ndarray
    sticks: bool | np.ndarray
    released_by_position: bool | np.ndarray
    max_penetration: float | np.ndarray
    _peak_accel: Any
    mass: float | None

    @property
    def peak_force(self) -> float | np.ndarray:
        """Largest contact force in newtons: ``mass`` times the peak constraint acceleration."""
        if self.mass is None:
            raise ValueError("peak_force needs the effective mass: call predict(..., mass=m)")
        return self.mass * self._peak_accel


def _flat(damp, stiff, d, rho, gravity, speed, extremes=True):
    dp = _effective(d, rho)
    omega = np.sqrt(dp * d * stiff)
    D = dp * damp / (2.0 * omega)
    gamma = gravity / (omega * speed)
    rel = linear_release(D, (1.0 - dp) * gamma, dp * gamma, extremes=extremes)
    return (
        rel.restitution,
        rel.contact_time / omega,
        rel.released_by_position,
        rel.max_penetration * speed / omega,
        rel.peak_force * omega * speed,
    )


def _hermite(s, x0, v0, a0, x1, v1, a1, h):
    """Cubic Hermite state at fraction ``s`` of a step (``x`` from ``v``, ``v`` from ``a``)."""
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    x = h00 * x0 + h10 * h * v0 + h01 * x1 + h11 * h * v1
    v = h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1
    return x, v


def _crossing(mask, x0, v0, a0, x1, v1, a1, h, kind, force, g0, g1):
    """Fraction of the step where the threshold crosses zero (secant on the Hermite state)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(mask, g0 / (g0 - g1), np.inf)
        s = np.clip(np.where(np.isfinite(s), s, 1.0), 0.0, 1.0)
        lo, hi, glo, ghi = np.zeros_like(s), np.ones_like(s), g0, g1
        for _ in range(4):
            xs, vs = _hermite(s, x0, v0, a0, x1, v1, a1, h)
            gs = xs if kind == "position" else force(xs, vs)
            left = gs * glo > 0
            lo, glo = np.where(left, s, lo), np.where(left, gs, glo)
            hi, ghi = np.where(left, hi, s), np.where(left, ghi, gs)
            s = np.clip(lo + glo / (glo - ghi) * (hi - lo), 0.0, 1.0)
            s = np.where(np.isfinite(s), s, 0.5 * (lo + hi))
    return np.where(mask, s, np.inf)


def _varying(damp, stiff, solimp, rho, gravity, speed):
    """Runge-Kutta integration of ``x'' = (1-d')g - d'(b x' + d k-bar x)`` to first release."""
    shape = damp.shape
    damp, stiff, rho, g, v0 = (
        np.array(a, dtype=float).ravel() for a in (damp, stiff, rho, gravity, speed)
    )
    d_hi, d_lo = _effective(solimp[1], rho), _effective(solimp[0], rho)
    omega_hi = np.sqrt(d_hi * solimp[1] * stiff)
    omega_lo = np.sqrt(d_lo * solimp[0] * stiff)
    D_lo = d_lo * damp / (2.0 * omega_lo)
    h = _RK_STEP / np.maximum(omega_hi, d_hi * damp)
    # a flat contact releases before the second extremum of its oscillation (3 pi / mu)
    # or never (impactsym.contact.release); allow that with margin at the softest d
    mu = np.sqrt(np.abs(1.0 - D_lo**2))
    periods = np.where(D_lo < 1.0, 3.5 * np.pi / np.maximum(mu, 1e-3), 0.0)
    horizon = np.maximum(80.0, np.minimum(periods, 4000.0)) * np.maximum(1.0, D_lo) / omega_lo
    n_steps = int(np.ceil(np.max(horizon / h)))

    def accel(x, v):
        dd = _impedance(x, solimp)
        dp = _effective(dd, rho)
        return (1.0 - dp) * g - dp * (damp * v + dd * stiff * x), dp, dd

    def force_dd(x, v, dd):
        return g + damp * v + dd * stiff * x

    def force(x, v):
        return force_dd(x, v, _impedance(x, solimp))

    def vn_dot(x, v):
        return accel(x, v)[0]

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
    at_rest = _RestTest(damp, stiff, solimp, rho, g)
    # under gravity, where rest cannot be proven (static penetration inside the
    # impedance width), a sticking body runs to the horizon: refuse a long one at once
    hopeless = (horizon / h > _MAX_RK_STEPS) & (g > 0) & ~at_rest.usable
    if hopeless.any():
        _too_long(damp, stiff, solimp, np.flatnonzero(hopeless)[0])
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
            _too_long(damp, stiff, solimp, np.flatnonzero(~done)[0])
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
            s_f = _crossing(hit_f, x, v, k1v, xn, vn, vn_dot(xn, vn), h, "force", force, f_prev, fn)
            s_p = _crossing(hit_p, x, v, k1v, xn, vn, vn_dot(xn, vn), h, "position", force, x, xn)
            s = np.minimum(s_f, s_p)
            _, v_at = _hermite(np.where(hit, s, 0.0), x, v, k1v, xn, vn, vn_dot(xn, vn), h)
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
    return tuple(a.reshape(shape) for a in (e, tc, by_pos & done, xmax, fmax))


def _too_long(damp, stiff, solimp, i):
    dmax = float(np.clip(solimp[1], _MIN_IMP, _MAX_IMP))
    timeconst = 2.0 / (dmax * damp[i])
    dampratio = 1.0 / (dmax * timeconst * np.sqrt(stiff[i]))
    raise ValueError(
        f"predict: solref = ({timeconst:.6g}, {dampratio:.6g}) (or equivalently "
        f"({-stiff[i] * dmax**2:.6g}, {-damp[i] * dmax:.6g}); element {i}) needs more "
        f"than {_MAX_RK_STEPS} integration steps with the varying solimp {solimp!r} "
        f"(very overdamped, and rest is not provable: the static penetration lies within "
        f"the impedance width); use a flat solimp (d_min == d_max), whose prediction is "
        f"in closed form, or less damping"
    )


class _RestTest:
    """Proof that a contact of :func:`_varying` sticks from a state ``(x, v)`` on.

    Beyond ``width`` the impedance is constant, ``d = d_max``, and the equation is
    linear: ``u = x - x_s = A e^(l1 t) + B e^(l2 t)`` with ``l^2 + d' b l + d' d k = 0``
    and ``x_s = (1 - d') g / (d' d k)``; the force threshold is
    ``g + b v + d k x = F_s + c1 A e^(l1 t) + c2 B e^(l2 t)``, ``c = b l + d k``,
    ``F_s = g + d k x_s``. If lower bounds of both sums over all ``t >= 0`` keep
    ``x > width`` and the threshold positive, the state never leaves the linear region,
    never loses the contact and never sees the force vanish: the body sticks.
    """

    def __init__(self, damp, stiff, solimp, rho, g):
        self.width = solimp[2]
        d = float(np.clip(solimp[1], _MIN_IMP, _MAX_IMP))
        dp = _effective(d, rho)
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


def _warn_timestep(damp, stiff, solimp, rho, gravity, speed, timestep, stacklevel=3):
    """Warn when MuJoCo's Euler step is too coarse for about 1 % in the restitution.

    Measured: the error grows like ``omega0 dt`` (0.9 % at 0.045) and, under gravity,
    like ``g dt / v0`` (0.7 % at 0.005, slow impacts that lose contact while pressed).
    """
    if timestep is None:
        return
    dp = _effective(solimp[1], rho)
    omega = np.max(np.maximum(np.sqrt(dp * solimp[1] * stiff), 0.5 * dp * damp))
    limits = [(_OMEGA_DT / omega, f"omega0 * dt = {omega * timestep:.3g}")]
    pressing = np.max(gravity / speed)
    if pressing > 0:
        limits.append((_GRAVITY_DT / pressing, f"g * dt / v0 = {pressing * timestep:.3g}"))
    worst = min(limits)
    if timestep > worst[0]:
        warnings.warn(
            f"timestep = {timestep:g} s is too coarse for this contact ({worst[1]}; "
            f"MuJoCo's Euler step then misses the predicted restitution by more than "
            f"about 1 %); timestep <= {worst[0]:.3g} s would do",
            RuntimeWarning,
            stacklevel=stacklevel,
        )


def _rho(mass, inverse_weight):
    if inverse_weight is None:
        return 1.0
    if mass is None:
        raise ValueError("inverse_weight needs mass (rho = (1/mass) / inverse_weight)")
    w, _ = real_array("inverse_weight", inverse_weight, lower=0.0, strict=True)
    return (1.0 / mass) / w


def _timestep(timestep):
    value, scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    return float(value)


def _mass(mass):
    if mass is None:
        return None
    value, scalar = real_array("mass", mass, lower=0.0, strict=True)
    if not scalar:
        raise ValueError("mass must be one number (the effective mass of the contact)")
    return float(value)


def predict(
    *,
    solref: Any,
    solimp: Any = DEFAULT_SOLIMP,
    speed: Any,
    gravity: Any = 0.0,
    mass: float | None = None,
    timestep: float | None = None,
    inverse_weight: Any = None,
) -> Prediction:
    r"""Predict MuJoCo's restitution and contact time for a contact with ``solref``, ``solimp``.

    Parameters
    ----------
    solref
        ``(timeconst, dampratio)`` (both > 0, seconds and 1) or
        ``(-stiffness, -damping)`` (1/s^2 and 1/s, per unit mass as MuJoCo reads them).
        Entries may be arrays; they broadcast with ``speed`` and ``gravity``.
    solimp
        ``(d_min, d_max, width, midpoint, power)`` of the contact (one tuple).
    speed
        Normal approach speed at first touch, m/s (> 0).
    gravity
        Acceleration pressing along the normal, m/s^2 (>= 0).
    mass
        Effective mass of the contact, kg (``1 / (J M^-1 J^T)``); needed for
        ``peak_force`` and with ``inverse_weight``.
    timestep
        MuJoCo's timestep, seconds: applies *refsafe* (``timeconst >= 2 timestep``) and
        warns when it is too coarse for the contact.
    inverse_weight
        MuJoCo's ``efc_diagA`` for the contact (the two bodies' ``body_invweight0[:, 0]``
        summed), 1/kg. Default: ``1 / mass``, exact for one free or slide-jointed body.

    Returns
    -------
    Prediction
        In seconds, metres and newtons. With a varying ``solimp`` a body is reported
        sticking as soon as its state provably never releases (beyond the impedance
        width the equation is linear; see ``_RestTest``), not after a fixed horizon.

    Raises
    ------
    ValueError
        For bad input (named), and with a varying ``solimp`` when the integration would
        need more than 400 000 steps (a very overdamped ``solref`` whose static
        penetration lies within the impedance width), naming the ``solref``.

    Examples
    --------
    >>> p = predict(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001, 0.5, 2), speed=1.0)
    >>> round(p.restitution, 4), round(p.contact_time, 5)
    (0.2984, 0.02418)
    >>> predict(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001), speed=0.1, gravity=9.81).sticks
    True
    """
    simp = _check_solimp(solimp)
    v0, s_scalar = real_array("speed", speed, lower=0.0, strict=True)
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    if timestep is not None:
        timestep = _timestep(timestep)
    m = _mass(mass)
    rho = _rho(m, inverse_weight)
    damp, stiff, _positive = _coefficients(solref, simp, timestep)
    scalar = s_scalar and g_scalar and damp.ndim == 0
    damp, stiff, v0, g, rho = np.broadcast_arrays(damp, stiff, v0, g, np.asarray(rho, float))
    _warn_timestep(damp, stiff, simp, rho, g, v0, timestep)
    if _is_flat(simp):
        d = _impedance(np.zeros(()), simp)
        out = _flat(damp, stiff, d, rho, g, v0)
    else:
        out = _varying(damp, stiff, simp, rho, g, v0)
    e, tc, by_pos, xmax, amax = out
    sticks = np.isinf(tc)
    if scalar:
        return Prediction(
            float(e), float(tc), bool(sticks), bool(by_pos), float(xmax), float(amax), m
        )
    return Prediction(e, tc, sticks, by_pos, xmax, amax, m)


def stick_speed(
    *,
    solref: Any,
    solimp: Any,
    gravity: float,
    mass: float | None = None,
    inverse_weight: Any = None,
    timestep: float | None = None,
) -> float | np.ndarray:
    r"""Approach speed (m/s) below which MuJoCo's body sticks under ``gravity`` (flat solimp).

    With ``gamma = g / (omega0 v0)`` the body sticks where
    :func:`impactsym.contact.release.release_margin` of
    ``(D, (1 - d') gamma, d' gamma)`` is positive; the boundary ``gamma*(D, d')`` is
    found by the Illinois method in ``log gamma`` and ``v* = g / (omega0 gamma*)``.
    ``0.0`` without gravity, or where the body releases for every ``gamma`` up to
    ``1e9`` (e.g. no damping); ``inf`` where it sticks for every ``gamma`` down to
    ``1e-9`` (every speed).

    >>> round(stick_speed(solref=(0.02, 0.5), solimp=(0.9, 0.9, 0.001), gravity=9.81), 5)
    0.11954
    """
    simp = _check_solimp(solimp)
    if not _is_flat(simp):
        raise ValueError(
            f"stick_speed needs a flat solimp (d_min == d_max), got {simp!r}; use predict "
            "over speeds for a varying impedance"
        )
    g_arr, g_scalar = real_array("gravity", gravity, lower=0.0)
    if not g_scalar:
        raise ValueError(f"gravity must be one number here, got {gravity!r}")
    g = float(g_arr)
    if timestep is not None:
        timestep = _timestep(timestep)
    m = _mass(mass)
    rho = np.asarray(_rho(m, inverse_weight), float)
    damp, stiff, _ = _coefficients(solref, simp, timestep)
    scalar = damp.ndim == 0
    damp, stiff, rho = (
        np.array(a, dtype=float).ravel() for a in np.broadcast_arrays(damp, stiff, rho)
    )
    if g == 0:
        return 0.0 if scalar else np.zeros(np.shape(damp))
    d = float(_impedance(np.zeros(()), simp))
    dp = _effective(d, rho)
    omega = np.sqrt(dp * d * stiff)
    D = dp * damp / (2.0 * omega)

    def margin(gamma, i):
        return release_margin(D[i], (1.0 - dp[i]) * gamma, dp[i] * gamma)

    every = np.arange(D.size)
    lo, hi = np.full(D.size, _GAMMA_RANGE[0]), np.full(D.size, _GAMMA_RANGE[1])
    never = margin(hi, every) <= 0  # releases even at gamma = 1e9 (the slowest impacts)
    always = ~never & (margin(lo, every) > 0)  # sticks even at gamma = 1e-9 (the fastest)
    out = np.where(never, 0.0, np.inf)
    ok = np.flatnonzero(~never & ~always)
    if ok.size:
        gamma = bracketed_illinois(lambda x, i: margin(x, ok[i]), lo[ok], hi[ok], log=True)
        out[ok] = g / (omega[ok] * gamma)
    return float(out[0]) if scalar else out


# -- design ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Design:
    """MuJoCo contact parameters for a wanted restitution (and contact time), SI units.

    Attributes
    ----------
    solref
        The pair to write in MJCF: ``(timeconst, dampratio)`` or
        ``(-stiffness, -damping)`` (``form="stiffness"``); floats or arrays.
    solimp
        The ``solimp`` the design assumes (write it too).
    restitution, contact_time
        Predicted by :func:`predict` for this design (contact time in seconds).
    prediction
        The full :class:`Prediction`.
    """

    solref: tuple[Any, Any]
    solimp: tuple[float, ...]
    prediction: Prediction

    @property
    def restitution(self) -> float | np.ndarray:
        """Predicted restitution of the design."""
        return self.prediction.restitution

    @property
    def contact_time(self) -> float | np.ndarray:
        """Predicted contact time of the design, seconds."""
        return self.prediction.contact_time

    def mjcf(self) -> str:
        """The MJCF attributes, e.g. ``solref="0.02 0.29" solimp="0.9 0.95 0.001 0.5 2"``."""
        if np.ndim(self.solref[0]):
            raise ValueError("mjcf() needs a scalar design")
        ref = " ".join(f"{float(v):.10g}" for v in self.solref)
        imp = " ".join(f"{v:g}" for v in self.solimp)
        return f'solref="{ref}" solimp="{imp}"'


def _unreachable(what: str, mask: np.ndarray, targets: np.ndarray, hint: str) -> None:
    if mask.any():
        index = np.flatnonzero(mask)[0]
        raise ValueError(
            f"restitution = {float(targets.flat[index])!r} (element {index}) cannot be "
            f"reached: {what}; {hint}"
        )


def _design_flat_dampratio(e_t, v0, g, tc, simp, rho):
    """Dampratio with timeconst ``tc`` giving restitution ``e_t`` (flat impedance)."""
    d = float(_impedance(np.zeros(()), simp))

    n = e_t.size
    # the last dampratio tried and its restitution, per element: the gap check below
    # reads the restitution at the root the solver last evaluated instead of redoing it
    last_dr, last_e = np.full(n, np.nan), np.full(n, np.nan)

    def e_of(dr, idx):
        damp, stiff, _ = _coefficients((tc[idx], dr), simp, None)
        e = _flat(damp, stiff, d, rho[idx], g[idx], v0[idx], extremes=False)[0]
        last_dr[idx], last_e[idx] = dr, e
        return e

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
    lo, hi = np.exp(np.log(np.full(n, 1e-3))), np.exp(np.log(np.full(n, 1e2)))
    e_lo = e_of(lo, idx)
    _unreachable(
        "the body sticks or rebounds too slowly for every dampratio in [1e-3, 100]",
        e_lo <= e_t,
        e_t,
        "a higher speed, less gravity or a shorter timeconst (contact_time=...) reaches it",
    )
    e_hi = e_of(hi, idx)
    hi = np.where(e_hi <= e_t, hi, np.nan)
    _unreachable(
        "even dampratio = 100 rebounds faster",
        np.isnan(hi),
        e_t,
        "a lower speed or more gravity reaches it",
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
    _check_gap(lambda x: e_at(x) if x is dr else e_of(x, idx), e_t, dr, "dampratio")
    return dr


def _check_gap(e_of, e_t, at, name):
    """The restitution jumps where the release switches from force to position: refuse."""
    achieved = e_of(at)
    miss = np.abs(achieved - e_t) > 1e-6 * np.maximum(e_t, 1e-3)
    if miss.any():
        i = np.flatnonzero(miss)[0]
        below, above = e_of(at * (1 - 1e-7))[i], e_of(at * (1 + 1e-7))[i]
        raise ValueError(
            f"restitution = {float(e_t[i])!r} (element {i}) cannot be reached: at "
            f"{name} = {float(at[i]):.6g} the restitution jumps from {below:.4g} to "
            f"{above:.4g} (the force no longer vanishes before the penetration does), "
            f"so targets in between are out of reach here; a higher speed, less gravity "
            f"or another contact_time moves the jump"
        )


def _design_flat_both(e_t, v0, g, t_c, simp, rho):
    """``(timeconst, dampratio)`` for restitution ``e_t`` and contact time ``t_c`` (flat)."""

    def inner(dr, idx):
        # timeconst that gives the contact time t_c at this dampratio
        lo = np.full(idx.size, 1e-6)
        hi = np.full(idx.size, 1e3)

        def t_of(tc, j):
            damp, stiff, _ = _coefficients((tc, dr[j]), simp, None)
            d = float(_impedance(np.zeros(()), simp))
            t = _flat(damp, stiff, d, rho[idx[j]], g[idx[j]], v0[idx[j]])[1]
            return np.arctan(np.log(np.where(np.isfinite(t), t, 1e300) / t_c[idx[j]]))

        # the contact time grows with the timeconst: one bracket
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
            d = float(_impedance(np.zeros(()), simp))
            damp, stiff, _ = _coefficients((tc[good], dr[good]), simp, None)
            j = idx[good]
            out[good] = _flat(damp, stiff, d, rho[j], g[j], v0[j])[0] - e_t[j]
        return out

    n = e_t.size
    idx = np.arange(n)
    grid = np.geomspace(1e-3, 1e2, 21)
    vals = np.stack([residual(np.full(n, q), idx) for q in grid])
    below = vals <= 0
    has = below.any(axis=0)
    first = np.argmax(below, axis=0)
    _unreachable(
        "no (timeconst, dampratio) gives both this restitution and this contact time",
        ~has | (first == 0),
        e_t,
        "a longer contact_time or a higher speed reaches it",
    )
    dr = bracketed_illinois(
        lambda x, i: -residual(x, i), grid[first - 1], grid[first], log=True, rtol=1e-12
    )
    _check_gap(lambda x: residual(x, idx) + e_t, e_t, dr, "dampratio")
    return inner(dr, idx), dr


def _design_varying(e_t, v0, g, t_c, tc0, dr0, simp, rho):
    """Newton on ``log`` of the unknowns with a finite-difference Jacobian (varying solimp)."""
    both = t_c is not None
    u = np.stack([np.log(tc0), np.log(dr0)]) if both else np.log(dr0)[None]

    def resid(u):
        tc = np.exp(u[0]) if both else tc0
        dr = np.exp(u[-1])
        damp, stiff, _ = _coefficients((tc, dr), simp, None)
        e, t, *_ = _varying(damp, stiff, simp, rho, g, v0)
        r = [e - e_t]
        if both:
            r.append(np.log(np.where(np.isfinite(t), t, 1e300) / t_c))
        return np.stack(r)

    r = resid(u)
    for _ in range(12):
        eps = 1e-6
        J = np.empty((u.shape[0], u.shape[0], u.shape[1]))
        for j in range(u.shape[0]):
            du = np.zeros_like(u)
            du[j] = eps
            J[:, j] = (resid(u + du) - r) / eps
        step = np.linalg.solve(np.moveaxis(J, -1, 0), np.moveaxis(r, -1, 0)[..., None])[..., 0]
        step = np.clip(np.moveaxis(step, 0, -1), -0.5, 0.5)
        u = u - step
        r = resid(u)
        if np.all(np.abs(r) < 1e-9):
            break
    _unreachable(
        "the varying-impedance design did not converge",
        ~np.all(np.abs(r) < 1e-6, axis=0),
        e_t,
        "try flat impedance (solimp[0] == solimp[1]) or a nearby target",
    )
    tc = np.exp(u[0]) if both else tc0
    return tc, np.exp(u[-1])


def solref_for(
    *,
    restitution: Any,
    speed: Any,
    gravity: Any = 0.0,
    contact_time: Any = None,
    solimp: Any = DEFAULT_SOLIMP,
    mass: float | None = None,
    timestep: float | None = None,
    inverse_weight: Any = None,
    form: str = "timeconst",
) -> Design:
    r"""``solref`` for which MuJoCo gives ``restitution`` (and ``contact_time``).

    Without ``contact_time`` the timeconst stays MuJoCo's default 0.02 s (or
    ``2 timestep`` if that is longer, as MuJoCo enforces) and the dampratio is designed;
    with it both are designed. The result is checked by :func:`predict`, whose model it
    inverts (bracketed on a grid of dampratios, then the Illinois method; Newton with a
    finite-difference Jacobian from the flat design for a varying impedance).

    Parameters
    ----------
    restitution
        Wanted coefficient of restitution, ``0 < e < 1`` (array allowed).
    speed, gravity, mass, timestep, inverse_weight, solimp
        As in :func:`predict` (m/s, m/s^2, kg, s, 1/kg).
    contact_time
        Wanted contact time, seconds (array allowed).
    form
        ``"timeconst"``: ``solref = (timeconst, dampratio)``; ``"stiffness"``:
        ``solref = (-stiffness, -damping)`` with the same contact dynamics.

    Returns
    -------
    Design

    Raises
    ------
    ValueError
        When no ``solref`` reaches the target (e.g. the body sticks at that speed under
        gravity), saying what would reach it; when the design needs
        ``timeconst < 2 timestep`` (MuJoCo would raise it); and when :func:`predict` of the
        design misses a target by more than ``1e-5`` (absolute in the restitution,
        relative in the contact time).

    Examples
    --------
    >>> des = solref_for(restitution=0.5, speed=1.0, solimp=(0.9, 0.9, 0.001))
    >>> des.mjcf()
    'solref="0.02 0.2552756376" solimp="0.9 0.9 0.001 0.5 2"'
    >>> round(des.restitution, 10)
    0.5
    """
    if form not in ("timeconst", "stiffness"):
        raise ValueError(f"form must be 'timeconst' or 'stiffness', got {form!r}")
    simp = _check_solimp(solimp)
    e_t, e_scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e_t >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e_t.max())!r}")
    v0, s_scalar = real_array("speed", speed, lower=0.0, strict=True)
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    scalar = e_scalar and s_scalar and g_scalar
    t_c = None
    if contact_time is not None:
        t_c, t_scalar = real_array("contact_time", contact_time, lower=0.0, strict=True)
        scalar = scalar and t_scalar
    if timestep is not None:
        timestep = _timestep(timestep)
    m = _mass(mass)
    rho = _rho(m, inverse_weight)
    arrays = [e_t, v0, g, np.asarray(rho, float)] + ([t_c] if t_c is not None else [])
    shape = np.broadcast_shapes(*(np.shape(a) for a in arrays))
    flat = [np.broadcast_to(a, shape).ravel() for a in arrays]
    e_f, v_f, g_f, rho_f = flat[:4]
    t_f = flat[4] if t_c is not None else None
    tc_default = DEFAULT_TIMECONST if timestep is None else max(DEFAULT_TIMECONST, 2 * timestep)
    # flat design first (exact for flat solimp, a start for a varying one)
    flat_imp = simp if _is_flat(simp) else (simp[1], simp[1], 0.0, simp[3], simp[4])
    if t_f is None:
        tc = np.full(e_f.shape, tc_default)
        dr = _design_flat_dampratio(e_f, v_f, g_f, tc, flat_imp, rho_f)
    else:
        tc, dr = _design_flat_both(e_f, v_f, g_f, t_f, flat_imp, rho_f)
    if not _is_flat(simp):
        tc, dr = _design_varying(e_f, v_f, g_f, t_f, tc, dr, simp, rho_f)
    if timestep is not None and np.any(tc < 2 * timestep):  # on the final timeconst
        i = int(np.argmin(tc))
        raise ValueError(
            f"contact_time = {float(t_f[i])!r} with restitution = {float(e_f[i])!r} "
            f"needs timeconst = {float(tc[i]):.6g} s < 2 * timestep; MuJoCo would raise "
            f"it to {2 * timestep:g} s. Use timestep <= {float(tc[i]) / 2:.3g} s or a "
            f"longer contact_time"
        )
    tc, dr = tc.reshape(shape), dr.reshape(shape)
    if form == "timeconst":
        solref = (tc, dr)
    else:
        damp, stiff, _ = _coefficients((tc, dr), simp, None)
        dmax = np.clip(simp[1], _MIN_IMP, _MAX_IMP)
        solref = (-stiff * dmax**2, -damp * dmax)
    if scalar:
        solref = (float(solref[0]), float(solref[1]))
    pred = predict(
        solref=solref,
        solimp=simp,
        speed=speed if t_c is None or scalar else np.broadcast_to(v0, shape),
        gravity=gravity if scalar else np.broadcast_to(g, shape),
        mass=m,
        timestep=timestep,
        inverse_weight=inverse_weight,
    )
    _check_design(pred, e_f, t_f, shape)
    return Design(solref, simp, pred)


def _check_design(pred: Prediction, e_t, t_c, shape) -> None:
    """Refuse a design whose prediction (with refsafe) misses the targets.

    Tolerances: ``_DESIGN_TOL`` absolute in the restitution, relative in the contact
    time (the designs converge to about ``1e-6``).
    """
    e = np.broadcast_to(pred.restitution, shape).ravel()
    miss = np.abs(e - e_t) > _DESIGN_TOL
    if t_c is not None:
        t = np.broadcast_to(pred.contact_time, shape).ravel()
        with np.errstate(invalid="ignore"):
            miss |= ~(np.abs(t / t_c - 1.0) <= _DESIGN_TOL)
    if miss.any():
        i = np.flatnonzero(miss)[0]
        wanted = f"restitution = {float(e_t[i])!r}" + (
            "" if t_c is None else f", contact_time = {float(t_c[i])!r} s"
        )
        got = f"restitution {float(e[i]):.6g}" + (
            "" if t_c is None else f", contact time {float(t[i]):.6g} s"
        )
        raise ValueError(
            f"{wanted} (element {i}) is not reached within {_DESIGN_TOL:g}: the designed "
            f"solref gives {got} in predict"
        )


def from_reduced(reduced: Any) -> dict[str, float]:
    """Keyword arguments ``mass``, ``speed``, ``gravity`` for a reduced multibody contact.

    ``mass`` is the effective mass ``m~``, ``speed`` the approach speed ``v0`` and
    ``gravity = load / m~`` the pressing acceleration of a
    :class:`impactsym.multibody.ReducedContact`. Use as
    ``solref_for(restitution=0.5, **from_reduced(r), inverse_weight=w)``. MuJoCo's
    contact has no further stiffness or damping, so ``delta_c`` and ``delta_d`` of the
    reduction (the system's own linearized forces) are not part of the engine's contact
    model; they are small during a short impact and are ignored here.

    >>> from types import SimpleNamespace
    >>> from_reduced(SimpleNamespace(m_eff=2.0, v0=1.5, load=9.81, is_symbolic=False))
    {'mass': 2.0, 'speed': 1.5, 'gravity': 4.905}
    """
    if getattr(reduced, "is_symbolic", True):
        raise TypeError("reduced must be a numeric ReducedContact (substitute symbols first)")
    m = float(reduced.m_eff)
    v = float(reduced.v0)
    load = float(reduced.load)
    if not (m > 0 and v > 0 and load >= 0 and math.isfinite(m + v + load)):
        raise ValueError(f"reduced needs m_eff > 0, v0 > 0, load >= 0, got {m}, {v}, {load}")
    return {"mass": m, "speed": v, "gravity": load / m}
