"""Result records whose fields may be NumPy arrays: one ``==`` and one ``hash`` for all.

The package returns its results as frozen dataclasses. Their fields are floats for
scalar input and NumPy arrays for array input, and the ``__eq__`` and ``__hash__`` a
dataclass writes for itself fail on arrays: ``==`` raises NumPy's "truth value of an
array is ambiguous" and ``hash`` raises "unhashable type". A result class declared

.. code-block:: python

    @dataclass(frozen=True, eq=False)
    class Result(ArrayRecord): ...

gets instead:

* ``a == b`` when both are of the same class and their fields hold the same values
  (:func:`values_equal`: arrays element by element with their shapes, NaN equal to
  NaN -- a recomputed NaN is the same result --, containers and nested records item by
  item);
* a ``hash`` of the class and of the fields that hold no array (the scalar parameters
  a result was computed for), so records can be dictionary keys and set members, and
  equal records hash alike. Arrays stay out of the hash: their contents can change.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Hashable
from typing import Any

import numpy as np


def values_equal(a: Any, b: Any) -> bool:
    """Whether two values are the same result: dataclasses field by field, arrays element
    by element with their shapes, lists, tuples and dicts item by item, NaN equal to NaN.

    >>> values_equal([np.array([1.0, np.nan])], [np.array([1.0, np.nan])])
    True
    >>> values_equal(np.zeros(2), np.zeros(3)), values_equal([1.0], (1.0,))
    (False, False)
    """
    if a is b:
        return True
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            values_equal(getattr(a, fld.name), getattr(b, fld.name))
            for fld in dataclasses.fields(a)
            if fld.compare
        )
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        numeric = a.dtype.kind in "biufc" and b.dtype.kind in "biufc"
        return bool(np.array_equal(a, b, equal_nan=numeric))
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return (
            type(a) is type(b)
            and len(a) == len(b)
            and all(values_equal(x, y) for x, y in zip(a, b, strict=True))
        )
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(values_equal(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    try:
        return bool(a == b)
    except (TypeError, ValueError):  # an == that is not a truth value
        return False


def _hash_key(value: Any) -> Any:
    """``value`` as it enters a record's hash, or ``None`` to leave it out (arrays and
    anything unhashable). NaN enters as one key: ``hash(nan)`` differs per object."""
    if isinstance(value, float) and math.isnan(value):
        return "nan"
    if isinstance(value, np.ndarray):
        return None
    if isinstance(value, (list, tuple)):
        keys = tuple(_hash_key(v) for v in value)
        return None if any(k is None for k in keys) else keys
    if isinstance(value, dict) or not isinstance(value, Hashable):
        return None
    try:  # a plain frozen dataclass holding arrays says Hashable and then raises
        hash(value)
    except TypeError:
        return None
    return value


class ArrayRecord:
    """Mixin for a frozen ``@dataclass(eq=False)`` whose fields may hold arrays.

    >>> @dataclasses.dataclass(frozen=True, eq=False)
    ... class Pair(ArrayRecord):
    ...     speed: float
    ...     times: Any
    >>> a, b = Pair(1.0, np.array([1.0, np.inf])), Pair(1.0, np.array([1.0, np.inf]))
    >>> a == b, hash(a) == hash(b), a == Pair(1.0, np.array([1.0, 2.0])), len({a, b})
    (True, True, False, 1)
    """

    __slots__ = ()

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return values_equal(self, other)

    def __hash__(self) -> int:
        keys = [
            _hash_key(getattr(self, fld.name))
            for fld in dataclasses.fields(self)  # type: ignore[arg-type]
            if fld.compare
        ]
        return hash((type(self).__qualname__, *keys))
