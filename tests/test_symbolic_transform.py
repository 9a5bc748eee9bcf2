"""The forward Laplace transform of exponential polynomials,
:mod:`impactsym.symbolic.transform`: against SymPy's ``laplace_transform`` and the table
pairs, and what it refuses."""

from __future__ import annotations

import pytest
import sympy as sp
from conftest import CODE

from impactsym.symbolic.rational import LaplaceInversionError
from impactsym.symbolic.transform import laplace_exp_poly

s, t = sp.symbols("s t")
a = sp.Symbol("a", positive=True)


@pytest.mark.parametrize(
    "g",
    [
        t**3 * sp.exp(-2 * t),
        sp.exp(-t) * (3 * sp.cos(2 * t) - t * sp.sin(2 * t)),
        t * sp.cosh(a * t) + sp.sinh(3 * t) / 3,
        sp.Integer(5) + 2 * t,
    ],
)
def test_agrees_with_sympy_laplace_transform(g):
    ours = laplace_exp_poly(g, t, s)
    theirs = sp.laplace_transform(g, t, s, noconds=True)
    assert sp.simplify((ours - theirs).rewrite(sp.exp)) == 0


def test_dirac_deltas_transform_to_powers_of_s():
    assert laplace_exp_poly(3 * sp.DiracDelta(t, 2) - sp.DiracDelta(t), t, s) == 3 * s**2 - 1


def test_forward_transform_rejects_non_exponential_polynomials():
    with pytest.raises(LaplaceInversionError):
        laplace_exp_poly(sp.log(t + 1), t, s)
    with pytest.raises(LaplaceInversionError, match="not linear"):
        laplace_exp_poly(sp.exp(t**2), t, s)


@pytest.mark.usefixtures("no_code_runs")
def test_strings_carrying_code_are_refused_by_name():
    with pytest.raises(TypeError, match=r"^g\b.*(string|symbols|Symbol|real number)"):
        laplace_exp_poly(CODE, t, s)
