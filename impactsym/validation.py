"""Checks for public inputs: every public function validates at its boundary.

Errors name the offending argument and value, so that a bad call fails early
and clearly instead of returning NaN.

Symbolic inputs go through :func:`as_sympy` (one expression) or :func:`as_sympy_matrix`
(a matrix or vector): strings are refused anywhere, also nested in lists, tuples, dicts
or arrays, and everything else is converted with ``sympy.sympify(value, strict=True)``,
which never parses text. No input of the package is ever evaluated as code.
"""

from __future__ import annotations

import contextlib
import numbers
from collections.abc import Iterable, Iterator, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import sympy as sp

CONDITIONS = ("position", "force")
#: Text and raw bytes: never numbers, and SymPy would parse them as code.
_BYTES_OR_TEXT = (str, bytes, bytearray, memoryview, np.str_, np.bytes_)
#: Anything that holds several values (lists, ranges, generators, SymPy tuples and arrays).
_CONTAINERS = (Iterable, Mapping, np.ndarray)


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


def check_count(name: str, value: object, *, lower: int = 1, upper: int) -> int:
    """Return ``value`` as an ``int`` if it is a whole number in ``[lower, upper]``.

    Any integral type is taken (``int``, NumPy integers); ``bool``, floats (also
    ``2.0``) and text are refused, as is a count above ``upper``: caps and step
    counts set how much work and memory a call may take, so an absurd one is an
    error naming the argument, not minutes of work or a ``MemoryError``.

    >>> check_count("max_contacts", np.int64(5), upper=10**6)
    5
    >>> check_count("steps", 0, upper=10)
    Traceback (most recent call last):
    ...
    ValueError: steps must be an integer in [1, 10], got 0
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(
            f"{name} must be an integer, got {_short(value)} of type {type(value).__name__}"
        )
    if not lower <= value <= upper:
        raise ValueError(f"{name} must be an integer in [{lower}, {upper}], got {value}")
    return int(value)


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
    if isinstance(value, _BYTES_OR_TEXT) or value is None:
        raise TypeError(f"{name} must be a real number or array, got {value!r}")
    is_scalar = np.ndim(value) == 0
    try:
        raw = np.asarray(value)
    except Exception as exc:  # pragma: no cover - exotic array-likes
        raise TypeError(f"{name} must be a real number or array, got {value!r}") from exc
    if raw.dtype == object and raw.ndim == 0 and isinstance(value, numbers.Real):
        try:
            raw = np.asarray(float(value))  # e.g. a SymPy Float or Fraction
        except OverflowError:  # an integer beyond the float range
            digits = len(str(abs(int(value)))) if isinstance(value, numbers.Integral) else None
            shown = f"an integer of {digits} digits" if digits else repr(value)
            raise ValueError(
                f"{name} must be a finite float, got {shown} (beyond the float range)"
            ) from None
    if raw.dtype.kind not in "iuf":
        raise TypeError(
            f"{name} must be a real number or array of real numbers, got {value!r} "
            f"(dtype {raw.dtype})"
        )
    if raw.ndim and not isinstance(value, np.ndarray):
        # NumPy turns True into 1 inside a list of numbers; refuse it as for a scalar
        items = np.asarray(value, dtype=object)
        flags = np.frompyfunc(lambda x: isinstance(x, (bool, np.bool_)), 1, 1)(items)
        if flags.any():
            index = tuple(int(i[0]) for i in np.nonzero(flags.astype(bool)))
            raise TypeError(
                f"{name} must be a real number or array of real numbers, got the boolean "
                f"{items[index]!r} at index {index} of {value!r}"
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


def reject_strings(name: str, value: object) -> None:
    """Raise ``TypeError`` if ``value`` is or contains (at any depth) a string or bytes.

    SymPy parses strings as Python code, also the keys of a dict given to
    ``sympify(..., strict=True)`` and the entries of a list given to ``Matrix``; this
    check runs before any of them sees user input.

    >>> reject_strings("M", [[1, 2], [3, 4]])
    >>> reject_strings("M", [[1, "x"]])
    Traceback (most recent call last):
        ...
    TypeError: M must not contain strings (SymPy would run them as code), got 'x' at M[0][1]
    """
    _scan_strings(name, value, name)


def _scan_strings(name: str, value: object, where: str) -> None:
    if isinstance(value, _BYTES_OR_TEXT):
        raise TypeError(
            f"{name} must not contain strings (SymPy would run them as code), got {value!r}"
            + (f" at {where}" if where != name else "")
        )
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "USO":
            for index, item in np.ndenumerate(value):
                _scan_strings(name, item, where + "".join(f"[{i}]" for i in index))
        return
    if isinstance(value, Mapping):
        for key, item in value.items():
            _scan_strings(name, key, f"{where} key {key!r}")
            _scan_strings(name, item, f"{where}[{key!r}]")
    elif isinstance(value, (list, tuple, set, frozenset)):
        for i, item in enumerate(value):
            _scan_strings(name, item, f"{where}[{i}]")


def as_sympy(name: str, value: object, *, finite: bool = False) -> sp.Basic:
    """One SymPy expression from a number or SymPy object; never parses a string.

    Parameters
    ----------
    name
        Argument name used in error messages.
    value
        A Python or NumPy number or a SymPy expression. Strings, bytes, ``None``,
        booleans and containers (anything iterable, such as lists, ranges, generators,
        SymPy tuples, sets, matrices and arrays) are refused with ``TypeError``.
    finite
        Whether NaN and infinities (also inside an expression) are refused.

    >>> as_sympy("delay", 2)
    2
    >>> as_sympy("delay", "__import__('os')")
    Traceback (most recent call last):
        ...
    TypeError: delay must not contain strings (SymPy would run them as code), got "__import__('os')"
    >>> as_sympy("F", float("nan"), finite=True)
    Traceback (most recent call last):
        ...
    ValueError: F must be finite, got NaN
    """
    import sympy as sp  # here: the numeric kernels import this module without SymPy

    reject_strings(name, value)
    if value is None or isinstance(value, (bool, np.bool_, sp.logic.boolalg.BooleanAtom)):
        raise TypeError(f"{name} must be a number or SymPy expression, got {value!r}")
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (*_CONTAINERS, sp.MatrixBase, sp.NDimArray)):
        raise TypeError(f"{name} must be a single number or SymPy expression, got {value!r}")
    try:
        expr = sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError) as exc:
        raise TypeError(f"{name} must be a number or SymPy expression, got {value!r}") from exc
    if not isinstance(expr, sp.Basic) or isinstance(
        expr, (*_CONTAINERS, sp.MatrixBase, sp.NDimArray, sp.Set)
    ):
        raise TypeError(f"{name} must be a single number or SymPy expression, got {value!r}")
    if finite:
        _check_finite(name, expr, name)
    return expr


def _check_finite(name: str, expr: sp.Basic, where: str) -> None:
    import sympy as sp

    if expr.has(sp.nan):
        raise ValueError(f"{name} must be finite, got NaN" + _at(name, where))
    if expr.has(sp.oo, -sp.oo, sp.zoo):
        raise ValueError(f"{name} must be finite, got {expr}" + _at(name, where))


def _at(name: str, where: str) -> str:
    return "" if where == name else f" at {where}"


def as_sympy_matrix(name: str, value: object, *, finite: bool = False) -> sp.Matrix:
    """A SymPy matrix from a SymPy matrix or a (nested) sequence or array of numbers and
    expressions, each entry converted by :func:`as_sympy`; a scalar becomes ``1 x 1``.

    >>> as_sympy_matrix("F", [0, 1.5])
    Matrix([
    [  0],
    [1.5]])
    >>> as_sympy_matrix("M", [[1, float("nan")], [0, 1]], finite=True)
    Traceback (most recent call last):
        ...
    ValueError: M must be finite, got NaN at M[0, 1]
    """
    import sympy as sp

    reject_strings(name, value)
    if isinstance(value, sp.MatrixBase):
        matrix = sp.Matrix(value)
    else:
        if value is None or isinstance(value, (Mapping, set, frozenset)):
            raise TypeError(f"{name} must be a SymPy matrix or a numeric array, got {value!r}")
        try:
            arr = np.asarray(value, dtype=object)
        except ValueError as exc:  # ragged nesting
            raise ValueError(f"{name} must be a rectangular array, got {value!r}") from exc
        if arr.ndim == 0:
            arr = arr.reshape(1, 1)
        if arr.ndim > 2:
            raise ValueError(f"{name} must be a vector or a matrix, got {arr.ndim} dimensions")
        rows = arr if arr.ndim == 2 else arr.reshape(-1, 1)
        matrix = sp.Matrix(
            [
                [as_sympy(f"{name}[{i}, {j}]", item) for j, item in enumerate(row)]
                for i, row in enumerate(rows)
            ]
        )
    if finite:
        for (i, j), entry in np.ndenumerate(np.array(matrix.tolist(), dtype=object)):
            _check_finite(name, entry, f"{name}[{i}, {j}]")
    return matrix


def renamed(name: str, value: Any, former: str, former_value: Any, default: Any) -> Any:
    """The keyword ``name``, or its former name ``former``: one of the two, never both.

    Every renamed keyword of the package goes through here, so that all of them behave
    alike: ``default`` when neither is given, a ``TypeError`` naming both when both are.

    >>> renamed("t_max", None, "t_end", 8.0, 40.0), renamed("t_max", None, "t_end", None, 40.0)
    (8.0, 40.0)
    """
    if former_value is None:
        return default if value is None else value
    if value is not None:
        raise TypeError(f"give {name} or its former name {former}, not both")
    return former_value


def broadcast(**arrays: np.ndarray) -> tuple[int, ...]:
    """The common shape of the named arrays; ``ValueError`` naming them if there is none.

    >>> broadcast(D=np.zeros(3), f=np.zeros((2, 1)))
    (2, 3)
    >>> broadcast(D=np.zeros(3), f=np.zeros(4))
    Traceback (most recent call last):
        ...
    ValueError: D (shape (3,)) and f (shape (4,)) cannot be broadcast to one shape
    """
    try:
        return np.broadcast_shapes(*(np.shape(a) for a in arrays.values()))
    except ValueError:
        shaped = [(n, np.shape(a)) for n, a in arrays.items() if np.ndim(a) > 0]
        names = [f"{n} (shape {s})" for n, s in shaped]
        listed = ", ".join(names[:-1]) + f" and {names[-1]}" if len(names) > 1 else names[0]
        raise ValueError(f"{listed} cannot be broadcast to one shape") from None


@contextlib.contextmanager
def inputs_named(function: str, **inputs: object) -> Iterator[None]:
    """Re-raise a failure deep inside ``function`` as ``ValueError`` naming its inputs.

    Errors from derived quantities (a normalized force, a solver bracket) mean little to
    the caller; this adds the inputs that led there (the original stays chained).

    >>> with inputs_named("design", k=1e-300):
    ...     raise OverflowError("Numerical result out of range")
    Traceback (most recent call last):
        ...
    ValueError: design(k = 1e-300): Numerical result out of range
    """
    try:
        yield
    except (ValueError, ArithmeticError, RuntimeError, IndexError) as exc:
        shown = ", ".join(f"{name} = {_short(value)}" for name, value in inputs.items())
        message = exc.args[0] if len(exc.args) == 1 else str(exc)
        raise ValueError(f"{function}({shown}): {message}") from exc


def _short(value: object) -> str:
    if np.ndim(value) and not isinstance(value, str):
        return f"<array of shape {np.shape(value)}>"
    return repr(float(value)) if isinstance(value, (int, float, np.number)) else repr(value)
