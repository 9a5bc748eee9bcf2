"""impactsym: exact symbolic-numeric impact mechanics.

Three analyses of a body hitting a contact partner, after Waltersberger, Keppler and
Wauer (PAMM 2004): an elastic rod struck by a point mass (:mod:`impactsym.rod`), a
unilateral spring-damper contact (:mod:`impactsym.oscillator`, :mod:`impactsym.contact`)
and penalty contacts in multibody systems (:mod:`impactsym.multibody`).

Importing the package is cheap: the public functions below are loaded on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

_LAZY = {
    "contact_time": "impactsym.contact",
    "restitution": "impactsym.contact",
    "stick_boundary": "impactsym.contact",
    "physical_contact": "impactsym.contact",
    "SpringDamperContact": "impactsym.oscillator",
    "reduce_contact": "impactsym.multibody",
    "RodImpact": "impactsym.rod",
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'impactsym' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
