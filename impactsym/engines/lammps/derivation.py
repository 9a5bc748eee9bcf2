r"""SymPy: LAMMPS's velocity-Verlet step applied to one Hooke contact, and the coast.

From ``fix nve/sphere`` (``initial_integrate``: ``v += dt/2 f/m``, ``x += dt v``; forces
at the new positions with that half-step velocity; ``final_integrate``: ``v += dt/2
f/m``) and the granular Hooke force ``F = kn x + eta w`` (overlap ``x``, overlap rate
``w``; ``fix gravity`` adds ``m g``), with ``w_n = v_{n-1/2}``:

.. math::

    a_n = g - (k_n x_n + \eta w_n)/m, \quad w_{n+1} = w_n + h a_n, \quad
    x_{n+1} = x_n + h w_{n+1}, \quad v_n = w_n + \tfrac{h}{2} a_n.

:class:`VerletHooke` writes the normalized step map ``M``, its offset, fixed point,
determinant, trace, characteristic polynomial and Jury stability limit, the free flight
before touch (exact under velocity-Verlet: the first state's overlap and half-step
velocity) and the continuous coast after a force zero under ``limit_damping`` (the band
``e < 4 D load`` and the departure speed ``v0 sqrt(e (e - 4 D load))``).
:mod:`impactsym.engines.lammps.verlet` and :func:`impactsym.engines.lammps.hooke.coast`
write them in closed form and are tested against these expressions.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

__all__ = ["VerletHooke"]


class VerletHooke:
    """The derivation, as SymPy expressions (attributes are cached).

    >>> vh = VerletHooke()
    >>> sp.expand(vh.determinant), sp.expand(vh.trace)
    (-2*D*tau + 1, -2*D*tau - tau**2 + 2)
    >>> sp.simplify(vh.stability_limit - 2 / (vh.D + sp.sqrt(1 + vh.D**2)))
    0
    """

    def __init__(self) -> None:
        self.k, self.eta, self.m, self.h = sp.symbols("k_n eta m h", positive=True)
        self.g = sp.symbols("g", nonnegative=True)
        self.omega, self.v0 = sp.symbols("omega_0 v_0", positive=True)
        self.D, self.tau = sp.symbols("D tau", positive=True)
        self.load = sp.symbols("L", nonnegative=True)
        self.x, self.w = sp.symbols("x w", real=True)
        self.p = sp.symbols("p", nonnegative=True)

    @cached_property
    def step(self) -> tuple[sp.Expr, sp.Expr]:
        """``(x_{n+1}, w_{n+1})`` of LAMMPS's update in contact (SI symbols)."""
        a = self.g - (self.k * self.x + self.eta * self.w) / self.m
        w1 = self.w + self.h * a
        return self.x + self.h * w1, w1

    @cached_property
    def normalized(self) -> dict[sp.Symbol, sp.Expr]:
        """``kn = m omega0^2``, ``eta = 2 D m omega0``, ``h = tau/omega0``, ``g = L omega0 v0``."""
        return {
            self.k: self.m * self.omega**2,
            self.eta: 2 * self.D * self.m * self.omega,
            self.h: self.tau / self.omega,
            self.g: self.load * self.omega * self.v0,
        }

    @cached_property
    def step_normalized(self) -> tuple[sp.Expr, sp.Expr]:
        """The step in ``z = x omega0 / v0``, ``w / v0`` (both components)."""
        z, u = sp.symbols("z u", real=True)
        sub = {**self.normalized, self.x: z * self.v0 / self.omega, self.w: u * self.v0}
        x1, w1 = (sp.expand(e.subs(sub)) for e in self.step)
        return sp.expand(x1 * self.omega / self.v0).subs({z: self.x, u: self.w}), sp.expand(
            w1 / self.v0
        ).subs({z: self.x, u: self.w})

    @cached_property
    def matrix(self) -> sp.Matrix:
        """The step matrix ``M`` (Jacobian of the normalized step)."""
        return sp.Matrix(self.step_normalized).jacobian([self.x, self.w]).applyfunc(sp.factor)

    @cached_property
    def fixed_point(self) -> dict[sp.Symbol, sp.Expr]:
        """``x = L``, ``w = 0``: the static overlap ``m g / kn``."""
        eqs = [sp.Eq(s, v) for s, v in zip(self.step_normalized, (self.x, self.w), strict=True)]
        return sp.solve(eqs, [self.x, self.w], dict=True)[0]

    @cached_property
    def determinant(self) -> sp.Expr:
        """``det M = 1 - 2 D tau``."""
        return sp.factor(self.matrix.det())

    @cached_property
    def trace(self) -> sp.Expr:
        """``tr M = 2 - tau^2 - 2 D tau``."""
        return sp.expand(self.matrix.trace())

    @cached_property
    def discriminant(self) -> sp.Expr:
        """``tr^2 - 4 det = tau^2 ((tau + 2 D)^2 - 4)``: complex eigenvalues below 0."""
        return sp.factor(self.trace**2 - 4 * self.determinant)

    @cached_property
    def stability_limit(self) -> sp.Expr:
        """The Jury bound ``1 + tr + det = 0`` solved for ``tau > 0``."""
        roots = sp.solve(sp.Eq(1 + self.trace + self.determinant, 0), self.tau)
        return next(r for r in roots if sp.simplify(r.subs(self.D, 1)) > 0)

    @cached_property
    def first_state(self) -> tuple[sp.Expr, sp.Expr]:
        """Overlap and half-step rate of state 0, touch ``p`` steps before (normalized).

        Free flight from state ``-1`` (no force, ``a = L``) by one Verlet step, starting
        from the exact free-flight state at ``t = (p - 1) tau``.
        """
        t = (self.p - 1) * self.tau
        x_prev, v_prev = t + self.load * t**2 / 2, 1 + self.load * t
        w0 = v_prev + self.tau * self.load / 2
        return sp.expand(x_prev + self.tau * w0), sp.expand(w0)

    @cached_property
    def coast(self) -> dict[str, sp.Expr]:
        """After a force zero (``z = 2 D e``, ``z' = -e``), free flight under ``L``.

        ``reengage``: the time at which the force ``z + 2 D z'`` is zero again;
        ``overlap_there``: ``z`` at that time (positive: the body sticks);
        ``departure``: ``z'^2`` at ``z = 0``.
        """
        e, s = sp.symbols("e s", positive=True)
        z = 2 * self.D * e - e * s + self.load * s**2 / 2
        force = sp.factor(z + 2 * self.D * sp.diff(z, s))
        reengage = next(r for r in sp.solve(force, s) if r != 0)
        return {
            "reengage": reengage,
            "overlap_there": sp.factor(z.subs(s, reengage)),
            "departure": sp.expand(e**2 - 2 * self.load * z.subs(s, 0)),
        }
