r"""SymPy: one contact row of Bullet's sequential-impulse solver, as a map per step.

From ``btMultiBodyConstraintSolver::setupMultiBodyContactConstraint`` (bullet3, the solver
of PyBullet's default reduced-coordinate bodies; ``btSequentialImpulseConstraintSolver``
has the same row): with ``contactStiffness`` ``k``, ``contactDamping`` ``c`` and the step
``h``,

.. math::

    \mathrm{erp} = \frac{h k}{h k + c}, \quad \mathrm{cfm} = \frac{1}{h (h k + c)}, \quad
    D = \frac{1}{1/m + \mathrm{cfm}},

the distance ``d = s - x`` (``contactSlop`` ``s``, penetration ``x``) and the normal
velocity after the unconstrained step ``w* = w + g h`` (approach positive) give the
right-hand side ``b = w* - d/h`` (``d > 0``: a speculative contact, the impulse only stops
the crossing) or ``b = w* - erp d / h`` (``d <= 0``). Projected Gauss-Seidel on the one
row, ``lambda <- max(0, lambda + D (b - cfm lambda) - D lambda / m)``, reaches ``lambda =
max(0, D b)`` in its first iteration from any start (warm start) and stays there.
Then ``w' = w* - lambda / m`` and ``x' = x + h w'`` (``integrateTransforms`` moves the
body with the new velocity). :class:`BulletContactRow` writes the row, the step map in
both branches, its matrix (determinant, trace) and the continuous limit ``h -> 0``
(``m x'' = m g - k x - c x'``); :mod:`impactsym.engines.pybullet.stepping` iterates the
map numerically and is tested against these expressions and against PyBullet.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

__all__ = ["BulletContactRow"]


class BulletContactRow:
    """The derivation, as SymPy expressions (attributes are cached).

    >>> row = BulletContactRow()
    >>> sp.simplify(row.pgs_first_iteration - row.D * row.rhs["penetrating"])
    0
    >>> sp.simplify(row.continuous_limit - (row.g - (row.k * row.x + row.c * row.w) / row.m))
    0
    >>> row.determinant
    m/(c*h + h**2*k + m)
    """

    def __init__(self) -> None:
        self.k, self.c, self.m, self.h = sp.symbols("k c m h", positive=True)
        self.g, self.s = sp.symbols("g s", nonnegative=True)
        self.x, self.w, self.lam0 = sp.symbols("x w lambda_0", real=True)

    @cached_property
    def erp(self) -> sp.Expr:
        """``erp = h k / (h k + c)`` (the source's comment and code)."""
        return self.h * self.k / (self.h * self.k + self.c)

    @cached_property
    def cfm(self) -> sp.Expr:
        """``cfm = 1 / (h k + c)`` times ``1 / h`` (``cfm *= invTimeStep``)."""
        return 1 / (self.h * self.k + self.c) / self.h

    @cached_property
    def D(self) -> sp.Expr:
        """``m_jacDiagABInv = 1 / (1/m + cfm)`` (relaxation ``m_sor = 1``)."""
        return 1 / (1 / self.m + self.cfm)

    @cached_property
    def rhs(self) -> dict[str, sp.Expr]:
        """The velocity target ``b`` of the row (``m_rhs / D``) in both branches."""
        w_star = self.w + self.g * self.h
        d = self.s - self.x
        return {"speculative": w_star - d / self.h, "penetrating": w_star - self.erp * d / self.h}

    @cached_property
    def pgs_first_iteration(self) -> sp.Expr:
        """``lambda`` after one Gauss-Seidel sweep from a warm start ``lambda_0`` (unclamped)."""
        b = self.rhs["penetrating"]
        delta = self.D * b - self.D * self.cfm * self.lam0 - self.D * self.lam0 / self.m
        return sp.simplify(self.lam0 + delta)

    def step(self, branch: str) -> tuple[sp.Expr, sp.Expr]:
        """``(x', w')`` of one step with a positive impulse in ``branch``."""
        w1 = self.w + self.g * self.h - self.D * self.rhs[branch] / self.m
        return sp.simplify(self.x + self.h * w1), sp.simplify(w1)

    @cached_property
    def matrix(self) -> sp.Matrix:
        """The step matrix in ``(x, w)`` where the contact pushes (``d <= 0``)."""
        return sp.Matrix(self.step("penetrating")).jacobian([self.x, self.w]).applyfunc(sp.factor)

    @cached_property
    def determinant(self) -> sp.Expr:
        """``det M = m / (m + h c + h^2 k)``: the map contracts for any ``c >= 0``."""
        return sp.factor(self.matrix.det())

    @cached_property
    def trace(self) -> sp.Expr:
        """``tr M = (2 m + h c) / (m + h c + h^2 k)``."""
        return sp.factor(self.matrix.trace())

    @cached_property
    def continuous_limit(self) -> sp.Expr:
        """``lim_{h -> 0} (w' - w) / h`` at ``s = 0``: the spring-dashpot ``g - (k x + c w)/m``."""
        w1 = self.step("penetrating")[1].subs(self.s, 0)
        return sp.limit(sp.simplify((w1 - self.w) / self.h), self.h, 0)
