"""The viscoelastic restitution series, checked against what it did not use: the published
constants, an mpmath quadrature of the hierarchy (incomplete Beta functions), the exact
numerics of ``impact`` and scipy's solve_ivp with events, whose differences from the
truncated series must fall like the first power left out (the order is tested, not only
the closeness)."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest
import sympy as sp
from references import latex_reader
from scipy.integrate import solve_ivp

from impactsym.cli import main
from impactsym.contact.lawlatex import viscoelastic_formulas
from impactsym.contact.nonlinear import impact
from impactsym.contact.viscoseries import (
    delayed_recovery_coefficients,
    position_polynomials,
    reduction_residual,
    universal_coefficients,
    viscoelastic_restitution_series,
)


def observed_order(beta: np.ndarray, error: np.ndarray) -> float:
    """Slope of log|error| against log beta (least squares)."""
    return float(np.polyfit(np.log(beta), np.log(np.abs(error)), 1)[0])


def first_term_left_out(order: int, condition: str) -> tuple[float, float]:
    """The lowest power of beta above ``order`` with a non-zero coefficient, and that
    coefficient."""
    longer = viscoelastic_restitution_series(order + 2, condition=condition)
    keep = (longer.powers > order) & (np.abs(longer.coefficients) > 1e-12)
    return float(longer.powers[keep][0]), float(longer.coefficients[keep][0])


def betas_for(order: int, condition: str) -> np.ndarray:
    """Damping numbers 1, 2, 4, 8 times the one where the first term left out is 1e-10:
    large enough for the integrations' 1e-13, small enough for that term to dominate."""
    power, coefficient = first_term_left_out(order, condition)
    return (1e-10 / abs(coefficient)) ** (1 / power) * 2.0 ** np.arange(4)


def test_the_published_constants_and_the_exact_second_coefficient():
    s = viscoelastic_restitution_series(2, condition="position")
    # Ramirez, Poschel, Brilliantov & Schwager 1999: C1 = 1.15344, C2 = 0.79826
    assert -s.coefficients[2] == pytest.approx(1.15344, abs=1e-5)
    assert s.coefficients[4] == pytest.approx(0.79826, abs=1e-5)
    with mpmath.workdps(30):
        C1 = (
            mpmath.gamma(mpmath.mpf(3) / 5)
            * mpmath.sqrt(mpmath.pi)
            / (
                2 ** (mpmath.mpf(1) / 5)
                * 5 ** (mpmath.mpf(2) / 5)
                * mpmath.gamma(mpmath.mpf(21) / 10)
            )
        )
        assert abs(-s.precise[2] - C1) < 1e-25
    # C2 = 3/5 C1^2 exactly, and both are exact Gamma-function numbers
    assert sp.simplify(s.exact[4] - sp.Rational(3, 5) * s.exact[2] ** 2) == 0
    assert s.powers.tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]
    # the force condition's first half-integer terms involve C_1 only: exact
    f = viscoelastic_restitution_series(5, condition="force")
    C_1 = -f.exact[2]
    assert f.exact[5] == sp.Rational(4, 15)
    assert sp.simplify(f.exact[7] + sp.Rational(2, 5) * C_1) == 0
    assert sp.simplify(f.exact[9] - sp.Rational(17, 50) * C_1**2) == 0
    assert f.exact[6] is None
    assert f.exact[10] is None


def test_the_reduction_to_the_universal_function_is_exact():
    assert reduction_residual() == 0
    # the gamma^2 term of the odd part of log Y vanishes: h_2 involves c_1 only
    c_1, kappa = sp.symbols("c_1 kappa")
    assert position_polynomials(2)[1:] == (-c_1 * kappa, sp.Rational(3, 5) * c_1**2 * kappa**2)


def test_the_hierarchy_against_an_independent_quadrature():
    # c_2 = 1/2 int_0^1 t^(1/2) s_0(t) I(t) dt with I(t) = int_0^t u^(1/2)/s_0(u) du an
    # incomplete Beta function (order of integration swapped), by tanh-sinh quadrature
    with mpmath.workdps(30):
        fifth = mpmath.mpf(1) / 5

        def inner(t):
            return 2 * fifth * mpmath.betainc(3 * fifth, mpmath.mpf(1) / 2, 0, t**2.5)

        c_2 = mpmath.quad(lambda t: mpmath.sqrt(t) * mpmath.sqrt(1 - t**2.5) * inner(t), [0, 1]) / 2
        c = universal_coefficients(3, nodes=48, dps=40)
        assert abs(c[2] - c_2) < 1e-20
        # two resolutions agree: the spectral integration has converged
        finer = universal_coefficients(6, nodes=80, dps=50)
        coarse = universal_coefficients(6, nodes=48, dps=40)
        assert all(abs(a - b) < 1e-18 for a, b in zip(finer, coarse, strict=True))


def test_the_delayed_recovery_coefficients_against_an_integration():
    # e_f / e_p = G(t): integrate dS/dr = 2t (r^2 - r^4/S) from S(0) = 1 to r^2 = S with
    # mpmath's Taylor integrator; the truncation error of G falls like t^5 at 4 terms
    g = [mpmath.mpf(x.numerator) / x.denominator for x in delayed_recovery_coefficients(4)]
    errors = []
    ts = [mpmath.mpf("0.05"), mpmath.mpf("0.1"), mpmath.mpf("0.2")]
    with mpmath.workdps(30):
        for t in ts:
            S = mpmath.odefun(lambda r, S, t=t: 2 * t * (r**2 - r**4 / S), 0, 1)
            r_star = mpmath.findroot(lambda r, S=S: r**2 - S(r), 1)
            errors.append(r_star**2 - mpmath.polyval(g[::-1], t))
    slopes = [float(mpmath.log(errors[i + 1] / errors[i]) / mpmath.log(2)) for i in range(2)]
    assert slopes == pytest.approx([5.0, 5.0], abs=0.1)


@pytest.mark.parametrize("condition", ["position", "force"])
@pytest.mark.parametrize("order", [2, 3, 4])
def test_the_truncation_error_falls_like_the_next_power_against_impact(order, condition):
    betas = betas_for(order, condition)
    r = impact(
        "viscoelastic",
        stiffness=1.0,
        damping=betas / 1.5,
        mass=1.0,
        speed=1.0,
        condition=condition,
    )
    np.testing.assert_allclose(r.damping_number, betas, rtol=1e-15)
    s = viscoelastic_restitution_series(order, condition=condition)
    error = r.restitution - s.restitution(betas)
    power, coefficient = first_term_left_out(order, condition)
    assert observed_order(betas, error) == pytest.approx(power, abs=0.1)
    # and the error is that term, up to the next one (relative size ~ beta^(1/2))
    np.testing.assert_allclose(error[0] / (coefficient * betas[0] ** power), 1.0, atol=0.1)


def release_speed(beta: float, condition: str) -> float:
    """scipy's DOP853 with an event: z = 0 (position) or z + beta z' = 0 (force)."""

    def rhs(_, y):
        z, v = y
        root = np.sqrt(max(z, 0.0))
        return [v, -z * root - beta * root * v]

    def ends(_, y):
        return y[0] if condition == "position" else y[0] + beta * y[1]

    ends.terminal, ends.direction = True, -1
    run = solve_ivp(rhs, (0, 20), [0.0, 1.0], method="DOP853", events=ends, rtol=1e-13, atol=1e-15)
    return -run.y_events[0][0][1]


@pytest.mark.parametrize("condition", ["position", "force"])
def test_the_series_against_solve_ivp_with_events(condition):
    betas = np.array([0.01, 0.02, 0.04])
    e = np.array([release_speed(b, condition) for b in betas])
    s = viscoelastic_restitution_series(3, condition=condition)
    error = e - s.restitution(betas)
    expected = 4.0 if condition == "position" else 3.5
    assert observed_order(betas, error) == pytest.approx(expected, abs=0.12)
    # a longer series is closer, by about the next power
    longer = viscoelastic_restitution_series(5, condition=condition)
    assert np.all(np.abs(e - longer.restitution(betas)) < np.abs(error) * 0.05)


def test_the_evaluator_is_vectorized_and_checks_its_input():
    s = viscoelastic_restitution_series(4, condition="force")
    grid = np.linspace(0.0, 0.1, 12).reshape(3, 4)
    e = s.restitution(grid)
    assert e.shape == (3, 4)
    assert e[0, 0] == 1.0
    assert isinstance(s.restitution(0.02), float)
    np.testing.assert_allclose(s.restitution(grid.ravel()), e.ravel(), rtol=0, atol=0)
    with pytest.raises(ValueError, match="beta"):
        s.restitution(-0.1)
    with pytest.raises(ValueError, match="order"):
        viscoelastic_restitution_series(-1, condition="position")
    with pytest.raises(ValueError, match="order"):
        viscoelastic_restitution_series(2.0, condition="position")
    with pytest.raises(ValueError, match="condition"):
        viscoelastic_restitution_series(2, condition="positon")
    with pytest.raises(TypeError):
        viscoelastic_restitution_series(2)  # condition has no default
    with pytest.raises(ValueError, match="order"):
        viscoelastic_restitution_series(17, condition="force")
    with pytest.raises(ValueError, match="nodes"):
        universal_coefficients(2, nodes=4)
    with pytest.raises(ValueError, match="dps"):
        universal_coefficients(2, dps=10.5)
    assert s == viscoelastic_restitution_series(4, condition="force")
    assert s != viscoelastic_restitution_series(4, condition="position")


@pytest.fixture
def formulas(monkeypatch):
    """The viscoelastic formulas of ``impactsym latex`` read back by the test reader,
    without their remainder terms."""
    monkeypatch.setitem(latex_reader.NAMES, r"\beta", "beta")
    monkeypatch.setitem(latex_reader.FUNCTIONS, r"\Gamma", "gamma")
    read = {}
    for label, _, text in viscoelastic_formulas():
        text = re.sub(r" \+ \\mathcal\{O\}\\left\(.*?\\right\)", "", text)
        read[label] = latex_reader.read(text.replace(r"\cdot", " "), {"gamma": sp.gamma})["rhs"]
    return read


def test_the_formulas_are_printed_by_the_command_line(capsys):
    for label, _, text in viscoelastic_formulas():
        assert main(["latex", label]) == 0
        assert capsys.readouterr().out.strip() == text


def test_the_formulas_read_back_give_the_exact_numerics(formulas):
    beta, C_1, e_p = sp.symbols("beta C_1 e_p")
    c1_value = float(formulas["law-viscoelastic-c1"])
    assert c1_value == pytest.approx(1.15344, abs=1e-5)
    series = sp.lambdify(beta, formulas["law-viscoelastic-restitution-series"].subs(C_1, c1_value))
    recovery = sp.lambdify((beta, e_p), formulas["law-viscoelastic-delayed-recovery"])
    betas = np.array([0.01, 0.02, 0.05, 0.1, 0.2])
    runs = {
        condition: impact(
            "viscoelastic",
            stiffness=1.0,
            damping=betas / 1.5,
            mass=1.0,
            speed=1.0,
            condition=condition,
        ).restitution
        for condition in ("position", "force")
    }
    # position: the remainder is h_3 beta^3 with |h_3| = 0.523
    np.testing.assert_array_less(np.abs(runs["position"] - series(betas)), 0.6 * betas**3)
    # force from position: the remainder is O(beta^(15/2)) (g_3 = 0.0304)
    np.testing.assert_array_less(
        np.abs(runs["force"] - recovery(betas, runs["position"])), 0.05 * betas**7.5 + 1e-12
    )
