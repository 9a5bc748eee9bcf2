"""Source generation (:mod:`impactsym.numeric.codegen`): the exported code is the code the
package runs, and a generated module defines and imports exactly what it uses."""

from __future__ import annotations

import ast
import importlib.util
import inspect

import numpy as np
import pytest
import sympy as sp

from impactsym.numeric.codegen import (
    broadcast_evaluate,
    lambdified_source,
    lambdify,
    module_source,
    package_source,
)

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


SAMPLE = '''"""A sample module."""

from __future__ import annotations

from functools import cache

import numpy as np

#: The limit, with its doc comment.
LIMIT = 2.0
A, B = 1, 2


def helper(value):
    return value


@cache
def scaled(x: np.ndarray, *, mode: str = "fast", factor: float = 2.0) -> np.ndarray:
    """Docstring: scaled(x) doubles."""
    return factor * helper(x) if mode == "fast" else scaled(x, mode="fast")


class Box:
    """A box."""

    def __init__(self, value):
        self.value = value

    def twice(self):
        return 2 * self.value
'''


@pytest.fixture
def sample(tmp_path):
    path = tmp_path / "sample_module.py"
    path.write_text(SAMPLE)
    spec = importlib.util.spec_from_file_location("sample_module", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_package_source_cuts_definitions_with_decorators_and_doc_comments(sample):
    assert package_source(sample, "LIMIT") == "#: The limit, with its doc comment.\nLIMIT = 2.0"
    assert package_source(sample, "B") == "A, B = 1, 2"
    source = package_source(sample, "scaled")
    assert source.startswith("@cache\ndef scaled(")
    assert source == inspect.getsource(sample.scaled).rstrip("\n")
    with pytest.raises(ValueError, match="'missing' is not defined at the top level"):
        package_source(sample, "missing")
    with pytest.raises(ValueError, match="'LIMIT' is a constant"):
        package_source(sample, "LIMIT", rename="BOUND")


def test_package_source_renames_requires_and_replaces(sample):
    source = package_source(sample, "scaled", rename="doubled", required=("mode",))
    assert "def doubled(" in source
    assert 'else doubled(x, mode="fast")' in source
    assert "scaled" not in source.replace("scaled(x) doubles", "")
    namespace = {"cache": __import__("functools").cache, "np": np, "helper": lambda v: v}
    exec("from __future__ import annotations\n" + source, namespace)
    parameters = inspect.signature(namespace["doubled"]).parameters
    assert parameters["mode"].default is inspect.Parameter.empty  # now required
    assert parameters["factor"].default == 2.0  # untouched
    with pytest.raises(TypeError, match="required keyword-only argument: 'mode'"):
        namespace["doubled"](1.0)
    assert namespace["doubled"](1.5, mode="fast") == 3.0
    new_init = "def __init__(self, value):\n    self.value = value + 1"
    box = package_source(sample, "Box", replace={"__init__": new_init})
    namespace = {}
    exec(box, namespace)
    assert namespace["Box"](1).twice() == 4
    assert '"""A box."""' in box


def test_module_source_imports_what_it_uses_and_refuses_what_is_undefined():
    pieces = [
        "def area(r):\n    return math.pi * r * r",
        "def area(r):\n    return math.pi * r * r",  # the same piece twice: written once
        "@dataclass\nclass Point:\n    x: Sequence[float]",
    ]
    source = module_source("Demo.", pieces, exports=("area", "Point"))
    tree = ast.parse(source)
    imports = [ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
    assert imports == [
        "from __future__ import annotations",
        "import math",
        "from collections.abc import Sequence",
        "from dataclasses import dataclass",
    ]  # no NumPy: nothing uses it
    assert source.count("def area") == 1
    assert '__all__ = [\n    "Point",\n    "area",\n]' in source
    namespace = {}
    exec(compile(source, "<demo>", "exec"), namespace)
    assert namespace["area"](1.0) == np.pi
    with pytest.raises(ValueError, match=r"undefined names: \['helper'\]"):
        module_source("Demo.", ["def f(x):\n    cache = 1\n    return helper(x) + cache"])
    # a local of the same name elsewhere does not hide a global use (scopes as Python's)
    scoped = module_source("Demo.", ["@cache\ndef f(x):\n    return x", "def g():\n    cache = 2"])
    assert "from functools import cache" in scoped
    with pytest.raises(ValueError, match="two pieces of the generated module define 'f'"):
        module_source("Demo.", ["def f():\n    return 1", "def f():\n    return 2"])
    with pytest.raises(ValueError, match="exported names not defined"):
        module_source("Demo.", ["def f():\n    return 1"], exports=("g",))
    with pytest.raises(ValueError, match="undefined names"):  # annotations count too
        module_source("Demo.", ["def f(x: Unknown):\n    return x"])
