"""Checks for public inputs: every public function validates at its boundary.

Errors name the offending argument and value, so that a bad call fails early
and clearly instead of returning NaN.
"""

from __future__ import annotations

import numbers

import numpy as np

CONDITIONS = ("position", "force")


def check_condition(condition: object) -> str:
    """Return ``condition`` if it names a contact condition, else raise.

    >>> check_condition("force")
    'force'
    """
    if not isinstance(condition, str):
        raise TypeError(
            f"condition must be the string 'position' or 'force', got {condition!r} "
            f"of type {type(condition).__name__}"
        )
    if condition not in CONDITIONS:
        raise ValueError(f"condition must be 'position' or 'force', got {condition!r}")
    return condition


def real_array(
    name: str,
    value: object,
    *,
    lower: float | None = None,
    strict: bool = False,
    allow_inf: bool = False,
) -> tuple[np.ndarray, bool]:
    """Convert ``value`` to a float array and check its range.

    Parameters
    ----------
    name
        Argument name used in error messages.
    value
        A real number or array-like of real numbers (booleans, strings,
        complex numbers and objects are refused with ``TypeError``).
    lower
        Lower bound; values below it (or equal to it when ``strict``) are refused.
    strict
        Whether the lower bound itself is excluded.
    allow_inf
        Whether ``+inf`` is admissible (NaN never is).

    Returns
    -------
    (array, is_scalar)
        The values as a float64 array and whether the input was a scalar.

    >>> real_array("D", 0.5)
    (array(0.5), True)
    >>> real_array("D", -1.0, lower=0.0)
    Traceback (most recent call last):
        ...
    ValueError: D must be >= 0, got -1.0
    """
    is_scalar = np.ndim(value) == 0
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be a real number or array, got {value!r}")
    try:
        raw = np.asarray(value)
    except Exception as exc:  # pragma: no cover - exotic array-likes
        raise TypeError(f"{name} must be a real number or array, got {value!r}") from exc
    if raw.dtype == object and raw.ndim == 0 and isinstance(value, numbers.Real):
        raw = np.asarray(float(value))  # e.g. a SymPy Float or Fraction
    if raw.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must be a real number or array of real numbers, got {value!r} "
            f"(dtype {raw.dtype})"
        )
    arr = raw.astype(np.float64)
    bad = np.isnan(arr) | (np.isinf(arr) & ~(allow_inf & (arr > 0)))
    if bad.any():
        first = float(arr[bad].flat[0])
        raise ValueError(f"{name} must be finite, got {first!r}" + _where(arr, bad, is_scalar))
    if lower is not None:
        low = arr <= lower if strict else arr < lower
        if low.any():
            first = float(arr[low].flat[0])
            op = ">" if strict else ">="
            raise ValueError(
                f"{name} must be {op} {lower:g}, got {first!r}" + _where(arr, low, is_scalar)
            )
    return arr, is_scalar


def _where(arr: np.ndarray, mask: np.ndarray, is_scalar: bool) -> str:
    if is_scalar:
        return ""
    index = tuple(int(i[0]) for i in np.nonzero(mask))
    return f" (at index {index} of an array of shape {arr.shape})"


def finish(result: np.ndarray, is_scalar: bool) -> float | np.ndarray:
    """Return a Python float for scalar input, else the float array.

    >>> finish(np.asarray(2.0), True), finish(np.arange(2), False)
    (2.0, array([0., 1.]))
    """
    if is_scalar:
        return float(result)
    return np.asarray(result, dtype=np.float64)
