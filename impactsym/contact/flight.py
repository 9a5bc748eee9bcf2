r"""Free flight after a release of the spring-damper contact: the derivation with SymPy.

After the body leaves the contact it flies under the pressing force alone (acceleration
:math:`2 D f` towards the contact, normalized on the first impact); time ``s`` runs from
the release, ``u > 0`` is the speed of departure. Under the force condition the massless
element is released still deflected by :math:`2Du` and relaxes freely, so with
:math:`x = s/(2D)` and :math:`r = 2D^2 f/u` the gap between body and element is

.. math::  h = z_b - z_e = 2 D u\, x^2\, \bigl(r - \psi(x)\bigr), \qquad
           \psi(x) = \frac{x - 1 + e^{-x}}{x^2} .

:math:`\psi` falls strictly from :math:`1/2` to :math:`0`, so for :math:`0 < r < 1/2` the
re-contact is the unique root of :math:`\psi(x) = r`, and elementary bounds on
:math:`\psi` bracket it, :math:`3 - 6 r \le x^* < 1/r`: the root is found by a
bracketed Newton method, never by sampling. The proof, the arrival state and the
position-condition flight: See `docs/physics.md#free-flight`.
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
