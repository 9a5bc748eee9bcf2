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

:func:`entering_step` runs that step with every stage written as free flight about touch
plus the contact's share (the free-flight part of stage 4 and of the new state is the
penetration ``v s + g s^2 / 2`` at ``s = phase h``, not ``x_0 + h v_2``: at a phase of
``1e-300`` the latter rounds to 0, so the first state and stage 4 fell out of the
contact, and the summary's first grid phase was not the limit ``phase -> 0+``).

SI: seconds, m/s, m/s^2.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from impactsym.engines.mujoco.rk4_record import stage_bits

__all__ = ["entering_step", "rk4_entry_phases"]


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


def entering_step(
    stage: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]],
    gravity: np.ndarray,
    speed: np.ndarray,
    timestep: np.ndarray,
    phase: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""The first detecting state after the entering step, and its stage bits.

    The RK4 step from the free-flight state at ``t0 = (phase - 1) h`` (flat arrays of one
    shape; ``stage(x, v)[0]`` is a stage's acceleration, ``g`` out of contact). With
    ``x(t) = v t + g t^2/2``, ``m = (phase - 1/2) h``, ``s = phase h`` and each stage's
    share ``D_i = a_i - g`` (0 where it is free) the stages and the new state are

    .. math::

        x_2 = x(m) - \tfrac{g h^2}{8}, \quad x_3 = x(m) + \tfrac{g h^2}{8}
        + \tfrac{h^2}{4} D_1, \quad x_4 = x(s) + \tfrac{h^2}{2} D_2, \quad
        x_{new} = x(s) + \tfrac{h^2}{6}(D_1 + D_2 + D_3),

    velocities ``v + g m + h D_1 / 2``, ``v + g m + h D_2 / 2``, ``v + g s + h D_3``
    and ``v + g s + h (D_1 + 2 D_2 + 2 D_3 + D_4) / 6``: MuJoCo's stage arithmetic
    rearranged (the same to rounding), without the cancellation of ``x_0 + h v_2`` near
    touch. Returns ``x_new``, ``v_new`` and the step's
    :func:`~impactsym.engines.mujoco.rk4_record.stage_bits`.

    >>> x, v, n = entering_step(lambda x, v: (np.where(x > 0, -1.0, 0.0), 1.0 + 0 * x),
    ...                         np.zeros(1), np.ones(1), np.full(1, 0.01), np.full(1, 1e-300))
    >>> bool(x[0] > 0), round(float(v[0]), 6), int(n[0])
    (True, 0.998333, 8)
    """
    g, v, h = gravity, speed, timestep
    t0, m, s = (phase - 1.0) * h, (phase - 0.5) * h, phase * h
    x_m, x_s = v * m + 0.5 * g * m * m, v * s + 0.5 * g * s * s
    x1, v1 = v * t0 + 0.5 * g * t0 * t0, v + g * t0
    d1 = stage(x1, v1)[0] - g
    x2, v2 = x_m - 0.125 * g * h * h, v + g * m + 0.5 * h * d1
    d2 = stage(x2, v2)[0] - g
    x3, v3 = x_m + 0.125 * g * h * h + 0.25 * h * h * d1, v + g * m + 0.5 * h * d2
    d3 = stage(x3, v3)[0] - g
    x4, v4 = x_s + 0.5 * h * h * d2, v + g * s + h * d3
    d4 = stage(x4, v4)[0] - g
    x_new = x_s + h * h / 6.0 * (d1 + d2 + d3)
    v_new = v + g * s + h / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4)
    return x_new, v_new, stage_bits(x1, x2, x3, x4)
