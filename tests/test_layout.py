"""The package's architecture, drawn from every import (module and function level).

Imports run one way: no circle between files; a module imports only its own floor or
lower ones, with one exception, the ``.plot()`` method of a result object, which
imports its figure from :mod:`impactsym.plotting` (and plotting, in turn, imports no
compute module at all); no private name crosses a module boundary; no file is over
600 lines; the kernels need no SymPy; options are keyword-only.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "impactsym"
MAX_LINES = 600

#: Floors from the ground up; a module may import only its own floor or lower ones. A
#: prefix names a module and everything below it (``impactsym.rod.elastic`` covers
#: ``rod/elastic.py`` as well as ``rod/elastic/taylor.py``); the longest prefix wins. A
#: prefix that matches no file is allowed (a module yet to come), a file that no prefix
#: matches is an error.
FLOORS = [
    (  # ground: shared helpers, no physics
        "impactsym._lazy",
        "impactsym._files",
        "impactsym.validation",
        "impactsym.records",
        "impactsym.numeric",
        "impactsym.symbolic",
    ),
    (  # derivations and kernels
        "impactsym.contact.derivation",
        "impactsym.contact.flight",
        "impactsym.contact.kernel",
        "impactsym.contact.unpressed",
        "impactsym.contact.extrema",
        "impactsym.contact.laws",
        "impactsym.contact.lawmaps",
        "impactsym.contact.viscoseries",
        "impactsym.contact.lawclosed",
        "impactsym.contact.lawkernel",
        "impactsym.contact.lawcoast",
        "impactsym.contact.lawtable",
        "impactsym.contact.lawpatch",
        "impactsym.contact.lawpressed",
        "impactsym.contact.lawonset",
        "impactsym.contact.lawrecord",
        "impactsym.contact.rk853",
        "impactsym.rod.derivation",
        "impactsym.rod.kernel",
        "impactsym.rod.rigid_search",
    ),
    (  # the wings' solvers and public faces
        "impactsym.contact.release",
        "impactsym.contact.api",
        "impactsym.contact.bounce",
        "impactsym.contact.codegen",
        "impactsym.contact.loop",
        "impactsym.contact.nonlinear",
        "impactsym.contact.lawdesign",
        "impactsym.contact.lawformulas",
        "impactsym.contact.lawnumbers",
        "impactsym.contact.lawstick",
        "impactsym.contact.lawgrid",
        "impactsym.contact.lawbounce",
        "impactsym.contact.lawlatex",
        "impactsym.rod.elastic",
        "impactsym.rod.codegen",
        "impactsym.rod.api",
        "impactsym.rod.contact_times",
        "impactsym.rod.history",
        "impactsym.rod.sequence",
        "impactsym.rod.sequence_rigid",
        "impactsym.rod.sequence_elastic",
    ),
    ("impactsym.multibody",),  # on top of the section-2 contact
    ("impactsym.engines",),  # MuJoCo and LAMMPS, bridged to contact and multibody
    ("impactsym.plotting", "impactsym.export"),  # presentation
    ("impactsym.results",),
    ("impactsym.reproduce", "impactsym.cli", "impactsym.__main__"),
]
#: The wings that compute; plotting imports none of them, at any level.
COMPUTE = (
    "impactsym.contact",
    "impactsym.rod",
    "impactsym.multibody",
    "impactsym.engines",
    "impactsym.numeric",
    "impactsym.symbolic",
)

#: Subpackages whose ``__init__`` holds lazy names (or nothing): the ground floor.
LAZY_PACKAGES = {*COMPUTE, "impactsym.plotting", "impactsym.results"}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def modules() -> dict[str, Path]:
    return {
        module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "__pycache__" not in p.parts
    }


def is_package(module: str) -> bool:
    path = modules().get(module)
    return path is not None and path.name == "__init__.py"


def floor_of(module: str) -> int | None:
    """The floor of ``module``; subpackage ``__init__`` files (lazy names only) and the
    package root are on the ground floor; ``None`` if no prefix matches."""
    if module == "impactsym" or (is_package(module) and module in LAZY_PACKAGES):
        return 0
    best = None
    for level, prefixes in enumerate(FLOORS):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and (
                best is None or len(prefix) > best[1]
            ):
                best = (level, len(prefix))
    return None if best is None else best[0]


def listed(items) -> str:
    """The offending modules, one a line, for the assertion message."""
    return "\n" + "\n".join(str(item) for item in items)


@dataclass(frozen=True)
class Import:
    source: str  #: the importing module
    target: str  #: the imported module of the package
    names: tuple[str, ...]  #: names taken from ``target`` (empty: the module itself)
    function: str | None  #: the enclosing function, ``None`` at module level
    line: int

    def __str__(self) -> str:
        where = f" in {self.function}()" if self.function else ""
        names = f" ({', '.join(self.names)})" if self.names else ""
        return f"{self.source}:{self.line}{where} -> {self.target}{names}"


def resolve(name: str) -> str | None:
    """The package module ``name`` refers to (its longest existing prefix)."""
    while name and name not in modules():
        name = name.rpartition(".")[0]
    return name or None


def walk(node: ast.AST, function: str | None = None):
    """Every import node under ``node`` with the name of its enclosing function."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.Import | ast.ImportFrom):
            yield child, function
        inner = child.name if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef) else None
        yield from walk(child, inner or function)


@cache
def imports() -> tuple[Import, ...]:
    """All imports between files of the package (also under ``if TYPE_CHECKING:``)."""
    found = []
    for source, path in modules().items():
        for node, function in walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [(alias.name, ()) for alias in node.names]
            else:
                base = node.module or ""
                if node.level:
                    package = source if is_package(source) else source.rpartition(".")[0]
                    for _ in range(node.level - 1):
                        package = package.rpartition(".")[0]
                    base = f"{package}.{base}" if base else package
                targets = []
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    targets.append((sub, ()) if sub in modules() else (base, (alias.name,)))
            for name, names in targets:
                target = resolve(name)
                if target is not None and target != source:
                    found.append(Import(source, target, names, function, node.lineno))
    return tuple(found)


def test_every_module_has_a_floor():
    homeless = [m for m in modules() if floor_of(m) is None]
    assert homeless == [], listed(homeless)


def test_no_import_circles():
    graph: dict[str, set[str]] = {m: set() for m in modules()}
    for edge in imports():
        graph[edge.source].add(edge.target)
    # Tarjan's strongly connected components; a component of two or more is a circle
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    circles = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(" <-> ".join(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert circles == [], listed(circles)


def test_imports_never_run_up_a_floor():
    upward = []
    for edge in imports():
        src, dst = floor_of(edge.source), floor_of(edge.target)
        if src is None or dst is None or dst <= src:
            continue  # a module without a floor is reported by its own test
        if edge.function == "plot" and edge.target.startswith("impactsym.plotting."):
            continue  # the one allowed upward call: a result object's .plot()
        upward.append(str(edge))
    assert upward == [], listed(upward)


def test_plotting_imports_no_compute_module():
    computing = [
        str(edge)
        for edge in imports()
        if edge.source.startswith("impactsym.plotting")
        and any(edge.target == w or edge.target.startswith(w + ".") for w in COMPUTE)
    ]
    assert computing == [], listed(computing)


def test_no_private_name_crosses_a_module_boundary():
    private = [
        str(edge)
        for edge in imports()
        for name in edge.names
        if name.startswith("_") and not name.startswith("__")
    ]
    assert private == [], listed(private)


def test_no_file_is_over_600_lines():
    long = {
        name: n
        for name, path in modules().items()
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert long == {}, listed(f"{name}: {n} lines" for name, n in long.items())


def test_the_layout_check_sees_function_level_imports_and_names_them():
    # the check itself: it sees .plot()'s function-level import, and its floors take
    # the subpackages of the target layout
    edges = [str(e) for e in imports() if e.source == "impactsym.contact.bounce"]
    assert any(" in plot() -> impactsym.plotting.bounce" in e for e in edges), edges
    assert floor_of("impactsym.rod.elastic.taylor") == floor_of("impactsym.rod.elastic")
    assert floor_of("impactsym.engines.mujoco.model") == floor_of("impactsym.engines.lammps")
    assert floor_of("impactsym.contact.kernel") < floor_of("impactsym.contact.api")


def test_kernels_and_root_finders_import_without_sympy():
    code = (
        "import sys\n"
        "for m in ('sympy', 'matplotlib'):\n"
        "    sys.modules[m] = None  # any import of them now fails\n"
        "import numpy as np\n"
        "import impactsym, impactsym.validation, impactsym.numeric.roots, impactsym.rod.kernel\n"
        "from impactsym.rod.kernel import rigid_evaluate\n"
        "one = np.ones(1)\n"
        "# rigid contact, f = 0: N(t) = exp(-t / alpha) before the first reflection\n"
        "print(float(rigid_evaluate('N', 0.5 * one, one, 0.0 * one)[0]))\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=PACKAGE.parent
    )
    assert run.returncode == 0, run.stderr
    assert float(run.stdout) == pytest.approx(float(__import__("numpy").exp(-0.5)), rel=1e-14)


#: Options are keyword-only everywhere (docs/vocabulary.md).
OPTIONS = {"condition", "kappa", "t_max", "n_points", "ax", "axes"}
#: An earlier contract: ReducedContact methods whose only argument is the condition.
POSITIONAL_CONDITION = {"ReducedContact"}
#: Functions whose subject is the option itself (a validator, a figure to save).
SUBJECT = {"impactsym.validation.check_condition", "impactsym.results.files.save_figure"}


def public_callables():
    import importlib
    import inspect

    for name in modules():
        if name.endswith("__main__") or "._" in name:
            continue
        module = importlib.import_module(name)
        for attr, obj in vars(module).items():
            if attr.startswith("_") or getattr(obj, "__module__", None) != name:
                continue
            if inspect.isfunction(obj):
                yield f"{name}.{attr}", obj
            elif inspect.isclass(obj) and attr not in POSITIONAL_CONDITION:
                for meth, fn in vars(obj).items():
                    if inspect.isfunction(fn) and not meth.startswith("_"):
                        yield f"{name}.{attr}.{meth}", fn


def test_options_are_keyword_only_in_every_public_function():
    import inspect

    positional = []
    for qualname, fn in public_callables():
        for param in inspect.signature(fn).parameters.values():
            subject = qualname in SUBJECT
            if param.name in OPTIONS and param.kind is not param.KEYWORD_ONLY and not subject:
                positional.append(f"{qualname}({param.name})")
    assert positional == [], listed(positional)


#: Where the two contact conditions give different answers, the caller must say which one
#: (a default would hand out a plausible number that may be the wrong one).
CONDITION_REQUIRED = {
    "impactsym.contact.api.contact_time",
    "impactsym.contact.api.restitution",
    "impactsym.contact.api.contact_surface",
    "impactsym.contact.api.stick_boundary",
    "impactsym.contact.api.physical_contact",
    "impactsym.contact.bounce.bounce_sequence",
    "impactsym.contact.bounce.bounce_map",
    "impactsym.rod.contact_times.contact_time",
    "impactsym.multibody.design.stick_damping",
    "impactsym.multibody.design.damping_for_restitution",
    "impactsym.multibody.design.penalty_for_targets",
    "impactsym.multibody.simulation.simulate_contact",
}


def test_condition_has_no_default_where_the_conditions_differ():
    import inspect

    callables = dict(public_callables())
    assert set(callables) >= CONDITION_REQUIRED, sorted(CONDITION_REQUIRED - set(callables))
    defaulted = [
        name
        for name, fn in callables.items()
        if "condition" in inspect.signature(fn).parameters
        # None means "only where it matters, and then it is asked for" (the latex methods)
        and inspect.signature(fn).parameters["condition"].default
        not in (inspect.Parameter.empty, None)
    ]
    assert defaulted == [], listed(defaulted)


def test_reduced_contact_verdicts_need_the_condition():
    import inspect

    from impactsym.multibody.oscillator import ReducedContact

    for method in (
        "contact",
        "contact_time",
        "normalized_contact_time",
        "restitution",
        "sticks",
        "verdict",
    ):
        param = inspect.signature(getattr(ReducedContact, method)).parameters["condition"]
        assert param.default is inspect.Parameter.empty, method


def test_a_forgotten_condition_is_a_type_error_naming_it():
    from impactsym import contact

    with pytest.raises(TypeError, match="condition"):
        contact.contact_time(0.5, 0.2)
