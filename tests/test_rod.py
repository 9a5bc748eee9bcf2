"""Tests of the rod impact analysis (paper section 1), :mod:`impactsym.rod`."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from rod_characteristics import Characteristics
from scipy.optimize import brentq

from impactsym.rod import (
    RodImpact,
    contact_force,
    contact_time,
    displacement,
    latex_formulas,
    numpy_source,
)
from impactsym.symbolic.laplace import laplace_exp_poly

s, t, xi = RodImpact.s, RodImpact.t, RodImpact.xi
alpha, f = RodImpact.alpha, RodImpact.f
kappa = sp.Symbol("kappa", positive=True)


@pytest.fixture(scope="module")
def rigid() -> RodImpact:
    return RodImpact()


@pytest.fixture(scope="module")
def elastic() -> RodImpact:
    return RodImpact(kappa)


def vanishes_at_samples(expr: sp.Expr, n: int = 3) -> bool:
    """|expr| < 1e-30 at random rational points (40-digit evaluation)."""
    rng = np.random.default_rng(7)
    for _ in range(n):
        values = {
            sym: sp.Rational(int(rng.integers(1, 40)), int(rng.integers(1, 9)))
            for sym in expr.free_symbols
        }
        if xi in values:
            values[xi] = sp.Rational(int(rng.integers(0, 9)), 8)
        if abs(sp.N(expr.subs(values), 40)) > 1e-30:
            return False
    return True


# ------------------------------------------------------------- eq. (1) and (2)


def test_rigid_solution_solves_eq1(rigid):
    residuals = rigid.residuals(rigid.W, rigid.Y)
    assert set(residuals) == {"rod", "fixed end", "contact", "end"}
    for name, value in residuals.items():
        assert sp.simplify(value.rewrite(sp.exp)) == 0, name


def test_finite_stiffness_solution_solves_eq1(elastic):
    residuals = elastic.residuals(elastic.W, elastic.Y)
    assert set(residuals) == {"rod", "fixed end", "mass", "end"}
    for name, value in residuals.items():
        assert vanishes_at_samples(value), name


def test_residuals_detect_a_wrong_solution(rigid):
    wrong = rigid.residuals(rigid.W, rigid.Y * (1 + s / 100))
    assert not vanishes_at_samples(wrong["contact"])


def test_contact_force_is_minus_the_strain_at_the_struck_end(rigid, elastic):
    for model in (rigid, elastic):
        assert vanishes_at_samples(model.N + sp.diff(model.W, xi).subs(xi, 0))


def test_finite_stiffness_closed_forms_tend_to_rigid(rigid, elastic):
    for name in ("Y", "N"):
        assert (
            sp.simplify(sp.limit(elastic.closed_form(name), kappa, sp.oo) - rigid.closed_form(name))
            == 0
        )


def paper_eq2(n: int) -> tuple[int, sp.Expr]:
    """Term n of the paper's eq. (2), typed in from the paper."""
    if n == 1:
        return 0, (alpha * s + f) / (s**2 * (alpha * s + 1))
    return 2 * (n - 1), -2 * (alpha * s + f) * (alpha * s - 1) ** (n - 2) / (
        s**2 * (alpha * s + 1) ** n
    )


def test_rigid_Y_series_equals_eq2_term_by_term(rigid):
    terms = rigid.series("Y", 15)
    assert len(terms) == 15
    for n, (delay, coeff) in enumerate(terms, start=1):
        paper_delay, paper_coeff = paper_eq2(n)
        assert delay == paper_delay
        assert sp.cancel(coeff - paper_coeff) == 0


def test_rigid_N_series_follows_from_the_end_condition(rigid):
    # end condition: N = f/s + alpha - alpha s^2 Y, applied term by term
    Y, N = rigid.series("Y", 10), rigid.series("N", 10)
    for k, ((dy, cy), (dn, cn)) in enumerate(zip(Y, N, strict=True)):
        assert dy == dn
        expected = -alpha * s**2 * cy + (f / s + alpha if k == 0 else 0)
        assert sp.cancel(cn - expected) == 0


def test_series_sum_converges_to_the_closed_form(rigid, elastic):
    values = {alpha: sp.Rational(3, 2), f: sp.Rational(1, 3), kappa: 5, s: sp.Rational(3, 10)}
    for model in (rigid, elastic):
        for name in ("Y", "N"):
            exact = sp.N(model.closed_form(name).subs(values), 30)
            errors = []
            for n in (5, 10, 20):
                partial = sum(c * sp.exp(-d * s) for d, c in model.series(name, n))
                errors.append(abs(sp.N(partial.subs(values), 30) - exact))
            assert errors[2] < errors[1] < errors[0]
            assert errors[2] < 1e-3 * errors[0]


def test_finite_stiffness_coefficients_have_quadratic_denominators(elastic):
    P = alpha * s**2 + alpha * kappa * s + kappa
    for k, (_, coeff) in enumerate(elastic.series("N", 6)):
        denominator = sp.fraction(sp.factor(coeff))[1]
        assert sp.cancel(denominator / P ** (k + 1)).free_symbols <= {s, alpha, kappa}
        quadratic = [b for b in sp.Mul.make_args(denominator) if b.as_base_exp()[0].has(s)]
        assert any(sp.degree(b.as_base_exp()[0], s) == 2 for b in quadratic)


def test_finite_stiffness_series_tends_to_eq2_term_by_term(elastic):
    for n, (delay, coeff) in enumerate(elastic.series("Y", 6), start=1):
        paper_delay, paper_coeff = paper_eq2(n)
        assert delay == paper_delay
        assert sp.simplify(sp.limit(coeff, kappa, sp.oo) - paper_coeff) == 0


def test_W_series_has_incident_and_reflected_waves(rigid):
    terms = rigid.series("W", 4)
    assert [d for d, _ in terms] == [2 - xi, xi, 4 - xi, xi + 2]
    # at the struck end W(0) = Y term by term (delays 2j from both waves)
    Y = dict(rigid.series("Y", 3))
    W0: dict[sp.Expr, sp.Expr] = {}
    for d, c in rigid.series("W", 6):
        W0[d.subs(xi, 0)] = W0.get(d.subs(xi, 0), 0) + c
    for d in (0, 2, 4):
        assert sp.cancel(W0[d] - Y[d]) == 0


# ------------------------------------------------------------------ inversion


def test_inverted_terms_transform_back(rigid, elastic):
    for model, names, n in ((rigid, ("Y", "N"), 8), (elastic, ("N",), 3)):
        for name in names:
            for (d1, g), (d2, c) in zip(
                model.time_terms(name, n), model.series(name, n), strict=True
            ):
                assert d1 == d2
                assert vanishes_at_samples(laplace_exp_poly(g, t, s) - c, n=2)


def test_W_time_terms_have_delays_on_the_rod(rigid):
    terms = rigid.time_terms("W", 4)
    assert [d for d, _ in terms] == [2 - xi, xi, 4 - xi, xi + 2]


def test_series_and_time_terms_do_not_depend_on_call_order():
    one, two = RodImpact(), RodImpact()
    long_first = one.time_terms("N", 6)[:3]
    short = two.time_terms("N", 3)
    assert long_first == short
    assert one.series("Y", 2) == two.series("Y", 6)[:2]


def test_inverted_first_N_term_is_the_classical_rigid_striker(rigid):
    # f = 0: N = exp(-t/alpha) before the first reflection returns
    (delay, g), *_ = rigid.time_terms("N", 1)
    assert delay == 0
    assert sp.simplify(g.subs(f, 0) - sp.exp(-t / alpha)) == 0


@pytest.mark.parametrize("bad", [0, -1, float("nan"), -sp.oo])
def test_rod_impact_rejects_non_positive_kappa(bad):
    with pytest.raises(ValueError, match="kappa"):
        RodImpact(bad)


def test_rod_impact_rejects_non_numbers():
    with pytest.raises(TypeError, match="kappa"):
        RodImpact("stiff")
    with pytest.raises(ValueError, match="name"):
        RodImpact().series("X", 2)
    with pytest.raises(ValueError, match="n_terms"):
        RodImpact().series("Y", -1)
    with pytest.raises(TypeError, match="n_terms"):
        RodImpact().time_terms("Y", 2.0)


def test_rod_impact_accepts_float_and_infinite_kappa():
    assert RodImpact(2.5).kappa == sp.Rational(5, 2)
    assert RodImpact(np.float64(0.1)).kappa == sp.Rational(1, 10)
    with pytest.raises(ValueError, match="kappa"):
        RodImpact(sp.Symbol("k", negative=True))
    assert RodImpact(float("inf")).rigid


def test_latex_formulas_are_labelled_snippets():
    formulas = latex_formulas(2)
    labels = [label for label, _, _ in formulas]
    assert len(set(labels)) == len(labels)
    for required in ("rod-bvp", "rod-Y-rigid", "rod-N-kappa", "rod-eq2", "rod-N-series"):
        assert required in labels
    for _, caption, body in formulas:
        assert caption
        assert body.count("{") == body.count("}")
        assert "\\[" not in body
        assert "$" not in body


# --------------------------------------------------------------- time functions


@pytest.mark.parametrize("a", [0.05, 0.7, 50.0])
def test_classical_rigid_striker_before_the_first_reflection(a):
    tt = np.linspace(0.0, 1.999, 50)
    assert np.allclose(contact_force(tt, a, 0.0), np.exp(-tt / a), rtol=0, atol=1e-14)
    assert np.allclose(displacement(tt, a, 0.0), a * (1 - np.exp(-tt / a)), rtol=0, atol=1e-14)
    assert contact_force(0.0, a, 0.0) == 1.0  # the impact force of a rigid striker


def test_contact_force_jumps_by_two_when_a_reflection_returns():
    for k in (1, 2, 7, 30):
        left = contact_force(np.nextafter(2.0 * k, 0), 1.3, 0.4)
        right = contact_force(2.0 * k, 1.3, 0.4)
        assert abs(right - left - 2.0) < 1e-10


@pytest.mark.parametrize("a", [0.05, 1.0, 50.0])
@pytest.mark.parametrize("force", [0.0, 0.7, 5.0])
def test_agrees_with_the_method_of_characteristics_up_to_t_100(a, force):
    reference = Characteristics(a, force, 51)
    tt = np.sort(np.random.default_rng(3).uniform(0, 100, 150))
    assert np.max(np.abs(reference.N(tt) - contact_force(tt, a, force))) < 1e-9
    assert np.max(np.abs(reference.y(tt) - displacement(tt, a, force))) < 1e-9


def _dehoog(F, T):
    with mp.workdps(30):
        return float(mp.invertlaplace(F, T, method="dehoog", degree=100))


@pytest.mark.parametrize(
    ("a", "force", "k"), [(0.7, 0.4, math.inf), (2.0, 1.5, 3.0), (1.0, 0.0, 4.0)]
)
def test_agrees_with_numerical_inverse_laplace_up_to_t_5(a, force, k):
    """de Hoog (100 terms) on the closed forms; reliable only up to t = 5."""
    if math.isinf(k):
        den = lambda x: mp.cosh(x) + a * x * mp.sinh(x)  # noqa: E731
        N = lambda x: (a * x + force) * mp.cosh(x) / (x * den(x))  # noqa: E731
    else:
        den = lambda x: (a * x**2 + k) * mp.cosh(x) + a * k * x * mp.sinh(x)  # noqa: E731
        N = lambda x: k * (a * x + force) * mp.cosh(x) / (x * den(x))  # noqa: E731
    Y = (lambda x: N(x) * mp.tanh(x) / x) if math.isinf(k) else None
    for T in (0.9, 4.7):  # before and after the first reflection
        assert abs(_dehoog(N, T) - contact_force(T, a, force, k)) < 1e-10
    if Y is not None:
        assert abs(_dehoog(Y, 4.1) - displacement(4.1, a, force)) < 1e-10


@pytest.fixture(scope="module")
def exact_rigid_terms():
    """Reference: the exact inverted terms evaluated with mpmath (> 30 correct digits)."""
    rod = RodImpact()
    return {
        name: [
            (int(d), sp.lambdify((t, alpha, f), g, "mpmath")) for d, g in rod.time_terms(name, 51)
        ]
        for name in ("Y", "N")
    }


def _exact(terms, T, a, force):
    # the expanded terms cancel ~20 digits for small alpha: 60 working digits
    with mp.workdps(60):
        x, a, force = mp.mpf(T), mp.mpf(a), mp.mpf(force)
        return float(mp.fsum(g(x - d, a, force) for d, g in terms if d <= x))


@pytest.mark.parametrize("a", [0.05, 1.0, 50.0])
def test_far_out_agrees_with_30_digit_exact_terms(exact_rigid_terms, a):
    for T in (37.3, 71.9, 99.7):
        for name, fn in (("Y", displacement), ("N", contact_force)):
            assert abs(_exact(exact_rigid_terms[name], T, a, 5.0) - fn(T, a, 5.0)) < 1e-10


@pytest.fixture(scope="module")
def exact_elastic_terms(elastic):
    return {
        name: [
            (int(d), sp.lambdify((t, alpha, f, kappa), g, "mpmath"))
            for d, g in elastic.time_terms(name, 11)
        ]
        for name in ("N",)
    }


@pytest.mark.parametrize(
    ("a", "k"), [(0.05, 1.0), (1.0, 3.999), (50.0, 2.0), (0.05, 1000.0), (1.0, 100.0)]
)
def test_finite_stiffness_agrees_with_exact_terms_for_ten_round_trips(exact_elastic_terms, a, k):
    terms = exact_elastic_terms["N"]
    for T in (1.7, 9.4, 19.9):
        with mp.workdps(60):
            x = mp.mpf(T)
            args = (mp.mpf(a), mp.mpf("0.6"), mp.mpf(k))
            exact = float(mp.re(mp.fsum(g(x - d, *args) for d, g in terms if d <= x)))
        assert abs(exact - contact_force(T, a, 0.6, k)) < 1e-10


def test_critical_contact_damping_is_continuous_in_kappa():
    # alpha kappa = 4: the two poles merge; the neighbours are evaluated apart
    tt = np.array([0.5, 3.1, 8.7, 15.2, 19.5])
    at = contact_force(tt, 1.0, 0.3, 4.0)
    for dk in (1e-7, -1e-7):
        assert np.max(np.abs(contact_force(tt, 1.0, 0.3, 4.0 + dk) - at)) < 1e-5


def test_finite_stiffness_tends_to_rigid_contact():
    tt = np.linspace(0.0, 20.0, 201)
    away = np.abs(tt / 2 - np.round(tt / 2)) > 0.1  # away from the jumps of the rigid N
    errors_y, errors_N = [], []
    for k in (1e2, 1e3, 1e4):
        errors_y.append(np.max(np.abs(displacement(tt, 0.8, 0.5, k) - displacement(tt, 0.8, 0.5))))
        diff = contact_force(tt, 0.8, 0.5, k) - contact_force(tt, 0.8, 0.5)
        errors_N.append(np.max(np.abs(diff[away])))
    for errors in (errors_y, errors_N):
        assert errors[2] < errors[1] < errors[0]
        assert errors[1] / errors[2] > 5  # first order in 1/kappa
    assert errors_y[2] < 1e-3


@settings(max_examples=30, deadline=None)
@given(
    a=st.floats(0.05, 50.0),
    force=st.floats(0.0, 5.0),
    T=st.floats(0.05, 60.0).filter(lambda x: abs(x / 2 - round(x / 2)) > 0.01),
)
def test_striker_obeys_newton(a, force, T):
    """alpha y'' = f - N, by central differences away from the reflections."""
    h = 1e-3 * min(1.0, a)
    y = displacement(np.array([T - h, T, T + h]), a, force)
    acceleration = (y[0] - 2 * y[1] + y[2]) / h**2
    assert abs(a * acceleration - (force - contact_force(T, a, force))) < 1e-4 * (1 + force)


# ----------------------------------------------------------------- contact time


@pytest.mark.parametrize("a", [0.05, 0.5, 1.0, 1.5])
def test_contact_time_of_the_classical_rigid_striker(a):
    # f = 0: N = e^{-t/a} + 2 e^{-(t-2)/a} (1 - (t-2)/a) on (2, 4)
    expected = 2 + a * (1 + math.exp(-2 / a) / 2)
    assert abs(contact_time(a, 0.0) - expected) < 1e-12


def test_position_contact_time_of_the_classical_rigid_striker():
    a = 0.5  # y = a(1 - e^{-t/a}) - 2a + (2a + 2u) e^{-u/a}, u = t - 2, on (2, 4)

    def y(T: float) -> float:
        u = T - 2
        return a * (1 - math.exp(-T / a)) - 2 * a + (2 * a + 2 * u) * math.exp(-u / a)

    expected = brentq(y, 2.0, 4.0, xtol=1e-15)
    assert abs(contact_time(a, 0.0, "position") - expected) < 1e-12


def _dense_times(t_end: float) -> np.ndarray:
    """Uniform samples plus very fine ones right after every reflection, where the
    force oscillates on the time scale alpha / (number of reflections)."""
    after = (2.0 * np.arange(int(t_end // 2) + 1))[:, None] + np.linspace(0, 0.2, 4001)
    tt = np.r_[np.linspace(1e-9, t_end, 100_001), after.ravel()]
    return np.sort(tt[(tt > 0) & (tt <= t_end)])


def test_sticking_gives_infinity_and_is_real():
    assert contact_time(0.05, 2.0) == math.inf
    assert np.all(contact_force(_dense_times(100.0), 0.05, 2.0) > 0)


def test_release_in_a_fast_transient_after_many_reflections_is_found():
    # alpha = 0.05, f = 1: N dips below zero for ~2e-3 just after the 23rd reflection
    tc = contact_time(0.05, 1.0)
    assert 46.0 < tc < 46.006
    assert abs(contact_force(tc, 0.05, 1.0)) < 1e-9
    tt = _dense_times(tc)
    assert np.all(contact_force(tt[tt < tc - 1e-9], 0.05, 1.0) > 0)


def test_contact_time_is_a_zero_of_the_right_quantity():
    a = np.array([0.3, 2.0, 20.0])
    force = np.array([0.3, 0.8, 1.6])
    for condition, fn in (("force", contact_force), ("position", displacement)):
        tc = contact_time(a, force, condition)
        assert tc.shape == (3,)
        assert np.all(np.isfinite(tc))
        assert np.all(np.abs(fn(tc, a, force)) < 1e-9)
        for ti, ai, fi in zip(tc, a, force, strict=True):  # first crossing: positive before
            assert np.all(fn(np.linspace(1e-9, ti - 1e-6, 2000), ai, fi) > 0)


def test_contact_time_with_finite_stiffness():
    tc = contact_time(1.0, 0.2, kappa=50.0)
    assert 2.0 < tc < 20.0
    assert abs(contact_force(tc, 1.0, 0.2, 50.0)) < 1e-9
    # a stiff spring releases close to the rigid striker ...
    assert abs(contact_time(3.0, 0.0, kappa=1e5) - contact_time(3.0, 0.0)) < 1e-4
    assert abs(contact_time(1.0, 0.2, "position", 1e5) - contact_time(1.0, 0.2, "position")) < 1e-4
    # ... but not always under the force condition: when a reflection returns, the
    # spring force first dips (by about 0.15, for a time ~ 1/kappa) before it rises
    # by 2; if N is small just before, the spring releases there (non-uniform limit)
    for k in (1e3, 1e5):
        assert 4.0 < contact_time(1.0, 0.2, kappa=k) < 4.0 + 1.0 / k
    assert contact_time(1.0, 0.2) > 4.4


def test_heavy_striker_conditions_almost_coincide_and_force_spreads_them():
    """The paper's observation: large alpha, small f: the two contact times nearly
    coincide; growing f makes them differ strongly (small alpha)."""
    heavy = contact_time(50.0, 0.0, "position") / contact_time(50.0, 0.0, "force")
    assert abs(heavy - 1) < 0.05
    light = contact_time(0.1, 1.2, "position") / contact_time(0.1, 1.2, "force")
    assert light < 0.5


def test_contact_time_broadcasts():
    tc = contact_time(np.array([[0.5], [2.0]]), np.array([0.0, 0.3, 0.6]))
    assert tc.shape == (2, 3)
    assert tc[0, 0] == contact_time(0.5, 0.0)


# --------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"alpha": 0.0}, "alpha"),
        ({"alpha": -1.0}, "alpha"),
        ({"f": -0.1}, "f"),
        ({"kappa": 0.0}, "kappa"),
        ({"alpha": math.nan}, "alpha"),
        ({"f": math.inf}, "f"),
        ({"t": math.nan}, "t"),
    ],
)
def test_time_functions_reject_bad_input(kwargs, name):
    args = {"t": 1.0, "alpha": 1.0, "f": 0.5, "kappa": math.inf} | kwargs
    for fn in (displacement, contact_force):
        with pytest.raises(ValueError, match=name):
            fn(**args)


def test_contact_time_rejects_bad_input():
    with pytest.raises(ValueError, match="condition"):
        contact_time(1.0, 0.5, "pressure")
    with pytest.raises(ValueError, match="alpha"):
        contact_time(-1.0, 0.5)
    with pytest.raises(ValueError, match="kappa"):
        contact_time(1.0, 0.5, kappa=-2.0)
    with pytest.raises(ValueError, match="t_max"):
        contact_time(1.0, 0.5, t_max=0.0)
    with pytest.raises(TypeError, match="alpha"):
        contact_time("heavy", 0.5)


def test_time_functions_are_zero_before_impact_and_keep_shapes():
    assert displacement(-0.5, 1.0, 0.3) == 0.0
    assert contact_force(-0.5, 1.0, 0.3, 10.0) == 0.0
    assert isinstance(contact_force(1.0, 1.0, 0.3), float)
    assert contact_force(np.zeros((2, 3)), np.ones(3), 0.2).shape == (2, 3)


# ------------------------------------------------------------- generated module


def test_numpy_source_runs_with_numpy_only_and_matches():
    source = numpy_source()
    for word in ("sympy", "mpmath", "impactsym", "scipy"):
        assert f"import {word}" not in source
        assert f"from {word}" not in source
    namespace: dict = {}
    exec(compile(source, "<rod_numpy>", "exec"), namespace)
    tt = np.linspace(-1.0, 100.0, 997)
    for a, force in ((0.05, 0.0), (1.0, 2.0), (50.0, 5.0)):
        assert np.array_equal(
            namespace["rod_displacement"](tt, a, force), displacement(tt, a, force)
        )
        assert np.array_equal(
            namespace["rod_contact_force"](tt, a, force), contact_force(tt, a, force)
        )
    assert "alpha" in namespace["rod_displacement"].__doc__
    with pytest.raises(ValueError, match="alpha"):
        namespace["rod_contact_force"](1.0, 0.0, 0.0)
