r"""The Hooke spring-dashpot of LAMMPS ``pair_style granular``: design and prediction.

LAMMPS's normal force for the ``hooke`` model with ``damping velocity`` is (LAMMPS
documentation, ``pair_style granular``)

.. math::

    F_n = k_n \delta - \eta_n \dot\delta\ (\text{towards separation}),

with overlap ``delta``, ``kn`` (N/m) and ``eta_n`` (N s/m) given directly
(``damping mass_velocity`` takes ``eta_n / m_eff``; ``damping coeff_restitution e``
sets ``eta_n = sqrt(4 m_eff kn / (1 + (pi / ln e)^2))``, the textbook relation). For two
particles (or a particle and a wall) this is paper section 2 with
``omega0 = sqrt(kn / m_eff)``, ``D = eta_n / (2 sqrt(kn m_eff))``:

* without ``limit_damping`` the force turns tensile near the end and contact lasts
  while the particles overlap: the **position condition**;
* with ``limit_damping`` an attractive force is set to zero: contact force ends at
  ``k_n delta - eta_n delta' = 0``, the **force condition** (the overlap then ends later
  at constant speed when nothing presses).

A pressing acceleration ``gravity`` (e.g. a particle dropped on a wall) is the load
``F = m_eff g``. Both are :func:`impactsym.contact.release.linear_release` (no force
offset); the results use the wing's vocabulary (``restitution``, ``contact_time``,
``max_penetration``, ``peak_force``, ``released_by_position``, as MuJoCo's
:class:`~impactsym.engines.mujoco.prediction.Prediction`;
`docs/physics.md#simulation-engines`). All quantities are SI: kilograms, N/m, N s/m,
seconds, metres, m/s, newtons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.contact.release import linear_release
from impactsym.numeric.roots import bracketed_illinois
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, finish, real_array, renamed

__all__ = [
    "HookeContact",
    "coeff_restitution_achieved",
    "coeff_restitution_for",
    "hooke_for",
    "predict",
    "textbook_damping_ratio",
]


def textbook_damping_ratio(restitution: Any) -> float | np.ndarray:
    r"""``D`` of the textbook relation ``e = exp(-pi D / sqrt(1 - D^2))`` (position condition).

    .. math:: D = -\ln e / \sqrt{\pi^2 + \ln^2 e}

    >>> round(textbook_damping_ratio(0.5), 6)
    0.215454
    """
    e, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e > 1):
        raise ValueError(f"restitution must be <= 1, got {float(e.max())!r}")
    log_e = np.log(e)
    return finish(-log_e / np.sqrt(np.pi**2 + log_e**2), scalar)


#: largest damping ratio searched for a force-condition restitution (e there ~ 1.5e-8;
#: the release loses its accuracy in double precision a little beyond)
_D_MAX = 4096.0


#: the smallest normal float: products and quotients below it have lost digits
_TINY = float(np.finfo(float).tiny)
#: hooke_for refuses a design whose prediction misses a target by more than this
#: (relative; as solref_for: the release is accurate to ~1e-6 at the largest damping)
_DESIGN_RTOL = 1e-5


def _release(D, load, limit_damping):
    """The normalized first release (``omega0``, ``v0`` units) of a Hooke contact."""
    return linear_release(D, load, np.zeros_like(D), force=limit_damping, position=True)


def _natural(k, eta, m):
    """``omega0 = sqrt(kn / m)``, ``sqrt(kn m)`` and ``D = eta_n / (2 sqrt(kn m))``.

    Scale-free: where ``kn / m`` or ``kn m`` leaves the normal float range (``kn = m =
    1e160``: ``kn m = inf``, ``D = 0``) the square roots are taken first, which cannot
    overflow or underflow for finite positive inputs; elsewhere the plain products
    (unchanged results).
    """
    with np.errstate(over="ignore", under="ignore"):
        omega = np.sqrt(k / m)
        redo = ~(np.isfinite(omega) & (omega >= _TINY))
        omega = np.where(redo, np.sqrt(k) / np.sqrt(m), omega)
        root = np.sqrt(k * m)
        redo = ~(np.isfinite(root) & (root >= _TINY))
        root = np.where(redo, np.sqrt(k) * np.sqrt(m), root)
        D = eta / (2.0 * root)
    return omega, root, D


def _check_flag(name: str, value: object) -> bool:
    """``value`` if it is a bool (``bool("no")`` is True: strings are refused), else raise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _unrepresentable(what: str, values: np.ndarray, inputs: dict[str, Any]) -> None:
    """Refuse a derived quantity beyond the float range, naming the inputs behind it."""
    bad = ~np.isfinite(values)
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        shown = ", ".join(
            f"{name} = {float(np.ravel(np.broadcast_to(v, values.shape))[i])!r}"
            for name, v in inputs.items()
        )
        raise ValueError(f"{what} is beyond the float range for {shown}")


@dataclass(frozen=True, eq=False)
class HookeContact(ArrayRecord):
    """A Hooke contact and its first release (SI units).

    Attributes
    ----------
    kn
        Normal stiffness, N/m (``pair_coeff ... hooke kn eta_n``).
    damping
        ``eta_n`` for ``damping velocity``, N s/m.
    mass
        Effective mass ``m_eff``, kg.
    limit_damping
        Whether the contact force is kept compressive.
    restitution, contact_time
        Normal separation speed over approach speed and seconds until the contact
        ends (``0.0``/``inf`` when the particle sticks under ``gravity``).
    max_penetration
        Largest overlap, metres.
    released_by_position
        True where the overlap ends while the force is still compressive (always
        without ``limit_damping``); False where the force vanishes first.
    peak_force
        Largest normal force ``kn delta + eta_n delta'``, newtons.
    """

    kn: float | np.ndarray
    damping: float | np.ndarray
    mass: float
    limit_damping: bool
    restitution: float | np.ndarray
    contact_time: float | np.ndarray
    max_penetration: float | np.ndarray
    released_by_position: bool | np.ndarray
    peak_force: float | np.ndarray

    @property
    def sticks(self) -> bool | np.ndarray:
        """True where the contact never ends (``contact_time`` is ``inf``)."""
        out = np.isinf(self.contact_time)
        return bool(out) if np.ndim(out) == 0 else out

    @property
    def max_overlap(self) -> float | np.ndarray:
        """Former name of :attr:`max_penetration`."""
        return self.max_penetration

    @property
    def damping_ratio(self) -> float | np.ndarray:
        """Lehr's ``D = eta_n / (2 sqrt(kn m_eff))``."""
        k, eta = np.asarray(self.kn, float), np.asarray(self.damping, float)
        out = _natural(k, eta, self.mass)[2]
        return finish(out, out.ndim == 0)

    @property
    def mass_velocity(self) -> float | np.ndarray:
        """The coefficient for ``damping mass_velocity``: ``eta_n / m_eff`` (1/s)."""
        return self.damping / self.mass

    def pair_coeff(self) -> str:
        """The LAMMPS ``pair_coeff`` line (scalar contact)."""
        limit = " limit_damping" if self.limit_damping else ""
        return (
            f"pair_coeff * * hooke {float(self.kn):.10g} {float(self.damping):.10g} "
            f"tangential linear_nohistory 0 0 damping velocity{limit}"
        )


def predict(
    *,
    kn: Any,
    damping: Any,
    mass: float,
    speed: Any,
    gravity: Any = 0.0,
    limit_damping: bool = True,
) -> HookeContact:
    r"""Restitution, contact time and overlap of a LAMMPS Hooke contact.

    Parameters
    ----------
    kn
        Stiffness, N/m (> 0).
    damping
        ``eta_n`` of ``damping velocity``, N s/m (>= 0).
    mass
        Effective mass ``m_eff = m1 m2 / (m1 + m2)`` (the mass for a wall), kg.
    speed
        Normal approach speed, m/s (> 0).
    gravity
        Pressing acceleration along the normal, m/s^2 (>= 0).
    limit_damping
        LAMMPS's ``limit_damping`` keyword (force condition) or not (position): a bool.

    Notes
    -----
    The contact is solved in its natural units (``omega0``, ``v0``); ``omega0`` and ``D``
    are formed without the product ``kn m`` where it would leave the float range, so
    the result depends only on the ratios (``kn = eta_n = m = 1e160`` is the same
    contact as ``1, 1, 1``). A quantity whose value itself is beyond the float range
    is refused with a ``ValueError`` naming the inputs.

    >>> c = predict(kn=1e5, damping=50.0, mass=4.18879 / 2, speed=1.0)
    >>> round(c.restitution, 4), round(c.contact_time, 6)  # LAMMPS: 0.8471
    (0.8471, 0.013898)
    """
    k, _ = real_array("kn", kn, lower=0.0, strict=True)
    eta, _ = real_array("damping", damping, lower=0.0)
    m, m_scalar = real_array("mass", mass, lower=0.0, strict=True)
    v, _ = real_array("speed", speed, lower=0.0, strict=True)
    g, _ = real_array("gravity", gravity, lower=0.0)
    limit = _check_flag("limit_damping", limit_damping)
    if not m_scalar:
        raise ValueError(f"mass must be one number (the effective mass), got {mass!r}")
    scalar = all(np.ndim(a) == 0 for a in (kn, damping, speed, gravity))
    shape = broadcast(kn=k, damping=eta, speed=v, gravity=g)
    k, eta, v, g = (np.broadcast_to(a, shape) for a in (k, eta, v, g))
    omega, root, D = _natural(k, eta, m)
    named = {"kn": k, "damping": eta, "mass": m, "speed": v, "gravity": g}
    _unrepresentable("the damping ratio eta_n / (2 sqrt(kn m))", D, named)
    with np.errstate(over="ignore", under="ignore", divide="ignore"):
        load = g / (omega * v)
        load = np.where(np.isfinite(load), load, g / omega / v)
    _unrepresentable("the normalized load gravity / (omega0 speed)", load, named)
    rel = _release(D, load, limit)
    with np.errstate(over="ignore", under="ignore"):
        t_c = rel.contact_time / omega
        x_max = rel.max_penetration * v / omega
        peak = rel.peak_force * m * omega * v
        peak = np.where(np.isfinite(peak), peak, rel.peak_force * root * v)
    _unrepresentable("the contact time", np.where(rel.sticks, 0.0, t_c), named)
    _unrepresentable("the largest overlap", x_max, named)
    _unrepresentable("the peak force", peak, named)
    out = [finish(a, scalar) for a in (rel.restitution, t_c, x_max)]
    by_position = bool(rel.released_by_position) if scalar else rel.released_by_position
    return HookeContact(
        finish(k, scalar),
        finish(eta, scalar),
        float(m),
        limit,
        *out,
        by_position,
        finish(peak, scalar),
    )


def _damping_ratio_for(e: np.ndarray, limit_damping: bool) -> np.ndarray:
    if not limit_damping:
        return np.asarray(textbook_damping_ratio(e))
    # force condition without load: e falls from 1 (D = 0) towards 0 as D grows
    zero = np.zeros_like(e)

    def residual(D, i):
        return e[i] - _release(D, zero[i], True).restitution

    every = np.arange(e.size)
    hi = np.full(e.shape, 1.0)
    short = residual(hi, every) < 0
    while short.any():
        hi = np.where(short, 4.0 * hi, hi)
        if hi.max() > _D_MAX:
            i = np.flatnonzero(short)[0]
            e_min = float(_release(np.array([_D_MAX]), np.zeros(1), True).restitution[0])
            raise ValueError(
                f"restitution = {float(e[i])!r} is too small: under limit_damping it needs "
                f"a damping ratio above {_D_MAX:g} (e = {e_min:.3g} there; "
                f"e ~ 1 / (4 D^2)), beyond what the release is resolved for"
            )
        short = residual(hi, every) < 0
    return bracketed_illinois(residual, np.full(e.shape, 1e-12), hi, rtol=1e-13)


def hooke_for(
    *,
    restitution: Any,
    mass: float,
    contact_time: Any = None,
    max_penetration: Any = None,
    speed: Any = None,
    limit_damping: bool = True,
    max_overlap: Any = None,
) -> HookeContact:
    r"""``kn`` and ``eta_n`` for a wanted restitution and contact time (or largest overlap).

    With ``limit_damping`` the damping ratio solves the force-condition restitution
    ``e_force(D) = e`` (paper section 2, ``f = 0``); without it the textbook
    ``D = -ln e / sqrt(pi^2 + ln^2 e)``. Then ``omega0 = tau_c(D) / t_c`` (or
    ``max_penetration(D) v / delta_max`` with the normalized contact time and largest
    penetration of the release), ``kn = m omega0^2`` and ``eta_n = 2 D m omega0``.
    No pressing load (particle-particle collisions).

    Parameters
    ----------
    restitution
        Wanted ``e`` in (0, 1).
    mass
        Effective mass, kg.
    contact_time
        Wanted duration of the contact force, seconds; or
    max_penetration
        Wanted largest overlap, metres (needs ``speed``).
    speed
        Approach speed, m/s (for ``max_penetration``, and for the returned prediction).
    limit_damping
        Whether the LAMMPS input uses ``limit_damping``.
    max_overlap
        Former name of ``max_penetration`` (give one of the two).

    >>> c = hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)
    >>> round(c.restitution, 12), round(c.contact_time, 15), round(c.damping_ratio, 6)
    (0.5, 0.001, 0.255276)
    """
    max_penetration = renamed("max_penetration", max_penetration, "max_overlap", max_overlap, None)
    e, _ = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e.max())!r}")
    limit = _check_flag("limit_damping", limit_damping)
    if (contact_time is None) == (max_penetration is None):
        raise ValueError("give exactly one of contact_time and max_penetration")
    if max_penetration is not None and speed is None:
        raise ValueError("max_penetration needs the approach speed (speed=...)")
    m_arr, m_scalar = real_array("mass", mass, lower=0.0, strict=True)
    if not m_scalar:
        raise ValueError(f"mass must be one number (the effective mass, kg), got {mass!r}")
    m = float(m_arr)
    v = 1.0 if speed is None else real_array("speed", speed, lower=0.0, strict=True)[0]
    scalar = all(np.ndim(a) == 0 for a in (restitution, contact_time, max_penetration, speed))
    target_name = "contact_time" if max_penetration is None else "max_penetration"
    target = real_array(
        target_name,
        contact_time if max_penetration is None else max_penetration,
        lower=0.0,
        strict=True,
    )[0]
    shape = broadcast(**{"restitution": e, target_name: target, "speed": v})
    e, target, v = (np.broadcast_to(a, shape) for a in (e, target, v))
    D = _damping_ratio_for(e.ravel(), limit).reshape(e.shape)
    rel = _release(D, np.zeros_like(D), limit)
    with np.errstate(over="ignore", under="ignore"):
        if max_penetration is None:
            omega = rel.contact_time / target
        else:
            omega = rel.max_penetration * v / target
        kn = m * omega**2
        eta = 2.0 * D * m * omega
    named = {"restitution": e, target_name: target, "mass": m}
    for what, value in (("the stiffness kn = m omega0^2", kn), ("the damping eta_n", eta)):
        # an underflow to a subnormal or zero has lost the design as surely as an overflow
        _unrepresentable(what, np.where(np.abs(value) < _TINY, np.inf, value), named)
    design = predict(
        kn=finish(kn, scalar),
        damping=finish(eta, scalar),
        mass=m,
        speed=finish(v, scalar),
        limit_damping=limit,
    )
    _check_design(design, e, target, target_name)
    return design


def _check_design(design: HookeContact, e, target, target_name) -> None:
    """Refuse a design whose own prediction misses its targets (relative ``1e-5``).

    Under ``limit_damping`` at damping ratios above a few hundred the release's contact
    time is resolved only to ``1e-5 .. 1e-3`` in double precision (a cancellation in
    the force ``2 D z' + z``): such designs are refused rather than returned off target.
    """
    got = getattr(design, target_name)
    e_got = np.broadcast_to(design.restitution, e.shape)
    t_got = np.broadcast_to(got, e.shape)
    miss = np.abs(e_got - e) > _DESIGN_RTOL * e
    miss |= ~(np.abs(t_got / target - 1.0) <= _DESIGN_RTOL)
    if miss.any():
        i = np.flatnonzero(miss.ravel())[0]
        D = float(np.ravel(np.broadcast_to(design.damping_ratio, e.shape))[i])
        raise ValueError(
            f"restitution = {float(e.ravel()[i])!r} with {target_name} = "
            f"{float(target.ravel()[i])!r} (element {i}) is not reached within "
            f"{_DESIGN_RTOL:g}: the designed kn, eta_n (damping ratio {D:.6g}) give "
            f"restitution {float(e_got.ravel()[i]):.10g} and {target_name} "
            f"{float(t_got.ravel()[i]):.10g} in predict"
            + (
                "; at this damping the force-condition contact time is not resolved in "
                "double precision: a larger restitution or limit_damping=False reaches it"
                if D > 100
                else ""
            )
        )


def coeff_restitution_achieved(restitution: Any) -> float | np.ndarray:
    r"""What LAMMPS's ``damping coeff_restitution e`` really gives under ``limit_damping``.

    LAMMPS sets the textbook damping ``D = -ln e / sqrt(pi^2 + ln^2 e)`` (position
    condition) but ``limit_damping`` ends contact by the force condition, so the
    achieved restitution is ``e_force(D)`` (paper section 2, ``f = 0``), always larger.

    >>> round(coeff_restitution_achieved(0.5), 4)
    0.5503
    """
    D = textbook_damping_ratio(restitution)
    arr = np.asarray(D, dtype=float)
    out = _release(arr, np.zeros_like(arr), True).restitution
    return finish(out, np.ndim(D) == 0)


def coeff_restitution_for(restitution: Any) -> float | np.ndarray:
    r"""The value to give ``damping coeff_restitution`` so that ``limit_damping`` yields ``e``.

    The force-condition damping ratio ``D`` for ``e`` is written in the textbook's
    terms, ``e_input = exp(-pi D / sqrt(1 - D^2))``. Needs ``D < 1`` (the textbook
    cannot express more damping), and the critically damped force condition rebounds
    with exactly ``e = exp(-2) = 0.1353...`` (``z = tau e^-tau``, the force
    ``(2 - tau) e^-tau`` vanishes at ``tau = 2``): every target ``e <= exp(-2)`` is out
    of reach of ``coeff_restitution`` under ``limit_damping`` (LAMMPS itself gives
    0.1374 for ``e_input = 1e-9``), and just above it ``e_input`` falls towards zero
    (``1.3e-16`` for 0.136); a target whose ``e_input`` underflows is refused too.
    Use ``damping velocity`` with :func:`hooke_for` for those.

    >>> round(coeff_restitution_for(0.5), 4), round(coeff_restitution_achieved(0.4363), 4)
    (0.4363, 0.5)
    """
    e, scalar = real_array("restitution", restitution, lower=0.0, strict=True)
    if np.any(e >= 1):
        raise ValueError(f"restitution must be < 1, got {float(e.max())!r}")
    D = _damping_ratio_for(e.ravel(), True).reshape(e.shape)
    with np.errstate(divide="ignore", invalid="ignore", under="ignore"):
        out = np.exp(-np.pi * D / np.sqrt(1.0 - D**2))
    bad = (D >= 1) | ~(out >= _TINY)
    if np.any(bad):
        raise ValueError(
            f"restitution = {float(e[bad].flat[0])!r} is out of reach: under limit_damping "
            f"'damping coeff_restitution' cannot express targets e <= exp(-2) = "
            f"{math.exp(-2):.6g} (the critically damped force condition; just above it "
            f"the input underflows to 0); use 'damping velocity' with eta_n from "
            f"hooke_for(...)"
        )
    return finish(out, scalar)
