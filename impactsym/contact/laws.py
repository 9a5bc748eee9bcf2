r"""Nonlinear contact laws: the one place that defines them, and their normalization (SymPy).

A body of mass :math:`m` hits a massless contact element at speed :math:`v_0` under a
constant pressing force :math:`F_0`; :math:`d \ge 0` is the overlap (penetration) and
:math:`m d'' = F_0 - F(d, d')` while in contact, :math:`d(0) = 0`, :math:`d'(0) = v_0`.
The laws (``docs/physics.md``, "Nonlinear contact laws"):

====================  ================================================  ===========
law                   contact force :math:`F(d, d')`                    damping
====================  ================================================  ===========
``"linear"``          :math:`k d + c d'`                                :math:`c`
``"hertz-linear"``    :math:`k d^p + c d'`                              :math:`c`
``"hunt-crossley"``   :math:`k d^p (1 + \lambda d')`                    :math:`\lambda`
``"tsuji"``           :math:`k d^p + \alpha\sqrt{mk}\, d^{(p-1)/2} d'`  :math:`\alpha`
``"viscoelastic"``    :math:`k (d^{3/2} + \tfrac32 A d^{1/2} d')`       :math:`A`
====================  ================================================  ===========

Each is normalized with the time scale :math:`T` at which spring and inertia balance for
an impact at :math:`v_0` (:math:`T^{p+1} = m / (k v_0^{p-1})`), the length :math:`L = v_0 T`
and the force unit :math:`m v_0 / T = k L^p`: with :math:`\tau = t/T`, :math:`z = d/L`,

.. math::  z'' = b - \varphi(z, z'), \qquad z(0) = 0, \quad z'(0) = 1,

where :math:`\varphi` is the normalized contact force, a function of ``z``, ``z'``, one
damping number :math:`\delta` (``D``, ``s``, ``alpha`` or ``beta``) and the exponent. The
pressing number is :math:`f = F_0 T/(m v_0)` (so that the static penetration is
:math:`f^{1/p}`), except for ``"linear"``, which keeps the paper's :math:`f = F_0/(c v_0)`
with :math:`b = 2 D f`. :class:`ContactLaw` derives all of this from the physical law and
checks it by substitution (:attr:`ContactLaw.normalization_residual`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property

import sympy as sp

from impactsym.symbolic.typeset import latex

#: The laws :func:`contact_law` knows, in the order of the docs.
LAWS = ("linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic")

# physical symbols
m, k, v0, F0, p = sp.symbols("m k v_0 F_0 p", positive=True)
d, dd = sp.symbols("d d'", positive=True)  # overlap and its rate (sign free in use)
c, lam, alpha, A = sp.symbols("c lambda alpha A", positive=True)
# normalized symbols
z = sp.Symbol("z", positive=True)  # z = d/L
w = sp.Symbol("w", real=True)  # w = z', the normalized rate
D, s, beta, f = sp.symbols("D s beta f", positive=True)

_HALF3 = sp.Rational(3, 2)


@dataclass(frozen=True)
class _Definition:
    force: sp.Expr  # physical contact force F(d, d')
    exponent: sp.Expr  # spring exponent (p or a number)
    parameter: sp.Symbol  # the law's damping parameter
    number: sp.Symbol  # the damping number's symbol
    number_of: sp.Expr  # damping number in physical symbols (T written as _T)
    touch_factor: sp.Expr  # factor of phi that vanishes at z = 0 (1 if none)


_T = sp.Symbol("T", positive=True)

_DEFINITIONS = {
    "linear": _Definition(k * d + c * dd, sp.Integer(1), c, D, c / (2 * sp.sqrt(k * m)), 1),
    "hertz-linear": _Definition(k * d**p + c * dd, p, c, D, c * _T / (2 * m), 1),
    "hunt-crossley": _Definition(k * d**p * (1 + lam * dd), p, lam, s, lam * v0, z**p),
    "tsuji": _Definition(
        k * d**p + alpha * sp.sqrt(m * k) * d ** ((p - 1) / 2) * dd,
        p,
        alpha,
        alpha,
        alpha,
        z ** ((p - 1) / 2),
    ),
    "viscoelastic": _Definition(
        k * (d**_HALF3 + _HALF3 * A * sp.sqrt(d) * dd),
        _HALF3,
        A,
        beta,
        _HALF3 * A / _T,
        sp.sqrt(z),
    ),
}

#: The normalized contact force :math:`\varphi(z, w)` of each law (``w = z'``).
_NORMALIZED = {
    "linear": z + 2 * D * w,
    "hertz-linear": z**p + 2 * D * w,
    "hunt-crossley": z**p * (1 + s * w),
    "tsuji": z**p + alpha * z ** ((p - 1) / 2) * w,
    "viscoelastic": z**_HALF3 + beta * sp.sqrt(z) * w,
}

_PARAMETER_NAMES = {"linear": "c", "hertz-linear": "c", "hunt-crossley": "lambda",
                    "tsuji": "alpha", "viscoelastic": "A"}  # fmt: skip


def check_law(law: object) -> str:
    """Return ``law`` if it names a known contact law, else raise listing the laws.

    >>> check_law("tsuji")
    'tsuji'
    >>> check_law("hertz")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: law must be one of 'linear', 'hertz-linear', ..., 'viscoelastic'; got 'hertz'
    """
    known = ", ".join(repr(name) for name in LAWS)
    if not isinstance(law, str):
        raise TypeError(f"law must be a string, one of {known}; got {law!r}")
    if law not in LAWS:
        raise ValueError(f"law must be one of {known}; got {law!r}")
    return law


class ContactLaw:
    r"""One contact law, its normalization and the quantities the numerics need.

    Parameters
    ----------
    name : str
        One of :data:`LAWS`.

    Attributes
    ----------
    force
        Physical force :math:`F(d, d')` (symbols ``d``, ``d'``, ``k``, ``m``, ``p`` and the
        damping parameter).
    parameter_name
        Name of the damping parameter in the API: ``"c"``, ``"lambda"``, ``"alpha"``
        or ``"A"``.
    uses_exponent
        Whether the law has the exponent ``p`` (``"linear"`` and ``"viscoelastic"``
        ignore it).

    Examples
    --------
    >>> law = ContactLaw("tsuji")
    >>> law.phi
    alpha*w*z**(p/2 - 1/2) + z**p
    >>> law.normalization_residual
    0
    >>> law.damping_number, law.pressing_number
    (alpha, F_0*T/(m*v_0))
    """

    def __init__(self, name: str) -> None:
        self.name = check_law(name)
        self._definition = _DEFINITIONS[name]
        self.force: sp.Expr = self._definition.force
        self.parameter: sp.Symbol = self._definition.parameter
        self.parameter_name: str = _PARAMETER_NAMES[name]
        self.number: sp.Symbol = self._definition.number
        self.exponent: sp.Expr = self._definition.exponent
        self.uses_exponent: bool = name in ("hertz-linear", "hunt-crossley", "tsuji")
        self.phi: sp.Expr = _NORMALIZED[name]
        self.touch_factor: sp.Expr = sp.sympify(self._definition.touch_factor, strict=True)

    def __repr__(self) -> str:
        return f"ContactLaw({self.name!r})"

    @cached_property
    def time_scale(self) -> sp.Expr:
        r""":math:`T = (m / (k v_0^{p-1}))^{1/(p+1)}`: spring force and inertia balance."""
        q = self.exponent
        return (m / (k * v0 ** (q - 1))) ** (1 / (q + 1))

    @cached_property
    def length_scale(self) -> sp.Expr:
        """:math:`L = v_0 T`, so that the normalized speed at touch is 1."""
        return v0 * self.time_scale

    @cached_property
    def damping_number(self) -> sp.Expr:
        r"""The damping number :math:`\delta` in physical symbols (``T`` the time scale)."""
        return self._definition.number_of

    @cached_property
    def pressing_number(self) -> sp.Expr:
        r"""The pressing number :math:`f`: :math:`F_0/(c v_0)` for ``"linear"`` (the
        paper's), else :math:`F_0 T/(m v_0)`."""
        if self.name == "linear":
            return F0 / (c * v0)
        return F0 * _T / (m * v0)

    @cached_property
    def load(self) -> sp.Expr:
        """The normalized pressing term ``b`` of :math:`z'' = b - \\varphi`."""
        return 2 * D * f if self.name == "linear" else f

    @cached_property
    def normalization_residual(self) -> sp.Expr:
        r"""Zero when the normalization is right: the physical law over the force unit
        :math:`m v_0/T` with :math:`d = L z`, :math:`d' = v_0 w`, minus :math:`\varphi`
        (damping number in physical symbols), plus the same for the pressing term,
        :math:`F_0/(m v_0/T) - b`."""
        T = self.time_scale
        unit = m * v0 / T
        number = self.damping_number.subs(_T, T)
        physical = self.force.subs({d: self.length_scale * z, dd: v0 * w}) / unit
        force_residual = physical - self.phi.subs(self.number, number)
        load_residual = F0 / unit - self.load.subs({f: self.pressing_number.subs(_T, T), D: number})
        total = sp.expand_power_base(force_residual + load_residual, force=True)
        return sp.simplify(sp.powsimp(sp.expand(total), force=True))

    @cached_property
    def reduced_force(self) -> sp.Expr:
        r""":math:`\varphi / (\text{touch factor})`: the sign of the force, smooth at
        ``z = 0`` (``1 + s w``, ``alpha w + z^((p+1)/2)``, ``z + beta w``)."""
        return sp.expand(sp.powsimp(sp.expand(self.phi / self.touch_factor), force=True))

    @cached_property
    def release_speed(self) -> sp.Expr:
        r"""The rate :math:`w_0(z)` at which the force vanishes at overlap ``z > 0`` (the
        root of :math:`\varphi = 0`, linear in ``w`` for every law)."""
        (solution,) = sp.solve(sp.Eq(self.reduced_force, 0), w)
        return sp.powsimp(solution, force=True)

    @cached_property
    def spring(self) -> sp.Expr:
        r""":math:`\varphi(z, 0)`, the elastic part."""
        return self.phi.subs(w, 0)

    @cached_property
    def damper(self) -> sp.Expr:
        r""":math:`\partial\varphi/\partial w`, the damping coefficient at overlap ``z``."""
        return sp.diff(self.phi, w)

    @cached_property
    def potential(self) -> sp.Expr:
        r""":math:`\int_0^z \varphi(\zeta, 0)\,d\zeta`, the elastic energy."""
        zeta = sp.Symbol("zeta", positive=True)
        return sp.integrate(self.spring.subs(z, zeta), (zeta, 0, z))

    @cached_property
    def force_rate(self) -> sp.Expr:
        r""":math:`d\varphi/d\tau = \varphi_z w + \varphi_w (b - \varphi)` along a motion;
        ``b`` is the symbol :math:`b` here (the pressing term)."""
        b = sp.Symbol("b", positive=True)
        rate = sp.diff(self.phi, z) * w + sp.diff(self.phi, w) * (b - self.phi)
        return sp.powsimp(sp.expand(rate), force=True)

    def latex(self) -> str:
        r"""The law, its normalized equation and its two groups as one LaTeX ``aligned``.

        >>> print(ContactLaw("hunt-crossley").latex().splitlines()[1])
        F &= d^{p} k \left(d' \lambda + 1\right) \\
        """
        T = self.time_scale
        rows = [
            rf"F &= {latex(self.force)}",
            rf"z'' &= {latex(self.load)} - \left({latex(self.phi)}\right),"
            r"\quad z(0) = 0,\ z'(0) = 1",
            rf"T &= {latex(T)},\quad L = v_0 T",
            rf"{latex(self.number)} &= {latex(self.damping_number)},\quad "
            rf"f = {latex(self.pressing_number)}",
        ]
        return "\\begin{aligned}\n" + " \\\\\n".join(rows) + " \\\\\n\\end{aligned}"


@cache
def contact_law(name: str) -> ContactLaw:
    """The (cached) :class:`ContactLaw` of ``name``.

    >>> contact_law("viscoelastic").parameter_name
    'A'
    """
    return ContactLaw(check_law(name))
