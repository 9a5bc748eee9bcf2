"""Package source into NumPy-only modules (:mod:`impactsym.numeric.pysource`): cuts are
the package's text, a module defines and imports exactly what it uses, and what a cut
uses is found through the package's own imports."""

from __future__ import annotations

import ast
import importlib.util
import inspect

import numpy as np
import pytest

from impactsym.numeric.pysource import Cut, Text, collect, module_source, package_source

SAMPLE = '''"""A sample module."""

from __future__ import annotations

from functools import cache
from time import perf_counter as clock

import numpy as np

#: The limit, with its doc comment.
LIMIT = 2.0
A, B = 1, 2


def helper(value):
    return value


def timed():
    return clock()


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


def test_collect_follows_the_package_imports_to_every_definition_used():
    from impactsym.contact import api

    pieces = collect(["# banner", Cut(api, "stick_boundary", required=("condition",))])
    first = pieces.index("# banner")  # the items come last, after what they use
    assert pieces[first + 1].startswith("def stick_boundary(f: ArrayLike, *, condition: str)")
    assert len(pieces) == first + 2
    defined = {n for p in pieces for n in module_source_names(p)}
    # through api -> kernel -> numeric.roots and validation, as the package imports them
    for name in ("flat_inputs", "boundary_value", "ridge", "kernels", "bracketed_newton"):
        assert name in defined, name
    for name in ("real_array", "_where", "F_FAR", "D_FAR", "ArrayLike", "ArrayFunction"):
        assert name in defined, name
    assert "contact_time" not in defined  # only what is used
    banner = "# -- impactsym.contact.kernel: definitions used below"
    kernel_pieces = pieces[pieces.index(banner) + 1 : first]
    order = [p for p in kernel_pieces if p.split("\n")[-1].startswith(("D_FAR", "F_FAR"))]
    assert order[0].endswith("D_FAR = 1e8")  # in the module's own order: F_FAR uses D_FAR


def module_source_names(piece):
    tree = ast.parse(piece)
    names = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)]
    return names


def test_collect_imports_the_standard_library_and_numpy_as_the_package_does(sample):
    from impactsym.rod import api
    from impactsym.symbolic import laplace

    pieces = collect([Cut(api, "displacement")])  # ArrayLike: numpy.typing in rod.api
    assert "from numpy.typing import ArrayLike" in pieces
    assert any(p.startswith("def time_function(") for p in pieces)  # the pole sums too
    source = module_source("Demo.", collect([Cut(sample, "timed")]))
    assert source.split("\n\n\n")[0].endswith("\n\nfrom time import perf_counter as clock")
    namespace = {}
    exec(source, namespace)
    assert namespace["timed"]() > 0
    with pytest.raises(ValueError, match="'sp' \\(impactsym.symbolic.laplace\\), not a package"):
        collect([Cut(laplace, "check_delay")])  # SymPy: never in an exported module
    with pytest.raises(ValueError, match="standard library and NumPy only"):
        module_source("Demo.", ["import sympy as sp", "def f():\n    return sp.pi"])


def test_collect_refuses_names_nothing_defines_and_conflicts():
    with pytest.raises(ValueError, match="'helper' \\(the written source\\)"):
        collect([Text("def f():\n    return helper()")])
    with pytest.raises(ValueError, match="two pieces of the generated module define 'f'"):
        collect([Text("def f():\n    return 1"), Text("def f():\n    return 2")])
