"""Independent event-driven simulation of the bounce sequence (tests only).

Nothing here comes from impactsym: contact phases integrate ``z'' + 2Dz' + z = 2Df``
and flights integrate the body (``z'' = 2Df``) together with the massless element
(``2D z_e' + z_e = 0``) with scipy's DOP853 and event location; a contact that shows
no release within ``t_contact`` counts as sticking.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp


def simulate(D, f, condition, *, max_contacts=100, t_contact=400.0, rtol=1e-11, atol=1e-15):
    """Rows ``(start, end, arrival velocity, departure speed, element deflection)`` of
    every contact, and whether the body sticks."""
    a = 2.0 * D * f
    t, z, v = 0.0, 0.0, 1.0
    rows = []
    for _ in range(max_contacts):
        start, z_start, v_start = t, z, v

        def release(_t, y):
            return y[0] if condition == "position" else 2 * D * y[1] + y[0]

        release.terminal, release.direction = True, -1
        scale = max(abs(v), abs(z))
        sol = solve_ivp(
            lambda _t, y: [y[1], a - 2 * D * y[1] - y[0]],
            (t, t + t_contact),
            [z, v],
            events=release,
            rtol=rtol,
            atol=atol * scale,
            method="DOP853",
        )
        if not sol.t_events[0].size:
            rows.append((start, np.inf, v_start, 0.0, z_start))
            return np.array(rows), True
        t = sol.t_events[0][0]
        z, v = sol.y_events[0][0]
        rows.append((start, t, v_start, -v, z_start))
        if a == 0:
            return np.array(rows), False
        if condition == "position":  # constant acceleration: the flight is a parabola
            t, z, v = t - 2.0 * v / a, 0.0, -v
            continue

        def gap(_t, y):
            return y[0] - y[2]

        gap.terminal, gap.direction = True, 1
        sol = solve_ivp(
            lambda _t, y: [y[1], a, -y[2] / (2 * D)],
            (t, t + 10 * (1 - v / a)),
            [z, v, z],
            events=gap,
            rtol=rtol,
            atol=atol * abs(v),
            method="DOP853",
        )
        t = sol.t_events[0][0]
        z, v, _ = sol.y_events[0][0]
    return np.array(rows), False
