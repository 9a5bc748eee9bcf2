"""The Hooke spring-dashpot of LAMMPS ``pair_style granular``: prediction and design.

* :mod:`~impactsym.engines.lammps.hooke`: :class:`HookeContact` and :func:`predict`, the
  continuous contact (``timestep=None``, the limit ``timestep -> 0``) with the coast
  through the overlap under ``limit_damping``, or LAMMPS at its timestep;
* :mod:`~impactsym.engines.lammps.verlet`: the exact discrete model of velocity-Verlet
  (the touch phase, the end state from the closed form, the stability limit);
* :mod:`~impactsym.engines.lammps.phases`: mean and range over touch phases;
* :mod:`~impactsym.engines.lammps.design`: :func:`hooke_for`, ``coeff_restitution``;
* :mod:`~impactsym.engines.lammps.advisor`: :func:`timestep_for`;
* :mod:`~impactsym.engines.lammps.derivation`: the SymPy derivation of the step map;
* :mod:`~impactsym.engines.lammps.common`: shared helpers (natural units, checks).

The physics is in `docs/physics.md#simulation-engines`. SI units throughout.
"""

from __future__ import annotations

from impactsym.engines.lammps.advisor import timestep_for
from impactsym.engines.lammps.design import (
    coeff_restitution_achieved,
    coeff_restitution_for,
    hooke_for,
    textbook_damping_ratio,
)
from impactsym.engines.lammps.hooke import HookeContact, predict

__all__ = [
    "HookeContact",
    "coeff_restitution_achieved",
    "coeff_restitution_for",
    "hooke_for",
    "predict",
    "textbook_damping_ratio",
    "timestep_for",
]
