"""SymPy to NumPy (:mod:`impactsym.numeric.codegen`): the exported source of a lambdified
form is the code the package runs."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from impactsym.numeric.codegen import broadcast_evaluate, lambdified_source, lambdify

x, y = sp.symbols("x y")
EXPRESSIONS = [
    sp.exp(-x) * sp.cos(y) + sp.Rational(1, 3) * x**2,
    sp.Piecewise((sp.atan2(y, x), x * y < sp.Rational(1, 2)), (sp.pi + x, True)) / (1 + y**2),
    sp.sqrt(1 + x**2) * (sp.exp(-y) - 1) - sp.log(1 + y**2) + 2 * x * y * sp.sinc(x),
    sp.Integer(3),  # a constant: broadcast to the arguments' shape
]


@pytest.mark.parametrize("expr", EXPRESSIONS)
def test_lambdified_source_computes_the_same_floats_with_numpy_alone(expr):
    function = lambdify([x, y], expr, name="f")
    source = lambdified_source(function, "exported", "An exported form.")
    namespace = {"np": np}  # nothing else: SymPy's names must all have become np.<name>
    exec(compile(source, "<exported>", "exec"), namespace)
    exported = namespace["exported"]
    assert exported.__doc__ == "An exported form."
    rng = np.random.default_rng(1)
    a, b = rng.uniform(-3.0, 3.0, (2, 500))
    got = broadcast_evaluate(exported, a, b)
    assert np.array_equal(got, function(a, b), equal_nan=True)
    # and against SymPy itself at 30 digits, at a few points
    for u, v in zip(a[:5], b[:5], strict=True):
        exact = complex(expr.subs({x: u, y: v}).evalf(30))
        assert got[np.flatnonzero(a == u)[0]] == pytest.approx(exact.real, rel=1e-13, abs=1e-15)


def test_broadcast_evaluate_gives_float64_of_the_arguments_shape():
    out = broadcast_evaluate(lambda p, q: 2, np.zeros(3), np.zeros((2, 1)))
    assert out.shape == (2, 3)
    assert out.dtype == np.float64
