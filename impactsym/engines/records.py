"""Equality and hashing for the engines' result objects, which may hold NumPy arrays.

A frozen dataclass compares its fields as a tuple: with array fields ``==`` then asks
NumPy for the truth value of an elementwise comparison (``ValueError``: "ambiguous") and
``hash`` fails on the unhashable array with a message that names neither the object nor
the cause. :class:`ArrayRecord` compares field by field with :func:`numpy.array_equal`
(same shape, same values; NaN unequal as for floats) and hashes only records whose
fields are all scalars, refusing the others with a ``TypeError`` that says why.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["ArrayRecord"]


class ArrayRecord:
    """Mixin for ``@dataclass(frozen=True, eq=False)`` results that may hold arrays.

    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True, eq=False)
    ... class R(ArrayRecord):
    ...     x: object
    >>> R(np.arange(2)) == R(np.arange(2)), R(np.arange(2)) == R(np.arange(3))
    (True, False)
    >>> hash(R(1.0)) == hash(R(1.0))
    True
    """

    def _values(self) -> tuple:
        return tuple(getattr(self, f.name) for f in dataclasses.fields(self))

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(_same(a, b) for a, b in zip(self._values(), other._values(), strict=True))

    def __hash__(self) -> int:
        values = self._values()
        for field, value in zip(dataclasses.fields(self), values, strict=True):
            shape = _array_shape(value)
            if shape is not None:
                raise TypeError(
                    f"{type(self).__name__} holding arrays (field {field.name!r} has shape "
                    f"{shape}) is not hashable; compare it with == instead"
                )
        return hash((type(self).__name__, *(_key(v) for v in values)))


def _same(a: object, b: object) -> bool:
    if isinstance(a, ArrayRecord) or isinstance(b, ArrayRecord):
        return a == b
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        try:
            return bool(np.array_equal(a, b))
        except TypeError:  # pragma: no cover - exotic dtypes
            return False
    return bool(a == b)


def _array_shape(value: object) -> tuple[int, ...] | None:
    """The shape of the first array (``ndim > 0``) in ``value``, nested ones included."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return value.shape
    if isinstance(value, ArrayRecord):
        inner = (_array_shape(v) for v in value._values())
        return next((s for s in inner if s is not None), None)
    if isinstance(value, tuple):
        return next((s for s in map(_array_shape, value) if s is not None), None)
    return None


def _key(value: object) -> object:
    if isinstance(value, np.ndarray):  # 0-d
        return value.item()
    if isinstance(value, tuple):
        return tuple(_key(v) for v in value)
    return value
