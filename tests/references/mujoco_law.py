"""MuJoCo's soft contact for one body, integrated by SciPy (DOP853) with events: the
independent reference of ``impactsym.engines.mujoco.predict`` in the limit timestep -> 0.

``x'' = (1 - d) g - d (b x' + d kbar x)`` with the impedance ``d(x)`` of ``solimp``,
``b = 2 / (d_max tc)``, ``kbar = 1 / (d_max^2 tc^2 dampratio^2)``; the contact ends where
the constraint force ``g + b x' + d kbar x`` or the penetration ``x`` falls to zero.
"""

from __future__ import annotations

from scipy.integrate import solve_ivp

from impactsym.engines.mujoco import impedance


def mujoco_contact(solref, solimp, speed, gravity=0.0):
    """``(restitution, contact time, ended by position)`` of an impact at ``speed``."""
    tc, dr = solref
    b, kbar = 2 / (solimp[1] * tc), 1 / (solimp[1] ** 2 * tc**2 * dr**2)

    def d_of(x):
        return impedance(max(x, 0.0), solimp)

    def rhs(t, y):
        d = d_of(y[0])
        return [y[1], (1 - d) * gravity - d * (b * y[1] + d * kbar * y[0])]

    def force(t, y):
        return gravity + b * y[1] + d_of(y[0]) * kbar * y[0]

    def position(t, y):
        return y[0] if t > 1e-12 else 1.0

    force.terminal = position.terminal = True
    force.direction = position.direction = -1
    sol = solve_ivp(
        rhs,
        (0, 2.0),
        [0.0, speed],
        method="DOP853",
        events=[force, position],
        rtol=1e-12,
        atol=1e-15,
        max_step=tc / 200,
    )
    assert sol.status == 1, "no end of contact within t = 2"
    return -sol.y[1, -1] / speed, sol.t[-1], len(sol.t_events[1]) > 0
