"""The normalized contact laws written out by hand (p = 3/2): the independent reference of
``impactsym.contact.laws`` for the tests that integrate them with SciPy.

``phi(law, z, w, d)`` is the normalized force at overlap ``z``, rate ``w`` and damping
number ``d``; ``sign(law, z, w, d)`` has the sign of that force for ``z > 0`` and stays
smooth at ``z = 0`` (the event function of the force condition).
"""

from __future__ import annotations

import numpy as np

P = 1.5


def phi(law: str, z, w, d: float):
    z = np.maximum(z, 0.0)
    return {
        "linear": lambda: z + 2 * d * w,
        "hertz-linear": lambda: z**P + 2 * d * w,
        "hunt-crossley": lambda: z**P * (1 + d * w),
        "tsuji": lambda: z**P + d * z ** ((P - 1) / 2) * w,
        "viscoelastic": lambda: z**1.5 + d * np.sqrt(z) * w,
    }[law]()


def sign(law: str, z: float, w: float, d: float) -> float:
    """A function with the sign of the force for z > 0, smooth at z = 0."""
    z = max(z, 0.0)
    return {
        "linear": z + 2 * d * w,
        "hertz-linear": z**P + 2 * d * w,
        "hunt-crossley": 1 + d * w,
        "tsuji": d * w + z ** ((P + 1) / 2),
        "viscoelastic": z + d * w,
    }[law]
