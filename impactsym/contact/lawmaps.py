r"""Nonlinear contact laws: the results in closed form, derived with SymPy (no pressing force).

* **Hunt–Crossley** :math:`z'' = -z^p (1 + s z')`. In the phase plane (``w = z'`` as a
  function of ``z``) the law separates: :math:`\frac{w\,dw}{1 + s w} = -z^p\,dz`. Between
  touch (``w = 1``) and exit (``w = -e``) the right side integrates to zero, so
  :math:`G(-e) = G(1)` with :math:`G(w) = w/s - \ln(1 + s w)/s^2`, whose root other than
  :math:`e = -1` is

  .. math::  e = \frac{1 + W_0\!\left(-(1 + s)\,e^{-(1 + s)}\right)}{s},

  independent of ``p`` and ``k``; the force :math:`z^p(1 + s w)` stays compressive
  (:math:`s e < 1`), so both conditions end at ``z = 0``. The maximum penetration follows
  from :math:`z_{max}^{p+1}/(p+1) = G(1) - G(0)`, the contact time is the quadrature
  :math:`\tau_c = \int_{-e}^{1} dw / \bigl((1 + s w)\, z(w)^p\bigr)`.
* **Power law with Tsuji damping** :math:`z'' = -z^p - \alpha z^{(p-1)/2} z'`. With
  :math:`x = c\, z^{(p+1)/2}`, :math:`c = \sqrt{2/(p+1)}`, the phase-plane equation
  becomes :math:`w\,dw/dx + 2\zeta w + x = 0`, the linear contact's, with
  :math:`\zeta = \alpha/\sqrt{2(p+1)}` (Antypov & Elliott 2011); the force is
  :math:`z^{(p-1)/2} (\alpha w + z^{(p+1)/2}) = z^{(p-1)/2} (2\zeta w + x)/c`, so it
  vanishes where the linear contact's force does. The velocity at the end is therefore
  the linear contact's under either condition; only time is not mapped.

:class:`HuntCrossleyClosedForm` and :class:`TsujiMap` expose the expressions and their
residual checks (:attr:`residual`), which the tests drive to zero.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from impactsym.contact.laws import alpha, contact_law, p, s, w, z
from impactsym.symbolic.typeset import latex

e = sp.Symbol("e", positive=True)
x = sp.Symbol("x", positive=True)
zeta = sp.Symbol("zeta", positive=True)


class HuntCrossleyClosedForm:
    r"""The Hunt–Crossley impact without pressing force, in closed form.

    Examples
    --------
    >>> hc = HuntCrossleyClosedForm()
    >>> hc.restitution
    (LambertW((-s - 1)*exp(-s - 1)) + 1)/s
    >>> round(float(hc.restitution.subs(s, 2.083)), 4)
    0.3999
    """

    @cached_property
    def energy_integral(self) -> sp.Expr:
        r""":math:`G(w) = \int w/(1 + s w)\,dw`."""
        return sp.integrate(w / (1 + s * w), w)

    @cached_property
    def exit_equation(self) -> sp.Expr:
        r""":math:`G(-e) - G(1) = 0` times :math:`s^2`, written with logarithms."""
        G = self.energy_integral
        return sp.expand(s**2 * (G.subs(w, -e) - G.subs(w, 1)))

    @cached_property
    def restitution(self) -> sp.Expr:
        r""":math:`e(s) = (1 + W_0(-(1+s) e^{-(1+s)}))/s`."""
        return (1 + sp.LambertW(-(1 + s) * sp.exp(-(1 + s)))) / s

    @cached_property
    def residual(self) -> sp.Expr:
        r"""The exit equation with :math:`e(s) = (1 - V)/s`, :math:`V = -W_0 \in (0, 1)`,
        substituted and :math:`\ln V = \ln(1+s) - (1+s) + V` (the defining identity
        :math:`W e^W = -(1+s) e^{-(1+s)}`) applied: simplifies to 0."""
        V = sp.Symbol("V", positive=True)  # V = -W in (0, 1)
        eq = self.exit_equation.subs(e, (1 - V) / s)
        eq = sp.expand(eq).subs(sp.log(V), sp.log(1 + s) - (1 + s) + V)
        return sp.simplify(eq)

    @cached_property
    def max_penetration(self) -> sp.Expr:
        r""":math:`z_{max} = \bigl((p+1)(1/s - \ln(1+s)/s^2)\bigr)^{1/(p+1)}`."""
        G = self.energy_integral
        return ((p + 1) * sp.simplify(G.subs(w, 1) - G.subs(w, 0))) ** (1 / (p + 1))

    @cached_property
    def overlap(self) -> sp.Expr:
        r""":math:`z(w)` on the trajectory: :math:`z^{p+1}/(p+1) = G(1) - G(w)`."""
        G = self.energy_integral
        return ((p + 1) * (G.subs(w, 1) - G)) ** (1 / (p + 1))

    @cached_property
    def contact_time_integrand(self) -> sp.Expr:
        r""":math:`1/((1 + s w) z(w)^p)`, to integrate over :math:`-e < w < 1`
        (:math:`d\tau = dz/w = -dw/((1 + sw) z^p)`)."""
        return 1 / ((1 + s * w) * self.overlap**p)

    def latex(self) -> str:
        r"""The restitution and the contact-time quadrature in LaTeX.

        >>> HuntCrossleyClosedForm().latex().startswith("e = ")
        True
        """
        return (
            rf"e = {latex(self.restitution)}, \qquad "
            rf"\tau_c = \int_{{-e}}^{{1}} {latex(self.contact_time_integrand)}\, dw"
        )


class TsujiMap:
    r"""The power law with Tsuji damping mapped onto the linear contact.

    Examples
    --------
    >>> tm = TsujiMap()
    >>> tm.zeta
    alpha/sqrt(2*p + 2)
    >>> tm.residual, tm.force_residual
    (0, 0)
    """

    @cached_property
    def scale(self) -> sp.Expr:
        """:math:`c = \\sqrt{2/(p+1)}` in :math:`x = c z^{(p+1)/2}`."""
        return sp.sqrt(2 / (p + 1))

    @cached_property
    def zeta(self) -> sp.Expr:
        r""":math:`\zeta = \alpha/\sqrt{2(p+1)}`."""
        return alpha / sp.sqrt(2 * (p + 1))

    @cached_property
    def residual(self) -> sp.Expr:
        r"""The phase-plane equation :math:`w\,dw/dz = -\varphi(z, w)` of the law, divided
        by :math:`dx/dz`, minus :math:`(-2\zeta w - x)` of the linear contact: 0."""
        law = contact_law("tsuji")
        x_of_z = self.scale * z ** ((p + 1) / 2)
        dxdz = sp.diff(x_of_z, z)
        lhs = -law.phi / dxdz  # w dw/dx
        linear = -2 * self.zeta * w - x_of_z
        difference = sp.powsimp(sp.expand(lhs - linear), force=True)
        return sp.simplify(sp.factor(difference.subs(p, sp.Symbol("P", positive=True) - 1)))

    @cached_property
    def force_residual(self) -> sp.Expr:
        r""":math:`\varphi - z^{(p-1)/2} (2\zeta w + x)/c`: 0, so both forces vanish together."""
        law = contact_law("tsuji")
        x_of_z = self.scale * z ** ((p + 1) / 2)
        mapped = z ** ((p - 1) / 2) * (2 * self.zeta * w + x_of_z) / self.scale
        return sp.simplify(sp.powsimp(sp.expand(law.phi - mapped), force=True))

    def latex(self) -> str:
        r"""The map in LaTeX.

        >>> print(TsujiMap().latex())  # doctest: +ELLIPSIS
        x = ...
        """
        return (
            rf"x = {latex(self.scale * z ** ((p + 1) / 2))}, \qquad "
            rf"w \frac{{dw}}{{dx}} + 2 \zeta w + x = 0, \qquad \zeta = {latex(self.zeta)}"
        )
