r"""Spring-damper contact kernel (paper section 2): flat arrays in, flat arrays out.

Internal: the numbers behind :mod:`impactsym.contact.api`, :mod:`impactsym.contact.bounce`
and :mod:`impactsym.contact.release`. No validation here beyond :func:`flat_inputs`; the
functions take flat float arrays of one length.

**What.** The closed forms of :mod:`impactsym.contact.derivation` (solution, contact
functions ``g`` of both conditions, ridge time, :math:`\partial g/\partial D`), lambdified
once per regime and evaluated piecewise in ``D`` (:class:`PiecewiseInD`); the contact
time as the first root of :math:`g(\tau, D, f)` for :math:`z'' + 2Dz' + z = 2Df`
(`docs/physics.md, section 2 <../physics.html#2-spring-damper-contact-paper-2>`_), from
the first impact ``(z, z') = (0, 1)`` or from any state ``(z0, v0)``.

**Why this numerics.** The root is bracketed without time sampling: the closed-form
ridge time :math:`\tau_r` is the first local minimum of ``g``; the body sticks when
:math:`g(\tau_r) \ge 0`, and otherwise ``g`` falls monotonically from the preceding
maximum (or from impact) to :math:`\tau_r`, where a safeguarded Newton iteration
(:func:`impactsym.numeric.roots.bracketed_newton`) polishes the root on the whole array.
Near-tangent, almost sticking cases are never missed. ``g`` is evaluated with its decay
scaled out (:meth:`Kernels.scaled_g`) so that its sign survives underflow. Where the
closed forms lose double precision (far over-damped ``D``, a huge static penetration)
:func:`limits` decides from asymptotes (physics.md, section 2, *Numerics of the contact time*).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache

import numpy as np

from impactsym.contact.unpressed import unpressed_release
from impactsym.numeric.roots import bracketed_newton
from impactsym.validation import broadcast, check_condition, real_array


def _aux(regime: str, damping: np.ndarray) -> tuple[np.ndarray, ...]:
    """Auxiliary arguments of the numeric forms, computed without cancellation."""
    if regime == "underdamped":
        return (np.sqrt((1.0 - damping) * (1.0 + damping)),)
    if regime == "critical":
        return ()
    spread = np.sqrt(damping - 1.0) * np.sqrt(damping + 1.0)  # no overflow for D > 1e154
    return spread, damping + spread


class PiecewiseInD:
    """A numeric form evaluated regime by regime (masks on D), as one NumPy function.

    Internal. Arguments ``([tau,] D, f)``, or ``([tau,] D, f, z0, v0)`` for a contact
    started from an arbitrary state (``restart``,
    :class:`impactsym.contact.derivation.SpringDamperRestart`).
    """

    def __init__(
        self, name: str, with_tau: bool, critical_separate: bool, restart: bool = False
    ) -> None:
        # SymPy is imported on first use only: importing the kernel stays cheap
        import sympy as sp

        from impactsym.contact import derivation
        from impactsym.contact.derivation import D, f, tau, v0, z0
        from impactsym.numeric.codegen import lambdify

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
        shape = np.broadcast_shapes(*(np.shape(a) for a in args))
        present = [(regime, mask) for regime, mask in masks.items() if mask.any()]
        if len(present) == 1 and np.shape(damping) == shape:  # one regime: no masking
            regime = present[0][0]
            out = self.functions[regime](*args, *_aux(regime, damping))
            return np.broadcast_to(out, shape).copy()  # writable, of the full shape
        out = np.empty(shape)
        for regime, mask in present:
            sub = [a[mask] for a in args]
            out[mask] = self.functions[regime](*sub, *_aux(regime, sub[self.d_index]))
        return out


@dataclass(frozen=True)
class Kernels:
    """Internal: the numeric forms of one condition (see :func:`kernels`)."""

    g: PiecewiseInD
    oscillation: PiecewiseInD
    oscillation_dot: PiecewiseInD
    ridge: PiecewiseInD
    ridge_exists: PiecewiseInD
    boundary_slope: PiecewiseInD

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
        static = _static_part(t, damping, force, rate)
        return self.oscillation_dot(t, damping, force, *state) + rate * static


def _decay_rate(damping: np.ndarray) -> np.ndarray:
    """Decay rate c of the slowest mode (``derivation.DECAY``): D for D <= 1, else 1/mu."""
    over = damping > 1
    if not over.any():  # the under-damped and critical rate is D itself
        return damping
    rate = damping.copy()
    rate[over] = 1.0 / _aux("overdamped", damping[over])[1]
    return rate


def _static_part(
    t: np.ndarray, damping: np.ndarray, force: np.ndarray, rate: np.ndarray | None = None
) -> np.ndarray:
    static = 2.0 * damping * force
    rate = _decay_rate(damping) if rate is None else rate
    with np.errstate(over="ignore", invalid="ignore"):
        grown = static * np.exp(rate * t)
    return np.where(static > 0, grown, 0.0)  # no 0 * inf


@cache
def kernels(*, condition: str, restart: bool = False) -> Kernels:
    """Internal: numeric forms of one condition; ``restart``: from a state (z0, v0)."""

    def piece(name: str, with_tau: bool = True, critical: bool = False) -> PiecewiseInD:
        return PiecewiseInD(
            f"{name}_{condition}", with_tau=with_tau, critical_separate=critical, restart=restart
        )

    return Kernels(
        g=piece("g"),
        oscillation=piece("g_oscillation"),
        oscillation_dot=piece("g_oscillation_dot"),
        ridge=piece("ridge", with_tau=False, critical=True),
        ridge_exists=piece("ridge_exists", with_tau=False, critical=True),
        boundary_slope=piece("g_D"),
    )


@cache
def z_dot(*, restart: bool = False) -> PiecewiseInD:
    """Internal: the penetration rate z'(tau; D, f[, z0, v0]) as a NumPy function."""
    return PiecewiseInD("z_dot", with_tau=True, critical_separate=False, restart=restart)


class Homogeneous:
    r"""Internal: :math:`h` and :math:`h'` of :math:`h'' + 2Dh' + h = 0`, :math:`h(0) = h_0`,
    :math:`h'(0) = h_1`, as one NumPy function ``(tau, D, h0, h1) -> (h, h')``.

    .. math::  h = h_0 C + (h_1 + D h_0) S, \qquad h' = h_1 C - (h_0 + D h_1) S,

    with the damped basis :math:`C` (state :math:`(1, -D)`, :math:`e^{-D\tau}\cos\omega\tau`
    when under-damped) and :math:`S` (state :math:`(0, 1)`) of
    :attr:`impactsym.contact.derivation.SpringDamperContact.numeric_basis`: two
    closed-form evaluations give both ``h`` and ``h'``.
    """

    def __init__(self) -> None:
        from impactsym.contact import derivation  # SymPy on first use only
        from impactsym.numeric.codegen import lambdify

        self.functions = {}
        for r in ("underdamped", "overdamped"):
            args = (derivation.tau, derivation.D) + derivation.NUMERIC_AUX[r]
            c, s = derivation.spring_damper(r).numeric_basis
            self.functions[r] = (
                lambdify(args, c, name=f"C_{r}"),
                lambdify(args, s, name=f"S_{r}"),
            )

    def basis(self, t: np.ndarray, damping: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``C(tau)`` and ``S(tau)`` on flat arrays of one length."""
        under = damping <= 1  # the under-damped form is valid at D = 1 (sinc)
        for regime, everywhere in (("underdamped", under), ("overdamped", ~under)):
            if np.all(everywhere):  # one regime: no masking and copying
                aux = _aux(regime, damping)
                return tuple(fn(t, damping, *aux) for fn in self.functions[regime])
        c, s = np.empty(t.shape), np.empty(t.shape)
        for regime, mask in (("underdamped", under), ("overdamped", ~under)):
            sub = (t[mask], damping[mask])
            aux = _aux(regime, sub[1])
            c[mask], s[mask] = (fn(*sub, *aux) for fn in self.functions[regime])
        return c, s

    def __call__(
        self, t: np.ndarray, damping: np.ndarray, h0: np.ndarray, h1: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        c, s = self.basis(t, damping)
        return c * h0 + s * (h1 + damping * h0), c * h1 - s * (h0 + damping * h1)


@cache
def homogeneous() -> Homogeneous:
    """Internal: the (cached) :class:`Homogeneous` solution of the section-2 oscillator."""
    return Homogeneous()


def ridge(
    damping: np.ndarray,
    force: np.ndarray,
    state: tuple[np.ndarray, ...] = (),
    *,
    condition: str,
) -> np.ndarray:
    """Internal: ridge time, the first local minimum of g after impact; NaN where g has none.

    ``state`` = ``(z0, v0)`` arrays: the contact starts from that state instead.
    """
    k = kernels(condition=condition, restart=bool(state))
    exists = k.ridge_exists(damping, force, *state) > 0.5
    out = np.full(damping.shape, np.nan)
    out[exists] = k.ridge(damping[exists], force[exists], *(a[exists] for a in state))
    return out


def boundary_value(damping: np.ndarray, force: np.ndarray, *, condition: str) -> np.ndarray:
    """Internal: G(D, f) = g at the ridge time (the infimum 2Df of g where g has no minimum)."""
    at = ridge(damping, force, condition=condition)
    exists = ~np.isnan(at)
    minimum = 2.0 * damping * force
    if exists.any():
        g = kernels(condition=condition).g
        minimum[exists] = g(at[exists], damping[exists], force[exists])
    return minimum


#: Damping ratio above which the far over-damped limit replaces the closed-form kernels
#: (their exponentials lose accuracy beyond about 1e9 and overflow beyond 1e154).
D_FAR = 1e8
#: Pressing force below which the force-condition boundary D* = f^(-1/4)/2 lies above
#: ``D_FAR``, where that asymptote is exact to double precision (relative correction
#: of order 2/D*^2 < 1e-16).
F_FAR = (0.5 / D_FAR) ** 4
#: Static penetration 2Df above which the kernels cannot resolve the stick boundary
#: (the minimum of g is a difference of terms of size 2Df; relative resolution of D*
#: about eps (2Df)^2, 2e-8 here).
B_MAX = 1e4
#: Large-f asymptote of the stick boundary, D* = (16 pi f^2)^(-1/3) (both conditions).
C_LARGE_F = (16.0 * np.pi) ** (-1.0 / 3.0)
#: Above this f the stick boundary is the large-f asymptote (its relative correction,
#: about -0.55 f^(-2/3), is below 5e-9 there, and the kernels' resolution eps (2 D* f)^2
#: would be worse beyond).
F_LARGE = 1e12


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
            f"D = {D_bad!r}, f = {f_bad!r}: for D > {D_FAR:g} the contact time is computed "
            "only for f = 0 or where the body sticks (D >= D*(f) = f^(-1/4)/2); this point "
            "releases, below the stick boundary, outside the supported range"
        )
    return tau_c, e


def limits(
    damping: np.ndarray, force: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Internal: points decided by a limit, without the kernels: ``(mask, tau_c, e)``.

    * :math:`D > 10^8`: the far over-damped limit.
    * static penetration :math:`2Df > 10^4`: the body sticks when
      :math:`D \ge 2 D^*_\infty(f)`, twice the large-``f`` boundary
      :math:`D^*_\infty = (16\pi f^2)^{-1/3}`; closer to the boundary the sign of the
      first minimum of ``z`` is below double-precision rounding, and the point is refused
      (physics.md, section 2, *Numerics of the contact time*).
    """
    with np.errstate(over="ignore"):
        static = damping * force * 2.0  # not 2 D first: 2 D may overflow where f = 0
    far = damping > D_FAR
    big = (static > B_MAX) & ~far
    tau_c, e = np.full(damping.shape, np.inf), np.zeros(damping.shape)
    if far.any():
        tau_c[far], e[far] = _far_overdamped(condition, damping[far], force[far])
    if big.any():
        unresolved = damping[big] < 2.0 * C_LARGE_F * force[big] ** (-2.0 / 3.0)
        if unresolved.any():
            D_bad, f_bad = float(damping[big][unresolved][0]), float(force[big][unresolved][0])
            raise ValueError(
                f"D = {D_bad!r}, f = {f_bad!r}: the static penetration 2 D f exceeds "
                f"{B_MAX:g} and D is within a factor 2 of the stick boundary "
                "D* ~ (16 pi f^2)^(-1/3), where double precision cannot tell whether the "
                "body releases; only clearly sticking points are computed there"
            )
    decided = far | big
    return decided, tau_c[decided], e[decided]


def first_release(
    damping: np.ndarray,
    force: np.ndarray,
    at_ridge: np.ndarray | None = None,
    state: tuple[np.ndarray, ...] = (),
    *,
    condition: str,
) -> np.ndarray:
    """Internal: contact time on flat arrays (no validation); ``at_ridge`` if computed.

    ``state`` = ``(z0, v0)`` arrays: the contact starts from ``z(0) = z0, z'(0) = v0``
    (with ``g(0) > 0``) instead of the first impact's ``(0, 1)``; the same argument holds.
    The :func:`limits` are those of the first impact (``state = ()``).
    """
    if not state:
        decided, tau_limit, _ = limits(damping, force, condition=condition)
        if decided.any():
            result = np.empty(damping.shape)
            result[decided] = tau_limit
            rest = ~decided
            result[rest] = first_release(
                damping[rest],
                force[rest],
                None if at_ridge is None else at_ridge[rest],
                condition=condition,
            )
            return result
    k = kernels(condition=condition, restart=bool(state))
    if at_ridge is None:
        at_ridge = ridge(damping, force, state, condition=condition)
    exists = ~np.isnan(at_ridge)
    release = exists.copy()
    at = [a[exists] for a in state]
    release[exists] = k.scaled_g(at_ridge[exists], damping[exists], force[exists], *at) < 0
    result = np.full(damping.shape, np.inf)
    if release.any():
        d, fr, hi = damping[release], force[release], at_ridge[release]
        lo = np.zeros_like(hi)  # g decreases from impact, or from the preceding maximum:
        under = d < 1
        half_period = np.pi / np.sqrt((1.0 - d[under]) * (1.0 + d[under]))
        lo[under] = np.maximum(hi[under] - half_period, 0.0)
        params = [d, fr, *(a[release] for a in state)]
        result[release] = bracketed_newton(k.scaled_g, k.scaled_g_dot, lo, hi, params)
    return result


def check_derived(what: str, inputs: str, values: np.ndarray, valid) -> None:
    """Internal: raise naming the inputs when a derived quantity leaves double precision.

    ``valid(values)`` is the mask of admissible values (e.g. finite and positive).
    """
    bad = ~valid(values)
    if np.any(bad):
        raise ValueError(
            f"the inputs {inputs} are too extreme: {what} = {float(values[bad].flat[0])!r} "
            "is not representable in double precision"
        )


def flat_inputs(
    *, condition: str, **arrays: object
) -> tuple[list[np.ndarray], tuple[int, ...], bool]:
    """Internal: validate ``condition`` and non-negative real ``arrays``; return them
    broadcast and flattened, their common shape, and whether all were scalars."""
    check_condition(condition)
    checked = [real_array(name, value, lower=0.0) for name, value in arrays.items()]
    shape = broadcast(**{name: a for name, (a, _) in zip(arrays, checked, strict=True)})
    flat = [np.broadcast_to(a, shape).ravel() for a, _ in checked]
    return flat, shape, all(s for _, s in checked)


def by_pressing(
    damping: np.ndarray,
    force: np.ndarray,
    unpressed: Callable[[np.ndarray], tuple[np.ndarray, ...]],
    pressed: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]],
) -> tuple[np.ndarray, ...]:
    """Internal: flat arrays ``unpressed(D)`` where ``f == 0`` (the closed forms of
    :mod:`impactsym.contact.unpressed`), ``pressed(D, f)`` elsewhere (the kernel); both
    return tuples of the same length."""
    free = force == 0
    if free.all():  # the common cases: no copies
        return unpressed(damping)
    if not free.any():
        return pressed(damping, force)
    parts = zip(unpressed(damping[free]), pressed(damping[~free], force[~free]), strict=True)
    out = []
    for a, b in parts:
        o = np.empty(damping.shape)
        o[free], o[~free] = a, b
        out.append(o)
    return tuple(out)


def first_impact(
    damping: np.ndarray, force: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    """Internal: contact time and restitution (not clipped; ``0`` where the body sticks) of
    the first impact on flat arrays: the closed forms where ``f == 0``, else the kernel's
    contact time (one root per element), its :func:`limits` and ``-z'`` there."""
    return by_pressing(
        damping,
        force,
        lambda d: unpressed_release(d, condition=condition),
        lambda d, fr: _pressed_impact(d, fr, condition=condition),
    )


def _pressed_impact(
    damping: np.ndarray, force: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    tau_c = first_release(damping, force, condition=condition)
    decided, _, e_limit = limits(damping, force, condition=condition)
    e = np.zeros(damping.shape)
    e[decided] = e_limit
    release = ~decided & np.isfinite(tau_c)
    if release.any():
        e[release] = -z_dot()(tau_c[release], damping[release], force[release])
    return tau_c, e
