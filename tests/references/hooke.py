"""LAMMPS's granular Hooke contact, integrated by SciPy with events (an independent
reference for ``impactsym.engines.lammps``).

``m x'' = m g - kn x - eta x'`` from ``x = 0``, ``x' = v``: with ``limit_damping`` the
contact ends where the force ``kn x + eta x'`` falls to zero, otherwise where the overlap
``x`` does (SI units).
"""

from __future__ import annotations

from scipy.integrate import solve_ivp


def hooke_contact(kn, eta, m, v, *, gravity=0.0, limit_damping=True, t_max=1.0):
    """The SciPy solution up to the end of contact (``dense_output``; ``sol.t[-1]`` is the
    contact time, ``-sol.y[1, -1] / v`` the restitution, ``sol.t_events[-1]`` non-empty
    where the overlap ended it)."""

    def rhs(t, y):
        return [y[1], gravity - (kn * y[0] + eta * y[1]) / m]

    def force(t, y):
        return kn * y[0] + eta * y[1]

    def overlap(t, y):
        return y[0] if t > 1e-12 else 1.0

    force.terminal = overlap.terminal = True
    force.direction = overlap.direction = -1
    events = [force, overlap] if limit_damping else [overlap]
    return solve_ivp(
        rhs, (0, t_max), [0.0, v], events=events, rtol=1e-12, atol=1e-15, dense_output=True
    )
