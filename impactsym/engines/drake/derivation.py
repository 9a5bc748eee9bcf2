r"""SymPy derivation of Drake's one-contact discrete update (the reference of ``update``).

For one normal degree of freedom (penetration ``x``, approach rate ``u``, mass ``m``,
pressing acceleration ``g``, step ``h``) Drake's discrete plant solves for the new rate
``u'`` (``docs/physics.md``, "Drake point contact"):

* Hunt–Crossley (``"tamsi"``, ``"similar"``, ``"lagged"``), where the impulse is positive:
  :math:`m (u' - u - h g) + h k (x + h u')(1 + d u') = 0`, a quadratic in ``u'``;
* ``"sap"``: :math:`m (u' - u - h g) + (x/(h + \tau) + u')/R = 0`, linear.

:func:`hunt_crossley_roots` solves the quadratic and :func:`hunt_crossley_root` picks the
root that lies where both factors are positive and writes it in the cancellation-free
form :math:`u' = 2c/(b + \sqrt{b^2 + 4ac})` that
:func:`~impactsym.engines.drake.update.hunt_crossley_velocity` evaluates;
:func:`hunt_crossley_residual` is zero when that form solves the update. As ``h -> 0``
the update is the continuous law :math:`m u' = m g - k x (1 + d u)`
(:func:`continuous_limit`).
"""

from __future__ import annotations

from functools import cache

import sympy as sp

__all__ = [
    "continuous_limit",
    "hunt_crossley_equation",
    "hunt_crossley_root",
    "hunt_crossley_roots",
    "sap_root",
]

x, u, k, d, m, g, h, tau, R = sp.symbols("x u k d m g h tau R", positive=True)
unew = sp.Symbol("u'", real=True)


def hunt_crossley_equation() -> sp.Expr:
    """Momentum balance of one update with a positive Hunt–Crossley impulse (``= 0``)."""
    return m * (unew - u - h * g) + h * k * (x + h * unew) * (1 + d * unew)


@cache
def hunt_crossley_roots() -> tuple[sp.Expr, sp.Expr]:
    """The two roots of :func:`hunt_crossley_equation` in ``u'`` (larger first)."""
    a, b, c = stable_coefficients()
    disc = sp.sqrt(b**2 + 4 * a * c)
    return (-b + disc) / (2 * a), (-b - disc) / (2 * a)


@cache
def stable_coefficients() -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """``(a, b, c)`` with :func:`hunt_crossley_equation` ``= a u'^2 + b u' - c``."""
    poly = sp.Poly(sp.expand(hunt_crossley_equation()), unew)
    a, b, c0 = poly.all_coeffs()
    return sp.factor(a), sp.collect(sp.expand(b), h), sp.expand(-c0)


@cache
def hunt_crossley_root() -> sp.Expr:
    """The root of the update: the larger one, in the form ``2c/(b + sqrt(b^2 + 4ac))``.

    Where both factors ``x + h u'`` and ``1 + d u'`` are positive the left side of
    :func:`hunt_crossley_equation` increases strictly with ``u'`` and is negative at the
    edge of that region (the impulse vanishes there and ``u' < u + h g``): one root lies
    inside, the larger; the smaller lies outside and is no impulse of the law.
    """
    a, b, c = stable_coefficients()
    return 2 * c / (b + sp.sqrt(b**2 + 4 * a * c))


def hunt_crossley_residual() -> sp.Expr:
    """Zero: the stable form equals the larger root (rationalized difference)."""
    big, _ = hunt_crossley_roots()
    return sp.simplify(sp.radsimp(hunt_crossley_root() - big))


@cache
def sap_root() -> sp.Expr:
    """The new rate of one ``"sap"`` update with a positive impulse."""
    eq = m * (unew - u - h * g) + (x / (h + tau) + unew) / R
    (root,) = sp.solve(eq, unew)
    return sp.simplify(root)


def continuous_limit() -> sp.Expr:
    """``lim_{h -> 0} (u' - u)/h`` of the Hunt–Crossley update: ``g - k x (1 + d u)/m``."""
    return sp.simplify(sp.limit((hunt_crossley_root() - u) / h, h, 0))
