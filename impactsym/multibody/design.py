r"""Penalty-parameter design for a reduced multibody contact (paper sections 2 and 3).

Given the reduction of a system at its impact state
(:func:`impactsym.multibody.reduce_contact`) these functions choose the penalty
stiffness ``k`` and damping ``d``. Only ``d~ = d + delta_d`` and ``c~ = k + delta_c``
depend on them, so along a line of constant ``k`` the section-2 parameters move on the
hyperbola

.. math::

    2 D f = \beta(k) = \frac{F_n}{\tilde m\, \omega_0\, v_0}, \qquad
    D = \frac{d + \Delta d}{2 \tilde m \omega_0}, \qquad
    \omega_0 = \sqrt{(k + \Delta c)/\tilde m},

and cross the stick/release boundary ``D = D*(f)`` of section 2
(:func:`impactsym.contact.stick_boundary`) where ``D = D*(beta / (2 D))``. Each target is
a monotone scalar equation along that line, solved by bracketing and the Illinois method
(:func:`impactsym.numeric.roots.bracketed_illinois`), vectorized over ``k``
(``docs/physics.md``, sections 2 and 3).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.multibody.reduction import ReducedContact
from impactsym.numeric.roots import bracketed_illinois
from impactsym.validation import check_condition, finish, inputs_named, real_array

__all__ = ["damping_for_restitution", "penalty_for_targets", "stick_damping"]


def _numeric_reduction(reduced: object) -> ReducedContact:
    if not isinstance(reduced, ReducedContact):
        raise TypeError(f"reduced must be a ReducedContact, got {type(reduced).__name__}")
    if reduced.is_symbolic:
        raise TypeError("reduced is symbolic; substitute numbers with reduced.subs({...}) first")
    for name in ("m_eff", "delta_d", "delta_c", "load", "v0"):
        if np.ndim(getattr(reduced, name)):
            raise ValueError(
                f"reduced must be the reduction of one impact state ({name} is an array)"
            )
    for name, strict in (("m_eff", True), ("v0", True), ("load", False)):
        value = float(getattr(reduced, name))
        if value < 0 or (strict and value == 0):
            raise ValueError(
                f"reduced.{name} = {value!r} is outside paper section 2 "
                f"({name} must be {'>' if strict else '>='} 0)"
            )
    return reduced


def _scales(reduced: ReducedContact, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``m~ omega0`` and ``beta = 2 D f`` for each stiffness ``k``."""
    c_eff = k + reduced.delta_c
    if np.any(c_eff <= 0):
        bad = float(k[c_eff <= 0].flat[0])
        raise ValueError(
            f"k = {bad!r} does not outweigh the system's negative stiffness "
            f"{reduced.delta_c!r} along the normal: c_eff = k + delta_c must be > 0"
        )
    m_omega = np.sqrt(c_eff * reduced.m_eff)
    return m_omega, reduced.load / (m_omega * reduced.v0)


def stick_damping(reduced: ReducedContact, k: Any, *, condition: str) -> float | np.ndarray:
    r"""Penalty damping ``d*`` on the stick/release boundary for each stiffness ``k``.

    The contact releases for ``d < d*`` and sticks for ``d > d*`` (so "guaranteed
    sticking" needs ``d > d*``); over an array of ``k`` this is the boundary curve of
    the admissible ``(k, d)`` region. With the section-2 boundary ``D*(f)``:

    .. math::

        D = D^*\!\left(\frac{\beta(k)}{2D}\right), \qquad
        d^* = 2 D \tilde m \omega_0 - \Delta d .

    Parameters
    ----------
    reduced
        A numeric reduction of one impact state (its ``k``, ``d`` are not used).
    k
        Penalty stiffness (number or array, ``> 0``).
    condition
        ``"position"`` or ``"force"``.

    Returns
    -------
    float or ndarray
        ``d*`` for each ``k``: ``inf`` where no damping sticks (force condition without
        load); negative where the contact sticks already for ``d = 0``.

    >>> import sympy as sp
    >>> from impactsym.multibody import reduce_contact
    >>> x, v = sp.symbols("x v")
    >>> particle = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0.0]), x, [x], [v],
    ...                           {x: 0, v: 1}, 1.0, 0.0)
    >>> stick_damping(particle, 1.0, condition="position")  # no load: D* = 1, d* = 2 sqrt(k m)
    2.0
    """
    red = _numeric_reduction(reduced)
    check_condition(condition)

    k_arr, scalar = real_array("k", k, lower=0.0, strict=True)
    with inputs_named("stick_damping", k=k, condition=condition):
        d_star = _stick_damping(red, k_arr.ravel(), condition)
    return finish(d_star.reshape(k_arr.shape), scalar)


def _stick_damping(red: ReducedContact, k: np.ndarray, condition: str) -> np.ndarray:
    from impactsym.contact import stick_boundary

    m_omega, beta = _scales(red, k)
    D_star = np.empty_like(beta)
    unloaded = beta == 0
    D_star[unloaded] = float(stick_boundary(0.0, condition=condition))
    loaded = np.flatnonzero(~unloaded)
    if loaded.size:
        b = beta[loaded]

        def excess(D: np.ndarray, index: np.ndarray) -> np.ndarray:
            return D - np.asarray(stick_boundary(b[index] / (2 * D), condition=condition))

        lo, hi = np.full(b.size, 1e-8), np.ones(b.size)
        every = np.arange(b.size)
        if np.any(excess(lo, every) > 0):
            raise RuntimeError("the contact sticks already for D = 1e-8")
        short = excess(hi, every) <= 0
        while short.any():
            hi[short] *= 10.0
            if hi.max() > 1e12:
                raise RuntimeError("no stick boundary below D = 1e12")
            short[short] = excess(hi[short], every[short]) <= 0
        D_star[loaded] = bracketed_illinois(excess, lo, hi, log=True)
    return 2 * D_star * m_omega - red.delta_d


def damping_for_restitution(
    reduced: ReducedContact, k: Any, restitution: float, *, condition: str
) -> float | np.ndarray:
    r"""Penalty damping that gives the coefficient of restitution ``restitution``.

    Solves, for each ``k``, along ``d >= max(0, -delta_d)``

    .. math::

        e\!\left(\frac{d + \Delta d}{2\tilde m\omega_0},
        \frac{F_n}{(d + \Delta d) v_0}\right) = e_{\mathrm{target}},

    where ``e`` falls with ``d`` and drops to 0 where the contact sticks.

    Parameters
    ----------
    reduced
        A numeric reduction of one impact state.
    k
        Penalty stiffness (number or array, ``> 0``).
    restitution
        Target coefficient of restitution in ``(0, 1)``.
    condition
        ``"position"`` or ``"force"``.

    Returns
    -------
    float or ndarray
        The damping ``d`` for each ``k``. A target above the restitution at the least
        damping raises ``ValueError``.

    >>> import sympy as sp
    >>> from impactsym.multibody import reduce_contact
    >>> x, v = sp.symbols("x v")
    >>> particle = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0.0]), x, [x], [v],
    ...                           {x: 0, v: 1}, 1.0, 0.0)
    >>> d = damping_for_restitution(particle, 1.0, float(np.exp(-np.pi / np.sqrt(3))),
    ...                             condition="position")
    >>> round(d, 9)  # e = exp(-pi D / sqrt(1 - D^2)) for D = 1/2, so d = 2 D = 1
    1.0
    """
    red = _numeric_reduction(reduced)
    check_condition(condition)
    e_target = _target_restitution(restitution)
    k_arr, scalar = real_array("k", k, lower=0.0, strict=True)
    k_flat = k_arr.ravel()
    with inputs_named("damping_for_restitution", k=k, restitution=e_target, condition=condition):
        d, e_max = _restitution_damping(red, k_flat, e_target, condition)
    if np.isnan(d).any():
        i = int(np.flatnonzero(np.isnan(d))[0])
        raise ValueError(
            f"restitution {e_target!r} is not reachable at k = {float(k_flat[i])!r} under "
            f"the {condition} condition: the largest restitution (d = 0) is {e_max[i]:.6g}"
        )
    return finish(d.reshape(k_arr.shape), scalar)


def _target_restitution(restitution: object) -> float:
    e_target, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if not scalar or e_target >= 1:
        raise ValueError(f"restitution must be a number in (0, 1), got {restitution!r}")
    return float(e_target)


def _restitution_damping(
    red: ReducedContact, k: np.ndarray, e_target: float, condition: str
) -> tuple[np.ndarray, np.ndarray]:
    """Damping for the target restitution per ``k`` (NaN where even the least damping
    gives less), and the restitution at the least damping."""
    m_omega, _ = _scales(red, k)

    def shortfall(d: np.ndarray, index: np.ndarray) -> np.ndarray:
        e = red.with_penalty(k[index], d).restitution(condition)
        return e_target - np.asarray(e, dtype=float)

    every = np.arange(k.size)
    d_lo = np.full(k.size, max(0.0, -float(red.delta_d)))
    e_max = e_target - shortfall(d_lo, every)
    d = np.full(k.size, np.nan)
    ok = np.flatnonzero(e_max >= e_target)
    if ok.size:
        d_hi = 2 * m_omega[ok] + d_lo[ok]  # D = 1 and up until e is below the target
        short = shortfall(d_hi, ok) <= 0
        while short.any():
            d_hi[short] *= 4.0
            if np.any(d_hi > 1e12 * m_omega[ok]):
                raise RuntimeError("damping_for_restitution: e stays above the target")
            short[short] = shortfall(d_hi[short], ok[short]) <= 0
        d[ok] = bracketed_illinois(lambda x, i: shortfall(x, ok[i]), d_lo[ok], d_hi, log=False)
    return d, e_max


def penalty_for_targets(
    reduced: ReducedContact,
    *,
    restitution: float,
    contact_time: float,
    condition: str,
) -> tuple[float, float]:
    r"""Penalty ``(k, d)`` that releases with a given restitution after a given time.

    For each ``k`` the damping comes from :func:`damping_for_restitution`; ``k`` is
    then chosen (regula falsi in ``log k``) so that the physical contact time matches:

    .. math::

        e(D, f) = e_{\mathrm{target}}, \qquad
        \frac{\tau_c(D, f)}{\omega_0} = t_{\mathrm{target}} .

    Parameters
    ----------
    reduced
        A numeric reduction of one impact state.
    restitution
        Target coefficient of restitution in ``(0, 1)``.
    contact_time
        Target physical contact time (``> 0``).
    condition
        ``"position"`` or ``"force"``.

    Returns
    -------
    (k, d)
        Penalty stiffness and damping; ``ValueError`` if no stiffness within six
        decades around ``m~ (pi / t)^2`` meets both targets.

    >>> import sympy as sp
    >>> from impactsym.multibody import reduce_contact
    >>> x, v = sp.symbols("x v")
    >>> particle = reduce_contact(sp.Matrix([[1.0]]), sp.Matrix([0.0]), x, [x], [v],
    ...                           {x: 0, v: 1}, 1.0, 0.0)
    >>> k, d = penalty_for_targets(particle, restitution=1e-3, contact_time=1e-2,
    ...                            condition="position")
    >>> r = particle.with_penalty(k, d)
    >>> round(r.restitution("position"), 9), round(r.contact_time("position"), 12)
    (0.001, 0.01)
    """
    red = _numeric_reduction(reduced)
    check_condition(condition)
    e_target = _target_restitution(restitution)
    t_target, scalar = real_array("contact_time", contact_time, lower=0.0, strict=True)
    if not scalar:
        raise ValueError(f"contact_time must be a number, got {contact_time!r}")
    t_target = float(t_target)
    with np.errstate(over="ignore", under="ignore"):
        k_grid = red.m_eff * (np.pi / np.float64(t_target)) ** 2 * np.logspace(-3, 3, 13)
    if not (np.all(np.isfinite(k_grid)) and np.all(k_grid > 0)):
        raise ValueError(
            f"contact_time = {t_target!r} is out of range for this reduction: the stiffness "
            f"m~ (pi / t)^2 around which k is searched ({float(k_grid[6])!r}) is not a positive "
            "finite double"
        )
    k_grid = k_grid[k_grid + red.delta_c > 0]
    if k_grid.size < 2:
        raise ValueError(
            f"contact_time = {t_target!r} is too long for this reduction: every stiffness "
            f"searched is below the system's negative stiffness {red.delta_c!r} along the normal"
        )
    with inputs_named(
        "penalty_for_targets",
        restitution=e_target,
        contact_time=t_target,
        condition=condition,
    ):
        return _penalty_for_targets(red, k_grid, e_target, t_target, condition)


def _penalty_for_targets(
    red: ReducedContact, k_grid: np.ndarray, e_target: float, t_target: float, condition: str
) -> tuple[float, float]:

    def excess(k: np.ndarray, _index: np.ndarray | None = None) -> np.ndarray:
        d, _ = _restitution_damping(red, k, e_target, condition)
        t = np.full(k.shape, np.nan)
        ok = ~np.isnan(d)
        if ok.any():
            t[ok] = np.asarray(red.with_penalty(k[ok], d[ok]).contact_time(condition))
        return t_target - t  # rises with k: the contact gets shorter

    values = excess(k_grid)
    change = np.flatnonzero((values[:-1] <= 0) & (values[1:] > 0))
    if change.size == 0:
        raise ValueError(
            f"no stiffness in [{k_grid[0]:.3g}, {k_grid[-1]:.3g}] releases after "
            f"contact_time = {t_target!r} with restitution {e_target!r} under the "
            f"{condition} condition"
        )
    i = change[:1]
    k = float(bracketed_illinois(excess, k_grid[i], k_grid[i + 1], log=True)[0])
    d = float(damping_for_restitution(red, k, e_target, condition=condition))
    return k, d
