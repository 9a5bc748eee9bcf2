"""Numeric machinery shared by every analysis.

* :mod:`~impactsym.numeric.roots` -- vectorized bracketed root finders (NumPy only);
* :mod:`~impactsym.numeric.exppoly` -- certified roots of :math:`e^x A(x) + B(x)`, and a
  cheap positivity certificate;
* :mod:`~impactsym.numeric.codegen` -- SymPy expressions to NumPy functions.
"""

from __future__ import annotations

from impactsym._lazy import lazy_names

_NAMES = {
    "bracketed_newton": "impactsym.numeric.roots",
    "bracketed_illinois": "impactsym.numeric.roots",
    "exp_poly_positive": "impactsym.numeric.exppoly",
    "exp_poly_roots": "impactsym.numeric.exppoly",
    "lambdify": "impactsym.numeric.codegen",
}
__all__ = sorted(_NAMES)
__getattr__, __dir__ = lazy_names(__name__, _NAMES)
