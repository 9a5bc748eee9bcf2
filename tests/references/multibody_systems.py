"""Reference systems and the SciPy full simulation for the multibody tests.

The two systems are built here independently of ``impactsym.multibody.examples``, the
way users write them: the falling bar with ``sympy.physics.mechanics.System``, the
double pendulum with ``KanesMethod``. The full nonlinear penalty simulation uses
``scipy.integrate.solve_ivp`` (DOP853) with terminal events.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from sympy.physics import mechanics as me

GRAVITY = 9.81


@dataclass
class Model:
    """A mechanics model with its penetration, impact configuration and velocity direction."""

    model: object  # KanesMethod or System, equations formed
    g: sp.Expr  # penetration in the model's coordinates
    q: list  # coordinates (dynamicsymbols)
    u: list  # speeds (dynamicsymbols), u = q'
    q0: list[float]
    direction: list[float]

    def at(self, speed: float) -> dict:
        state = dict(zip(self.q, self.q0, strict=True))
        state.update({ui: speed * c for ui, c in zip(self.u, self.direction, strict=True)})
        return state


def bar_system(
    mass=1.0, length=1.0, angle=np.pi / 6, drag=0.5, rotational_drag=2.0, *, params=None
) -> Model:
    """Planar rigid bar (centre x, y; angle theta to the ground) falling onto its lower end."""
    system = me.System.from_newtonian(me.RigidBody("ground"))
    N, origin = system.frame, system.fixed_point
    x, y, th = me.dynamicsymbols("x y theta")
    vx, vy, om = me.dynamicsymbols("v_x v_y omega")
    m, L = (mass, length) if params is None else params
    bar = me.RigidBody("bar", mass=m)
    bar.central_inertia = me.inertia(bar.frame, 0, 0, m * L**2 / 12)
    system.add_coordinates(x, y, th)
    system.add_speeds(vx, vy, om)
    system.add_kdes(vx - x.diff(), vy - y.diff(), om - th.diff())
    bar.frame.orient_axis(N, N.z, th)
    bar.frame.set_ang_vel(N, om * N.z)
    bar.masscenter.set_pos(origin, x * N.x + y * N.y)
    bar.masscenter.set_vel(N, vx * N.x + vy * N.y)
    system.add_bodies(bar)
    system.apply_uniform_gravity(-GRAVITY * N.y)
    system.add_loads(
        me.Force(bar.masscenter, -drag * (vx * N.x + vy * N.y)),
        me.Torque(bar.frame, -rotational_drag * om * N.z),
    )
    system.form_eoms()
    end = bar.masscenter.locatenew("end", -L / 2 * bar.frame.x)
    g = -end.pos_from(origin).dot(N.y)
    q0 = [0.0, float(L / 2 * np.sin(angle)), float(angle)]
    return Model(system, g, [x, y, th], [vx, vy, om], q0, [0.0, -1.0, 0.0])


def pendulum_kane(
    masses=(1.0, 0.5),
    lengths=(1.0, 0.7),
    angles=(np.pi / 9, np.pi / 4),
    stiffness=(50.0, 20.0),
    rest=(1.5, 1.382),
    damping=(1.0, 0.5),
) -> Model:
    """Double pendulum (absolute angles from the downward vertical) with joint springs and
    dampers, tip striking the vertical wall through the impact configuration."""
    q1, q2 = me.dynamicsymbols("q1 q2")
    u1, u2 = me.dynamicsymbols("u1 u2")
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", (q1, N.z))
    B = N.orientnew("B", "Axis", (q2, N.z))
    A.set_ang_vel(N, u1 * N.z)
    B.set_ang_vel(N, u2 * N.z)
    origin = me.Point("O")
    origin.set_vel(N, 0)
    P1 = origin.locatenew("P1", -lengths[0] * A.y)
    P2 = P1.locatenew("P2", -lengths[1] * B.y)
    P1.v2pt_theory(origin, N, A)
    P2.v2pt_theory(P1, N, B)
    bodies = [me.Particle("p1", P1, masses[0]), me.Particle("p2", P2, masses[1])]
    shoulder = -stiffness[0] * (q1 - rest[0]) - damping[0] * u1
    elbow = -stiffness[1] * (q2 - q1 - rest[1]) - damping[1] * (u2 - u1)
    loads = [
        (P1, -masses[0] * GRAVITY * N.y),
        (P2, -masses[1] * GRAVITY * N.y),
        (A, (shoulder - elbow) * N.z),
        (B, elbow * N.z),
    ]
    kane = me.KanesMethod(
        N, q_ind=[q1, q2], u_ind=[u1, u2], kd_eqs=[u1 - q1.diff(), u2 - q2.diff()]
    )
    kane.kanes_equations(bodies, loads)
    wall = lengths[0] * np.sin(angles[0]) + lengths[1] * np.sin(angles[1])
    g = P2.pos_from(origin).dot(N.x) - wall
    return Model(kane, g, [q1, q2], [u1, u2], [float(a) for a in angles], [1.0, 1.0])


class FullSimulation:
    """SciPy simulation of ``M(q) u' = F(q, u) - n(q) (k g + d g')`` from the impact state."""

    def __init__(self, model: Model) -> None:
        method = model.model.eom_method if hasattr(model.model, "eom_method") else model.model
        kin = method.kindiffdict()
        plain_q = sp.symbols(f"Q0:{len(model.q)}")
        plain_u = sp.symbols(f"U0:{len(model.u)}")
        to_plain = dict(zip(model.u, plain_u, strict=True)) | dict(
            zip(model.q, plain_q, strict=True)
        )
        M = method.mass_matrix.xreplace(kin).xreplace(to_plain)
        F = method.forcing.xreplace(kin).xreplace(to_plain)
        g = model.g.xreplace(to_plain)
        normal = sp.Matrix([g]).jacobian(plain_q)
        args = [plain_q, plain_u]
        self._M = sp.lambdify(args, M, "numpy")
        self._F = sp.lambdify(args, F, "numpy")
        self._n = sp.lambdify(args, normal, "numpy")
        self._g = sp.lambdify(args, g, "numpy")
        self.model = model
        self.n = len(model.q)

    def contact_time(self, k, d, speed, condition, t_max):
        """First time the condition (g or k g + d g') turns negative; inf before t_max."""
        return self.contact(k, d, speed, condition, t_max)[0]

    def contact(self, k, d, speed, condition, t_max):
        """``(t_c, e)``: the contact time as in :meth:`contact_time` and the restitution
        ``e = -g'(t_c) / g'(0)`` (``inf, 0.0`` when still in contact at ``t_max``)."""
        n = self.n

        def parts(y):
            q, u = y[:n], y[n:]
            normal = np.asarray(self._n(q, u), dtype=float).ravel()
            return q, u, normal, float(self._g(q, u))

        def rhs(_t, y):
            q, u, normal, g = parts(y)
            lam = -(k * g + d * normal @ u)
            M = np.asarray(self._M(q, u), dtype=float)
            F = np.asarray(self._F(q, u), dtype=float).ravel()
            return np.concatenate([u, np.linalg.solve(M, F + normal * lam)])

        def event(_t, y):
            _, u, normal, g = parts(y)
            return g if condition == "position" else k * g + d * normal @ u

        event.terminal = True
        event.direction = -1
        y0 = [*self.model.q0, *(speed * c for c in self.model.direction)]
        sol = solve_ivp(
            rhs, (0.0, t_max), y0, method="DOP853", events=event, rtol=1e-10, atol=1e-13
        )
        if sol.status == -1:
            raise RuntimeError(sol.message)
        if not sol.t_events[0].size:
            return np.inf, 0.0
        _, u0, normal0, _ = parts(np.asarray(y0, dtype=float))
        _, u_c, normal_c, _ = parts(sol.y_events[0][0])
        return float(sol.t_events[0][0]), float(-(normal_c @ u_c) / (normal0 @ u0))


def reduced_oscillator(r, condition: str, t_end: float, *, atol: float, max_step=np.inf):
    """``m~ z'' + d~ z' + c~ z = F_n`` from ``z = 0, z' = v0`` (the reduced contact ``r``),
    integrated by SciPy ``solve_ivp`` to the first end of contact under ``condition``
    (an event; none before ``t_end`` when the body sticks). Independent of the section-2
    closed forms; ``sol.t_events[0]`` and ``sol.y_events[0]`` hold the end."""
    m_, d_, c_, load = r.m_eff, r.d_eff, r.c_eff, r.load

    def end(_t, y):
        return y[0] if condition == "position" else c_ * y[0] + d_ * y[1]

    end.terminal, end.direction = True, -1
    return solve_ivp(
        lambda _t, y: [y[1], (load - d_ * y[1] - c_ * y[0]) / m_],
        (0.0, t_end),
        [0.0, r.v0],
        events=end,
        rtol=1e-12,
        atol=atol,
        max_step=max_step,
    )
