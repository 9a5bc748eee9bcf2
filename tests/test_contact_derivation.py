"""The symbolic derivation of the spring-damper contact (paper section 2)."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from conftest import CODE

from impactsym.contact.derivation import (
    NUMERIC_AUX,
    REGIMES,
    D,
    SpringDamperContact,
    f,
    mu,
    omega,
    regime_of,
    sigma,
    spring_damper,
    spring_damper_restart,
    tau,
    v0,
    z0,
)

SAMPLE_D = {
    "underdamped": [0.0, 0.3, 0.9, 0.999],
    "critical": [1.0],
    "overdamped": [1.001, 1.7, 8.0],
}
SAMPLE_F = [0.0, 0.2, 1.3]


def ode_residual(z: sp.Expr, regime: str) -> sp.Expr:
    damping = 1 if regime == "critical" else D
    return z.diff(tau, 2) + 2 * damping * z.diff(tau) + z - 2 * damping * f


@pytest.mark.parametrize("regime", REGIMES)
def test_solution_satisfies_ode_and_initial_conditions(regime):
    model = spring_damper(regime)
    assert sp.simplify(ode_residual(model.z, regime)) == 0
    assert sp.simplify(model.z.subs(tau, 0)) == 0
    assert sp.simplify(model.z.diff(tau).subs(tau, 0)) == 1


@pytest.mark.parametrize("regime", REGIMES)
def test_derivatives_and_contact_functions_are_consistent(regime):
    model = spring_damper(regime)
    damping = 1 if regime == "critical" else D
    assert sp.simplify(model.z_dot - model.z.diff(tau)) == 0
    assert sp.simplify(model.g["position"] - model.z) == 0
    assert sp.simplify(model.g["force"] - (2 * damping * model.z_dot + model.z)) == 0
    for condition in ("position", "force"):
        assert sp.simplify(model.g_dot[condition] - model.g[condition].diff(tau)) == 0


@pytest.mark.parametrize(
    ("regime", "damping"), [("underdamped", sp.Rational(1, 3)), ("critical", 1), ("overdamped", 3)]
)
def test_solution_agrees_with_sympy_dsolve(regime, damping):
    x = sp.Function("x")
    ode = sp.Eq(x(tau).diff(tau, 2) + 2 * damping * x(tau).diff(tau) + x(tau), 2 * damping * f)
    ics = {x(0): 0, x(tau).diff(tau).subs(tau, 0): 1}
    reference = sp.dsolve(ode, x(tau), ics=ics).rhs
    ours = spring_damper(regime).z.subs(D, damping)
    for t_value, f_value in [("0.7", "0"), ("2.3", "0.4"), ("5.1", "2")]:
        at = {tau: sp.Rational(t_value), f: sp.Rational(f_value)}
        assert float(sp.N(ours.subs(at) - reference.subs(at), 30)) == pytest.approx(0, abs=1e-25)


def _numeric_value(expr, regime, t_value, d_value, f_value):
    """Evaluate a numeric form at 40 digits, with its auxiliary symbols."""
    with mp.workdps(40):
        d_mp = mp.mpf(d_value)
        aux = {omega: mp.sqrt(1 - d_mp**2)} if regime == "underdamped" else {}
        if regime == "overdamped":
            s = mp.sqrt(d_mp**2 - 1)
            aux = {sigma: s, mu: d_mp + s}
        args = [tau, D, f, *NUMERIC_AUX[regime]]
        fn = sp.lambdify(args, expr, modules="mpmath")
        return fn(mp.mpf(t_value), d_mp, mp.mpf(f_value), *[aux[a] for a in NUMERIC_AUX[regime]])


@pytest.mark.parametrize("regime", REGIMES)
def test_numeric_forms_equal_display_forms(regime):
    model = spring_damper(regime)
    damping = 1 if regime == "critical" else D
    decay = {"underdamped": D, "critical": 1, "overdamped": D - sp.sqrt(D**2 - 1)}[regime]
    pairs = [("z_dot", model.z_dot)]
    for c in ("position", "force"):
        # the oscillation is g with its static part removed and its decay scaled out
        oscillation = (model.g[c] - 2 * damping * f) * sp.exp(decay * tau)
        pairs += [
            (f"g_{c}", model.g[c]),
            (f"g_oscillation_{c}", oscillation),
            (f"g_oscillation_dot_{c}", oscillation.diff(tau)),
        ]
    for d_value in SAMPLE_D[regime]:
        for f_value in SAMPLE_F:
            for t_value in (0.0, 0.4, 3.0, 17.0):
                for key, display in pairs:
                    with mp.workdps(40):
                        fn = sp.lambdify([tau, D, f], display, modules="mpmath")
                        expected = fn(mp.mpf(t_value), mp.mpf(d_value), mp.mpf(f_value))
                    got = _numeric_value(
                        model.numeric_forms[key], regime, t_value, d_value, f_value
                    )
                    assert float(got - expected) == pytest.approx(0, abs=1e-30), (key, d_value)


@pytest.mark.parametrize("regime", ["underdamped", "overdamped"])
def test_numeric_D_derivative_matches_finite_difference(regime):
    model = spring_damper(regime)
    for c in ("position", "force"):
        for d_value in SAMPLE_D[regime][1:]:
            h = mp.mpf("1e-15")
            slope = _numeric_value(model.numeric_forms[f"g_D_{c}"], regime, 1.3, d_value, 0.4)
            with mp.workdps(40):
                up = _numeric_value(model.numeric_forms[f"g_{c}"], regime, 1.3, d_value + h, 0.4)
                down = _numeric_value(model.numeric_forms[f"g_{c}"], regime, 1.3, d_value - h, 0.4)
                assert float(slope - (up - down) / (2 * h)) == pytest.approx(0, abs=1e-20)


def _first_local_minimum_by_scan(g_dot, d_value, f_value, t_max=80.0):
    """First upward sign change of g' on a fine grid (independent of the closed form)."""
    fn = sp.lambdify(tau, g_dot.subs({D: d_value, f: f_value}), "mpmath")
    grid = np.linspace(1e-9, t_max, 8001)
    values = np.array([float(fn(t)) for t in grid])
    upward = np.flatnonzero((values[:-1] < 0) & (values[1:] >= 0))
    if upward.size == 0:
        return None
    return float(mp.findroot(fn, (grid[upward[0]], grid[upward[0] + 1]), solver="anderson"))


@pytest.mark.parametrize("condition", ["position", "force"])
@pytest.mark.parametrize(
    ("d_value", "f_value"),
    [
        (0.0, 0.5),
        (0.2, 0.0),
        (0.2, 0.7),
        (0.6, 2.0),
        (0.95, 0.1),
        (1.0, 0.1),
        (1.0, 0.0),
        (1.4, 0.02),
        (3.0, 0.0),
        (3.0, 0.5),
    ],
)
def test_ridge_time_is_first_local_minimum(condition, d_value, f_value):
    model = spring_damper(regime_of(d_value))
    exists = model.ridge_exists[condition].subs({D: d_value, f: f_value})
    expected = _first_local_minimum_by_scan(model.g_dot[condition], d_value, f_value)
    if expected is None:
        assert not bool(exists)
    else:
        assert bool(exists)
        ridge = float(model.ridge_time[condition].subs({D: d_value, f: f_value}))
        assert ridge == pytest.approx(expected, rel=1e-12)
        boundary = float(model.boundary[condition].subs({D: d_value, f: f_value}))
        at_ridge = float(model.g[condition].subs({D: d_value, f: f_value, tau: expected}))
        assert boundary == pytest.approx(at_ridge, rel=1e-10, abs=1e-14)


def test_latex_forms_and_bad_names():
    model = SpringDamperContact("underdamped")
    assert "\\sqrt{1 - D^{2}}" in model.latex("z")
    assert "\\operatorname{atan}_{2}" in model.latex("ridge_time", condition="force")
    with pytest.raises(ValueError, match="condition"):
        model.latex("g")
    with pytest.raises(ValueError, match="'speed'"):
        model.latex("speed")
    with pytest.raises(ValueError, match="condition must be"):
        model.latex("g", condition="pressure")
    with pytest.raises(ValueError, match="regime must be one of"):
        SpringDamperContact("critically")


@pytest.mark.usefixtures("no_code_runs")
@pytest.mark.parametrize("value", [math.nan, -1.0, [0.5, 1.0], CODE])
def test_regime_of_refuses_what_is_not_a_damping_ratio(value):
    with pytest.raises((ValueError, TypeError), match="^D "):
        regime_of(value)


# -- symbolic: the contact from an arbitrary initial state ---------------------------------
REGIME_POINTS = {
    "underdamped": sp.Rational(37, 100),
    "critical": 1,
    "overdamped": sp.Rational(13, 5),
}


@pytest.mark.parametrize("regime", REGIMES)
def test_restart_solution_solves_the_contact_equation_from_its_initial_state(regime):
    model = spring_damper_restart(regime)
    z = model.z  # symbolic in D (D = 1 substituted in the critical regime)
    d = D if regime != "critical" else 1
    residual = sp.diff(z, tau, 2) + 2 * d * sp.diff(z, tau) + z - 2 * d * f
    assert sp.simplify(residual) == 0
    assert sp.simplify(z.subs(tau, 0) - z0) == 0
    assert sp.simplify(sp.diff(z, tau).subs(tau, 0) - v0) == 0
    z_dot = model.z_dot
    assert sp.simplify(sp.diff(z, tau) - z_dot) == 0


@pytest.mark.parametrize("regime", REGIMES)
def test_restart_contact_function_and_ridge_at_a_point(regime):
    """g = 2Dz' + z and dg/dtau = 0 at the closed-form ridge time (numbers, 30 digits)."""
    model = spring_damper_restart(regime)
    d = REGIME_POINTS[regime]
    z_start = sp.Rational(1, 2) if regime == "overdamped" else sp.Rational(1, 10)
    point = {D: d, f: sp.Rational(1, 20), z0: z_start, v0: sp.Rational(1, 5)}
    g = model.g["force"].subs(point)
    z = model.z.subs(point)
    assert abs(sp.N((g - 2 * d * sp.diff(z, tau) - z).subs(tau, sp.Rational(7, 3)), 30)) < 1e-25
    assert bool(model.ridge_exists["force"].subs(point))
    ridge = sp.N(model.ridge_time["force"].subs(point), 30)
    assert ridge > 0
    slope = sp.diff(model.g["force"].subs(point), tau).subs(tau, ridge)
    assert abs(sp.N(slope, 30)) < 1e-25


def test_restart_reduces_to_the_first_impact():
    for regime in REGIMES:
        start = {z0: 0, v0: 1}
        plain = SpringDamperContact(regime)
        restart = spring_damper_restart(regime)
        for condition in ("position", "force"):
            difference = restart.g[condition].subs(start) - plain.g[condition]
            assert sp.simplify(difference) == 0


@pytest.mark.parametrize("regime", ["underdamped", "overdamped"])
def test_numeric_basis_is_the_homogeneous_solution_from_its_states(regime):
    # C from (1, -D) and S from (0, 1), against the display-form solution (30 digits)
    model = spring_damper(regime)
    restart = spring_damper_restart(regime)
    for d_value in SAMPLE_D[regime]:
        d = sp.Rational(str(d_value))
        aux = {
            omega: sp.sqrt(1 - d**2),
            sigma: sp.sqrt(d**2 - 1),
            mu: d + sp.sqrt(d**2 - 1),
        }
        for form, state in zip(model.numeric_basis, ({z0: 1, v0: -d}, {z0: 0, v0: 1}), strict=True):
            for t_value in (sp.Rational(1, 3), sp.Integer(4)):
                point = {D: d, tau: t_value, f: 0, **state}
                got = form.subs(aux).subs(point).evalf(30)
                want = restart.z.subs(point).evalf(30)
                assert abs(got - want) < 1e-25, (regime, d_value, t_value)
