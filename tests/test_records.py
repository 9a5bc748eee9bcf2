"""Array-aware equality and hashing of result records (impactsym.records)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from impactsym.records import ArrayRecord, values_equal


@dataclass(frozen=True, eq=False)
class Pair(ArrayRecord):
    speed: float
    time: Any
    parts: Any = ()
    note: str = field(default="", compare=False)


@dataclass(frozen=True, eq=False)
class Other(ArrayRecord):
    speed: float
    time: Any
    parts: Any = ()


def test_equal_arrays_compare_equal_and_different_ones_do_not():
    a = Pair(1.0, np.array([1.0, np.inf, np.nan]), (np.arange(3),))
    assert a == Pair(1.0, np.array([1.0, np.inf, np.nan]), (np.arange(3),))
    assert a != Pair(1.0, np.array([1.0, np.inf, 2.0]), (np.arange(3),))
    assert a != Pair(1.0, np.array([1.0, np.inf, np.nan]), (np.arange(4),))  # shape counts
    assert a != Pair(1.0, np.array([[1.0, np.inf, np.nan]]), (np.arange(3),))
    assert a != Other(1.0, np.array([1.0, np.inf, np.nan]), (np.arange(3),))  # class counts
    assert a == Pair(1.0, a.time, a.parts, note="not compared")
    assert a != "a pair"


def test_equal_records_hash_alike_also_with_nan_and_arrays():
    # hash(nan) differs per float object since Python 3.10: records must not inherit that
    a, b = Pair(float("nan"), np.zeros(2)), Pair(float("nan"), np.zeros(2))
    assert a == b
    assert hash(a) == hash(b)
    assert len({a, b, Pair(2.0, np.zeros(2))}) == 2
    assert hash(Pair(2.0, 3.0, (1, 2))) == hash(Pair(2.0, 3.0, (1, 2)))
    assert hash(Pair(1.0, [np.ones(2)], {"x": 1}))  # unhashable fields stay out

    @dataclass(frozen=True)
    class Plain:  # its generated hash raises on the array it holds
        table: Any

    nested = Pair(1.0, Plain(np.zeros(2)))
    assert hash(nested) == hash(Pair(1.0, Plain(np.zeros(2))))


def test_values_equal_on_nested_containers_and_mismatched_kinds():
    assert values_equal({"a": np.ones(2)}, {"a": np.ones(2)})
    assert not values_equal({"a": np.ones(2)}, {"b": np.ones(2)})
    assert not values_equal([np.ones(2)], (np.ones(2),))
    assert values_equal([1.0, (2.0, math.nan)], [1.0, (2.0, math.nan)])
    assert values_equal(float("nan"), float("nan"))
    assert not values_equal(np.array(["x"]), np.array([1.0]))
    assert not values_equal(np.zeros((2, 1)), np.zeros(2))


def test_the_multibody_results_compare_and_hash_by_value():
    from impactsym.multibody.examples import falling_bar

    bar = falling_bar()
    k = np.array([1e3, 2e3])
    a, b = bar.reduce(k, 1.0, 0.5), bar.reduce(k, 1.0, 0.5)
    assert a == b
    assert hash(a) == hash(b)
    assert a != bar.reduce(k, 2.0, 0.5)
    assert bar.reduce(1e3, 1.0, 0.5) == bar.reduce(1e3, 1.0, 0.5)
