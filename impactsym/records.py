"""Result records whose fields may be NumPy arrays.

The package returns its results as frozen dataclasses. Their fields are floats for
scalar input and NumPy arrays for array input, and the ``__eq__`` and ``__hash__`` a
dataclass writes for itself fail on arrays: ``==`` raises NumPy's "truth value of an
array is ambiguous" and ``hash`` raises "unhashable type". :func:`array_record` replaces
both:

* ``a == b`` is ``True`` when both are records of the same class whose fields are equal
  element by element (same shape; NaN equals NaN, as a result compared with itself
  must be equal); nested tuples, lists and dicts of arrays are compared the same way;
* ``hash(a)`` works when no field holds an array (scalar results can be dictionary
  keys and set members) and otherwise raises a ``TypeError`` that names the class and
  the field: an array's contents can change, so a hash of them would lie.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T", bound=type)


def values_equal(a: Any, b: Any) -> bool:
    """Element-wise equality of two field values, NaN equal to NaN, shapes included.

    >>> values_equal(np.array([1.0, np.nan]), np.array([1.0, np.nan]))
    True
    >>> values_equal((1, np.zeros(2)), (1, np.zeros(3)))
    False
    """
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        if a.dtype.kind in "fc" and b.dtype.kind in "fc":
            return bool(np.array_equal(a, b, equal_nan=True))
        return bool(np.array_equal(a, b))
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return type(a) is type(b) and len(a) == len(b) and all(map(values_equal, a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(values_equal(a[k], b[k]) for k in a)
    if dataclasses.is_dataclass(a) or dataclasses.is_dataclass(b):
        return bool(a == b)
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True  # NaN fields of two scalar results
    try:
        return bool(a == b)
    except (TypeError, ValueError):  # objects whose == is not a truth value
        return a is b


def _holds_array(value: Any) -> bool:
    if isinstance(value, np.ndarray):
        return True
    if isinstance(value, (tuple, list)):
        return any(map(_holds_array, value))
    if isinstance(value, dict):
        return any(map(_holds_array, value.values()))
    return False


def array_record(cls: T) -> T:
    """Class decorator (applied on top of ``@dataclass``): array-aware ``==`` and ``hash``.

    >>> from dataclasses import dataclass
    >>> @array_record
    ... @dataclass(frozen=True)
    ... class Result:
    ...     time: Any
    >>> Result(np.array([1.0, np.inf])) == Result(np.array([1.0, np.inf]))
    True
    >>> hash(Result(2.0)) == hash(Result(2.0))
    True
    >>> hash(Result(np.array([1.0])))
    Traceback (most recent call last):
    ...
    TypeError: Result is not hashable: its field 'time' holds a NumPy array
    """
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"array_record needs a dataclass, got {cls!r}")
    fields = [f.name for f in dataclasses.fields(cls) if f.compare]

    def equal(self: Any, other: Any) -> Any:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(values_equal(getattr(self, n), getattr(other, n)) for n in fields)

    def hashed(self: Any) -> int:
        values = tuple(getattr(self, n) for n in fields)
        for name, value in zip(fields, values, strict=True):
            if _holds_array(value):
                raise TypeError(
                    f"{type(self).__name__} is not hashable: its field {name!r} holds a NumPy array"
                )
        return hash((type(self).__qualname__, values))

    cls.__eq__ = equal  # type: ignore[method-assign]
    cls.__hash__ = hashed  # type: ignore[method-assign,assignment]
    return cls
