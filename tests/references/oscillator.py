"""Independent high-precision reference for the spring-damper contact (tests only).

Nothing here comes from impactsym's derivation: the state is propagated with the
mpmath matrix exponential of the first-order system, and roots are bracketed by
sampling and refined with mpmath's bisection-safe solvers at 30+ digits.
"""

from __future__ import annotations

import mpmath as mp


def state(t, damping, force, dps=40):
    """(z, z') at time t of z'' + 2 D z' + z = 2 D f, z(0)=0, z'(0)=1, via expm."""
    with mp.workdps(dps):
        t, damping, force = mp.mpf(t), mp.mpf(damping), mp.mpf(force)
        static = 2 * damping * force
        A = mp.matrix([[0, 1], [-1, -2 * damping]])
        x = mp.expm(A * t) * mp.matrix([-static, 1])
        return x[0] + static, x[1]


def contact_function(t, damping, force, condition, dps=40):
    z, v = state(t, damping, force, dps)
    return z if condition == "position" else 2 * damping * v + z


def first_root(damping, force, condition, t_max=60.0, samples=600, dps=40):
    """First sign change of g after t = 0 by sampling (t_max/samples steps), then
    refined with the Anderson-Bjorck bracketing solver; None when none is seen."""
    with mp.workdps(dps):
        h = mp.mpf(t_max) / samples
        previous_t = h / 1000  # g_position(0) = 0: start just after impact
        previous = contact_function(previous_t, damping, force, condition, dps)
        for i in range(1, samples + 1):
            t = i * h
            value = contact_function(t, damping, force, condition, dps)
            if previous > 0 and value == 0:
                return t
            if previous > 0 and value < 0:
                return mp.findroot(
                    lambda x: contact_function(x, damping, force, condition, dps),
                    (previous_t, t),
                    solver="anderson",
                )
            previous_t, previous = t, value
        return None


def refine_root(guess, damping, force, condition, dps=40):
    """Polish a root of g near ``guess`` at ``dps`` digits (secant from two nearby points)."""
    with mp.workdps(dps):
        g = mp.mpf(guess)
        return mp.findroot(
            lambda x: contact_function(x, damping, force, condition, dps),
            (g * (1 - mp.mpf("1e-9")), g * (1 + mp.mpf("1e-9"))),
            solver="secant",
        )
