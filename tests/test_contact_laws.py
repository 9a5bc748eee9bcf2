"""The laws' normalization and their closed forms, checked symbolically and numerically.

Residuals: the normalization of every law substituted back (SymPy); the Hunt–Crossley
exit equation with the Lambert-W restitution substituted (SymPy, and mpmath at 30
digits); the Tsuji phase plane mapped onto the linear one (SymPy). Independent
numbers: the published inverse ``lambda v0`` table, mpmath quadrature of the contact
time, and the integration of the Tsuji contact against the exact linear contact.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

from impactsym.contact import (
    LAWS,
    ContactLaw,
    HuntCrossleyClosedForm,
    TsujiMap,
    contact_law,
    impact,
    restitution,
)
from impactsym.contact.lawclosed import hunt_crossley_parameter, hunt_crossley_restitution
from impactsym.contact.lawkernel import integrate
from impactsym.contact.laws import s


@pytest.mark.parametrize("name", LAWS)
def test_every_law_normalizes_to_its_two_groups(name):
    law = contact_law(name)
    assert law.normalization_residual == 0
    groups = law.damping_number.free_symbols | law.pressing_number.free_symbols
    assert sp.Symbol("F_0", positive=True) in groups
    assert law.latex().startswith("\\begin{aligned}")
    assert ("p" in {str(x) for x in law.force.free_symbols}) == law.uses_exponent


def test_the_damping_parameters_are_named():
    names = {name: contact_law(name).parameter_name for name in LAWS}
    assert names == {"linear": "c", "hertz-linear": "c", "hunt-crossley": "lambda",
                     "tsuji": "alpha", "viscoelastic": "A"}  # fmt: skip


def test_an_unknown_law_is_refused_with_the_list():
    with pytest.raises(ValueError, match="'hunt-crossley'.*got 'hertz'"):
        ContactLaw("hertz")
    with pytest.raises(TypeError, match="law must be a string"):
        ContactLaw(3)


def test_hunt_crossley_restitution_solves_the_exit_equation():
    hc = HuntCrossleyClosedForm()
    assert hc.residual == 0
    e_sym = sp.Symbol("e", positive=True)
    equation = sp.lambdify((s, e_sym), hc.exit_equation, "mpmath")
    with mpmath.workdps(30):
        for value in ("0.001", "0.3", "2", "25"):
            sv = mpmath.mpf(value)
            ev = (1 + mpmath.lambertw(-(1 + sv) * mpmath.exp(-(1 + sv)))) / sv
            assert abs(equation(sv, ev)) < mpmath.mpf("1e-18")  # conditioning ~ s/(1 - s e)
            assert float(hunt_crossley_restitution(np.array(float(sv)))) == pytest.approx(
                float(ev), rel=2e-15
            )


def test_hunt_crossley_inverse_matches_the_published_table():
    e = np.array([0.2, 0.4, 0.6, 0.8, 0.9, 0.95])
    table = np.array([4.919, 2.083, 0.975, 0.373, 0.1665, 0.0789])
    s_values = hunt_crossley_parameter(e)
    np.testing.assert_allclose(s_values, table, rtol=6e-4)
    np.testing.assert_allclose(hunt_crossley_restitution(s_values), e, rtol=1e-14)


def test_hunt_crossley_is_independent_of_stiffness_and_exponent():
    r = impact(
        "hunt-crossley",
        stiffness=np.array([1e3, 1e7])[:, None],
        damping=0.8,
        mass=2.0,
        speed=1.5,
        exponent=np.array([1.0, 1.5, 2.5]),
        condition="position",
    )
    # integrated restitution (the kernel, not the closed form) against the closed form
    run = integrate("hunt-crossley", np.full(3, 1.2), np.zeros(3), np.array([1.0, 1.5, 2.5]),
                    condition="position")  # fmt: skip
    np.testing.assert_allclose(run.e, hunt_crossley_restitution(np.array(1.2)), atol=1e-11)
    np.testing.assert_allclose(r.restitution, hunt_crossley_restitution(np.array(1.2)), rtol=1e-15)


def test_hunt_crossley_contact_time_quadrature_and_penetration():
    hc = HuntCrossleyClosedForm()
    p_sym = sp.Symbol("p", positive=True)
    w_sym = sp.Symbol("w", real=True)
    for sv, pv in ((sp.Rational(7, 10), sp.Rational(3, 2)), (sp.Integer(3), sp.Integer(1))):
        integrand = hc.contact_time_integrand.subs({s: sv, p_sym: pv})
        integrand = sp.lambdify(w_sym, integrand, "mpmath")
        with mpmath.workdps(60):  # endpoint singularities (distance)^(-p/(p+1)): tanh-sinh
            e = mpmath.re(sp.lambdify(s, hc.restitution, "mpmath")(mpmath.mpf(sv.p) / sv.q))
            tau = mpmath.quad(lambda x, f=integrand: mpmath.re(f(x)), [-e, 0, 1])
        run = integrate("hunt-crossley", np.array([float(sv)]), np.zeros(1),
                        np.array([float(pv)]), condition="force")  # fmt: skip
        assert run.tau_c[0] == pytest.approx(float(tau), rel=1e-10)
        z_max = float(hc.max_penetration.subs({s: sv, p_sym: pv}))
        assert run.z_max[0] == pytest.approx(z_max, rel=1e-12)


def test_tsuji_maps_onto_the_linear_contact_symbolically():
    tm = TsujiMap()
    assert tm.residual == 0
    assert tm.force_residual == 0
    assert sp.simplify(tm.zeta.subs(sp.Symbol("p", positive=True), sp.Rational(3, 2))
                       - sp.Symbol("alpha", positive=True) / sp.sqrt(5)) == 0  # fmt: skip


@pytest.mark.parametrize("condition", ["position", "force"])
def test_tsuji_integrated_equals_the_linear_contact_exactly(condition):
    """The map proved numerically: integration of the Tsuji law (no closed form used)
    against the linear contact's exact restitution at zeta = alpha / sqrt(2 (p + 1))."""
    alpha = np.array([0.05, 0.5, 1.5, 2.1, 2.9, 4.0, 2.5])
    p = np.array([1.5, 1.5, 1.5, 1.5, 2.0, 3.0, 1.25])
    zeta = alpha / np.sqrt(2.0 * (p + 1.0))
    releases = (zeta < 1.0) | (condition == "force")
    run = integrate("tsuji", alpha[releases], np.zeros(releases.sum()), p[releases],
                    condition=condition)  # fmt: skip
    exact = restitution(zeta[releases], 0.0, condition=condition)
    np.testing.assert_allclose(run.e, exact, atol=1e-10)


def test_clipped_tsuji_with_the_dem_formula_misses_its_target():
    """The DEM design zeta = -ln e / sqrt(pi^2 + ln^2 e) is exact for the position
    condition (tensile force kept) and misses under the force condition (0.550 for 0.5)."""
    targets = np.array([0.5, 0.3, 0.2])
    zeta = -np.log(targets) / np.sqrt(np.pi**2 + np.log(targets) ** 2)
    alpha = zeta * np.sqrt(5.0)
    kept = impact("tsuji", stiffness=1e5, damping=alpha, mass=1.0, speed=1.0, condition="position")
    cut = impact("tsuji", stiffness=1e5, damping=alpha, mass=1.0, speed=1.0, condition="force")
    np.testing.assert_allclose(kept.restitution, targets, rtol=1e-12)
    np.testing.assert_allclose(cut.restitution, [0.550, 0.397, 0.325], atol=1.5e-3)
