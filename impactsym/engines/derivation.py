r"""SymPy: MuJoCo's soft contact as paper section 2's oscillator with a load and an offset.

MuJoCo's soft-constraint relation for one frictionless contact (documentation,
*Computation*),

.. math::

    a_1 = a_0 + d'\,(a_\mathrm{ref} - a_0), \qquad
    a_\mathrm{ref} = -b\,v - d\,\bar k\,r, \qquad f = m\,(a_1 - a_0) \ge 0,

with ``r = -x`` (penetration ``x``), ``v = -x'``, ``a0 = -g``, ``d' = d rho / (d rho + 1
- d)`` (``rho = A / A_diag``; ``d' = d`` for one free body), is solved here for the
equation of motion and brought to the section-2 normalization
``tau = omega0 t``, ``z = x omega0 / v0``:

.. math::

    z'' + 2 D z' + z = c, \qquad \lambda = \frac{f}{m\,\omega_0 v_0} = 2 D z' + z + \delta,

    \omega_0^2 = d' d \bar k, \quad D = \frac{d' b}{2 \omega_0}, \quad
    c = (1 - d')\,\gamma, \quad \delta = d' \gamma, \quad \gamma = \frac{g}{\omega_0 v_0}.

The trajectory is the paper's with ``2 D f = c``; the force threshold is offset by
``delta``. :mod:`impactsym.engines.mujoco.model` writes ``omega0``, ``D``, ``c``, ``delta``
and the ``solref`` coefficients in closed form and is tested against these expressions
at random points; the one solver :mod:`impactsym.contact.release` solves the oscillator
(`docs/physics.md#simulation-engines`).
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

__all__ = ["MujocoContact"]


class MujocoContact:
    """The derivation, as SymPy expressions (attributes are cached).

    >>> mc = MujocoContact()
    >>> sp.simplify(mc.normalized_load - (1 - mc.d_eff) * mc.gamma)
    0
    """

    def __init__(self) -> None:
        self.m, self.g, self.v0 = sp.symbols("m g v_0", positive=True)
        self.d, self.rho, self.b, self.kbar = sp.symbols("d rho b kbar", positive=True)
        self.x, self.x_dot = sp.symbols("x xdot", real=True)
        self.timeconst, self.dampratio, self.d_max = sp.symbols(
            "timeconst dampratio d_max", positive=True
        )
        self.stiffness, self.damping = sp.symbols("stiffness damping", nonnegative=True)

    @cached_property
    def d_eff(self) -> sp.Expr:
        """Effective impedance ``d' = d rho / (d rho + 1 - d)``."""
        return self.d * self.rho / (self.d * self.rho + 1 - self.d)

    @cached_property
    def acceleration(self) -> sp.Expr:
        """``x''`` from the soft-constraint relation (penetration positive)."""
        r, v, a0 = -self.x, -self.x_dot, -self.g
        a_ref = -self.b * v - self.d * self.kbar * r
        a1 = a0 + self.d_eff * (a_ref - a0)
        return sp.expand(-a1)

    @cached_property
    def contact_force(self) -> sp.Expr:
        """Contact force ``f = m (a1 - a0)`` along the normal (newtons)."""
        a1 = -self.acceleration
        return sp.factor(self.m * (a1 + self.g))

    @cached_property
    def omega0(self) -> sp.Expr:
        """``omega0 = sqrt(-d x''/dx)``."""
        return sp.sqrt(-sp.diff(self.acceleration, self.x))

    @cached_property
    def damping_ratio(self) -> sp.Expr:
        """Lehr's ``D = -(d x''/dx') / (2 omega0)``."""
        return sp.simplify(-sp.diff(self.acceleration, self.x_dot) / (2 * self.omega0))

    @cached_property
    def gamma(self) -> sp.Expr:
        """``gamma = g / (omega0 v0)``."""
        return self.g / (self.omega0 * self.v0)

    @cached_property
    def normalized_load(self) -> sp.Expr:
        """``c``: the constant part of ``x''`` in units of ``omega0 v0``."""
        load = self.acceleration.subs({self.x: 0, self.x_dot: 0})
        return sp.simplify(load / (self.omega0 * self.v0))

    @cached_property
    def normalized_offset(self) -> sp.Expr:
        """``delta = lambda - (2 D z' + z)``, with ``lambda = f / (m omega0 v0)``."""
        tau_scale = self.v0 / self.omega0  # x = z v0 / omega0, x' = z' v0
        z, z_dot = sp.symbols("z zdot", real=True)
        lam = self.contact_force.subs({self.x: z * tau_scale, self.x_dot: z_dot * self.v0})
        lam = lam / (self.m * self.omega0 * self.v0)
        return sp.simplify(sp.expand(lam - 2 * self.damping_ratio * z_dot - z))

    @cached_property
    def solref_positive(self) -> dict[sp.Symbol, sp.Expr]:
        """``b``, ``kbar`` of ``solref = (timeconst, dampratio)``."""
        return {
            self.b: 2 / (self.d_max * self.timeconst),
            self.kbar: 1 / (self.d_max**2 * self.timeconst**2 * self.dampratio**2),
        }

    @cached_property
    def solref_negative(self) -> dict[sp.Symbol, sp.Expr]:
        """``b``, ``kbar`` of ``solref = (-stiffness, -damping)``."""
        return {self.b: self.damping / self.d_max, self.kbar: self.stiffness / self.d_max**2}


def mujoco_rk4_step() -> dict[str, sp.Expr]:
    r"""SymPy: one step of MuJoCo's RK4 (``mj_RungeKutta``) in the interior of a flat contact.

    MuJoCo's classical Runge-Kutta step (``engine_forward.c``) evaluates the state at four
    stages, ``X_i = X_0 + h\,c_i F_{i-1}`` with ``c = (1/2, 1/2, 1)``, runs the whole forward
    pass (collision, constraint force) at each, and advances
    ``X_0 + h (F_0 + 2 F_1 + 2 F_2 + F_3) / 6``. Where every stage is in contact with a
    positive force and the impedance is flat, the stage acceleration is the loaded
    oscillator's (penetration ``x``, rate ``v``)

    .. math::

        a = g - d'\,(g + b\,v + d\,\bar k\,x) = (1 - d')\,g - d' b\,v - d' d \bar k\,x,

    and the step is the affine map ``y -> M y + h q`` of ``y = (x, v)``. Returns

    * ``"matrix"``: ``M`` (2x2) and ``"offset"``: ``h q`` from the four stages as MuJoCo
      computes them;
    * ``"taylor"``: ``P(hA) = I + hA + (hA)^2/2 + (hA)^3/6 + (hA)^4/24`` with
      ``A = [[0, 1], [-d' d kbar, -d' b]]`` (``matrix - taylor`` simplifies to zero: the
      step matrix is the degree-4 Taylor polynomial of ``exp(hA)``);
    * ``"equilibrium"``: the fixed point ``x* = (1 - d') g / (d' d kbar)``, ``v* = 0``;
    * ``"eigenvalues"``: ``P(h lambda)`` for the roots ``lambda`` of
      ``lambda^2 + d' b lambda + d' d kbar = 0``; the spectral radius is the larger
      modulus (the map is stable where it is below 1);
    * ``"stages"``: the four stage states ``(x_i, v_i)`` as functions of ``(x, v)``;
    * ``"undamped_modulus2"``: ``|P(i y)|^2 = 1 - y^6/72 + y^8/576`` (``y = omega0 h``, no
      damping): at most 1 iff ``omega0 h <= 2 sqrt(2)``, RK4's stability limit there.

    >>> r = mujoco_rk4_step()
    >>> sp.simplify(r["matrix"] - r["taylor"])
    Matrix([
    [0, 0],
    [0, 0]])
    """
    h, g, b, d, kbar, dp = sp.symbols("h g b d kbar d_eff", positive=True)
    x, v, lam = sp.symbols("x v lambda")
    y = sp.Symbol("y", positive=True)

    def accel(xs, vs):
        return g - dp * (g + b * vs + d * kbar * xs)

    stages = [(x, v)]
    for c in (sp.Rational(1, 2), sp.Rational(1, 2), 1):
        xs, vs = stages[-1]
        stages.append((x + h * c * vs, v + h * c * accel(xs, vs)))
    weights = (sp.Rational(1, 6), sp.Rational(1, 3), sp.Rational(1, 3), sp.Rational(1, 6))
    x1 = sp.expand(x + h * sum(w * s[1] for w, s in zip(weights, stages, strict=True)))
    v1 = sp.expand(v + h * sum(w * accel(*s) for w, s in zip(weights, stages, strict=True)))
    new = sp.Matrix([x1, v1])
    matrix = new.jacobian([x, v])
    offset = sp.expand(new.subs({x: 0, v: 0}))
    a_mat = sp.Matrix([[0, 1], [-dp * d * kbar, -dp * b]])
    hA = h * a_mat
    taylor = sp.eye(2) + hA + hA**2 / 2 + hA**3 / 6 + hA**4 / 24
    x_star = (1 - dp) * g / (dp * d * kbar)

    def poly(z):
        return 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24

    roots = sp.solve(lam**2 + dp * b * lam + dp * d * kbar, lam)
    return {
        "matrix": sp.expand(matrix),
        "offset": offset,
        "taylor": sp.expand(taylor),
        "equilibrium": sp.Matrix([x_star, 0]),
        "eigenvalues": [poly(h * r) for r in roots],
        "stages": [sp.Matrix([sp.expand(xs), sp.expand(vs)]) for xs, vs in stages],
        "undamped_modulus2": sp.expand(poly(sp.I * y) * poly(-sp.I * y)),
    }


def mujoco_euler_step() -> dict[str, sp.Expr]:
    r"""MuJoCo's ``Euler`` step on one contact in SymPy: the affine map and its powers.

    ``mj_forward`` computes the constraint acceleration from the state at the start of the
    step (impedance ``d``, effective impedance ``d'``, per unit mass, unclipped inside the
    contact); ``mj_Euler`` then updates the velocity first and the position with the new
    velocity (``engine_forward.c``):

    .. math::

        v_1 = v + h\,\bigl(g - d'(g + b\,v + d\bar k\,x)\bigr), \qquad x_1 = x + h\,v_1 .

    ``implicitfast`` solves ``(M - h D)\,a = f`` where ``D`` is the velocity derivative of
    the *smooth* forces (joint damping, actuators); a contact without them has ``D = 0``
    and the same ``a``: the same map (``"implicitfast"`` below builds it that way and
    equals ``"matrix"``). Returns

    * ``"matrix"`` ``M`` and ``"offset"`` ``c`` of ``y -> M y + c``, ``y = (x, v)``;
    * ``"implicitfast"``: the matrix of ``(m - h D) a = f`` with ``D = 0``;
    * ``"trace"``, ``"det"``: ``2 - h d'b - h^2 d' d kbar`` and ``1 - h d' b`` (so a
      complex pair has modulus ``sqrt(1 - h d' b)``);
    * ``"eigenvalues"``: the two roots of ``mu^2 - trace mu + det``;
    * ``"equilibrium"``: the fixed point ``x* = (1 - d') g / (d' d kbar)``, ``v* = 0``;
    * ``"flip_step"``: the step ``h`` where an eigenvalue reaches ``-1`` (the map is
      unstable beyond it): ``4 / (d' b + sqrt(d'^2 b^2 + 4 d' d kbar))``.

    >>> r = mujoco_euler_step()
    >>> sp.simplify(r["matrix"] - r["implicitfast"])
    Matrix([
    [0, 0],
    [0, 0]])
    """
    h, g, b, d, kbar, dp, m = sp.symbols("h g b d kbar d_eff m", positive=True)
    x, v, mu = sp.symbols("x v mu")
    accel = g - dp * (g + b * v + d * kbar * x)
    v1 = v + h * accel
    x1 = x + h * v1
    new = sp.Matrix([x1, v1])
    matrix = sp.expand(new.jacobian([x, v]))
    offset = sp.expand(new.subs({x: 0, v: 0}))
    # implicitfast: (m - h D) a = m accel with D = 0 (no smooth velocity-dependent force)
    smooth_derivative = sp.Integer(0)
    a_if = m * accel / (m - h * smooth_derivative)
    v_if = v + h * a_if
    matrix_if = sp.expand(sp.Matrix([x + h * v_if, v_if]).jacobian([x, v]))
    trace, det = sp.expand(matrix.trace()), sp.factor(matrix.det())
    omega2 = dp * d * kbar
    return {
        "matrix": matrix,
        "offset": offset,
        "implicitfast": matrix_if,
        "trace": trace,
        "det": det,
        "eigenvalues": sp.solve(mu**2 - trace * mu + det, mu),
        "equilibrium": sp.Matrix([(1 - dp) * g / omega2, 0]),
        "flip_step": 4 / (dp * b + sp.sqrt(dp**2 * b**2 + 4 * omega2)),
    }
