r"""Restitution of the viscoelastic Hertz contact as a series in its damping number.

The normalized viscoelastic contact of :mod:`impactsym.contact.laws` (no pressing force),

.. math::  z'' = -z^{3/2} - \beta z^{1/2} z', \qquad z(0) = 0,\ z'(0) = 1,
           \qquad \beta = \tfrac32 A (k/m)^{2/5} v_0^{1/5},

restitutes (``docs/physics.md``, "The viscoelastic restitution as a series")

.. math::  e = \sum_{j \ge 0} h_j\, \beta^{j/2},

with :math:`h_j = 0` for odd :math:`j` under the position condition (:math:`e` analytic in
:math:`\beta`) and the first odd term at :math:`\beta^{5/2}` under the force condition
(the delayed recovery of Schwager & Pöschel 2008: the force vanishes at
:math:`z = \beta |z'|` before the overlap does). :math:`h_2 = -C_1`,
:math:`h_4 = C_2 = \tfrac35 C_1^2` with
:math:`C_1 = \tfrac25 (5/4)^{3/5} \sqrt{\pi}\, \Gamma(3/5)/\Gamma(21/10) = 1.15344...`,
the constants of Ramírez et al. 1999 in this :math:`\beta`.

The derivation (no fit):

1. **Reduction to one universal function.** On either branch, :math:`w = z'^2` obeys
   :math:`dw/dz = -2 z^{3/2} \mp 2\beta z^{1/2} \sqrt{w}` with :math:`w = 0` at the
   turning point :math:`z_m`. With :math:`u = z/z_m`, :math:`P = z_m^{5/2}`,
   :math:`w = \tfrac45 P\, y(u)` and :math:`\gamma = 2\sqrt{5/4}\,\beta P^{1/10}` both
   branches become :math:`y(u) = 1 - u^{5/2} + g \int_u^1 t^{1/2} \sqrt{y(t)}\, dt` with
   :math:`g = \gamma` (compression) and :math:`g = -\gamma` (restitution)
   (:func:`reduction_residual` checks it by substitution). The touch :math:`w(0) = 1`
   and the exit give, with :math:`Y(g) = y(0; g)`,

   .. math::  e^2 = \frac{Y(-\gamma)}{Y(\gamma)}, \qquad
              \gamma = \kappa \beta\, Y(\gamma)^{-1/10}, \quad \kappa = 2 (5/4)^{3/5}.

   The moving turning point is absorbed in :math:`u` and :math:`P`; only the odd part of
   :math:`\ln Y` enters :math:`e`.
2. **Regular perturbation of** :math:`y` in :math:`g`:
   :math:`y = \sum g^n y_n`, :math:`\sqrt y = \sum g^n s_n`, :math:`y_0 = 1 - u^{5/2}`,
   :math:`y_n(u) = \int_u^1 t^{1/2} s_{n-1}\, dt`,
   :math:`s_n = (y_n - \sum_{i=1}^{n-1} s_i s_{n-i})/(2 s_0)`, and
   :math:`Y(g) = 1 + \sum c_n g^n`, :math:`c_n = y_n(0)`. :math:`c_1 = \tfrac25
   B(\tfrac35, \tfrac32)` is a Beta function; from :math:`c_2` on the integrals are
   iterated (:func:`universal_coefficients` evaluates them with mpmath, see there).
3. **Series algebra** (exact, over polynomials in :math:`c_n` and :math:`\kappa` with
   rational coefficients): :math:`\gamma(\beta)` by fixed-point iteration, then
   :math:`e`. A coefficient that involves :math:`c_1` only is exact in Gamma functions.
4. **Force condition.** Until :math:`z = \beta |z'|` both conditions share the path, so
   the force condition's restitution follows from the position condition's :math:`e_p`
   through the last stretch: with :math:`z = \beta e_p r^2` and
   :math:`|z'| = e_p S(r)`, :math:`dS/dr = 2t (r^2 - r^4/S)`, :math:`S(0) = 1`,
   :math:`t = \beta^{5/2} e_p^{1/2}`, and the force vanishes at :math:`r^2 = S`. Hence

   .. math::  e_f = e_p\, G\!\left(\beta^{5/2} e_p^{1/2}\right), \qquad
              G(t) = 1 + \tfrac{4}{15} t + \tfrac{13}{150} t^2 + \dots

   with rational coefficients (:func:`delayed_recovery_coefficients`, exact).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cache

import mpmath
import numpy as np
import sympy as sp
from sympy.polys.domains import QQ
from sympy.polys.rings import ring

from impactsym.numeric.precision import workdps
from impactsym.records import ArrayRecord
from impactsym.validation import check_condition, real_array

ArrayLike = float | np.ndarray

#: :math:`\kappa = 2 (5/4)^{3/5}`: :math:`\gamma = \kappa\beta` to leading order.
KAPPA = 2 * sp.Rational(5, 4) ** sp.Rational(3, 5)
#: :math:`c_1 = \tfrac25 B(3/5, 3/2) = \int_0^1 t^{1/2} (1 - t^{5/2})^{1/2} dt`.
C1_UNIVERSAL = (
    sp.Rational(2, 5) * sp.gamma(sp.Rational(3, 5)) * sp.gamma(sp.Rational(3, 2))
    / sp.gamma(sp.Rational(21, 10))
)  # fmt: skip

beta = sp.Symbol("beta", positive=True)


def reduction_residual() -> sp.Expr:
    r"""Zero when the reduction to the universal :math:`y(u; g)` is right (SymPy).

    Substitutes :math:`z = P^{2/5} u`, :math:`w = \tfrac45 P y` and
    :math:`y'(u) = -\tfrac52 u^{3/2} - g u^{1/2} \sqrt{y}` with
    :math:`g = \pm 2\sqrt{5/4}\,\beta P^{1/10}` into
    :math:`dw/dz + 2 z^{3/2} \pm 2\beta z^{1/2}\sqrt{w}` for both branches and returns the
    sum of the squared, simplified differences.

    >>> reduction_residual()
    0
    """
    P, u, y = sp.symbols("P u y", positive=True)
    total = sp.Integer(0)
    for sign in (1, -1):
        g = sign * 2 * sp.sqrt(sp.Rational(5, 4)) * beta * P ** sp.Rational(1, 10)
        dy_du = -sp.Rational(5, 2) * u ** sp.Rational(3, 2) - g * sp.sqrt(u) * sp.sqrt(y)
        z = P ** sp.Rational(2, 5) * u
        w = sp.Rational(4, 5) * P * y
        dw_dz = sp.Rational(4, 5) * P * dy_du / P ** sp.Rational(2, 5)
        residual = dw_dz + 2 * z ** sp.Rational(3, 2) + sign * 2 * beta * sp.sqrt(z) * sp.sqrt(w)
        total += sp.simplify(sp.expand(residual)) ** 2
    return sp.simplify(total)


@cache
def universal_coefficients(order: int, *, nodes: int = 48, dps: int = 40) -> tuple:
    r"""Taylor coefficients :math:`c_0, \dots, c_{order}` of :math:`Y(g) = y(0; g)`.

    Evaluates the perturbation hierarchy of step 2 of the module docstring with mpmath at
    ``dps`` digits. With :math:`u = \sin^2\theta` every :math:`y_n` and :math:`s_n` is
    analytic in :math:`\theta \in [0, \pi/2]` (the half-integer powers of :math:`u` at
    touch and of :math:`1 - u` at the turning point become powers of :math:`\sin\theta`
    and :math:`\cos\theta`; :math:`s_0 = \cos\theta \sqrt{(1 - \sin^5\theta)/(1 -
    \sin^2\theta)}`), so the integrals :math:`y_n(u) = \int_u^1 t^{1/2} s_{n-1} dt` are
    taken spectrally: values at ``nodes`` Chebyshev points of the first kind in
    :math:`\theta` (interior, so :math:`s_0 \ne 0`), Chebyshev coefficients, their exact
    antiderivative. The error falls geometrically with ``nodes`` (48 nodes give about 20
    digits; :func:`viscoelastic_restitution_series` states the precision by comparing two
    resolutions).

    Examples
    --------
    >>> c = universal_coefficients(2)
    >>> with mpmath.workdps(40):
    ...     c_1 = mpmath.mpf(2) / 5 * mpmath.beta(mpmath.mpf(3) / 5, mpmath.mpf(3) / 2)
    ...     bool(abs(c[1] - c_1) < 1e-18), mpmath.nstr(c[2], 15)
    (True, '0.0793550465879704')
    """
    for name, value, least in (("order", order, 0), ("nodes", nodes, 8), ("dps", dps, 20)):
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            raise ValueError(f"{name} must be an integer >= {least}; got {value!r}")
    with workdps(dps):
        cos, sin = np.frompyfunc(mpmath.cos, 1, 1), np.frompyfunc(mpmath.sin, 1, 1)
        sqrt = np.frompyfunc(mpmath.sqrt, 1, 1)
        mpf = np.frompyfunc(mpmath.mpf, 1, 1)
        phi = mpf(np.arange(nodes) + 0.5) * mpmath.pi / nodes
        chebyshev = cos(np.outer(np.arange(nodes + 1), phi))  # T_n(x_j), n = 0..nodes
        theta = (chebyshev[1] + 1) * mpmath.pi / 4
        sn, cs = sin(theta), cos(theta)
        degrees = mpf(np.arange(1, nodes + 1))
        alternating = mpf((-1.0) ** np.arange(nodes + 1))

        def integral_to_turn(values: np.ndarray) -> tuple[np.ndarray, object]:
            """:math:`\\int_x^1 f` at the nodes and at :math:`x = -1`, times dtheta/dx."""
            a = chebyshev[:nodes].dot(values) * 2 / nodes
            a[0] = a[0] / 2
            lower = np.concatenate([[2 * a[0]], a[1:]])
            upper = np.concatenate([a[2:], [0, 0]])
            b = np.concatenate([[mpmath.mpf(0)], (lower - upper) / (2 * degrees)])
            top = b.sum()
            scale = mpmath.pi / 4
            return (top - chebyshev.T.dot(b)) * scale, (top - alternating.dot(b)) * scale

        s = [sqrt(1 - sn**5)]
        c = [mpmath.mpf(1)]
        for n in range(1, order + 1):
            # dt = 2 sin cos dtheta, t^(1/2) = sin
            y_n, c_n = integral_to_turn(2 * sn**2 * cs * s[n - 1])
            c.append(c_n)
            cross = sum((s[i] * s[n - i] for i in range(1, n)), np.zeros(nodes, dtype=object))
            s.append((y_n - cross) / (2 * s[0]))
        return tuple(+value for value in c)


@cache
def delayed_recovery_coefficients(terms: int) -> tuple[Fraction, ...]:
    r"""Coefficients :math:`g_0, \dots, g_{terms}` of :math:`G(t)` in
    :math:`e_f = e_p\, G(\beta^{5/2} e_p^{1/2})` (module docstring, step 4), exact.

    :math:`S = \sum t^n S_n(r)` with polynomials :math:`S_n` from
    :math:`S_n = \int_0^r 2(\rho^2 [n = 1] - \rho^4 I_{n-1})\, d\rho`, :math:`I = 1/S`;
    the exit :math:`r_*^2 = S(r_*)` by fixed-point iteration in :math:`t`;
    :math:`G = r_*^2`. Rational arithmetic throughout.

    >>> [str(g) for g in delayed_recovery_coefficients(3)]
    ['1', '4/15', '13/150', '4897/160875']
    """
    n = terms

    def poly_mul(a: list, b: list) -> list:
        out = [Fraction(0)] * (len(a) + len(b) - 1)
        for i, x in enumerate(a):
            for j, y in enumerate(b):
                out[i + j] += x * y
        return out

    def poly_add(a: list, b: list) -> list:
        size = max(len(a), len(b))
        return [(a[i] if i < len(a) else 0) + (b[i] if i < len(b) else 0) for i in range(size)]

    S, inverse = [[Fraction(1)]], [[Fraction(1)]]
    for order in range(1, n + 1):
        integrand = [-2 * x for x in poly_mul([0, 0, 0, 0, 1], inverse[order - 1])]
        if order == 1:
            integrand = poly_add(integrand, [0, 0, 2])
        S.append([Fraction(0)] + [x / (i + 1) for i, x in enumerate(integrand)])
        acc = [Fraction(0)]
        for k in range(1, order + 1):
            acc = poly_add(acc, poly_mul(S[k], inverse[order - k]))
        inverse.append([-x for x in acc])
    one = [Fraction(1)] + [Fraction(0)] * n
    root = list(one)
    for _ in range(n + 1):
        powers = [one]
        for _ in range(1, max(len(p) for p in S)):
            powers.append(series_mul(powers[-1], root))
        value = [Fraction(0)] * (n + 1)
        for m, S_m in enumerate(S):
            for d, coefficient in enumerate(S_m):
                for k in range(n + 1 - m):
                    value[k + m] += coefficient * powers[d][k]
        root = series_power(value, Fraction(1, 2))
    return tuple(series_mul(root, root))


def series_mul(a: list, b: list) -> list:
    """Product of two truncated power series of equal length (coefficients of any ring)."""
    return [sum((a[i] * b[k - i] for i in range(1, k + 1)), a[0] * b[k]) for k in range(len(a))]


def series_power(a: list, exponent: object) -> list:
    r"""``a**exponent`` of a truncated power series with :math:`a_0 = 1` (J. C. P. Miller's
    recurrence :math:`k b_k = \sum_{j=1}^k ((\alpha + 1) j - k) a_j b_{k-j}`)."""
    b = [a[0] ** 0] + [a[0] * 0] * (len(a) - 1)
    for k in range(1, len(a)):
        b[k] = sum(((exponent + 1) * j - k) * a[j] * b[k - j] for j in range(1, k + 1)) / k
    return b


@cache
def position_polynomials(order: int) -> tuple:
    r""":math:`h_0, \dots, h_{order}` of :math:`e_p = \sum h_k \beta^k` as polynomials in
    :math:`c_1, \dots, c_{order}` and :math:`\kappa` with rational coefficients (SymPy
    expressions): step 3 of the module docstring.

    >>> position_polynomials(2)[1:]
    (-c_1*kappa, 3*c_1**2*kappa**2/5)
    """
    names = [f"c_{n}" for n in range(1, order + 1)] + ["kappa"]
    R, *gens = ring(",".join(names), QQ)
    c, kappa = [R.one, *gens[:-1]], gens[-1]
    zero = [R.zero] * (order + 1)
    gamma = list(zero)
    if order >= 1:
        gamma[1] = kappa
    for _ in range(order):
        Y = compose(c, gamma)
        factor = series_power(Y, QQ(-1, 10))
        gamma = [R.zero] + [kappa * x for x in factor[:-1]]
    Y_plus = compose(c, gamma)
    Y_minus = compose([(-1) ** n * x for n, x in enumerate(c)], gamma)
    e_squared = series_mul(Y_minus, series_power(Y_plus, QQ(-1)))
    e = series_power(e_squared, QQ(1, 2))
    return tuple(x.as_expr() for x in e)


def compose(coefficients: list, inner: list) -> list:
    """:math:`\\sum_n a_n g(x)^n` truncated, for a series ``inner`` without constant term."""
    zero = inner[0] * 0
    out = [coefficients[0] + zero] + [zero] * (len(inner) - 1)
    power = [zero + 1] + [zero] * (len(inner) - 1)
    for a_n in coefficients[1:]:
        power = series_mul(power, inner)
        out = [x + a_n * y for x, y in zip(out, power, strict=True)]
    return out


@dataclass(frozen=True, eq=False)
class ViscoelasticRestitutionSeries(ArrayRecord):
    r"""The series :math:`e = \sum_{j=0}^{2\,order} h_j \beta^{j/2}` of one condition.

    Attributes
    ----------
    condition : {"position", "force"}
    order : int
        Highest power of :math:`\beta` kept.
    powers : ndarray
        :math:`j/2`, the power of :math:`\beta` of each coefficient.
    coefficients : ndarray
        :math:`h_j` as floats.
    exact : tuple
        :math:`h_j` as a SymPy number where it involves :math:`c_1` only (Gamma
        functions and rationals), else ``None``.
    precise : tuple
        :math:`h_j` as mpmath numbers, good to ``digits`` significant digits.
    digits : int
        Significant digits the numeric coefficients agree to between two resolutions of
        :func:`universal_coefficients` (the exact ones are exact).
    """

    condition: str
    order: int
    powers: np.ndarray
    coefficients: np.ndarray
    exact: tuple
    precise: tuple
    digits: int

    def restitution(self, beta: ArrayLike) -> ArrayLike:
        r"""The truncated series at damping numbers ``beta`` (:math:`\ge 0`, any shape):
        Horner's scheme in :math:`\sqrt\beta`.

        >>> s = viscoelastic_restitution_series(2, condition="position")
        >>> round(s.restitution(0.01), 6)
        0.988545
        """
        b, scalar = real_array("beta", beta, lower=0.0)
        e = np.polynomial.polynomial.polyval(np.sqrt(b), self.coefficients)
        return float(e) if scalar else e


def viscoelastic_restitution_series(order: int, *, condition: str) -> ViscoelasticRestitutionSeries:
    r"""The viscoelastic restitution :math:`e = \sum_j h_j \beta^{j/2}` through
    :math:`\beta^{order}`, derived (module docstring), not fitted.

    Parameters
    ----------
    order : int
        Highest power of :math:`\beta = \tfrac32 A (k/m)^{2/5} v_0^{1/5}` kept
        (:math:`0 \le order \le 16`).
    condition : {"position", "force"}
        Contact while :math:`d > 0`, or while the force is compressive (delayed recovery:
        half-integer powers from :math:`\beta^{5/2}` on).

    Returns
    -------
    ViscoelasticRestitutionSeries
        Coefficients exact where they involve :math:`c_1` only, else mpmath numbers with
        their stated precision; ``.restitution(beta)`` evaluates on arrays.

    Examples
    --------
    >>> s = viscoelastic_restitution_series(3, condition="force")
    >>> s.exact[2], round(float(s.exact[4] / s.exact[2] ** 2), 15), s.exact[5]
    (-2**(4/5)*5**(3/5)*sqrt(pi)*gamma(3/5)/(10*gamma(21/10)), 0.6, 4/15)
    >>> [round(float(h), 5) for h in s.coefficients]
    [1.0, 0.0, -1.15345, 0.0, 0.79827, 0.26667, -0.52288]
    >>> s.exact[6] is None, s.digits >= 15
    (True, True)
    """
    check_condition(condition)
    if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= 16:
        raise ValueError(f"order must be an integer from 0 to 16; got {order!r}")
    return _series(order, condition)


@cache
def _series(order: int, condition: str) -> ViscoelasticRestitutionSeries:
    polynomials = position_polynomials(order)
    size = 2 * order + 1
    h = [sp.Integer(0)] * size
    for k, p in enumerate(polynomials):
        h[2 * k] = p
    if condition == "force":
        g = delayed_recovery_coefficients(size // 5)
        for n in range(1, size // 5 + 1):
            # e_p * (beta^{5/2} e_p^{1/2})^n = beta^{5n/2} e_p^{1 + n/2}
            power = series_power(list(polynomials), sp.Rational(2 + n, 2))
            for k, term in enumerate(power):
                if 5 * n + 2 * k < size:
                    h[5 * n + 2 * k] += sp.Rational(g[n].numerator, g[n].denominator) * term
    h = [sp.expand(x) for x in h]
    symbols = {f"c_{n}": sp.Symbol(f"c_{n}") for n in range(1, order + 1)}
    kappa = sp.Symbol("kappa")
    exact = tuple(
        sp.expand(x.subs({symbols.get("c_1", kappa): C1_UNIVERSAL, kappa: KAPPA}))
        if x.free_symbols <= {kappa, symbols.get("c_1")}
        else None
        for x in h
    )
    values = []
    for nodes, dps in ((48, 40), (64, 50)):
        c = universal_coefficients(order, nodes=nodes, dps=dps)
        with workdps(dps):
            table = {symbols[f"c_{n}"]: sp.Float(c[n], dps) for n in range(1, order + 1)}
            table[kappa] = sp.Float(mpmath.mpf(2) * mpmath.mpf(1.25) ** 0.6, dps)
            values.append([mpmath.mpf(str(sp.N(x.xreplace(table), dps))) for x in h])
    with workdps(50):
        errors = [
            abs(a - b) / max(abs(b), mpmath.mpf(10) ** -45) for a, b in zip(*values, strict=True)
        ]
        worst = max((err for err, x in zip(errors, exact, strict=True) if x is None), default=0)
        digits = 35 if worst == 0 else min(35, int(-mpmath.log10(worst)))
    with workdps(50):
        precise = tuple(
            mpmath.mpf(str(sp.N(x, 50))) if x is not None else v
            for x, v in zip(exact, values[1], strict=True)
        )
    coefficients = np.array([float(v) for v in precise])
    powers = np.arange(size) / 2
    coefficients.flags.writeable = powers.flags.writeable = False
    return ViscoelasticRestitutionSeries(
        condition=condition,
        order=order,
        powers=powers,
        coefficients=coefficients,
        exact=exact,
        precise=precise,
        digits=digits,
    )
