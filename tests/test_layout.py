"""The package's architecture: imports run one way and the kernels need no SymPy."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "impactsym"

#: Floors from the ground up; a module may import (at module level) only its own floor
#: or lower ones. Imports inside functions (``.plot()`` methods, lazy engines) are free.
FLOORS = [
    ("impactsym._lazy", "impactsym.validation", "impactsym.numeric", "impactsym.symbolic"),
    (
        "impactsym.contact.derivation",
        "impactsym.contact.flight",
        "impactsym.rod.derivation",
        "impactsym.rod.kernel",
        "impactsym.rod.rigid_search",
    ),
    (
        "impactsym.rod.elastic",
        "impactsym.contact.api",
        "impactsym.contact.bounce",
    ),
    ("impactsym.rod.api", "impactsym.rod.contact_times", "impactsym.rod.codegen"),
    (
        "impactsym.rod.continuation",
        "impactsym.rod.elastic_continuation",
        "impactsym.multibody",
        "impactsym.engines",
    ),
    ("impactsym.plotting", "impactsym.export", "impactsym.results"),
    ("impactsym.reproduce", "impactsym.cli", "impactsym.__main__"),
]
ALIASES = {"oscillator", "laplace", "penalty_design", "penalty_simulation"}
#: Subpackage ``__init__`` modules hold lazy names only: the ground floor.
PACKAGES = {"impactsym.contact", "impactsym.rod"}


def floor_of(module: str) -> int:
    if module in PACKAGES:
        return 0
    best = None
    for level, prefixes in enumerate(FLOORS):
        for prefix in prefixes:
            matches = module == prefix or module.startswith(prefix + ".")
            if matches and (best is None or len(prefix) > best[1]):
                best = (level, len(prefix))
    if best is None:
        raise AssertionError(f"{module} has no floor in tests/test_layout.py")
    return best[0]


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def top_level_imports(path: Path) -> set[str]:
    out = set()
    for node in ast.parse(path.read_text()).body:  # module level only
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module)
        elif isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
    return {m for m in out if m.startswith("impactsym.")}


def package_modules() -> list[Path]:
    return [
        p
        for p in sorted(PACKAGE.rglob("*.py"))
        if p.parent != PACKAGE or (p.stem not in ALIASES and p.stem != "__init__")
    ]


def test_imports_never_run_up_a_floor():
    upward = []
    for path in package_modules():
        name = module_name(path)
        if name == "impactsym":
            continue
        for target in top_level_imports(path):
            if floor_of(target) > floor_of(name):
                upward.append(f"{name} -> {target}")
    assert upward == []


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


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("oscillator", "contact.derivation"),
        ("laplace", "symbolic.laplace"),
        ("penalty_design", "multibody.design"),
        ("penalty_simulation", "multibody.simulation"),
    ],
)
def test_former_module_names_are_the_new_modules(old, new):
    import importlib

    assert importlib.import_module(f"impactsym.{old}") is importlib.import_module(
        f"impactsym.{new}"
    )


#: Options are keyword-only everywhere (docs/vocabulary.md).
OPTIONS = {"condition", "kappa", "t_max", "n_points", "ax", "axes"}
#: An earlier contract: ReducedContact methods whose only argument is the condition.
POSITIONAL_CONDITION = {"ReducedContact"}
#: Functions whose subject is the option itself (a validator, a figure to save).
SUBJECT = {"impactsym.validation.check_condition", "impactsym.results.files.save_figure"}


def public_callables():
    import importlib
    import inspect

    for path in package_modules():
        name = module_name(path)
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
    assert positional == []
