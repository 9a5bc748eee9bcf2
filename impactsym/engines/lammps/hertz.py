r"""The Hertz contact of LAMMPS ``pair_style granular`` with Tsuji damping: the exact map
onto the package's ``"tsuji"`` law, the prediction and the design.

LAMMPS (``pair_style granular``, ``fix wall/gran granular``; source
``src/GRANULAR/gran_sub_mod_normal.cpp`` and ``gran_sub_mod_damping.cpp``) computes the
normal force on an overlap :math:`\delta` closing at :math:`\dot\delta` as
:math:`F_n = F_{ne} + \eta_n \dot\delta` with

* ``hertz kn``: :math:`F_{ne} = k_n a \delta`, contact radius
  :math:`a = \sqrt{R_{eff}\delta}`, so :math:`F_{ne} = k_n\sqrt{R_{eff}}\,\delta^{3/2}`;
* ``hertz/material E e nu``: the same with :math:`k_n = \tfrac43 E_{eff}`,
  :math:`E_{eff} = E/(2(1-\nu^2))` for two particles of one material and for a particle
  on a wall (``mix_stiffnessE``, ``mix_stiffnessE_wall``);
* ``damping tsuji``: :math:`\eta_n = \alpha\sqrt{m_{eff} F_{ne}/\delta}`, the damping
  coefficient ``e`` of ``pair_coeff`` entering only through Marshall's (2009, Eq. 53)
  fit :math:`\alpha(e) = 1.2728 - 4.2783 e + 11.087 e^2 - 22.348 e^3 + 27.467 e^4 -
  18.022 e^5 + 4.8218 e^6` (the 22Jul2025 release measured here; later sources multiply
  it by :math:`\sqrt2`, ``tsuji_sqrt2=True``);
* ``damping coeff_restitution`` (non-Hooke normal models): the same :math:`\eta_n` with
  :math:`\alpha = -\sqrt{3/2}\cdot 2\sqrt{5/6}\,\ln e/\sqrt{\pi^2 + \ln^2 e} =
  \sqrt5\,|\beta(e)|`, the DEM formula;
* ``limit_damping``: a negative total :math:`F_n` is set to zero.

With :math:`k = k_n\sqrt{R_{eff}}` (``hertz``) or :math:`k = \tfrac43 E_{eff}
\sqrt{R_{eff}}` (``hertz/material``), :math:`F_{ne}/\delta = k\,\delta^{1/2}` and

.. math::  F_n = k\,\delta^{3/2} + \alpha\sqrt{m_{eff} k}\,\delta^{1/4}\dot\delta,

which is **exactly** the ``"tsuji"`` law of :mod:`impactsym.contact.laws` with
``stiffness = k``, ``damping = alpha``, ``exponent = 3/2``, ``mass = m_eff`` (``m`` on a
wall or a frozen particle, :math:`m_i m_j/(m_i + m_j)` otherwise) and ``force = m g``
for a particle pressed by gravity. Without ``limit_damping`` the tensile force is kept
and contact lasts while the particles overlap: the **position** condition. With it LAMMPS
sets the negative total force to zero on the geometric overlap: the **clipped** condition
(``docs/physics.md``, *The clipped condition*): where the force would pull, the sphere
coasts inside the overlap under gravity alone and either leaves at zero overlap or is
caught again by the force. Without gravity the coast keeps its speed and the clipped
restitution is the force condition's; with gravity the departure is slower, or never
comes. So :func:`predict_hertz` is :func:`~impactsym.contact.nonlinear.impact`, and
:func:`hertz_coefficient_for` turns :func:`~impactsym.contact.lawdesign.damping_for`'s
``alpha`` into the coefficient to write in ``pair_coeff``. SI units throughout.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from impactsym.contact.lawdesign import damping_for
from impactsym.contact.nonlinear import NonlinearImpact, impact
from impactsym.engines.lammps.common import check_flag
from impactsym.validation import finish, real_array

__all__ = [
    "DAMPING_STYLES",
    "NORMAL_MODELS",
    "TSUJI_FIT",
    "design_alpha",
    "hertz_coefficient_for",
    "hertz_stiffness",
    "predict_hertz",
    "tsuji_alpha",
]

#: Coefficients of Marshall's fit alpha(e) of LAMMPS's ``damping tsuji``, from e^0 up.
TSUJI_FIT = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)
#: The damping styles mapped here.
DAMPING_STYLES = ("tsuji", "coeff_restitution")
#: The normal models mapped here.
NORMAL_MODELS = ("hertz/material", "hertz")


def _choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"{name} must be one of {allowed}, got {value!r}")
    return value


def hertz_stiffness(
    *,
    modulus: Any,
    effective_radius: Any,
    poisson: Any = 0.0,
    normal: str = "hertz/material",
) -> float | np.ndarray:
    r"""``k`` of the ``"tsuji"`` law for LAMMPS's Hertz normal model (N/m^1.5).

    ``hertz/material``: :math:`k = \tfrac43\,E/(2(1-\nu^2))\,\sqrt{R_{eff}}` with Young's
    modulus ``modulus`` (Pa) and ``poisson``; ``hertz``: :math:`k = k_n\sqrt{R_{eff}}`
    with ``modulus`` the ``kn`` of ``pair_coeff`` (``poisson`` unused). ``R_eff`` is the
    radius on a wall, half of it for two equal spheres.

    >>> round(hertz_stiffness(modulus=1e7, poisson=0.3, effective_radius=0.1), 3)
    2316686.931
    >>> hertz_stiffness(modulus=4.0, effective_radius=0.25, normal="hertz")
    2.0
    """
    _choice("normal", normal, NORMAL_MODELS)
    E, s1 = real_array("modulus", modulus, lower=0.0, strict=True)
    R, s2 = real_array("effective_radius", effective_radius, lower=0.0, strict=True)
    nu, s3 = real_array("poisson", poisson)
    if normal == "hertz":
        return finish(E * np.sqrt(R), s1 and s2)
    if np.any((nu <= -1.0) | (nu >= 1.0)):
        raise ValueError(f"poisson must lie in (-1, 1), got {poisson!r}")
    return finish(4.0 / 3.0 * E / (2.0 * (1.0 - nu * nu)) * np.sqrt(R), s1 and s2 and s3)


def tsuji_alpha(
    coefficient: Any, *, damping: str = "tsuji", tsuji_sqrt2: bool = False
) -> float | np.ndarray:
    r"""``alpha`` of the ``"tsuji"`` law that LAMMPS uses for the damping ``coefficient``
    of ``pair_coeff`` (module docstring): Marshall's fit (``damping tsuji``, times
    :math:`\sqrt2` if ``tsuji_sqrt2``) or :math:`\sqrt5\,|\beta(e)|`
    (``damping coeff_restitution``).

    >>> round(tsuji_alpha(0.5), 8), round(tsuji_alpha(0.5, damping="coeff_restitution"), 6)
    (0.34074063, 0.481769)
    """
    _choice("damping", damping, DAMPING_STYLES)
    check_flag("tsuji_sqrt2", tsuji_sqrt2)
    e, scalar = real_array("coefficient", coefficient, lower=0.0, strict=damping != "tsuji")
    if np.any(e > 1.0):
        raise ValueError(f"coefficient must be <= 1 (a restitution), got {coefficient!r}")
    if damping == "tsuji":
        alpha = np.polynomial.polynomial.polyval(e, TSUJI_FIT)
        return finish(alpha * (np.sqrt(2.0) if tsuji_sqrt2 else 1.0), scalar)
    log_e = np.log(e)
    return finish(-np.sqrt(5.0) * log_e / np.sqrt(np.pi**2 + log_e**2), scalar)


def hertz_coefficient_for(
    alpha: Any, *, damping: str = "coeff_restitution", tsuji_sqrt2: bool = False
) -> float | np.ndarray:
    r"""The ``pair_coeff`` damping coefficient at which LAMMPS uses ``alpha``: the inverse
    of :func:`tsuji_alpha`.

    ``coeff_restitution``: :math:`\zeta = \alpha/\sqrt5 < 1`,
    :math:`e = \exp(-\pi\zeta/\sqrt{1-\zeta^2})`; ``tsuji``: the root of the fit on
    ``[0, 1]`` (bisection; the fit falls from 1.2728 at ``e = 0`` to 0.0003 at 1), which
    exists for ``0.0003 <= alpha <= 1.2728`` (times :math:`\sqrt2`).

    >>> round(hertz_coefficient_for(tsuji_alpha(0.3, damping="coeff_restitution")), 12)
    0.3
    >>> round(hertz_coefficient_for(0.34074063, damping="tsuji"), 6)
    0.5
    """
    _choice("damping", damping, DAMPING_STYLES)
    check_flag("tsuji_sqrt2", tsuji_sqrt2)
    a, scalar = real_array("alpha", alpha, lower=0.0)
    if damping == "coeff_restitution":
        zeta = a / np.sqrt(5.0)
        if np.any(zeta >= 1.0):
            raise ValueError(
                f"alpha = {float(a[zeta >= 1.0].flat[0])!r} is beyond damping "
                "coeff_restitution, which reaches alpha < sqrt(5) only (e -> 0); use damping "
                "velocity or a smaller damping"
            )
        return finish(np.exp(-np.pi * zeta / np.sqrt(1.0 - zeta * zeta)), scalar)
    scale = np.sqrt(2.0) if tsuji_sqrt2 else 1.0
    low, high = scale * np.polynomial.polynomial.polyval(np.array([1.0, 0.0]), TSUJI_FIT)
    if np.any((a < low) | (a > high)):
        bad = float(a[(a < low) | (a > high)].flat[0])
        raise ValueError(
            f"alpha = {bad!r} is out of reach of damping tsuji, whose fit spans "
            f"[{low:.6g}, {high:.6g}]; use damping coeff_restitution"
        )
    lo, hi = np.zeros(a.shape), np.ones(a.shape)
    for _ in range(60):  # the fit decreases on [0, 1]
        mid = 0.5 * (lo + hi)
        above = scale * np.polynomial.polynomial.polyval(mid, TSUJI_FIT) > a
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return finish(0.5 * (lo + hi), scalar)


def predict_hertz(
    *,
    stiffness: Any,
    alpha: Any,
    mass: Any,
    speed: Any,
    gravity: Any = 0.0,
    limit_damping: bool,
) -> NonlinearImpact:
    r"""The continuous LAMMPS Hertz–Tsuji impact: :func:`~impactsym.contact.impact` of the
    ``"tsuji"`` law (``exponent = 3/2``) with ``stiffness`` from :func:`hertz_stiffness`,
    ``alpha`` from :func:`tsuji_alpha`, the effective ``mass`` and the pressing force
    ``mass * gravity``; the position condition without ``limit_damping``, the
    ``"clipped"`` condition with it.

    Under ``limit_damping`` the fields are those of LAMMPS's reading
    (:class:`~impactsym.engines.reading.StateReading`, which the drivers use):
    ``restitution`` is the clipped one, the upward speed at zero overlap over ``speed``
    (the reading's ``departure_speed`` over ``speed``); ``sticks`` is the clipped verdict
    (the reading's: the force comes back while the overlap lasts); ``contact_time`` is
    the end of the contact **force**, its first return to zero, as the reading ends the
    contact (``inf`` where it sticks), not the clipped one's later zero overlap (the
    coast, :math:`z_1/e` longer without gravity). Without gravity every field is the
    force condition's, as before the clipped condition existed.

    >>> r = predict_hertz(stiffness=2.3e6, alpha=0.3407, mass=4.19, speed=1.0,
    ...                   limit_damping=False)
    >>> round(r.restitution, 4)
    0.6161

    Under gravity the sphere coasts out of the overlap slower than the force released it
    (at 0.3 m/s: 0.481 against 0.589), or is caught again and sticks (at 0.1 m/s with
    ``damping tsuji 0.7``):

    >>> kw = dict(stiffness=2316686.9, mass=4.18879, gravity=9.81, limit_damping=True)
    >>> round(predict_hertz(alpha=tsuji_alpha(0.5), speed=0.3, **kw).restitution, 4)
    0.4807
    >>> predict_hertz(alpha=tsuji_alpha(0.7), speed=0.1, **kw).sticks
    True
    """
    limit = check_flag("limit_damping", limit_damping)
    g, _ = real_array("gravity", gravity, lower=0.0)
    kwargs = {
        "stiffness": stiffness,
        "damping": alpha,
        "mass": mass,
        "speed": speed,
        "force": np.multiply(mass, g),
        "exponent": 1.5,
    }
    if not limit:
        return impact("tsuji", condition="position", **kwargs)
    clipped = impact("tsuji", condition="clipped", **kwargs)
    released = impact("tsuji", condition="force", **kwargs)
    t_c = np.where(clipped.sticks, np.inf, released.contact_time)
    return replace(clipped, contact_time=finish(t_c, isinstance(clipped.contact_time, float)))


def design_alpha(
    *,
    restitution: Any,
    stiffness: Any,
    mass: Any,
    speed: Any,
    gravity: Any = 0.0,
    limit_damping: bool,
) -> float | np.ndarray:
    r"""The ``alpha`` at which the LAMMPS Hertz–Tsuji contact restitutes ``restitution``
    (:func:`~impactsym.contact.damping_for` of the ``"tsuji"`` law, position condition
    without ``limit_damping``, clipped with it: the restitution is the speed at which the
    sphere leaves the overlap, :func:`predict_hertz`'s); :func:`hertz_coefficient_for`
    gives the ``pair_coeff`` value.

    >>> a = design_alpha(restitution=0.5, stiffness=1e6, mass=1.0, speed=1.0,
    ...                  limit_damping=False)
    >>> round(hertz_coefficient_for(a), 10)  # the DEM formula is exact here
    0.5
    """
    condition = "clipped" if check_flag("limit_damping", limit_damping) else "position"
    g, _ = real_array("gravity", gravity, lower=0.0)
    return damping_for(
        "tsuji",
        restitution=restitution,
        stiffness=stiffness,
        mass=mass,
        speed=speed,
        force=np.multiply(mass, g),
        exponent=1.5,
        condition=condition,
    )
