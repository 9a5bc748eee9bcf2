"""Surveys over the engines' predictions: textbook against exact restitution, MuJoCo's
stick map.

The textbook damping ``D = -ln e / sqrt(pi^2 + ln^2 e)`` gives the wanted restitution
only for a linear spring-damper released when the force vanishes; the engines differ
(MuJoCo's impedance ``solimp``, LAMMPS's ``limit_damping``). These functions evaluate the
predictions of :mod:`impactsym.engines.mujoco` and :mod:`impactsym.engines.lammps` on
grids, so that figures (:mod:`impactsym.plotting.engines`) only draw; see
notebooks/04_engine_parameters.ipynb.
"""

from __future__ import annotations

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
