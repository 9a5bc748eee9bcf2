"""Helpers shared by the LAMMPS Hooke modules: natural units, flags, range checks.

Not part of the public API of :mod:`impactsym.engines.lammps` (they are public names
only so that the package's modules may share them).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from impactsym.contact.release import LinearRelease, linear_release

__all__ = ["TINY", "check_flag", "natural", "release", "unrepresentable"]

#: the smallest normal float: products and quotients below it have lost digits
TINY = float(np.finfo(float).tiny)


def release(D: np.ndarray, load: np.ndarray, limit_damping: bool) -> LinearRelease:
    """The normalized first release (``omega0``, ``v0`` units) of a Hooke contact."""
    return linear_release(D, load, np.zeros_like(D), force=limit_damping, position=True)


def natural(k: np.ndarray, eta: np.ndarray, m: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``omega0 = sqrt(kn / m)``, ``sqrt(kn m)`` and ``D = eta_n / (2 sqrt(kn m))``.

    Scale-free: where ``kn / m`` or ``kn m`` leaves the normal float range (``kn = m =
    1e160``: ``kn m = inf``, ``D = 0``) the square roots are taken first, which cannot
    overflow or underflow for finite positive inputs; elsewhere the plain products
    (unchanged results).
    """
    with np.errstate(over="ignore", under="ignore"):
        omega = np.sqrt(k / m)
        redo = ~(np.isfinite(omega) & (omega >= TINY))
        omega = np.where(redo, np.sqrt(k) / np.sqrt(m), omega)
        root = np.sqrt(k * m)
        redo = ~(np.isfinite(root) & (root >= TINY))
        root = np.where(redo, np.sqrt(k) * np.sqrt(m), root)
        D = eta / (2.0 * root)
    return omega, root, D


def check_flag(name: str, value: object) -> bool:
    """``value`` if it is a bool (``bool("no")`` is True: strings are refused), else raise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def unrepresentable(what: str, values: np.ndarray, inputs: dict[str, Any]) -> None:
    """Refuse a derived quantity beyond the float range, naming the inputs behind it."""
    bad = ~np.isfinite(values)
    if bad.any():
        i = np.flatnonzero(bad.ravel())[0]
        shown = ", ".join(
            f"{name} = {float(np.ravel(np.broadcast_to(v, values.shape))[i])!r}"
            for name, v in inputs.items()
        )
        raise ValueError(f"{what} is beyond the float range for {shown}")
