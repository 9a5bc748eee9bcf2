"""MuJoCo's soft contact as an impact oscillator: predict and design ``solref``/``solimp``.

* :mod:`~impactsym.engines.mujoco.model`: MuJoCo's contact law (impedance ``solimp``,
  the coefficients of ``solref``, refsafe, the effective mass) as paper section 2's
  loaded oscillator;
* :mod:`~impactsym.engines.mujoco.prediction`: :func:`predict` (restitution, contact time,
  penetration, force of the first contact phase; continuous, or exact at the user's
  timestep and touch phase) and :func:`stick_speed`;
* :mod:`~impactsym.engines.mujoco.continuous` (the limit ``timestep -> 0``),
  :mod:`~impactsym.engines.mujoco.euler` and :mod:`~impactsym.engines.mujoco.stepmap`
  (MuJoCo's Euler/implicitfast step on one contact), :mod:`~impactsym.engines.mujoco.discrete`
  (dispatch per integrator, the phase mean and range), and
  :mod:`~impactsym.engines.mujoco.stepping` (the touch-phase definitions);
* :mod:`~impactsym.engines.mujoco.design`: :func:`solref_for` (the inverse) and
  :func:`from_reduced` (a reduced multibody contact as its input); with a timestep
  :mod:`~impactsym.engines.mujoco.discrete_design` designs the phase mean;
* :mod:`~impactsym.engines.mujoco.advisor`: :func:`timestep_for` (the largest timestep
  that keeps the restitution within a tolerance at every touch phase).

The physics, and how the engine was read, is in `docs/physics.md#simulation-engines`.
All physical quantities are SI: seconds, metres, m/s, m/s^2, kilograms, newtons.
"""

from __future__ import annotations

from impactsym.engines.mujoco.advisor import TimestepAdvice, timestep_for
from impactsym.engines.mujoco.design import Design, from_reduced, solref_for
from impactsym.engines.mujoco.model import DEFAULT_SOLIMP, DEFAULT_TIMECONST, impedance
from impactsym.engines.mujoco.prediction import Prediction, predict, stick_speed

__all__ = [
    "DEFAULT_SOLIMP",
    "DEFAULT_TIMECONST",
    "Design",
    "Prediction",
    "TimestepAdvice",
    "from_reduced",
    "impedance",
    "predict",
    "solref_for",
    "stick_speed",
    "timestep_for",
]
