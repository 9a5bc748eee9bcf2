r"""Spring-damper contact (paper section 2): contact time, restitution, stick boundary.

The public face of the section-2 contact: validated, broadcasting functions for
:math:`z'' + 2Dz' + z = 2Df`, :math:`z(0) = 0`, :math:`z'(0) = 1`, ending at the first
sign change of :math:`g = z` (position condition) or :math:`g = 2Dz' + z` (force
condition) (`docs/physics.md, section 2 <../physics.html#2-spring-damper-contact-paper-2>`_).
The numbers come from the closed forms of :mod:`impactsym.contact.derivation`, evaluated
by :mod:`impactsym.contact.kernel` (ridge-bracketed Newton iteration, no time sampling);
without pressing force (``f == 0``) the contact time and restitution are themselves
closed forms (:mod:`impactsym.contact.unpressed`), taken element by element.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impactsym.contact.kernel import (
    B_MAX,
    C_LARGE_F,
    D_FAR,
    F_FAR,
    F_LARGE,
    boundary_value,
    by_pressing,
    check_derived,
    first_impact,
    first_release,
    flat_inputs,
    kernels,
    limits,
    ridge,
)
from impactsym.contact.unpressed import unpressed_release
from impactsym.numeric.roots import bracketed_newton
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, check_condition, finish, real_array

ArrayLike = float | np.ndarray


def _release(
    damping: np.ndarray, force: np.ndarray, *, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    """Contact time and restitution (clipped to [0, 1]) on flat arrays."""
    tau_c, e = first_impact(damping, force, condition=condition)
    # 0 <= e <= 1 by the energy balance; rounding must not push it past 1
    return tau_c, np.clip(e, 0.0, 1.0)


def contact_time(D: ArrayLike, f: ArrayLike, *, condition: str) -> ArrayLike:
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

    Notes
    -----
    Where ``f == 0`` the contact time is the closed form of
    :func:`impactsym.contact.unpressed.unpressed_release`: :math:`\pi/\sqrt{1 - D^2}`
    (position, ``inf`` from :math:`D = 1` on) and :math:`2\arccos(D)/\sqrt{1 - D^2}`
    (force, :math:`2\operatorname{arcosh}(D)/\sqrt{D^2 - 1}` over-damped); elsewhere the
    kernel's bracketed root.

    Examples
    --------
    Without damping every contact lasts half a period. A critically damped body
    without pressing force has the contact force :math:`(2 - \tau) e^{-\tau}`, so it
    releases at :math:`\tau_c = 2` under the force condition, while its penetration
    :math:`\tau e^{-\tau}` never returns to zero:

    >>> contact_time(0.0, 1.0, condition="force")
    3.141592653589793
    >>> round(contact_time(1.0, 0.0, condition="force"), 12)
    2.0
    >>> contact_time(1.0, 0.0, condition="position")
    inf
    """
    (damping, force), shape, scalar = flat_inputs(condition=condition, D=D, f=f)
    (tau_c,) = by_pressing(
        damping,
        force,
        lambda d: unpressed_release(d, condition=condition)[:1],
        lambda d, fr: (first_release(d, fr, condition=condition),),
    )
    return finish(tau_c.reshape(shape), scalar)


def restitution(D: ArrayLike, f: ArrayLike, *, condition: str) -> ArrayLike:
    r"""Coefficient of restitution :math:`e = -z'(\tau_c)`; ``0.0`` where the body sticks.

    Parameters are those of :func:`contact_time`. Where ``f == 0``, :math:`e =
    e^{-D\tau_c}` in closed form (:mod:`impactsym.contact.unpressed`).

    Examples
    --------
    >>> restitution(0.0, 2.0, condition="force")
    1.0
    >>> round(restitution(1.0, 0.0, condition="force"), 12)  # z'(2) = -exp(-2) for D = 1, f = 0
    0.135335283237
    """
    (damping, force), shape, scalar = flat_inputs(condition=condition, D=D, f=f)
    e = _release(damping, force, condition=condition)[1]
    return finish(e.reshape(shape), scalar)


def contact_surface(
    D: ArrayLike, f: ArrayLike, *, condition: str
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
    >>> first, second, ridge = contact_surface(0.0, 1.0, condition="force")
    >>> [round(x / np.pi, 12) for x in (first, second, ridge)]
    [1.0, 2.0, 1.5]
    """
    (damping, force), shape, scalar = flat_inputs(condition=condition, D=D, f=f)
    if limits(damping, force, condition=condition)[0].any():
        raise ValueError(
            f"contact_surface needs D <= {D_FAR:g} and 2 D f <= {B_MAX:g} (the sheets "
            "of the surface are not resolved beyond); use contact_time there"
        )
    k = kernels(condition=condition)
    at_ridge = ridge(damping, force, condition=condition)
    first = first_release(damping, force, at_ridge, condition=condition)
    release = np.isfinite(first)
    second = np.full(damping.shape, np.nan)
    d, fr, lo = damping[release], force[release], at_ridge[release]
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
    return tuple(finish(a.reshape(shape), scalar) for a in (first, second, at_ridge))


#: Damping ratio beyond which the bracket search for the force boundary gives up.
_D_SEARCH_LIMIT = 1e150


def stick_boundary(f: ArrayLike, *, condition: str) -> ArrayLike:
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
    (force,), shape, scalar = flat_inputs(condition=condition, f=f)
    result = np.full(force.shape, 1.0 if condition == "position" else np.inf)
    pressed = force > 0
    if condition == "force":  # D* > 1e8: the asymptote, exact there to double precision
        tiny = pressed & (force < F_FAR)
        result[tiny] = 0.5 * force[tiny] ** -0.25
        pressed &= ~tiny
    large = pressed & (force > F_LARGE)  # the large-f asymptote, relative error < 5e-9
    result[large] = C_LARGE_F * force[large] ** (-2.0 / 3.0)
    pressed &= ~large
    if pressed.any():
        fr = force[pressed]
        k = kernels(condition=condition)

        def minimum(damping: np.ndarray, fv: np.ndarray) -> np.ndarray:
            return boundary_value(damping, fv, condition=condition)

        def slope(damping: np.ndarray, fv: np.ndarray) -> np.ndarray:
            at = ridge(damping, fv, condition=condition)
            exists = ~np.isnan(at)
            out = 2.0 * fv  # d(2Df)/dD where g has no minimum
            out[exists] = k.boundary_slope(at[exists], damping[exists], fv[exists])
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


@dataclass(frozen=True, eq=False)
class PhysicalContact(ArrayRecord):
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
    condition: str,
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
    >>> c = physical_contact(m=2.0, k=800.0, d=0.0, v0=1.0, condition="force")
    >>> c.omega0, round(c.contact_time, 12) == round(float(np.pi) / 20.0, 12), c.restitution
    (20.0, True, 1.0)
    >>> physical_contact(m=1.0, k=1.0, d=4.0, v0=1.0, F=1.0, condition="force").sticks
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
    check_derived("omega0 = sqrt(k/m)", "m, k", omega0, lambda w: (w > 0) & np.isfinite(w))
    check_derived("D = d/(2 sqrt(k m))", "d, k, m", D_, np.isfinite)
    # d = 0 < F, or d so small that D b^2 and D (b = 2Df, the static penetration) vanish
    # to double precision: undamped with offset b (f may overflow there)
    with np.errstate(over="ignore", invalid="ignore"):  # 0 * inf where D = 0: caught below
        negligible = (D_ < 1e-16) & (D_ * static**2 < 1e-16)
    undamped_pressed = (load > 0) & ((D_ == 0) | (~np.isfinite(f_) & negligible))
    finite = ~undamped_pressed
    check_derived("f = F/(d v0)", "F, d, v0", f_[finite], np.isfinite)
    tau_c, e = np.empty(D_.shape), np.empty(D_.shape)
    try:
        if finite.all():  # no copies
            tau_c, e = _release(D_, f_, condition=condition)
        else:
            tau_c[finite], e[finite] = _release(D_[finite], f_[finite], condition=condition)
    except ValueError as exc:
        raise ValueError(f"physical_contact: the inputs m, k, d, v0, F give {exc}") from None
    tau_c[undamped_pressed] = 2.0 * np.pi - 2.0 * np.arctan2(1.0, static[undamped_pressed])
    e[undamped_pressed] = 1.0
    with np.errstate(over="ignore", under="ignore"):
        t_c = tau_c / omega0
    check_derived(
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
