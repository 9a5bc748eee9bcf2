r"""One physical request, answered for every engine: :func:`conformance_table`.

"A ball of mass ``m`` hits at ``v``; I want restitution ``e`` and contact time ``t_c``"
means different parameters, and different errors, in MuJoCo, LAMMPS, Drake and PyBullet.
:func:`conformance_table` asks each bridge's own design function for the request at the
engine's default step and integrator, and collects, per engine, the parameters to paste
and what the engine then delivers (the phase mean over touch phases, with the range).
Nothing is derived here: every number comes from

* MuJoCo: :func:`impactsym.engines.mujoco.solref_for` at ``timestep = 0.002`` s, Euler
  (``mjOption`` defaults), the phase mean
  (:mod:`~impactsym.engines.mujoco.discrete_design`). ``solref``/``solimp`` do not
  depend on the mass: MuJoCo scales the contact's stiffness and damping with the
  constraint's effective mass itself (the body's ``mass`` cancels out of ``e`` and
  ``t_c``); the mass is passed along only for the prediction's forces.
* LAMMPS: :func:`impactsym.engines.lammps.hooke_for` (``pair_style granular``, Hooke
  ``kn`` and ``eta_n``, ``damping velocity limit_damping``), the force law scaled by the
  effective mass. LAMMPS has no default step for this (``units si`` starts at
  ``1e-8`` s, chosen for nothing granular), so the table takes the step
  :func:`impactsym.engines.lammps.timestep_for` advises for the continuous design (the
  largest at which velocity-Verlet keeps the restitution within 1 % at every touch
  phase: the step a careful user would run), rounded down to two significant digits,
  and designs the phase mean of velocity-Verlet at that step exactly
  (``hooke_for(timestep=...)``); the step is printed with the design. ``hooke_for``
  designs collisions without a load; with ``gravity > 0`` the row predicts that design
  under the load (its restitution then differs from the target, as in the ``lammps``
  command).
* Drake: :func:`impactsym.engines.drake.point_contact_for` at
  ``MultibodyPlantConfig``'s default ``time_step = 1e-3`` s with the default
  ``discrete_contact_approximation = "lagged"``, ``contact_model = "point"``
  (``f_n = k x (1 + d x')_+``: the mass sets ``k``).
* PyBullet: :func:`impactsym.engines.pybullet.contact_for` at the default
  ``fixedTimeStep = 1/240`` s with PyBullet's defaults (speculative contacts, one
  sub-step) against a static plane left at its defaults (``contactDamping`` 0.1, which
  the pair rule adds: the body's value is the rest); the mass sets ``k`` and ``c``.

One engine failing does not stop the table: where a bridge refuses the request at its
step (a ``ValueError``: e.g. a contact shorter than two Drake steps, MuJoCo's refsafe
floor ``timeconst >= 2 timestep``, a contact of one PyBullet step), that row carries the
bridge's reason instead of numbers (most reasons name a step that would reach the target).
Bad input (not a bridge's verdict) raises at once. SI units throughout.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

from impactsym.engines import drake, lammps, mujoco, pybullet
from impactsym.records import ArrayRecord
from impactsym.validation import real_array

__all__ = [
    "DRAKE_TIME_STEP",
    "ENGINES",
    "MUJOCO_TIMESTEP",
    "PYBULLET_TIMESTEP",
    "ConformanceTable",
    "EngineRow",
    "conformance_table",
    "lammps_timestep",
]

#: the engines of the table, in its order
ENGINES = ("MuJoCo", "LAMMPS", "Drake", "PyBullet")
#: MuJoCo's default ``mjOption.timestep`` (s), with its default Euler integrator
MUJOCO_TIMESTEP = 0.002
#: Drake's default ``MultibodyPlantConfig.time_step`` (s), with ``"lagged"``
DRAKE_TIME_STEP = 1e-3
#: PyBullet's default ``fixedTimeStep`` (s)
PYBULLET_TIMESTEP = 1.0 / 240.0


@dataclass(frozen=True, eq=False)
class EngineRow(ArrayRecord):
    """One engine's answer to the request (SI units).

    Attributes
    ----------
    engine
        ``"MuJoCo"``, ``"LAMMPS"``, ``"Drake"`` or ``"PyBullet"``.
    step, model
        The step the answer is designed at (s; ``nan`` where LAMMPS's step could not be
        chosen) and the integrator or contact approximation there (e.g. ``"Euler"``,
        ``"velocity-Verlet"``, ``"lagged"``).
    step_note
        Where the step comes from (the engine's default, or why this one).
    parameters
        The designed numbers by name (empty where refused), e.g. ``timeconst``,
        ``dampratio``; ``kn``, ``eta_n``; ``point_contact_stiffness``,
        ``hunt_crossley_dissipation``; ``contactStiffness``, ``contactDamping``.
    paste
        The text to paste into the engine's input, one item a line (empty where
        refused).
    restitution, contact_time
        The predicted phase means at ``step`` (``None`` where refused).
    restitution_range, contact_time_range
        ``(low, high)`` over touch phases (``None`` where refused).
    error
        The bridge's reason where it refuses the request, else ``None``.
    notes
        The warnings the bridge gave on the way (their texts).
    design
        The bridge's own design record (``None`` where refused).
    """

    engine: str
    step: float
    model: str
    step_note: str
    parameters: dict = field(default_factory=dict)
    paste: str = ""
    restitution: float | None = None
    contact_time: float | None = None
    restitution_range: tuple[float, float] | None = None
    contact_time_range: tuple[float, float] | None = None
    error: str | None = None
    notes: tuple[str, ...] = ()
    design: Any = None

    @property
    def reachable(self) -> bool:
        """Whether the engine delivers the request at ``step``."""
        return self.error is None

    def text(self) -> str:
        """The row as a readable block: header, parameters to paste, prediction."""
        step = "no step" if math.isnan(self.step) else f"step {self.step:.6g} s"
        head = f"{self.engine}: {step}, {self.model} ({self.step_note})"
        notes = "".join(f"\n  note: {n}" for n in self.notes)
        if self.error is not None:
            return f"{head}\n  unreachable: {self.error}{notes}"
        paste = "\n".join("    " + line for line in self.paste.splitlines())
        e_lo, e_hi = self.restitution_range
        t_lo, t_hi = self.contact_time_range
        return (
            f"{head}\n  paste:\n{paste}\n"
            f"  predicted restitution:  {self.restitution:.6g} (phase mean; "
            f"{e_lo:.6g} .. {e_hi:.6g} over touch phases)\n"
            f"  predicted contact time: {self.contact_time:.6g} s (phase mean; "
            f"{t_lo:.6g} .. {t_hi:.6g} s over touch phases){notes}"
        )


@dataclass(frozen=True, eq=False)
class ConformanceTable(ArrayRecord):
    """The request and one :class:`EngineRow` per engine (in the order of :data:`ENGINES`).

    Attributes
    ----------
    restitution, contact_time, mass, speed, gravity
        The request (SI units).
    rows
        The engines' answers.
    """

    restitution: float
    contact_time: float
    mass: float
    speed: float
    gravity: float
    rows: tuple[EngineRow, ...]

    def row(self, engine: str) -> EngineRow:
        """The row of ``engine`` (one of :data:`ENGINES`)."""
        for r in self.rows:
            if r.engine == engine:
                return r
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")

    def text(self) -> str:
        """The table as text: the request, then one block per engine."""
        load = f", gravity {self.gravity:g} m/s^2" if self.gravity else ""
        head = (
            f"request: restitution {self.restitution:g}, contact time {self.contact_time:g} s, "
            f"mass {self.mass:g} kg, speed {self.speed:g} m/s{load}"
        )
        return "\n\n".join([head, *(r.text() for r in self.rows)])


def _number(name: str, value: Any, *, strict: bool) -> float:
    """``value`` as one finite real ``> 0`` (``>= 0`` unless ``strict``), or raise naming it."""
    arr, scalar = real_array(name, value, lower=0.0, strict=strict)
    if not scalar:
        raise ValueError(f"{name} must be one number, got {value!r}")
    return float(arr)


def lammps_timestep(*, kn: float, damping: float, mass: float, speed: float,
                    gravity: float = 0.0) -> float:  # fmt: skip
    """The LAMMPS step of the table: :func:`~impactsym.engines.lammps.timestep_for` (1 %
    at every touch phase, ``limit_damping``) rounded down to two significant digits (s).

    >>> c = lammps.hooke_for(restitution=0.5, contact_time=1e-3, mass=1.0)
    >>> lammps_timestep(kn=c.kn, damping=c.damping, mass=1.0, speed=1.0)
    1.1e-05
    """
    h = float(lammps.timestep_for(kn=kn, damping=damping, mass=mass, speed=speed,
                                  gravity=gravity, limit_damping=True))  # fmt: skip
    exponent = math.floor(math.log10(h)) - 1
    return float(f"{math.floor(h / 10.0**exponent)}e{exponent}")  # the number "timestep" reads


def conformance_table(
    *,
    restitution: float,
    contact_time: float,
    mass: float,
    speed: float,
    gravity: float = 0.0,
) -> ConformanceTable:
    """The parameters each engine needs for one impact, and what it then delivers.

    Parameters
    ----------
    restitution
        Wanted coefficient of restitution, ``0 < e < 1`` (the phase mean at each step).
    contact_time
        Wanted contact time, s (``> 0``).
    mass
        The contact's effective mass, kg (the body's own against a static ground).
    speed
        Normal approach speed, m/s (``> 0``).
    gravity
        Pressing acceleration, m/s^2 (``>= 0``).

    Returns
    -------
    ConformanceTable
        One :class:`EngineRow` per engine (module docstring: which bridge function and
        which step); a row the bridge refuses carries its reason in ``error``, and the
        other rows are unaffected.

    Raises
    ------
    ValueError, TypeError
        For bad input (not a number, not finite, out of range), naming it, before any
        engine is asked.

    Examples
    --------
    >>> t = conformance_table(restitution=0.5, contact_time=0.02, mass=0.1, speed=1.0)
    >>> [(r.engine, r.reachable) for r in t.rows]
    [('MuJoCo', True), ('LAMMPS', True), ('Drake', True), ('PyBullet', False)]
    >>> round(t.row("Drake").restitution, 9)
    0.5
    """
    e = _number("restitution", restitution, strict=True)
    if e >= 1.0:
        raise ValueError(f"restitution must be < 1, got {restitution!r}")
    request = {
        "restitution": e,
        "contact_time": _number("contact_time", contact_time, strict=True),
        "mass": _number("mass", mass, strict=True),
        "speed": _number("speed", speed, strict=True),
        "gravity": _number("gravity", gravity, strict=False),
    }
    rows = tuple(_row(engine, request) for engine in ENGINES)
    return ConformanceTable(**request, rows=rows)


def _row(engine: str, request: dict) -> EngineRow:
    """The row of ``engine``, or the bridge's ``ValueError`` as the row's reason."""
    model, note, step, build = _SPECS[engine]
    error = None
    with warnings.catch_warnings(record=True) as caught:  # kept as notes, not raised
        warnings.simplefilter("always")
        try:
            if step is None:  # LAMMPS: the step depends on the design
                step = _lammps_step(request)
            design, parameters, paste, pred = build(request, step)
        except ValueError as exc:
            error = str(exc)
    notes = tuple(str(w.message) for w in caught)
    if engine == "LAMMPS" and request["gravity"] > 0:
        notes += (
            "hooke_for designs collisions without a load; the prediction is that design "
            f"under gravity {request['gravity']:g} m/s^2",
        )
    if error is not None:
        return EngineRow(engine, math.nan if step is None else step, model, note,
                         error=error, notes=notes)  # fmt: skip
    return EngineRow(
        engine,
        step,
        model,
        note,
        parameters=parameters,
        paste=paste,
        restitution=float(pred.restitution),
        contact_time=float(pred.contact_time),
        restitution_range=tuple(float(x) for x in pred.restitution_range),
        contact_time_range=tuple(float(x) for x in pred.contact_time_range),
        notes=notes,
        design=design,
    )


def _mujoco(r: dict, step: float):
    d = mujoco.solref_for(restitution=r["restitution"], contact_time=r["contact_time"],
                          speed=r["speed"], gravity=r["gravity"], mass=r["mass"],
                          timestep=step, integrator="euler")  # fmt: skip
    tc, dr = d.solref
    paste = f'<option timestep="{step:g}" integrator="Euler"/>\n<geom ... {d.mjcf()}/>'
    return d, {"timeconst": tc, "dampratio": dr, "solimp": d.solimp}, paste, d.prediction


def _lammps_step(r: dict) -> float:
    c = lammps.hooke_for(restitution=r["restitution"], contact_time=r["contact_time"],
                         mass=r["mass"], speed=r["speed"])  # fmt: skip
    return lammps_timestep(kn=c.kn, damping=c.damping, mass=r["mass"], speed=r["speed"],
                           gravity=r["gravity"])  # fmt: skip


def _lammps(r: dict, step: float):
    c = lammps.hooke_for(restitution=r["restitution"], contact_time=r["contact_time"],
                         mass=r["mass"], speed=r["speed"], timestep=step)  # fmt: skip
    p = lammps.predict(kn=c.kn, damping=c.damping, mass=r["mass"], speed=r["speed"],
                       gravity=r["gravity"], limit_damping=True, timestep=step)  # fmt: skip
    coeff = c.pair_coeff().split(" hooke ", 1)[1]
    paste = (
        f"pair_style granular\n{c.pair_coeff()}\n"
        f"# or a wall: fix 2 all wall/gran granular hooke {coeff} zplane 0.0 NULL\n"
        f"timestep {step:g}"
    )
    return c, {"kn": float(c.kn), "eta_n": float(c.damping)}, paste, p


def _drake(r: dict, step: float):
    c = drake.point_contact_for(restitution=r["restitution"], contact_time=r["contact_time"],
                                speed=r["speed"], mass=r["mass"], gravity=r["gravity"],
                                time_step=step, approximation="lagged")  # fmt: skip
    k, d = float(c.point_contact_stiffness), float(c.hunt_crossley_dissipation)
    paste = (
        f'MultibodyPlantConfig(time_step={step:g}, contact_model="point", '
        'discrete_contact_approximation="lagged")\n'
        f"# on both geometries (2k and 2k in series give k = {k:.10g} N/m):\n"
        f"AddContactMaterial(dissipation={d:.10g}, point_stiffness={2.0 * k:.10g}, "
        "properties=props)"
    )
    params = {"point_contact_stiffness": k, "hunt_crossley_dissipation": d}
    return c, params, paste, c.prediction


def _pybullet(r: dict, step: float):
    c = pybullet.contact_for(restitution=r["restitution"], contact_time=r["contact_time"],
                             speed=r["speed"], mass=r["mass"], gravity=r["gravity"],
                             timestep=step)  # fmt: skip
    k, d = float(c.stiffness), float(c.damping)
    paste = (
        f"p.setPhysicsEngineParameter(fixedTimeStep={step:.10g})\n"
        f"p.changeDynamics(body, -1, contactStiffness={k:.10g}, contactDamping={d:.10g}, "
        "linearDamping=0)\n"
        "# against a static plane at its defaults (contactDamping 0.1, added by the pair rule)"
    )
    return c, {"contactStiffness": k, "contactDamping": d}, paste, c


#: per engine: integrator or approximation, where the step comes from, the step (s;
#: ``None``: chosen per design), the design
_SPECS = {
    "MuJoCo": ("Euler", "MuJoCo's default timestep and integrator", MUJOCO_TIMESTEP, _mujoco),
    "LAMMPS": (
        "velocity-Verlet, limit_damping",
        "LAMMPS has no default: timestep_for's step, within 1 % at every touch phase",
        None,
        _lammps,
    ),
    "Drake": ("discrete, 'lagged'", "MultibodyPlantConfig's default", DRAKE_TIME_STEP, _drake),
    "PyBullet": (
        "sequential impulse, speculative contacts",
        "PyBullet's default fixedTimeStep",
        PYBULLET_TIMESTEP,
        _pybullet,
    ),
}
