r"""The touch phases at which MuJoCo's RK4 entering step gains a stage in contact.

The step that carries the body in starts from free flight at ``t0 = (phase - 1) dt``
before touch (:mod:`~impactsym.engines.mujoco.stepping`); its stages sit at the
penetrations (``c = 1/2, 1/2``, stage 1 free, ``a = g``)

.. math::

    x_2 = x_0 + \tfrac{h}{2} v_0, \qquad x_3 = x_0 + \tfrac{h}{2}\bigl(v_0 + \tfrac{h}{2} g\bigr),
    \qquad x_0 = v\,t_0 + \tfrac12 g t_0^2,\ v_0 = v + g t_0 .

Where ``x_2`` or ``x_3`` crosses zero as the phase grows, that stage starts to feel the
contact force, and the restitution and contact time jump although the number of steps
does not change; stage 4 feels it at every phase above 0. These two phases are where
:func:`~impactsym.engines.mujoco.discrete.phase_summary` must split the phase interval
besides the end-step jumps it finds itself. Both are quadratics in ``t0``; the root near
``-h/2`` is taken in the cancellation-free form ``-2c / (b + sqrt(b^2 - 4ac))``.

SI: seconds, m/s, m/s^2.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["rk4_entry_phases"]


def rk4_entry_phases(gravity: Any, speed: Any, timestep: Any) -> np.ndarray:
    """Phases in ``(0, 1)`` where stages 2 and 3 of the entering step reach the contact.

    Returns an array of shape ``broadcast + (2,)``; ``nan`` where a stage never enters
    within the step.

    >>> rk4_entry_phases(0.0, 1.0, 0.002).tolist()
    [0.5, 0.5]
    """
    g, v, h = np.broadcast_arrays(*(np.asarray(a, float) for a in (gravity, speed, timestep)))
    a = 0.5 * g
    b = v + 0.5 * g * h
    out = []
    for c in (0.5 * v * h, 0.5 * v * h + 0.25 * g * h * h):
        with np.errstate(invalid="ignore"):
            t0 = -2.0 * c / (b + np.sqrt(b * b - 4.0 * a * c))
            phase = 1.0 + t0 / h
        out.append(np.where((phase > 0.0) & (phase < 1.0), phase, np.nan))
    return np.stack(out, axis=-1)
