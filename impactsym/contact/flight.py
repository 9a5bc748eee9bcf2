r"""Free flight after a release of the spring-damper contact: the derivation with SymPy.

After the body leaves the contact it flies under the pressing force alone; normalized on
the first impact (``docs/physics.md``, section 2) its acceleration towards the contact is
:math:`2 D f`. Time ``s`` runs from the release, ``u > 0`` is the speed at which the body
moves away at the release.

*Position condition.* The contact ends at :math:`z = 0` with the element undeformed, so

.. math::  z_b(s) = -u s + D f s^2, \qquad s^* = \frac{2u}{2Df}, \qquad z_b'(s^*) = u,

and the next contact starts undeformed at speed ``u``.

*Force condition.* The contact force :math:`2Dz' + z` vanishes at the release, so the
massless element is still deflected, :math:`z_c = -2Dz'(\tau_c) = 2Du`, and relaxes freely
(:math:`2 D z_e' + z_e = 0`) while the body flies:

.. math::  z_e(s) = 2Du\, e^{-s/(2D)}, \qquad z_b(s) = 2Du - u s + D f s^2 .

With :math:`x = s/(2D)` and :math:`r = 2D^2 f/u` the gap is

.. math::  h = z_b - z_e = 2 D u\, x^2\, \bigl(r - \psi(x)\bigr), \qquad
           \psi(x) = \frac{x - 1 + e^{-x}}{x^2} = \int_0^1 (1 - t)\, e^{-x t}\, dt .

The integral shows that :math:`\psi` falls strictly from :math:`\psi(0) = 1/2` to
:math:`0`. The release is transversal (the contact force crosses zero with slope
:math:`4D^2f - u < 0`) exactly when :math:`r < 1/2`, so for :math:`0 < r < 1/2` the body
re-contacts the element at the *unique* root :math:`x^*` of :math:`\psi(x) = r`, and for
``f = 0`` never. Bounding the integrand, :math:`e^{-xt} \ge 1 - xt` gives
:math:`\psi(x) \ge 1/2 - x/6` and :math:`\psi(x) < 1/x`, so

.. math::  3 - 6 r \;\le\; x^* \;<\; 1/r,

a bracket that provably holds the root (no sampling). The body arrives with velocity
(positive into the contact) and meets the element deflected by

.. math::  v^* = z_b'(s^*) = u\,(2 r x^* - 1), \qquad z^* = 2 D u\, e^{-x^*};

:math:`v^* < 0` (the element catches the body from behind) happens for
:math:`r > 1/(2 x_0) \approx 0.314`, with :math:`(1 - e^{-x_0})/x_0 = 1/2`. The contact
force at the re-contact, :math:`2 D v^* + z^* = -2 D u\, x^{*2}\, \psi'(x^*)`, is positive.
"""

from __future__ import annotations

from functools import cache

import sympy as sp
from sympy.codegen.cfunctions import expm1

from impactsym.contact.derivation import D, f
from impactsym.validation import check_condition

s = sp.Symbol("s", nonnegative=True)
u = sp.Symbol("u", positive=True)
x = sp.Symbol("x", nonnegative=True)
r = sp.Symbol("r", nonnegative=True)

#: below this x the numeric chi uses its Taylor series (the closed form cancels)
SERIES_BELOW = 1


class FreeFlight:
    r"""Body, element and gap during the free flight after a force-condition release.

    Attributes
    ----------
    body, element, gap
        :math:`z_b(s)`, :math:`z_e(s)` and :math:`h = z_b - z_e` (symbols ``s, u, D, f``).
    psi
        :math:`\psi(x) = (x - 1 + e^{-x})/x^2`; the re-contact equation is
        :math:`\psi(x) = r`.
    reduced_gap
        :math:`2 D u x^2 (r - \psi(x))` with :math:`x = s/(2D)`, :math:`r = 2D^2f/u`.
    arrival_velocity, arrival_deflection
        :math:`v^*` and :math:`z^*` as functions of the root ``x`` and ``u, D, f``.
    chi, chi_numeric, chi_dot_numeric
        :math:`\chi(x) = x\psi(x)`, so that the re-contact is the root of
        :math:`\chi(x) - r x` (same sign as :math:`\psi - r` for :math:`x > 0`), and its
        float-stable forms: Taylor series below ``SERIES_BELOW``, ``expm1`` form above.

    Examples
    --------
    >>> flight = FreeFlight()
    >>> sp.limit(flight.psi, x, 0), sp.limit(flight.psi, x, sp.oo)
    (1/2, 0)
    >>> sp.simplify(flight.gap.subs(s, 2 * D * x) - flight.reduced_gap.subs(r, 2 * D**2 * f / u))
    0
    """

    @property
    def body(self) -> sp.Expr:
        """Body penetration: released at z_c = 2 D u with speed -u, accelerated by 2 D f."""
        return 2 * D * u - u * s + D * f * s**2

    @property
    def element(self) -> sp.Expr:
        """Deflection of the freely relaxing massless element, 2 D z_e' + z_e = 0."""
        return 2 * D * u * sp.exp(-s / (2 * D))

    @property
    def gap(self) -> sp.Expr:
        """h = z_b - z_e: negative while the body is off the element."""
        return self.body - self.element

    @property
    def psi(self) -> sp.Expr:
        """The decreasing function of the re-contact equation psi(x) = r."""
        return (x - 1 + sp.exp(-x)) / x**2

    @property
    def reduced_gap(self) -> sp.Expr:
        """The gap written through psi: 2 D u x^2 (r - psi(x))."""
        return 2 * D * u * x**2 * (r - self.psi)

    @property
    def arrival_velocity(self) -> sp.Expr:
        """Body velocity at the re-contact, z_b'(2 D x), positive into the contact."""
        return sp.diff(self.body, s).subs(s, 2 * D * x)

    @property
    def arrival_deflection(self) -> sp.Expr:
        """Element deflection at the re-contact, z_e(2 D x)."""
        return self.element.subs(s, 2 * D * x)

    def latex(self, name: str, *, condition: str | None = None) -> str:
        r"""LaTeX of the attribute ``name`` (``body``, ``element``, ``gap``, ``psi``,
        ``reduced_gap``, ``arrival_velocity``, ``arrival_deflection``); the flight is the
        same for both conditions, so ``condition`` is accepted and ignored (the one
        ``latex`` signature of the derivation objects).

        >>> FreeFlight().latex("element")
        '2 D u e^{- \\frac{s}{2 D}}'
        """
        if name not in _ATTRIBUTES:
            raise ValueError(f"name must be one of {sorted(_ATTRIBUTES)}, got {name!r}")
        if condition is not None:
            check_condition(condition)
        return sp.latex(getattr(self, name))

    def _series(self, expr: sp.Expr) -> sp.Expr:
        return sp.series(expr, x, 0, 22).removeO()

    @property
    def chi(self) -> sp.Expr:
        """x psi(x) = (x - 1 + exp(-x))/x: the re-contact equation as chi(x) = r x."""
        return sp.cancel(x * self.psi)

    @property
    def chi_numeric(self) -> sp.Expr:
        """chi for floats: series below SERIES_BELOW, (expm1(-x) + x)/x above (no
        overflow for any float x, unlike psi' with its x^3)."""
        closed = (expm1(-x) + x) / x
        return sp.Piecewise((self._series(self.chi), x < SERIES_BELOW), (closed, True))

    @property
    def chi_dot_numeric(self) -> sp.Expr:
        """chi'(x) for floats: (-expm1(-x) - x exp(-x))/x^2 above SERIES_BELOW."""
        closed = (-expm1(-x) - x * sp.exp(-x)) / x**2
        series = self._series(sp.diff(self.chi, x))
        return sp.Piecewise((series, x < SERIES_BELOW), (closed, True))


_ATTRIBUTES = {
    "body",
    "element",
    "gap",
    "psi",
    "reduced_gap",
    "arrival_velocity",
    "arrival_deflection",
}


@cache
def free_flight() -> FreeFlight:
    """The (cached) free-flight derivation.

    >>> free_flight() is free_flight()
    True
    """
    return FreeFlight()
