"""The author's LaTeX printer: conventions, collected forms, minimal conditions."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from impactsym.symbolic.typeset import (
    Abbreviation,
    Branch,
    Typeset,
    aligned,
    latex,
    minimal_condition,
    positive_factor,
    tidy,
)

D, f, t, alpha, x, y = sp.symbols("D f t alpha x y", positive=True)


def test_printer_writes_atan2_arctan_artanh_and_plain_function_brackets():
    u, v = sp.symbols("u v", real=True)  # atan2 of a positive x evaluates to atan(y/x)
    assert latex(sp.atan2(v, u)) == r"\operatorname{atan2}\left(v, u\right)"
    assert latex(sp.atan(x)) == r"\arctan\left(x\right)"
    assert latex(sp.atanh(x)) == r"\operatorname{artanh}\left(x\right)"
    assert latex(sp.cos(2 * x)) == r"\cos(2 x)"
    assert latex(sp.sinh(x)) == r"\sinh x"
    assert latex(sp.exp(-t / alpha)) == r"e^{- t / \alpha}"


def test_sums_start_with_a_constant_or_a_positive_term():
    assert latex(1 - 2 * f) == "1 - 2 f"
    assert latex(-4 * D**2 * (1 - f) + 1) == r"1 - 4 D^{2} \left(1 - f\right)"
    assert latex(sp.pi + sp.atan(x)) == r"\pi + \arctan\left(x\right)"
    assert latex(alpha * x + 1) == r"\alpha x + 1"
    assert latex(-x - y) == "- x - y"


def test_series_sum_is_set_as_a_fraction_times_its_delay_factor():
    n = sp.Symbol("n", integer=True, positive=True)
    delta = sp.Symbol("Delta", positive=True)
    term = 2 * ((x + f) * (x - 1) ** (n - 2)) / (x + 1) ** n
    body = latex(
        sp.Sum(
            sp.Mul(term, delta ** sp.Mul(2, n - 1, evaluate=False), evaluate=False), (n, 2, sp.oo)
        )
    )
    assert body == (
        r"\sum_{n \ge 2} \frac{2 \left(f + x\right) \left(x - 1\right)^{n - 2}}"
        r"{\left(x + 1\right)^{n}} \Delta^{2 \left(n - 1\right)}"
    )


@pytest.mark.parametrize("seed", range(5))
def test_tidy_and_positive_factor_keep_the_value(seed):
    rng = np.random.default_rng(seed)
    c = [sp.Integer(int(v)) for v in rng.integers(-5, 6, size=6)]
    decay = sp.exp(-t / alpha)
    expr = c[0] * alpha * f + c[1] * f * t + (c[2] * alpha * f + c[3] * t + c[4] * t**2 * f) * decay
    tidied = tidy(expr, (decay,), t)
    assert sp.expand(tidied - expr) == 0
    assert sp.expand(positive_factor(sp.factor(c[5] * (f - 1) * t)) - c[5] * (f - 1) * t) == 0


def test_positive_factor_turns_the_sign_into_the_bracket():
    assert latex(positive_factor(sp.factor(-2 * t * (f - 1)))) == r"2 t \left(1 - f\right)"


def test_typeset_sets_branches_as_cases_and_substitutes_abbreviations_back():
    w = sp.Symbol("omega_d", positive=True)
    form = Typeset(
        "x",
        (Branch(sp.cos(w * t), f < 1), Branch(sp.sin(w * t), f > 1)),
        (Abbreviation(w, sp.sqrt(1 - D**2)),),
    )
    body = form.latex()
    assert body.startswith(r"x = \begin{cases}\cos(\omega_{d} t), & f < 1 \\ ")
    assert body.endswith(r"\end{cases}, \qquad \text{with } \omega_{d} = \sqrt{1 - D^{2}}")
    value = form.expression().subs({D: sp.Rational(1, 2), t: 1, f: sp.Rational(1, 3)})
    assert value == sp.cos(sp.sqrt(3) / 2)
    assert form.expression().subs({D: sp.Rational(1, 2), t: 1, f: 1}) is sp.nan
    rows = aligned([form, r"y &= 0"])
    assert rows.startswith(r"\begin{aligned}x &= \begin{cases}")
    assert rows.endswith(r"y &= 0\end{aligned}")


def brute_force_equivalent(a: sp.Boolean, b: sp.Boolean, D_range, n=4000, seed=0) -> bool:
    """Whether ``a`` and ``b`` agree at random points (measure zero on a boundary)."""
    rng = np.random.default_rng(seed)
    Ds = rng.uniform(*D_range, n)
    fs = rng.uniform(0, 3, n)
    fa, fb = (sp.lambdify((D, f), c, "numpy") for c in (a, b))
    return bool(np.all(fa(Ds, fs) == fb(Ds, fs)))


def test_minimal_condition_of_the_overdamped_force_ridge_is_one_bound():
    # the condition derived for the ridge of the force condition, D > 1 (the issue's
    # example of a redundant condition): f < (D - sqrt(D^2 - 1)) / (2 D) alone
    s = sp.sqrt(D**2 - 1)
    p0 = 4 * D**2 * f - 4 * D**2 + 1
    q = -4 * D**3 * f + 4 * D**3 + 2 * D * f - 3 * D
    original = sp.And(p0 < 0, q + s * p0 > 0)
    reduced = minimal_condition(original, f, parameter=D, interval=sp.Interval.open(1, sp.oo))
    assert reduced == (f < (D - s) / (2 * D))
    assert brute_force_equivalent(original, reduced, (1, 6))


def test_minimal_condition_keeps_bounds_that_cross_and_flips_negative_coefficients():
    # f < D and f < 2 - D cross at D = 1 on (0, 2): both stay
    both = minimal_condition(
        sp.And(f < D, f - 2 + D < 0), f, parameter=D, interval=sp.Interval.open(0, 2)
    )
    assert len(sp.And.make_args(both)) == 2
    assert brute_force_equivalent(both, sp.And(f < D, f < 2 - D), (0, 2))
    # a negative coefficient turns the inequality round; a lower bound is kept
    flipped = minimal_condition(sp.And(1 - 2 * f < 0, 3 - f > 0), f)
    assert flipped == sp.And(f > sp.Rational(1, 2), f < 3)


def test_minimal_condition_refuses_what_it_cannot_reduce():
    with pytest.raises(ValueError, match="not linear"):
        minimal_condition(f**2 < 1, f)
    with pytest.raises(ValueError, match="not an inequality"):
        minimal_condition(sp.Eq(f, 1), f)
    with pytest.raises(ValueError, match="may change sign"):
        minimal_condition((D - 1) * f < 1, f, parameter=D, interval=sp.Interval.open(0, 2))
