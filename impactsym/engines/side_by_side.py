"""The same request in four engines: what each delivers with its native recipe and with
impactsym's design, predicted and measured at the engine's default step.

For each wanted restitution ``e`` (with one contact time, mass and approach speed, with or
without gravity) and each engine of :data:`ENGINES`:

* ``"native"``: the parameters users paste (:mod:`impactsym.engines.recipes`);
* ``"native-restitution"`` (PyBullet only): PyBullet's own velocity ``restitution``
  (:func:`impactsym.engines.recipes.pybullet_restitution`: the body's ``e``, the plane's
  ``1``, rigid default contact), predicted by
  :func:`impactsym.engines.pybullet.predict_rigid`; it has no contact time to ask for;
* ``"impactsym"``: the engine model's inverse at the engine's step (phase mean equal to
  ``e``, contact time equal to the target): :func:`impactsym.engines.mujoco.solref_for`,
  :func:`impactsym.engines.lammps.hooke_for`,
  :func:`impactsym.engines.drake.point_contact_for`,
  :func:`impactsym.engines.pybullet.contact_for`.

:func:`cases` makes both parameter sets (a target out of an engine's reach at its step
keeps NaN parameters and the design's reason); :func:`predict_cases` evaluates the
engine models per touch phase (exact discrete maps, so the table is explained, not only
measured); :func:`measure_cases` runs the engines themselves through their drivers at
the same touch phases. Default steps (:data:`TIMESTEPS`): MuJoCo ``0.002`` s, Drake
``1e-3`` s (``lagged``), PyBullet ``1/240`` s; LAMMPS has no default step for SI units,
so the usual ``t_c / 50`` (:data:`LAMMPS_STEPS_PER_CONTACT`). LAMMPS drops its driver's
sphere (:data:`impactsym.engines.survey.DROP_MASS`) on a wall without gravity
(:func:`impactsym.engines.lammps.hooke_for` designs without gravity), with
``limit_damping``; the other engines drop a sphere of ``mass`` on a plane.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from impactsym.engines import drake, lammps, mujoco
from impactsym.engines import pybullet as pyb
from impactsym.engines import recipes as paste
from impactsym.engines.survey import DROP_MASS
from impactsym.validation import real_array

__all__ = [
    "ENGINES",
    "LAMMPS_STEPS_PER_CONTACT",
    "RECIPES",
    "TIMESTEPS",
    "Case",
    "cases",
    "measure_cases",
    "predict_cases",
]

ENGINES = ("MuJoCo", "LAMMPS", "Drake", "PyBullet")
RECIPES = ("native", "native-restitution", "impactsym")
#: Each engine's default step (s); LAMMPS: ``contact_time / LAMMPS_STEPS_PER_CONTACT``.
TIMESTEPS = {"MuJoCo": 0.002, "LAMMPS": None, "Drake": 1e-3, "PyBullet": 1 / 240}
LAMMPS_STEPS_PER_CONTACT = 50


@dataclass(frozen=True, eq=False)
class Case:
    """One engine and recipe over the wanted restitutions (arrays over ``targets``).

    ``parameters`` maps the engine's own names (``solref`` timeconst/dampratio, ``kn``/
    ``eta_n`` with the ``coeff_restitution`` value ``e``, ``stiffness``/``dissipation``,
    ``stiffness``/``damping``, ``restitution``/``plane_restitution``) to arrays; NaN
    where ``reasons`` holds why impactsym's design cannot reach that target at the step.
    ``mass`` is the contact's effective mass, ``timestep`` the engine's step, ``gravity``
    the pressing acceleration.
    """

    engine: str
    recipe: str
    targets: np.ndarray
    parameters: dict[str, np.ndarray]
    mass: float
    speed: float
    gravity: float
    timestep: float
    reasons: tuple[str | None, ...]

    @property
    def reachable(self) -> np.ndarray:
        """True where the parameters exist (always for the native recipes)."""
        return np.array([r is None for r in self.reasons])


def _design_each(design: Callable[[np.ndarray], dict], targets: np.ndarray, names) -> tuple:
    """``design`` over all targets at once; if one is out of reach, target by target (only
    then), keeping NaN parameters and the reason for those out of reach."""
    try:
        values = design(targets)
        return {n: np.broadcast_to(np.asarray(values[n], float), targets.shape) for n in names}, (
            (None,) * targets.size
        )
    except ValueError:
        pass
    out = {n: np.full(targets.shape, np.nan) for n in names}
    reasons: list[str | None] = []
    for i in range(targets.size):  # the error path only: which targets are out of reach
        try:
            values = design(targets[i : i + 1])
        except ValueError as exc:
            reasons.append(str(exc))
            continue
        for n in names:
            out[n][i] = float(np.ravel(values[n])[0])
        reasons.append(None)
    return out, tuple(reasons)


def cases(
    *,
    restitution: Any,
    contact_time: float,
    gravity: float,
    mass: float = 0.1,
    speed: float = 1.0,
    engines: tuple[str, ...] = ENGINES,
    recipes: tuple[str, ...] = RECIPES,
) -> list[Case]:
    """The native recipe(s) and impactsym's design of each engine for every target.

    ``restitution`` is a 1-D array of wanted ``e`` in ``(0, 1)``; ``contact_time`` (s),
    ``mass`` (kg), ``speed`` (m/s) and ``gravity`` (m/s^2) are single numbers. LAMMPS is
    left out under gravity (its Hooke design has none) and uses the driver's sphere mass.
    ``engines`` and ``recipes`` (of :data:`ENGINES`, :data:`RECIPES`) choose the cases.
    Predictions only: no engine runs. impactsym's designs cost seconds each (phase-exact
    inverses at the step); the native recipes are closed forms.
    """
    e = real_array("restitution", restitution, lower=0.0, strict=True)[0]
    if e.ndim != 1 or np.any(e >= 1.0):
        raise ValueError(f"restitution must be a 1-D array of values in (0, 1), got {e!r}")
    for name, value in (("contact_time", contact_time), ("mass", mass), ("speed", speed)):
        if not real_array(name, value, lower=0.0, strict=True)[1]:
            raise ValueError(f"{name} must be one number, got {value!r}")
    g, g_scalar = real_array("gravity", gravity, lower=0.0)
    if not g_scalar:
        raise ValueError(f"gravity must be one number, got {gravity!r}")
    for name, chosen, known in (("engines", engines, ENGINES), ("recipes", recipes, RECIPES)):
        if isinstance(chosen, str) or set(chosen) - set(known):
            raise ValueError(f"{name} must be a tuple of names among {known}, got {chosen!r}")
    t_c, m, v, g = float(contact_time), float(mass), float(speed), float(g)
    out: list[Case] = []
    ok = (None,) * e.size

    def add(engine, recipe, params, mass_, step, reasons=ok):
        if recipe not in recipes:
            return
        params = {k: np.broadcast_to(np.asarray(p, float), e.shape) for k, p in params.items()}
        out.append(Case(engine, recipe, e, params, mass_, v, g, step, reasons))

    if "MuJoCo" in engines:
        h = TIMESTEPS["MuJoCo"]
        tc, dr = paste.mujoco_textbook(restitution=e)
        add("MuJoCo", "native", {"timeconst": tc, "dampratio": dr}, m, h)

        def mj(x):
            d = mujoco.solref_for(restitution=x, speed=v, gravity=g, contact_time=t_c, timestep=h)
            return {"timeconst": d.solref[0], "dampratio": d.solref[1]}

        if "impactsym" in recipes:
            params, reasons = _design_each(mj, e, ("timeconst", "dampratio"))
            add("MuJoCo", "impactsym", params, m, h, reasons)
    if "LAMMPS" in engines and g == 0.0:
        h, M = t_c / LAMMPS_STEPS_PER_CONTACT, DROP_MASS
        kn, coeff, eta = paste.lammps_coeff_restitution(restitution=e, contact_time=t_c, mass=M)
        add("LAMMPS", "native", {"kn": kn, "eta_n": eta, "coeff_restitution": coeff}, M, h)

        def lm(x):
            d = lammps.hooke_for(restitution=x, contact_time=t_c, mass=M, speed=v, timestep=h)
            return {"kn": d.kn, "eta_n": d.damping}

        if "impactsym" in recipes:
            params, reasons = _design_each(lm, e, ("kn", "eta_n"))
            add("LAMMPS", "impactsym", params, M, h, reasons)
    if "Drake" in engines:
        h = TIMESTEPS["Drake"]
        k, d = paste.drake_hunt_crossley(restitution=e, contact_time=t_c, mass=m, speed=v)
        add("Drake", "native", {"stiffness": k, "dissipation": d}, m, h)

        def dr(x):
            c = drake.point_contact_for(
                restitution=x, speed=v, mass=m, gravity=g, contact_time=t_c, time_step=h
            )
            return {
                "stiffness": c.point_contact_stiffness,
                "dissipation": c.hunt_crossley_dissipation,
            }

        if "impactsym" in recipes:
            params, reasons = _design_each(dr, e, ("stiffness", "dissipation"))
            add("Drake", "impactsym", params, m, h, reasons)
    if "PyBullet" in engines:
        h = TIMESTEPS["PyBullet"]
        k, c = paste.pybullet_textbook(restitution=e, contact_time=t_c, mass=m)
        add("PyBullet", "native", {"stiffness": k, "damping": c}, m, h)
        body, plane = paste.pybullet_restitution(restitution=e)
        add("PyBullet", "native-restitution", {"restitution": body, "plane_restitution": plane},
            m, h)  # fmt: skip

        def pb(x):
            d = pyb.contact_for(
                restitution=x, speed=v, mass=m, gravity=g, contact_time=t_c, timestep=h
            )
            return {"stiffness": d.stiffness, "damping": d.damping}

        if "impactsym" in recipes:
            params, reasons = _design_each(pb, e, ("stiffness", "damping"))
            add("PyBullet", "impactsym", params, m, h, reasons)
    return out


def _rigid(case: Case, phase: Any) -> SimpleNamespace:
    """:func:`impactsym.engines.pybullet.predict_rigid` for each reachable target of
    ``case`` (the pair restitution, the product of the body's and the plane's, is one
    engine setting per call, so one call per target), stacked like :func:`_model`."""
    pair = (case.parameters["restitution"] * case.parameters["plane_restitution"])[case.reachable]
    rows = [
        pyb.predict_rigid(
            restitution=float(r),
            speed=case.speed,
            gravity=case.gravity,
            timestep=case.timestep,
            phase=None if phase is None else phase[i],
        )
        for i, r in enumerate(pair)
    ]
    low, high = (np.array([row.restitution_range[j] for row in rows], float) for j in (0, 1))
    return SimpleNamespace(
        **{k: np.array([getattr(row, k) for row in rows]) for k in ("restitution",
           "contact_time", "sticks")},
        restitution_range=(low, high),
    )  # fmt: skip


def _model(case: Case, phase: Any):
    """The engine model's prediction for the reachable targets of ``case`` at ``phase``
    (``None``: phase mean and range; else an array broadcasting against the targets)."""
    if case.recipe == "native-restitution":
        return _rigid(case, phase)
    column = (slice(None),) if phase is None else (slice(None), None)  # targets down
    p = {k: v[case.reachable][column] for k, v in case.parameters.items()}
    common = {"speed": case.speed, "gravity": case.gravity}
    if case.engine == "MuJoCo":
        return mujoco.predict(
            solref=(p["timeconst"], p["dampratio"]), timestep=case.timestep, phase=phase, **common
        )
    if case.engine == "LAMMPS":
        return lammps.predict(
            kn=p["kn"], damping=p["eta_n"], mass=case.mass, timestep=case.timestep, phase=phase,
            **common,
        )  # fmt: skip
    if case.engine == "Drake":
        return drake.predict(
            stiffness=p["stiffness"], dissipation=p["dissipation"], mass=case.mass,
            time_step=case.timestep, phase=phase, **common,
        )  # fmt: skip
    return pyb.predict(
        stiffness=p["stiffness"], damping=p["damping"], mass=case.mass, timestep=case.timestep,
        phase=phase, **common,
    )  # fmt: skip


def predict_cases(case_list: list[Case], *, phases: Any = None) -> list[dict[str, np.ndarray]]:
    """What each case delivers by the engine models (no engine run), arrays over targets.

    Keys: ``restitution``, ``contact_time`` (phase means, or per phase with ``phases``
    given: shape ``(targets, phases)``), ``min``, ``max`` (range over every phase;
    with ``phases``: over those phases) and ``sticks``; NaN where the case has no
    parameters. A ``RuntimeWarning`` of a model (an unstable step map, e.g. MuJoCo's
    textbook solref at high ``e``) is kept quiet here: the values are still the map's.
    """
    out = []
    for case in case_list:
        n = case.targets.size
        phase = None if phases is None else np.asarray(phases, float)[None, :]
        shape = (n,) if phase is None else (n, phase.shape[1])
        row = {k: np.full(shape, np.nan) for k in ("restitution", "contact_time")}
        row |= {"min": np.full(n, np.nan), "max": np.full(n, np.nan), "sticks": np.zeros(n, bool)}
        mask = case.reachable
        if mask.any():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                p = _model(
                    case, None if phase is None else np.broadcast_to(phase, (mask.sum(), shape[1]))
                )
            e = np.broadcast_to(np.asarray(p.restitution, float), (mask.sum(), *shape[1:]))
            row["restitution"][mask] = e
            row["contact_time"][mask] = np.broadcast_to(np.asarray(p.contact_time, float), e.shape)
            sticks = np.broadcast_to(np.asarray(p.sticks, bool), e.shape)
            if phase is None:
                row["min"][mask], row["max"][mask] = (
                    np.asarray(r, float) for r in p.restitution_range
                )
                row["sticks"][mask] = sticks
            else:
                row["min"][mask], row["max"][mask] = e.min(1), e.max(1)
                row["sticks"][mask] = sticks.any(1)
        out.append(row)
    return out


def measure_cases(case_list: list[Case], *, phases: Any) -> list[dict[str, np.ndarray]]:
    """Run each case in its engine at ``phases`` (touch phases in ``[0, 1)``).

    Drivers: :func:`impactsym.engines.drivers.mujoco_phases` (Euler),
    :func:`impactsym.engines.drivers.lammps_drop` (the native recipe with LAMMPS's own
    ``damping coeff_restitution``: the driver hands ``damping / mass`` to a style other
    than ``velocity``, so ``e * mass`` passes ``e``; the design with ``velocity``),
    :func:`impactsym.engines.drake.driver.drake_phases` (``lagged``),
    :func:`impactsym.engines.pybullet.driver.pybullet_steps` (defaults, plane at
    PyBullet's defaults; ``native-restitution``: the rigid sphere, ``stiffness=None``,
    with both bodies' ``restitution``). Returns per case ``restitution`` and
    ``contact_time`` of shape ``(targets, phases)`` and ``sticks`` (any phase), NaN where
    the case has no parameters. Needs the engines of the cases.
    """
    at = real_array("phases", phases, lower=0.0)[0].ravel()
    out = []
    for case in case_list:
        n = case.targets.size
        row = {k: np.full((n, at.size), np.nan) for k in ("restitution", "contact_time")}
        row["sticks"] = np.zeros(n, bool)
        for i in np.flatnonzero(case.reachable):  # one engine model per design: engine runs
            p = {k: float(v[i]) for k, v in case.parameters.items()}
            e, t, s = _run(case, p, at)
            row["restitution"][i], row["contact_time"][i], row["sticks"][i] = e, t, np.any(s)
        out.append(row)
    return out


def _run(case: Case, p: dict[str, float], at: np.ndarray):
    common = {"speed": case.speed, "gravity": case.gravity}
    if case.engine == "MuJoCo":
        from impactsym.engines.drivers import mujoco_phases

        r = mujoco_phases(
            solref=(p["timeconst"], p["dampratio"]), solimp=mujoco.DEFAULT_SOLIMP,
            timestep=case.timestep, phases=at, mass=case.mass, **common,
        )  # fmt: skip
        return r["restitution"], r["contact_time"], r["sticks"]
    if case.engine == "LAMMPS":
        from impactsym.engines.drivers import lammps_drop

        if case.recipe == "native":
            kw = {
                "damping": p["coeff_restitution"] * case.mass,
                "damping_style": "coeff_restitution",
            }
        else:
            kw = {"damping": p["eta_n"]}
        runs = [
            lammps_drop(kn=p["kn"], timestep=case.timestep, phase=float(q), **kw, **common)
            for q in at
        ]
        return (np.array([r[k] for r in runs]) for k in ("restitution", "contact_time", "sticks"))
    if case.engine == "Drake":
        from impactsym.engines.drake.driver import drake_phases

        r = drake_phases(
            stiffness=p["stiffness"], dissipation=p["dissipation"], mass=case.mass,
            time_step=case.timestep, phases=at, **common,
        )  # fmt: skip
        return r["restitution"], r["contact_time"], r["sticks"]
    from impactsym.engines.pybullet.driver import pybullet_steps

    if case.recipe == "native-restitution":
        r = pybullet_steps(
            stiffness=None, damping=None, mass=case.mass, timestep=case.timestep, phase=at,
            restitution=(p["restitution"], p["plane_restitution"]), **common,
        )  # fmt: skip
        return r.restitution, r.contact_time, r.sticks
    r = pybullet_steps(
        stiffness=p["stiffness"], damping=p["damping"], mass=case.mass,
        timestep=case.timestep, phase=at, **common,
    )  # fmt: skip
    return r.restitution, r.contact_time, r.sticks
