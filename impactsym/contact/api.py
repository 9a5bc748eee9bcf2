r"""Spring-damper contact (paper section 2): fast vectorized numbers.

Contact times, coefficients of restitution and the stick/release boundary, computed
from the closed forms of :mod:`impactsym.contact.derivation` (lambdified once, on first use).

The first root of :math:`g(\tau, D, f)` is bracketed without any time sampling: the
closed-form ridge time :math:`\tau_r(D, f)` is the first local minimum of ``g``; the
body sticks when :math:`g(\tau_r) \ge 0` (later minima lie higher, and without a
minimum ``g`` decays monotonically to :math:`2Df \ge 0`); otherwise ``g`` falls
monotonically from the preceding maximum (or from impact) to :math:`\tau_r`, and a
safeguarded Newton iteration polishes the root in that bracket. Near-tangent, almost
sticking cases are therefore never missed.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from impactsym.contact import derivation
from impactsym.contact.derivation import D, f, tau, v0, z0
from impactsym.numeric.codegen import lambdify
from impactsym.numeric.roots import bracketed_newton
from impactsym.validation import broadcast, check_condition, finish, real_array

ArrayLike = float | np.ndarray


def _aux(regime: str, damping: np.ndarray) -> tuple[np.ndarray, ...]:
    """Auxiliary arguments of the numeric forms, computed without cancellation."""
    if regime == "underdamped":
        return (np.sqrt((1.0 - damping) * (1.0 + damping)),)
    if regime == "critical":
        return ()
    spread = np.sqrt(damping - 1.0) * np.sqrt(damping + 1.0)  # no overflow for D > 1e154
    return spread, damping + spread


class _PiecewiseInD:
    """A numeric form evaluated regime by regime (masks on D), as one NumPy function.

    Arguments ``([tau,] D, f)``, or ``([tau,] D, f, z0, v0)`` for a contact started from
    an arbitrary state (``restart``, :class:`impactsym.contact.derivation.SpringDamperRestart`).
    """

    def __init__(
        self, name: str, with_tau: bool, critical_separate: bool, restart: bool = False
    ) -> None:
        self.name = name
        self.critical_separate = critical_separate
        regimes = derivation.REGIMES if critical_separate else ("underdamped", "overdamped")
        model = derivation.spring_damper_restart if restart else derivation.spring_damper
        self.d_index = 1 if with_tau else 0
        leading = (tau, D, f)[1 - self.d_index :] + ((z0, v0) if restart else ())
        self.functions = {
            r: lambdify(
                leading + derivation.NUMERIC_AUX[r],
                sp.sympify(model(r).numeric_forms[name], strict=True),
                name=f"{name}_{r}",
            )
            for r in regimes
        }

    def __call__(self, *args: np.ndarray) -> np.ndarray:
        damping = args[self.d_index]
        if self.critical_separate:
            masks = {
                "underdamped": damping < 1,
                "critical": damping == 1,
                "overdamped": damping > 1,
            }
        else:  # the under-damped form is valid at D = 1 (sinc at omega = 0)
            masks = {"underdamped": damping <= 1, "overdamped": damping > 1}
        out = np.empty(np.broadcast_shapes(*(np.shape(a) for a in args)))
        for regime, mask in masks.items():
            if mask.any():
                sub = [a[mask] for a in args]
                out[mask] = self.functions[regime](*sub, *_aux(regime, sub[self.d_index]))
        return out


@dataclass(frozen=True)
class _Kernels:
    g: _PiecewiseInD
    oscillation: _PiecewiseInD
    oscillation_dot: _PiecewiseInD
    ridge: _PiecewiseInD
    ridge_exists: _PiecewiseInD
    boundary_slope: _PiecewiseInD

    def scaled_g(
        self, t: np.ndarray, damping: np.ndarray, force: np.ndarray, *state: np.ndarray
    ) -> np.ndarray:
        """g exp(c tau) = oscillation + 2Df exp(c tau): the sign of g without underflow."""
        return self.oscillation(t, damping, force, *state) + _static_part(t, damping, force)

    def scaled_g_dot(
        self, t: np.ndarray, damping: np.ndarray, force: np.ndarray, *state: np.ndarray
    ) -> np.ndarray:
        """d/dtau of :meth:`scaled_g`."""
        rate = _decay_rate(damping)
        static = _static_part(t, damping, force)
        return self.oscillation_dot(t, damping, force, *state) + rate * static


def _decay_rate(damping: np.ndarray) -> np.ndarray:
    """Decay rate c of the slowest mode (``derivation.DECAY``): D for D <= 1, else 1/mu."""
    mu_ = _aux("overdamped", np.maximum(damping, 1.0))[1]
    return np.where(damping <= 1, damping, 1.0 / mu_)


def _static_part(t: np.ndarray, damping: np.ndarray, force: np.ndarray) -> np.ndarray:
    static = 2.0 * damping * force
    with np.errstate(over="ignore", invalid="ignore"):
        grown = static * np.exp(_decay_rate(damping) * t)
    return np.where(static > 0, grown, 0.0)  # no 0 * inf


@cache
def _kernels(condition: str, restart: bool = False) -> _Kernels:
    """Numeric forms of one condition; ``restart``: from an arbitrary state (z0, v0)."""

    def piece(name: str, with_tau: bool = True, critical: bool = False) -> _PiecewiseInD:
        return _PiecewiseInD(
            f"{name}_{condition}", with_tau=with_tau, critical_separate=critical, restart=restart
        )

    return _Kernels(
        g=piece("g"),
        oscillation=piece("g_oscillation"),
        oscillation_dot=piece("g_oscillation_dot"),
        ridge=piece("ridge", with_tau=False, critical=True),
        ridge_exists=piece("ridge_exists", with_tau=False, critical=True),
        boundary_slope=piece("g_D"),
    )


@cache
def _z_dot(restart: bool = False) -> _PiecewiseInD:
    return _PiecewiseInD("z_dot", with_tau=True, critical_separate=False, restart=restart)


def _ridge(
    condition: str, damping: np.ndarray, force: np.ndarray, state: tuple[np.ndarray, ...] = ()
) -> np.ndarray:
    """Ridge time: the first local minimum of g after impact; NaN where g has none.

    ``state`` = ``(z0, v0)`` arrays: the contact starts from that state instead.
    """
    k = _kernels(condition, bool(state))
    exists = k.ridge_exists(damping, force, *state) > 0.5
    ridge = np.full(damping.shape, np.nan)
    ridge[exists] = k.ridge(damping[exists], force[exists], *(a[exists] for a in state))
    return ridge


def _boundary_value(condition: str, damping: np.ndarray, force: np.ndarray) -> np.ndarray:
    """G(D, f) = g at the ridge time (the infimum 2Df of g where g has no minimum)."""
    ridge = _ridge(condition, damping, force)
    exists = ~np.isnan(ridge)
    minimum = 2.0 * damping * force
    if exists.any():
        minimum[exists] = _kernels(condition).g(ridge[exists], damping[exists], force[exists])
    return minimum


#: Damping ratio above which the far over-damped limit replaces the closed-form kernels
#: (their exponentials lose accuracy beyond about 1e9 and overflow beyond 1e154).
_D_FAR = 1e8
#: Pressing force below which the force-condition boundary D* = f^(-1/4)/2 lies above
#: ``_D_FAR``, where that asymptote is exact to double precision (relative correction
#: of order 2/D*^2 < 1e-16).
_F_FAR = (0.5 / _D_FAR) ** 4


def _far_overdamped(
    condition: str, damping: np.ndarray, force: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    r"""Contact time and restitution for :math:`D > 10^8` (the far over-damped limit).

    Position condition: an over-damped body never comes back out (:math:`D^* \le 1`).
    Force condition: the body sticks for :math:`D \ge D^*(f) = f^{-1/4}/2`; for
    :math:`f = 0` the normalized force :math:`a_1 e^{\lambda_1 \tau} + a_2 e^{\lambda_2
    \tau}` has its root in closed form, with :math:`\lambda_1 = -1/\mu`,
    :math:`\lambda_2 = -\mu`, :math:`\mu = D + \sigma`, :math:`\sigma = \sqrt{D^2 - 1}`,

    .. math:: \tau_c = \frac{\ln\left((2 D \mu - 1)\mu^2\right)}{2\sigma}, \qquad
              e = \frac{e^{-\tau_c/\mu}/\mu - \mu e^{-\mu \tau_c}}{2\sigma},

    evaluated through logarithms (no overflow up to the largest float). The rest,
    :math:`0 < f < (0.5/D)^4`, is refused.
    """
    tau_c, e = np.full(damping.shape, np.inf), np.zeros(damping.shape)
    if condition == "position":
        return tau_c, e
    free = force == 0
    d = damping[free]
    root = np.sqrt((1.0 - 1.0 / d) * (1.0 + 1.0 / d))
    sigma = d * root
    log_mu = np.log(d) + np.log1p(root)
    # ln(2 D mu - 1) = ln 2 + ln D + ln mu up to 1/(2 D mu) < 3e-17, below rounding
    log_ratio = np.log(2.0) + np.log(d) + 3.0 * log_mu
    tau_c[free] = log_ratio / 2.0 / sigma
    slow = np.exp(-tau_c[free] * np.exp(-log_mu) - log_mu)
    fast = np.exp(log_mu - (1.0 + root) / (2.0 * root) * log_ratio)
    e[free] = (slow - fast) / 2.0 / sigma
    pressed = ~free
    releases = damping[pressed] < 0.5 * force[pressed] ** -0.25
    if releases.any():
        D_bad, f_bad = float(damping[pressed][releases][0]), float(force[pressed][releases][0])
        raise ValueError(
            f"D = {D_bad!r}, f = {f_bad!r}: for D > {_D_FAR:g} the contact time is computed "
            "only for f = 0 or where the body sticks (D >= D*(f) = f^(-1/4)/2); this point "
            "releases, below the stick boundary, outside the supported range"
        )
    return tau_c, e


#: Static penetration 2Df above which the kernels cannot resolve the stick boundary
#: (the minimum of g is a difference of terms of size 2Df; relative resolution of D*
#: about eps (2Df)^2, 2e-8 here).
_B_MAX = 1e4
#: Large-f asymptote of the stick boundary, D* = (16 pi f^2)^(-1/3) (both conditions).
_C_LARGE_F = (16.0 * np.pi) ** (-1.0 / 3.0)
#: Above this f the stick boundary is the large-f asymptote (its relative correction,
#: about -0.55 f^(-2/3), is below 5e-9 there, and the kernels' resolution eps (2 D* f)^2
#: would be worse beyond).
_F_LARGE = 1e12


def _limits(
    condition: str, damping: np.ndarray, force: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Points decided by a limit, without the kernels: ``(mask, tau_c, e)`` on them.

    * :math:`D > 10^8`: the far over-damped limit (:func:`_far_overdamped`).
    * static penetration :math:`2Df > 10^4`: the body sticks when
      :math:`D \ge 2 D^*_\infty(f)`, twice the large-``f`` boundary
      :math:`D^*_\infty = (16\pi f^2)^{-1/3}` (the first minimum of ``z`` near
      :math:`\tau = 2\pi` is :math:`4\pi D b^2 - 1` over :math:`2b`, :math:`b = 2Df`,
      and :math:`D^* < D^*_\infty`); closer to the boundary the sign of that minimum is
      below double-precision rounding, and the point is refused.
    """
    with np.errstate(over="ignore"):
        static = damping * force * 2.0  # not 2 D first: 2 D may overflow where f = 0
    far = damping > _D_FAR
    big = (static > _B_MAX) & ~far
    tau_c, e = np.full(damping.shape, np.inf), np.zeros(damping.shape)
    if far.any():
        tau_c[far], e[far] = _far_overdamped(condition, damping[far], force[far])
    if big.any():
        unresolved = damping[big] < 2.0 * _C_LARGE_F * force[big] ** (-2.0 / 3.0)
        if unresolved.any():
            D_bad, f_bad = float(damping[big][unresolved][0]), float(force[big][unresolved][0])
            raise ValueError(
                f"D = {D_bad!r}, f = {f_bad!r}: the static penetration 2 D f exceeds "
                f"{_B_MAX:g} and D is within a factor 2 of the stick boundary "
                "D* ~ (16 pi f^2)^(-1/3), where double precision cannot tell whether the "
                "body releases; only clearly sticking points are computed there"
            )
    decided = far | big
    return decided, tau_c[decided], e[decided]


def _contact_time(
    condition: str,
    damping: np.ndarray,
    force: np.ndarray,
    ridge: np.ndarray | None = None,
    state: tuple[np.ndarray, ...] = (),
) -> np.ndarray:
    """Contact time on flat arrays (no validation); ``ridge`` if already computed.

    ``state`` = ``(z0, v0)`` arrays: the contact starts from ``z(0) = z0, z'(0) = v0``
    (with ``g(0) > 0``) instead of the first impact's ``(0, 1)``; the same argument holds.
    The limits of :func:`_limits` are those of the first impact (``state = ()``).
    """
    if not state:
        decided, tau_limit, _ = _limits(condition, damping, force)
        if decided.any():
            result = np.empty(damping.shape)
            result[decided] = tau_limit
            rest = ~decided
            result[rest] = _contact_time(
                condition, damping[rest], force[rest], None if ridge is None else ridge[rest]
            )
            return result
    k = _kernels(condition, bool(state))
    ridge = _ridge(condition, damping, force, state) if ridge is None else ridge
    exists = ~np.isnan(ridge)
    release = exists.copy()
    at = [a[exists] for a in state]
    release[exists] = k.scaled_g(ridge[exists], damping[exists], force[exists], *at) < 0
    result = np.full(damping.shape, np.inf)
    if release.any():
        d, fr, hi = damping[release], force[release], ridge[release]
        lo = np.zeros_like(hi)  # g decreases from impact, or from the preceding maximum:
        under = d < 1
        half_period = np.pi / np.sqrt((1.0 - d[under]) * (1.0 + d[under]))
        lo[under] = np.maximum(hi[under] - half_period, 0.0)
        params = [d, fr, *(a[release] for a in state)]
        result[release] = bracketed_newton(k.scaled_g, k.scaled_g_dot, lo, hi, params)
    return result


def _inputs(condition: str, **arrays: object) -> tuple[list[np.ndarray], tuple[int, ...], bool]:
    check_condition(condition)
    checked = [real_array(name, value, lower=0.0) for name, value in arrays.items()]
    shape = broadcast(**{name: a for name, (a, _) in zip(arrays, checked, strict=True)})
    flat = [np.broadcast_to(a, shape).ravel() for a, _ in checked]
    return flat, shape, all(s for _, s in checked)


def contact_time(D: ArrayLike, f: ArrayLike, *, condition: str = "force") -> ArrayLike:
    r"""Normalized contact time :math:`\tau_c(D, f)` of the spring-damper contact.

    The first sign change in :math:`\tau > 0` of :math:`g = z` (position condition) or
    :math:`g = 2Dz' + z` (force condition), where
    :math:`z'' + 2Dz' + z = 2Df,\ z(0) = 0,\ z'(0) = 1` (paper section 2).

    Parameters
    ----------
    D : float or array_like
        Lehr's damping ratio, ``>= 0``.
    f : float or array_like
        Pressing force over damper force at impact, ``>= 0``.
    condition : {"force", "position"}
        How contact ends: the contact force vanishes, or the penetration.

    Returns
    -------
    float or ndarray
        :math:`\tau_c = \omega_0 t_c`, broadcast over ``D`` and ``f``; ``inf`` where the
        body sticks.

    Examples
    --------
    Without damping every contact lasts half a period. A critically damped body
    without pressing force has the contact force :math:`(2 - \tau) e^{-\tau}`, so it
    releases at :math:`\tau_c = 2` under the force condition, while its penetration
    :math:`\tau e^{-\tau}` never returns to zero:

    >>> contact_time(0.0, 1.0)
    3.141592653589793
    >>> round(contact_time(1.0, 0.0), 12)
    2.0
    >>> contact_time(1.0, 0.0, condition="position")
    inf
    """
    (damping, force), shape, scalar = _inputs(condition, D=D, f=f)
    return finish(_contact_time(condition, damping, force).reshape(shape), scalar)


def restitution(D: ArrayLike, f: ArrayLike, *, condition: str = "force") -> ArrayLike:
    r"""Coefficient of restitution :math:`e = -z'(\tau_c)`; ``0.0`` where the body sticks.

    Parameters are those of :func:`contact_time`.

    Examples
    --------
    >>> restitution(0.0, 2.0)
    1.0
    >>> round(restitution(1.0, 0.0), 12)  # z'(2) = -exp(-2) for D = 1, f = 0
    0.135335283237
    """
    (damping, force), shape, scalar = _inputs(condition, D=D, f=f)
    decided, _, e_limit = _limits(condition, damping, force)
    e = np.zeros(damping.shape)
    e[decided] = e_limit
    near = ~decided
    d, fr = damping[near], force[near]
    tau_c = _contact_time(condition, d, fr)
    e_near = np.zeros(d.shape)
    release = np.isfinite(tau_c)
    if release.any():
        e_near[release] = -_z_dot()(tau_c[release], d[release], fr[release])
    e[near] = e_near
    # 0 <= e <= 1 by the energy balance; rounding must not push it past 1
    return finish(np.clip(e, 0.0, 1.0).reshape(shape), scalar)


def contact_surface(
    D: ArrayLike, f: ArrayLike, *, condition: str = "force"
) -> tuple[ArrayLike, ArrayLike, ArrayLike]:
    r"""The two sheets and the ridge of the implicit surface :math:`g(\tau, D, f) = 0`.

    The paper's Fig. 1a: where the body releases, ``g`` crosses zero downwards at the
    contact time (lower sheet) and upwards again after its first minimum (upper
    sheet); both sheets meet along the fold :math:`\partial g/\partial\tau = 0`, at the
    ridge time :math:`\tau_r(D, f)`, on the stick boundary.

    Returns
    -------
    first, second, ridge
        Lower sheet (the contact time), upper sheet, and ridge time; ``nan`` where
        the body sticks (no sheet) or where ``g`` has no minimum (no ridge). The upper
        sheet is ``nan`` also when ``g`` only creeps back to zero (``f = 0``, ``D >= 1``).

    Examples
    --------
    >>> first, second, ridge = contact_surface(0.0, 1.0)
    >>> [round(x / np.pi, 12) for x in (first, second, ridge)]
    [1.0, 2.0, 1.5]
    """
    (damping, force), shape, scalar = _inputs(condition, D=D, f=f)
    if _limits(condition, damping, force)[0].any():
        raise ValueError(
            f"contact_surface needs D <= {_D_FAR:g} and 2 D f <= {_B_MAX:g} (the sheets "
            "of the surface are not resolved beyond); use contact_time there"
        )
    k = _kernels(condition)
    ridge = _ridge(condition, damping, force)
    first = _contact_time(condition, damping, force, ridge)
    release = np.isfinite(first)
    second = np.full(damping.shape, np.nan)
    d, fr, lo = damping[release], force[release], ridge[release]
    hi = np.empty_like(lo)
    under = d < 1
    hi[under] = lo[under] + np.pi / np.sqrt((1.0 - d[under]) * (1.0 + d[under]))  # next maximum
    hi[~under] = 2.0 * lo[~under]  # g rises monotonically towards 2Df: search upwards
    rising = (~under) & (fr > 0)
    for _ in range(60):
        short = rising & ~(k.scaled_g(hi, d, fr) > 0)
        if not short.any():
            break
        hi[short] *= 2.0
    solvable = under | rising
    second_release = np.full(d.shape, np.nan)
    second_release[solvable] = bracketed_newton(
        k.scaled_g, k.scaled_g_dot, lo[solvable], hi[solvable], [d[solvable], fr[solvable]]
    )
    second[release] = second_release
    first = np.where(release, first, np.nan)
    return tuple(finish(a.reshape(shape), scalar) for a in (first, second, ridge))


#: Damping ratio beyond which the bracket search for the force boundary gives up.
_D_SEARCH_LIMIT = 1e150


def stick_boundary(f: ArrayLike, *, condition: str = "force") -> ArrayLike:
    r"""Damping ratio :math:`D^*(f)` at which sticking begins for pressing force ``f``.

    The body releases for :math:`D < D^*` and sticks for :math:`D > D^*`. :math:`D^*`
    is the root in ``D`` of the boundary equation :math:`G(D, f) = g(\tau_r(D, f), D, f)
    = 0` (the implicit curve of the paper's Fig. 1b), found by safeguarded Newton
    iteration with the envelope derivative :math:`\partial G/\partial D = \partial g/
    \partial D` at :math:`\tau_r`.

    Limits at :math:`f = 0`: under the position condition :math:`D^* = 1` (an
    under-damped body always comes back out, a critically or over-damped one creeps
    back to :math:`z = 0` without crossing); under the force condition
    :math:`D^* = \infty` (without pressing force the contact force always becomes
    tensile first), and :math:`D^*(f) \to \infty` as :math:`f \to 0`, following
    :math:`D^* = f^{-1/4}/2` (used for :math:`f < 6.25 \cdot 10^{-34}`, where it is exact
    to double precision). For large ``f`` both boundaries follow
    :math:`D^* = (16\pi f^2)^{-1/3}` (used for :math:`f > 10^{12}`, relative error
    below :math:`5 \cdot 10^{-9}`).

    Parameters
    ----------
    f : float or array_like
        Normalized pressing force, ``>= 0``.
    condition : {"force", "position"}

    Returns
    -------
    float or ndarray
        :math:`D^*(f)`, broadcast like ``f``.

    Examples
    --------
    >>> stick_boundary(0.0, condition="position"), stick_boundary(0.0, condition="force")
    (1.0, inf)
    >>> d_star = stick_boundary(0.5, condition="position")
    >>> bool(contact_time(d_star - 1e-6, 0.5, condition="position") < float("inf"))
    True
    >>> contact_time(d_star + 1e-6, 0.5, condition="position")
    inf
    """
    (force,), shape, scalar = _inputs(condition, f=f)
    result = np.full(force.shape, 1.0 if condition == "position" else np.inf)
    pressed = force > 0
    if condition == "force":  # D* > 1e8: the asymptote, exact there to double precision
        tiny = pressed & (force < _F_FAR)
        result[tiny] = 0.5 * force[tiny] ** -0.25
        pressed &= ~tiny
    large = pressed & (force > _F_LARGE)  # the large-f asymptote, relative error < 5e-9
    result[large] = _C_LARGE_F * force[large] ** (-2.0 / 3.0)
    pressed &= ~large
    if pressed.any():
        fr = force[pressed]
        k = _kernels(condition)

        def minimum(damping: np.ndarray, fv: np.ndarray) -> np.ndarray:
            return _boundary_value(condition, damping, fv)

        def slope(damping: np.ndarray, fv: np.ndarray) -> np.ndarray:
            ridge = _ridge(condition, damping, fv)
            exists = ~np.isnan(ridge)
            out = 2.0 * fv  # d(2Df)/dD where g has no minimum
            out[exists] = k.boundary_slope(ridge[exists], damping[exists], fv[exists])
            return out

        hi = np.ones_like(fr)  # position: G(1, f) = 2f > 0, D* < 1
        if condition == "force":
            low = minimum(hi, fr) < 0
            while low.any():
                hi[low] *= 4.0
                if hi.max() > _D_SEARCH_LIMIT:
                    raise ValueError(f"f = {float(fr[low].min())!r} is too small to locate D*")
                low[low] = minimum(hi[low], fr[low]) < 0
        result[pressed] = bracketed_newton(minimum, slope, np.zeros_like(fr), hi, [fr])
    return finish(result.reshape(shape), scalar)


def _check_derived(what: str, inputs: str, values: np.ndarray, valid) -> None:
    """Raise naming the inputs when a derived quantity leaves double precision."""
    bad = ~valid(values)
    if np.any(bad):
        raise ValueError(
            f"the inputs {inputs} are too extreme: {what} = {float(values[bad].flat[0])!r} "
            "is not representable in double precision"
        )


@dataclass(frozen=True)
class PhysicalContact:
    r"""A spring-damper impact in physical units, with its normalized description.

    Attributes
    ----------
    D, f, omega0
        Lehr's damping, normalized pressing force :math:`F/(d v_0)` (``inf`` for
        :math:`d = 0 < F`), natural frequency :math:`\sqrt{k/m}`.
    normalized_contact_time, contact_time
        Normalized contact time :math:`\tau_c` and contact time in the caller's time
        unit (seconds for SI input), :math:`t_c = \tau_c/\omega_0`; ``inf``: sticking.
    restitution
        Coefficient of restitution (``0.0`` when sticking).
    condition
        The contact condition used.
    """

    D: ArrayLike
    f: ArrayLike
    omega0: ArrayLike
    normalized_contact_time: ArrayLike
    contact_time: ArrayLike
    restitution: ArrayLike
    condition: str

    @property
    def sticks(self) -> bool | np.ndarray:
        """Whether the body sticks (never releases)."""
        stuck = np.isinf(self.contact_time)
        return bool(stuck) if np.ndim(stuck) == 0 else stuck


def physical_contact(
    m: ArrayLike,
    k: ArrayLike,
    d: ArrayLike,
    v0: ArrayLike,
    F: ArrayLike = 0.0,
    *,
    condition: str = "force",
) -> PhysicalContact:
    r"""Contact time and restitution of a body of mass ``m`` hitting a spring ``k`` and
    damper ``d`` at speed ``v0`` under a pressing force ``F`` (any consistent units).

    .. math::  \omega_0 = \sqrt{k/m},\quad D = \frac{d}{2\sqrt{km}},\quad
               f = \frac{F}{d v_0},\quad t_c = \tau_c(D, f)/\omega_0.

    For an undamped contact with pressing force (:math:`d = 0 < F`), where the paper's
    :math:`f` is infinite, :math:`z'' + z = b` with the static penetration
    :math:`b = 2Df = F/(\sqrt{km} v_0)` is solved in closed form:
    :math:`\tau_c = 2\pi - 2\arctan(1/b)`, :math:`e = 1`.

    Examples
    --------
    >>> c = physical_contact(m=2.0, k=800.0, d=0.0, v0=1.0)
    >>> c.omega0, round(c.contact_time, 12) == round(float(np.pi) / 20.0, 12), c.restitution
    (20.0, True, 1.0)
    >>> physical_contact(m=1.0, k=1.0, d=4.0, v0=1.0, F=1.0).sticks
    True
    """
    check_condition(condition)
    values = {
        name: real_array(name, value, lower=0.0, strict=strict)
        for name, value, strict in (
            ("m", m, True),
            ("k", k, True),
            ("d", d, False),
            ("v0", v0, True),
            ("F", F, False),
        )
    }
    scalar = all(s for _, s in values.values())
    shape = broadcast(**{name: a for name, (a, _) in values.items()})
    mass, stiffness, damping, speed, load = (
        np.broadcast_to(a, shape).ravel() for a, _ in values.values()
    )
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        root_k, root_m = np.sqrt(stiffness), np.sqrt(mass)  # no overflow in k * m or k / m
        omega0 = root_k / root_m
        D_ = damping / 2.0 / (root_k * root_m)
        f_ = np.where(load > 0, load / damping / speed, 0.0)
        static = load / (root_k * root_m) / speed  # 2 D f, finite also where d = 0
    _check_derived("omega0 = sqrt(k/m)", "m, k", omega0, lambda w: (w > 0) & np.isfinite(w))
    _check_derived("D = d/(2 sqrt(k m))", "d, k, m", D_, np.isfinite)
    # d = 0 < F, or d so small that D b^2 and D (b = 2Df, the static penetration) vanish
    # to double precision: undamped with offset b (f may overflow there)
    with np.errstate(over="ignore", invalid="ignore"):  # 0 * inf where D = 0: caught below
        negligible = (D_ < 1e-16) & (D_ * static**2 < 1e-16)
    undamped_pressed = (load > 0) & ((D_ == 0) | (~np.isfinite(f_) & negligible))
    finite = ~undamped_pressed
    _check_derived("f = F/(d v0)", "F, d, v0", f_[finite], np.isfinite)
    tau_c, e = np.empty(D_.shape), np.empty(D_.shape)
    try:
        tau_c[finite] = contact_time(D_[finite], f_[finite], condition=condition)
        e[finite] = restitution(D_[finite], f_[finite], condition=condition)
    except ValueError as exc:
        raise ValueError(f"physical_contact: the inputs m, k, d, v0, F give {exc}") from None
    tau_c[undamped_pressed] = 2.0 * np.pi - 2.0 * np.arctan2(1.0, static[undamped_pressed])
    e[undamped_pressed] = 1.0
    with np.errstate(over="ignore", under="ignore"):
        t_c = tau_c / omega0
    _check_derived(
        "t_c = tau_c/omega0", "m, k", t_c, lambda t: np.isinf(tau_c) | ((t > 0) & np.isfinite(t))
    )
    D_, f_, omega0, tau_c, t_c, e = (a.reshape(shape) for a in (D_, f_, omega0, tau_c, t_c, e))
    return PhysicalContact(
        D=finish(D_, scalar),
        f=finish(f_, scalar),
        omega0=finish(omega0, scalar),
        normalized_contact_time=finish(tau_c, scalar),
        contact_time=finish(t_c, scalar),
        restitution=finish(e, scalar),
        condition=condition,
    )
