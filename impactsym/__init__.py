"""impactsym: exact symbolic-numeric impact mechanics.

Three analyses of a body hitting a contact partner, after Waltersberger, Keppler and
Wauer (PAMM 2004), each a subpackage with the same three layers (SymPy derivation,
NumPy/mpmath kernels, public API):

* :mod:`impactsym.rod` -- an elastic rod struck by a point mass (paper section 1);
* :mod:`impactsym.contact` -- the unilateral spring-damper contact (section 2);
* :mod:`impactsym.multibody` -- penalty contacts in multibody systems (section 3).

Shared machinery sits below them (:mod:`impactsym.symbolic`, :mod:`impactsym.numeric`,
:mod:`impactsym.validation`); presentation above (:mod:`impactsym.plotting`,
:mod:`impactsym.results`, :mod:`impactsym.export`, :mod:`impactsym.cli`).

Importing the package is cheap: the public functions below are loaded on first use.
"""

from __future__ import annotations

from impactsym._lazy import lazy_names

__version__ = "0.1.0"

_NAMES = {
    "contact_time": "impactsym.contact.api",
    "restitution": "impactsym.contact.api",
    "stick_boundary": "impactsym.contact.api",
    "physical_contact": "impactsym.contact.api",
    "bounce_sequence": "impactsym.contact.bounce",
    "SpringDamperContact": "impactsym.contact.derivation",
    "reduce_contact": "impactsym.multibody.reduction",
    "RodImpact": "impactsym.rod.derivation",
}

__all__ = ["__version__", *_NAMES]
__getattr__, _dir = lazy_names(__name__, _NAMES)


def __dir__() -> list[str]:
    return sorted(__all__)
