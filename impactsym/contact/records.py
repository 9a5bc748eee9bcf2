"""Result records of the contact wing: equality over fields that hold arrays.

The results of :mod:`impactsym.contact` (:class:`~impactsym.contact.bounce.BounceSequence`,
:class:`~impactsym.contact.api.PhysicalContact`, ...) are frozen dataclasses whose fields
are NumPy arrays. The ``==`` a dataclass writes compares tuples of fields and so asks an
array for its truth value (``ValueError: The truth value of an array ... is ambiguous``),
and its ``hash`` hashes the arrays (``TypeError: unhashable type: 'numpy.ndarray'``).
:class:`ArrayRecord` gives them an ``==`` that compares arrays element by element and
makes them plainly unhashable (they hold mutable arrays).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np


def same_value(a: object, b: object) -> bool:
    """Whether two field values are equal: arrays by shape and elements, NaN equal to NaN.

    >>> same_value(np.array([1.0, np.nan]), np.array([1.0, np.nan]))
    True
    >>> same_value(np.array([1.0]), np.array([1.0, 1.0])), same_value(float("nan"), 0.0)
    (False, False)
    """
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        left, right = np.asarray(a), np.asarray(b)
        if left.shape != right.shape:
            return False
        numeric = left.dtype.kind in "fc" and right.dtype.kind in "fc"
        return bool(np.array_equal(left, right, equal_nan=numeric))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


class ArrayRecord:
    """Mixin for a frozen ``@dataclass(eq=False)`` whose fields may hold arrays.

    ``==`` holds between two records of the same class whose fields are all equal
    (:func:`same_value`); a record of another class is not equal. Records are
    unhashable: ``hash()`` raises ``TypeError: unhashable type``, as for the arrays
    they hold.

    >>> @dataclasses.dataclass(frozen=True, eq=False)
    ... class Pair(ArrayRecord):
    ...     x: np.ndarray
    >>> Pair(np.arange(3.0)) == Pair(np.arange(3.0)), Pair(np.arange(3.0)) == Pair(np.ones(3))
    (True, False)
    >>> hash(Pair(np.arange(3.0)))
    Traceback (most recent call last):
        ...
    TypeError: unhashable type: 'Pair'
    """

    __slots__ = ()
    __hash__ = None  # type: ignore[assignment]

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(
            same_value(getattr(self, field.name), getattr(other, field.name))
            for field in dataclasses.fields(self)  # type: ignore[arg-type]
        )
