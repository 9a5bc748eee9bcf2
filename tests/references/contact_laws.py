"""The normalized contact laws written out by hand (p = 3/2): the independent reference of
``impactsym.contact.laws`` for the tests that integrate them with SciPy.

``phi(law, z, w, d)`` is the normalized force at overlap ``z``, rate ``w`` and damping
number ``d``; ``sign(law, z, w, d)`` has the sign of that force for ``z > 0`` and stays
smooth at ``z = 0`` (the event function of the force condition). ``impact_ivp`` integrates
``z'' = f - phi``, ``z(0) = 0``, ``z'(0) = 1`` with SciPy (DOP853, ``rtol = 1e-13``) and
its events, ``peak_force`` maximizes the force along that solution.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

P = 1.5


def phi(law: str, z, w, d: float):
    z = np.maximum(z, 0.0)
    return {
        "linear": lambda: z + 2 * d * w,
        "hertz-linear": lambda: z**P + 2 * d * w,
        "hunt-crossley": lambda: z**P * (1 + d * w),
        "tsuji": lambda: z**P + d * z ** ((P - 1) / 2) * w,
        "viscoelastic": lambda: z**1.5 + d * np.sqrt(z) * w,
    }[law]()


def sign(law: str, z: float, w: float, d: float) -> float:
    """A function with the sign of the force for z > 0, smooth at z = 0."""
    z = max(z, 0.0)
    return {
        "linear": z + 2 * d * w,
        "hertz-linear": z**P + 2 * d * w,
        "hunt-crossley": 1 + d * w,
        "tsuji": d * w + z ** ((P + 1) / 2),
        "viscoelastic": z + d * w,
    }[law]


def impact_ivp(law: str, d: float, f: float, condition: str, t_end: float):
    """``solve_ivp`` of the pressed impact: terminal events ``z = 0`` and, unless the
    condition is ``"position"``, the force's sign through zero (index 2); event 1 is the
    deepest point ``z' = 0`` (not terminal). ``status == 0``: no end by ``t_end``."""

    def rhs(t, y):
        return [y[1], f - phi(law, y[0], y[1], d)]

    def out(t, y):
        return y[0] if t > 1e-9 else 1.0

    def released(t, y):
        return sign(law, y[0], y[1], d) if t > 1e-9 else 1.0

    def top(t, y):
        return y[1]

    out.terminal = released.terminal = True
    out.direction = released.direction = top.direction = -1
    events = [out, top] + ([released] if condition != "position" else [])
    return solve_ivp(rhs, (0.0, t_end), [0.0, 1.0], method="DOP853", rtol=1e-13, atol=1e-16,
                     events=events, dense_output=True)  # fmt: skip


def peak_force(law: str, sol, d: float, samples: int) -> float:
    """The largest force along ``sol`` (:func:`impact_ivp`): sampled, then refined by
    bounded minimization around the largest sample."""
    grid = np.linspace(0.0, sol.t[-1], samples)
    force = phi(law, *sol.sol(grid), d)
    i = int(np.argmax(force))
    peak = force[i]
    if 0 < i < grid.size - 1:
        best = minimize_scalar(lambda t: -float(phi(law, *sol.sol(t), d)),
                               bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                               options={"xatol": 1e-14})  # fmt: skip
        peak = max(peak, -best.fun)
    return float(peak)
