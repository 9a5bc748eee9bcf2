r"""Spring-damper contact (paper section 2): the derivation with SymPy.

A body hits a unilateral spring-damper contact. While in contact, normalized as in
``docs/physics.md``, section 2 (:math:`\tau = \omega_0 t`, :math:`z = x\omega_0/v_0`,
:math:`D = d/(2\sqrt{km})`, :math:`f = F/(d v_0)`),

.. math::  z'' + 2 D z' + z = 2 D f, \qquad z(0) = 0, \quad z'(0) = 1.

Contact ends at the first sign change of the contact function

.. math::  g_\mathrm{position} = z, \qquad g_\mathrm{force} = 2 D z' + z,

the second being the normalized contact force. Both ``g`` solve the same ODE as
``z``; ``g'`` solves its homogeneous part. Every solution is therefore written in the
damped basis :math:`(C, S)` of the regime, with :math:`C(0)=1, C'(0)=-D`, :math:`S(0)=0,
S'(0)=1`:

.. math::  y(\tau) = 2Df + (y_0 - 2Df)\, C(\tau) + \bigl(y_0' + D (y_0 - 2Df)\bigr) S(\tau).

The *ridge* of the implicit surface :math:`g(\tau, D, f) = 0` is where
:math:`\partial g/\partial\tau = 0`; its closed-form solution :math:`\tau_r(D, f)` is the
first local minimum of ``g`` after impact, and :math:`G(D, f) = g(\tau_r, D, f) = 0`
is the boundary between release (:math:`G < 0`) and sticking (:math:`G \ge 0`).

:class:`SpringDamperContact` exposes every expression twice: in *display form* (the
symbols ``tau, D, f`` only, as one would print them) and in *numeric form*, the same
function written so that float evaluation is stable in its whole regime (auxiliary
symbols ``omega``, ``sigma``, ``mu`` that :mod:`impactsym.contact` computes
accurately; ``sinc``, ``expm1`` and ``log1p`` instead of differences that cancel).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property

import sympy as sp
from sympy.codegen.cfunctions import expm1, log1p

from impactsym.symbolic.typeset import (
    Abbreviation,
    Branch,
    Typeset,
    minimal_condition,
    positive_factor,
)
from impactsym.validation import CONDITIONS, check_condition, real_array

tau = sp.Symbol("tau", nonnegative=True)
D = sp.Symbol("D", nonnegative=True)
f = sp.Symbol("f", nonnegative=True)
#: under-damped angular frequency sqrt(1 - D^2) (numeric forms)
omega = sp.Symbol("omega", nonnegative=True)
#: over-damped decay spread sqrt(D^2 - 1) (numeric forms)
sigma = sp.Symbol("sigma", positive=True)
#: fast over-damped decay rate D + sigma; the slow one is 1/mu (numeric forms)
mu = sp.Symbol("mu", positive=True)
#: state at the start of a contact that begins from an arbitrary state (a re-contact):
#: penetration = element deflection z(0) and body speed z'(0), in units of the first impact
z0 = sp.Symbol("z_0", real=True)
v0 = sp.Symbol("v_0", real=True)

REGIMES = ("underdamped", "critical", "overdamped")

#: Auxiliary symbols of the numeric forms, per regime, after ``(tau, D, f)``.
NUMERIC_AUX = {"underdamped": (omega,), "critical": (), "overdamped": (sigma, mu)}


@dataclass(frozen=True)
class _Basis:
    """Damped basis functions C, S of one regime, in display and numeric form."""

    C: sp.Expr
    S: sp.Expr


def _display_basis(regime: str) -> _Basis:
    if regime == "underdamped":
        w = sp.sqrt(1 - D**2)
        return _Basis(sp.exp(-D * tau) * sp.cos(w * tau), sp.exp(-D * tau) * sp.sin(w * tau) / w)
    if regime == "critical":
        return _Basis(sp.exp(-tau), tau * sp.exp(-tau))
    s = sp.sqrt(D**2 - 1)
    return _Basis(sp.exp(-D * tau) * sp.cosh(s * tau), sp.exp(-D * tau) * sp.sinh(s * tau) / s)


def _to_mu(expr: sp.Expr) -> sp.Expr:
    r"""Rewrite ``expr`` in (D, sigma) through :math:`\mu = D + \sigma` and factor it.

    With :math:`D = (\mu^2+1)/(2\mu)` and :math:`\sigma = (\mu^2-1)/(2\mu)` the
    cancellation :math:`D - \sigma = 1/\mu` that ruins float evaluation for large ``D``
    is done exactly; the factor :math:`\mu - 1` is then written as
    :math:`2\sigma\mu/(\mu+1)`, which stays accurate as :math:`D \to 1`.
    """
    in_mu = sp.factor(
        sp.together(expr.subs({D: (mu**2 + 1) / (2 * mu), sigma: (mu**2 - 1) / (2 * mu)}))
    )
    return in_mu.subs(mu - 1, 2 * sigma * mu / (mu + 1))


#: Decay rate c of the slowest mode per regime: y = b + exp(-c tau) * oscillation.
DECAY = {"underdamped": D, "critical": sp.Integer(1), "overdamped": 1 / mu}


def _numeric_oscillation(regime: str, b: sp.Expr, y0: sp.Expr, q: sp.Expr) -> sp.Expr:
    """(y - b) exp(c tau) for y = b + (y0 - b) C + q S, written stably for floats.

    ``q`` is the coefficient of ``S`` (:math:`y_0' + D (y_0 - b)`). Scaling the decay
    out keeps the sign of ``y`` visible where ``exp(-c tau)`` underflows.
    """
    h0 = y0 - b
    if regime == "underdamped":  # sinc keeps S finite at omega = 0 (critical damping)
        return h0 * sp.cos(omega * tau) + q * tau * sp.sinc(omega * tau)
    if regime == "critical":
        return h0 + q * tau
    # h0 C + q S = exp(-tau/mu) [A (1 - E) + h0 E],  E = exp(-2 sigma tau),
    # A = (sigma h0 + q) / (2 sigma) is the coefficient of the slow exponential.
    A = _to_mu(sigma * h0 + q) / (2 * sigma)
    return -A * expm1(-2 * sigma * tau) + h0 * sp.exp(-2 * sigma * tau)


def _initial_values(
    condition: str, start: tuple[sp.Expr, sp.Expr] = (sp.Integer(0), sp.Integer(1))
) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """g(0), g'(0), g''(0) of the contact function for the initial state ``start`` =
    (z(0), z'(0)) (from the ODE, no solution needed)."""
    b = 2 * D * f
    z0, z1 = start
    z2 = b - 2 * D * z1 - z0
    if condition == "position":
        g0, g1 = z0, z1
    else:  # g = 2 D z' + z
        g0, g1 = 2 * D * z1 + z0, 2 * D * z2 + z1
    g2 = b - 2 * D * g1 - g0  # g solves the same ODE as z
    return g0, sp.expand(g1), sp.expand(g2)


class SpringDamperContact:
    r"""Explicit solution, contact functions, ridge time and boundary of one regime.

    Parameters
    ----------
    regime : {"underdamped", "critical", "overdamped"}
        Damping regime: :math:`D < 1`, :math:`D = 1` or :math:`D > 1`.

    Attributes
    ----------
    z, z_dot
        Penetration :math:`z(\tau; D, f)` and its rate (display form).
    g, g_dot
        Dicts ``condition -> expression``: contact function and :math:`\partial g/\partial\tau`.
    ridge_time, ridge_exists
        Dicts: closed-form first local minimum :math:`\tau_r(D, f)` of ``g`` and the
        condition (a SymPy boolean) under which that minimum exists.
    boundary
        Dict: :math:`G(D, f) = g(\tau_r(D, f), D, f)`; release where :math:`G < 0`.

    Examples
    --------
    >>> model = SpringDamperContact("critical")
    >>> model.z
    2*f + (-2*f + tau*(1 - 2*f))*exp(-tau)
    >>> model.ridge_time["force"], model.ridge_exists["force"]
    ((4*f - 3)/(2*f - 1), (1 - 2*f > 0) & (4*f - 3 < 0))
    """

    #: initial state (z(0), z'(0)) of the contact: the first impact
    start: tuple[sp.Expr, sp.Expr] = (sp.Integer(0), sp.Integer(1))

    def __init__(self, regime: str) -> None:
        if regime not in REGIMES:
            raise ValueError(f"regime must be one of {REGIMES}, got {regime!r}")
        self.regime = regime
        self.symbols = (tau, D, f)
        self._basis = _display_basis(regime)

    def __repr__(self) -> str:
        return f"SpringDamperContact({self.regime!r})"

    # -- construction ------------------------------------------------------------
    def _display(self, b: sp.Expr, y0: sp.Expr, y1: sp.Expr) -> sp.Expr:
        C, S = self._basis.C, self._basis.S
        h0 = y0 - b
        q = sp.expand(y1 + D * h0)
        if self.regime == "critical":
            return (b + (h0 + q * tau) * sp.exp(-tau)).subs(D, 1)
        return b + h0 * C + q * S

    def _numeric(self, b: sp.Expr, y0: sp.Expr, y1: sp.Expr, scaled: bool = False) -> sp.Expr:
        q = sp.expand(y1 + D * (y0 - b))
        oscillation = _numeric_oscillation(self.regime, b, y0, q)
        expr = oscillation if scaled else b + sp.exp(-DECAY[self.regime] * tau) * oscillation
        return expr.subs(D, 1) if self.regime == "critical" else expr

    # -- solution ----------------------------------------------------------------
    @cached_property
    def z(self) -> sp.Expr:
        """Penetration z(tau): the persistent-contact solution (display form)."""
        return self._display(2 * D * f, *self.start)

    @cached_property
    def z_dot(self) -> sp.Expr:
        """Penetration rate dz/dtau (display form), a homogeneous solution."""
        return self._display(sp.Integer(0), *self._z_dot_start)

    @property
    def _z_dot_start(self) -> tuple[sp.Expr, sp.Expr]:
        """z'(0) and z''(0) (from the ODE)."""
        y0, y1 = self.start
        return y1, sp.expand(2 * D * f - 2 * D * y1 - y0)

    @cached_property
    def g(self) -> dict[str, sp.Expr]:
        """Contact functions: z (position) and 2 D z' + z (force), display form."""
        return {
            c: self._display(2 * D * f, *_initial_values(c, self.start)[:2]) for c in CONDITIONS
        }

    @cached_property
    def g_dot(self) -> dict[str, sp.Expr]:
        """Their tau-derivatives dg/dtau (display form)."""
        return {
            c: self._display(sp.Integer(0), *_initial_values(c, self.start)[1:]) for c in CONDITIONS
        }

    # -- ridge and boundary --------------------------------------------------------
    def _ridge(self, condition: str, numeric: bool) -> tuple[sp.Expr, sp.Boolean]:
        _, p0, p1 = _initial_values(condition, self.start)  # g'(0), g''(0)
        q = sp.expand(p1 + D * p0)  # coefficient of S in g'
        if self.regime == "underdamped":
            # g' ~ exp(-D tau) (omega p0 cos + q sin)/omega; the first upward zero of g'
            w = omega if numeric else sp.sqrt(1 - D**2)
            theta = sp.Piecewise(
                (sp.atan2(-w * p0, q), p0 < 0),  # = pi + atan2(w p0, -q) without cancellation
                (sp.pi + sp.atan2(w * p0, -q), True),
            )
            return theta / w, sp.true
        if self.regime == "critical":
            p0, q = p0.subs(D, 1), q.subs(D, 1)
            return sp.cancel(-p0 / q), sp.And(p0 < 0, q > 0)
        # over-damped: tanh(sigma tau) = -sigma p0 / q, a minimum when p0 < 0 < q + sigma p0
        if numeric:
            denominator = _to_mu(q + sigma * p0)
            ridge = log1p(-2 * sigma * p0 / denominator) / (2 * sigma)
            return ridge, sp.And(p0 < 0, denominator > 0)
        s = sp.sqrt(D**2 - 1)
        return sp.atanh(-s * p0 / q) / s, sp.And(p0 < 0, q + s * p0 > 0)

    @cached_property
    def _display_ridges(self) -> dict[str, tuple[sp.Expr, sp.Boolean]]:
        return {c: self._ridge(c, numeric=False) for c in CONDITIONS}

    @cached_property
    def ridge_time(self) -> dict[str, sp.Expr]:
        """Closed-form first local minimum tau_r(D, f) of g, from dg/dtau = 0."""
        return {c: ridge for c, (ridge, _) in self._display_ridges.items()}

    @cached_property
    def ridge_exists(self) -> dict[str, sp.Boolean]:
        """Where g has a local minimum after impact (always for D < 1)."""
        return {c: exists for c, (_, exists) in self._display_ridges.items()}

    @cached_property
    def boundary(self) -> dict[str, sp.Expr]:
        """G(D, f) = g(tau_r(D, f), D, f): release where G < 0, sticking where G >= 0."""
        return {c: self.g[c].subs(tau, self.ridge_time[c]) for c in CONDITIONS}

    # -- numeric forms ------------------------------------------------------------
    @cached_property
    def numeric_basis(self) -> tuple[sp.Expr, sp.Expr]:
        """The damped basis ``(C, S)`` of the regime in numeric form, arguments
        ``(tau, D) + NUMERIC_AUX[regime]`` (``D = 1`` substituted when critical).

        Every homogeneous solution is :math:`h = h_0 C + (h_1 + D h_0) S`.
        """
        zero, one = sp.Integer(0), sp.Integer(1)
        return self._numeric(zero, one, -D), self._numeric(zero, zero, one)

    @cached_property
    def numeric_forms(self) -> dict[str, sp.Expr]:
        """Stable float forms, keyed ``'z_dot'``, ``'g_<condition>'`` (``g_position``
        is ``z``), ``'ridge_<condition>'``, ``'ridge_exists_<condition>'``,
        ``'g_oscillation_<condition>'`` :math:`= (g - 2Df) e^{c\\tau}` with the decay rate
        ``c = DECAY[regime]`` and its tau-derivative ``'g_oscillation_dot_<condition>'``,
        and (not for the critical regime) ``'g_D_<condition>'`` = dg/dD.

        Their arguments are ``(tau, D, f) + NUMERIC_AUX[regime]``.
        """
        forms = {"z_dot": self._numeric(sp.Integer(0), *self._z_dot_start)}
        for c in CONDITIONS:
            g0, g1, g2 = _initial_values(c, self.start)
            forms[f"g_{c}"] = self._numeric(2 * D * f, g0, g1)
            oscillation = self._numeric(2 * D * f, g0, g1, scaled=True)
            forms[f"g_oscillation_{c}"] = oscillation
            # d/dtau [(g - 2Df) e^{c tau}] = g' e^{c tau} + c (g - 2Df) e^{c tau}; g' is a
            # homogeneous solution with the same decay (sp.diff of the sinc form cancels)
            decay = (
                DECAY[self.regime].subs(D, 1) if self.regime == "critical" else DECAY[self.regime]
            )
            forms[f"g_oscillation_dot_{c}"] = (
                self._numeric(sp.Integer(0), g1, g2, scaled=True) + decay * oscillation
            )
            forms[f"ridge_{c}"], forms[f"ridge_exists_{c}"] = self._ridge(c, numeric=True)
            if self.regime != "critical":
                forms[f"g_D_{c}"] = self._total_D_derivative(forms[f"g_{c}"])
        return forms

    def _total_D_derivative(self, expr: sp.Expr) -> sp.Expr:
        """d expr / dD of a numeric form, through its auxiliary symbols too."""
        if self.regime == "underdamped":  # omega = sqrt(1 - D^2)
            return sp.diff(expr, D) - sp.diff(expr, omega) * D / omega
        # sigma = sqrt(D^2 - 1), mu = D + sigma
        return sp.diff(expr, D) + (sp.diff(expr, sigma) + sp.diff(expr, mu) * mu / D) * D / sigma

    # -- presentation --------------------------------------------------------------
    def latex(self, name: str, *, condition: str | None = None) -> str:
        r"""LaTeX of the attribute ``name`` (``z``, ``z_dot``, ``g``, ``g_dot``,
        ``ridge_time``, ``ridge_exists``, ``boundary``); per-condition attributes need
        ``condition``.

        >>> SpringDamperContact("critical").latex("z")
        '2 f + \\left(- 2 f + \\tau \\left(1 - 2 f\\right)\\right) e^{- \\tau}'
        """
        if name not in _ATTRIBUTES:
            raise ValueError(f"name must be one of {sorted(_ATTRIBUTES)}, got {name!r}")
        value = getattr(self, name)
        if isinstance(value, dict):
            if condition is None:
                raise ValueError(f"{name!r} depends on the contact condition; pass condition=")
            value = value[check_condition(condition)]
        return sp.latex(value)


class SpringDamperRestart(SpringDamperContact):
    r"""The contact of one regime started from an arbitrary state (a re-contact).

    .. math::  z'' + 2 D z' + z = 2 D f, \qquad z(0) = z_0, \quad z'(0) = v_0,

    in the units of the *first* impact (:math:`v_0 = 1, z_0 = 0` is
    :class:`SpringDamperContact`). Under the force condition a body that re-contacts the
    relaxing massless element meets it still deflected, :math:`z_0 > 0`, and possibly
    while still moving away, :math:`v_0 < 0`; the contact force at the start,
    :math:`g_\mathrm{force}(0) = 2 D v_0 + z_0`, is positive all the same. Everything
    the parent class derives (solution, contact functions, closed-form ridge time and
    its existence condition, the stick test :math:`G = g(\tau_r)`, the numeric forms)
    holds for this start, with the extra arguments ``z0, v0`` after ``(tau, D, f)``.

    Examples
    --------
    >>> model = SpringDamperRestart("critical")
    >>> model.symbols
    (tau, D, f, z_0, v_0)
    >>> model.g["force"].subs({z0: 0, v0: 1}) == SpringDamperContact("critical").g["force"]
    True
    >>> model.ridge_exists["force"]
    (-2*f + v_0 + z_0 > 0) & (4*f - 3*v_0 - 2*z_0 < 0)
    """

    start = (z0, v0)

    def __init__(self, regime: str) -> None:
        super().__init__(regime)
        self.symbols = (tau, D, f, z0, v0)

    def __repr__(self) -> str:
        return f"SpringDamperRestart({self.regime!r})"


_ATTRIBUTES = {"z", "z_dot", "g", "g_dot", "ridge_time", "ridge_exists", "boundary"}


@cache
def spring_damper(regime: str) -> SpringDamperContact:
    """The (cached) derivation of one damping regime.

    >>> spring_damper("critical") is spring_damper("critical")
    True
    """
    return SpringDamperContact(regime)


@cache
def spring_damper_restart(regime: str) -> SpringDamperRestart:
    """The (cached) derivation of one damping regime from an arbitrary initial state.

    >>> spring_damper_restart("overdamped")
    SpringDamperRestart('overdamped')
    """
    return SpringDamperRestart(regime)


def regime_of(damping: float) -> str:
    """Name of the damping regime of a numeric ``D``.

    >>> regime_of(0.5), regime_of(1.0), regime_of(2.0)
    ('underdamped', 'critical', 'overdamped')
    >>> regime_of(float("nan"))
    Traceback (most recent call last):
        ...
    ValueError: D must be finite, got nan
    """
    value, scalar = real_array("D", damping, lower=0.0, allow_inf=True)
    if not scalar:
        raise TypeError(f"D must be a single number, got an array of shape {value.shape}")
    damping = float(value)
    if damping < 1:
        return "underdamped"
    return "critical" if damping == 1 else "overdamped"


# -- typeset formulas (LaTeX for documents) -----------------------------------------

#: abbreviations of the typeset formulas: sqrt(1 - D^2), sqrt(D^2 - 1), the initial slope
#: of the contact force lambda'(0) and the ridge time
OMEGA_UNDER = sp.Symbol("omega_d", positive=True)
OMEGA_OVER = sp.Symbol("omega_D", positive=True)
FORCE_SLOPE = sp.Symbol("lambdaprime_0", real=True)
TAU_R = sp.Symbol("tau_r", positive=True)

#: where each regime's formulas hold
REGIME_DOMAIN = {"underdamped": sp.And(D >= 0, D < 1), "critical": sp.Eq(D, 1), "overdamped": D > 1}
_REGIME_WORDS = {
    "underdamped": "under-damped contact ($D < 1$)",
    "critical": "critically damped contact ($D = 1$)",
    "overdamped": "over-damped contact ($D > 1$)",
}


def _omega(regime: str) -> tuple[Abbreviation, ...]:
    if regime == "critical":
        return ()
    if regime == "underdamped":
        return (Abbreviation(OMEGA_UNDER, sp.sqrt(1 - D**2)),)
    return (Abbreviation(OMEGA_OVER, sp.sqrt(D**2 - 1)),)


def _typeset_solution(model: SpringDamperContact) -> Typeset:
    """z = 2Df + e^{-D tau} (h0 C + q S / omega), collected, in one regime."""
    b, (g0, g1, _) = 2 * D * f, _initial_values("position", model.start)
    h0, q = g0 - b, sp.expand(g1 + D * (g0 - b))  # q = 1 - 2 D^2 f
    if model.regime == "critical":
        expr = (b + sp.exp(-tau) * (q * tau + h0)).subs(D, 1)
    else:
        w, cos, sin = {
            "underdamped": (OMEGA_UNDER, sp.cos, sp.sin),
            "overdamped": (OMEGA_OVER, sp.cosh, sp.sinh),
        }[model.regime]
        expr = b + sp.exp(-D * tau) * (h0 * cos(w * tau) + positive_factor(q) / w * sin(w * tau))
    return Typeset("z", (Branch(expr),), _omega(model.regime), model.z, REGIME_DOMAIN[model.regime])


def _typeset_ridge(model: SpringDamperContact, condition: str) -> Typeset:
    r"""tau_r from g' = e^{-D tau} (p0 C - x S / omega) = 0, p0 = g'(0), x = -q: atan2
    (one arctan where p0 = 1) for D < 1, a fraction at D = 1, artanh for D > 1.

    Under the force condition p0 is the initial slope of the contact force,
    lambda'_0 = 1 - 4 D^2 (1 - f), and x = D (lambda'_0 + 2 - 2f).
    """
    slope = ()
    if condition == "position":
        p0, x = sp.Integer(1), D * (1 - 2 * f)
    else:
        p0, x = FORCE_SLOPE, D * (FORCE_SLOPE + 2 - 2 * f)
        slope = (Abbreviation(FORCE_SLOPE, 1 - 4 * D**2 * (1 - f)),)
    exists, factor = model.ridge_exists[condition], sp.S.One
    if model.regime == "underdamped":  # theta = pi + atan2(omega p0, x) in (0, 2 pi)
        factor, where = 1 / OMEGA_UNDER, sp.true
        if p0 == 1:  # atan2(y, x) = pi/2 - arctan(x/y) for y > 0: one arctan
            expr = 3 * sp.pi / 2 + sp.atan(positive_factor(-x) / OMEGA_UNDER)
        else:
            expr = sp.pi + sp.atan2(OMEGA_UNDER * p0, x)
    elif model.regime == "critical":  # tau_r = p0 / x at D = 1
        num, den = sp.fraction(sp.factor(sp.cancel((p0 / x).subs(FORCE_SLOPE, slope[0][1]))))
        num, den = num.subs(D, 1), den.subs(D, 1)
        if num.as_coeff_Add()[0] < 0 and den.as_coeff_Add()[0] < 0:
            num, den = -num, -den  # (3 - 4f)/(1 - 2f)
        expr, slope, where = num / den, (), minimal_condition(exists, f)
    else:  # tanh(omega tau) = omega p0 / x
        expr, factor = sp.atanh(OMEGA_OVER * p0 / x), 1 / OMEGA_OVER
        where = minimal_condition(exists, f, parameter=D, interval=sp.Interval.open(1, sp.oo))
        where = where.subs(sp.sqrt(D**2 - 1), OMEGA_OVER)
    return Typeset(
        r"\tau_r",
        (Branch(expr, where),),
        (*slope, *_omega(model.regime)),
        model.ridge_time[condition],
        sp.And(REGIME_DOMAIN[model.regime], exists),
        factor=factor,
    )


def _typeset_boundary(model: SpringDamperContact, condition: str, ridge: Typeset) -> Typeset:
    r"""G = g(tau_r) = 2Df - e^{-D tau_r} sqrt(Q0): h = g - 2Df has h'' = -h where h' = 0,
    so h < 0 at a minimum, and Q = h^2 + 2D h h' + h'^2 decays as e^{-2 D tau}; Q(0) is
    1 - 4 D^2 f (1 - f) for both conditions."""
    if model.regime == "critical":  # sqrt((1 - 2f)^2) = 1 - 2f where the minimum exists
        expr = 2 * f - (1 - 2 * f) * sp.exp(-TAU_R)
    else:
        expr = 2 * D * f - sp.exp(-D * TAU_R) * sp.sqrt(1 - 4 * D**2 * f * (1 - f))
    return Typeset(
        "G(D, f)",
        (Branch(expr),),
        (Abbreviation(TAU_R, ridge.expression(), shown=False),),
        model.boundary[condition],
        ridge.domain,
    )


def typeset_formulas() -> list[tuple[str, str, Typeset | str]]:
    r"""``(label, sentence, formula)`` of the section-2 results, typeset for a paper.

    ``formula`` is a :class:`~impactsym.symbolic.typeset.Typeset` (with the expression
    it came from, for checks) or, for an equation written by hand, a LaTeX string.
    The ridge time is the closed-form first local minimum :math:`\tau_r` of the contact
    function; the boundary :math:`G(D, f) = g(\tau_r, D, f)` uses that at a stationary
    point the quadratic form :math:`h^2 + 2Dhh' + h'^2` of :math:`h = g - 2Df`, which
    decays as :math:`e^{-2D\tau}`, gives :math:`h(\tau_r) = -e^{-D\tau_r}\sqrt{h(0)^2 +
    2Dh(0)h'(0) + h'(0)^2}`.

    >>> label, sentence, form = typeset_formulas()[5]
    >>> label, form.lhs
    ('sd-ridge-position-underdamped', '\\tau_r')
    """
    models = {regime: spring_damper(regime) for regime in REGIMES}
    items: list[tuple[str, str, Typeset | str]] = [
        (
            "sd-ode",
            "The normalized contact oscillator of paper section 2: penetration $z$, "
            "Lehr's damping ratio $D$ and the pressing force $f$ measured against the damper "
            "force at impact.",
            r"z'' + 2 D z' + z = 2 D f, \quad z(0) = 0, \quad z'(0) = 1",
        ),
        (
            "sd-conditions",
            "Contact lasts while the contact function $g$ is positive: the penetration "
            "(position condition) or the contact force (force condition).",
            r"g_\mathrm{position} = z, \qquad g_\mathrm{force} = 2 D z' + z",
        ),
    ]
    short = {"underdamped": "under", "critical": "critical", "overdamped": "over"}
    for regime, model in models.items():
        items.append(
            (
                f"sd-z-{short[regime]}",
                f"Penetration of the persistent contact, {_REGIME_WORDS[regime]}.",
                _typeset_solution(model),
            )
        )
    for condition in CONDITIONS:
        for regime, model in models.items():
            if model.ridge_exists[condition] == sp.false:  # no minimum: the body sticks
                continue
            ridge = _typeset_ridge(model, condition)
            if regime != "underdamped":
                note = "; for larger $f$ there is no minimum and the body sticks"
            elif condition == "position":
                note = "; for $D \\ge 1$ there is none and the body sticks"
            else:
                note = "; $\\operatorname{atan2}(y, x)$ is the angle of the point $(x, y)$"
            items.append(
                (
                    f"sd-ridge-{condition}-{regime}",
                    f"Ridge time $\\tau_r(D, f)$ of the {condition} condition, "
                    f"{_REGIME_WORDS[regime]}: the first local minimum of $g$ after impact, "
                    f"where $\\partial g / \\partial \\tau = 0${note}.",
                    ridge,
                )
            )
            items.append(
                (
                    f"sd-boundary-{condition}-{regime}",
                    f"Stick/release test of the {condition} condition, "
                    f"{_REGIME_WORDS[regime]}: $G = g(\\tau_r)$ with $\\tau_r$ from the "
                    "ridge time above; the body releases where $G < 0$, and $G(D, f) = 0$ "
                    "is the stick/release boundary (Fig. 1b).",
                    _typeset_boundary(model, condition, ridge),
                )
            )
    return items


def latex_formulas() -> list[tuple[str, str, str]]:
    r"""``(label, caption, LaTeX body)`` of the section-2 results, for documents.

    The typeset forms of :func:`typeset_formulas`: abbreviations
    :math:`\omega_d = \sqrt{1 - D^2}`, :math:`\omega_D = \sqrt{D^2 - 1}`, ridge
    conditions reduced to their tightest bound, the boundary through the ridge time.

    >>> label, caption, body = latex_formulas()[0]
    >>> label, body.split(",")[0]
    ('sd-ode', "z'' + 2 D z' + z = 2 D f")
    """
    return [
        (label, caption, form if isinstance(form, str) else form.latex())
        for label, caption, form in typeset_formulas()
    ]
