r"""The Hooke contact of LAMMPS ``pair_style granular``: the record and the prediction.

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
  ``k_n delta - eta_n delta' = 0``, the **force condition**; the body then coasts
  through the rest of the overlap (:func:`coast`): at constant speed when nothing
  presses, under gravity slowed, or caught again by the force (it sticks).

A pressing acceleration ``gravity`` (e.g. a particle dropped on a wall) is the load
``F = m_eff g``. With a ``timestep``, :func:`predict` is LAMMPS's velocity-Verlet
(:mod:`~impactsym.engines.lammps.verlet`, over phases
:mod:`~impactsym.engines.lammps.phases`); without, the continuous contact, whose two
conditions are :func:`impactsym.contact.release.linear_release` (no force offset). The
results use the wing's vocabulary (``restitution``, ``contact_time``,
``max_penetration``, ``peak_force``, ``released_by_position``, as MuJoCo's
:class:`~impactsym.engines.mujoco.prediction.Prediction`;
`docs/physics.md#simulation-engines`). All quantities are SI: kilograms, N/m, N s/m,
seconds, metres, m/s, newtons.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from impactsym.engines.lammps.common import check_flag, natural, release, unrepresentable
from impactsym.engines.lammps.phases import phase_statistics
from impactsym.engines.lammps.verlet import verlet_phase
from impactsym.records import ArrayRecord
from impactsym.validation import broadcast, finish, real_array

__all__ = ["HookeContact", "coast", "predict"]


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
    departure_speed
        Speed (m/s) with which the body finally leaves the overlap: ``restitution *
        speed`` where the contact ends by overlap; after a force end (``limit_damping``)
        the body coasts through the remaining overlap, under ``gravity`` slowed to
        ``v0 sqrt(e (e - 4 D load))`` (``0`` where it sticks).
    timestep
        ``None`` for the continuous contact (the limit ``timestep -> 0``), else the
        timestep of the velocity-Verlet model, seconds.
    phase
        The touch phase of a discrete result, ``None`` for the mean over phases.
    restitution_range, contact_time_range
        ``(min, max)`` over all touch phases with a timestep, ``None`` without.
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
    departure_speed: float | np.ndarray | None = None
    timestep: float | None = None
    phase: float | np.ndarray | None = None
    restitution_range: tuple | None = None
    contact_time_range: tuple | None = None

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
        out = natural(k, eta, self.mass)[2]
        return finish(out, out.ndim == 0)

    def __repr__(self) -> str:
        model = (
            "continuous (timestep -> 0)"
            if self.timestep is None
            else f"velocity-Verlet, timestep {self.timestep!r} s, "
            + ("mean over touch phases" if self.phase is None else f"phase {self.phase!r}")
        )
        return (
            f"HookeContact({model}: restitution={self.restitution!r}, "
            f"contact_time={self.contact_time!r}, kn={self.kn!r}, damping={self.damping!r}, "
            f"mass={self.mass!r}, limit_damping={self.limit_damping!r})"
        )

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
    timestep: float | None = None,
    phase: Any = None,
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
    timestep
        ``None`` (default): the continuous contact, the limit ``timestep -> 0``. A number
        (seconds): LAMMPS's velocity-Verlet as it runs at that timestep
        (:mod:`~impactsym.engines.lammps.verlet`; `docs/physics.md#lammps-at-its-timestep`).
    phase
        With a timestep: the touch phase in ``[0, 1)`` (geometric touch ``phase *
        timestep`` before the first state with overlap; broadcasts), the results exact
        for it; ``None``: ``restitution`` and ``contact_time`` are the means over phases
        and ``max_penetration``, ``peak_force``, ``released_by_position``,
        ``departure_speed`` those at phase 1/2. ``restitution_range`` and
        ``contact_time_range`` are always ``(min, max)`` over all phases
        (:mod:`~impactsym.engines.lammps.phases`).

    Notes
    -----
    Under ``limit_damping`` a force zero is not the end of the overlap: the body coasts
    through the rest of it in free flight. Without gravity it leaves with the force-zero
    speed ``e v0``; with gravity the force comes back before the overlap is gone when
    ``e < 4 D load`` (``load = g / (omega0 v0)``): the body sticks (``contact_time =
    inf``, ``restitution = 0``) and settles at ``m g / kn``; otherwise it leaves with
    ``departure_speed = v0 sqrt(e (e - 4 D load))``. ``restitution`` and ``contact_time``
    stay those of the force zero, the end of the contact force.

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
    limit = check_flag("limit_damping", limit_damping)
    if not m_scalar:
        raise ValueError(f"mass must be one number (the effective mass), got {mass!r}")
    scalar = all(np.ndim(a) == 0 for a in (kn, damping, speed, gravity))
    shape = broadcast(kn=k, damping=eta, speed=v, gravity=g)
    k, eta, v, g = (np.broadcast_to(a, shape) for a in (k, eta, v, g))
    omega, root, D = natural(k, eta, m)
    named = {"kn": k, "damping": eta, "mass": m, "speed": v, "gravity": g}
    unrepresentable("the damping ratio eta_n / (2 sqrt(kn m))", D, named)
    with np.errstate(over="ignore", under="ignore", divide="ignore"):
        load = g / (omega * v)
        load = np.where(np.isfinite(load), load, g / omega / v)
    unrepresentable("the normalized load gravity / (omega0 speed)", load, named)
    if timestep is not None:
        return _discrete(k, eta, m, v, g, limit, timestep, phase, scalar, shape)
    if phase is not None:
        raise ValueError("phase needs a timestep (the continuous contact has no touch phase)")
    rel = release(D, load, limit)
    e_rel = np.asarray(rel.restitution, dtype=float)
    departure, band = coast(D, load, e_rel, np.asarray(rel.released_by_position), limit)
    sticks_now = np.asarray(rel.sticks) | band
    restitution_now = np.where(band, 0.0, e_rel)
    with np.errstate(over="ignore", under="ignore"):
        t_c = rel.contact_time / omega
        x_max = rel.max_penetration * v / omega
        peak = rel.peak_force * m * omega * v
        peak = np.where(np.isfinite(peak), peak, rel.peak_force * root * v)
    t_c = np.where(band, np.inf, t_c)
    unrepresentable("the contact time", np.where(sticks_now, 0.0, t_c), named)
    unrepresentable("the largest overlap", x_max, named)
    unrepresentable("the peak force", peak, named)
    out = [finish(a, scalar) for a in (restitution_now, t_c, x_max)]
    by_position = bool(rel.released_by_position) if scalar else rel.released_by_position
    return HookeContact(
        finish(k, scalar),
        finish(eta, scalar),
        float(m),
        limit,
        *out,
        by_position,
        finish(peak, scalar),
        finish(departure * v, scalar),
    )


def coast(D, load, e, by_position, limit_damping: bool):
    """The coast through the overlap left at a force zero (normalized; continuous).

    At the force zero ``z = 2 D e``, ``z' = -e``; in free flight under the load
    ``z(s) = 2 D e - e s + load s^2 / 2`` and the force ``z + 2 D z' = s (load s / 2 - e +
    2 D load)`` comes back at ``s = 2 (e - 2 D load) / load`` while ``z > 0`` iff
    ``e < 4 D load`` (then the minimum of ``z`` stays positive); otherwise the body
    leaves at ``z = 0`` with ``z'^2 = e^2 - 2 load 2 D e``.

    Returns ``(departure_speed, sticks_in_band)``, normalized by ``v0``.
    """
    e = np.asarray(e, dtype=float)
    force_end = limit_damping & ~np.asarray(by_position, bool) & (e > 0)
    band = force_end & (e < 4.0 * D * load)
    with np.errstate(invalid="ignore"):
        leave = np.sqrt(np.maximum(e * (e - 4.0 * D * load), 0.0))
    departure = np.where(force_end, leave, e)
    return np.where(band, 0.0, departure), band


def _discrete(k, eta, m, v, g, limit, timestep, phase, scalar, shape) -> HookeContact:
    """:func:`predict` with a timestep: velocity-Verlet per phase, or its phase statistics."""
    h, h_scalar = real_array("timestep", timestep, lower=0.0, strict=True)
    if not h_scalar:
        raise ValueError(f"timestep must be one number (seconds), got {timestep!r}")
    h = float(h)
    if phase is not None:
        p, p_scalar = real_array("phase", phase, lower=0.0)
        if np.any(p >= 1):
            raise ValueError(f"phase must be in [0, 1), got {float(p.max())!r}")
        shape = np.broadcast_shapes(shape, p.shape)
        scalar = scalar and p_scalar
    omega, _, D = natural(k, eta, m)
    with np.errstate(over="ignore", under="ignore", divide="ignore"):
        load = g / (omega * v)
    named = {"kn": k, "damping": eta, "mass": m, "speed": v, "gravity": g}
    unrepresentable("the normalized load gravity / (omega0 speed)", load, named)
    arrays = [np.broadcast_to(a, shape).ravel() for a in (D, load, omega * h, omega, v)]
    Dn, Ln, tau, om, vv = arrays
    stats = phase_statistics(Dn, Ln, tau, limit)
    at = 0.5 if phase is None else np.broadcast_to(p, shape).ravel()
    r = verlet_phase(Dn, Ln, tau, at, limit)
    if phase is None:
        e, t = stats["restitution"], stats["contact_time"] / om
    else:
        e, t = r["restitution"], r["contact_time"] / om

    def out(a):
        return finish(np.asarray(a, dtype=float).reshape(shape), scalar)

    by_position = r["released_by_position"].reshape(shape)
    return HookeContact(
        finish(np.broadcast_to(k, shape), scalar),
        finish(np.broadcast_to(eta, shape), scalar),
        float(m),
        limit,
        out(e),
        out(t),
        out(r["max_penetration"] * vv / om),
        bool(by_position) if scalar else by_position,
        out(r["peak_force"] * m * om * vv),
        out(r["departure_speed"] * vv),
        h,
        None if phase is None else finish(np.broadcast_to(p, shape), scalar),
        (out(stats["restitution_min"]), out(stats["restitution_max"])),
        (out(stats["contact_time_min"] / om), out(stats["contact_time_max"] / om)),
    )
