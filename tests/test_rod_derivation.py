"""The rod impact's derivation (paper section 1), :mod:`impactsym.rod.derivation`: the
solution of eq. (1) by residuals, the Delta-series of eq. (2) against the print (typed in
:mod:`references.paper`), and the term-by-term inversion by forward transforms."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from conftest import CODE
from references.paper import eq2_sum, eq2_term

from impactsym.export import formula, latex_document
from impactsym.rod import RodImpact, latex_formulas
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


def test_rigid_Y_series_equals_eq2_term_by_term(rigid):
    terms = rigid.series("Y", 15)
    assert len(terms) == 15
    for n, (delay, coeff) in enumerate(terms, start=1):
        paper_delay, paper_coeff = eq2_term(n, s, alpha, f)
        assert delay == paper_delay
        assert sp.cancel(coeff - paper_coeff) == 0


def test_rigid_N_series_follows_from_the_end_condition(rigid):
    # end condition: N = f/s + alpha - alpha s^2 Y, applied term by term
    Y, N = rigid.series("Y", 10), rigid.series("N", 10)
    for k, ((dy, cy), (dn, cn)) in enumerate(zip(Y, N, strict=True)):
        assert dy == dn
        expected = -alpha * s**2 * cy + (f / s + alpha if k == 0 else 0)
        assert sp.cancel(cn - expected) == 0


def test_rigid_closed_form_is_eq2_summed(rigid):
    # eq. (2) as printed is a geometric series in exp(-2 s); the test sums it by hand
    assert vanishes_at_samples(rigid.closed_form("Y") - eq2_sum(s, alpha, f))


def test_series_partial_sums_approach_the_closed_forms_at_the_rate_of_eq2(rigid, elastic):
    # the closed forms solve eq. (1) (residual tests above); the remainder after n terms of
    # eq. (2) is of the order of its ratio q^n, q = exp(-2 s) |alpha s - 1| / (alpha s + 1)
    values = {alpha: sp.Rational(3, 2), f: sp.Rational(1, 3), kappa: 5, s: sp.Rational(3, 10)}
    q = float((sp.exp(-2 * s) * abs(alpha * s - 1) / (alpha * s + 1)).subs(values))
    for model in (rigid, elastic):
        for name in ("Y", "N"):
            exact = sp.N(model.closed_form(name).subs(values), 40)
            for n in (5, 10, 20):
                partial = sum(c * sp.exp(-d * s) for d, c in model.series(name, n))
                error = abs(sp.N(partial.subs(values), 40) - exact) / abs(exact)
                assert error < 4 * q ** (n - 1), (model.rigid, name, n)
            assert error < 1e-12


def test_finite_stiffness_coefficients_have_quadratic_denominators(elastic):
    P = alpha * s**2 + alpha * kappa * s + kappa
    for k, (_, coeff) in enumerate(elastic.series("N", 6)):
        denominator = sp.fraction(sp.factor(coeff))[1]
        assert sp.cancel(denominator / P ** (k + 1)).free_symbols <= {s, alpha, kappa}
        quadratic = [b for b in sp.Mul.make_args(denominator) if b.as_base_exp()[0].has(s)]
        assert any(sp.degree(b.as_base_exp()[0], s) == 2 for b in quadratic)


def test_finite_stiffness_series_tends_to_eq2_term_by_term(elastic):
    for n, (delay, coeff) in enumerate(elastic.series("Y", 6), start=1):
        paper_delay, paper_coeff = eq2_term(n, s, alpha, f)
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
    # round trip through the package's forward transform (itself checked against SymPy's)
    for model, names, n in ((rigid, ("Y", "N"), 8), (elastic, ("N",), 3)):
        for name in names:
            for (d1, g), (d2, c) in zip(
                model.time_terms(name, n), model.series(name, n), strict=True
            ):
                assert d1 == d2
                assert vanishes_at_samples(laplace_exp_poly(g, t, s) - c, n=2)


def laplace_integral(g: sp.Expr, s_value: sp.Rational) -> mp.mpf:
    """int_0^oo g(t) exp(-s t) dt by mpmath's tanh-sinh quadrature (30 digits)."""
    g_t = sp.lambdify(t, g, "mpmath")
    with mp.workdps(30):
        x = mp.mpf(s_value.p) / s_value.q
        return mp.quad(lambda u: g_t(u) * mp.exp(-x * u), [0, 1, 5, mp.inf])


def test_inverted_terms_transform_back_by_quadrature(rigid, elastic):
    """The Laplace integral of each inverted term, by quadrature, is the image term: a
    round trip that shares nothing with the package's transform rules."""
    values = {alpha: sp.Rational(3, 2), f: sp.Rational(1, 3), kappa: 5}
    for model, names, n in ((rigid, ("Y", "N"), 4), (elastic, ("N",), 2)):
        for name in names:
            for (_, g), (_, c) in zip(
                model.time_terms(name, n), model.series(name, n), strict=True
            ):
                for s_value in (sp.Rational(7, 10), sp.Rational(3)):
                    image = sp.N(c.subs(values).subs(s, s_value), 30)
                    with mp.workdps(30):
                        error = laplace_integral(g.subs(values), s_value) - mp.mpf(str(image))
                    assert abs(error) < 1e-25 * (1 + abs(image)), name


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


@pytest.mark.parametrize(
    ("kappa", "error", "pattern"),
    [
        (-math.inf, ValueError, "kappa must be > 0, got -inf"),
        (math.nan, ValueError, "kappa must be a positive number or inf, got nan"),
        (0.0, ValueError, "kappa must be > 0"),
        (sp.zoo, ValueError, "kappa must be > 0"),
        (sp.I, ValueError, "kappa must be > 0"),
        (True, TypeError, "kappa must be"),
        (None, TypeError, "kappa must be"),
    ],
)
def test_rod_impact_kappa_is_validated(kappa, error, pattern):
    with pytest.raises(error, match=pattern):
        RodImpact(kappa=kappa)


def test_rod_impact_extreme_kappa_is_exact():
    assert RodImpact(kappa=1e300).kappa == sp.Integer(10) ** 300
    assert RodImpact(kappa=np.float64(1e-300)).kappa == sp.Rational(1, 10**300)
    assert RodImpact(kappa=math.inf).rigid


@pytest.mark.parametrize("n_terms", [200, 21, 10**9])
def test_formula_documents_check_their_budget_before_any_work(n_terms):
    with pytest.raises(ValueError, match=f"n_terms = {n_terms} exceeds the budget of 20"):
        formula("rod-bvp", n_terms=n_terms)
    with pytest.raises(ValueError, match="exceeds the budget"):
        latex_document(n_terms)
    with pytest.raises(ValueError, match="exceeds the budget"):
        latex_formulas(n_terms)


@pytest.mark.parametrize("n_terms", [2.5, "3", True, -1])
def test_series_term_counts_are_validated(n_terms):
    with pytest.raises((TypeError, ValueError), match="n_terms must be"):
        RodImpact().series("Y", n_terms)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: RodImpact(kappa=CODE), "kappa"),
        (lambda: RodImpact(kappa=[CODE]), "kappa"),
        (lambda: RodImpact().residuals(1 / sp.Symbol("s"), CODE), "Y"),
    ],
)
def test_strings_carrying_code_are_refused_by_name(call, name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError, match=rf"^{name}\b.*(string|symbols|Symbol|real number)"):
        call()
    assert not (tmp_path / "PWNED").exists(), "a string input was run as code"
