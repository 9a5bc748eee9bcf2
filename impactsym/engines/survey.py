"""Surveys over the engines' predictions: textbook against exact restitution, MuJoCo's
stick map, the engines at their timestep and the timestep advisors.

The textbook damping ``D = -ln e / sqrt(pi^2 + ln^2 e)`` gives the wanted restitution
only for a linear spring-damper released when the force vanishes; the engines differ
(MuJoCo's impedance ``solimp``, LAMMPS's ``limit_damping``). These functions evaluate the
predictions of :mod:`impactsym.engines.mujoco` and :mod:`impactsym.engines.lammps` on
grids, so that figures (:mod:`impactsym.plotting.engines`) only draw; see
notebooks/04_engine_parameters.ipynb.
"""

from __future__ import annotations

import warnings

import numpy as np

from impactsym.engines import lammps, mujoco
from impactsym.validation import real_array

#: A flat MuJoCo impedance (``solimp``): 0.9 at every penetration, so the contact is a
#: linear spring-damper with the stiffness and damping of ``solref``.
FLAT = (0.9, 0.9, 0.001, 0.5, 2.0)


def textbook_restitution(targets: np.ndarray) -> dict[str, np.ndarray]:
    """Restitution the engines give when the textbook damping is used for ``targets``.

    Keys: ``"MuJoCo flat solimp"``, ``"MuJoCo default solimp"`` (timeconst 0.02,
    1 m/s, no gravity) and ``"LAMMPS coeff_restitution + limit_damping"``.

    >>> out = textbook_restitution(np.array([0.5]))
    >>> round(float(out["LAMMPS coeff_restitution + limit_damping"][0]), 4)
    0.5503
    """
    targets = real_array("targets", targets, lower=0.0, strict=True)[0]
    if np.any(targets > 1):
        raise ValueError(f"targets must be <= 1 (restitutions), got {float(targets.max())!r}")
    dampratio = np.asarray(lammps.textbook_damping_ratio(targets))
    out = {}
    for name, solimp in (("flat", FLAT), ("default", mujoco.DEFAULT_SOLIMP)):
        p = mujoco.predict(solref=(mujoco.DEFAULT_TIMECONST, dampratio), solimp=solimp, speed=1.0)
        out[f"MuJoCo {name} solimp"] = np.asarray(p.restitution)
    out["LAMMPS coeff_restitution + limit_damping"] = np.asarray(
        lammps.coeff_restitution_achieved(targets)
    )
    return out


def stick_map(speed: np.ndarray, dampratio: np.ndarray, gravity: float = 9.81, solimp=FLAT):
    """MuJoCo's verdict on a (speed, dampratio) grid: 0 sticks, 1 force, 2 penetration.

    Timeconst :data:`impactsym.engines.mujoco.DEFAULT_TIMECONST`; 1 means the contact
    ends when the force vanishes, 2 when the penetration does (contact lost while still
    pressed). Returns ``(verdict, restitution)`` arrays of shape
    ``(len(dampratio), len(speed))``.

    >>> v, e = stick_map(np.array([0.05, 1.0]), np.array([0.2, 1.0]))
    >>> v.tolist()
    [[2, 1], [0, 0]]
    """
    speed = real_array("speed", speed, lower=0.0, strict=True)[0]
    dampratio = real_array("dampratio", dampratio, lower=0.0, strict=True)[0]
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    for name, value in (("speed", speed), ("dampratio", dampratio)):
        if value.ndim != 1:
            raise ValueError(f"{name} must be a 1-D array (one grid axis), got shape {value.shape}")
    if not g_scalar:
        raise ValueError(f"gravity must be one number, got {gravity!r}")
    S, R = np.meshgrid(speed, dampratio)
    p = mujoco.predict(
        solref=(mujoco.DEFAULT_TIMECONST, R), solimp=solimp, speed=S, gravity=float(g)
    )
    verdict = np.where(p.sticks, 0, np.where(p.released_by_position, 2, 1))
    return verdict, np.asarray(p.restitution)


#: Mass (kg) of the sphere that :func:`impactsym.engines.drivers.lammps_drop` drops on a
#: wall (radius 0.1 m, density 1000 kg/m^3): the effective mass of that contact.
DROP_MASS = 4.0 / 3.0 * np.pi * 0.1**3 * 1000.0


def touch_phases(count: int) -> np.ndarray:
    """``count`` touch phases at the midpoints of equal parts of ``[0, 1)``.

    Their mean of a quantity is the midpoint rule for its mean over phases (uniform
    phase), which is what the models' ``phase=None`` results are.

    >>> touch_phases(4).tolist()
    [0.125, 0.375, 0.625, 0.875]
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"count must be a positive integer, got {count!r}")
    return (np.arange(count) + 0.5) / count


def mujoco_measured(
    *,
    solref,
    solimp,
    speed: float,
    gravity: float,
    timesteps,
    integrator: str = "euler",
    phases: int = 16,
) -> dict[str, np.ndarray]:
    """MuJoCo's restitution at each of ``timesteps``, over touch phases (engine output).

    Runs MuJoCo (:func:`impactsym.engines.drivers.mujoco_phases`, one model per timestep,
    ``phases`` touch phases of :func:`touch_phases`). Returns arrays over ``timesteps``:
    ``"timestep"``, ``"mean"``, ``"min"``, ``"max"`` of the measured restitution, and
    ``"sticks"`` (the body stuck at some phase). Needs MuJoCo.
    """
    from impactsym.engines.drivers import mujoco_phases

    steps = real_array("timesteps", timesteps, lower=0.0, strict=True)[0].ravel()
    at = touch_phases(phases)
    # one engine model per timestep: a loop over engine runs, not over a computed grid
    runs = [
        mujoco_phases(
            solref=solref,
            solimp=solimp,
            speed=speed,
            gravity=gravity,
            timestep=float(dt),
            integrator=integrator,
            phases=at,
        )
        for dt in steps
    ]
    e = np.array([run["restitution"] for run in runs])
    sticks = np.array([run["sticks"].any() for run in runs], dtype=bool)
    return {
        "timestep": steps,
        "mean": e.mean(1),
        "min": e.min(1),
        "max": e.max(1),
        "sticks": sticks,
    }


def mujoco_at_timesteps(
    *,
    solref,
    solimp=mujoco.DEFAULT_SOLIMP,
    speed: float,
    gravity: float = 0.0,
    timesteps,
    integrator: str = "euler",
) -> dict[str, np.ndarray]:
    """MuJoCo's predicted restitution over touch phases at each of ``timesteps``.

    One design (``solref`` a pair of numbers) at every timestep of the 1-D array
    ``timesteps`` (s), by :func:`impactsym.engines.mujoco.predict` with ``phase=None``.
    ``predict`` takes one timestep; time scaling puts every timestep ``h`` into one call at
    the common timestep ``H`` (the median), exactly: with ``sigma = h / H`` the contact
    keeps its positions and runs ``1 / sigma`` times faster with ``solref`` ``(timeconst /
    sigma, dampratio)`` (or ``(-sigma^2 k, -sigma b)``), speed ``sigma v`` and gravity
    ``sigma^2 g``; velocities scale by ``sigma``, so the restitution is unchanged, the
    contact time is ``sigma`` times the scaled one, and MuJoCo's refsafe (``timeconst >=
    2 h``) holds at ``h`` iff it holds at ``H``. Returns arrays over ``timesteps``:
    ``"timestep"``, the restitution's phase ``"mean"``, ``"min"``, ``"max"``, the mean
    contact time ``"tc_mean"`` (s) and ``"sticks"`` (at some phase). Predictions, no
    engine run; a ``RuntimeWarning`` where the in-contact step map is unstable.

    >>> out = mujoco_at_timesteps(solref=(0.02, 1.0), speed=1.0, timesteps=[1e-3, 2e-3])
    >>> bool(np.all(out["min"] <= out["mean"])), bool(np.all(out["mean"] <= out["max"]))
    (True, True)
    """
    steps = real_array("timesteps", timesteps, lower=0.0, strict=True)[0]
    if steps.ndim != 1:
        raise ValueError(f"timesteps must be a 1-D array, got shape {steps.shape}")
    ref = real_array("solref", solref)[0]
    if ref.shape != (2,):
        raise ValueError(f"solref must be one pair of numbers, got {solref!r}")
    common = float(np.median(steps))
    sigma = steps / common
    a, b = float(ref[0]), float(ref[1])
    scaled = (a / sigma, b + 0.0 * sigma) if a > 0 else (a * sigma**2, b * sigma)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        p = mujoco.predict(
            solref=scaled,
            solimp=solimp,
            speed=sigma * speed,
            gravity=sigma**2 * gravity,
            timestep=common,
            integrator=integrator,
        )
    if any(issubclass(w.category, RuntimeWarning) for w in caught):
        # predict names the scaled timestep: say it in the caller's timesteps instead
        warnings.warn(
            f"MuJoCo's in-contact step map is unstable for solref {solref!r} at some of "
            f"the timesteps {steps.min():g} ... {steps.max():g} s: the restitution there "
            "is that of a diverging map",
            RuntimeWarning,
            stacklevel=2,
        )
    low, high = p.restitution_range
    return {
        "timestep": steps,
        "mean": np.asarray(p.restitution),
        "min": np.asarray(low),
        "max": np.asarray(high),
        "tc_mean": sigma * np.asarray(p.contact_time),
        "sticks": np.asarray(p.sticks, dtype=bool),
    }


#: ``omega0 dt`` of the one-parameter rule of thumb the advisor replaces.
RULE_OF_THUMB = 0.03


def mujoco_advice(
    targets,
    *,
    speed: float,
    gravity: float = 0.0,
    solimp=mujoco.DEFAULT_SOLIMP,
    tolerance: float = 0.01,
    integrator: str = "euler",
) -> dict[str, np.ndarray]:
    """The timestep advisor for MuJoCo's continuous design of each target restitution.

    Designs ``solref_for(restitution=targets, ...)`` (no timestep) and asks
    :func:`impactsym.engines.mujoco.timestep_for` for the largest timestep keeping the
    restitution within ``tolerance`` of the continuous value at every touch phase.
    Returns ``"targets"``, ``"timeconst"``, ``"dampratio"``, the advisor's ``"timestep"``
    (s) and worst ``"error"`` there, and ``"rule_of_thumb"``: the timestep of
    ``omega0 dt =`` :data:`RULE_OF_THUMB` with ``omega0 = 1 / (timeconst dampratio)``
    (the natural frequency at the impedance ``d_max``), the one-parameter rule the
    advisor replaces. Predictions, no engine run; each advice costs many phase-exact
    predictions (seconds per call, vectorized over the targets).
    """
    e = real_array("targets", targets, lower=0.0, strict=True)[0].ravel()
    design = mujoco.solref_for(restitution=e, speed=speed, gravity=gravity, solimp=solimp)
    tc, dr = (np.broadcast_to(np.asarray(v, dtype=float), e.shape) for v in design.solref)
    advice = mujoco.timestep_for(
        solref=design.solref,
        solimp=solimp,
        speed=speed,
        gravity=gravity,
        tolerance=tolerance,
        integrator=integrator,
    )
    return {
        "targets": e,
        "timeconst": tc,
        "dampratio": dr,
        "timestep": np.asarray(advice.timestep, dtype=float),
        "error": np.asarray(advice.error, dtype=float),
        "rule_of_thumb": RULE_OF_THUMB * tc * dr,
    }


def lammps_at_timestep(
    targets,
    *,
    steps_per_contact: float = 50.0,
    contact_time: float = 0.01,
    mass: float = DROP_MASS,
    speed: float = 1.0,
    limit_damping: bool = True,
) -> dict[str, np.ndarray]:
    """What LAMMPS's velocity-Verlet gives at ``timestep = contact_time /
    steps_per_contact`` for the continuous and the discrete design of each target e.

    Designs: :func:`impactsym.engines.lammps.hooke_for` for ``targets`` and
    ``contact_time`` without a timestep (``"continuous"``) and with it
    (``"discrete"``); each predicted at the timestep
    (:func:`impactsym.engines.lammps.predict`, phase mean and range). Returns the
    ``"targets"``, the ``"timestep"`` and, per design ``name``, ``name_kn``,
    ``name_damping``, ``name_mean``, ``name_min``, ``name_max`` (restitution) and
    ``name_tc_mean`` (contact time, s). Predictions, no engine run.

    >>> out = lammps_at_timestep(np.array([0.5]))
    >>> round(float(out["discrete_mean"][0]), 9)
    0.5
    """
    e = real_array("targets", targets, lower=0.0, strict=True)[0].ravel()
    n, _ = real_array("steps_per_contact", steps_per_contact, lower=0.0, strict=True)
    dt = float(contact_time) / float(n)
    out = {"targets": e, "timestep": np.full(e.shape, dt)}
    for name, design_step in (("continuous", None), ("discrete", dt)):
        design = lammps.hooke_for(
            restitution=e,
            contact_time=contact_time,
            mass=mass,
            speed=speed,
            limit_damping=limit_damping,
            timestep=design_step,
        )
        p = lammps.predict(
            kn=design.kn,
            damping=design.damping,
            mass=mass,
            speed=speed,
            limit_damping=limit_damping,
            timestep=dt,
        )
        low, high = p.restitution_range
        out |= {
            f"{name}_kn": np.asarray(design.kn),
            f"{name}_damping": np.asarray(design.damping),
            f"{name}_mean": np.asarray(p.restitution),
            f"{name}_min": np.asarray(low),
            f"{name}_max": np.asarray(high),
            f"{name}_tc_mean": np.asarray(p.contact_time),
        }
    return out


def lammps_measured(
    *, kn, damping, speed: float, timestep: float, limit_damping: bool = True, phases: int = 4
) -> dict[str, np.ndarray]:
    """LAMMPS's restitution for each design (``kn``, ``damping`` arrays) over touch phases.

    Runs LAMMPS (:func:`impactsym.engines.drivers.lammps_drop`: a sphere of
    :data:`DROP_MASS` on a wall, no gravity) at ``phases`` phases of
    :func:`touch_phases`. Returns ``"restitution"`` and ``"contact_time"`` of shape
    ``(designs, phases)``, the ``"phase"`` array and the restitution's ``"mean"``,
    ``"min"``, ``"max"`` over the phases, per design. Needs LAMMPS.
    """
    from impactsym.engines.drivers import lammps_drop

    kn = np.atleast_1d(np.asarray(kn, dtype=float))
    damping = np.broadcast_to(np.asarray(damping, dtype=float), kn.shape)
    at = touch_phases(phases)
    # each run is one LAMMPS instance: a loop over engine runs
    runs = [
        [
            lammps_drop(
                kn=float(k),
                damping=float(eta),
                speed=speed,
                timestep=timestep,
                phase=float(p),
                limit_damping=limit_damping,
            )
            for p in at
        ]
        for k, eta in zip(kn, damping, strict=True)
    ]
    e = np.array([[r["restitution"] for r in row] for row in runs])
    return {
        "phase": at,
        "restitution": e,
        "contact_time": np.array([[r["contact_time"] for r in row] for row in runs]),
        "mean": e.mean(1),
        "min": e.min(1),
        "max": e.max(1),
    }


def lammps_advice(
    targets,
    *,
    contact_time: float = 0.01,
    mass: float = DROP_MASS,
    speed: float = 1.0,
    limit_damping: bool = True,
    tolerance: float = 0.01,
) -> np.ndarray:
    """Steps per contact time ``t_c / timestep`` that LAMMPS needs to keep the restitution
    of the continuous design of each target within ``tolerance`` at every touch phase
    (:func:`impactsym.engines.lammps.timestep_for`). Prediction, no engine run.

    >>> round(float(lammps_advice(np.array([0.5]))[0]))
    90
    """
    e = real_array("targets", targets, lower=0.0, strict=True)[0].ravel()
    design = lammps.hooke_for(
        restitution=e,
        contact_time=contact_time,
        mass=mass,
        speed=speed,
        limit_damping=limit_damping,
    )
    step = lammps.timestep_for(
        kn=design.kn,
        damping=design.damping,
        mass=mass,
        speed=speed,
        limit_damping=limit_damping,
        tolerance=tolerance,
    )
    return contact_time / np.asarray(step)
