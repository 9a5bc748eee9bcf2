"""Lazy public names for the package and its subpackages (PEP 562).

A subpackage lists which of its modules holds each public name; the module is imported
on first access only. This keeps ``import impactsym`` and the NumPy-only kernels free of
SymPy and Matplotlib until a name that needs them is used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def lazy_names(
    package: str, names: dict[str, str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package`` exporting ``names`` (name -> module).

    >>> getattr_, dir_ = lazy_names("demo", {"sqrt": "math"})
    >>> getattr_("sqrt")(4.0)
    2.0
    >>> dir_()
    ['sqrt']
    """

    def module_getattr(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(module), name)

    def module_dir() -> list[str]:
        return sorted(names)

    return module_getattr, module_dir
